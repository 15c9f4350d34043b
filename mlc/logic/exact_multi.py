"""Exact multi-output resynthesis of small functions by SAT (effort 3 only).

Starting from the best heuristic network with ``k`` ANDs, ask the SAT solver for a
``k-1`` circuit, then ``k-2`` ..., each call under a time limit, and keep the last
success.  When an UNSAT answer stops the descent, the result is a proven minimum.
"""
from __future__ import annotations


from mlc.logic import exactsat
from mlc.logic import tt as T
from mlc.logic.aig import AIG
from mlc.logic import work
from mlc.logic.equiv import spec_tables

MAX_INPUTS = 5


def try_exact(spec, best: AIG, deadline: float, info: dict | None = None) -> AIG | None:
    n = len(spec.inputs)
    if n > MAX_INPUTS or not exactsat.available() or best.num_ands() <= 1:
        return None
    full = T.mask(n)
    on, dc = spec_tables(spec)
    # outputs that are constants or literals need no gate
    fixed: dict[int, int] = {}
    targets: list[tuple[int, int]] = []
    tmap: dict[int, int] = {}
    for o, (f, d) in enumerate(zip(on, dc)):
        care = full & ~d
        f &= care
        if f == 0:
            fixed[o] = 0
            continue
        if f == care:
            fixed[o] = 1
            continue
        hit = None
        for i in range(n):
            v = T.var(n, i) & care
            if v == f:
                hit = 2 * (i + 1)
            elif (~T.var(n, i)) & care == f:
                hit = 2 * (i + 1) + 1
        if hit is not None:
            fixed[o] = hit
            continue
        # same function as an earlier target (either phase, on common cares)?
        for t, (g, c) in enumerate(targets):
            if c == care and (g == f or g == care & ~f):
                tmap[o] = t
                break
        else:
            tmap[o] = len(targets)
            targets.append((f, care))
    if not targets:
        return None
    k = best.num_ands() - 1
    found = None
    proven = False
    while k >= len(targets):
        left = deadline - work.now()
        if left < 0.05:
            break
        r = exactsat.synthesize_exact(n, targets, k, time_limit=left)
        if r == "timeout":
            break
        if r is None:
            proven = True
            break
        found = r
        k -= 1
    if info is not None:
        info["exact_proven"] = proven
    if found is None:
        return None
    gates, outs = found
    g = AIG(spec.inputs)
    lits = [2 * (i + 1) for i in range(n)]
    for j, l, fj, fl, fo in gates:
        lits.append(g.and_(lits[j] ^ fj, lits[l] ^ fl) ^ fo)
    for o, name in enumerate(spec.outputs):
        if o in fixed:
            g.add_output(name, fixed[o])
        else:
            t = tmap[o]
            node, c = outs[t]
            lit = lits[node] ^ c
            # the target may be shared with the complement phase
            f, care = targets[t]
            want = on[o] & care
            if want != f:
                lit ^= 1
            g.add_output(name, lit)
    return g.cleanup()
