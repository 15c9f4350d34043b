"""Writers for AIGs: BLIF (``.names`` per AND node), ASCII AIGER (``.aag``) and binary
AIGER (``.aig``, AIGER 1.9), plus converters between the two AIGER forms.

* :func:`write_blif`, :func:`write_aiger`, :func:`write_aiger_binary` -- an :class:`AIG` out;
* :func:`aag_to_aig` -- any ASCII AIGER text (e.g. ``Netlist.to_aiger()``) to binary, the
  AND nodes kept one for one (renumbered into the order the binary format requires);
* :func:`aig_to_aag` -- any AIGER file (either form) to ASCII.

The converters keep the symbol table and the comment.  Binary AND ``k`` of a file with
``I`` inputs defines literal ``lhs = 2 (I + k + 1)`` from ``rhs0 >= rhs1``, both smaller
than ``lhs``, stored as the two deltas ``lhs - rhs0`` and ``rhs0 - rhs1``, each in 7-bit
groups, lowest first, the high bit set on every byte but the last.
"""
from __future__ import annotations

import re

from mlc.errors import InternalError
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


def encode_delta(x: int) -> bytes:
    """One unsigned integer in AIGER's variable-length code (7 bits a byte, lowest first)."""
    if x < 0:
        raise InternalError(f"AIGER delta {x} is negative")
    out = bytearray()
    while x >= 0x80:
        out.append((x & 0x7F) | 0x80)
        x >>= 7
    out.append(x)
    return bytes(out)


def _binary(num_inputs: int, output_lits, ands, in_names, out_names, comment) -> bytes:
    """Binary AIGER from inputs ``1..I`` and ``ands[k] = (rhs0, rhs1)`` of literal
    ``2 (I + k + 1)`` with ``lhs > rhs0 >= rhs1``."""
    m = num_inputs + len(ands)
    parts = [f"aig {m} {num_inputs} 0 {len(output_lits)} {len(ands)}\n".encode()]
    parts += [f"{x}\n".encode() for x in output_lits]
    body = bytearray()
    for k, (r0, r1) in enumerate(ands):
        lhs = 2 * (num_inputs + 1 + k)
        if not lhs > r0 >= r1:
            raise InternalError(f"AND {k}: binary AIGER needs lhs {lhs} > rhs0 {r0} >= rhs1 {r1}")
        body += encode_delta(lhs - r0)
        body += encode_delta(r0 - r1)
    parts.append(bytes(body))
    sym = [f"i{i} {name}\n" for i, name in sorted(in_names.items())]
    sym += [f"o{i} {name}\n" for i, name in sorted(out_names.items())]
    if comment is not None:
        sym.append("c\n")
        sym += [f"{line}\n" for line in comment]
    parts.append("".join(sym).encode("utf-8"))
    return b"".join(parts)


def write_aiger_binary(aig: AIG, comment: str = "written by mlc") -> bytes:
    """Binary AIGER (``aig``) of ``aig`` with a symbol table for inputs and outputs.

    mlc's AIG numbering is already the binary format's: inputs ``1..n``, then the AND
    nodes in topological order, so literals are written as they are."""
    aig.check()
    ands = [(b, a) for a, b in aig.ands]        # invariant a < b, so rhs0 = b >= rhs1 = a
    return _binary(aig.num_inputs, aig.output_lits, ands, dict(enumerate(aig.inputs)),
                   dict(enumerate(aig.outputs)), comment.split("\n") if comment else None)


def aag_to_aig(data: str | bytes, filename: str = "<aag>") -> bytes:
    """Binary AIGER of an AIGER file (usually ASCII): every AND kept, renumbered so that
    inputs come first and each AND follows its fanins; symbols and comment kept.

    ``data`` is checked by :func:`mlc.front.aiger.read` first (a malformed file raises
    its :class:`~mlc.errors.MlcError`)."""
    from mlc.front.aiger import read

    raw, _spec = read(data, filename)
    var_of_and = {lhs >> 1: k for k, (lhs, _r0, _r1) in enumerate(raw.ands)}
    new_var = {0: 0}
    for i, lit in enumerate(raw.inputs):
        new_var[lit >> 1] = i + 1
    order: list[int] = []                 # AND indices, fanins first (read() rejected cycles)
    state = [0] * len(raw.ands)
    for root in range(len(raw.ands)):
        if state[root]:
            continue
        stack = [root]
        while stack:
            k = stack[-1]
            if state[k] == 0:
                state[k] = 1
                for r in raw.ands[k][1:]:
                    j = var_of_and.get(r >> 1)
                    if j is not None and state[j] == 0:
                        stack.append(j)
            else:
                stack.pop()
                if state[k] == 1:
                    state[k] = 2
                    order.append(k)
    n = len(raw.inputs)
    for pos, k in enumerate(order):
        new_var[raw.ands[k][0] >> 1] = n + 1 + pos

    def lit(x: int) -> int:
        return 2 * new_var[x >> 1] + (x & 1)

    ands = []
    for k in order:
        a, b = lit(raw.ands[k][1]), lit(raw.ands[k][2])
        ands.append((max(a, b), min(a, b)))
    return _binary(n, [lit(x) for x in raw.outputs], ands, raw.in_names, raw.out_names, raw.comment)


def aig_to_aag(data: str | bytes, filename: str = "<aig>") -> str:
    """ASCII AIGER of an AIGER file (usually binary): literals, symbols and comment kept."""
    from mlc.front.aiger import read

    raw, _spec = read(data, filename)
    lines = [f"aag {raw.M} {len(raw.inputs)} 0 {len(raw.outputs)} {len(raw.ands)}"]
    lines += [str(x) for x in raw.inputs]
    lines += [str(x) for x in raw.outputs]
    lines += [f"{lhs} {r0} {r1}" for lhs, r0, r1 in raw.ands]
    lines += [f"i{i} {name}" for i, name in sorted(raw.in_names.items())]
    lines += [f"o{i} {name}" for i, name in sorted(raw.out_names.items())]
    if raw.comment is not None:
        lines += ["c"] + raw.comment
    return "\n".join(lines) + "\n"
