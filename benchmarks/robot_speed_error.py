"""Speed against error of the stiff scheme on the Tetris robot (issue 10, item 6): one row
from rest at several steps dt, one seed; the joint angles at the end and averaged over
the last ``--avg`` t0, against the run at the smallest dt (the reference) and against
the row's targets; wall time.

At kT = 1e-5 two runs with different dt follow different noise paths (the increments
are drawn per step), so the angle differences contain the thermal spread of the joints
(1.4-7 deg for the lever DOFs, docs/robot.md 3.2) on top of the discretisation error.
The time-averaged angles (mean over the last ``--avg`` t0, sampled every 5 t0) lower the
noise part.  ``--kT 0`` removes it (deterministic runs).

    python benchmarks/robot_speed_error.py OUT/robot.yaml [--rows 00 01] [--dts 0.4 0.2 0.1 0.05]
        [--time 400] [--avg 100] [--seed 0] [-o benchmarks/results/robot_speed_error.json]
    python benchmarks/robot_speed_error.py --plot benchmarks/results/robot_speed_error.json

Runs are merged into the JSON (keyed by row, dt, kT, seed, time), one at a time.
Units: t0, degrees (and rad), seconds wall.
"""
from __future__ import annotations

import argparse
import json
import math
import os
import platform
import sys
import time

import numpy as np


def run_one(scene, row: str, dt: float, T: float, avg: float, seed: int, kT: float) -> dict:
    from mlc.robot.verify import read_shape
    from mlc.sim.drive import Drive
    from mlc.sim.integrator import SimOptions, Simulation

    drives = {inp: Drive.constant(int(b)) for inp, b in zip(scene.inputs, row)}
    sim = Simulation(scene, drives, SimOptions(scheme="stiff", kT=kT, seed=seed, dt=dt))
    wall = time.perf_counter()
    samples, t, every = [], 0.0, 5.0
    while t < T - 1e-9:
        res = sim.run(every, quiet=True)
        t = res.time
        if t >= T - avg - 1e-9:
            samples.append([d["angle"] for d in read_shape(scene, sim.pos, sim.quat, row)["dofs"]])
    wall = time.perf_counter() - wall
    sh = read_shape(scene, sim.pos, sim.quat, row)
    return {"row": row, "dt": dt, "kT": kT, "seed": seed, "time_t0": round(t, 3), "wall_s": round(wall, 1),
            "quarter_turns": sh["quarter_turns"], "turns_read": [round(x, 2) for x in sh["turns"]],
            "dofs": [d["name"] for d in sh["dofs"]],
            "angle_end_deg": [round(d["angle"], 3) for d in sh["dofs"]],
            "angle_mean_deg": [round(float(x), 3) for x in np.mean(samples, 0)],
            "target_deg": [d.get("target") for d in sh["dofs"]],
            "load_1min": round(os.getloadavg()[0], 2)}


def compare(runs: list[dict]) -> list[dict]:
    """Per (row, kT, seed, time): each run's largest angle difference to the smallest-dt run
    (end and mean, deg and rad) and to the targets."""
    out = []
    keys = sorted({(r["row"], r["kT"], r["seed"], r["time_t0"]) for r in runs})
    for k in keys:
        rs = sorted([r for r in runs if (r["row"], r["kT"], r["seed"], r["time_t0"]) == k], key=lambda r: r["dt"])
        ref = rs[0]
        for r in rs:
            e_end = max(abs(a - b) for a, b in zip(r["angle_end_deg"], ref["angle_end_deg"]))
            e_mean = max(abs(a - b) for a, b in zip(r["angle_mean_deg"], ref["angle_mean_deg"]))
            e_tgt = max(abs(a - b) for a, b in zip(r["angle_mean_deg"], r["target_deg"]))
            out.append({"row": k[0], "kT": k[1], "seed": k[2], "time_t0": k[3], "dt": r["dt"], "ref_dt": ref["dt"],
                        "wall_s": r["wall_s"],
                        "max_err_end_deg": round(e_end, 3), "max_err_end_rad": round(math.radians(e_end), 4),
                        "max_err_mean_deg": round(e_mean, 3), "max_err_mean_rad": round(math.radians(e_mean), 4),
                        "max_mean_err_to_target_deg": round(e_tgt, 3)})
    return out


def plot(path: str) -> str:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    with open(path) as f:
        data = json.load(f)
    cmp_ = data["comparison"]
    fig, ax = plt.subplots(1, 2, figsize=(9, 3.6))
    for row in sorted({c["row"] for c in cmp_}):
        cs = sorted([c for c in cmp_ if c["row"] == row and c["dt"] != c["ref_dt"]], key=lambda c: c["dt"])
        if not cs:
            continue
        ax[0].plot([c["wall_s"] for c in cs], [c["max_err_mean_rad"] for c in cs], "o-", label=f"row {row}")
        for c in cs:
            ax[0].annotate(f"dt {c['dt']:g}", (c["wall_s"], c["max_err_mean_rad"]), fontsize=7)
        allc = sorted([c for c in cmp_ if c["row"] == row], key=lambda c: c["dt"])
        ax[1].plot([c["dt"] for c in allc], [c["wall_s"] for c in allc], "o-", label=f"row {row}")
    ax[0].axhline(0.05, color="grey", ls=":", lw=1)
    ax[0].set_xlabel("wall time (s)")
    ax[0].set_ylabel("largest DOF angle difference to the\nsmallest dt, time-averaged (rad)")
    ax[0].legend(fontsize=8)
    ax[1].set_xscale("log")
    ax[1].set_yscale("log")
    ax[1].set_xlabel("dt (t0)")
    ax[1].set_ylabel("wall time (s)")
    ax[1].legend(fontsize=8)
    T = cmp_[0]["time_t0"]
    fig.suptitle(f"Tetris robot, stiff scheme, {T:g} t0 from rest, kT = {cmp_[0]['kT']:g}, seed {cmp_[0]['seed']}",
                 fontsize=9)
    fig.tight_layout()
    png = path.replace(".json", ".png")
    fig.savefig(png, dpi=120)
    return png


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scene", nargs="?")
    ap.add_argument("--rows", nargs="*", default=["00", "01"])
    ap.add_argument("--dts", nargs="*", type=float, default=[0.4, 0.2, 0.1, 0.05])
    ap.add_argument("--time", type=float, default=400.0)
    ap.add_argument("--avg", type=float, default=100.0)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--kT", type=float, default=1e-5)
    ap.add_argument("--plot", default=None)
    ap.add_argument("-o", "--out", default="benchmarks/results/robot_speed_error.json")
    a = ap.parse_args(argv)
    if a.plot:
        print(plot(a.plot))
        return 0
    from mlc.scene.io import load_scene
    sc = load_scene(a.scene)
    data = {}
    if os.path.exists(a.out):
        with open(a.out) as f:
            data = json.load(f)
    runs = {(r["row"], r["dt"], r["kT"], r["seed"], r["time_t0"]): r for r in data.get("runs", [])}
    for row in a.rows:
        for dt in a.dts:
            try:
                r = run_one(sc, row, dt, a.time, a.avg, a.seed, a.kT)
            except Exception as e:             # an unstable step: recorded, not fatal
                r = {"row": row, "dt": dt, "kT": a.kT, "seed": a.seed, "time_t0": a.time, "failed": str(e)[:300]}
                print(f"row {row} dt {dt}: FAILED {e}", flush=True)
                continue
            runs[(row, dt, a.kT, a.seed, r["time_t0"])] = r
            print(f"row {row} dt {dt}: wall {r['wall_s']} s, turns {r['turns_read']}, "
                  f"mean angles {r['angle_mean_deg']}", flush=True)
            data = {"what": "Tetris robot, stiff scheme: DOF angles against dt (benchmarks/robot_speed_error.py)",
                    "scene": a.scene, "bodies": len(sc.bodies),
                    "machine": f"{platform.machine()}, {os.cpu_count()} cores, shared",
                    "units": "t0, degrees / rad, seconds wall",
                    "runs": sorted(runs.values(), key=lambda r: (r["row"], r["dt"]))}
            data["comparison"] = compare([r for r in data["runs"] if "failed" not in r])
            with open(a.out + ".tmp", "w") as f:
                json.dump(data, f, indent=1)
            os.replace(a.out + ".tmp", a.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
