"""The ASCII AIGER parser: golden output, semantics, error rules (binary AIGER: test_front_aig_binary.py)."""
from pathlib import Path

import pytest

from mlc.front.aiger import parse
from mlc.front.expr import parse as parse_expr
from mlc.front.load import spec_text, truth_tables
from helpers import assert_parse_error, check_golden

ROOT = Path(__file__).resolve().parents[1]
GOLDEN = ROOT / "tests" / "golden" / "front"




def test_golden_compare2():
    spec = parse((ROOT / "examples" / "compare2.aag").read_text(), "examples/compare2.aag")
    check_golden("compare2.aag.txt", spec_text(spec))
    ref = parse_expr("inputs a0 a1 b0 b1\ngt = a1 & !b1 | (a1 <-> b1) & a0 & !b0\n"
                     "lt = !a1 & b1 | (a1 <-> b1) & !a0 & b0\neq = (a1 <-> b1) & (a0 <-> b0)", "ref")
    assert truth_tables(spec) == truth_tables(ref)


def test_unordered_ands_constants_and_default_names():
    src = "aag 4 2 0 4 2\n2\n4\n8\n0\n1\n3\n8 6 2\n6 2 4\n"
    spec = parse(src, "u.aag")
    assert spec.inputs == ["i0", "i1"] and spec.outputs == ["o0", "o1", "o2", "o3"]
    on, _ = truth_tables(spec)
    assert on == [0b1000, 0, 0b1111, 0b1010 ^ 0b1111]


def test_aiger_1_9_header_with_zero_properties():
    spec = parse("aag 1 1 0 1 0 0 0 0 0\n2\n2\n", "h.aag")
    assert truth_tables(spec)[0] == [0b10]


BAD = [
    ("", "1", "empty AIGER"),
    ("aig 1 1 0 1 0\n", "1", "file ends before the output 0 line"),   # binary, by its header
    ("foo\n", "1:1", "first line must start with 'aag'"),
    ("aag 1 1\n", "1:1", "5 to 9 numbers"),
    ("aag 1 1 x 1 0\n2\n", "1:9", "non-negative integer"),
    ("aag 3 1 1 1 0\n2\n4 2\n4\n", "1:9", "latch"),
    ("aag 1 1 0 1 0 1\n2\n2\n", "1:15", "bad-state"),
    ("aag 1 1 0 1 1\n2\n2\n", "1:5", "M = 1 is smaller"),
    ("aag 1 1 0 1 0\n3\n2\n", "2:1", "input literal must be even"),
    ("aag 2 2 0 1 0\n2\n2\n2\n", "3:1", "defined twice"),
    ("aag 1 1 0 1 0\n2\n9\n", "3:1", "exceeds 2M+1"),
    ("aag 2 1 0 1 1\n2\n4\n5 2 2\n", "4:1", "AND output literal must be even"),
    ("aag 2 1 0 1 1\n2\n4\n4 2 9\n", "4:5", "literal 9 exceeds"),
    ("aag 2 1 0 1 1\n2\n4\n4 2\n", "4:4", "needs 3 numbers"),
    ("aag 2 1 0 1 1\n2\n4\n", "3", "file ends before the AND 0 line"),
    ("aag 3 1 0 1 1\n2\n4\n4 6 2\n", "4:3", "variable 3, which is neither"),
    ("aag 3 1 0 1 2\n2\n4\n4 6 2\n6 4 2\n", "4:1", "combinational loop"),
    ("aag 1 1 0 1 0\n2\n2\nx0 foo\n", "4:1", "expected a symbol line"),
    ("aag 1 1 0 1 0\n2\n2\ni1 foo\n", "4:1", "out of range"),
    ("aag 1 1 0 1 0\n2\n2\ni0 foo\ni0 bar\n", "5:1", "named twice"),
    ("aag 1 1 0 1 0\n2\n2\nl0 foo\n", "4:1", "'l' entry"),
    ("aag 1 1 0 1 0\n2\n2\ni0 my name\n", "4:4", "blanks"),
    ("aag 2 2 0 1 0\n2\n4\n2\ni0 i1\n", "1", "two inputs are called 'i1'"),
    ("aag 1 1 0 0 0\n2\n", "1:11", "no outputs"),
]


@pytest.mark.parametrize("text,where,words", BAD)
def test_error_rules(text, where, words):
    assert_parse_error(parse, text, "bad.aag", where, words)
