"""What each scheme does to bond fluctuations (docs/simulation.md, issue 12 item 2).

1. A bonded pair (two bodies joined by one bond of rest 1 sigma between their centres,
   200 independent pairs): the bond-length variance over its exact value (Boltzmann
   quadrature, ~kT/k) for Euler across dt up to its limit, the plain stiff scheme and the
   fluctuation mode (``fluct``: SK-ROCK with eta = 0 and post-processed records), at
   kT = 1e-5 and 1e-3.
2. A 64-slab hinged chain at kT = 1e-5: mean squared hinge-bond length against Euler at a
   tenth of its limit (itself up to 1/(1 - 0.1) = 1.11 high for the stiffest modes), with
   and without rotational noise (without it the exact value is not an equipartition
   number, so the reference is numerical), after 5 t0 of burn-in.
3. A gate's output (NAND, state 11): mean and spread per scheme.

Lengths are taken from the recorded frames (post-processed in the fluctuation mode).

    python benchmarks/sim_fluctuations.py

Writes benchmarks/results/sim_fluctuations.json and .png.
"""
from __future__ import annotations

import json
import math
import os
from pathlib import Path

import mlc  # noqa: F401 -- before numpy: pins OpenBLAS's kernels (mlc/__init__.py)
import numpy as np
from scipy.integrate import quad

from mlc.gates.library import gate_scene
from mlc.geometry.rotation import quat_to_matrix
from mlc.scene.model import Body, Bond, Box, Scene
from mlc.sim.drive import Drive
from mlc.sim.integrator import SimOptions, Simulation
from mlc.sim.testscenes import chain_scene

RESULTS = Path(__file__).resolve().parent / "results"


def pairs(n=200, rest=1.0, k=1.0):
    bodies, bonds = [], []
    for i in range(n):
        c = 4.0 * np.array([i % 15, i // 15, 0.0])
        for tag, dx in (("a", -0.5 * rest), ("b", 0.5 * rest)):
            bodies.append(Body(f"{tag}{i}", c + [dx, 0, 0], np.array([1.0, 0, 0, 0]),
                               [Box(np.array([0.3, 0.3, 0.01]))], {"c": np.zeros(3)}))
        bonds.append(Bond(f"u{i}", f"a{i}.c", f"b{i}.c", k, rest, 0.0, "universal", f"u{i}"))
    return Scene("pairs", bodies, bonds).check()


def exact_length_var(kT, L=1.0, k=1.0):
    w = lambda r: r * r * math.exp(-k * (r - L) ** 2 / (2 * kT))
    lo, hi = L - 12 * math.sqrt(kT / k), L + 12 * math.sqrt(kT / k)
    z = quad(w, lo, hi)[0]
    m1 = quad(lambda r: r * w(r), lo, hi)[0] / z
    return quad(lambda r: r * r * w(r), lo, hi)[0] / z - m1 * m1


def pair_variance(opt, samples=100, stride=1):
    sim = Simulation(pairs(), None, opt)
    sim.run(5 * sim.dt)
    res = sim.run(samples * stride * sim.dt, frames=samples + 1)
    d = res.frame_pos[:-1, 1::2] - res.frame_pos[:-1, 0::2]
    v = np.linalg.norm(d, axis=2).var(axis=0, ddof=1)
    return float(v.mean()), float(v.std(ddof=1) / math.sqrt(len(v))), sim


def chain_bond_msd(opt, T=2.0, samples=200, burn=5.0):
    """Mean squared hinge-bond length over ``samples`` frames in ``T`` t0 after ``burn`` t0
    (the chain starts with unstretched bonds; without damping, modes near a Chebyshev
    extremum of the fluctuation mode relax over several t0)."""
    sc = chain_scene(64)
    sim = Simulation(sc, None, opt)
    sim.run(burn)
    res = sim.run(T, frames=samples + 1)
    acc = []
    for P, Q in zip(res.frame_pos[:-1], res.frame_quat[:-1]):
        R = np.array([quat_to_matrix(q) for q in Q])
        ws = P[sim.site_body] + np.einsum("sij,sj->si", R[sim.site_body], sim.site_local)
        d = ws[sim.sp_j] - ws[sim.sp_i]
        acc.append(np.mean(np.sum(d * d, axis=1)))
    return float(np.mean(acc))


def main():
    out = {"loadavg_start": os.getloadavg()}
    # 1. bonded pairs against theory
    prow = []
    for kT in (1e-5, 1e-3):
        ex = exact_length_var(kT)
        lim = Simulation(pairs(), None, SimOptions(scheme="euler", kT=kT)).euler_limit()
        cfg = [("euler", f, lim * f, False) for f in (0.1, 0.5, 0.8)]
        cfg += [("stiff", None, dt, fl) for dt in (0.01, 0.05, 0.5, 5.0) for fl in (False, True)]
        for scheme, frac, dt, fl in cfg:
            stride = max(1, int(2 / (2 * dt * 1000 / lim * 1e-3))) if scheme == "euler" else 1
            m, e, sim = pair_variance(SimOptions(scheme=scheme, dt=dt, kT=kT, seed=11, fluct=fl), stride=stride)
            b = sim.variance_bias()
            prow.append({"kT": kT, "scheme": scheme, "fluct": fl, "dt_t0": dt, "dt_over_euler_limit": dt / lim,
                         "variance_over_exact": m / ex, "sampling_error": e / ex,
                         "linear_theory_min": b["ratio_min"], "linear_theory_max": b["ratio_max"]})
            print(prow[-1], flush=True)
    out["bonded_pair"] = {"scene": "200 pairs, one bond (k = 1, rest 1) between body centres",
                          "exact": "Boltzmann quadrature of r^2 exp(-k (r - 1)^2 / 2kT)", "rows": prow}
    # 2. chain of 64 hinged slabs
    kT = 1e-5
    crow = []
    for rot in (False, True):
        lim = Simulation(chain_scene(64), None, SimOptions(scheme="euler", kT=kT)).euler_limit()
        ref = chain_bond_msd(SimOptions(scheme="euler", dt=lim / 10, kT=kT, seed=11, rot_noise=rot))
        for scheme, dt, fl in [("euler", lim * 0.5, False), ("stiff", 0.01, False), ("stiff", 0.01, True),
                               ("stiff", 0.05, False), ("stiff", 0.05, True), ("stiff", 0.2, True)]:
            m = chain_bond_msd(SimOptions(scheme=scheme, dt=dt, kT=kT, seed=11, fluct=fl, rot_noise=rot))
            crow.append({"rot_noise": rot, "scheme": scheme, "fluct": fl, "dt_t0": dt, "dt_over_euler_limit": dt / lim,
                         "bond_msd": m, "ratio_to_euler_limit_over_10": m / ref})
            print(crow[-1], flush=True)
    out["chain64"] = {"kT": kT, "rows": crow}
    # 3. gate output
    gate = gate_scene("NAND")
    g = []
    for scheme, dt, fl in (("euler", 0.5 * Simulation(gate, None, SimOptions(scheme="euler")).euler_limit(), False),
                           ("stiff", 0.01, False), ("stiff", 0.05, False), ("stiff", 0.05, True)):
        sim = Simulation(gate, {"a": Drive.constant(1), "b": Drive.constant(1)},
                         SimOptions(scheme=scheme, dt=dt, kT=kT, seed=3, fluct=fl))
        sim.run(0.5)
        vals = sim.run(5.0, record_interval=0.01).probes["out"][:-1]
        g.append({"scheme": scheme, "fluct": fl, "dt_t0": dt, "out_mean": float(np.mean(vals)),
                  "out_std": float(np.std(vals))})
        print(g[-1], flush=True)
    out["gate_NAND_11_output"] = g
    out["loadavg_end"] = os.getloadavg()
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "sim_fluctuations.json").write_text(json.dumps(out, indent=1) + "\n")
    plot(out)


def plot(out):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.5, 4.5))
    for kT, mk in ((1e-5, "o"), (1e-3, "s")):
        for (scheme, fl), col, lab in ((("euler", False), "C0", "Euler"), (("stiff", False), "C3", "stiff"),
                                       (("stiff", True), "C2", "stiff --fluct")):
            rows = [r for r in out["bonded_pair"]["rows"] if r["kT"] == kT and r["scheme"] == scheme
                    and r["fluct"] == fl]
            if rows:
                ax.errorbar([r["dt_t0"] for r in rows], [r["variance_over_exact"] for r in rows],
                            [r["sampling_error"] for r in rows], fmt=mk + "-", color=col,
                            mfc="none" if kT > 1e-5 else col, label=f"{lab}, kT={kT:g}")
    ax.axhspan(0.95, 1.05, color="k", alpha=0.08, label="within 5 %")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("dt (t0)")
    ax.set_ylabel("bond-length variance / exact")
    ax.set_title("bonded pair: stationary bond fluctuations per scheme", fontsize=9)
    ax.legend(fontsize=7)
    ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(RESULTS / "sim_fluctuations.png", dpi=120)


if __name__ == "__main__":
    main()
