"""The folded robot's thermal mean joint angles against the step (issue 10 item 6; docs/robot.md
3.4, "Session 50"): does each scheme's seed-mean angle converge as dt -> 0, and to the same value?

An Euler reference of a thermal fold is out of reach here (about 1e8 steps of 7e-7 t0 a fold,
docs/robot.md 3.4), so the check is the one a consistent scheme must pass: its weak error falls
with dt, and two independent integrators (the stiff scheme, SK-ROCK; the linearly implicit one,
``mlc/sim/implicit.py``) approach one limit, the SDE's.  Each run is what ``mlc verify ROBOT
--dynamic --scheme S --dt DT --seeds 1`` does for one row and seed (:func:`mlc.robot.verify.verify_robot_dynamic`,
from rest at kT = 1e-5 until relaxed; the implicit scheme takes its short fold steps over the
first ROBOT_FOLD_TIME at every dt); the angle kept is each DOF's time average over the run's plateau.

    python benchmarks/robot_thermal_dt.py [--scene ROBOT.yaml] [--row 11] [--seeds 0 1 2 3 4 5]
        [--schemes implicit stiff] [--dts 0.8 0.4 0.2 0.1] [-o JSON]
    python benchmarks/robot_thermal_dt.py --plot benchmarks/results/robot_thermal_dt.json

Without ``--scene`` the per-lever Tetris robot is compiled here (``mlc compile examples/tetris.tt
--robot examples/tetris.robot.yaml --muscle-per-lever``).  Runs are merged into the output file
one by one (it resumes; each run records its commit), seed by seed so that a stopped run leaves
every (scheme, dt) with the same seeds.  The summary gives, per scheme, dt and DOF, the seed mean
and its standard error, and per scheme and DOF the weighted straight-line fit of the mean against
dt with its value at dt = 0; then the two schemes' dt = 0 values and their difference.
Units: t0 (dt, times), degrees (angles), CPU seconds (process_time).
"""
from __future__ import annotations

import argparse
import json
import math
import platform
import sys
import tempfile
import time
from pathlib import Path

import mlc  # noqa: F401 -- before numpy: pins OpenBLAS's kernels (mlc/__init__.py)

from mlc.io.atomic import atomic_path

HERE = Path(__file__).resolve().parent
RESULTS = HERE / "results"


def one_run(scene, row: str, seed: int, scheme: str, dt: float, kT: float) -> dict:
    from mlc.robot.verify import verify_robot_dynamic
    c, w = time.process_time(), time.perf_counter()
    rep = verify_robot_dynamic(scene, rows=[row], seeds=1, first_seed=seed, scheme=scheme, dt=dt, kT=kT,
                               progress=False)
    cpu, wall = time.process_time() - c, time.perf_counter() - w
    r = rep.rows[0]
    ps = r["per_seed"][0]
    return {"row": row, "seed": seed, "scheme": scheme, "dt": dt, "kT": kT, "ok": bool(r["ok"]),
            "shape_read": ps["shape_read"], "relaxed": bool(r["relaxed"]), "time_t0": float(ps["time"]),
            "mean_deg": {d["name"]: round(float(d["mean_angle"]), 4) for d in ps["dof_angles"]},
            "cpu_s": round(cpu, 2), "wall_s": round(wall, 2)}


def fit_zero(dts, means, sems):
    """Weighted least-squares line mean = a + b dt over two steps or more; returns (a, its
    standard error, b)."""
    import numpy as np
    x, y, s = (np.asarray(v, float) for v in (dts, means, sems))
    w = 1.0 / np.maximum(s, 1e-3) ** 2
    A = np.column_stack([np.ones_like(x), x])
    cov = np.linalg.inv(A.T @ (w[:, None] * A))
    a, b = cov @ (A.T @ (w * y))
    return float(a), float(math.sqrt(cov[0, 0])), float(b)


def summarise(runs: list[dict]) -> dict:
    import numpy as np
    out = {"by_step": {}, "dt0": {}, "dt0_diff": {}}
    schemes = sorted({r["scheme"] for r in runs})
    for sch in schemes:
        dts = sorted({r["dt"] for r in runs if r["scheme"] == sch}, reverse=True)
        for dt in dts:
            rs = [r for r in runs if r["scheme"] == sch and r["dt"] == dt]
            names = list(rs[0]["mean_deg"])
            a = np.array([[r["mean_deg"][n] for n in names] for r in rs])
            sem = a.std(0, ddof=1) / math.sqrt(len(rs)) if len(rs) > 1 else np.full(len(names), float("nan"))
            out["by_step"].setdefault(sch, {})[str(dt)] = {
                "seeds": sorted(r["seed"] for r in rs), "all_right": all(r["ok"] for r in rs),
                "relaxed": sum(r["relaxed"] for r in rs), "cpu_s": round(sum(r["cpu_s"] for r in rs), 1),
                "t0": round(sum(r["time_t0"] for r in rs), 1),
                "mean_deg": {n: round(float(m), 3) for n, m in zip(names, a.mean(0))},
                "sem_deg": {n: round(float(e), 3) for n, e in zip(names, sem)}}
        steps = out["by_step"][sch]
        ok = [dt for dt in steps if len(steps[dt]["seeds"]) > 1]
        if len(ok) < 2:        # a line needs two steps
            continue
        names = list(steps[ok[0]]["mean_deg"])
        for n in names:
            a, ea, b = fit_zero([float(d) for d in ok], [steps[d]["mean_deg"][n] for d in ok],
                                [steps[d]["sem_deg"][n] for d in ok])
            out["dt0"].setdefault(sch, {})[n] = {"deg": round(a, 3), "err_deg": round(ea, 3),
                                                 "slope_deg_per_t0": round(b, 3), "steps": [float(d) for d in ok]}
    if len(out["dt0"]) == 2:
        s1, s2 = sorted(out["dt0"])
        for n in out["dt0"][s1]:
            d = out["dt0"][s2][n]["deg"] - out["dt0"][s1][n]["deg"]
            e = math.hypot(out["dt0"][s1][n]["err_deg"], out["dt0"][s2][n]["err_deg"])
            out["dt0_diff"][n] = {"diff_deg": round(d, 3), "err_deg": round(e, 3),
                                  "within_2_err": abs(d) <= 2 * e, "what": f"{s2} - {s1} at dt = 0"}
    return out


def plot(path: str) -> str:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np
    data = json.loads(Path(path).read_text())
    s = data["summary"]
    names = list(next(iter(next(iter(s["by_step"].values())).values()))["mean_deg"])
    fig, axes = plt.subplots(2, 4, figsize=(14, 6.5), sharex=True)
    colors = {"implicit": "tab:blue", "stiff": "tab:orange", "euler": "tab:green"}
    for ax, n in zip(axes.ravel(), names):
        for sch, steps in s["by_step"].items():
            dts = [float(d) for d in steps]
            m = [steps[d]["mean_deg"][n] for d in steps]
            e = [steps[d]["sem_deg"][n] for d in steps]
            ax.errorbar(dts, m, yerr=e, fmt="o", color=colors.get(sch), capsize=3, label=sch)
            z = s["dt0"].get(sch, {}).get(n)
            if z:
                x = np.linspace(0, max(dts), 20)
                ax.plot(x, z["deg"] + z["slope_deg_per_t0"] * x, "-", color=colors.get(sch), lw=0.8)
                ax.errorbar([0], [z["deg"]], yerr=[z["err_deg"]], fmt="s", mfc="none", color=colors.get(sch), capsize=3)
        ax.set_title(n, fontsize=9)
        ax.set_xlabel("dt (t0)")
    axes[0, 0].set_ylabel("seed-mean angle (deg)")
    axes[1, 0].set_ylabel("seed-mean angle (deg)")
    axes[0, 0].legend(fontsize=8)
    fig.suptitle(f"{data['robot']}: row {data['row']}, kT = {data['kT']}, time-averaged DOF angles against the step "
                 f"(open squares: weighted line to dt = 0)", fontsize=10)
    fig.tight_layout()
    png = str(Path(path).with_suffix(".png"))
    fig.savefig(png, dpi=110)
    return png


def main(argv=None) -> int:
    sys.path.insert(0, str(HERE))
    from gitstate import commit
    from robot_muscle_per_lever import compile_robot

    from mlc.scene.io import load_scene
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scene", help="a compiled robot scene (default: the per-lever Tetris robot, compiled here)")
    ap.add_argument("--row", default="11")
    ap.add_argument("--seeds", nargs="*", type=int, default=[0, 1, 2, 3, 4, 5])
    ap.add_argument("--schemes", nargs="*", default=["implicit", "stiff"], choices=["implicit", "stiff", "euler"])
    ap.add_argument("--dts", nargs="*", type=float, default=[0.8, 0.4, 0.2, 0.1])
    ap.add_argument("--kT", type=float, default=1e-5)
    ap.add_argument("-o", "--out", default=str(RESULTS / "robot_thermal_dt.json"))
    ap.add_argument("--plot", metavar="JSON", help="only redraw the plot of a results file")
    a = ap.parse_args(argv)
    if a.plot:
        print("wrote", plot(a.plot))
        return 0
    with tempfile.TemporaryDirectory() as tmp:
        if a.scene:
            scene, robot = load_scene(a.scene), str(a.scene)
        else:
            scene, robot = compile_robot(["--muscle-per-lever"], Path(tmp) / "pl"), "per-lever Tetris robot"
    out = Path(a.out)
    data = json.loads(out.read_text()) if out.exists() else {"runs": []}
    done = {(r["scheme"], r["dt"], r["seed"]) for r in data["runs"] if r["row"] == a.row}
    data.update({"robot": robot, "bodies": len(scene.bodies), "row": a.row, "kT": a.kT,
                 "machine": platform.platform(), "cpus": __import__("os").cpu_count()})
    for seed in a.seeds:
        for sch in a.schemes:
            for dt in a.dts:
                if (sch, dt, seed) in done:
                    continue
                r = one_run(scene, a.row, seed, sch, dt, a.kT)
                r["commit"] = commit()
                data["runs"].append(r)
                data["summary"] = summarise(data["runs"])
                with atomic_path(out) as tmp_path:
                    Path(tmp_path).write_text(json.dumps(data, indent=1))
                print(f"seed {seed} {sch} dt={dt}: {r['shape_read']} relaxed={r['relaxed']} {r['time_t0']} t0 "
                      f"{r['cpu_s']} s CPU", flush=True)
    if data["runs"]:
        print("wrote", out, "and", plot(str(out)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
