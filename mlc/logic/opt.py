"""Optimisation passes on AIGs.  Cost = AND nodes (inversions are free), then depth.

Every pass returns a new AIG (functional style); the driver :func:`optimize` keeps
the best network seen and stops when a round brings nothing.

Passes
------
* :func:`sweep`      -- merge nodes with equal (or complementary) global functions
                        (exhaustive simulation; up to :data:`TT_LIMIT` inputs);
* :func:`resub`      -- resubstitution: re-express a node with 0..3 new gates over
                        existing nodes (divisors), freeing its maximum fanout-free
                        cone; uses the external don't cares on output drivers;
* :func:`rewrite`    -- DAG-aware rewriting of 4-input cuts with the exact NPN table
                        (:mod:`mlc.logic.npn`), counting shared nodes;
* :func:`balance`    -- AND-tree balancing for depth, never adding nodes.
"""
from __future__ import annotations

import gc
import random
import sys
from contextlib import contextmanager
from heapq import heappop, heappush

from mlc.spec import NetworkSpec, TableSpec
from mlc.logic import tt as T
from mlc.logic import work
from mlc.logic.aig import AIG
from mlc.logic.lower import from_spec

TT_LIMIT = 16


def cost(g: AIG) -> tuple[int, int]:
    return (g.num_ands(), g.depth())


# ----------------------------------------------------------------------------- helpers
def refcounts(g: AIG) -> list[int]:
    return g.fanout_counts()


def mffc(g: AIG, node: int, refs: list[int], leaves: set[int] = frozenset()) -> list[int]:
    """Nodes of the maximum fanout-free cone of ``node`` (including it), stopping at
    inputs and ``leaves``.  ``refs`` is left unchanged."""
    n = g.num_inputs
    out = [node]
    stack = [node]
    touched = []
    while stack:
        x = stack.pop()
        for f in g.ands[x - n - 1]:
            y = f >> 1
            if y <= n or y in leaves:
                continue
            refs[y] -= 1
            touched.append(y)
            if refs[y] == 0:
                out.append(y)
                stack.append(y)
    for y in touched:
        refs[y] += 1
    return out


def tfo_mark(g: AIG, node: int, upto: int | None = None) -> bytearray:
    """Transitive fanout of ``node`` (including it), among nodes below ``upto``."""
    n = g.num_inputs
    mark = bytearray(g.num_nodes)
    mark[node] = 1
    end = len(g.ands) if upto is None else min(len(g.ands), upto - n - 1)
    for k in range(node - n, end):
        a, b = g.ands[k]
        if mark[a >> 1] or mark[b >> 1]:
            mark[n + 1 + k] = 1
    return mark


def _expr_nodes(e, acc: list[int]) -> list[int]:
    if isinstance(e, int):
        acc.append(e >> 1)
    else:
        _expr_nodes(e[1], acc)
        _expr_nodes(e[2], acc)
    return acc


def _fanin_nodes(g: AIG, x: int) -> tuple[int, int]:
    a, b = g.ands[x - g.num_inputs - 1]
    return a >> 1, b >> 1


def _postorder(roots, deps, done, rng: random.Random | None = None):
    """Yield the nodes reachable from ``roots`` that are not in ``done``, each after
    its dependencies (``deps(x)``); the caller adds every yielded node to ``done``
    before asking for the next.  With ``rng``, two pending dependencies are visited
    in random order."""
    for root in roots:
        stack = [root]
        while stack:
            x = stack[-1]
            if x in done:
                stack.pop()
                continue
            pend = [y for y in deps(x) if y not in done]
            if rng is not None and len(pend) == 2 and rng.random() < 0.5:
                pend.reverse()
            if pend:
                stack.extend(pend)
                continue
            stack.pop()
            yield x


def rebuild(g: AIG, repl: dict[int, tuple]) -> AIG:
    """Copy ``g`` replacing node ``x`` by the expression ``repl[x]``.

    An expression is an old literal (int) or ``("and", e1, e2, compl)``.  The
    replacements must keep the network acyclic (see :class:`_Virtual`); nodes are
    rebuilt in a depth-first order of the resulting network.
    """
    h = AIG(g.inputs)
    n = g.num_inputs
    m: dict[int, int] = {i: 2 * i for i in range(n + 1)}

    def deps(x: int) -> list[int]:
        r = repl.get(x)
        if r is not None:
            return _expr_nodes(r, [])
        a, b = g.ands[x - n - 1]
        return [a >> 1, b >> 1]

    def ev(e):
        if isinstance(e, int):
            return m[e >> 1] ^ (e & 1)
        _, e1, e2, c = e
        return h.and_(ev(e1), ev(e2)) ^ c

    for x in _postorder([lit >> 1 for lit in g.output_lits], deps, m):
        r = repl.get(x)
        if r is not None:
            m[x] = ev(r)
        else:
            a, b = g.ands[x - n - 1]
            m[x] = h.and_(m[a >> 1] ^ (a & 1), m[b >> 1] ^ (b & 1))
    for name, lit in zip(g.outputs, g.output_lits):
        h.add_output(name, m[lit >> 1] ^ (lit & 1))
    return h.cleanup()


class _Virtual:
    """The network as it will be after the replacements accepted so far; used to
    refuse a replacement that would create a cycle."""

    def __init__(self, g: AIG):
        self.g = g
        self.repl_deps: dict[int, list[int]] = {}
        # the least replaced node with a dependency above itself (none yet: above all);
        # every other edge of the virtual network goes down
        self.min_up = g.num_nodes

    def deps(self, x: int) -> list[int]:
        r = self.repl_deps.get(x)
        if r is not None:
            return r
        n = self.g.num_inputs
        if x <= n:
            return []
        a, b = self.g.ands[x - n - 1]
        return [a >> 1, b >> 1]

    def reaches(self, sources: list[int], target: int) -> bool:
        seen = set()
        stack = [s for s in sources if s > self.g.num_inputs]
        while stack:
            x = stack.pop()
            if x == target:
                return True
            # a path from a node below the target up to the target needs an upward
            # edge, i.e. a replaced node with a dependency above it, at or below the
            # node (only downward edges lead there): none below min_up
            if x in seen or x < target and x < self.min_up:
                continue
            seen.add(x)
            stack.extend(y for y in self.deps(x) if y > self.g.num_inputs)
        return False

    def accept(self, x: int, e) -> bool:
        ds = _expr_nodes(e, [])
        if self.reaches(ds, x):
            return False
        self.repl_deps[x] = ds
        if x < self.min_up and any(d > x for d in ds):
            self.min_up = x
        return True


class _Pass:
    """The skeleton of the local passes: :meth:`nodes` visits the live nodes not
    ``touched`` by an accepted move (each visit one tick of the work clock, stopping past
    ``deadline`` in virtual seconds), :meth:`replace` keeps a replacement that
    :class:`_Virtual` accepts and marks its freed cone, :meth:`result` rebuilds."""

    def __init__(self, g: AIG, touched, refs, deadline: float | None, tick: float = 1.0):
        self.g = g
        self.touched = touched
        self.refs = refs
        self.deadline = deadline
        self.tick = tick
        self.repl: dict[int, tuple] = {}
        self.virt = _Virtual(g)

    def nodes(self, order=None):
        """The AND nodes in ``order`` (default: inputs to outputs) still worth a visit."""
        N = self.g.num_nodes
        touched, refs = self.touched, self.refs
        for x in range(self.g.num_inputs + 1, N) if order is None else order:
            if self.deadline is not None and work.now(N, self.tick) > self.deadline:
                return
            if touched[x] or refs[x] == 0:
                continue
            yield x

    def replace(self, x: int, e, cone=()) -> bool:
        """Replace ``x`` by expression ``e`` (None: no move) and mark ``cone`` touched;
        False where there is no move or it would make a cycle."""
        if e is None or not self.virt.accept(x, e):
            return False
        self.repl[x] = e
        for y in cone:
            self.touched[y] = 1
        return True

    def result(self) -> AIG:
        return rebuild(self.g, self.repl) if self.repl else self.g


def reorder(g: AIG, rng: random.Random | None = None) -> AIG:
    """Re-number nodes in DFS order from the outputs (optionally shuffled order)."""
    h = AIG(g.inputs)
    n = g.num_inputs
    m: dict[int, int] = {i: 2 * i for i in range(n + 1)}
    order = list(range(len(g.outputs)))
    if rng is not None:
        rng.shuffle(order)
    for x in _postorder([g.output_lits[o] >> 1 for o in order], lambda x: _fanin_nodes(g, x), m, rng):
        a, b = g.ands[x - n - 1]
        m[x] = h.and_(m[a >> 1] ^ (a & 1), m[b >> 1] ^ (b & 1))
    for name, lit in zip(g.outputs, g.output_lits):
        h.add_output(name, m[lit >> 1] ^ (lit & 1))
    return h


# ----------------------------------------------------------------------------- sweep
def sweep(g: AIG) -> AIG:
    """Merge functionally equivalent nodes (up to complement) using global tables."""
    n = g.num_inputs
    if n > TT_LIMIT:
        return g
    full = T.mask(n)
    vals = g.node_tables()
    seen: dict[int, int] = {}
    repl: dict[int, tuple] = {}
    for x in range(n + 1):
        v = vals[x]
        seen.setdefault(v, 2 * x)
        seen.setdefault(v ^ full, 2 * x + 1)
    for x in range(n + 1, g.num_nodes):
        v = vals[x]
        r = seen.get(v)
        if r is not None:
            repl[x] = r
        else:
            seen[v] = 2 * x
            seen[v ^ full] = 2 * x + 1
    if not repl:
        return g
    return rebuild(g, repl)


def fraig(g: AIG, seed: int = 1, width: int = 2048, conflicts: int = 1000,
          rounds: int = 3, deadline: float | None = None) -> AIG:
    """SAT sweeping for networks too wide for :func:`sweep`'s global tables (ABC's
    ``fraig``): nodes with equal signatures (up to complement) under seeded random
    patterns are candidates; each is proven equal to its class's first node by
    incremental SAT (:class:`mlc.logic.cec._Sat`, ``conflicts`` per query, a pair over
    budget is left alone) and merged; counterexamples refine the patterns for the next
    of ``rounds`` rounds."""
    n = g.num_inputs
    if n <= TT_LIMIT:
        return sweep(g)
    if not g.ands:
        return g
    from mlc.logic.cec import SWEEP_SOLVER, _Sat
    rng = random.Random(seed)
    words = [rng.getrandbits(width) for _ in range(n)]
    N = g.num_nodes
    repl: dict[int, int] = {}
    sat = None
    done: set[int] = set()          # merged, disproved for good or over budget
    try:
        for _ in range(rounds):
            full = (1 << width) - 1
            sig = g.simulate_nodes(words, width)
            reps: dict[int, int] = {0: 0}
            for i in range(1, n + 1):
                reps.setdefault(sig[i] ^ full if sig[i] & 1 else sig[i], i)
            cexs: list[int] = []
            for v in range(n + 1, N):
                if deadline is not None and work.now(N, FRAIG_TICK) > deadline:
                    break
                s = sig[v]
                key = s ^ full if s & 1 else s
                r = reps.get(key)
                if r is None or v in done:
                    reps.setdefault(key, v)
                    continue
                y = 2 * r ^ ((s ^ sig[r]) & 1)          # the literal v would equal
                if r == 0:
                    y = s & 1
                if sat is None:
                    sat = _Sat(g, SWEEP_SOLVER)
                x = 2 * v
                verdict = True
                for q in ([x, y ^ 1], [x ^ 1, y]):
                    ok = sat.satisfiable(q, conflicts)
                    if ok is None:
                        verdict = None
                        break
                    if ok:
                        cexs.append(sat.model_minterm())
                        verdict = False
                        break
                if verdict is True:
                    sat.add_equal(x, y)
                    repl[v] = y
                    done.add(v)
                elif verdict is None:
                    done.add(v)
            if not cexs or (deadline is not None and work.now(N, FRAIG_TICK) > deadline):
                break
            for i in range(n):
                bits = sum(((c >> i) & 1) << j for j, c in enumerate(cexs))
                words[i] |= bits << width
            width += len(cexs)
    finally:
        if sat is not None:
            sat.close()
    if not repl:
        return g
    return rebuild(g, repl)


# ----------------------------------------------------------------------------- resub
def resub(g: AIG, care_out: list[int] | None = None, max_new: int = 2, max_div: int = 150,
          deadline: float | None = None) -> AIG:
    """One resubstitution pass with global truth tables (``n <= TT_LIMIT``)."""
    n = g.num_inputs
    if n > TT_LIMIT or not g.ands:
        return g
    full = T.mask(n)
    vals = g.node_tables()
    refs = refcounts(g)
    # care set of each node: external don't cares apply to nodes feeding only outputs
    node_care: dict[int, int] = {}
    if care_out is not None:
        drv: dict[int, int] = {}
        cnt: dict[int, int] = {}
        for lit, c in zip(g.output_lits, care_out):
            x = lit >> 1
            drv[x] = drv.get(x, 0) | (full & ~c)      # union of don't cares -> intersect cares
            cnt[x] = cnt.get(x, 0) + 1
        # a node driving several outputs: care = union of the outputs' cares
        for lit, c in zip(g.output_lits, care_out):
            x = lit >> 1
            node_care[x] = node_care.get(x, 0) | c
        for x in list(node_care):
            if refs[x] != cnt[x]:        # also used inside the network: fully cared
                node_care[x] = full
    # output drivers whose function may change inside the don't cares are no divisors
    relaxed = {x for x, c in node_care.items() if c != full}
    kernels = _use_kernels(g)
    if kernels:
        import numpy as np
        from mlc.logic import kern
        tabs, W = kern.tables_array(vals, n)
        fullw = kern.words(full, W)
    touched = bytearray(g.num_nodes)
    ps = _Pass(g, touched, refs, deadline)
    N = g.num_nodes
    or_width = 16 if len(g.ands) < 300 else 2
    for x in ps.nodes():
        cone = mffc(g, x, refs)
        save = len(cone)
        if any(touched[y] for y in cone):
            continue
        care = node_care.get(x, full)
        f = vals[x] & care
        incone = set(cone)
        lo, hi = max(n + 1, x - max_div), min(N, x + max_div // 3)
        tfo = tfo_mark(g, x, hi)
        divs = list(range(1, n + 1)) + [d for d in range(lo, hi) if d not in incone
                                        and not touched[d] and not tfo[d] and refs[d] > 0
                                        and d not in relaxed]
        if kernels:
            e = kern.decode(kern.find_resub_rows(
                tabs, W, kern.words(f, W), fullw if care == full else kern.words(care, W),
                np.array(divs, dtype=np.int64), min(max_new, save - 1), or_width))
        else:
            e = _find_resub(f, care, full, divs, vals, min(max_new, save - 1), or_width)
        ps.replace(x, e, cone)
    return ps.result()


def odc_care(g: AIG, x: int, vals: list[int], care_out: list[int] | None, full: int) -> int:
    """Observability care set of node ``x`` (global tables): the minterms where
    complementing ``x`` changes some output inside that output's care set."""
    n = g.num_inputs
    flip = {x: vals[x] ^ full}
    for k in range(x - n, len(g.ands)):
        a, b = g.ands[k]
        if (a >> 1) in flip or (b >> 1) in flip:
            va = flip.get(a >> 1, vals[a >> 1]) ^ (full if a & 1 else 0)
            vb = flip.get(b >> 1, vals[b >> 1]) ^ (full if b & 1 else 0)
            flip[n + 1 + k] = va & vb
    care = 0
    for o, lit in enumerate(g.output_lits):
        y = lit >> 1
        if y in flip:
            d = flip[y] ^ vals[y]
            care |= d & (care_out[o] if care_out is not None else full)
    return care


def resub_odc(g: AIG, care_out: list[int] | None = None, max_new: int = 2,
              max_div: int = 150, deadline: float | None = None, max_moves: int = 50) -> AIG:
    """Resubstitution with observability don't cares (global tables, ``n <=
    TT_LIMIT``): a node may be replaced by a cheaper expression that differs from it
    only where no output observes it.  Don't-care moves interact, so one move is
    made per scan and the network rebuilt before the next (at most ``max_moves``)."""
    n = g.num_inputs
    if n > TT_LIMIT or not g.ands or len(g.ands) > 400:
        return g
    full = T.mask(n)
    kernels = _use_kernels(g)
    if kernels:
        import numpy as np
        from mlc.logic import kern
    for _ in range(max_moves):
        vals = g.node_tables()
        if kernels:
            tabs, W = kern.tables_array(vals, n)
        refs = refcounts(g)
        N = g.num_nodes
        done = None
        for x in range(n + 1, N):
            if deadline is not None and work.now(g.num_nodes) > deadline:
                return g
            if refs[x] == 0:
                continue
            cone = mffc(g, x, refs)
            if len(cone) < 2:
                continue
            care = odc_care(g, x, vals, care_out, full)
            if care == full:
                continue
            incone = set(cone)
            lo, hi = max(n + 1, x - max_div), min(N, x + max_div // 3)
            tfo = tfo_mark(g, x, hi)
            divs = list(range(1, n + 1)) + [d for d in range(lo, hi) if d not in incone
                                            and not tfo[d] and refs[d] > 0]
            if kernels:
                e = kern.decode(kern.find_resub_rows(
                    tabs, W, kern.words(vals[x] & care, W), kern.words(care, W),
                    np.array(divs, dtype=np.int64), min(max_new, len(cone) - 1), 16))
            else:
                e = _find_resub(vals[x] & care, care, full, divs, vals,
                                min(max_new, len(cone) - 1), 16)
            if e is None:
                continue
            done = (x, e)
            break
        if done is None:
            return g
        g = rebuild(g, {done[0]: done[1]})
    return g


def _grow_window(ands, n: int, fanouts, vals: dict[int, int], leaves, full: int, top: int,
                 max_window: int, changed=None, win=None) -> None:
    """Grow a window from ``leaves`` up through fanouts: a node joins (its table over
    the leaves into ``vals``) once both its fanins have tables, smallest node first
    (a heap), up to node ``top`` and ``max_window`` tables in all.  Nodes marked in
    ``changed`` and nodes with a fanin in ``win`` are left out (for resub_dc)."""
    # (nodes come off the heap in increasing order and every push is above the node
    # being processed, so once a node above ``top`` comes off, none below it remains:
    # nodes above ``top`` are never pushed)
    cand = sorted({y for leaf in leaves for y in fanouts[leaf] if y <= top})
    seen = set(cand)
    size = len(vals)
    get = vals.get
    while cand and size < max_window:
        y = heappop(cand)
        if y in vals:
            continue
        if changed is not None and changed[y]:
            continue
        a, b = ands[y - n - 1]
        if win is not None and ((a >> 1) in win or (b >> 1) in win):
            continue
        va = get(a >> 1)
        if va is None:
            continue
        vb = get(b >> 1)
        if vb is None:
            continue
        vals[y] = (va ^ full if a & 1 else va) & (vb ^ full if b & 1 else vb)
        size += 1
        for z in fanouts[y]:
            if z <= top and z not in seen:
                seen.add(z)
                heappush(cand, z)


def resub_window(g: AIG, max_leaves: int | None = None, max_new: int = 2, max_window: int | None = None,
                 deadline: float | None = None) -> AIG:
    """Resubstitution for networks too wide for global tables: each node gets a
    window (a reconvergence-driven cut and the nodes computable from it), and its
    function and the divisors' are truth tables over the cut's leaves."""
    n = g.num_inputs
    if not g.ands:
        return g
    if max_leaves is None:
        max_leaves = WINDOW_LEAVES
    if max_window is None:
        max_window = WINDOW_SIZE
    tick = WIDE_TICK if n > TT_LIMIT else 1.0
    if _use_kernels(g) and max_leaves <= 14:
        return _resub_window_nb(g, max_leaves, max_new, max_window, deadline, tick)
    refs = refcounts(g)
    fanouts: list[list[int]] = [[] for _ in range(g.num_nodes)]
    for k, (a, b) in enumerate(g.ands):
        x = n + 1 + k
        fanouts[a >> 1].append(x)
        if (b >> 1) != (a >> 1):
            fanouts[b >> 1].append(x)
    touched = bytearray(g.num_nodes)
    ps = _Pass(g, touched, refs, deadline, tick)
    for x in ps.nodes():
        leaves = reconv_cut(g, x, max_leaves)
        if any(touched[y] for y in leaves):
            continue
        cone = mffc(g, x, refs, set(leaves))
        if len(cone) < 2 or any(touched[y] for y in cone):
            continue
        k = len(leaves)
        full = T.mask(k)
        vals: dict[int, int] = {leaf: T.var(k, i) for i, leaf in enumerate(leaves)}
        # window: grow from the leaves through fanouts whose fanins are all inside
        # (candidates are taken smallest first: a heap)
        _grow_window(g.ands, n, fanouts, vals, leaves, full, x + max_window, max_window)
        if x not in vals:
            continue
        # exclude the node's fanout cone and its MFFC from the divisors
        bad = set(cone)
        tfo = {x}
        for y in sorted(vals):
            if y > x and y > n:
                a, b = g.ands[y - n - 1]
                if (a >> 1) in tfo or (b >> 1) in tfo:
                    tfo.add(y)
        bad |= tfo
        divs = [d for d in sorted(vals) if d not in bad and not touched[d] and refs[d] > 0]
        e = _find_resub(vals[x], full, full, divs, vals, min(max_new, len(cone) - 1), 8)
        ps.replace(x, e, cone)
    return ps.result()


def _resub_window_nb(g: AIG, max_leaves: int, max_new: int, max_window: int,
                     deadline: float | None, tick: float) -> AIG:
    """:func:`resub_window` with its per-node work in :mod:`mlc.logic.kern` (the same moves)."""
    import numpy as np
    from mlc.logic import kern
    n = g.num_inputs
    N = g.num_nodes
    fa, fb, fo_start, fo_list = kern.aig_arrays(g)
    refs = np.array(refcounts(g), dtype=np.int64)
    touched = bytearray(N)
    tv = np.frombuffer(touched, dtype=np.uint8)
    ws = kern.Workspace(N, max_leaves)
    out = ws.out
    cone_buf = ws.buf[1]
    ps = _Pass(g, touched, refs, deadline, tick)
    for x in ps.nodes():
        while True:
            kern.window_node(x, fa, fb, n, fo_start, fo_list, refs, tv, max_leaves, max_window,
                             max_new, ws.tabs, ws.slot, ws.ids, ws.mark, ws.seen, ws.buf, ws.vec,
                             out)
            if out[0] != -2:
                break
            ws.grow()
        e = kern.decode(out)
        if e is not None:
            ps.replace(x, e, cone_buf[:int(out[5])].tolist())
    return ps.result()


def _in_tfo(g: AIG, x: int, v: int, memo: dict[int, bool], budget: list[int]) -> bool:
    """Whether ``v`` is in the transitive fanout of ``x`` (a search down from ``v``
    through nodes above ``x``); True (the safe answer) once ``budget[0]`` visits ran out."""
    if v <= x:
        return v == x
    r = memo.get(v)
    if r is not None:
        return r
    budget[0] -= 1
    if budget[0] < 0:
        return True
    a, b = g.ands[v - g.num_inputs - 1]
    r = _in_tfo(g, x, a >> 1, memo, budget) or _in_tfo(g, x, b >> 1, memo, budget)
    memo[v] = r
    return r


def resub_dc(g: AIG, max_leaves: int | None = None, levels: int | None = None,
             max_fanout: int | None = None, max_window: int = 300, max_new: int = 2,
             deadline: float | None = None) -> AIG:
    """Windowed resubstitution with observability don't cares, for networks of any
    width (the windowed counterpart of :func:`resub_odc`, in the spirit of ABC's
    ``mfs``): node ``x`` gets a window of its fanout up to ``levels`` levels and a
    reconvergence-driven cut (up to ``max_leaves`` leaves) below the whole window;
    truth tables over the leaves give ``x``'s care set -- the leaf values under which
    complementing ``x`` changes some window node seen from outside the window (a
    primary output or a node with a fanout outside) -- and ``x`` may be replaced by an
    expression over divisors that equals it on the care set.

    Moves are sound together: a move changes the functions of ``x`` and of the window
    nodes not seen from outside (only outside their care sets) and relies on the
    functions of its window (leaves, the nodes between, the divisors it uses); a later
    move is skipped when its window contains a changed node or when it would change a
    node an earlier move relies on, and changed nodes are no divisors."""
    n = g.num_inputs
    if not g.ands:
        return g
    if max_leaves is None:
        max_leaves = DC_LEAVES
    if levels is None:
        levels = DC_LEVELS
    if max_fanout is None:
        max_fanout = DC_FANOUT
    tick = WIDE_TICK if n > TT_LIMIT else 1.0
    if _use_kernels(g) and max_leaves <= 14:
        return _resub_dc_nb(g, max_leaves, levels, max_fanout, max_window, max_new, deadline, tick)
    N = g.num_nodes
    ands = g.ands
    refs = refcounts(g)
    fanouts: list[list[int]] = [[] for _ in range(N)]
    for k, (a, b) in enumerate(ands):
        y = n + 1 + k
        fanouts[a >> 1].append(y)
        if (b >> 1) != (a >> 1):
            fanouts[b >> 1].append(y)
    is_po = bytearray(N)
    for lit in g.output_lits:
        is_po[lit >> 1] = 1
    touched = bytearray(N)       # the freed cones of accepted moves
    changed = bytearray(N)       # nodes whose function an accepted move changed
    read = bytearray(N)          # nodes whose function an accepted move relies on
    ps = _Pass(g, touched, refs, deadline, tick)
    for x in ps.nodes():
        if changed[x]:
            continue
        # the fanout window: nodes up to `levels` levels above x whose fanins in
        # the fanout of x are all in the window (then every leaf below is outside it)
        win = {x}
        memo: dict[int, bool] = {x: True}
        budget = [200]
        frontier = [x]
        for _lev in range(levels):
            nxt = []
            for y in frontier:
                if len(fanouts[y]) > max_fanout:
                    continue
                for z in fanouts[y]:
                    if z in win:
                        continue
                    a, b = ands[z - n - 1]
                    if any(v not in win and _in_tfo(g, x, v, memo, budget)
                           for v in (a >> 1, b >> 1)):
                        continue
                    win.add(z)
                    nxt.append(z)
            frontier = nxt
        if len(win) == 1:
            continue
        if any(changed[y] for y in win):
            continue
        # the leaves: a reconvergence-driven cut below x and the window
        inside = set(win)
        leaves: set[int] = set()
        for y in win:
            a, b = ands[y - n - 1]
            for v in (a >> 1, b >> 1):
                if v not in win:
                    leaves.add(v)
        leaves.discard(0)
        if len(leaves) > max_leaves:
            continue
        _expand_cut(ands, n, leaves, inside, max_leaves)
        if any(changed[y] or touched[y] for y in leaves) or any(changed[y] for y in inside):
            continue
        lv = sorted(leaves)
        cone = mffc(g, x, refs, leaves)
        if any(touched[y] for y in cone):
            continue
        k = len(lv)
        full = T.mask(k)
        vals: dict[int, int] = dict(zip(lv, T.var_tables(k)[0]))
        ok = True
        for y in sorted(inside):
            a, b = ands[y - n - 1]
            va = vals.get(a >> 1)
            vb = vals.get(b >> 1)
            if va is None or vb is None:
                ok = False                # (not a cut: cannot happen; be safe)
                break
            vals[y] = (va ^ full if a & 1 else va) & (vb ^ full if b & 1 else vb)
        if not ok:
            continue
        # care set of x: complement it and re-simulate the window
        flip = {x: vals[x] ^ full}
        for y in sorted(win):
            if y == x:
                continue
            a, b = ands[y - n - 1]
            va = flip.get(a >> 1, vals[a >> 1])
            vb = flip.get(b >> 1, vals[b >> 1])
            flip[y] = (va ^ full if a & 1 else va) & (vb ^ full if b & 1 else vb)
        roots = [y for y in win if is_po[y] or any(z not in win for z in fanouts[y])]
        rootset = set(roots)
        if any(read[y] for y in win if y not in rootset):
            continue                  # would change what an accepted move relies on
        care = 0
        for y in roots:
            care |= flip[y] ^ vals[y]
        # more divisors: nodes computable from the leaves, outside x's fanout
        _grow_window(ands, n, fanouts, vals, lv, full, x + max_window, max_window, changed, win)
        incone = set(cone)
        divs = [d for d in sorted(vals) if d not in win and d not in incone and not touched[d]
                and not changed[d] and refs[d] > 0]
        e = _find_resub(vals[x] & care, care, full, divs, vals, min(max_new, len(cone) - 1), 8)
        if not ps.replace(x, e, cone):
            continue
        for y in win:
            if y not in rootset:
                changed[y] = 1
        changed[x] = 1
        for y in leaves:
            read[y] = 1
        for y in inside:
            read[y] = 1
        # the divisors and their cones down to the window's nodes and leaves
        stack = _expr_nodes(e, [])
        while stack:
            y = stack.pop()
            if read[y]:
                continue
            read[y] = 1
            if y > n:
                a, b = ands[y - n - 1]
                stack += [a >> 1, b >> 1]
    return ps.result()


def _resub_dc_nb(g: AIG, max_leaves: int, levels: int, max_fanout: int, max_window: int,
                 max_new: int, deadline: float | None, tick: float) -> AIG:
    """:func:`resub_dc` with its per-node work in :mod:`mlc.logic.kern` (the same moves)."""
    import numpy as np
    from mlc.logic import kern
    n = g.num_inputs
    N = g.num_nodes
    fa, fb, fo_start, fo_list = kern.aig_arrays(g)
    refs = np.array(refcounts(g), dtype=np.int64)
    is_po = np.zeros(N, dtype=np.uint8)
    for lit in g.output_lits:
        is_po[lit >> 1] = 1
    touched = np.zeros(N, dtype=np.uint8)
    changed = np.zeros(N, dtype=np.uint8)
    read = np.zeros(N, dtype=np.uint8)
    ws = kern.Workspace(N, max_leaves)
    # flipped tables of the fanout window: at most 1 + f + f^2 + ... nodes (f = max_fanout)
    wmax = sum(max_fanout ** i for i in range(levels + 1))
    ftabs = np.zeros((min(N + 2, wmax + 2), ws.tabs.shape[1]), dtype=np.uint64)
    fslot = np.full(N + 1, -1, dtype=np.int64)
    winmark = np.zeros(N + 1, dtype=np.int8)
    memo = np.zeros(N + 1, dtype=np.int8)
    lens = np.zeros(4, dtype=np.int64)
    out = ws.out
    ps = _Pass(g, touched, refs, deadline, tick)
    for x in ps.nodes():
        if changed[x]:
            continue
        while True:
            kern.dc_node(x, fa, fb, n, fo_start, fo_list, refs, touched, changed, read, is_po,
                         max_leaves, levels, max_fanout, max_window, max_new, ws.tabs, ftabs,
                         ws.slot, fslot, ws.ids, ws.mark, winmark, memo, ws.seen, ws.buf, ws.vec,
                         out, lens)
            if out[0] != -2:
                break
            kern.dc_clear(ws.buf, lens, ws.mark, winmark)
            ws.grow()
        e = kern.decode(out)
        if ps.replace(x, e):
            kern.dc_commit(x, fa, fb, n, touched, changed, read, ws.buf, lens, winmark,
                           np.array(_expr_nodes(e, []), dtype=np.int64))
        kern.dc_clear(ws.buf, lens, ws.mark, winmark)
    return ps.result()


def _find_resub(f: int, care: int, full: int, divs: list[int], vals: list[int], max_new: int,
                or_width: int = 16):
    """An expression over divisors for ``f`` (on ``care``) with at most ``max_new`` ANDs."""
    if max_new < 0:
        return None
    nf = ~f & care
    # 0-resub
    if f == 0:
        return 0
    if nf == 0:
        return 1
    # one pass over the divisors, on the divisor's tables as they are (f and !f lie in
    # the care set, so f & x == f & (x & care)): a 0-resub answer (the first divisor
    # that matches), and the divisor literals that contain f (pos, for f = AND) or !f
    # (neg, for f = OR = !AND(!,!)) with their tables on the care set
    pos, neg = [], []
    info = []
    for d in divs:
        x = vals[d]
        fv = f & x
        nfv = nf & x
        if fv == f:
            if nfv == 0:
                return 2 * d                   # x == f on the care set
        elif fv == 0 and nfv == nf:
            return 2 * d + 1                   # x == !f on the care set
        info.append((d, x, fv, nfv))
    if max_new < 1:
        return None
    for d, x, fv, nfv in info:
        if fv == f or fv == 0 or nfv == nf or nfv == 0:
            v = x & care
            nv = v ^ care
            if fv == f:
                pos.append((2 * d, v))
            if nfv == nf:
                neg.append((2 * d, v))
            if fv == 0:
                pos.append((2 * d + 1, nv))
            if nfv == 0:
                neg.append((2 * d + 1, nv))
    # 1-resub
    for target, cands, oc in ((f, pos, 0), (nf, neg, 1)):
        L = len(cands)
        for i in range(L):
            li, wi = cands[i]
            for j in range(i + 1, L):
                lj, wj = cands[j]
                if (li >> 1) != (lj >> 1) and wi & wj == target:
                    return ("and", li, lj, oc)
    if max_new < 2:
        return None
    # 2-resub: f = d1 & (d2 & d3)  (all three in pos), or f = d1 & (d2 | d3)
    for target, cands, oc in ((f, pos, 0), (nf, neg, 1)):
        L = len(cands)
        if L <= 30:
            for i in range(L):
                li, wi = cands[i]
                extra = wi & ~target          # minterms d1 lets through that must be removed
                for j in range(i + 1, L):
                    lj, wj = cands[j]
                    e2 = extra & wj
                    if e2 == 0 and j + 1 < L:     # any third literal will do: the first
                        return ("and", li, ("and", lj, cands[j + 1][0], 0), oc)
                    for k in range(j + 1, L):
                        lk, wk = cands[k]
                        if e2 & wk == 0:
                            return ("and", li, ("and", lj, lk, 0), oc)
        # d1 & (d2 | d3): d2, d3 avoid what d1 lets through, together cover the target.
        # Candidates d2, d3: the divisor literals that meet the target (a divisor's
        # table where it has some of the target, its complement where not all of it),
        # in divisor order, each with how much of the target it covers (two whose
        # counts add up to less than the target's cannot cover it); a divisor avoids
        # ``extra`` where x & extra == 0, its complement where x & extra == extra.
        if not L:
            continue
        full_t = f if oc == 0 else nf
        ct = full_t.bit_count()
        meet = [(d, x, fv if oc == 0 else nfv) for d, x, fv, nfv in info]
        vcache: dict[int, tuple[int, int]] = {}     # d -> (x & care, |m|)
        for i in range(min(L, or_width)):
            li, wi = cands[-1 - i]
            extra = wi & ~target
            di = li >> 1
            avoid = []
            for d, x, m in meet:
                if d == di:
                    continue
                xe = x & extra
                if m and xe == 0:
                    vc = vcache.get(d)
                    if vc is None:
                        vc = vcache[d] = (x & care, m.bit_count())
                    avoid.append((2 * d, vc[0], vc[1]))
                if m != full_t and xe == extra:
                    vc = vcache.get(d)
                    if vc is None:
                        vc = vcache[d] = (x & care, m.bit_count())
                    avoid.append((2 * d + 1, vc[0] ^ care, ct - vc[1]))
            if len(avoid) > 60:
                avoid = avoid[-60:]
            A = len(avoid)
            for j in range(A):
                lj, wj, cj = avoid[j]
                need = ct - cj
                rest = None
                for k in range(j + 1, A):
                    lk, wk, ck = avoid[k]
                    if ck < need:
                        continue
                    if rest is None:
                        rest = target & ~wj
                    if rest & ~wk == 0 and (lk >> 1) != (lj >> 1):
                        return ("and", li, ("and", lj ^ 1, lk ^ 1, 1), oc)
    return None


# ----------------------------------------------------------------------------- rewrite
def enumerate_cuts(g: AIG, k: int = 4, limit: int = 10) -> list[list[tuple[int, ...]]]:
    n = g.num_inputs
    cuts: list[list[tuple[int, ...]]] = [[()]] + [[(i,)] for i in range(1, n + 1)]
    sets: list[list[frozenset]] = [[frozenset()]] + [[frozenset((i,))] for i in range(1, n + 1)]
    for idx, (a, b) in enumerate(g.ands):
        x = n + 1 + idx
        ca, cb = sets[a >> 1], sets[b >> 1]
        res = set()
        for c1 in ca:
            for c2 in cb:
                u = c1 | c2
                if len(u) <= k:
                    res.add(u)
        lst = sorted((tuple(sorted(u)) for u in res), key=lambda c: (len(c), c))
        # drop dominated cuts (supersets of another cut)
        kept: list[tuple[int, ...]] = []
        kept_s: list[frozenset] = []
        for c in lst:
            sc = frozenset(c)
            if any(d <= sc for d in kept_s):
                continue
            kept.append(c)
            kept_s.append(sc)
            if len(kept) >= limit:
                break
        cuts.append(kept + [(x,)])
        sets.append(kept_s + [frozenset((x,))])
    return cuts


def cut_table(g: AIG, node: int, leaves: tuple[int, ...]) -> int:
    """16-bit table of ``node`` over ``leaves`` (padded to 4 variables)."""
    return cone_table(g, node, leaves, 4)


def _place_class_circuit(g: AIG, ent: dict, lits: list, out: int, incone: set[int],
                         touched, refs):
    """Expression of the NPN class circuit ``ent`` on leaf literals ``lits`` (output
    complemented by ``out``), reusing nodes of ``g`` outside ``incone``; also the
    number of new nodes it needs."""
    lits = list(lits)
    exprs: list = list(lits)
    new = 0
    for j, l, fj, fl, fo in ent["gates"]:
        a, b = lits[j], lits[l]
        r = None
        if a is not None and b is not None:
            r = g.lookup(a ^ fj, b ^ fl)
            if r is not None and ((r >> 1) in incone or touched[r >> 1] or refs[r >> 1] == 0):
                r = None
        if r is None:
            new += 1
            lits.append(None)
            exprs.append(("and", _neg(exprs[j], fj), _neg(exprs[l], fl), fo))
        else:
            lits.append(r ^ fo)
            exprs.append(r ^ fo)
    node, c_out = ent["out"]
    if node < 0:
        return c_out ^ out, new
    return _neg(exprs[node], c_out ^ out), new


def _place_cost(g: AIG, ent: dict, lits: list, incone: set[int], touched, refs, lev,
                threshold: int) -> tuple[int, int]:
    """``(new nodes, depth)`` of what :func:`_place_class_circuit` would build (the
    depth as :func:`_expr_depth` of its expression), without building it; the depth
    is only computed (else -1) when ``new <= threshold``."""
    lits = list(lits)
    new = 0
    lookup = g.lookup
    for j, l, fj, fl, fo in ent["gates"]:
        a, b = lits[j], lits[l]
        r = None
        if a is not None and b is not None:
            r = lookup(a ^ fj, b ^ fl)
            if r is not None and ((r >> 1) in incone or touched[r >> 1] or refs[r >> 1] == 0):
                r = None
        if r is None:
            new += 1
            lits.append(None)
        else:
            lits.append(r ^ fo)
    if new > threshold:
        return new, -1
    node, _c = ent["out"]
    if node < 0:
        return new, lev[0]
    # depth: a placed literal has its level, a new gate one more than its fanins'
    dep = [lev[x >> 1] for x in lits[:4]]
    for k, (j, l, _fj, _fl, _fo) in enumerate(ent["gates"]):
        x = lits[4 + k]
        dep.append(lev[x >> 1] if x is not None else 1 + max(dep[j], dep[l]))
    return new, dep[node]


CUT_LIMIT = 10
STRUCT_VARIANTS = True
# the passes' per-node work in numba (mlc.logic.kern; the same networks), on networks
# wider than TT_LIMIT inputs or of at least KERNEL_MIN_ANDS ANDs, and on any network
# once numba runs in the process: synthesising a small function in a process that never
# calls a kernel saves numba's start-up (0.4-0.5 s to load the cached kernels)
KERNELS = True
KERNEL_MIN_ANDS = 200


def _use_kernels(g: AIG) -> bool:
    if not KERNELS:
        return False
    if g.num_inputs > TT_LIMIT or len(g.ands) >= KERNEL_MIN_ANDS:
        return True
    kern = sys.modules.get("mlc.logic.kern")
    return kern is not None and kern.READY
ROUNDS_BIG = 30
# resub_window in the plain rounds of wide networks: 14-leaf cuts, windows of up to
# 300 nodes (was 10 and 150; with WIDE_TICK, EPFL i2c 1105 -> 1050, max 2860 -> 2795,
# priority 423 -> 387, router 159 -> 157; 12 leaves gave 1052 and 414 in the same
# time, 16 leaves 1050 and 384 in twice the time); the zero-gain rounds keep 10 and 150
WINDOW_LEAVES = 14
WINDOW_SIZE = 300
# resub_dc (windowed resubstitution with observability don't cares)
# fraig: work-clock tick per node visited (its SAT queries are few and cheap)
FRAIG_TICK = 0.25
FRAIG_BIG = True
FRAIG_EVERY = False
DC_BIG = True
DC_LEAVES = 14
DC_LEVELS = 3
DC_FANOUT = 12
DC_ROUND_MAX = 2000
DC_FIRST = False
DC_POLISH = 4
WINDOW_LEAVES_Z = 10
WINDOW_SIZE_Z = 150
# work-clock tick of resub_window and rewrite on wide networks (> TT_LIMIT inputs):
# their real cost per node visited is 0.15-0.22 of the usual tick on EPFL sin (0.78 s
# and 1.1 s CPU for 5.1 and 5.0 virtual s), so the budget stopped them after one
# round; at 0.25 sin gets 5149 -> 5089 ANDs (and takes 8 -> 19 s CPU)
WIDE_TICK = 0.25
STALE_BIG = 4


def rewrite(g: AIG, zero_gain: bool = False, deadline: float | None = None) -> AIG:
    """One pass of DAG-aware exact 4-cut rewriting."""
    from mlc.logic import npn
    n = g.num_inputs
    if not g.ands:
        return g
    if _use_kernels(g):
        return _rewrite_nb(g, zero_gain, deadline)
    tab = npn.table()
    refs = refcounts(g)
    cuts = enumerate_cuts(g, limit=CUT_LIMIT)
    lev = g.levels()
    tick = WIDE_TICK if n > TT_LIMIT else 1.0
    touched = bytearray(g.num_nodes)
    ps = _Pass(g, touched, refs, deadline, tick)
    for x in ps.nodes():
        best = None
        for c in cuts[x]:
            if len(c) < 2 or c == (x,):
                continue
            if any(touched[y] for y in c):
                continue
            cone = mffc(g, x, refs, set(c))
            if any(touched[y] for y in cone):
                continue
            f = cut_table(g, x, c)
            R = npn.canon(f)[0]
            ent = tab[R]
            if ent["ands"] > len(cone) or (ent["ands"] == len(cone) and not zero_gain):
                continue
            leaves = [2 * y for y in c] + [0] * (4 - len(c))
            incone = set(cone)
            seen_lits = set()
            for _R, perm, neg, out in (npn.canon_all(f) if STRUCT_VARIANTS else [npn.canon(f)]):
                lits = [leaves[perm[i]] ^ ((neg >> i) & 1) for i in range(4)]
                if (tuple(lits), out) in seen_lits:
                    continue
                seen_lits.add((tuple(lits), out))
                # a move must not lose nodes, nor tie without zero_gain, nor lose to best
                limit = len(cone) - (0 if zero_gain else 1)
                if best is not None:
                    limit = min(limit, len(cone) - best[0][0])
                new, dep = _place_cost(g, ent, lits, incone, touched, refs, lev, limit)
                if new > limit:
                    continue
                gain = len(cone) - new
                key = (gain, -dep)      # depth estimate as a tie-breaker
                if best is None or key > best[0]:
                    e, _new = _place_class_circuit(g, ent, lits, out, incone, touched, refs)
                    best = (key, e, cone)
        if best is None:
            continue
        if best[0][0] == 0 and best[0][1] <= -lev[x]:
            continue                       # zero gain must at least not worsen depth
        ps.replace(x, best[1], best[2])
    return ps.result()


def _rewrite_nb(g: AIG, zero_gain: bool, deadline: float | None) -> AIG:
    """:func:`rewrite` with its per-node work in :mod:`mlc.logic.kern` (the same moves)."""
    import numpy as np
    from mlc.logic import kern, npn
    n = g.num_inputs
    N = g.num_nodes
    tab = npn.table()
    fa, fb, _s, _l = kern.aig_arrays(g)
    refs = np.array(refcounts(g), dtype=np.int64)
    cl, cn, cc = kern.enumerate_cuts(fa, fb, n, N, 4, CUT_LIMIT)
    keys, hvals = kern.strash_table(fa, fb, n, N)
    lev = np.array(g.levels(), dtype=np.int64)
    lo, hi, perms, negs, ands, ngates, gates, out_node, out_c = kern.npn_arrays()
    canon, mstart, mcount, pool, top = kern.npn_match_cache()
    tick = WIDE_TICK if n > TT_LIMIT else 1.0
    touched = np.zeros(N, dtype=np.uint8)
    mark = np.zeros(N + 1, dtype=np.int8)
    vis = np.zeros(N + 1, dtype=np.int8)
    tv = np.zeros(N + 1, dtype=np.int64)
    buf = np.zeros((5, 2 * N + 4), dtype=np.int64)    # (MFFC decrements, DFS stack: <= 2N)
    res = np.zeros(8, dtype=np.int64)
    M = 2 * N + 2
    ps = _Pass(g, touched, refs, deadline, tick)
    for x in ps.nodes():
        kern.rewrite_node(x, fa, fb, n, refs, touched, lev, cl, cn, cc, keys, hvals, M,
                          zero_gain, lo, hi, perms, negs, ands, ngates, gates, out_node, out_c,
                          mark, tv, vis, buf, res, canon, mstart, mcount, pool, top)
        if not res[0]:
            continue
        cone = buf[1, :int(res[7])].tolist()
        lits = [int(v) for v in res[2:6]]
        e, _new = _place_class_circuit(g, tab[int(res[1])], lits, int(res[6]), set(cone),
                                       touched, refs)
        ps.replace(x, e, cone)
    return ps.result()


def _neg(e, c):
    if not c:
        return e
    if isinstance(e, int):
        return e ^ 1
    return (e[0], e[1], e[2], e[3] ^ 1)


def _expr_depth(e, lev) -> int:
    if isinstance(e, int):
        return lev[e >> 1]
    return 1 + max(_expr_depth(e[1], lev), _expr_depth(e[2], lev))


# ----------------------------------------------------------------------------- refactor
def reconv_cut(g: AIG, x: int, max_leaves: int) -> list[int]:
    """A reconvergence-driven cut of node ``x``: expand the leaf that adds fewest leaves."""
    n = g.num_inputs
    a, b = g.ands[x - n - 1]
    leaves = {a >> 1, b >> 1}
    leaves.discard(0)
    inside = {x}
    _expand_cut(g.ands, n, leaves, inside, max_leaves)
    return sorted(leaves)


def _expand_cut(ands, n: int, leaves: set[int], inside: set[int], max_leaves: int) -> None:
    """Grow a cut in place: move into ``inside`` the leaf whose fanins add fewest new
    leaves (the larger node on a tie) while the cut stays within ``max_leaves``."""
    both = leaves | inside           # = leaves | inside | {0} throughout
    both.add(0)
    while True:
        best, bcost = -1, 3
        for y in leaves:
            if y <= n:
                continue
            fa, fb = ands[y - n - 1]
            c = ((fa >> 1) not in both) + ((fb >> 1) not in both)
            if c < bcost or (c == bcost and y > best):
                best, bcost = y, c
        if best < 0 or len(leaves) + bcost - 1 > max_leaves:
            break
        leaves.discard(best)
        inside.add(best)
        fa, fb = ands[best - n - 1]
        for z in (fa >> 1, fb >> 1):
            if z and z not in inside:
                leaves.add(z)
                both.add(z)


def cone_table(g: AIG, node: int, leaves: list[int], k: int | None = None) -> int:
    """Truth table of ``node`` over ``leaves`` as ``k`` variables (default: one per leaf)."""
    k = len(leaves) if k is None else k
    full = T.mask(k)
    val = dict(zip(leaves, T.var_tables(k)[0]))
    ands = g.ands
    off = g.num_inputs + 1
    stack = [node]
    while stack:
        x = stack[-1]
        if x in val:
            stack.pop()
            continue
        a, b = ands[x - off]
        ya, yb = a >> 1, b >> 1
        va = val.get(ya)
        vb = val.get(yb)
        if va is None or vb is None:
            if va is None:
                stack.append(ya)
            if vb is None:
                stack.append(yb)
            continue
        stack.pop()
        val[x] = (va ^ full if a & 1 else va) & (vb ^ full if b & 1 else vb)
    return val[node]


def _aig_to_expr(s: AIG, leaf_lits: list[int]):
    """Expression (see :func:`rebuild`) of the single output of scratch AIG ``s``."""
    n = s.num_inputs
    ex: dict[int, object] = {0: 0}
    for i in range(n):
        ex[i + 1] = leaf_lits[i]
    for k, (a, b) in enumerate(s.ands):
        ea = ex[a >> 1]
        eb = ex[b >> 1]
        ex[n + 1 + k] = ("and", _neg(ea, a & 1), _neg(eb, b & 1), 0)
    lit = s.output_lits[0]
    return _neg(ex[lit >> 1], lit & 1)


def _dag_expr(g: AIG, s: AIG, leaf_lits: list[int], incone: set[int], touched, refs):
    """Expression of the single output of scratch AIG ``s`` over ``leaf_lits`` of
    ``g``, reusing the nodes of ``g`` that already compute a sub-expression (structural
    hashing, outside the cone being replaced); also the number of new nodes needed."""
    n = s.num_inputs
    ex: dict[int, object] = {0: 0}
    for i in range(n):
        ex[i + 1] = leaf_lits[i]
    new = 0
    for k, (a, b) in enumerate(s.ands):
        ea = _neg(ex[a >> 1], a & 1)
        eb = _neg(ex[b >> 1], b & 1)
        r = None
        if isinstance(ea, int) and isinstance(eb, int):
            r = g.lookup(ea, eb)
            if r is not None and r > 1 and ((r >> 1) in incone or touched[r >> 1]
                                            or refs[r >> 1] == 0):
                r = None
        if r is None:
            new += 1
            ex[n + 1 + k] = ("and", ea, eb, 0)
        else:
            ex[n + 1 + k] = r
    lit = s.output_lits[0]
    return _neg(ex[lit >> 1], lit & 1), new


def refactor(g: AIG, max_leaves: int = 8, zero_gain: bool = False,
             deadline: float | None = None) -> AIG:
    """Collapse the cone of each node over a reconvergence-driven cut of up to
    ``max_leaves`` leaves and resynthesise it by decomposition (exact below 5
    variables); replace when it frees more nodes than it adds."""
    from mlc.logic.decomp import _Dec
    n = g.num_inputs
    if not g.ands:
        return g
    refs = refcounts(g)
    touched = bytearray(g.num_nodes)
    ps = _Pass(g, touched, refs, deadline)
    decs: dict[int, _Dec] = {}
    # scratch AIG of each plan built in this pass (a plan is the memoised answer of
    # _Dec.rec for one function; building it again gives the same AIG and adds nothing
    # to the _Dec's available functions), by cut size and plan: the constant plans are
    # one object shared by the _Decs of all cut sizes
    scratch: dict[tuple[int, int], AIG] = {}
    lev = None
    kernels = _use_kernels(g) and max_leaves <= 14
    if kernels:
        from mlc.logic import kern
        fa, fb, _s, _l = kern.aig_arrays(g)
        ws = kern.Workspace(g.num_nodes, 6)
    for x in ps.nodes(range(g.num_nodes - 1, n, -1)):      # outputs first: large cones
        if kernels:
            leaves = kern.reconv_cut_py(fa, fb, n, x, max_leaves, ws.mark, ws.buf[0],
                                        ws.buf[1]).tolist()
        else:
            leaves = reconv_cut(g, x, max_leaves)
        if len(leaves) < 3 or any(touched[y] for y in leaves):
            continue
        cone = mffc(g, x, refs, set(leaves))
        if len(cone) < 3 or any(touched[y] for y in cone):
            continue
        k = len(leaves)
        f = cone_table(g, x, leaves)
        d = decs.get(k)
        if d is None:
            d = decs[k] = _Dec(k, 2)
        _, plan = d.rec(f, T.mask(k))
        s = scratch.get((k, id(plan)))
        if s is None:
            s = AIG([f"l{i}" for i in range(k)])
            s.add_output("f", d.build(s, plan))
            s = scratch[k, id(plan)] = s.cleanup()
        e, new = _dag_expr(g, s, [2 * y for y in leaves], set(cone), touched, refs)
        if new > len(cone) or (new == len(cone) and not zero_gain):
            continue
        if new == len(cone):
            if lev is None:
                lev = g.levels()
            if _expr_depth(e, lev) >= lev[x]:
                continue
        ps.replace(x, e, cone)
    return ps.result()


# ----------------------------------------------------------------------------- balance
class _Rebuild:
    """A new AIG over ``g``'s inputs, built node by node with the level of every new
    node tracked (for the balancing passes): ``m[x]`` is the new literal of old node ``x``."""

    def __init__(self, g: AIG):
        self.g = g
        self.n = g.num_inputs
        self.h = AIG(g.inputs)
        self.m = [0] * g.num_nodes
        for i in range(1, self.n + 1):
            self.m[i] = 2 * i
        self.lev: dict[int, int] = {}

    def level(self, lit: int) -> int:
        return self.lev.get(lit >> 1, 0)

    def lit(self, old: int) -> int:
        """The new literal of an old literal."""
        return self.m[old >> 1] ^ (old & 1)

    def _new(self, r: int, depth: int) -> int:
        if (r >> 1) not in self.lev and (r >> 1) > self.n:
            self.lev[r >> 1] = depth
        return r

    def and_(self, a: int, b: int) -> int:
        return self._new(self.h.and_(a, b), 1 + max(self.level(a), self.level(b)))

    def xor_(self, a: int, b: int) -> int:
        return self._new(self.h.xor_(a, b), 2 + max(self.level(a), self.level(b)))

    def finish(self) -> AIG:
        for name, lit in zip(self.g.outputs, self.g.output_lits):
            self.h.add_output(name, self.lit(lit))
        return self.h.cleanup()


def balance(g: AIG) -> AIG:
    """AND-tree balancing: collapse single-fanout, uncomplemented AND trees into
    multi-input ANDs and rebuild them pairing the shallowest operands first."""
    n = g.num_inputs
    refs = refcounts(g)
    R = _Rebuild(g)
    for k, (a, b) in enumerate(g.ands):
        x = n + 1 + k
        # collect the super-gate leaves
        leaves = []
        stack = [a, b]
        while stack:
            lit = stack.pop()
            y = lit >> 1
            if not (lit & 1) and y > n and refs[y] == 1 and len(leaves) + len(stack) < 16:
                stack.extend(g.ands[y - n - 1])
            else:
                leaves.append(R.lit(lit))
        leaves = list(dict.fromkeys(leaves))
        if any((l ^ 1) in leaves for l in leaves):
            R.m[x] = 0
            continue
        while len(leaves) > 1:
            leaves.sort(key=R.level)
            leaves = leaves[2:] + [R.and_(leaves[0], leaves[1])]
        R.m[x] = leaves[0] if leaves else 1
    return R.finish()


def extract_and(g: AIG, max_leaves: int = 16) -> AIG:
    """AND-tree regrouping for sharing: collapse single-fanout, uncomplemented AND
    trees into multi-input ANDs (as :func:`balance`), then repeatedly build first the
    pair of operands that most of these ANDs have in common (greedy, ties broken by
    the literals' order; deterministic), so that the pair is one shared node; the rest
    of each AND is paired shallowest first.  Never adds nodes to the collapsed form;
    used on restart starting points (every other -O3 restart; every other one of the
    12 extra -O2 restarts), where it opens sharing that resubstitution and rewriting
    then exploit (3-bit comparator: 14 -> 13 ANDs)."""
    n = g.num_inputs
    refs = refcounts(g)
    absorbed = bytearray(g.num_nodes)
    uses_un = [0] * g.num_nodes
    for a, b in g.ands:
        for lit in (a, b):
            if not lit & 1:
                uses_un[lit >> 1] += 1
    for y in range(n + 1, g.num_nodes):
        if refs[y] == 1 and uses_un[y] == 1 and (2 * y) not in g.output_lits:
            absorbed[y] = 1
    roots = {}
    # from the outputs down, so that a node left unexpanded at the leaf limit is
    # made a root before it is reached
    for y in range(g.num_nodes - 1, n, -1):
        if absorbed[y]:
            continue
        leaves = []
        stack = list(g.ands[y - n - 1])
        while stack:
            lit = stack.pop()
            z = lit >> 1
            if not (lit & 1) and z > n and absorbed[z] and len(leaves) + len(stack) < max_leaves:
                stack.extend(g.ands[z - n - 1])
            else:
                if z > n and absorbed[z]:
                    absorbed[z] = 0
                leaves.append(lit)
        roots[y] = set(leaves)
    virt = _extract_pairs(roots)
    R = _Rebuild(g)
    memo = {}

    def lit_of(l):
        if isinstance(l, tuple):
            if l not in memo:
                u, w = virt[l[1]]
                memo[l] = R.and_(lit_of(u), lit_of(w))
            return memo[l]
        return R.lit(l)

    for y in range(n + 1, g.num_nodes):
        if absorbed[y]:
            continue
        ls = [lit_of(l) for l in sorted(roots[y], key=repr)]
        ls = list(dict.fromkeys(ls))
        if any((l ^ 1) in ls for l in ls):
            R.m[y] = 0
            continue
        while len(ls) > 1:
            ls.sort(key=R.level)
            ls = ls[2:] + [R.and_(ls[0], ls[1])]
        R.m[y] = ls[0] if ls else 1
    return R.finish()


def _extract_pairs(roots: dict) -> list:
    """:func:`extract_and`'s greedy pair extraction on the operand sets ``roots``
    (changed in place): while some pair of operands is in two or more sets, the pair
    in most sets (ties: the greatest ``repr``) becomes a pseudo-literal ``("v", i)``
    replacing it in every set that has both; returns the pairs, ``virt[i] = (u, w)``.
    A pair is ordered by ``repr``; the counts of all pairs are kept up to date as
    pairs are extracted (bucketed by count) instead of recounted every step."""
    cnt: dict = {}
    byc: dict[int, set] = {}          # count -> the pairs with that count
    rep: dict = {}

    def r(x):
        t = rep.get(x)
        if t is None:
            t = rep[x] = repr(x)
        return t

    def bump(a, b, d: int) -> None:
        p = (a, b) if r(a) <= r(b) else (b, a)
        c = cnt.get(p, 0)
        if c:
            byc[c].discard(p)
        c += d
        if c:
            cnt[p] = c
            byc.setdefault(c, set()).add(p)
        else:
            del cnt[p]

    for s in roots.values():
        ls = list(s)
        for i in range(len(ls)):
            for j in range(i + 1, len(ls)):
                bump(ls[i], ls[j], 1)
    virt = []
    while True:
        top = max((c for c, ps in byc.items() if ps), default=0)
        if top < 2:
            break
        p = max(byc[top], key=repr)
        v = ("v", len(virt))
        virt.append(p)
        a, b = p
        for s in roots.values():
            if a in s and b in s:
                s.discard(a)
                s.discard(b)
                bump(a, b, -1)
                for o in s:
                    bump(a, o, -1)
                    bump(b, o, -1)
                    bump(v, o, 1)
                s.add(v)
    return virt


def _xor_gadget(g: AIG, x: int):
    """``(u, v)`` if node ``x`` computes ``u XOR v`` as ``!(u & v) & !(!u & !v)``."""
    n = g.num_inputs
    if x <= n:
        return None
    a, b = g.ands[x - n - 1]
    if not (a & 1 and b & 1):
        return None
    p, q = a >> 1, b >> 1
    if p <= n or q <= n:
        return None
    pa, pb = g.ands[p - n - 1]
    qa, qb = g.ands[q - n - 1]
    if {pa ^ 1, pb ^ 1} == {qa, qb}:
        return (pa, pb, p, q)
    return None


def balance_xor(g: AIG) -> AIG:
    """Rebuild XOR trees (chains of 3-AND XOR gadgets with no other fanout) as
    balanced trees: the same number of ANDs, less depth."""
    n = g.num_inputs
    refs = refcounts(g)
    gad = {}
    for x in range(n + 1, g.num_nodes):
        r = _xor_gadget(g, x)
        if r is not None:
            gad[x] = r
    if not gad:
        return g

    def absorbable(y: int) -> bool:
        r = gad.get(y)
        return r is not None and refs[y] == 2 and refs[r[2]] == 1 and refs[r[3]] == 1

    R = _Rebuild(g)
    for k, (a, b) in enumerate(g.ands):
        x = n + 1 + k
        r = gad.get(x)
        if r is None:
            R.m[x] = R.and_(R.lit(a), R.lit(b))
            continue
        leaves, par = [], 0
        stack = [r[0], r[1]]
        while stack:
            lit = stack.pop()
            y = lit >> 1
            if absorbable(y) and len(leaves) + len(stack) < 32:
                par ^= lit & 1
                stack.extend(gad[y][:2])
            else:
                nl = R.lit(lit)
                par ^= nl & 1
                leaves.append(nl & ~1)
        if len(leaves) <= 2:
            R.m[x] = R.and_(R.lit(a), R.lit(b))
            continue
        while len(leaves) > 1:
            leaves.sort(key=R.level)
            leaves = leaves[2:] + [R.xor_(leaves[0], leaves[1])]
        # the gadget's node value is u ^ v (uncomplemented)
        R.m[x] = leaves[0] ^ par
    return R.finish()


# ----------------------------------------------------------------------------- initial
def _filled(spec: TableSpec, mode: str) -> TableSpec:
    """``spec`` with its don't cares assigned: by the ISOP cover, to 0 or to 1."""
    full = T.mask(spec.n)
    on = []
    for f, d in zip(spec.on, spec.dc):
        if mode == "isop":
            _, cov = T.isop(f & full, (f | d) & full, spec.n)
            on.append(cov)
        elif mode == "one":
            on.append((f | d) & full)
        else:
            on.append(f & full)
    return TableSpec(list(spec.inputs), list(spec.outputs), on, [0] * len(on), spec.source)


def _two_level(spec: TableSpec) -> AIG:
    """Each output as its ISOP (of the interval [on, on|dc]): balanced ANDs of
    literals ORed by a balanced tree, cubes shared between outputs."""
    n = spec.n
    full = T.mask(n)
    g = AIG(spec.inputs)
    for name, on, dc in zip(spec.outputs, spec.on, spec.dc):
        cubes, _ = T.isop(on & full, (on | dc) & full, n)
        terms = []
        for p, q in cubes:
            lits = [2 * (i + 1) for i in range(n) if (p >> i) & 1]
            lits += [2 * (i + 1) + 1 for i in range(n) if (q >> i) & 1]
            terms.append(g.and_many(lits))
        g.add_output(name, g.or_many(terms) if terms else 0)
    return g.cleanup()


def initial_candidates(spec, effort: int) -> list[AIG]:
    big_table = isinstance(spec, TableSpec) and spec.n >= 9 and effort >= 1
    # (for wide tables the decomposition's SOP step subsumes the plain lowering)
    cands = [] if big_table else [from_spec(spec)]
    if effort >= 1 and isinstance(spec, TableSpec):
        from mlc.logic import decomp
        cands.append(decomp.from_table(spec, effort))
        if effort >= 2 and any(spec.dc) and spec.n <= 10:
            # other don't-care assignments: sharing between outputs may prefer them;
            # the passes still see the don't cares (resubstitution at the outputs)
            for mode in ("isop", "zero", "one"):
                cands.append(decomp.from_table(_filled(spec, mode), effort))
    if effort >= 2 and isinstance(spec, TableSpec) and spec.n <= 8 and len(spec.outputs) > 1:
        # the two-level form (cubes shared between outputs by structural hashing):
        # unfactored, it leaves the passes more to share (comparators)
        cands.append(_two_level(spec))
    if effort >= 1 and isinstance(spec, NetworkSpec) and len(spec.inputs) <= 12:
        # collapse to tables and decompose: finds structure the network hides
        from mlc.logic import decomp
        from mlc.logic.equiv import spec_tables
        on, dc = spec_tables(spec)
        ts = TableSpec(list(spec.inputs), list(spec.outputs), on, dc, spec.source)
        cands.append(decomp.from_table(ts, effort))
    return cands


def _care(spec) -> list[int] | None:
    n = len(spec.inputs)
    if n > TT_LIMIT:
        return None
    full = T.mask(n)
    dc = spec.dc if spec.dc else None
    if not dc or not any(dc):
        return None
    return [full & ~d for d in dc]


def improve(g: AIG, effort: int, care, deadline: float) -> AIG:
    """Iterate the passes until a round brings no improvement."""
    best = g
    rounds = {0: 0, 1: 2, 2: 6, 3: 20}[effort]
    big = effort >= 2 and g.num_inputs > TT_LIMIT
    if big:
        rounds = ROUNDS_BIG
    stale = 0
    walk = g
    # big networks: zero-gain moves from the start on small ones, else once the plain
    # rounds stall (measured: router 228 -> 212, priority 552 -> 443)
    explore = big and g.num_ands() < 500
    for r in range(rounds):
        if work.now(best.num_nodes) > deadline:
            break
        cur = walk if big else best
        if big and EXTRACT_BIG and stale > 0:
            # regroup AND trees for sharing before the round's passes (router 189 -> 179
            # in three rounds of sweep/resub/rewrite/refactor after it)
            cur = extract_and(cur)
        if cur.num_inputs > TT_LIMIT and effort >= 2 and FRAIG_BIG and (r == 0 or FRAIG_EVERY):
            cur = fraig(cur, deadline=deadline)
        else:
            cur = sweep(cur)
        if cur.num_inputs > TT_LIMIT:
            if DC_FIRST and effort >= 2 and DC_BIG and cur.num_ands() <= DC_ROUND_MAX:
                cur = resub_dc(cur, deadline=deadline)
            cur = resub_window(cur, max_new=1 if effort == 1 else 2, deadline=deadline)
            if not DC_FIRST and effort >= 2 and DC_BIG and cur.num_ands() <= DC_ROUND_MAX:
                cur = resub_dc(cur, deadline=deadline)
        cur = resub(cur, care, max_new=1 if effort == 1 else 2, deadline=deadline)
        if effort >= 2:
            cur = rewrite(cur, deadline=deadline)
            cur = resub(cur, care, max_new=2, deadline=deadline)
            rf = refactor(cur, deadline=deadline)
            if cost(rf) < cost(cur):
                cur = rf
            od = resub_odc(cur, care, deadline=deadline, max_moves=10 if effort == 2 else 50)
            if cost(od) < cost(cur):
                cur = resub(od, care, max_new=2, deadline=deadline)
            if effort >= 3 or explore:
                cur = rewrite(cur, zero_gain=True, deadline=deadline)
                cur = resub(cur, care, max_new=2, deadline=deadline)
            if explore:
                # compress2rs-like: zero-gain restructuring over wider cuts opens
                # moves for the next round (router 242 -> 231)
                cur = refactor(cur, max_leaves=10, zero_gain=True, deadline=deadline)
                cur = resub_window(cur, max_leaves=WINDOW_LEAVES_Z, max_window=WINDOW_SIZE_Z,
                                   max_new=2, deadline=deadline)
                cur = rewrite(cur, zero_gain=True, deadline=deadline)
        b = balance(cur)
        if cost(b) <= cost(cur):
            cur = b
        b = balance(balance_xor(cur))
        if cost(b) <= cost(cur):
            cur = b
        if big:
            # keep walking from the zero-gain result; stop after 2 rounds without gain
            walk = cur
            if cost(cur) < cost(best):
                best, stale = cur, 0
            else:
                stale += 1
                if stale >= STALE_BIG + (not explore):
                    break
                explore = True
            continue
        if cost(cur) < cost(best):
            best = cur
        else:
            if effort >= 3 and r < rounds - 1:
                # perturb: renumber in a random DFS order and try again
                cur2 = reorder(best, random.Random(r))
                cur2 = rewrite(resub(cur2, care, deadline=deadline), deadline=deadline)
                if cost(cur2) < cost(best):
                    best = cur2
                    continue
            break
    if big and DC_BIG:
        # don't-care polish (any size; the only use on networks above DC_ROUND_MAX):
        # AND-tree regrouping, SAT sweeping and resub_dc while they gain (at most
        # DC_POLISH times; sin's rounds all gain until the budget ends them, so
        # extract_and, which the rounds use only after one without gain, never ran:
        # 5034 -> 4953 ANDs from it here)
        for _ in range(DC_POLISH):
            d = best
            if EXTRACT_BIG:
                e = extract_and(d)
                if e.num_ands() < d.num_ands():
                    d = e
            d = resub_dc(fraig(d) if FRAIG_BIG else d)
            if cost(d) < cost(best):
                best = d
            else:
                break
    if effort >= 2:
        # depth polish: zero-gain rewrites that shorten paths, then balancing
        for _ in range(3):
            if work.now(best.num_nodes) > deadline:
                break
            d = balance(balance_xor(rewrite(best, zero_gain=True, deadline=deadline)))
            d2 = balance(refactor(best, zero_gain=True, deadline=deadline))
            d = min(d, d2, key=cost)
            if cost(d) < cost(best):
                best = d
            else:
                break
    return best


CANON_NETWORK_INPUTS = 12
EXTRACT_BIG = True
# -O2 restarts after the plain ones (tables of <= 8 inputs), every O2_MOD-th from the
# start regrouped by extract_and: 3-bit comparator 14 -> 13 (the 16th restart), the
# random 7-input functions 53 -> 52 and 34 -> 32; no function of the suite worse
O2_EXTRA = 12
O2_MOD = 2


@contextmanager
def _no_full_gc():
    """Python's full (oldest-generation) garbage collections held off, the young
    generations still collected; the thresholds restored after.  A full collection
    walks every container alive, and the optimisation keeps hundreds of thousands
    in its caches (the decomposition's memos): on the EPFL circuits the full
    collections took 9-12 % of the optimisation's CPU time (sin 0.64 of 7.3 s, i2c
    0.28 of 2.4 s).  Nothing computed depends on when garbage is freed."""
    t = gc.get_threshold()
    gc.set_threshold(t[0], t[1], 10 ** 9)
    try:
        yield
    finally:
        gc.set_threshold(*t)


def optimize(spec, effort: int, time_budget: float | None = None) -> AIG:
    """Best AIG for ``spec`` at ``effort``.  ``time_budget`` is in seconds of the
    deterministic work clock (:mod:`mlc.logic.work`), so the result never depends on
    the machine's load.

    Tables (up to :data:`canon.MAX_INPUTS` inputs) and networks of up to
    :data:`CANON_NETWORK_INPUTS` inputs are first put into their canonical input and
    output order (:mod:`mlc.logic.canon`), so the result does not depend on how the
    specification lists them; the circuit is mapped back to the given order.  Full
    garbage collections wait until the end (:func:`_no_full_gc`)."""
    with _no_full_gc():
        return _optimize_spec(spec, effort, time_budget)


def _optimize_spec(spec, effort: int, time_budget: float | None = None) -> AIG:
    from mlc.io.progress import stage
    from mlc.logic import canon
    stage("decomposing")
    n = len(spec.inputs)
    if isinstance(spec, TableSpec) and 0 < n <= canon.MAX_INPUTS:
        c = canon.canonical(spec)
        g = _optimize(c.spec, effort, time_budget)
        return canon.restore(g, c, spec)
    if isinstance(spec, NetworkSpec) and 0 < n <= CANON_NETWORK_INPUTS:
        from mlc.logic.equiv import spec_tables
        on, dc = spec_tables(spec)
        c = canon.canonical(TableSpec(list(spec.inputs), list(spec.outputs), on, dc, spec.source))
        structural = canon.to_canonical(from_spec(spec), c)
        g = _optimize(c.spec, effort, time_budget, [structural])
        return canon.restore(g, c, spec)
    return _optimize(spec, effort, time_budget)


def _optimize(spec, effort: int, time_budget: float | None = None,
              extra: list[AIG] | None = None) -> AIG:
    work.reset()
    t0 = work.now()
    default_budget = time_budget is None
    if time_budget is None:
        n = len(spec.inputs)
        # -O2 answers within a second up to 4 inputs, two up to 8 (the extract_and
        # restarts), under a second at 9-10, a few seconds at 16
        o2 = (1.0 if n <= 4 else 2.0 if n <= 8 else 0.6) + 0.8 * max(0, min(n, 20) - 10)
        time_budget = {0: 1.0, 1: 0.5, 2: o2,
                       3: 5.0 + 2.0 * max(0, min(n, 20) - 10)}[effort]
    cands = initial_candidates(spec, effort) + list(extra or [])
    if effort == 0:
        return min(cands, key=cost)
    if effort == 2 and default_budget and len(spec.inputs) > TT_LIMIT:
        # large networks: the work clock's ticks grow with the network, so a fixed
        # budget leaves few passes; add 3 s per 1000 ANDs (at most 16 s; measured on
        # EPFL: sin 5275 -> 5149, i2c 1133 -> 1093 ANDs for 25 s in all)
        time_budget += min(16.0, 3.0 * min(c.num_ands() for c in cands) / 1000.0)
    from mlc.io.progress import stage
    stage("improving", lambda: (work._ticks * 1e-6 - t0) / time_budget)    # the work clock against the budget
    care = _care(spec)
    results = []
    cands.sort(key=cost)
    for i, c in enumerate(cands):
        left = t0 + time_budget - work.now()
        deadline = work.now() + max(0.0, left) / (len(cands) - i)
        results.append(improve(c, effort, care, deadline))
    best = min(results, key=cost)
    n = len(spec.inputs)
    exact = effort >= 3 and (n <= 4 or (n == 5 and best.num_ands() <= 9))
    if effort >= 2 and 2 <= n <= TT_LIMIT:
        best = _restarts(spec, effort, care, best, t0 + time_budget, time_budget,
                         8 if exact else None)
    if exact:
        from mlc.logic import exact_multi
        e = exact_multi.try_exact(spec, best, t0 + time_budget)
        if e is not None and cost(e) < cost(best):
            best = e
    if effort >= 2 and isinstance(spec, TableSpec):
        from mlc.logic import cofexact
        if n == cofexact.INPUTS:
            # -O2: the deterministic part only (cofactors by the -O2 flow, no SAT)
            limit = cofexact.TIME_LIMIT if default_budget else min(cofexact.TIME_LIMIT, time_budget)
            e = cofexact.try_cofactor_exact(spec, best, limit, sat=effort >= 3)
            if e is not None:
                e = improve(e, effort, care, work.now() + 1.0)
                if cost(e) < cost(best):
                    best = e
    return best


def _restarts(spec, effort: int, care, best: AIG, end: float, time_budget: float,
              cap: int | None = None) -> AIG:
    """Restarts: decompositions of the specification listed in random orders of its
    inputs and outputs (fixed seed) with a randomised Shannon choice, each mapped back
    to the given order and improved; the best network is kept.  -O2 does a fixed
    number (deterministic unless the budget runs out): 8 (up to 4 inputs) or 4 (5..8
    inputs) plain ones, then :data:`O2_EXTRA` more of which every other one starts
    from the decomposition regrouped by :func:`extract_and` (the plain ones come
    first, so the result is never worse than without the extra ones); -O3 runs until
    25 restarts in a row bring nothing or the budget is spent."""
    from mlc.logic import canon, decomp
    from mlc.logic.equiv import spec_tables
    n = len(spec.inputs)
    if isinstance(spec, TableSpec):
        ts = spec
    else:
        on, dc = spec_tables(spec)
        ts = TableSpec(list(spec.inputs), list(spec.outputs), on, dc, spec.source)
    rng = random.Random(12345)
    stale = 0
    restarts = 0
    base = 0
    if effort == 2:
        base = 8 if n <= 4 else 4 if n <= 8 else 0
        max_restarts = base + (O2_EXTRA if n <= 8 else 0)
    else:
        max_restarts = 10 ** 9
    if cap is not None:
        max_restarts = min(max_restarts, cap)
    m = len(ts.outputs)
    while work.now(best.num_nodes) < end and stale < 25 and restarts < max_restarts:
        restarts += 1
        pi, po = list(range(n)), list(range(m))
        rng.shuffle(pi)
        rng.shuffle(po)
        ps = canon.permuted(ts, pi, po)
        c = decomp.from_table(ps, effort, rng)
        c = canon.restore(c, canon.Canon(ps, pi, po, True), ts)
        if (effort >= 3 and restarts % 2 == 0) or (effort == 2 and restarts > base
                                                      and (restarts - base) % O2_MOD == 0):
            c = extract_and(c)
        step_end = min(end, work.now() + max(0.5, 0.2 * time_budget))
        c = improve(c, effort, care, step_end)
        if cost(c) < cost(best):
            best = c
            stale = 0
        else:
            stale += 1
    return best
