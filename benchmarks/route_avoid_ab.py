"""The router's keep-away re-solves (``avoid``) by its two methods, in one run.

When no plane keeps a chain ``space_clear`` from the chains placed before it and from the
other gates, the builder solves the best plane's route again with ``avoid`` terms that push
its layers away (``build._route_chain``).  With the whole-chain solve ("ik") that re-solve
took about three quarters of a fast build's solving time (docs/circuits.md).  Here every
such re-solve of a build of the NAND mesh of width 7 and depth ``--depth`` (the fast
router's build, the router's cache off) is solved again by each method, alternating, in
this process, one BLAS thread: its CPU time, whether it closed, its closure by
``chain_frames`` (the exact rotations that build the bodies, not either solver's
recurrence), and how far its layers keep from what they avoid: for each avoid set
(points, distance D), the smallest distance d of a layer centre (from ``avoid_from`` on)
to the set's points, less D (``keep``: the smaller over the sets; negative: inside).  The
same for the route the re-solve starts from (the plane's route, without ``avoid``), so
that both methods are read against what they improve on.  One fast solve runs first,
untimed: the compiled kernels' first call.

    python benchmarks/route_avoid_ab.py [--depth 8]

Writes benchmarks/results/route_avoid_ab.json and .png.  CPU seconds of one process,
compared as ratios within the run.  Units: sigma, radians, seconds.
"""
from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import mlc  # noqa: F401 -- before numpy: pins OpenBLAS's kernels (mlc/__init__.py)
import numpy as np
from scipy.spatial import cKDTree

from mlc.circuit import route as R
from route_fast_ab import closure, record_solves, write

OUT = Path(__file__).resolve().parent / "results"


def keep(a, kw, route) -> float:
    """The smallest distance of the route's layer centres (from ``avoid_from``) to each avoid
    set's points less the set's distance (sigma; negative: inside)."""
    n, pitch = len(route.bends), a[4].pitch
    last = kw.get("last_pitch")
    cs, _, _ = R._fk(route.centre, route.axis, route.tangent, route.bends,
                     [pitch] * (n - 1) + [pitch if last is None else last])
    m = 0.5 * (cs[1:] + cs[:-1])[min(int(kw.get("avoid_from", 0)), len(route.bends)):]
    out = np.inf
    for pts, d in kw["avoid"]:
        pts = np.asarray(pts, float).reshape(-1, 3)
        if len(pts) and len(m):
            out = min(out, float(cKDTree(pts).query(m)[0].min()) - float(d))
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--depth", type=int, default=8)
    args_ = ap.parse_args()
    calls = [(a, kw) for a, kw in record_solves(args_.depth, router="fast") if kw.get("avoid")]
    print(len(calls), "avoid solves", flush=True)
    rows = []
    with R.blas_single_thread():
        R._solve_plain(calls[0][0], dict(calls[0][1], method="fast"))     # compile the kernels: not timed
        for i, (a, kw) in enumerate(calls):
            base_kw = {k: v for k, v in kw.items() if k not in ("avoid", "avoid_from")}
            base = R._solve_plain(a, dict(base_kw, method="fast"))
            row = {"solve": i, "start_keep": None if base is None else keep(a, kw, base)}
            for method in (("ik", "fast") if i % 2 == 0 else ("fast", "ik")):
                t = time.process_time()
                r = R._solve_plain(a, dict(kw, method=method))
                dt = time.process_time() - t
                entry = {"cpu_s": dt, "closed": r is not None}
                if r is not None:
                    entry.update(n=r.n, keep=keep(a, kw, r), closure=closure(a, kw, r))
                row[method] = entry
            rows.append(row)
            print(json.dumps(row), flush=True)
    both = [r for r in rows if r["ik"]["closed"] and r["fast"]["closed"]]
    ik_cpu = sum(r["ik"]["cpu_s"] for r in rows)
    fast_cpu = sum(r["fast"]["cpu_s"] for r in rows)
    summary = {
        "solves": len(rows), "closed_ik": sum(r["ik"]["closed"] for r in rows),
        "closed_fast": sum(r["fast"]["closed"] for r in rows),
        "cpu_ik_s": ik_cpu, "cpu_fast_s": fast_cpu, "cpu_ratio_ik_over_fast": ik_cpu / fast_cpu,
        "keep_median_start": float(np.median([r["start_keep"] for r in both if r["start_keep"] is not None])),
        "keep_median_ik": float(np.median([r["ik"]["keep"] for r in both])),
        "keep_median_fast": float(np.median([r["fast"]["keep"] for r in both])),
        "fast_keeps_farther": sum(r["fast"]["keep"] > r["ik"]["keep"] for r in both),
        "fast_improves_on_start": sum(r["start_keep"] is not None and r["fast"]["keep"] > r["start_keep"]
                                      for r in both),
        "ik_improves_on_start": sum(r["start_keep"] is not None and r["ik"]["keep"] > r["start_keep"]
                                    for r in both),
        "closure_max_ik": max(r["ik"]["closure"] for r in both),
        "closure_max_fast": max(r["fast"]["closure"] for r in both),
    }
    write(f"every avoid re-solve of the fast build of nand_mesh(7, {args_.depth}), solved again by each method",
          summary, rows, OUT / "route_avoid_ab.json", plot)


def plot(res: dict, png: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    rows = [r for r in res["rows"] if r["ik"]["closed"] and r["fast"]["closed"]]
    fig, ax = plt.subplots(1, 2, figsize=(10, 4))
    ax[0].semilogy([r["ik"]["n"] for r in rows], [r["ik"]["cpu_s"] for r in rows], "o", label="ik (trust region)")
    ax[0].semilogy([r["fast"]["n"] for r in rows], [r["fast"]["cpu_s"] for r in rows], "s", label="fast")
    ax[0].set_xlabel("half units")
    ax[0].set_ylabel("CPU s per avoid re-solve")
    ax[0].legend(fontsize=8)
    ax[1].plot([r["ik"]["keep"] for r in rows], [r["fast"]["keep"] for r in rows], "o")
    lo = min(min(r["ik"]["keep"] for r in rows), min(r["fast"]["keep"] for r in rows))
    hi = max(max(r["ik"]["keep"] for r in rows), max(r["fast"]["keep"] for r in rows))
    ax[1].plot([lo, hi], [lo, hi], "k:", lw=0.8)
    ax[1].set_xlabel("ik: smallest distance less the keep-away distance (sigma)")
    ax[1].set_ylabel("fast: the same (sigma)")
    s = res["summary"]
    fig.suptitle(f"{s['solves']} avoid re-solves: CPU ik/fast = {s['cpu_ratio_ik_over_fast']:.1f} in one run",
                 fontsize=10)
    fig.tight_layout()
    fig.savefig(png, dpi=110)


if __name__ == "__main__":
    main()
