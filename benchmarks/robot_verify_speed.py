"""The Tetris robot's dynamic verification at several step settings (issue 10 item 6; docs/robot.md 3.4):
every row and seed verified exactly as ``mlc verify ROBOT --dynamic`` does (from rest at kT = 1e-5,
stiff scheme, until relaxed; :func:`robot_dynamic.run_one`), with the reference setting A of the
committed 12-run benchmark (dt 0.2 t0, drift bound ``disp_acc`` 0.01 sigma) and others, by default
B (dt 3.2 t0, ``disp_acc`` 0.1 sigma); ``--setting NAME DT DISP_ACC`` runs others (session 18: C = 3.2,
0.05 and D = 0.8, 0.1, now mlc.robot.verify's default).  The settings alternate run by run in one
process, so machine load falls on all alike; cost ratios are of CPU seconds over the same runs.

What it compares:

* the shape read in every run (every setting must read every row right);
* per row and DOF, the seed mean of the time-averaged angle (each run's plateau mean), each setting
  against A, with the error bar sqrt(sd_A^2/n + sd^2/n) from the seed spreads: a difference inside
  2 bars is not resolved at this number of seeds;
* total CPU per setting and its ratio to A's over the same (row, seed) runs;
* the smallest distance between the centres of two bodies no bond joins (the WCA range is 0.2 sigma).

    python benchmarks/robot_verify_speed.py OUT/robot.yaml [--seeds 0 1 2] [--rows 00 01 10 11]
        [--setting D 0.8 0.1 ...]
    python benchmarks/robot_verify_speed.py --plot benchmarks/results/robot_verify_speed.json

Writes benchmarks/results/robot_verify_speed.json (merged run by run, so it resumes) and .png.
Units: t0 (times), degrees (angles), sigma, CPU seconds.
"""
from __future__ import annotations

import argparse
import hashlib
import json
import math
import os
import platform
import sys
from pathlib import Path

import mlc  # noqa: F401 -- before numpy: pins OpenBLAS's kernels (mlc/__init__.py)

from mlc.io.atomic import atomic_path

RESULTS = Path(__file__).resolve().parent / "results"
SETTINGS = {"A": (0.2, 0.01), "B": (3.2, 0.1)}     # name: (dt t0, disp_acc sigma); A is the reference


def compare(runs: list[dict]) -> dict:
    """Per setting: all right?, CPU; per other setting, row and DOF: seed means of the
    time-averaged angles and X - A with its error bar (degrees).  CPU ratios are over the
    (row, seed) pairs both settings ran."""
    import numpy as np
    out = {"settings": {}, "diffs": {}, "cpu_ratio_vs_A": {}, "largest_difference": {}}
    names = sorted({r["setting"] for r in runs})
    for name in names:
        rs = [r for r in runs if r["setting"] == name]
        out["settings"][name] = {"dt": rs[0]["dt"], "disp_acc": rs[0]["disp_acc"], "runs": len(rs),
                                 "rows": sorted({r["row"] for r in rs}),
                                 "all_right": all(r["ok"] for r in rs),
                                 "cpu_s": round(sum(r["cpu_s"] for r in rs), 1),
                                 "wall_s": round(sum(r["wall_s"] for r in rs), 1),
                                 "relaxed": sum(bool(r["relaxed"]) for r in rs)}
    ref = {(r["row"], r["seed"]): r for r in runs if r["setting"] == "A"}
    for name in names:
        if name == "A":
            continue
        mine = {(r["row"], r["seed"]): r for r in runs if r["setting"] == name}
        both = sorted(set(mine) & set(ref))
        if both:
            out["cpu_ratio_vs_A"][name] = round(sum(ref[k]["cpu_s"] for k in both) /
                                                sum(mine[k]["cpu_s"] for k in both), 2)
        worst, rows = None, {}
        for row in sorted({k[0] for k in both}):
            keys = [k for k in both if k[0] == row]
            per = {}
            for k in keys:
                for tag, r in (("A", ref[k]), ("X", mine[k])):
                    for d in r["dof_angles"]:
                        per.setdefault(d["name"], {}).setdefault(tag, []).append(d["mean_angle"])
            if len(keys) < 2:
                continue
            dofs = {}
            for dof, v in per.items():
                xa, xb = np.array(v["A"]), np.array(v["X"])
                diff = float(xb.mean() - xa.mean())
                bar = float(math.sqrt(xa.var(ddof=1) / len(xa) + xb.var(ddof=1) / len(xb)))
                dofs[dof] = {"mean_A": round(float(xa.mean()), 3), "mean": round(float(xb.mean()), 3),
                             "diff_deg": round(diff, 3), "bar_deg": round(bar, 3),
                             "resolved": bool(abs(diff) > 2 * bar)}
                if worst is None or abs(diff) > abs(worst["diff_deg"]):
                    worst = {"row": row, "dof": dof, **dofs[dof]}
            rows[row] = dofs
        out["diffs"][name] = rows
        out["largest_difference"][name] = worst
    return out


def nearest_unbonded_centres(sc) -> float:
    """Smallest distance (sigma) between the centres of two bodies that no bond or muscle joins,
    in the scene as built: the simulator's only contact force (WCA) acts between such centres
    within 2 r0 = 0.2 sigma, so a drift bound of ROBOT_DISP_ACC per substep cannot carry a pair
    through it unseen while they stay this far apart."""
    import numpy as np
    from scipy.spatial import cKDTree
    a = sc.arrays() if callable(sc.arrays) else sc.arrays
    sb = a.site_body
    joined = {tuple(sorted((int(sb[i]), int(sb[j])))) for i, j in
              zip(np.r_[a.bond_i, a.muscle_i], np.r_[a.bond_j, a.muscle_j])}
    pairs = cKDTree(a.pos).query_pairs(2.0, output_type="ndarray")
    d = [float(np.linalg.norm(a.pos[p] - a.pos[q])) for p, q in pairs if (min(p, q), max(p, q)) not in joined]
    return round(min(d), 4) if d else float("inf")


def plot(path: str) -> str:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    with open(path) as f:
        data = json.load(f)
    c = data["comparison"]
    others = [n for n in c["settings"] if n != "A"]
    fig, ax = plt.subplots(1, 1 + len(others), figsize=(4 + 6 * len(others), 3.8), squeeze=False)
    ax = ax[0]
    ax[0].bar([f"{n}: dt {c['settings'][n]['dt']:g}\ndrift {c['settings'][n]['disp_acc']:g}" for n in others],
              [c["cpu_ratio_vs_A"].get(n, float("nan")) for n in others], color="tab:blue")
    ax[0].set_ylabel("CPU of A / CPU of setting (same runs)")
    ax[0].set_title(f"A: dt {c['settings']['A']['dt']:g}, drift {c['settings']['A']['disp_acc']:g}", fontsize=9)
    for i, n in enumerate(others, start=1):
        x, labels = 0, []
        for row, dofs in sorted(c["diffs"][n].items()):
            for dof, d in dofs.items():
                ax[i].errorbar([x], [d["diff_deg"]], yerr=[2 * d["bar_deg"]], fmt="o",
                               color="tab:red" if d["resolved"] else "tab:blue", capsize=2)
                labels.append(f"{row} {dof}")
                x += 1
        ax[i].axhline(0, color="k", lw=0.5)
        for s in (-1, 1):
            ax[i].axhline(s * math.degrees(0.05), color="tab:green", ls=":", lw=1)
        ax[i].set_xticks(range(len(labels)), labels, rotation=90, fontsize=6)
        ax[i].set_ylabel(f"{n} - A, seed mean of DOF angle (deg)")
        ax[i].set_title(f"{n}: 2 error bars; red: resolved; dotted: +-0.05 rad", fontsize=9)
    fig.tight_layout()
    out = str(Path(path).with_suffix(".png"))
    fig.savefig(out, dpi=120)
    return out


def main(argv=None) -> int:
    from mlc.scene.io import load_scene
    from robot_dynamic import run_one
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scene", nargs="?")
    ap.add_argument("--rows", nargs="*")
    ap.add_argument("--seeds", nargs="*", type=int, default=[0, 1, 2])
    ap.add_argument("--tau", type=float, default=100.0, help="t0 (mlc.robot.verify.ROBOT_TAU)")
    ap.add_argument("--max-time", type=float, default=1800.0, help="t0, the paper's fold time")
    ap.add_argument("--kT", type=float, default=1e-5)
    ap.add_argument("-o", "--out", default=str(RESULTS / "robot_verify_speed.json"))
    ap.add_argument("--plot", metavar="JSON", help="only redraw the plot of a results file")
    ap.add_argument("--setting", nargs=3, action="append", metavar=("NAME", "DT", "DISP_ACC"),
                    help="run these settings (t0, sigma) instead of A and B (repeatable; A is the reference)")
    a = ap.parse_args(argv)
    if a.plot:
        print(plot(a.plot))
        return 0
    if not a.scene:
        ap.error("give the robot scene (mlc compile examples/tetris.tt --robot examples/tetris.robot.yaml -o OUT)")
    sc = load_scene(a.scene)
    digest = hashlib.sha256(Path(a.scene).read_bytes()).hexdigest()[:16]     # the scene file's key (resume)
    rows = a.rows or sorted(sc.truth_table)
    data = {}
    if os.path.exists(a.out):
        with open(a.out) as f:
            data = json.load(f)
        if data.get("scene_digest") != digest:
            print(f"{a.out} holds another scene ({data.get('scene_digest')}); starting afresh", file=sys.stderr)
            data = {}
    runs = {(r["setting"], r["row"], r["seed"]): r for r in data.get("runs", [])}
    settings = ({n: (float(d), float(e)) for n, d, e in a.setting} if a.setting else SETTINGS)
    for state in rows:
        for seed in a.seeds:
            for name, (dt, da) in settings.items():
                if (name, state, seed) in runs:
                    continue
                r = run_one(sc, state, seed, dt, a.tau, a.max_time, a.kT, every=100.0, disp_acc=da)
                r.pop("history", None)
                r.update({"setting": name, "dt": dt, "disp_acc": da, "tau": a.tau, "kT": a.kT,
                          "load_1min": round(os.getloadavg()[0], 2)})
                runs[(name, state, seed)] = r
                print(f"{name} row {state} seed {seed}: {r['shape_read']} (expected {r['shape_expected']}) "
                      f"relaxed {r['relaxed']} at {r['time_t0']} t0, cpu {r['cpu_s']} s "
                      f"{'ok' if r['ok'] else 'WRONG'}", flush=True)
                allr = sorted(runs.values(), key=lambda r: (r["row"], r["seed"], r["setting"]))
                data = {"what": "Tetris robot: dynamic verification at several step settings "
                                "(benchmarks/robot_verify_speed.py)",
                        "scene": a.scene, "scene_digest": digest, "bodies": len(sc.bodies),
                        "machine": f"{platform.machine()}, {os.cpu_count()} cores, shared",
                        "units": "t0, degrees, sigma, CPU seconds",
                        "runs": allr, "comparison": compare(allr)}
                with atomic_path(a.out) as tmp:
                    Path(tmp).write_text(json.dumps(data, indent=1))
    if data:
        # once at the end: the centres check, and the comparison also when every run was resumed
        data["nearest_unbonded_centres_sigma"] = nearest_unbonded_centres(sc)
        data["comparison"] = compare(data["runs"])
        with atomic_path(a.out) as tmp:
            Path(tmp).write_text(json.dumps(data, indent=1))
        print("nearest centres of two unjoined bodies (sigma):", data["nearest_unbonded_centres_sigma"])
        print(json.dumps(data["comparison"]["settings"], indent=1))
        print("CPU of A over each:", data["comparison"]["cpu_ratio_vs_A"])
        print("largest difference:", json.dumps(data["comparison"]["largest_difference"], indent=1))
        print(plot(a.out))
    return 0


if __name__ == "__main__":
    sys.exit(main())
