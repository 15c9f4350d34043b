"""Every library gate, both muscle conventions, every printer profile: build + report, and the
states check's clearance confirmed by a second distance code.

    python benchmarks/mesh_gates.py [--gates NAND NOR] [--signals expand] [--profiles mjp]

Each case goes through ``export_assembly`` (what ``mlc stl`` runs): the poses of the logic
states and 6 points on each path from rest (the parts' trims and the blocking ``states``
check), the dense paths from rest and every switch between two states (``state_poses`` with
``max_move`` = the profile's clearance: the motion trims and the ``motion_clearance`` goal), the
parts, the report.
Writes benchmarks/results/mesh_gates.json: per (gate, signal, profile) whether the report
passes, the failed checks (blocking, and the goals that do not block yet), part count, the
number of dense poses, the smallest gap in motion and the pairs under the clearance, the
measured walls (``thinnest_wall_mm``, ``thin_walls``, ``wall_detail``: the ``wall_thickness`` goal),
the notes of the webs thinner than the minimum wall that the mesher carried and bridged
(``web_notes``: the split test, and since session 37 the measured one), the print-only feet
(``feet_mm3``: volume added a part) and the first layer's share of the footprint
(``bed_contact``, ``bed_detail``; since session 38), wall and
CPU seconds, and ``commit`` (benchmarks/gitstate.py: HEAD, ``-dirty`` when mlc/ differs from it).

**Outside check of the web at hinge c** (``section_web``, session 36): the hinge's owner
(core_cd) cut by planes normal to the axis in the middle of the other bodies' knuckles, each
piece of the section near the axis other than the pin measured by the largest disc that fits
in it (manifold3d's slice and Clipper2 polygon offsets, not the voxel grid of
``mlc.mesh.walls``): ``web_mm``, the thinnest.

``axis_webs`` (session 37): the same measurement at every hinge axis, for every body with
knuckles on both sides of another body's (where the mesher's measured web test looks).

**Outside check** (when ``python-fcl`` is installed, ``pip install python-fcl``; not an mlc
dependency): the Flexible Collision Library's mesh-mesh distance (its own BVH and
triangle-triangle distance, not manifold3d's ``min_gap``) between every two parts whose posed
bounding boxes come within twice the clearance, in every ``--fcl-every``-th dense pose and in
every pose where mlc's goal names a pair or where a motion trim was made (the pair was closer
than the clearance there before the trim) (``--fcl-profiles``: about 20 ms a query, so not every
profile); recorded as ``fcl_smallest_gap_mm``, ``fcl_pairs_below_clearance`` (poses x pairs)
and ``fcl_poses``, with ``motion_below_clearance_in_fcl_poses`` (mlc's count in the same poses).
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import numpy as np  # noqa: E402

from mlc.gates.library import GATE_NAMES, gate_scene  # noqa: E402
from mlc.io.atomic import atomic_path  # noqa: E402
from mlc.mesh.pipeline import export_assembly, state_poses  # noqa: E402
from mlc.mesh.profiles import load_profile  # noqa: E402
from gitstate import commit  # noqa: E402  (benchmarks/gitstate.py)

RESULTS = ROOT / "benchmarks" / "results"


def _inscribed(cs) -> float:
    """Diameter (mm) of the largest disc inside the polygon ``cs`` (a manifold3d CrossSection),
    by bisection on the inward offset (Clipper2) that empties it: 0.001 mm."""
    import manifold3d as mf
    lo, hi = 0.0, 0.5 * max(b - a for a, b in zip(cs.bounds()[:2], cs.bounds()[2:]))
    while hi - lo > 5e-4:
        r = 0.5 * (lo + hi)
        if cs.offset(-r, mf.JoinType.Round).is_empty():
            hi = r
        else:
            lo = r
    return 2 * lo


def section_webs(asm) -> dict:
    """Outside check of the web at the three-body hinge (hinge c), independent of the voxel
    measurement of ``mlc.mesh.walls``: core_cd (the hinge's owner) cut by planes normal to the
    hinge axis at the middle of each stretch of the axis where the other bodies' knuckles are
    (manifold3d ``slice``); every polygon of the section within the trim radius + 2 minimum walls
    of the axis, except the one around the axis (the pin), is a web; its thickness is the
    diameter of the largest disc that fits in it (:func:`_inscribed`, polygon offsets).
    ``{"web_mm": thinnest, "webs": count}``; ``web_mm`` None where no web is cut."""
    axes = [ax for ax in asm.axes if len(ax.bodies) == 3]
    out = {"web_mm": None, "webs": 0}
    for ax in axes:
        own = ax.owner
        solid = asm.part(own).solid
        d = np.asarray(ax.direction, float)
        e1 = np.cross(d, [1.0, 0, 0] if abs(d[0]) < 0.9 else [0, 1.0, 0])
        e1 /= np.linalg.norm(e1)
        R = np.vstack([e1, np.cross(d, e1), d])
        M = np.hstack([R, (-R @ np.asarray(ax.origin, float))[:, None]])
        local = solid.transform(M.tolist())
        ivs = sorted(iv for bn, v in ax.intervals.items() if bn != own for iv in v)
        for a0, a1 in ivs:
            cs = local.slice(0.5 * (a0 + a1))
            for piece in cs.decompose():
                (x0, y0), (x1, y1) = piece.bounds()[:2], piece.bounds()[2:]
                if x0 <= 0 <= x1 and y0 <= 0 <= y1:      # the pin through the axis
                    continue
                if min(np.hypot(x, y) for x in (x0, x1) for y in (y0, y1)) > ax.rho + 2 * asm.profile.min_wall:
                    continue
                w = _inscribed(piece)
                out["webs"] += 1
                out["web_mm"] = w if out["web_mm"] is None else min(out["web_mm"], w)
    if out["web_mm"] is not None:
        out["web_mm"] = round(out["web_mm"], 4)
    return out


def axis_webs(asm) -> dict:
    """The same outside measurement as :func:`section_webs` at every hinge axis and for every body
    with knuckles on both sides of another body's (session 37: where the mesher's web test looks):
    the body cut by a plane normal to the axis in the middle of each such stretch, every piece
    near the axis but the pin measured by the largest disc in it.  ``{"web_mm": thinnest or None,
    "at": "axis/body", "webs": count}``."""
    out = {"web_mm": None, "at": None, "webs": 0}
    for ax in asm.axes:
        d = np.asarray(ax.direction, float)
        e1 = np.cross(d, [1.0, 0, 0] if abs(d[0]) < 0.9 else [0, 1.0, 0])
        e1 /= np.linalg.norm(e1)
        R = np.vstack([e1, np.cross(d, e1), d])
        M = np.hstack([R, (-R @ np.asarray(ax.origin, float))[:, None]])
        for bn in ax.bodies:
            own = sorted(ax.intervals[bn])
            local = None
            for (_, a0), (a1, _) in zip(own, own[1:]):
                if a1 - a0 < 1e-9:
                    continue
                if local is None:
                    local = asm.part(bn).solid.transform(M.tolist())
                for piece in local.slice(0.5 * (a0 + a1)).decompose():
                    (x0, y0), (x1, y1) = piece.bounds()[:2], piece.bounds()[2:]
                    if x0 <= 0 <= x1 and y0 <= 0 <= y1:      # the pin through the axis
                        continue
                    if np.hypot(max(x0, 0, -x1), max(y0, 0, -y1)) > ax.rho + 2 * asm.profile.min_wall:
                        continue
                    w = _inscribed(piece)
                    out["webs"] += 1
                    if out["web_mm"] is None or w < out["web_mm"]:
                        out["web_mm"], out["at"] = w, f"{ax.name}/{bn}"
    if out["web_mm"] is not None:
        out["web_mm"] = round(out["web_mm"], 4)
    return out


def fcl_gaps(asm, poses: dict, clearance: float) -> tuple[float | None, int, int]:
    """(smallest gap, poses x pairs closer than the clearance, distance queries) over every pose of
    ``poses`` by FCL; (None, 0, 0) without python-fcl."""
    try:
        import fcl
    except ImportError:
        return None, 0, 0
    if not poses:
        return None, 0, 0
    models = []
    for p in asm.parts:
        m = p.solid.to_mesh64()
        V = np.asarray(m.vert_properties, float)[:, :3]
        F = np.asarray(m.tri_verts, np.int64)
        bv = fcl.BVHModel()
        bv.beginModel(len(V), len(F))
        bv.addSubModel(V, F)
        bv.endModel()
        models.append((bv, V))
    smallest, below, n = None, 0, 0
    for pos, quat in poses.values():
        T = asm.part_transforms(pos, quat)
        Ts = [T[p.name] for p in asm.parts]
        boxes = []
        for (bv, V), Tk in zip(models, Ts):
            W = V @ Tk[:3, :3].T + Tk[:3, 3]
            boxes.append((W.min(axis=0), W.max(axis=0)))
        objs = [fcl.CollisionObject(bv, fcl.Transform(Tk[:3, :3], Tk[:3, 3])) for (bv, _), Tk in zip(models, Ts)]
        for i in range(len(objs)):
            for j in range(i + 1, len(objs)):
                (l1, h1), (l2, h2) = boxes[i], boxes[j]
                if np.any(l1 > h2 + 2 * clearance) or np.any(l2 > h1 + 2 * clearance):
                    continue
                g = float(fcl.distance(objs[i], objs[j], fcl.DistanceRequest(), fcl.DistanceResult()))
                n += 1
                smallest = g if smallest is None else min(smallest, g)
                below += g < clearance - 1e-6
    return smallest, below, n


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--gates", nargs="+", default=list(GATE_NAMES))
    ap.add_argument("--signals", nargs="+", default=["expand", "contract"])
    ap.add_argument("--profiles", nargs="+", default=["mjp", "sla", "fdm"])
    ap.add_argument("--out", default=str(RESULTS / "mesh_gates.json"))
    ap.add_argument("--fcl-every", type=int, default=5)
    ap.add_argument("--fcl-profiles", nargs="+", default=["mjp"])
    args = ap.parse_args()
    rows = []
    for signal in args.signals:
        for name in args.gates:
            scene = gate_scene(name, signal)
            for prof in args.profiles:
                profile = load_profile(prof)
                t0, c0 = time.perf_counter(), time.process_time()
                asm, rep = export_assembly(scene, profile)
                wall, cpu = time.perf_counter() - t0, time.process_time() - c0
                mc = rep.check("motion_clearance")
                dense, _ = state_poses(scene, max_move=profile.clearance / profile.sigma_mm)   # as export_assembly
                # FCL also in every pose where a motion trim was made (short of the clearance before)
                named = {f.split(": ")[0] for f in mc.failures} | {k for t in asm.motion_trims for k in t["poses"]}
                sub = {k: v for n, (k, v) in enumerate(dense.items()) if n % args.fcl_every == 0 or k in named}
                if prof not in args.fcl_profiles:
                    sub = {}
                mlc_in_sub = sum(f.split(": ")[0] in sub for f in mc.failures)
                g, below, nq = fcl_gaps(asm, sub, profile.clearance)
                row = {"gate": name, "signal": signal, "profile": prof, "ok": rep.ok, "parts": len(asm.parts),
                       "failed": {c.name: c.failures[:3] for c in rep.checks if not c.ok and c.blocking},
                       "goals_not_met": sorted(c.name for c in rep.checks if not c.ok and not c.blocking),
                       "dense_poses": len(dense), "motion_smallest_gap_mm": mc.value, "clearance_mm": profile.clearance,
                       "motion_detail": mc.detail, "motion_below_clearance": len(mc.failures),
                       "motion_pairs": sorted({f.split(": ")[1] for f in mc.failures}),
                       "fcl_smallest_gap_mm": None if g is None else round(g, 6), "fcl_pairs_below_clearance": below,
                       "fcl_queries": nq, "fcl_poses": len(sub), "motion_below_clearance_in_fcl_poses": mlc_in_sub,
                       "trims": [n for n in asm.notes if n.startswith("trimmed")],
                       "motion_trims": [{k: v for k, v in t.items() if k != "poses"} | {"poses": len(t["poses"])}
                                        for t in asm.motion_trims],
                       "motion_trimmed_poses": len({k for t in asm.motion_trims for k in t["poses"]}),
                       "thinnest_wall_mm": rep.check("wall_thickness").value,
                       "min_wall_mm": profile.min_wall,
                       "thin_walls": rep.check("wall_thickness").failures,
                       "wall_detail": rep.check("wall_thickness").detail,
                       "web_notes": [n for n in asm.notes if "thinner than the minimum wall" in n],
                       "feet_mm3": dict(getattr(asm, "feet", {})),
                       "bed_contact": rep.check("bed_contact").value,
                       "bed_detail": rep.check("bed_contact").detail,
                       "section_web": section_webs(asm),
                       "axis_webs": axis_webs(asm),
                       "export_s": round(wall, 2), "export_cpu_s": round(cpu, 2), "commit": commit()}
                rows.append(row)
                print(json.dumps(row), flush=True)
    out = {"benchmark": "mesh_gates", "commit": commit(), "python": platform.python_version(), "cpus": os.cpu_count(),
           "load_average": [round(x, 2) for x in os.getloadavg()],
           "passed": sum(r["ok"] for r in rows), "total": len(rows), "rows": rows}
    path = Path(args.out)
    path.parent.mkdir(parents=True, exist_ok=True)
    with atomic_path(path) as tmp:
        Path(tmp).write_text(json.dumps(out, indent=2) + "\n")
    print(f"{out['passed']}/{out['total']} pass")
    return 0


if __name__ == "__main__":
    sys.exit(main())
