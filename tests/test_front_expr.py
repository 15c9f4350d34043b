"""The expression parser and printer: semantics, golden output, error rules, and the
parse -> print -> parse property."""
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mlc.errors import MlcError
from mlc.front.expr import parse, print_network
from mlc.front.load import spec_text, truth_tables
from helpers import assert_parse_error, check_golden

ROOT = Path(__file__).resolve().parents[1]
GOLDEN = ROOT / "tests" / "golden" / "front"




def table(text, out=0):
    spec = parse(text, "t")
    return truth_tables(spec)[0][out], spec


def tt_of(fn, n):
    """Truth table of a Python function of n bits (input i = bit i of the minterm)."""
    return sum(1 << m for m in range(1 << n) if fn(*[(m >> i) & 1 for i in range(n)]))


def test_golden_full_adder():
    spec = parse((ROOT / "examples" / "full_adder.expr").read_text(), "examples/full_adder.expr")
    check_golden("full_adder.expr.txt", spec_text(spec))
    check_golden("full_adder.expr.printed", print_network(spec))
    on, _ = truth_tables(spec)
    assert on == [tt_of(lambda a, b, c: a ^ b ^ c, 3), tt_of(lambda a, b, c: a + b + c >= 2, 3)]


@pytest.mark.parametrize("text,fn,n", [
    ("a & b | c", lambda a, b, c: (a & b) | c, 3),
    ("a | b & c", lambda a, b, c: a | (b & c), 3),
    ("a ^ b & c", lambda a, b, c: a ^ (b & c), 3),
    ("a | b ^ c", lambda a, b, c: a | (b ^ c), 3),
    ("!a & ~b", lambda a, b: (1 - a) & (1 - b), 2),
    ("a -> b -> c", lambda a, b, c: (1 - a) | ((1 - b) | c), 3),
    ("a -> b | c", lambda a, b, c: (1 - a) | b | c, 3),
    ("a <-> b -> c", lambda a, b, c: int(a == ((1 - b) | c)), 3),
    ("a <-> b <-> c", lambda a, b, c: int(int(a == b) == c), 3),
    ("maj(a, b, c)", lambda a, b, c: int(a + b + c >= 2), 3),
    ("maj(a, b, c, d, e)", lambda a, b, c, d, e: int(a + b + c + d + e >= 3), 5),
    ("mux(s, a, b)", lambda s, a, b: a if s else b, 3),
    ("ite(s, a, b)", lambda s, a, b: a if s else b, 3),
    ("xor(a, b, c)", lambda a, b, c: a ^ b ^ c, 3),
    ("xnor(a, b)", lambda a, b: 1 - (a ^ b), 2),
    ("nand(a, b, c)", lambda a, b, c: 1 - (a & b & c), 3),
    ("nor(a, b)", lambda a, b: 1 - (a | b), 2),
    ("and(a, b) | or(a, b) & not(a)", lambda a, b: (a & b) | ((a | b) & (1 - a)), 2),
    ("a & 1 | 0", lambda a: a, 1),
])
def test_semantics(text, fn, n):
    got, spec = table(text)
    assert got == tt_of(fn, n), text
    assert spec.outputs == ["f"]


def test_statements_inputs_outputs_and_newlines():
    src = """# comment
inputs c, b a
outputs o2 o1
t = a &
    b          # continues after an operator
o1 = t | (c
  & a)
o2 = !t; unused = a
"""
    spec = parse(src, "s.expr")
    assert spec.inputs == ["c", "b", "a"] and spec.outputs == ["o2", "o1"]
    on, _ = truth_tables(spec)
    assert on[0] == tt_of(lambda c, b, a: 1 - (a & b), 3)
    assert on[1] == tt_of(lambda c, b, a: (a & b) | (c & a), 3)
    # canonical shape: inputs first, in declared order
    assert [nd.op for nd in spec.nodes[:3]] == ["input"] * 3


def test_every_assignment_is_an_output_without_declaration():
    spec = parse("s = a ^ b ^ c; co = maj(a, b, c)", "<-e>")
    assert spec.outputs == ["s", "co"] and spec.inputs == ["a", "b", "c"]
    spec = parse("a & b; a | b", "<-e>")
    assert spec.outputs == ["f0", "f1"]


def test_aliases_constants_and_inputs_as_outputs():
    spec = parse("x = a & b; y = x; z = a; k = 1", "t")
    assert spec.output_nodes[0] == spec.output_nodes[1]
    assert spec.nodes[spec.output_nodes[2]].op == "input"
    text = print_network(spec)
    assert "y = x;" in text and "z = a;" in text and "k = 1;" in text
    assert print_network(parse(text, "t2")) == text


def test_sharing_creates_named_wires():
    spec = parse("outputs f; t = a ^ b; f = t & c | t & d", "t")
    text = print_network(spec)
    assert "t = a ^ b;" in text
    assert print_network(parse(text, "t2")) == text


def test_deep_nesting_is_split_not_crashing():
    src = "f = " + "(" * 90 + "a" + " & b)" * 90
    spec = parse(src, "d")
    text = print_network(spec)
    assert print_network(parse(text, "d2")) == text
    with pytest.raises(MlcError, match="nested more than"):
        parse("f = " + "(" * 1000 + "a" + ")" * 1000, "d")


BAD = [
    ("f = a $ b", "1:7", "unexpected character '$'"),
    ("f = a & 2", "1:9", "the only constants are 0 and 1"),
    ("f = a &", "1:8", "found end of input"),
    ("f = (a & b", "1:11", "expected ')'"),
    ("f = a b", "1:7", "expected ';' or a line break"),
    ("f = foo(a)", "1:5", "unknown function 'foo'"),
    ("f = mux(a, b)", "1:5", "takes 3 arguments"),
    ("f = maj(a, b)", "1:5", "odd number"),
    ("f = not(a, b)", "1:5", "not takes 1 argument"),
    ("f = a\nf = b", "2:1", "defined twice"),
    ("f = t & a\nt = b", "2:1", "used as an input before, at line 1 column 5"),
    ("inputs a\nf = a & b", "2:9", "neither a declared input"),
    ("inputs a\na = 1", "2:1", "declared as an input"),
    ("outputs f, g\nf = a\n", "1:12", "'g' is declared but never defined"),
    ("outputs g\noutputs h", "2:1", "second 'outputs'"),
    ("f = a\ninputs a", "2:1", "before the first expression"),
    ("inputs a a", "1:10", "listed twice"),
    ("inputs a, ", "1:11", "expected a name after ','"),
    ("outputs f g\nf = g & a\ng = b", "2:5", "output 'g' is used before it is defined"),
    ("a = a", "1:1", "used in its own definition"),
    ("", "1", "no expressions"),
    ("inputs a b\noutputs a", "2:9", "both as an input and as an output"),
]


@pytest.mark.parametrize("text,where,words", BAD)
def test_error_rules(text, where, words):
    assert_parse_error(parse, text, "bad.expr", where, words)


# ---------------------------------------------------------------- property: parse / print / parse

NAMES = ["a", "b", "c", "d"]


def _exprs():
    leaf = st.one_of(st.sampled_from(NAMES), st.sampled_from(["0", "1"]))

    def extend(children):
        return st.one_of(
            st.tuples(st.sampled_from(["!", "~"]), children).map(lambda t: f"{t[0]}{t[1]}"),
            st.tuples(children, st.sampled_from(["&", "|", "^", "->", "<->"]), children,
                      st.booleans()).map(lambda t: f"({t[0]} {t[1]} {t[2]})" if t[3] else f"{t[0]} {t[1]} {t[2]}"),
            st.tuples(st.sampled_from(["maj", "xor", "nand", "nor", "xnor", "and", "or"]),
                      st.lists(children, min_size=1, max_size=4)).map(
                lambda t: f"{t[0]}({', '.join(t[1] if t[0] != 'maj' or len(t[1]) % 2 else t[1][:-1])})"),
            st.tuples(st.sampled_from(["mux", "ite"]), children, children, children).map(
                lambda t: f"{t[0]}({t[1]}, {t[2]}, {t[3]})"),
            children.map(lambda s: f"({s})"),
        )
    return st.recursive(leaf, extend, max_leaves=12)


@st.composite
def programs(draw):
    k = draw(st.integers(1, 3))
    stmts = []
    for i in range(k):
        e = draw(_exprs())
        if i and draw(st.booleans()):
            e = f"{e} ^ w{i - 1}"            # reuse an earlier statement: shared nodes
        stmts.append(f"w{i} = {e}")
    return ";\n".join(stmts)


def _shape(spec):
    return ([(n.op, n.args) for n in spec.nodes], spec.output_nodes, spec.inputs, spec.outputs)


@settings(max_examples=150, deadline=None)
@given(programs())
def test_parse_print_parse(src):
    p1 = parse(src, "p1")
    t1 = print_network(p1)
    p2 = parse(t1, "p2")
    assert truth_tables(p2) == truth_tables(p1)
    assert _shape(p2) == _shape(p1)
    assert print_network(p2) == t1


def test_abc_eqn_style():
    """ABC's write_eqn output: INORDER/OUTORDER, * and +, statements may wrap lines."""
    src = """# Equations for "mux4" written by ABC
INORDER = s0 s1 d0 d1
  d2 d3;
OUTORDER = y;
new_n9_ = (d1 * s0) + (d0 * !s0);
y = (s1 * ((d3 * s0) + (d2 * !s0))) +
    (!s1 * new_n9_);
"""
    spec = parse(src, "m.eqn")
    assert spec.inputs == ["s0", "s1", "d0", "d1", "d2", "d3"] and spec.outputs == ["y"]
    on, _ = truth_tables(spec)
    for m in range(64):
        assert (on[0] >> m) & 1 == (m >> (2 + (m & 3))) & 1


def test_star_and_plus_operators():
    got, _ = table("a * b + !c")
    assert got == tt_of(lambda a, b, c: (a & b) | (1 - c), 3)
