"""Pictures: the Fig. 1B design space and 3D renders of scenes in their input states.

All drawing goes through matplotlib's non-interactive Agg back end; files are written
atomically."""
from __future__ import annotations

import itertools

import numpy as np

from mlc.geometry.rotation import quat_to_matrix
from mlc.io.atomic import atomic_path

# Muscle colours per input, as in the paper: the first input yellow, the second blue.
INPUT_COLOURS = ["#e6b800", "#1f5fd1", "#d1361f", "#2a9d3a", "#8e44ad", "#e67e22"]
SLAB_COLOUR = "#9aa4ad"


def _plt():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def _save(fig, path):
    with atomic_path(path, suffix=".png") as tmp:
        fig.savefig(tmp, dpi=130, format="png")
    _plt().close(fig)


def plot_design_space(space: dict, path, marker=(0.5, 2.0)) -> None:
    """Fig. 1B: dout vs din for several h, the accessible boundary dotted, the slope-one line."""
    plt = _plt()
    fig, ax = plt.subplots(figsize=(5.2, 4.2))
    for h, pts in space["curves"].items():
        if pts:
            d, o = np.array(pts).T
            ax.plot(d, o, lw=1.6, label=f"h = {h:g} $\\sigma$")
    b = np.array(space["boundary"])
    if len(b):
        ax.plot(b[:, 1], b[:, 2], "k:", lw=1.4, label="accessible boundary")
    lim = max(2.0, float(b[:, 2].max()) if len(b) else 2.0)
    ax.plot([0, lim], [0, lim], "k-", lw=0.8, label="slope one")
    if marker:
        from mlc.geometry.core import solve_core
        s = solve_core(*marker)
        ax.plot([s.din], [s.dout], "o", mfc="none", mec="k", ms=9, label=f"this work ({s.din:g}, {s.dout:.3f})")
    ax.set_xlabel(r"$\Delta_{in}/\sigma$")
    ax.set_ylabel(r"$\Delta_{out}/\sigma$")
    ax.set_title("Logic core design space (Fig. 1B)")
    ax.set_xlim(0, None)
    ax.set_ylim(0, None)
    ax.legend(fontsize=7, loc="upper left")
    fig.tight_layout()
    _save(fig, path)


def box_faces(box, pos, R) -> list[np.ndarray]:
    """The six faces (world coordinates) of a body's box at pose (pos, R)."""
    Rb = quat_to_matrix(box.orientation)
    half = 0.5 * np.asarray(box.size)
    corners = np.array([[sx, sy, sz] for sx, sy, sz in itertools.product((-1, 1), repeat=3)]) * half
    world = pos + (R @ (box.center + corners @ Rb.T).T).T
    idx = [(0, 1, 3, 2), (4, 5, 7, 6), (0, 1, 5, 4), (2, 3, 7, 6), (0, 2, 6, 4), (1, 3, 7, 5)]
    return [world[list(f)] for f in idx]


# World (x, y, z) -> display (x, z, y): the scene's y axis (a gate's bisector, "up" in
# paper Fig. 1A) is drawn vertical and the core plane faces the viewer.
_VIEW = [0, 2, 1]


def _draw_scene(ax, scene, pos, quat, state: str, probe_lengths: dict):
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection
    faces = []
    for b, p, q in zip(scene.bodies, pos, quat):
        R = quat_to_matrix(q)
        for box in b.boxes:
            faces += [f[:, _VIEW] for f in box_faces(box, p, R)]
    ax.add_collection3d(Poly3DCollection(faces, facecolor=SLAB_COLOUR, edgecolor="#4a5560", linewidths=0.3, alpha=0.9))
    site = {}
    for b, p, q in zip(scene.bodies, pos, quat):
        R = quat_to_matrix(q)
        for k, v in b.sites.items():
            site[f"{b.name}.{k}"] = (p + R @ v)[_VIEW]
    bits = dict(zip(scene.inputs, state))
    for m in scene.muscles:
        i = scene.inputs.index(m.input)
        a, c = site[m.a], site[m.b]
        on = bits.get(m.input) == "1"
        ax.plot(*np.array([a, c]).T, color=INPUT_COLOURS[i % len(INPUT_COLOURS)], lw=5 if on else 3,
                solid_capstyle="round", alpha=1.0 if on else 0.6)
    for pr in scene.probes:
        a, c = site[pr.a], site[pr.b]
        ax.plot(*np.array([a, c]).T, color="k", ls="--", lw=1)
    allp = np.array(list(site.values()))
    ctr = 0.5 * (allp.max(0) + allp.min(0))
    r = 0.55 * float((allp.max(0) - allp.min(0)).max())
    ax.set_xlim(ctr[0] - r, ctr[0] + r)
    ax.set_ylim(ctr[1] - r, ctr[1] + r)
    ax.set_zlim(ctr[2] - r, ctr[2] + r)
    ax.set_box_aspect((1, 1, 1))
    ax.view_init(elev=20, azim=-58)
    ax.set_axis_off()


def draw_scene_states(scene, equilibria: dict, path, title: str | None = None) -> None:
    """Render a scene in each of its input states (like paper Fig. 2C), one panel per state.

    ``equilibria`` maps state -> object with ``pos``, ``quat`` and ``probes``."""
    plt = _plt()
    states = list(equilibria)
    n = len(states)
    cols = min(n, 2 if n == 4 else 4)
    rows = int(np.ceil(n / cols))
    fig = plt.figure(figsize=(4.2 * cols, 4.0 * rows))
    for k, st in enumerate(states):
        eq = equilibria[st]
        ax = fig.add_subplot(rows, cols, k + 1, projection="3d")
        _draw_scene(ax, scene, eq.pos, eq.quat, st, eq.probes)
        ins = ", ".join(f"{n_}={v}" for n_, v in zip(scene.inputs, st))
        outs = []
        for pr in scene.probes:
            L = eq.probes[pr.name]
            outs.append(f"{pr.output}={pr.bit(L)} ({L:.3f}$\\sigma$)")
        ax.set_title(f"{ins}  ->  {', '.join(outs)}", fontsize=10)
    handles = [plt.Line2D([], [], color=INPUT_COLOURS[i % len(INPUT_COLOURS)], lw=4, label=f"muscle {n_}")
               for i, n_ in enumerate(scene.inputs)]
    handles.append(plt.Line2D([], [], color="k", ls="--", label="output probe"))
    fig.legend(handles=handles, loc="lower center", ncol=len(handles), fontsize=9)
    fig.suptitle(title or scene.name, fontsize=12)
    fig.tight_layout(rect=(0, 0.05, 1, 0.97))
    _save(fig, path)
