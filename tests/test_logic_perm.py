"""Issue 15: the gate count does not depend on the order in which a specification
lists its inputs and outputs.

Every benchmark function and a set of multi-output functions of 4 to 8 inputs are
compiled in random listings (inputs and outputs permuted, seeded); each listing must
give the same AND count.  The permuted specifications are built here with plain
Python loops, independently of :func:`mlc.logic.canon.permuted`.
"""
import random

import pytest

from mlc.spec import NetworkSpec, Node, TableSpec
from mlc.logic import canon, library
from mlc.logic.equiv import check_equivalent
from mlc.logic.synth import synthesize


def relist(spec: TableSpec, pi: list[int], po: list[int]) -> TableSpec:
    """New input k is old input pi[k]; new output k is old output po[k]."""
    n = spec.n
    on, dc = [], []
    for o in po:
        f = d = 0
        for m in range(1 << n):
            old = sum(((m >> k) & 1) << pi[k] for k in range(n))
            f |= ((spec.on[o] >> old) & 1) << m
            d |= ((spec.dc[o] >> old) & 1) << m
        on.append(f)
        dc.append(d)
    return TableSpec([spec.inputs[i] for i in pi], [spec.outputs[o] for o in po], on, dc,
                     spec.source)


def listings(spec: TableSpec, count: int, seed: int):
    """The given listing, the reversed one and ``count - 2`` random ones."""
    rng = random.Random(seed)
    n, m = spec.n, len(spec.outputs)
    yield spec
    yield relist(spec, list(range(n - 1, -1, -1)), list(range(m - 1, -1, -1)))
    for _ in range(count - 2):
        pi, po = list(range(n)), list(range(m))
        rng.shuffle(pi)
        rng.shuffle(po)
        yield relist(spec, pi, po)


def multi_output_functions():
    """Multi-output functions of 4 to 8 inputs outside the benchmark suite."""
    return [library.gray(6), library.gray_to_bin(8), library.parity_prefix(6),
            library.comparator(3), library.adder(3), library.multiplier(2, 3),
            library.random_function(5, 3, 21), library.random_function(6, 2, 22, 0.2),
            library.random_function(8, 2, 23)]


def _names(fs):
    return [f.source for f in fs]


SUITE = library.suite()
MULTI = multi_output_functions()


@pytest.mark.parametrize("spec", SUITE + MULTI, ids=_names(SUITE + MULTI))
def test_canonical_form_is_listing_independent(spec):
    forms = set()
    for s in listings(spec, 5, seed=len(spec.source)):
        c = canon.canonical(s)
        assert c.exhaustive
        forms.add((tuple(c.spec.on), tuple(c.spec.dc)))
        # the canonical spec is the given one listed in c's order
        back = relist(s, c.in_perm, c.out_perm)
        assert (back.on, back.dc) == (c.spec.on, c.spec.dc)
    assert len(forms) == 1


def _budget(spec):
    # a small fixed work-clock budget keeps the test short; the result is still
    # deterministic (mlc/logic/work.py), so every listing must give the same count
    return 0.25 if spec.n >= 6 else None


@pytest.mark.parametrize("spec", SUITE + MULTI, ids=_names(SUITE + MULTI))
def test_gate_count_is_listing_independent(spec):
    counts = []
    for s in listings(spec, 3, seed=1 + len(spec.source)):
        g = synthesize(s, 2, time_budget=_budget(spec))   # proves equivalence itself
        assert g.inputs == s.inputs and g.outputs == s.outputs
        counts.append(g.num_ands())
    assert len(set(counts)) == 1, counts


@pytest.mark.parametrize("effort", [0, 1])
def test_low_effort_listing_independent(effort):
    for spec in (library.bcd7seg(), library.comparator(2), library.gray_to_bin(4)):
        counts = {synthesize(s, effort).num_ands() for s in listings(spec, 4, seed=5)}
        assert len(counts) == 1, (spec.source, counts)


def test_issue_15_examples_reach_the_minimum():
    # Gray-to-binary listed MSB first was 15 ANDs, the 2-bit comparator 10 in one
    # listing; both have 9-AND circuits (proven minima, benchmarks/results/synthesis.md)
    g2b = library.reversed_bits(library.gray_to_bin(4))
    assert g2b.inputs == ["g3", "g2", "g1", "g0"]
    assert synthesize(g2b, 2).num_ands() == 9
    for s in listings(library.comparator(2), 4, seed=9):
        assert synthesize(s, 2).num_ands() == 9


def test_network_listing_independent():
    # a network (expression) whose inputs and outputs are listed in two orders
    def net(order, out_order):
        ins = ["a", "b", "c", "d"]
        nodes = [Node("input", name=ins[i]) for i in order]
        pos = {ins[i]: k for k, i in enumerate(order)}
        a, b, c, d = (pos[x] for x in ins)
        nodes += [Node("xor", (a, b)), Node("xor", (c, d))]
        nodes += [Node("xor", (4, c)), Node("xor", (4, 5)), Node("and", (a, d))]
        outs = [4, 6, 7, 8]
        names = ["p", "q", "r", "s"]
        return NetworkSpec([ins[i] for i in order], [names[o] for o in out_order], nodes,
                           [outs[o] for o in out_order])

    s1 = net([0, 1, 2, 3], [0, 1, 2, 3])
    s2 = net([3, 1, 0, 2], [2, 0, 3, 1])
    g1, g2 = synthesize(s1, 2), synthesize(s2, 2)
    assert check_equivalent(g2, s2)["equivalent"]
    assert g1.num_ands() == g2.num_ands()


def test_restore_maps_back_to_the_listing():
    spec = library.adder(2)
    s = relist(spec, [3, 0, 2, 1], [2, 0, 1])
    c = canon.canonical(s)
    g = synthesize(c.spec, 1)
    h = canon.restore(g, c, s)
    assert h.inputs == s.inputs and h.outputs == s.outputs
    assert h.truth_tables() == s.on


def test_default_effort_meets_abc_on_majority5_and_cmp3():
    """At the default -O2 (issue 15 step): majority-5 in 10 ANDs (the Shannon split with
    the cofactors synthesised together, its deterministic part) and the 3-bit
    comparator in 13 (extra restarts regrouped by extract_and), ABC compress2rs's and
    &deepsyn's counts, in the given and the reversed listing (was 12 and 14)."""
    for spec, want in ((library.majority(5), 10), (library.comparator(3), 13)):
        for s in list(listings(spec, 2, seed=3)):
            assert synthesize(s, 2).num_ands() == want, s.source
