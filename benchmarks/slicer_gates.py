"""Slice every library gate in every printer profile with PrusaSlicer's command line (not CI).

    python benchmarks/slicer_gates.py [--signal expand] [--gates NAND,NOR] [--profiles mjp,sla,fdm]

For each gate and profile: build the printable assembly with ``export_assembly``, exactly as
``mlc stl`` does (posed in every logic state and on the way to them, the dense paths and their
motion trims, the printability report), write the 3MF (one object, the parts as volumes), ask
``prusa-slicer --info`` how many objects and parts it sees, then slice it twice -- without and
with supports (``--support-material``) -- and read the G-code's own summary: layers
(``;LAYER_CHANGE``), estimated time, filament volume.  The support volume is the difference of
the two filament volumes.  Also records mlc's own bed statistics (mlc.mesh.printability).
Results: benchmarks/results/slicer_gates.json.  Needs ``prusa-slicer`` on PATH (Debian:
``apt-get install prusa-slicer``); without it the script says so and exits 1.
"""
from __future__ import annotations

import argparse
import json
import platform
import re
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from mlc.gates.library import GATE_NAMES, gate_scene  # noqa: E402
from mlc.mesh.build import transform_solid  # noqa: E402
from mlc.mesh.checks import OVERHANG_DEG  # noqa: E402
from mlc.mesh.export import part_meshes, threemf_bytes  # noqa: E402
from mlc.mesh.pipeline import export_assembly  # noqa: E402
from mlc.mesh.printability import bed_stats  # noqa: E402
from mlc.mesh.profiles import load_profile  # noqa: E402

LAYER = {"mjp": 0.1, "sla": 0.1, "fdm": 0.2}


def _time_s(txt: str) -> float | None:
    m = re.search(r"estimated printing time \(normal mode\) = (.*)", txt)
    if not m:
        return None
    tot = 0
    for v, u in re.findall(r"(\d+)([dhms])", m.group(1)):
        tot += int(v) * {"d": 86400, "h": 3600, "m": 60, "s": 1}[u]
    return float(tot)


def slice_once(exe, path: Path, layer: float, supports: bool) -> dict:
    out = path.with_suffix(".sup.gcode" if supports else ".gcode")
    cmd = [exe, "--export-gcode", "--layer-height", str(layer), "--first-layer-height", str(max(layer, 0.2)),
           "-o", str(out), str(path)]
    if supports:
        cmd.insert(1, "--support-material")
    t0 = time.perf_counter()
    r = subprocess.run(cmd, capture_output=True, text=True)
    dt = time.perf_counter() - t0
    if r.returncode != 0 or not out.exists():
        return {"ok": False, "error": (r.stderr or r.stdout)[-400:], "slice_s": round(dt, 2)}
    txt = out.read_text(errors="replace")
    cm3 = re.search(r"; filament used \[cm3\] = ([\d.]+)", txt)
    return {"ok": True, "layers": txt.count(";LAYER_CHANGE"), "print_time_s": _time_s(txt),
            "filament_mm3": round(float(cm3.group(1)) * 1000, 1) if cm3 else None, "slice_s": round(dt, 2)}


def info(exe, path: Path) -> dict:
    r = subprocess.run([exe, "--info", str(path)], capture_output=True, text=True)
    txt = r.stdout
    return {"objects": txt.count(f"[{path.name}]"),
            "parts": [int(x) for x in re.findall(r"number_of_parts =\s*(\d+)", txt)],
            "min_z": [float(x) for x in re.findall(r"min_z = ([-\d.]+)", txt)],
            "size": [[float(x) for x in m] for m in re.findall(r"size_x = ([\d.]+)\s+size_y = ([\d.]+)\s+size_z = ([\d.]+)", txt)]}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--signal", default="expand")
    ap.add_argument("--gates", default=",".join(GATE_NAMES))
    ap.add_argument("--profiles", default="mjp,sla,fdm")
    ap.add_argument("-o", "--out", default=str(ROOT / "benchmarks/results/slicer_gates.json"))
    a = ap.parse_args()
    exe = shutil.which("prusa-slicer")
    if not exe:
        print("prusa-slicer is not installed (Debian: apt-get install prusa-slicer)", file=sys.stderr)
        return 1
    ver = subprocess.run([exe, "--help"], capture_output=True, text=True).stdout.split("\n")
    ver = next((x for x in ver if x.startswith("PrusaSlicer")), "?")
    rows = []
    tmp = Path(tempfile.mkdtemp(prefix="mlc_slicer_"))
    for g in a.gates.split(","):
        scene = gate_scene(g, a.signal)
        for pn in a.profiles.split(","):
            prof = load_profile(pn)
            t0 = time.perf_counter()
            asm, rep = export_assembly(scene, prof)
            t_build = time.perf_counter() - t0
            f = tmp / f"{g}_{a.signal}_{pn}.3mf"
            f.write_bytes(threemf_bytes(part_meshes(asm), f"{g}_{a.signal}"))
            solids = [(p.name, transform_solid(p.solid, asm.orient)) for p in asm.parts]
            bs = bed_stats(solids, OVERHANG_DEG, 0.25 if pn == "fdm" else 0.05,
                           first_layer=min(0.2, prof.min_wall / 2))
            row = {"gate": g, "signal": a.signal, "profile": pn, "orient": prof.orient, "layer_mm": LAYER[pn],
                   "parts": len(asm.parts), "part_volume_mm3": round(sum(float(p.solid.volume()) for p in asm.parts), 1),
                   "export_s": round(t_build, 2), "report_ok": rep.ok,
                   "goals_not_met": sorted(c.name for c in rep.checks if not c.ok and not c.blocking),
                   "motion_trims": len(asm.motion_trims), "mlc_bed": bs.to_dict(),
                   "prusa_info": info(exe, f),
                   "no_supports": slice_once(exe, f, LAYER[pn], False),
                   "supports": slice_once(exe, f, LAYER[pn], True)}
            n, s = row["no_supports"], row["supports"]
            if n.get("ok") and s.get("ok") and n["filament_mm3"] is not None and s["filament_mm3"] is not None:
                row["support_mm3"] = round(s["filament_mm3"] - n["filament_mm3"], 1)
                row["support_fraction"] = round(row["support_mm3"] / max(n["filament_mm3"], 1e-9), 3)
            rows.append(row)
            print(f"{g:8s} {pn}: parts {row['prusa_info']['parts']}, layers {n.get('layers')}/{s.get('layers')}, "
                  f"filament {n.get('filament_mm3')}/{s.get('filament_mm3')} mm3, time {n.get('print_time_s')}/"
                  f"{s.get('print_time_s')} s, contact {bs.contact_fraction:.3f}", flush=True)
            Path(a.out).write_text(json.dumps({"slicer": ver, "machine": platform.platform(),
                                               "note": "support_mm3 = filament with supports - without",
                                               "rows": rows}, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
