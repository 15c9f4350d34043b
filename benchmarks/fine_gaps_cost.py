"""What ``FINE_GAPS`` (issue 13, session 61) costs: the time the two tests that may grow a
compound junction's stack (``mlc.mesh.build._far_clear``, ``_grown_near``) take with it and
without it, in one run, and how many stacks each build grows.

For each scene (a compiled circuit's ``circuit.yaml``, or a ``tests/data_mesh`` piece by name)
the largest mechanism is posed once (``mlc.mesh.pipeline.state_poses``; a piece's stored print
poses instead) and laid out at mjp without the final trims (``build_assembly(...,
resolve=False)``: the stacks are grown or not before the trims) ``--repeat`` times with
``FINE_GAPS`` off and on, alternating, so that both see the same machine load.  Each build
records its wall time, the wall time spent inside the two tests (wrapped timers) and the number
of compound stacks with knuckles of the minimum wall.  The ratios on / off are of the medians.

    python benchmarks/fine_gaps_cost.py --scene out/circuit.yaml --piece circuit_fine \\
        -o benchmarks/results/fine_gaps_cost_s62.json

Writes the JSON and a bar plot next to it (``.png``).  Units: seconds, mm."""
from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import mlc  # noqa: F401 -- before numpy (mlc/__init__.py)

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent / "tests"))
from gitstate import commit  # noqa: E402  (benchmarks/gitstate.py)
from case_plot import case_bars  # noqa: E402

from mlc.io.atomic import atomic_path  # noqa: E402
from mlc.mesh import build as B  # noqa: E402
from mlc.mesh.profiles import load_profile  # noqa: E402

TIMED = ("_far_clear", "_grown_near")


def _timers():
    """Wrap the two tests in ``mlc.mesh.build`` with wall-clock timers: ``(spent, restore)``."""
    spent = {name: 0.0 for name in TIMED}
    calls = {name: 0 for name in TIMED}
    orig = {name: getattr(B, name) for name in TIMED}

    def wrap(name):
        def timed(*a, **k):
            t0 = time.perf_counter()
            try:
                return orig[name](*a, **k)
            finally:
                spent[name] += time.perf_counter() - t0
                calls[name] += 1
        return timed

    for name in TIMED:
        setattr(B, name, wrap(name))

    def restore():
        for name in TIMED:
            setattr(B, name, orig[name])
    return spent, calls, restore


def _load(scene: str | None, piece: str | None):
    """``(label, scene, poses)`` of the largest mechanism of a compiled scene, or of a piece."""
    if piece is not None:
        from helpers import load_piece  # tests/helpers.py
        sc, poses = load_piece(piece)
        return piece, sc, poses
    from mlc.mesh.pipeline import split_mechanisms, state_poses
    from mlc.scene.io import load_scene
    big = max(split_mechanisms(load_scene(scene)), key=lambda m: len(m.scene.bodies)).scene
    poses, _ = state_poses(big)
    return scene, big, poses


def _build(sc, poses, fine: bool) -> dict:
    prof = load_profile("mjp")
    spent, calls, restore = _timers()
    try:
        with B.flags(FINE_GAPS=fine):
            t0 = time.perf_counter()
            asm = B.build_assembly(sc, prof, poses, reuse=True, resolve=False)
            wall = time.perf_counter() - t0
    finally:
        restore()
    stacks = [ax for ax in asm.axes if ax.joint is not None]
    grown = sum(ax.knuckle >= prof.min_wall - 1e-9 for ax in stacks)
    return {"fine_gaps": fine, "layout_s": round(wall, 3),
            "tests_s": {k: round(v, 3) for k, v in spent.items()}, "calls": dict(calls),
            "stacks": len(stacks), "grown": int(grown)}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scene", action="append", default=[], help="a compiled scene (circuit.yaml)")
    ap.add_argument("--piece", action="append", default=[], help="a tests/data_mesh piece by name")
    ap.add_argument("--repeat", type=int, default=2, help="builds of each kind per case (alternating)")
    ap.add_argument("-o", "--out", required=True)
    args = ap.parse_args(argv)
    cases = []
    for scene, piece in [(s, None) for s in args.scene] + [(None, p) for p in args.piece]:
        label, sc, poses = _load(scene, piece)
        runs = []
        for _ in range(args.repeat):
            for fine in (False, True):
                r = _build(sc, poses, fine)
                print(label, r, flush=True)
                runs.append(r)

        def med(fine, key):
            return float(np.median([r[key] if key == "layout_s" else sum(r["tests_s"].values())
                                    for r in runs if r["fine_gaps"] is fine]))
        grown = {f: sorted({r["grown"] for r in runs if r["fine_gaps"] is f}) for f in (False, True)}
        cases.append({"case": label, "bodies": len(sc.bodies), "poses": len(poses), "runs": runs,
                      "grown_off": grown[False], "grown_on": grown[True],
                      "tests_s_off": med(False, "tests"), "tests_s_on": med(True, "tests"),
                      "layout_s_off": med(False, "layout_s"), "layout_s_on": med(True, "layout_s"),
                      "tests_ratio": med(True, "tests") / max(med(False, "tests"), 1e-9),
                      "layout_ratio": med(True, "layout_s") / med(False, "layout_s")})
    out = {"benchmark": "fine_gaps_cost", "commit": commit(), "profile": "mjp", "repeat": args.repeat,
           "cases": cases}
    with atomic_path(args.out) as tmp:
        Path(tmp).write_text(json.dumps(out, indent=1) + "\n")
    case_bars(args.out, cases, [([c["tests_ratio"] for c in cases], "the two tests"),
                                ([c["layout_ratio"] for c in cases], "whole layout")],
              "time with FINE_GAPS / without", ref=1.0)
    return 0


if __name__ == "__main__":
    sys.exit(main())
