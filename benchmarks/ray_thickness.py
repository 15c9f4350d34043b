"""Wall thickness of every part of a 3MF written by ``mlc stl``, measured outside mlc by rays
(issue 13, session 60: a second, independent measure of the thin regions that
``mlc.mesh.walls`` finds on a voxel grid).

The 3MF is read with the standard library alone (``half_unit_gaps.read_parts``); each part's
surface is sampled by trimesh (``--density`` points per mm^2, seeded), and from each sample a
ray is cast inwards along the face's normal: the thickness there is the distance to the first
triangle it meets, counted only when that triangle faces the other way (its normal within
about 25 degrees of opposite: a wall's far side, not the side of a corner).  The ray test is a
plain Moller-Trumbore intersection written here in numpy, against every triangle of the part.

What it reports, per part and summed by kind (half units' ``AB``/``CD``, ``BC``/``DA``, joint
parts, the rest): the samples under ``--sliver`` (0.3 mm: the slivers the trims leave) and under
``--wall`` (0.58 mm: under mjp's 0.6 mm wall, past the facet tolerance), and the thinnest.
A ray through a round knuckle's wall reads its wall across the chord, so a 0.5 mm knuckle reads
0.5 mm and more.

    python benchmarks/ray_thickness.py OUT/circuit.3mf --label "README job" -o RESULTS.json

Units: mm.  Rerun for the same numbers (the samples' seeds are fixed)."""
from __future__ import annotations

import argparse
import json
import re
import sys
from pathlib import Path

import mlc  # noqa: F401 -- before numpy (mlc/__init__.py)

import numpy as np
import trimesh

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from gitstate import commit  # noqa: E402  (benchmarks/gitstate.py)
from half_unit_gaps import read_parts  # noqa: E402

from mlc.io.atomic import atomic_path  # noqa: E402

COS_OPPOSITE = -0.9


def ray_thickness(V, T, density: float, seed: int = 0):
    """Thickness (mm) at surface samples of the closed mesh (V, T): per sample, the distance
    along the inward normal to the first triangle hit, inf where that triangle does not face
    the sample's (a corner, not a wall)."""
    m = trimesh.Trimesh(V, T, process=False)
    pts, fi = trimesh.sample.sample_surface(m, max(int(m.area * density), 50), seed=seed)
    n = m.face_normals[fi]
    A = V[T[:, 0]]
    e1, e2 = V[T[:, 1]] - A, V[T[:, 2]] - A
    fn = m.face_normals
    out = np.full(len(pts), np.inf)
    origin, dirs = pts - 1e-5 * n, -n
    for s in range(0, len(pts), 256):
        D, O = dirs[s:s + 256, None, :], origin[s:s + 256, None, :]
        p = np.cross(D, e2[None])
        det = (p * e1[None]).sum(-1)
        ok = np.abs(det) > 1e-12
        inv = np.where(ok, 1.0 / np.where(ok, det, 1.0), 0.0)
        tv = O - A[None]
        u = (tv * p).sum(-1) * inv
        q = np.cross(tv, e1[None])
        v = (D * q).sum(-1) * inv
        t = (e2[None] * q).sum(-1) * inv
        t = np.where(ok & (u >= 0) & (v >= 0) & (u + v <= 1) & (t > 1e-6), t, np.inf)
        j = np.argmin(t, axis=1)
        tm = t[np.arange(len(j)), j]
        out[s:s + 256] = np.where((fn[j] * n[s:s + 256]).sum(-1) < COS_OPPOSITE, tm, np.inf)
    return out


def kind(name: str) -> str:
    if re.search(r"_(AB|CD)$", name):
        return "half unit AB/CD"
    if re.search(r"_(BC|DA)$", name):
        return "half unit BC/DA"
    if re.search(r"_j\d*_(hi|lo)$|_j_(hi|lo)$|ujoint", name):
        return "joint part"
    return "other"


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("mf3", help="3MF written by mlc stl")
    ap.add_argument("--label", default="")
    ap.add_argument("--density", type=float, default=20.0, help="samples per mm^2")
    ap.add_argument("--sliver", type=float, default=0.3, help="mm")
    ap.add_argument("--wall", type=float, default=0.58, help="mm")
    ap.add_argument("--min-samples", type=int, default=3, help="samples under a mark for a part to count")
    ap.add_argument("--match", default="", help="regular expression: only the parts it matches")
    ap.add_argument("-o", "--out", required=True)
    a = ap.parse_args()
    parts = read_parts(a.mf3)
    rows = []
    for name, (V, T) in sorted(parts.items()):
        if a.match and not re.search(a.match, name):
            continue
        d = ray_thickness(V, T, a.density)
        rows.append({"part": name, "kind": kind(name), "samples": len(d),
                     "under_sliver": int((d < a.sliver).sum()), "under_wall": int((d < a.wall).sum()),
                     "thinnest_mm": round(float(d.min()), 4)})
    summary = {}
    for r in rows:
        s = summary.setdefault(r["kind"], {"parts": 0, "with_sliver": 0, "under_wall": 0})
        s["parts"] += 1
        s["with_sliver"] += r["under_sliver"] >= a.min_samples
        s["under_wall"] += r["under_wall"] >= a.min_samples
    out = {"benchmark": "ray_thickness", "commit": commit(), "label": a.label, "file": str(a.mf3),
           "density_per_mm2": a.density, "sliver_mm": a.sliver, "wall_mm": a.wall, "min_samples": a.min_samples,
           "parts": len(rows), "parts_with_sliver": sum(r["under_sliver"] >= a.min_samples for r in rows),
           "parts_under_wall": sum(r["under_wall"] >= a.min_samples for r in rows), "by_kind": summary,
           "thinnest": sorted(rows, key=lambda r: r["thinnest_mm"])[:30]}
    print(json.dumps({k: v for k, v in out.items() if k != "thinnest"}))
    with atomic_path(a.out) as tmp:
        Path(tmp).write_text(json.dumps(out, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
