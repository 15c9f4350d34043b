"""Bias of the fluctuation mode (``--fluct``) against dt: bond-length variance over exact.

The fluctuation mode (post-processed SK-ROCK, eta = 0) gives every *linear* mode its exact
stationary variance at any dt.  Measured here on 200 independent bonded pairs (one bond,
k = 1 k0, rest 1 sigma, between the bodies' centres: no torques), bond-length variance over
its exact Boltzmann value (quadrature of r^2 exp(-k (r - 1)^2 / 2kT); closed form and an
Euler check in sim_pair_exact.py), against dt from 0.01 t0 to 100 t0 (the largest dt a sweep
spec accepts; ``mlc simulate`` takes any dt without rotational noise) at kT = 1e-5 ... 1e-2
k0 sigma^2.  ``phi2`` = 4 kT h/(gamma L^2) (h = dt in gamma/k0, L = 1 sigma) is the pair's
noise turn per step.  ``mlc simulate --json`` reports the measured ratio at the nearest
measured kT and the run's dt (``variance_bias.pair_ratio_measured``, from
``mlc.sim.integrator.FLUCT_PAIR_RATIO``, a copy of this benchmark's rows).

Each point: ``--burn`` steps of burn-in (default 50: modes near an interior Chebyshev
extremum relax slowly without damping; 5 steps left 0.910 at kT = 1e-5, dt = 0.2 t0), then
``--steps`` measured (default 200), one record per step, variance per pair over time,
averaged over pairs (independent, so the standard error is over pairs).  Runs longer than
``--cap`` seconds are cut short (steps_measured says how many were kept).  Rows with
fluct False: the plain stiff scheme for comparison.

    python benchmarks/sim_fluct_bias.py [--quick] [--burn N] [--steps N] [--out STEM]

Writes benchmarks/results/sim_fluct_bias.json and .png (~6 min on the shared 2-core machine;
session 13's stage rule, ~10 min; session 15's random substep levels, ~11 min at load 5-8).
Units: sigma, k0, gamma, t0 = gamma/(1e-3 k0).
"""
from __future__ import annotations

import argparse
import json
import math
import os
import platform
import sys
import time
from pathlib import Path

import mlc  # noqa: F401 -- before numpy: pins OpenBLAS's kernels (mlc/__init__.py)
import numpy as np

from mlc.io.atomic import atomic_path
from mlc.sim.integrator import SimOptions, Simulation
from mlc.sim.testscenes import bond_length_var, bonded_pairs

RESULTS = Path(__file__).resolve().parent / "results"
T_UNIT = 1000.0


exact_var = bond_length_var              # mlc.sim.testscenes: the exact theory


def point(sc, kT, dt, fluct, seed, cap, burn=5, nmeas=100):
    sim = Simulation(sc, None, SimOptions(kT=kT, dt=dt, seed=seed, fluct=fluct, wca_eps=0.0))
    t = time.perf_counter()
    sim.run(burn * dt, quiet=True)
    lengths, steps, evals = [], 0, 0
    for _ in range(nmeas // 5):
        res = sim.run(5 * dt, frames=6, quiet=True)
        # frames[:-1]: the (post-processed) records at each step's start; frames[-1]: the raw final state
        d = res.frame_pos[:-1, 1::2] - res.frame_pos[:-1, 0::2]
        lengths.extend(np.linalg.norm(d, axis=2))
        steps += 5
        evals += res.force_evals
        if time.perf_counter() - t > cap:
            break
    L = np.array(lengths)
    wall = time.perf_counter() - t
    return L, steps, wall, evals


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--pairs", type=int, default=200)
    ap.add_argument("--cap", type=float, default=60.0, help="seconds per point before it is cut short")
    ap.add_argument("--burn", type=int, default=50, help="steps of burn-in")
    ap.add_argument("--steps", type=int, default=200, help="measured steps (one record each)")
    ap.add_argument("--out", default="sim_fluct_bias", help="file stem in benchmarks/results")
    args = ap.parse_args()
    sc = bonded_pairs(args.pairs)          # mlc.sim.testscenes: rest 1, tol 0, k 1
    kTs = [1e-5, 1e-4, 1e-3, 1e-2]
    dts = [0.01, 0.05, 0.2, 0.5, 2.0, 5.0, 20.0, 100.0]
    if args.quick:
        kTs, dts = [1e-5, 1e-3], [0.05, 5.0]
    rows = []
    load0 = os.getloadavg()
    for kT in kTs:
        ex = exact_var(kT)
        for dt in dts:
            for fluct in (True, False):
                if not fluct and dt not in (0.05, 5.0):
                    continue
                L, steps, wall, evals = point(sc, kT, dt, fluct, 11, args.cap, args.burn, args.steps)
                v = L.var(axis=0, ddof=1) / ex
                m, e = float(np.mean(v)), float(np.std(v, ddof=1) / math.sqrt(len(v)))
                # the same records over the pairs at each record time (unbiased when records are
                # correlated over many steps; per pair, averaged over time: pairs are independent)
                n = L.shape[1]
                q = ((L - L.mean(axis=1, keepdims=True)) ** 2).mean(axis=0) * n / (n - 1) / ex
                h = dt * T_UNIT
                probe = Simulation(sc, None, SimOptions(kT=kT, dt=dt, fluct=fluct))
                mst, sst, rst = probe.fluct_stages_target() if fluct else (1.0, 0, 0.0)
                row = {"kT": kT, "dt_t0": dt, "fluct": fluct, "phi2": 4 * kT * h, "noise_step_sigma": math.sqrt(2 * kT * h),
                       "ratio": m, "ratio_se": e, "ratio_ens": float(q.mean()),
                       "ratio_ens_se": float(q.std(ddof=1) / math.sqrt(n)), "steps_measured": steps, "force_evals": evals, "wall_s": wall,
                       "exact_var_over_kT": ex / kT,
                       "stage_factor": probe.fluct_stage_factor(), "stages": sst if fluct else None,
                       "R_stiffest": rst if fluct else None}
                rows.append(row)
                print(json.dumps(row), flush=True)
    out = {"benchmark": "fluctuation-mode bond-length variance / exact against dt (bonded pairs, rest 1 sigma, k = 1)",
           "machine": {"platform": platform.platform(), "cpus": os.cpu_count(), "python": platform.python_version(),
                       "loadavg": [load0, os.getloadavg()]},
           "pairs": args.pairs, "burn_in_steps": args.burn, "measured_steps": args.steps, "rows": rows,
           "notes": "phi2 = 4 kT h/gamma (h = dt in gamma/k0): the pair's noise turn per step squared (rad^2) for a "
                    "1 sigma bond; ratio = mean over pairs of the per-pair variance over the measured steps / exact; fluct "
                    "False rows: the plain stiff scheme for comparison; fluctuation mode with its default stage rule "
                    "(session 13, Simulation.fluct_stages_target: stages = s of a full step, R_stiffest = T_s(1 - h "
                    "rho/s^2) of the pair's mode, stage_factor = the m that gives s); ratio_ens: the same records' "
                    "variance over the pairs at each record time, averaged over time (unbiased when a pair's "
                    "records are correlated over many steps)"}
    RESULTS.mkdir(exist_ok=True)
    with atomic_path(RESULTS / f"{args.out}.json") as tmp:
        Path(tmp).write_text(json.dumps(out, indent=1) + "\n")
    plot(out, args.out)


def plot(out, stem="sim_fluct_bias"):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(11, 4.3))
    for kT, col in zip(sorted({r["kT"] for r in out["rows"]}), ("C0", "C1", "C2", "C3")):
        for ax, x in ((axes[0], "dt_t0"), (axes[1], "phi2")):
            sel = [r for r in out["rows"] if r["kT"] == kT and r["fluct"]]
            ax.errorbar([r[x] for r in sel], [r["ratio"] for r in sel], yerr=[r["ratio_se"] for r in sel],
                        fmt="o-", color=col, ms=4, capsize=2, label=f"--fluct, kT={kT:g}")
            sel = [r for r in out["rows"] if r["kT"] == kT and not r["fluct"]]
            ax.plot([r[x] for r in sel], [r["ratio"] for r in sel], "x", color=col, label=f"plain stiff, kT={kT:g}")
    for ax, lab in ((axes[0], "dt (t0)"), (axes[1], "noise turn per step phi^2 = 4 kT h/(gamma L^2) (rad^2)")):
        ax.set_xscale("log")
        ax.axhspan(0.95, 1.05, color="0.9", label="within 5 %")
        ax.axhline(1.0, color="k", lw=0.8)
        ax.set_xlabel(lab)
        ax.set_ylabel("bond-length variance / exact")
        ax.grid(True, which="both", alpha=0.3)
    axes[0].legend(fontsize=6)
    axes[0].set_title("fluctuation mode, bonded pairs (rest 1 sigma, k = 1)", fontsize=9)
    axes[1].set_title("the same against the noise turn per step", fontsize=9)
    fig.tight_layout()
    with atomic_path(RESULTS / f"{stem}.png") as tmp:
        fig.savefig(tmp, dpi=120, format="png")


if __name__ == "__main__":
    if sys.argv[1:] == ["--plot-only"]:
        plot(json.loads((RESULTS / "sim_fluct_bias.json").read_text()))
    else:
        main()
