"""The static verifier's factorisation: SuperLU's symmetric mode against COLAMD, the order it
replaced (session 26), on compiled circuits.

For each example (default: the full adder, the 4-to-1 multiplexer and the Tetris logic) and
one row (the all-ones row: every muscle moves), the static minimiser
(:func:`mlc.verify.static.equilibrium`) runs twice in one process, once with
:func:`~mlc.verify.static.colamd_lu` (its factorisation) and once with
:func:`~mlc.verify.static.spd_lu` (SuperLU's symmetric mode): CPU seconds
(``process_time``) and Levenberg-Marquardt iterations of each, their CPU ratio, the fill and
CPU of one factorisation (L + U entries of the damped normal equations at the built pose),
and how far the two equilibria differ (each probe's length, the largest joint stretch, in
sigma).  The two runs alternate in order per example, so a change of load hits both.

    python benchmarks/static_lu.py [--only full_adder.expr mux4.blif tetris.tt] [--row 111]

Writes benchmarks/results/static_lu.json and static_lu.png.  Compare ratios, not absolute
times: the machine is shared.
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

import mlc.verify.static as S
from mlc.io.atomic import atomic_path
from mlc.pipeline import build, compile_spec, load

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "benchmarks" / "results"
DEFAULT = ("full_adder.expr", "mux4.blif", "tetris.tt")


def fill(scene, row: str) -> dict:
    """L + U entries of each factorisation of the damped normal equations at the built pose."""
    A = scene.arrays()
    prob = S._Problem(scene, A.pos, A.quat, pin_first=False)
    J = prob.jacobian(np.zeros(6 * len(prob.free)), A.muscle_lengths([int(b) for b in row])).tocsc()
    M = prob.normal_matrix(J, S.REG)
    out = {"unknowns": int(M.shape[0]), "nnz": int(M.nnz)}
    for name, f in (("symmetric", S.spd_lu), ("colamd", S.colamd_lu)):
        c = time.process_time()
        lu = f(M)
        out[f"{name}_factor_cpu_s"] = time.process_time() - c
        out[f"{name}_fill"] = int(lu.L.nnz + lu.U.nnz)
    return out


def one(scene, row: str, which: str) -> dict:
    """The row's equilibrium by the minimiser with one factorisation: CPU, iterations, and
    what verification reads off it (probe lengths, largest joint stretch; sigma)."""
    f = S.spd_lu if which == "symmetric" else S.colamd_lu
    c = time.process_time()
    eq = S.equilibrium(scene, row, lu_of=f)
    cpu = time.process_time() - c
    return {"cpu_s": cpu, "iterations": eq.iterations, "joint_stretch": eq.max_joint_stretch, "probes": eq.probes}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--only", nargs="*", default=list(DEFAULT))
    ap.add_argument("--row", default=None, help="input row (default all ones)")
    args = ap.parse_args()
    res = {"what": __doc__.splitlines()[0], "machine": {"platform": platform.platform(), "cpus": os.cpu_count()},
           "load": os.getloadavg()[0], "examples": []}
    for k, name in enumerate(args.only):
        sc = build(compile_spec(load(str(ROOT / "examples" / name)))).circuit.scene
        row = args.row or "1" * len(sc.inputs)
        order = ("symmetric", "colamd") if k % 2 == 0 else ("colamd", "symmetric")
        runs = {w: one(sc, row, w) for w in order}
        a, b = runs["symmetric"], runs["colamd"]
        diffs = {"probe_length": max(abs(a["probes"][o] - b["probes"][o]) for o in a["probes"]),
                 "joint_stretch": abs(a["joint_stretch"] - b["joint_stretch"])}
        ex = {"example": name, "bodies": len(sc.bodies), "row": row, "order": list(order), "runs": runs,
              "cpu_ratio_colamd_over_symmetric": b["cpu_s"] / a["cpu_s"], "largest_difference": diffs,
              "fill": fill(sc, row)}
        res["examples"].append(ex)
        print(json.dumps({k2: v for k2, v in ex.items() if k2 != "runs"}), flush=True)
    OUT.mkdir(exist_ok=True)
    with atomic_path(OUT / "static_lu.json") as tmp:
        tmp.write_text(json.dumps(res, indent=1))
    plot(res)


def plot(res: dict) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    ex = res["examples"]
    names = [f"{e['example']}\n{e['bodies']} bodies" for e in ex]
    x = np.arange(len(ex))
    fig, ax = plt.subplots(1, 2, figsize=(10, 3.8))
    ax[0].bar(x - 0.2, [e["runs"]["colamd"]["cpu_s"] for e in ex], 0.4, label="COLAMD (before)")
    ax[0].bar(x + 0.2, [e["runs"]["symmetric"]["cpu_s"] for e in ex], 0.4, label="symmetric mode (spd_lu)")
    ax[0].set_ylabel("CPU s, one row's equilibrium")
    ax[1].bar(x - 0.2, [e["fill"]["colamd_fill"] for e in ex], 0.4, label="COLAMD")
    ax[1].bar(x + 0.2, [e["fill"]["symmetric_fill"] for e in ex], 0.4, label="symmetric mode")
    ax[1].set_ylabel("L + U entries, one factorisation")
    for a in ax:
        a.set_xticks(x, names, fontsize=8)
        a.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(OUT / "static_lu.png", dpi=110)


if __name__ == "__main__":
    main()
