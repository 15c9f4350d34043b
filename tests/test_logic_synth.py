"""Synthesis: property tests (random tables with don't cares, every effort level),
the proven minima of issue 4, and network specifications."""
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from mlc.errors import MlcError
from mlc.spec import NetworkSpec, Node, TableSpec
from mlc.logic import library
from mlc.logic import tt as T
from mlc.logic.equiv import check_equivalent
from mlc.logic.synth import synthesize


@st.composite
def tables(draw, max_inputs=6, max_outputs=3):
    n = draw(st.integers(0, max_inputs))
    m = draw(st.integers(1, max_outputs))
    full = T.mask(n)
    on, dc = [], []
    for _ in range(m):
        f = draw(st.integers(0, full))
        d = draw(st.sampled_from([0, 0, draw(st.integers(0, full))]))
        on.append(f & ~d)
        dc.append(d)
    return TableSpec([f"x{i}" for i in range(n)], [f"y{k}" for k in range(m)], on, dc)


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(spec=tables(), effort=st.integers(0, 2))
def test_random_tables_equivalent(spec, effort):
    g = synthesize(spec, effort)            # proves equivalence itself ...
    g.check()
    assert check_equivalent(g, spec)["equivalent"]   # ... and again, independently
    assert g.inputs == spec.inputs and g.outputs == spec.outputs


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(spec=tables(max_inputs=4, max_outputs=2))
def test_random_tables_effort3(spec):
    g = synthesize(spec, 3, time_budget=0.5)
    assert check_equivalent(g, spec)["equivalent"]


@pytest.mark.parametrize("spec, minimum", [
    (library.full_adder(), 7), (library.adder(2), 10), (library.multiplier(2), 8),
    (library.majority(3), 4), (library.parity(4), 9), (library.half_adder(), 3),
    (library.parity(3), 6), (library.mux(1), 3),
])
def test_proven_minima(spec, minimum):
    g = synthesize(spec)
    assert g.num_ands() == minimum, g.to_text()


def test_effort_levels_and_errors():
    spec = library.bcd7seg()
    sizes = [synthesize(spec, e, time_budget=2.0).num_ands() for e in (0, 1, 2)]
    assert sizes[2] <= sizes[1] <= sizes[0]
    with pytest.raises(MlcError):
        synthesize(spec, 4)


def test_constant_and_literal_outputs():
    full = T.mask(2)
    spec = TableSpec(["a", "b"], ["zero", "one", "a", "nb"], [0, full, T.var(2, 0),
                                                               full & ~T.var(2, 1)], [0] * 4)
    g = synthesize(spec)
    assert g.num_ands() == 0
    assert g.output_lits == [0, 1, 2, 5]


def test_network_spec_synthesis_shares_logic():
    # s = a ^ b ^ c; co = maj(a, b, c): the full adder from expressions -> 7 ANDs
    nodes = [Node("input", name=x) for x in "abc"] + [Node("xor", (0, 1, 2)),
                                                      Node("maj", (0, 1, 2))]
    spec = NetworkSpec(list("abc"), ["s", "co"], nodes, [3, 4])
    g = synthesize(spec)
    assert g.num_ands() == 7


def test_wide_network_synthesis_proven_by_sat():
    n = 18
    ins = [f"x{i}" for i in range(n)]
    nodes = [Node("input", name=x) for x in ins] + [Node("xor", tuple(range(n))),
                                                   Node("or", tuple(range(0, n, 2)))]
    spec = NetworkSpec(ins, ["p", "o"], nodes, [n, n + 1])
    st_: dict = {}
    g = synthesize(spec, stats=st_)
    assert st_["equivalence"]["method"] == "sat"
    # 3 (n - 1) for the XOR, n/2 - 1 for the OR, less the n // 4 XOR gadgets on two
    # even inputs whose NOR (~a & ~b) the OR tree shares
    assert g.num_ands() == 3 * (n - 1) + n // 2 - 1 - n // 4


def test_dont_cares_used():
    spec = library.bcd7seg()
    g = synthesize(spec)
    assert g.num_ands() <= 16     # ABC compress2rs: 16


def test_xor_chain_balanced_for_depth():
    # ((((x0 ^ x1) ^ x2) ^ x3) ...) as a chain: same 21 ANDs, depth of a balanced tree
    n = 8
    nodes = [Node("input", name=f"x{i}") for i in range(n)]
    prev = 0
    for i in range(1, n):
        nodes.append(Node("xor", (prev, i)))
        prev = len(nodes) - 1
    spec = NetworkSpec([f"x{i}" for i in range(n)], ["p"], nodes, [prev])
    g = synthesize(spec)
    assert g.num_ands() == 21
    assert g.depth() == 6


def test_wide_adder_network_windowed_resub():
    # 24 inputs: beyond global truth tables; windowed resubstitution still shares the
    # XOR internals with the carries: 3 (half adder) + 11 * 7 (full adders) = 80 ANDs
    spec = library.ripple_adder(12)
    st_: dict = {}
    g = synthesize(spec, stats=st_)
    assert st_["equivalence"]["method"] == "sat"
    assert g.num_ands() == 80


_OPS = ["and", "or", "xor", "nand", "nor", "xnor", "implies", "iff", "maj", "mux", "not",
        "buf", "sop", "const0", "const1"]


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(rnd=st.randoms(use_true_random=False), n=st.sampled_from([1, 2, 3, 5, 7, 17]),
       effort=st.integers(0, 2))
def test_random_networks_equivalent(rnd, n, effort):
    nodes = [Node("input", name=f"x{i}") for i in range(n)]
    for _ in range(rnd.randint(1, 20)):
        op, k = rnd.choice(_OPS), len(nodes)
        if op in ("const0", "const1"):
            nodes.append(Node(op, ()))
            continue
        if op == "sop":
            a = rnd.randint(1, 3)
            args = tuple(rnd.randrange(k) for _ in range(a))
            bit = rnd.choice("01")
            cover = [("".join(rnd.choice("01-") for _ in range(a)), bit)
                     for _ in range(rnd.randint(0, 3))]
            nodes.append(Node("sop", args, cover=cover))
            continue
        arity = {"not": 1, "buf": 1, "implies": 2, "iff": 2, "mux": 3}.get(op)
        if op == "maj":
            arity = rnd.choice([1, 3, 5])
        if arity is None:
            arity = rnd.randint(1, 4)
        nodes.append(Node(op, tuple(rnd.randrange(k) for _ in range(arity))))
    outs = [rnd.randrange(len(nodes)) for _ in range(rnd.randint(1, 3))]
    spec = NetworkSpec([f"x{i}" for i in range(n)], [f"o{i}" for i in range(len(outs))],
                       nodes, outs)
    g = synthesize(spec, effort)
    assert check_equivalent(g, spec)["equivalent"]


def test_optimize_holds_off_full_garbage_collections(monkeypatch):
    # full collections (generation 2) wait until the optimisation ends, the young
    # generations are still collected, and the thresholds come back, also on an error
    import gc
    from mlc.logic import opt
    spec = TableSpec([f"x{i}" for i in range(7)], ["y"], [0x96696996_69969669_12345678_9ABCDEF0],
                     [0])
    gens = []

    def seen(phase, info):
        if phase == "start":
            gens.append(info["generation"])

    old = gc.get_threshold()
    gc.set_threshold(10, 1, 1)              # a full collection every 100 allocations
    gc.callbacks.append(seen)
    try:
        g = opt.optimize(spec, 2)
        during = list(gens)
        assert gc.get_threshold() == (10, 1, 1)

        def boom(*a):
            raise RuntimeError("boom")
        monkeypatch.setattr(opt, "_optimize_spec", boom)
        with pytest.raises(RuntimeError):
            opt.optimize(spec, 2)
        assert gc.get_threshold() == (10, 1, 1)
    finally:
        gc.callbacks.remove(seen)
        gc.set_threshold(*old)
    assert g.truth_tables() == spec.on
    assert 0 in during and 2 not in during
