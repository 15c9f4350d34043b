"""How unique is a robot's static pose?  Each coupling chain solved alone, its ends held,
against the whole robot's static solve (docs/robot.md section 6, session 55).

The model has no slab contact, so coupling chains do not act on each other: a chain's
equilibrium in a row depends only on the bodies its bonds reach (its gate's output levers
and the skeleton bodies of its DOF).  For every row this script

1. solves the whole robot (:func:`mlc.robot.verify.verify_robot_static`, as ``mlc verify``),
2. solves each chain alone: the chain's bodies free, the bodies its bonds reach held, moved
   from their as-built poses to the whole solve's in ``--steps`` straight steps (positions
   linearly, rotations by slerp), a Levenberg-Marquardt minimisation after each
   (:func:`mlc.verify.static._minimise`, the static solver's own), then a polish;
3. records the largest bond residual of each alone solve (0: an equilibrium with every bond
   met), how far each chain's bodies lie from the whole solve's (max and mean, sigma), and
   every two chains' smallest slab clearance in both (the oriented-box distance,
   ``benchmarks/robot_overlaps.chain_pairs``).

Two equilibria of one chain with its ends in one place are both zero-energy poses: a
difference measures the chains' floppy modes, and a clearance that differs between them is a
property of the path the solve took, not of the robot.

    python benchmarks/robot_chain_alone.py OUT/robot.yaml [--rows 01 11] [--steps 20]
        [-o benchmarks/results/robot_chain_alone.json]

Units: sigma, seconds wall.
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))      # gitstate, robot_overlaps


def solve_alone(scene, chain: list[int], P0, Q0, P1, Q1, steps: int):
    """(positions, quaternions, largest |residual|, held body names, iterations) of the bodies
    ``chain`` of ``scene`` at equilibrium with the bodies their bonds reach held, moved from
    (P0, Q0) to (P1, Q1) in ``steps`` steps."""
    import numpy as np
    from scipy.spatial.transform import Rotation, Slerp

    from mlc.geometry.rotation import matrix_to_quat, quat_to_matrix
    from mlc.scene.model import Scene
    from mlc.verify import static as S

    names = [b.name for b in scene.bodies]
    index = {n: i for i, n in enumerate(names)}
    cset = set(chain)

    def body(ref):
        return index[ref.split(".")[0]]

    held = sorted({body(x) for bd in scene.bonds for x in (bd.a, bd.b)
                   if body(bd.a) in cset or body(bd.b) in cset} - cset)
    keep = list(chain) + held
    kset = set(keep)
    sub = Scene(name="chain_alone", bodies=[scene.bodies[i] for i in keep],
                bonds=[bd for bd in scene.bonds if body(bd.a) in kset and body(bd.b) in kset])
    nc = len(chain)
    prob = S._Problem(sub, P0[keep], Q0[keep], free=np.arange(nc))
    rot = [Slerp([0.0, 1.0], Rotation.from_matrix([quat_to_matrix(Q0[h]), quat_to_matrix(Q1[h])])) for h in held]
    none = np.zeros(0)
    its = 0
    for t in np.linspace(0.0, 1.0, steps + 1)[1:]:
        prob.pos[nc:] = (1.0 - t) * P0[held] + t * P1[held]
        prob.R[nc:] = np.array([r(t).as_matrix() for r in rot])
        its += S._minimise(prob, none)
    its += S._minimise(prob, none, reg=S.REG_POLISH)
    res = float(np.abs(prob.residuals(none)).max(initial=0.0))
    quat = np.array([matrix_to_quat(R) for R in prob.R[:nc]])
    return prob.pos[:nc].copy(), quat, res, [names[h] for h in held], its


def main(argv=None) -> int:
    import numpy as np
    from gitstate import commit
    from robot_overlaps import chain_pairs, part

    from mlc.io.atomic import atomic_path
    from mlc.robot.verify import verify_robot_static
    from mlc.scene.io import load_scene

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scene")
    ap.add_argument("--rows", nargs="*")
    ap.add_argument("--steps", type=int, default=20)
    ap.add_argument("-o", "--out", default="benchmarks/results/robot_chain_alone.json")
    a = ap.parse_args(argv)
    sc = load_scene(a.scene)
    rows = a.rows or sorted(sc.truth_table)
    P0 = np.array([b.position for b in sc.bodies], float)
    Q0 = np.array([b.orientation for b in sc.bodies], float)
    chains: dict = {}
    for i, b in enumerate(sc.bodies):
        k, ch, _ = part(b.name)
        if k == "chain":
            chains.setdefault(ch, []).append(i)
    out = {"what": "each coupling chain solved alone with its ends held, against the whole robot's static solve "
                   "(benchmarks/robot_chain_alone.py)", "commit": commit(), "scene": a.scene,
           "bodies": len(sc.bodies), "steps": a.steps, "units": "sigma, seconds wall", "rows": {}}
    for row in rows:
        t = time.perf_counter()
        rep = verify_robot_static(sc, rows=[row], keep_poses=True, clearance=False)
        P1, Q1 = (np.asarray(x, float) for x in rep.poses[row])
        r = {"shape_read": rep.rows[0]["shape_read"], "whole_s": round(time.perf_counter() - t, 1), "chains": {}}
        Pa, Qa = P1.copy(), Q1.copy()
        for ch, idx in sorted(chains.items()):
            t = time.perf_counter()
            p, q, res, held, its = solve_alone(sc, idx, P0, Q0, P1, Q1, a.steps)
            d = np.linalg.norm(p - P1[idx], axis=1)
            Pa[idx], Qa[idx] = p, q
            r["chains"][ch] = {"bodies": len(idx), "held": held, "residual_max": float(f"{res:.3g}"),
                               "iterations": its, "from_whole_max": round(float(d.max()), 4),
                               "from_whole_mean": round(float(d.mean()), 4), "seconds": round(time.perf_counter() - t, 2)}
        whole, alone = chain_pairs(sc, P1, Q1), chain_pairs(sc, Pa, Qa)
        r["chain_pairs"] = {k: {"whole": whole.get(k, [None])[0], "alone": alone.get(k, [None])[0]}
                            for k in sorted(set(whole) | set(alone))}
        out["rows"][row] = r
        print(f"row {row} ({r['shape_read']}, whole solve {r['whole_s']} s): "
              + "; ".join(f"{ch} {c['from_whole_max']:.3f}/{c['from_whole_mean']:.3f} (res {c['residual_max']:.1e})"
                          for ch, c in r["chains"].items())
              + " | clearance whole/alone: " + ", ".join(f"{k} {v['whole']}/{v['alone']}"
                                                        for k, v in r["chain_pairs"].items()), flush=True)
        with atomic_path(a.out) as tmp, open(tmp, "w") as f:
            json.dump(out, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
