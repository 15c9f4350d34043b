"""Equivalence of a synthesized AIG with its specification, don't cares respected.

* up to :data:`EXHAUSTIVE_LIMIT` inputs: exhaustive bit-parallel simulation (every
  minterm at once, one big int per signal);
* above: random simulation first (finds most bugs in milliseconds), then a proof that
  every miter output ``(aig XOR spec) AND NOT dc`` is the constant 0:

  - networks (expressions, BLIF, AIGER): SAT sweeping (:mod:`mlc.logic.cec`), which
    is fast when the implementation was derived from the specification, as here;
    if it exceeds its conflict budget, a BDD;
  - tables: a BDD built from the tables.

  If neither proof finishes within its limits, the check fails with a clear
  :class:`~mlc.errors.MlcError`: an unproven network is never passed on.

A mismatch raises :class:`~mlc.errors.InternalError` naming the output and a
counterexample: a synthesized network that differs from its specification is a bug
of mlc, never something to pass on silently.
"""
from __future__ import annotations

import random

from mlc.errors import InternalError
from mlc.spec import NetworkSpec, TableSpec
from mlc.logic import tt as T
from mlc.logic.aig import AIG
from mlc.logic.bdd import BDD
from mlc.logic.netsim import eval_network, simulate_network

EXHAUSTIVE_LIMIT = 16
SAT_CONFLICTS = 300_000     # per output, before the BDD is tried instead


def spec_tables(spec) -> tuple[list[int], list[int]]:
    """Exhaustive (on, dc) tables of every output of ``spec``."""
    n = len(spec.inputs)
    full = T.mask(n)
    if isinstance(spec, TableSpec):
        return [x & full for x in spec.on], [x & full for x in spec.dc]
    words = [T.var(n, i) for i in range(n)]
    vals = simulate_network(spec, words, 1 << n)
    dc = [(d & full) for d in spec.dc] if spec.dc else [0] * len(vals)
    return [v & ~d & full for v, d in zip(vals, dc)], dc


def _assignment(spec, m: int) -> str:
    return ", ".join(f"{x}={(m >> i) & 1}" for i, x in enumerate(spec.inputs))


def _fail(spec, out: str, m: int, got: int, want: int):
    raise InternalError(f"synthesized network is NOT equivalent to {spec.source}: output {out} "
                        f"is {got}, specification says {want}, at {_assignment(spec, m)}")


def check_equivalent(aig: AIG, spec, seed: int = 1) -> dict:
    """Prove ``aig`` implements ``spec`` (either kind); raise InternalError if it does not."""
    aig.check()
    if list(aig.inputs) != list(spec.inputs):
        raise InternalError(f"AIG inputs {aig.inputs} differ from the specification's {spec.inputs}")
    if list(aig.outputs) != list(spec.outputs):
        raise InternalError(f"AIG outputs {aig.outputs} differ from the specification's {spec.outputs}")
    n = len(spec.inputs)
    if n <= EXHAUSTIVE_LIMIT:
        full = T.mask(n)
        on, dc = spec_tables(spec)
        got = aig.truth_tables()
        for name, g, o, d in zip(spec.outputs, got, on, dc):
            diff = (g ^ o) & ~d & full
            if diff:
                m = (diff & -diff).bit_length() - 1
                _fail(spec, name, m, (g >> m) & 1, (o >> m) & 1)
        return {"method": "exhaustive", "equivalent": True, "inputs": n,
                "outputs": len(spec.outputs), "minterms": 1 << n}

    # --- wide: random simulation, then a SAT-sweeping or BDD proof
    rng = random.Random(seed)
    width = 4096
    words = [rng.getrandbits(width) for _ in range(n)]
    got = aig.simulate(words, width)
    if isinstance(spec, NetworkSpec):
        want = simulate_network(spec, words, width)
    else:
        want = None
    if want is not None and not spec.dc:
        for name, g, w in zip(spec.outputs, got, want):
            diff = g ^ w
            if diff:
                b = (diff & -diff).bit_length() - 1
                m = sum(((words[i] >> b) & 1) << i for i in range(n))
                _fail(spec, name, m, (g >> b) & 1, (w >> b) & 1)
    if isinstance(spec, NetworkSpec):
        from mlc.logic import cec
        st: dict = {}
        try:
            res = cec.check(aig, spec, seed=seed, max_conflicts=SAT_CONFLICTS, stats=st)
        except cec.Undecided:
            pass
        else:
            for o, m in enumerate(res):
                if m is not None:
                    want = _spec_value(spec, o, m)
                    _fail(spec, spec.outputs[o], m, 1 - want, want)
            return {"method": "sat", "equivalent": True, "inputs": n, "outputs": len(spec.outputs),
                    "random_patterns": width, "miter_ands": st["miter_ands"],
                    "merged": st["merged"]}
    return _bdd_check(aig, spec, width)


def _spec_value(spec: NetworkSpec, o: int, m: int) -> int:
    """Output ``o`` of the network on minterm ``m``."""
    return simulate_network(spec, [(m >> i) & 1 for i in range(len(spec.inputs))], 1)[o]


def _bdd_check(aig: AIG, spec, width: int) -> dict:
    n = len(spec.inputs)
    # variable order: inputs in depth-first order from the outputs (interleaves the
    # operands of arithmetic circuits), unless don't cares or tables fix the natural one
    natural = not isinstance(spec, NetworkSpec) or bool(spec.dc and any(spec.dc))
    order = list(range(n)) if natural else _dfs_order(aig)
    pos = [0] * n
    for level, i in enumerate(order):
        pos[i] = level
    bdd = BDD(n)
    if isinstance(spec, NetworkSpec):
        vals = eval_network(spec, _Ordered(bdd, pos))
        sb = [vals[k] for k in spec.output_nodes]
        db = [bdd.from_table(d, n) if d else 0 for d in spec.dc] if spec.dc else [0] * len(sb)
    else:
        sb = [bdd.from_table(o, n) for o in spec.on]
        db = [bdd.from_table(d, n) if d else 0 for d in spec.dc]
    ab = _aig_bdds(aig, bdd, pos)
    for name, a, s, d in zip(spec.outputs, ab, sb, db):
        miter = bdd.and_(bdd.xor_(a, s), bdd.not_(d))
        if miter != 0:
            cex = bdd.sat_one(miter)
            m = sum(cex.get(pos[i], 0) << i for i in range(n))
            want = _eval_bdd(bdd, s, m, pos)
            _fail(spec, name, m, 1 - want, want)
    return {"method": "bdd", "equivalent": True, "inputs": n, "outputs": len(spec.outputs),
            "bdd_nodes": len(bdd.nodes), "random_patterns": width}


class _Ordered:
    """BDD algebra whose input ``i`` is BDD variable ``pos[i]``."""

    def __init__(self, bdd: BDD, pos: list[int]):
        self.bdd = bdd
        self.pos = pos

    def inp(self, i):
        return self.bdd.var(self.pos[i])

    def __getattr__(self, name):
        return getattr(self.bdd, name)


def _dfs_order(aig: AIG) -> list[int]:
    n = aig.num_inputs
    seen = bytearray(aig.num_nodes)
    order: list[int] = []
    for lit in aig.output_lits:
        stack = [lit >> 1]
        while stack:
            x = stack.pop()
            if seen[x]:
                continue
            seen[x] = 1
            if 1 <= x <= n:
                order.append(x - 1)
            elif x > n:
                a, b = aig.ands[x - n - 1]
                stack.append(b >> 1)
                stack.append(a >> 1)
    order += [i for i in range(n) if not seen[i + 1]]
    return order


def _eval_bdd(bdd: BDD, f: int, m: int, pos: list[int] | None = None) -> int:
    inv = None
    if pos is not None:
        inv = {p: i for i, p in enumerate(pos)}
    while f > 1:
        v, lo, hi = bdd.nodes[f]
        i = inv[v] if inv is not None else v
        f = hi if (m >> i) & 1 else lo
    return f


def _aig_bdds(aig: AIG, bdd: BDD, pos: list[int] | None = None) -> list[int]:
    n = aig.num_inputs
    pos = pos if pos is not None else list(range(n))
    val = [0] + [bdd.var(pos[i]) for i in range(n)]
    for a, b in aig.ands:
        x = val[a >> 1]
        if a & 1:
            x = bdd.not_(x)
        y = val[b >> 1]
        if b & 1:
            y = bdd.not_(y)
        val.append(bdd.and_(x, y))
    return [bdd.not_(val[x >> 1]) if x & 1 else val[x >> 1] for x in aig.output_lits]
