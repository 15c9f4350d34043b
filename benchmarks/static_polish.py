"""What the static minimiser's polish buys a circuit's verification, and what it costs.

:func:`mlc.verify.static.equilibrium` ends with a minimisation at ``REG_POLISH`` (1e-16 k0)
that takes the least-motion term's bias (``REG``, 1e-9 k0) off the pose.  In a connector
circuit that polish crawls along the chains' floppy modes.  For each circuit and row here,
the equilibrium is solved twice, with and without the polish, and compared:

* the wall time and the number of LU factorisations of each;
* the largest change of a probe's read length and of a body's position (sigma);
* the bits read, the largest joint stretch and the smallest slab clearance
  (:func:`mlc.verify.overlap.clearance`) of each pose.

The summary also gives ``auto``, what ``mlc verify`` does (``polish=None``): the unpolished
pose where its largest joint stretch and muscle strain are within ``POLISH_ABOVE``, else
the polished one.  It is derived from the two solves, not run a third time: ``polish=None``
is the unpolished path followed, past the threshold, by the polish, so its pose is bit for
bit one of the two (``tests/test_verify_static.py``); its time is counted as that solve's.

Circuits: the examples, compiled and built as ``mlc compile`` does (every row of tetris,
snake3 and both full adders; ``--sample`` rows drawn with ``--seed`` for the larger
tables), and ``nand_mesh(7, depth)`` at -O0 for each ``--meshes`` depth (its all-ones row,
the row ``circuit_scaling.py`` times).

    python benchmarks/static_polish.py [--only tetris.tt ...] [--meshes 2] [--sample 4] [--seed 0]
    python benchmarks/static_polish.py --summarise     (the summary again from the JSON; runs nothing)

Writes benchmarks/results/static_polish.json and .png.  Wall seconds in one run on this
(shared) machine: compare the ratio of the two times, not absolute numbers.
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import random
import time
from pathlib import Path

import mlc  # noqa: F401 -- before numpy: pins OpenBLAS's kernels (mlc/__init__.py)
import numpy as np

from circuit_examples import SUFFIXES      # the example files circuit_examples.py compiles
from mlc.verify import static
from mlc.verify.overlap import clearance
from gitstate import commit as git_commit      # benchmarks/gitstate.py

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "benchmarks" / "results"
ALL_ROWS = ("tetris.tt", "snake3.tt", "full_adder.tt", "full_adder.expr")


def solve(scene, row: str, polish: bool) -> tuple:
    """(Equilibrium, wall seconds, LU factorisations) of ``row``."""
    lus = [0]

    def lu_of(M):
        lus[0] += 1
        return static.colamd_lu(M)
    t0 = time.perf_counter()
    eq = static.equilibrium(scene, row, polish=polish, lu_of=lu_of)
    return eq, time.perf_counter() - t0, lus[0]


def compare_row(scene, row: str) -> dict:
    with_, t_with, lu_with = solve(scene, row, True)
    without, t_without, lu_without = solve(scene, row, False)
    probes = {pr.name: pr for pr in scene.probes}
    bits = {n: (probes[n].bit(with_.probes[n]), probes[n].bit(without.probes[n])) for n in probes}
    c_with = clearance(scene, with_.pos, with_.quat).min_clearance
    c_without = clearance(scene, without.pos, without.quat).min_clearance
    return {"row": row, "seconds_polish": t_with, "seconds_no_polish": t_without,
            "lu_polish": lu_with, "lu_no_polish": lu_without,
            "iterations_polish": with_.iterations, "iterations_no_polish": without.iterations,
            "max_probe_change": max(abs(with_.probes[n] - without.probes[n]) for n in probes),
            "max_body_move": float(np.abs(with_.pos - without.pos).max()),
            "same_bits": all(a == b for a, b in bits.values()),
            "stretch_polish": with_.max_joint_stretch, "stretch_no_polish": without.max_joint_stretch,
            "strain_no_polish": without.max_muscle_strain,
            "clearance_polish": c_with, "clearance_no_polish": c_without}


def example_scene(path: Path):
    from mlc.pipeline import build, compile_spec, load
    return build(compile_spec(load(str(path)))).circuit.scene


def mesh_scene(depth: int):
    from mlc.circuit import build as cb
    from mlc.logic.library import nand_mesh
    from mlc.pipeline import compile_spec
    spec = nand_mesh(7, depth)
    c = compile_spec(spec, 0, "expand")
    return cb.build_circuit(c.netlist, spec, cb.CircuitOptions(max_gates=len(c.netlist.gates))).scene


def auto_polishes(r: dict) -> bool:
    """Whether ``polish=None`` polished this row (the muscle strain was not recorded before
    session 29's second run: then the stretch alone)."""
    return max(r["stretch_no_polish"], r.get("strain_no_polish", 0.0)) > static.POLISH_ABOVE


def summary(points: list[dict]) -> dict:
    rows = [r for p in points for r in p["rows"]]
    t_with = sum(r["seconds_polish"] for r in rows)
    t_without = sum(r["seconds_no_polish"] for r in rows)
    auto = [auto_polishes(r) for r in rows]
    t_auto = sum(r["seconds_polish"] if a else r["seconds_no_polish"] for r, a in zip(rows, auto))
    lu_auto = sum(r["lu_polish"] if a else r["lu_no_polish"] for r, a in zip(rows, auto))
    left = [r for r, a in zip(rows, auto) if not a]
    return {"rows": len(rows), "seconds_polish": t_with, "seconds_no_polish": t_without,
            "time_ratio": t_with / t_without if t_without else None,
            "lu_ratio": sum(r["lu_polish"] for r in rows) / max(1, sum(r["lu_no_polish"] for r in rows)),
            "max_probe_change": max(r["max_probe_change"] for r in rows),
            "max_body_move": max(r["max_body_move"] for r in rows),
            "all_same_bits": all(r["same_bits"] for r in rows),
            "max_stretch_no_polish": max(r["stretch_no_polish"] for r in rows),
            "max_clearance_change": max(abs(r["clearance_polish"] - r["clearance_no_polish"]) for r in rows),
            "auto": {"polish_above": static.POLISH_ABOVE, "rows_polished": sum(auto), "seconds": t_auto,
                     "time_ratio_polish_to_auto": t_with / t_auto if t_auto else None,
                     "lu_ratio_polish_to_auto": sum(r["lu_polish"] for r in rows) / max(1, lu_auto),
                     "max_probe_change": max((r["max_probe_change"] for r in left), default=0.0),
                     "max_body_move": max((r["max_body_move"] for r in left), default=0.0),
                     "max_stretch": max([r["stretch_polish"] for r, a in zip(rows, auto) if a]
                                        + [r["stretch_no_polish"] for r in left])}}


def plot(points: list[dict], path: Path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(1, 2, figsize=(10, 4))
    for p in points:
        r = p["rows"]
        ax[0].scatter([x["seconds_no_polish"] for x in r], [x["seconds_polish"] for x in r], s=14,
                      label=f"{p['circuit']} ({p['bodies']} bodies)")
        ax[1].scatter([p["bodies"]] * len(r), [max(x["max_probe_change"], 1e-18) for x in r], s=14)
    lim = max(x["seconds_polish"] for p in points for x in p["rows"]) * 1.1
    ax[0].plot([0, lim], [0, lim], "k:", lw=0.8, label="equal")
    ax[0].set(xlabel="row without polish (s)", ylabel="row with polish (s)", xscale="log", yscale="log",
              title="static equilibrium of one row")
    ax[0].legend(fontsize=7)
    ax[1].set(xlabel="bodies", ylabel="largest probe change (sigma)", xscale="log", yscale="log",
              title="what the polish changes in the readings")
    fig.tight_layout()
    fig.savefig(path, dpi=120)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--only", nargs="*", help="example file names (default: all)")
    ap.add_argument("--meshes", nargs="*", type=int, default=[2], help="nand_mesh(7, depth) depths")
    ap.add_argument("--sample", type=int, default=4, help="rows drawn from the larger examples' tables")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--summarise", action="store_true", help="recompute the summary from the JSON; run nothing")
    args = ap.parse_args()
    if args.summarise:
        res = json.loads((OUT / "static_polish.json").read_text())
        res["summary"] = summary(res["points"])
        (OUT / "static_polish.json").write_text(json.dumps(res, indent=1))
        print(json.dumps(res["summary"], indent=1))
        return
    commit = git_commit()
    paths = sorted(p for p in (ROOT / "examples").iterdir() if p.suffix in SUFFIXES)
    if args.only is not None:
        paths = [p for p in paths if p.name in args.only]
    jobs = [(p.name, lambda p=p: example_scene(p)) for p in paths]
    jobs += [(f"nand_mesh(7, {d})", lambda d=d: mesh_scene(d)) for d in args.meshes]
    rng = random.Random(args.seed)
    points = []
    for name, make in jobs:
        sc = make()
        states = sorted(sc.states())
        if name.startswith("nand_mesh"):
            rows = ["1" * len(sc.inputs)]
        elif name in ALL_ROWS or len(states) <= args.sample:
            rows = states
        else:
            rows = sorted(rng.sample(states, args.sample))
        pt = {"circuit": name, "bodies": len(sc.bodies), "rows": []}
        for row in rows:
            r = compare_row(sc, row)
            pt["rows"].append(r)
            print(f"{name} {row}: {r['seconds_polish']:.1f} s -> {r['seconds_no_polish']:.1f} s, "
                  f"LU {r['lu_polish']} -> {r['lu_no_polish']}, probe change {r['max_probe_change']:.2e}, "
                  f"same bits {r['same_bits']}", flush=True)
        points.append(pt)
        res = {"machine": {"platform": platform.platform(), "cpus": os.cpu_count(),
                           "load_after": list(os.getloadavg())}, "commit": commit, "seed": args.seed,
               "date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()),
               "points": points, "summary": summary(points), "complete": len(points) == len(jobs)}
        OUT.mkdir(parents=True, exist_ok=True)
        (OUT / "static_polish.json").write_text(json.dumps(res, indent=1))
    plot(points, OUT / "static_polish.png")
    print(json.dumps(summary(points), indent=1))


if __name__ == "__main__":
    main()
