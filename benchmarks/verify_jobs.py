"""Static verification with rows in parallel processes (``mlc verify --jobs N``).

    python benchmarks/verify_jobs.py [--example full_adder.tt] [--jobs 1 2] [--repeat 2]

Builds the example's circuit once (as ``mlc compile`` does), then verifies every row of
its truth table statically with each ``--jobs`` value, alternating the values ``--repeat``
times so that a change of the machine's load falls on all of them.  Records each run's wall
time, the speed-up of each N against N = 1 (the medians' ratio, measured in this one run),
and whether the report is the same as N = 1's, number for number (every row's seconds
left out).  Writes benchmarks/results/verify_jobs.json and verify_jobs.png.

The machine is shared and noisy: compare the ratios, not the seconds.  Two cores give at
most 2; a row left alone at the end (8 rows on 3 processes, say) takes its own time.
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import time
from pathlib import Path

from mlc.io.atomic import atomic_path
from mlc.pipeline import build, compile_spec, load
from mlc.verify.circuit import verify_static
from gitstate import commit as git_commit      # benchmarks/gitstate.py

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "benchmarks" / "results"


def _comparable(rep) -> dict:
    d = rep.as_dict()
    d.pop("seconds")
    for row in d["rows"]:
        row.pop("seconds")
    return d


def plot(res: dict, path: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    jobs = [p["jobs"] for p in res["points"]]
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(9, 3.6))
    for p in res["points"]:
        ax.plot([p["jobs"]] * len(p["wall_s"]), p["wall_s"], "o", color="C0", alpha=0.6)
    ax.plot(jobs, [p["median_s"] for p in res["points"]], "-", color="C0", label="median")
    ax.set_xlabel("--jobs")
    ax.set_ylabel("wall s, every row")
    ax.set_title(f"{res['example']}: {res['rows']} rows, {res['bodies']} bodies", fontsize=9)
    ax.legend(fontsize=8)
    bx.plot(jobs, [p["speedup"] for p in res["points"]], "o-", label="measured")
    bx.plot(jobs, [min(j, res["machine"]["cpus"] or 1) for j in jobs], ":", color="grey", label="cores used")
    bx.set_xlabel("--jobs")
    bx.set_ylabel("speed-up against --jobs 1")
    bx.legend(fontsize=8)
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", dpi=110)
    plt.close(fig)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--example", default="full_adder.tt")
    ap.add_argument("--jobs", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--repeat", type=int, default=2)
    args = ap.parse_args()
    jobs = sorted(set(args.jobs) | {1})
    compiled = build(compile_spec(load(str(ROOT / "examples" / args.example))))
    scene = compiled.circuit.scene
    load0 = os.getloadavg()
    walls = {j: [] for j in jobs}
    reports = {}
    for _ in range(args.repeat):
        for j in jobs:
            t0 = time.perf_counter()
            rep = verify_static(scene, jobs=j)
            walls[j].append(time.perf_counter() - t0)
            reports.setdefault(j, _comparable(rep))
            print(f"--jobs {j}: {walls[j][-1]:.1f} s, ok {rep.ok}", flush=True)
    base = statistics.median(walls[1])
    res = {"what": "static verification of every row, rows in parallel processes (mlc verify --jobs)",
           "example": args.example, "bodies": len(scene.bodies), "rows": len(scene.states()),
           "commit": git_commit(), "date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()),
           "machine": {"platform": platform.platform(), "cpus": os.cpu_count(), "load_before": list(load0),
                       "load_after": list(os.getloadavg())},
           "units": "wall seconds",
           "points": [{"jobs": j, "wall_s": walls[j], "median_s": statistics.median(walls[j]),
                       "speedup": base / statistics.median(walls[j]),
                       "same_report_as_jobs_1": reports[j] == reports[1], "ok": reports[j]["ok"]} for j in jobs]}
    OUT.mkdir(exist_ok=True)
    with atomic_path(OUT / "verify_jobs.json") as tmp:
        Path(tmp).write_text(json.dumps(res, indent=1))
    plot(res, OUT / "verify_jobs.png")
    print(json.dumps(res["points"], indent=1))


if __name__ == "__main__":
    main()
