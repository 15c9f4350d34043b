"""Shannon decomposition with exact multi-output synthesis of the cofactors (-O3).

For a table of 5 inputs, split on one input ``x``: every output ``f`` is
``x ? f1 : f0``, and the cofactors ``f0, f1`` of all outputs are functions of the
other 4 inputs.  All the cofactors are synthesised *together* (shared gates), and
each output is joined from its two cofactors with the cheapest gate pattern their
realised functions allow: 0 gates (equal), 1 (one a constant), 2 (one implies the
other: ``f = f0 | x & f1``) or 3 (a multiplexer or an XOR).  The cofactors are
first synthesised as one 4-input table by the heuristic flow at -O2 (deterministic),
then SAT looks for smaller circuits within the time limit.

Majority of 5 is the example this was written for: the cofactors are the
at-least-3 and at-least-2 thresholds of 4 inputs, which SAT synthesises together in
8 ANDs (the minimum: exactsat.minimum_circuit; the -O2 flow finds 8 too), and
``T3 <= T2`` joins them with 2 more: 10 ANDs, as ABC's ``&deepsyn`` finds; the
heuristic flow gives 12.

Every input is tried as ``x`` (inputs whose cofactor targets coincide are tried once),
so the result does not depend on the order in which the inputs are listed, except
through the SAT solver's real-time limit.  Time is real seconds (like
:mod:`mlc.logic.exact_multi`).
"""
from __future__ import annotations

import time

from mlc.logic import exactsat
from mlc.logic import tt as T
from mlc.logic.aig import AIG
from mlc.logic.equiv import spec_tables
from mlc.spec import TableSpec

INPUTS = 5
TIME_LIMIT = 6.0     # real seconds of SAT per -O3 run, after the deterministic heuristic part


def _classify(t: int, care: int, k: int):
    """('const', v) / ('lit', i, c) when ``t`` needs no gate on ``care``, else None."""
    full = T.mask(k)
    t &= care
    if t == 0:
        return ("const", 0)
    if t == care:
        return ("const", 1)
    for i in range(k):
        v = T.var(k, i) & care
        if v == t:
            return ("lit", i, 0)
        if full & ~T.var(k, i) & care == t:
            return ("lit", i, 1)
    return None


def _split(n: int, on: list[int], dc: list[int], x: int):
    """Cofactor targets of every output over the inputs other than ``x``.

    Returns (targets, refs): ``targets`` a list of (table, care) over ``n-1``
    variables, distinct up to complement; ``refs[o] = (r0, r1)`` for output ``o``,
    each ``('const', v)``, ``('lit', i, c)`` or ``('tgt', index, complement)``."""
    full = T.mask(n)
    others = [i for i in range(n) if i != x]
    k = n - 1
    targets: list[tuple[int, int]] = []
    refs = []
    for f, d in zip(on, dc):
        care = full & ~d
        pair = []
        for cof in (T.cof0, T.cof1):
            t = T.shrink(cof(f & care, n, x), n, others)
            c = T.shrink(cof(care, n, x), n, others)
            r = _classify(t, c, k)
            if r is None:
                t &= c
                for idx, (g, gc) in enumerate(targets):
                    if gc == c and g == t:
                        r = ("tgt", idx, 0)
                        break
                    if gc == c and g == c & ~t:
                        r = ("tgt", idx, 1)
                        break
                else:
                    r = ("tgt", len(targets), 0)
                    targets.append((t, c))
            pair.append(r)
        refs.append(tuple(pair))
    return targets, refs


def _join_bound(r0, r1, targets) -> int:
    """Gates needed to join the cofactors of one output (a lower bound when the
    cofactors have don't cares, and ignoring gates shared between outputs)."""
    if r0 == r1:
        return 0
    if r0[0] == "const" or r1[0] == "const":
        return 1
    if r0[0] == "tgt" and r1[0] == "tgt":
        (t0, c0), (t1, c1) = targets[r0[1]], targets[r1[1]]
        if r0[2]:
            t0 = c0 & ~t0
        if r1[2]:
            t1 = c1 & ~t1
        both = c0 & c1
        if t0 & both & ~t1 and t1 & both & ~t0:
            return 3                    # neither implies the other: a mux or an XOR
    return 2


def _circuit_aig(k: int, circuit) -> AIG:
    """An exactsat circuit ``(gates, outs)`` over ``k`` inputs as an AIG."""
    gates, outs = circuit
    g = AIG([f"v{i}" for i in range(k)])
    lits = [2 * (i + 1) for i in range(k)]
    for j, l, fj, fl, fo in gates:
        lits.append(g.and_(lits[j] ^ fj, lits[l] ^ fl) ^ fo)
    for h, (node, c) in enumerate(outs):
        g.add_output(f"t{h}", lits[node] ^ c)
    return g


def _build(spec, x: int, refs, sub: AIG | None, k: int) -> AIG:
    """The network of ``spec``: ``sub`` (inputs = the inputs other than ``x``, in
    order; output ``h`` realises target ``h`` on its care set) joined on ``x``."""
    n = len(spec.inputs)
    others = [i for i in range(n) if i != x]
    fk = T.mask(k)
    g = AIG(spec.inputs)
    outs: list[int] = []
    tabs: list[int] = []
    if sub is not None:
        m = [0] + [2 * (i + 1) for i in others]
        for a, b in sub.ands:
            m.append(g.and_(m[a >> 1] ^ (a & 1), m[b >> 1] ^ (b & 1)))
        outs = [m[lit >> 1] ^ (lit & 1) for lit in sub.output_lits]
        tabs = sub.truth_tables()

    def realise(r):
        """(literal, table over the k other inputs) of a cofactor reference."""
        if r[0] == "const":
            return r[1], fk if r[1] else 0
        if r[0] == "lit":
            return (2 * (others[r[1]] + 1)) ^ r[2], T.var(k, r[1]) ^ (fk if r[2] else 0)
        return outs[r[1]] ^ r[2], tabs[r[1]] ^ (fk if r[2] else 0)

    xl = 2 * (x + 1)
    for name, (r0, r1) in zip(spec.outputs, refs):
        (l0, t0), (l1, t1) = realise(r0), realise(r1)
        if t0 == t1:
            lit = l0
        elif t0 & ~t1 == 0:          # f0 <= f1: f0 | x & f1
            lit = g.or_(l0, g.and_(xl, l1))
        elif t1 & ~t0 == 0:          # f1 <= f0: f1 | !x & f0
            lit = g.or_(l1, g.and_(xl ^ 1, l0))
        else:
            lit = g.mux_(xl, l1, l0)
        g.add_output(name, lit)
    return g.cleanup()


def try_cofactor_exact(spec, best: AIG, time_limit: float, info: dict | None = None,
                       sat: bool = True) -> AIG | None:
    """The smallest network found this way if smaller than ``best``, else None.

    ``time_limit``: real seconds in all (each SAT call gets what is left).  With
    ``sat=False`` (-O2) only the deterministic part runs: the cofactors by the -O2
    flow, no SAT descent."""
    n = len(spec.inputs)
    if n != INPUTS or (sat and not exactsat.available()) or best.num_ands() <= 3:
        return None
    end = time.monotonic() + time_limit
    per_call = max(1.0, time_limit / (2 * n))
    on, dc = spec_tables(spec)
    k = n - 1
    seen = set()
    found = None
    for x in range(n):
        targets, refs = _split(n, on, dc, x)
        key = (tuple(targets), tuple(refs))
        if key in seen:
            continue
        seen.add(key)
        if not targets:
            g = _build(spec, x, refs, None, k)
            if g.num_ands() < (found or best).num_ands():
                found = g
            continue
        # the cofactors together as a table of k inputs, by the heuristic flow at -O2
        # (deterministic work clock); then the SAT descent below its size
        others = [spec.inputs[i] for i in range(n) if i != x]
        ts = TableSpec(others, [f"t{h}" for h in range(len(targets))],
                       [t for t, _ in targets], [T.mask(k) & ~c for _, c in targets],
                       spec.source)
        from mlc.logic import opt
        sub = opt.optimize(ts, 2)
        g = _build(spec, x, refs, sub, k)
        if g.num_ands() < (found or best).num_ands():
            found = g
        joins = sum(_join_bound(r0, r1, targets) for r0, r1 in refs)
        gates = min(sub.num_ands(), (found or best).num_ands() - joins) - 1
        while sat and gates >= len(targets):
            left = end - time.monotonic()
            if left < 0.05:
                break
            # SAT times are erratic (a smaller k is often solved faster): a call that
            # times out moves on to k - 1; UNSAT ends the descent
            r = exactsat.synthesize_exact(k, targets, gates, time_limit=min(left, per_call))
            if r is None:
                break
            if r != "timeout":
                g = _build(spec, x, refs, _circuit_aig(k, r), k)
                if g.num_ands() < (found or best).num_ands():
                    found = g
            gates -= 1
    if info is not None:
        info["cofactor_exact"] = found is not None
    return found
