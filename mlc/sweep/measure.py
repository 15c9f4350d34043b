"""One run of a sweep: build the scene, drive it, simulate, measure.  Runs in a Dask worker.

Measurements (all lengths in sigma, times in t0):

* ``square_response`` (paper Fig. 5C): the input ``drive_input`` follows a square wave of
  ``frequency`` (high for the first ``duty`` of each period, from t = 0), the other inputs
  the constants of ``inputs``; ``cycles`` periods are simulated with ``samples_per_cycle``
  probe samples each.  The response is the probe's *normalised state*
  y(t) = (L(t) - L0)/(L1 - L0) (0 at the state-0 length, 1 at the state-1 length: the
  deviation is a fraction of the 0.5 sigma signal swing) and the ideal response is the
  drive u(t) (0 or 1).  Columns: ``rms_dev`` = sqrt(time average of (y - u)^2) over every
  period but the first (the periodic regime; trapezoidal in time, u piecewise constant:
  see :func:`_rms`), ``rms_dev_all`` over all periods, ``rms_dev_l1``
  the same as ``rms_dev`` but with deviations measured as a fraction of the state-1
  length L1 (the paper's "signal length" scale), ``y_high``/``y_low`` (mean y over the
  last 20 % of the high/low half periods after the first period: how far the output gets)
  and ``lag`` (time from each rising edge until y first crosses 0.5, averaged; NaN if it
  never does).
* ``steady`` (paper Fig. 5D): constant drives ``inputs``; after ``time`` t0, every
  probe's mean, variance over time (population) and fraction of samples on the wrong
  side of its threshold (``{probe}_mean``, ``{probe}_var``, ``{probe}_wrong``, the
  expected bit from the scene's truth table) over the last ``window`` of the run,
  ``{probe}_off`` (fraction of samples farther than half the swing |L1 - L0|/2 from the
  expected state's length: a wrong bit, or no bit at all, e.g. a collapsed chain reading
  0.3 sigma for a 1.0/1.5 sigma signal, which the threshold alone reads as 0), and
  ``{probe}_drift``: the mean of the window's second half less that of its first half
  (a check that the run was long enough to be stationary).
"""
from __future__ import annotations

import math
import time
import traceback

import numpy as np


def _scene(scene: str, params: dict):
    from mlc.sweep.scenes import BUILDERS
    fn, defaults = BUILDERS[scene]
    return fn(**{k: params[k] for k in defaults})


def check_names(scene_obj, measure: str, params: dict) -> list[tuple[str, str]]:
    """(parameter, message) for every input or probe the spec names that the scene lacks."""
    bad = []
    ins = set(scene_obj.inputs)
    for k in params.get("inputs", {}) or {}:
        if k not in ins:
            bad.append(("inputs", f"scene {scene_obj.name} has no input {k!r} (inputs: {', '.join(sorted(ins))})"))
    if measure == "square_response":
        if params["drive_input"] not in ins:
            bad.append(("drive_input", f"scene {scene_obj.name} has no input {params['drive_input']!r} "
                                       f"(inputs: {', '.join(sorted(ins))})"))
        if params["probe"] not in {p.name for p in scene_obj.probes}:
            bad.append(("probe", f"scene {scene_obj.name} has no probe {params['probe']!r} "
                                 f"(probes: {', '.join(p.name for p in scene_obj.probes)})"))
    return bad


def _options(params: dict, seed: int):
    from mlc.sim.integrator import SimOptions
    return SimOptions(dt=params["dt"], scheme=params["scheme"], kT=float(params["kT"]), seed=int(seed),
                      fluct=bool(params["fluct"]), rot_noise=bool(params["rot_noise"]),
                      disp_acc=float(params["drift_tol"]), gamma_r=params.get("gamma_r"))


def _times(res) -> np.ndarray:
    """The run's record times (t0): exact multiples of its step, however the integrator
    chunked the run (chunks follow the machine's load), so every measurement is the same to
    the last digit with 1 or 2 workers."""
    return np.asarray(res.times, dtype=float)


def _rms(t, y, drive, mask) -> float:
    """sqrt(time average of (y - u)^2) over the samples in ``mask`` (a contiguous run).

    The drive u is piecewise constant and jumps at its switching instants, which need not
    fall on a sample (Euler's record times drift off them) or fall exactly on one (where
    u(t) alone would count the old output against the new drive for a whole sample
    interval: 6 such samples in 800 added 0.01 to the mean square of a 1-unit chain at
    0.05/t0).  So the switching instants are inserted into the time grid (y interpolated
    linearly there) and the square deviation is integrated by the trapezoidal rule on
    each interval with u at its midpoint."""
    idx = np.flatnonzero(mask)
    tt, yy = t[idx], y[idx]
    if len(tt) < 2:
        return float("nan")
    if drive.kind == "square":
        period, duty, start = drive.params[:3]
        k = np.arange(math.floor((tt[0] - start) / period), math.ceil((tt[-1] - start) / period) + 1)
        edges = np.concatenate([start + k * period, start + (k + duty) * period])
        edges = edges[(edges > tt[0]) & (edges < tt[-1])]
        grid = np.union1d(tt, edges)
        yy = np.interp(grid, tt, yy)
        tt = grid
    um = np.array([drive.value(0.5 * (a + b)) for a, b in zip(tt[:-1], tt[1:])])
    e = 0.5 * ((yy[:-1] - um) ** 2 + (yy[1:] - um) ** 2) * np.diff(tt)
    return float(math.sqrt(e.sum() / (tt[-1] - tt[0])))


def square_response(scene, params: dict, seed: int):
    from mlc.sim.drive import Drive
    from mlc.sim.integrator import Simulation
    f = float(params["frequency"])
    period = 1.0 / f
    cyc = int(params["cycles"])
    duty = float(params["duty"])
    drives = {k: Drive.constant(v) for k, v in (params.get("inputs") or {}).items()}
    drives[params["drive_input"]] = Drive.square(period, duty)
    sim = Simulation(scene, drives, _options(params, seed))
    rec = period / int(params["samples_per_cycle"])
    res = sim.run(period * cyc, record_interval=rec, quiet=True)
    pr = next(p for p in scene.probes if p.name == params["probe"])
    L0, L1 = pr.rest, pr.actuated
    t = _times(res)
    u = np.array([drives[params["drive_input"]].value(x) for x in t])
    # a sample at a switching instant belongs to the new state already (drive value at t)
    traces = {}
    for p in scene.probes:
        traces[p.name] = (np.asarray(res.probes[p.name]) - p.rest) / (p.actuated - p.rest)
    y = traces[pr.name]
    steady = t >= period - 1e-12
    drv = drives[params["drive_input"]]
    row = {
        "rms_dev": _rms(t, y, drv, steady),
        "rms_dev_all": _rms(t, y, drv, np.ones_like(steady)),
        "rms_dev_l1": _rms(t, y, drv, steady) * (L1 - L0) / L1,
    }
    phase = (t % period) / period
    hi = steady & (phase >= 0.8 * duty) & (phase < duty)
    lo = steady & (phase >= duty + 0.8 * (1 - duty))
    row["y_high"] = float(np.mean(y[hi])) if hi.any() else float("nan")
    row["y_low"] = float(np.mean(y[lo])) if lo.any() else float("nan")
    lags = []
    for k in range(cyc):
        t0 = k * period
        m = (t >= t0) & (t < t0 + duty * period) & (y >= 0.5)
        if m.any():
            lags.append(float(t[m][0] - t0))
    row["lag"] = float(np.mean(lags)) if len(lags) == cyc else float("nan")
    row.update({"steps": int(res.steps), "force_evals": int(res.force_evals), "dt_used": float(res.dt)})
    trace = {"time": t, "drive": u, **{f"y_{k}": v for k, v in traces.items()}}
    return row, trace


def steady(scene, params: dict, seed: int):
    from mlc.sim.drive import Drive
    from mlc.sim.integrator import Simulation
    drives = {k: Drive.constant(v) for k, v in (params.get("inputs") or {}).items()}
    sim = Simulation(scene, drives, _options(params, seed))
    T = float(params["time"])
    rec = params["record"] if params["record"] is not None else T / 2000.0
    res = sim.run(T, record_interval=rec, quiet=True)
    t = _times(res)
    m = t >= T * (1.0 - float(params["window"])) - 1e-12
    state = "".join(str(int(round(drives[i].value(0.0)))) if i in drives else "0" for i in scene.inputs)
    expected = scene.truth_table.get(state)
    row = {}
    for j, p in enumerate(scene.probes):
        x = np.asarray(res.probes[p.name])[m]
        row[f"{p.name}_mean"] = float(np.mean(x))
        row[f"{p.name}_var"] = float(np.var(x))
        h = len(x) // 2
        row[f"{p.name}_drift"] = float(np.mean(x[h:]) - np.mean(x[:h])) if h else float("nan")
        if expected is not None and j < len(expected) and expected[j] in "01":
            bits = np.array([p.bit(v) for v in x])
            row[f"{p.name}_wrong"] = float(np.mean(bits != int(expected[j])))
            want = p.actuated if expected[j] == "1" else p.rest
            row[f"{p.name}_off"] = float(np.mean(np.abs(x - want) > 0.5 * abs(p.actuated - p.rest)))
    row["samples"] = int(m.sum())
    row.update({"steps": int(res.steps), "force_evals": int(res.force_evals), "dt_used": float(res.dt)})
    return row, None


MEASURES = {"square_response": square_response, "steady": steady}


def run_task(task: dict) -> dict:
    """Run one task (see :meth:`mlc.sweep.spec.Run.task`); never raises: a failure is a
    result with ``status`` "failed" and its ``error``.  Returns
    {"run_id", "index", "status", "error", "wall_s", "row": {...}, "trace": {...} or None}."""
    t = time.perf_counter()
    out = {"run_id": task["run_id"], "index": task["index"], "status": "ok", "error": "", "row": {}, "trace": None}
    try:
        sc = _scene(task["scene"], task["params"])
        row, trace = MEASURES[task["measure"]](sc, task["params"], task["seed"])
        bad = [k for k, v in row.items() if isinstance(v, float) and not math.isfinite(v)
               and k != "lag" and not k.endswith("_drift")]
        out["row"], out["trace"] = row, trace
        if bad:
            out["status"], out["error"] = "failed", f"non-finite measurement: {', '.join(bad)}"
    except Exception as e:  # noqa: BLE001 - a failed run is a row, whatever went wrong
        from mlc.errors import MlcError
        out["status"] = "failed"
        msg = e.format() if isinstance(e, MlcError) else f"{type(e).__name__}: {e}"
        if not isinstance(e, MlcError) and not isinstance(e, (ValueError, ArithmeticError)):
            msg += " | " + traceback.format_exc(limit=3).replace("\n", " ")[-400:]
        out["error"] = " ".join(msg.split())
    out["wall_s"] = time.perf_counter() - t
    return out
