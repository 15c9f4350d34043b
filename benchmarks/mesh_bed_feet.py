"""The print-only feet (mlc.mesh.feet) on the library gates: bed contact and support, before and after.

    python benchmarks/mesh_bed_feet.py [--gates NAND NOR] [--signals expand] [--profiles fdm] [--slice]

Each case goes through ``export_assembly`` (what ``mlc stl`` runs, with the feet: the dense
poses, the motion trims, the feet, the orientation, the printability report).  Recorded per
(gate, signal, profile):

* ``after``: the report's ``bed_contact`` and ``supports`` (the print pose ``mlc stl`` writes,
  ``asm.orient``; its up direction in the model's frame), and the blocking checks
  (``ok``, ``failed``), the smallest gap in motion (``motion_clearance``), at rest (``min_gap``)
  and the measured walls;
* ``before``: the same parts without their feet (``asm.feet_free``), the model's z up -- the
  pose of every library gate before the feet (fdm ``orient: auto`` chose the model's z; mjp and
  sla print ``as_is``) -- by the report's own bed statistics (``mlc.mesh.printability.bed_stats``
  on the report's grid);
* ``feet_mm3``: the material the feet add, per part;
* ``holes``: the attachment holes drilled inside slabs, per part: ``round`` or ``teardrop``
  (``mlc.mesh.build.hole_kind``: across the layers of the feet's up, fdm);
* ``support_by_part`` (in ``after`` and ``before``): the support of each part's overhangs by the
  same statistics, ``{part: [overhang mm^2, support mm^3, of it between parts mm^3]}`` (which parts
  the support is for: the output lever, ``out_lo`` and ``out_hi``, gets no feet).

``--slice`` (needs ``prusa-slicer`` on PATH): the ``after`` pose is also sliced by PrusaSlicer
(``benchmarks/slicer_gates.py``'s ``pose_row``: the 3MF, slices without supports, with supports
and with supports on the build plate only): first-layer filament (about the first layer's area)
and support volume, as an outside check; with supports, also the support filament by the part
it holds up (``prusa_after["all"]["support_by_part_mm3"]``: each support extrusion of the G-code
is given to the first part above it, straight up or within 3 mm sideways, ``none`` if no part is;
PrusaSlicer's counterpart of ``support_by_part``).

Every row also gets ``prusa_before``: PrusaSlicer's figures for the same gate and profile before
the feet (the pose ``before`` of ``benchmarks/results/slicer_gates.json``: the model's z up, the
parts without feet), with that file's mlc bed contact beside them (``mlc_contact_fraction``: the
same geometry when it equals this row's ``before``).  ``--annotate`` only adds these to the rows
already in ``--out``.  ``--table`` only prints the rows of ``--out`` (those of ``--gates``,
``--signals`` and ``--profiles``) as the Markdown table of docs/printing.md, against the goals of
issue 13 (bed contact at least 20 % of the footprint; support under 10 % of the part volume, none
between parts).

Each row records ``commit`` (the HEAD it ran on, with ``mlc_dirty``: files under ``mlc/`` that
differed from it), ``export_s`` (``export_assembly``), ``slice_s`` (the three PrusaSlicer runs) and
``wall_s`` (the whole row).

Writes benchmarks/results/mesh_bed_feet.json (``--out``; ``--append`` keeps rows of other cases and
replaces, in place, the rows of the cases it runs again).
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import shutil
import sys
import tempfile
import time
import types
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))

import gitstate  # noqa: E402 (benchmarks/gitstate.py)
import numpy as np  # noqa: E402

from mlc.gates.library import GATE_NAMES, gate_scene  # noqa: E402
from mlc.io.atomic import atomic_path  # noqa: E402
from mlc.mesh.build import Part  # noqa: E402
from mlc.mesh.pipeline import export_assembly  # noqa: E402
from mlc.mesh.profiles import load_profile  # noqa: E402

RESULTS = ROOT / "benchmarks" / "results"
LAYER = {"mjp": 0.1, "sla": 0.1, "fdm": 0.2}


def _check(rep, name) -> dict:
    c = rep.check(name)
    return {"ok": c.ok, "value": c.value, "limit": c.limit, "detail": c.detail}


def _by_part(b) -> dict:
    """{part: [overhang mm^2, support mm^3, of it between parts mm^3]} of bed statistics ``b``."""
    return {n: [round(float(x), 1) for x in v] for n, v in (b.per_part or {}).items()}


def prusa_before(row: dict, ref: dict) -> dict | None:
    """PrusaSlicer's figures before the feet for ``row``'s case, from slicer_gates.json rows."""
    for r in ref.get("rows", []):
        if (r["gate"], r["signal"], r["profile"], r.get("orient", "auto")) == (row["gate"], row["signal"],
                                                                             row["profile"], "auto"):
            b = r["before"]
            return {"source": "benchmarks/results/slicer_gates.json, pose before", "commit": r.get("commit"),
                    "mlc_contact_fraction": b["mlc_bed"]["contact_fraction"],
                    "first_layer_mm2": b["none"].get("first_layer_mm2"),
                    "prusa_support_mm3": b.get("prusa_support_mm3"),
                    "prusa_support_on_print_mm3": b.get("prusa_support_on_print_mm3"),
                    "filament_mm3": b["none"].get("filament_mm3")}
    return None


def _pct(x) -> str:
    return "—" if x is None else f"{100 * x:.1f} %"


def table(rows: list) -> str:
    """The Markdown table of ``rows`` (docs/printing.md), one line a row, in the file's order."""
    head = ("| gate | muscles | profile | commit | feet mm³ | mlc bed contact (goal ≥ 20 %) | "
            "PrusaSlicer first layer mm² (of mlc's footprint) | mlc support mm³ (% of part volume; goal < 10 %) | "
            "of it between parts mm³ (goal 0) | PrusaSlicer support mm³ (% of the filament without) | "
            "of it on the print mm³ | walls | blocking checks |")
    out = [head, "|" + "---|" * head.count(" |")]
    for r in rows:
        a = r["after"]["bed"]
        pa = r.get("prusa_after") or {}
        fl = (pa.get("none") or {}).get("first_layer_mm2")
        fl_s = "—" if fl is None else f"{fl:.0f} ({_pct(fl / a['footprint_mm2'])})"
        ps = pa.get("prusa_support_mm3")
        ps_s = "—" if ps is None else f"{ps:.0f} ({_pct(pa.get('prusa_support_fraction'))})"
        po = pa.get("prusa_support_on_print_mm3")
        wt = r["wall_thickness"]
        walls = "met" if wt["ok"] else f"{wt['value']:.3f} mm < {wt['limit']:g}"
        out.append(f"| {r['gate']} | {r['signal']} | {r['profile']} | {r.get('commit') or '—'} | "
                   f"{r['feet_total_mm3']:.0f} | {_pct(a['contact_fraction'])} | {fl_s} | "
                   f"{a['support_mm3']:.0f} ({_pct(a['support_fraction'])}) | {a['support_inside_mm3']:.0f} | "
                   f"{ps_s} | {'—' if po is None else f'{po:.0f}'} | {walls} | "
                   f"{'pass' if r['ok'] else 'FAIL: ' + ', '.join(r['failed'])} |")
    return "\n".join(out)


def _git_state() -> tuple[str | None, list]:
    """The HEAD this runs on and the files under mlc/ that differ from it (benchmarks/gitstate.py)."""
    return gitstate.head(), gitstate.dirty()


def _write(path: Path, rows: list) -> None:
    ref_path = RESULTS / "slicer_gates.json"
    ref = json.loads(ref_path.read_text()) if ref_path.exists() else {}
    for r in rows:
        r["prusa_before"] = prusa_before(r, ref)
    out = {"benchmark": "mesh_bed_feet", "python": platform.python_version(), "cpus": os.cpu_count(),
           "load_average": [round(x, 2) for x in os.getloadavg()], "rows": rows}
    with atomic_path(path) as t:
        Path(t).write_text(json.dumps(out, indent=2) + "\n")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--gates", nargs="+", default=list(GATE_NAMES))
    ap.add_argument("--signals", nargs="+", default=["expand"])
    ap.add_argument("--profiles", nargs="+", default=["fdm"])
    ap.add_argument("--slice", action="store_true", help="slice the after pose with prusa-slicer")
    ap.add_argument("--out", default=str(RESULTS / "mesh_bed_feet.json"))
    ap.add_argument("--append", action="store_true")
    ap.add_argument("--annotate", action="store_true", help="only add prusa_before to the rows in --out")
    ap.add_argument("--table", action="store_true", help="only print the rows of --out as a Markdown table")
    args = ap.parse_args()
    if args.table:
        rows = [r for r in json.loads(Path(args.out).read_text())["rows"]
                if r["gate"] in args.gates and r["signal"] in args.signals and r["profile"] in args.profiles]
        print(table(rows))
        return 0
    if args.annotate:
        path = Path(args.out)
        _write(path, json.loads(path.read_text())["rows"])
        return 0
    from mlc.errors import MlcError
    try:        # bad names: one message, before any case runs
        scenes = {(g, s): gate_scene(g, s) for s in args.signals for g in args.gates}
        profiles = {p: load_profile(p) for p in args.profiles}
    except MlcError as e:
        print(f"mesh_bed_feet: {e}", file=sys.stderr)
        return 2
    from slicer_gates import pose_row, stats   # noqa: E402 (benchmarks/slicer_gates.py)
    exe = shutil.which("prusa-slicer") if args.slice else None
    if args.slice and exe is None:
        print("prusa-slicer is not on PATH: --slice needs it", file=sys.stderr)
        return 1
    path = Path(args.out)
    rows = []
    if args.append and path.exists():
        rows = json.loads(path.read_text())["rows"]
    tmp = Path(tempfile.mkdtemp(prefix="mlc_feet_"))
    for signal in args.signals:
        for name in args.gates:
            scene = scenes[(name, signal)]
            for prof in args.profiles:
                profile = profiles[prof]
                head, dirty = _git_state()
                t0 = time.perf_counter()
                asm, rep = export_assembly(scene, profile)
                wall = time.perf_counter() - t0
                R = np.asarray(asm.orient, float)[:3, :3]
                up = R.T @ np.array([0.0, 0.0, 1.0])        # the model's direction that points up
                free = types.SimpleNamespace(
                    parts=[Part(p.name, p.kind, asm.feet_free.get(p.name, p.solid), []) for p in asm.parts],
                    profile=profile)
                _, b0 = stats(free, np.eye(3))
                row = {"gate": name, "signal": signal, "profile": prof, "ok": rep.ok,
                       "failed": {c.name: c.failures[:3] for c in rep.checks if not c.ok and c.blocking},
                       "goals_not_met": sorted(c.name for c in rep.checks if not c.ok and not c.blocking),
                       "feet_mm3": asm.feet, "feet_total_mm3": round(sum(asm.feet.values()), 1),
                       "holes": {n: k for n, _, _, k in getattr(asm, "holes", [])},
                       "up": [round(float(x), 4) for x in up],
                       "after": {"bed_contact": _check(rep, "bed_contact"), "supports": _check(rep, "supports"),
                                 "bed": asm.bed.to_dict(), "support_by_part": _by_part(asm.bed)},
                       "before": {"up": [0.0, 0.0, 1.0], "bed": b0.to_dict(), "support_by_part": _by_part(b0)},
                       "motion_clearance": _check(rep, "motion_clearance"), "min_gap": _check(rep, "min_gap"),
                       "states": _check(rep, "states"), "wall_thickness": _check(rep, "wall_thickness"),
                       "notes": [n for n in rep.notes if n.startswith("feet") or "up is" in n][:4],
                       "export_s": round(wall, 1), "commit": head, "mlc_dirty": dirty}
                if exe:
                    f = tmp / f"{name}_{signal}_{prof}.3mf"
                    t1 = time.perf_counter()
                    row["prusa_after"] = pose_row(exe, asm, R, up, f, f"{name} {prof}", LAYER[prof], by_part=True)
                    row["slice_s"] = round(time.perf_counter() - t1, 1)
                row["wall_s"] = round(time.perf_counter() - t0, 1)
                key = (name, signal, prof)
                same = [i for i, r in enumerate(rows) if (r["gate"], r["signal"], r["profile"]) == key]
                if same:        # a case run again replaces its old row, in place
                    rows[same[0]] = row
                    rows = [r for i, r in enumerate(rows) if i not in same[1:]]
                else:
                    rows.append(row)
                print(json.dumps({k: row[k] for k in ("gate", "signal", "profile", "ok", "feet_total_mm3", "up")}
                                 | {"contact": [row["before"]["bed"]["contact_fraction"],
                                                row["after"]["bed"]["contact_fraction"]],
                                    "wall_s": row["wall_s"],
                                    "support": [row["before"]["bed"]["support_fraction"],
                                                row["after"]["bed"]["support_fraction"]],
                                    "motion_gap": row["motion_clearance"]["value"],
                                    "prusa": {k: row.get("prusa_after", {}).get(k) for k in
                                              ("prusa_support_mm3", "prusa_support_fraction")}}), flush=True)
                _write(path, rows)
    shutil.rmtree(tmp, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
