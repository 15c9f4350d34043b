"""Shannon decomposition with exact synthesis of the cofactors (mlc.logic.cofexact)."""
from __future__ import annotations

import pytest

from mlc.logic import cofexact, exactsat, library
from mlc.logic import tt as T
from mlc.logic.equiv import check_equivalent, spec_tables

pytestmark = pytest.mark.skipif(not exactsat.available(), reason="python-sat not installed")


def test_majority5_in_10_ands():
    """The cofactors of majority-5 on any input are the thresholds T3, T2 of the other
    four; SAT joins them in 8 gates (the minimum, checked below by UNSAT at 7) and
    T3 <= T2 costs 2 more: 10, as ABC's &deepsyn (the heuristic flow gives 12)."""
    spec = library.majority(5)
    on, dc = spec_tables(spec)
    targets, refs = cofexact._split(5, on, dc, 0)
    assert len(targets) == 2 and refs == [(("tgt", 0, 0), ("tgt", 1, 0))]
    assert cofexact._join_bound(*refs[0], targets) == 2
    r = exactsat.synthesize_exact(4, targets, 8)
    assert isinstance(r, tuple)
    g = cofexact._build(spec, 0, refs, cofexact._circuit_aig(4, r), 4)
    assert g.num_ands() == 10
    assert check_equivalent(g, spec)["equivalent"]


@pytest.mark.parametrize("x", range(5))
def test_split_and_build_respect_dont_cares(x):
    """_build joins any realisation of the cofactor targets into a network equal to the
    specification on its care set; here every target is realised by its own SOP
    network, so the check covers constants, literals, complements and the mux/OR joins."""
    spec = library.random_function(5, 3, 40 + x, 0.3)
    on, dc = spec_tables(spec)
    targets, refs = cofexact._split(5, on, dc, x)
    # one gate list realising every target exactly on its care set (Shannon-free SOP)
    gates, outs = [], []
    for t, care in targets:
        cubes, _ = T.isop(t & care, t | (T.mask(4) & ~care), 4)
        terms = []
        for p, q in cubes:
            lits = [(i, 0) for i in range(4) if (p >> i) & 1] + [(i, 1) for i in range(4) if (q >> i) & 1]
            node, c = lits[0]
            for i, ci in lits[1:]:
                gates.append((node, i, c, ci, 0))
                node, c = 4 + len(gates) - 1, 0
            terms.append((node, c))
        node, c = terms[0]
        for n2, c2 in terms[1:]:             # OR = !( !a & !b )
            gates.append((node, n2, c ^ 1, c2 ^ 1, 1))
            node, c = 4 + len(gates) - 1, 0
        outs.append((node, c))
    tabs = exactsat.circuit_tables(4, gates, outs)
    for (t, care), tab in zip(targets, tabs):
        assert tab & care == t & care
    g = cofexact._build(spec, x, refs, cofexact._circuit_aig(4, (gates, outs)), 4)
    assert check_equivalent(g, spec)["equivalent"]


def test_majority5_found_without_sat_luck():
    """The -O2 flow on the cofactor table already gives 8, so the 10 does not depend
    on the SAT solver's time limit (0.2 s here: at most the heuristic part runs)."""
    from mlc.logic.lower import from_spec
    spec = library.majority(5)
    g = cofexact.try_cofactor_exact(spec, from_spec(spec), 0.0)
    assert g is not None and g.num_ands() == 10
    assert check_equivalent(g, spec)["equivalent"]


def test_only_five_inputs():
    spec = library.majority(3)
    from mlc.logic.lower import from_spec
    assert cofexact.try_cofactor_exact(spec, from_spec(spec), 1.0) is None


def test_every_input_of_a_symmetric_function_gives_the_same_targets():
    spec = library.majority(5)
    on, dc = spec_tables(spec)
    keys = {tuple(cofexact._split(5, on, dc, x)[0]) for x in range(5)}
    assert len(keys) == 1


def test_extract_and_shares_common_pairs():
    """(The -O3 restarts' other new pass.)  Three 3-input ANDs over a, b and one more
    input each, built so that no pair is shared: 6 ANDs; extract_and builds a & b
    once and reuses it: 1 + 3 = 4 ANDs, same functions."""
    from mlc.logic.aig import AIG
    from mlc.logic.opt import extract_and
    g = AIG(["a", "b", "c", "d", "e"])
    a, b, c, d, e = (2 * (i + 1) for i in range(5))
    g.add_output("x", g.and_(g.and_(a, c), b))
    g.add_output("y", g.and_(g.and_(b, d), a))
    g.add_output("z", g.and_(g.and_(a, e), b))
    g = g.cleanup()
    assert g.num_ands() == 6
    h = extract_and(g)
    assert h.num_ands() == 4
    assert h.truth_tables() == g.truth_tables()


def test_extract_and_keeps_functions_on_random_networks():
    from mlc.logic.opt import extract_and
    from mlc.logic.lower import from_spec
    for seed in range(6):
        spec = library.random_function(6, 3, 100 + seed)
        g = from_spec(spec)
        h = extract_and(g)
        assert h.truth_tables() == g.truth_tables()
        assert h.num_ands() <= g.num_ands()


def test_extract_and_wide_and_trees_past_the_leaf_limit():
    """An AND chain over 20 inputs (more than the 16-leaf limit) and an OR chain: the
    node where collapsing stops must become a root of its own (it was once left as a
    constant 0)."""
    from mlc.logic.aig import AIG
    from mlc.logic.opt import extract_and
    g = AIG([f"x{i}" for i in range(20)])
    a = o = 2
    for i in range(1, 20):
        a = g.and_(a, 2 * (i + 1))
        o = g.or_(o, 2 * (i + 1))
    g.add_output("a", a)
    g.add_output("o", o)
    g.add_output("m", g.and_(a ^ 1, o))
    h = extract_and(g)
    width = 1 << 10
    import random
    rnd = random.Random(3)
    words = [rnd.getrandbits(width) for _ in range(20)]
    words[0] = words[1] = (1 << width) - 1
    for i in range(2, 20):
        words[i] |= rnd.getrandbits(width) | rnd.getrandbits(width)
    assert h.simulate(words, width) == g.simulate(words, width)
    ones = [(1 << width) - 1] * 20
    assert h.simulate(ones, width) == g.simulate(ones, width)
    assert h.num_ands() <= g.num_ands()
