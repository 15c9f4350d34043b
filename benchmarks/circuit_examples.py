"""Every example as a circuit: size, build time, static verification of every row.

For each logic file in ``examples/`` (the same set as ``tests/test_circuit_examples.py``):
compile (synthesis, mapping, proof), build the circuit scene, verify it statically on
every row of its truth table, and record gates, bodies, chains, half units, the chains
the router flagged tight, the build and verification wall times, the rows read right,
the largest joint stretch and the smallest slab clearance per row (exact oriented-box
test) with the pair of bodies that sets it.

    python benchmarks/circuit_examples.py [--only tetris.tt ...] [--joint-k K] [--direct] [--jobs N]

With ``--only`` the other examples' last entries are kept (each entry names its commit).
``--joint-k K`` builds with connector joints K times k0 (``mlc compile --joint-k``);
``--direct`` with direct gate-to-gate connections (``mlc compile --direct``; the nets made
direct and those dropped as crossed are recorded), into ``circuit_examples_direct.json``.

``--jobs N`` routes in N processes and verifies N rows at once (``mlc compile --jobs``,
``mlc verify --jobs``: the same scenes and results; the build's and the verification's wall
time is then not one core's).
Writes benchmarks/results/circuit_examples.json (``circuit_examples_jointk{K}.json`` with ``--joint-k``).  Wall seconds on this machine in one
run (shared, noisy): compare ratios, not absolute numbers across machines.
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import time
from pathlib import Path

from mlc.circuit.build import CircuitOptions
from mlc.pipeline import build, compile_spec, load
from mlc.verify.circuit import verify_static
from gitstate import commit as git_commit      # benchmarks/gitstate.py

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "benchmarks" / "results"
SUFFIXES = (".tt", ".pla", ".expr", ".blif", ".aag")


def example_point(path: Path, joint_k: float | None = None, direct: bool = False, jobs: int = 1) -> dict:
    t0 = time.perf_counter()
    compiled = compile_spec(load(str(path)))
    t1 = time.perf_counter()
    kw = {} if joint_k is None else {"joint_k": joint_k}
    compiled = build(compiled, options=CircuitOptions(direct=direct, jobs=jobs, **kw))
    t2 = time.perf_counter()
    circ = compiled.circuit
    sc = circ.scene
    rep = verify_static(sc, jobs=jobs)
    t3 = time.perf_counter()
    rows = [{"state": r["state"], "ok": r["ok"], "clearance": r.get("clearance"),
             "clearance_pair": r.get("clearance_pair"), "joint_stretch": r["joint_stretch"]} for r in rep.rows]
    return {"example": path.name, "joint_k": sc.meta["connector"]["joint_k"], "inputs": len(sc.inputs), "outputs": len(sc.outputs),
            "gates": len(compiled.netlist.gates), "bodies": len(sc.bodies), "chains": circ.chains,
            "half_units": circ.half_units, "tight_chains": sc.meta["connector"]["tight_chains"],
            "compile_s": t1 - t0, "build_s": t2 - t1, "verify_all_rows_s": t3 - t2,
            "rows": len(rows), "rows_ok": sum(r["ok"] for r in rows), "ok": rep.ok,
            "max_joint_stretch": max(r["joint_stretch"] for r in rows),
            "min_clearance": min(r["clearance"] for r in rows), "rows_clear": sum(r["clearance"] > 0 for r in rows),
            "direct": sc.meta["connector"].get("direct"), "direct_dropped": sc.meta["connector"].get("direct_dropped"),
            "per_row": rows}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--only", nargs="*", help="example file names (default: all)")
    ap.add_argument("--joint-k", type=float, default=None, help="connector joint stiffness, in k0 (default: mlc's)")
    ap.add_argument("--direct", action="store_true", help="direct gate-to-gate connections (mlc compile --direct)")
    ap.add_argument("--jobs", type=int, default=1,
                    help="processes that route, and rows verified at once (mlc compile/verify --jobs; the same "
                         "scenes and results)")
    args = ap.parse_args()
    res_path = OUT / ("circuit_examples_direct.json" if args.direct else "circuit_examples.json" if args.joint_k is None
                      else f"circuit_examples_jointk{args.joint_k:g}.json")
    paths = sorted(p for p in (ROOT / "examples").iterdir() if p.suffix in SUFFIXES)
    if args.only:
        paths = [p for p in paths if p.name in args.only]
    commit = git_commit()
    points = []
    OUT.mkdir(parents=True, exist_ok=True)
    old = {}
    if args.only and res_path.exists():      # keep the other examples' last results
        prev = json.loads(res_path.read_text())
        old = {e["example"]: e for e in prev.get("examples", []) if e["example"] not in args.only}
    for p in paths:
        pt = example_point(p, args.joint_k, args.direct, args.jobs)
        pt["commit"] = commit
        pt["jobs"] = args.jobs
        points.append(pt)
        print(f"{pt['example']:>18}: {pt['gates']} gates, {pt['bodies']} bodies, build {pt['build_s']:.1f} s, "
              f"{pt['rows_ok']}/{pt['rows']} rows right in {pt['verify_all_rows_s']:.1f} s, "
              f"clear in {pt['rows_clear']}/{pt['rows']} rows, smallest clearance {pt['min_clearance']:+.4f} sigma",
              flush=True)
        res = {"machine": {"platform": platform.platform(), "cpus": os.cpu_count(),
                           "load_after": list(os.getloadavg())}, "commit": commit,
               "date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()),
               "examples": sorted(points + list(old.values()), key=lambda e: e["example"]),
               "complete": len(points) == len(paths)}
        res_path.write_text(json.dumps(res, indent=1))     # after each example
    print(f"wrote {res_path}")


if __name__ == "__main__":
    main()
