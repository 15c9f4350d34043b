"""Compiled circuits with stiffer connector joints (``mlc compile --joint-k K``).

For each example (default Tetris and the full adder) and each K (default 1, 10, 100):
build the circuit as ``mlc compile --joint-k K`` does, verify it statically on every row
with the thermal spread at kT = 1e-5 k0 sigma^2 (``mlc verify``: rows right, worst
margin / spread, largest joint stretch, wall time), and record each row's signal time
from rest (t0, :func:`mlc.verify.dynamic.signal_time`: the dynamic check's time floor).
With ``--solvers`` the static solver is also run on the stiffest K with the stiffness
homotopy and the geodesic acceleration switched off (``STIFF_CAP = inf``,
``ACCEL_RATIO = 0``, the solver of session 7), and with each alone, on ``--solver-rows``.
With ``--dynamic ROWS`` each example and K is also verified by Brownian dynamics on those
rows (seed 0, stiff scheme, the verifier's own time floor).

    python benchmarks/circuit_joint_k.py [--only full_adder.expr] [--k 1 100] [--solvers]

Writes benchmarks/results/circuit_joint_k.json after each step.  Units: sigma, k0, t0,
seconds wall (a shared 2-core machine: compare ratios within one run).
"""
from __future__ import annotations

import argparse
import json
import os
import time
from pathlib import Path

import mlc.verify.static as S
from mlc.circuit.build import CircuitOptions
from mlc.pipeline import build, compile_spec, load
from mlc.verify.circuit import THERMAL_SDS, verify_dynamic, verify_static
from mlc.verify.dynamic import signal_time
from gitstate import commit as git_commit      # benchmarks/gitstate.py

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "benchmarks" / "results" / "circuit_joint_k.json"
KT = 1e-5


def solver_run(scene, rows, cap, accel):
    old = S.STIFF_CAP, S.ACCEL_RATIO
    S.STIFF_CAP, S.ACCEL_RATIO = cap, accel
    try:
        out = {}
        for s in rows:
            t = time.perf_counter()
            e = S.equilibrium(scene, s)
            want = scene.truth_table[s]
            bits = "".join(str(int(pr.bit(e.probes[pr.name]))) for pr in scene.probes)
            out[s] = {"wall_s": time.perf_counter() - t, "iterations": e.iterations, "energy": e.energy,
                      "stretch": e.max_joint_stretch, "probes": e.probes, "bits": bits, "want": want,
                      "right": bits == want.replace("-", bits[0] if bits else "")}
            print("   ", cap, accel, s, {k: (round(v, 4) if isinstance(v, float) else v) for k, v in out[s].items()
                                        if k != "probes"}, flush=True)
        return out
    finally:
        S.STIFF_CAP, S.ACCEL_RATIO = old


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--only", nargs="*", default=["tetris.tt", "full_adder.expr"])
    ap.add_argument("--k", nargs="*", type=float, default=[1.0, 10.0, 100.0])
    ap.add_argument("--solvers", action="store_true")
    ap.add_argument("--solver-rows", nargs="*", default=None, help="rows for --solvers (default all)")
    ap.add_argument("--dynamic", nargs="*", default=[], help="rows to verify by Brownian dynamics (seed 0)")
    a = ap.parse_args()
    res = json.loads(OUT.read_text()) if OUT.exists() else {"examples": {}}
    res.update({"commit": git_commit(), "kT": KT, "load_start": list(os.getloadavg())})
    for name in a.only:
        ex = res["examples"].setdefault(name, {})
        for K in a.k:
            t0 = time.perf_counter()
            sc = build(compile_spec(load(str(ROOT / "examples" / name))),
                       options=CircuitOptions(joint_k=K)).circuit.scene
            row = {"bodies": len(sc.bodies), "build_s": time.perf_counter() - t0}
            t1 = time.perf_counter()
            rep = verify_static(sc, kT=KT, clearance=False)
            row["static"] = {"wall_s": time.perf_counter() - t1, "rows_right": sum(r["ok"] for r in rep.rows),
                             "rows": len(rep.rows), "thermal_ok_rows": sum(bool(r.get("thermal_ok")) for r in rep.rows),
                             "worst_margin_over_sd": min((e["margin"] / e["thermal_sd"] for e in rep.entries
                                                          if e.get("thermal_sd") and e["margin"] is not None),
                                                         default=None),
                             "largest_sd": max(e.get("thermal_sd") or 0.0 for e in rep.entries),
                             "largest_stretch": max(r["joint_stretch"] for r in rep.rows),
                             "thermal_sds_needed": THERMAL_SDS}
            rest = "0" * len(sc.inputs)
            row["signal_time"] = {s: signal_time(sc, rest, s) for s in sc.states() if s != rest}
            print(name, K, {k: v for k, v in row.items() if k != "signal_time"},
                  "signal", {s: round(v, 1) for s, v in row["signal_time"].items()}, flush=True)
            if a.solvers and K == max(a.k):
                rows = a.solver_rows or sc.states()
                row["solvers"] = {label: solver_run(sc, rows, cap, acc) for label, cap, acc in (
                    ("homotopy+accel", S.STIFF_CAP, S.ACCEL_RATIO), ("accel only", float("inf"), S.ACCEL_RATIO),
                    ("homotopy only", S.STIFF_CAP, 0.0), ("neither (session 7)", float("inf"), 0.0))}
            if a.dynamic:
                t2 = time.perf_counter()
                d = verify_dynamic(sc, rows=a.dynamic, kT=KT, seeds=1)
                row["dynamic"] = {"wall_s": time.perf_counter() - t2, "ok": d.ok,
                                  "entries": [{k: e[k] for k in ("state", "output", "measured", "margin",
                                                                 "relax_time", "tau", "ok")} for e in d.entries]}
                print(name, K, "dynamic", row["dynamic"], flush=True)
            ex[f"{K:g}"] = row
            OUT.write_text(json.dumps(res, indent=1))
    res["load_end"] = list(os.getloadavg())
    OUT.write_text(json.dumps(res, indent=1))
    print(f"wrote {OUT}")


if __name__ == "__main__":
    main()
