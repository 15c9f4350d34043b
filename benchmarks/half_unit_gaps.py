"""The gap between each connector half unit's two slab pairs that share no hinge of their own
there, AB-DA and BC-CD, in a 3MF written by ``mlc stl``, measured outside mlc and manifold3d
(issue 13, session 59: with grown compound stacks, 60 such pairs of the README circuit came
0.10-0.16 mm apart as printed).

The 3MF is read with the standard library alone (zip, the core 3MF mesh XML, and PrusaSlicer's
``Metadata/Slic3r_PE_model.config`` for each named part's triangle range); each part's surface is
sampled by trimesh (``N`` points, seeded) and the nearest pairs found with a SciPy k-d tree.
A sampled gap is an upper bound of the true gap, so a pair under the clearance is under it
for sure.  The 3MF's coordinates carry six significant digits (0.001 mm at 100 mm): hinge
partners that sit at the clearance read a few tenths of a micrometre either side of it.

    python benchmarks/half_unit_gaps.py OUT/circuit.3mf --label "README job" -o RESULTS.json

``--joint-parts`` measures instead every junction's joint part against each part whose bounding
box comes within 1 mm of its own (session 60: a half unit's fin now reaches to the ball's
clearance, ``FIN_KEPT``); ``--parts REGEX`` the same for the parts whose names match REGEX
(session 61: the bodies of the compound stacks that grew with ``FINE_GAPS``).

Units: mm.  Rerun for the same numbers (the samples' seeds are fixed)."""
from __future__ import annotations

import argparse
import json
import re
import sys
import zipfile
import xml.etree.ElementTree as ET
from pathlib import Path

import mlc  # noqa: F401 -- before numpy (mlc/__init__.py)

import numpy as np
import trimesh
from scipy.spatial import cKDTree

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from gitstate import commit  # noqa: E402  (benchmarks/gitstate.py)

from mlc.io.atomic import atomic_path  # noqa: E402

CORE = "{http://schemas.microsoft.com/3dmanufacturing/core/2015/02}"
UNIT = re.compile(r"^(.*_\d+)_(AB|BC|CD|DA)$")


def read_parts(path) -> dict:
    """``{part name: (vertices (n, 3), triangles (m, 3))}`` of a 3MF with named volumes."""
    z = zipfile.ZipFile(path)
    V, T = [], []
    for _, el in ET.iterparse(z.open("3D/3dmodel.model")):
        if el.tag == CORE + "vertex":
            V.append((float(el.get("x")), float(el.get("y")), float(el.get("z"))))
            el.clear()
        elif el.tag == CORE + "triangle":
            T.append((int(el.get("v1")), int(el.get("v2")), int(el.get("v3"))))
            el.clear()
    V, T = np.array(V), np.array(T)
    out = {}
    for vol in ET.fromstring(z.read("Metadata/Slic3r_PE_model.config")).iter("volume"):
        name = next(m.get("value") for m in vol.iter("metadata") if m.get("key") == "name")
        u, inv = np.unique(T[int(vol.get("firstid")):int(vol.get("lastid")) + 1], return_inverse=True)
        out[name] = (V[u], inv.reshape(-1, 3))
    return out


JOINT = re.compile(r"_j\d*_(hi|lo)$|_j_(hi|lo)$")


def joint_part_gaps(parts: dict, n: int, which=JOINT) -> list:
    """Each part whose name ``which`` matches (by default each compound or branch junction's joint
    part, named ``..._j<k>_lo/hi``) against every other part whose bounding box comes within 1 mm
    of its own: the sampled gap of each pair (session 60: the fin kept past the joint part's
    ball, ``FIN_KEPT``).  A pair of two matching parts is measured once."""
    box = {k: (V.min(0), V.max(0)) for k, (V, _) in parts.items()}
    names = list(parts)
    lo = np.array([box[k][0] for k in names])
    hi = np.array([box[k][1] for k in names])

    cache: dict = {}

    def pts(k, seed):
        # each part's samples once (the same points: the seed is fixed)
        if (k, seed) not in cache:
            cache[(k, seed)] = trimesh.sample.sample_surface(trimesh.Trimesh(*parts[k], process=False), n,
                                                             seed=seed)[0]
        return cache[(k, seed)]
    rows = []
    for i, j in enumerate(names):
        if not which.search(j):
            continue
        near = np.all((lo <= hi[i] + 1.0) & (hi >= lo[i] - 1.0), axis=1)
        tree = cKDTree(pts(j, 1))
        for k in np.nonzero(near)[0]:
            if names[k] == j or (k < i and which.search(names[k])):
                continue
            rows.append({"a": j, "b": names[k], "gap_mm": round(float(tree.query(pts(names[k], 2))[0].min()), 5)})
    return rows


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("mf3", help="3MF written by mlc stl")
    ap.add_argument("--label", default="")
    ap.add_argument("-n", type=int, default=60000, help="surface samples per part")
    ap.add_argument("--clearance", type=float, default=0.2, help="mm (mjp: 0.2)")
    ap.add_argument("-o", "--out", required=True)
    ap.add_argument("--joint-parts", action="store_true",
                    help="instead: every joint part against every body whose box comes within 1 mm of its own")
    ap.add_argument("--parts", metavar="REGEX",
                    help="instead: every part whose name matches REGEX against every body whose box comes within 1 mm of its own")
    a = ap.parse_args()
    parts = read_parts(a.mf3)
    units = sorted({m.group(1) for n in parts if (m := UNIT.match(n))})
    rows = []
    if a.joint_parts or a.parts:
        rows = joint_part_gaps(parts, a.n, re.compile(a.parts) if a.parts else JOINT)
        units = []
    for u in units:
        for x, y in (("AB", "DA"), ("BC", "CD")):
            if f"{u}_{x}" not in parts or f"{u}_{y}" not in parts:
                continue
            pa, pb = (trimesh.sample.sample_surface(trimesh.Trimesh(*parts[f"{u}_{s}"], process=False), a.n,
                                                    seed=k)[0] for k, s in ((1, x), (2, y)))
            rows.append({"a": f"{u}_{x}", "b": f"{u}_{y}", "gap_mm": round(float(cKDTree(pb).query(pa)[0].min()), 5)})
    g = np.array([r["gap_mm"] for r in rows])
    kind = f" (parts {a.parts})" if a.parts else " (joint parts)" if a.joint_parts else ""
    out = {"benchmark": "half_unit_gaps" + kind, "commit": commit(), "label": a.label, "file": str(a.mf3),
           "samples_per_part": a.n, "clearance_mm": a.clearance, "pairs": len(rows),
           "min_mm": float(g.min()), "under_clearance_by_0.01_mm_or_more": int((g < a.clearance - 0.01).sum()),
           "smallest": sorted(rows, key=lambda r: r["gap_mm"])[:20]}
    print(json.dumps({k: v for k, v in out.items() if k != "smallest"}))
    with atomic_path(a.out) as tmp:
        Path(tmp).write_text(json.dumps(out, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
