"""How fast Brownian dynamics folds the gate with the lowest fold barrier, against Arrhenius
(docs/gates.md section 6; issue 12, item 6).

    python benchmarks/gate_fold_rate.py [--seeds 16] [--time 200]

The continuation of :func:`mlc.verify.branches.fold_barrier` finds 0.0042 k0 sigma^2 between
NAND expanding's design equilibrium in state 10 (output 1.5 sigma) and a folded-core
equilibrium (d below c, output 2.21 sigma).  This script checks that number with dynamics and
theory instead: it drives the gate from rest into state 10 at several kT (mlc.sim, stiff
scheme, default dt), records the output every 0.1 t0 and takes the first time it passes
2.1 sigma (inside the folded basin) as the escape time, each run cut at ``--time`` t0.  The
escape rate at each kT is the maximum-likelihood estimate for exponential waiting times with
censoring, k = escapes / (total time watched); Arrhenius, k = A exp(-E/kT), then gives the
barrier E as minus the slope of ln k against 1/kT (weighted least squares, weights = escapes).
Done twice: with rotational noise (``rot_noise``: the thermodynamically consistent dynamics,
whose stationary distribution is Boltzmann's) and without it (mlc's and the paper's default,
where a body's orientation follows its torque only).  Units: sigma, k0, t0.
Writes benchmarks/results/gate_fold_rate.json and .png.
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

from mlc.gates.library import gate_scene
from mlc.io.atomic import atomic_path
from mlc.sim.drive import Drive
from mlc.sim.integrator import SimOptions, Simulation
from mlc.verify.branches import fold_barrier
from mlc.verify.static import equilibrium

ROOT = Path(__file__).resolve().parents[1]
THRESHOLD = 2.1       # sigma: the output inside the folded basin (design 1.5, folded 2.21)
CHUNK = 10.0          # t0 per run() call between checks
CASES = ((True, (6e-4, 7e-4, 8e-4, 1e-3)), (False, (1.5e-3, 2e-3, 2.5e-3, 3e-3)))


def escape_time(scene, drives, kT, seed, rot_noise, T):
    """First time (t0) the output passes THRESHOLD, or None if not within T."""
    sim = Simulation(scene, drives, SimOptions(kT=kT, seed=seed, rot_noise=rot_noise))
    probe = scene.probes[0].name
    t = 0.0
    while t < T - 1e-9:
        span = min(CHUNK, T - t)
        v = np.asarray(sim.run(span, record_interval=0.1, quiet=True).probes[probe])
        hit = np.nonzero(v > THRESHOLD)[0]
        if len(hit):
            return t + span * (hit[0] + 1) / len(v)
        t += span
    return None


def arrhenius(rows):
    """Weighted fit of ln k = ln A - E/kT over the rows with escapes: (E, ln A)."""
    pts = [(1.0 / r["kT"], np.log(r["rate"]), r["escapes"]) for r in rows if r["escapes"] > 0]
    if len(pts) < 2:
        return None, None
    x, y, w = (np.array(c, float) for c in zip(*pts))
    slope, icpt = np.polyfit(x, y, 1, w=np.sqrt(w))
    return float(-slope), float(icpt)


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--seeds", type=int, default=16)
    ap.add_argument("--time", type=float, default=200.0, help="t0 per run before it is cut")
    args = ap.parse_args()
    scene = gate_scene("NAND", "expand")
    state = "10"
    drives = {i: Drive.constant(int(b)) for i, b in zip(scene.inputs, state)}
    eq = equilibrium(scene, state)
    fb = fold_barrier(scene, state, "out.out", eq.pos, eq.quat, steps=6, target=0.0)
    out = {"gate": "NAND", "signal": "expand", "state": state, "threshold": THRESHOLD, "T": args.time,
           "seeds": args.seeds, "continuation_barrier": fb.peak, "cases": []}
    print(f"continuation barrier {fb.peak:.5f} k0 sigma^2", flush=True)
    t_start = time.time()
    for rot_noise, kTs in CASES:
        rows = []
        for kT in kTs:
            t0 = time.time()
            times = [escape_time(scene, drives, kT, seed, rot_noise, args.time) for seed in range(args.seeds)]
            esc = [x for x in times if x is not None]
            watched = sum(x if x is not None else args.time for x in times)
            rows.append({"kT": kT, "times": times, "escapes": len(esc), "watched_t0": watched,
                         "rate": len(esc) / watched, "rate_rel_err": 1 / np.sqrt(len(esc)) if esc else None,
                         "wall_s": time.time() - t0})
            print(f"rot_noise={rot_noise} kT={kT:g}: {len(esc)}/{args.seeds} folded, rate {rows[-1]['rate']:.4g}/t0, "
                  f"{time.time() - t0:.0f} s", flush=True)
        E, lnA = arrhenius(rows)
        out["cases"].append({"rot_noise": rot_noise, "rows": rows, "barrier_fit": E, "ln_prefactor": lnA,
                             "barrier_fit_over_continuation": E / fb.peak if E else None})
        print(f"rot_noise={rot_noise}: Arrhenius barrier {E} ({E / fb.peak if E else float('nan'):.2f} x the "
              f"continuation's)", flush=True)
    out["wall_seconds"] = time.time() - t_start
    out["machine"] = {"platform": platform.platform(), "cpus": os.cpu_count()}
    res = ROOT / "benchmarks" / "results"
    with atomic_path(res / "gate_fold_rate.json") as tmp:
        tmp.write_text(json.dumps(out, indent=1))
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(5.5, 4))
    for case, mk in zip(out["cases"], ("o", "s")):
        r = [x for x in case["rows"] if x["escapes"]]
        x = np.array([1 / q["kT"] for q in r])
        y = np.array([q["rate"] for q in r])
        ax.errorbar(x, y, yerr=y * np.array([q["rate_rel_err"] for q in r]), fmt=mk,
                    label=f"rot. noise {'on' if case['rot_noise'] else 'off'}: fit E = {case['barrier_fit']:.4f}")
        if case["barrier_fit"]:
            xx = np.linspace(x.min(), x.max(), 20)
            ax.plot(xx, np.exp(case["ln_prefactor"] - case["barrier_fit"] * xx), "-", lw=0.8)
    ax.set_yscale("log")
    ax.set_xlabel("1 / kT  (1 / k0 sigma^2)")
    ax.set_ylabel("fold rate (1 / t0)")
    ax.set_title(f"NAND expanding, state 10; continuation barrier {fb.peak:.4f}", fontsize=9)
    ax.legend(fontsize=8)
    fig.tight_layout()
    with atomic_path(res / "gate_fold_rate.png") as tmp:
        fig.savefig(tmp, dpi=120, format="png")
    print(f"wrote {res / 'gate_fold_rate.json'}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
