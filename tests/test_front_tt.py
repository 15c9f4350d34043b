"""The .tt truth-table parser: golden outputs, one bad input per error rule, and the
Tetris example's geometry (four different tetrominoes)."""
from pathlib import Path

import pytest

from mlc.errors import MlcError
from mlc.front.load import load, spec_text, truth_tables
from mlc.front.tt import parse, print_table
from helpers import assert_parse_error, check_golden

ROOT = Path(__file__).resolve().parents[1]
GOLDEN = ROOT / "tests" / "golden" / "front"




@pytest.mark.parametrize("name", ["tetris.tt", "full_adder.tt"])
def test_golden_examples(name):
    spec = parse((ROOT / "examples" / name).read_text(), f"examples/{name}")
    check_golden(name + ".txt", spec_text(spec))


def test_cubes_dont_cares_and_separators():
    s = parse(".inputs a b c\n.outputs f g\n1-0 | 1-\n 0 1 1   0 1  # blanks are fine\n", "x.tt")
    assert s.inputs == ["a", "b", "c"] and s.outputs == ["f", "g"]
    # minterm m: a = bit 0, b = bit 1, c = bit 2
    assert s.value(0, 0b001) == 1 and s.value(0, 0b011) == 1          # a=1, c=0
    assert s.value(1, 0b001) is None                                   # explicit '-'
    assert s.value(0, 0b110) == 0 and s.value(1, 0b110) == 1           # a=0 b=1 c=1
    assert s.value(0, 0b000) is None                                   # unlisted -> dc


def test_unlisted_directive():
    s = parse(".inputs a b\n.outputs f\n.unlisted 0\n11 | 1\n", "x.tt", strict=True)
    assert s.on == [0b1000] and s.dc == [0]
    s = parse(".inputs a b\n.outputs f\n.unlisted 1\n00 | 0\n", "x.tt")
    assert s.on == [0b1110] and s.dc == [0]
    s = parse(".inputs a b\n.outputs f g\n.unlisted 1\n", "x.tt")        # no rows: a constant, on purpose
    assert s.on == [0b1111, 0b1111] and s.dc == [0, 0]


def test_overlapping_rows_that_agree_are_fine():
    s = parse(".inputs a b\n.outputs f\n1- | 1\n11 | 1\n-1 | 1\n00 | 0\n", "x.tt", strict=True)
    assert s.on == [0b1110]


def test_print_parse_roundtrip():
    s = parse((ROOT / "examples" / "tetris.tt").read_text(), "t.tt")
    s2 = parse(print_table(s), "t2.tt")
    assert (s2.inputs, s2.outputs, s2.on, s2.dc) == (s.inputs, s.outputs, s.on, s.dc)


# One bad input per error rule: (text, expected "line:col", words in the message)
BAD = [
    ("00 | 1\n", "1:1", "row before the .inputs"),
    (".inputs a\n0 | 1\n", "2:1", "row before the .outputs"),
    (".inputs a 1x\n.outputs f\n", "1:11", "invalid input name"),
    (".inputs a a\n.outputs f\n", "1:11", "declared twice"),
    (".inputs a\n.outputs a\n", "2:10", "declared twice"),
    (".inputs a\n.outputs\n", "2:1", "at least one name"),
    (".inputs a\n.inputs b\n.outputs f\n", "2:1", "second .inputs"),
    (".inputs a\n.outputs f\n.outputs g\n", "3:1", "second .outputs"),
    (".inputs a\n.outputs f\n.frob\n", "3:1", "unknown directive"),
    (".inputs a\n.outputs f\n.unlisted maybe\n", "3:11", ".unlisted takes"),
    (".inputs a\n.outputs f\n.unlisted 0\n.unlisted 1\n", "4:1", "second .unlisted"),
    (".inputs a\n.outputs f\n0 | 1\n.inputs b\n", "4:1", "after the first row"),
    (".inputs a b\n.outputs f\n0x | 1\n", "3:2", "unexpected character 'x'"),
    (".inputs a b\n.outputs f\n0 | 1\n", "3:3", "1 input values before '|'"),
    (".inputs a b\n.outputs f\n01 | 10\n", "3:7", "2 output values after '|'"),
    (".inputs a b\n.outputs f\n0 1 1 1\n", "3:7", "4 values, expected 3"),
    (".inputs a b\n.outputs f\n01 | 1 | 0\n", "3:8", "at most one '|'"),
    (".inputs a b\n.outputs f g\n01 | 1 0\n-1 | 1 1\n", "4:8", "line 4 sets g=1 but line 3 sets g=0"),
    ("# nothing\n", "1", "no .inputs line"),
    (".inputs a\n", "1", "no .outputs line"),
    # issue 14: a table that gives an output no value used to compile to a silent constant 0
    (".inputs a b\n.outputs f g\n", "2:10", "output f is a don't care on every input combination (the table has no rows)"),
    (".inputs a b\n.outputs f g\n00 | 1 -\n1- | 0 -\n", "2:12", "output g is a don't care on every input combination (every row gives it -)"),
    (".inputs a b\n.outputs f\n.unlisted dc\n", "2:10", "the table has no rows"),
]


@pytest.mark.parametrize("text,where,words", BAD)
def test_error_rules(text, where, words):
    assert_parse_error(parse, text, "bad.tt", where, words)


def test_conflict_names_both_lines():
    text = ".inputs a b\n.outputs f\n1- | 1\n# comment\n11 | 0\n"
    with pytest.raises(MlcError) as e:
        parse(text, "c.tt")
    assert str(e.value).startswith("c.tt:5:6: conflicting rows: line 5 sets f=0 but line 3 sets f=1 for a=1 b=1")


def test_strict_reports_missing_rows():
    text = ".inputs a b\n.outputs f\n00 | 1\n11 | 0\n"
    parse(text, "s.tt")                       # not strict: unlisted rows are don't cares
    with pytest.raises(MlcError) as e:
        parse(text, "s.tt", strict=True)
    assert str(e.value).startswith("s.tt:1:1:") and "2 input combination(s)" in str(e.value)
    assert "a=1 b=0" in str(e.value)


def test_too_many_inputs():
    names = " ".join(f"x{i}" for i in range(25))
    with pytest.raises(MlcError, match=r"t\.tt:1:1: 25 inputs is too many"):
        parse(f".inputs {names}\n.outputs f\n", "t.tt")


def test_wide_table_is_fast():
    # 16 inputs, all 65536 rows listed: bit sets are built in one pass
    n = 16
    rows = "\n".join(f"{m:016b}"[::-1] + f" | {bin(m).count('1') & 1}" for m in range(1 << n))
    s = parse(f".inputs {' '.join(f'x{i}' for i in range(n))}\n.outputs p\n{rows}\n", "p.tt", strict=True)
    assert s.dc == [0] and bin(s.on[0]).count("1") == 1 << (n - 1)


# ---------------------------------------------------------------- Tetris geometry

TETROMINOES = {  # one-sided tetrominoes, as sets of cells, any rotation
    "I": {(0, 0), (1, 0), (2, 0), (3, 0)},
    "O": {(0, 0), (1, 0), (0, 1), (1, 1)},
    "T": {(0, 0), (1, 0), (2, 0), (1, 1)},
    "S": {(0, 0), (1, 0), (1, 1), (2, 1)},
    "Z": {(0, 1), (1, 1), (1, 0), (2, 0)},
    "L": {(0, 0), (1, 0), (2, 0), (2, 1)},
    "J": {(0, 0), (1, 0), (2, 0), (0, 1)},
}


def _normal(cells):
    x0 = min(x for x, _ in cells)
    y0 = min(y for _, y in cells)
    return frozenset((x - x0, y - y0) for x, y in cells)


def classify(cells):
    """Name of the one-sided tetromino ``cells`` is (rotations allowed, no reflections), or None."""
    shapes = {}
    for name, c in TETROMINOES.items():
        for _ in range(4):
            shapes[_normal(c)] = name
            c = {(-y, x) for x, y in c}
    return shapes.get(_normal(cells))


def walk(bits: dict) -> list:
    """Turtle-walk the chain: the body sits in cell (0,0), the chain leaves it along +x;
    unit i turns by +90 (up) or -90 (down) degrees at its joint, then occupies the next cell."""
    pos, heading = (0, 0), (1, 0)
    cells = []
    for i in range(1, 5):
        up, dn = bits[f"u{i}_up"], bits[f"u{i}_dn"]
        assert not (up and dn), f"unit {i} bends up and down at once"
        if up:
            heading = (-heading[1], heading[0])
        elif dn:
            heading = (heading[1], -heading[0])
        pos = (pos[0] + heading[0], pos[1] + heading[1])
        cells.append(pos)
    return cells


def test_tetris_folds_four_different_tetrominoes():
    spec = load(str(ROOT / "examples" / "tetris.tt"), strict=True)
    assert spec.inputs == ["y", "b"]
    assert spec.outputs == [f"u{i}_{d}" for i in range(1, 5) for d in ("up", "dn")]
    on, dc = truth_tables(spec)
    assert dc == [0] * len(spec.outputs)
    shapes = {}
    for y in (0, 1):
        for b in (0, 1):
            m = y | (b << 1)                     # y is input 0, b input 1
            bits = {name: (on[o] >> m) & 1 for o, name in enumerate(spec.outputs)}
            cells = walk(bits)
            assert len(set(cells)) == 4, f"(y,b)=({y},{b}): the chain overlaps itself: {cells}"
            assert (0, 0) not in cells, "the chain runs into the body"
            shape = classify(cells)
            assert shape is not None, f"(y,b)=({y},{b}) folds {cells}, not a tetromino"
            shapes[(y, b)] = shape
    assert shapes[(0, 0)] == "I"
    assert len(set(shapes.values())) == 4, shapes
    assert shapes == {(0, 0): "I", (0, 1): "L", (1, 0): "S", (1, 1): "O"}


def test_classifier_sanity():
    assert classify([(1, 0), (2, 0), (3, 0), (4, 0)]) == "I"
    assert classify([(0, 0), (0, 1), (0, 2), (0, 3)]) == "I"
    assert classify([(0, 0), (1, 0), (2, 0), (1, 1)]) == "T"
    assert classify([(0, 0), (1, 0), (1, 1), (2, 2)]) is None
    assert classify([(0, 0), (1, 0), (2, 0), (2, 1)]) != classify([(0, 0), (1, 0), (2, 0), (0, 1)])


def test_docs_example_parses():
    doc = (ROOT / "docs" / "formats.md").read_text()
    block = doc.split("## `.tt`", 1)[1].split("```", 2)[1]
    s = parse(block, "docs/formats.md")
    assert s.inputs == ["a", "b", "ci"] and s.outputs == ["s", "co"]
    assert s.value(0, 0b001) == 1 and s.value(1, 0b110) == 1 and s.value(1, 0b011) is None
