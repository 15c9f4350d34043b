"""The Tetris robot's folds at kT = 0 to their end, stiff scheme against the linearly implicit
scheme, and both against the static equilibrium (issue 10, item 6: final joint angles).

Euler can follow a fold only over its first few t0 (benchmarks/robot_euler_reference.py: 4 t0
cost 537-656 s of CPU on the 524-body robot); a fold lasts hundreds of t0.  At kT = 0 the runs
are deterministic, so two integrators can be compared on one run each, to the end of the fold:

* the stiff scheme (SK-ROCK) and the implicit scheme at ``--dt`` and drift bound ``--disp-acc``
  (the verifier's: 0.8 t0, 0.1 sigma), each from rest for ``--time`` t0, DOF angles every
  ``--every`` t0, and their CPU time;
* the static equilibrium of the row (:func:`mlc.robot.verify.verify_robot_static`: the
  Levenberg-Marquardt solver, a second implementation of the mechanics), the end both runs
  should reach.

    python benchmarks/robot_scheme_final.py OUT/robot.yaml [--rows 01 10 11] [--time 300]
        [--every 25] [--dt 0.8] [--disp-acc 0.1] [--stretch-joint 0.25] [--no-fold-steps] [-o OUT.json]

The implicit run takes the verifier's steps (:func:`mlc.robot.verify.fold_step`: ROBOT_FOLD_DT over
the fold's first ROBOT_FOLD_TIME t0, session 49); ``--no-fold-steps``: ``--dt`` throughout, as before.

``--stretch-joint`` as in robot_euler_reference.py (at kT = 0 the joint bound is c_0 alone;
the per-lever robot's u3_up hinge peaks at 0.166 sigma when its muscle switches).
Writes benchmarks/results/robot_scheme_final.json (or ``-o``) and its .png.  Units: t0,
degrees, CPU seconds.
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import sys
import time
from pathlib import Path

import mlc  # noqa: F401 -- before numpy: pins OpenBLAS's kernels (mlc/__init__.py)
import numpy as np

from mlc.io.atomic import atomic_path

HERE = Path(__file__).resolve().parent
OUT = HERE / "results" / "robot_scheme_final.json"


def plot(res: dict, out: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    rows = list(res["rows"])
    fig, ax = plt.subplots(1, 2, figsize=(11, 4))
    for row in rows:
        r = res["rows"][row]
        ax[0].semilogy(r["t"], np.maximum(r["max_dof_diff_deg"], 1e-6), "o-", label=f"row {row}")
        for name, st in (("stiff", "s"), ("implicit", "^")):
            ax[1].plot(r["t"], r[name]["max_dof_from_static_deg"], st + "-", label=f"{row} {name}")
    ax[0].axhline(np.degrees(0.05), color="tab:red", ls="--", label="0.05 rad")
    ax[0].set_ylabel("largest DOF angle difference, implicit - stiff (deg)")
    ax[1].set_ylabel("largest DOF angle from the static equilibrium (deg)")
    ax[1].set_yscale("log")
    for a in ax:
        a.set_xlabel("t (t0), from rest, kT = 0")
        a.legend(fontsize=7)
    fs = res.get("implicit_fold_steps")
    fold = f" (implicit: {fs['dt']:g} over the first {fs['time_t0']:g} t0)" if fs else ""
    fig.suptitle(f"{res['bodies']}-body robot: folds at kT = 0, dt {res['dt']} t0{fold}, drift bound {res['disp_acc']} sigma")
    fig.tight_layout()
    with atomic_path(out.with_suffix(".png")) as tmp:
        fig.savefig(tmp, dpi=110, format="png")


def main(argv=None) -> int:
    sys.path.insert(0, str(HERE))
    from gitstate import commit
    from robot_euler_reference import trajectory

    from mlc.robot.verify import ROBOT_FOLD_DT, ROBOT_FOLD_TIME, dof_angles, verify_robot_static
    from mlc.scene.io import load_scene
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("scene", nargs="?")
    ap.add_argument("--rows", nargs="*", default=["01", "10", "11"])
    ap.add_argument("--time", type=float, default=300.0)
    ap.add_argument("--every", type=float, default=25.0)
    ap.add_argument("--dt", type=float, default=0.8)
    ap.add_argument("--disp-acc", type=float, default=0.1)
    ap.add_argument("--stretch-joint", type=float, default=0.25)
    ap.add_argument("--no-fold-steps", action="store_true",
                    help="the implicit run at --dt throughout, not the verifier's short steps over the fold's "
                         "first ROBOT_FOLD_TIME t0 (mlc.robot.verify.fold_step; before session 49)")
    ap.add_argument("--plot", action="store_true", help="only redraw the PNG from the JSON")
    ap.add_argument("-o", "--out", type=Path, default=OUT)
    a = ap.parse_args(argv)
    if a.plot:
        plot(json.loads(a.out.read_text()), a.out)
        return 0
    if not a.scene:
        ap.error("give the robot scene (mlc compile ... --robot ... -o OUT: OUT/robot.yaml)")
    sc = load_scene(a.scene)
    res = {"scene": str(a.scene), "bodies": len(sc.bodies), "kT": 0.0, "time_t0": a.time, "dt": a.dt,
           "disp_acc": a.disp_acc, "stretch_joint": a.stretch_joint,
           "implicit_fold_steps": None if a.no_fold_steps else {"dt": ROBOT_FOLD_DT, "time_t0": ROBOT_FOLD_TIME},
           "rows": {}, "commit": commit(),
           "machine": {"platform": platform.platform(), "cpus": os.cpu_count()}}
    for row in a.rows:
        c0 = time.process_time()
        st = verify_robot_static(sc, [row], keep_poses=True)
        pos, quat = st.poses[row]
        ang_static = np.asarray(dof_angles(sc, pos, quat))
        entry = {"static": {"dof_angles_deg": [round(float(x), 4) for x in ang_static],
                            "ok": bool(st.rows[0]["ok"]), "cpu_s": round(time.process_time() - c0, 1)}}
        runs = {}
        for scheme in ("stiff", "implicit"):
            r = trajectory(sc, row, scheme, a.dt, a.time, a.every, not a.no_fold_steps, disp_acc=a.disp_acc,
                           stretch_joint=a.stretch_joint)
            ang = np.asarray(r["ang"])
            runs[scheme] = ang
            entry[scheme] = {"cpu_s": round(r["cpu_s"], 1), "dof_angles_deg": np.round(ang, 4).tolist(),
                             "max_dof_from_static_deg": np.round(np.max(np.abs(ang - ang_static), axis=1), 4).tolist()}
            entry["t"] = [round(t, 3) for t in r["t"]]
            print(f"row {row} {scheme}: {r['cpu_s']:.1f} s CPU; at {a.time:g} t0 the largest DOF angle from the "
                  f"static equilibrium {entry[scheme]['max_dof_from_static_deg'][-1]:.3f} deg", flush=True)
        diff = np.max(np.abs(runs["implicit"] - runs["stiff"]), axis=1)
        entry["max_dof_diff_deg"] = np.round(diff, 4).tolist()
        entry["final_max_dof_diff_deg"] = round(float(diff[-1]), 4)
        entry["final_max_dof_diff_rad"] = round(float(np.radians(diff[-1])), 5)
        res["rows"][row] = entry
        print(f"row {row}: implicit - stiff at {a.time:g} t0: {diff[-1]:.3f} deg (largest on the way "
              f"{diff.max():.3f})", flush=True)
        a.out.parent.mkdir(exist_ok=True)
        with atomic_path(a.out) as tmp:
            Path(tmp).write_text(json.dumps(res, indent=1))
    plot(res, a.out)
    print(f"wrote {a.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
