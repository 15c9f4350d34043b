"""Scaling of the oriented-box overlap test (mlc.verify.overlap.clearance).

    python benchmarks/overlap_scale.py

Scenes: copies of the contracting NAND gate (8 bodies, 17 bonds) on a cubic grid 4 sigma
apart, from 8 to ~10,000 bodies; each is timed (best of 3) and, up to 1,000 bodies,
compared with a brute-force evaluation over all box pairs in the same run (speed ratio
and agreement of the smallest clearance).  Writes benchmarks/results/overlap_scale.json
and overlap_scale.png.
"""
from __future__ import annotations

import json
import os
import platform
import sys
import time
from pathlib import Path

import mlc  # noqa: F401 -- before numpy: pins OpenBLAS's kernels (mlc/__init__.py)
import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from mlc.gates.library import gate_scene  # noqa: E402
from mlc.scene.model import Body, Bond, Scene  # noqa: E402
from mlc.verify.overlap import _world_boxes, box_separation, clearance  # noqa: E402

RESULTS = ROOT / "benchmarks" / "results"


def tiled(n_gates: int, spacing: float = 4.0) -> Scene:
    g = gate_scene("NAND", "contract")
    k = int(np.ceil(n_gates ** (1 / 3)))
    bodies, bonds = [], []
    for t in range(n_gates):
        off = spacing * np.array([t % k, (t // k) % k, t // (k * k)], float)
        bodies += [Body(f"g{t}_{b.name}", b.position + off, b.orientation, b.boxes, b.sites) for b in g.bodies]
        bonds += [Bond(f"g{t}_{b.name}", f"g{t}_{b.a}", f"g{t}_{b.b}", b.k, b.rest, b.tolerance, b.kind,
                       f"g{t}_{b.joint}") for b in g.bonds]
    return Scene(f"tiled_{n_gates}", bodies, bonds)


def brute(scene: Scene) -> float:
    """All box pairs of different bodies, no broad phase, no hinge-contact rule: the
    deepest interpenetration (separating-axis test over every pair)."""
    pos = np.array([b.position for b in scene.bodies])
    quat = np.array([b.orientation for b in scene.bodies])
    C, A, H, B = _world_boxes(scene, pos, quat)
    i, j = np.triu_indices(len(C), 1)
    keep = B[i] != B[j]
    i, j = i[keep], j[keep]
    out = np.inf
    for x in range(0, len(i), 4096):
        a, b = i[x:x + 4096], j[x:x + 4096]
        out = min(out, box_separation(C[a], A[a], H[a], C[b], A[b], H[b]).min())
    return float(out)


def main() -> int:
    rows = []
    for n_gates in (1, 8, 27, 125, 343, 729, 1250):
        s = tiled(n_gates)
        ts = []
        for _ in range(3):
            t0 = time.perf_counter()
            r = clearance(s)
            ts.append(time.perf_counter() - t0)
        row = {"bodies": len(s.bodies), "boxes": sum(len(b.boxes) for b in s.bodies), "seconds": min(ts),
               "min_clearance": r.min_clearance, "overlapping_pairs": len(r.overlaps), "box_pairs": r.pairs_tested}
        if len(s.bodies) <= 1000:
            t0 = time.perf_counter()
            bmin = brute(s)
            row["brute_seconds"] = time.perf_counter() - t0
            row["speedup"] = row["brute_seconds"] / row["seconds"]
            # raw (no hinge rule) deepest overlap agrees with clearance(skip_joined_contact=False)
            row["brute_min"] = bmin
            row["raw_min"] = clearance(s, skip_joined_contact=False).min_clearance
        rows.append(row)
        print(json.dumps(row), flush=True)
    out = {"benchmark": "overlap_scale", "python": platform.python_version(), "cpus": os.cpu_count(),
           "load_average": [round(x, 2) for x in os.getloadavg()], "rows": rows}
    RESULTS.mkdir(parents=True, exist_ok=True)
    (RESULTS / "overlap_scale.json").write_text(json.dumps(out, indent=2) + "\n")
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(5, 3.5))
    ax.loglog([r["bodies"] for r in rows], [r["seconds"] for r in rows], "o-", label="clearance()")
    br = [r for r in rows if "brute_seconds" in r]
    ax.loglog([r["bodies"] for r in br], [r["brute_seconds"] for r in br], "s--", label="all box pairs (SAT only)")
    ax.set_xlabel("bodies")
    ax.set_ylabel("seconds")
    ax.legend()
    ax.set_title("oriented-box overlap test")
    fig.tight_layout()
    fig.savefig(RESULTS / "overlap_scale.png", dpi=120)
    return 0


if __name__ == "__main__":
    sys.exit(main())
