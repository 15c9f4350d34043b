"""Every library gate, both muscle conventions, every printer profile: build + report.

    python benchmarks/mesh_gates.py

Writes benchmarks/results/mesh_gates.json: per (gate, signal, profile) whether the
printability report passes, the failed checks, part count and seconds (the equilibrium
poses of the four input states are solved once per gate and signal, timed separately).
"""
from __future__ import annotations

import json
import os
import platform
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from mlc.gates.library import GATE_NAMES, gate_scene  # noqa: E402
from mlc.mesh.build import build_assembly  # noqa: E402
from mlc.mesh.checks import check_assembly  # noqa: E402
from mlc.mesh.pipeline import state_poses  # noqa: E402
from mlc.mesh.profiles import load_profile  # noqa: E402

RESULTS = ROOT / "benchmarks" / "results"


def main() -> int:
    rows = []
    for signal in ("expand", "contract"):
        for name in GATE_NAMES:
            scene = gate_scene(name, signal)
            t0 = time.perf_counter()
            poses, _ = state_poses(scene)
            solve = time.perf_counter() - t0
            for prof in ("mjp", "sla", "fdm"):
                t0 = time.perf_counter()
                asm = build_assembly(scene, load_profile(prof), poses)
                rep = check_assembly(asm)
                row = {"gate": name, "signal": signal, "profile": prof, "ok": rep.ok, "parts": len(asm.parts),
                       "failed": {c.name: c.failures[:3] for c in rep.checks if not c.ok},
                       "mesh_s": round(time.perf_counter() - t0, 3), "solve_s": round(solve, 3)}
                rows.append(row)
                print(json.dumps(row), flush=True)
    out = {"benchmark": "mesh_gates", "python": platform.python_version(), "cpus": os.cpu_count(),
           "load_average": [round(x, 2) for x in os.getloadavg()],
           "passed": sum(r["ok"] for r in rows), "total": len(rows), "rows": rows}
    RESULTS.mkdir(parents=True, exist_ok=True)
    (RESULTS / "mesh_gates.json").write_text(json.dumps(out, indent=2) + "\n")
    print(f"{out['passed']}/{out['total']} pass")
    return 0


if __name__ == "__main__":
    sys.exit(main())
