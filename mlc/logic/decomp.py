"""Truth-table decomposition: a strong starting AIG for (incompletely specified) tables.

For each output, recursively:

1. drop the variables the interval ``[on, on | dc]`` need not depend on;
2. at most four variables left: the exact minimum circuit from the NPN table, trying
   the fillings of the don't cares (all of them when there are few);
3. otherwise a *disjoint-support* step where one exists: ``f = x & g``, ``x | g``,
   ``x ^ g`` (with any polarities), recursing on ``g``;
4. otherwise the cheaper of a factored irredundant SOP (either phase) and a Shannon
   expansion ``x ? f1 : f0`` on the most promising variables.

Sub-results are memoised by (function, care set), so equal cofactors are shared.
"""
from __future__ import annotations

import sys

from mlc.spec import TableSpec
from mlc.logic import npn
from mlc.logic import tt as T
from mlc.logic.aig import AIG
from mlc.logic.lower import factor_sop


# Caches of the pure steps (their results depend only on the arguments and the
# number of variables), shared by all decompositions: refactoring meets the same cone
# functions again in every round.  Cleared when they grow past _CACHE_MAX entries.
_CACHE_MAX = 200_000
_support_cache: dict = {}
_sop_cache: dict = {}
_exact_cache: dict = {}
# _Dec._rec's analysis of an interval (see _Dec._analyse), by (n, effort, f, care):
# everything _rec works out before it looks at the plans already built or recurses
_analysis_cache: dict = {}
# False: _Dec._rec analyses every interval afresh (the plain path, kept for the tests)
ANALYSIS_MEMO = True

# the constant plans (one object each, as _rec's constants always were: build's
# self._key is keyed by a plan's id)
_CONST0 = ("const", 0)
_CONST1 = ("const", 1)


def _kernels(n: int):
    """:mod:`mlc.logic.kern` where its kernels serve a decomposition over ``n``
    variables: numba already running in the process (``kern.READY``), kernels not
    switched off (``opt.KERNELS``) and ``n <= kern.SOP_MAX_VARS``; else None."""
    kern = sys.modules.get("mlc.logic.kern")
    if kern is None or not kern.READY or n > kern.SOP_MAX_VARS:
        return None
    opt = sys.modules.get("mlc.logic.opt")
    if opt is not None and not opt.KERNELS:
        return None
    return kern


def _cache_put(cache: dict, key, value) -> None:
    if len(cache) >= _CACHE_MAX:
        cache.clear()
    cache[key] = value


def _cofactors(f: int, care: int, s: int, vi: int, ni: int, full: int):
    """The cofactors of the interval (on-set ``f``, care set ``care``, off-set
    ``care & ~f``) with respect to variable ``i`` (``s = 1 << i``, ``vi``/``ni`` its
    positive and negative tables, ``full`` the all-ones table), each spread over both
    halves: (on0, on1, of0, of1, c0, c1).  Spreading acts bit by bit, so the off-set's
    cofactors are ``c & ~on``; a full care set (refactoring's cones and all their
    cofactors) has full cofactors."""
    t = f & ni
    on0 = t | (t << s)
    t = f & vi
    on1 = t | (t >> s)
    if care == full:
        return on0, on1, full ^ on0, full ^ on1, full, full
    t = care & ni
    c0 = t | (t << s)
    t = care & vi
    c1 = t | (t >> s)
    return on0, on1, c0 & ~on0, c1 & ~on1, c0, c1


def _no_step(f: int, s: int, vi: int, ni: int) -> bool:
    """For a completely specified ``f``: no one-variable step (``x & g``, ``x | g``,
    ``x ^ g`` in any polarity) exists on variable ``i`` (``s``, ``vi``, ``ni`` as in
    :func:`_cofactors`).  Tested on the halves without spreading them: a cofactor is 0
    or all ones where its half is, and the cofactors are complements where the
    positive half is the negative half, moved up, complemented."""
    t0 = f & ni
    t1 = f & vi
    return t0 and t1 and t0 != ni and t1 != vi and (t0 << s) != vi ^ t1


class _Dec:
    def __init__(self, n: int, effort: int, rng=None):
        self.rng = rng
        self.n = n
        self.full = T.mask(n)
        self.effort = effort
        self.memo: dict[tuple[int, int], tuple[int, object]] = {}
        self.vars = [T.var(n, i) for i in range(n)]
        self.shannon_limit = {1: 6, 2: 9, 3: 11}.get(effort, 6)
        # functions already built (by earlier outputs): (f, care) -> plan; reusing one
        # costs nothing, so a step whose remainder is available is preferred
        self.avail: dict[tuple[int, int], object] = {}
        self._key: dict[int, tuple[int, int]] = {}

    # -------------------------------------------------------------- analysis
    def reduce_support(self, f: int, care: int) -> tuple[int, int, list[int]]:
        n = self.n
        key = (n, f, care)
        r = _support_cache.get(key)
        if r is not None:
            return r[0], r[1], list(r[2])
        pos, neg = T.var_tables(n)
        if care == self.full:
            # completely specified (refactoring's cones, their cofactors): a variable
            # can be dropped only where f does not depend on it
            sup = [i for i in range(n) if ((f & pos[i]) >> (1 << i)) != (f & neg[i])]
            _cache_put(_support_cache, key, (f, care, tuple(sup)))
            return f, care, sup
        sup = []
        for i in range(n):
            s = 1 << i
            vi, ni = pos[i], neg[i]
            if ((f & vi) >> s) == (f & ni) and ((care & vi) >> s) == (care & ni):
                continue                      # depends on neither
            on0, on1, of0, of1, c0, c1 = _cofactors(f, care, s, vi, ni, self.full)
            if on0 & of1 == 0 and on1 & of0 == 0:
                # need not depend on i: merge the cofactors
                f = on0 | on1
                care = c0 | c1
            else:
                sup.append(i)
        r = (f & care, care, tuple(sup))
        _cache_put(_support_cache, key, r)
        return r[0], r[1], sup

    # -------------------------------------------------------------- main recursion
    def rec(self, f: int, care: int) -> tuple[int, object]:
        """(estimated ANDs, plan) for the interval (f on care)."""
        f &= care
        key = (f, care)
        r = self.memo.get(key)
        if r is not None:
            return r
        r = self._rec(f, care)
        self.memo[key] = r
        self._key[id(r[1])] = key
        return r

    def shared_step(self, f: int, care: int, sup: list[int]):
        """A one-step decomposition ``x op g`` whose remainder ``g`` (or its
        complement) an earlier output has already built: (cost, plan) or None."""
        if not self.avail:
            return None
        best = None
        for cost, kind, lit, g, gc in self._steps(f, care, sup):
            p = self._find_avail(g, gc)
            if p is not None and (best is None or cost < best[0]):
                best = (cost, (kind, lit, p))
        return best

    def _find_avail(self, g: int, gc: int):
        """A built plan computing ``g`` on the care set ``gc``, or its complement
        (as a ("not", plan)); exact care match only."""
        p = self.avail.get((g, gc))
        if p is not None:
            return p
        p = self.avail.get((gc & ~g, gc))
        if p is not None:
            return ("not", p)
        return None

    def _rec(self, f: int, care: int):
        if self.rng is not None or not ANALYSIS_MEMO:
            return self._rec_plain(f, care)
        key = (self.n, self.effort, f, care)
        a = _analysis_cache.get(key)
        if a is None:
            a = self._analyse(f, care)
            _cache_put(_analysis_cache, key, a)
        tag = a[0]
        if tag == 0:
            return 0, _CONST0
        if tag == 1:
            return 0, _CONST1
        if tag == 2:
            return 0, ("lit", a[1])
        _, nsup, steps, base, shannon = a
        sh = None
        if steps and self.avail:                 # shared_step
            find = self._find_avail
            for cost, kind, lit, g, gc in steps:
                p = find(g, gc)
                if p is not None and (sh is None or cost < sh[0]):
                    sh = (cost, (kind, lit, p))
        if nsup <= 4:
            ex = (base[0], (base[1][0], base[1][1], base[1][2]))
            return sh if sh is not None and sh[0] < ex[0] else ex
        if sh is not None:
            return sh
        if steps:                                # the first disjoint-support step
            cost, kind, lit, g, gc = steps[0]
            c, p = self.rec(g, gc)
            return c + cost, (kind, lit, p)
        return self._mux_best((base[0], (base[1][0], base[1][1], base[1][2])), shannon)

    def _mux_best(self, best, cands):
        """The cheaper of ``best`` (cost, plan) and a 2:1 mux on each Shannon candidate
        ``(i, on0, on1, c0, c1)`` in turn (cofactors built by :meth:`rec`, on1 first)."""
        for i, on0, on1, c0, c1 in cands:
            ca, pa = self.rec(on1, c1)
            cb, pb = self.rec(on0, c0)
            c = ca + cb + 3
            if c < best[0]:
                best = (c, ("mux", 2 * (i + 1), pa, pb))
        return best

    def _analyse(self, f: int, care: int):
        """What :meth:`_rec_plain` works out for the interval (``f`` on ``care``)
        before it looks at ``self.avail`` or recurses; it depends only on the
        interval, ``n`` and the effort (not on a random Shannon choice).  One of
        (0,) constant 0, (1,) constant 1, (2, lit) a literal, or
        (3, |support|, steps, base, shannon): ``steps`` the one-variable steps
        (cost, kind, literal, g, g's care) in shared_step's order (the first is the
        disjoint-support step), ``base`` the exact plan (support <= 4) or the
        factored SOP's (cost, plan), ``shannon`` the (i, on0, on1, c0, c1) that the
        Shannon expansion tries, in order."""
        full = self.full
        if f == 0:
            return (0,)
        if (f | ~care) & full == full:
            return (1,)
        if care == full:
            kern = _kernels(self.n)
            if kern is not None:
                return self._analyse_full_nb(f, kern)
        f, care, sup = self.reduce_support(f, care)
        for i in sup:
            v = self.vars[i] & care
            if v == f:
                return (2, 2 * (i + 1))
            if (~self.vars[i]) & care == f:
                return (2, 2 * (i + 1) + 1)
        steps = tuple(self._steps(f, care, sup))
        if len(sup) <= 4:
            return (3, len(sup), steps, self.exact(f, care, sup), ())
        if steps:
            return (3, len(sup), steps, None, ())
        base = self.sop_plan(f, care)
        shannon = ()
        if len(sup) <= self.shannon_limit:
            shannon = tuple(t[1:] for t in self._shannon_scored(f, care, sup))
        return (3, len(sup), steps, base, shannon)

    def _analyse_full_nb(self, f: int, kern):
        """:meth:`_analyse` of a completely specified, non-constant ``f``, its table
        work (support, steps, Shannon scores, the table over a support of at most 4)
        done by :func:`mlc.logic.kern.analyse_full`."""
        n, full = self.n, self.full
        dep, stepbits, score, t16 = kern.analyse_full(f, n)
        sup = [i for i in range(n) if dep[i]]
        if len(sup) == 1:               # a completely specified function of one variable
            i = sup[0]
            return (2, 2 * (i + 1) + (f != self.vars[i]))
        pos, neg = T.var_tables(n)
        steps = []
        for i in sup:
            b = int(stepbits[i])
            if not b:
                continue
            s = 1 << i
            t = f & neg[i]
            on0 = t | (t << s)
            t = f & pos[i]
            on1 = t | (t >> s)
            x = 2 * (i + 1)
            if b & 1:
                steps.append((1, "and", x, on1, full))
            if b & 2:
                steps.append((1, "and", x ^ 1, on0, full))
            if b & 4:
                steps.append((1, "or", x, on0, full))
            if b & 8:
                steps.append((1, "or", x ^ 1, on1, full))
            if b & 16:
                steps.append((3, "xor", x, on0, full))
        steps = tuple(steps)
        if len(sup) <= 4:
            t16 = int(t16)
            return (3, len(sup), steps, (npn.cost4(t16), ("exact", t16, tuple(sup))), ())
        if steps:
            return (3, len(sup), steps, None, ())
        base = self.sop_plan(f, full)
        shannon = ()
        if len(sup) <= self.shannon_limit:
            width = (len(sup) if len(sup) <= 6 else 2) if self.effort >= 2 else 1
            sh = []
            for _, i in sorted((int(score[i]), i) for i in sup)[:width]:
                s = 1 << i
                t = f & neg[i]
                on0 = t | (t << s)
                t = f & pos[i]
                on1 = t | (t >> s)
                sh.append((i, on0, on1, full, full))
            shannon = tuple(sh)
        return (3, len(sup), steps, base, shannon)

    def _steps(self, f: int, care: int, sup: list[int]):
        """The one-variable steps ``x op g`` of the interval, as shared_step tries
        them: (cost, kind, literal of x, g & g's care, g's care)."""
        pos, neg = T.var_tables(self.n)
        whole = care == self.full
        for i in sup:
            if whole and _no_step(f, 1 << i, pos[i], neg[i]):
                continue
            on0, on1, of0, of1, c0, c1 = _cofactors(f, care, 1 << i, pos[i], neg[i], self.full)
            x = 2 * (i + 1)
            if on0 == 0:
                yield 1, "and", x, on1 & c1, c1
            if on1 == 0:
                yield 1, "and", x ^ 1, on0 & c0, c0
            if of1 == 0:
                yield 1, "or", x, on0 & c0, c0
            if of0 == 0:
                yield 1, "or", x ^ 1, on1 & c1, c1
            if on0 & on1 == 0 and of0 & of1 == 0:
                gc = c0 | c1
                yield 3, "xor", x, (on0 | of1) & gc, gc

    def _shannon_scored(self, f: int, care: int, sup: list[int]):
        """The Shannon candidates (score, i, on0, on1, c0, c1), best first, that
        _rec tries: at most ``width`` of them; with ``self.rng``, each variable's
        score gets a noise in [0, 3) (one draw a variable, in support order)."""
        pos, neg = T.var_tables(self.n)
        scored = []
        for i in sup:
            on0, on1, _, _, c0, c1 = _cofactors(f, care, 1 << i, pos[i], neg[i], self.full)
            s0 = len(self.reduce_support(on0, c0)[2])
            s1 = len(self.reduce_support(on1, c1)[2])
            noise = self.rng.random() * 3 if self.rng is not None else 0.0
            scored.append((s0 + s1 + noise, i, on0, on1, c0, c1))
        scored.sort()
        width = (len(sup) if len(sup) <= 6 else 2) if self.effort >= 2 else 1
        return scored[:width]

    def _rec_plain(self, f: int, care: int):
        full = self.full
        if f == 0:
            return 0, _CONST0
        if (f | ~care) & full == full:
            return 0, _CONST1
        f, care, sup = self.reduce_support(f, care)
        for i in sup:
            v = self.vars[i] & care
            if v == f:
                return 0, ("lit", 2 * (i + 1))
            if (~self.vars[i]) & care == f:
                return 0, ("lit", 2 * (i + 1) + 1)
        sh = self.shared_step(f, care, sup)
        if len(sup) <= 4:
            ex = self.exact(f, care, sup)
            return sh if sh is not None and sh[0] < ex[0] else ex
        if sh is not None:
            return sh
        # disjoint-support steps: the first one-variable step
        for cost, kind, lit, g, gc in self._steps(f, care, sup):
            c, p = self.rec(g, gc)
            return c + cost, (kind, lit, p)
        # factored SOP, both phases
        best = self.sop_plan(f, care)
        if len(sup) <= self.shannon_limit:
            # Shannon on the variables whose cofactors are simplest
            best = self._mux_best(best, (t[1:] for t in self._shannon_scored(f, care, sup)))
        return best

    def sop_plan(self, f: int, care: int):
        key = (self.n, f, care)
        r = _sop_cache.get(key)
        if r is None:
            r = self._sop_plan(f, care)
            _cache_put(_sop_cache, key, r)
        return r[0], (r[1][0], r[1][1], r[1][2])      # a fresh plan object (see build)

    def _sop_plan(self, f: int, care: int):
        n, full = self.n, self.full
        kern = _kernels(n)
        if kern is not None:
            # the same covers and counts in numba (kern.sop_costs); the on-set wins ties
            (k0, cs0), (k1, cs1) = kern.sop_costs(f, care, n)
            return (k0, ("sop", cs0, 0)) if k0 <= k1 else (k1, ("sop", cs1, 1))
        cubes, _ = T.isop(f, f | (full & ~care), n)
        off = care & ~f
        cubes_n, _ = T.isop(off, off | (full & ~care), n)
        best = None
        for cs, c in ((cubes, 0), (cubes_n, 1)):
            g = AIG([f"x{i}" for i in range(n)])
            factor_sop(g, cs, [2 * (i + 1) for i in range(n)])
            k = g.num_ands()
            if best is None or k < best[0]:
                best = (k, ("sop", cs, c))
        return best

    def exact(self, f: int, care: int, sup: list[int]):
        key = (self.n, f, care, tuple(sup))
        r = _exact_cache.get(key)
        if r is None:
            r = self._exact(f, care, sup)
            _cache_put(_exact_cache, key, r)
        return r[0], (r[1][0], r[1][1], r[1][2])      # a fresh plan object (see build)

    def _exact(self, f: int, care: int, sup: list[int]):
        n = self.n
        k = len(sup)
        lf = T.shrink(f, n, sup)
        lc = T.shrink(care, n, sup)
        width = 1 << k
        # replicate to 16 bits so that unused variables are don't-care-free no-ops
        def pad(t):
            w = width
            while w < 16:
                t |= t << w
                w *= 2
            return t
        lf, lc = pad(lf), pad(lc)
        dcbits = [b for b in range(width) if not (lc >> b) & 1]
        cands = []
        if len(dcbits) <= 7:
            for s in range(1 << len(dcbits)):
                t = lf
                for j, b in enumerate(dcbits):
                    if (s >> j) & 1:
                        t |= 1 << b
                cands.append(pad(t & ((1 << width) - 1)))
        else:
            cubes, tab = T.isop(lf & ((1 << width) - 1), (lf | ~lc) & ((1 << width) - 1), k)
            cands.append(pad(tab))
            offt = (~lf & lc) & ((1 << width) - 1)
            cubes, tab = T.isop(offt, (offt | ~lc) & ((1 << width) - 1), k)
            cands.append(pad(~tab & ((1 << width) - 1)))
            cands.append(pad(lf & ((1 << width) - 1)))
        best = None
        for t in cands:
            c = npn.cost4(t)
            if best is None or c < best[0]:
                best = (c, t)
        return best[0], ("exact", best[1], tuple(sup))

    # -------------------------------------------------------------- building
    def build(self, g: AIG, plan) -> int:
        lit = self._build(g, plan)
        key = self._key.get(id(plan))
        if key is not None:
            self.avail.setdefault(key, plan)
        return lit

    def _build(self, g: AIG, plan) -> int:
        kind = plan[0]
        if kind == "not":
            return self.build(g, plan[1]) ^ 1
        if kind == "const":
            return plan[1]
        if kind == "lit":
            return plan[1]
        if kind == "and":
            return g.and_(plan[1], self.build(g, plan[2]))
        if kind == "or":
            return g.or_(plan[1], self.build(g, plan[2]))
        if kind == "xor":
            return g.xor_(plan[1], self.build(g, plan[2]))
        if kind == "mux":
            return g.mux_(plan[1], self.build(g, plan[2]), self.build(g, plan[3]))
        if kind == "sop":
            _, cs, c = plan
            return factor_sop(g, cs, [2 * (i + 1) for i in range(self.n)]) ^ c
        if kind == "exact":
            _, t, sup = plan
            leaves = [2 * (i + 1) for i in sup] + [0] * (4 - len(sup))
            return npn.build4(g, t, leaves)
        raise AssertionError(kind)


def from_table(spec: TableSpec, effort: int = 2, rng=None) -> AIG:
    """A decomposed AIG for ``spec``; ``rng`` randomises the Shannon variable choice."""
    n = spec.n
    d = _Dec(n, effort, rng)
    g = AIG(spec.inputs)
    full = d.full
    # outputs of small support first: larger ones may then reuse them (XOR prefixes)
    order = sorted(range(len(spec.outputs)),
                   key=lambda o: (len(T.support(spec.on[o] | spec.dc[o], n))
                                  + len(T.support(spec.dc[o], n)), o))
    lits = [0] * len(spec.outputs)
    for o in order:
        care = full & ~spec.dc[o]
        _, plan = d.rec(spec.on[o] & care, care)
        lits[o] = d.build(g, plan)
    for name, lit in zip(spec.outputs, lits):
        g.add_output(name, lit)
    return g.cleanup()
