"""A larger step with a looser drift bound on the Tetris robot's fold (issue 10 item 6; docs/robot.md 3.4,
session 17): the same fold from rest at kT = 0 (deterministic: only the integrator's settings differ)
with the stiff scheme at its defaults (dt 0.2 t0, drift bound ``disp_acc`` 0.01 sigma) and at dt 3.2 t0,
``disp_acc`` 0.1 sigma; the DOF angles (degrees) every 100 t0 and the CPU seconds of each run.

    python benchmarks/robot_drift_probe.py OUT/robot.yaml [--time 600] [--rows 11,01]

Writes benchmarks/results/robot_drift_probe.json.  Units: t0, degrees, CPU seconds.
"""
from __future__ import annotations

import argparse
import json
import os
import platform
from pathlib import Path

import mlc  # noqa: F401 -- before numpy: pins OpenBLAS's kernels (mlc/__init__.py)

from mlc.io.atomic import atomic_path

RESULTS = Path(__file__).resolve().parent / "results"
SETTINGS = ((0.2, 0.01), (3.2, 0.1))      # (dt t0, disp_acc sigma): the defaults, then the probe


def main():
    from mlc.robot.verify import robot_meta
    from mlc.scene.io import load_scene
    from robot_euler_reference import trajectory     # the same fold from rest at kT = 0, angles every 100 t0
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scene")
    ap.add_argument("--time", type=float, default=600.0, help="t0 per run")
    ap.add_argument("--rows", default="11,01")
    a = ap.parse_args()
    sc = load_scene(a.scene)
    runs = []
    for row in a.rows.split(","):
        for dt, acc in SETTINGS:
            tr = trajectory(sc, row, "stiff", dt, a.time, 100.0, disp_acc=acc)
            r = {"row": row, "dt": dt, "disp_acc": acc, "cpu_s": round(tr["cpu_s"], 1),
                 "angles_deg_every_100t0": [[round(float(x), 3) for x in ang] for ang in tr["ang"]]}
            runs.append(r)
            print(json.dumps(r), flush=True)
    out = {"what": "Tetris robot fold at kT = 0: stiff scheme defaults against dt 3.2 t0, disp_acc 0.1 sigma",
           "scene": a.scene, "bodies": len(sc.bodies), "time_t0": a.time,
           "dofs": [d.get("name") for d in robot_meta(sc)["dofs"]],
           "machine": {"platform": platform.platform(), "cpus": os.cpu_count(), "loadavg": os.getloadavg()},
           "runs": runs}
    RESULTS.mkdir(exist_ok=True)
    with atomic_path(RESULTS / "robot_drift_probe.json") as tmp:
        Path(tmp).write_text(json.dumps(out, indent=1) + "\n")


if __name__ == "__main__":
    main()
