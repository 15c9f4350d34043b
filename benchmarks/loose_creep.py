"""Why a loose (toleranced) connector chain creeps, and why a loose gate fares better
(issue 11, docs/reproduction.md sections 3 and 4).

    python benchmarks/loose_creep.py [--parts slack,creep,gate,kscale,kscan,pair] [--seeds 3]
        # writes benchmarks/results/loose_creep.json

Parts (units: sigma, k0, gamma, t0 = gamma/(1e-3 k0); kT in k0 sigma^2):

* ``slack``: the flat bottom in the signal coordinates, from geometry alone (no
  simulation): with the muscles held at their lengths, how far can each probe (the
  signal after each unit of a 5-unit chain; the output of an AND gate) move while every
  joint stays within its tolerance delta, i.e. at zero energy?  Linearised about the
  tight scene's pose (the Jacobian of :mod:`mlc.verify.static`): a linear program
  (scipy HiGHS) maximising and minimising the probe's change subject to every joint's
  separation (3 components, zero-length bonds) within a box: half-width delta (the box
  holds the ball |d| <= delta: an upper bound of the range) and delta/sqrt(3) (inside the
  ball: a lower bound).  The range is symmetric about the tight value (so in the linear
  theory a loose joint biases no mean) and is the width W of the probe's flat bottom.
* ``creep``: Brownian dynamics of the 5-unit chain with tolerance 0.025 sigma, posed at
  rest (a = 0), input a switched to 1 at t = 0; the signal after each unit at 1, 2, 5,
  10, 20, 30 t0 (mean over seeds and 0.5 t0 around each time), for kT = 0, 1e-5 and
  1e-4 with the stiff scheme (dt 0.01 t0), kT = 1e-5 with Euler-Maruyama at its default
  dt (half its stability limit) and at a third of it (first 10 t0); ``half_time_out``: when
  the far end's mean over seeds (smoothed over 0.5 t0) first reaches 1.25 sigma.  Is the creep thermal
  (none at kT = 0; ten times faster at ten times kT: diffusion over a flat bottom, time
  ~ W^2 gamma_eff / kT) or the integrator's (it would change with the scheme and dt)?
* ``gate``: the same for the AND gate (tolerance 0.05 sigma, inputs 00 -> 11 and
  00 -> 01): the gate's output after 1, 2, 5, 10, 20 t0.
* ``kscale``: the creep of the 5-unit chain (tolerance 0.025 sigma) with hard walls (every
  joint 100 k0, so the wall's thermal give sqrt(kT/k) is 0.0003-0.001 sigma, not 0.003-0.01)
  at kT = 1e-5 and 1e-4, stiff scheme at dt = 0.01 and 0.001 t0 (at 1e-4 a body's thermal
  step in 0.01 t0, sqrt(2 kT dt/gamma) = 0.045 sigma, exceeds the tolerance), to 60 t0:
  diffusion over a flat bottom takes a time proportional to 1/kT, so the two curves
  should be one curve with time scaled 10x.  ``kscan``: the same at dt = 0.001 t0 and
  kT = 3e-5 and 3e-4, to see how the half-way time scales with kT.
* ``pair``: the integrator inside a tolerance, against exact theory: two free slabs joined
  by one flat-bottomed bond (tolerance 0.025 sigma, k0 outside), kT = 1e-5, 20 t0 (the
  first 1 t0 dropped), sampled every 0.001 t0.  The separation d of the two sites has the
  stationary density r^2 exp(-U(r)/kT) (U = 0 inside, k0 (r - delta)^2 / 2 outside; the
  slabs' translations make every d equally accessible), so mean |d| and mean |d|^2 are
  one-dimensional integrals; Euler at its default dt and at 1e-5 t0, the stiff scheme at
  0.01 and 0.001 t0 are compared with them.
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

TIMES = (1.0, 2.0, 5.0, 10.0, 20.0, 30.0)
HALF = 1.25         # sigma: half-way between the states (1.0 and 1.5 sigma)


def slack_ranges(scene, pos, quat, delta: float, probes: list[str]):
    """{probe: (lo, hi) for the outer box, (lo, hi) for the inner box} of the probe's
    linear change at zero joint energy (muscles held), about the tight pose ``pos``/``quat``."""
    from scipy.optimize import linprog
    from mlc.verify.dynamic import _probe_gradients
    from mlc.verify.static import _Problem
    prob = _Problem(scene, pos, quat, pin_first=False)
    if len(prob.isc):
        raise ValueError("slack_ranges: the tight scene must have zero-length joints only")
    A = scene.arrays()
    J = prob.jacobian().toarray()
    nb = 3 * len(prob.iv)
    Jb = J[:nb] / np.repeat(np.sqrt(prob.bond_k[prob.iv]), 3)[:, None]
    Jm = J[nb:] / np.sqrt(np.asarray(A.muscle_k, float))[:, None]
    G = _probe_gradients(prob, scene)
    names = [p.name for p in scene.probes]
    out = {}
    for name in probes:
        g = G[:, names.index(name)]
        rng = {}
        for label, h in (("outer", delta), ("inner", delta / math.sqrt(3))):
            lohi = []
            for sgn in (1.0, -1.0):
                r = linprog(-sgn * g, A_ub=np.vstack([Jb, -Jb]), b_ub=np.full(2 * nb, h), A_eq=Jm,
                            b_eq=np.zeros(len(Jm)), bounds=[(None, None)] * prob.n, method="highs")
                lohi.append(sgn * -r.fun if r.status == 0 else (sgn * math.inf))   # max, then min
            rng[label] = (float(lohi[1]), float(lohi[0]))
        out[name] = rng
    return out


def part_slack():
    from mlc.gates.connector import chain_scene
    from mlc.gates.library import gate_scene
    from mlc.verify.static import equilibrium
    rows = []
    for delta in (0.0125, 0.025, 0.05):
        sc = chain_scene(5, "expand", 0.0, tolerance=0.0, probe_every_unit=True)
        for st in ("0", "1"):
            eq = equilibrium(sc, st)
            r = slack_ranges(sc, eq.pos, eq.quat, delta, [p.name for p in sc.probes])
            row = {"scene": "chain5", "state": st, "tolerance": delta,
                   "width_outer": {k: v["outer"][1] - v["outer"][0] for k, v in r.items()},
                   "width_inner": {k: v["inner"][1] - v["inner"][0] for k, v in r.items()}}
            print(json.dumps(row), flush=True)
            rows.append(row)
        g = gate_scene("AND", "expand")
        for st in ("00", "01", "11"):
            eq = equilibrium(g, st)
            r = slack_ranges(g, eq.pos, eq.quat, delta, ["out"])
            row = {"scene": "AND", "state": st, "tolerance": delta,
                   "width_outer": {"out": r["out"]["outer"][1] - r["out"]["outer"][0]},
                   "width_inner": {"out": r["out"]["inner"][1] - r["out"]["inner"][0]}}
            print(json.dumps(row), flush=True)
            rows.append(row)
    return rows


def _run(scene, drives, scheme: str, dt, kT: float, seed: int, T: float, probes: list[str]):
    from mlc.sim.integrator import SimOptions, Simulation
    sim = Simulation(scene, drives, SimOptions(dt=dt, scheme=scheme, kT=kT, seed=seed))
    t = time.perf_counter()
    res = sim.run(T, record_interval=0.05, quiet=True)
    wall = time.perf_counter() - t
    # record times carry round-off that depends on the integrator's chunking (1e-13 t0 with
    # Euler): rounded, so that a sample on a window's edge is in or out whatever the chunks
    tt = np.round(np.asarray(res.times), 9)
    at = {}
    for p in probes:
        x = np.asarray(res.probes[p])
        at[p] = [float(np.mean(x[(tt >= s - 0.25) & (tt <= s + 0.25)])) for s in TIMES if s <= T]
    return at, wall, float(res.dt), tt, np.asarray(res.probes[probes[-1]])


def half_time(t, x, level: float = HALF) -> float:
    """First time (t0) at which ``x``, smoothed over 0.5 t0, reaches ``level``; NaN if never."""
    w = max(1, int(round(0.5 / (t[1] - t[0]))))
    xs = np.convolve(x, np.ones(w) / w, mode="same")
    i = np.flatnonzero(xs[w:-w] >= level)
    return float(t[w + i[0]]) if len(i) else float("nan")


def _cases(scene, drives, probes, cases, seeds, T):
    rows = []
    for scheme, dt, kT, TT in cases:
        per = []
        walls = []
        last = []
        n = 1 if kT == 0 else seeds
        for s in range(n):
            at, wall, dt_used, tt, x = _run(scene, drives, scheme, dt, kT, s, TT or T, probes)
            per.append(at)
            walls.append(wall)
            last.append(x)
        row = {"scheme": scheme, "dt": dt_used, "kT": kT, "seeds": n, "times": [x for x in TIMES if x <= (TT or T)],
               f"half_time_{probes[-1]}": half_time(tt, np.mean(last, axis=0)),
               "mean": {p: np.mean([a[p] for a in per], axis=0).round(4).tolist() for p in probes},
               "se": {p: (np.std([a[p] for a in per], axis=0, ddof=1) / math.sqrt(n)).round(4).tolist()
                      if n > 1 else None for p in probes},
               "wall_s": float(np.median(walls))}
        print(json.dumps(row), flush=True)
        rows.append(row)
    return rows


def part_creep(seeds: int):
    from mlc.gates.connector import chain_scene
    from mlc.sim.drive import Drive
    sc = chain_scene(5, "expand", 0.0, tolerance=0.025, probe_every_unit=True)
    probes = [p.name for p in sc.probes]
    cases = [("stiff", 0.01, 0.0, None), ("stiff", 0.01, 1e-5, None), ("stiff", 0.01, 1e-4, None),
             ("euler", None, 1e-5, None), ("euler", "third", 1e-5, 10.0)]
    from mlc.sim.integrator import SimOptions, Simulation
    lim = Simulation(sc, {"a": Drive.constant(1)}, SimOptions(scheme="euler")).euler_limit()
    cases = [(s, (lim / 6 if d == "third" else d), k, T) for s, d, k, T in cases]
    return {"scene": "chain 5 units, tolerance 0.025", "probes": probes,
            "rows": _cases(sc, {"a": Drive.constant(1)}, probes, cases, seeds, 30.0)}


def part_gate(seeds: int):
    from mlc.sim.drive import Drive
    from mlc.sweep.scenes import gate
    sc = gate("AND", "expand", 0.05)
    out = []
    for row_in in ("11", "01"):
        drives = {"a": Drive.constant(int(row_in[0])), "b": Drive.constant(int(row_in[1]))}
        cases = [("stiff", 0.01, 0.0, None), ("stiff", 0.01, 1e-5, None), ("stiff", 0.01, 1e-4, None),
                 ("euler", None, 1e-5, None)]
        out.append({"scene": "AND, tolerance 0.05", "row": row_in,
                    "rows": _cases(sc, drives, ["out"], cases, seeds, 20.0)})
    return out


def part_kscale(seeds: int):
    from mlc.gates.connector import chain_scene
    from mlc.sim.drive import Drive
    global TIMES
    old, TIMES = TIMES, (1.0, 2.0, 5.0, 10.0, 20.0, 30.0, 45.0, 60.0)
    try:
        sc = chain_scene(5, "expand", 0.0, tolerance=0.025, probe_every_unit=True)
        for b in sc.bonds:
            b.k *= 100.0
        probes = [p.name for p in sc.probes]
        cases = [("stiff", 0.01, 1e-5, None), ("stiff", 0.01, 1e-4, None), ("stiff", 0.01, 0.0, None),
                 ("stiff", 0.001, 1e-5, None), ("stiff", 0.001, 1e-4, None)]
        return {"scene": "chain 5 units, tolerance 0.025, joints 100 k0", "probes": probes,
                "rows": _cases(sc, {"a": Drive.constant(1)}, probes, cases, seeds, 60.0)}
    finally:
        TIMES = old


def part_kscan(seeds: int):
    """``kscale``'s hard-walled chain at dt = 0.001 t0 and kT = 3e-5, 3e-4 (to put beside its
    1e-5 and 1e-4): how the half-way time scales with kT."""
    from mlc.gates.connector import chain_scene
    from mlc.sim.drive import Drive
    global TIMES
    old, TIMES = TIMES, (1.0, 2.0, 5.0, 10.0, 20.0, 30.0, 45.0, 60.0)
    try:
        sc = chain_scene(5, "expand", 0.0, tolerance=0.025, probe_every_unit=True)
        for b in sc.bonds:
            b.k *= 100.0
        probes = [p.name for p in sc.probes]
        cases = [("stiff", 0.001, 3e-5, None), ("stiff", 0.001, 3e-4, 20.0)]
        return {"scene": "chain 5 units, tolerance 0.025, joints 100 k0", "probes": probes,
                "rows": _cases(sc, {"a": Drive.constant(1)}, probes, cases, seeds, 60.0)}
    finally:
        TIMES = old


def pair_scene(delta: float, k: float = 1.0):
    """Two free slabs 0.5 sigma apart whose facing edge sites are joined by one flat-bottomed
    bond (WCA-free: the centres stay ~0.5 sigma apart); probe ``d``: the sites' separation."""
    from mlc.scene.model import Body, Bond, Box, Probe, Scene
    q = np.array([1.0, 0.0, 0.0, 0.0])
    box = [Box(np.array([0.5, 0.5, 0.01]))]
    a = Body("A", np.zeros(3), q, box, {"s": np.array([0.25, 0.0, 0.0])})
    b = Body("B", np.array([0.5, 0.0, 0.0]), q.copy(), box, {"s": np.array([-0.25, 0.0, 0.0])})
    return Scene("pair", [a, b], [Bond("j", "A.s", "B.s", k, 0.0, delta, "universal", "j")], [],
                 [Probe("d", "d", "A.s", "B.s", 0.0, 1.0)], [], ["d"], None)


def pair_exact(delta: float, kT: float, k: float = 1.0):
    """(mean |d|, mean |d|^2) of the stationary density r^2 exp(-U(r)/kT)."""
    r = np.linspace(0.0, delta + 12.0 * math.sqrt(kT / k), 200001)
    w = r ** 2 * np.exp(-np.where(r > delta, 0.5 * k * (r - delta) ** 2, 0.0) / kT)
    return float((w * r).sum() / w.sum()), float((w * r * r).sum() / w.sum())


def part_pair():
    from mlc.sim.integrator import SimOptions, Simulation
    delta, kT = 0.025, 1e-5
    m1, m2 = pair_exact(delta, kT)
    out = {"tolerance": delta, "kT": kT, "exact_mean": m1, "exact_mean_sq": m2, "runs": []}
    sc = pair_scene(delta)
    for scheme, dt in (("euler", None), ("euler", 1e-5), ("stiff", 0.01), ("stiff", 0.001)):
        for seed in (1, 2):
            t = time.perf_counter()
            res = Simulation(sc, {}, SimOptions(dt=dt, scheme=scheme, kT=kT, seed=seed)).run(
                20.0, record_interval=0.001, quiet=True)
            x = np.asarray(res.probes["d"])[np.asarray(res.times) > 1.0]
            r = {"scheme": scheme, "dt": float(res.dt), "seed": seed, "mean": float(x.mean()),
                 "mean_sq": float((x * x).mean()), "mean_rel_err": float(x.mean() / m1 - 1),
                 "mean_sq_rel_err": float((x * x).mean() / m2 - 1), "wall_s": time.perf_counter() - t}
            print(json.dumps(r), flush=True)
            out["runs"].append(r)
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--parts", default="slack,creep,gate,kscale,kscan,pair")
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("-o", "--output", default=os.path.join(HERE, "results", "loose_creep.json"))
    a = ap.parse_args(argv)
    res = {}
    if os.path.exists(a.output):
        with open(a.output) as f:
            res = json.load(f)
    for part in a.parts.split(","):
        t = time.perf_counter()
        fn = {"slack": part_slack, "creep": lambda: part_creep(a.seeds), "gate": lambda: part_gate(a.seeds),
              "kscale": lambda: part_kscale(a.seeds), "kscan": lambda: part_kscan(a.seeds), "pair": part_pair}[part]
        res[part] = {"result": fn(), "wall_s": time.perf_counter() - t}
        tmp = a.output + ".tmp"
        with open(tmp, "w") as f:
            json.dump(res, f, indent=1)
        os.replace(tmp, a.output)
    print("wrote", a.output)


if __name__ == "__main__":
    main()
