"""Verification of a robot scene: the skeleton's shape read from body poses, per input row.

The shape is read from the final poses alone (not from the probes): the heading of link
i is its body's x axis in the world (the links are built straight along x), the plane
normal is the body's (link 0) z axis, and the turn at unit i is the signed angle from
the heading of link i-1 to that of link i about the normal.  Each turn is rounded to
the nearest of -90, 0, +90 degrees (a turn nearer 180 is read as a U-turn and is wrong);
walking the rounded turns gives the grid cells.  A DOF's angle is the rotation of its
second body relative to its first about the normal; its target is +90 (up) or -90 (dn)
degrees when its output is 1 and 0 otherwise.

A row passes when the turns read are the expected pose (the robot file's, stored in the
scene's meta), every probe reads its bit (circuit outputs and DOF lengths) and, for the
static check, the largest joint stretch is below ``TOL_STRETCH``.

* **static**: :func:`mlc.verify.static.equilibrium` of each row, reached from the rest
  pose in ``STEPS`` continuation steps (the skeleton folds far, so more than the
  circuit verifier's four);
* **dynamic**: Brownian dynamics from rest into each row, over several seeds, until
  relaxed (:func:`run_fold`: the time floor of 3 tau, the circuit outputs on a plateau,
  the joint angles within their own thermal noise, :func:`angles_relaxed`) or the fold
  time; the shape is read from the final poses.  tau and dt default to ``ROBOT_TAU``
  and ``ROBOT_DT`` (no relaxation-time computation, docs/robot.md section 3); the stiff
  scheme's drift bound is ``ROBOT_DISP_ACC``.

Units: sigma, k0, t0, degrees in reports.
"""
from __future__ import annotations

import math
import time

import numpy as np

from mlc.errors import MlcError
from mlc.geometry.rotation import quat_to_matrix
from mlc.robot.spec import walk
from mlc.scene.model import Scene
from mlc.verify.circuit import Report, select_rows

STEPS = 12                # continuation steps of the static check
TOL_STRETCH = 1e-3        # sigma
TOL_LENGTH = 0.05         # sigma: static probe lengths within this of the ideal
FOLD_TIME = 1800.0        # t0: the paper's fold time, a dynamic run's default limit
ROBOT_TAU = 100.0         # t0: a robot's slowest relaxation time, measured, not computed (docs/robot.md section 3)
ROBOT_SCHEME = "implicit"  # a robot's integrator: the linearly implicit scheme (mlc/sim/implicit.py; session 48:
                          # 3.5 times less CPU than the stiff scheme on the per-lever Tetris robot's 12 runs,
                          # docs/robot.md 3.4); circuits keep the stiff scheme (mlc.verify.dynamic)
ROBOT_DT = 0.8            # t0: the step for a robot's fold (the implicit and the stiff scheme) ...
ROBOT_FOLD_DT = 0.2       # t0: the implicit scheme's step over a fold's first ROBOT_FOLD_TIME t0, its fast phase, where
ROBOT_FOLD_TIME = 50.0    # a first-order step at ROBOT_DT lags (docs/robot.md 3.4, "Session 49"); ROBOT_DT after
ROBOT_DISP_ACC = 0.1      # sigma: ... with this drift bound (SimOptions.disp_acc, default 0.01). Against dt 0.2 t0
                          # at 0.01 sigma: 1.67 times less CPU for the Tetris robot's 12 runs, all right, angles
                          # within 2.3 deg (docs/robot.md 3.4, benchmarks/results/robot_verify_speed.json);
                          # dt 3.2 t0 was 2.75 times faster but slowed a locked DOF's creep by 3 deg


def robot_meta(scene: Scene) -> dict:
    meta = scene.meta if isinstance(scene.meta, dict) else {}
    rm = meta.get("robot")
    if meta.get("element") != "robot" or not isinstance(rm, dict):
        raise MlcError(f"scene {scene.name} is not a robot scene (meta.element != robot)", scene.source or scene.name,
                       "compile with mlc compile LOGIC --robot ROBOT.yaml")
    for key in ("links", "dofs", "poses", "units"):
        if key not in rm:
            raise MlcError(f"robot scene {scene.name}: meta.robot has no {key!r}", scene.source or scene.name,
                           "recompile the robot with this version of mlc")
    return rm


def read_shape(scene: Scene, pos, quat, state: str | None = None) -> dict:
    """The skeleton's pose in body poses ``pos``/``quat``: turns (deg, measured and rounded
    to quarter turns), cells, and each DOF's angle (deg) and its error from the target of
    row ``state`` (if given)."""
    rm = robot_meta(scene)
    idx = {b.name: i for i, b in enumerate(scene.bodies)}
    R = {n: quat_to_matrix(quat[idx[n]]) for n in rm["links"] + [b for d in rm["dofs"] for b in d["bodies"]]}
    nrm = R[rm["links"][0]][:, 2]
    heads = [R[n][:, 0] for n in rm["links"]]
    turns = []
    for h0, h1 in zip(heads[:-1], heads[1:]):
        turns.append(math.degrees(math.atan2(float(np.cross(h0, h1) @ nrm), float(h0 @ h1))))
    q = []
    for t in turns:
        k = int(round(t / 90.0))
        q.append(k if k in (-1, 0, 1) else 2)
    outs = scene.outputs
    want = scene.truth_table.get(state) if (state is not None and scene.truth_table) else None
    dofs = []
    for d in rm["dofs"]:
        Ra, Rb = R[d["bodies"][0]], R[d["bodies"][1]]
        rel = Ra.T @ Rb
        ang = math.degrees(math.atan2(rel[1, 0], rel[0, 0]))
        e = {"name": d["name"], "angle": ang}
        if want is not None:
            if d.get("coupling") == "lock" or d.get("output") is None:
                on = int(d.get("value", 0))
            else:
                on = int(want[outs.index(d["output"])] == "1")
            target = (90.0 if d["side"] == "up" else -90.0) if on else 0.0
            e["target"] = target
            e["error"] = ang - target
        dofs.append(e)
    cells = [list(c) for c in walk(q)] if 2 not in q else None
    return {"turns": turns, "quarter_turns": q, "cells": cells, "dofs": dofs}


def dof_angle_from_length(rm: dict, side: str, length: float) -> float:
    """A DOF's turn (deg, signed: + up, - down) from its tip distance (sigma), by the law of
    cosines on its lever triangle (meta.robot.dof_geometry): the time-averaged angle from
    a probe's plateau mean."""
    g = rm["dof_geometry"]
    P, Q = g["gain"] * g["p"], g["gain"] * g["q"]
    c = max(-1.0, min(1.0, (P * P + Q * Q - length * length) / (2 * P * Q)))
    ang = math.degrees(math.acos(c)) - g["theta0_deg"]
    return ang if side == "up" else -ang


def dof_angles(scene: Scene, pos, quat) -> np.ndarray:
    """Every DOF's angle (deg, order of ``meta.robot.dofs``) in body poses ``pos``/``quat``."""
    return np.array([d["angle"] for d in read_shape(scene, pos, quat)["dofs"]])


def angles_relaxed(angles, block: float, tau: float, z: float = 3.0) -> tuple[bool, dict]:
    """The skeleton's relaxation test, allowing for its thermal noise (docs/robot.md section 3.2).

    ``angles``: DOF angles (deg), one row per sample, equally spaced over the run's last
    part (the plateau); split into 3 blocks of ``block`` t0.  For a harmonic DOF of angular
    stiffness kappa at temperature kT, equipartition gives the angle's variance
    s^2 = kT / kappa; kappa (the coupling chain's stiffness times (dL/dtheta)^2) is not
    known beforehand, so s is estimated from the samples about their straight-line trend
    (a drift does not count as noise).  A block mean over B t0 of a signal with correlation
    time tau has the variance s^2 min(1, 2 tau / B), so two relaxed block means differ by
    at most ``z`` sqrt(2 s^2 min(1, 2 tau / B)).  Relaxed when every DOF's block means
    lie within that.  Returns (relaxed, {"drift_deg", "tol_deg", "noise_deg"} per DOF as
    lists)."""
    a = np.asarray(angles, float)
    n = a.shape[0]
    if n < 6:
        return False, {}
    x = np.arange(n, dtype=float)
    A = np.vstack([x, np.ones(n)]).T
    coef, *_ = np.linalg.lstsq(A, a, rcond=None)
    s = np.std(a - A @ coef, axis=0, ddof=2)
    means = np.array([b.mean(0) for b in np.array_split(a, 3)])
    drift = means.max(0) - means.min(0)
    tol = z * np.sqrt(2.0 * s * s * min(1.0, 2.0 * tau / max(block, 1e-12)))
    return bool(np.all(drift <= tol)), {"drift_deg": drift.tolist(), "tol_deg": tol.tolist(), "noise_deg": s.tolist()}


def fold_step(scheme: str, dt: float, t: float) -> float:
    """The step (t0) a robot's fold takes at time ``t`` (t0) after its inputs switched, for a run at
    step ``dt``: the implicit scheme takes at most ``ROBOT_FOLD_DT`` over the first ``ROBOT_FOLD_TIME``
    (its first-order steps slow the modes about as fast as a step: at ROBOT_DT throughout, the
    per-lever Tetris robot's row 11 lags the stiff scheme by 34 deg at 25 t0 and 5 deg at 100 t0;
    docs/robot.md 3.4, "Session 49"); the other schemes, and later times, take ``dt``."""
    if scheme == "implicit" and t < ROBOT_FOLD_TIME - 1e-9:
        return min(dt, ROBOT_FOLD_DT)
    return dt


def run_fold(sim, scene: Scene, state: str, kT: float, tau: float, max_time: float, every: float | None = None,
             min_time: float | None = None, on_window=None):
    """Advance ``sim`` (inputs already set to row ``state``) in windows of max(0.05, tau/20)
    t0 until relaxed or ``max_time`` t0.  Relaxed: at least ``TAU_FACTOR`` tau (not for the
    rest row), the three block means of every circuit output over the last third within
    :func:`mlc.verify.dynamic.plateau_tol`, and the DOF angles' block means within their
    own thermal noise (:func:`angles_relaxed`).  The DOF probes are not plateau-tested:
    the skeleton's soft joints fluctuate far more than the circuit's stiff pairs.
    The step is :func:`fold_step`'s for the simulation's scheme and dt (restored at the end).
    ``min_time`` (t0): run at least this long (default ``TAU_FACTOR`` tau; the rest row 0).
    Returns (probe means over the plateau {name: sigma}, time t0, relaxed, test details,
    history of turns every ``every`` t0 or []).  ``on_window(t)``, if given, is called after
    every window with the time run so far (t0)."""
    from mlc.verify.dynamic import MIN_WINDOWS, TAU_FACTOR, plateau_start, plateau_tol

    rm = robot_meta(scene)
    names = [p.name for p in scene.probes]
    circ = [p for p in names if not p.startswith("dof_")]
    window = max(0.05, tau / 20.0)
    t_min = TAU_FACTOR * tau if state != "0" * len(scene.inputs) else 0.0
    if min_time is not None:
        t_min = float(min_time)
    ends, means, hist, angs = [], {p: [] for p in names}, [], []
    t, relaxed, detail, first = 0.0, False, {}, 0
    next_rec = every if every else float("inf")
    dt_run = sim.dt
    try:
        while True:
            sim.dt = fold_step(sim.opt.scheme, dt_run, t)
            res = sim.run(window, record_interval=window / 10, quiet=True)
            t = res.time
            ends.append(t)
            if on_window is not None:
                on_window(t)
            angs.append(dof_angles(scene, sim.pos, sim.quat))
            for p in names:
                v = res.probes[p]
                means[p].append(float(np.mean(v[1:] if len(v) > 1 else v)))
            if t >= next_rec - 1e-9:
                sh = _shape_row(scene, rm, state, sim.pos.copy(), sim.quat.copy())
                hist.append({"t": round(t, 3), "turns": sh["turns_read"], "shape": sh["shape_read"]})
                next_rec += every
            first = plateau_start(ends, window, t)
            if first >= 0 and t >= t_min - 1e-12:
                block = (len(ends) - first) * window / MIN_WINDOWS
                circ_ok = all(np.ptp([np.mean(b) for b in np.array_split(means[p][first:], MIN_WINDOWS)])
                              < plateau_tol(kT, sim.k0, 0.0, tau, block) for p in circ)
                ang_ok, detail = angles_relaxed(angs[first:], block, tau)
                if circ_ok and ang_ok:
                    relaxed = True
                    break
            if t >= max_time - 1e-9:
                break
    finally:
        sim.dt = dt_run
    k = max(first, 0) if relaxed else max(len(ends) - MIN_WINDOWS, 0)
    return {p: float(np.mean(means[p][k:])) for p in names}, t, relaxed, detail, hist


def _shape_row(scene, rm, state, pos, quat, probe_means: dict | None = None) -> dict:
    got = read_shape(scene, pos, quat, state)
    if probe_means:
        for d, dm in zip(got["dofs"], rm["dofs"]):
            L = probe_means.get(f"dof_{d['name']}")
            if L is not None and "target" in d:
                d["mean_angle"] = dof_angle_from_length(rm, dm["side"], L)
                d["mean_error"] = d["mean_angle"] - d["target"]
    pose = rm["poses"].get(state)
    if pose is None:
        raise MlcError(f"robot scene {scene.name} has no expected pose for row {state}", scene.source or scene.name)
    exp_q = [int(t) // 90 for t in pose["turns"]]
    ok = got["quarter_turns"] == exp_q
    # a turn error per unit: measured minus expected (deg)
    terr = [t - 90.0 * e for t, e in zip(got["turns"], exp_q)]
    derr = [abs(d["error"]) for d in got["dofs"] if "error" in d]
    merr = [abs(d["mean_error"]) for d in got["dofs"] if "mean_error" in d]
    extra = {"max_dof_mean_error_deg": max(merr)} if merr else {}
    return {**extra, "shape_expected": pose.get("shape", state), "turns_expected": [90 * e for e in exp_q],
            "turns_read": [round(t, 3) for t in got["turns"]], "cells_expected": [list(c) for c in walk(exp_q)],
            "cells_read": got["cells"], "turn_errors_deg": [round(e, 3) for e in terr],
            "dof_angles": got["dofs"], "max_dof_error_deg": max(derr, default=0.0),
            "max_dof_error_rad": math.radians(max(derr, default=0.0)), "shape_ok": bool(ok),
            "shape_read": _name_of(got["quarter_turns"], rm)}


def _name_of(q, rm) -> str:
    for row, p in rm["poses"].items():
        if [int(t) // 90 for t in p["turns"]] == q:
            return p.get("shape", row)
    return "?" + "".join({-1: "d", 0: "s", 1: "u", 2: "x"}[k] for k in q)


def _clearance_row(scene: Scene, pos=None, quat=None) -> dict:
    """The oriented-box slab test (:func:`mlc.verify.overlap.clearance`) of ``scene`` posed at
    ``pos``/``quat`` (default: as built): smallest clearance (sigma; negative: the deepest
    interpenetration), its pair of bodies, and the first 10 interpenetrating pairs."""
    from mlc.verify.overlap import clearance

    c = clearance(scene, pos, quat)
    return {"clearance": c.min_clearance if abs(c.min_clearance) > 1e-12 else 0.0, "clearance_pair": list(c.pair), "overlaps": [list(o) for o in c.overlaps[:10]],
            "n_overlaps": len(c.overlaps), "clearance_ok": bool(c.ok())}


def verify_robot_static(scene: Scene, rows=None, steps: int = STEPS, progress=None, keep_poses: bool = False,
                        clearance: bool = True, jobs: int = 1, require_clearance: bool = False) -> Report:
    """Static check of every row (see the module doc).  With ``clearance`` each row's
    equilibrium and the scene as built also get the slab-overlap test (docs/robot.md 3):
    reported, a warning when slabs interpenetrate, part of a row's verdict only with
    ``require_clearance`` (a row whose pose interpenetrates fails).  ``jobs``:
    rows solved at once, each in a forked process (:func:`mlc.verify.circuit.map_rows`;
    the same report for any ``jobs``)."""
    from mlc.verify.circuit import map_rows

    rm = robot_meta(scene)
    states = select_rows(scene, rows)
    t0 = time.perf_counter()
    rep = Report(scene.name, "static", params={"tol_length": TOL_LENGTH, "tol_stretch": TOL_STRETCH, "steps": steps,
                                               "robot": True, "require_clearance": bool(require_clearance)})
    if clearance:
        rep.params["as_built"] = _clearance_row(scene)
    poses = {}
    for entries, row, pose in map_rows(lambda state: _static_row(scene, rm, state, steps, clearance), states, jobs,
                                       progress):
        rep.entries.extend(entries)
        if require_clearance and clearance and not row["clearance_ok"]:
            row["ok"] = False
        rep.rows.append(row)
        poses[row["state"]] = pose
    rep.seconds = time.perf_counter() - t0
    if keep_poses:
        rep.poses = poses
    return rep


def _static_row(scene: Scene, rm, state: str, steps: int, clearance: bool) -> tuple[list, dict, tuple]:
    """One row of :func:`verify_robot_static`: its entries, its summary and its pose (pos, quat)."""
    from mlc.verify.circuit import probe_entry
    from mlc.verify.static import equilibrium

    t_row = time.perf_counter()
    eq = equilibrium(scene, state, steps=steps)
    row_ok = eq.max_joint_stretch <= TOL_STRETCH
    entries = []
    for pr in scene.probes:
        # a DOF's stroke may be longer than a gate's 0.5 sigma: the tolerance grows with it
        entry = probe_entry(scene, pr, state, eq.probes[pr.name],
                            TOL_LENGTH * max(1.0, abs(pr.actuated - pr.rest) / 0.5))
        if pr.name.startswith("dof_"):
            entry["output"] = pr.name
        row_ok &= entry["ok"]
        entries.append(entry)
    row = {"state": state, "joint_stretch": eq.max_joint_stretch}
    row.update(_shape_row(scene, rm, state, eq.pos, eq.quat))
    if clearance:                      # slab overlap in the row's pose (a printability check, not the shape's)
        row.update(_clearance_row(scene, eq.pos, eq.quat))
    row["ok"] = bool(row_ok and row["shape_ok"])
    row["seconds"] = time.perf_counter() - t_row
    return entries, row, (eq.pos, eq.quat)


def verify_robot_dynamic(scene: Scene, rows=None, kT: float = 1e-5, seeds: int = 3, scheme: str | None = None,
                         max_time: float | None = None, progress=None, keep_poses: bool = False,
                         tau: float | None = None, dt: float | None = None, first_seed: int = 0,
                         clearance: bool = True, require_clearance: bool = False) -> Report:
    """Brownian dynamics from rest into each row, ``seeds`` seeds, until relaxed
    (:func:`run_fold`: at least 3 tau, circuit outputs on a plateau, joint angles within
    their thermal noise) or ``max_time`` t0 (default the paper's 1800 t0); the shape is
    read from each seed's final poses (see the module doc).
    ``scheme``: the integrator (default ``ROBOT_SCHEME``); ``dt`` (t0): its step (default ``ROBOT_DT``); ``tau`` (t0): the slowest
    relaxation time (default ``ROBOT_TAU``, measured on the robots' folds, docs/robot.md
    section 3; ``"compute"`` runs :func:`mlc.verify.dynamic.relaxation_time` at the rest pose,
    densely up to ``DENSE_ROBOT`` coordinates: seconds for the 524-body per-lever Tetris robot;
    a larger one takes the sparse Lanczos, more than 8 min for a 2000-body robot).  Seeds are ``first_seed``, ``first_seed + 1``, ...
    With ``clearance`` each seed's final pose gets the slab test (:func:`_clearance_row`): the
    model has WCA between body centres only (the paper's), so slabs may end inside each other,
    which a print could not do; the report warns, and ``require_clearance`` fails such a row."""
    from mlc.io.progress import Progress
    from mlc.sim.drive import Drive
    from mlc.sim.integrator import SimOptions, Simulation, check_kT
    from mlc.verify.dynamic import DENSE_ROBOT, TAU_FACTOR, relaxation_time

    rm = robot_meta(scene)
    states = select_rows(scene, rows)
    scheme = ROBOT_SCHEME if scheme is None else scheme
    if int(seeds) < 1:
        raise MlcError(f"need at least one seed, got {seeds}", "--seeds")
    check_kT(kT)
    for opt, v in (("--tau", tau), ("--dt", dt)):
        if v is not None and not (isinstance(v, str) and v == "compute" and opt == "--tau") \
                and not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
            raise MlcError(f"{opt} must be a finite time > 0 (t0), got {v}", opt)
    t0 = time.perf_counter()
    opt0 = SimOptions(scheme=scheme)
    if tau == "compute":
        tau = relaxation_time(scene, gamma_r=opt0.gamma_r, dense_max=DENSE_ROBOT)
    tau = ROBOT_TAU if tau is None else float(tau)
    dt = ROBOT_DT if (dt is None and scheme in ("stiff", "implicit")) else dt
    rep = Report(scene.name, "dynamic", params={"kT": kT, "seeds": int(seeds), "first_seed": int(first_seed),
                                                "scheme": scheme, "tau": tau, "dt": dt, "robot": True,
                                                "disp_acc": ROBOT_DISP_ACC if scheme in ("stiff", "implicit") else None,
                                                "fold_dt": fold_step(scheme, dt, 0.0) if dt is not None else None,
                                                "fold_time": ROBOT_FOLD_TIME if scheme == "implicit" else 0.0,
                                                "require_clearance": bool(require_clearance)})
    poses = {}
    total, done = len(states) * int(seeds), 0
    bar = Progress(f"dynamic check of {scene.name}", total=total, show=None if progress is None else False)
    with bar:
        for state in states:
            want = scene.truth_table.get(state)
            drives = {inp: Drive.constant(int(b)) for inp, b in zip(scene.inputs, state)}
            t_max = float(max_time) if max_time is not None else FOLD_TIME
            per = []
            for seed in range(int(first_seed), int(first_seed) + int(seeds)):
                sim = Simulation(scene, drives, SimOptions(scheme=scheme, kT=kT, seed=seed,
                                                           dt=None if dt is None else float(dt),
                                                           disp_acc=ROBOT_DISP_ACC))
                # the bar moves within a fold: time run over 3 tau (tau at rest)
                inner = bar.within(done, TAU_FACTOR * tau if state != "0" * len(scene.inputs) else tau)
                means, t_rel, relaxed, _, _ = run_fold(sim, scene, state, kT, tau, t_max, on_window=inner)
                shape = _shape_row(scene, rm, state, sim.pos.copy(), sim.quat.copy(), means)
                if clearance:                  # slab overlap in the final pose (a print's concern, not the shape's)
                    shape["end"] = _clearance_row(scene, sim.pos, sim.quat)
                per.append((means, t_rel, relaxed, shape))
                poses[(state, seed)] = (sim.pos.copy(), sim.quat.copy())
                done += 1
                bar.update(done)
                if callable(progress):
                    progress(done, total)
            row_ok = True
            for pr in scene.probes:
                k = scene.outputs.index(pr.output)
                bit = None if want is None or want[k] == "-" else int(want[k])
                vals = [m[pr.name] for m, *_ in per]
                margins = None if bit is None else [float(pr.margin(v, bit)) for v in vals]
                ok = bit is None or all(pr.bit(v) == bit and m > 0 for v, m in zip(vals, margins))
                row_ok &= ok
                rep.entries.append({"state": state, "output": pr.name if pr.name.startswith("dof_") else pr.output,
                                    "expected": bit, "measured": float(np.mean(vals)), "bit": pr.bit(float(np.mean(vals))),
                                    "margin": None if margins is None else min(margins), "per_seed": vals,
                                    "ok": bool(ok)})
            shapes = [sh for *_, sh in per]
            worst = max(shapes, key=lambda sh: (not sh["shape_ok"], sh["max_dof_error_deg"]))
            row = {"state": state, "relax_time": max(t for _, t, _, _ in per),
                   "relaxed": all(r for _, _, r, _ in per), "seeds": int(seeds)}
            row.update({k: v for k, v in worst.items() if k != "end"})
            if clearance:                      # the seed whose final pose interpenetrates deepest
                s_end, end = min(enumerate((sh["end"] for sh in shapes), start=int(first_seed)),
                                 key=lambda e: e[1]["clearance"])
                row["end"] = dict(end, seed=s_end)
            row["max_dof_mean_error_deg"] = max(sh.get("max_dof_mean_error_deg", 0.0) for sh in shapes)
            row["max_dof_mean_error_rad"] = math.radians(row["max_dof_mean_error_deg"])
            row["per_seed"] = [{"seed": s, "shape_read": sh["shape_read"], "turns_read": sh["turns_read"],
                                "max_dof_error_deg": sh["max_dof_error_deg"],
                                "max_dof_mean_error_deg": sh.get("max_dof_mean_error_deg"), "time": t,
                                "dof_angles": sh["dof_angles"],
                                **({"clearance_end": sh["end"]["clearance"], "clearance_pair_end": sh["end"]["clearance_pair"]}
                                   if clearance else {})}
                               for s, (_, t, _, sh) in enumerate(per, start=int(first_seed))]
            row["shape_ok"] = all(sh["shape_ok"] for sh in shapes)
            row["ok"] = bool(row_ok and row["shape_ok"])
            if require_clearance and clearance and not row["end"]["clearance_ok"]:
                row["ok"] = False
            rep.rows.append(row)
    rep.seconds = time.perf_counter() - t0
    if keep_poses:
        rep.poses = poses
    return rep


def verify_robot(scene: Scene, dynamic: bool = False, kT: float = 1e-5, seeds: int = 3, scheme: str | None = None,
                 rows=None, tau: float | None = None, dt: float | None = None, jobs: int = 1,
                 require_clearance: bool = False) -> Report:
    """``mlc verify`` of a robot scene: static (default; ``jobs`` rows at once) or by
    Brownian dynamics (``scheme`` default ``ROBOT_SCHEME``; ``tau`` and ``dt`` in t0, defaults
    ``ROBOT_TAU`` and ``ROBOT_DT``).  ``require_clearance``: a row whose pose (static) or a
    seed's final pose (dynamic) has slabs inside each other fails."""
    from mlc.io.progress import Progress

    robot_meta(scene)
    if dynamic:
        return verify_robot_dynamic(scene, rows, kT=kT, seeds=seeds, scheme=scheme, tau=tau, dt=dt,
                                    require_clearance=require_clearance)
    n = len(select_rows(scene, rows))
    with Progress(f"static verification of {scene.name}", total=n) as bar:
        return verify_robot_static(scene, rows, progress=lambda done, total: bar.update(done), jobs=jobs,
                                   require_clearance=require_clearance)


def _steps_text(p: dict) -> str:
    """', implicit scheme, dt 0.8 t0 (0.2 over the first 50 t0)' from a dynamic report's params."""
    if not p.get("scheme"):
        return ""
    out = f", {p['scheme']} scheme"
    if p.get("dt") is not None:
        out += f", dt {p['dt']:g} t0"
        if p.get("fold_time") and p.get("fold_dt") is not None and p["fold_dt"] < p["dt"]:
            out += f" ({p['fold_dt']:g} over the first {p['fold_time']:g} t0)"
    return out


def format_robot_report(rep: Report) -> str:
    """The probe table of :func:`mlc.verify.circuit.format_report` (circuit outputs and DOF
    lengths), then one line per row: shape read vs expected, turns (deg) and the largest
    DOF angle error."""
    from mlc.verify.circuit import format_report

    table = [ln for ln in format_report(rep).splitlines() if not ln.startswith(("all ", "WRONG", "WARNING: row"))]
    lines = table + [f"{rep.scene}: {rep.mode} verification of the skeleton, {len(rep.rows)} rows"
             + (f", {rep.params.get('seeds')} seeds, kT = {rep.params.get('kT')}" + _steps_text(rep.params)
                if rep.mode == "dynamic" else "")]
    for r in rep.rows:
        turns = " ".join(f"{t:+7.2f}" for t in r["turns_read"])
        tail = (f"stretch {r['joint_stretch']:.1e}" if rep.mode == "static"
                else f"(time-averaged {r['max_dof_mean_error_deg']:.2f} deg)  t = {r['relax_time']:.1f} t0"
                     f"{'' if r['relaxed'] else ' (not relaxed)'}")
        lines.append(f"row {r['state']}: shape {r['shape_read']:<6} expected {r['shape_expected']:<6} turns (deg) "
                     f"{turns}  largest DOF error {r['max_dof_error_deg']:.2f} deg ({r['max_dof_error_rad']:.4f} rad)"
                     f"  {tail}  {'ok' if r['ok'] else 'WRONG'}")
    built = rep.params.get("as_built")
    if built is not None:
        lines.append(f"slab clearance as built: {built['clearance']:+.4f} sigma ({'/'.join(built['clearance_pair'])})"
                     + ("" if "clearance" not in (rep.rows[0] if rep.rows else {}) else
                        "; in the rows' poses: " + ", ".join(f"{r['state']} {r['clearance']:+.4f}" for r in rep.rows)))
    for r in [dict(built, state="as built")] if built and built.get("overlaps") else []:
        a, b, d = r["overlaps"][0]
        lines.append(f"WARNING: {r['state']}: slabs {a} and {b} interpenetrate by {d:.4f} sigma "
                     f"({r['n_overlaps']} pairs); smallest clearance {r['clearance']:+.4f} sigma (not printable as built)")
    word = "WRONG" if rep.params.get("require_clearance") else "WARNING"
    for r in rep.rows:
        if r.get("overlaps"):
            a, b, d = r["overlaps"][0]
            lines.append(f"{word}: row {r['state']}: slabs {a} and {b} interpenetrate by {d:.4f} sigma "
                         f"({r['n_overlaps']} pairs) in the static pose; smallest clearance {r['clearance']:+.4f} sigma")
    if any("end" in r for r in rep.rows):
        lines.append("slab clearance at the end of the runs (the deepest seed): "
                     + ", ".join(f"{r['state']} {r['end']['clearance']:+.4f}" for r in rep.rows))
    for r in rep.rows:
        e = r.get("end")
        if e and e.get("overlaps"):
            a, b, d = e["overlaps"][0]
            lines.append(f"{word}: row {r['state']}: slabs {a} and {b} end {d:.4f} sigma inside each other "
                         f"({e['n_overlaps']} pairs, seed {e['seed']}): the simulation's contact is between body "
                         f"centres only (the paper's model); printed parts could not pass there")
    for r in rep.rows:
        if not r["shape_ok"]:
            lines.append(f"WRONG: row {r['state']}: the skeleton folded into {r['shape_read']} (turns "
                         f"{[round(t) for t in r['turns_read']]}, cells {r['cells_read']}), expected "
                         f"{r['shape_expected']} (turns {r['turns_expected']}, cells {r['cells_expected']})")
        elif not r["ok"]:
            bad = [e for e in rep.entries if e["state"] == r["state"] and not e["ok"]]
            what = ", ".join(f"{e['output']} read {e['measured']:.3f}" for e in bad[:4])
            if rep.mode == "static" and r["joint_stretch"] > TOL_STRETCH:
                what = (what + ", " if what else "") + f"joint stretch {r['joint_stretch']:.2e} sigma"
            if what:                           # else the slabs alone (--require-clearance: its line above)
                lines.append(f"WRONG: row {r['state']}: {what}")
    lines.append(f"all {len(rep.rows)} rows fold correctly ({rep.seconds:.1f} s)" if rep.ok else
                 f"FAILED: rows {', '.join(r['state'] for r in rep.rows if not r['ok'])}")
    return "\n".join(lines)


def format_any(rep: Report) -> str:
    """:func:`format_robot_report` for a robot's report, else the circuit's table."""
    if rep.params.get("robot"):
        return format_robot_report(rep)
    from mlc.verify.circuit import format_report
    return format_report(rep)


__all__ = ["FOLD_TIME", "ROBOT_DISP_ACC", "ROBOT_DT", "ROBOT_FOLD_DT", "ROBOT_FOLD_TIME", "fold_step", "ROBOT_TAU", "angles_relaxed", "dof_angles", "format_any", "run_fold", "format_robot_report", "read_shape", "robot_meta", "verify_robot_dynamic", "verify_robot_static"]
