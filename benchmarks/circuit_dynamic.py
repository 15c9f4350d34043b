"""Compiled circuits verified by Brownian dynamics, one (row, seed) run at a time.

For each example (default: the Tetris logic, the full adder and the 4-to-1 multiplexer,
the three that issue 9 asks to pass ``mlc verify --dynamic`` over 3 seeds): compile and
build the circuit scene as ``mlc compile`` does, then for seed 0 over every row, seed 1
over every row, ... run :func:`mlc.verify.dynamic.check_scene_dynamic_multi` on that one
row and seed (from rest in the all-zero row, until every probe has relaxed; kT = 1e-5
k0 sigma^2 by default, the stiff scheme) and record each output's read length, bit,
margin, the relaxation time (t0) and the wall time.

    python benchmarks/circuit_dynamic.py [--only full_adder.expr ...] [--seeds 3] [--kT 1e-5]
                                         [--joint-k 100] [--rows 000 101] [--dt 0.2]

``--joint-k K`` builds the circuit as ``mlc compile --joint-k K`` does (connector joints K
times stiffer; default: mlc compile's default, 100 k0 since 2026-11-25; runs before that
date used 1 unless they record ``joint_k``); ``--rows`` limits the rows run; ``--out F``
writes to F instead (runs already in circuit_dynamic.json are skipped as well), so two
campaigns can run at once without overwriting each other.

Writes benchmarks/results/circuit_dynamic.json after every run and resumes from it (a
(example, row, seed) already recorded for the same scene is skipped), so a long
campaign can be stopped and continued.  The time floor is the verifier's own: 3 times the
row's signal_time (``tau`` of each run; runs before 2026-11-24 evening used one eigensolver
tau per scene, kept in ``scenes``).  Wall seconds on a shared 2-core
machine: compare ratios, not absolute numbers.
"""
from __future__ import annotations

import argparse
import hashlib
import json
import os
import platform
import time
from pathlib import Path

from mlc.circuit.build import CircuitOptions
from mlc.io.atomic import atomic_path
from mlc.pipeline import build, compile_spec, load
from mlc.scene.io import dump_scene
from mlc.verify.dynamic import check_scene_dynamic_multi
from gitstate import commit as git_commit      # benchmarks/gitstate.py

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "benchmarks" / "results" / "circuit_dynamic.json"
DEFAULT = ("tetris.tt", "full_adder.expr", "mux4.blif")


def scene_key(sc, res: dict) -> str:
    """The scene's key: sha256 prefix of its text with ``meta.source`` relative to the checkout
    (so clones at other paths resume the same runs); a key of the older kind (the absolute
    path in the text) is kept when the results already hold it."""
    legacy = hashlib.sha256(dump_scene(sc).encode()).hexdigest()[:16]
    if legacy in res["scenes"]:
        return legacy
    src = sc.meta.get("source")
    if isinstance(src, str) and Path(src).is_absolute():
        try:
            sc.meta["source"] = str(Path(src).resolve().relative_to(ROOT))
            return hashlib.sha256(dump_scene(sc).encode()).hexdigest()[:16]
        finally:
            sc.meta["source"] = src
    return legacy


def build_host() -> dict:
    """What a build depends on beyond the code (docs/circuits.md, "Reproducibility"): the CPU,
    numpy's SIMD dispatch in use and OpenBLAS's kernel choice."""
    import numpy as np
    from numpy._core._multiarray_umath import __cpu_dispatch__, __cpu_features__
    cpu = next((ln.split(":", 1)[1].strip() for ln in open("/proc/cpuinfo") if ln.startswith("model name")),
               platform.processor()) if Path("/proc/cpuinfo").exists() else platform.processor()
    return {"cpu": cpu, "numpy": np.__version__,
            "numpy_dispatch": [f for f in __cpu_dispatch__ if __cpu_features__.get(f)],
            "openblas_coretype": os.environ.get("OPENBLAS_CORETYPE")}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--only", nargs="*", default=list(DEFAULT), help="example file names")
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--seed-list", type=int, nargs="*", default=None,
                    help="run these seeds instead of 0 .. --seeds - 1 (e.g. a second campaign on seed 1)")
    ap.add_argument("--kT", type=float, default=1e-5)
    ap.add_argument("--scheme", default="stiff", choices=("stiff", "euler"))
    ap.add_argument("--dt", type=float, default=None,
                    help="t0: the step (default the verifier's: mlc.verify.dynamic.DT_LARGE, 0.2 with the stiff scheme, for a "
                         "circuit); each run "
                         "records it; a row already verified at another dt counts as done")
    ap.add_argument("--joint-k", type=float, default=CircuitOptions().joint_k,
                    help="connector joint stiffness (k0), as mlc compile (default: its default)")
    ap.add_argument("--out", type=Path, default=OUT,
                    help="results file (default benchmarks/results/circuit_dynamic.json); runs already in "
                         "circuit_dynamic.json are skipped too, so two campaigns can run at once on two files")
    ap.add_argument("--rows", nargs="*", default=None, help="rows to run (default all)")
    ap.add_argument("--reuse-tau", action="store_true",
                    help="use the scene's tau recorded by an earlier run (default: the verifier's signal_time)")
    args = ap.parse_args()
    commit = git_commit()
    out = args.out
    res = json.loads(out.read_text()) if out.exists() else {"runs": [], "scenes": {}}
    main_runs = json.loads(OUT.read_text())["runs"] if out != OUT and OUT.exists() else []
    for name in args.only:
        compiled = build(compile_spec(load(str(ROOT / "examples" / name))),
                         options=CircuitOptions(joint_k=args.joint_k))
        sc = compiled.circuit.scene
        key = scene_key(sc, res)
        info = res["scenes"].get(key)
        if info is None:
            info = {"example": name, "bodies": len(sc.bodies), "tau": None, "commit": commit,
                    "joint_k": args.joint_k, "host": build_host()}
            res["scenes"][key] = info
        done = {(r["scene"], r["state"], r["seed"]) for r in res["runs"] + main_runs if "tau" in r or args.reuse_tau}
        cache = {}      # each row's static preparation, made once for all its seeds (same numbers)
        for seed in (args.seed_list if args.seed_list is not None else range(args.seeds)):
            for state in sc.states():
                if (key, state, seed) in done or (args.rows and state not in args.rows):
                    continue
                t0, c0 = time.perf_counter(), time.process_time()
                # tau: the one computed for this scene in an earlier session (the eigensolver), or
                # None: the verifier's own per-row signal_time, as `mlc verify --dynamic` does
                entries = check_scene_dynamic_multi(sc, kT=args.kT, seeds=[seed], scheme=args.scheme, rows=[state],
                                                    progress=False, dt=args.dt, tau=info["tau"] if args.reuse_tau else None,
                                                    cache=cache)
                wall, cpu = time.perf_counter() - t0, time.process_time() - c0
                run = {"scene": key, "example": name, "joint_k": args.joint_k, "state": state, "seed": seed, "kT": args.kT,
                       "scheme": args.scheme, "dt": entries[0]["dt"],
                       "ok": all(e["ok"] for e in entries),
                       "relax_time": max((e["relax_time"] or float("nan")) for e in entries), "wall_s": wall,
                       "cpu_s": cpu, "tau": max(e["tau"] for e in entries),
                       "outputs": {e["output"]: {"measured": e["measured"], "expected": e["expected"],
                                                 "margin": e["margin"], "ok": e["ok"]} for e in entries},
                       "commit": commit, "load": list(os.getloadavg())}
                res["runs"].append(run)
                res["machine"] = {"platform": platform.platform(), "cpus": os.cpu_count()}
                with atomic_path(out) as tmp:
                    tmp.write_text(json.dumps(res, indent=1))
                print(f"{name} row {state} seed {seed}: {'right' if run['ok'] else 'WRONG'}, relaxed at "
                      f"{run['relax_time']:.1f} t0, {wall:.0f} s", flush=True)
    rows = [r for r in res["runs"]]
    print(f"{sum(r['ok'] for r in rows)}/{len(rows)} runs right; wrote {out}")


if __name__ == "__main__":
    main()
