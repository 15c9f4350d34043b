"""Evaluate a :class:`~mlc.spec.NetworkSpec` over any Boolean algebra.

One evaluator serves three purposes: bit-parallel simulation (ints as words),
lowering to an AIG (literals) and BDD construction (node ids).  An algebra provides
``const(b)``, ``inp(i)``, ``not_(x)``, ``and_(x, y)``, ``or_(x, y)``, ``xor_(x, y)``
and optionally ``mux_(s, t, e)`` and ``maj3(a, b, c)``.
"""
from __future__ import annotations

from mlc.errors import InternalError, MlcError
from mlc.spec import NetworkSpec
from mlc.logic.aig import balanced


def input_map(spec: NetworkSpec) -> dict[int, int]:
    """Node index of every ``input`` node -> index into ``spec.inputs``.

    An input node is matched by name; unnamed ones take the remaining inputs in order.
    """
    pos = {name: i for i, name in enumerate(spec.inputs)}
    res: dict[int, int] = {}
    used: set[int] = set()
    pending = []
    for k, node in enumerate(spec.nodes):
        if node.op == "input":
            if node.name is not None and node.name in pos and pos[node.name] not in used:
                res[k] = pos[node.name]
                used.add(pos[node.name])
            else:
                pending.append(k)
    free = [i for i in range(len(spec.inputs)) if i not in used]
    if len(pending) > len(free):
        raise MlcError(f"network has more input nodes than the {len(spec.inputs)} declared inputs",
                       spec.source)
    for k, i in zip(pending, free):
        res[k] = i
    return res


def majority(alg, xs):
    k = len(xs)
    if k == 1:
        return xs[0]
    if k == 3 and hasattr(alg, "maj3"):
        return alg.maj3(*xs)
    t = k // 2 + 1
    ge = [alg.const(True)] + [alg.const(False)] * t   # ge[j]: at least j of the seen args are 1
    for x in xs:
        for j in range(t, 0, -1):
            ge[j] = alg.or_(ge[j], alg.and_(ge[j - 1], x))
    return ge[t]


def eval_network(spec: NetworkSpec, alg) -> list:
    """Values of all nodes of ``spec`` in ``alg``."""
    imap = input_map(spec)
    vals: list = []
    for k, node in enumerate(spec.nodes):
        op = node.op
        a = [vals[j] for j in node.args]
        for j in node.args:
            if not 0 <= j < k:
                raise InternalError(f"network node {k} refers to node {j}, not an earlier one")
        if op == "input":
            v = alg.inp(imap[k])
        elif op == "const0":
            v = alg.const(False)
        elif op == "const1":
            v = alg.const(True)
        elif op == "buf":
            v = a[0]
        elif op == "not":
            v = alg.not_(a[0])
        elif op in ("and", "nand"):
            v = balanced(alg.and_, a) if a else alg.const(True)
            if op == "nand":
                v = alg.not_(v)
        elif op in ("or", "nor"):
            v = balanced(alg.or_, a) if a else alg.const(False)
            if op == "nor":
                v = alg.not_(v)
        elif op in ("xor", "xnor"):
            v = balanced(alg.xor_, a) if a else alg.const(False)
            if op == "xnor":
                v = alg.not_(v)
        elif op == "implies":
            v = alg.or_(alg.not_(a[0]), a[1])
        elif op == "iff":
            v = alg.not_(alg.xor_(a[0], a[1]))
        elif op == "maj":
            v = majority(alg, a)
        elif op == "mux":
            if hasattr(alg, "mux_"):
                v = alg.mux_(a[0], a[1], a[2])
            else:
                v = alg.or_(alg.and_(a[0], a[1]), alg.and_(alg.not_(a[0]), a[2]))
        elif op == "sop":
            cover = node.cover or []
            terms = []
            for cube, _bit in cover:
                if len(cube) != len(a):
                    raise InternalError(f"network node {k}: cube {cube!r} has {len(cube)} "
                                        f"columns for {len(a)} fanins")
                lits = []
                for c, x in zip(cube, a):
                    if c == "1":
                        lits.append(x)
                    elif c == "0":
                        lits.append(alg.not_(x))
                terms.append(balanced(alg.and_, lits) if lits else alg.const(True))
            v = balanced(alg.or_, terms) if terms else alg.const(False)
            if cover and cover[0][1] == "0":
                v = alg.not_(v)
        else:
            raise InternalError(f"network node {k}: unknown operator {op!r}")
        vals.append(v)
    return vals


class WordAlgebra:
    """Bit-parallel simulation on ``width``-bit ints."""

    def __init__(self, words, width: int):
        self.words = list(words)
        self.full = (1 << width) - 1

    def const(self, b):
        return self.full if b else 0

    def inp(self, i):
        return self.words[i]

    def not_(self, x):
        return x ^ self.full

    def and_(self, x, y):
        return x & y

    def or_(self, x, y):
        return x | y

    def xor_(self, x, y):
        return x ^ y

    def mux_(self, s, t, e):
        return (s & t) | (~s & e & self.full)

    def maj3(self, a, b, c):
        return (a & b) | (a & c) | (b & c)


class AIGAlgebra:
    """Structural translation into an :class:`~mlc.logic.aig.AIG` (literals)."""

    def __init__(self, g):
        self.g = g

    def const(self, b):
        return 1 if b else 0

    def inp(self, i):
        return 2 * (i + 1)

    def not_(self, x):
        return x ^ 1

    def and_(self, x, y):
        return self.g.and_(x, y)

    def or_(self, x, y):
        return self.g.or_(x, y)

    def xor_(self, x, y):
        return self.g.xor_(x, y)

    def mux_(self, s, t, e):
        return self.g.mux_(s, t, e)

    def maj3(self, a, b, c):
        return self.g.maj_(a, b, c)


def simulate_network(spec: NetworkSpec, words, width: int) -> list[int]:
    """Bit-parallel output values of ``spec`` on the given input words."""
    vals = eval_network(spec, WordAlgebra(words, width))
    return [vals[k] for k in spec.output_nodes]
