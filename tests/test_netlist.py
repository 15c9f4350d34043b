"""Technology mapping and the gate netlist IR: where inversions go, lever types,
branches, depth, JSON (schema), text, DOT, PNG, BLIF and AIGER exports."""
import json
from pathlib import Path

import jsonschema
import pytest

from mlc.errors import InternalError, MlcError
from mlc.front.aiger import parse as parse_aag
from mlc.front.blif import parse as parse_blif
from mlc.front.load import load, truth_tables
from mlc.netlist.mapper import map_aig
from mlc.netlist.ir import Netlist
from mlc.gates.library import load_library
from mlc.io.schema import load_schema, validate
from mlc.logic.aig import AIG
from mlc.logic.equiv import check_equivalent
from mlc.logic.lower import from_spec
from helpers import check_golden

ROOT = Path(__file__).resolve().parents[1]
GOLDEN = ROOT / "tests" / "golden" / "front"




def tetris_aig() -> AIG:
    """The Tetris function built by hand (independent of synthesis)."""
    g = AIG(["y", "b"])
    y, b = g.input_lit(0), g.input_lit(1)
    up2 = g.and_(y ^ 1, b)          # !y & b
    for name, lit in [("u1_up", 0), ("u1_dn", 0), ("u2_up", up2), ("u2_dn", 0), ("u3_up", y),
                      ("u3_dn", up2), ("u4_up", g.and_(y, b)), ("u4_dn", g.and_(y, b ^ 1))]:
        g.add_output(name, lit)
    return g


def mixed_aig() -> AIG:
    """Every inversion case: output lever, input levers, half units, constants, plain inputs."""
    g = AIG(["a", "b", "c"])
    a, b, c = (g.input_lit(i) for i in range(3))
    ab = g.and_(a, b)
    nand_only = g.and_(b, c)              # used only complemented, by a gate and an output
    t = g.and_(nand_only ^ 1, a ^ 1)
    u = g.and_(ab ^ 1, c)                 # ab: one complemented gate edge, one plain output edge
    for name, lit in [("f_ab", ab), ("f_nab", ab ^ 1), ("f_t", t), ("f_u", u), ("f_nbc", nand_only ^ 1),
                      ("f_na", a ^ 1), ("f_b", b), ("f_0", 0), ("f_1", 1)]:
        g.add_output(name, lit)
    return g


@pytest.mark.parametrize("signal", ["expand", "contract"])
def test_tetris_mapping(signal):
    nl = map_aig(tetris_aig(), signal, "examples/tetris.tt")
    s = nl.stats
    assert s["gates"] == 3 and s["depth"] == 1 and s["half_units"] == 0
    assert s["gate_types"] == {"AND": 1, "CNIMPLY": 1, "NIMPLY": 1}
    assert s["const_outputs"] == 3 and s["input_outputs"] == 1
    # y feeds three gates and u3_up: four branches; b feeds three gates; g1 (!y & b) feeds two outputs
    fan = {w.name: (w.fanout, w.branches) for w in nl.inputs}
    assert fan == {"y": (4, 4), "b": (3, 3)}
    assert [g.fanout for g in nl.gates] == [2, 1, 1] and s["branches"] == 4 + 3 + 2
    spec = load(str(ROOT / "examples" / "tetris.tt"))
    check_equivalent(nl.to_aig(), spec)
    if signal == "expand":
        check_golden("tetris.netlist.txt", nl.to_text())
        check_golden("tetris.netlist.dot", nl.to_dot())


def test_inversions_go_to_levers_or_half_units():
    nl = map_aig(mixed_aig(), "expand", "mixed")
    outs = {o.name: o for o in nl.outputs}
    # ab drives f_ab (plain) and f_nab (complemented) and u (complemented): outputs tie -> no output inversion,
    # the gate input of u inverts, and f_nab needs a half unit
    ab = nl.gate_by_id()[outs["f_ab"].src[1]]
    assert ab.out_invert == 0 and ab.type == "AND"
    u = nl.gate_by_id()[outs["f_u"].src[1]]
    pin = u.a if u.a.src == ("gate", ab.id) else u.b
    assert pin.edge_invert == 1 and pin.invert == 1           # the consumer's input lever inverts
    assert outs["f_nab"].half_unit and not outs["f_ab"].half_unit
    # nand_only is wanted complemented by every consumer: the inversion sits in its output lever
    nbc = nl.gate_by_id()[outs["f_nbc"].src[1]]
    assert nbc.out_invert == 1 and nbc.type == "NAND" and not outs["f_nbc"].half_unit
    t = nl.gate_by_id()[outs["f_t"].src[1]]
    pin = t.a if t.a.src == ("gate", nbc.id) else t.b
    assert pin.edge_invert == 1 and pin.invert == 0          # the source already inverted it
    # an inverted plain input needs a half unit; constants and plain inputs are reported as such
    assert outs["f_na"].kind == "input" and outs["f_na"].half_unit
    assert outs["f_b"].kind == "input" and not outs["f_b"].half_unit
    assert (outs["f_0"].kind, outs["f_0"].value, outs["f_1"].value) == ("const", 0, 1)
    assert nl.stats["half_units"] == 2
    # the mapped netlist computes what the AIG computes
    assert nl.to_aig().truth_tables() == mixed_aig().truth_tables()


@pytest.mark.parametrize("signal", ["expand", "contract"])
def test_gate_types_and_levers_follow_the_library(signal):
    lib = load_library()
    nl = map_aig(mixed_aig(), signal, "mixed")
    for g in nl.gates:
        d = lib[g.type]
        assert (d.polarity["a"], d.polarity["b"], d.polarity["out"]) == g.polarity
        assert d.levers[signal] == {"a": g.a.lever, "b": g.b.lever, "out": g.out_lever}


def test_all_eight_gate_types_appear():
    g = AIG(["a", "b"])
    a, b = g.input_lit(0), g.input_lit(1)
    for k, (pa, pb, po) in enumerate([(0, 0, 0), (0, 0, 1), (1, 1, 1), (1, 1, 0),
                                      (0, 1, 0), (1, 0, 0), (0, 1, 1), (1, 0, 1)]):
        g.add_output(f"f{k}", g.and_(a ^ pa, b ^ pb) ^ po)
    # and_ hashes: (a,b) pairs repeat, so only four AND nodes with two output polarities each
    nl = map_aig(g, "expand", "all")
    assert nl.stats["gates"] == 4 and nl.stats["half_units"] == 4
    assert nl.to_aig().truth_tables() == g.truth_tables()


def test_json_schema_roundtrip_and_tamper_detection(tmp_path):
    nl = map_aig(mixed_aig(), "contract", "mixed")
    data = json.loads(nl.dumps())
    jsonschema.validate(data, load_schema("netlist"))
    validate(data, load_schema("netlist"), "n.json")
    back = Netlist.loads(nl.dumps(), "n.json")
    assert back.to_text() == nl.to_text() and back.dumps() == nl.dumps()
    bad = json.loads(nl.dumps())
    bad["gates"][0]["type"] = "NOR" if bad["gates"][0]["type"] != "NOR" else "AND"
    with pytest.raises(MlcError, match="inconsistent netlist"):
        Netlist.from_json(bad, "n.json")
    bad = json.loads(nl.dumps())
    bad["gates"][0]["a"]["lever"] = "sliding"
    with pytest.raises(MlcError, match=r"gates\[0\]\.a\.lever"):
        Netlist.from_json(bad, "n.json")
    with pytest.raises(MlcError, match=r"n\.json:1:2"):
        Netlist.loads("{]", "n.json")


def test_check_catches_broken_invariants():
    nl = map_aig(mixed_aig(), "expand", "mixed")
    nl.gates[0].depth = 7
    with pytest.raises(InternalError, match="depth"):
        nl.check()
    nl = map_aig(mixed_aig(), "expand", "mixed")
    nl.inputs[0].fanout += 1
    with pytest.raises(InternalError, match="fanout"):
        nl.check()
    nl = map_aig(mixed_aig(), "expand", "mixed")
    nl.outputs[0].half_unit = not nl.outputs[0].half_unit
    with pytest.raises(InternalError, match="half_unit"):
        nl.check()


@pytest.mark.parametrize("example", ["tetris.tt", "full_adder.expr", "bcd7seg.pla", "mux4.blif", "compare2.aag"])
def test_exports_reparse_equivalent(example):
    spec = load(str(ROOT / "examples" / example))
    nl = map_aig(from_spec(spec), "expand", example)
    want = nl.to_aig().truth_tables()
    for text, parser in ((nl.to_blif(), parse_blif), (nl.to_aiger(), parse_aag)):
        back = parser(text, "export")
        assert back.inputs == spec.inputs and back.outputs == spec.outputs
        assert truth_tables(back)[0] == want
    on, dc = truth_tables(spec)
    assert all((w ^ o) & ~d == 0 for w, o, d in zip(want, on, dc))
    assert nl.to_aiger().startswith(f"aag {len(spec.inputs) + nl.stats['gates']} {len(spec.inputs)} 0 ")


def test_depth_matches_aig():
    for example in ["full_adder.tt", "bcd7seg.pla", "compare2.aag"]:
        aig = from_spec(load(str(ROOT / "examples" / example)))
        assert map_aig(aig).stats["depth"] == aig.depth()


def test_draw_png(tmp_path):
    nl = map_aig(mixed_aig(), "expand", "mixed")
    png = nl.render_png()
    assert png[:8] == b"\x89PNG\r\n\x1a\n"
    out = tmp_path / "c.png"
    nl.draw(out)
    assert out.read_bytes()[:4] == b"\x89PNG"
    with pytest.raises(MlcError, match="does not exist"):
        nl.draw(tmp_path / "missing" / "c.png")
