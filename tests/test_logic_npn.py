"""The shipped exact NPN table of 4-input functions."""
import random

from mlc.logic import npn
from mlc.logic import tt as T
from mlc.logic.aig import AIG


def test_table_covers_all_classes_and_is_correct():
    tab = npn.table()
    reps = npn.classes()
    assert len(reps) == 222 and set(tab) == set(reps)
    for R, ent in tab.items():
        g = AIG(["a", "b", "c", "d"])
        lits = [2, 4, 6, 8]
        for j, l, fj, fl, fo in ent["gates"]:
            lits.append(g.and_(lits[j] ^ fj, lits[l] ^ fl) ^ fo)
        node, c = ent["out"]
        lit = c if node < 0 else lits[node] ^ c
        g.add_output("f", lit)
        assert g.truth_tables() == [R], hex(R)
        assert len(ent["gates"]) == ent["ands"]


def test_known_costs():
    a, b, c, d = (T.var(4, i) for i in range(4))
    assert npn.cost4(a & b) == 1
    assert npn.cost4(a ^ b) == 3
    assert npn.cost4(a ^ b ^ c ^ d) == 9
    assert npn.cost4((a & b) | (a & c) | (b & c)) == 4


def test_canon_and_build_random():
    rng = random.Random(3)
    for _ in range(300):
        f = rng.getrandbits(16)
        R, perm, neg, out = npn.canon(f)
        assert npn.canon(R)[0] == R
        g = AIG(["a", "b", "c", "d"])
        g.add_output("f", npn.build4(g, f, [2, 4, 6, 8]))
        assert g.truth_tables() == [f]
        assert g.cleanup().num_ands() <= npn.cost4(f)


def _eval_transform(R, perm, neg, out):
    """The table x -> R(y) ^ out with y_i = x[perm[i]] ^ neg_i, evaluated minterm by minterm."""
    f = 0
    for x in range(16):
        y = 0
        for i in range(4):
            if ((x >> perm[i]) & 1) ^ ((neg >> i) & 1):
                y |= 1 << i
        f |= (((R >> y) & 1) ^ out) << x
    return f


def test_canon_all_lists_exactly_the_transforms_onto_the_representative():
    # every listed transform maps f onto its class representative (checked minterm
    # by minterm, not through the LUTs), and their number is the size of f's
    # stabiliser: 768 transforms (24 permutations x 16 negations x 2) / its orbit size
    rng = random.Random(5)
    a, b, c, d = (T.var(4, i) for i in range(4))
    for f in [a & b, a ^ b ^ c ^ d, (a & b) | (c & d)] + [rng.getrandbits(16) for _ in range(20)]:
        R = npn.canon(f)[0]
        ts = npn.canon_all(f)
        assert npn.canon(f) in ts
        for R2, perm, neg, out in ts:
            assert R2 == R and _eval_transform(R, perm, neg, out) == f
        orbit = {_eval_transform(f, p, n, o) for p, n, _ in npn._TRANSFORMS for o in (0, 1)}
        assert len(ts) * len(orbit) == 768


def test_sat_proves_small_minima():
    """The exact engine proves the full adder (7) and majority-3 (4) minimal and its
    circuits simulate correctly."""
    from mlc.logic import exactsat, library
    for spec, k in ((library.full_adder(), 7), (library.majority(3), 4)):
        full = T.mask(spec.n)
        targets = [(f, full) for f in spec.on]
        assert exactsat.synthesize_exact(spec.n, targets, k - 1) is None
        r = exactsat.synthesize_exact(spec.n, targets, k)
        assert r is not None
        got = exactsat.circuit_tables(spec.n, *r)
        assert got == list(spec.on)


def test_table_metadata():
    import json
    data = json.loads(npn.TABLE_PATH.read_text())
    cls = data["classes"]
    assert all(isinstance(v.get("proven"), bool) for v in cls.values())
    assert sorted(k for k, v in cls.items() if not v["proven"]) == data["unproven"]
    assert sum(v["proven"] for v in cls.values()) == 222 and data["unproven"] == []
    assert cls["6996"]["ands"] == 9 and cls["6996"]["proven"]       # parity-4


def test_cadical_time_limit_runs_in_a_child():
    """CaDiCaL cannot be interrupted through python-sat: a time-limited call runs in a
    child process that is killed at the limit; an easy call still returns its answer."""
    from mlc.logic import exactsat, library
    spec = library.full_adder()
    targets = [(f, T.mask(3)) for f in spec.on]
    r = exactsat.synthesize_exact(3, targets, 7, time_limit=60, solver="cadical195")
    assert r not in (None, "timeout")
    assert exactsat.circuit_tables(3, *r) == list(spec.on)
    # proving that NPN class 0x0197 needs more than 8 ANDs takes minutes
    assert exactsat.synthesize_exact(4, [(0x0197, 0xFFFF)], 8, time_limit=0.5,
                                     solver="cadical195") == "timeout"


def test_minimality_of_small_entries_re_proven():
    """Re-prove, independently of the generator, that every entry of 2 to 6 ANDs
    cannot be built with one gate fewer (the larger ones take minutes each)."""
    from mlc.logic import exactsat
    tab = npn.table()
    for R in sorted(R for R, e in tab.items() if 2 <= e["ands"] <= 6):
        k = tab[R]["ands"]
        assert exactsat.synthesize_exact(4, [(R, 0xFFFF)], k - 1, solver="cadical195") is None, hex(R)


def test_fences_and_symmetry_breaking_keep_the_minimum():
    """Fences partition the search and symmetry breaking keeps one circuit per orbit:
    on a seeded sample of classes both must still find the stored size and prove one
    gate fewer infeasible (a wrong constraint would lose solutions or keep none)."""
    from mlc.logic import exactsat
    assert exactsat.fences(4) == [(1, 1, 1, 1), (1, 2, 1), (2, 1, 1)]
    tab = npn.table()
    pool = sorted(R for R, e in tab.items() if 3 <= e["ands"] <= 5)
    for R in random.Random(2).sample(pool, 10):
        k = tab[R]["ands"]
        hits = []
        for f in exactsat.fences(k):
            r = exactsat.synthesize_exact(4, [(R, 0xFFFF)], k, solver="cadical195", fence=f,
                                          symmetry=True)
            if r is not None:
                assert exactsat.circuit_tables(4, *r) == [R]
                hits.append(f)
        assert hits, hex(R)
        assert all(exactsat.synthesize_exact(4, [(R, 0xFFFF)], k - 1, solver="cadical195", fence=f,
                                             symmetry=True) is None for f in exactsat.fences(k - 1))
    assert exactsat.symmetric_inputs(4, 0x6996) == [[0, 1, 2, 3]]      # parity-4
    a, b, c = (T.var(4, i) for i in range(3))
    assert exactsat.symmetric_inputs(4, (a & b) | c) == [[0, 1]]        # d unused: no link


def test_first_use_symmetry_breaking_on_fully_symmetric_classes():
    """Fully symmetric classes get the stronger first-use constraint (fences only): it
    must keep a circuit of the stored size and still refute one gate fewer."""
    from mlc.logic import exactsat
    tab = npn.table()
    for R in (0x0001, 0x0117, 0x0180):
        assert exactsat.symmetric_inputs(4, R) == [[0, 1, 2, 3]]
        k = tab[R]["ands"]
        r = exactsat.synthesize_exact_fenced(4, [(R, 0xFFFF)], k)
        assert r not in (None, "timeout") and exactsat.circuit_tables(4, *r) == [R]
        assert exactsat.synthesize_exact_fenced(4, [(R, 0xFFFF)], k - 1) is None


def test_prover_moves_a_symmetric_group_last_and_maps_back():
    from mlc.logic import exactsat
    from mlc.logic.gen_npn_table import _permuted, _suffix_perm, _unpermute
    tab = npn.table()
    a, b, c = (T.var(4, i) for i in range(3))
    for f in ((a & b) | c, 0x0018):
        R = npn.canon(f)[0]
        perm = _suffix_perm(R)
        assert perm is not None
        Rp = _permuted(R, perm)
        assert exactsat.suffix_symmetric(4, Rp)
        k = tab[R]["ands"]
        r = exactsat.synthesize_exact_fenced(4, [(Rp, 0xFFFF)], k)
        assert exactsat.circuit_tables(4, *_unpermute(r, perm)) == [R]
        assert exactsat.synthesize_exact_fenced(4, [(Rp, 0xFFFF)], k - 1) is None
