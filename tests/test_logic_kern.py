"""The numba kernels of the windowed passes (mlc.logic.kern) against the Python code
they replace: the same networks out of resub_window and resub_dc, the same cuts."""
import random

import pytest

from mlc.logic import kern, opt
from helpers import random_aig
from mlc.logic.aig import AIG


def _random_aig(seed: int, n_in: int = 20, n_and: int = 400, n_out: int = 12) -> AIG:
    return random_aig(seed, n_in, n_and, n_out, window=40)


def _both(fn, g, **kw):
    old = opt.KERNELS, opt.KERNEL_MIN_ANDS
    try:
        opt.KERNELS = False
        ref = fn(g, **kw)
        opt.KERNELS, opt.KERNEL_MIN_ANDS = True, 0
        new = fn(g, **kw)
    finally:
        opt.KERNELS, opt.KERNEL_MIN_ANDS = old
    return ref, new


def test_warm_and_size_gate(monkeypatch):
    assert kern.warm() >= 0.0
    monkeypatch.setattr(kern, "READY", False)      # as in a process without numba yet
    calls = []
    monkeypatch.setattr(opt, "_rewrite_nb", lambda *a: calls.append(1) or a[0])
    small = _random_aig(7, n_in=opt.TT_LIMIT, n_and=opt.KERNEL_MIN_ANDS - 20)
    big = _random_aig(7, n_and=3 * opt.KERNEL_MIN_ANDS)
    assert small.num_ands() < opt.KERNEL_MIN_ANDS <= big.num_ands()
    opt.rewrite(small)
    assert calls == []
    opt.rewrite(big)
    assert calls == [1]
    wide = _random_aig(7, n_in=opt.TT_LIMIT + 1, n_and=opt.KERNEL_MIN_ANDS - 20)
    assert wide.num_ands() < opt.KERNEL_MIN_ANDS
    opt.rewrite(wide)
    assert calls == [1, 1]
    monkeypatch.setattr(kern, "READY", True)       # numba running: small ones too
    opt.rewrite(small)
    assert calls == [1, 1, 1]


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_resub_window_same_network(seed):
    g = _random_aig(seed)
    for kw in ({}, {"max_leaves": 10, "max_window": 150}, {"max_new": 1}):
        ref, new = _both(opt.resub_window, g, **kw)
        assert new.to_text() == ref.to_text()
    assert ref.num_ands() < g.num_ands()        # the pass did something to compare


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_resub_dc_same_network(seed):
    g = _random_aig(seed)
    ref, new = _both(opt.resub_dc, g)
    assert new.to_text() == ref.to_text()
    assert ref.num_ands() < g.num_ands()
    # and on the result of a few passes (shared nodes, fewer redundancies)
    h = opt.resub_window(opt.rewrite(ref))
    ref2, new2 = _both(opt.resub_dc, h)
    assert new2.to_text() == ref2.to_text()


def test_reconv_cut_same_leaves():
    g = _random_aig(3)
    fa, fb, _s, _l = kern.aig_arrays(g)
    ws = kern.Workspace(g.num_nodes, 14)
    for x in range(g.num_inputs + 1, g.num_nodes, 7):
        for m in (4, 8, 14):
            got = kern.reconv_cut_py(fa, fb, g.num_inputs, x, m, ws.mark, ws.buf[0], ws.buf[1])
            assert got.tolist() == opt.reconv_cut(g, x, m)
    assert not ws.mark.any()


def test_fanouts_csr():
    g = _random_aig(4, n_and=100)
    _fa, _fb, start, lst = kern.aig_arrays(g)
    n = g.num_inputs
    fo = [[] for _ in range(g.num_nodes)]
    for k, (a, b) in enumerate(g.ands):
        fo[a >> 1].append(n + 1 + k)
        if b >> 1 != a >> 1:
            fo[b >> 1].append(n + 1 + k)
    for y in range(g.num_nodes):
        assert lst[start[y]:start[y + 1]].tolist() == fo[y]


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_rewrite_same_network(seed):
    g = _random_aig(seed)
    ref, new = _both(opt.rewrite, g)
    assert new.to_text() == ref.to_text()
    assert ref.to_text() != g.to_text()          # moves were made
    for zg in (False, True):
        h = opt.resub_window(ref)
        r2, n2 = _both(opt.rewrite, h, zero_gain=zg)
        assert n2.to_text() == r2.to_text()


def test_cuts_same():
    g = _random_aig(5, n_and=200)
    fa, fb, _s, _l = kern.aig_arrays(g)
    cl, cn, cc = kern.enumerate_cuts(fa, fb, g.num_inputs, g.num_nodes, 4, opt.CUT_LIMIT)
    ref = opt.enumerate_cuts(g, limit=opt.CUT_LIMIT)
    for x in range(g.num_inputs + 1, g.num_nodes):
        got = [tuple(cl[x, c, :cn[x, c]].tolist()) for c in range(cc[x])]
        assert got == ref[x]
    # the strash table answers as AIG.lookup
    keys, vals = kern.strash_table(fa, fb, g.num_inputs, g.num_nodes)
    M = 2 * g.num_nodes + 2
    rng = random.Random(0)
    for _ in range(2000):
        a = rng.randrange(2 * g.num_nodes)
        b = rng.randrange(2 * g.num_nodes)
        if rng.random() < 0.5:
            a, b = g.ands[rng.randrange(len(g.ands))]
        r = g.lookup(a, b)
        assert kern.lookup(keys, vals, M, a, b) == (-1 if r is None else r)


@pytest.mark.parametrize("n_in", [5, 7, 11])
def test_global_resub_same_network(n_in):
    g = _random_aig(10 + n_in, n_in=n_in, n_and=150, n_out=6)
    rng = random.Random(n_in)
    full = (1 << (1 << n_in)) - 1
    care = [full & ~rng.getrandbits(1 << n_in) & rng.getrandbits(1 << n_in) | (full if k % 2 else 0)
            for k in range(len(g.outputs))]
    for kw in ({}, {"care_out": care}, {"max_new": 1}):
        ref, new = _both(opt.resub, g, **kw)
        assert new.to_text() == ref.to_text()
    ref, new = _both(opt.resub_odc, g, care_out=care)
    assert new.to_text() == ref.to_text()
    assert ref.num_ands() < g.num_ands()


@pytest.mark.parametrize("seed", [0, 1])
def test_refactor_same_network(seed):
    g = _random_aig(seed)
    for kw in ({}, {"max_leaves": 10, "zero_gain": True}):
        ref, new = _both(opt.refactor, g, **kw)
        assert new.to_text() == ref.to_text()
    assert ref.to_text() != g.to_text()


def test_npn_canon_same():
    from mlc.logic import npn
    kern.aig_arrays(_random_aig(0, n_and=100))         # READY: npn.canon goes to numba
    assert kern.READY
    rng = random.Random(1)
    lo, hi = kern.npn_arrays()[:2]
    for f in [0, 0xFFFF, 0x8000, 0x6996, 0x1669] + [rng.getrandbits(16) for _ in range(300)]:
        npn.canon.cache_clear()
        got = npn.canon(f)
        kern.READY = False
        npn.canon.cache_clear()
        ref = npn.canon(f)
        kern.READY = True
        assert got == ref
        assert type(got[0]) is int and type(got[3]) is int
    npn.canon.cache_clear()


def test_table_rows_grow_on_demand(monkeypatch):
    # few table rows at first: windows that may not fit are retried after grow()
    monkeypatch.setattr(kern.Workspace, "ROWS", 40)
    grown = []
    real = kern.Workspace.grow
    monkeypatch.setattr(kern.Workspace, "grow", lambda self: grown.append(1) or real(self))
    g = _random_aig(1)
    for fn in (opt.resub_window, opt.resub_dc):
        ref, new = _both(fn, g)
        assert new.to_text() == ref.to_text()
    assert grown


def test_mffc_same():
    g = _random_aig(6)
    fa, fb, _s, _l = kern.aig_arrays(g)
    ws = kern.Workspace(g.num_nodes)
    refs = opt.refcounts(g)
    import numpy as np
    r = np.array(refs, dtype=np.int64)
    for x in range(g.num_inputs + 1, g.num_nodes):
        if refs[x] == 0:
            continue
        k = kern.mffc(fa, fb, g.num_inputs, x, r, ws.mark, ws.buf[1], ws.buf[2], ws.buf[3])
        assert sorted(ws.buf[1, :k].tolist()) == sorted(opt.mffc(g, x, refs))
    assert r.tolist() == refs


def _sop_reference(f, care, n):
    """decomp._Dec._sop_plan's Python work: tt.isop of each phase, factor_sop's count."""
    from mlc.logic import tt as T
    from mlc.logic.lower import factor_sop
    full = T.mask(n)
    out = []
    for on in (f, care & ~f):
        cubes, _ = T.isop(on, on | (full & ~care), n)
        g = AIG([f"x{i}" for i in range(n)])
        factor_sop(g, cubes, [2 * (i + 1) for i in range(n)])
        out.append((g.num_ands(), cubes))
    return tuple(out)


def test_sop_costs_same_as_isop_and_factor_sop(monkeypatch):
    from mlc.logic import decomp
    from mlc.logic import tt as T
    monkeypatch.setattr(kern, "READY", True)
    rng = random.Random(5)
    cases = []
    for n in range(1, kern.SOP_MAX_VARS + 1):
        full = T.mask(n)
        parity = 0
        for m in range(1 << n):
            parity |= (bin(m).count("1") & 1) << m
        cases += [(0, full, n), (full, full, n), (parity, full, n)]     # 2^(n-1) cubes
        for _ in range(40):
            f = rng.getrandbits(1 << n)
            for _ in range(rng.randint(0, 3)):                          # sparser, structured
                f &= rng.getrandbits(1 << n) | rng.getrandbits(1 << n)
            care = full if rng.random() < 0.4 else (rng.getrandbits(1 << n)
                                                      | rng.getrandbits(1 << n))
            cases.append((f & care, care, n))
    for f, care, n in cases:
        got = kern.sop_costs(f, care, n)
        assert got == _sop_reference(f, care, n), (f, care, n)
        full = T.mask(n)
        for (_k, cubes), on in zip(got, (f, care & ~f)):
            cover = 0
            for c in cubes:
                cover |= T.cube_tt(c, n)
            assert cover & care == on                  # the cover is in the interval
        plans = []
        for on in (False, True):                       # _Dec's choice of phase (ties: on-set)
            monkeypatch.setattr(opt, "KERNELS", on)
            plans.append(decomp._Dec(n, 2)._sop_plan(f, care))
        assert plans[0] == plans[1]


@pytest.mark.parametrize("seed", [0, 1])
def test_refactor_decomposition_kernel_same_network(seed, monkeypatch):
    # the decomposition's caches are cleared between the paths, so that the kernel
    # path computes its factored-SOP costs itself (kern.sop_costs) instead of reading
    # the Python path's
    from mlc.logic import decomp
    calls = []
    real = kern.sop_costs
    monkeypatch.setattr(kern, "sop_costs", lambda *a: calls.append(1) or real(*a))
    g = _random_aig(seed + 10)
    for kw in ({}, {"max_leaves": 10, "zero_gain": True}):
        texts = []
        for on in (False, True):
            for c in (decomp._support_cache, decomp._sop_cache, decomp._exact_cache,
                      decomp._analysis_cache):
                c.clear()
            old = opt.KERNELS, opt.KERNEL_MIN_ANDS
            opt.KERNELS, opt.KERNEL_MIN_ANDS = on, 0
            try:
                n_calls = len(calls)
                texts.append(opt.refactor(g, **kw).to_text())
                assert (len(calls) > n_calls) == on
            finally:
                opt.KERNELS, opt.KERNEL_MIN_ANDS = old
        assert texts[0] == texts[1]
    assert texts[0] != g.to_text()


def test_npn_matches_memo_fits_and_matches_the_transforms():
    import numpy as np
    from mlc.logic import npn
    lo, hi = kern.npn_arrays()[:2]
    canon = np.full(1 << 16, -1, dtype=np.int64)
    start = np.zeros(1 << 16, dtype=np.int64)
    count = np.zeros(1 << 16, dtype=np.int64)
    pool = np.zeros(kern.NPN_POOL, dtype=np.int32)
    top = np.zeros(1, dtype=np.int64)
    rng = random.Random(9)
    sample = {0, 0xFFFF, 0x8000, 0x6996, 0xCAFE} | {rng.getrandbits(16) for _ in range(200)}
    for f in range(1 << 16):                   # every function: the pool holds them all
        R = kern.npn_matches(f, lo, hi, canon, start, count, pool, top)
        assert kern.npn_matches(f, lo, hi, canon, start, count, pool, top) == R   # memo
        if f not in sample:
            continue
        assert R == npn.canon(f)[0]
        want = []
        for idx, (perm, neg, _x) in enumerate(npn._TRANSFORMS):
            # the transform's table, straight from its definition
            g = 0
            for m in range(16):
                y = sum((((m >> perm[i]) & 1) ^ ((neg >> i) & 1)) << i for i in range(4))
                g |= ((f >> m) & 1) << y
            if g == R:
                want.append(2 * idx)
            elif g ^ 0xFFFF == R:
                want.append(2 * idx + 1)
        assert pool[start[f]:start[f] + count[f]].tolist() == want
    assert top[0] <= kern.NPN_POOL


def test_analyse_full_same_records_as_python_analysis(monkeypatch):
    # decomp._Dec._analyse of completely specified functions: kern.analyse_full's
    # support, steps, Shannon scores and 4-variable table give the Python path's record
    from mlc.logic import decomp
    from mlc.logic import tt as T
    monkeypatch.setattr(kern, "READY", True)
    rng = random.Random(41)
    cases = []
    for n in range(1, kern.SOP_MAX_VARS + 1):
        full = T.mask(n)
        pos, _ = T.var_tables(n)
        for _ in range(30):
            f = rng.getrandbits(1 << n) & full
            for i in range(n):                          # drop some variables
                if rng.random() < 0.4:
                    f = T.cof0(f, n, i) if rng.random() < 0.5 else T.cof1(f, n, i)
            if n > 1 and rng.random() < 0.5:            # one-variable steps on top
                i = rng.randrange(n)
                g = T.cof0(f, n, i)
                x = pos[i] ^ (full if rng.random() < 0.5 else 0)
                f = rng.choice([x & g, x | g, x ^ g]) & full
            cases.append((n, f))
        cases += [(n, pos[0]), (n, full ^ pos[n - 1])]
    kinds = set()
    for n, f in cases:
        full = T.mask(n)
        recs = []
        for on in (False, True):
            monkeypatch.setattr(opt, "KERNELS", on)
            for c in (decomp._support_cache, decomp._sop_cache, decomp._exact_cache):
                c.clear()
            for effort in (1, 2, 3):
                recs.append(decomp._Dec(n, effort)._analyse(f, full))
        assert recs[:3] == recs[3:], (n, f)
        for r in recs:
            kinds.add((r[0], r[0] == 3 and r[1] <= 4, r[0] == 3 and bool(r[2]),
                       r[0] == 3 and bool(r[4])))
    # constants, literals, exact, steps, SOP + Shannon and SOP alone all met
    assert {(0, False, False, False), (2, False, False, False), (3, True, False, False),
            (3, True, True, False), (3, False, True, False), (3, False, False, True),
            (3, False, False, False)} <= kinds
