"""A muscle per input lever (CircuitOptions.muscle_per_lever, ``mlc compile
--muscle-per-lever``; docs/circuits.md, "A muscle per lever"): under a global stimulus
every input lever a circuit input drives carries its own muscle of that input, no chain
runs from the inputs to the gates, and the circuit still computes its table."""
import copy
import dataclasses
from pathlib import Path

import pytest

from mlc.circuit.build import CircuitOptions, build_circuit
from mlc.cli import main
from mlc.front.load import load
from mlc.pipeline import compile_spec
from mlc.verify.circuit import format_report, verify_static


def _build(src, expr=None, **kw):
    spec = load(src, expr)
    c = compile_spec(spec)
    return c.netlist, build_circuit(c.netlist, spec, options=CircuitOptions(**kw))


@pytest.fixture(scope="module")
def tetris():
    return _build(str(Path(__file__).resolve().parents[1] / "examples" / "tetris.tt"), muscle_per_lever=True)


def test_every_input_lever_carries_its_own_muscle_and_no_input_chain_is_built(tetris):
    nl, circ = tetris
    sc = circ.scene
    pins = {(g.id, pin): p.src[1] for g in nl.gates for pin, p in (("a", g.a), ("b", g.b)) if p.src[0] == "input"}
    assert len(pins) == 6                          # y and b each feed all three gates
    on_lever = {}
    for m in sc.muscles:
        body = m.a.split(".")[0]
        if not body.startswith("src_"):
            gid, lever = body.split("_")[:2]
            on_lever[(gid, lever)] = m.input
    assert on_lever == pins
    assert len({m.name for m in sc.muscles}) == len(sc.muscles)
    # u3_up = y reads the input itself: y keeps its source half unit for that output alone
    assert {b.name.split("_")[1] for b in sc.bodies if b.name.startswith("src_")} == {"y"}
    # no wire from an input to a gate: only the stub that gives u3_up its parity
    assert {b.name.split("_")[3] for b in sc.bodies if b.name.startswith("w_")} <= {"stub"}
    assert sc.meta["connector"]["muscle_per_lever"] is True
    # and it names that output, so that a robot drives u3_up's DOF by a muscle of y (mlc.robot.build)
    assert sc.meta["connector"]["input_outputs"] == {o.name: o.src[1] for o in nl.outputs if o.kind == "input"} \
        == {"u3_up": "y"}
    # against the default build: the same logic, 1623 bodies there (the inputs' wires)
    assert len(sc.bodies) < 40


def test_the_circuit_computes_every_row_without_interpenetration(tetris):
    rep = verify_static(tetris[1].scene)
    assert rep.ok, format_report(rep)
    assert min(r["clearance"] for r in rep.rows) > 0


def test_a_muscle_on_the_wrong_input_is_caught(tetris):
    sc = copy.deepcopy(tetris[1].scene)
    k = next(i for i, m in enumerate(sc.muscles) if m.a.startswith("g3_"))   # g3 = y & b (u4_up)
    m = sc.muscles[k]
    sc.muscles[k] = dataclasses.replace(m, input="b" if m.input == "y" else "y")
    rep = verify_static(sc)
    assert not rep.ok
    assert "u4_up" in {e["output"] for e in rep.failures()}


def test_gate_to_gate_chains_stay_and_a_fanned_out_input_needs_no_source():
    nl, circ = _build(None, "s = a ^ b; c = a & b", muscle_per_lever=True)
    sc = circ.scene
    assert not [b for b in sc.bodies if b.name.startswith("src_")]
    gate_pins = [p for g in nl.gates for p in (g.a, g.b) if p.src[0] == "gate"]
    assert gate_pins and circ.chains == len(gate_pins)    # a chain from gate to gate, none from an input
    inputs = sorted(p.src[1] for g in nl.gates for p in (g.a, g.b) if p.src[0] == "input")
    assert sorted(m.input for m in sc.muscles) == inputs and inputs.count("a") == 2
    rep = verify_static(sc)
    assert rep.ok, format_report(rep)
    _, default = _build(None, "s = a ^ b; c = a & b")
    assert any(b.name.startswith("src_a") for b in default.scene.bodies)     # a's source and its branch
    assert len(sc.bodies) < len(default.scene.bodies)


def test_cli_builds_it_and_refuses_it_without_a_circuit(tmp_path, capsys):
    out = tmp_path / "o"
    assert main(["compile", "-e", "s = a ^ b; c = a & b", "--muscle-per-lever", "-o", str(out), "--verify"]) == 0
    assert "muscle_per_lever: true" in (out / "circuit.yaml").read_text()
    capsys.readouterr()
    assert main(["compile", "-e", "f = a & b", "--muscle-per-lever", "--no-circuit", "-o", str(tmp_path / "n")]) == 2
    err = capsys.readouterr().err
    assert "--muscle-per-lever only applies to the circuit" in err and "Traceback" not in err
    assert not (tmp_path / "n").exists()
