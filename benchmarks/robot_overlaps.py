"""Which slabs of a robot interpenetrate in its rows' static poses (docs/robot.md section 6).

For every row: the static equilibrium (:func:`mlc.robot.verify.verify_robot_static`, the
same solve as ``mlc verify ROBOT.yaml``), then the oriented-box slab test
(:func:`mlc.verify.overlap.clearance`) of that pose, and every interpenetrating pair of
bodies sorted into a class by the bodies' names:

* ``chain_self_adjacent``: two slabs of one coupling chain in neighbouring half units
  (a junction bent past its largest bend: the chain has no junction stops,
  ``mlc.robot.build.CHAIN_STOPS``);
* ``chain_self_far``: two slabs of one chain further apart along it (the chain folds
  onto itself);
* ``chain_chain``: slabs of two different coupling chains;
* ``chain_skeleton``: a coupling-chain slab against a skeleton body (``skel_*``);
* ``chain_circuit``: a coupling-chain slab against a circuit body;
* ``skeleton``: two skeleton bodies; ``circuit``: two circuit bodies.

For a chain slab it records the half unit's index and the chain's length in half units
(0 and n - 1 are its ends: the circuit's output pair and the lever sites).  For every two
coupling chains within 4 sigma: their smallest slab clearance, as built and in each row
(``chain_pairs``; chains do not act on each other, so a pair that keeps apart as built may
meet as the skeleton folds).

``--outside`` confirms each pose's list without mlc.verify.overlap: manifold3d's boolean
intersection of every two nearby boxes of different bodies (benchmarks/outside_overlap.py,
hinge contact within 0.06 sigma of a shared joint left out), recording its pairs, their
intersection volumes, and which pairs only one of the two tests lists.

    python benchmarks/robot_overlaps.py OUT/robot.yaml [--rows 01 10 11] [--outside]
        [-o benchmarks/results/robot_overlaps.json]

Units: sigma (depths), degrees, seconds wall.
"""
from __future__ import annotations

import argparse
import collections
import json
import re
import sys
import time
from pathlib import Path

from mlc.io.atomic import atomic_path

_RC = re.compile(r"^rc_(u\d+_(?:up|dn))_(pg|w\d+|\d+)_([A-D]{2})$")


def part(name: str) -> tuple[str, str | None, int | None]:
    """(kind, chain, half-unit index) of a body name: kind 'chain', 'skeleton' or 'circuit'."""
    m = _RC.match(name)
    if m:
        g = m.group(2)       # page: -1; wrist half units (mlc.robot.build.WRIST): 1000 + i, after the chain
        return "chain", m.group(1), (-1 if g == "pg" else 1000 + int(g[1:]) if g[0] == "w" else int(g))
    if name.startswith("skel_"):
        return "skeleton", None, None
    return "circuit", None, None


def classify(a: str, b: str) -> str:
    ka, ca, ia = part(a)
    kb, cb, ib = part(b)
    kinds = {ka, kb}
    if kinds == {"chain"}:
        if ca != cb:
            return "chain_chain"
        if ia >= 0 and ib >= 0 and abs(ia - ib) <= 1:
            return "chain_self_adjacent"
        return "chain_self_far"
    if kinds == {"chain", "skeleton"}:
        return "chain_skeleton"
    if kinds == {"chain", "circuit"}:
        return "chain_circuit"
    if kinds == {"skeleton"}:
        return "skeleton"
    if kinds == {"skeleton", "circuit"}:
        return "skeleton_circuit"
    return "circuit"


def outside(scene, pos, quat, box_pairs) -> dict:
    """The boolean check of one pose (benchmarks/outside_overlap.py) against the box test's
    pairs ``box_pairs`` ({(a, b): depth})."""
    import numpy as np
    from outside_overlap import boolean_contacts

    if pos is None:
        pos = np.array([b.position for b in scene.bodies], float)
        quat = np.array([b.orientation for b in scene.bodies], float)
    t = time.perf_counter()
    bad = boolean_contacts(scene, pos, quat)
    vol: dict = {}
    for a, b, v, _ in bad:
        key = tuple(sorted((a, b)))
        vol[key] = vol.get(key, 0.0) + v
    boxed = {tuple(sorted(k)): d for k, d in box_pairs.items()}
    return {"n_pairs": len(vol), "volume_max": round(max(vol.values(), default=0.0), 6),
            "pairs": [{"a": a, "b": b, "volume": round(v, 6), "box_depth": boxed.get((a, b))}
                      for (a, b), v in sorted(vol.items(), key=lambda kv: -kv[1])],
            "only_boolean": [list(k) for k in sorted(set(vol) - set(boxed))],
            "only_box": [list(k) for k in sorted(set(boxed) - set(vol))],
            "wall_s": round(time.perf_counter() - t, 1)}


def chain_pairs(scene, pos, quat, reach: float = 4.0) -> dict:
    """The smallest slab clearance (sigma; negative: interpenetration) of every two coupling
    chains whose slabs come within ``reach`` (box centres), with the two bodies:
    ``{"u4_up/u4_dn": [clearance, body, body]}`` (the oriented-box distance of
    mlc.verify.overlap, no contact left out: two chains share no joint)."""
    import numpy as np
    from scipy.spatial import cKDTree

    from mlc.verify.overlap import _world_boxes, box_clearance

    if pos is None:
        pos = np.array([b.position for b in scene.bodies], float)
        quat = np.array([b.orientation for b in scene.bodies], float)
    C, A, H, B = _world_boxes(scene, np.asarray(pos, float), np.asarray(quat, float))
    names = [b.name for b in scene.bodies]
    ch = np.array([part(names[int(b)])[1] or "" for b in B])
    idx = np.nonzero(ch != "")[0]
    pr = cKDTree(C[idx]).query_pairs(reach, output_type="ndarray")
    I, J = idx[pr[:, 0]], idx[pr[:, 1]]
    keep = ch[I] != ch[J]
    I, J = I[keep], J[keep]
    out: dict = {}
    for i, j, c in zip(I, J, box_clearance(C[I], A[I], H[I], C[J], A[J], H[J])):
        a, b = sorted((ch[i], ch[j]))
        key = f"{a}/{b}"
        if key not in out or c < out[key][0]:
            na, nb = names[int(B[i])], names[int(B[j])]
            out[key] = [round(float(c), 4), *((na, nb) if ch[i] == a else (nb, na))]
    return dict(sorted(out.items()))


def analyse(scene, pos, quat, check_outside: bool = False) -> dict:
    from mlc.verify.overlap import clearance

    c = clearance(scene, pos, quat)
    chains = collections.Counter(part(b.name)[1] for b in scene.bodies if part(b.name)[0] == "chain")
    n_half = {ch: n // 4 for ch, n in chains.items()}           # 4 slabs (AB BC CD DA) per half unit
    pairs = []
    for a, b, d in c.overlaps:
        cls = classify(a, b)
        where = []
        for nm in (a, b):
            k, ch, i = part(nm)
            if k == "chain":
                where.append(f"{ch} page" if i < 0 else f"{ch} wrist half unit {i - 1000}" if i >= 1000
                             else f"{ch} half unit {i} of {n_half[ch]}")
            else:
                where.append(nm)
        pairs.append({"a": a, "b": b, "depth": round(d, 4), "class": cls, "where": where})
    by = collections.defaultdict(list)
    for p in pairs:
        by[p["class"]].append(p["depth"])
    out = {"min_clearance": round(c.min_clearance, 4), "pair": list(c.pair), "n_overlaps": len(pairs),
           "by_class": {k: {"n": len(v), "deepest": max(v)} for k, v in sorted(by.items())},
           "overlaps": pairs, "chain_pairs": chain_pairs(scene, pos, quat)}
    if check_outside:
        out["outside"] = outside(scene, pos, quat, {(p["a"], p["b"]): p["depth"] for p in pairs})
    return out


def main(argv=None) -> int:
    from mlc.robot.verify import verify_robot_static
    from mlc.scene.io import load_scene

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scene")
    ap.add_argument("--rows", nargs="*")
    ap.add_argument("--outside", action="store_true",
                    help="confirm each pose by manifold3d's boolean intersections (benchmarks/outside_overlap.py)")
    ap.add_argument("-o", "--out", default="benchmarks/results/robot_overlaps.json")
    a = ap.parse_args(argv)
    sys.path.insert(0, str(Path(__file__).resolve().parent))      # gitstate, outside_overlap
    sc = load_scene(a.scene)
    rows = a.rows or sorted(sc.truth_table)
    from gitstate import commit
    out = {"what": "slab overlaps of a robot's static poses, by class (benchmarks/robot_overlaps.py)",
           "commit": commit(), "scene": a.scene, "bodies": len(sc.bodies),
           "joint_k": float((sc.meta.get("circuit", {}).get("connector", {}) or {}).get("joint_k", 1.0)),
           "build_overrides": sc.meta.get("robot", {}).get("build_overrides", {}),
           "units": "sigma (depth), degrees, seconds wall", "as_built": analyse(sc, None, None, a.outside), "rows": {}}
    for row in rows:
        t = time.perf_counter()
        rep = verify_robot_static(sc, rows=[row], keep_poses=True, clearance=False)
        pos, quat = rep.poses[row]
        r = analyse(sc, pos, quat, a.outside)
        r.update({"shape_read": rep.rows[0]["shape_read"], "shape_ok": rep.rows[0]["shape_ok"],
                  "joint_stretch": rep.rows[0]["joint_stretch"], "row_ok": rep.rows[0]["ok"],
                  "max_dof_error_deg": round(rep.rows[0]["max_dof_error_deg"], 3),
                  "turns_read": rep.rows[0]["turns_read"], "wall_s": round(time.perf_counter() - t, 1)})
        out["rows"][row] = r
        print(f"row {row}: {r['shape_read']} (verdict {'ok' if r['row_ok'] else 'WRONG'}, DOF error "
              f"{r['max_dof_error_deg']:.1f} deg, stretch {r['joint_stretch']:.1e}), clearance {r['min_clearance']} {r['pair']}, {r['n_overlaps']} pairs: "
              + ", ".join(f"{k} {v['n']} (deepest {v['deepest']:.3f})" for k, v in r["by_class"].items())
              + (f"; boolean: {r['outside']['n_pairs']} pairs (largest {r['outside']['volume_max']:.2e} sigma^3), "
                 f"{len(r['outside']['only_boolean'])} not in the box test's list, "
                 f"{len(r['outside']['only_box'])} not in the boolean's" if a.outside else ""), flush=True)
        with atomic_path(a.out) as tmp, open(tmp, "w") as f:
            json.dump(out, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
