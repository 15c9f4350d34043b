"""Robot body files (docs/robot.md): the schema, the checks against the logic, every
error one MlcError at file:line; and the lever triangle of a DOF against the law of
cosines (an independent check of the closed form in mlc.robot.build)."""
import math
from pathlib import Path
from types import SimpleNamespace

import jsonschema
import pytest

from mlc.errors import MlcError
from mlc.io import yamlsrc
from mlc.io.schema import load_schema
from mlc.robot.build import dof_geometry
from mlc.robot.spec import cells_to_turns, load_robot, parse_robot, walk

ROOT = Path(__file__).resolve().parents[1]
TETRIS = (ROOT / "examples" / "tetris.robot.yaml").read_text()
# examples/tetris.tt: outputs u1_up u1_dn u2_up u2_dn u3_up u3_dn u4_up u4_dn
LOGIC = SimpleNamespace(inputs=["y", "b"],
                        outputs=["u1_up", "u1_dn", "u2_up", "u2_dn", "u3_up", "u3_dn", "u4_up", "u4_dn"],
                        truth_table={"00": "00000000", "01": "00100100", "10": "00001001", "11": "00001010"})


def line_of(text, needle):
    return next(i for i, ln in enumerate(text.splitlines(), 1) if needle in ln)


def err(text, logic=LOGIC):
    with pytest.raises(MlcError) as e:
        parse_robot(text, "r.robot.yaml", logic)
    return e.value


def test_tetris_file_loads_and_matches_the_header_of_tetris_tt():
    spec = load_robot(ROOT / "examples" / "tetris.robot.yaml", LOGIC)
    assert spec.units == 4 and len(spec.dofs) == 8
    assert {r: p.turns for r, p in spec.poses.items()} == {
        "00": [0, 0, 0, 0], "01": [0, 1, -1, 0], "10": [0, 0, 1, -1], "11": [0, 0, 1, 1]}
    # the cells of examples/tetris.tt's header comment
    assert spec.poses["01"].cells == [(1, 0), (1, 1), (2, 1), (3, 1)]
    assert spec.poses["11"].cells == [(1, 0), (2, 0), (2, 1), (1, 1)]


def test_examples_validate_with_jsonschema():
    for f in sorted((ROOT / "examples").glob("*.robot.yaml")):
        jsonschema.validate(yamlsrc.load(f.read_text(), str(f)), load_schema("robot"))


def test_cells_and_turns_round_trip():
    for turns in ([0, 1, -1, 0], [1, 1, 0, -1], [-1, 0, 0, 1]):
        assert cells_to_turns(walk(turns), "x") == turns


@pytest.mark.parametrize("old,new,needle,words", [
    ("name: tetris", "name: tetris\ncolour: red", "colour", "unknown key 'colour'"),
    ("units: 4", "units: 0", "units:", "must be >= 1"),
    ("side: up, output: u2_up", "side: upward, output: u2_up", "u2_up", "must be one of"),
    ("{row: \"00\", shape: I, turns: [0, 0, 0, 0]}", "{row: \"00\", shape: I, turns: [0, 45, 0, 0]}", "shape: I",
     "must be one of"),
])
def test_schema_errors_name_the_line(old, new, needle, words):
    text = TETRIS.replace(old, new)
    e = err(text)
    assert words in e.message
    assert e.where.file == "r.robot.yaml" and e.where.line == line_of(text, needle)


@pytest.mark.parametrize("old,new,needle,words", [
    # an output the logic does not have
    ("output: u4_dn}", "output: u5_dn}", "u5_dn", "the logic has no output 'u5_dn'"),
    # a degree of freedom driven twice
    ("{unit: 2, side: dn, output: u2_dn}", "{unit: 2, side: up, output: u2_dn}", "side: up, output: u2_dn",
     "driven twice"),
    # a unit the skeleton does not have
    ("{unit: 4, side: dn, output: u4_dn}", "{unit: 5, side: dn, output: u4_dn}", "unit: 5", "does not exist"),
    # unreachable poses: a U-turn, two units in one cell, a step that is no step
    ("cells: [[1, 0], [1, 1], [2, 1], [3, 1]]", "cells: [[1, 0], [2, 0], [1, 0], [1, 1]]", "row: \"01\"",
     "180-degree turn"),
    ("turns: [0, 0, 90, 90]", "turns: [90, 90, 90, 90]", "row: \"11\"", "cannot reach it"),
    ("cells: [[1, 0], [1, 1], [2, 1], [3, 1]]", "cells: [[1, 0], [3, 1], [2, 1], [3, 1]]", "row: \"01\"",
     "is not next to"),
    # a pose the logic does not make
    ("turns: [0, 0, 90, 90]", "turns: [0, 0, 90, -90]", "row: \"11\"", "the pose needs u4_up = 0"),
    # a row without a pose, a row twice
    ("  - {row: \"11\", shape: O, turns: [0, 0, 90, 90]}\n", "", "row: \"00\"", "row 11 has no pose"),
    ("{row: \"11\", shape: O", "{row: \"10\", shape: O", "shape: O", "two poses"),
    # inputs in the wrong order
    ("inputs: [y, b]", "inputs: [b, y]", "inputs:", "are not the logic's inputs"),
])
def test_semantic_errors_name_the_line(old, new, needle, words):
    text = TETRIS.replace(old, new)
    assert text != TETRIS
    e = err(text)
    assert words in e.message, e.message
    assert e.where.line == line_of(text, needle), (e.where, e.message)


def test_a_turn_with_no_dof_is_unreachable():
    text = TETRIS.replace("  - {unit: 1, side: up, output: u1_up}     # constant 0 in the logic: locked\n", "")
    e = err(text.replace("turns: [0, 0, 0, 0]", "turns: [90, 0, 0, 0]"))
    assert "no output drives dof u1_up" in e.message


def test_not_a_robot_file():
    with pytest.raises(MlcError, match="not an mlc robot file"):
        parse_robot("name: x\n", "r.yaml")
    with pytest.raises(MlcError, match="YAML mapping"):
        parse_robot("- 1\n", "r.yaml")


def test_cli_reports_a_bad_robot_file_without_output(tmp_path, capsys):
    from mlc.cli import main
    bad = tmp_path / "bad.robot.yaml"
    bad.write_text(TETRIS.replace("output: u4_dn}", "output: nope}"))
    out = tmp_path / "out"
    rc = main(["compile", str(ROOT / "examples" / "tetris.tt"), "--robot", str(bad), "-o", str(out), "--no-circuit"])
    assert rc == 2 and not out.exists()
    assert "--robot needs the circuit" in capsys.readouterr().err
    bad.write_text(TETRIS.replace("units: 4", "units: four"))
    rc = main(["compile", str(ROOT / "examples" / "tetris.tt"), "--robot", str(bad), "-o", str(out)])
    err_text = capsys.readouterr().err
    assert rc == 2 and not out.exists()
    assert f"bad.robot.yaml:{line_of(TETRIS, 'units: 4')}" in err_text and "Traceback" not in err_text


@pytest.mark.parametrize("L0,L1", [(1.0, 1.5), (1.0, 1.25), (1.0, 2.0)])
def test_lever_triangle_by_the_law_of_cosines(L0, L1):
    g = dof_geometry(L0, L1, 2.0)
    for th, L in ((g.theta0, L0), (g.theta0 + math.pi / 2, L1)):
        # the pair sites at p, q on arms th apart, built as points (not from the closed form)
        a = (g.p, 0.0)
        b = (g.q * math.cos(th), g.q * math.sin(th))
        assert math.dist(a, b) == pytest.approx(L, abs=1e-12)
        # the tips, gain times further out: the DOF's length, gain times the signal
        assert math.dist((g.gain * a[0], 0), (g.gain * b[0], g.gain * b[1])) == pytest.approx(g.gain * L, abs=1e-12)
    # the swing stays 45 degrees clear of both dead points (0 and 180 degrees)
    assert math.degrees(g.theta0) == pytest.approx(45.0) and g.gain == 2.0


def test_no_lever_for_a_contracting_signal():
    with pytest.raises(MlcError, match="no lever triangle"):
        dof_geometry(1.0, 0.5, 2.0)


def _tt_table(path):
    """The rows of a .tt file, read directly from its text (independent of mlc.front)."""
    ins = outs = None
    table = {}
    for ln in Path(path).read_text().splitlines():
        ln = ln.split("#")[0].strip()
        if ln.startswith(".inputs"):
            ins = ln.split()[1:]
        elif ln.startswith(".outputs"):
            outs = ln.split()[1:]
        elif "|" in ln:
            a, b = ln.split("|")
            table["".join(a.split())] = "".join(b.split())
    return SimpleNamespace(inputs=ins, outputs=outs, truth_table=table)


@pytest.mark.parametrize("name", ["tetris", "snake3"])
def test_example_robots_agree_with_their_logic(name):
    logic = _tt_table(ROOT / "examples" / f"{name}.tt")
    spec = load_robot(ROOT / "examples" / f"{name}.robot.yaml", logic)
    assert len(spec.poses) == 2 ** len(logic.inputs)
    # every row a different pose (snake3: 3 inputs, 8 poses)
    assert len({tuple(p.turns) for p in spec.poses.values()}) == len(spec.poses)
