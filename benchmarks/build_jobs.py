"""Routing with solves started ahead in other processes (``mlc compile --jobs N``).

    python benchmarks/build_jobs.py [--examples full_adder.expr mux4.blif] [--adders 3]
                                    [--jobs 1 2] [--repeat 2]

For each circuit (examples from ``examples/``; ``--adders W``: the W-bit ripple-carry adder
of ``benchmarks/circuit_scaling.py``), builds the circuit with each ``--jobs`` value,
alternating the values ``--repeat`` times so that a change of the machine's load falls on
all of them, each build from an empty route cache.  Records each build's wall and CPU time
(``process_time`` of this process: with N > 1 the other processes' CPU is not in it), the
solves started ahead and taken (``route.PREFETCH``), the speed-up of each N against N = 1
(the medians' ratio, measured in this one run), and whether the scene is the same as
N = 1's (sha256 of its text).  Writes benchmarks/results/build_jobs.json and build_jobs.png.

The machine is shared and noisy: compare the ratios, not the seconds, and read the load
recorded with them.  Two cores give at most 2, and less: only the next chains' first
solves and a chain's next plane start ahead (``mlc.circuit.route.Prefetch``); the rest of
the routing, the keep-apart re-routes and the assembly stay in one process.
"""
from __future__ import annotations

import argparse
import hashlib
import json
import os
import platform
import statistics
import time
from pathlib import Path

import mlc  # noqa: F401 -- before numpy: pins OpenBLAS's kernels (mlc/__init__.py)

from mlc.circuit import route
from mlc.circuit.build import CircuitOptions, build_circuit
from mlc.io.atomic import atomic_path
from mlc.logic.library import ripple_adder
from mlc.pipeline import compile_spec, load
from mlc.scene.io import dump_scene
from gitstate import commit as git_commit      # benchmarks/gitstate.py

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "benchmarks" / "results"


def one_build(netlist, spec, jobs: int) -> dict:
    route._CACHE.clear()
    p0 = list(route.PREFETCH)
    load0 = os.getloadavg()[0]
    t0, c0 = time.perf_counter(), time.process_time()
    circ = build_circuit(netlist, spec, CircuitOptions(max_gates=len(netlist.gates), jobs=jobs))
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    text = dump_scene(circ.scene)
    return {"wall_s": wall, "cpu_s": cpu, "load": load0, "started": route.PREFETCH[0] - p0[0],
            "taken": route.PREFETCH[1] - p0[1], "bodies": len(circ.scene.bodies),
            "sha256": hashlib.sha256(text.encode()).hexdigest()[:16]}


def plot(res: dict, path: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6.5, 3.6))
    names = [c["circuit"] for c in res["circuits"]]
    for k, c in enumerate(res["circuits"]):
        for p in c["points"]:
            ax.plot([k + 0.12 * (p["jobs"] - 1)] * len(p["runs"]), [r["wall_s"] for r in p["runs"]], "o",
                    color=f"C{p['jobs'] - 1}", alpha=0.7, label=f"--jobs {p['jobs']}" if k == 0 else None)
    ax.set_xticks(range(len(names)), names, fontsize=8)
    ax.set_ylabel("build wall s")
    ax.set_yscale("log")
    ax.set_title("circuit build, route solves started ahead (same scene for every N)", fontsize=9)
    ax.legend(fontsize=8)
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", dpi=110)
    plt.close(fig)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--examples", nargs="*", default=["full_adder.expr", "mux4.blif"])
    ap.add_argument("--adders", type=int, nargs="*", default=[3])
    ap.add_argument("--jobs", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--repeat", type=int, default=2)
    ap.add_argument("-o", "--out", type=Path, default=OUT / "build_jobs.json")
    args = ap.parse_args()
    jobs = sorted(set(args.jobs) | {1})
    todo = [(e, load(str(ROOT / "examples" / e)), 2) for e in args.examples]
    todo += [(f"adder{w}", ripple_adder(w), 2) for w in args.adders]
    load0 = os.getloadavg()
    circuits = []
    for name, spec, level in todo:
        c = compile_spec(spec, level, "expand")
        runs = {j: [] for j in jobs}
        for _ in range(args.repeat):
            for j in jobs:
                runs[j].append(one_build(c.netlist, spec, j))
                r = runs[j][-1]
                print(f"{name} --jobs {j}: {r['wall_s']:.1f} s wall, {r['cpu_s']:.1f} s CPU, started {r['started']}, "
                      f"taken {r['taken']}, load {r['load']:.2f}, scene {r['sha256']}", flush=True)
        base = statistics.median(r["wall_s"] for r in runs[1])
        ref = runs[1][0]["sha256"]
        circuits.append({"circuit": name, "gates": len(c.netlist.gates), "bodies": runs[1][0]["bodies"],
                         "points": [{"jobs": j, "runs": runs[j],
                                     "median_wall_s": statistics.median(r["wall_s"] for r in runs[j]),
                                     "speedup": base / statistics.median(r["wall_s"] for r in runs[j]),
                                     "same_scene_as_jobs_1": all(r["sha256"] == ref for r in runs[j])}
                                    for j in jobs]})
    res = {"what": "circuit build with route solves started ahead in other processes (mlc compile --jobs)",
           "commit": git_commit(), "date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()),
           "machine": {"platform": platform.platform(), "cpus": os.cpu_count(), "load_before": list(load0),
                       "load_after": list(os.getloadavg())},
           "units": {"time": "s"}, "circuits": circuits}
    OUT.mkdir(exist_ok=True)
    with atomic_path(args.out) as tmp:
        Path(tmp).write_text(json.dumps(res, indent=1))
    plot(res, args.out.with_suffix(".png"))
    for c in circuits:
        print(c["circuit"], [(p["jobs"], round(p["speedup"], 2), p["same_scene_as_jobs_1"]) for p in c["points"]])


if __name__ == "__main__":
    main()
