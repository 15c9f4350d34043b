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


def _encode(n: int, targets: list[tuple[int, int]], k: int):
    """CNF for: ``k`` gates over ``n`` inputs realise every (on, care) target."""
    V = _Vars()
    clauses: list[list[int]] = []
    T = range(1, 1 << n)
    N = n + k
    # x[i][t] for gates i in n..N-1; inputs are constants
    x = {i: {t: V.new() for t in T} for i in range(n, N)}
    sel = {}
    for i in range(n, N):
        sel[i] = {}
        for j in range(i):
            for l in range(j + 1, i):
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
    # consecutive gates not using each other are ordered by their fanin pair
    for i in range(n, N - 1):
        i2 = i + 1
        for (j, l), s in sel[i].items():
            for (j2, l2), s2 in sel[i2].items():
                if i in (j2, l2):
                    continue
                if (l2, j2) < (l, j):
                    clauses.append([-s, -s2])
    return V, clauses, x, sel, op, outsel


def synthesize_exact(n: int, targets: list[tuple[int, int]], k: int, time_limit: float | None = None,
                     solver: str = "minisat22"):
    """A k-gate circuit for ``targets`` or None (UNSAT) or "timeout".

    Returns ``(gates, outs)``: ``gates[g] = (j, l, fj, fl, fo)`` meaning node ``n+g`` is
    ``((node_j ^ fj) & (node_l ^ fl)) ^ fo``; ``outs[h] = (node, complement)``.
    """
    from pysat.solvers import Solver

    V, clauses, x, sel, op, outsel = _encode(n, targets, k)
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
