"""Lower a specification to a first, unoptimised-but-reasonable AIG.

* :class:`~mlc.spec.NetworkSpec`: structural translation, node by node, with
  structural hashing and constant folding (don't cares are kept for later passes).
* :class:`~mlc.spec.TableSpec`: per output an irredundant SOP of the interval
  ``[on, on | dc]`` (Minato-Morreale), algebraically factored.
"""
from __future__ import annotations

from collections.abc import Sequence

from mlc.errors import InternalError
from mlc.spec import NetworkSpec, TableSpec
from mlc.logic import tt as T
from mlc.logic.aig import AIG
from mlc.logic.netsim import AIGAlgebra, eval_network


def factor_sop(g: AIG, cubes: Sequence[tuple[int, int]], var_lits: Sequence[int]) -> int:
    """Add an algebraically factored form of the cover ``cubes`` to ``g``; return its literal.

    ``cubes`` are ``(pos_mask, neg_mask)`` over the variables whose literals are ``var_lits``.
    """
    nv = len(var_lits)

    def cube_lit(p: int, q: int) -> int:
        lits = [var_lits[i] for i in range(nv) if (p >> i) & 1]
        lits += [var_lits[i] ^ 1 for i in range(nv) if (q >> i) & 1]
        return g.and_many(lits)

    def rec(cs: list[tuple[int, int]]) -> int:
        if not cs:
            return 0
        if (0, 0) in cs:                       # the empty cube: a tautology
            return 1
        if len(cs) == 1:
            return cube_lit(*cs[0])
        cp, cq = -1, -1
        for p, q in cs:
            cp &= p
            cq &= q
        if cp or cq:
            rest = [(p & ~cp, q & ~cq) for p, q in cs]
            return g.and_(cube_lit(cp, cq), rec(rest))
        # the literal in most cubes
        best, bestc = None, 1
        cnt_p = [0] * nv
        cnt_q = [0] * nv
        for p, q in cs:
            while p:
                low = p & -p
                cnt_p[low.bit_length() - 1] += 1
                p ^= low
            while q:
                low = q & -q
                cnt_q[low.bit_length() - 1] += 1
                q ^= low
        for i in range(nv):
            if cnt_p[i] > bestc:
                best, bestc = (i, 0), cnt_p[i]
            if cnt_q[i] > bestc:
                best, bestc = (i, 1), cnt_q[i]
        if best is None:
            return g.or_many([cube_lit(p, q) for p, q in cs])
        i, neg = best
        bit = 1 << i
        if neg:
            inside = [(p, q & ~bit) for p, q in cs if q & bit]
            outside = [(p, q) for p, q in cs if not q & bit]
        else:
            inside = [(p & ~bit, q) for p, q in cs if p & bit]
            outside = [(p, q) for p, q in cs if not p & bit]
        t = g.and_(var_lits[i] ^ neg, rec(inside))
        return g.or_(t, rec(outside)) if outside else t

    return rec([(p, q) for p, q in cubes])       # tuples, as `(0, 0) in cs` compares


def table_output(g: AIG, on: int, dc: int, n: int, var_lits: Sequence[int] | None = None,
                 both_phases: bool = True) -> int:
    """Literal of a factored ISOP for the incompletely specified function (on, dc)."""
    full = T.mask(n)
    on &= full
    dc &= full
    if var_lits is None:
        var_lits = [2 * (i + 1) for i in range(n)]
    if on == 0:
        return 0
    if (on | dc) == full:
        return 1
    cubes, _ = T.isop(on, on | dc, n)
    if not both_phases:
        return factor_sop(g, cubes, var_lits)
    off = full & ~(on | dc)
    cubes_n, _ = T.isop(off, off | dc, n)
    # choose the phase with fewer literals (a cheap estimate), build only that one
    lp = sum((p | q).bit_count() for p, q in cubes)
    ln = sum((p | q).bit_count() for p, q in cubes_n)
    if ln < lp:
        return factor_sop(g, cubes_n, var_lits) ^ 1
    return factor_sop(g, cubes, var_lits)


def from_table(spec: TableSpec) -> AIG:
    g = AIG(spec.inputs)
    n = spec.n
    for name, on, dc in zip(spec.outputs, spec.on, spec.dc):
        g.add_output(name, table_output(g, on, dc, n))
    return g


def from_network(spec: NetworkSpec) -> AIG:
    g = AIG(spec.inputs)
    vals = eval_network(spec, AIGAlgebra(g))
    for name, k in zip(spec.outputs, spec.output_nodes):
        g.add_output(name, vals[k])
    return g


def from_spec(spec) -> AIG:
    """A first AIG for ``spec`` (either kind), cleaned of dangling nodes."""
    if isinstance(spec, TableSpec):
        g = from_table(spec)
    elif isinstance(spec, NetworkSpec):
        g = from_network(spec)
    else:
        raise InternalError(f"from_spec: not a specification: {type(spec).__name__}")
    g = g.cleanup()
    g.check()
    return g
