"""What session 67's clearances in motion (issue 13: ``RIM_CHAMFER``, the knuckle rims that face
across a compound junction's joint point chamfered; ``HOST_CUT_MARGIN``, the host body trimmed a
clearance farther about the first pin; ``CLOSE_STROKES``, bodies that come within the clearance on
the way to a state trimmed as the meeting ones) change on compiled circuits and robots, and what
they cost; and session 68's ``owner_margin`` (``OWNER_CUT_MARGIN``: the hinge's other bodies, the
stack's owner, trimmed with ``HOST_CUT_MARGIN`` too), which the pairs left after session 67 ask for,
and session 68's build (``JOINT_STROKES``: a body near a joint part not its own trimmed as well);
and session 69's (``CAP_END_CUT``: a compound junction's one-sided yoke trims its body a knuckle gap
past the joint part's end cap; ``s69_cap`` without ``CLIP_NEAR_PLATES``, a yoke plate off its slab's
layer stopped short of another body).

Each case (a compiled scene's largest mechanism posed by ``mlc.mesh.pipeline.state_poses``, or a
``tests/data_mesh`` piece with its stored print poses) is built at mjp as ``mlc stl`` builds it
(``build_assembly(..., reuse=True)``) once per variant in one run (``--variants``; by default as
session 66 built it, the three flags off, and with the defaults), alternating the order per case so
the builds see the same load, and checked (``check_assembly``, with the
wall measure unless ``--no-walls``).  Recorded per build: its seconds and the check's, every check's
result, ``motion_clearance``'s pairs under the clearance by kind (``coarse_clearance.kind_of``) with
the smallest gap, and the wall measure's thin regions.

    python benchmarks/rim_chamfer.py --piece circuit_junction --piece robot_g2 --piece robot_wrist \\
        --scene out/circuit.yaml -o benchmarks/results/rim_chamfer_s67.json
    python benchmarks/rim_chamfer.py --piece circuit_twist --piece robot_wrist --variants s67 owner_margin \\
        -o benchmarks/results/rim_chamfer_s68_owner.json
    python benchmarks/rim_chamfer.py --piece robot_plates --piece robot_skel --piece circuit_g1 \
        --piece robot_g2 --variants s68 s69 -o benchmarks/results/rim_chamfer_s69_pieces.json
    python benchmarks/rim_chamfer.py --piece robot_skel --piece robot_plates --piece robot_g2 \
        --piece circuit_g1 --variants s69_cap s69 -o benchmarks/results/rim_chamfer_s69_plates.json

Writes the JSON and a bar plot next to it (``.png``).  Units: seconds, mm."""
from __future__ import annotations

import argparse
import json
import sys
import time
from collections import Counter
from pathlib import Path

import mlc  # noqa: F401 -- before numpy (mlc/__init__.py)


HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent / "tests"))
from coarse_clearance import kind_of  # noqa: E402
from fine_gaps_cost import _load  # noqa: E402
from gitstate import commit  # noqa: E402
from case_plot import case_bars  # noqa: E402

from mlc.io.atomic import atomic_path  # noqa: E402
from mlc.mesh import build as B  # noqa: E402
from mlc.mesh import checks as C  # noqa: E402
from mlc.mesh.profiles import load_profile  # noqa: E402

VARIANTS = {"s66": {"RIM_CHAMFER": 0.0, "HOST_CUT_MARGIN": 0.0, "CLOSE_STROKES": False, "JOINT_STROKES": False},
            "s67": {"JOINT_STROKES": False},
            # session 68: the hinge's other bodies (the stack's owner) trimmed with the margin too (on
            # session 67's build), and session 68's build (JOINT_STROKES)
            "owner_margin": {"OWNER_CUT_MARGIN": True, "JOINT_STROKES": False},
            # session 69: the one-sided yoke's trim past the joint part's end cap (CAP_END_CUT)
            "s68": {"CAP_END_CUT": False}, "s69_cap": {"CLIP_NEAR_PLATES": False}, "s69": {}}
LABELS = {"s66": "session 66's build", "s67": "session 67's", "owner_margin": "the owner trimmed with the margin",
          "s68": "session 68's", "s69_cap": "session 69's cap trim alone", "s69": "session 69's"}


def _run(sc, poses, flags: dict, walls: bool) -> dict:
    with B.flags(**flags):
        t0 = time.perf_counter()
        asm = B.build_assembly(sc, load_profile("mjp"), poses, reuse=True)
        build_s = time.perf_counter() - t0
        t0 = time.perf_counter()
        rep = C.check_assembly(asm, walls=walls)
        check_s = time.perf_counter() - t0
    mc = rep.check("motion_clearance")
    pairs = sorted({f.split(": ")[1] for f in mc.failures})
    out = {"flags": flags, "build_s": round(build_s, 2), "check_s": round(check_s, 2),
           "checks": {ch.name: {"ok": ch.ok, "blocking": ch.blocking, "value": ch.value,
                                 "failures": len(ch.failures)} for ch in rep.checks},
           "clearance_smallest_mm": mc.value, "pairs_under_clearance": len(pairs),
           "pose_pairs_under_clearance": len(mc.failures),
           "kinds": dict(Counter(kind_of(p) for p in pairs).most_common()), "pairs": pairs[:300]}
    if walls:
        wt = rep.check("wall_thickness")
        out["thin_regions"] = len(wt.failures)
        out["thinnest_mm"] = wt.value
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scene", action="append", default=[], help="a compiled scene (circuit.yaml, robot.yaml)")
    ap.add_argument("--piece", action="append", default=[], help="a tests/data_mesh piece by name")
    ap.add_argument("--no-walls", action="store_true", help="skip the wall measure")
    ap.add_argument("--variants", nargs="+", default=["s66", "s67"], choices=list(VARIANTS),
                    help="which builds (default s66 s67; each against the first named, one alone records no comparison)")
    ap.add_argument("-o", "--out", required=True)
    args = ap.parse_args(argv)
    cases = []
    for scene, piece in [(None, p) for p in args.piece] + [(s, None) for s in args.scene]:
        label, sc, poses = _load(scene, piece)
        runs = {}
        names = [v for v in VARIANTS if v in args.variants]
        order = names if len(cases) % 2 == 0 else names[::-1]
        for name in order:
            runs[name] = _run(sc, poses, VARIANTS[name], not args.no_walls)
            r = runs[name]
            print(label, name, {k: r[k] for k in ("build_s", "check_s", "pairs_under_clearance",
                                                  "clearance_smallest_mm", "kinds")},
                  "thin", r.get("thin_regions"), flush=True)
        case = {"case": label, "bodies": len(sc.bodies), "poses": len(poses), "runs": runs}
        for v in runs:
            case[f"pairs_{v}"] = runs[v]["pairs_under_clearance"]
        ref = runs[names[0]]                       # each other build against the first named
        for v in names[1:]:
            ch = runs[v]
            case.update({f"build_ratio_{v}": ch["build_s"] / ref["build_s"],
                         f"blocking_same_{v}": all(ref["checks"][k]["ok"] == ch["checks"][k]["ok"]
                                                   for k in ref["checks"] if ref["checks"][k]["blocking"])})
        cases.append(case)
    out = {"benchmark": "rim_chamfer", "commit": commit(), "profile": "mjp", "cases": cases}
    with atomic_path(args.out) as tmp:
        Path(tmp).write_text(json.dumps(out, indent=1) + "\n")
    case_bars(args.out, cases, [([max(c.get(f"pairs_{v}", 0), 0.5) for c in cases], LABELS[v])
                                for v in VARIANTS if v in args.variants],
              "pairs of parts under the clearance", log=True, size=(7, 3.5))
    return 0


if __name__ == "__main__":
    sys.exit(main())
