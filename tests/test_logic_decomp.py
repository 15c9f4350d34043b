"""Truth-table helpers of the decomposition (mlc.logic.tt.isop, decomp._Dec.reduce_support):
their fast paths give the same answers, in the same order, as the plain algorithms
(refactoring's networks depend on both)."""
import random

from helpers import random_aig
from mlc.logic import decomp
from mlc.logic import tt as T


def _isop_lists(lower, upper, n):
    """Minato-Morreale as it was written first: cube lists concatenated at every level."""
    full = T.mask(n)
    memo = {}

    def rec(L, U, top):
        if L == 0:
            return [], 0
        if U == full:
            return [(0, 0)], full
        if (L, U, top) in memo:
            return memo[L, U, top]
        v = top - 1
        while not (T.depends(L, n, v) or T.depends(U, n, v)):
            v -= 1
        L0, L1 = T.cof0(L, n, v), T.cof1(L, n, v)
        U0, U1 = T.cof0(U, n, v), T.cof1(U, n, v)
        c0, f0 = rec(L0 & ~U1 & full, U0, v)
        c1, f1 = rec(L1 & ~U0 & full, U1, v)
        c2, f2 = rec((L0 & ~f0 | L1 & ~f1) & full, U0 & U1, v)
        bit = 1 << v
        cubes = [(p, q | bit) for p, q in c0] + [(p | bit, q) for p, q in c1] + c2
        f = f2 | (f0 & T.nvar(n, v)) | (f1 & T.var(n, v))
        memo[L, U, top] = (cubes, f)
        return cubes, f

    return rec(lower, upper, n)


def test_isop_same_cubes_as_list_version_and_a_valid_cover():
    rng = random.Random(16)
    for _ in range(400):
        n = rng.randint(0, 8)
        full = T.mask(n)
        lower = rng.getrandbits(1 << n) & rng.getrandbits(1 << n) & full
        upper = (lower | (rng.getrandbits(1 << n) if rng.random() < 0.5 else 0)) & full
        cubes, tab = T.isop(lower, upper, n)
        assert (cubes, tab) == _isop_lists(lower, upper, n)
        cover = 0
        for c in cubes:
            cover |= T.cube_tt(c, n)
        assert cover == tab and lower & ~cover == 0 and cover & ~upper == 0
        for j in range(len(cubes)):            # irredundant: no cube can be dropped
            rest = 0
            for c in cubes[:j] + cubes[j + 1:]:
                rest |= T.cube_tt(c, n)
            assert lower & ~rest


def _support_general(n, f, care):
    """reduce_support's loop for incompletely specified functions."""
    sup = []
    for i in range(n):
        if not (T.depends(f, n, i) or T.depends(care, n, i)):
            continue
        on0, on1 = T.cof0(f, n, i), T.cof1(f, n, i)
        off = care & ~f
        of0, of1 = T.cof0(off, n, i), T.cof1(off, n, i)
        if on0 & of1 == 0 and on1 & of0 == 0:
            f, care = on0 | on1, T.cof0(care, n, i) | T.cof1(care, n, i)
        else:
            sup.append(i)
    return f & care, care, sup


def test_reduce_support_full_care_path_matches_general_loop():
    rng = random.Random(12)
    for _ in range(300):
        n = rng.randint(1, 8)
        full = T.mask(n)
        f = rng.getrandbits(1 << n) & full
        for i in range(n):                     # make some variables irrelevant
            if rng.random() < 0.3:
                f = T.cof0(f, n, i)
        for care in (full, full & ~(rng.getrandbits(1 << n) & rng.getrandbits(1 << n))):
            d = decomp._Dec(n, 2)
            got = d.reduce_support(f & care, care)
            assert got == _support_general(n, f & care, care)
            assert d.reduce_support(f & care, care) == got          # from the cache


def test_factor_sop_tautology_cube_and_covers():
    from mlc.logic.aig import AIG
    from mlc.logic.lower import factor_sop
    g = AIG(["a", "b", "c"])
    lits = [2, 4, 6]
    assert factor_sop(g, [(1, 0), (0, 0)], lits) == 1          # the empty cube
    assert factor_sop(g, [[1, 0], [0, 0]], lits) == 1          # given as lists
    assert factor_sop(g, [], lits) == 0
    rng = random.Random(3)
    for _ in range(100):                                       # the cover's function
        cubes = [(p & ~q, q) for p, q in ((rng.getrandbits(3), rng.getrandbits(3))
                                           for _ in range(rng.randint(1, 5)))]
        h = AIG(["a", "b", "c"])
        h.add_output("f", factor_sop(h, cubes, lits))
        want = 0
        for c in cubes:
            want |= T.cube_tt(c, 3)
        assert h.truth_tables()[0] == want


def test_cofactors_off_set_from_care_and_on_set():
    rng = random.Random(21)
    for _ in range(300):
        n = rng.randint(1, 8)
        full = T.mask(n)
        care = full & ~(rng.getrandbits(1 << n) & rng.getrandbits(1 << n))
        if rng.random() < 0.3:
            care = full                   # the full-care shortcut
        f = rng.getrandbits(1 << n) & care
        pos, neg = T.var_tables(n)
        i = rng.randrange(n)
        off = care & ~f
        want = (T.cof0(f, n, i), T.cof1(f, n, i), T.cof0(off, n, i), T.cof1(off, n, i),
                T.cof0(care, n, i), T.cof1(care, n, i))
        assert decomp._cofactors(f, care, 1 << i, pos[i], neg[i], full) == want


def test_no_step_matches_the_cofactor_conditions():
    rng = random.Random(22)
    seen = set()
    for _ in range(2000):
        n = rng.randint(1, 9)
        full = T.mask(n)
        pos, neg = T.var_tables(n)
        i = rng.randrange(n)
        g = rng.getrandbits(1 << n)
        if n > 1 and rng.random() < 0.6:
            # a one-variable step on i: x_i op g with g independent of x_i
            g = T.cof0(g, n, i)
            x = pos[i] ^ (full if rng.random() < 0.5 else 0)
            g = rng.choice([x & g, x | g, x ^ g]) & full
        on0, on1, of0, of1, _c0, _c1 = decomp._cofactors(g, full, 1 << i, pos[i], neg[i], full)
        step = (on0 == 0 or on1 == 0 or of1 == 0 or of0 == 0
                or (on0 & on1 == 0 and of0 & of1 == 0))
        got = bool(decomp._no_step(g, 1 << i, pos[i], neg[i]))
        assert got == (not step)
        seen.add(got)
    assert seen == {True, False}


def _random_network(seed: int, n_in: int = 14, n_and: int = 250, n_out: int = 8):
    return random_aig(seed, n_in, n_and, n_out, window=30)


def test_refactor_constant_cones_of_several_cut_sizes():
    # the constant plans are one object for the decompositions of every cut size:
    # refactor's scratch AIG of a constant met at 10 leaves was taken for a constant
    # cone over fewer leaves (IndexError) before the scratch AIGs were keyed by size
    from mlc.logic import opt
    for seed in (3, 4):
        g = _random_network(seed)
        h = opt.refactor(g, max_leaves=10, zero_gain=True)
        assert h.truth_tables() == g.truth_tables()
        assert h.num_ands() < g.num_ands()


def _random_tables(rng, n: int, n_out: int):
    """Outputs sharing remainders (g, x & g, !x | g, x ^ g, ...), so that the
    decomposition's shared steps find plans of earlier outputs; some don't cares."""
    from mlc.spec import TableSpec
    full = T.mask(n)
    pos, _ = T.var_tables(n)
    g = rng.getrandbits(1 << n) & full
    on, dc = [], []
    for _ in range(n_out):
        x = pos[rng.randrange(n)] ^ (full if rng.random() < 0.5 else 0)
        f = rng.choice([g, x & g, x | g, x ^ g, full ^ g, rng.getrandbits(1 << n) & full])
        d = 0 if rng.random() < 0.6 else rng.getrandbits(1 << n) & rng.getrandbits(1 << n) & full
        on.append(f & ~d & full)
        dc.append(d)
        if rng.random() < 0.5:
            g = f
    return TableSpec([f"x{i}" for i in range(n)], [f"o{k}" for k in range(n_out)], on, dc)


def _clear_caches():
    for c in (decomp._support_cache, decomp._sop_cache, decomp._exact_cache,
              decomp._analysis_cache):
        c.clear()


def test_analysis_memo_same_networks_as_plain_recursion(monkeypatch):
    # _Dec._rec reads its analysis of an interval from decomp._analysis_cache (the
    # memo path) or works it out afresh (ANALYSIS_MEMO False): same plans, same AIGs,
    # with the memo cold and warm (refactoring's later passes meet the same cones)
    from mlc.logic import opt
    analysed = []
    real = decomp._Dec._analyse
    monkeypatch.setattr(decomp._Dec, "_analyse",
                        lambda self, f, care: analysed.append(1) or real(self, f, care))
    rng = random.Random(31)
    jobs = []
    for _ in range(80):
        n = rng.randint(3, 7)
        spec = _random_tables(rng, n, rng.randint(1, 6))
        jobs.append(lambda spec=spec: decomp.from_table(spec).to_text())
    for seed in (3, 4):
        g = _random_network(seed)
        jobs.append(lambda g=g: opt.refactor(g).to_text())
        jobs.append(lambda g=g: opt.refactor(g, max_leaves=10, zero_gain=True).to_text())
    for job in jobs:
        _clear_caches()
        monkeypatch.setattr(decomp, "ANALYSIS_MEMO", False)
        want = job()
        assert not analysed
        monkeypatch.setattr(decomp, "ANALYSIS_MEMO", True)
        _clear_caches()
        assert job() == want                   # cold memo
        k = len(analysed)
        assert k > 0
        assert job() == want                   # warm memo: nothing analysed again
        assert len(analysed) == k
        analysed.clear()


def test_analysis_memo_leaves_random_shannon_choices_to_the_plain_path(monkeypatch):
    monkeypatch.setattr(decomp, "ANALYSIS_MEMO", True)
    rng = random.Random(32)
    for _ in range(20):
        spec = _random_tables(rng, rng.randint(5, 8), 3)
        texts = []
        for memo in (False, True):
            monkeypatch.setattr(decomp, "ANALYSIS_MEMO", memo)
            _clear_caches()
            texts.append(decomp.from_table(spec, rng=random.Random(7)).to_text())
        assert texts[0] == texts[1]
