"""SAT-sweeping equivalence (mlc.logic.cec) and its place in check_equivalent:
wide networks proven by SAT, counterexamples found where simulation misses them,
don't cares respected, and the BDD fallback when SAT exceeds its budget."""
import random

import pytest

from mlc.errors import InternalError
from mlc.spec import NetworkSpec, Node
from mlc.logic import cec, equiv, library
from mlc.logic.lower import from_spec
from mlc.logic.netsim import simulate_network
from mlc.logic.synth import synthesize


def _and_all(n: int, dc: list[int] | None = None) -> NetworkSpec:
    ins = [f"x{i}" for i in range(n)]
    nodes = [Node("input", name=x) for x in ins] + [Node("and", tuple(range(n)))]
    return NetworkSpec(ins, ["f"], nodes, [n], dc=dc)


def test_wide_multiplier_synthesized_and_proven_by_sat():
    spec = library.array_multiplier(10)           # 20 inputs: beyond exhaustive simulation
    st: dict = {}
    g = synthesize(spec, stats=st)
    rep = st["equivalence"]
    assert rep["method"] == "sat" and rep["equivalent"] is True and rep["inputs"] == 20
    assert rep["merged"] > 0
    rng = random.Random(3)
    for _ in range(20):
        m = rng.getrandbits(20)
        bits = [(m >> i) & 1 for i in range(20)]
        got = g.simulate(bits, 1)
        assert sum(b << k for k, b in enumerate(got)) == (m & 1023) * (m >> 10)


def test_single_minterm_difference_found_by_sat_not_simulation():
    # impl = constant 0, spec = 24-input AND: they differ on one minterm of 2**24,
    # which random simulation practically never hits; SAT must return exactly it
    spec = _and_all(24)
    g = from_spec(spec)
    g.output_lits[0] = 0
    res = cec.check(g, spec)
    assert res == [(1 << 24) - 1]
    with pytest.raises(InternalError, match="output f is 0, specification says 1"):
        equiv.check_equivalent(g, spec)


def test_dont_cares_respected():
    n = 17
    only = 1 << ((1 << n) - 1)                     # don't care on the all-ones minterm
    spec = _and_all(n, dc=[only])
    g = from_spec(_and_all(n))
    g.output_lits[0] = 0                           # differs only inside the don't cares
    assert cec.check(g, spec) == [None]
    assert equiv.check_equivalent(g, spec)["method"] == "sat"
    spec_other = _and_all(n, dc=[1])               # don't care elsewhere: still a mismatch
    assert cec.check(g, spec_other) == [(1 << n) - 1]


def test_sweeping_refines_candidates_with_counterexamples():
    # two outputs whose nodes agree on most random patterns: x0&...&x9 vs x0&...&x8
    n = 18
    ins = [f"x{i}" for i in range(n)]
    nodes = [Node("input", name=x) for x in ins] + [Node("and", tuple(range(10))),
                                                   Node("and", tuple(range(9)))]
    spec = NetworkSpec(ins, ["f", "g"], nodes, [n, n + 1])
    g = from_spec(spec)
    st: dict = {}
    assert cec.check(g, spec, stats=st) == [None, None]
    bad = from_spec(spec)
    bad.output_lits[0] = bad.output_lits[1]        # f := g, differs when x9 = 0 only
    res = cec.check(bad, spec)
    assert res[1] is None and res[0] is not None
    m = res[0]
    bits = [(m >> i) & 1 for i in range(n)]
    assert simulate_network(spec, bits, 1) != bad.simulate(bits, 1)


def _xor_chain(n: int, order) -> NetworkSpec:
    ins = [f"x{i}" for i in range(n)]
    nodes = [Node("input", name=x) for x in ins]
    prev = order[0]
    for i in order[1:]:
        nodes.append(Node("xor", (prev, i)))
        prev = len(nodes) - 1
    return NetworkSpec(ins, ["p"], nodes, [prev])


def test_over_budget_is_undecided_never_equivalent(monkeypatch):
    # b*a against a*b: unrelated structures, hard for SAT (14 inputs: cec works at any
    # width).  Over its budget the check says Undecided; with its budget it proves it.
    # (Sweeping with Glucose and 16384 patterns merges enough of the two that the
    # outputs then need no conflict at all, so the sweep gets 1 conflict per pair too.)
    spec = library.array_multiplier(7)
    g = from_spec(library.array_multiplier(7, swap=True))
    monkeypatch.setattr(cec, "SWEEP_CONFLICTS", 1)
    with pytest.raises(cec.Undecided):
        cec.check(g, spec, max_conflicts=1)


def test_undecided_sat_falls_back_to_bdd(monkeypatch):
    n = 18
    spec = _xor_chain(n, list(range(n)))
    g = from_spec(_xor_chain(n, list(range(n))[::-1]))
    assert cec.check(g, spec) == [None]
    assert equiv.check_equivalent(g, spec)["method"] == "sat"

    def undecided(*a, **k):
        raise cec.Undecided("over budget")
    monkeypatch.setattr(cec, "check", undecided)
    assert equiv.check_equivalent(g, spec)["method"] == "bdd"
    bad = g.copy()
    bad.output_lits[0] ^= 1
    with pytest.raises(InternalError, match="output p"):
        equiv.check_equivalent(bad, spec)


def test_miter_is_structurally_zero_for_a_copy():
    spec = library.array_multiplier(4)
    m, outs = cec.miter(from_spec(spec), spec)
    assert outs == [0] * 8


def test_output_left_open_by_the_sweeping_solver_goes_to_cadical(monkeypatch):
    # nothing merged by the sweep and no conflict allowed to the sweeping solver on the
    # outputs: the proof (and a counterexample for a wrong circuit) comes from the
    # CaDiCaL fallback, which gets the same clauses and the proven equivalences
    spec = library.array_multiplier(6)
    g = from_spec(library.array_multiplier(6, swap=True))
    monkeypatch.setattr(cec, "SWEEP_CONFLICTS", 1)
    monkeypatch.setattr(cec, "SWEEP_OUTPUT_CONFLICTS", 1)
    calls = []
    real = cec._Sat.__init__

    def spy(self, m, solver=cec.SOLVER):
        calls.append(solver)
        real(self, m, solver)
    monkeypatch.setattr(cec._Sat, "__init__", spy)
    assert cec.check(g, spec) == [None] * len(spec.outputs)
    assert calls == [cec.SWEEP_SOLVER, cec.SOLVER]
    bad = from_spec(library.array_multiplier(6, swap=True))
    bad.output_lits[3] ^= 1
    res = cec.check(bad, spec)
    assert res[3] is not None
