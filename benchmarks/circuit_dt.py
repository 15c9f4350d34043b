"""Speed against error of the circuit dynamic check: the stiff scheme's step dt.

`mlc verify --dynamic` runs the stiff scheme at dt = 0.01 t0 (``mlc.verify.dynamic.DT``).
This script runs the same check (:func:`mlc.verify.dynamic.check_scene_dynamic_multi`:
from rest, switch the row, run until every probe has relaxed, at its floor of 3 signal
times) on compiled example circuits at several dt, and compares each run's relaxed probe
lengths with an independent reference: the row's static equilibrium (an energy minimiser,
:func:`mlc.verify.circuit.verify_static`, no dynamics).  At kT = 1e-5 k0 sigma^2 the relaxed
mean differs from the equilibrium by the averaging noise (of the order of the probe's thermal
spread over the number of independent samples) plus the step's bias; the bias is what grows
with dt.

    python benchmarks/circuit_dt.py [--only tetris.tt] [--dts 0.01 0.05 0.2] [--seeds 0 1]
                                    [--rows 01 10] [--out F]

For each run: the CPU seconds of the check (process_time; NUMBA_NUM_THREADS=1 makes that one
core), the wall seconds, the relaxation time (t0), and per output the dynamic mean, the static
length, their difference, the thermal spread and the margin.  Writes
benchmarks/results/circuit_dt.json (after every run; runs already there are skipped) and a plot
circuit_dt.png (CPU per run and the largest |dynamic - static| against dt).  Units: sigma, t0,
k0.  Times from a shared 2-core machine: compare ratios within one run of the script.
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

from mlc.circuit.build import CircuitOptions
from mlc.io.atomic import atomic_path
from mlc.pipeline import build, compile_spec, load
from mlc.verify.circuit import verify_static
from mlc.verify.dynamic import check_scene_dynamic_multi
from gitstate import commit as git_commit      # benchmarks/gitstate.py

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "benchmarks" / "results" / "circuit_dt.json"


def plot(res: dict, path: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(1, 2, figsize=(10, 4))
    for ex in sorted({r["example"] for r in res["runs"]}):
        runs = [r for r in res["runs"] if r["example"] == ex]
        dts = sorted({r["dt"] for r in runs})
        cpu = [np.mean([r["cpu_s"] for r in runs if r["dt"] == d]) for d in dts]
        err = [max(o["abs_diff"] for r in runs if r["dt"] == d for o in r["outputs"].values()) for d in dts]
        ax[0].loglog(dts, cpu, "o-", label=ex)
        ax[1].loglog(dts, err, "o-", label=ex)
    ax[0].set_xlabel("dt (t0)")
    ax[0].set_ylabel("CPU per run, mean over rows and seeds (s)")
    ax[1].set_xlabel("dt (t0)")
    ax[1].set_ylabel("largest |dynamic - static| (sigma)")
    ax[1].axhline(0.25, color="grey", ls=":", label="logic margin 0.25 sigma")
    for a in ax:
        a.legend()
        a.grid(True, which="both", alpha=0.3)
    fig.suptitle("circuit dynamic check: the stiff scheme's step against its error (kT = 1e-5)")
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=110, format="png")
    plt.close(fig)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--only", nargs="*", default=["tetris.tt"], help="example file names")
    ap.add_argument("--dts", type=float, nargs="*", default=[0.01, 0.05, 0.2])
    ap.add_argument("--seeds", type=int, nargs="*", default=[0, 1])
    ap.add_argument("--rows", nargs="*", default=None, help="rows to run (default all)")
    ap.add_argument("--kT", type=float, default=1e-5)
    ap.add_argument("--out", type=Path, default=OUT)
    args = ap.parse_args()
    commit = git_commit()
    out = args.out
    res = json.loads(out.read_text()) if out.exists() else {"runs": [], "static": {}}
    for name in args.only:
        sc = build(compile_spec(load(str(ROOT / "examples" / name))), options=CircuitOptions()).circuit.scene
        rows = [s for s in sc.states() if not args.rows or s in args.rows]
        static = res["static"].setdefault(name, {})
        todo = [s for s in rows if s not in static]
        if todo:
            rep = verify_static(sc, rows=todo, kT=args.kT)
            for e in rep.entries:
                static.setdefault(e["state"], {})[e["output"]] = {"measured": e["measured"],
                                                                  "thermal_sd": e.get("thermal_sd")}
        done = {(r["example"], r["state"], r["seed"], r["dt"]) for r in res["runs"]}
        for dt in args.dts:
            for seed in args.seeds:
                for state in rows:
                    if (name, state, seed, dt) in done:
                        continue
                    t0, c0 = time.perf_counter(), time.process_time()
                    entries = check_scene_dynamic_multi(sc, kT=args.kT, seeds=[seed], rows=[state], dt=dt,
                                                        progress=False)
                    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
                    outs = {}
                    for e in entries:
                        ref = static[state][e["output"]]["measured"]
                        outs[e["output"]] = {"measured": e["measured"], "static": ref,
                                             "abs_diff": abs(e["measured"] - ref), "thermal_sd": e["thermal_sd"],
                                             "margin": e["margin"], "ok": e["ok"]}
                    run = {"example": name, "bodies": len(sc.bodies), "state": state, "seed": seed, "dt": dt,
                           "kT": args.kT, "ok": all(e["ok"] for e in entries),
                           "relax_time": max((e["relax_time"] or float("nan")) for e in entries),
                           "tau": max(e["tau"] for e in entries), "cpu_s": cpu, "wall_s": wall, "outputs": outs,
                           "commit": commit, "load": list(os.getloadavg())}
                    res["runs"].append(run)
                    res["machine"] = {"platform": platform.platform(), "cpus": os.cpu_count(),
                                      "numba_threads": os.environ.get("NUMBA_NUM_THREADS")}
                    with atomic_path(out) as tmp:
                        tmp.write_text(json.dumps(res, indent=1))
                    worst = max(o["abs_diff"] for o in outs.values())
                    print(f"{name} row {state} seed {seed} dt {dt}: {'right' if run['ok'] else 'WRONG'}, "
                          f"relaxed at {run['relax_time']:.1f} t0, cpu {cpu:.1f} s, |dyn - static| <= {worst:.2e}",
                          flush=True)
    plot(res, out.with_suffix(".png"))
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
