"""Throughput of `mlc sweep` against the number of local Dask workers (issue 11, item 6).

    python benchmarks/sweep_throughput.py [--reps 2]    # writes benchmarks/results/fig5c_throughput.{json,png}

A reduced Fig. 5C sweep (examples/sweeps/fig5c.yaml with units 1 and 5, frequencies
0.5 and 0.05 /t0, 3 seeds: 12 runs, stiff scheme) is run from scratch on a local cluster
of 1 and of 2 workers, alternately, ``--reps`` times each.  Recorded: the wall time of
the whole sweep (cluster start-up included), the sum of the runs' own wall times
(``wall_s``, inside the workers), runs per second, and the load average before and after
(the machine is shared: compare ratios within one run).  The results table of every
repetition must be identical in its measured columns (reproducibility on 1 and 2 workers).
"""
from __future__ import annotations

import argparse
import csv
import json
import os
import shutil
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))

SPEC = """\
name: fig5c_throughput
scene: and_chain_and
measure: square_response
params: {signal: expand, scheme: stiff, dt: 0.01, kT: 1.0e-5, cycles: 4, samples_per_cycle: 2000,
         inputs: {hold: 1}}
grid:
  units: [1, 5]
  frequency: [0.5, 0.05]
seeds: 3
"""


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--reps", type=int, default=2)
    ap.add_argument("-o", "--output", default=os.path.join(HERE, "results", "fig5c_throughput.json"))
    a = ap.parse_args(argv)
    from mlc.sweep.run import run_sweep
    from mlc.sweep.spec import load_spec
    tmp = tempfile.mkdtemp(prefix="mlc_sweep_tp_")
    spec_p = os.path.join(tmp, "spec.yaml")
    with open(spec_p, "w") as f:
        f.write(SPEC)
    spec = load_spec(spec_p)
    rows, tables = [], []
    try:
        for rep in range(a.reps):
            for workers in (1, 2):
                d = os.path.join(tmp, f"w{workers}_r{rep}")
                load0 = os.getloadavg()[0]
                t = time.perf_counter()
                info = run_sweep(spec, d, workers=workers, progress=False)
                wall = time.perf_counter() - t
                with open(os.path.join(d, "results.csv"), newline="") as f:
                    table = list(csv.DictReader(f))
                tables.append(table)
                run_wall = sum(float(r["wall_s"]) for r in table)
                row = {"workers": workers, "rep": rep, "runs": info["ran"], "wall_s": wall,
                       "sum_run_wall_s": run_wall, "runs_per_s": info["ran"] / wall,
                       "load_before": load0, "load_after": os.getloadavg()[0]}
                rows.append(row)
                print(row, flush=True)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    keys = ("rms_dev", "rms_dev_all", "y_high", "y_low", "lag", "steps")
    same = all([{k: r[k] for k in keys} for r in t] == [{k: r[k] for k in keys} for r in tables[0]] for t in tables)
    mean = {w: sum(r["wall_s"] for r in rows if r["workers"] == w) / a.reps for w in (1, 2)}
    out = {"spec": SPEC, "rows": rows, "identical_results": same, "cpus": os.cpu_count(),
           "speedup_2_over_1": mean[1] / mean[2],
           "note": "wall_s includes starting the local cluster (a few seconds); the machine is shared"}
    with open(a.output, "w") as f:
        json.dump(out, f, indent=1)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(5, 3.6))
    for w in (1, 2):
        ys = [r["runs_per_s"] for r in rows if r["workers"] == w]
        ax.plot([w] * len(ys), ys, "o", color="#1f4e8c")
    ax.plot([1, 2], [sum(r["runs_per_s"] for r in rows if r["workers"] == w) / a.reps for w in (1, 2)], "-",
            color="#1f4e8c", label="mean")
    ax.set_xticks([1, 2])
    ax.set_xlabel("local Dask workers")
    ax.set_ylabel("runs per second (12-run Fig. 5C sweep)")
    ax.set_title(f"mlc sweep throughput; 2 vs 1 worker: {out['speedup_2_over_1']:.2f}x\n"
                 f"(shared {os.cpu_count()}-core machine, load {min(r['load_before'] for r in rows):.0f}-"
                 f"{max(r['load_after'] for r in rows):.0f})", fontsize=9)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(a.output.replace(".json", ".png"), dpi=100)
    print("wrote", a.output, "identical results:", same, "speedup:", round(out["speedup_2_over_1"], 2))


if __name__ == "__main__":
    main()
