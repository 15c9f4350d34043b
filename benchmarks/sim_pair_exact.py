"""The exact reference of the bond-fluctuation benchmarks, checked three ways.

The benchmark pair (``mlc.sim.testscenes.bonded_pairs``: two bodies joined by one bond
between their centres, k = 1 k0, rest L = 1 sigma, no rotational noise) has no torques, so
the bodies' orientations never move and only the relative position d (3-D, mobility 2/gamma)
matters: p(d) ~ exp(-k (|d| - L)^2 / 2kT), i.e. p(r) ~ r^2 exp(-k (r - L)^2 / 2kT) for the
length.  Its variance is (closed form, ``bond_length_var_closed``)

    Var r = s^2 (L^4 + 3 s^4) / (L^2 + s^2)^2,   s^2 = kT/k,

not kT/k: 0.99998 kT/k at kT = 1e-5, 0.99801 at 1e-3, 0.98059 at 1e-2 (k0 sigma^2).  The
benchmarks (sim_fluctuations.py, sim_fluct_bias.py) compare with this value, computed by
quadrature (``bond_length_var``).  Checked here: (1) closed form against quadrature;
(2) Euler-Maruyama far below its stability limit (1e-3 t0 for this pair: h lambda = 2 at
h = 1 gamma/k0), at dt = 1e-5 and 2e-5 t0, whose linear bias 1/(1 - h lambda/2) = 1.0101 and
1.0204 is removed by linear extrapolation to dt -> 0; 200 pairs, 5 t0 (2500 records, 2 gamma/k0
= 4 relaxation times apart) after 0.02 t0 of burn-in.

    python benchmarks/sim_pair_exact.py        (~2 min)

Writes benchmarks/results/sim_pair_exact.json.  Units: sigma, k0, gamma, t0 = gamma/(1e-3 k0).
"""
from __future__ import annotations

import json
import math
import os
import platform
import time
from pathlib import Path

import mlc  # noqa: F401 -- before numpy: pins OpenBLAS's kernels (mlc/__init__.py)
import numpy as np

from mlc.sim.integrator import SimOptions, Simulation
from mlc.sim.testscenes import bond_length_var, bond_length_var_closed, bonded_pairs

RESULTS = Path(__file__).resolve().parent / "results"


def euler_var(kT, dt, seed=5, pairs=200, T=5.0, records=2500):
    sim = Simulation(bonded_pairs(pairs), None, SimOptions(kT=kT, dt=dt, seed=seed, scheme="euler", wca_eps=0.0))
    sim.run(0.02, quiet=True)
    r = sim.run(T, frames=records + 1, quiet=True)
    d = r.frame_pos[:-1, 1::2] - r.frame_pos[:-1, 0::2]
    L = np.linalg.norm(d, axis=2)
    v = L.var(axis=0, ddof=1)
    return float(v.mean()), float(v.std(ddof=1) / math.sqrt(len(v))), float(L.mean() - 1.0)


def main():
    rows = []
    load0 = os.getloadavg()
    for kT in (1e-2, 1e-3):
        t = time.perf_counter()
        (v1, e1, m1), (v2, e2, m2) = euler_var(kT, 1e-5), euler_var(kT, 2e-5)
        v0, e0 = 2 * v1 - v2, math.hypot(2 * e1, e2)
        row = {"kT": kT, "closed_form_over_kT": bond_length_var_closed(kT) / kT,
               "quadrature_over_kT": bond_length_var(kT) / kT,
               "euler_dt1e-5_over_kT": v1 / kT, "euler_dt2e-5_over_kT": v2 / kT,
               "euler_linear_theory_dt1e-5": 1 / (1 - 0.01), "euler_linear_theory_dt2e-5": 1 / (1 - 0.02),
               "euler_extrapolated_over_kT": v0 / kT, "euler_extrapolated_se": e0 / kT,
               "mean_stretch_euler_dt1e-5": m1, "mean_stretch_exact": 2 * kT / (1 + kT),
               "wall_s": time.perf_counter() - t}
        rows.append(row)
        print(json.dumps(row), flush=True)
    out = {"benchmark": "exact bond-length variance of the benchmark pair (k = 1, rest 1 sigma): closed form, "
                        "quadrature, Euler extrapolated to dt -> 0",
           "machine": {"platform": platform.platform(), "cpus": os.cpu_count(), "python": platform.python_version(),
                       "loadavg": [load0, os.getloadavg()]},
           "rows": rows}
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "sim_pair_exact.json").write_text(json.dumps(out, indent=1) + "\n")


if __name__ == "__main__":
    main()
