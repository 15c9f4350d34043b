"""Printable-mesh benchmark: one gate, and a 100-gate assembly.

    python benchmarks/mesh_export.py [--quick]

* ``gate``: the NAND gate for each printer profile -- build every part (manifold3d CSG),
  run the printability report (all four logic states posed), write STL + 3MF (in memory).
  The equilibrium poses come from static verification, timed separately (``solve_s``).
  Target: under 2 s per gate.
* ``grid``: 100 NAND gates on a 10 x 10 grid as one scene, ``mlc stl`` end to end
  (static verification of every mechanism, build, report, STL + 3MF written).
  Identical mechanisms are built once and translated.  Target: under 60 s.

Writes benchmarks/results/mesh_export.json.
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from mlc.gates.library import gate_scene  # noqa: E402
from mlc.mesh import examples  # noqa: E402
from mlc.mesh.build import build_assembly  # noqa: E402
from mlc.mesh.checks import check_assembly  # noqa: E402
from mlc.mesh.export import part_meshes, stl_bytes, threemf_bytes, write_outputs  # noqa: E402
from mlc.mesh.pipeline import export_assembly, state_poses  # noqa: E402
from mlc.mesh.profiles import load_profile  # noqa: E402

RESULTS = ROOT / "benchmarks" / "results"


def bench_gate(repeat: int) -> list[dict]:
    scene = gate_scene("NAND", "expand")
    t0 = time.perf_counter()
    poses, _ = state_poses(scene)
    solve = time.perf_counter() - t0
    rows = []
    for prof in ("mjp", "sla", "fdm"):
        best = None
        for _ in range(repeat):
            t0 = time.perf_counter()
            asm = build_assembly(scene, load_profile(prof), poses)
            t1 = time.perf_counter()
            rep = check_assembly(asm)
            t2 = time.perf_counter()
            meshes = part_meshes(asm)
            stl, mf3 = stl_bytes(meshes), threemf_bytes(meshes)
            t3 = time.perf_counter()
            row = {"gate": "NAND", "profile": prof, "ok": rep.ok, "parts": len(asm.parts),
                   "triangles": int(sum(len(m.faces) for _, m in meshes)), "stl_bytes": len(stl),
                   "threemf_bytes": len(mf3), "build_s": round(t1 - t0, 3), "report_s": round(t2 - t1, 3),
                   "export_s": round(t3 - t2, 3), "total_s": round(t3 - t0, 3), "solve_s": round(solve, 3),
                   "target_s": 2.0}
            if best is None or row["total_s"] < best["total_s"]:
                best = row
        best["meets_target"] = best["total_s"] < best["target_s"]
        rows.append(best)
        print(json.dumps(best), flush=True)
    return rows


def bench_grid(n: int) -> dict:
    side = int(round(n ** 0.5))
    scene = examples.grid(gate_scene("NAND", "expand"), side, n // side, (5.0, 5.0))
    prof = load_profile("mjp")
    with tempfile.TemporaryDirectory() as d:
        t0 = time.perf_counter()
        asm, rep = export_assembly(scene, prof)
        t1 = time.perf_counter()
        meshes = part_meshes(asm)
        write_outputs(asm, stl=Path(d) / "grid.stl", threemf=Path(d) / "grid.3mf", meshes=meshes)
        t2 = time.perf_counter()
        size = (Path(d) / "grid.stl").stat().st_size
    row = {"gates": side * (n // side), "profile": "mjp", "ok": rep.ok, "parts": len(asm.parts),
           "triangles": int(sum(len(m.faces) for _, m in meshes)), "stl_bytes": size,
           "build_and_report_s": round(t1 - t0, 3), "write_s": round(t2 - t1, 3), "total_s": round(t2 - t0, 3),
           "target_s": 60.0}
    row["meets_target"] = row["total_s"] < row["target_s"]
    print(json.dumps(row), flush=True)
    return row


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true", help="one repeat, 16 gates in the grid")
    args = ap.parse_args()
    gate = bench_gate(1 if args.quick else 3)
    grid = bench_grid(16 if args.quick else 100)
    out = {"benchmark": "mesh_export", "python": platform.python_version(), "machine": platform.machine(),
           "cpus": os.cpu_count(), "load_average": [round(x, 2) for x in os.getloadavg()],
           "note": "wall-clock seconds on a shared machine; solve_s (static verification of the 4 states) "
                   "is not part of the per-gate mesh time", "gate": gate, "grid": grid}
    if not args.quick:
        RESULTS.mkdir(parents=True, exist_ok=True)
        (RESULTS / "mesh_export.json").write_text(json.dumps(out, indent=2) + "\n")
    return 0 if all(r["ok"] for r in gate) and grid["ok"] else 1


if __name__ == "__main__":
    sys.exit(main())
