"""A small reduced ordered BDD package (no complement edges), for equivalence checks
of networks too wide for exhaustive simulation."""
from __future__ import annotations

from mlc.errors import MlcError


class BDD:
    """Nodes are ints: 0 and 1 are the terminals; others index ``self.nodes``."""

    def __init__(self, nvars: int, max_nodes: int = 1_000_000):
        self.nvars = nvars
        self.nodes: list[tuple[int, int, int]] = [(nvars, 0, 0), (nvars, 1, 1)]
        self.unique: dict[tuple[int, int, int], int] = {}
        self.cache: dict[tuple, int] = {}
        self.max_nodes = max_nodes

    def mk(self, v: int, lo: int, hi: int) -> int:
        if lo == hi:
            return lo
        key = (v, lo, hi)
        r = self.unique.get(key)
        if r is None:
            r = len(self.nodes)
            if r >= self.max_nodes:
                raise MlcError(f"BDD exceeds {self.max_nodes} nodes during the equivalence check",
                               fix="the function is too large to prove equivalent (SAT sweeping and BDD both exceeded their limits)")
            self.nodes.append(key)
            self.unique[key] = r
        return r

    def var(self, i: int) -> int:
        return self.mk(i, 0, 1)

    def ite(self, f: int, g: int, h: int) -> int:
        if f == 1:
            return g
        if f == 0:
            return h
        if g == h:
            return g
        if g == 1 and h == 0:
            return f
        key = (f, g, h)
        r = self.cache.get(key)
        if r is not None:
            return r
        nodes = self.nodes
        v = min(nodes[f][0], nodes[g][0], nodes[h][0])

        def co(x, b):
            nv, lo, hi = nodes[x]
            if nv != v:
                return x
            return hi if b else lo

        lo = self.ite(co(f, 0), co(g, 0), co(h, 0))
        hi = self.ite(co(f, 1), co(g, 1), co(h, 1))
        r = self.mk(v, lo, hi)
        self.cache[key] = r
        return r

    # algebra interface (see mlc.logic.netsim)
    def const(self, b):
        return 1 if b else 0

    def inp(self, i):
        return self.var(i)

    def not_(self, x):
        return self.ite(x, 0, 1)

    def and_(self, x, y):
        return self.ite(x, y, 0)

    def or_(self, x, y):
        return self.ite(x, 1, y)

    def xor_(self, x, y):
        return self.ite(x, self.not_(y), y)

    def mux_(self, s, t, e):
        return self.ite(s, t, e)

    def from_table(self, t: int, n: int) -> int:
        """BDD of a truth table over the first ``n`` variables."""
        memo: dict[tuple[int, int], int] = {}

        def rec(t: int, v: int) -> int:
            # t is a table over variables 0..v-1 (2**v bits)
            if v == 0:
                return t & 1
            full = (1 << (1 << v)) - 1
            if t == 0:
                return 0
            if t == full:
                return 1
            key = (t, v)
            r = memo.get(key)
            if r is not None:
                return r
            half = 1 << (v - 1)
            lo = rec(t & ((1 << half) - 1), v - 1)
            hi = rec(t >> half, v - 1)
            r = self.mk(v - 1, lo, hi) if lo != hi else lo
            memo[key] = r
            return r

        # variable ordering of this package: smaller index nearer the root; tables put
        # the highest variable in the most significant half, so build bottom-up by
        # mapping level (v-1) -> variable (v-1) and then reorder via ite.
        return self._reorder(rec(t, n), n)

    def _reorder(self, f: int, n: int) -> int:
        # rec() built a diagram whose nodes test variable v-1 above v-2 ...: the order is
        # reversed w.r.t. the package; rebuild it with ite on properly ordered variables.
        memo: dict[int, int] = {}

        def rb(x: int) -> int:
            if x < 2:
                return x
            r = memo.get(x)
            if r is not None:
                return r
            v, lo, hi = self.nodes[x]
            r = self.ite(self.var(v), rb(hi), rb(lo))
            memo[x] = r
            return r

        return rb(f)

    def sat_one(self, f: int) -> dict[int, int] | None:
        """One satisfying assignment of ``f`` (variable -> value), or None."""
        if f == 0:
            return None
        a: dict[int, int] = {}
        while f != 1:
            v, lo, hi = self.nodes[f]
            if lo != 0:
                a[v] = 0
                f = lo
            else:
                a[v] = 1
                f = hi
        return a
