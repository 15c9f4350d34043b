"""What each scheme does to bond fluctuations (docs/simulation.md).

A 64-slab hinged chain at kT = 1e-5: the mean squared hinge-bond length <|d|^2> over
a run, against the exact equilibrium value, for Euler across dt up to its limit and
the stiff scheme across dt; and a gate's output (NAND, state 11) mean and spread.

    python benchmarks/sim_fluctuations.py

Writes benchmarks/results/sim_fluctuations.json.
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from mlc.gates.library import gate_scene
from mlc.sim.drive import Drive
from mlc.sim.integrator import SimOptions, Simulation
from mlc.sim.testscenes import chain_scene

RESULTS = Path(__file__).resolve().parent / "results"


def bond_msd(scheme, dt, kT=1e-5, T=2.0, samples=200):
    sc = chain_scene(64)
    sim = Simulation(sc, None, SimOptions(scheme=scheme, dt=dt, kT=kT, seed=11))
    sim.run(0.2)
    acc = []
    for _ in range(samples):
        sim.run(T / samples)
        sim._eval()
        d = sim.ws[sim.sp_j] - sim.ws[sim.sp_i]
        acc.append(np.mean(np.sum(d * d, axis=1)))
    return float(np.mean(acc)), sim


def main():
    kT = 1e-5
    sim = Simulation(chain_scene(64), None, SimOptions(scheme="euler", kT=kT))
    lim = sim.euler_limit()
    rows = []
    # reference: Euler at a small fraction of its limit
    ref, _ = bond_msd("euler", lim / 10)
    for scheme, dts in (("euler", [lim * f for f in (0.1, 0.5, 0.8, 0.95)]),
                        ("stiff", [0.001, 0.01, 0.05, 0.2])):
        for dt in dts:
            m, s = bond_msd(scheme, dt)
            rows.append({"scheme": scheme, "dt_t0": dt, "dt_over_euler_limit": dt / lim,
                         "bond_msd": m, "ratio_to_reference": m / ref})
            print(rows[-1], flush=True)
    gate = gate_scene("NAND")
    g = []
    for scheme, dt in (("euler", 0.5 * Simulation(gate, None, SimOptions(scheme="euler")).euler_limit()),
                       ("stiff", 0.01), ("stiff", 0.05)):
        vals = []
        sim = Simulation(gate, {"a": Drive.constant(1), "b": Drive.constant(1)},
                         SimOptions(scheme=scheme, dt=dt, kT=kT, seed=3))
        sim.run(0.5)
        r = sim.run(5.0, record_interval=0.01)
        vals = r.probes["out"]
        g.append({"scheme": scheme, "dt_t0": dt, "out_mean": float(np.mean(vals)), "out_std": float(np.std(vals))})
        print(g[-1], flush=True)
    out = {"kT": kT, "euler_limit_t0": lim, "reference_bond_msd_euler_limit_over_10": ref,
           "equipartition_note": "a zero-rest bond between two free ends has <|d|^2> ~ 3 kT / k_eff",
           "chain64": rows, "gate_NAND_11_output": g}
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "sim_fluctuations.json").write_text(json.dumps(out, indent=1) + "\n")


if __name__ == "__main__":
    main()
