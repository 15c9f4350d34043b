"""Thermal spread and signal time of compiled circuits (docs/circuits.md, "Thermal spread").

For each example (default Tetris and the full adder), built as ``mlc compile`` builds it:

* the harmonic thermal spread (sigma) at kT = 1e-5 k0 sigma^2 of every output probe and of
  every gate's input and output pair, about the scene's rest pose
  (:func:`mlc.verify.dynamic.probe_thermal_sd`), with the scene as built and with the
  connector chains' bonds (names ``w_...``) 10 and 100 times stiffer, and the gates' bonds
  10 times stiffer: where the compliance sits;
* the signal time (t0) of every row from rest (:func:`mlc.verify.dynamic.signal_time`) and
  its wall time, and for the connector chains the ratio to the slowest relaxation time
  against theory's pi^2/8;
* with ``--drift T``: a Brownian-dynamics run of the first example's rest row for T t0
  (stiff scheme, dt 0.01 t0, seed 0, kT 1e-5): every gate pair's length at the end, then
  the static equilibrium from that pose (is the drift thermal, or a second equilibrium?).

    python benchmarks/circuit_thermal.py [--only full_adder.expr] [--drift 200]

Writes benchmarks/results/circuit_thermal.json.  Units: sigma, t0, seconds wall.
"""
from __future__ import annotations

import argparse
import copy
import json
import math
import os
import time
from pathlib import Path

import mlc  # noqa: F401 -- before numpy: pins OpenBLAS's kernels (mlc/__init__.py)
import numpy as np

from mlc.gates.connector import chain_scene
from mlc.pipeline import build, compile_spec, load
from mlc.scene.model import Probe
from mlc.verify.dynamic import probe_thermal_sd, relaxation_time, signal_time
from gitstate import commit as git_commit      # benchmarks/gitstate.py

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "benchmarks" / "results" / "circuit_thermal.json"
KT = 1e-5


def with_pair_probes(scene):
    """A copy of ``scene`` that also probes every gate's input and output pair."""
    sc = copy.deepcopy(scene)
    sites = {f"{b.name}.{s}" for b in sc.bodies for s in b.sites}
    for g in sorted(sc.meta.get("gates", {})):
        for pin, sfx in (("a", "in"), ("b", "in"), ("out", "out")):
            lo, hi = f"{g}_{pin}_lo.{sfx}", f"{g}_{pin}_hi.{sfx}"
            if lo in sites and hi in sites:
                sc.probes.append(Probe(f"{g}.{pin}", sc.outputs[0], lo, hi, 1.0, 1.5))
    return sc


def scaled(scene, chains: float = 1.0, gates: float = 1.0):
    sc = copy.deepcopy(scene)
    for b in sc.bonds:
        b.k *= chains if b.name.startswith("w_") else gates
    return sc


def pair_lengths(scene, pos, quat) -> dict:
    from mlc.verify.static import _Problem
    A = scene.arrays()
    p, _ = _Problem(scene, pos, quat, pin_first=False).sites()
    return {pr.name: float(np.linalg.norm(p[A.probe_i[k]] - p[A.probe_j[k]])) for k, pr in enumerate(scene.probes)}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--only", nargs="*", default=["tetris.tt", "full_adder.expr"])
    ap.add_argument("--drift", type=float, default=0.0, help="t0 of Brownian dynamics at rest (first example)")
    a = ap.parse_args()
    res = {"commit": git_commit(), "kT": KT, "load": list(os.getloadavg()),
           "examples": {}, "chains": []}
    for u in (5, 10, 20):
        sc = chain_scene(u, "contract")
        st, tau = signal_time(sc, "0", "1"), relaxation_time(sc)
        res["chains"].append({"units": u, "signal": "contract", "signal_time": st, "tau": tau,
                              "ratio": st / tau, "theory": math.pi ** 2 / 8})
        print(res["chains"][-1], flush=True)
    for name in a.only:
        t0 = time.perf_counter()
        sc = build(compile_spec(load(str(ROOT / "examples" / name)))).circuit.scene
        ex = {"bodies": len(sc.bodies), "build_s": time.perf_counter() - t0, "spread": {}, "signal_time": {}}
        probed = with_pair_probes(sc)
        for label, kw in (("as built", {}), ("chains x10", {"chains": 10.0}), ("chains x100", {"chains": 100.0}),
                          ("gates x10", {"gates": 10.0})):
            t1 = time.perf_counter()
            ex["spread"][label] = probe_thermal_sd(scaled(probed, **kw), KT)
            print(name, label, f"{time.perf_counter() - t1:.1f} s",
                  {k: round(v, 3) for k, v in ex["spread"][label].items()}, flush=True)
        rest = "0" * len(sc.inputs)
        for s in sc.states():
            if s == rest:
                continue
            t1 = time.perf_counter()
            ex["signal_time"][s] = {"t0": signal_time(sc, rest, s), "wall_s": time.perf_counter() - t1}
        print(name, "signal time", {s: round(v["t0"], 1) for s, v in ex["signal_time"].items()}, flush=True)
        res["examples"][name] = ex
        if a.drift > 0 and name == a.only[0]:
            from mlc.sim.drive import Drive
            from mlc.sim.integrator import SimOptions, Simulation
            from mlc.verify.static import equilibrium
            sim = Simulation(probed, {i: Drive.constant(0) for i in probed.inputs},
                             SimOptions(scheme="stiff", kT=KT, seed=0, dt=0.01))
            t1 = time.perf_counter()
            r = sim.run(a.drift, quiet=True)
            after = pair_lengths(probed, r.pos, r.quat)
            eq = equilibrium(probed.with_poses(r.pos, r.quat), rest)
            back = pair_lengths(probed, eq.pos, eq.quat)
            ex["drift"] = {"t0": a.drift, "wall_s": time.perf_counter() - t1, "lengths_after": after,
                           "lengths_re_minimised": back, "stretch_re_minimised": eq.max_joint_stretch}
            print(name, "drift", {k: round(v, 3) for k, v in after.items()}, flush=True)
            print(name, "re-minimised", {k: round(v, 4) for k, v in back.items()}, flush=True)
        OUT.write_text(json.dumps(res, indent=1))
    print(f"wrote {OUT}")


if __name__ == "__main__":
    main()
