"""numba kernels of the windowed passes of :mod:`mlc.logic.opt` over array AIGs.

The network is given as arrays indexed by node (``fa[y]``, ``fb[y]``: the fanin
literals of AND node ``y``, -1 for inputs and the constant; ``fo_start``/``fo_list``:
the fanouts of each node in increasing order, CSR) and a window's truth tables as
rows of a ``uint64`` matrix (``W`` words per table; bit ``m`` of a table is its value
on minterm ``m`` of the window's leaves, as in :mod:`mlc.logic.tt`).  Each kernel
does exactly what the Python code it replaces did, in the same order (the same
networks come out); :mod:`mlc.logic.opt` keeps the Python versions as the reference
(``tests/test_logic_kern.py`` compares them).

Kernels are compiled on first use and cached on disk (``cache=True``).
"""
from __future__ import annotations

import numpy as np
from numba import njit

ONES = np.uint64(0xFFFFFFFFFFFFFFFF)
ZERO = np.uint64(0)
_VARW = np.array([0xAAAAAAAAAAAAAAAA, 0xCCCCCCCCCCCCCCCC, 0xF0F0F0F0F0F0F0F0,
                  0xFF00FF00FF00FF00, 0xFFFF0000FFFF0000, 0xFFFFFFFF00000000], dtype=np.uint64)
MAX_LEAVES = 14


# set once a kernel has run in this process (numba's start-up paid): from then on
# npn.canon uses canon_index too
READY = False


def aig_arrays(g):
    """``(fa, fb, fo_start, fo_list)`` of AIG ``g`` (see the module docstring)."""
    global READY
    READY = True
    N = g.num_nodes
    n = g.num_inputs
    fa = np.full(N, -1, dtype=np.int64)
    fb = np.full(N, -1, dtype=np.int64)
    if g.ands:
        arr = np.array(g.ands, dtype=np.int64).reshape(-1, 2)
        fa[n + 1:] = arr[:, 0]
        fb[n + 1:] = arr[:, 1]
    fo_start, fo_list = _fanouts(fa, fb, n, N)
    return fa, fb, fo_start, fo_list


@njit(cache=True)
def _fanouts(fa, fb, n, N):
    cnt = np.zeros(N + 1, dtype=np.int64)
    for y in range(n + 1, N):
        a = fa[y] >> 1
        b = fb[y] >> 1
        cnt[a + 1] += 1
        if b != a:
            cnt[b + 1] += 1
    for i in range(N):
        cnt[i + 1] += cnt[i]
    lst = np.zeros(cnt[N], dtype=np.int64)
    pos = cnt[:N].copy()
    for y in range(n + 1, N):
        a = fa[y] >> 1
        b = fb[y] >> 1
        lst[pos[a]] = y
        pos[a] += 1
        if b != a:
            lst[pos[b]] = y
            pos[b] += 1
    return cnt, lst


class Workspace:
    """Scratch arrays of the kernels for a network of ``N`` nodes (allocated once per pass)."""

    # table rows allocated at first (a window needs at most its leaves, inside nodes and
    # max_window more; the kernels answer -2 when a window may not fit, and the caller
    # calls grow() and retries the node)
    ROWS = 2048

    def __init__(self, N: int, max_leaves: int = MAX_LEAVES):
        wmax = max(1, (1 << max_leaves) // 64)
        self.tabs = np.zeros((min(N + 2, self.ROWS), wmax), dtype=np.uint64)
        self.slot = np.full(N + 1, -1, dtype=np.int64)
        self.ids = np.zeros(N + 2, dtype=np.int64)
        self.mark = np.zeros(N + 1, dtype=np.int8)
        self.seen = np.zeros(N + 1, dtype=np.int8)
        # (2N: an MFFC records up to two decrements per node, a DFS stack two per level)
        self.buf = np.zeros((8, 2 * N + 4), dtype=np.int64)
        self.vec = np.zeros((8, wmax), dtype=np.uint64)
        self.out = np.zeros(6, dtype=np.int64)

    def grow(self) -> None:
        """Twice the table rows (at most one per node and two more)."""
        rows = min(2 * self.tabs.shape[0], self.slot.shape[0] + 1)
        self.tabs = np.zeros((rows, self.tabs.shape[1]), dtype=np.uint64)


# ----------------------------------------------------------------------------- helpers

@njit(cache=True, inline="always")
def _popcount(x):
    x = x - ((x >> np.uint64(1)) & np.uint64(0x5555555555555555))
    x = (x & np.uint64(0x3333333333333333)) + ((x >> np.uint64(2)) & np.uint64(0x3333333333333333))
    x = (x + (x >> np.uint64(4))) & np.uint64(0x0F0F0F0F0F0F0F0F)
    return (x * np.uint64(0x0101010101010101)) >> np.uint64(56)


@njit(cache=True)
def expand_cut(fa, fb, n, mark, leaves, nl, inside, ni, max_leaves):
    """:func:`mlc.logic.opt._expand_cut` on arrays: ``leaves[:nl]`` (``mark`` 1) and
    ``inside[:ni]`` (``mark`` 2) grown in place; returns ``(nl, ni)``."""
    while True:
        best = -1
        bcost = 3
        bt = -1
        for t in range(nl):
            y = leaves[t]
            if y <= n:
                continue
            za = fa[y] >> 1
            zb = fb[y] >> 1
            c = 0
            if za != 0 and mark[za] == 0:
                c += 1
            if zb != 0 and mark[zb] == 0:
                c += 1
            if c < bcost or (c == bcost and y > best):
                best = y
                bcost = c
                bt = t
        if best < 0 or nl + bcost - 1 > max_leaves:
            break
        nl -= 1
        leaves[bt] = leaves[nl]
        mark[best] = 2
        inside[ni] = best
        ni += 1
        for z in (fa[best] >> 1, fb[best] >> 1):
            if z != 0 and mark[z] != 2:
                if mark[z] != 1:
                    mark[z] = 1
                    leaves[nl] = z
                    nl += 1
    return nl, ni


@njit(cache=True)
def reconv_cut(fa, fb, n, x, max_leaves, mark, leaves, inside):
    """:func:`mlc.logic.opt.reconv_cut`: the sorted leaves into ``leaves``, their count
    returned; ``mark`` is left clear."""
    nl = 0
    for z in (fa[x] >> 1, fb[x] >> 1):
        if z != 0 and mark[z] == 0:
            mark[z] = 1
            leaves[nl] = z
            nl += 1
    mark[x] = 2
    inside[0] = x
    nl, ni = expand_cut(fa, fb, n, mark, leaves, nl, inside, 1, max_leaves)
    for t in range(nl):
        mark[leaves[t]] = 0
    for t in range(ni):
        mark[inside[t]] = 0
    leaves[:nl].sort()
    return nl


@njit(cache=True)
def reconv_cut_py(fa, fb, n, x, max_leaves, mark, leaves, inside):
    nl = reconv_cut(fa, fb, n, x, max_leaves, mark, leaves, inside)
    return leaves[:nl].copy()


@njit(cache=True)
def mffc(fa, fb, n, x, refs, leafmark, out, stack, dec):
    """:func:`mlc.logic.opt.mffc` (nodes into ``out``, their count returned); leaves
    are the nodes with ``leafmark == 1``; ``refs`` is left unchanged."""
    no = 1
    out[0] = x
    ns = 1
    stack[0] = x
    nd = 0
    while ns > 0:
        ns -= 1
        y0 = stack[ns]
        for f in (fa[y0], fb[y0]):
            y = f >> 1
            if y <= n or leafmark[y] == 1:
                continue
            refs[y] -= 1
            dec[nd] = y
            nd += 1
            if refs[y] == 0:
                out[no] = y
                no += 1
                stack[ns] = y
                ns += 1
    for t in range(nd):
        refs[dec[t]] += 1
    return no


@njit(cache=True)
def set_leaves(tabs, W, k, full, leaves, slot, ids):
    """Rows 0..k-1: the variable tables of ``leaves[:k]``; ``full`` gets the all-ones table."""
    for w in range(W):
        full[w] = ONES
    if k < 6:
        full[0] = (np.uint64(1) << np.uint64(1 << k)) - np.uint64(1)
    for i in range(k):
        if i < 6:
            v = _VARW[i]
            for w in range(W):
                tabs[i, w] = v & full[w]
        else:
            s = i - 6
            for w in range(W):
                tabs[i, w] = ONES if (w >> s) & 1 else ZERO
        slot[leaves[i]] = i
        ids[i] = leaves[i]


@njit(cache=True, inline="always")
def _and_row(tabs, W, full, r, ra, ca, rb, cb):
    for w in range(W):
        va = tabs[ra, w]
        if ca:
            va = va ^ full[w]
        vb = tabs[rb, w]
        if cb:
            vb = vb ^ full[w]
        tabs[r, w] = va & vb


@njit(cache=True, inline="always")
def _push_fanouts(fo_start, fo_list, node, top, seen, seenlist, ns):
    """Appends the fanouts of ``node`` up to ``top`` not yet ``seen`` to ``seenlist``
    (from index ``ns``) and marks them; returns the new length."""
    for p in range(fo_start[node], fo_start[node + 1]):
        z = fo_list[p]
        if z <= top and seen[z] == 0:
            seen[z] = 1
            seenlist[ns] = z
            ns += 1
    return ns


@njit(cache=True)
def grow_window(fa, fb, n, fo_start, fo_list, tabs, W, full, slot, ids, nrows,
                leaves, k, top, max_window, changed, use_changed, winmark, use_win, seen, seenlist):
    """:func:`mlc.logic.opt._grow_window`: rows appended from ``nrows``; returns the
    new row count.  The heap is a forward scan (nodes come off it in increasing order)."""
    ns = 0
    for t in range(k):
        ns = _push_fanouts(fo_start, fo_list, leaves[t], top, seen, seenlist, ns)
    pending = ns
    lo = 1 << 62
    for t in range(ns):
        if seenlist[t] < lo:
            lo = seenlist[t]
    size = nrows
    y = lo
    while pending > 0 and size < max_window:
        while seen[y] == 0:
            y += 1
        pending -= 1
        cy = y
        y += 1
        if slot[cy] >= 0:
            continue
        if use_changed and changed[cy]:
            continue
        a = fa[cy]
        b = fb[cy]
        if use_win and (winmark[a >> 1] or winmark[b >> 1]):
            continue
        ra = slot[a >> 1]
        if ra < 0:
            continue
        rb = slot[b >> 1]
        if rb < 0:
            continue
        _and_row(tabs, W, full, nrows, ra, a & 1, rb, b & 1)
        slot[cy] = nrows
        ids[nrows] = cy
        nrows += 1
        size += 1
        ns2 = _push_fanouts(fo_start, fo_list, cy, top, seen, seenlist, ns)
        pending += ns2 - ns
        ns = ns2
    for t in range(ns):
        seen[seenlist[t]] = 0
    return nrows


# ----------------------------------------------------------------------------- find_resub

@njit(cache=True)
def find_resub(tabs, W, f, care, nf, divrows, divids, D, max_new, or_width, out,
               flags, cl, cr, cc, al, ar, ac, an, cnt, ex, e2, rest):
    """:func:`mlc.logic.opt._find_resub`: ``f``, ``care`` as word arrays, divisors
    ``divids[:D]`` with tables ``tabs[divrows[i]]``.  Answer in ``out``: ``out[0]`` =
    -1 (none), 0 (literal ``out[1]``), 1 (``and(out[1], out[2])``), 2
    (``and(out[1], and(out[2], out[3]))``), 3 (``and(out[1], !and(out[2], out[3]))``),
    ``out[4]`` the output complement."""
    out[0] = -1
    if max_new < 0:
        return
    fz = True
    nfz = True
    for w in range(W):
        nf[w] = ~f[w] & care[w]
        if f[w] != ZERO:
            fz = False
        if nf[w] != ZERO:
            nfz = False
    if fz:
        out[0] = 0
        out[1] = 0
        return
    if nfz:
        out[0] = 0
        out[1] = 1
        return
    for i in range(D):
        r = divrows[i]
        A = True    # f & x == f
        B = True    # f & x == 0
        C = True    # nf & x == nf
        E = True    # nf & x == 0
        for w in range(W):
            x = tabs[r, w]
            if f[w] & ~x != ZERO:
                A = False
            if f[w] & x != ZERO:
                B = False
            if nf[w] & ~x != ZERO:
                C = False
            if nf[w] & x != ZERO:
                E = False
        d = divids[i]
        if A:
            if E:
                out[0] = 0
                out[1] = 2 * d
                return
        elif B and C:
            out[0] = 0
            out[1] = 2 * d + 1
            return
        flags[i] = (1 if A else 0) | (2 if B else 0) | (4 if C else 0) | (8 if E else 0)
    if max_new < 1:
        return
    # candidate lists: pos at [0, Lp), neg at [D2, D2 + Ln)
    D2 = 2 * D
    Lp = 0
    Ln = 0
    for i in range(D):
        fl = flags[i]
        if fl == 0:
            continue
        d = divids[i]
        r = divrows[i]
        if fl & 1:
            cl[Lp] = 2 * d
            cr[Lp] = r
            cc[Lp] = 0
            Lp += 1
        if fl & 4:
            cl[D2 + Ln] = 2 * d
            cr[D2 + Ln] = r
            cc[D2 + Ln] = 0
            Ln += 1
        if fl & 2:
            cl[Lp] = 2 * d + 1
            cr[Lp] = r
            cc[Lp] = 1
            Lp += 1
        if fl & 8:
            cl[D2 + Ln] = 2 * d + 1
            cr[D2 + Ln] = r
            cc[D2 + Ln] = 1
            Ln += 1
    # 1-resub
    for oc in range(2):
        base = 0 if oc == 0 else D2
        L = Lp if oc == 0 else Ln
        tgt = f if oc == 0 else nf
        for i in range(L):
            li = cl[base + i]
            ri = cr[base + i]
            ci = ONES if cc[base + i] else ZERO
            for j in range(i + 1, L):
                lj = cl[base + j]
                if (li >> 1) == (lj >> 1):
                    continue
                rj = cr[base + j]
                cj = ONES if cc[base + j] else ZERO
                ok = True
                for w in range(W):
                    if ((tabs[ri, w] ^ ci) & (tabs[rj, w] ^ cj) & care[w]) != tgt[w]:
                        ok = False
                        break
                if ok:
                    out[0] = 1
                    out[1] = li
                    out[2] = lj
                    out[4] = oc
                    return
    if max_new < 2:
        return
    for oc in range(2):
        base = 0 if oc == 0 else D2
        L = Lp if oc == 0 else Ln
        tgt = f if oc == 0 else nf
        if L <= 30:
            for i in range(L):
                li = cl[base + i]
                ri = cr[base + i]
                ci = ONES if cc[base + i] else ZERO
                for w in range(W):
                    ex[w] = ((tabs[ri, w] ^ ci) & care[w]) & ~tgt[w]
                for j in range(i + 1, L):
                    lj = cl[base + j]
                    rj = cr[base + j]
                    cj = ONES if cc[base + j] else ZERO
                    z = True
                    for w in range(W):
                        e2[w] = ex[w] & ((tabs[rj, w] ^ cj) & care[w])
                        if e2[w] != ZERO:
                            z = False
                    if z and j + 1 < L:
                        out[0] = 2
                        out[1] = li
                        out[2] = lj
                        out[3] = cl[base + j + 1]
                        out[4] = oc
                        return
                    for kk in range(j + 1, L):
                        rk = cr[base + kk]
                        ck = ONES if cc[base + kk] else ZERO
                        ok = True
                        for w in range(W):
                            if e2[w] & ((tabs[rk, w] ^ ck) & care[w]) != ZERO:
                                ok = False
                                break
                        if ok:
                            out[0] = 2
                            out[1] = li
                            out[2] = lj
                            out[3] = cl[base + kk]
                            out[4] = oc
                            return
        if L == 0:
            continue
        ct = 0
        for w in range(W):
            ct += _popcount(tgt[w])
        for i in range(D):
            cnt[i] = -1
        # A/B/C/E flags of meet m = tgt & x: m == tgt and m == 0
        full_bit = 1 if oc == 0 else 4
        zero_bit = 2 if oc == 0 else 8
        for ii in range(min(L, or_width)):
            li = cl[base + L - 1 - ii]
            ri = cr[base + L - 1 - ii]
            ci = ONES if cc[base + L - 1 - ii] else ZERO
            for w in range(W):
                ex[w] = ((tabs[ri, w] ^ ci) & care[w]) & ~tgt[w]
            di = li >> 1
            A = 0
            for t in range(D):
                d = divids[t]
                if d == di:
                    continue
                r = divrows[t]
                xz = True      # x & extra == 0
                xf = True      # x & extra == extra
                for w in range(W):
                    xe = tabs[r, w] & ex[w]
                    if xe != ZERO:
                        xz = False
                    if xe != ex[w]:
                        xf = False
                    if not xz and not xf:
                        break
                fl = flags[t]
                m_nonzero = (fl & zero_bit) == 0
                m_notfull = (fl & full_bit) == 0
                if (m_nonzero and xz) or (m_notfull and xf):
                    if cnt[t] < 0:
                        s = 0
                        for w in range(W):
                            s += _popcount(tgt[w] & tabs[r, w])
                        cnt[t] = s
                if m_nonzero and xz:
                    al[A] = 2 * d
                    ar[A] = r
                    ac[A] = 0
                    an[A] = cnt[t]
                    A += 1
                if m_notfull and xf:
                    al[A] = 2 * d + 1
                    ar[A] = r
                    ac[A] = 1
                    an[A] = ct - cnt[t]
                    A += 1
            st = A - 60 if A > 60 else 0
            for j in range(st, A):
                lj = al[j]
                rj = ar[j]
                cj = ONES if ac[j] else ZERO
                need = ct - an[j]
                have_rest = False
                for kk in range(j + 1, A):
                    if an[kk] < need:
                        continue
                    if not have_rest:
                        for w in range(W):
                            rest[w] = tgt[w] & ~((tabs[rj, w] ^ cj) & care[w])
                        have_rest = True
                    lk = al[kk]
                    rk = ar[kk]
                    ck = ONES if ac[kk] else ZERO
                    ok = True
                    for w in range(W):
                        if rest[w] & ~((tabs[rk, w] ^ ck) & care[w]) != ZERO:
                            ok = False
                            break
                    if ok and (lk >> 1) != (lj >> 1):
                        out[0] = 3
                        out[1] = li
                        out[2] = lj ^ 1
                        out[3] = lk ^ 1
                        out[4] = oc
                        return


def decode(out):
    """The expression (see :func:`mlc.logic.opt.rebuild`) of a :func:`find_resub` answer."""
    kind = int(out[0])
    if kind < 0:
        return None
    l1, l2, l3, oc = int(out[1]), int(out[2]), int(out[3]), int(out[4])
    if kind == 0:
        return l1
    if kind == 1:
        return ("and", l1, l2, oc)
    if kind == 2:
        return ("and", l1, ("and", l2, l3, 0), oc)
    return ("and", l1, ("and", l2, l3, 1), oc)


# ----------------------------------------------------------------------------- resub_window

@njit(cache=True)
def window_node(x, fa, fb, n, fo_start, fo_list, refs, touched, max_leaves, max_window,
                max_new, tabs, slot, ids, mark, seen, buf, vec, out):
    """The body of :func:`mlc.logic.opt.resub_window` for node ``x``: ``out[0]`` as in
    :func:`find_resub` (-1 also when the node is skipped); the freed cone is
    ``buf[1, :out[5]]``."""
    out[0] = -1
    out[5] = 0
    leaves = buf[0]
    cone = buf[1]
    stack = buf[2]
    dec = buf[3]
    inside = buf[4]
    k = reconv_cut(fa, fb, n, x, max_leaves, mark, leaves, inside)
    for t in range(k):
        if touched[leaves[t]]:
            return
    for t in range(k):
        mark[leaves[t]] = 1
    nc = mffc(fa, fb, n, x, refs, mark, cone, stack, dec)
    for t in range(k):
        mark[leaves[t]] = 0
    if nc < 2:
        return
    for t in range(nc):
        if touched[cone[t]]:
            return
    if k + max_window + 2 > tabs.shape[0] and tabs.shape[0] < slot.shape[0] + 1:
        out[0] = -2              # more table rows needed: the caller enlarges and retries
        return
    W = max(1, (1 << k) // 64)
    full = vec[0]
    set_leaves(tabs, W, k, full, leaves, slot, ids)
    nrows = grow_window(fa, fb, n, fo_start, fo_list, tabs, W, full, slot, ids, k,
                        leaves, k, x + max_window, max_window, touched, False, mark, False,
                        seen, stack)
    _resub_tail(x, n, fa, fb, refs, touched, nrows, nc, max_new, tabs, W, full, full, slot,
                ids, mark, buf, vec, out)
    for t in range(nrows):
        slot[ids[t]] = -1
    out[5] = nc


@njit(cache=True)
def _resub_tail(x, n, fa, fb, refs, touched, nrows, nc, max_new, tabs, W, full, care, slot,
                ids, mark, buf, vec, out):
    if slot[x] < 0:
        return
    cone = buf[1]
    order = np.argsort(ids[:nrows])
    # bad = cone (mark 4) | tfo of x inside the window (mark 3)
    for t in range(nc):
        mark[cone[t]] = 4
    mark[x] = 3
    for t in range(nrows):
        y = ids[order[t]]
        if y > x and y > n:
            if mark[fa[y] >> 1] == 3 or mark[fb[y] >> 1] == 3:
                mark[y] = 3
    divrows = buf[5]
    divids = buf[6]
    D = 0
    for t in range(nrows):
        d = ids[order[t]]
        if mark[d] == 0 and not touched[d] and refs[d] > 0:
            divrows[D] = order[t]
            divids[D] = d
            D += 1
    for t in range(nrows):
        mark[ids[t]] = 0
    for t in range(nc):
        mark[cone[t]] = 0
    fx = vec[1]
    for w in range(W):
        fx[w] = tabs[slot[x], w] & care[w]
    _call_find(tabs, W, fx, care, divrows, divids, D, min(max_new, nc - 1), 8, out, buf, vec)


@njit(cache=True)
def _call_find(tabs, W, f, care, divrows, divids, D, max_new, or_width, out, buf, vec):
    n2 = 2 * D + 2
    flags = np.empty(D + 1, dtype=np.int64)
    cl = np.empty(2 * n2, dtype=np.int64)
    cr = np.empty(2 * n2, dtype=np.int64)
    cc = np.empty(2 * n2, dtype=np.int64)
    al = np.empty(n2, dtype=np.int64)
    ar = np.empty(n2, dtype=np.int64)
    ac = np.empty(n2, dtype=np.int64)
    an = np.empty(n2, dtype=np.int64)
    cnt = np.empty(D + 1, dtype=np.int64)
    find_resub(tabs, W, f, care, vec[2], divrows, divids, D, max_new, or_width, out,
               flags, cl, cr, cc, al, ar, ac, an, cnt, vec[3], vec[4], vec[5])


# ----------------------------------------------------------------------------- resub_dc

@njit(cache=True)
def _in_tfo(fa, fb, x, v0, memo, memolist, nm, budget, sv, ss):
    """:func:`mlc.logic.opt._in_tfo` without recursion: ``(answer, memo count,
    budget left)``; ``memo[v]`` 1 = True, 2 = False (``memolist[:nm]`` the set ones)."""
    sv[0] = v0
    ss[0] = 0
    sp = 1
    ret = False
    while sp > 0:
        v = sv[sp - 1]
        s = ss[sp - 1]
        if s == 0:
            if v <= x:
                ret = v == x
                sp -= 1
                continue
            m = memo[v]
            if m != 0:
                ret = m == 1
                sp -= 1
                continue
            budget -= 1
            if budget < 0:
                ret = True
                sp -= 1
                continue
            ss[sp - 1] = 1
            sv[sp] = fa[v] >> 1
            ss[sp] = 0
            sp += 1
        elif s == 1:
            if ret:
                memo[v] = 1
                memolist[nm] = v
                nm += 1
                sp -= 1
                continue
            ss[sp - 1] = 2
            sv[sp] = fb[v] >> 1
            ss[sp] = 0
            sp += 1
        else:
            memo[v] = 1 if ret else 2
            memolist[nm] = v
            nm += 1
            sp -= 1
    return ret, nm, budget


@njit(cache=True)
def dc_node(x, fa, fb, n, fo_start, fo_list, refs, touched, changed, read, is_po, max_leaves,
            levels, max_fanout, max_window, max_new, tabs, ftabs, slot, fslot, ids, mark,
            winmark, memo, seen, buf, vec, out, lens):
    """The body of :func:`mlc.logic.opt.resub_dc` for node ``x`` up to its
    :func:`find_resub` (``out`` as there, -1 also when skipped).  For
    :func:`dc_commit`: the window ``buf[4, :lens[0]]``, the cone ``buf[1, :lens[1]]``,
    the leaves ``buf[0, :lens[2]]``, the inside nodes ``buf[7, :lens[3]]`` and the
    roots marked 1 in ``winmark``... (kept until dc_clear)."""
    out[0] = -1
    lens[0] = 0
    lens[1] = 0
    lens[2] = 0
    lens[3] = 0
    leaves = buf[0]
    cone = buf[1]
    stack = buf[2]
    dec = buf[3]
    win = buf[4]
    inside = buf[7]
    memolist = dec
    # the fanout window
    win[0] = x
    nw = 1
    winmark[x] = 1
    nm = 0
    budget = 200
    fstart = 0
    fend = 1
    sv = np.empty(512, dtype=np.int64)
    ss = np.empty(512, dtype=np.int64)
    for _lev in range(levels):
        for t in range(fstart, fend):
            y = win[t]
            if fo_start[y + 1] - fo_start[y] > max_fanout:
                continue
            for p in range(fo_start[y], fo_start[y + 1]):
                z = fo_list[p]
                if winmark[z]:
                    continue
                va = fa[z] >> 1
                vb = fb[z] >> 1
                skip = False
                if not winmark[va]:
                    r, nm, budget = _in_tfo(fa, fb, x, va, memo, memolist, nm, budget, sv, ss)
                    skip = r
                if not skip and not winmark[vb]:
                    r, nm, budget = _in_tfo(fa, fb, x, vb, memo, memolist, nm, budget, sv, ss)
                    skip = r
                if skip:
                    continue
                winmark[z] = 1
                win[nw] = z
                nw += 1
        fstart = fend
        fend = nw
    for t in range(nm):
        memo[memolist[t]] = 0
    lens[0] = nw
    if nw == 1:
        return
    for t in range(nw):
        if changed[win[t]]:
            return
    # leaves below the window, then the reconvergence-driven cut
    nl = 0
    for t in range(nw):
        y = win[t]
        mark[y] = 2
    for t in range(nw):
        y = win[t]
        for v in (fa[y] >> 1, fb[y] >> 1):
            if v != 0 and winmark[v] == 0 and mark[v] == 0:
                mark[v] = 1
                leaves[nl] = v
                nl += 1
    for t in range(nw):
        inside[t] = win[t]
    ni = nw
    lens[2] = nl
    lens[3] = ni
    if nl > max_leaves:
        return
    nl, ni = expand_cut(fa, fb, n, mark, leaves, nl, inside, ni, max_leaves)
    lens[2] = nl
    lens[3] = ni
    for t in range(nl):
        y = leaves[t]
        if changed[y] or touched[y]:
            return
    for t in range(ni):
        if changed[inside[t]]:
            return
    leaves[:nl].sort()
    nc = mffc(fa, fb, n, x, refs, mark, cone, stack, dec)
    lens[1] = nc
    for t in range(nc):
        if touched[cone[t]]:
            return
    k = nl
    if k + ni + max_window + 2 > tabs.shape[0] and tabs.shape[0] < slot.shape[0] + 1:
        out[0] = -2              # more table rows needed: the caller enlarges and retries
        return
    W = max(1, (1 << k) // 64)
    full = vec[0]
    set_leaves(tabs, W, k, full, leaves, slot, ids)
    nrows = k
    srt = np.sort(inside[:ni])
    for t in range(ni):
        y = srt[t]
        a = fa[y]
        b = fb[y]
        _and_row(tabs, W, full, nrows, slot[a >> 1], a & 1, slot[b >> 1], b & 1)
        slot[y] = nrows
        ids[nrows] = y
        nrows += 1
    # care set of x: complement it and re-simulate the window
    ws = np.sort(win[:nw])
    nf = 0
    rx = slot[x]
    for w in range(W):
        ftabs[nf, w] = tabs[rx, w] ^ full[w]
    fslot[x] = nf
    nf += 1
    for t in range(nw):
        y = ws[t]
        if y == x:
            continue
        a = fa[y]
        b = fb[y]
        for w in range(W):
            fr = fslot[a >> 1]
            va = ftabs[fr, w] if fr >= 0 else tabs[slot[a >> 1], w]
            if a & 1:
                va = va ^ full[w]
            fr = fslot[b >> 1]
            vb = ftabs[fr, w] if fr >= 0 else tabs[slot[b >> 1], w]
            if b & 1:
                vb = vb ^ full[w]
            ftabs[nf, w] = va & vb
        fslot[y] = nf
        nf += 1
    care = vec[6]
    for w in range(W):
        care[w] = ZERO
    blocked = False
    for t in range(nw):
        y = win[t]
        root = is_po[y] != 0
        if not root:
            for p in range(fo_start[y], fo_start[y + 1]):
                if winmark[fo_list[p]] == 0:
                    root = True
                    break
        if root:
            winmark[y] = 2
            fr = fslot[y]
            ry = slot[y]
            for w in range(W):
                care[w] |= ftabs[fr, w] ^ tabs[ry, w]
        elif read[y]:
            blocked = True
    for t in range(nw):
        fslot[win[t]] = -1
    if not blocked:
        nrows = grow_window(fa, fb, n, fo_start, fo_list, tabs, W, full, slot, ids, nrows,
                            leaves, k, x + max_window, max_window, changed, True, winmark, True,
                            seen, stack)
        order = np.argsort(ids[:nrows])
        for t in range(nc):
            mark[cone[t]] = 4        # (leaves 1, inside 2: left as they are)
        divrows = buf[5]
        divids = buf[6]
        D = 0
        for t in range(nrows):
            d = ids[order[t]]
            if winmark[d] == 0 and mark[d] != 4 and not touched[d] and not changed[d] \
                    and refs[d] > 0:
                divrows[D] = order[t]
                divids[D] = d
                D += 1
        for t in range(nc):
            mark[cone[t]] = 0
        fx = vec[1]
        for w in range(W):
            fx[w] = tabs[rx, w] & care[w]
        _call_find(tabs, W, fx, care, divrows, divids, D, min(max_new, nc - 1), 8, out, buf, vec)
    for t in range(nrows):
        slot[ids[t]] = -1


@njit(cache=True)
def dc_clear(buf, lens, mark, winmark):
    """Clear the marks :func:`dc_node` left (after :func:`dc_commit`, if any)."""
    for t in range(lens[0]):
        winmark[buf[4, t]] = 0
    for t in range(lens[2]):
        mark[buf[0, t]] = 0
    for t in range(lens[3]):
        mark[buf[7, t]] = 0


@njit(cache=True)
def dc_commit(x, fa, fb, n, touched, changed, read, buf, lens, winmark, enodes):
    """The bookkeeping of an accepted :func:`dc_node` move (as in :func:`mlc.logic.opt.resub_dc`)."""
    for t in range(lens[1]):
        touched[buf[1, t]] = 1
    for t in range(lens[0]):
        y = buf[4, t]
        if winmark[y] != 2:
            changed[y] = 1
    changed[x] = 1
    for t in range(lens[2]):
        read[buf[0, t]] = 1
    for t in range(lens[3]):
        read[buf[7, t]] = 1
    stack = buf[2]
    sp = 0
    for t in range(len(enodes)):
        stack[sp] = enodes[t]
        sp += 1
    while sp > 0:
        sp -= 1
        y = stack[sp]
        if read[y]:
            continue
        read[y] = 1
        if y > n:
            stack[sp] = fa[y] >> 1
            stack[sp + 1] = fb[y] >> 1
            sp += 2


# ----------------------------------------------------------------------------- rewrite

@njit(cache=True)
def strash_table(fa, fb, n, N):
    """Open-addressing hash of the AND nodes: keys ``a * 2N + b`` (a < b), values literals."""
    size = 1
    while size < 4 * max(N, 1):
        size *= 2
    keys = np.full(size, -1, dtype=np.int64)
    vals = np.zeros(size, dtype=np.int64)
    M = 2 * N + 2
    for y in range(n + 1, N):
        key = fa[y] * M + fb[y]
        h = (key * 0x9E3779B1) & (size - 1)
        while keys[h] >= 0 and keys[h] != key:
            h = (h + 1) & (size - 1)
        if keys[h] < 0:
            keys[h] = key
            vals[h] = 2 * y
    return keys, vals


@njit(cache=True, inline="always")
def lookup(keys, vals, M, a, b):
    """:meth:`mlc.logic.aig.AIG.lookup`: the literal, or -1 where it would be a new node."""
    if a > b:
        t = a
        a = b
        b = t
    if a == 0:
        return 0
    if a == 1:
        return b
    if a == b:
        return a
    if a ^ b == 1:
        return 0
    key = a * M + b
    size = len(keys)
    h = (key * 0x9E3779B1) & (size - 1)
    while keys[h] >= 0:
        if keys[h] == key:
            return vals[h]
        h = (h + 1) & (size - 1)
    return -1


@njit(cache=True)
def _cut_less(cand, cn, i, j):
    # (len, tuple) order
    if cn[i] != cn[j]:
        return cn[i] < cn[j]
    for t in range(cn[i]):
        if cand[i, t] != cand[j, t]:
            return cand[i, t] < cand[j, t]
    return False


@njit(cache=True)
def enumerate_cuts(fa, fb, n, N, k, limit):
    """:func:`mlc.logic.opt.enumerate_cuts`: node ``x``'s cuts are
    ``cl[x, c, :cn[x, c]]`` for ``c < cc[x]`` (the trivial cut last)."""
    C = limit + 1
    cl = np.zeros((N, C, 4), dtype=np.int64)
    cn = np.zeros((N, C), dtype=np.int64)
    cc = np.zeros(N, dtype=np.int64)
    cc[0] = 1
    for i in range(1, n + 1):
        cc[i] = 1
        cn[i, 0] = 1
        cl[i, 0, 0] = i
    cand = np.zeros((C * C, 4), dtype=np.int64)
    candn = np.zeros(C * C, dtype=np.int64)
    order = np.zeros(C * C, dtype=np.int64)
    u = np.zeros(8, dtype=np.int64)
    for x in range(n + 1, N):
        a = fa[x] >> 1
        b = fb[x] >> 1
        m = 0
        for i in range(cc[a]):
            na = cn[a, i]
            for j in range(cc[b]):
                nb = cn[b, j]
                # merge two sorted lists
                p = 0
                q = 0
                s = 0
                while (p < na or q < nb) and s <= k:
                    if q >= nb or (p < na and cl[a, i, p] < cl[b, j, q]):
                        u[s] = cl[a, i, p]
                        p += 1
                    elif p >= na or cl[b, j, q] < cl[a, i, p]:
                        u[s] = cl[b, j, q]
                        q += 1
                    else:
                        u[s] = cl[a, i, p]
                        p += 1
                        q += 1
                    s += 1
                if s > k:
                    continue
                dup = False
                for t in range(m):
                    if candn[t] == s:
                        same = True
                        for r in range(s):
                            if cand[t, r] != u[r]:
                                same = False
                                break
                        if same:
                            dup = True
                            break
                if dup:
                    continue
                for r in range(s):
                    cand[m, r] = u[r]
                candn[m] = s
                m += 1
        # insertion sort of the indices by (len, tuple)
        for t in range(m):
            order[t] = t
        for t in range(1, m):
            v = order[t]
            r = t - 1
            while r >= 0 and _cut_less(cand, candn, v, order[r]):
                order[r + 1] = order[r]
                r -= 1
            order[r + 1] = v
        nk = 0
        for t in range(m):
            ci = order[t]
            s = candn[ci]
            dom = False
            for kk in range(nk):
                # kept cut kk a subset of ci?
                ks = cn[x, kk]
                if ks > s:
                    continue
                p = 0
                ok = True
                for r in range(ks):
                    v = cl[x, kk, r]
                    while p < s and cand[ci, p] < v:
                        p += 1
                    if p >= s or cand[ci, p] != v:
                        ok = False
                        break
                if ok:
                    dom = True
                    break
            if dom:
                continue
            for r in range(s):
                cl[x, nk, r] = cand[ci, r]
            cn[x, nk] = s
            nk += 1
            if nk >= limit:
                break
        cl[x, nk, 0] = x
        cn[x, nk] = 1
        cc[x] = nk + 1
    return cl, cn, cc


def npn_arrays():
    """The NPN look-up tables and the exact table of :mod:`mlc.logic.npn` as arrays
    (cached): ``(lo, hi, perms, ands, ngates, gates, out_node, out_c)``."""
    global _NPN
    if _NPN is None:
        from mlc.logic import npn
        luts = npn._luts()
        lo = np.array([l for l, _h in luts], dtype=np.int64)
        hi = np.array([h for _l, h in luts], dtype=np.int64)
        perms = np.array([p for p, _n, _x in npn._TRANSFORMS], dtype=np.int64)
        negs = np.array([ng for _p, ng, _x in npn._TRANSFORMS], dtype=np.int64)
        ands = np.full(1 << 16, 99, dtype=np.int64)
        ngates = np.zeros(1 << 16, dtype=np.int64)
        gates = np.zeros((1 << 16, 12, 5), dtype=np.int8)
        out_node = np.zeros(1 << 16, dtype=np.int64)
        out_c = np.zeros(1 << 16, dtype=np.int64)
        for R, ent in npn.table().items():
            ands[R] = ent["ands"]
            ngates[R] = len(ent["gates"])
            for t, gt in enumerate(ent["gates"]):
                gates[R, t, :] = gt
            out_node[R], out_c[R] = ent["out"]
        _NPN = (lo, hi, perms, negs, ands, ngates, gates, out_node, out_c)
    return _NPN


_NPN = None

# every 16-bit function's matches (the transforms taking it to its class
# representative or its complement) over all 65536 functions: 170496 entries
NPN_POOL = 1 << 18


def npn_match_cache():
    """The memo of :func:`rewrite_node`'s NPN work, filled as functions are met and kept
    for the process: ``(canon, start, count, pool, top)``: ``canon[f]`` the class
    representative of 16-bit function ``f`` (-1: not met yet), and its matches
    ``pool[start[f]:start[f] + count[f]]`` (transform index * 2 + output complement,
    in increasing index order); ``top[0]`` the pool's fill."""
    global _MATCH
    if _MATCH is None:
        _MATCH = (np.full(1 << 16, -1, dtype=np.int64), np.zeros(1 << 16, dtype=np.int64),
                  np.zeros(1 << 16, dtype=np.int64), np.zeros(NPN_POOL, dtype=np.int32),
                  np.zeros(1, dtype=np.int64))
    return _MATCH


_MATCH = None


@njit(cache=True)
def npn_matches(f, lo, hi, canon, start, count, pool, top):
    """``f``'s class representative, its matches filled into the memo on first use."""
    R = canon[f]
    if R >= 0:
        return R
    R = npn_canon(f, lo, hi)
    lo8 = f & 0xFF
    hi8 = f >> 8
    t = top[0]
    if t + lo.shape[0] > pool.shape[0]:
        raise ValueError("npn_matches: pool too small")
    start[f] = t
    for idx in range(lo.shape[0]):
        g = lo[idx, lo8] | hi[idx, hi8]
        if g == R:
            pool[t] = 2 * idx
            t += 1
        elif g ^ 0xFFFF == R:
            pool[t] = 2 * idx + 1
            t += 1
    count[f] = t - start[f]
    top[0] = t
    canon[f] = R
    return R


@njit(cache=True)
def cut_table(fa, fb, x, leaves, nl, tv, vis, stack, cstack):
    """:func:`mlc.logic.opt.cut_table`: 16-bit table of ``x`` over ``leaves[:nl]``."""
    VAR4 = (0xAAAA, 0xCCCC, 0xF0F0, 0xFF00)
    nv = 0
    for i in range(nl):
        tv[leaves[i]] = VAR4[i]
        vis[leaves[i]] = 1
        stack[nv] = leaves[i]
        nv += 1
    cstack[0] = x
    sp = 1
    while sp > 0:
        y = cstack[sp - 1]
        if vis[y]:
            sp -= 1
            continue
        ya = fa[y] >> 1
        yb = fb[y] >> 1
        if vis[ya] and vis[yb]:
            sp -= 1
            va = tv[ya] ^ 0xFFFF if fa[y] & 1 else tv[ya]
            vb = tv[yb] ^ 0xFFFF if fb[y] & 1 else tv[yb]
            tv[y] = va & vb
            vis[y] = 1
            stack[nv] = y
            nv += 1
            continue
        if not vis[ya]:
            cstack[sp] = ya
            sp += 1
        if not vis[yb]:
            cstack[sp] = yb
            sp += 1
    r = tv[x]
    for t in range(nv):
        vis[stack[t]] = 0
    return r


@njit(cache=True)
def npn_canon(f, lo, hi):
    lo8 = f & 0xFF
    hi8 = f >> 8
    best = 1 << 17
    for idx in range(lo.shape[0]):
        g = lo[idx, lo8] | hi[idx, hi8]
        if g < best:
            best = g
        h = g ^ 0xFFFF
        if h < best:
            best = h
    return best


@njit(cache=True)
def rewrite_node(x, fa, fb, n, refs, touched, lev, cl, cn, cc, keys, hvals, M, zero_gain,
                 lo, hi, perms, negs, ands, ngates, gates, out_node, out_c,
                 mark, tv, vis, buf, res, canon, mstart, mcount, pool, top):
    """The body of :func:`mlc.logic.opt.rewrite` for node ``x``, but building the
    replacement: ``res[0]`` = 1 if a move is to be made (gain, and the zero-gain
    depth rule passed), ``res[1]`` its class ``R``, ``res[2:6]`` the leaf literals,
    ``res[6]`` the output complement, ``res[7]`` the cone size (cone in ``buf[1]``)."""
    res[0] = 0
    cone = buf[0]
    stack = buf[2]
    dec = buf[3]
    bestcone = buf[1]
    have = False
    bgain = 0
    bdep = 0
    leaves = np.empty(4, dtype=np.int64)
    lits = np.empty(20, dtype=np.int64)
    dep = np.empty(20, dtype=np.int64)
    seen = np.empty((1600, 5), dtype=np.int64)
    for c in range(cc[x]):
        s = cn[x, c]
        if s < 2:
            continue
        skip = False
        for t in range(s):
            if touched[cl[x, c, t]]:
                skip = True
        if skip:
            continue
        for t in range(s):
            mark[cl[x, c, t]] = 1
            leaves[t] = cl[x, c, t]
        nc = mffc(fa, fb, n, x, refs, mark, cone, stack, dec)
        for t in range(s):
            mark[cl[x, c, t]] = 0
        for t in range(nc):
            if touched[cone[t]]:
                skip = True
        if skip:
            continue
        f = cut_table(fa, fb, x, leaves, s, tv, vis, stack, buf[4])
        R = npn_matches(f, lo, hi, canon, mstart, mcount, pool, top)
        if ands[R] > nc or (ands[R] == nc and not zero_gain):
            continue
        for t in range(nc):
            mark[cone[t]] = 2
        ng = ngates[R]
        nseen = 0
        for q in range(mstart[f], mstart[f] + mcount[f]):
            idx = pool[q] >> 1
            out = pool[q] & 1
            neg = negs[idx]
            for i in range(4):
                p = perms[idx, i]
                lits[i] = (2 * leaves[p] if p < s else 0) ^ ((neg >> i) & 1)
            dupl = False
            for t in range(nseen):
                if seen[t, 0] == lits[0] and seen[t, 1] == lits[1] and seen[t, 2] == lits[2] \
                        and seen[t, 3] == lits[3] and seen[t, 4] == out:
                    dupl = True
                    break
            if dupl:
                continue
            seen[nseen, 0] = lits[0]
            seen[nseen, 1] = lits[1]
            seen[nseen, 2] = lits[2]
            seen[nseen, 3] = lits[3]
            seen[nseen, 4] = out
            nseen += 1
            limit = nc - (0 if zero_gain else 1)
            if have:
                limit = min(limit, nc - bgain)
            # _place_cost
            new = 0
            for t in range(ng):
                j = gates[R, t, 0]
                l = gates[R, t, 1]
                a = lits[j]
                b = lits[l]
                r = -1
                if a >= 0 and b >= 0:
                    r = lookup(keys, hvals, M, a ^ gates[R, t, 2], b ^ gates[R, t, 3])
                    if r >= 0 and (mark[r >> 1] == 2 or touched[r >> 1] or refs[r >> 1] == 0):
                        r = -1
                if r < 0:
                    new += 1
                    lits[4 + t] = -1
                else:
                    lits[4 + t] = r ^ gates[R, t, 4]
            if new > limit:
                continue
            node = out_node[R]
            if node < 0:
                d = lev[0]
            else:
                for i in range(4):
                    dep[i] = lev[lits[i] >> 1]
                for t in range(ng):
                    xl = lits[4 + t]
                    if xl >= 0:
                        dep[4 + t] = lev[xl >> 1]
                    else:
                        dep[4 + t] = 1 + max(dep[gates[R, t, 0]], dep[gates[R, t, 1]])
                d = dep[node]
            gain = nc - new
            if not have or gain > bgain or (gain == bgain and -d > -bdep):
                have = True
                bgain = gain
                bdep = d
                res[1] = R
                for i in range(4):
                    res[2 + i] = seen[nseen - 1, i]
                res[6] = out
                res[7] = nc
                for t in range(nc):
                    bestcone[t] = cone[t]
        for t in range(nc):
            mark[cone[t]] = 0
    if not have:
        return
    if bgain == 0 and -bdep <= -lev[x]:
        return
    res[0] = 1


# ----------------------------------------------------------------------------- global tables

def tables_array(vals, n: int):
    """Truth tables over ``n`` variables (Python ints) as rows of a uint64 matrix."""
    W = max(1, (1 << n) // 64)
    nb = 8 * W
    data = b"".join(v.to_bytes(nb, "little") for v in vals)
    return np.frombuffer(data, dtype=np.uint64).reshape(-1, W), W


def words(v: int, W: int):
    return np.frombuffer(v.to_bytes(8 * W, "little"), dtype=np.uint64)


@njit(cache=True)
def find_resub_rows(tabs, W, f, care, divs, max_new, or_width):
    """:func:`find_resub` with the divisors' tables in rows ``divs`` (their node ids)."""
    out = np.zeros(6, dtype=np.int64)
    vec = np.zeros((8, W), dtype=np.uint64)
    buf = np.zeros((1, 1), dtype=np.int64)
    _call_find(tabs, W, f, care, divs, divs, len(divs), max_new, or_width, out, buf, vec)
    return out


def warm() -> float:
    """Load (or compile) every kernel once, on a small network; seconds taken.  For
    callers that time synthesis without numba's start-up (as Python's imports)."""
    import time
    from mlc.logic import opt
    from mlc.logic.aig import AIG
    t0 = time.perf_counter()
    g = AIG([f"i{i}" for i in range(6)])
    x = [g.input_lit(i) for i in range(6)]
    a = g.and_(x[0], x[1])
    b = g.and_(a, x[2])
    c = g.and_(b ^ 1, g.and_(x[3], x[1]))
    d = g.and_(g.and_(c, x[4]) ^ 1, g.and_(a, x[5]) ^ 1)
    g.add_output("o0", d)
    g.add_output("o1", b)
    old = opt.KERNELS, opt.KERNEL_MIN_ANDS
    opt.KERNELS, opt.KERNEL_MIN_ANDS = True, 0
    try:
        for h in (g, opt.rewrite(g)):
            opt.rewrite(h, zero_gain=True)
            opt.resub_window(h)
            opt.resub_dc(h)
            opt.resub(h)
            opt.resub_odc(h)
    finally:
        opt.KERNELS, opt.KERNEL_MIN_ANDS = old
    npn_arrays()
    sop_costs(0b0110, 0b1111, 2)              # the decomposition's kernels
    analyse_full(0b0110, 2)
    return time.perf_counter() - t0


@njit(cache=True)
def canon_index(f, lo, hi):
    """:func:`mlc.logic.npn.canon`'s search: ``(R, transform index, out)``, the first
    transform reaching the least table (the table before its complement)."""
    lo8 = f & 0xFF
    hi8 = f >> 8
    best = 1 << 17
    bi = 0
    bo = 0
    for idx in range(lo.shape[0]):
        g = lo[idx, lo8] | hi[idx, hi8]
        if g < best:
            best = g
            bi = idx
            bo = 0
        h = g ^ 0xFFFF
        if h < best:
            best = h
            bi = idx
            bo = 1
    return best, bi, bo


# ----------------------------------------------------------------------------- factored-SOP costing

# refactoring's decompositions have at most 10 variables (its largest cuts); wider
# tables (TableSpec decompositions) keep the Python path
SOP_MAX_VARS = 10


_FULLW: dict = {}


def _full_words(n: int):
    """``(W, full, fullw)`` for tables over ``n`` variables: the number of 64-bit words,
    the all-ones table as a Python int and as words (kept per ``n``)."""
    r = _FULLW.get(n)
    if r is None:
        W = max(1, (1 << n) >> 6)
        full = (1 << (1 << n)) - 1
        r = _FULLW[n] = (W, full, np.frombuffer(full.to_bytes(8 * W, "little"),
                                                dtype="<u8").astype(np.uint64))
    return r


def sop_costs(f: int, care: int, n: int):
    """:meth:`mlc.logic.decomp._Dec._sop_plan`'s work for the interval (on-set ``f``,
    care set ``care``; Python ints over ``n <= SOP_MAX_VARS`` variables): the irredundant
    SOP of each phase (:func:`mlc.logic.tt.isop`'s cubes, in its order) and the AND count
    of its factored form (:func:`mlc.logic.lower.factor_sop` into an empty AIG of ``n``
    inputs).  Returns ``((ands, cubes) of the on-set, (ands, cubes) of the off-set)``,
    cubes as lists of ``(pos_mask, neg_mask)``."""
    W, full, fullw = _full_words(n)
    off = care & ~f
    nb = 8 * W
    if care == full:                 # no don't cares: each phase's interval is one table
        t = np.frombuffer(f.to_bytes(nb, "little") + off.to_bytes(nb, "little"),
                          dtype="<u8").astype(np.uint64).reshape(2, W)
        words = (t[0], t[0], t[1], t[1])
    else:
        dc = full & ~care
        words = np.frombuffer(b"".join(x.to_bytes(nb, "little") for x in (f, f | dc, off, off | dc)),
                              dtype="<u8").astype(np.uint64).reshape(4, W)
    k0, P0, Q0, k1, P1, Q1 = _sop_phases(words[0], words[1], words[2], words[3], n, W, fullw)
    return ((k0, list(zip(P0.tolist(), Q0.tolist()))),
            (k1, list(zip(P1.tolist(), Q1.tolist()))))


@njit(cache=True)
def _sop_phases(L0, U0, L1, U1, n, W, full):
    """:func:`_sop_phase` of the on-set's interval [L0, U0] and the off-set's [L1, U1]
    in one call: ``(ANDs, P, Q)`` of each, the masks cut to the cube count."""
    k0, P0, Q0, m0 = _sop_phase(L0, U0, n, W, full)
    k1, P1, Q1, m1 = _sop_phase(L1, U1, n, W, full)
    return k0, P0[:m0], Q0[:m0], k1, P1[:m1], Q1[:m1]


@njit(cache=True)
def _tw_depends(t, v, W):
    """Whether table ``t`` (``W`` words) depends on variable ``v``."""
    if v < 6:
        s = np.uint64(1 << v)
        x = _VARW[v]
        for w in range(W):
            if ((t[w] & x) >> s) != (t[w] & ~x):
                return True
        return False
    st = 1 << (v - 6)
    for w in range(W):
        if w & st == 0 and t[w] != t[w | st]:
            return True
    return False


@njit(cache=True)
def _tw_cof(t, v, W, pos):
    """The cofactor of ``t`` for variable ``v`` = ``pos``, spread over both halves."""
    r = np.empty(W, dtype=np.uint64)
    _tw_cof_to(t, v, W, pos, r)
    return r


@njit(cache=True)
def _tw_cof_to(t, v, W, pos, r):
    """:func:`_tw_cof` written into ``r`` (no new array)."""
    if v < 6:
        s = np.uint64(1 << v)
        x = _VARW[v]
        for w in range(W):
            if pos:
                u = t[w] & x
                r[w] = u | (u >> s)
            else:
                u = t[w] & ~x
                r[w] = u | (u << s)
    else:
        st = 1 << (v - 6)
        for w in range(W):
            r[w] = t[w | st] if pos else t[w & ~st]


@njit(cache=True)
def _isop(L, U, n, W, full, outp, outq):
    """:func:`mlc.logic.tt.isop`'s recursion on word tables, with an explicit stack
    (numba's disk cache does not hold recursive functions) and without its memo (a
    repeated interval gives the same cubes): the cubes go to ``outp``/``outq`` in the
    order ``tt.isop`` lists them; returns their number."""
    D = n + 2
    SL = np.empty((D, W), dtype=np.uint64)
    SU = np.empty((D, W), dtype=np.uint64)
    L0 = np.empty((D, W), dtype=np.uint64)
    L1 = np.empty((D, W), dtype=np.uint64)
    U0 = np.empty((D, W), dtype=np.uint64)
    U1 = np.empty((D, W), dtype=np.uint64)
    F0 = np.empty((D, W), dtype=np.uint64)
    F1 = np.empty((D, W), dtype=np.uint64)
    stop = np.empty(D, dtype=np.int64)
    sp = np.empty(D, dtype=np.int64)
    sq = np.empty(D, dtype=np.int64)
    stage = np.empty(D, dtype=np.int64)
    sv = np.empty(D, dtype=np.int64)
    ret = np.empty(W, dtype=np.uint64)
    cnt = 0
    d = 0
    SL[0] = L
    SU[0] = U
    stop[0] = n
    sp[0] = 0
    sq[0] = 0
    stage[0] = 0
    while d >= 0:
        stg = stage[d]
        if stg == 0:
            zero = True
            for w in range(W):
                if SL[d, w] != ZERO:
                    zero = False
                    break
            if zero:
                for w in range(W):
                    ret[w] = ZERO
                d -= 1
                continue
            isfull = True
            for w in range(W):
                if SU[d, w] != full[w]:
                    isfull = False
                    break
            if isfull:
                outp[cnt] = sp[d]
                outq[cnt] = sq[d]
                cnt += 1
                for w in range(W):
                    ret[w] = full[w]
                d -= 1
                continue
            v = stop[d] - 1
            while v >= 0:
                if _tw_depends(SL[d], v, W) or _tw_depends(SU[d], v, W):
                    break
                v -= 1
            sv[d] = v
            _tw_cof_to(SL[d], v, W, False, L0[d])
            _tw_cof_to(SL[d], v, W, True, L1[d])
            _tw_cof_to(SU[d], v, W, False, U0[d])
            _tw_cof_to(SU[d], v, W, True, U1[d])
            for w in range(W):
                SL[d + 1, w] = L0[d, w] & ~U1[d, w] & full[w]
                SU[d + 1, w] = U0[d, w]
            sp[d + 1] = sp[d]
            sq[d + 1] = sq[d] | (1 << v)
        elif stg == 1:
            v = sv[d]
            F0[d] = ret
            for w in range(W):
                SL[d + 1, w] = L1[d, w] & ~U0[d, w] & full[w]
                SU[d + 1, w] = U1[d, w]
            sp[d + 1] = sp[d] | (1 << v)
            sq[d + 1] = sq[d]
        elif stg == 2:
            v = sv[d]
            F1[d] = ret
            for w in range(W):
                SL[d + 1, w] = ((L0[d, w] & ~F0[d, w]) | (L1[d, w] & ~F1[d, w])) & full[w]
                SU[d + 1, w] = U0[d, w] & U1[d, w]
            sp[d + 1] = sp[d]
            sq[d + 1] = sq[d]
        else:
            v = sv[d]
            if v < 6:
                x = _VARW[v]
                for w in range(W):
                    ret[w] = ret[w] | (F0[d, w] & ~x & full[w]) | (F1[d, w] & x & full[w])
            else:
                st = 1 << (v - 6)
                for w in range(W):
                    ret[w] = ret[w] | (F1[d, w] if w & st else F0[d, w])
            d -= 1
            continue
        stage[d] = stg + 1
        stop[d + 1] = sv[d]
        stage[d + 1] = 0
        d += 1
    return cnt


@njit(cache=True)
def _fx_and(a, b, keys, vals, M, st):
    """:meth:`mlc.logic.aig.AIG.and_` on a scratch AIG held as a hash table; ``st[0]``
    is its node count."""
    r = lookup(keys, vals, M, a, b)
    if r >= 0:
        return r
    if a > b:
        t = a
        a = b
        b = t
    r = 2 * st[0]
    st[0] += 1
    key = a * M + b
    size = len(keys)
    h = (key * 0x9E3779B1) & (size - 1)
    while keys[h] >= 0:
        h = (h + 1) & (size - 1)
    keys[h] = key
    vals[h] = r
    return r


@njit(cache=True)
def _fx_and_many(xs, m, keys, vals, M, st):
    """:meth:`mlc.logic.aig.AIG.and_many` (the balanced tree) of ``xs[:m]``, in place."""
    if m == 0:
        return 1
    while m > 1:
        k = 0
        i = 0
        while i < m - 1:
            xs[k] = _fx_and(xs[i], xs[i + 1], keys, vals, M, st)
            k += 1
            i += 2
        if m % 2:
            xs[k] = xs[m - 1]
            k += 1
        m = k
    return xs[0]


@njit(cache=True)
def _fx_cube(p, q, nv, keys, vals, M, st):
    xs = np.empty(2 * nv, dtype=np.int64)
    m = 0
    for i in range(nv):
        if (p >> i) & 1:
            xs[m] = 2 * (i + 1)
            m += 1
    for i in range(nv):
        if (q >> i) & 1:
            xs[m] = 2 * (i + 1) + 1
            m += 1
    return _fx_and_many(xs, m, keys, vals, M, st)


@njit(cache=True)
def _fx_factor(P0, Q0, nv, keys, vals, M, st):
    """:func:`mlc.logic.lower.factor_sop`'s recursion on the cubes ``P0``/``Q0``, with an
    explicit stack (frames' cubes one after the other in an arena); returns the literal."""
    m0 = len(P0)
    cap = 2 * m0 + 1                      # grown on demand (as the frames)
    AP = np.empty(cap, dtype=np.int64)
    AQ = np.empty(cap, dtype=np.int64)
    AP[:m0] = P0
    AQ[:m0] = Q0
    D = 8
    fs = np.empty(D, dtype=np.int64)       # a frame's first cube in the arena
    fm = np.empty(D, dtype=np.int64)       # its cube count
    fstage = np.empty(D, dtype=np.int64)
    fa = np.empty(D, dtype=np.int64)       # the literal waiting for the child's
    fb = np.empty(D, dtype=np.int64)       # the chosen literal's variable
    fn = np.empty(D, dtype=np.int64)       # ... and its polarity
    cnt_p = np.empty(nv, dtype=np.int64)
    cnt_q = np.empty(nv, dtype=np.int64)
    d = 0
    fs[0] = 0
    fm[0] = m0
    fstage[0] = 0
    ret = 0
    while d >= 0:
        s = fs[d]
        m = fm[d]
        e = s + m
        stg = fstage[d]
        cm = 0                              # the child's cube count (at most m)
        if e + m > cap:                     # room for a child's cubes after this frame's
            while e + m > cap:
                cap *= 2
            AP = _grown(AP, cap)
            AQ = _grown(AQ, cap)
        if stg == 0:
            if m == 0:
                ret = 0
                d -= 1
                continue
            taut = False
            for j in range(s, e):
                if AP[j] == 0 and AQ[j] == 0:
                    taut = True
                    break
            if taut:
                ret = 1
                d -= 1
                continue
            if m == 1:
                ret = _fx_cube(AP[s], AQ[s], nv, keys, vals, M, st)
                d -= 1
                continue
            cp = -1
            cq = -1
            for j in range(s, e):
                cp &= AP[j]
                cq &= AQ[j]
            if cp != 0 or cq != 0:
                fa[d] = _fx_cube(cp, cq, nv, keys, vals, M, st)
                fstage[d] = 1
                cm = m
                for j in range(m):
                    AP[e + j] = AP[s + j] & ~cp
                    AQ[e + j] = AQ[s + j] & ~cq
            else:
                for i in range(nv):
                    cnt_p[i] = 0
                    cnt_q[i] = 0
                for j in range(s, e):
                    for i in range(nv):
                        cnt_p[i] += (AP[j] >> i) & 1
                        cnt_q[i] += (AQ[j] >> i) & 1
                best = -1
                neg = 0
                bestc = 1
                for i in range(nv):
                    if cnt_p[i] > bestc:
                        best = i
                        neg = 0
                        bestc = cnt_p[i]
                    if cnt_q[i] > bestc:
                        best = i
                        neg = 1
                        bestc = cnt_q[i]
                if best < 0:
                    xs = np.empty(m, dtype=np.int64)
                    for j in range(m):
                        xs[j] = _fx_cube(AP[s + j], AQ[s + j], nv, keys, vals, M, st) ^ 1
                    ret = _fx_and_many(xs, m, keys, vals, M, st) ^ 1
                    d -= 1
                    continue
                fb[d] = best
                fn[d] = neg
                fstage[d] = 2
                bit = 1 << best
                cm = bestc
                k = e
                for j in range(s, e):
                    if neg:
                        if AQ[j] & bit:
                            AP[k] = AP[j]
                            AQ[k] = AQ[j] & ~bit
                            k += 1
                    elif AP[j] & bit:
                        AP[k] = AP[j] & ~bit
                        AQ[k] = AQ[j]
                        k += 1
        elif stg == 1:
            ret = _fx_and(fa[d], ret, keys, vals, M, st)
            d -= 1
            continue
        elif stg == 2:
            t = _fx_and(2 * (fb[d] + 1) + fn[d], ret, keys, vals, M, st)
            bit = 1 << fb[d]
            k = e
            for j in range(s, e):
                if not ((AQ[j] if fn[d] else AP[j]) & bit):
                    AP[k] = AP[j]
                    AQ[k] = AQ[j]
                    k += 1
            cm = k - e
            if cm == 0:
                ret = t
                d -= 1
                continue
            fa[d] = t
            fstage[d] = 3
        else:
            ret = _fx_and(fa[d] ^ 1, ret ^ 1, keys, vals, M, st) ^ 1
            d -= 1
            continue
        if d + 1 >= D:
            D *= 2
            fs = _grown(fs, D)
            fm = _grown(fm, D)
            fstage = _grown(fstage, D)
            fa = _grown(fa, D)
            fb = _grown(fb, D)
            fn = _grown(fn, D)
        fs[d + 1] = e
        fm[d + 1] = cm
        fstage[d + 1] = 0
        d += 1
    return ret


@njit(cache=True)
def _grown(a, size):
    b = np.empty(size, dtype=a.dtype)
    b[:len(a)] = a
    return b


@njit(cache=True)
def _sop_phase(L, U, n, W, full):
    """``(ANDs of the factored form, cube masks P, Q, cube count)`` of the ISOP of [L, U]."""
    cap = 1 << n                   # an irredundant cover has at most one cube a minterm
    P = np.zeros(cap, dtype=np.int64)
    Q = np.zeros(cap, dtype=np.int64)
    m = _isop(L, U, n, W, full, P, Q)
    lits = 0
    for j in range(m):
        for i in range(n):
            lits += ((P[j] >> i) & 1) + ((Q[j] >> i) & 1)
    # the factored form of a cover with l literals has at most l ANDs
    N = n + 2 + lits
    size = 1
    while size < 4 * N:
        size *= 2
    keys = np.full(size, -1, dtype=np.int64)
    vals = np.zeros(size, dtype=np.int64)
    st = np.full(1, n + 1, dtype=np.int64)
    _fx_factor(P[:m].copy(), Q[:m].copy(), n, keys, vals, 2 * N + 2, st)
    return st[0] - (n + 1), P, Q, m


# ----------------------------------------------------------------------------- decomposition analysis


def analyse_full(f: int, n: int):
    """The table work of :meth:`mlc.logic.decomp._Dec._analyse` for a completely
    specified ``f`` (Python int over ``n <= SOP_MAX_VARS`` variables, neither
    constant): ``(dep, steps, score, t16)``, arrays over the variables --
    ``dep[i]`` whether ``f`` depends on variable ``i``; ``steps[i]`` the one-variable
    steps on ``i`` as bits (1: cofactor 0 is 0, 2: cofactor 1 is 0, 4: cofactor 1 is
    all ones, 8: cofactor 0 is all ones, 16: the cofactors are complements); ``score[i]``
    the number of variables each cofactor depends on, summed -- and ``t16`` the table
    over the support (its variables in increasing order) repeated to 16 bits, where the
    support has at most 4 variables (else 0)."""
    W, _full, fullw = _full_words(n)
    t = np.frombuffer(f.to_bytes(8 * W, "little"), dtype="<u8").astype(np.uint64)
    return _analyse_full(t, n, W, fullw)


@njit(cache=True)
def _analyse_full(t, n, W, full):
    dep = np.zeros(n, dtype=np.int64)
    steps = np.zeros(n, dtype=np.int64)
    score = np.zeros(n, dtype=np.int64)
    nsup = 0
    for i in range(n):
        if _tw_depends(t, i, W):
            dep[i] = 1
            nsup += 1
    c0 = np.empty(W, dtype=np.uint64)
    c1 = np.empty(W, dtype=np.uint64)
    for i in range(n):
        if dep[i] == 0:
            continue
        _tw_cof_to(t, i, W, False, c0)
        _tw_cof_to(t, i, W, True, c1)
        z0 = True
        z1 = True
        o0 = True
        o1 = True
        cp = True
        for w in range(W):
            if c0[w] != 0:
                z0 = False
            if c1[w] != 0:
                z1 = False
            if c0[w] != full[w]:
                o0 = False
            if c1[w] != full[w]:
                o1 = False
            if c0[w] != (c1[w] ^ full[w]):
                cp = False
        steps[i] = (1 if z0 else 0) | (2 if z1 else 0) | (4 if o1 else 0) \
            | (8 if o0 else 0) | (16 if cp else 0)
        s = 0
        for j in range(n):
            if j != i:
                if _tw_depends(c0, j, W):
                    s += 1
                if _tw_depends(c1, j, W):
                    s += 1
        score[i] = s
    t16 = 0
    if nsup <= 4:
        sup = np.zeros(4, dtype=np.int64)
        k = 0
        for i in range(n):
            if dep[i]:
                sup[k] = i
                k += 1
        for lm in range(1 << k):
            m = 0
            for i in range(k):
                if (lm >> i) & 1:
                    m |= 1 << sup[i]
            if (t[m >> 6] >> np.uint64(m & 63)) & np.uint64(1):
                t16 |= 1 << lm
        w = 1 << k
        while w < 16:
            t16 |= t16 << w
            w *= 2
    return dep, steps, score, t16
