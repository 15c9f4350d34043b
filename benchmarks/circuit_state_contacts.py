"""The router's predicted contacts against the static minimiser (issue 9, deliverable 2).

The builder's rigid-layer test (:mod:`mlc.circuit.contact`) predicts which layers of two
chains would touch in some input row: each layer a rigid rhombus where it is built, in
every state of its wire.  What it leaves out is how the chains move when the circuit
relaxes in that row.  The scene's meta names the pairs it could not route apart
(``connector.state_contacts``, clearance in sigma).  This script takes a circuit with such
pairs -- the 7-bit ripple-carry adder by default, the widest the benchmark builds -- and
checks the prediction with something that does not share its model: the static minimiser
(:func:`mlc.verify.circuit.verify_static`, the circuit's equilibrium in the row) and the
exact oriented-box clearance of every pair of slabs of different bodies in that pose.

Rows: the wires named in the predicted contacts (below zero) take a few combinations of
values over all input rows (:func:`mlc.circuit.build._wire_values`); for each combination
the row with the fewest ones (then the smallest) is checked, the combinations whose wires
switch most from the built row first.  Then, up to ``--max-rows``, the all-ones row (every
muscle moved) and rows drawn at random (``--seed``): with no contact predicted, these test
the prediction's "clear" on rows it did not single out.  Each row's result is written as
soon as it is measured, so a run stopped part way keeps what it measured.

    python benchmarks/circuit_state_contacts.py [--adder 7] [--max-rows 8] [--budget S] [--seed 0]

Writes ``benchmarks/results/circuit_state_contacts.json``: per row the wires' values, the
row's smallest clearance and its pair, whether the row reads right, and the seconds.
"""
from __future__ import annotations

import argparse
import itertools
import json
import os
import platform
import re
import time
from pathlib import Path

import mlc  # noqa: F401 -- before numpy: pins OpenBLAS's kernels (mlc/__init__.py)
import numpy as np

from mlc.circuit.build import CircuitOptions, _wire_values, build_circuit
from mlc.io.atomic import atomic_path
from mlc.logic.library import ripple_adder
from mlc.pipeline import compile_spec
from mlc.verify.circuit import verify_static

OUT = Path(__file__).resolve().parent / "results"


def wire_of(tag: str, netlist) -> tuple:
    """The wire (``("input", name)`` or ``("gate", id)``) a chain tag ``w_<src>_<k>`` carries."""
    m = re.fullmatch(r"w_(.+)_(\d+)", tag)
    if m is None:
        raise ValueError(f"not a chain tag: {tag!r}")
    src = m.group(1)
    if any(g.id == src for g in netlist.gates):
        return ("gate", src)
    if any(w.name == src for w in netlist.inputs):
        return ("input", src)
    raise ValueError(f"chain {tag!r}: no gate or input {src!r}")


def rows_for(netlist, inputs: list[str], wires: list[tuple]) -> list[tuple[str, tuple]]:
    """One input row per combination of the ``wires``' physical values, with the fewest ones
    (then the smallest bit string); ordered by how many of the wires differ from the all-zero
    row (most first)."""
    n = len(inputs)
    zero = _wire_values(netlist, {x: 0 for x in inputs})
    base = tuple(zero[w] for w in wires)
    best: dict = {}
    for bits in itertools.product((0, 1), repeat=n):
        v = _wire_values(netlist, dict(zip(inputs, bits)))
        combo = tuple(v[w] for w in wires)
        row = "".join(map(str, bits))
        key = (row.count("1"), row)
        if combo not in best or key < best[combo][0]:
            best[combo] = (key, row)
    order = sorted(best, key=lambda c: (-sum(a != b for a, b in zip(c, base)), best[c][0]))
    return [(best[c][1], c) for c in order]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--adder", type=int, default=7, help="width of the ripple-carry adder (bits)")
    ap.add_argument("--max-rows", type=int, default=8, help="check at most this many rows")
    ap.add_argument("--budget", type=float, default=None, help="stop starting rows after this many seconds")
    ap.add_argument("--seed", type=int, default=0, help="seed of the random rows that fill up to --max-rows")
    ap.add_argument("--json", type=Path, default=OUT / "circuit_state_contacts.json")
    a = ap.parse_args()
    spec = ripple_adder(a.adder)
    c = compile_spec(spec, 2, "expand")
    t0, c0 = time.perf_counter(), time.process_time()
    circ = build_circuit(c.netlist, spec, CircuitOptions(max_gates=len(c.netlist.gates)))
    sc = circ.scene
    res = {"what": __doc__.split("\n\n")[0], "circuit": f"ripple_adder({a.adder}), -O2, expand",
           "gates": len(c.netlist.gates), "bodies": len(sc.bodies),
           "build_s": time.perf_counter() - t0, "build_cpu_s": time.process_time() - c0,
           "machine": {"platform": platform.platform(), "cpus": os.cpu_count()},
           "units": "sigma, seconds",
           "predicted": sc.meta["connector"].get("state_contacts", []), "rows": []}
    touching = [p for p in res["predicted"] if p[4] < 0]
    tags = sorted({p[0] for p in touching} | {p[2] for p in touching})
    wires = sorted({wire_of(t, c.netlist) for t in tags})
    res["wires"] = ["/".join(w) for w in wires]
    inputs = list(sc.inputs)
    plan = [(r, combo, "contact" if wires else "all zero (as built; no contact predicted)")
            for r, combo in rows_for(c.netlist, inputs, wires)][:a.max_rows]
    fill = ["1" * len(inputs)]
    rng = np.random.default_rng(a.seed)
    while len(fill) < a.max_rows + 1:
        fill.append("".join(map(str, rng.integers(0, 2, len(inputs)))))
    for r in fill:
        if len(plan) < a.max_rows and r not in [p[0] for p in plan]:
            v = _wire_values(c.netlist, dict(zip(inputs, map(int, r))))
            plan.append((r, tuple(v[w] for w in wires), "all ones" if r == fill[0] else f"random (seed {a.seed})"))
    res["planned_rows"] = [[r, why] for r, _, why in plan]

    def save():
        with atomic_path(a.json) as tmp:
            Path(tmp).write_text(json.dumps(res, indent=1) + "\n")
    save()
    print(f"{len(sc.bodies)} bodies, built in {res['build_cpu_s']:.0f} s CPU; predicted below zero: {touching}")
    start = time.perf_counter()
    for row, combo, why in plan:
        if a.budget is not None and time.perf_counter() - start > a.budget:
            res["stopped"] = f"budget of {a.budget} s passed before row {row}"
            break
        rep = verify_static(sc, rows=[row])
        r = rep.rows[0]
        res["rows"].append({"row": row, "why": why, "wire_values": dict(zip(res["wires"], combo)), "ok": bool(r["ok"]),
                            "clearance": r.get("clearance"), "clearance_pair": r.get("clearance_pair"),
                            "joint_stretch": r["joint_stretch"], "seconds": r["seconds"]})
        print(res["rows"][-1], flush=True)
        save()


if __name__ == "__main__":
    main()
