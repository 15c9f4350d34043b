"""Direct gate-to-gate connection against connector chains (``mlc compile --direct``,
docs/circuits.md section 3 "Direct connection").

For each circuit (default ``~(a & b) & c``, whose NAND feeds the AND's b alone) and each
joint stiffness (1 and 100 k0), build it with chains and with ``direct=True``, then
record bodies, build wall time, the static check of every row (rows right, wall time,
largest joint stretch, smallest slab clearance) and the Brownian-dynamics check of every
row (kT = 1e-5 k0 sigma^2, stiff scheme, one seed: rows right, wall time, the slowest
row's relaxation time in t0).  The two checks are independent: an energy minimiser and
the integrator.

    python benchmarks/circuit_direct.py [--expr '~(a & b) & c' ...] [--no-dynamic]

Writes benchmarks/results/circuit_direct.json.  Wall seconds on a shared 2-core machine:
compare the ratios within one run.
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import time
from pathlib import Path

from mlc.circuit.build import CircuitOptions
from mlc.pipeline import build, compile_spec, load
from mlc.verify.circuit import verify_dynamic, verify_static
from gitstate import commit as git_commit      # benchmarks/gitstate.py

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "benchmarks" / "results"


def point(expr: str, joint_k: float, direct: bool, dynamic: bool) -> dict:
    c = compile_spec(load(None, expr))
    t0 = time.perf_counter()
    c = build(c, options=CircuitOptions(joint_k=joint_k, direct=direct))
    t1 = time.perf_counter()
    sc = c.circuit.scene
    st = verify_static(sc)
    t2 = time.perf_counter()
    res = {"expr": expr, "joint_k": joint_k, "direct": direct, "bodies": len(sc.bodies),
           "direct_nets": sc.meta["connector"].get("direct", []), "build_s": t1 - t0,
           "static_rows_ok": sum(r["ok"] for r in st.rows), "rows": len(st.rows), "static_s": t2 - t1,
           "max_joint_stretch": max(r["joint_stretch"] for r in st.rows),
           "min_clearance": min(r["clearance"] for r in st.rows)}
    if dynamic:
        dy = verify_dynamic(sc, kT=1e-5, seeds=1)
        res.update({"dynamic_rows_ok": sum(r["ok"] for r in dy.rows), "dynamic_s": time.perf_counter() - t2,
                    "max_relax_time": max((r["relax_time"] or float("inf")) for r in dy.rows),
                    "min_dynamic_margin": min(e["margin"] for e in dy.entries)})
    return res


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--expr", nargs="*", default=["y = ~(a & b) & c"])
    ap.add_argument("--joint-k", nargs="*", type=float, default=[1.0, 100.0])
    ap.add_argument("--no-dynamic", action="store_true")
    args = ap.parse_args()
    commit = git_commit()
    points = []
    for expr in args.expr:
        for k in args.joint_k:
            for direct in (False, True):
                p = point(expr, k, direct, not args.no_dynamic)
                points.append(p)
                dyn = (f", dynamic {p['dynamic_rows_ok']}/{p['rows']} in {p['dynamic_s']:.1f} s, "
                       f"relaxed by {p['max_relax_time']:.1f} t0") if "dynamic_s" in p else ""
                print(f"{expr} K={k:g} {'direct' if direct else 'chain '}: {p['bodies']} bodies, build "
                      f"{p['build_s']:.2f} s, static {p['static_rows_ok']}/{p['rows']} in {p['static_s']:.1f} s, "
                      f"clearance {p['min_clearance']:+.4f}{dyn}", flush=True)
    OUT.mkdir(parents=True, exist_ok=True)
    res = {"machine": {"platform": platform.platform(), "cpus": os.cpu_count(),
                       "load_after": list(os.getloadavg())}, "commit": commit,
           "date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()), "points": points}
    (OUT / "circuit_direct.json").write_text(json.dumps(res, indent=1, default=float))
    print(f"wrote {OUT / 'circuit_direct.json'}")


if __name__ == "__main__":
    main()
