"""Dynamic gate verification: Brownian dynamics from rest into every input state.

For each library gate, muscle convention and input state, and for each seed: start
the gate at rest (all inputs 0), switch the inputs into the state at t = 0 (constant
drives), and integrate at ``kT`` until the output probe has relaxed.  Relaxation is
detected, not assumed: the probe is averaged over windows of ``WINDOW`` t0 and the run
stops once the last ``SETTLE`` window means agree within ``tol = 2e-3 + 3 sqrt(kT/k0)``
sigma (and at most ``MAX_TIME`` t0).  The measured output is the mean of those windows;
the margin is its signed distance from the probe threshold towards the expected bit.
"""
from __future__ import annotations

import math

import numpy as np

from mlc.sim.drive import Drive
from mlc.sim.integrator import SimOptions, Simulation

WINDOW = 0.05      # t0
SETTLE = 3         # windows that must agree
MAX_TIME = 20.0    # t0
DT = {"stiff": 0.01, "euler": None}   # None: half the estimated Euler limit


def relax(sim: Simulation, probe: str, kT: float, window: float = WINDOW, settle: int = SETTLE,
          max_time: float = MAX_TIME):
    """Run ``sim`` until the probe's window means settle; returns (mean, relax_time t0, relaxed)."""
    tol = 2e-3 + 3.0 * math.sqrt(max(kT, 0.0) / sim.k0)
    means = []
    t = 0.0
    while t < max_time:
        res = sim.run(window, record_interval=min(window / 10, window), quiet=True)
        t = res.time
        means.append(float(np.mean(res.probes[probe][1:] if len(res.probes[probe]) > 1 else res.probes[probe])))
        if len(means) >= settle:
            last = means[-settle:]
            if max(last) - min(last) < tol:
                return float(np.mean(last)), t, True
    return float(np.mean(means[-settle:])), t, False


def check_scene_dynamic(scene, kT: float, seeds: int, scheme: str = "stiff",
                        dt: float | None = None) -> list[dict]:
    """Dynamic check of one scene with one probe against its truth table: one row per
    input state with the probe measured after relaxation (mean over seeds), the
    smallest margin over seeds (sigma) and ok = every seed relaxed and read the
    expected bit with a positive margin.  Row keys: state, expected, measured, margin,
    ok, seed(s), relax_time (largest over seeds, t0; None if a seed did not relax)."""
    rows = []
    seed_list = list(range(int(seeds)))
    probe = scene.probes[0]
    for state in scene.states():
        expected = int(scene.truth_table[state])
        drives = {inp: Drive.constant(int(bit)) for inp, bit in zip(scene.inputs, state)}
        vals, margins, relax_times, oks = [], [], [], []
        for seed in seed_list:
            opt = SimOptions(scheme=scheme, kT=kT, seed=seed,
                             dt=dt if dt is not None else DT.get(scheme))
            sim = Simulation(scene, drives, opt)
            mean, t_rel, relaxed = relax(sim, probe.name, kT)
            m = probe.margin(mean, expected)
            vals.append(mean)
            margins.append(m)
            relax_times.append(t_rel if relaxed else None)
            oks.append(relaxed and probe.bit(mean) == expected and m > 0)
        rows.append({"state": state, "expected": str(expected),
                     "measured": float(np.mean(vals)), "margin": float(min(margins)), "ok": all(oks),
                     "seed(s)": seed_list,
                     "relax_time": (max(relax_times) if all(r is not None for r in relax_times) else None)})
    return rows


def check_gates_dynamic(names: list[str], signals: list[str], kT: float, seeds: int, scheme: str = "stiff",
                        quiet: bool = True, dt: float | None = None) -> list[dict]:
    """:func:`check_scene_dynamic` for every library gate in ``names`` and convention in
    ``signals``; rows also carry ``gate`` and ``signal``."""
    import sys

    from mlc.gates.library import gate_scene

    rows = []
    for name in names:
        for signal in signals:
            for r in check_scene_dynamic(gate_scene(name, signal), kT, seeds, scheme, dt):
                row = {"gate": name, "signal": signal, **r}
                rows.append(row)
                if not quiet:
                    rt = "not relaxed" if row["relax_time"] is None else f"{row['relax_time']:.2f} t0"
                    sys.stderr.write(f"{name:8s} {signal:8s} {row['state']}: expected {row['expected']}, "
                                     f"out = {row['measured']:.4f} sigma, margin {row['margin']:+.4f}, {rt}"
                                     f"{'' if row['ok'] else '  WRONG'}\n")
    return rows
