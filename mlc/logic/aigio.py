"""Writers for AIGs: BLIF (``.names`` per AND node) and ASCII AIGER (``.aag``)."""
from __future__ import annotations

import re

from mlc.logic.aig import AIG


def _safe(name: str) -> str:
    s = re.sub(r"\s", "_", name)
    return s or "_"


def write_blif(aig: AIG, model: str = "mlc") -> str:
    """BLIF with one two-input ``.names`` per AND node and a buffer/inverter per output."""
    aig.check()
    ins = [_safe(x) for x in aig.inputs]
    outs = [_safe(x) for x in aig.outputs]
    n = aig.num_inputs

    names = set(ins) | set(outs)
    prefix = "n"
    while any(x.startswith(prefix) and x[len(prefix):].isdigit() for x in names) or \
            "$false" in names:
        prefix = "_" + prefix

    def sig(node: int) -> str:
        if node == 0:
            return "$false"
        if node <= n:
            return ins[node - 1]
        return f"{prefix}{node}"

    lines = [f".model {_safe(model)}", ".inputs " + " ".join(ins), ".outputs " + " ".join(outs)]
    used_false = any(x >> 1 == 0 for x in aig.output_lits)
    if used_false:
        lines += [".names $false"]
    for k, (a, b) in enumerate(aig.ands):
        node = n + 1 + k
        lines.append(f".names {sig(a >> 1)} {sig(b >> 1)} {sig(node)}")
        lines.append(f"{1 - (a & 1)}{1 - (b & 1)} 1")
    for name, x in zip(outs, aig.output_lits):
        src = sig(x >> 1)
        if src == name and not x & 1:
            continue
        lines.append(f".names {src} {name}")
        lines.append(f"{1 - (x & 1)} 1")
    lines.append(".end")
    return "\n".join(lines) + "\n"


def write_aiger(aig: AIG) -> str:
    """ASCII AIGER (``aag``) with a symbol table for inputs and outputs."""
    aig.check()
    n = aig.num_inputs
    m = aig.num_nodes - 1
    lines = [f"aag {m} {n} 0 {len(aig.outputs)} {len(aig.ands)}"]
    for i in range(n):
        lines.append(str(2 * (i + 1)))
    for x in aig.output_lits:
        lines.append(str(x))
    for k, (a, b) in enumerate(aig.ands):
        lines.append(f"{2 * (n + 1 + k)} {b} {a}")   # AIGER convention: lhs > rhs0 >= rhs1
    for i, name in enumerate(aig.inputs):
        lines.append(f"i{i} {name}")
    for i, name in enumerate(aig.outputs):
        lines.append(f"o{i} {name}")
    lines.append("c")
    lines.append("written by mlc")
    return "\n".join(lines) + "\n"
