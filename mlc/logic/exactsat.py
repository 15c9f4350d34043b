"""SAT-based exact synthesis of minimum-AND multi-output AIGs (inversions free).

Used at -O3 (:mod:`mlc.logic.exact_multi`), to generate the shipped NPN table
(:mod:`mlc.logic.gen_npn_table`), by the benchmark (proven minima) and by the tests.
``python-sat`` is imported lazily (:func:`available`).

Encoding (after Kojevnikov, Kulikov and Yaroslavtsev; Knuth TAOCP 7.1.2): ``k`` gates,
each a *normal* AND-class two-input operator (value 0 on (0,0): a&b, a&!b, !a&b, a|b),
so every node is 0 on minterm 0 and only minterms ``1 .. 2**n - 1`` are simulated;
each output picks a gate and a free complement.  Don't cares are minterms that are
simply not constrained.
"""
from __future__ import annotations

import itertools


def available() -> bool:
    try:
        import pysat.solvers  # noqa: F401
    except ImportError:
        return False
    return True


class _Vars:
    def __init__(self):
        self.n = 0

    def new(self) -> int:
        self.n += 1
        return self.n


def _encode(n: int, targets: list[tuple[int, int]], k: int, fence: tuple[int, ...] | None = None,
            symmetric: list[list[int]] | None = None):
    """CNF for: ``k`` gates over ``n`` inputs realise every (on, care) target.

    ``fence`` (optional, Haaswijk et al.'s topology families) fixes how many gates sit
    on each logic level 1, 2, ...: a gate on level L takes one fanin from level L-1
    and the other from any lower level (inputs are level 0).  Every circuit has
    exactly one fence (its gates' longest-path levels, gates sorted by level), so
    the fences of ``k`` gates partition the search: a circuit exists iff one
    fence's instance is satisfiable.

    ``symmetric`` (optional): groups of inputs that the targets' symmetries permute
    arbitrarily (:func:`symmetric_inputs`).  Relabelling a circuit's inputs by such a
    symmetry gives another solution with the same gates in the same order, so
    within a group the inputs may be required to have non-increasing fanout counts
    (a property of the circuit's graph, independent of the gate order, hence
    compatible with the ordering constraints below)."""
    V = _Vars()
    clauses: list[list[int]] = []
    T = range(1, 1 << n)
    N = n + k
    # x[i][t] for gates i in n..N-1; inputs are constants
    x = {i: {t: V.new() for t in T} for i in range(n, N)}
    level = [0] * n
    if fence is not None:
        if sum(fence) != k:
            raise ValueError(f"fence {fence} does not have {k} gates")
        for lv, cnt in enumerate(fence, 1):
            level += [lv] * cnt
    sel = {}
    for i in range(n, N):
        sel[i] = {}
        for j in range(i):
            for l in range(j + 1, i):
                if fence is None or level[l] == level[i] - 1:
                    sel[i][(j, l)] = V.new()
    op = {i: (V.new(), V.new(), V.new()) for i in range(n, N)}   # values at (0,1),(1,0),(1,1)

    def val(node, t):
        """(literal or None, constant) of node at minterm t."""
        if node < n:
            return None, (t >> node) & 1
        return x[node][t], None

    for i in range(n, N):
        o01, o10, o11 = op[i]
        # operator in {0001, 0010, 0100, 0111} = odd parity of the three bits
        for a, b, c in itertools.product((0, 1), repeat=3):
            if (a ^ b ^ c) == 0:
                clauses.append([(-o01 if a else o01), (-o10 if b else o10), (-o11 if c else o11)])
        clauses.append(list(sel[i].values()))
        for (j, l), s in sel[i].items():
            for t in T:
                for b in (0, 1):
                    lj, cj = val(j, t)
                    if lj is None and cj != b:
                        continue
                    for c in (0, 1):
                        ll, cl = val(l, t)
                        if ll is None and cl != c:
                            continue
                        base = [-s]
                        if lj is not None:
                            base.append(-lj if b else lj)
                        if ll is not None:
                            base.append(-ll if c else ll)
                        xi = x[i][t]
                        if (b, c) == (0, 0):
                            clauses.append(base + [-xi])
                            continue
                        o = {(0, 1): o01, (1, 0): o10, (1, 1): o11}[(b, c)]
                        clauses.append(base + [-o, xi])
                        clauses.append(base + [o, -xi])
    # outputs
    outsel = []
    for h, (on, care) in enumerate(targets):
        cv = V.new()      # output complement
        if care & 1:
            clauses.append([cv] if on & 1 else [-cv])
        os_ = {i: V.new() for i in range(n, N)}
        outsel.append((cv, os_))
        clauses.append(list(os_.values()))
        for i, ov in os_.items():
            for t in T:
                if not (care >> t) & 1:
                    continue
                xi = x[i][t]
                if (on >> t) & 1:
                    clauses.append([-ov, xi, cv])
                    clauses.append([-ov, -xi, -cv])
                else:
                    clauses.append([-ov, -xi, cv])
                    clauses.append([-ov, xi, -cv])
    # symmetry breaking: every gate is used by a later gate or an output
    for i in range(n, N):
        users = [s for i2 in range(i + 1, N) for (j, l), s in sel[i2].items() if i in (j, l)]
        users += [os_[i] for _, os_ in outsel]
        clauses.append(users)
    # inputs of one symmetric group
    suffix_group = (fence is not None and symmetric is not None and len(symmetric) == 1
                    and symmetric[0] == list(range(n - len(symmetric[0]), n)))
    for group in symmetric or []:
        if suffix_group:
            # the last inputs are interchangeable and level-1 gates are sorted by fanin
            # pair: they can be labelled in the order level-1 gates first use them
            # (docs/synthesis.md)
            lvl1 = [i for i in range(n, N) if level[i] == 1]
            use = {p: [[v for (j, l), v in sel[i].items() if p in (j, l)] for i in lvl1]
                   for p in group}
            for p, q in zip(group, group[1:]):
                for a in range(len(lvl1)):
                    for v in use[q][a]:
                        clauses.append([-v] + [w for b in range(a + 1) for w in use[p][b]])
            continue
        # otherwise: fanout counts non-increasing in input order
        cnt = {}
        for p in group:
            uses = [V.new() for _ in range(n, N)]
            for u, i in zip(uses, range(n, N)):
                lits = [v for (j, l), v in sel[i].items() if p in (j, l)]
                clauses.append([-u] + lits)
                clauses += [[u, -v] for v in lits]
            cnt[p] = _unary_count(V, clauses, uses)
        for p, q in zip(group, group[1:]):
            for t in range(len(cnt[p])):
                clauses.append([-cnt[q][t], cnt[p][t]])      # count(q) >= t+1 -> count(p) >= t+1
    # consecutive gates not using each other are ordered by their fanin pair (with a
    # fence: only within a level, since swapping across levels leaves the fence)
    for i in range(n, N - 1):
        i2 = i + 1
        if level[i] != level[i2] if fence is not None else False:
            continue
        for (j, l), s in sel[i].items():
            for (j2, l2), s2 in sel[i2].items():
                if i in (j2, l2):
                    continue
                if (l2, j2) < (l, j):
                    clauses.append([-s, -s2])
    return V, clauses, x, sel, op, outsel


def _unary_count(V: _Vars, clauses: list, lits: list[int]) -> list[int]:
    """Variables ``c[t]`` <-> "at least t+1 of ``lits`` are true" (sequential counter,
    both directions), t = 0 .. len(lits)-1."""
    prev: list[int] = []
    for x in lits:
        cur = []
        for t in range(len(prev) + 1):
            c = V.new()
            a = prev[t] if t < len(prev) else None        # at least t+1 before x
            b = prev[t - 1] if t >= 1 else True           # at least t before x
            # c <-> a | (b & x)
            if a is not None:
                clauses.append([c, -a])
            if b is True:
                clauses.append([c, -x])
                clauses.append([-c, x] + ([a] if a is not None else []))
            else:
                clauses.append([c, -b, -x])
                clauses.append([-c, b] + ([a] if a is not None else []))
                clauses.append([-c, x] + ([a] if a is not None else []))
            cur.append(c)
        prev = cur
    return prev


def symmetric_inputs(n: int, f: int) -> list[list[int]]:
    """Groups of inputs of the completely specified ``f`` that its symmetries permute
    arbitrarily: inputs p, q are linked when swapping them (with any input negations,
    and possibly complementing the output) maps ``f`` to itself; the connected
    components of those transpositions generate every permutation of a component."""
    from mlc.logic import tt as T
    full = T.mask(n)
    parent = list(range(n))

    def find(a):
        while parent[a] != a:
            a = parent[a]
        return a

    for p in range(n):
        for q in range(p + 1, n):
            perm = list(range(n))
            perm[p], perm[q] = q, p
            for neg in range(1 << n):
                g = 0
                for m in range(1 << n):
                    y = 0
                    for i in range(n):
                        y |= (((m >> perm[i]) & 1) ^ ((neg >> i) & 1)) << i
                    g |= ((f >> y) & 1) << m
                if g in (f, f ^ full):
                    parent[find(q)] = find(p)
                    break
    groups: dict[int, list[int]] = {}
    for i in range(n):
        groups.setdefault(find(i), []).append(i)
    return [g for g in groups.values() if len(g) > 1]


def synthesize_exact(n: int, targets: list[tuple[int, int]], k: int, time_limit: float | None = None,
                     solver: str = "minisat22", fence: tuple[int, ...] | None = None,
                     symmetry: bool | list[list[int]] = False):
    """A k-gate circuit for ``targets`` or None (UNSAT) or "timeout".

    ``symmetry``: True breaks the input symmetries of one completely specified
    target (:func:`symmetric_inputs`); a list gives the groups of interchangeable
    inputs to break (any subset of the true ones is sound).

    Returns ``(gates, outs)``: ``gates[g] = (j, l, fj, fl, fo)`` meaning node ``n+g`` is
    ``((node_j ^ fj) & (node_l ^ fl)) ^ fo``; ``outs[h] = (node, complement)``.
    """
    from pysat.solvers import Solver

    if time_limit is not None and not solver.startswith(("minisat", "glucose", "maple")):
        # CaDiCaL and Kissat cannot be interrupted through python-sat: run in a child
        return _in_child(n, targets, k, time_limit, solver, fence, symmetry)
    sym = None
    if isinstance(symmetry, list):
        sym = symmetry
    elif symmetry and len(targets) == 1 and targets[0][1] == (1 << (1 << n)) - 1:
        sym = symmetric_inputs(n, targets[0][0])
    V, clauses, x, sel, op, outsel = _encode(n, targets, k, fence, sym)
    with Solver(name=solver, bootstrap_with=clauses) as s:
        if time_limit is None:
            ok = s.solve()
        else:
            import threading
            timer = threading.Timer(time_limit, s.interrupt)
            timer.start()
            try:
                ok = s.solve_limited(expect_interrupt=True)
            finally:
                timer.cancel()
            if ok is None:
                return "timeout"
        if not ok:
            return None
        model = set(v for v in s.get_model() if v > 0)
    gates = []
    for i in range(n, n + k):
        j, l = next(p for p, v in sel[i].items() if v in model)
        o01, o10, o11 = (v in model for v in op[i])
        # normal operator -> AND form
        code = (o01, o10, o11)
        if code == (False, False, True):
            g = (j, l, 0, 0, 0)
        elif code == (False, True, False):      # a & !b  (a = node j)
            g = (j, l, 0, 1, 0)
        elif code == (True, False, False):      # !a & b
            g = (j, l, 1, 0, 0)
        else:                                   # a | b = !(!a & !b)
            g = (j, l, 1, 1, 1)
        gates.append(g)
    outs = []
    for cv, os_ in outsel:
        i = next(i for i, v in os_.items() if v in model)
        outs.append((i, int(cv in model)))
    return gates, outs


def _child(conn, n, targets, k, solver, fence, symmetry):
    conn.send(synthesize_exact(n, targets, k, None, solver, fence, symmetry))
    conn.close()


def _in_child(n, targets, k, time_limit, solver, fence=None, symmetry=False):
    """:func:`synthesize_exact` in a forked process, killed after ``time_limit`` s."""
    import multiprocessing as mp
    ctx = mp.get_context("fork")
    recv, send = ctx.Pipe(duplex=False)
    p = ctx.Process(target=_child, args=(send, n, targets, k, solver, fence, symmetry), daemon=True)
    p.start()
    send.close()
    try:
        if recv.poll(time_limit):
            return recv.recv()
        return "timeout"
    finally:
        if p.is_alive():
            p.kill()
        p.join()
        recv.close()


def fences(k: int, outputs: int = 1):
    """Every fence of ``k`` gates that a circuit with ``outputs`` outputs, all gates
    used, can have: the top level holds at most ``outputs`` gates (all outputs), and
    every other level at most twice as many gates as all higher levels together plus
    the outputs not on the top level (each gate has a user above it or is an output,
    and a user takes two fanins)."""
    res = []

    def rec(rest: int, acc: list[int]):
        if rest == 0:
            if acc and acc[-1] <= outputs:
                res.append(tuple(acc))
            return
        for c in range(1, rest + 1):
            rec(rest - c, acc + [c])

    rec(k, [])
    ok = []
    for f in res:
        spare = outputs - f[-1]          # outputs that may sit below the top level
        above = f[-1]
        good = True
        for lv in range(len(f) - 2, -1, -1):
            if f[lv] > 2 * above + spare:
                good = False
                break
            above += f[lv]
        if good:
            ok.append(f)
    return ok


def suffix_symmetric(n: int, f: int) -> bool:
    """Does ``f`` have a single group of interchangeable inputs, the last ones?"""
    g = symmetric_inputs(n, f)
    return len(g) == 1 and g[0] == list(range(n - len(g[0]), n))


def synthesize_exact_fenced(n: int, targets: list[tuple[int, int]], k: int,
                            time_limit: float | None = None, solver: str = "cadical195",
                            symmetry: bool | list[list[int]] = True):
    """:func:`synthesize_exact` one fence at a time (the fences partition the search):
    a circuit, None (every fence unsatisfiable) or "timeout" (``time_limit`` seconds
    in all).  When the target's interchangeable inputs are the last ones
    (:func:`suffix_symmetric`), fences allow the stronger first-use symmetry breaking
    (see :func:`_encode`)."""
    import time
    deadline = None if time_limit is None else time.monotonic() + time_limit
    for f in fences(k, len(targets)):
        left = None if deadline is None else deadline - time.monotonic()
        if left is not None and left <= 0:
            return "timeout"
        r = synthesize_exact(n, targets, k, left, solver, f, symmetry)
        if r is not None:
            return r
    return None


def minimum_circuit(n: int, targets: list[tuple[int, int]], upper: int | None = None,
                    time_limit: float | None = None, start: int = 1):
    """Smallest circuit by increasing k.  Returns ``(k, circuit, proven)``.

    Targets that are constants or (complemented) inputs must be removed by the caller.
    With a ``time_limit`` per SAT call, a timeout at k stops the search: ``proven`` is
    False and the circuit (if any) is the ``upper`` one supplied by the caller (None).
    """
    k = start
    while upper is None or k < upper:
        r = synthesize_exact(n, targets, k, time_limit)
        if r == "timeout":
            return None, None, False
        if r is not None:
            return k, r, True
        k += 1
    return None, None, True


def circuit_tables(n: int, gates, outs) -> list[int]:
    full = (1 << (1 << n)) - 1
    from mlc.logic import tt as T
    vals = [T.var(n, i) for i in range(n)]
    for j, l, fj, fl, fo in gates:
        a = vals[j] ^ (full if fj else 0)
        b = vals[l] ^ (full if fl else 0)
        vals.append((a & b) ^ (full if fo else 0))
    return [vals[i] ^ (full if c else 0) for i, c in outs]
