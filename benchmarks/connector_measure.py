"""Measured numbers of the connector library for docs/circuits.md (sections 1-2).

    python benchmarks/connector_measure.py      # writes benchmarks/results/connector.json

Per convention: the geometry, the largest bend (formula and bisection on the overlap
test), the smallest clearance of every element over its quasi-static poses, the floppy
mode count, and for chains of 1, 5, 10, 20 units (straight and bent) and the 3-way branch
the static error and the Brownian-dynamics reading at kT = 1e-5 (one seed), relaxation
time and thermal spread.  Units: sigma, t0, degrees.
"""
import json
import math
import os
import sys
import time

import mlc  # noqa: F401 -- before numpy: pins OpenBLAS's kernels (mlc/__init__.py)
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
import mlc.gates.connector as C  # noqa: E402
from mlc.gates.connector import (branch_scene, chain_scene, connector_geometry, full_unit_scene,  # noqa: E402
                                 half_unit_scene, max_bend)
from mlc.verify.overlap import clearance, static_poses, sweep_clearance
from mlc.verify.dynamic import check_scene_dynamic_multi, relaxation_time
from mlc.verify.static import _Problem, equilibrium
from mlc.verify.static import verify_scene
out = {}
for sig in ("expand", "contract"):
    geo = connector_geometry(sig); mb = max_bend(geo)
    d = out[sig] = {"L0": geo.L0, "L1": geo.L1, "side": geo.side, "width": geo.width, "thickness": geo.thickness,
                    "gap": geo.gap, "pitch": geo.pitch, "reach": geo.reach, "branch_post": geo.branch_post,
                    "max_bend_formula_deg": math.degrees(mb)}
    def worst(b):
        sc = full_unit_scene(sig, bend=b)
        return min(clearance(sc, p, q).min_clearance for p, q, _ in static_poses(sc, [[0.0],[0.5],[1.0]]))
    lo, hi = 0.9*mb, 1.05*mb
    for _ in range(12):
        mid = 0.5*(lo+hi)
        lo, hi = (mid, hi) if worst(mid) > 0 else (lo, mid)
    d["max_bend_measured_deg"] = math.degrees(lo)
    cl = {}
    for name, sc in [("half_unit", half_unit_scene(sig)), ("full_unit", full_unit_scene(sig)),
                     ("full_unit_bent", full_unit_scene(sig, bend=0.9*mb)),
                     ("chain20_straight", chain_scene(20, sig)), ("chain20_bent", chain_scene(20, sig, min(0.9*mb, math.pi/19))),
                     ("chain20_bent_0.9max", chain_scene(20, sig, 0.9*mb))] + \
                    [(f"branch{k}", branch_scene(k, sig)) for k in (1, 2, 3, 4, 5)]:
        w, fr, rows = sweep_clearance(sc, grid=3)
        cl[name] = {"min": w.min_clearance, "pair": list(w.pair), "at": fr}
    d["clearance"] = cl
    dyn = {}
    for units in (1, 5, 10, 20):
        for bent in (False, True):
            if units == 1 and bent:
                sc = full_unit_scene(sig, bend=0.9*mb)
            else:
                sc = chain_scene(units, sig, min(0.9*mb, math.pi/(units-1)) if bent and units > 1 else 0.0, probe_every_unit=True)
            st = verify_scene(sc)
            tau = relaxation_time(sc)
            t = time.time()
            rows = check_scene_dynamic_multi(sc, 1e-5, 1, tau=tau, progress=False)
            outr = [r for r in rows if r["output"] == "out"]
            dyn[f"{units}_{'bent' if bent else 'straight'}"] = {
                "bodies": len(sc.bodies), "tau": tau,
                "static_max_error": max(r["error"] for r in st), "static_max_stretch": max(r["joint_stretch"] for r in st),
                "min_margin_all_probes": min(r["margin"] for r in rows), "all_ok": all(r["ok"] for r in rows),
                "out": [(r["state"], r["measured"], r["margin"], r["relax_time"], r["thermal_sd"]) for r in outr], "wall": time.time()-t}
            print(sig, units, bent, dyn[f"{units}_{'bent' if bent else 'straight'}"], flush=True)
    sc = branch_scene(3, sig); tau = relaxation_time(sc)
    rows = check_scene_dynamic_multi(sc, 1e-5, 2, tau=tau, progress=False)
    dyn["branch3"] = {"tau": tau, "rows": [(r["state"], r["output"], r["measured"], r["margin"], r["relax_time"]) for r in rows],
                      "all_ok": all(r["ok"] for r in rows)}
    d["dynamic"] = dyn
    nulls = {}
    for units in (1, 2, 3, 4):
        sc = chain_scene(units, sig); e = equilibrium(sc, "1")
        J = _Problem(sc, e.pos, e.quat, pin_first=True).jacobian().toarray()
        sv = np.linalg.svd(J, compute_uv=False)
        z = int((sv < 1e-9 * sv[0]).sum())
        nulls[units] = {"dof_free": J.shape[1], "rows": J.shape[0], "rank": J.shape[1] - z, "zero_modes": z,
                        "smallest_nonzero_sv_over_max": float(sv[len(sv) - z - 1] / sv[0])}
    d["floppy"] = nulls
    print(sig, json.dumps({k: v for k, v in d.items() if k != "dynamic"}, indent=1), flush=True)
out["default_gap"] = C.DEFAULT_GAP
path = os.path.join(os.path.dirname(os.path.abspath(__file__)), "results", "connector.json")
with open(path, "w") as f:
    json.dump(out, f, indent=1)
print("wrote", path)
