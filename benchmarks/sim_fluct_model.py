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

Session 13: the stage rule.  ``stage_rule`` is the rule mlc's fluctuation mode now uses
(mlc.sim.integrator.Simulation.fluct_stages_target), written again here from its statement:
base factor m0 = 3 when one step's noise variance per axis 2 kT h/gamma exceeds 1.5e-3 sigma^2
(0.5 sigma^2 in sessions 13-16), else 1; s0 = ceil(m0 sqrt(h rho 1.2/2)); s = the smallest s in [s0, 1.5 s0] whose
R_s(-h rho) = T_s(1 - h rho/s^2) (the stiffest mode's one-step factor, rho without the
safety factor) lies in [-0.5, 0.5], else the one there nearest that window.  Each point
reports two estimators of the variance: ``time`` (per pair over its 200 records, averaged
over pairs: what benchmarks/sim_fluct_bias.py measures; biased low when the records are
correlated over many steps, R near +1) and ``ens`` (over the pairs at each record time,
averaged over time: unbiased once relaxed).  ``harmonic``: the same scheme on the exactly
linear force -2k(d - L e_x) (x-axis variance / (kT/k); exact for every s in linear theory,
given a burn-in long enough for the mode to relax from its zero-variance start).

    python benchmarks/sim_fluct_model.py      (~10 min on the shared machine)

Writes benchmarks/results/sim_fluct_model.json.  Units: sigma, k0, gamma; h in gamma/k0
(1 t0 = 1000 gamma/k0).
"""
from __future__ import annotations

import json
import math
from pathlib import Path

import mlc  # noqa: F401 -- before numpy: pins OpenBLAS's kernels (mlc/__init__.py)
import numpy as np

from mlc.io.atomic import atomic_path

RESULTS = Path(__file__).resolve().parent / "results"


def exact_var(kT, L=1.0, k=1.0):
    s2 = kT / k
    return s2 * (L ** 4 + 3 * s2 * s2) / (L * L + s2) ** 2


def force(d, k=1.0, L=1.0):
    r = np.linalg.norm(d, axis=1, keepdims=True)
    return -2.0 * k * (r - L) * d / r


def R_stiff(h, s, lam):
    """SK-ROCK (eta = 0) one-step factor T_s(1 - h lam/s^2) of a mode of rate lam."""
    x = 1.0 - h * lam / (s * s)
    return math.cos(s * math.acos(max(-1.0, min(1.0, x))))


def stage_rule(kT, h, rho, gamma=1.0, safety=1.2, m_hi=3.0, noise_hi=1.5e-3, lo=-0.5, hi=0.5, span=1.5):
    """Stages of the session-13 rule (module docstring); rho = the stiffest mode's rate."""
    m0 = m_hi if 2.0 * kT * h / gamma > noise_hi else 1.0
    s0 = max(2, math.ceil(m0 * math.sqrt(h * rho * safety / 2.0)))
    cand = range(s0, math.ceil(span * s0) + 1)
    for s in cand:
        if lo <= R_stiff(h, s, rho) <= hi:
            return s
    return min(cand, key=lambda s: max(lo - R_stiff(h, s, rho), R_stiff(h, s, rho) - hi))


def run_pairs(kT, h, s, n=2000, steps=200, burn=50, seed=1, L=1.0, k=1.0, linear=False):
    """n pairs, ``burn`` steps then ``steps`` post-processed records with s stages: returns
    (time, time_se, ens, ens_se) for the bond length (variance / exact) or, ``linear``, for
    the x axis of the exactly linear force (variance / (kT/k))."""
    rng = np.random.default_rng(seed)
    d = np.zeros((n, 3))
    d[:, 0] = L
    amp = math.sqrt(4.0 * kT * h)
    e0 = np.array([L, 0.0, 0.0])
    f = (lambda y: -2.0 * k * (y - e0)) if linear else (lambda y: force(y, k, L))
    rec = []
    for it in range(burn + steps):
        if it >= burn:
            y = d + amp / (2 * s) * rng.standard_normal((n, 3))
            rec.append(y[:, 0] if linear else np.linalg.norm(y, axis=1))
        Q = amp * rng.standard_normal((n, 3))
        K0 = d
        K1 = d + h / s ** 2 * f(d + Q / (2 * s)) + Q / s
        for _ in range(2, s + 1):
            K0, K1 = K1, 2 * h / s ** 2 * f(K1) + 2 * K1 - K0
        d = K1
    A = np.array(rec)
    ex = kT / k if linear else exact_var(kT, L, k)
    v = A.var(axis=0, ddof=1) / ex
    q = ((A - A.mean(axis=1, keepdims=True)) ** 2).mean(axis=0) * n / (n - 1) / ex
    return (float(v.mean()), float(v.std(ddof=1) / math.sqrt(n)), float(q.mean()), float(q.std(ddof=1) / math.sqrt(n)))


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
    # session 13: the table's 32 points under the old rule (m = 2 when 2 kT h/gamma > 1, else 1)
    # and under the new stage rule, both estimators; the linear check at a few s
    rule_rows = []
    for kT in (1e-5, 1e-4, 1e-3, 1e-2):
        for dt in (0.01, 0.05, 0.2, 0.5, 2.0, 5.0, 20.0, 100.0):
            h = dt * 1000.0
            s_old = max(2, math.ceil((2.0 if 2.0 * kT * h > 1.0 else 1.0) * math.sqrt(h * 1.2)))
            s_new = stage_rule(kT, h, 2.0)
            row = {"kT": kT, "dt_t0": dt, "noise_var_per_step": 2.0 * kT * h}
            for tag, s in (("old", s_old), ("new", s_new)):
                t, te, en, ee = run_pairs(kT, h, s)
                row[tag] = {"stages": s, "R_stiffest": R_stiff(h, s, 2.0), "time": t, "time_se": te, "ens": en,
                            "ens_se": ee}
            rule_rows.append(row)
            print(json.dumps(row), flush=True)
    harmonic = []
    for kT, h, s in ((1e-3, 200.0, 16), (1e-3, 200.0, 17), (1e-3, 200.0, 20), (1e-2, 5000.0, 245), (1e-2, 50.0, 24)):
        t, te, en, ee = run_pairs(kT, h, s, linear=True)
        harmonic.append({"kT": kT, "h": h, "stages": s, "R": R_stiff(h, s, 2.0), "time": t, "time_se": te, "ens": en,
                         "ens_se": ee})
        print(json.dumps(harmonic[-1]), flush=True)
    cost_old = sum(r["old"]["stages"] + 1 for r in rule_rows)
    cost_new = sum(r["new"]["stages"] + 1 for r in rule_rows)
    out = {"benchmark": "numpy model of post-processed SK-ROCK (eta = 0) on a bonded pair's relative coordinate: "
                        "bond-length variance / exact (no substeps, no step-size control)",
           "settings": "2000 pairs, 50 steps burn-in, 200 measured, seed 1", "rows": rows,
           "stage_rule": {"rule": "m0 = 3 if 2 kT h/gamma > 1.5e-3 sigma^2 else 1 (0.5 sigma^2 before session 17); s0 = ceil(m0 sqrt(1.2 h rho/2)); "
                                  "s = smallest s in [s0, 1.5 s0] with T_s(1 - h rho/s^2) in [-0.5, 0.5], else the "
                                  "nearest to that window (rho = 2 k/gamma, the pair's mode)",
                          "old": "s = ceil(m sqrt(1.2 h rho/2)), m = 2 if 2 kT h/gamma > 1 sigma^2 else 1",
                          "estimators": "time: per-pair variance over the 200 records (what sim_fluct_bias.py "
                                        "measures); ens: variance over pairs at each record, averaged over records",
                          "rows": rule_rows,
                          "force_evals_per_step_sum": {"old": cost_old, "new": cost_new, "ratio": cost_new / cost_old},
                          "harmonic": harmonic}}
    RESULTS.mkdir(exist_ok=True)
    with atomic_path(RESULTS / "sim_fluct_model.json") as tmp:
        Path(tmp).write_text(json.dumps(out, indent=1) + "\n")


if __name__ == "__main__":
    main()
