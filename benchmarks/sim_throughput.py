"""Throughput of the bundled integrator: body-steps per second against bodies.

Workload (the issue's, and the HOOMD-blue anchor's): hinged slab chains, 4 bond sites
per slab, WCA on, kT = 1e-5, Euler at dt = 1e-4 t0.  Measured in one run, on the
same machine: mlc Euler on one thread (serial kernels) and on two threads (parallel
kernels), mlc's stiff scheme (body-steps per second counts force evaluations, so it is
comparable per evaluation), and a plain-numpy Euler of the same physics
(benchmarks/sim_numpy_ref.py).  Also the memory of the integrator's arrays per body.
Gate rows: the library gates NAND and NOR (expanding muscles) held in state 11, the
scenes `mlc check-gate` and dynamic verification run, with the same three mlc configs.

    python benchmarks/sim_throughput.py [--quick]

Writes benchmarks/results/sim_throughput.json and .png; ``--quick`` (3 chain sizes, a smoke
run) writes sim_throughput_quick.json only.
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import sys
import time
from pathlib import Path

import mlc  # noqa: F401 -- before numpy: pins OpenBLAS's kernels (mlc/__init__.py)
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from sim_numpy_ref import NumpyEuler  # noqa: E402

from mlc.gates.library import gate_scene  # noqa: E402
from mlc.sim.drive import Drive  # noqa: E402
from mlc.sim.integrator import SimOptions, Simulation  # noqa: E402
from mlc.sim.testscenes import chain_scene  # noqa: E402

RESULTS = Path(__file__).resolve().parent / "results"
HOOMD_ANCHOR = (0.71e6, 0.83e6)     # HOOMD-blue 4.8.2, one CPU thread, chains of 8..4096 (issue 3)
GOAL = 4e6


def measure(sim, budget, numpy_ref=None):
    """Body-steps per second: best of 5 repeats of about budget/3 seconds each (one, if a repeat
    takes longer than the budget)."""
    N = sim.N
    if numpy_ref is not None:
        numpy_ref.step(2, sim.dt * sim.t_unit, sim.opt.kT)
        t = time.perf_counter()
        numpy_ref.step(1, sim.dt * sim.t_unit, sim.opt.kT)
        per = max(time.perf_counter() - t, 1e-6)
        n = max(1, int(budget / 3 / per))
        best = 0.0
        for _ in range(3):
            t = time.perf_counter()
            numpy_ref.step(n, sim.dt * sim.t_unit, sim.opt.kT)
            best = max(best, n * N / (time.perf_counter() - t))
        return best
    sim.advance(2)                   # compile outside the clock
    # size the repeats from a sample of at least budget/12 s (doubling the steps until then):
    # two steps alone mis-sized a stiff point by 100x (152 s on a 1.5 s budget)
    n = 2
    while True:
        t = time.perf_counter()
        sim.advance(n)
        el = time.perf_counter() - t
        if el >= budget / 12 or n >= 1 << 30:
            break
        n *= 2
    per = max(el, 1e-9) / n
    n = max(2, int(budget / 3 / per))
    best = 0.0
    for _ in range(5 if per * n < budget else 1):
        e0 = sim.stages_out[0]
        t = time.perf_counter()
        sim.advance(n)
        el = time.perf_counter() - t
        evals = sim.stages_out[0] - e0 if sim.opt.scheme == "stiff" else n
        best = max(best, evals * N / el)
        if el > 2 * budget:          # a stalled point (threads descheduled on a loaded machine): one repeat
            break
    return best


def memory_per_body(sim) -> float:
    total = 0
    for v in vars(sim).values():
        if isinstance(v, np.ndarray):
            total += v.nbytes
    return total / sim.N


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--budget", type=float, default=1.5, help="seconds per point")
    ap.add_argument("--crossover", action="store_true",
                    help="only the serial/parallel crossover: 64..4096 bodies, Euler and stiff on 1 and 2 threads "
                         "(parallel kernels forced), -> sim_throughput_crossover.json")
    args = ap.parse_args()
    if args.crossover:
        return crossover(args.budget)
    sizes = [8, 32, 128, 512, 2048, 8192, 32768, 100000]
    if args.quick:
        sizes = [8, 128, 2048]
    rows = []
    for N in sizes:
        sc = chain_scene(N, check=False)     # valid by construction; Scene.check is O(N^2)
        row = {"bodies": N}
        for label, opt in (("euler_1thread", SimOptions(scheme="euler", dt=1e-4, kT=1e-5, threads=1)),
                           ("euler_2threads", SimOptions(scheme="euler", dt=1e-4, kT=1e-5, threads=2,
                                                        parallel_min_bodies=0)),
                           ("stiff_1thread_per_eval", SimOptions(scheme="stiff", dt=0.01, kT=1e-5, threads=1))):
            sim = Simulation(sc, None, opt)
            row[label] = measure(sim, args.budget)
            if label == "euler_1thread":
                row["memory_bytes_per_body"] = memory_per_body(sim)
        if N <= 32768:
            sim = Simulation(sc, None, SimOptions(scheme="euler", dt=1e-4, kT=1e-5))
            row["numpy_euler"] = measure(sim, args.budget, NumpyEuler(sim))
        rows.append(row)
        print(json.dumps(row), flush=True)
    gate_rows = []
    for name in ("NAND", "NOR"):
        sc = gate_scene(name, "expand")
        drives = {"a": Drive.constant(1), "b": Drive.constant(1)}
        row = {"gate": name, "convention": "expand", "state": "11", "bodies": len(sc.bodies)}
        for label, opt in (("euler_1thread", SimOptions(scheme="euler", dt=1e-4, kT=1e-5, threads=1)),
                           ("euler_2threads", SimOptions(scheme="euler", dt=1e-4, kT=1e-5, threads=2,
                                                        parallel_min_bodies=0)),
                           ("stiff_1thread_per_eval", SimOptions(scheme="stiff", dt=0.01, kT=1e-5, threads=1))):
            row[label] = measure(Simulation(sc, drives, opt), args.budget)
        gate_rows.append(row)
        print(json.dumps(row), flush=True)
    load = os.getloadavg()
    out = {
        "benchmark": "throughput, body-steps per second (hinged slab chains, 4 sites per slab, WCA on, kT=1e-5)",
        "machine": {"platform": platform.platform(), "cpus": os.cpu_count(), "loadavg_at_end": load,
                    "python": platform.python_version()},
        "anchor_hoomd_blue_1thread": HOOMD_ANCHOR, "goal_euler_per_thread": GOAL,
        "rows": rows, "gate_rows": gate_rows,
        "notes": "best of 5 repeats per point (1 when a single step is slow); the machine is shared (see loadavg), so compare ratios "
                 "within one run. stiff_1thread_per_eval counts force evaluations (stages), not steps.",
    }
    RESULTS.mkdir(exist_ok=True)
    if args.quick:   # a smoke run: 3 sizes, kept apart from the full results and their plot
        (RESULTS / "sim_throughput_quick.json").write_text(json.dumps(out, indent=1) + "\n")
        return 0
    (RESULTS / "sim_throughput.json").write_text(json.dumps(out, indent=1) + "\n")
    plot(out)


def crossover(budget):
    """Where the parallel kernels on 2 threads start to beat the serial ones (the default of
    ``SimOptions.parallel_min_bodies``): hinged slab chains of 64..4096 bodies, Euler and the
    stiff scheme, serial kernels on one thread against parallel kernels on two, interleaved
    per size so that a change of machine load hits both."""
    load0 = os.getloadavg()
    rows = []
    for N in (64, 128, 256, 512, 1024, 2048, 4096):
        sc = chain_scene(N, check=False)
        row = {"bodies": N}
        for label, opt in (("euler_1thread", SimOptions(scheme="euler", dt=1e-4, kT=1e-5, threads=1)),
                           ("euler_2threads", SimOptions(scheme="euler", dt=1e-4, kT=1e-5, threads=2,
                                                        parallel_min_bodies=0)),
                           ("stiff_1thread_per_eval", SimOptions(scheme="stiff", dt=0.01, kT=1e-5, threads=1)),
                           ("stiff_2threads_per_eval", SimOptions(scheme="stiff", dt=0.01, kT=1e-5, threads=2,
                                                                 parallel_min_bodies=0))):
            row[label] = measure(Simulation(sc, None, opt), budget)
        row["euler_speedup_2threads"] = row["euler_2threads"] / row["euler_1thread"]
        row["stiff_speedup_2threads"] = row["stiff_2threads_per_eval"] / row["stiff_1thread_per_eval"]
        rows.append(row)
        print(json.dumps(row), flush=True)
    out = {"benchmark": "serial (1 thread) against parallel kernels (2 threads), body-steps per second, hinged slab "
                        "chains, kT = 1e-5",
           "machine": {"platform": platform.platform(), "cpus": os.cpu_count(), "python": platform.python_version(),
                       "loadavg": [load0, os.getloadavg()]},
           "rows": rows}
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "sim_throughput_crossover.json").write_text(json.dumps(out, indent=1) + "\n")


def plot(out):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = out["rows"]
    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    for key, lab, st in (("euler_1thread", "mlc Euler, 1 thread", "o-"), ("euler_2threads", "mlc Euler, 2 threads", "s-"),
                         ("stiff_1thread_per_eval", "mlc stiff (per force eval), 1 thread", "^-"),
                         ("numpy_euler", "plain numpy Euler", "x--")):
        pts = [(r["bodies"], r[key]) for r in rows if key in r]
        if pts:
            x, y = zip(*pts)
            ax.loglog(x, y, st, label=lab)
    for g, mk in zip(out.get("gate_rows", []), ("*", "P")):
        for key, col in (("euler_1thread", "C0"), ("stiff_1thread_per_eval", "C2")):
            ax.loglog([g["bodies"]], [g[key]], mk, color=col, ms=9,
                      label=f"{g['gate']} gate ({g['bodies']} bodies), {key.split('_')[0]}, 1 thread")
    ax.axhspan(*out["anchor_hoomd_blue_1thread"], color="0.8", label="HOOMD-blue 4.8.2, 1 thread (anchor)")
    ax.axhline(out["goal_euler_per_thread"], color="g", ls=":", label="goal: 4 M/s per thread")
    ax.set_xlabel("bodies")
    ax.set_ylabel("body-steps per second")
    ax.set_title("mlc simulate throughput (hinged slab chains)")
    ax.legend(fontsize=7)
    ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(RESULTS / "sim_throughput.png", dpi=120)


if __name__ == "__main__":
    main()
