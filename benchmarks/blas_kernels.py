"""Circuit builds against OpenBLAS's kernels (docs/circuits.md, "Reproducibility").

    python benchmarks/blas_kernels.py

Builds examples/full_adder.expr at --joint-k 100 in a fresh process per kernel choice:
OPENBLAS_CORETYPE unset (mlc's pin applies) and forced to Haswell, SkylakeX and Sandybridge
(mlc keeps a user's setting).  Records bodies, half units and the scene text's sha256 with
``meta.source`` made relative.  Writes benchmarks/results/blas_kernels.json.
"""
from __future__ import annotations

import json
import os
import platform
import subprocess
import sys
from pathlib import Path

from mlc.io.atomic import atomic_path
from gitstate import commit as git_commit      # benchmarks/gitstate.py

ROOT = Path(__file__).resolve().parents[1]
CODE = """
import hashlib, json, mlc, sys
from mlc.circuit.build import CircuitOptions
from mlc.pipeline import build, compile_spec, load
from mlc.scene.io import dump_scene
sc = build(compile_spec(load(sys.argv[1])), options=CircuitOptions(joint_k=100.0)).circuit.scene
sc.meta["source"] = "examples/full_adder.expr"
import os
print(json.dumps({"bodies": len(sc.bodies), "half_units": sc.meta["connector"].get("half_units"),
                  "sha256": hashlib.sha256(dump_scene(sc).encode()).hexdigest()[:16],
                  "coretype_seen": os.environ.get("OPENBLAS_CORETYPE")}))
"""


def main() -> int:
    rows = []
    for ct in (None, "Haswell", "SkylakeX", "Sandybridge"):
        env = {k: v for k, v in os.environ.items() if k != "OPENBLAS_CORETYPE"}
        if ct:
            env["OPENBLAS_CORETYPE"] = ct
        out = subprocess.run([sys.executable, "-c", CODE, str(ROOT / "examples" / "full_adder.expr")], env=env,
                             capture_output=True, text=True, check=True).stdout.strip().splitlines()[-1]
        r = {"OPENBLAS_CORETYPE": ct or "unset (mlc pins)", **json.loads(out)}
        rows.append(r)
        print(r, flush=True)
    git = git_commit()
    res = {"what": "full adder at joint_k 100 built under each OpenBLAS kernel choice", "git": git,
           "machine": {"platform": platform.platform(), "cpus": os.cpu_count()}, "rows": rows}
    with atomic_path(ROOT / "benchmarks" / "results" / "blas_kernels.json") as tmp:
        Path(tmp).write_text(json.dumps(res, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
