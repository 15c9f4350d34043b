"""Equivalence checking: exhaustive, SAT (see also test_logic_cec.py), BDD, don't cares,
and mismatches caught."""
import pytest

from mlc.errors import InternalError
from mlc.spec import NetworkSpec, Node, TableSpec
from mlc.logic import tt as T
from mlc.logic.aig import AIG
from mlc.logic.equiv import check_equivalent
from mlc.logic.lower import from_spec


def fa_spec():
    a, b, c = (T.var(3, i) for i in range(3))
    return TableSpec(["a", "b", "c"], ["s", "co"], [a ^ b ^ c, (a & b) | (a & c) | (b & c)], [0, 0])


def test_exhaustive_ok_and_broken_aig_caught():
    spec = fa_spec()
    g = from_spec(spec)
    r = check_equivalent(g, spec)
    assert r["method"] == "exhaustive" and r["equivalent"] is True
    bad = g.copy()
    bad.output_lits[1] ^= 1              # complement the carry
    with pytest.raises(InternalError, match="NOT equivalent.*output co"):
        check_equivalent(bad, spec)
    bad = g.copy()
    a, b = bad.ands[0]
    bad.ands[0] = (a ^ 1, b) if (a ^ 1) < b else (b, a ^ 1)   # flip one fanin polarity
    with pytest.raises(InternalError):
        check_equivalent(bad, spec)


def test_dont_cares_respected():
    # y = a & b, don't care where a=1,b=0: y = a is a valid implementation
    spec = TableSpec(["a", "b"], ["y"], [0b1000], [0b0010])
    g = AIG(["a", "b"])
    g.add_output("y", 2)
    assert check_equivalent(g, spec)["equivalent"]
    g2 = AIG(["a", "b"])
    g2.add_output("y", 4)                # y = b differs on minterm 0b01? no: on m=0b10 -> care
    with pytest.raises(InternalError):
        check_equivalent(g2, spec)


def test_names_must_match():
    spec = fa_spec()
    g = from_spec(spec)
    g.outputs = ["s", "carry"]
    with pytest.raises(InternalError, match="outputs"):
        check_equivalent(g, spec)


def _all_ops_network(n=4):
    ins = [f"x{i}" for i in range(n)]
    nodes = [Node("input", name=x) for x in ins]
    ops = [("and", (0, 1, 2)), ("or", (0, 1)), ("xor", (0, 1, 2, 3)), ("nand", (1, 2)),
           ("nor", (2, 3)), ("xnor", (0, 3)), ("implies", (0, 1)), ("iff", (1, 2)),
           ("maj", (0, 1, 2)), ("maj", (0, 1, 2, 3, 3)), ("mux", (0, 1, 2)), ("not", (3,)),
           ("buf", (2,)), ("const0", ()), ("const1", ())]
    for op, args in ops:
        nodes.append(Node(op, args))
    nodes.append(Node("sop", (0, 1, 2), cover=[("1-0", "1"), ("011", "1")]))
    nodes.append(Node("sop", (0, 1), cover=[("11", "0")]))
    nodes.append(Node("sop", (0,), cover=[]))
    outs = list(range(n, len(nodes)))
    return NetworkSpec(ins, [f"o{k}" for k in range(len(outs))], nodes, outs)


def test_network_ops_lowered_correctly():
    spec = _all_ops_network()
    g = from_spec(spec)
    check_equivalent(g, spec)
    tabs = g.truth_tables()
    x = [T.var(4, i) for i in range(4)]
    full = T.mask(4)
    want = [x[0] & x[1] & x[2], x[0] | x[1], x[0] ^ x[1] ^ x[2] ^ x[3], full & ~(x[1] & x[2]),
            full & ~(x[2] | x[3]), full & ~(x[0] ^ x[3]), (full & ~x[0]) | x[1],
            full & ~(x[1] ^ x[2]), (x[0] & x[1]) | (x[0] & x[2]) | (x[1] & x[2]),
            None, (x[0] & x[1]) | (~x[0] & x[2] & full), full & ~x[3], x[2], 0, full,
            (x[0] & ~x[2] & full) | (~x[0] & x[1] & x[2] & full), full & ~(x[0] & x[1]), 0]
    for k, w in enumerate(want):
        if w is not None:
            assert tabs[k] == w, k
    # maj of (x0, x1, x2, x3, x3): at least 3 of 5
    for m in range(16):
        bits = [(m >> i) & 1 for i in (0, 1, 2, 3, 3)]
        assert (tabs[9] >> m) & 1 == int(sum(bits) >= 3)


def _wide_parity(n):
    ins = [f"x{i}" for i in range(n)]
    nodes = [Node("input", name=x) for x in ins] + [Node("xor", tuple(range(n))),
                                                   Node("and", tuple(range(n)))]
    return NetworkSpec(ins, ["p", "a"], nodes, [n, n + 1])


def test_wide_network_uses_sat_and_catches_mismatch():
    spec = _wide_parity(20)
    g = from_spec(spec)
    r = check_equivalent(g, spec)
    assert r["method"] == "sat"
    bad = g.copy()
    bad.output_lits[1] = 0               # constant 0 instead of the 20-input AND:
    with pytest.raises(InternalError, match="output a"):   # differs on one minterm only
        check_equivalent(bad, spec)


def test_wide_table_uses_bdd():
    n = 17
    x0, x1, x16 = T.var(n, 0), T.var(n, 1), T.var(n, 16)
    spec = TableSpec([f"x{i}" for i in range(n)], ["f"], [(x0 & x1) | x16], [0])
    g = from_spec(spec)
    assert check_equivalent(g, spec)["method"] == "bdd"
    bad = g.copy()
    bad.output_lits[0] ^= 1
    with pytest.raises(InternalError, match="output f"):
        check_equivalent(bad, spec)
