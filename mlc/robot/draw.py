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
        col = "#555555" if b.name == rm["links"][0] else _COLOURS[(int(b.name[6:]) if b.name.startswith("skel_u")
                                                                   else int(b.name[6:]) + 1) % 2]
        for box in b.boxes:
            f = box_faces(box, pos[i], Rb)[1]            # the top face
            loc = (f - o) @ R                            # into the skeleton's plane frame
            polys.append(loc[:, :2])
            cols.append(col)
        del k
    for c in cells or []:
        ax.add_patch(Rectangle(((c[0] - 0.5) * l, (c[1] - 0.5) * l), l, l, facecolor="#dddddd",
                               edgecolor="#bbbbbb", zorder=0))
    ax.add_patch(Rectangle((-0.5 * l, -0.5 * l), l, l, facecolor="#bbbbbb", edgecolor="#999999", zorder=0))
    ax.add_collection(PolyCollection(polys, facecolors=cols, edgecolors="k", linewidths=0.3, zorder=2))
    ax.set_aspect("equal")
    ax.set_title(title, fontsize=9)
    ax.set_xlim(-0.75 * l, 4.75 * l)
    ax.set_ylim(-2.25 * l, 2.25 * l)
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


def render_frames(scene, frames_pos, frames_quat, times, title: str, cells=None) -> list[bytes]:
    """PNG bytes of each frame of a fold (the skeleton only)."""
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
    return out


def gif_bytes(pngs: list[bytes], ms: int = 120) -> bytes:
    """An animated GIF of PNG frames (Pillow, which matplotlib already needs)."""
    from PIL import Image

    ims = [Image.open(io.BytesIO(b)).convert("P", palette=Image.ADAPTIVE) for b in pngs]
    buf = io.BytesIO()
    ims[0].save(buf, format="GIF", save_all=True, append_images=ims[1:], duration=ms, loop=0)
    return buf.getvalue()


__all__ = ["draw_skeleton", "gif_bytes", "render_frames", "render_shapes"]
