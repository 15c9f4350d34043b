"""A/B of the serial Euler kernel before and after issue 12 (drift-only monitor, no
cell-list fallback, phase-aware records), measured in one run on the same machine.

The full ``sim_throughput.py`` could not be re-run for issue 12: on a machine loaded by
other jobs its two-thread rows stall (each parallel region waits for descheduled
threads).  This script times the old kernel (``git show REV:mlc/sim/kernels.py``) and the
current one on the same arrays: hinged slab chains, WCA on, kT = 1e-5, dt = 1e-4 t0.

    python benchmarks/sim_throughput_ab.py [REV]

Writes benchmarks/results/sim_throughput_ab.json.
"""
from __future__ import annotations

import importlib.util
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import mlc  # noqa: F401 -- before numpy: pins OpenBLAS's kernels (mlc/__init__.py)
import numpy as np

from mlc.sim import kernels as NK
from mlc.sim.integrator import SimOptions, Simulation
from mlc.sim.testscenes import chain_scene

RESULTS = Path(__file__).resolve().parent / "results"


def load_old(rev):
    src = subprocess.run(["git", "show", f"{rev}:mlc/sim/kernels.py"], capture_output=True, text=True,
                         check=True, cwd=Path(__file__).resolve().parent.parent).stdout
    d = Path(tempfile.mkdtemp())
    (d / "oldkernels.py").write_text(src)
    spec = importlib.util.spec_from_file_location("oldkernels", d / "oldkernels.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def args_for(s, n, new):
    eps, sg, rc = s._wca()
    a = s.arrays
    N = s.N
    base = (s.pos, s.quat, 0.0, 0, n, 0.1, 1e-5, 1.0, 1.0, False, np.uint64(1), s.site_body, s.site_local,
            s.bsite0, s.sp_i, s.sp_j, s.sp_k, s.sp_rest0, s.sp_rest1, s.sp_tol, s.sp_inp, s.sp_bound, s.end0,
            s.end_sp, s.end_sign, s.dkind, s.dpar, s.tab_t, s.tab_v, eps, sg, rc, 0.1, s.ex0, s.ex_list, s.head,
            s.nxt, s.cell, s.nl0, s.nl, s.pos_nl, s.nlstate, 1.0, 1.0, a.probe_i, a.probe_j)
    rec, fp, fq = np.zeros((1, 1)), np.zeros((1, N, 3)), np.zeros((1, N, 4))
    mid = (0, 0, rec, 0, 0, fp, fq) if new else (0, rec, 0, fp, fq)
    tail = (s.uval, s.ws, s.arm, s.fsp, s.ratio, s.dmin, s.dpart, s.F, s.T, s.disp, s.mon, s.status)
    return base + mid + tail


def main():
    rev = sys.argv[1] if len(sys.argv) > 1 else "fb5f69a"
    old = load_old(rev)
    rows = []
    load0 = os.getloadavg()
    for N in (8, 128, 2048):
        sc = chain_scene(N, check=False)
        s = Simulation(sc, None, SimOptions(scheme="euler", dt=1e-4, kT=1e-5, threads=1))
        n = max(200, 2_000_000 // N)
        row = {"bodies": N}
        for name, fn, new in (("before", old._serial["euler"], False), ("after", NK._serial["euler"], True)):
            a = args_for(s, n, new)
            fn(*a[:4], 2, *a[5:])                    # compile / warm up
            best = 0.0
            for _ in range(5):
                t = time.perf_counter()
                fn(*a)
                best = max(best, n * N / (time.perf_counter() - t))
            row[f"{name}_body_steps_per_s"] = best
        row["ratio_after_over_before"] = row["after_body_steps_per_s"] / row["before_body_steps_per_s"]
        rows.append(row)
        print(json.dumps(row), flush=True)
    out = {"before_rev": rev, "loadavg": [load0, os.getloadavg()], "rows": rows}
    (RESULTS / "sim_throughput_ab.json").write_text(json.dumps(out, indent=1) + "\n")


if __name__ == "__main__":
    main()
