"""Other equilibria of the library gates (issue 12, item 6): rigidity, fold barriers,
and whether Brownian dynamics from rest reaches another branch.

    python benchmarks/gate_branches.py [--quick]

1. Smallest singular value of the joint + muscle Jacobian (body 0 fixed, central
   differences) at the design equilibrium of every gate, convention and state.
2. Fold barriers (mlc.verify.branches.fold_barrier): the constrained-minimum energy
   profile of a lever side's branch indicator from the design equilibrium to its fold,
   for the cases named in the issue and a few more; the peak is the barrier along that
   path (k0 sigma^2).
3. Brownian dynamics (mlc.sim, stiff scheme, default dt) from rest into every input
   state at kT = 1e-5, 1e-4, 1e-3, several seeds, 10 t0 each; frames are quenched to
   their local equilibrium (mlc.verify.branches.quench) and compared with the design
   equilibrium.  Plus long runs of the lowest-barrier case.
Writes benchmarks/results/gate_branches.json.
"""
from __future__ import annotations

import json
import os
import platform
import sys
import time
from pathlib import Path

import mlc  # noqa: F401 -- before numpy: pins OpenBLAS's kernels (mlc/__init__.py)
import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from mlc.gates.library import GATE_NAMES, gate_scene  # noqa: E402
from mlc.sim.drive import Drive  # noqa: E402
from mlc.sim.integrator import SimOptions, Simulation  # noqa: E402
from mlc.verify.branches import fold_barrier, quench, singular_values  # noqa: E402
from mlc.verify.static import equilibrium  # noqa: E402

RESULTS = ROOT / "benchmarks" / "results"
# (gate, signal, state, indicator, target): the cases first
BARRIER_CASES = [
    ("NAND", "contract", "10", "b.out", -0.3),     # the wrong-bit (folded) equilibrium at b.out = -0.25
    ("NAND", "contract", "11", "a.out", 0.0),      # the 0.854-sigma branch (b.out ~ 0.1)
    ("CIMPLY", "contract", "01", "a.out", 0.0),
    ("AND", "contract", "11", "a.out", 0.0),       # the 0.657-sigma branch
    ("CNIMPLY", "contract", "01", "b.out", 0.0),
    ("NAND", "contract", "00", "a.out", 0.0),
    ("NAND", "contract", "10", "a.out", 0.0),
    ("NAND", "expand", "11", "a.out", 0.0),
    ("NAND", "expand", "00", "a.out", 0.0),
    ("NOR", "expand", "01", "b.out", 0.0),
    ("NAND", "contract", "10", "out.out", 0.0),
    ("NAND", "expand", "10", "out.out", 0.0),
]


def bd_study(kT, seeds, T, names, signals, frames=5):
    rows = []
    for name in names:
        for signal in signals:
            s = gate_scene(name, signal)
            for state in s.states():
                ref = equilibrium(s, state)
                pr = s.probes[0]
                exp = int(s.truth_table[state])
                left, nq, minm = [], 0, np.inf
                for seed in range(seeds):
                    drives = {i: Drive.constant(int(b)) for i, b in zip(s.inputs, state)}
                    res = Simulation(s, drives, SimOptions(kT=kT, seed=seed)).run(
                        T, record_interval=T / 200, frames=frames, quiet=True)
                    v = res.probes[pr.name]
                    minm = min(minm, float(min(pr.margin(x, exp) for x in v[len(v) // 2:])))
                    for fp, fq in zip(res.frame_pos[1:], res.frame_quat[1:]):
                        q = quench(s, state, fp, fq, ref)
                        nq += 1
                        if not q["design"]:
                            left.append({"seed": seed, "probe": q["probe"], "folded": q["folded"]})
                rows.append({"gate": name, "signal": signal, "state": state, "kT": kT, "seeds": seeds, "T": T,
                             "quenched_frames": nq, "left_design": len(left), "examples": left[:3],
                             "min_margin_second_half": minm})
                print(json.dumps(rows[-1]), flush=True)
    return rows


def main() -> int:
    quick = "--quick" in sys.argv
    if "--long-only" in sys.argv:       # redo the long runs only, into the existing results
        path = RESULTS / "gate_branches.json"
        out = json.loads(path.read_text())
        out["brownian"] = [r for r in out["brownian"] if r["T"] < 50] + \
            bd_study(1e-3, 8, 50.0, ["NAND"], ["contract", "expand"], frames=20)
        path.write_text(json.dumps(out, indent=1) + "\n")
        return 0
    t0 = time.time()
    out = {"benchmark": "gate_branches", "python": platform.python_version(), "cpus": os.cpu_count()}
    sv = []
    for signal in ("expand", "contract"):
        for name in GATE_NAMES:
            s = gate_scene(name, signal)
            for state in s.states():
                eq = equilibrium(s, state)
                sv.append({"gate": name, "signal": signal, "state": state,
                           "sigma_min": float(singular_values(s, state, eq.pos, eq.quat).min())})
    out["singular_values"] = {"min": min(r["sigma_min"] for r in sv), "max": max(r["sigma_min"] for r in sv),
                              "rows": sv}
    print("sigma_min range", out["singular_values"]["min"], out["singular_values"]["max"], flush=True)
    bar = []
    for name, signal, state, ind, target in (BARRIER_CASES[:2] if quick else BARRIER_CASES):
        s = gate_scene(name, signal)
        eq = equilibrium(s, state)
        fb = fold_barrier(s, state, ind, eq.pos, eq.quat, steps=12 if target < 0 else 6, target=target)
        bar.append({"gate": name, "signal": signal, "state": state, "indicator": ind, "start": fb.start,
                    "target": target, "peak": fb.peak, "end": fb.barrier,
                    "profile": [[float(a), float(b)] for a, b in fb.profile]})
        print(json.dumps(bar[-1]), flush=True)
    out["fold_barriers"] = bar
    names = ["NAND", "AND"] if quick else list(GATE_NAMES)
    bd = []
    for kT, seeds in ((1e-5, 2), (1e-4, 2), (1e-3, 4)):
        bd += bd_study(kT, seeds, 10.0, names, ["contract", "expand"])
    # the lowest barrier found: long runs
    bd += bd_study(1e-3, 4 if quick else 8, 50.0, ["NAND"], ["contract", "expand"], frames=20)
    out["brownian"] = bd
    out["wall_seconds"] = time.time() - t0
    RESULTS.mkdir(parents=True, exist_ok=True)
    (RESULTS / "gate_branches.json").write_text(json.dumps(out, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
