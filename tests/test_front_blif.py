"""The BLIF parser and writer: golden output, semantics, error rules, round trip."""
from pathlib import Path

import pytest

from mlc.errors import MlcError
from mlc.front.blif import parse, print_blif
from mlc.front.expr import parse as parse_expr
from mlc.front.load import spec_text, truth_tables
from helpers import assert_parse_error, check_golden

ROOT = Path(__file__).resolve().parents[1]
GOLDEN = ROOT / "tests" / "golden" / "front"




def test_golden_mux4():
    spec = parse((ROOT / "examples" / "mux4.blif").read_text(), "examples/mux4.blif")
    check_golden("mux4.blif.txt", spec_text(spec))
    on, _ = truth_tables(spec)
    for m in range(64):
        s = m & 3
        assert (on[0] >> m) & 1 == (m >> (2 + s)) & 1


def test_out_of_order_covers_offset_constants_conn_and_ignored():
    src = """.model t
.inputs a b
.outputs y z k0 k1 w
.attr src "x.v:1"   # yosys attributes are ignored
.names t y
0 1
.names a b t
11 0
.names z
.names k0
.names k1
1
.conn a w
.end
.model ignored_after_end_is_not_allowed_but_text_is
"""
    with pytest.raises(MlcError, match="second .model"):
        parse(src, "t.blif")
    spec = parse(src.rsplit(".model", 1)[0], "t.blif")
    on, _ = truth_tables(spec)
    # t = !(a & b) (off-set cover), y = !t = a & b; z, k0 = 0; k1 = 1; w = a
    assert on == [0b1000, 0, 0, 0b1111, 0b1010]


def test_roundtrip_through_print_blif():
    spec = parse_expr("s = a ^ b ^ c; co = maj(a, b, c); n = !a; k = 1; i = b", "e")
    text = print_blif(spec)
    back = parse(text, "rt.blif")
    assert truth_tables(back) == truth_tables(spec)
    assert back.inputs == spec.inputs and back.outputs == spec.outputs


BAD = [
    (".model m\n.inputs a\n.outputs y\n.names a z y\n11 1\n.end\n", "4:10", "'z' is used but never driven"),
    (".inputs a\n.outputs y\n.names y a y\n11 1\n", "3:12", "combinational loop"),
    (".inputs a\n.outputs y\n.latch a y\n", "3:1", "latches"),
    (".inputs a\n.outputs y\n.subckt foo x=a y=y\n", "3:1", "hierarchical"),
    (".inputs a\n.outputs y\n.gate and2 A=a Y=y\n", "3:1", "mapped BLIF"),
    (".model a\n.model b\n", "2:1", "second .model"),
    (".inputs a\n.inputs a\n", "2:9", "declared twice"),
    (".outputs y\n.outputs y\n", "2:10", "declared twice"),
    (".inputs a\n.outputs y\n.names a y\n1 1\n.names a y\n0 1\n", "5:10", "driven twice (first at line 3)"),
    (".inputs a\n.outputs a\n.names a\n1\n", "3:8", "primary input and cannot be driven"),
    (".inputs a\n.outputs y\n.names\n", "3:1", "at least the name"),
    (".inputs a\n.outputs y\n.conn a\n", "3:1", ".conn takes two"),
    (".inputs a\n.outputs y\n.frob\n", "3:1", "unknown BLIF keyword"),
    (".inputs a\n.outputs y\n11 1\n", "3:1", "outside a .names"),
    (".inputs a\n.outputs y\n.names y\n11\n", "4:1", "single 0 or 1"),
    (".inputs a b\n.outputs y\n.names a b y\n11 1 1\n", "4:6", "CUBE BIT"),
    (".inputs a b\n.outputs y\n.names a b y\n1x 1\n", "4:2", "unexpected character 'x'"),
    (".inputs a b\n.outputs y\n.names a b y\n111 1\n", "4:1", "3 columns but .names has 2"),
    (".inputs a b\n.outputs y\n.names a b y\n11 2\n", "4:4", "must be 0 or 1"),
    (".inputs a b\n.outputs y\n.names a b y\n11 1\n00 0\n", "5:4", "mixes on-set"),
    (".inputs a\n.outputs y z\n.names a y\n1 1\n", "2:12", "'z' is never driven"),
    (".inputs a\n", "1", "no .outputs"),
    ("# nothing\n", "1", "empty BLIF"),
]


@pytest.mark.parametrize("text,where,words", BAD)
def test_error_rules(text, where, words):
    assert_parse_error(parse, text, "bad.blif", where, words)


def test_continuation_keeps_locations():
    with pytest.raises(MlcError) as e:
        parse(".inputs a \\\n  b\n.outputs y\n.names a \\\n  q y\n11 1\n", "c.blif")
    assert str(e.value).startswith("c.blif:5:3: signal 'q'")
