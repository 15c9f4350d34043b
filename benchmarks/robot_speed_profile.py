"""Where a robot fold's time goes (issue 10 item 6; docs/robot.md section 3.4, session 11).

For one row of a robot scene, short runs from rest (``--time`` t0 each, kT = 1e-5, stiff
scheme) at several dt and, optionally, with the coupling chains' and circuit connectors'
joint stiffness scaled back to the design k0 (``--k0-chains``: every bond whose k is the
scene's ``joint_k`` times k0 gets k0 instead; a probe of "model only what a scene needs":
the stiff joints set the scheme's stage count).  For each run: wall seconds, wall per t0,
force evaluations per step and per t0 (the compiled kernel's work: every evaluation is one
pass over all bodies, bonds and neighbour pairs), the SK-ROCK stage count, and the wall per
force evaluation per body.  Plus the one-off costs of a verification run: reading the
scene and building the simulation.

    python benchmarks/robot_speed_profile.py OUT/robot.yaml --row 11 --dts 0.2 0.4 0.8
        [--time 20] [--k0-chains] [-o benchmarks/results/robot_speed_profile.json]

Units: t0, seconds wall, k0.
"""
from __future__ import annotations

import argparse
import copy
import json
import os
import platform
import sys
import time

from mlc.io.atomic import atomic_path


def main(argv=None) -> int:
    from mlc.scene.io import load_scene
    from mlc.sim.drive import Drive
    from mlc.sim.integrator import SimOptions, Simulation

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scene")
    ap.add_argument("--row", default="11")
    ap.add_argument("--dts", nargs="*", type=float, default=[0.2, 0.4, 0.8])
    ap.add_argument("--time", type=float, default=20.0, help="t0 per run")
    ap.add_argument("--kT", type=float, default=1e-5)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--k0-chains", action="store_true")
    ap.add_argument("-o", "--out", default="benchmarks/results/robot_speed_profile.json")
    a = ap.parse_args(argv)
    t = time.perf_counter()
    sc = load_scene(a.scene)
    t_load = time.perf_counter() - t
    joint_k = float((sc.meta.get("circuit", {}).get("connector", {}) or {}).get("joint_k", 1.0))
    variants = [("as built", sc)]
    if a.k0_chains:
        k0 = copy.deepcopy(sc)
        kmax = max(b.k for b in sc.bonds)
        n = 0
        for b in k0.bonds:
            if joint_k != 1.0 and abs(b.k - joint_k) < 1e-9:   # connector bonds at joint_k k0; skeleton, stops stay
                b.k = 1.0
                n += 1
        variants.append((f"connector bonds back to k0 ({n} bonds; largest k was {kmax:g})", k0))
    out = {"what": "robot fold cost by dt (benchmarks/robot_speed_profile.py)", "scene": a.scene,
           "bodies": len(sc.bodies), "bonds": len(sc.bonds), "joint_k": joint_k, "row": a.row,
           "time_t0": a.time, "kT": a.kT, "seed": a.seed, "load_scene_s": round(t_load, 2),
           "machine": f"{platform.machine()}, {os.cpu_count()} cores, shared", "units": "t0, seconds wall, k0",
           "runs": []}
    for label, scene in variants:
        drives = {inp: Drive.constant(int(b)) for inp, b in zip(scene.inputs, a.row)}
        for dt in a.dts:
            t = time.perf_counter()
            sim = Simulation(scene, drives, SimOptions(scheme="stiff", kT=a.kT, seed=a.seed, dt=dt))
            t_build = time.perf_counter() - t
            sim.run(min(2 * dt, a.time), quiet=True)          # compile / warm up (not timed)
            res = sim.run(a.time, quiet=True)
            r = {"variant": label, "dt": dt, "build_sim_s": round(t_build, 2), "wall_s": round(res.wall, 2),
                 "wall_per_t0_s": round(res.wall / a.time, 4), "steps": res.steps,
                 "force_evals": res.force_evals, "evals_per_step": round(res.force_evals / max(res.steps, 1), 2),
                 "evals_per_t0": round(res.force_evals / a.time, 1), "stages": res.stages,
                 "wall_per_eval_per_body_us": round(1e6 * res.wall / max(res.force_evals, 1) / len(scene.bodies), 4),
                 "load_1min": round(os.getloadavg()[0], 2)}
            out["runs"].append(r)
            print(r, flush=True)
            with atomic_path(a.out) as tmp, open(tmp, "w") as f:
                json.dump(out, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
