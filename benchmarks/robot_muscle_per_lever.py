"""The Tetris robot with a muscle per input lever against the default build (issue 10 item 6;
docs/robot.md 3.4, "Session 46"): both compiled here from ``examples/tetris.tt`` and
``examples/tetris.robot.yaml`` (``mlc compile --robot``, and the same with
``--muscle-per-lever``), then every row and seed verified exactly as ``mlc verify ROBOT
--dynamic`` does (:func:`robot_dynamic.run_one` at mlc.robot.verify's step, drift bound and
tau: from rest at kT = 1e-5, stiff scheme, until relaxed).  The two builds alternate run by
run in one process, so the machine's load falls on both alike; the cost ratio is of CPU
seconds over the same (row, seed) runs.

Other builds: ``per_lever_k10`` (``--joint-k 10``), ``per_lever_chain`` (session 46's per-lever
robot: u3_up carried by a chain, ``COUPLINGS``) and ``per_lever_tau50`` (the per-lever robot
verified with ``--tau 50``: runs of at least 150 t0, ``TAUS``), ``per_lever_implicit`` and
``default_implicit`` (those robots verified with the linearly implicit scheme, ``SCHEMES``;
compare with ``--ref per_lever``).

What it records, per build: bodies, every run's shape and relax time and CPU; per row and
DOF the seed mean of the time-averaged angle, and the per-lever build's difference to the
default with the error bar sqrt(sd^2/n + sd_ref^2/n) of the two seed spreads.

    python benchmarks/robot_muscle_per_lever.py [--rows 00 01 10 11] [--seeds 0 1 2]
        [--builds default per_lever] [--ref default]
    python benchmarks/robot_muscle_per_lever.py --plot benchmarks/results/robot_muscle_per_lever.json

Writes benchmarks/results/robot_muscle_per_lever.json (merged run by run, so it resumes; each run
records the commit it ran at) and .png.  The implicit builds take the verifier's steps
(:func:`mlc.robot.verify.fold_step`: short ones over the fold's first ROBOT_FOLD_TIME t0, session 49).
Units: t0 (times), degrees (angles), CPU seconds.
"""
from __future__ import annotations

import argparse
import json
import math
import os
import platform
import sys
import tempfile
from pathlib import Path

import mlc  # noqa: F401 -- before numpy: pins OpenBLAS's kernels (mlc/__init__.py)

from mlc.io.atomic import atomic_path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
RESULTS = HERE / "results"
BUILDS = {"default": [], "per_lever": ["--muscle-per-lever"],
          "per_lever_k10": ["--muscle-per-lever", "--joint-k", "10"],     # name: mlc compile flags
          "per_lever_chain": ["--muscle-per-lever"],
          "per_lever_tau50": ["--muscle-per-lever"],
          "per_lever_implicit": ["--muscle-per-lever"], "default_implicit": []}
# builds verified with their own relaxation time tau (t0; the others: mlc.robot.verify.ROBOT_TAU),
# as `mlc verify --dynamic --tau 50` would (the runs last at least 3 tau)
TAUS = {"per_lever_tau50": 50.0}
# builds verified with another integrator (the others: the stiff scheme, SK-ROCK, the verifier's default);
# "implicit" is the linearly implicit scheme of mlc/sim/implicit.py (session 48), at the same dt and drift bound
SCHEMES = {"per_lever_implicit": "implicit", "default_implicit": "implicit"}
# builds whose robot file sets some DOFs' coupling: per_lever_chain is session 46's per-lever robot,
# u3_up (= y) carried by a chain from y's source instead of a muscle of its own (session 47)
COUPLINGS = {"per_lever_chain": {"u3_up": "lever"}}
GOAL_CPU_S = 120.0          # issue 10: 4 rows x 3 seeds in under 2 minutes on one core


def compile_robot(flags: list[str], out: Path, couplings: dict | None = None):
    """``mlc compile examples/tetris.tt --robot examples/tetris.robot.yaml`` (plus ``flags``)
    into ``out``; the robot scene.  ``couplings`` ({dof name: coupling}): a copy of the robot
    file with those DOFs' ``coupling`` set is compiled instead."""
    import yaml

    from mlc.cli import main
    from mlc.scene.io import load_scene
    robot = ROOT / "examples" / "tetris.robot.yaml"
    if couplings:
        data = yaml.safe_load(robot.read_text())
        for d in data["dofs"]:
            name = f"u{d['unit']}_{d['side']}"
            if name in couplings:
                d["coupling"] = couplings[name]
        out.mkdir(parents=True, exist_ok=True)
        robot = out / "tetris.robot.yaml"
        robot.write_text(yaml.safe_dump(data, sort_keys=False))
    rc = main(["compile", str(ROOT / "examples" / "tetris.tt"), "--robot", str(robot), "-o", str(out), *flags])
    if rc != 0:
        raise SystemExit(f"mlc compile {' '.join(flags)} exited {rc}")
    return load_scene(out / "robot.yaml")


def compare(runs: list[dict], ref_name: str = "default") -> dict:
    """Per build: bodies, all right?, CPU; each other build against ``ref_name``: the CPU ratio over
    the (row, seed) runs both made, and per row and DOF the seed means of the time-averaged angles
    and their difference with its error bar (degrees)."""
    import numpy as np
    out = {"reference": ref_name, "builds": {}, "angle_diffs": {}, "cpu_ratio_vs_reference": {},
           "largest_angle_diff": {}}
    for name in BUILDS:
        rs = [r for r in runs if r["build"] == name]
        if not rs:
            continue
        out["builds"][name] = {"runs": len(rs), "bodies": rs[0]["bodies"], "all_right": all(r["ok"] for r in rs),
                               "relaxed": sum(bool(r["relaxed"]) for r in rs),
                               "cpu_s": round(sum(r["cpu_s"] for r in rs), 1),
                               "wall_s": round(sum(r["wall_s"] for r in rs), 1),
                               "t0": round(sum(r["time_t0"] for r in rs), 1),
                               "cpu_per_t0_s": round(sum(r["cpu_s"] for r in rs) / sum(r["time_t0"] for r in rs), 4),
                               "worst_clearance_end": min(r["clearance_end"] for r in rs)}
    ref = {(r["row"], r["seed"]): r for r in runs if r["build"] == ref_name}
    for name in [n for n in out["builds"] if n != ref_name]:
        mine = {(r["row"], r["seed"]): r for r in runs if r["build"] == name}
        both = sorted(set(ref) & set(mine))
        if not both:
            continue
        out["cpu_ratio_vs_reference"][name] = {"ratio": round(sum(ref[k]["cpu_s"] for k in both) /
                                                              sum(mine[k]["cpu_s"] for k in both), 2),
                                               "pairs": len(both)}
        largest = (0.0, None)
        for row in sorted({k[0] for k in both}):
            keys = [k for k in both if k[0] == row]
            if len(keys) < 2:
                continue
            for j, d in enumerate(ref[keys[0]]["dof_angles"]):
                a = np.array([ref[k]["dof_angles"][j]["mean_angle"] for k in keys])
                b = np.array([mine[k]["dof_angles"][j]["mean_angle"] for k in keys])
                diff = float(b.mean() - a.mean())
                bar = math.sqrt(a.std(ddof=1) ** 2 / len(a) + b.std(ddof=1) ** 2 / len(b))
                out["angle_diffs"].setdefault(name, {}).setdefault(row, {})[d["name"]] = {
                    "reference_deg": round(float(a.mean()), 3), "deg": round(float(b.mean()), 3),
                    "diff_deg": round(diff, 3), "bar_deg": round(bar, 3), "resolved": abs(diff) > 2 * bar}
                if abs(diff) > abs(largest[0]):
                    largest = (diff, f"{row} {d['name']} ({diff:+.2f} +- {bar:.2f} deg)")
        out["largest_angle_diff"][name] = largest[1]
    for name, b in out["builds"].items():       # how far the shapes sit from the targets (seed means)
        rs = [r for r in runs if r["build"] == name]
        b["worst_time_averaged_dof_error_deg"] = max(r["max_dof_mean_error_deg"] for r in rs)
    return out


def plot(path: str) -> str:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    data = json.loads(Path(path).read_text())
    runs = data["runs"]
    rows = sorted({r["row"] for r in runs})
    names = list(data["summary"]["builds"])
    colors = dict(zip(BUILDS, ("tab:gray", "tab:blue", "tab:orange", "tab:green", "tab:purple", "tab:red",
                               "tab:brown")))
    wid = 0.8 / len(names)
    fig, ax = plt.subplots(1, 2, figsize=(10, 4))
    for i, name in enumerate(names):
        cpu = [sum(r["cpu_s"] for r in runs if r["build"] == name and r["row"] == row) for row in rows]
        ax[0].bar([k + wid * i for k in range(len(rows))], cpu, wid, color=colors.get(name),
                  label=f"{name} ({data['summary']['builds'][name]['bodies']} bodies)")
    ax[0].set_xticks([k + 0.4 - 0.5 * wid for k in range(len(rows))], rows)
    ax[0].set_xlabel("row (y b)")
    ax[0].set_ylabel("CPU s, all seeds")
    ax[0].legend()
    ax[0].set_title("dynamic verification, CPU per row")
    tot = [data["summary"]["builds"][n]["cpu_s"] for n in names]
    ax[1].bar(names, tot, color=[colors.get(n) for n in names])
    ax[1].axhline(GOAL_CPU_S, color="tab:red", ls="--", label="issue 10 goal (120 s)")
    ax[1].set_ylabel("CPU s, all rows and seeds")
    ax[1].legend()
    ratios = ", ".join(f"{n} {v['ratio']}x" for n, v in data["summary"]["cpu_ratio_vs_reference"].items())
    ax[1].set_title(f"CPU of {data['summary']['reference']} over: {ratios}", fontsize=9)
    fig.tight_layout()
    png = str(Path(path).with_suffix(".png"))
    fig.savefig(png, dpi=110)
    return png


def main(argv=None) -> int:
    sys.path.insert(0, str(HERE))
    from gitstate import commit
    from robot_dynamic import run_one

    from mlc.robot.verify import ROBOT_DISP_ACC, ROBOT_DT, ROBOT_FOLD_DT, ROBOT_FOLD_TIME, ROBOT_TAU
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rows", nargs="*", default=["00", "01", "10", "11"])
    ap.add_argument("--seeds", nargs="*", type=int, default=[0, 1, 2])
    ap.add_argument("--builds", nargs="*", default=["default", "per_lever"], choices=list(BUILDS))
    ap.add_argument("--ref", default="default", choices=list(BUILDS), help="the build the others are compared with")
    ap.add_argument("--kT", type=float, default=1e-5)
    ap.add_argument("-o", "--out", default=str(RESULTS / "robot_muscle_per_lever.json"))
    ap.add_argument("--plot", metavar="JSON", help="only redraw the plot of a results file")
    a = ap.parse_args(argv)
    if a.plot:
        print(plot(a.plot))
        return 0
    out = Path(a.out)
    data = json.loads(out.read_text()) if out.exists() else {"runs": []}
    done = {(r["build"], r["row"], r["seed"]) for r in data["runs"]}
    with tempfile.TemporaryDirectory() as tmp:
        scenes, built = {}, {}        # builds that differ only in how they are verified share one compile
        for name in a.builds:
            key = (tuple(BUILDS[name]), tuple(sorted(COUPLINGS.get(name, {}).items())))
            if key not in built:
                built[key] = compile_robot(BUILDS[name], Path(tmp) / name, COUPLINGS.get(name))
            scenes[name] = built[key]
    for row in a.rows:
        for seed in a.seeds:
            for name, sc in scenes.items():
                if (name, row, seed) in done:
                    continue
                tau = TAUS.get(name, ROBOT_TAU)
                scheme = SCHEMES.get(name, "stiff")
                r = run_one(sc, row, seed, ROBOT_DT, tau, 1800.0, a.kT, scheme=scheme, disp_acc=ROBOT_DISP_ACC)
                r.pop("history", None)
                r.update(build=name, bodies=len(sc.bodies), tau=tau, scheme=scheme, commit=commit())
                data["runs"].append(r)
                data.update(commit=commit(), machine=platform.machine(), cpus=os.cpu_count(),
                            settings={"dt": ROBOT_DT, "disp_acc": ROBOT_DISP_ACC, "tau": ROBOT_TAU, "kT": a.kT,
                                      "implicit_fold_dt": ROBOT_FOLD_DT, "implicit_fold_time": ROBOT_FOLD_TIME},
                            summary=compare(data["runs"], a.ref))
                with atomic_path(out) as tmpf:
                    Path(tmpf).write_text(json.dumps(data, indent=1))
                print(f"{name:9s} row {row} seed {seed}: {r['shape_read']} (want {r['shape_expected']}) "
                      f"{r['time_t0']:.0f} t0, {r['cpu_s']:.1f} s CPU", flush=True)
    print(json.dumps(data["summary"], indent=1))
    print(plot(str(out)))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
