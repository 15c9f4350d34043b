"""Picture for docs/circuits.md: a connector chain bent while it carries a signal.

    python benchmarks/connector_figures.py [--units 8] [--signal expand] [-o docs/img/circuits_chain.png]

An ``--units``-unit chain (mlc.gates.connector.chain_scene) with every other junction
bent to 90% of its largest bend, solved statically (mlc.verify.static.equilibrium) in
both input states and drawn side by side: half units alternate in colour (each turned
90 degrees about the chain from the last), the muscle is drawn thick when actuated and
dashed at rest, and every probe (one per full unit) is labelled with the bit it reads.
Units: sigma.
"""
from __future__ import annotations

import argparse
import math
import os
import sys

import mlc  # noqa: F401 -- before numpy: pins OpenBLAS's kernels (mlc/__init__.py)
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))

from mlc.draw import box_faces  # noqa: E402
from mlc.gates.connector import chain_scene, connector_geometry, max_bend  # noqa: E402
from mlc.geometry.rotation import quat_to_matrix  # noqa: E402
from mlc.verify.static import equilibrium  # noqa: E402

LAYER_COLOURS = ("#9fb3c8", "#52677d")     # even / odd half units
MUSCLE = "#e0a800"
BIT_COLOURS = {0: "#2e6fbf", 1: "#c0392b"}


def draw(units: int, signal: str, path: str, frac: float = 0.9) -> dict:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    geo = connector_geometry(signal)
    bend = min(frac * max_bend(geo), math.pi / max(units - 1, 1))     # at most a U turn in all
    sc = chain_scene(units, signal, bend, probe_every_unit=True)
    eqs = {s: equilibrium(sc, s) for s in ("0", "1")}
    fig = plt.figure(figsize=(12.5, 6.4))
    allpts = []
    for e in eqs.values():
        for b, p, q in zip(sc.bodies, e.pos, e.quat):
            for box in b.boxes:
                allpts += list(np.concatenate(box_faces(box, p, quat_to_matrix(q))))
    allpts = np.array(allpts)
    lo, hi = allpts.min(0), allpts.max(0)
    ctr, half = 0.5 * (lo + hi), 0.5 * (hi - lo).max() * 0.56
    info = {}
    for k, (state, e) in enumerate(eqs.items()):
        ax = fig.add_subplot(1, 2, k + 1, projection="3d")
        view = sc.with_poses(e.pos, e.quat)
        for parity in (0, 1):
            faces = []
            for b, p, q in zip(sc.bodies, e.pos, e.quat):
                if int(b.name.split("_")[1]) % 2 != parity:
                    continue
                R = quat_to_matrix(q)
                for box in b.boxes:
                    faces += box_faces(box, p, R)
            ax.add_collection3d(Poly3DCollection(faces, facecolor=LAYER_COLOURS[parity], edgecolor="#34495e",
                                                 linewidths=0.25, alpha=0.7))
        m = sc.muscles[0]
        a, c = view.site_world(m.a), view.site_world(m.b)
        on = state == "1"
        ax.plot(*np.array([a, c]).T, color=MUSCLE, lw=5 if on else 2.2, ls="-" if on else (0, (3, 2)), zorder=9)
        for pr in sc.probes:
            a, c = view.site_world(pr.a), view.site_world(pr.b)
            L = e.probes[pr.name]
            bit = pr.bit(L)
            ax.plot(*np.array([a, c]).T, color=BIT_COLOURS[bit], lw=1.6, ls="--", zorder=9)
            if pr.name == "out":
                mid = 0.5 * (a + c)
                ax.text(mid[0], mid[1] - 0.6, mid[2] + 0.9, f"out = {bit}\n({L:.3f}$\\sigma$)", fontsize=10.5,
                        color=BIT_COLOURS[bit], ha="right", zorder=10)
        a = 0.5 * (view.site_world(m.a) + view.site_world(m.b))
        ax.text(a[0], a[1], a[2] - 0.55, f"a = {state}: muscle {'actuated' if on else 'at rest'}",
                fontsize=10, color="#8a6d00", ha="center", zorder=10)
        ax.set_xlim(ctr[0] - half, ctr[0] + half)
        ax.set_ylim(ctr[1] - half, ctr[1] + half)
        ax.set_zlim(ctr[2] - half, ctr[2] + half)
        ax.set_box_aspect((1, 1, 1), zoom=1.12)
        ax.view_init(elev=14, azim=28)
        ax.set_axis_off()
        reads = [f"{e.probes[p.name]:.3f}" for p in sc.probes]
        ax.set_title(f"input a = {state}: every unit reads {state} ({', '.join(sorted(set(reads)))} $\\sigma$)",
                     fontsize=11)
        info[state] = {p.name: e.probes[p.name] for p in sc.probes}
    handles = [plt.Line2D([], [], color=MUSCLE, lw=5, label="input muscle, actuated"),
               plt.Line2D([], [], color=MUSCLE, lw=2.2, ls=(0, (3, 2)), label="input muscle, at rest"),
               plt.Line2D([], [], color=BIT_COLOURS[0], ls="--", label="probe reading 0"),
               plt.Line2D([], [], color=BIT_COLOURS[1], ls="--", label="probe reading 1"),
               matplotlib.patches.Patch(facecolor=LAYER_COLOURS[0], label="half units 0, 2, 4, ..."),
               matplotlib.patches.Patch(facecolor=LAYER_COLOURS[1], label="half units 1, 3, 5, ... (turned 90°)")]
    fig.legend(handles=handles, loc="lower center", ncol=3, fontsize=9.5, frameon=False)
    fig.suptitle(f"{units}-unit connector chain ({signal}ing wires), the junctions between units bent by "
                 f"{math.degrees(bend):.1f}° (total {math.degrees(bend) * (units - 1):.0f}°), in both input states",
                 fontsize=12.5)
    fig.subplots_adjust(left=0, right=1, top=0.92, bottom=0.1, wspace=0)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return info


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--units", type=int, default=6)
    ap.add_argument("--signal", default="expand", choices=["expand", "contract"])
    ap.add_argument("-o", "--output", default=os.path.join(os.path.dirname(HERE), "docs", "img",
                                                           "circuits_chain.png"))
    a = ap.parse_args(argv)
    info = draw(a.units, a.signal, a.output)
    print(f"wrote {a.output}: probes {info}")


if __name__ == "__main__":
    main()
