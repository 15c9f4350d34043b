"""Pictures of a robot's skeleton (paper Fig. 6, top right): the skeleton seen from above
(its plane), its bodies in two alternating colours, the expected tetromino's grid cells
shaded behind it.  Units on the axes: sigma."""
from __future__ import annotations

import io

import numpy as np

from mlc.draw import INPUT_COLOURS, box_faces
from mlc.geometry.rotation import quat_to_matrix

_COLOURS = ("#e6b800", "#1f5fd1")      # alternating rigid bodies (paper Fig. 6)


def _skeleton_bodies(scene):
    return [i for i, b in enumerate(scene.bodies) if b.name.startswith("skel_")]


def _plane_frame(scene, pos, quat):
    """Origin and in-plane axes of the skeleton at a pose: the body (link 0) frame."""
    rm = scene.meta["robot"]
    i0 = next(i for i, b in enumerate(scene.bodies) if b.name == rm["links"][0])
    R = quat_to_matrix(quat[i0])
    return pos[i0], R


def draw_skeleton(ax, scene, pos, quat, title: str = "", cells=None):
    """Draw the skeleton at ``pos``/``quat`` into ``ax`` in its own plane (x along the
    body's heading); ``cells`` (grid cells of units 1..n) are shaded behind it."""
    from matplotlib.collections import PolyCollection
    from matplotlib.patches import Rectangle

    rm = scene.meta["robot"]
    l = float(rm["unit_length"])
    o, R = _plane_frame(scene, pos, quat)
    o = o + R @ np.array([0.0, 0.0, 0.0])
    polys, cols = [], []
    idx = _skeleton_bodies(scene)
    order = {n: k for k, n in enumerate(rm["links"])}
    for i in idx:
        b = scene.bodies[i]
        Rb = quat_to_matrix(quat[i])
        k = order.get(b.name)
        # a unit is a joint piece (yellow) and a link (blue); the body grey
        col = "#555555" if b.name == rm["links"][0] else _COLOURS[1 if b.name.startswith("skel_u") else 0]
        for box in b.boxes:
            faces = box_faces(box, pos[i], Rb)
            f = max(faces, key=lambda F: float(((F - o) @ R)[:, 2].mean()))     # the face on top
            loc = (f - o) @ R                            # into the skeleton's plane frame
            polys.append(loc[:, :2])
            cols.append(col)
        del k
    if cells:
        # the expected pose as grid cells, in an inset (the two-hinge joints pivot at the
        # units' corners, so the folded skeleton is not centred on the cells)
        ins = ax.inset_axes([0.68, 0.02, 0.3, 0.3])
        for k, c in enumerate([(0, 0)] + [tuple(c) for c in cells]):
            ins.add_patch(Rectangle((c[0] - 0.45, c[1] - 0.45), 0.9, 0.9, facecolor="#555555" if k == 0 else
                                    _COLOURS[1], alpha=0.6))
        xs = [c[0] for c in cells] + [0]
        ys = [c[1] for c in cells] + [0]
        ins.set_xlim(min(xs) - 0.6, max(xs) + 0.6)
        ins.set_ylim(min(ys) - 0.6, max(ys) + 0.6)
        ins.set_aspect("equal")
        ins.set_xticks([])
        ins.set_yticks([])
        ins.set_title("expected", fontsize=6, pad=1)
    ax.add_collection(PolyCollection(polys, facecolors=cols, edgecolors="k", linewidths=0.3, zorder=2))
    ax.set_aspect("equal")
    ax.set_title(title, fontsize=9)
    n = int(rm["units"])
    pts = np.concatenate(polys)
    span = max((n + 1.5) * l, float(np.ptp(pts[:, 0])) + 2, float(np.ptp(pts[:, 1])) + 2)
    cx, cy = 0.5 * (pts[:, 0].min() + pts[:, 0].max()), 0.5 * (pts[:, 1].min() + pts[:, 1].max())
    ax.set_xlim(cx - 0.5 * span, cx + 0.5 * span)
    ax.set_ylim(cy - 0.5 * span, cy + 0.5 * span)
    ax.tick_params(labelsize=6)


def render_shapes(scene, poses: dict, rows_info: dict, title: str | None = None) -> bytes:
    """PNG bytes: the skeleton of every row side by side.  ``poses``: row -> (pos, quat);
    ``rows_info``: row -> a report row (shape_read, shape_expected, cells_expected)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = sorted(poses)
    fig, axes = plt.subplots(1, len(rows), figsize=(3.0 * len(rows), 3.4), squeeze=False)
    inputs = scene.inputs
    for ax, r in zip(axes[0], rows):
        info = rows_info.get(r, {})
        bits = " ".join(f"{n}={v}" for n, v in zip(inputs, r))
        t = f"{bits}\nread {info.get('shape_read', '?')}, expected {info.get('shape_expected', '?')}"
        draw_skeleton(ax, scene, *poses[r], t, info.get("cells_expected"))
    for k, n in enumerate(inputs):
        axes[0][0].plot([], [], color=INPUT_COLOURS[k % len(INPUT_COLOURS)], label=n)
    fig.suptitle(title or scene.name, fontsize=10)
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110)
    plt.close(fig)
    return buf.getvalue()


def render_frames(scene, frames_pos, frames_quat, times, title: str, cells=None, progress=None) -> list[bytes]:
    """PNG bytes of each frame of a fold (the skeleton only); ``progress(k)`` after the k-th frame."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    out = []
    for p, q, t in zip(frames_pos, frames_quat, times):
        fig, ax = plt.subplots(figsize=(4.0, 3.6))
        draw_skeleton(ax, scene, p, q, f"{title}  t = {t:.1f} t0", cells)
        fig.tight_layout()
        buf = io.BytesIO()
        fig.savefig(buf, format="png", dpi=80)
        plt.close(fig)
        out.append(buf.getvalue())
        if progress is not None:
            progress(len(out))
    return out


def gif_bytes(pngs: list[bytes], ms: int = 120) -> bytes:
    """An animated GIF of PNG frames (Pillow, which matplotlib already needs)."""
    from PIL import Image

    ims = [Image.open(io.BytesIO(b)).convert("P", palette=Image.ADAPTIVE) for b in pngs]
    buf = io.BytesIO()
    ims[0].save(buf, format="GIF", save_all=True, append_images=ims[1:], duration=ms, loop=0)
    return buf.getvalue()


__all__ = ["draw_skeleton", "gif_bytes", "render_frames", "render_shapes"]
