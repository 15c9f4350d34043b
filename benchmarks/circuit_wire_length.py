"""Where a compiled circuit's connector length goes: each routed chain's half units against
its lane and against the straight line from its tap to its pin.

For every chain of each circuit built as ``mlc compile`` builds it (the builder's own
routing, with the router's cache off so that every solve runs and is seen):

* ``half_units``: the chain as built (each half unit is 1 sigma of chain, 4 slab bodies);
* ``guess``: the half units of the steered guess along the lane in the plane it was routed
  in (``mlc.circuit.route._steer``, what the inverse kinematics starts from), and ``extra``,
  the half units the router added beyond it before a length closed (``route._solve_route``
  tries ``extras`` in turn and keeps the first that closes);
* ``lane``: the length of the lane's polyline, tap - plane - riser - run - riser - crossing
  back - under the pin - pin (sigma), and ``straight``: the distance from the tap's pair to
  the pin's pair (sigma).

Per circuit: the sums, the bodies of the whole scene and of its chains, and the two ratios
half units / lane and lane / straight (what a shorter lane, and a router that closes
nearer its guess, could each take off).  A lane's length is measured on its corners, so a
chain following it with rounded corners may be a little shorter.

    python benchmarks/circuit_wire_length.py [--examples tetris.tt full_adder.tt mux4.blif snake3.tt compare2.aag]
        [--expr "y = (a & b) | (c ^ d)"]

Writes benchmarks/results/circuit_wire_length.json and .png.  Units: sigma.
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import re
import sys
from pathlib import Path

import mlc  # noqa: F401 -- before numpy: pins OpenBLAS's kernels (mlc/__init__.py)

import numpy as np

from gitstate import commit
from mlc.io.atomic import atomic_path

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "benchmarks" / "results"


def measure(name: str, spec) -> dict:
    import mlc.circuit.build as B
    import mlc.circuit.route as R
    from mlc.circuit.lanes import plane_y
    from mlc.pipeline import build, compile_spec

    guess_of: dict = {}                  # id(route) -> half units of its steered guess
    last = [0]
    steer, solve, route_chain = R._steer, R._solve_route, B._route_chain

    def steer_seen(*a, **k):
        g = steer(*a, **k)
        last[0] = len(g)
        return g

    def solve_seen(*a, **k):
        r = solve(*a, **k)
        if r is not None:
            guess_of[id(r)] = last[0]
        return r

    builds: list = []                    # the chains of each build (the builder may build twice)
    build_circuit = B._build_circuit

    def build_seen(*a, **k):
        builds.append({})
        return build_circuit(*a, **k)

    def route_chain_seen(ch, *a, **k):
        route_chain(ch, *a, **k)
        builds[-1][ch.tag] = ch

    saved = (R._steer, R._solve_route, B._route_chain, B._build_circuit, R.CACHE_SIZE)
    R._steer, R._solve_route, B._route_chain, B._build_circuit = steer_seen, solve_seen, route_chain_seen, build_seen
    R.CACHE_SIZE = 0
    try:
        c = build(compile_spec(spec))
    finally:
        R._steer, R._solve_route, B._route_chain, B._build_circuit, R.CACHE_SIZE = saved
    scene = c.circuit.scene
    built: dict = {}                     # chain -> half units in the scene kept
    for b in scene.bodies:
        m = re.match(r"(w_.+)_(\d+)_(?:AB|BC|CD|DA)$", b.name)
        if m:
            built[m.group(1)] = max(built.get(m.group(1), 0), int(m.group(2)) + 1)
    kept = [bd for bd in builds if {t: len(ch.route.bends) for t, ch in bd.items() if t in built} == built]
    if not kept:
        raise SystemExit(f"{name}: no build's chains match the scene's")
    rows = []
    for tag, ch in kept[-1].items():
        if tag not in built:
            continue
        r, ln = ch.route, ch.lane
        y = plane_y(ch.plane)
        c0, P = np.asarray(r.centre, float), np.asarray(ch.solve[2], float)
        pts = np.array([c0, (ln.x_r, y, ln.z_a), (ln.x_r, y, ln.z_run), (ln.x_in, y, ln.z_run),
                        (ln.x_in, y, ln.z_in), (ln.x_end, ch.yp - 1.0, ln.z_end), P], float)
        g = guess_of.get(id(r))
        rows.append({"chain": tag, "plane": int(ch.plane), "half_units": len(r.bends), "guess": g,
                     "extra": None if g is None else len(r.bends) - g,
                     "lane": float(np.linalg.norm(np.diff(pts, axis=0), axis=1).sum()),
                     "straight": float(np.linalg.norm(P - c0))})
    chain_bodies = sum(1 for b in scene.bodies if b.name.startswith("w_"))          # with branch pages and stubs
    tot = {k: float(sum(x[k] for x in rows)) for k in ("half_units", "lane", "straight")}
    known = [x for x in rows if x["extra"] is not None]
    return {"circuit": name, "gates": len(c.netlist.gates), "bodies": len(scene.bodies),
            "chain_bodies": chain_bodies, "chains": len(rows), "builds": len(builds), **{f"total_{k}": v for k, v in tot.items()},
            "total_extra": int(sum(x["extra"] for x in known)), "chains_with_guess": len(known),
            "half_units_over_lane": tot["half_units"] / tot["lane"] if tot["lane"] else None,
            "lane_over_straight": tot["lane"] / tot["straight"] if tot["straight"] else None,
            "rows": rows}


def plot(res: dict, path: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    pts = res["circuits"]
    fig, ax = plt.subplots(figsize=(8, 3.8))
    x = np.arange(len(pts))
    ax.bar(x - 0.27, [p["total_straight"] for p in pts], 0.27, label="straight tap to pin (sigma)")
    ax.bar(x, [p["total_lane"] for p in pts], 0.27, label="lane (sigma)")
    ax.bar(x + 0.27, [p["total_half_units"] for p in pts], 0.27, label="chain as built (half units, 1 sigma each)")
    for i, p in enumerate(pts):
        ax.text(i + 0.27, p["total_half_units"], f"+{p['total_extra']}", ha="center", va="bottom", fontsize=7)
    ax.set_xticks(x, [f"{p['circuit']}\n{p['bodies']} bodies" for p in pts], fontsize=7)
    ax.set_ylabel("summed over the chains")
    ax.set_title("connector length: straight, lane, built (label: half units added beyond the steered guesses)",
                 fontsize=8)
    ax.legend(fontsize=7)
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", dpi=120)
    plt.close(fig)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--examples", nargs="*",
                    default=["tetris.tt", "full_adder.tt", "mux4.blif", "snake3.tt", "compare2.aag"])
    ap.add_argument("--expr", nargs="*", default=["y = (a & b) | (c ^ d)"])
    args = ap.parse_args()
    from mlc.pipeline import load
    pts = []
    for ex in args.examples:
        pts.append(measure(ex, load(str(ROOT / "examples" / ex))))
        print(json.dumps({k: v for k, v in pts[-1].items() if k != "rows"}), flush=True)
    for e in args.expr:
        pts.append(measure(e, load(None, e)))
        print(json.dumps({k: v for k, v in pts[-1].items() if k != "rows"}), flush=True)
    tot = {k: sum(p[k] for p in pts) for k in ("total_half_units", "total_lane", "total_straight", "total_extra",
                                               "bodies", "chain_bodies")}
    res = {"benchmark": "circuit_wire_length", "commit": commit(),
           "machine": {"platform": platform.platform(), "python": sys.version.split()[0], "cpus": os.cpu_count()},
           "circuits": pts,
           "summary": {**tot, "half_units_over_lane": tot["total_half_units"] / tot["total_lane"],
                       "lane_over_straight": tot["total_lane"] / tot["total_straight"],
                       "half_units_over_straight": tot["total_half_units"] / tot["total_straight"],
                       "chain_body_fraction": tot["chain_bodies"] / tot["bodies"]}}
    OUT.mkdir(exist_ok=True)
    with atomic_path(OUT / "circuit_wire_length.json") as tmp:
        Path(tmp).write_text(json.dumps(res, indent=1))
    plot(res, OUT / "circuit_wire_length.png")
    print(json.dumps(res["summary"], indent=1))


if __name__ == "__main__":
    main()
