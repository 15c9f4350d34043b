"""Why the Tetris robot's printability report fails: part_count, min_gap and states, by cause.

    python benchmarks/mesh_robot_diagnosis.py --scene OUT/robot.yaml [--poses poses.pkl] [--mesh]
    python benchmarks/mesh_robot_diagnosis.py --scene OUT/robot.yaml --poses poses.pkl --stages skeleton \
        --out benchmarks/results/mesh_robot_skeleton.json

``OUT/robot.yaml`` is ``mlc compile examples/tetris.tt --robot examples/tetris.robot.yaml -o OUT``.
The largest mechanism (circuit + couplings + skeleton) is posed as ``mlc stl`` poses it
(``mlc.mesh.pipeline.state_poses``: 4 logic states and 18 poses on the way; about 6 min;
``--poses`` reuses a pickle this script wrote before).  Then, without the mesher's report:

* ``twist``: for every universal joint of the coupling chains (``rc_*``), the angle between its two
  printed pins (u on the first body, v on the second: ``mlc.mesh.build.UJoint.axes``) in every
  pose, less 90 degrees.  A printed cardan keeps it at 0; the scene's universal joint is one
  zero-length bond (a ball joint), which does not;
* ``rest_bend``: every chain junction's bend at rest from its junction-stop bond (the stop's sites
  are ``2 m cos(beta / 2)`` apart, ``mlc.gates.connector.junction_stops``), coupling chains against
  the circuit's chains;
* ``cross_chain``: the smallest slab-to-slab clearance (``mlc.verify.overlap.box_clearance``, scene
  slabs, sigma) between bodies of different chains, one of them a coupling body, in every pose.

``--mesh``: the mesher's own build and checks (``build_assembly``, ``check_assembly`` without the
wall check) on the couplings and the skeleton with one ring of neighbours (825 bodies, about
8 min), every failure of part_count, min_gap and states kept, and the states failures that
involve a coupling joint part set against that joint's twist.  ``--stages skeleton``: the skeleton's 9
bodies alone, built and checked the same way, with the place of every piece of a body that prints in
several (its box in the body's own frame, sigma).  Angles in degrees, lengths in
sigma unless named ``_mm``.  Writes benchmarks/results/mesh_robot_diagnosis.json (atomic).
"""
from __future__ import annotations

import argparse
import collections
import json
import pickle
import re
import sys
import time
from pathlib import Path

import mlc  # noqa: F401 -- before numpy: pins OpenBLAS's kernels (mlc/__init__.py)

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))


def chain_of(n: str) -> str:
    m = re.match(r"(rc_u\d_(up|dn))_", n)
    if m:
        return m.group(1)
    if n.startswith("skel"):
        return "skel"
    if n.startswith("w_"):
        return "_".join(n.split("_")[:3])
    return n.split("_")[0]


def sub_scene(big, sel):
    from mlc.mesh.pipeline import sub_scene as take
    idx = [i for i, b in enumerate(big.bodies) if b.name in sel]
    return take(big, idx, f"{big.name}_sub"), idx


def twist_of(big, names, poses, prof, res) -> dict:
    """Angle (degrees) between the two printed pins of every coupling joint, less 90, per pose."""
    import numpy as np

    from mlc.mesh.build import build_assembly
    t = time.perf_counter()
    sel = {n for n in names if n.startswith("rc_")}
    sub, idx = sub_scene(big, sel)
    sp = {k: (np.asarray(p)[idx], np.asarray(q)[idx]) for k, (p, q) in poses.items()}
    asm = build_assembly(sub, prof, sp, resolve=False)
    twist = {}
    for u in asm.ujoints:
        row = {}
        for st, (pos, quat) in sp.items():
            T = asm.part_transforms(pos, quat)
            x = T[u.bodies[0]][:3, :3] @ u.axes[0]
            y = T[u.bodies[1]][:3, :3] @ u.axes[1]
            row[st] = round(float(np.degrees(np.arcsin(np.clip(abs(x @ y), 0, 1)))), 3)
        twist[u.name] = row
    m = np.array([max(r.values()) for r in twist.values()])
    res["twist"] = {"joints": len(m), "max_deg": round(float(m.max()), 2), "median_of_max_deg": round(float(np.median(m)), 2),
                    "over_1": int((m > 1).sum()), "over_5": int((m > 5).sum()), "over_10": int((m > 10).sum()),
                    "seconds": round(time.perf_counter() - t, 1), "per_joint": twist}
    return twist


def main(argv=None) -> int:
    import numpy as np

    from mlc.io.atomic import atomic_path
    from mlc.mesh.build import build_assembly
    from mlc.mesh.pipeline import split_mechanisms, state_poses
    from mlc.mesh.profiles import load_profile
    from mlc.scene.io import load_scene
    from mlc.verify import overlap as ov

    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--scene", required=True)
    ap.add_argument("--poses", help="pickle of the poses (read if it exists, else written)")
    ap.add_argument("--mesh", action="store_true")
    ap.add_argument("--stages", default="bends,cross,twist", help="comma list of bends, cross, twist, skeleton")
    ap.add_argument("--out", default=str(ROOT / "benchmarks" / "results" / "mesh_robot_diagnosis.json"))
    a = ap.parse_args(argv)
    res: dict = {"benchmark": "mesh_robot_diagnosis", "scene": a.scene, "profile": "mjp"}
    scene = load_scene(a.scene)
    big = split_mechanisms(scene)[0].scene
    names = [b.name for b in big.bodies]
    res["bodies"] = len(scene.bodies)
    res["largest_mechanism_bodies"] = len(names)
    t = time.perf_counter()
    if a.poses and Path(a.poses).exists():
        P = pickle.load(open(a.poses, "rb"))
        assert P["names"] == names, "the poses are of another build"
        poses = P["poses"]
        res["poses_from"] = a.poses
    else:
        poses, _ = state_poses(big)
        res["poses_s"] = round(time.perf_counter() - t, 1)
        if a.poses:
            pickle.dump({"names": names, "poses": poses}, open(a.poses, "wb"))
    prof = load_profile("mjp")

    stages = set(a.stages.split(","))
    if "skeleton" in stages:
        from mlc.geometry.rotation import quat_to_matrix
        from mlc.mesh.checks import check_assembly
        sel = {n for n in names if n.startswith("skel_")}
        sub, idx = sub_scene(big, sel)
        sp = {k: (np.asarray(p)[idx], np.asarray(q)[idx]) for k, (p, q) in poses.items()}
        asm = build_assembly(sub, prof, sp)
        rep = check_assembly(asm, walls=False)
        out = {c.name: {"ok": c.ok, "detail": c.detail, "failures": c.failures} for c in rep.checks
               if c.name in ("part_count", "min_gap", "states", "retention", "features", "watertight")}
        pieces = {}
        by = {b.name: b for b in big.bodies}
        for p in asm.parts:
            got = p.solid.decompose()
            if len(got) > 1:
                b = by[p.name]
                R, o = quat_to_matrix(b.orientation), np.asarray(b.position, float) * prof.sigma_mm
                rows = []
                for q in got:
                    bb = np.asarray(q.bounding_box(), float).reshape(2, 3)
                    lo, hi = R.T @ (bb[0] - o) / prof.sigma_mm, R.T @ (bb[1] - o) / prof.sigma_mm
                    rows.append({"volume_mm3": round(float(q.volume()), 3),
                                 "box_sigma": [np.round(np.minimum(lo, hi), 3).tolist(), np.round(np.maximum(lo, hi), 3).tolist()]})
                pieces[p.name] = rows
        out["pieces"] = pieces
        out["notes_capped"] = [n for n in rep.notes if "capped" in n]
        res["skeleton_alone"] = out
    # -- rest bends from the junction stops ------------------------------------------------
    bends = collections.defaultdict(list)
    for b in big.bonds:
        if b.kind == "bond" and b.tolerance > 0 and b.a.endswith(".stop_out") and b.b.endswith(".stop_in"):
            d = float(np.linalg.norm(big.site_world(b.a) - big.site_world(b.b)))
            two_m = b.rest + b.tolerance - 0.5      # the free end d_free = 2 m + 0.5 (junction_stops)
            beta = 2 * np.degrees(np.arccos(min(1.0, d / two_m)))
            bends["coupling" if b.a.startswith("rc_") else "circuit"].append(
                (round(float(beta), 3), b.a.split(".")[0].rsplit("_", 1)[0], b.b.split(".")[0].rsplit("_", 1)[0]))
    res["rest_bend"] = {} if "bends" not in stages else {k: {"junctions": len(v), "max_deg": max(x[0] for x in v),
                            "over_22.5": sum(x[0] > 22.5 for x in v), "over_25": sum(x[0] > 25 for x in v),
                            "over_27": sum(x[0] > 27 for x in v)} for k, v in bends.items()}
    if "bends" in stages:
        res["rest_bend"]["coupling_junctions_over_25"] = sorted(
        [x for x in bends["coupling"] if x[0] > 25], reverse=True)

    # -- cross-chain slab clearance ----------------------------------------------------------
    from scipy.spatial import cKDTree
    cross = {}
    allp = [("rest", (np.array([b.position for b in big.bodies]), np.array([b.orientation for b in big.bodies])))]
    for st, (pos, quat) in (allp + list(poses.items())) if "cross" in stages else []:
        C, A, H, B = ov._world_boxes(big, pos, quat)
        rad = np.linalg.norm(H, axis=1)
        pr = cKDTree(C).query_pairs(2 * rad.max() + 0.5, output_type="ndarray")
        i, j = pr[:, 0], pr[:, 1]
        ch = np.array([chain_of(names[x]) for x in B])
        rc = np.array([names[x].startswith(("rc_", "skel")) for x in B])
        keep = (ch[i] != ch[j]) & (rc[i] | rc[j]) & (np.linalg.norm(C[i] - C[j], axis=1) - rad[i] - rad[j] < 0.5)
        i, j = i[keep], j[keep]
        d = ov.box_clearance(C[i], A[i], H[i], C[j], A[j], H[j])
        best: dict = {}
        for k in np.argsort(d):
            key = (names[B[i[k]]], names[B[j[k]]])
            if d[k] < 0.25 and key not in best:
                best[key] = round(float(d[k]), 4)
        cross[st] = [[x, y, v] for (x, y), v in list(best.items())[:12]]
    if cross:
        res["cross_chain_under_0.25_sigma"] = cross

    # -- twist of the coupling chains' printed cardans ----------------------------------------
    twist = {}
    if "twist" in stages or a.mesh:
        twist = twist_of(big, names, poses, prof, res)
    if a.mesh:
        from mlc.mesh.checks import check_assembly
        t = time.perf_counter()
        core = {n for n in names if n.startswith(("rc_", "skel_"))}
        sel = set(core)
        for x in big.bonds:
            p, q = x.a.split(".")[0], x.b.split(".")[0]
            if p in core and q not in core:
                sel.add(q)
            if q in core and p not in core:
                sel.add(p)
        sub, idx = sub_scene(big, sel)
        sp = {k: (np.asarray(p)[idx], np.asarray(q)[idx]) for k, (p, q) in poses.items()}
        asm = build_assembly(sub, prof, sp)
        rep = check_assembly(asm, walls=False)
        out = {"bodies": len(sub.bodies), "parts": len(asm.parts), "seconds": round(time.perf_counter() - t, 1)}
        for c in rep.checks:
            if c.name in ("part_count", "min_gap", "states", "retention", "features", "watertight"):
                out[c.name] = {"ok": c.ok, "detail": c.detail, "failures": c.failures}
        fails = collections.defaultdict(set)
        pairs = collections.Counter()
        for f in out["states"]["failures"]:
            st, x, y = re.match(r"state (\S+): (\S+) intersects (\S+) ", f).groups()
            fails[x].add(st)
            fails[y].add(st)
            pairs["same chain" if chain_of(x) == chain_of(y) else "cross"] += 1
        hit, miss = [], []
        for j, row in twist.items():
            for st, v in row.items():
                (hit if st in fails.get(j, ()) else miss).append(v)
        hit, miss = np.array(hit), np.array(miss)
        out["states_by_kind"] = dict(pairs)
        out["states_with_coupling_joint_part"] = sum(
            bool(re.search(r"rc_u\d_(up|dn)_(w|pg_)?j", f)) for f in out["states"]["failures"])
        out["joint_poses"] = {thr: {"twist_over": [int((hit > thr).sum()), int((hit > thr).sum() + (miss > thr).sum())],
                                    "twist_at_most": [int((hit <= thr).sum()), int((hit <= thr).sum() + (miss <= thr).sum())]}
                              for thr in (2, 4, 6, 10)}
        out["joint_poses_note"] = ("[intersecting, all] (joint part, pose) pairs with the joint's twist over / at most "
                                   "the threshold (degrees)")
        out["largest_twist_without_intersection_deg"] = round(float(miss.max()), 3) if len(miss) else None
        out["notes_capped_or_locked"] = [n for n in rep.notes if "capped" in n or "one point" in n
                                         or "overlap inside" in n]
        res["mesh"] = out
    with atomic_path(a.out) as tmp:
        Path(tmp).write_text(json.dumps(res, indent=1) + "\n")
    print(json.dumps({k: v for k, v in res.items() if k in ("rest_bend", "twist")}, default=str)[:3000])
    return 0


if __name__ == "__main__":
    sys.exit(main())
