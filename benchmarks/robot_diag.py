"""Diagnosis of a robot fold (issue 10, docs/robot.md 3.3): one row from rest, logging the
coupling chains' junction bends against the largest bend, the gate outputs and DOF
lengths, and the slab clearance of the chains (:func:`mlc.verify.overlap.clearance`).

A junction's bend beta is read from its stop sites (``_DA.stop_out`` of the lower half
unit, ``_AB.stop_in`` of the upper one, each ``STOP_ARM`` = m from the junction's joint on
its layer's centre line): they are 2 m cos(beta/2) apart, whatever the bond between them.
The first junction of a chain hung on a lever is read the same way from the lever's stop
site.  Every ``--every`` t0 the script prints and stores, per chain, the largest bend
(degrees) and its junction, the number of junctions beyond 0.9 max_bend (the stops) and
beyond max_bend (layers touching), and the smallest clearance between a chain body and
any other body.

    python benchmarks/robot_diag.py OUT/robot.yaml --row 01 --seed 1 --time 600 [--dt 0.2]
        [--chains rc_u2_up rc_u3_dn] [-o /tmp/diag.json]

Units: t0, sigma, degrees, seconds wall.
"""
from __future__ import annotations

import argparse
import json
import math
import sys
import time

import mlc  # noqa: F401 -- before numpy: pins OpenBLAS's kernels (mlc/__init__.py)
import numpy as np


def junction_sites(scene, prefix: str):
    """[(name, site a, site b)] of the junctions of chain ``prefix``, first (at the output
    pair) to last."""
    names = {b.name for b in scene.bodies}
    n = 0
    while f"{prefix}_{n}_AB" in names:
        n += 1
    out = []
    lev = [bd for bd in scene.bonds if bd.name == f"{prefix}_s0" and not bd.a.split(".")[0].startswith(prefix)]
    if lev:
        out.append(("s0", lev[0].a, lev[0].b))
    for i in range(1, n):
        out.append((f"s{i}", f"{prefix}_{i - 1}_DA.stop_out", f"{prefix}_{i}_AB.stop_in"))
    return out, n


def main(argv=None) -> int:
    from mlc.gates.connector import STOP_ARM, STOP_FRACTION, connector_geometry, max_bend
    from mlc.scene.io import load_scene
    from mlc.sim.drive import Drive
    from mlc.sim.integrator import SimOptions, Simulation
    from mlc.verify.overlap import clearance

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scene")
    ap.add_argument("--row", default="01")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--time", type=float, default=600.0)
    ap.add_argument("--dt", type=float, default=0.2)
    ap.add_argument("--every", type=float, default=25.0)
    ap.add_argument("--kT", type=float, default=1e-5)
    ap.add_argument("--chains", nargs="*", default=None)
    ap.add_argument("--no-clearance", action="store_true")
    ap.add_argument("-o", "--out", default=None)
    a = ap.parse_args(argv)
    sc = load_scene(a.scene)
    geo = connector_geometry("expand")
    bmax = math.degrees(max_bend(geo))
    chains = a.chains or sorted({b.name.split("_")[0] + "_" + "_".join(b.name.split("_")[1:3])
                                 for b in sc.bodies if b.name.startswith("rc_")})
    idx = {b.name: i for i, b in enumerate(sc.bodies)}
    J = {c: junction_sites(sc, c) for c in chains}
    bodies_of = {c: [i for n, i in idx.items() if n.startswith(c + "_")] for c in chains}
    drives = {inp: Drive.constant(int(b)) for inp, b in zip(sc.inputs, a.row)}
    sim = Simulation(sc, drives, SimOptions(scheme="stiff", kT=a.kT, seed=a.seed, dt=a.dt))
    probes = [p.name for p in sc.probes if p.output in {"u2_up", "u3_dn", "u3_up", "u4_up", "u4_dn"}]
    m = STOP_ARM
    log = []
    wall = time.perf_counter()

    def site(pos, R, s):
        b, n = s.split(".", 1)
        i = idx[b]
        return pos[i] + R[i] @ sc.bodies[i].sites[n]

    from mlc.verify.overlap import _quat_matrices
    t = 0.0
    while t < a.time - 1e-9:
        res = sim.run(a.every, record_interval=a.every / 10, quiet=True)
        t = res.time
        pos, quat = sim.pos.copy(), sim.quat.copy()
        R = _quat_matrices(quat)
        rec = {"t": round(t, 2), "probes": {p: round(float(np.mean(res.probes[p][1:])), 4) for p in probes},
               "chains": {}}
        if not a.no_clearance:
            rep = clearance(sc, pos, quat)
            names = [b.name for b in sc.bodies]
            rec["min_clearance_all"] = (round(rep.min_clearance, 4), list(rep.pair))
        for c in chains:
            js, n = J[c]
            betas = []
            for nm, s1, s2 in js:
                d = float(np.linalg.norm(site(pos, R, s1) - site(pos, R, s2)))
                betas.append(math.degrees(2.0 * math.acos(min(1.0, d / (2 * m)))))
            k = int(np.argmax(betas))
            ch = {"max_bend_deg": round(betas[k], 2), "at": js[k][0],
                  "n_over_stop": int(sum(b > STOP_FRACTION * bmax for b in betas)),
                  "n_over_max": int(sum(b > bmax for b in betas)),
                  "bends": [round(b, 1) for b in betas]}
            if not a.no_clearance:
                mine = set(names[i] for i in bodies_of[c])
                ov = [(x, y, round(dd, 3)) for x, y, dd in rep.overlaps if x in mine or y in mine]
                ch["overlaps"] = ov[:6]
                ch["n_overlaps"] = len(ov)
            rec["chains"][c] = ch
        log.append(rec)
        line = " ".join(f"{p}={v:.3f}" for p, v in rec["probes"].items())
        print(f"t={t:7.1f} {line}", flush=True)
        for c, ch in rec["chains"].items():
            print(f"   {c}: max bend {ch['max_bend_deg']:.1f} at {ch['at']} (stop {STOP_FRACTION * bmax:.1f}, "
                  f"max {bmax:.1f}); over stop {ch['n_over_stop']}, over max {ch['n_over_max']}"
                  + (f"; overlaps {ch['n_overlaps']} {ch['overlaps'][:2]}" if "overlaps" in ch else ""), flush=True)
        if "min_clearance_all" in rec:
            print(f"   min clearance (all) {rec['min_clearance_all']}", flush=True)
    if a.out:
        np.savez(a.out.replace(".json", "") + "_final.npz", pos=sim.pos, quat=sim.quat, t=t)
    out = {"scene": a.scene, "row": a.row, "seed": a.seed, "dt": a.dt, "kT": a.kT,
           "max_bend_deg": bmax, "stop_deg": STOP_FRACTION * bmax, "wall_s": round(time.perf_counter() - wall, 1),
           "log": log}
    if a.out:
        with open(a.out, "w") as f:
            json.dump(out, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
