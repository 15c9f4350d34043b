"""The Tetris robot's fold against an Euler-Maruyama reference (issue 10, item 6).

With the coupling joints at 100 k0 the Euler step is limited to ~1e-6 t0, so a whole fold
(100-400 t0) is ~1e8-1e9 Euler steps: not feasible here.  What is feasible is the start of
the fold, where the circuit switches and the stiff transients are (the Tetris circuit's
rows relax within 7 t0): this script runs one row from rest at kT = 0 (deterministic, so
the only difference between runs is the integrator and its step) for ``--time`` t0 with

* Euler at the integrator's default step (half its stability limit): the reference;
* Euler at half that step over the first ``--euler-check`` t0: the reference's own
  convergence (its error is first order in dt, so the difference of the two is about the
  reference's error);
* the stiff scheme at each ``--dts`` step,
* the linearly implicit scheme (``scheme="implicit"``, mlc/sim/implicit.py) at each
  ``--implicit-dts`` step, with the same drift bound,

and records, at every checkpoint (``--every`` t0), each run's largest body displacement
from the reference (sigma), its largest DOF-angle difference (degrees) and its wall and
CPU time.

    python benchmarks/robot_euler_reference.py OUT/robot.yaml [--row 01] [--time 2]
        [--every 0.25] [--dts 0.2 0.05 0.01] [--implicit-dts 0.8] [--euler-check 0.5] [--disp-acc 0.1]
        [--stretch-joint 0.25] [--reference-from EARLIER.json] [--no-fold-steps] [-o OUT.json]

The implicit runs take the verifier's steps (:func:`mlc.robot.verify.fold_step`: ROBOT_FOLD_DT
over the fold's first ROBOT_FOLD_TIME t0; ``--no-fold-steps``: their dt throughout, as before
session 49).  ``--reference-from`` reuses an earlier file's Euler reference (angles only).

``--disp-acc`` gives the stiff and implicit runs that drift bound (sigma; mlc.robot.verify.ROBOT_DISP_ACC
is the verifier's), else the integrator's default.  Writes benchmarks/results/robot_euler_reference.json
(or ``-o``) and its .png (atomic).  Units: sigma,
t0, degrees, seconds.  One process; Euler's steps dominate (about 0.3 ms of CPU a step for
2448 bodies).
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import time
from pathlib import Path

import mlc  # noqa: F401 -- before numpy: pins OpenBLAS's kernels (mlc/__init__.py)
import numpy as np

from mlc.io.atomic import atomic_path

OUT = Path(__file__).resolve().parent / "results" / "robot_euler_reference.json"


def trajectory(scene, row: str, scheme: str, dt: float | None, T: float, every: float, fold_steps: bool = True,
               **opt) -> dict:
    """Poses and DOF angles at t = every, 2 every, ... T from rest (kT = 0); ``opt``: further
    SimOptions (benchmarks/robot_drift_probe.py sets ``disp_acc``).  ``fold_steps``: each
    checkpoint interval at the verifier's step for its start (:func:`mlc.robot.verify.fold_step`:
    the implicit scheme's short steps over the fold's first ROBOT_FOLD_TIME t0, session 49)."""
    from mlc.robot.verify import dof_angles, fold_step
    from mlc.sim.drive import Drive
    from mlc.sim.integrator import SimOptions, Simulation
    drives = {inp: Drive.constant(int(b)) for inp, b in zip(scene.inputs, row)}
    sim = Simulation(scene, drives, SimOptions(scheme=scheme, kT=0.0, seed=0, dt=dt, **opt))
    n = int(round(T / every))
    pos, ang, times = [], [], []
    w0, c0 = time.perf_counter(), time.process_time()
    dt_run = sim.dt
    for _ in range(n):
        sim.dt = fold_step(scheme, dt_run, sim.t / sim.t_unit) if fold_steps else dt_run
        sim.run(every, quiet=True)
        times.append(sim.t / sim.t_unit)
        pos.append(sim.pos.copy())
        ang.append(dof_angles(scene, sim.pos, sim.quat))           # degrees already
    sim.dt = dt_run
    return {"scheme": scheme, "dt": sim.dt, "t": times, "pos": pos, "ang": ang,
            "wall_s": time.perf_counter() - w0, "cpu_s": time.process_time() - c0,
            "euler_limit": sim.euler_limit()}


def compare(run: dict, ref: dict) -> list[dict]:
    out = []
    for t, p, a, tr, pr, ar in zip(run["t"], run["pos"], run["ang"], ref["t"], ref["pos"], ref["ang"]):
        assert abs(t - tr) < 1e-6 * max(1.0, t), (t, tr)
        out.append({"t": round(t, 6),
                    "max_body_dev_sigma": None if pr is None else float(np.max(np.linalg.norm(p - pr, axis=1))),
                    "max_dof_dev_deg": float(np.max(np.abs(a - ar)))})
    return out


def plot(res: dict, out: Path = OUT) -> None:
    runs, ref, row = res["runs"], res["reference"], res["row"]
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(1, 2, figsize=(10, 4))
    for name, r in runs.items():
        ts = [c["t"] for c in r["vs_reference"]]
        if r["vs_reference"][0]["max_body_dev_sigma"] is not None:      # None: a reference without poses
            ax[0].semilogy(ts, [max(c["max_body_dev_sigma"], 1e-16) for c in r["vs_reference"]], "o-", label=name)
        ax[1].semilogy(ts, [max(c["max_dof_dev_deg"], 1e-16) for c in r["vs_reference"]], "o-", label=name)
    ax[0].set_ylabel("largest body displacement from Euler (sigma)")
    ax[1].set_ylabel("largest DOF angle difference from Euler (deg)")
    for a in ax:
        a.set_xlabel("t (t0), from rest, kT = 0")
        a.legend(fontsize=8)
    fig.suptitle(f"Tetris robot row {row}: stiff and implicit schemes against Euler at dt = {ref['dt']:.2g} t0")
    fig.tight_layout()
    with atomic_path(out.with_suffix(".png")) as tmp:
        fig.savefig(tmp, dpi=110, format="png")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("scene", nargs="?")
    ap.add_argument("--plot", action="store_true", help="only redraw the PNG from the JSON")
    ap.add_argument("--row", default="01")
    ap.add_argument("--time", type=float, default=2.0)
    ap.add_argument("--every", type=float, default=0.25)
    ap.add_argument("--dts", nargs="*", type=float, default=[0.2, 0.05, 0.01])
    ap.add_argument("--implicit-dts", nargs="*", type=float, default=[],
                    help="steps (t0) of the linearly implicit scheme to run as well")
    ap.add_argument("--euler-check", type=float, default=0.5)
    ap.add_argument("--disp-acc", type=float, default=None, help="the stiff runs' drift bound (sigma)")
    ap.add_argument("--stretch-joint", type=float, default=None,
                    help="every run's joint-bond bound c_0 (sigma; SimOptions.stretch_joint, default 0.15): at "
                         "kT = 0 the bound is c_0 alone, and the per-lever robot's u3_up hinge peaks at 0.166 sigma "
                         "as its muscle switches (session 47), inside the 0.197 of the verifier's kT = 1e-5")
    ap.add_argument("--reference-from", type=Path, metavar="JSON",
                    help="take the Euler reference (its DOF angles; no poses, so no body deviations) and its "
                         "half-step check from this earlier results file of the same scene and row instead of "
                         "running Euler again (537-656 s of CPU for 4 t0 of the 524-body robot)")
    ap.add_argument("--no-fold-steps", action="store_true",
                    help="the implicit runs at their dt throughout, not the verifier's short steps over the "
                         "fold's first ROBOT_FOLD_TIME t0 (mlc.robot.verify.fold_step; before session 49)")
    ap.add_argument("-o", "--out", type=Path, default=OUT)
    args = ap.parse_args()
    if args.plot:
        plot(json.loads(args.out.read_text()), args.out)
        return
    if not args.scene:
        ap.error("give the robot scene (mlc compile ... --robot ... -o OUT: OUT/robot.yaml)")
    from mlc.robot.verify import ROBOT_FOLD_DT, ROBOT_FOLD_TIME
    from mlc.scene.io import load_scene
    sc = load_scene(args.scene)
    runs = {}
    mon = {} if args.stretch_joint is None else {"stretch_joint": args.stretch_joint}
    if args.reference_from:
        old = json.loads(args.reference_from.read_text())
        if old["bodies"] != len(sc.bodies) or old["row"] != args.row or old["time_t0"] != args.time:
            ap.error(f"{args.reference_from}: its reference is of {old['bodies']} bodies, row {old['row']}, "
                     f"{old['time_t0']} t0; this run: {len(sc.bodies)} bodies, row {args.row}, {args.time} t0")
        r0 = old["reference"]
        ref = {"dt": r0["dt"], "euler_limit": r0["euler_limit"], "wall_s": r0["wall_s"], "cpu_s": r0["cpu_s"],
               "t": r0["t"], "pos": [None] * len(r0["t"]), "ang": [np.asarray(a) for a in r0["dof_angles_deg"]],
               "motion": r0["max_body_motion_since_first_checkpoint_sigma"]}
        runs["euler_half_dt"] = old["runs"]["euler_half_dt"]
    else:
        ref = trajectory(sc, args.row, "euler", None, args.time, args.every, **mon)
        print(f"euler dt {ref['dt']:.3g} t0 (limit {ref['euler_limit']:.3g}): {ref['wall_s']:.0f} s wall, "
              f"{ref['cpu_s']:.0f} s CPU", flush=True)
        half = trajectory(sc, args.row, "euler", ref["dt"] / 2, args.euler_check, args.every, **mon)
        runs["euler_half_dt"] = {"dt": half["dt"], "wall_s": half["wall_s"], "cpu_s": half["cpu_s"],
                                 "vs_reference": compare(half, ref)}
        print("euler dt/2:", runs["euler_half_dt"]["vs_reference"][-1], flush=True)
    for scheme, dts in (("stiff", args.dts), ("implicit", args.implicit_dts)):
        for dt in dts:
            r = trajectory(sc, args.row, scheme, dt, args.time, args.every, not args.no_fold_steps, **mon,
                           **({} if args.disp_acc is None else {"disp_acc": args.disp_acc}))
            runs[f"{scheme}_dt_{dt:g}"] = {"dt": dt, "wall_s": r["wall_s"], "cpu_s": r["cpu_s"],
                                           "vs_reference": compare(r, ref)}
            print(f"{scheme} dt {dt:g}: {r['wall_s']:.1f} s wall, {r['cpu_s']:.1f} s CPU, at {args.time:g} t0:",
                  runs[f"{scheme}_dt_{dt:g}"]["vs_reference"][-1], flush=True)
    motion = ref["motion"] if "motion" in ref else \
        [float(np.max(np.linalg.norm(p - ref["pos"][0], axis=1))) for p in ref["pos"]]
    res = {"scene": str(args.scene), "bodies": len(sc.bodies), "row": args.row, "kT": 0.0, "time_t0": args.time,
           "stiff_disp_acc": args.disp_acc, "stretch_joint": args.stretch_joint,
           "reference_from": str(args.reference_from) if args.reference_from else None,
           "implicit_fold_steps": None if args.no_fold_steps else {"dt": ROBOT_FOLD_DT, "time_t0": ROBOT_FOLD_TIME},
           "reference": {"scheme": "euler", "dt": ref["dt"], "euler_limit": ref["euler_limit"],
                         "wall_s": ref["wall_s"], "cpu_s": ref["cpu_s"], "t": ref["t"],
                         "max_body_motion_since_first_checkpoint_sigma": motion,
                         "dof_angles_deg": [[float(x) for x in a] for a in ref["ang"]]},
           "runs": runs,
           "machine": {"platform": platform.platform(), "cpus": os.cpu_count(), "load": os.getloadavg()[0]}}
    args.out.parent.mkdir(exist_ok=True)
    with atomic_path(args.out) as tmp:
        tmp.write_text(json.dumps(res, indent=1))
    plot(res, args.out)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
