"""An independent numpy model of the fluctuation mode on the bonded pair (the check behind
the numbers docs/simulation.md quotes for the cause of the bias).

The pair's relative coordinate d (3-D; point bodies, no torques, mobility 2/gamma) obeys
dd = -2k (|d| - L) d/|d| dt + sqrt(4 kT/gamma) dW.  One SK-ROCK step with eta = 0 and s
stages (w0 = 1, w1 = 1/s^2, T_j(1) = 1):
K1 = X + (h/s^2) f(X + Q/(2s)) + Q/s,  K_j = (2h/s^2) f(K_{j-1}) + 2 K_{j-1} - K_{j-2},
records post-processed as X + Q'/(2s), Q' a fresh increment (variance 4 kT h per axis);
s = ceil(m sqrt(h rho/2)) with rho = 1.2 x 2k/gamma (mlc's safety factor), fixed h, no
substeps, no step-size control.  Written from the equations, not from mlc's kernels; with
m = 1 and no refinement it is what mlc does on this scene.

    python benchmarks/sim_fluct_model.py      (~1 min)

Writes benchmarks/results/sim_fluct_model.json.  Units: sigma, k0, gamma; h in gamma/k0
(1 t0 = 1000 gamma/k0).
"""
from __future__ import annotations

import json
import math
from pathlib import Path

import mlc  # noqa: F401 -- before numpy: pins OpenBLAS's kernels (mlc/__init__.py)
import numpy as np

RESULTS = Path(__file__).resolve().parent / "results"


def exact_var(kT, L=1.0, k=1.0):
    s2 = kT / k
    return s2 * (L ** 4 + 3 * s2 * s2) / (L * L + s2) ** 2


def force(d, k=1.0, L=1.0):
    r = np.linalg.norm(d, axis=1, keepdims=True)
    return -2.0 * k * (r - L) * d / r


def ratio(kT, h, m=1.0, n=2000, steps=200, burn=50, seed=1, L=1.0, k=1.0):
    """Bond-length variance over exact: mean over n pairs of the per-pair variance over
    ``steps`` post-processed records after ``burn`` steps; and its standard error."""
    rng = np.random.default_rng(seed)
    s = max(2, math.ceil(m * math.sqrt(h * 1.2 * 2.0 * k / 2.0)))
    d = np.zeros((n, 3))
    d[:, 0] = L
    amp = math.sqrt(4.0 * kT * h)
    rec = []
    for it in range(burn + steps):
        if it >= burn:
            rec.append(np.linalg.norm(d + amp / (2 * s) * rng.standard_normal((n, 3)), axis=1))
        Q = amp * rng.standard_normal((n, 3))
        K0 = d
        K1 = d + h / s ** 2 * force(d + Q / (2 * s), k, L) + Q / s
        for _ in range(2, s + 1):
            K0, K1 = K1, 2 * h / s ** 2 * force(K1, k, L) + 2 * K1 - K0
        d = K1
    v = np.array(rec).var(axis=0, ddof=1) / exact_var(kT, L, k)
    return float(v.mean()), float(v.std(ddof=1) / math.sqrt(n)), s


def main():
    rows = []
    for kT, h, m in ((1e-2, 10.0, 1), (1e-2, 200.0, 1), (1e-2, 200.0, 2), (1e-2, 5000.0, 1), (1e-2, 5000.0, 2),
                     (1e-3, 200.0, 1), (1e-3, 200.0, 2), (1e-3, 10.0, 1), (1e-3, 10.0, 2)):
        r, e, s = ratio(kT, h, m)
        rows.append({"kT": kT, "h": h, "dt_t0": h / 1000.0, "stage_factor": m, "stages": s, "ratio": r, "ratio_se": e})
        print(json.dumps(rows[-1]), flush=True)
    out = {"benchmark": "numpy model of post-processed SK-ROCK (eta = 0) on a bonded pair's relative coordinate: "
                        "bond-length variance / exact (no substeps, no step-size control)",
           "settings": "2000 pairs, 50 steps burn-in, 200 measured, seed 1", "rows": rows}
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "sim_fluct_model.json").write_text(json.dumps(out, indent=1) + "\n")


if __name__ == "__main__":
    main()
