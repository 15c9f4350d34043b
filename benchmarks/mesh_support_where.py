"""Where a library gate's remaining print support is, by feature (issue 13, the supports goal).

For each gate, convention and profile: the assembly ``mlc stl`` exports (``export_assembly``, its
feet and print pose), then mlc's own support estimate (``mlc.mesh.printability``, exactly as the
report's ``supports`` check computes it: the columns under overhangs and the islands' columns, on
the report's grid) split by what each column holds up:

* ``pivot``: the output lever's pivot, the hinge axis whose bodies are ``out_lo`` and ``out_hi``:
  an overhang crossing or island within the knuckle radius plus ``--near`` mm of that axis line
  (in the print frame), over the knuckles' span;
* ``out_lo``, ``out_hi``: the rest of each output lever part (its arms and lower ends);
* ``ujoint_d``: the universal joint at d;
* ``loop``: every other part (core_ab, core_cd, the four input levers, with their feet).

The total is the report's figure (checked here: the script fails if they differ), so the split is a
breakdown of mlc's estimate, not a second measure; PrusaSlicer's support by part is in
``mesh_bed_feet.json`` (``support_by_part_mm3``) for comparison.

    python benchmarks/mesh_support_where.py [--gates NAND NOR] [--signals expand contract] [--profiles fdm]

Writes benchmarks/results/mesh_support_where.json.  Units: mm, mm^3.
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import time
from pathlib import Path

import mlc  # noqa: F401 -- before numpy: pins OpenBLAS's kernels (mlc/__init__.py)

import numpy as np

from gitstate import commit

RESULTS = Path(__file__).resolve().parent / "results"
LEVER = ("out_lo", "out_hi")


def _pivot(asm):
    """The output lever's pivot axis in the print frame: (point, unit direction, half span, R)."""
    for ax in asm.axes:
        if set(LEVER) <= set(ax.bodies):
            T = asm.print_T(ax.bodies[0])
            p = T[:3, :3] @ np.asarray(ax.origin) + T[:3, 3]
            d = T[:3, :3] @ np.asarray(ax.direction)
            return p, d / np.linalg.norm(d), 0.5 * ax.span, ax.R
    raise SystemExit("no hinge axis joins out_lo and out_hi")


def breakdown(gate: str, signal: str, profile: str, near: float) -> dict:
    from mlc.gates.library import gate_scene
    from mlc.mesh.build import transform_solid
    from mlc.mesh.checks import OVERHANG_DEG, island_side, print_size
    from mlc.mesh.pipeline import export_assembly
    from mlc.mesh.pose import report_grid
    from mlc.mesh.printability import _columns, merged_mesh
    from mlc.mesh.profiles import load_profile

    prof = load_profile(profile)
    t = time.process_time()
    asm, rep = export_assembly(gate_scene(gate, signal), prof)
    export_cpu = time.process_time() - t
    named = [(p.name, transform_solid(p.solid, asm.print_T(p.name))) for p in asm.parts]
    named = [(n, s) for n, s in named if not s.is_empty()]
    names = [n for n, _ in named]
    h = report_grid(print_size(asm) or [1.0], prof.min_wall)      # the report's grid (checks.bed_checks)
    V, F, own = merged_mesh(named)
    c = _columns(V, F, h, OVERHANG_DEG, 0.5 * min(0.2, prof.min_wall / 2), own, island_side(prof))
    cent = V[F].mean(axis=1)
    pts = np.concatenate([cent[c["tri_idx"]], c["island_pts"]])
    vol = np.concatenate([c["vol"], c["island_vol"]])
    who = np.concatenate([own[c["tri_idx"]], c["island_own"]])
    inside = np.concatenate([c["inside"], c["island_inside"]])
    p0, d, half, R = _pivot(asm)
    rel = pts - p0
    along = rel @ d
    radial = np.linalg.norm(rel - np.outer(along, d), axis=1)
    at_pivot = (radial <= R + near) & (np.abs(along) <= half + near)
    part = np.array(names)[who]
    cls = np.where(np.isin(part, LEVER) & at_pivot, "pivot",
                   np.where(np.isin(part, LEVER), part, np.where(part == "ujoint_d", "ujoint_d", "loop")))
    total = float(vol.sum())
    want = float(asm.bed.support_mm3)         # export_assembly's bed check (checks.bed_checks)
    if abs(total - want) > 1e-6 * max(1.0, want):
        raise SystemExit(f"{gate} {signal} {profile}: breakdown {total} != report {want}")
    by = {}
    for k in ("pivot", "out_lo", "out_hi", "ujoint_d", "loop"):
        m = cls == k
        by[k] = {"support_mm3": round(float(vol[m].sum()), 1),
                 "fraction": round(float(vol[m].sum()) / total, 4) if total else 0.0,
                 "between_parts_mm3": round(float(vol[m & inside].sum()), 1)}
    return {"gate": gate, "signal": signal, "profile": profile, "support_mm3": round(total, 1),
            "report_support_mm3": round(want, 1), "part_volume_mm3": round(float(asm.bed.part_volume_mm3), 1),
            "grid_mm": round(h, 4), "pivot_R_mm": round(float(R), 3), "near_mm": near,
            "by_feature": by, "export_cpu_s": round(export_cpu, 1),
            "blocking_pass": bool(rep.ok)}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--gates", nargs="*", default=["NAND", "NOR"])
    ap.add_argument("--signals", nargs="*", default=["expand"])
    ap.add_argument("--profiles", nargs="*", default=["fdm"])
    ap.add_argument("--near", type=float, default=1.0, help="mm beyond the knuckle radius counted as the pivot's")
    ap.add_argument("-o", "--out", default=str(RESULTS / "mesh_support_where.json"))
    a = ap.parse_args()
    rows = []
    for g in a.gates:
        for s in a.signals:
            for p in a.profiles:
                r = breakdown(g, s, p, a.near)
                rows.append(r)
                print(json.dumps(r))
    res = {"what": "mlc's support estimate of library gates split by the feature each column holds up "
                   "(benchmarks/mesh_support_where.py docstring)", "commit": commit(),
           "machine": f"{platform.machine()}, {os.cpu_count()} cores (shared)",
           "date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()), "units": "mm, mm^3", "rows": rows}
    Path(a.out).write_text(json.dumps(res, indent=1) + "\n")


if __name__ == "__main__":
    main()
