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
(0 and n - 1 are its ends: the circuit's output pair and the lever sites).  Optionally
(``--bend``) the bend of each junction involved, against the connector's largest bend.

    python benchmarks/robot_overlaps.py OUT/robot.yaml [--rows 01 10 11]
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


def analyse(scene, pos, quat) -> dict:
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
    return {"min_clearance": round(c.min_clearance, 4), "pair": list(c.pair), "n_overlaps": len(pairs),
            "by_class": {k: {"n": len(v), "deepest": max(v)} for k, v in sorted(by.items())},
            "overlaps": pairs}


def main(argv=None) -> int:
    from mlc.robot.verify import verify_robot_static
    from mlc.scene.io import load_scene

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scene")
    ap.add_argument("--rows", nargs="*")
    ap.add_argument("-o", "--out", default="benchmarks/results/robot_overlaps.json")
    a = ap.parse_args(argv)
    sc = load_scene(a.scene)
    rows = a.rows or sorted(sc.truth_table)
    out = {"what": "slab overlaps of a robot's static poses, by class (benchmarks/robot_overlaps.py)",
           "scene": a.scene, "bodies": len(sc.bodies),
           "joint_k": float((sc.meta.get("circuit", {}).get("connector", {}) or {}).get("joint_k", 1.0)),
           "build_overrides": sc.meta.get("robot", {}).get("build_overrides", {}),
           "units": "sigma (depth), degrees, seconds wall", "as_built": analyse(sc, None, None), "rows": {}}
    for row in rows:
        t = time.perf_counter()
        rep = verify_robot_static(sc, rows=[row], keep_poses=True, clearance=False)
        pos, quat = rep.poses[row]
        r = analyse(sc, pos, quat)
        r.update({"shape_read": rep.rows[0]["shape_read"], "shape_ok": rep.rows[0]["shape_ok"],
                  "joint_stretch": rep.rows[0]["joint_stretch"], "row_ok": rep.rows[0]["ok"],
                  "max_dof_error_deg": round(rep.rows[0]["max_dof_error_deg"], 3),
                  "turns_read": rep.rows[0]["turns_read"], "wall_s": round(time.perf_counter() - t, 1)})
        out["rows"][row] = r
        print(f"row {row}: {r['shape_read']} (verdict {'ok' if r['row_ok'] else 'WRONG'}, DOF error "
              f"{r['max_dof_error_deg']:.1f} deg, stretch {r['joint_stretch']:.1e}), clearance {r['min_clearance']} {r['pair']}, {r['n_overlaps']} pairs: "
              + ", ".join(f"{k} {v['n']} (deepest {v['deepest']:.3f})" for k, v in r["by_class"].items()), flush=True)
        with atomic_path(a.out) as tmp, open(tmp, "w") as f:
            json.dump(out, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
