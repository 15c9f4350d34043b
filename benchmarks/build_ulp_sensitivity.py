"""How far a circuit build depends on the last bits of numpy's transcendental functions
(docs/circuits.md, "Reproducibility").

    python benchmarks/build_ulp_sensitivity.py

On CPUs with AVX-512 numpy computes float64 sin, cos, arcsin, arctan2 and others with Intel's
SVML kernels, whose results differ from the C library's in the last bits; without AVX-512 it
calls the C library.  This machine may have no AVX-512, so the script emulates the difference:
it builds examples/full_adder.expr at --joint-k 100 in a fresh process per variant, with the
named numpy functions, as mlc's pure-Python modules see them, returning the next float up on
the elements whose mantissa has bit 6 set (about half of them, one ulp off, deterministic) and
everything else unchanged (numba kernels keep the C library's results).  Records bodies, half
units, the scene text's sha256 (``meta.source`` made relative) and how often each function was
called.  Writes benchmarks/results/build_ulp_sensitivity.json.
"""
from __future__ import annotations

import json
import os
import platform
import subprocess
import sys
from pathlib import Path

from mlc.io.atomic import atomic_path

ROOT = Path(__file__).resolve().parents[1]
CODE = r"""
import hashlib, importlib, json, os, pkgutil, sys, types
import mlc
import numpy as np
names = [n for n in os.environ.get("ULP_PERTURB", "").split(",") if n]
calls = {}

def wrapped(f, name):
    def g(*a, **k):
        r = f(*a, **k)
        calls[name] = calls.get(name, 0) + 1
        arr = np.asarray(r)
        if "out" in k or arr.dtype != np.float64:
            return r
        flat = np.atleast_1d(arr)
        up = (flat.view(np.uint64) & np.uint64(0x40)) != 0
        flat = np.where(up, np.nextafter(flat, np.inf), flat)
        return flat.reshape(arr.shape) if arr.ndim else np.float64(flat[0])
    return g

if names:
    proxy = types.ModuleType("numpy_one_ulp_off")
    proxy.__dict__.update({k: getattr(np, k) for k in dir(np) if not k.startswith("__")})
    for n in names:
        setattr(proxy, n, wrapped(getattr(np, n), n))
    for m in pkgutil.walk_packages(mlc.__path__, "mlc."):
        try:
            mod = importlib.import_module(m.name)
        except Exception:
            continue
        src = open(mod.__file__).read() if getattr(mod, "__file__", None) else ""
        # numba compiles np.* inside @njit kernels itself: leave those modules alone
        if getattr(mod, "np", None) is np and "njit" not in src and "numba" not in src:
            mod.np = proxy
from mlc.circuit.build import CircuitOptions
from mlc.pipeline import build, compile_spec, load
from mlc.scene.io import dump_scene
sc = build(compile_spec(load(sys.argv[1])), options=CircuitOptions(joint_k=100.0)).circuit.scene
sc.meta["source"] = "examples/full_adder.expr"
print(json.dumps({"bodies": len(sc.bodies), "half_units": sc.meta["connector"].get("half_units"),
                  "sha256": hashlib.sha256(dump_scene(sc).encode()).hexdigest()[:16], "calls": calls}))
"""
VARIANTS = ("", "sin,cos", "arcsin", "arctan2,hypot", "sin,cos,arcsin,arctan2,hypot")


def main() -> int:
    rows = []
    for v in VARIANTS:
        env = dict(os.environ, ULP_PERTURB=v)
        out = subprocess.run([sys.executable, "-c", CODE, str(ROOT / "examples" / "full_adder.expr")], env=env,
                             capture_output=True, text=True, check=True).stdout.strip().splitlines()[-1]
        row = {"one_ulp_off": v.split(",") if v else [], **json.loads(out)}
        rows.append(row)
        print(f"{v or 'unchanged':32s} {row['bodies']} bodies, {row['half_units']} half units, {row['sha256']}",
              flush=True)
    base = rows[0]["sha256"]
    res = {"example": "full_adder.expr", "joint_k": 100.0, "rows": rows,
           "changed": {",".join(r["one_ulp_off"]): r["sha256"] != base for r in rows[1:]},
           "machine": {"platform": platform.platform(), "cpus": os.cpu_count()}}
    path = ROOT / "benchmarks" / "results" / "build_ulp_sensitivity.json"
    with atomic_path(path) as tmp:
        tmp.write_text(json.dumps(res, indent=1))
    print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
