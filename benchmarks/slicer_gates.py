"""Slice every library gate in every printer profile with PrusaSlicer's command line (not CI).

    python benchmarks/slicer_gates.py [--signal expand] [--gates NAND,NOR] [--profiles mjp,sla,fdm]

For each gate and profile: build the printable assembly with ``export_assembly``, exactly as
``mlc stl`` does (posed in every logic state and on the way to them, the dense paths and their
motion trims, the printability report), with ``orient: auto`` (``--orient auto``; the fdm
default, mjp and sla default to the model's z).  Three print poses of the same parts are then
compared (issue 13, item 1):

* ``before``: the model's z up, the rest configuration as modelled: what the first
  ``orient: auto`` (session 20, axes and slab normals only) chose for every library gate in fdm
  (its note: "up is the model's (0, 0, 1)"), and the mjp and sla default (``as_is``);
* ``estimate``: the best up by mlc's support estimate alone (``mlc.mesh.pose.search_up``: the
  sphere, the hinge-45-degree directions, the axes and slab normals, refined), before the guard
  that keeps the best axis or slab normal unless another up meets more bed goals;
* ``after``: the pose ``mlc stl`` writes now (``asm.orient``).  A pose equal to an earlier one
  is not sliced again (its figures are copied).

With ``--orient auto_config`` (rows with ``"orient": "auto_config"``, kept beside the ``auto``
rows) the parts are printed in the configuration of the mechanism ``mlc stl`` chooses
(``asm.print_pose``, ``mlc.mesh.configs``; the row's ``configuration``: the input levers' hinge
angles from rest, degrees): ``estimate`` and ``after`` are in that configuration, ``before``
stays the rest configuration with the model's z up.

For each pose: mlc's own bed statistics on the report's grid (``mlc.mesh.printability``), the
3MF (one object, the parts as volumes), ``prusa-slicer --info`` (objects, parts), and three
slices -- without supports, with supports (``--support-material``), and with supports on the
build plate only (``--support-material-buildplate-only``) -- read from the G-code's own
summary: layers (``;LAYER_CHANGE``), estimated time, filament volume, and the filament of the
first layer without the skirt (mm^3, from the E moves; over the first layer height it is about
the area the first layer prints, to compare with mlc's bed contact).  Support volume = filament with supports - without;
support on the print (PrusaSlicer's counterpart of mlc's support on parts) = with supports
everywhere - build plate only.  Results: benchmarks/results/slicer_gates.json.  Needs
``prusa-slicer`` on PATH (Debian: ``apt-get install prusa-slicer``); without it the script says
so and exits 1.
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

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from mlc.gates.library import GATE_NAMES, gate_scene  # noqa: E402
from mlc.geometry.rotation import rotation_between  # noqa: E402
from mlc.mesh.build import _h, transform_solid  # noqa: E402
from mlc.mesh.checks import OVERHANG_DEG, island_side  # noqa: E402
from mlc.mesh.export import threemf_bytes, to_trimesh  # noqa: E402
from mlc.mesh.pipeline import export_assembly  # noqa: E402
from mlc.mesh.pose import report_grid  # noqa: E402
from mlc.mesh.printability import bed_stats  # noqa: E402
from mlc.mesh.profiles import load_profile  # noqa: E402
from gitstate import commit as git_commit      # benchmarks/gitstate.py

LAYER = {"mjp": 0.1, "sla": 0.1, "fdm": 0.2}
FIRST_LAYER = 0.2      # PrusaSlicer's first layer height here (mm)


def _time_s(txt: str) -> float | None:
    m = re.search(r"estimated printing time \(normal mode\) = (.*)", txt)
    if not m:
        return None
    tot = 0
    for v, u in re.findall(r"(\d+)([dhms])", m.group(1)):
        tot += int(v) * {"d": 86400, "h": 3600, "m": 60, "s": 1}[u]
    return float(tot)


def _first_layer_mm3(txt: str, mm3_per_mm: float) -> float | None:
    """Filament extruded in the first layer (mm^3), the skirt left out: the E moves between the
    first and the second ``;LAYER_CHANGE`` (absolute or relative E, G92 resets followed)."""
    parts = txt.split(";LAYER_CHANGE")
    if len(parts) < 2:
        return None
    rel = bool(re.search(r"^M83", txt, re.M))
    e = 0.0
    tot = 0.0
    for line in parts[0].splitlines():         # the E position when the first layer starts
        m = re.match(r"G92 E([-\d.]+)", line)
        if m:
            e = float(m.group(1))
        m = re.match(r"G[01] .*E([-\d.]+)", line)
        if m and not rel:
            e = float(m.group(1))
    skirt = False
    for line in parts[1].splitlines():
        if line.startswith(";TYPE:"):
            skirt = "skirt" in line.lower()
        m = re.match(r"G92 E([-\d.]+)", line)
        if m:
            e = float(m.group(1))
            continue
        m = re.match(r"G[01] .*E([-\d.]+)", line)
        if m:
            v = float(m.group(1))
            d = v if rel else v - e
            if not rel:
                e = v
            if not skirt:
                tot += d
    return round(tot * mm3_per_mm, 2)


def extrusions(txt: str) -> list:
    """Every extruding move of a G-code: ``(x, y, z, filament mm, type)`` at the middle of the
    move (``;TYPE:`` and ``;Z:`` comments; absolute or relative E, G92 resets followed)."""
    rel = bool(re.search(r"^M83", txt, re.M))
    typ, x, y, z, e0, out = None, 0.0, 0.0, 0.0, 0.0, []
    for line in txt.splitlines():
        if line.startswith(";TYPE:"):
            typ = line[6:].strip()
        elif line.startswith(";Z:"):
            z = float(line[3:])
        elif line.startswith("G92"):
            m = re.search(r" E([-\d.]+)", line)
            if m:
                e0 = float(m.group(1))
        elif line.startswith(("G1 ", "G0 ")):
            mx, my, me = (re.search(rf" {c}([-\d.]+)", line) for c in "XYE")
            nx, ny = (float(mx.group(1)) if mx else x), (float(my.group(1)) if my else y)
            if me:
                e = float(me.group(1))
                de = e if rel else e - e0
                if not rel:
                    e0 = e
                if de > 0 and (mx or my):
                    out.append((0.5 * (x + nx), 0.5 * (y + ny), z, de, typ))
            x, y = nx, ny
    return out


#: a support extrusion is held up for the first part above it within this distance (mm) sideways
HOLD_SEARCH_MM = 3.0


def support_by_part(txt: str, sol, mm3_per_mm: float, grid: float = 0.3) -> dict:
    """PrusaSlicer's support filament (mm^3) by the part it holds up: for every support extrusion
    (``;TYPE:Support material`` and its interface) of the G-code ``txt``, the first surface of
    the print-frame solids ``sol`` (``[(name, manifold)]``, as written to the 3MF) straight above
    it, else the nearest one above within :data:`HOLD_SEARCH_MM` sideways (a slicer's support
    reaches past the overhang it holds); ``"none"`` when nothing is above.  PrusaSlicer puts the
    object's box centre where the model's is, moved by an offset found from the printed
    extrusions (the skirt left out) against the model's box."""
    from mlc.mesh.printability import _raster, merged_mesh
    ext = extrusions(txt)
    V, F, own = merged_mesh(sol)
    pts = np.array([(a, b) for a, b, _, _, t in ext if t and "skirt" not in t.lower()
                    and "support" not in t.lower()])
    if len(pts) == 0:
        return {}
    off = 0.5 * (pts.min(0) + pts.max(0)) - 0.5 * (V[:, :2].min(0) + V[:, :2].max(0))
    S = np.array([(a - off[0], b - off[1], z, de * mm3_per_mm) for a, b, z, de, t in ext
                  if t and "support" in t.lower()])
    if len(S) == 0:
        return {}
    lo = V[:, :2].min(0) - HOLD_SEARCH_MM - grid
    A, B, C = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]
    flat = np.abs(np.cross(B - A, C - A)[:, 2]) > 1e-12      # vertical triangles cross no column
    col, zc, _, tri = _raster(A[flat], B[flat], C[flat], lo, grid)
    tri = np.nonzero(flat)[0][tri]
    nx = int(np.ceil((V[:, 0].max() - lo[0]) / grid)) + int(2 * HOLD_SEARCH_MM / grid) + 4
    key = col[:, 1] * nx + col[:, 0]
    order = np.lexsort((zc, key))
    key, zc, tri = key[order], zc[order], tri[order]
    top = float(V[:, 2].max()) + 1.0
    comb = key * top * 4 + zc
    who = np.full(len(S), -1)
    for r in [0.0] + list(np.arange(grid, HOLD_SEARCH_MM + 1e-9, grid)):
        angs = [0.0] if r == 0 else np.linspace(0.0, 2 * np.pi, 12, endpoint=False)
        for a in angs:
            todo = who < 0
            if not todo.any():
                break
            ix = np.floor((S[:, 0] + r * np.cos(a) - lo[0]) / grid).astype(np.int64)
            iy = np.floor((S[:, 1] + r * np.sin(a) - lo[1]) / grid).astype(np.int64)
            k = iy * nx + ix
            pos = np.searchsorted(comb, k * top * 4 + S[:, 2] + 0.05)
            q = np.minimum(pos, len(key) - 1)
            hit = todo & (pos < len(key)) & (key[q] == k)
            who[hit] = own[tri[q[hit]]]
    names = [n for n, _ in sol]
    out = {n: round(float(S[who == i, 3].sum()), 1) for i, n in enumerate(names)}
    out["none"] = round(float(S[who < 0, 3].sum()), 1)
    return out


def slice_once(exe, path: Path, layer: float, supports: str, sol=None) -> dict:
    """``supports``: "none", "all" or "buildplate"; ``sol`` (the print-frame solids written to
    ``path``): also the support filament by the part it holds up (:func:`support_by_part`)."""
    out = path.with_suffix(f".{supports}.gcode")
    cmd = [exe, "--export-gcode", "--layer-height", str(layer), "--first-layer-height", str(FIRST_LAYER),
           "-o", str(out), str(path)]
    if supports != "none":
        cmd[1:1] = ["--support-material"] + (["--support-material-buildplate-only"] if supports == "buildplate" else [])
    t0 = time.perf_counter()
    r = subprocess.run(cmd, capture_output=True, text=True)
    dt = time.perf_counter() - t0
    if r.returncode != 0 or not out.exists():
        return {"ok": False, "error": (r.stderr or r.stdout)[-400:], "slice_s": round(dt, 2)}
    txt = out.read_text(errors="replace")
    cm3 = re.search(r"; filament used \[cm3\] = ([\d.]+)", txt)
    mm = re.search(r"; filament used \[mm\] = ([\d.]+)", txt)
    ratio = float(cm3.group(1)) * 1000 / float(mm.group(1)) if cm3 and mm and float(mm.group(1)) > 0 else None
    fl = _first_layer_mm3(txt, ratio) if ratio else None
    out.unlink()
    row = {"ok": True, "layers": txt.count(";LAYER_CHANGE"), "print_time_s": _time_s(txt),
           "filament_mm3": round(float(cm3.group(1)) * 1000, 1) if cm3 else None,
           "first_layer_mm3": fl, "first_layer_mm2": round(fl / FIRST_LAYER, 1) if fl is not None else None,
           "slice_s": round(dt, 2)}
    if sol is not None and ratio:
        row["support_by_part_mm3"] = support_by_part(txt, sol, ratio)
    return row


def info(exe, path: Path) -> dict:
    r = subprocess.run([exe, "--info", str(path)], capture_output=True, text=True)
    txt = r.stdout
    return {"objects": txt.count(f"[{path.name}]"),
            "parts": [int(x) for x in re.findall(r"number_of_parts =\s*(\d+)", txt)],
            "min_z": [float(x) for x in re.findall(r"min_z = ([-\d.]+)", txt)],
            "size": [[float(x) for x in m] for m in re.findall(r"size_x = ([\d.]+)\s+size_y = ([\d.]+)\s+size_z = ([\d.]+)", txt)],
            "manifold": re.findall(r"manifold = (\w+)", txt),
            "volume_mm3": [float(x) for x in re.findall(r"volume = ([\d.]+)", txt)], "exit": r.returncode}


def posed_solids(asm, R, config: bool = False):
    """The parts rotated by ``R`` (model -> print), centred on the bed and resting on z = 0;
    ``config``: each part first moved into the printed configuration (``asm.print_pose``,
    ``orient: auto_config``), else the rest configuration."""
    pose = getattr(asm, "print_pose", {}) if config else {}
    sol = [(p.name, transform_solid(p.solid, _h(R, np.zeros(3)) @ pose.get(p.name, np.eye(4))))
           for p in asm.parts if not p.solid.is_empty()]
    lo = np.min([np.asarray(s.bounding_box())[:3] for _, s in sol], axis=0)
    hi = np.max([np.asarray(s.bounding_box())[3:] for _, s in sol], axis=0)
    sh = [-(lo[0] + hi[0]) / 2, -(lo[1] + hi[1]) / 2, -lo[2]]
    return [(n, s.translate(sh)) for n, s in sol], hi - lo


def stats(asm, R, config: bool = False):
    sol, size = posed_solids(asm, R, config)
    mw = asm.profile.min_wall
    return sol, bed_stats(sol, OVERHANG_DEG, report_grid(size, mw), first_layer=min(0.2, mw / 2),
                          island_mm=island_side(asm.profile))


def pose_row(exe, asm, R, up, f: Path, title: str, layer: float, config: bool = False, by_part: bool = False) -> dict:
    """mlc's bed statistics and PrusaSlicer's three slices of the parts posed by ``R``;
    ``by_part``: also PrusaSlicer's support by the part it holds up (``all``'s
    ``support_by_part_mm3``, :func:`support_by_part`)."""
    sol, bs = stats(asm, R, config)
    f.write_bytes(threemf_bytes([(n, to_trimesh(s)) for n, s in sol], title))
    row = {"up": [round(float(x), 4) for x in up], "mlc_bed": bs.to_dict(),
           "configuration": dict(getattr(asm, "print_config", {})) if config else {},
           "mlc_parts_off_bed": sum(1 for z in bs.lowest_mm.values() if z > 0.05),
           "prusa_info": info(exe, f)}
    for k in ("none", "all", "buildplate"):
        row[k] = slice_once(exe, f, layer, k, sol if by_part and k == "all" else None)
    n, s, b = row["none"], row["all"], row["buildplate"]
    if all(x.get("ok") and x.get("filament_mm3") is not None for x in (n, s, b)):
        row["prusa_support_mm3"] = round(s["filament_mm3"] - n["filament_mm3"], 1)
        row["prusa_support_on_print_mm3"] = round(s["filament_mm3"] - b["filament_mm3"], 1)
        row["prusa_support_fraction"] = round(row["prusa_support_mm3"] / max(n["filament_mm3"], 1e-9), 3)
    return row


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--signal", default="expand")
    ap.add_argument("--gates", default=",".join(GATE_NAMES))
    ap.add_argument("--profiles", default="mjp,sla,fdm")
    ap.add_argument("-o", "--out", default=str(ROOT / "benchmarks/results/slicer_gates.json"))
    ap.add_argument("--append", action="store_true", help="keep the rows already in --out (other gates/profiles)")
    ap.add_argument("--orient", default="auto", choices=("auto", "auto_config"),
                    help="auto_config: 'estimate' and 'after' in the configuration mlc stl chooses")
    a = ap.parse_args()
    exe = shutil.which("prusa-slicer")
    if not exe:
        print("prusa-slicer is not installed (Debian: apt-get install prusa-slicer)", file=sys.stderr)
        return 1
    ver = subprocess.run([exe, "--help"], capture_output=True, text=True).stdout.split("\n")
    ver = next((x for x in ver if x.startswith("PrusaSlicer")), "?")
    commit = git_commit()
    rows = []
    if a.append and Path(a.out).exists():
        rows = json.loads(Path(a.out).read_text()).get("rows", [])
    tmp = Path(tempfile.mkdtemp(prefix="mlc_slicer_"))
    for g in a.gates.split(","):
        scene = gate_scene(g, a.signal)
        for pn in a.profiles.split(","):
            rows = [r for r in rows if not (r["gate"] == g and r["profile"] == pn and r["signal"] == a.signal
                                            and r.get("orient", "auto") == a.orient)]
            prof = load_profile(pn, {"orient": a.orient})
            t0 = time.perf_counter()
            asm, rep = export_assembly(scene, prof)
            t_build = time.perf_counter() - t0
            cfg = bool(getattr(asm, "print_pose", {}))
            row = {"gate": g, "signal": a.signal, "profile": pn, "orient": a.orient, "layer_mm": LAYER[pn], "commit": commit,
                   "configuration": dict(getattr(asm, "print_config", {})),
                   "parts": len(asm.parts), "part_volume_mm3": round(sum(float(p.solid.volume()) for p in asm.parts), 1),
                   "export_s": round(t_build, 2), "report_ok": rep.ok,
                   "goals_not_met": sorted(c.name for c in rep.checks if not c.ok and not c.blocking),
                   "report_bed": {c.name: {"ok": c.ok, "value": c.value} for c in rep.checks
                                  if c.name in ("bed_contact", "supports")},
                   "motion_trims": len(asm.motion_trims)}
            u0 = np.array([0.0, 0.0, 1.0])
            row["before"] = pose_row(exe, asm, rotation_between(u0, [0, 0, 1.0]), u0, tmp / f"{g}_{pn}_before.3mf",
                                     f"{g}_{a.signal}", LAYER[pn])
            ue = np.asarray(asm.pose_search["estimate_up"], float)
            row["estimate"] = (dict(row["before"], up=[round(float(x), 4) for x in ue]) if np.allclose(ue, u0) and not cfg
                               else pose_row(exe, asm, rotation_between(ue, [0, 0, 1.0]), ue,
                                             tmp / f"{g}_{pn}_estimate.3mf", f"{g}_{a.signal}", LAYER[pn], cfg))
            R = asm.orient[:3, :3]
            ua = R[2]
            row["after"] = (dict(row["before"], up=[round(float(x), 4) for x in ua]) if np.allclose(ua, u0) and not cfg else
                            dict(row["estimate"], up=[round(float(x), 4) for x in ua]) if np.allclose(ua, ue) else
                            pose_row(exe, asm, R, ua, tmp / f"{g}_{pn}_after.3mf", f"{g}_{a.signal}", LAYER[pn], cfg))
            rows.append(row)
            for k in ("before", "estimate", "after"):
                r, b = row[k], row[k]["mlc_bed"]
                print(f"{g:8s} {pn} {k:6s}: up {r['up']}, mlc contact {100 * b['contact_fraction']:.2f} % "
                      f"support {100 * b['support_fraction']:.1f} % ({b['support_inside_mm3']:.1f} mm3 between parts); "
                      f"prusa first layer {r['none'].get('first_layer_mm2')} mm2, support {r.get('prusa_support_mm3')} mm3 "
                      f"({r.get('prusa_support_on_print_mm3')} on the print), filament {r['none'].get('filament_mm3')}",
                      flush=True)
            Path(a.out).write_text(json.dumps({"slicer": ver, "machine": platform.platform(), "commit": commit,
                                               "note": "per pose: support_mm3 = filament with supports - without; "
                                                       "support_on_print = with supports - build plate only; "
                                                       "first_layer_mm2 = first-layer filament / 0.2 mm",
                                               "rows": rows}, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
