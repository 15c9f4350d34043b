"""A ripple-carry adder's circuit checked statically on a seeded sample of its input rows.

    python benchmarks/circuit_rows.py --width 3 --rows 8 --seed 0

The all-zero and all-one rows are always checked, plus ``--rows`` - 2 others drawn with
``--seed`` (numpy default_rng) from the rest.  Per row: every probe's bit, the joint
stretch, the smallest slab clearance (exact oriented-box test) and its pair.  Writes
benchmarks/results/circuit_rows_w<width>.json.  Times are wall seconds on this machine.
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import time
from pathlib import Path

import mlc  # noqa: F401 -- before numpy: pins OpenBLAS's kernels (mlc/__init__.py)
import numpy as np

from mlc.circuit.build import build_circuit
from mlc.logic.library import ripple_adder
from mlc.pipeline import compile_spec
from mlc.verify.circuit import verify_static

OUT = Path(__file__).resolve().parent / "results"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--width", type=int, default=3)
    ap.add_argument("--rows", type=int, default=8)
    ap.add_argument("--seed", type=int, default=0)
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
    out = []
    for row in rows:
        rep = verify_static(sc, rows=[row])
        r = rep.rows[0]
        out.append({"row": row, "ok": rep.ok, "seconds": r["seconds"], "clearance": r.get("clearance"),
                    "clearance_pair": r.get("clearance_pair"), "joint_stretch": r["joint_stretch"]})
        print(json.dumps(out[-1]), flush=True)
    git = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True,
                         cwd=Path(__file__).resolve().parent).stdout.strip()
    res = {"width": args.width, "seed": args.seed, "git": git, "load": load0, "bodies": len(sc.bodies),
           "build_s": t_build, "tight_chains": sc.meta["connector"]["tight_chains"],
           "rerouted": sc.meta["connector"].get("rerouted", []), "rows": out,
           "all_ok": all(r["ok"] for r in out),
           "min_clearance": min(r["clearance"] for r in out if r["clearance"] is not None)}
    OUT.mkdir(exist_ok=True)
    (OUT / f"circuit_rows_w{args.width}.json").write_text(json.dumps(res, indent=1))
    print(json.dumps({k: v for k, v in res.items() if k != "rows"}))


if __name__ == "__main__":
    main()
