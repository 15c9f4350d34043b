"""Read 3MF files written by ``mlc stl`` with third-party clients (issue 13: "check like an
outsider"): lib3mf, the 3MF Consortium's library, in strict mode (its warnings counted), and
PrusaSlicer's ``--info`` (size, volume, facets, manifold), each when installed.  For the
README main job's meshes (``out/circuit.3mf``, ``out/robot/robot.3mf``, ``out/nand.3mf``),
beside each file's mlc printability report when one lies next to it.

    python benchmarks/outside_reads.py OUT/circuit.3mf OUT/robot/robot.3mf OUT/nand.3mf \\
        [--label "README job, session 47"] -o benchmarks/results/outside_reads.json

Writes the JSON atomically.  Units: mm (PrusaSlicer), seconds.
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import sys
from pathlib import Path

import mlc  # noqa: F401 -- before numpy: pins OpenBLAS's kernels (mlc/__init__.py)

from mlc.io.atomic import atomic_path

HERE = Path(__file__).resolve().parent


def report_summary(mf3: Path) -> dict | None:
    """The blocking checks of the mlc report written beside ``mf3`` (``X_print.json`` for
    ``X.3mf``, or ``X.json``), if any: {check: passed}."""
    for cand in (mf3.with_name(mf3.stem + "_print.json"), mf3.with_suffix(".json")):
        if cand.exists():
            rep = json.loads(cand.read_text())
            return {"file": cand.name, "ok": rep.get("ok"),
                    "checks": {c["name"]: c["ok"] for c in rep.get("checks", []) if c.get("blocking")}}
    return None


def main(argv=None) -> int:
    sys.path.insert(0, str(HERE))
    from gitstate import commit
    from mesh_circuit import outside_reads

    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("files", nargs="+", type=Path)
    ap.add_argument("--label", default="")
    ap.add_argument("-o", "--out", type=Path, required=True)
    a = ap.parse_args(argv)
    rows = []
    for f in a.files:
        row = {"file": str(f), "bytes": f.stat().st_size, **outside_reads(f)}
        rep = report_summary(f)
        if rep is not None:
            row["mlc_report"] = rep
        rows.append(row)
        print(json.dumps(row), flush=True)
    data = {"label": a.label, "commit": commit(), "machine": platform.machine(), "cpus": os.cpu_count(),
            "files": rows}
    with atomic_path(a.out) as tmp:
        Path(tmp).write_text(json.dumps(data, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
