"""Build a robot scene with some of :mod:`mlc.robot.build`'s module constants changed, for
probes of the coupling geometry (docs/robot.md section 6), without editing the builder.

    python benchmarks/robot_build_variant.py OUT/circuit.yaml examples/tetris.robot.yaml \\
        -o /tmp/variant/robot.yaml --set CHAIN_STOPS=True SLACK_FRACTION=0.3

Each ``--set NAME=VALUE`` sets ``mlc.robot.build.NAME`` to the Python literal VALUE
(``ast.literal_eval``; the name must exist).  The scene records them in
``meta.robot.build_overrides``, so ``benchmarks/robot_overlaps.py`` and ``mlc verify``
take it like any robot scene.  Prints each chain's half units and reach fraction
(docs/robot.md 2.4).  Units: sigma, seconds wall.
"""
from __future__ import annotations

import argparse
import ast
import sys
import time
from pathlib import Path


def main(argv=None) -> int:
    import mlc.robot.build as B
    from mlc.robot.spec import load_robot
    from mlc.scene.io import dump_scene, load_scene

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("circuit")
    ap.add_argument("robot")
    ap.add_argument("-o", "--out", required=True)
    ap.add_argument("--set", nargs="*", default=[], metavar="NAME=VALUE")
    a = ap.parse_args(argv)
    over = {}
    for s in a.set:
        k, _, v = s.partition("=")
        if not hasattr(B, k):
            raise SystemExit(f"mlc.robot.build has no {k}")
        over[k] = ast.literal_eval(v)
        setattr(B, k, over[k])
    circ = load_scene(a.circuit)
    spec = load_robot(a.robot, circ)
    t = time.perf_counter()
    rob = B.build_robot(circ, spec)
    rob.scene.meta["robot"]["build_overrides"] = over
    Path(a.out).parent.mkdir(parents=True, exist_ok=True)
    with open(a.out, "w") as f:
        f.write(dump_scene(rob.scene))
    print(f"{len(rob.scene.bodies)} bodies, {rob.chains} chains of {rob.half_units} half units, "
          f"built in {time.perf_counter() - t:.1f} s; overrides {over}")
    for d in rob.scene.meta["robot"]["dofs"]:
        if "chain" in d:
            c = d["chain"]
            print(f"  {d['name']}: {c['half_units']} half units, reach fraction {c['reach_fraction']}, fan "
                  f"{c['fan_deg']}, avoid {c['avoid']}, overlap {c.get('overlap')}, margin short {c.get('margin_short')}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
