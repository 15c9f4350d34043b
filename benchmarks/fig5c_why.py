"""Why mlc's Fig. 5C circuit relaxes ~100x more slowly than the paper's RMS deviations imply
(issue 11, docs/reproduction.md section 2, "Why").

    python benchmarks/fig5c_why.py [--parts linear,step,jointk,rigid_gr,timeunit,ramp,floor] [--seeds 2]
        # writes benchmarks/results/fig5c_why.json

Parts (units: sigma, k0, gamma, t0 = gamma/(1e-3 k0)):

* ``linear``: for the gate alone, the chain alone (1, 5, 10 units, driven by a muscle) and
  the paper's circuit AND -> n-unit chain -> AND (``and_chain_and``, n = 1, 5, 10), the mean
  response time T of the signal (:func:`mlc.verify.dynamic.signal_time`, the integral of
  the remaining step response in the linearised overdamped dynamics) and the slowest
  relaxation time tau (:func:`mlc.verify.dynamic.relaxation_time`), with every joint
  bond's stiffness multiplied by 1, 10, 100 and 1000 (muscles stay k0).  T is a sum over bodies
  (``T = sum_i gamma_i (H^+ g)_i (H^+ f)_i / g.H^+ f``: the drag of each body times the
  path's compliance it sits behind, the mechanical Elmore delay): split by gate 1,
  chain, gate 2 and translation / rotation for the chain-end probe; the probe's
  stiffness ``1 / g.H^+ g`` is given too, and T with the rotational drag gamma_r = 0.01 gamma
  (``T_probe_gr0.01``).  The circuit's ``signal_time`` is the largest over its probes; its
  output probe sits on a nearly free mode at the rest pose (stiffness 3e-4 k0), so the
  chain-end probe is the one decomposed.
* ``step``: the check of the linear analysis by simulation: the circuit (1 and 5 units)
  posed in row in=0, hold=1, both muscles of gate 1 switched on at t = 0, kT = 0, stiff
  scheme at dt = 0.01 and 0.002 t0; T_sim = integral of 1 - (L(t) - L(0))/(L(end) - L(0))
  for the chain-end and output probes, and tau_sim = the exponential tail's time constant
  (log-linear fit where the remainder is between 10 % and 0.3 % of the swing).
* ``jointk``: Fig. 5C's RMS deviation (``mlc.sweep.measure.square_response``, the sweep's
  own measurement, 5 units, 5/0.5/0.05 t0^-1, kT = 1e-5, stiff dt = 0.01 t0 or P/200)
  with joints 1, 100 and 1000 k0.
* ``rigid_gr``: the same with joints 1000 k0 and the rotational drag gamma_r = 0.01 gamma.
* ``timeunit``: the 5-unit circuit (joints k0) at 5/s, 0.5/s, 0.05/s t0^-1 for a time unit
  s = 100 times mlc's (the paper's t0 read as 100 of mlc's).
* ``ramp``: the drive as the muscles' rest length changing at a finite rate: a trapezoid
  with ramps of a fraction r of the half period, the RMS deviation of the output from
  the ramped drive itself (5 units, joints k0, the three frequencies).
* ``floor``: the noise floor: the thermal sd of the output about each of its two states
  at kT = 1e-5 (harmonic, :func:`mlc.verify.dynamic.probe_thermal_sd`) against a
  simulated steady run from the row's static equilibrium (20 t0, last 15 t0), as a fraction of the 0.5 sigma swing.
"""
from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))

FREQS = (5.0, 0.5, 0.05)
PAPER = {5.0: 17.0, 0.5: 4.5, 0.05: 3.6}       # %, 5 units


def _scene(kind: str, n: int = 0, joint_k: float = 1.0):
    from mlc.sweep.scenes import and_chain_and, chain, gate
    sc = {"gate": lambda: gate("AND"), "chain": lambda: chain(n), "circuit": lambda: and_chain_and(n)}[kind]()
    for b in sc.bonds:
        b.k *= joint_k
    return sc


ROWS = {"gate": ("00", "11"), "chain": ("0", "1"), "circuit": ("01", "11")}


def elmore(scene, start: str, state: str, probe: str, gamma_r: float = 1.0):
    """(T in t0, probe stiffness in k0, {group: (translation, rotation) share of T})."""
    from mlc.verify.dynamic import _factorised, _probe_gradients
    from mlc.verify.static import _Problem
    A = scene.arrays()
    prob = _Problem(scene, A.pos, A.quat, pin_first=False)
    J, lu, _ = _factorised(prob)
    a = np.asarray([int(c) for c in start], float)[A.muscle_input]
    b = np.asarray([int(c) for c in state], float)[A.muscle_input]
    dL = np.array([m.actuated - m.rest for m in scene.muscles]) * (b - a)
    r = np.zeros(prob.m)
    r[prob.m - len(A.muscle_i):] = np.sqrt(A.muscle_k) * dL
    yf = lu.solve(J.T @ r)
    g = _probe_gradients(prob, scene)[:, [p.name for p in scene.probes].index(probe)]
    yg = lu.solve(g)
    drag = np.tile(np.r_[np.ones(3), np.full(3, gamma_r)], prob.N)
    c = (drag * yg * yf).reshape(-1, 6) / float(g @ yf) / 1000.0
    groups: dict = {}
    for body, ci in zip(scene.bodies, c):
        key = {"g1": "gate1", "g2": "gate2", "c": "chain"}.get(body.name.split("_")[0], "gate")
        tr, ro = groups.get(key, (0.0, 0.0))
        groups[key] = (tr + float(ci[:3].sum()), ro + float(ci[3:].sum()))
    return float(c.sum()), 1.0 / float(g @ yg), groups


def part_linear():
    from mlc.verify.dynamic import relaxation_time, signal_time
    out = []
    for jk in (1.0, 10.0, 100.0, 1000.0):
        for kind, n in (("gate", 0), ("chain", 1), ("chain", 5), ("chain", 10),
                        ("circuit", 1), ("circuit", 5), ("circuit", 10)):
            sc = _scene(kind, n, jk)
            s0, s1 = ROWS[kind]
            row = {"scene": kind, "units": n, "bodies": len(sc.bodies), "joint_k": jk,
                   "T_signal": signal_time(sc, s0, s1)}
            if len(sc.bodies) * 6 <= 1800:
                row["tau_slowest"] = relaxation_time(sc)
            probe = "chain" if kind == "circuit" else "out"
            T, kp, groups = elmore(sc, s0, s1, probe)
            row.update({"probe": probe, "T_probe": T, "k_probe": kp, "T_parts": groups,
                        "T_probe_gr0.01": elmore(sc, s0, s1, probe, gamma_r=0.01)[0]})
            print(json.dumps(row), flush=True)
            out.append(row)
    return out


def _step(n: int, dt: float, T: float, rec: float):
    from mlc.sim.drive import Drive
    from mlc.sim.integrator import SimOptions, Simulation
    sc = _scene("circuit", n)
    sim = Simulation(sc, {"in": Drive.constant(1), "hold": Drive.constant(1)},
                     SimOptions(dt=dt, scheme="stiff", kT=0.0, seed=0))
    res = sim.run(T, record_interval=rec, quiet=True)
    t = np.asarray(res.times)
    out = {}
    for p in ("chain", "out"):
        L = np.asarray(res.probes[p])
        rem = 1.0 - (L - L[0]) / (L[-1] - L[0])
        Tsim = float(np.sum(0.5 * (rem[1:] + rem[:-1]) * np.diff(t)))
        m = (np.abs(rem) < 0.1) & (np.abs(rem) > 0.003) & (t < 0.8 * t[-1])
        tau = float(-1.0 / np.polyfit(t[m], np.log(np.abs(rem[m])), 1)[0]) if m.sum() > 5 else float("nan")
        out[p] = {"T_sim": Tsim, "tau_tail": tau, "L0": float(L[0]), "L_end": float(L[-1])}
    return out


def part_step():
    from mlc.verify.dynamic import relaxation_time, signal_time
    from mlc.verify.static import equilibrium
    out = []
    for n, T in ((1, 8.0), (5, 30.0)):
        sc = _scene("circuit", n)
        eq = equilibrium(sc, "11")
        row = {"units": n, "T_signal": signal_time(sc, "01", "11"),
               "tau_start": relaxation_time(sc), "tau_end": relaxation_time(sc, eq.pos, eq.quat)}
        for dt in (0.01, 0.002):
            t = time.perf_counter()
            row[f"dt{dt}"] = _step(n, dt, T, 0.002)
            row[f"dt{dt}"]["wall_s"] = time.perf_counter() - t
        print(json.dumps(row), flush=True)
        out.append(row)
    return out


def _params(f: float, kT: float = 1e-5, dt: float | None = None):
    P = 1.0 / f
    return {"frequency": f, "cycles": 4, "duty": 0.5, "inputs": {"hold": 1}, "drive_input": "in",
            "samples_per_cycle": 2000 if f < 0.5 else 400, "probe": "out",
            "dt": dt if dt else min(0.01, P / 200), "scheme": "stiff", "kT": kT, "fluct": False,
            "rot_noise": False, "drift_tol": 0.01}


def part_jointk(seeds: int):
    from mlc.sweep.measure import square_response
    out = []
    for jk in (1.0, 100.0, 1000.0):
        for f in FREQS:
            vals, yh, yl = [], [], []
            t = time.perf_counter()
            for s in range(seeds):
                row, _ = square_response(_scene("circuit", 5, jk), _params(f), s)
                vals.append(100 * row["rms_dev"])
                yh.append(row["y_high"])
                yl.append(row["y_low"])
            r = {"joint_k": jk, "frequency": f, "rms_dev_pct": vals, "mean": float(np.mean(vals)),
                 "sd": float(np.std(vals, ddof=1)) if seeds > 1 else 0.0, "y_high": float(np.mean(yh)),
                 "y_low": float(np.mean(yl)), "paper": PAPER[f], "wall_s": time.perf_counter() - t}
            print(json.dumps(r), flush=True)
            out.append(r)
    # the step's accuracy with stiff joints: one seed at a fifth of the step
    for f in FREQS:
        row, _ = square_response(_scene("circuit", 5, 1000.0), _params(f, dt=min(0.002, 1 / f / 1000)), 0)
        r = {"joint_k": 1000.0, "frequency": f, "dt": min(0.002, 1 / f / 1000), "rms_dev_pct_seed0": 100 * row["rms_dev"]}
        print(json.dumps(r), flush=True)
        out.append(r)
    return out


def part_rigid_gr(seeds: int):
    """Fig. 5C, 5 units, joints 1000 k0 and rotational drag gamma_r = 0.01 gamma (a key the
    sweep's spec does not offer; ``square_response`` passes it to the integrator)."""
    from mlc.sweep.measure import square_response
    out = []
    for f in FREQS:
        vals = []
        t = time.perf_counter()
        for s in range(seeds):
            p = _params(f)
            p["gamma_r"] = 0.01
            row, _ = square_response(_scene("circuit", 5, 1000.0), p, s)
            vals.append(100 * row["rms_dev"])
        r = {"joint_k": 1000.0, "gamma_r": 0.01, "frequency": f, "rms_dev_pct": vals, "mean": float(np.mean(vals)),
             "sd": float(np.std(vals, ddof=1)) if seeds > 1 else 0.0, "paper": PAPER[f], "wall_s": time.perf_counter() - t}
        print(json.dumps(r), flush=True)
        out.append(r)
    return out


def part_timeunit():
    from mlc.sweep.measure import square_response
    out = []
    s = 100.0
    for f in FREQS:
        p = _params(f / s, dt=min(0.2, s / f / 200))
        p["cycles"] = 3
        t = time.perf_counter()
        row, _ = square_response(_scene("circuit", 5), p, 0)
        r = {"scale": s, "paper_frequency": f, "mlc_frequency": f / s, "dt": p["dt"], "rms_dev_pct": 100 * row["rms_dev"],
             "y_high": row["y_high"], "y_low": row["y_low"], "paper": PAPER[f], "wall_s": time.perf_counter() - t}
        print(json.dumps(r), flush=True)
        out.append(r)
    return out


def _trapezoid(P: float, r: float, cycles: int):
    """Table drive: 0 -> 1 over r*P/2 from each period's start, 1 -> 0 from its middle."""
    from mlc.sim.drive import Drive
    ramp = r * P / 2
    ts, vs = [], []
    for k in range(cycles):
        t0 = k * P
        for t, v in ((t0, 0.0), (t0 + ramp, 1.0), (t0 + P / 2, 1.0), (t0 + P / 2 + ramp, 0.0), (t0 + P, 0.0)):
            if not ts or t > ts[-1] + 1e-12 * P:
                ts.append(t)
                vs.append(v)
    return Drive.table(ts, vs)


def part_ramp():
    from mlc.sim.drive import Drive
    from mlc.sim.integrator import SimOptions, Simulation
    out = []
    sc = _scene("circuit", 5)
    pr = next(p for p in sc.probes if p.name == "out")
    for f in FREQS:
        P = 1.0 / f
        for r in (0.0, 0.5, 1.0):
            cyc = 4
            drv = Drive.square(P, 0.5) if r == 0 else _trapezoid(P, r, cyc)
            sim = Simulation(sc, {"in": drv, "hold": Drive.constant(1)},
                             SimOptions(dt=min(0.01, P / 200), scheme="stiff", kT=1e-5, seed=0))
            res = sim.run(P * cyc, record_interval=P / 2000, quiet=True)
            t = np.asarray(res.times)
            y = (np.asarray(res.probes["out"]) - pr.rest) / (pr.actuated - pr.rest)
            u = np.array([drv.value(x) for x in t])
            m = t >= P - 1e-12
            e = (y[m] - u[m]) ** 2
            rms = math.sqrt(float(np.sum(0.5 * (e[1:] + e[:-1]) * np.diff(t[m]))) / (t[m][-1] - t[m][0]))
            row = {"frequency": f, "ramp_fraction": r, "rms_dev_pct": 100 * rms, "paper": PAPER[f]}
            print(json.dumps(row), flush=True)
            out.append(row)
    return out


def part_floor():
    from mlc.sim.drive import Drive
    from mlc.sim.integrator import SimOptions, Simulation
    from mlc.verify.dynamic import probe_thermal_sd
    from mlc.verify.static import equilibrium
    out = []
    sc = _scene("circuit", 5)
    pr = next(p for p in sc.probes if p.name == "out")
    swing = abs(pr.actuated - pr.rest)
    for row_in in ("01", "11"):
        eq = equilibrium(sc, row_in)
        sd_h = probe_thermal_sd(sc, 1e-5, eq.pos, eq.quat)["out"]
        want = pr.actuated if row_in == "11" else pr.rest
        sds, offs = [], []
        for s in range(2):
            sim = Simulation(sc, {"in": Drive.constant(int(row_in[0])), "hold": Drive.constant(1)},
                             SimOptions(dt=0.01, scheme="stiff", kT=1e-5, seed=s), pos=eq.pos, quat=eq.quat)
            res = sim.run(20.0, record_interval=0.01, quiet=True)
            t = np.asarray(res.times)
            x = np.asarray(res.probes["out"])[t >= 5.0]
            sds.append(float(np.std(x)))
            offs.append(float(np.mean(x) - want))
        r = {"row": row_in, "sd_harmonic": sd_h, "sd_sim": sds, "offset_sim": offs,
             "floor_pct": 100 * math.sqrt(np.mean(np.square(sds)) + np.mean(np.square(offs))) / swing,
             "sd_harmonic_pct_of_swing": 100 * sd_h / swing}
        print(json.dumps(r), flush=True)
        out.append(r)
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--parts", default="linear,step,jointk,rigid_gr,timeunit,ramp,floor")
    ap.add_argument("--seeds", type=int, default=2)
    ap.add_argument("-o", "--output", default=os.path.join(HERE, "results", "fig5c_why.json"))
    a = ap.parse_args(argv)
    res = {}
    if os.path.exists(a.output):
        with open(a.output) as f:
            res = json.load(f)
    for part in a.parts.split(","):
        t = time.perf_counter()
        fn = {"linear": part_linear, "step": part_step, "jointk": lambda: part_jointk(a.seeds),
              "rigid_gr": lambda: part_rigid_gr(a.seeds),
              "timeunit": part_timeunit, "ramp": part_ramp, "floor": part_floor}[part]
        res[part] = {"rows": fn(), "wall_s": time.perf_counter() - t}
        import mlc
        res["mlc_version"] = getattr(mlc, "__version__", "?")
        tmp = a.output + ".tmp"
        with open(tmp, "w") as f:
            json.dump(res, f, indent=1)
        os.replace(tmp, a.output)
    print("wrote", a.output)


if __name__ == "__main__":
    main()
