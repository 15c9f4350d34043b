"""The router's two methods on the same chains, in one run: CPU per solve, closure, lane.

The NAND mesh of width 7 and depth ``--depth`` (default 4: 28 gates, ~100 chains) is built
with the whole-chain solve ("ik"), every ``solve_route`` call's arguments recorded (the
router's cache off, so each is solved).  Each recorded solve in a lane (waypoints, no
``avoid``) is then solved again with each method, alternating, in this process, one BLAS
thread (as the builder runs them): the CPU time of each, whether it closed, its length,
and how far its pairs stay from the lane (the mean and the largest distance from the
polyline through the start, the lane points and the target, sampled every 1/20 of a
segment).  A fast solve that needs the whole solve's fallback is counted as such
(``fallback``), and its time includes the fallback's.  Closure of each route is checked
with ``chain_frames`` (the exact rotations that build the bodies), not with the solver's
own recurrence.  One fast solve runs first, untimed: the compiled kernels' first call.

    python benchmarks/route_fast_ab.py [--depth 4]

Writes benchmarks/results/route_fast_ab.json and .png.  CPU seconds of one process,
compared as ratios within the run.  Units: sigma, radians, seconds.
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import time
from pathlib import Path

import mlc  # noqa: F401 -- before numpy: pins OpenBLAS's kernels (mlc/__init__.py)
import numpy as np

from gitstate import commit
from mlc.circuit import route as R
from mlc.circuit.build import CircuitOptions, _build_circuit
from mlc.gates.connector import chain_frames
from mlc.io.atomic import atomic_path
from mlc.logic.library import nand_mesh
from mlc.pipeline import compile_spec

OUT = Path(__file__).resolve().parent / "results"


def record_solves(depth: int, router: str = "ik") -> list:
    """The (args, kw) of every solve of the ``router`` build of ``nand_mesh(7, depth)``."""
    spec = nand_mesh(7, depth)
    c = compile_spec(spec, 0)
    calls = []
    real = R._solve_plain

    def rec(args, kw):
        calls.append((args, dict(kw)))
        return real(args, kw)
    R._solve_plain, size, R.CACHE_SIZE = rec, R.CACHE_SIZE, 0
    try:
        _build_circuit(c.netlist, spec, CircuitOptions(router=router, max_gates=10_000))
    finally:
        R._solve_plain, R.CACHE_SIZE = real, size
    return calls


def lane_distance(args, kw, route) -> tuple[float, float]:
    """(mean, largest) distance of the route's pairs from the polyline start - lane points - target."""
    c0, _, P = args[0], args[1], args[2]
    line = np.array([np.asarray(c0, float)] + [np.asarray(w, float) for w in kw["waypoints"]] + [np.asarray(P, float)])
    dense = np.concatenate([np.linspace(line[i], line[i + 1], 20, endpoint=False) for i in range(len(line) - 1)]
                           + [line[-1:]])
    cs, _, _ = R._fk(route.centre, route.axis, route.tangent, route.bends, args[4].pitch)
    d = np.sqrt(((cs[:, None, :] - dense[None]) ** 2).sum(-1)).min(axis=1)
    return float(d.mean()), float(d.max())


def closure(args, kw, route) -> float:
    """Distance of the last pair from the target and of its axis from the target's line,
    by the exact rotations (the larger; sigma)."""
    geo = args[4]
    n = len(route.bends)
    cs, us, _ = chain_frames(route.centre, route.axis, route.tangent, route.bends, geo.pitch)
    if kw.get("last_pitch") is not None:         # the last half unit's longer pitch
        t_last = (cs[-1] - cs[-2]) / np.linalg.norm(cs[-1] - cs[-2])
        cs[-1] = cs[-2] + kw["last_pitch"] * t_last
    a = np.asarray(args[3], float) / np.linalg.norm(args[3])
    axis_off = float(np.linalg.norm(np.cross(us[n], a)))
    return max(float(np.linalg.norm(cs[-1] - np.asarray(args[2], float))), axis_off)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--depth", type=int, default=4)
    args_ = ap.parse_args()
    calls = [(a, kw) for a, kw in record_solves(args_.depth) if kw.get("waypoints") and not kw.get("avoid")]
    rows = []
    fallbacks = [0]
    real_n = R._solve_n

    def counting(*a, **k):
        fallbacks[0] += 1
        return real_n(*a, **k)
    with R.blas_single_thread():
        R._solve_plain(calls[0][0], dict(calls[0][1], method="fast"))     # compile the kernels: not timed
        for i, (a, kw) in enumerate(calls):
            row = {"solve": i}
            for method in (("ik", "fast") if i % 2 == 0 else ("fast", "ik")):
                fallbacks[0] = 0
                R._solve_n = counting if method == "fast" else real_n
                try:
                    t = time.process_time()
                    r = R._solve_plain(a, dict(kw, method=method))
                    dt = time.process_time() - t
                finally:
                    R._solve_n = real_n
                entry = {"cpu_s": dt, "closed": r is not None}
                if r is not None:
                    mean, top = lane_distance(a, kw, r)
                    entry.update(n=r.n, lane_mean=mean, lane_max=top, closure=closure(a, kw, r),
                                 approach_error=r.approach_error)
                if method == "fast":
                    entry["fallback"] = fallbacks[0] > 0
                row[method] = entry
            rows.append(row)
            print(json.dumps({k: ({kk: (round(vv, 4) if isinstance(vv, float) else vv) for kk, vv in v.items()}
                                  if isinstance(v, dict) else v) for k, v in row.items()}), flush=True)
    both = [r for r in rows if r["ik"]["closed"] and r["fast"]["closed"]]
    ik_cpu = sum(r["ik"]["cpu_s"] for r in rows)
    fast_cpu = sum(r["fast"]["cpu_s"] for r in rows)
    summary = {
        "solves": len(rows), "closed_ik": sum(r["ik"]["closed"] for r in rows),
        "closed_fast": sum(r["fast"]["closed"] for r in rows),
        "fast_fallbacks": sum(r["fast"].get("fallback", False) for r in rows),
        "cpu_ik_s": ik_cpu, "cpu_fast_s": fast_cpu, "cpu_ratio_ik_over_fast": ik_cpu / fast_cpu,
        "cpu_per_solve_median_ik_s": float(np.median([r["ik"]["cpu_s"] for r in rows])),
        "cpu_per_solve_median_fast_s": float(np.median([r["fast"]["cpu_s"] for r in rows])),
        "lane_mean_median_ik": float(np.median([r["ik"]["lane_mean"] for r in both])),
        "lane_mean_median_fast": float(np.median([r["fast"]["lane_mean"] for r in both])),
        "lane_max_median_ik": float(np.median([r["ik"]["lane_max"] for r in both])),
        "lane_max_median_fast": float(np.median([r["fast"]["lane_max"] for r in both])),
        "closure_max_ik": max(r["ik"]["closure"] for r in both),
        "closure_max_fast": max(r["fast"]["closure"] for r in both),
        "half_units_mean_ik": float(np.mean([r["ik"]["n"] for r in both])),
        "half_units_mean_fast": float(np.mean([r["fast"]["n"] for r in both])),
    }
    write(f"every lane solve of the ik build of nand_mesh(7, {args_.depth}), solved again by each method",
          summary, rows, OUT / "route_fast_ab.json", plot)


def write(what: str, summary: dict, rows: list, path: Path, plot_fn) -> None:
    """Write an A/B result (``what``, the commit, the machine, ``summary``, ``rows``) to
    ``path`` and its picture (``plot_fn(res, png)``) beside it."""
    res = {"what": what, "commit": commit(),
           "machine": {"platform": platform.platform(), "cpus": os.cpu_count(), "load": os.getloadavg()[0]},
           "units": "sigma, s (CPU of this process)", "summary": summary, "rows": rows}
    path.parent.mkdir(exist_ok=True)
    with atomic_path(path) as tmp:
        Path(tmp).write_text(json.dumps(res, indent=1))
    print(json.dumps(summary, indent=1))
    plot_fn(res, path.with_suffix(".png"))


def plot(res: dict, png: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    rows = [r for r in res["rows"] if r["ik"]["closed"] and r["fast"]["closed"]]
    fig, ax = plt.subplots(1, 2, figsize=(10, 4))
    n = [r["ik"]["n"] for r in rows]
    ax[0].semilogy(n, [r["ik"]["cpu_s"] for r in rows], "o", label="ik (whole chain, trust region)")
    ax[0].semilogy([r["fast"]["n"] for r in rows], [r["fast"]["cpu_s"] for r in rows], "s", label="fast")
    ax[0].set_xlabel("half units")
    ax[0].set_ylabel("CPU s per solve")
    ax[0].legend(fontsize=8)
    ax[1].plot([r["ik"]["lane_mean"] for r in rows], [r["fast"]["lane_mean"] for r in rows], "o")
    m = max(max(r["ik"]["lane_mean"] for r in rows), max(r["fast"]["lane_mean"] for r in rows))
    ax[1].plot([0, m], [0, m], "k:", lw=0.8)
    ax[1].set_xlabel("ik: mean distance from the lane (sigma)")
    ax[1].set_ylabel("fast: mean distance from the lane (sigma)")
    s = res["summary"]
    fig.suptitle(f"{s['solves']} lane solves: CPU ik/fast = {s['cpu_ratio_ik_over_fast']:.1f} in one run", fontsize=10)
    fig.tight_layout()
    fig.savefig(png, dpi=110)


if __name__ == "__main__":
    main()
