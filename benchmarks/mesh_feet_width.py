"""The print-only feet's width, measured on sections of the finished parts, with this checkout's
``mlc/mesh/feet.py`` and with an earlier commit's, in one run.

    python benchmarks/mesh_feet_width.py [--cases CNIMPLY:expand:mjp ...] [--old COMMIT] [--out FILE]

Each case goes through ``export_assembly`` (what ``mlc stl`` runs) twice: with the feet of
``--old`` (its ``mlc/mesh/feet.py``, ``git show``, put in the place of this checkout's while the
case is built) and with this checkout's.  For every part with a foot, the finished part is cut
half-way down its foot (the feet go down along the model's -z in every library gate; the cut is
halfway between the part's lowest point and the lowest point of the part without its foot,
``asm.feet_free``), and the section's **width** is measured: the largest diameter D such that
every point of the section lies within 0.005 mm of a disc of diameter D inside it (the section
less the opening by a disc of D, grown by 0.005 mm, is empty: manifold3d's CrossSection, Clipper2
offsets, bisected to 0.001 mm).  A sharp convex corner holds no disc: a section with one
measures about 0.02 mm (every foot's corners are rounded by the opening it is made with).  This is the outside check of the feet's walls: it does not use
``mlc.mesh.walls`` (the voxel grid and the distances to the surface).  ``wall_thickness`` of the
report (mlc's own measure) is recorded beside it.
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
TOL = 0.005     # mm: a point of the section this close to the opening counts as in it


def old_feet(rev: str):
    src = subprocess.run(["git", "-C", str(ROOT), "show", f"{rev}:mlc/mesh/feet.py"], check=True,
                         capture_output=True, text=True).stdout
    path = os.path.join(tempfile.mkdtemp(prefix="feet_old_"), "feet_old.py")
    Path(path).write_text(src)
    spec = importlib.util.spec_from_file_location("mlc.mesh.feet", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def fits(cs, D: float) -> bool:
    """Whether every point of ``cs`` lies within TOL of a disc of diameter D inside it."""
    import manifold3d as mf
    r = D / 2
    opened = cs.offset(-r, mf.JoinType.Round, 2.0, 256).offset(r + TOL, mf.JoinType.Round, 2.0, 256)
    return (cs - opened).area() < 1e-9


def width(cs) -> float:
    lo, hi = 0.0, 0.5 * max(b - a for a, b in zip(cs.bounds()[:2], cs.bounds()[2:])) * 2
    if fits(cs, hi):
        return hi
    while hi - lo > 1e-3:
        m = 0.5 * (lo + hi)
        if fits(cs, m):
            lo = m
        else:
            hi = m
    return lo


def feet_widths(asm) -> dict:
    out = {}
    for name in asm.feet:
        part = asm.part(name).solid
        free = asm.feet_free[name]
        pb, fb = part.bounding_box(), free.bounding_box()
        if pb[2] < fb[2] - 1e-6:           # down along -z (every library gate's feet)
            bed, top = float(pb[2]), float(fb[2])
        else:                              # up along +z
            bed, top = float(pb[5]), float(fb[5])
        z = 0.5 * (bed + top)
        cs = part.slice(z)
        # (a part that reaches the bed without its foot is not cut in its foot: nothing measured;
        # the results file of session 38 records such a part's empty section as width Infinity)
        pieces = [p for p in cs.decompose() if p.area() > 0] if abs(top - bed) > 1e-6 else []
        out[name] = {"z_mm": round(z, 3), "foot_mm": round(abs(top - bed), 3), "pieces": len(pieces),
                     "area_mm2": round(cs.area(), 3),
                     "width_mm": round(min(width(p) for p in pieces), 4) if pieces else None}
    return out


def run_case(gate, signal, prof_name):
    from mlc.gates.library import gate_scene
    from mlc.mesh.pipeline import export_assembly
    from mlc.mesh.profiles import load_profile
    prof = load_profile(prof_name)
    t0 = time.perf_counter()
    asm, rep = export_assembly(gate_scene(gate, signal), prof)
    w = feet_widths(asm)
    ws = [v["width_mm"] for v in w.values() if v["width_mm"] is not None]
    ch = rep.check("wall_thickness")
    return {"ok": rep.ok, "min_wall_mm": prof.min_wall, "feet": w, "narrowest_foot_mm": min(ws) if ws else None,
            "wall_thickness": ch.value, "thin_walls": ch.failures, "bed_contact": rep.check("bed_contact").value,
            "failed": [c.name for c in rep.checks if not c.ok and c.blocking], "export_s": round(time.perf_counter() - t0, 1)}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--cases", nargs="+", default=["CNIMPLY:expand:mjp", "CNIMPLY:contract:fdm", "CIMPLY:expand:fdm"])
    ap.add_argument("--old", default="42c7ec8", help="commit of the old feet (default: session 37's)")
    ap.add_argument("--out", default=str(RESULTS / "mesh_gates_walls_s38_feet_width.json"))
    args = ap.parse_args()
    import mlc.mesh
    import mlc.mesh.feet as new
    old = old_feet(args.old)
    rows = []
    for case in args.cases:
        gate, signal, prof = case.split(":")
        row = {"gate": gate, "signal": signal, "profile": prof}
        for label, mod in (("old", old), ("new", new)):
            sys.modules["mlc.mesh.feet"] = mod
            mlc.mesh.feet = mod
            try:
                row[label] = run_case(gate, signal, prof)
            finally:
                sys.modules["mlc.mesh.feet"] = new
                mlc.mesh.feet = new
        rows.append(row)
        print(json.dumps(row), flush=True)
    out = {"benchmark": "mesh_feet_width", "old_commit": args.old, "commit": commit(),
           "python": platform.python_version(), "load_average": [round(x, 2) for x in os.getloadavg()],
           "tolerance_mm": TOL, "rows": rows}
    with atomic_path(args.out) as tmp:
        Path(tmp).write_text(json.dumps(out, indent=1) + "\n")
    print("wrote", args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
