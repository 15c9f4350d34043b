"""The knuckle lengths of compound junctions' stacks measured on the finished meshes, outside
mlc's own layout (issue 13, session 57: stacks grown to knuckles of the minimum wall).

Builds a piece of the README circuit (``--piece``, default ``tests/data_mesh/circuit_junction``:
five half units of chain ``w_b_0`` and their four junctions; ``circuit_leaf``: a branch tree's
leaf pages; ``circuit_chain_y``: five half units of chain ``w_y_0``; each with the circuit's 22
print poses) at mjp with ``GROW_STACKS`` on and off, and on with ``STACK_CYLINDERS`` off (session
58: grown only where no other stack's axis comes within both radii and the clearance, session
57's test); ``GROWN_CLEAR`` (session 59) on in both grown builds.  For each compound stack it
measures, on each joint part's finished
mesh (trimesh, its vertices), the length along the stack's axis of the joint's knuckle: the
axial extent of the vertices on the knuckle's outer cylinder (radius R within 1 %, away from
the collar, which is thinner).  mlc gives only the axis line and R; the length is the mesh's.

    python benchmarks/knuckle_lengths.py -o benchmarks/results/knuckle_lengths_s57.json
    python benchmarks/knuckle_lengths.py --piece circuit_junction --piece circuit_leaf \
        -o benchmarks/results/knuckle_lengths_s58.json
    python benchmarks/knuckle_lengths.py --piece circuit_junction --piece circuit_leaf \
        --piece circuit_chain_y -o benchmarks/results/knuckle_lengths_s59.json

Units: mm."""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import mlc  # noqa: F401 -- before numpy (mlc/__init__.py)

import numpy as np
import trimesh

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent / "tests"))
from gitstate import commit  # noqa: E402  (benchmarks/gitstate.py)

from mlc.io.atomic import atomic_path  # noqa: E402
from mlc.mesh import build as B  # noqa: E402
from mlc.mesh.profiles import load_profile  # noqa: E402
from helpers import load_piece  # noqa: E402  (tests/helpers.py)


#: the builds compared: mlc.mesh.build's flags for each
VARIANTS = {"grown": {"GROW_STACKS": True, "STACK_CYLINDERS": True, "GROWN_CLEAR": True},
            "grown_axes_only": {"GROW_STACKS": True, "STACK_CYLINDERS": False, "GROWN_CLEAR": True},
            "short": {"GROW_STACKS": False}}


def measure(piece: str, flags: dict) -> list[dict]:
    sc, poses = load_piece(piece)
    with B.flags(**flags):
        asm = B.build_assembly(sc, load_profile("mjp"), poses, reuse=True)
    rows = []
    for ax in asm.axes:
        if ax.joint is None:
            continue
        m = asm.part(ax.joint).solid.to_mesh()
        tm = trimesh.Trimesh(np.asarray(m.vert_properties)[:, :3], np.asarray(m.tri_verts), process=False)
        rel = tm.vertices - ax.origin
        a = rel @ ax.direction
        r = np.linalg.norm(rel - np.outer(a, ax.direction), axis=1)
        on = np.abs(r - ax.R) < 0.01 * ax.R
        lo, hi = -ax.span / 2 - 1e-6, ax.span / 2 + 1e-6       # the stack, not the hub beyond it
        sel = on & (a >= lo) & (a <= hi)
        rows.append({"axis": ax.name, "joint": ax.joint, "R_mm": round(float(ax.R), 4),
                     "layout_knuckle_mm": round(float(ax.knuckle), 4),
                     "mesh_knuckle_mm": round(float(a[sel].max() - a[sel].min()), 4) if sel.any() else None,
                     "mesh_vertices": int(sel.sum())})
    return rows


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--piece", action="append", help="tests/data_mesh piece (repeatable; default circuit_junction)")
    ap.add_argument("-o", "--out", required=True)
    a = ap.parse_args()
    out = {"benchmark": "knuckle_lengths", "commit": commit(), "profile": "mjp", "variants": VARIANTS, "pieces": {}}
    for piece in a.piece or ["circuit_junction"]:
        res = {"piece": f"tests/data_mesh/{piece}"}
        for k, flags in VARIANTS.items():
            res[k] = measure(piece, flags)
            ks = [r["mesh_knuckle_mm"] for r in res[k] if r["mesh_knuckle_mm"] is not None]
            res[f"{k}_summary"] = {"stacks": len(res[k]), "at_least_0.6_mm": sum(x >= 0.6 - 1e-3 for x in ks),
                                   "min_mm": min(ks), "max_mm": max(ks)}
            print(piece, k, res[f"{k}_summary"])
        out["pieces"][piece] = res
    with atomic_path(a.out) as tmp:
        Path(tmp).write_text(json.dumps(out, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
