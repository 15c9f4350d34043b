"""``mlc stl``: printable meshes (STL, 3MF, one STL per part) with a printability report.

    mlc stl NAND --signal expand --profile mjp -o nand.stl [--3mf nand.3mf] [--parts DIR] [--json] [--force]
    mlc stl scene.yaml --profile fdm --clearance 0.5 -o x.stl

The first argument is a library gate name or a scene file.  The report is printed on
every export (``--json``: as JSON on stdout); a failed check is an error (exit 2) and
nothing is written, unless ``--force``.
"""
from __future__ import annotations

import json
import sys
from pathlib import Path


def register(sub):
    p = sub.add_parser("stl", help="write printable meshes (STL/3MF) of a gate or scene, with a printability report",
                       description=__doc__.split("\n\n")[0])
    p.add_argument("target", help="a library gate name (NAND, AND, ...) or a scene file (.yaml)")
    p.add_argument("--signal", default="expand", choices=("expand", "contract"),
                   help="muscle convention of a library gate (default expand)")
    p.add_argument("--profile", default="mjp", help="printer profile: mjp, sla, fdm or a profile file (default mjp)")
    p.add_argument("-o", "--output", help="STL of the whole assembly (all parts, printed in one piece)")
    p.add_argument("--3mf", dest="threemf", metavar="FILE", help="3MF with one named part per body (mm)")
    p.add_argument("--parts", metavar="DIR", help="also write one STL per part into DIR")
    p.add_argument("--json", action="store_true", help="print the report as JSON")
    p.add_argument("--report", metavar="FILE", help="also write the JSON report to FILE")
    p.add_argument("--force", action="store_true", help="write the files even if a check fails")
    p.add_argument("--no-states", action="store_true",
                   help="do not pose the logic states (faster; the states check then fails)")
    g = p.add_argument_group("profile overrides (mm)")
    g.add_argument("--sigma-mm", type=float, help="sigma (muscle rest length) in mm")
    g.add_argument("--clearance", type=float, help="hinge clearance and minimum gap between parts")
    g.add_argument("--knuckle-gap", type=float, help="axial gap between consecutive knuckles")
    g.add_argument("--slab-thickness", type=float, help="printed slab thickness")
    g.add_argument("--min-wall", type=float, help="minimum wall")
    g.add_argument("--min-feature", type=float, help="minimum feature (knuckle length, holes)")
    g.add_argument("--pin-diameter", type=float, help="hinge pin diameter")
    g.add_argument("--segments", dest="circular_segments", type=int, help="polygon segments per circle")
    g.add_argument("--orient", choices=("as_is", "axes_flat", "auto", "auto_config"),
                   help="print orientation (auto: least support, then most bed contact; auto_config: "
                        "also the configuration of the mechanism)")
    g.add_argument("--pin", choices=("pin", "cone"), help="hinge pins: a straight pin or 45 degree cone pins")
    p.set_defaults(func=run)


def load_target(target: str, signal: str):
    """A library gate by name, else a scene file."""
    from mlc.errors import MlcError
    path = Path(target)
    if path.suffix.lower() in (".yaml", ".yml", ".json") or path.exists():
        from mlc.scene.io import load_scene
        return load_scene(path)
    from mlc.gates.library import GATE_NAMES, gate_scene
    if target.upper() in GATE_NAMES:
        return gate_scene(target.upper(), signal)
    raise MlcError(f"{target!r} is neither a library gate nor a scene file", "TARGET",
                   f"use one of {', '.join(GATE_NAMES)} or a scene file")


def run(args) -> int:
    from mlc.errors import MlcError
    from mlc.io.outputs import Outputs
    from mlc.io.progress import Progress
    from mlc.mesh.export import declare_outputs, part_meshes, write_staged
    from mlc.mesh.pipeline import export_assembly
    from mlc.mesh.profiles import load_profile

    overrides = {k: getattr(args, k) for k in ("sigma_mm", "clearance", "knuckle_gap", "slab_thickness",
                                              "min_wall", "min_feature", "pin_diameter", "circular_segments",
                                              "orient", "pin")}
    prof = load_profile(args.profile, overrides)
    scene = load_target(args.target, args.signal)
    check_resources(scene, prof, {k: "--" + ("segments" if k == "circular_segments" else k.replace("_", "-"))
                                  for k, v in overrides.items() if v is not None})
    inputs = [p for p in (args.target, args.profile) if p and Path(p).exists()]
    outs = Outputs(inputs=inputs)
    files = declare_outputs(outs, args.output, args.threemf, args.parts)
    rep_out = outs.file(args.report, "--report", suffixes=(".json",))
    with outs:              # every output location checked before the meshes are built; all or none
        # a library gate takes about 5 s; a circuit of many gates minutes (quiet when not a terminal)
        from mlc.mesh.profiles import estimate_seconds
        with Progress(f"mlc stl: building and checking the parts of {scene.name}",
                      expect=estimate_seconds(prof, scene)):
            asm, report = export_assembly(scene, prof, solve=not args.no_states)
        report.outputs = []
        if report.ok or args.force:
            if any(f is not None for f in files):
                report.outputs = write_staged(part_meshes(asm), scene.name, *files)
            if rep_out is not None:
                rep_out.write_text(json.dumps(report.to_dict(), indent=2) + "\n")
                report.outputs.append(str(rep_out.path))
        _print_report(report, args)
        if not report.ok and not args.force:
            failed = [c.name for c in report.checks if not c.ok and c.blocking]
            raise MlcError(f"printability checks failed: {', '.join(failed)}; nothing written", args.target,
                           "see the report above, change the profile, or use --force")
    if not args.json:
        for o in outs.written:
            print(f"wrote {o}")
    if not report.ok:
        failed = [c.name for c in report.checks if not c.ok and c.blocking]
        sys.stderr.write(f"mlc: warning: printability checks failed ({', '.join(failed)}); written anyway "
                         f"(--force)\n")
    return 0


def _print_report(report, args) -> None:
    if args.json:
        print(json.dumps(report.to_dict(), indent=2))
    else:
        print(report.text())


def check_resources(scene, prof, options=None) -> None:
    """Refuse, before any work, a profile that does not fit the scene or would need too much memory
    (:func:`mlc.mesh.profiles.check_against_scene`); ``options``: field -> the option that set it."""
    from mlc.mesh.profiles import check_against_scene
    check_against_scene(prof, scene, "--profile", options)
