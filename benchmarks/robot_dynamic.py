"""Dynamic verification of the Tetris robot (issue 10, item 3): every row, several seeds,
Brownian dynamics at kT = 1e-5 from rest until relaxed or the paper's 1800 t0.

One (row, seed) at a time, one process (the machine is shared).  Each run is the same
as ``mlc verify ROBOT --dynamic`` (:func:`mlc.robot.verify.verify_robot_dynamic`; that
is, with ``--scheme implicit --dt 0.8 --disp-acc 0.1``, the verifier's defaults since
session 48): the inputs switch to the row at t = 0 from the rest pose, the scheme advances in
windows of ``tau/20`` t0, and the run stops when

* it has lasted at least ``3 tau`` (the time floor of :mod:`mlc.verify.dynamic`), the
  three block means of every circuit output over the last third agree within
  :func:`mlc.verify.dynamic.plateau_tol`, and the DOF angles' block means agree within
  their own thermal noise (:func:`mlc.robot.verify.angles_relaxed`, docs/robot.md 3.2)
  (relaxed), or
* it reaches ``--max-time`` (1800 t0, the paper's fold time; not relaxed).

The shape is read from the final body poses (:func:`mlc.robot.verify.read_shape`).  The
turns are also read every ``--every`` t0, so the JSON holds each fold's history, and the
final pose gets the slab-overlap test (``clearance_end``, sigma; negative: interpenetration).

    python benchmarks/robot_dynamic.py OUT/robot.yaml [--rows 11] [--seeds 0 1 2]
        [--dt 0.2] [--scheme stiff] [--disp-acc 0.1] [--tau 100] [--max-time 1800]
        [--backends block superlu] [-o benchmarks/results/robot_dynamic.json]

``--backends`` (implicit scheme): the step matrix's linear algebra, ``block`` (mlc's block
Cholesky, the default) or ``superlu`` (rows of G and SciPy's SuperLU, the reference); with
both, each (row, seed) runs with each in turn, so their CPU times are measured side by side.

A scene compiled with stiff joints (``mlc compile --joint-k K``) goes to its own file, e.g.
``-o benchmarks/results/robot_dynamic_jointk100.json``; every run records the scene's
``joint_k`` (k0).

Results are merged into the JSON (keyed by row and seed), so runs can be made one at a
time.  Units: t0 (times), degrees (angles), sigma, seconds (wall).
"""
from __future__ import annotations

import argparse
import json
import math
import os
import platform
import sys
import time


def run_one(scene, state: str, seed: int, dt: float, tau: float, max_time: float, kT: float = 1e-5,
            every: float = 100.0, scheme: str = "stiff", min_time: float | None = None,
            disp_acc: float | None = None, backend: str = "block") -> dict:
    from mlc.robot.verify import _shape_row, robot_meta, run_fold
    from mlc.sim.drive import Drive
    from mlc.sim.integrator import SimOptions, Simulation

    rm = robot_meta(scene)
    drives = {inp: Drive.constant(int(b)) for inp, b in zip(scene.inputs, state)}
    extra = {} if disp_acc is None else {"disp_acc": disp_acc}     # the step control's drift bound (sigma)
    sim = Simulation(scene, drives, SimOptions(scheme=scheme, kT=kT, seed=seed, dt=dt, **extra))
    if sim._imp is not None:
        sim._imp.backend = backend        # the implicit step's linear algebra (mlc/sim/implicit.py)
    wall, cpu = time.perf_counter(), time.process_time()
    pm, t, relaxed, detail, hist = run_fold(sim, scene, state, kT, tau, max_time, every, min_time)
    sh = _shape_row(scene, rm, state, sim.pos.copy(), sim.quat.copy(), pm)
    want = scene.truth_table.get(state)
    bad = []
    for pr in scene.probes:
        b = want[scene.outputs.index(pr.output)]
        if b in "01" and pr.bit(pm[pr.name]) != int(b):
            bad.append(pr.name)
    noise = detail.get("noise_deg", [])
    from mlc.robot.verify import _clearance_row
    cl = _clearance_row(scene, sim.pos, sim.quat)         # slab overlap in the final pose (sigma; docs/robot.md 6)
    return {"row": state, "seed": seed, "shape_read": sh["shape_read"], "shape_expected": sh["shape_expected"],
            "shape_ok": sh["shape_ok"], "probes_ok": not bad, "wrong_probes": bad,
            "ok": bool(sh["shape_ok"] and not bad), "turns_read": sh["turns_read"],
            "turns_expected": sh["turns_expected"], "max_dof_error_deg": round(sh["max_dof_error_deg"], 3),
            "max_dof_mean_error_deg": round(sh.get("max_dof_mean_error_deg", float("nan")), 3),
            "dof_angles": [{k2: (round(v, 3) if isinstance(v, float) else v) for k2, v in d.items()}
                           for d in sh["dof_angles"]],
            "relaxed": relaxed, "time_t0": round(t, 3), "wall_s": round(time.perf_counter() - wall, 1),
            "cpu_s": round(time.process_time() - cpu, 1),
            "relax_test": {"drift_deg": [round(v, 2) for v in detail.get("drift_deg", [])],
                           "tol_deg": [round(v, 2) for v in detail.get("tol_deg", [])],
                           "noise_deg": [round(v, 2) for v in noise],
                           "kappa_est_k0sigma2": [round(kT / math.radians(v) ** 2, 6) if v > 0 else None
                                                  for v in noise]},
            "clearance_end": round(cl["clearance"], 4), "clearance_pair_end": cl["clearance_pair"],
            "n_overlaps_end": cl["n_overlaps"],
            "history": hist}


def main(argv=None) -> int:
    from gitstate import commit
    from mlc.scene.io import load_scene

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scene")
    ap.add_argument("--rows", nargs="*")
    ap.add_argument("--seeds", nargs="*", type=int, default=[0, 1, 2])
    ap.add_argument("--dt", type=float, default=0.2, help="t0, the scheme's step")
    ap.add_argument("--scheme", default="stiff", choices=("stiff", "implicit", "euler"),
                    help="the integrator (mlc verify's default for a robot: mlc.robot.verify.ROBOT_SCHEME)")
    ap.add_argument("--disp-acc", type=float, default=None,
                    help="sigma: the step control's drift bound (mlc verify's for a robot: ROBOT_DISP_ACC)")
    ap.add_argument("--tau", type=float, default=100.0, help="t0, slowest relaxation time (time floor 3 tau)")
    ap.add_argument("--max-time", type=float, default=1800.0)
    ap.add_argument("--every", type=float, default=100.0)
    ap.add_argument("--min-time", type=float, default=None,
                    help="t0: run at least this long (default 3 tau; --min-time 1800 reads every shape at the "
                         "paper's fold time, the relaxation test then only reports)")
    ap.add_argument("--kT", type=float, default=1e-5)
    ap.add_argument("--backends", nargs="*", default=["block"], choices=("block", "superlu"),
                    help="implicit scheme: the step's linear algebra; several: each (row, seed) with each in turn")
    ap.add_argument("-o", "--out", default="benchmarks/results/robot_dynamic.json")
    a = ap.parse_args(argv)
    sc = load_scene(a.scene)
    rows = a.rows or sorted(sc.truth_table)
    # the chains' joint stiffness (mlc compile --joint-k K, k0): recorded with every run
    joint_k = float((sc.meta.get("circuit", {}).get("connector", {}) or {}).get("joint_k", 1.0))
    data = {}
    if os.path.exists(a.out):
        with open(a.out) as f:
            data = json.load(f)
    runs = {(r["row"], r["seed"], r.get("backend", "superlu")): r for r in data.get("runs", [])}
    for state in rows:
        for seed in a.seeds:
            for backend in a.backends:
                r = run_one(sc, state, seed, a.dt, a.tau, a.max_time, a.kT, a.every, scheme=a.scheme,
                            min_time=a.min_time, disp_acc=a.disp_acc, backend=backend)
                r.update({"min_time": a.min_time if a.min_time is not None else 3 * a.tau, "dt": a.dt, "tau": a.tau,
                          "kT": a.kT, "max_time": a.max_time, "scheme": a.scheme, "disp_acc": a.disp_acc,
                          "bodies": len(sc.bodies), "load_1min": round(os.getloadavg()[0], 2),
                          "joint_k": joint_k, "backend": backend if a.scheme == "implicit" else None,
                          "commit": commit()})
                runs[(state, seed, backend)] = r
                print(f"row {state} seed {seed} {backend}: cpu {r['cpu_s']} s, {r['shape_read']} (expected {r['shape_expected']}) "
                      f"turns {r['turns_read']}  relaxed {r['relaxed']} at {r['time_t0']} t0, "
                      f"wall {r['wall_s']} s  {'ok' if r['ok'] else 'WRONG'}", flush=True)
                data = {"what": "Tetris robot, dynamic verification per row and seed (benchmarks/robot_dynamic.py)",
                        "scene": a.scene, "machine": f"{platform.machine()}, {os.cpu_count()} cores, shared",
                        "units": "t0, degrees, seconds wall",
                        "runs": sorted(runs.values(), key=lambda r: (r["row"], r["seed"], r.get("backend", "superlu")))}
                data["all_ok"] = all(r["ok"] for r in data["runs"])
                data["cpu_total_s"] = {b: round(sum(r["cpu_s"] for r in data["runs"] if r.get("backend", "superlu") == b), 1)
                                       for b in sorted({r.get("backend", "superlu") for r in data["runs"]})}
                with open(a.out + ".tmp", "w") as f:
                    json.dump(data, f, indent=1)
                os.replace(a.out + ".tmp", a.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
