"""The fluctuation mode (``--fluct``) on a scene with many stiff modes of spread stiffness:
bond-length variance over exact for every mode.

The scene: bonded pairs (one bond, rest 1 sigma, between the bodies' centres: no torques)
in groups of ``--per`` pairs, the groups' stiffnesses k log-spaced from 1 down to 0.03 k0
(12 groups by default), so the pairs' modes (rate 2k/gamma) fill h lambda over a factor 33
below the stiffest, which the stage rule places; the others fall where they fall, some
near an interior Chebyshev extremum of the step (R = T_s(1 - h lambda/s^2) near -1 or +1).
Exact: the Boltzmann variance of each group's bond length (quadrature,
``mlc.sim.testscenes.bond_length_var``).  Each point: ``--burn`` steps of burn-in from the
bonds at rest, then ``--steps`` measured, one record per step; ``ratio`` is the per-pair
variance over the records, averaged over the group's pairs (standard error over pairs),
``ratio_ens`` the variance over the group's pairs at each record time, averaged over time
(unbiased when records stay correlated over many steps).

Rows per (kT, dt): ``fluct_levels`` 1 (session 13: every step at its largest substep, each
mode's h lambda fixed) and 4 (session 15's default: each step's least substep level random
in {0, 1, 2, 3}, so a mode on an extremum at one level is off it at the others; only where a
full step takes more than 4 stages, so the dt = 0.01 t0 rows of both are the same run).

    python benchmarks/sim_fluct_modes.py [--quick] [--per N] [--levels 1,4]

Writes benchmarks/results/sim_fluct_modes.json (~5 min on the shared 2-core machine).
Units: sigma, k0, gamma, t0 = gamma/(1e-3 k0).
"""
from __future__ import annotations

import argparse
import json
import math
import os
import platform
import time
from pathlib import Path

import mlc  # noqa: F401 -- before numpy: pins OpenBLAS's kernels (mlc/__init__.py)
import numpy as np

from mlc.io.atomic import atomic_path
from mlc.sim.integrator import SimOptions, Simulation, _cheb_factor
from mlc.sim.testscenes import bond_length_var, bonded_pairs

RESULTS = Path(__file__).resolve().parent / "results"
T_UNIT = 1000.0
KS = tuple(float(k) for k in np.geomspace(1.0, 0.03, 12))


def pooled_ratios(L, exact):
    """Per pair (columns of L, records in rows): the mean square deviation of its records from
    the mean over all pairs and records, over ``exact``.  A pair's own mean would bias its
    variance low by about twice its records' correlation time over their number (modes whose
    step factor |R| is near 1 stay correlated over many steps); the pooled mean of independent
    pairs does not, so the ratios are independent across pairs and their spread gives an
    honest standard error (the pooled mean's own error lowers them by at most 1/pairs)."""
    return ((L - L.mean()) ** 2).mean(axis=0) / exact


def spread_point(kT, dt, levels, per=100, ks=KS, seed=11, burn=50, steps=200):
    """One (kT, dt, fluct_levels) point: a dict with per-group rows (k, h_lambda, R at the
    step's full-size stages, ratio, ratio_se, ratio_ens) and the cost."""
    kk = np.repeat(np.asarray(ks), per)
    sim = Simulation(bonded_pairs(len(kk), k=kk), None,
                     SimOptions(kT=kT, dt=dt, seed=seed, fluct=True, wca_eps=0.0, fluct_levels=levels))
    _, s_full, _ = sim.fluct_stages_target()
    t = time.perf_counter()
    sim.run(burn * dt, quiet=True)
    res = sim.run(steps * dt, frames=steps + 1, quiet=True)
    wall = time.perf_counter() - t
    d = res.frame_pos[:-1, 1::2] - res.frame_pos[:-1, 0::2]     # post-processed records at each step's start
    L = np.linalg.norm(d, axis=2)
    rows = []
    for j, k in enumerate(ks):
        Lj = L[:, j * per:(j + 1) * per]
        ex = bond_length_var(kT, 1.0, k)
        v = Lj.var(axis=0, ddof=1) / ex
        q = Lj.var(axis=1, ddof=1) / ex
        w = pooled_ratios(Lj, ex)
        hl = 2.0 * k * dt * T_UNIT
        rows.append({"k": k, "h_lambda": hl, "R_full_step": _cheb_factor(hl, s_full), "ratio": float(v.mean()),
                     "ratio_se": float(v.std(ddof=1) / math.sqrt(per)), "ratio_ens": float(q.mean()),
                     "ratio_pool": float(w.mean()), "ratio_pool_se": float(w.std(ddof=1) / math.sqrt(per))})
    return {"kT": kT, "dt_t0": dt, "fluct_levels": levels, "stages_full_step": s_full, "rows": rows,
            "force_evals_per_step": res.force_evals / steps, "wall_s": wall,
            "worst": max(abs(r["ratio_pool"] - 1.0) for r in rows)}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--per", type=int, default=100, help="pairs per stiffness group")
    ap.add_argument("--levels", default="1,4", help="fluct_levels values to compare")
    ap.add_argument("--out", default="sim_fluct_modes")
    args = ap.parse_args()
    kTs = [1e-5, 1e-4, 1e-3, 1e-2]
    dts = [0.01, 0.05, 0.2, 0.5, 2.0, 5.0]
    if args.quick:
        kTs, dts = [1e-5, 1e-3], [0.2, 0.5]
    levels = [int(x) for x in args.levels.split(",")]
    load0 = os.getloadavg()
    points = []
    for kT in kTs:
        for dt in dts:
            for lv in levels:
                p = spread_point(kT, dt, lv, args.per)
                points.append(p)
                r = [x["ratio"] for x in p["rows"]]
                w = [x["ratio_pool"] for x in p["rows"]]
                print(f"kT={kT:g} dt={dt:g} levels={lv}: per pair {min(r):.3f}-{max(r):.3f}, pooled mean {min(w):.3f}-{max(w):.3f}, "
                      f"{p['force_evals_per_step']:.0f} evals/step, {p['wall_s']:.1f} s", flush=True)
    out = {"benchmark": "fluctuation mode, many stiff modes: bonded pairs in groups of spread stiffness, "
                        "bond-length variance / exact per group",
           "machine": {"platform": platform.platform(), "cpus": os.cpu_count(), "python": platform.python_version(),
                       "loadavg": [load0, os.getloadavg()]},
           "ks": list(KS), "pairs_per_group": args.per, "burn_in_steps": 50, "measured_steps": 200, "seed": 11,
           "points": points,
           "notes": "ratio: per-pair variance over the measured records / exact (quadrature), mean over the group's "
                    "pairs, ratio_se its standard error; ratio_ens: variance over the group's pairs at each record "
                    "time / exact, mean over time; R_full_step = T_s(1 - h lambda/s^2) with the stage rule's s of a "
                    "full step; fluct_levels 1: session 13 (every step at its largest substep), 4: each step's "
                    "least substep level random in {0, 1, 2, 3} where a full step takes more than 4 stages "
                    "(Simulation.fluct_level_span; at 4 stages, dt = 0.01 t0 here, full-size steps); ratio_pool: per pair, the mean square deviation from the "
                    "group's pooled mean over all pairs and records / exact, mean over pairs (unbiased by correlated "
                    "records up to 1/pairs), ratio_pool_se its standard error over pairs; worst: max |ratio_pool - 1| "
                    "over the groups"}
    RESULTS.mkdir(exist_ok=True)
    with atomic_path(RESULTS / f"{args.out}.json") as tmp:
        Path(tmp).write_text(json.dumps(out, indent=1) + "\n")


if __name__ == "__main__":
    main()
