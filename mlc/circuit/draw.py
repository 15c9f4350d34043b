"""A picture of a circuit scene: the mechanism seen from the front (x, z) and from the
side (y, z), gates labelled with their id and type, input muscles marked in their input's
colour, output probes named.  Labels of one kind whose anchors fall within ``MERGE_FRACTION``
of the view's span of each other (gates stacked behind one another in the side view, probes
of outputs wired to one pair) are written once, their names joined.  Units on the axes: sigma."""
from __future__ import annotations

import numpy as np

from mlc.draw import INPUT_COLOURS, box_faces

_WIRE = "#7a8793"
_GATE = "#3b4a57"
MERGE_FRACTION = 0.03       # labels this close (a fraction of the view's larger span) are merged
MERGE_SHOWN = 4             # names written in one merged label; the rest are counted


def merge_labels(labels: list, span: float, sep: str = ", ") -> list:
    """Labels ``(x, y, text)`` whose anchors lie within ``MERGE_FRACTION * span`` of the first
    label of a group (in order) become one label at that first anchor, their texts joined by
    ``sep`` (each text once, in order; past ``MERGE_SHOWN`` names, "+N more").  Returns
    ``[(x, y, text)]``."""
    tol = MERGE_FRACTION * max(float(span), 1e-9)
    groups: list = []
    for x, y, text in labels:
        for g in groups:
            if abs(g[0] - x) <= tol and abs(g[1] - y) <= tol:
                if text not in g[2]:
                    g[2].append(text)
                break
        else:
            groups.append([x, y, [text]])
    return [(x, y, sep.join(texts if len(texts) <= MERGE_SHOWN
                             else texts[:MERGE_SHOWN - 1] + [f"+{len(texts) - MERGE_SHOWN + 1} more"]))
            for x, y, texts in groups]


def _merged(ax, labels: list, prefix: str, span: float, sep: str = ", ", **style) -> None:
    """Annotate ``ax`` with the merged labels: ``prefix`` once, then the names."""
    for x, y, text in merge_labels(labels, span, sep):
        ax.annotate(f"{prefix}{text}", (x, y), **style)


def render_circuit(scene, pos=None, quat=None, title: str | None = None) -> bytes:
    """PNG bytes of ``scene`` at poses ``pos``/``quat`` (default: its own)."""
    import io

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.collections import PolyCollection

    from mlc.geometry.rotation import quat_to_matrix

    A = scene.arrays()
    pos = A.pos if pos is None else np.asarray(pos)
    quat = A.quat if quat is None else np.asarray(quat)
    gates = scene.meta.get("gates", {}) if isinstance(scene.meta, dict) else {}
    gate_of = {}
    for b in scene.bodies:
        head = b.name.split("_", 1)[0]
        gate_of[b.name] = head if head in gates else None
    faces = {"gate": ([], []), "wire": ([], [])}
    for b, p, q in zip(scene.bodies, pos, quat):
        R = quat_to_matrix(q)
        kind = "gate" if gate_of[b.name] else "wire"
        for box in b.boxes:
            for f in box_faces(box, p, R):
                faces[kind][0].append(f[:, [0, 2]])
                faces[kind][1].append(f[:, [1, 2]])
    span = np.ptp(pos, axis=0) if len(pos) else np.ones(3)
    wx = max(span[0], 4.0)
    wy = max(span[1], 4.0)
    fig, axes = plt.subplots(1, 2, figsize=(11, 6.5), gridspec_kw={"width_ratios": [wx, max(wy, 0.35 * wx)]})
    for k, (ax, view) in enumerate(zip(axes, ("front (x, z)", "side (y, z)"))):
        for kind, colour, lw in (("wire", _WIRE, 0.3), ("gate", _GATE, 0.5)):
            polys = faces[kind][k]
            if polys:
                ax.add_collection(PolyCollection(polys, facecolors=colour, edgecolors=colour, linewidths=lw,
                                                 alpha=0.55 if kind == "wire" else 0.8))
        c = [0, 2] if k == 0 else [1, 2]
        view_span = max(float(np.ptp(pos[:, c[0]])) if len(pos) else 1.0,
                        float(np.ptp(pos[:, c[1]])) if len(pos) else 1.0)
        gate_labels = []
        for gid, g in gates.items():
            o = np.asarray(g["origin"], float)
            xy = (o[0], o[2] - 1.2) if k == 0 else (o[1] + 1.2, o[2] - 1.2)
            gate_labels.append((xy[0], xy[1], f"{gid} {g['type']}"))
        _merged(ax, gate_labels, "", view_span, "\n", ha="center", va="top", fontsize=8, color="#b03a2e",
                fontweight="bold")
        in_labels, colour_of = [], {}
        for m in scene.muscles:
            colour = INPUT_COLOURS[scene.inputs.index(m.input) % len(INPUT_COLOURS)]
            colour_of[m.input] = colour
            p1, p2 = scene_point(scene, pos, quat, m.a), scene_point(scene, pos, quat, m.b)
            ax.plot([p1[c[0]], p2[c[0]]], [p1[c[1]], p2[c[1]]], color=colour, lw=3.0, solid_capstyle="round")
            mid = 0.5 * (p1 + p2)
            in_labels.append((mid[c[0]], mid[c[1]], m.input))
        for x, y, names in merge_labels(in_labels, view_span, "\n"):
            # muscles drawn on one spot (seen end on): one line per input, each in its colour
            for j, name in enumerate(names.split("\n")):
                ax.annotate(name if name.endswith(" more") else f"in {name}", (x, y), xytext=(0, -12 * (j + 1)),
                            textcoords="offset points", ha="center", fontsize=8,
                            color=colour_of.get(name, "black"), fontweight="bold")
        probe_labels = []
        for pr in scene.probes:
            p1, p2 = scene_point(scene, pos, quat, pr.a), scene_point(scene, pos, quat, pr.b)
            ax.plot([p1[c[0]], p2[c[0]]], [p1[c[1]], p2[c[1]]], color="#2a9d3a", lw=2.0, ls="--")
            mid = 0.5 * (p1 + p2)
            probe_labels.append((mid[c[0]], mid[c[1]], pr.output))
        _merged(ax, probe_labels, "out ", view_span, xytext=(0, 6), textcoords="offset points", ha="center",
                fontsize=7, color="#2a9d3a")
        ax.set_aspect("equal")
        ax.autoscale_view()
        ax.margins(0.05)
        ax.set_xlabel(("x" if k == 0 else "y") + r" ($\sigma$)")
        ax.set_ylabel(r"z ($\sigma$)")
        ax.set_title(view, fontsize=9)
    fig.suptitle(title or f"{scene.name}: {len(gates)} gates, {len(scene.bodies)} bodies "
                 f"(gates dark, connectors grey; muscles coloured by input, probes green dashed)", fontsize=9)
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, dpi=120, format="png")
    plt.close(fig)
    return buf.getvalue()


def scene_point(scene, pos, quat, ref: str) -> np.ndarray:
    from mlc.geometry.rotation import quat_to_matrix
    body, site = ref.split(".", 1)
    i = next(k for k, b in enumerate(scene.bodies) if b.name == body)
    return pos[i] + quat_to_matrix(quat[i]) @ scene.bodies[i].sites[site]


__all__ = ["render_circuit"]
