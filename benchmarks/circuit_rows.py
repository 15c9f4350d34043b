"""A ripple-carry adder's circuit checked statically on a seeded sample of its input rows.

    python benchmarks/circuit_rows.py --width 3 --rows 8 --seed 0

The all-zero and all-one rows are always checked, plus ``--rows`` - 2 others drawn with
``--seed`` (numpy default_rng) from the rest.  With ``--rest NAME`` every row not yet in the
result files ``--done`` (default circuit_rows_w<width>*.json) is checked instead, and the
results are written after each row to benchmarks/results/circuit_rows_w<width>_NAME.json
(so a stopped run keeps its rows).  Per row: every probe's bit, the joint
stretch, the smallest slab clearance (exact oriented-box test) and its pair.  Writes
benchmarks/results/circuit_rows_w<width>.json.  Times are wall seconds on this machine.
"""
from __future__ import annotations

import argparse
import hashlib
import json
import os
import time
from pathlib import Path

import mlc  # noqa: F401 -- before numpy: pins OpenBLAS's kernels (mlc/__init__.py)
import numpy as np

from mlc.circuit.build import build_circuit
from mlc.io.atomic import atomic_path
from mlc.logic.library import ripple_adder
from mlc.pipeline import compile_spec
from mlc.scene.io import dump_scene
from mlc.verify.circuit import verify_static
from gitstate import commit as git_commit      # benchmarks/gitstate.py

OUT = Path(__file__).resolve().parent / "results"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--width", type=int, default=3)
    ap.add_argument("--rows", type=int, default=8)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--rest", default=None, help="check every row not in the --done files; name of the output")
    ap.add_argument("--done", nargs="*", default=None, help="result files whose rows are done (default: all of this width)")
    args = ap.parse_args()
    spec = ripple_adder(args.width)
    c = compile_spec(spec)
    load0 = os.getloadavg()[0]
    t0 = time.perf_counter()
    circ = build_circuit(c.netlist, spec)
    t_build = time.perf_counter() - t0
    sc = circ.scene
    n = len(sc.inputs)
    rest = [format(i, f"0{n}b") for i in range(1, 2 ** n - 1)]
    rng = np.random.default_rng(args.seed)
    pick = sorted(rng.choice(len(rest), size=min(len(rest), max(0, args.rows - 2)), replace=False))
    rows = ["0" * n] + [rest[i] for i in pick] + ["1" * n]
    name = f"circuit_rows_w{args.width}.json"
    if args.rest:
        done_files = ([Path(f) for f in args.done] if args.done is not None
                      else sorted(OUT.glob(f"circuit_rows_w{args.width}*.json")))
        name = f"circuit_rows_w{args.width}_{args.rest}.json"
        done = set()
        for f in done_files:
            if f.name == name:
                continue
            d = json.loads(f.read_text())
            if d.get("bodies") != len(sc.bodies):
                raise SystemExit(f"{f}: built {d.get('bodies')} bodies, this build {len(sc.bodies)}: not the same circuit")
            done |= {r["row"] for r in d["rows"]}
        rows = [format(i, f"0{n}b") for i in range(2 ** n) if format(i, f"0{n}b") not in done]
        print(f"{len(done)} rows done in {', '.join(f.name for f in done_files)}; {len(rows)} to check", flush=True)
    git = git_commit()
    out = []

    def result():
        return {"width": args.width, "seed": None if args.rest else args.seed, "git": git, "load": load0,
                "bodies": len(sc.bodies), "scene_sha256": hashlib.sha256(dump_scene(sc).encode()).hexdigest()[:16],
                "build_s": t_build, "tight_chains": sc.meta["connector"]["tight_chains"],
                "rerouted": sc.meta["connector"].get("rerouted", []), "rows": out,
                "all_ok": all(r["ok"] for r in out),
                "min_clearance": min((r["clearance"] for r in out if r["clearance"] is not None), default=None)}
    OUT.mkdir(exist_ok=True)
    for row in rows:
        rep = verify_static(sc, rows=[row])
        r = rep.rows[0]
        out.append({"row": row, "ok": rep.ok, "seconds": r["seconds"], "clearance": r.get("clearance"),
                    "clearance_pair": r.get("clearance_pair"), "joint_stretch": r["joint_stretch"]})
        print(json.dumps(out[-1]), flush=True)
        if args.rest:
            with atomic_path(OUT / name) as tmp:
                Path(tmp).write_text(json.dumps(result(), indent=1))
    res = result()
    with atomic_path(OUT / name) as tmp:
        Path(tmp).write_text(json.dumps(res, indent=1))
    print(json.dumps({k: v for k, v in res.items() if k != "rows"}))


if __name__ == "__main__":
    main()
