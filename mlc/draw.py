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
_JOINT_MARKERS = {"hinge": ("o", "hinge"), "universal": ("D", "universal joint"), "bond": ("s", "bond")}
#: Largest extent drawn (sigma): a gate spans about 5, a large circuit a few thousand.
MAX_SPAN = 1e6
#: Scenes with more bodies than this get no slab names (they would cover the picture).
MAX_NAMED_BODIES = 40


def _scene_geometry(scene, pos, quat):
    """Display coordinates of every box face, site, body centre and joint at one pose."""
    faces, body_centres, site = [], {}, {}
    for b, p, q in zip(scene.bodies, pos, quat):
        R = quat_to_matrix(q)
        bf = []
        for box in b.boxes:
            bf += [f[:, _VIEW] for f in box_faces(box, p, R)]
        faces += bf
        for k, v in b.sites.items():
            site[f"{b.name}.{k}"] = (p + R @ v)[_VIEW]
        c = np.concatenate(bf).mean(0) if bf else np.asarray(p)[_VIEW]
        # label halfway to the farthest site: the two halves of a scissor lever share a centre
        far = max((site[f"{b.name}.{k}"] for k in b.sites), key=lambda x: float(np.linalg.norm(x - c)),
                  default=c)
        body_centres[b.name] = c + 0.5 * (far - c)
    joints: dict = {}
    for bd in scene.bonds:
        name = bd.joint or bd.name
        joints.setdefault(name, (bd.kind, []))[1].extend([site[bd.a], site[bd.b]])
    joints = {k: (kind, np.mean(pts, axis=0)) for k, (kind, pts) in joints.items()}
    return faces, body_centres, site, joints


def _draw_scene(ax, scene, pos, quat, state: str, probe_lengths: dict, names: bool = False):
    """One panel: slabs, joints (markers), muscles (solid = actuated, dashed = at rest), probes.

    With ``names``, slabs and joints are labelled by their names in the scene file."""
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection
    faces, centres, site, joints = _scene_geometry(scene, pos, quat)
    ax.add_collection3d(Poly3DCollection(faces, facecolor=SLAB_COLOUR, edgecolor="#4a5560", linewidths=0.3,
                                         alpha=0.55))
    for name, (kind, x) in joints.items():
        mk = _JOINT_MARKERS.get(kind, ("s", kind))[0]
        ax.plot([x[0]], [x[1]], [x[2]], mk, ms=4.5, mfc="white", mec="k", mew=0.8, zorder=5)
        if names:
            ax.text(x[0], x[1], x[2], "  " + name, fontsize=6, color="#5d6d7e", va="top", zorder=6)
    if names and len(scene.bodies) <= MAX_NAMED_BODIES:
        for name, c in centres.items():
            ax.text(c[0], c[1], c[2], name, fontsize=7, color="#1b2631", ha="center", va="center", zorder=7,
                    bbox=dict(boxstyle="round,pad=0.15", fc="white", ec="none", alpha=0.75))
    bits = dict(zip(scene.inputs, state))
    for m in scene.muscles:
        i = scene.inputs.index(m.input)
        a, c = site[m.a], site[m.b]
        on = bits.get(m.input) == "1"
        col = INPUT_COLOURS[i % len(INPUT_COLOURS)]
        ax.plot(*np.array([a, c]).T, color=col, lw=5 if on else 2.2, ls="-" if on else (0, (3, 2)),
                solid_capstyle="round", zorder=8)
        mid = 0.5 * (a + c)
        ax.text(mid[0], mid[1], mid[2], f"{m.input}={'1' if on else '0'}: {'actuated' if on else 'at rest'}",
                fontsize=7.5, color=col, fontweight="bold" if on else "normal", zorder=9,
                bbox=dict(boxstyle="round,pad=0.15", fc="white", ec="none", alpha=0.8))
    for pr in scene.probes:
        a, c = site[pr.a], site[pr.b]
        ax.plot(*np.array([a, c]).T, color="k", ls="--", lw=1.2, zorder=8)
        mid = 0.5 * (a + c)
        L = probe_lengths.get(pr.name)
        label = f"  {pr.output}={pr.bit(L)}" if L is not None else f"  {pr.output}"
        ax.text(mid[0], mid[1], mid[2], label, fontsize=8, color="k", zorder=9)
    allp = np.concatenate([np.concatenate(faces)] + [np.array(list(site.values()))]) if faces else \
        np.array(list(site.values()))
    lo, hi = allp.min(0), allp.max(0)
    ctr = 0.5 * (lo + hi)
    half = 0.5 * np.maximum(hi - lo, 0.05 * float((hi - lo).max() or 1.0)) * 1.04
    ax.set_xlim(ctr[0] - half[0], ctr[0] + half[0])
    ax.set_ylim(ctr[1] - half[1], ctr[1] + half[1])
    ax.set_zlim(ctr[2] - half[2], ctr[2] + half[2])
    ax.set_box_aspect(tuple(half / half.max()), zoom=1.25)   # true proportions, filling the panel
    ax.view_init(elev=20, azim=-58)
    ax.set_axis_off()


def draw_scene_states(scene, equilibria: dict, path, title: str | None = None) -> None:
    """Render a scene in each of its input states (like paper Fig. 2C), one panel per state.

    ``equilibria`` maps state -> object with ``pos``, ``quat`` and ``probes``.  The first
    panel names the slabs and joints; every panel marks each muscle actuated (thick, solid)
    or at rest (thin, dashed) and reads the output probe."""
    from mlc.errors import MlcError
    for st, eq in equilibria.items():
        with np.errstate(all="ignore"):
            span = float(np.ptp(np.asarray(eq.pos), axis=0).max()) if len(eq.pos) else 0.0
        if not (np.isfinite(np.asarray(eq.pos)).all() and span <= MAX_SPAN):
            raise MlcError(f"cannot draw input state {st}: the mechanism spans {span:.3g} sigma (limit {MAX_SPAN:g})",
                           scene.source or scene.name, "check the scene's lengths and positions (sigma)")
    plt = _plt()
    states = list(equilibria)
    n = len(states)
    cols = min(n, 2 if n == 4 else 4)
    rows = int(np.ceil(n / cols))
    fig = plt.figure(figsize=(5.6 * cols, 5.2 * rows))
    for k, st in enumerate(states):
        eq = equilibria[st]
        ax = fig.add_subplot(rows, cols, k + 1, projection="3d")
        _draw_scene(ax, scene, eq.pos, eq.quat, st, eq.probes, names=(k == 0))
        ins = ", ".join(f"{n_}={v}" for n_, v in zip(scene.inputs, st))
        outs = []
        for pr in scene.probes:
            L = eq.probes[pr.name]
            outs.append(f"{pr.output}={pr.bit(L)} ({L:.3f}$\\sigma$)")
        ax.set_title(f"{ins}  ->  {', '.join(outs)}" + ("\n(slabs and joints named)" if k == 0 else ""),
                     fontsize=10)
    handles = []
    for i, n_ in enumerate(scene.inputs):
        col = INPUT_COLOURS[i % len(INPUT_COLOURS)]
        handles.append(plt.Line2D([], [], color=col, lw=5, label=f"muscle {n_} actuated ({n_} = 1)"))
        handles.append(plt.Line2D([], [], color=col, lw=2.2, ls=(0, (3, 2)), label=f"muscle {n_} at rest ({n_} = 0)"))
    handles.append(plt.Line2D([], [], color="k", ls="--", label="output probe (length read as a bit)"))
    kinds = sorted({bd.kind for bd in scene.bonds})
    for kind in kinds:
        mk, label = _JOINT_MARKERS.get(kind, ("s", kind))
        handles.append(plt.Line2D([], [], ls="", marker=mk, mfc="white", mec="k", label=label))
    handles.append(plt.matplotlib.patches.Patch(facecolor=SLAB_COLOUR, edgecolor="#4a5560", label="rigid slab"))
    fig.legend(handles=handles, loc="lower center", ncol=min(len(handles), 4), fontsize=9, frameon=False)
    fig.suptitle(title or scene.name, fontsize=13)
    nrow_leg = int(np.ceil(len(handles) / 4))
    fig.subplots_adjust(left=0.0, right=1.0, top=0.93, bottom=0.03 + 0.035 * nrow_leg, wspace=0.0, hspace=0.08)
    _save(fig, path)
