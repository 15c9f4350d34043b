"""The measured wall check (``mlc.mesh.walls.thin_walls``), this checkout's against an earlier
commit's, on the same finished parts in one run: the time a part and the thin regions found.

    python benchmarks/mesh_walls_speed.py [--old COMMIT] [--every 10] [--out FILE]

The parts: a library gate (NAND, expanding, mjp: ``export_assembly``, what ``mlc stl`` runs) and
the compiled Tetris circuit (examples/tetris.tt, compiled as ``mlc compile`` does, its one
distinct mechanisms posed and built as ``export_assembly`` does, mjp; their checks are not run).  The old
measure is ``mlc/mesh/walls.py`` of ``--old`` (``git show``), loaded beside this checkout's
(both use this checkout's ``mlc.mesh.printability`` for the voxel raster, unchanged between
them).  Each part is measured by the old code, then by the new: every part of the gate, every
``--every``-th part of the circuit (in the scene's order), and then the new code alone on every
part of the circuit (the whole circuit's wall time as ``mlc stl`` would spend it, without the
per-shape reuse of congruent parts, which finds few in a circuit: ``distinct_shapes``).

Both measures are run once on a thin plate before any timing (Numba's kernels compiled; the
old module's are compiled afresh, from a temporary file).  Per part: seconds (old, new), the number of thin regions and the thinnest (``thickness_mm``) by
each.  Totals and the ratio old / new.  One process; ``commit`` as benchmarks/gitstate.py.
"""
from __future__ import annotations

import argparse
import importlib.util
import json
import os
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from gitstate import commit  # noqa: E402  (benchmarks/gitstate.py)
from mlc.io.atomic import atomic_path  # noqa: E402

RESULTS = ROOT / "benchmarks" / "results"


def old_walls(rev: str):
    """``mlc/mesh/walls.py`` at ``rev``, as a module of its own."""
    src = subprocess.run(["git", "-C", str(ROOT), "show", f"{rev}:mlc/mesh/walls.py"], check=True,
                         capture_output=True, text=True).stdout
    d = tempfile.mkdtemp(prefix="walls_old_")
    path = os.path.join(d, "walls_old.py")
    Path(path).write_text(src)
    spec = importlib.util.spec_from_file_location("walls_old", path)
    mod = importlib.util.module_from_spec(spec)
    sys.modules["walls_old"] = mod
    spec.loader.exec_module(mod)
    return mod


def gate_parts():
    from mlc.gates.library import gate_scene
    from mlc.mesh.pipeline import export_assembly
    from mlc.mesh.profiles import load_profile
    prof = load_profile("mjp")
    asm, _ = export_assembly(gate_scene("NAND", "expand"), prof)
    return asm, prof


def circuit_parts():
    """The distinct mechanisms of the circuit's scene, each posed and built as export_assembly
    builds it (copies of a mechanism are translated there, their walls the same): one list of
    parts (a namespace with ``parts``), the congruence frames of each mechanism's parts."""
    import types
    from mlc import pipeline
    from mlc.mesh.build import build_assembly
    from mlc.mesh.congruence import shape_key
    from mlc.mesh.pipeline import _dense_poses, _signature, split_mechanisms, state_poses
    from mlc.mesh.profiles import load_profile
    scene = pipeline.build(pipeline.compile_spec(pipeline.load(str(ROOT / "examples/tetris.tt"), None))).circuit.scene
    prof = load_profile("mjp")
    parts, keys, seen = [], set(), set()
    mechs = split_mechanisms(scene)
    for m in mechs:
        sig = _signature(m.scene)
        if sig in seen:
            continue
        seen.add(sig)
        poses, _ = state_poses(m.scene)
        dense = _dense_poses(m.scene, prof, [])
        a = build_assembly(m.scene, prof, poses or None, motion_poses=dense)
        parts += a.parts
        cong = getattr(a, "congruence", None)
        keys |= {shape_key(p.solid, cong.frames[i]) if cong else (len(seen), i) for i, p in enumerate(a.parts)}
    return types.SimpleNamespace(parts=parts, mechanisms=len(mechs), built=len(seen), shapes=len(keys)), prof


def summary(ws):
    return len(ws), (round(min(w.thickness_mm for w in ws), 4) if ws else None)


def compare(asm, prof, old, new, every: int) -> dict:
    rows = []
    parts = [p for p in asm.parts if not p.solid.is_empty()]
    for p in parts[::every]:
        t0 = time.perf_counter()
        a = old.thin_walls(p.name, p.solid, prof.min_wall)
        t1 = time.perf_counter()
        b = new.thin_walls(p.name, p.solid, prof.min_wall)
        t2 = time.perf_counter()
        rows.append({"part": p.name, "old_s": round(t1 - t0, 3), "new_s": round(t2 - t1, 3),
                     "old_regions": summary(a)[0], "old_thinnest_mm": summary(a)[1],
                     "new_regions": summary(b)[0], "new_thinnest_mm": summary(b)[1]})
    to, tn = sum(r["old_s"] for r in rows), sum(r["new_s"] for r in rows)
    return {"parts_measured": len(rows), "parts": len(parts), "every": every,
            "old_s": round(to, 2), "new_s": round(tn, 2), "ratio": round(to / tn, 2) if tn else None,
            "same_region_count": sum(r["old_regions"] == r["new_regions"] for r in rows), "rows": rows}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--old", default="42c7ec8", help="commit of the old measure (default: session 37's)")
    ap.add_argument("--every", type=int, default=10, help="circuit: compare every n-th part")
    ap.add_argument("--out", default=str(RESULTS / "mesh_walls_speed_s38.json"))
    args = ap.parse_args()
    from mlc.mesh import walls as new
    old = old_walls(args.old)
    import manifold3d as mf
    # Numba's kernels compiled or loaded before any timing, old and new alike: a plate thinner than
    # the minimum wall takes every measure (a thin region, its balls and chords, the surface's
    # distances); the old module, loaded from a temporary file, compiles its kernels afresh
    for mod in (old, new):
        mod.thin_walls("warm", mf.Manifold.cube([1, 1, 1]), 0.6)
        assert mod.thin_walls("warm plate", mf.Manifold.cube([3, 3, 0.4]), 0.6), "the warm-up plate is thin"
    out = {"old_commit": args.old, "commit": commit(), "machine": platform.machine(),
           "python": platform.python_version(), "load_start": os.getloadavg()[0]}
    t0 = time.perf_counter()
    asm, prof = gate_parts()
    out["gate"] = {"case": "NAND expand mjp", "build_s": round(time.perf_counter() - t0, 1),
                   **compare(asm, prof, old, new, 1)}
    print("gate", {k: v for k, v in out["gate"].items() if k != "rows"}, flush=True)
    t0 = time.perf_counter()
    asm, prof = circuit_parts()
    out["circuit"] = {"case": "tetris mjp", "build_s": round(time.perf_counter() - t0, 1),
                      "mechanisms": asm.mechanisms, "mechanisms_built": asm.built,
                      "distinct_shapes": asm.shapes, **compare(asm, prof, old, new, args.every)}
    print("circuit", {k: v for k, v in out["circuit"].items() if k != "rows"}, flush=True)
    t0 = time.perf_counter()
    n = sum(len(new.thin_walls(p.name, p.solid, prof.min_wall)) for p in asm.parts if not p.solid.is_empty())
    out["circuit_all_new"] = {"parts": len(asm.parts), "new_s": round(time.perf_counter() - t0, 1), "regions": n}
    print("circuit, every part, new", out["circuit_all_new"], flush=True)
    out["load_end"] = os.getloadavg()[0]
    with atomic_path(args.out) as tmp:
        Path(tmp).write_text(json.dumps(out, indent=1) + "\n")
    print("wrote", args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
