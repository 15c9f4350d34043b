"""Thin regions of the same parts by session 37's wall measure and by this checkout's, in one run.

    python benchmarks/mesh_walls_merge.py [--cases CIMPLY:expand:fdm CNIMPLY:contract:fdm] [--old 42c7ec8]

Session 37 (``mesh_gates_walls_s37_fdm.json``) found thin spots of 0.903 and 1.01 mm in the feet
of these two fdm cases, in regions of 1.2 and 1.8 mm^3; rebuilt with those feet in session 38
(``mesh_gates_walls_s38_feet_width.json``) the regions near the same places were 8-25 mm^3 and
1.18 mm thick.  Whether the measure or the parts changed: each case is built once with the feet of
``--old`` (its ``mlc/mesh/feet.py``, as ``mesh_feet_width.py`` does) and every part is measured by
``--old``'s ``mlc/mesh/walls.py`` (session 37: ball centres placed from surface samples) and by
this checkout's (session 38: exact distances); per part, every region's thickness, volume,
thinnest chord and place.
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
sys.path.insert(0, str(ROOT / "benchmarks"))

from gitstate import commit  # noqa: E402
from mlc.io.atomic import atomic_path  # noqa: E402
from mesh_feet_width import old_feet  # noqa: E402

RESULTS = ROOT / "benchmarks" / "results"


def old_walls(rev: str):
    src = subprocess.run(["git", "-C", str(ROOT), "show", f"{rev}:mlc/mesh/walls.py"], check=True,
                         capture_output=True, text=True).stdout
    path = Path(tempfile.mkdtemp(prefix="walls_old_")) / "walls_old.py"
    path.write_text(src)
    spec = importlib.util.spec_from_file_location("walls_old", path)
    mod = importlib.util.module_from_spec(spec)
    sys.modules["walls_old"] = mod
    spec.loader.exec_module(mod)
    return mod


def regions(mod, part) -> tuple[list, float]:
    t = time.perf_counter()
    out = [{"thickness_mm": round(w.thickness_mm, 4), "volume_mm3": round(w.volume_mm3, 3),
            "thinnest_mm": None if w.thinnest_mm is None else round(w.thinnest_mm, 4),
            "where_mm": [round(x, 2) for x in w.where_mm]}
           for w in mod.thin_walls(part.name, part.solid, MW)]
    return out, round(time.perf_counter() - t, 1)


MW = None


def main() -> int:
    global MW
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", nargs="+", default=["CIMPLY:expand:fdm", "CNIMPLY:contract:fdm"])
    ap.add_argument("--old", default="42c7ec8")
    ap.add_argument("--out", default=str(RESULTS / "mesh_walls_merge_s39.json"))
    args = ap.parse_args()
    import mlc.mesh
    import mlc.mesh.feet as new_feet
    from mlc.gates.library import gate_scene
    from mlc.mesh import walls as new_walls
    from mlc.mesh.pipeline import export_assembly
    from mlc.mesh.profiles import load_profile
    of, ow = old_feet(args.old), old_walls(args.old)
    rows = []
    for case in args.cases:
        gate, signal, prof = case.split(":")
        profile = load_profile(prof)
        MW = float(profile.min_wall)
        sys.modules["mlc.mesh.feet"] = of
        mlc.mesh.feet = of
        try:
            asm, _ = export_assembly(gate_scene(gate, signal), profile)
        finally:
            sys.modules["mlc.mesh.feet"] = new_feet
            mlc.mesh.feet = new_feet
        for part in asm.parts:
            if not asm.feet.get(part.name):
                continue
            o, to = regions(ow, part)
            n, tn = regions(new_walls, part)
            row = {"case": case, "part": part.name, "feet_mm3": round(asm.feet[part.name], 1),
                   "old_measure": o, "old_s": to, "new_measure": n, "new_s": tn}
            rows.append(row)
            print(json.dumps(row), flush=True)
    out = {"benchmark": "mesh_walls_merge", "old": args.old, "commit": commit(),
           "python": platform.python_version(), "load_average": [round(x, 2) for x in os.getloadavg()],
           "rows": rows}
    with atomic_path(Path(args.out)) as t:
        Path(t).write_text(json.dumps(out, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
