"""The Berkeley PLA parser: golden output, .type semantics, one bad input per error rule."""
from pathlib import Path

import pytest

from mlc.front.load import spec_text
from mlc.front.pla import parse, print_pla
from helpers import assert_parse_error, check_golden

ROOT = Path(__file__).resolve().parents[1]
GOLDEN = ROOT / "tests" / "golden" / "front"




def test_golden_bcd7seg():
    spec = parse((ROOT / "examples" / "bcd7seg.pla").read_text(), "examples/bcd7seg.pla")
    check_golden("bcd7seg.pla.txt", spec_text(spec))
    # digit 7 = x3 x2 x1 x0 = 0111; x3 is input 0 (least significant bit of the minterm)
    m7 = 0b1110
    assert [spec.value(o, m7) for o in range(7)] == [1, 1, 1, 0, 0, 0, 0]
    # codes 10..15 are don't cares for every segment
    for code in range(10, 16):
        m = int(f"{code:04b}"[::-1], 2)
        assert all(spec.value(o, m) is None for o in range(7))


def test_types():
    body = ".i 2\n.o 1\n{t}11 1\n00 0\n01 -\n.e\n"
    f = parse(body.format(t=".type f\n"), "f.pla")
    assert f.on == [0b1000] and f.dc == [0]
    fd = parse(body.format(t=""), "fd.pla")                       # default fd
    assert fd.on == [0b1000] and fd.dc == [0b0100]
    fr = parse(body.format(t=".type fr\n"), "fr.pla")
    assert fr.on == [0b1000] and fr.dc == [0b0110]
    fdr = parse(body.format(t=".type fdr\n"), "fdr.pla")
    assert fdr.on == [0b1000] and fdr.dc == [0b0110]


def test_on_and_dc_overlap_is_dc_and_default_names():
    s = parse(".i 2\n.o 2\n1- 11\n11 -~\n", "o.pla")
    assert s.inputs == ["x0", "x1"] and s.outputs == ["f0", "f1"]
    assert s.on == [0b0010, 0b1010] and s.dc == [0b1000, 0]   # x0 is bit 0: "1-" = minterms 1, 3


def test_large_cubes_use_bit_sets():
    s = parse(".i 20\n.o 1\n" + "-" * 19 + "1 1\n.e\n", "w.pla")
    assert bin(s.on[0]).count("1") == 1 << 19


def test_roundtrip():
    s = parse((ROOT / "examples" / "bcd7seg.pla").read_text(), "b.pla")
    s2 = parse(print_pla(s), "b2.pla")
    assert (s2.on, s2.dc, s2.inputs, s2.outputs) == (s.on, s.dc, s.inputs, s.outputs)


BAD = [
    ("11 1\n", "1:1", "cube before the .i"),
    (".i 2\n11 1\n", "2:1", "cube before the .o"),
    (".i x\n", "1:4", ".i takes one non-negative integer"),
    (".i 2\n.o 0\n", "2:1", ".o must be at least 1"),
    (".i 2\n.i 3\n", "2:1", "second .i"),
    (".i 2\n.o 1\n.ilb a\n", "3:7", "lists 1 names, expected 2"),
    (".i 2\n.o 1\n.ilb a a\n", "3:8", "appears twice"),
    (".ilb a\n", "1:1", ".ilb before .i"),
    (".i 1\n.o 1\n.ilb a\n.ob a\n", "4:5", "both an input and an output"),
    (".i 1\n.o 1\n.type q\n", "3:7", ".type must be"),
    (".i 1\n.o 1\n.mv 3 1 2\n", "3:1", "not supported"),
    (".i 1\n.o 1\n.frob\n", "3:1", "unknown keyword"),
    (".i 2\n.o 1\n1 1\n", "3:3", "2 characters, expected 3"),
    (".i 2\n.o 1\n1x 1\n", "3:2", "input part"),
    (".i 2\n.o 1\n11 x\n", "3:4", "output part"),
    (".i 2\n.o 1\n11 1\n.type fr\n", "4:1", "after the first cube"),
    (".i 2\n.o 1\n.p 2\n11 1\n", "3:1", ".p says 2 cubes"),
    (".i 2\n.o 1\n.type fr\n1- 1\n# x\n11 0\n", "6:4", "line 4 puts f0=1 and line 6 puts f0=0"),
    ("# empty\n", "1", "no .i line"),
    (".i 2\n", "1", "no .o line"),
]


@pytest.mark.parametrize("text,where,words", BAD)
def test_error_rules(text, where, words):
    assert_parse_error(parse, text, "bad.pla", where, words)
