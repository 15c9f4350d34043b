"""How far each coupling chain's end must turn about the skeleton's plane normal in each
row's static pose (docs/robot.md section 6, "Slab clearance").

A coupling chain ends on its DOF's two lever sites (``{b1}.lever_{dof}``,
``{b2}.lever_{dof}``) by two ball joints, so its last pair lies along the lever axis.  The
skeleton folds in its plane, so between rows that axis turns about the plane normal (z).
A chain that arrives from below (last tangent +z) can take that turn only as a *twist*
about its own tangent, which no junction of a connector chain does (each bends about its
pair axis only; docs/circuits.md, "The two twists above ...").  For every row this
script solves the static equilibrium (:func:`mlc.robot.verify.verify_robot_static`, as
``mlc verify``) and reports, for every lever-coupled DOF, the turn of its lever axis about
z from the scene as built and how far the lever pair's centre moved; and the same for
the chain's start (the circuit's output pair) for comparison.  No formula of
:mod:`mlc.robot.build` is used: sites and poses come from the scene and the solve.

    python benchmarks/robot_twist.py OUT/robot.yaml [--rows 01 10 11]
        [-o benchmarks/results/robot_twist.json]

Units: degrees (turns), sigma (moves), seconds wall.
"""
from __future__ import annotations

import argparse
import json
import math
import sys
import time

import mlc  # noqa: F401 -- before numpy: pins OpenBLAS's kernels (mlc/__init__.py)
import numpy as np
from mlc.io.atomic import atomic_path


def site_world(scene, idx, pos, R, site: str) -> np.ndarray:
    b, s = site.split(".", 1)
    i = idx[b]
    return pos[i] + R[i] @ np.asarray(scene.bodies[i].sites[s], float)


def pair_frame(scene, idx, pos, R, lo: str, hi: str):
    a, b = site_world(scene, idx, pos, R, lo), site_world(scene, idx, pos, R, hi)
    return 0.5 * (a + b), b - a


def turn_about_z(u0, u1) -> float:
    """Signed angle (deg) from u0 to u1 projected on the xy plane; the pair axis has no
    sign of its own here (both ends are joined the same way), so this is in (-180, 180]."""
    a0, a1 = math.atan2(u0[1], u0[0]), math.atan2(u1[1], u1[0])
    return (math.degrees(a1 - a0) + 180.0) % 360.0 - 180.0


def main(argv=None) -> int:
    from mlc.geometry.rotation import quat_to_matrix
    from mlc.robot.verify import verify_robot_static
    from mlc.scene.io import load_scene

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scene")
    ap.add_argument("--rows", nargs="*")
    ap.add_argument("-o", "--out", default="benchmarks/results/robot_twist.json")
    a = ap.parse_args(argv)
    sc = load_scene(a.scene)
    idx = {b.name: i for i, b in enumerate(sc.bodies)}
    rm = sc.meta["robot"]
    probes = {p.output: p for p in sc.probes if not p.name.startswith("dof_")}
    levers = [d for d in rm["dofs"] if d.get("coupling") == "lever"]
    A = sc.arrays()
    R0 = np.array([quat_to_matrix(q) for q in A.quat])
    built = {}
    for d in levers:
        b1, b2 = d["bodies"]
        pr = probes[d["output"]]
        built[d["name"]] = (pair_frame(sc, idx, A.pos, R0, f"{b1}.lever_{d['name']}", f"{b2}.lever_{d['name']}"),
                            pair_frame(sc, idx, A.pos, R0, pr.a, pr.b))
    rows = a.rows or sorted(sc.truth_table)
    out = {"what": "turn of each coupling chain's lever axis about the skeleton's plane normal, static poses "
                   "(benchmarks/robot_twist.py)", "scene": a.scene, "bodies": len(sc.bodies),
           "units": "degrees (turns), sigma (moves), seconds wall", "rows": {}}
    for row in rows:
        t = time.perf_counter()
        rep = verify_robot_static(sc, rows=[row], keep_poses=True, clearance=False)
        pos, quat = rep.poses[row]
        R = np.array([quat_to_matrix(q) for q in quat])
        r = {"shape_read": rep.rows[0]["shape_read"], "turns_read": rep.rows[0]["turns_read"], "dofs": {}}
        for d in levers:
            b1, b2 = d["bodies"]
            pr = probes[d["output"]]
            (c0, u0), (s0, v0) = built[d["name"]]
            c1, u1 = pair_frame(sc, idx, pos, R, f"{b1}.lever_{d['name']}", f"{b2}.lever_{d['name']}")
            s1, v1 = pair_frame(sc, idx, pos, R, pr.a, pr.b)
            ch = d.get("chain", {})
            r["dofs"][d["name"]] = {
                "half_units": ch.get("half_units"),
                "lever_turn_z_deg": round(turn_about_z(u0, u1), 2),
                "lever_move_sigma": round(float(np.linalg.norm(c1 - c0)), 3),
                "start_turn_z_deg": round(turn_about_z(v0, v1), 2),
                "start_move_sigma": round(float(np.linalg.norm(s1 - s0)), 3)}
        r["wall_s"] = round(time.perf_counter() - t, 1)
        out["rows"][row] = r
        print(f"row {row} ({r['shape_read']}): " + ", ".join(
            f"{k} {v['lever_turn_z_deg']:+.0f} deg / {v['lever_move_sigma']:.1f} s (start {v['start_turn_z_deg']:+.0f})"
            for k, v in r["dofs"].items()), flush=True)
        with atomic_path(a.out) as tmp, open(tmp, "w") as f:
            json.dump(out, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
