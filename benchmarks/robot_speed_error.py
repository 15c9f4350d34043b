"""Speed against error of the stiff scheme on the Tetris robot (issue 10, item 6): rows
from rest at several steps dt, over several seeds; the joint angles at the end and averaged
over the last ``--avg`` t0, against the runs at the smallest dt (the reference) and
against the row's targets; wall time.

At kT = 1e-5 two runs with different dt follow different noise paths (the increments
are drawn per step), so one seed's angle differences contain the thermal spread of the
joints (1.4-7 deg for the lever DOFs, docs/robot.md 3.2) on top of the discretisation
error.  With several seeds per dt (``--seeds``) the comparison is of seed means: for each
DOF the difference of the seed-averaged time-averaged angle at dt to that at the
reference dt, with the error bar sqrt(sd_dt^2 / n_dt + sd_ref^2 / n_ref) (sd: the spread
over seeds, ddof 1); a difference within 2 error bars is not resolved from noise.
``--kT 0`` removes the noise (deterministic runs).  ``--scheme euler`` runs the Euler
reference (at a dt below its stability limit); a comparison's reference is then its
smallest-dt Euler run.  The scene's coupling-joint stiffness (``mlc compile --joint-k K``)
is recorded as ``joint_k``; a stiff-joint scene goes to its own file, e.g.
``-o benchmarks/results/robot_speed_error_jointk100.json``.

    python benchmarks/robot_speed_error.py OUT/robot.yaml [--rows 00 01] [--dts 0.2 0.1 0.05]
        [--seeds 0 1 2] [--time 300] [--avg 100] [--kT 1e-5] [--scheme stiff]
        [-o benchmarks/results/robot_speed_error.json]
    python benchmarks/robot_speed_error.py --plot benchmarks/results/robot_speed_error.json

Runs are merged into the JSON (keyed by row, scheme, dt, kT, seed, time), one at a time.
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

import mlc  # noqa: F401 -- before numpy: pins OpenBLAS's kernels (mlc/__init__.py)
import numpy as np

from mlc.io.atomic import atomic_path


def run_one(scene, row: str, dt: float, T: float, avg: float, seed: int, kT: float, scheme: str = "stiff") -> dict:
    from mlc.robot.verify import read_shape
    from mlc.sim.drive import Drive
    from mlc.sim.integrator import SimOptions, Simulation

    drives = {inp: Drive.constant(int(b)) for inp, b in zip(scene.inputs, row)}
    sim = Simulation(scene, drives, SimOptions(scheme=scheme, kT=kT, seed=seed, dt=dt))
    wall = time.perf_counter()
    samples, t, every = [], 0.0, 5.0
    while t < T - 1e-9:
        res = sim.run(every, quiet=True)
        t = res.time
        if t >= T - avg - 1e-9:
            samples.append([d["angle"] for d in read_shape(scene, sim.pos, sim.quat, row)["dofs"]])
    wall = time.perf_counter() - wall
    sh = read_shape(scene, sim.pos, sim.quat, row)
    return {"row": row, "scheme": scheme, "dt": dt, "kT": kT, "seed": seed, "time_t0": round(t, 3), "wall_s": round(wall, 1),
            "quarter_turns": sh["quarter_turns"], "turns_read": [round(x, 2) for x in sh["turns"]],
            "dofs": [d["name"] for d in sh["dofs"]],
            "angle_end_deg": [round(d["angle"], 3) for d in sh["dofs"]],
            "angle_mean_deg": [round(float(x), 3) for x in np.mean(samples, 0)],
            "target_deg": [d.get("target") for d in sh["dofs"]],
            "load_1min": round(os.getloadavg()[0], 2)}


def _scheme(r: dict) -> str:
    return r.get("scheme", "stiff")


def _ref_order(r: dict):
    """The reference of a comparison: the smallest-dt Euler run if there is one, else the smallest dt."""
    return (_scheme(r) != "euler", r["dt"])


def compare(runs: list[dict]) -> list[dict]:
    """Per (row, kT, seed, time): each run's largest angle difference to the smallest-dt run
    (end and mean, deg and rad) and to the targets."""
    out = []
    keys = sorted({(r["row"], r["kT"], r["seed"], r["time_t0"]) for r in runs})
    for k in keys:
        rs = sorted([r for r in runs if (r["row"], r["kT"], r["seed"], r["time_t0"]) == k], key=_ref_order)
        ref = rs[0]
        for r in rs:
            e_end = max(abs(a - b) for a, b in zip(r["angle_end_deg"], ref["angle_end_deg"]))
            e_mean = max(abs(a - b) for a, b in zip(r["angle_mean_deg"], ref["angle_mean_deg"]))
            e_tgt = max(abs(a - b) for a, b in zip(r["angle_mean_deg"], r["target_deg"]))
            out.append({"row": k[0], "kT": k[1], "seed": k[2], "time_t0": k[3], "scheme": _scheme(r), "dt": r["dt"],
                        "ref_scheme": _scheme(ref), "ref_dt": ref["dt"],
                        "wall_s": r["wall_s"],
                        "max_err_end_deg": round(e_end, 3), "max_err_end_rad": round(math.radians(e_end), 4),
                        "max_err_mean_deg": round(e_mean, 3), "max_err_mean_rad": round(math.radians(e_mean), 4),
                        "max_mean_err_to_target_deg": round(e_tgt, 3)})
    return out


def compare_seeds(runs: list[dict]) -> list[dict]:
    """Per (row, kT, time, dt): the seed means and spreads (sd over seeds, ddof 1) of every
    DOF's time-averaged and final angle, and their differences to the smallest dt's seed
    means with the error bar sqrt(sd^2/n + sd_ref^2/n_ref); ``resolved`` lists the DOFs
    whose time-averaged difference exceeds 2 error bars (deg and rad)."""
    out = []
    keys = sorted({(r["row"], r["kT"], r["time_t0"]) for r in runs})
    for k in keys:
        rk = [r for r in runs if (r["row"], r["kT"], r["time_t0"]) == k]
        dts = sorted({(_scheme(r), r["dt"]) for r in rk}, key=lambda sd: (sd[0] != "euler", sd[1]))
        stats = {}
        for dt in dts:
            rs = sorted([r for r in rk if (_scheme(r), r["dt"]) == dt], key=lambda r: r["seed"])
            m = np.array([r["angle_mean_deg"] for r in rs])
            e = np.array([r["angle_end_deg"] for r in rs])
            n = len(rs)
            sd = m.std(0, ddof=1) if n > 1 else np.full(m.shape[1], np.nan)
            sde = e.std(0, ddof=1) if n > 1 else np.full(e.shape[1], np.nan)
            stats[dt] = (n, m.mean(0), sd, e.mean(0), sde, [r["seed"] for r in rs],
                         float(np.mean([r["wall_s"] for r in rs])), rs[0]["dofs"], rs[0]["target_deg"])
        ref = stats[dts[0]]
        for dt in dts:
            n, mu, sd, mue, sde, seeds, wall, dofs, tgt = stats[dt]
            bar = np.sqrt(sd ** 2 / n + ref[2] ** 2 / ref[0])
            bare = np.sqrt(sde ** 2 / n + ref[4] ** 2 / ref[0])
            d = mu - ref[1]
            de = mue - ref[3]
            res = [dofs[i] for i in range(len(d)) if abs(d[i]) > 2 * bar[i]]
            out.append({"row": k[0], "kT": k[1], "time_t0": k[2], "scheme": dt[0], "dt": dt[1],
                        "ref_scheme": dts[0][0], "ref_dt": dts[0][1], "seeds": seeds,
                        "wall_s_mean": round(wall, 1), "dofs": dofs, "target_deg": tgt,
                        "mean_deg": [round(float(x), 3) for x in mu], "sd_seeds_deg": [round(float(x), 3) for x in sd],
                        "end_deg": [round(float(x), 3) for x in mue], "sd_end_seeds_deg": [round(float(x), 3) for x in sde],
                        "diff_mean_deg": [round(float(x), 3) for x in d], "bar_mean_deg": [round(float(x), 3) for x in bar],
                        "diff_end_deg": [round(float(x), 3) for x in de], "bar_end_deg": [round(float(x), 3) for x in bare],
                        "max_abs_diff_mean_deg": round(float(np.max(np.abs(d))), 3),
                        "max_abs_diff_mean_rad": round(math.radians(float(np.max(np.abs(d)))), 4),
                        "max_bar_mean_deg": round(float(np.nanmax(bar)), 3) if np.isfinite(bar).any() else None,
                        "resolved_2bar": res, "within_2bar": not res})
    return out


def plot(path: str) -> str:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    with open(path) as f:
        data = json.load(f)
    if data.get("seed_comparison"):
        return plot_seeds(data, path)
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


def plot_seeds(data: dict, path: str) -> str:
    """Left: per row, each DOF's seed-averaged time-averaged angle minus the reference dt's,
    with the error bar (deg); right: wall time per run against dt."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    sc = data["seed_comparison"]
    rows = sorted({c["row"] for c in sc})
    fig, ax = plt.subplots(1, len(rows) + 1, figsize=(4.2 * (len(rows) + 1), 3.8))
    marks = {0.05: "o", 0.1: "s", 0.2: "^", 0.4: "v"}
    for a, row in zip(ax, rows):
        cs = sorted([c for c in sc if c["row"] == row], key=lambda c: c["dt"])
        dofs = cs[0]["dofs"]
        x = np.arange(len(dofs))
        for j, c in enumerate(cs):
            off = (j - 0.5 * (len(cs) - 1)) * 0.18
            a.errorbar(x + off, c["diff_mean_deg"], yerr=[2 * b for b in c["bar_mean_deg"]], fmt=marks.get(c["dt"], "d"),
                       ms=4, capsize=2, lw=1, label=f"dt {c['dt']:g} ({len(c['seeds'])} seeds)")
        a.axhline(0, color="k", lw=0.5)
        for y in (math.degrees(0.05), -math.degrees(0.05)):
            a.axhline(y, color="grey", ls=":", lw=1)
        a.set_xticks(x)
        a.set_xticklabels(dofs, rotation=60, fontsize=7)
        a.set_ylabel(f"seed-mean angle - dt {cs[0]['ref_dt']:g} (deg), 2 error bars")
        a.set_title(f"row {row}, {cs[0]['time_t0']:g} t0, mean of last {data.get('avg', 100):g} t0", fontsize=8)
        a.legend(fontsize=7)
    runs = [r for r in data["runs"] if "failed" not in r]
    for row in rows:
        rr = sorted([r for r in runs if r["row"] == row], key=lambda r: r["dt"])
        ax[-1].plot([r["dt"] for r in rr], [r["wall_s"] for r in rr], "o", label=f"row {row}", alpha=0.7)
    ax[-1].set_xscale("log")
    ax[-1].set_xlabel("dt (t0)")
    ax[-1].set_ylabel("wall time per run (s)")
    ax[-1].legend(fontsize=8)
    fig.suptitle(f"Tetris robot, stiff scheme, kT = {sc[0]['kT']:g}; grey: +-0.05 rad", fontsize=9)
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
    ap.add_argument("--seeds", nargs="*", type=int, default=[0])
    ap.add_argument("--kT", type=float, default=1e-5)
    ap.add_argument("--scheme", default="stiff", choices=["stiff", "euler"],
                    help="integrator (euler: the reference; a comparison's reference is its smallest-dt Euler run "
                         "if any, else its smallest dt)")
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
    runs = {(r["row"], _scheme(r), r["dt"], r["kT"], r["seed"], r["time_t0"]): r for r in data.get("runs", [])}
    # the coupling chains' joint stiffness (mlc compile --joint-k K, k0), recorded with the results
    joint_k = float((sc.meta.get("circuit", {}).get("connector", {}) or {}).get("joint_k", 1.0))
    for seed in a.seeds:                     # seed-major: every dt of a seed before the next seed
        for row in a.rows:
            for dt in a.dts:
                try:
                    r = run_one(sc, row, dt, a.time, a.avg, seed, a.kT, a.scheme)
                except Exception as e:             # an unstable step: recorded, not fatal
                    r = {"row": row, "dt": dt, "kT": a.kT, "seed": seed, "time_t0": a.time, "failed": str(e)[:300]}
                    print(f"row {row} dt {dt} seed {seed}: FAILED {e}", flush=True)
                    continue
                r["joint_k"] = joint_k
                runs[(row, a.scheme, dt, a.kT, seed, r["time_t0"])] = r
                print(f"row {row} dt {dt} seed {seed}: wall {r['wall_s']} s, turns {r['turns_read']}, "
                      f"mean angles {r['angle_mean_deg']}", flush=True)
                data = {"what": "Tetris robot, stiff scheme: DOF angles against dt (benchmarks/robot_speed_error.py)",
                        "scene": a.scene, "bodies": len(sc.bodies), "joint_k": joint_k, "avg": a.avg,
                        "machine": f"{platform.machine()}, {os.cpu_count()} cores, shared",
                        "units": "t0, degrees / rad, seconds wall",
                        "runs": sorted(runs.values(), key=lambda r: (r["row"], _scheme(r), r["dt"], r["seed"]))}
                ok = [r for r in data["runs"] if "failed" not in r]
                data["comparison"] = compare(ok)
                data["seed_comparison"] = compare_seeds(ok)
                with atomic_path(a.out) as tmp, open(tmp, "w") as f:
                    json.dump(data, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
