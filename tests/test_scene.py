"""Scene model and its YAML form: round trip, schema errors at file:line, check() invariants."""
import numpy as np
import pytest

from mlc.errors import MlcError
from mlc.gates.library import gate_scene
from mlc.scene.io import dump_scene, parse_scene


def test_round_trip_is_stable():
    s = gate_scene("NAND", "expand")
    text = dump_scene(s)
    s2 = parse_scene(text, "nand.yaml")
    assert dump_scene(s2) == text
    a, b = s.arrays(), s2.arrays()
    assert np.array_equal(a.site_local, b.site_local) and np.array_equal(a.bond_i, b.bond_i)


def test_libyaml_writes_the_same_scene_text_as_the_python_emitter():
    """dump_scene takes libyaml's emitter when PyYAML has it; the text must not change
    (the dynamic campaigns key their scenes by it).  Every library gate here, every
    example circuit in tests/test_circuit_examples.py."""
    import yaml

    from mlc.gates.library import GATE_NAMES, SIGNALS
    from mlc.io import yamlemit
    from mlc.scene import io

    if not yaml.__with_libyaml__:
        pytest.skip("PyYAML built without libyaml: dump_scene uses the Python emitter")
    assert io._Dumper is io._CDumper
    for gate in GATE_NAMES:
        for conv in SIGNALS:
            data = io.scene_to_data(gate_scene(gate, conv))
            assert io._emit(data, io._CDumper) == io._emit(data, io._PyDumper), (gate, conv)
            assert yamlemit.dump(data) == io._emit(data, io._CDumper), (gate, conv)   # what dump_scene writes


def test_arrays_shapes():
    a = gate_scene("AND", "contract").arrays()
    assert a.pos.shape == (8, 3) and a.quat.shape == (8, 4)
    assert len(a.bond_i) == 17 and len(a.muscle_i) == 2 and len(a.probe_i) == 1
    assert a.pos.flags.c_contiguous and a.site_local.dtype == np.float64
    assert list(a.muscle_lengths([1, 0])) == [0.5, 1.0]


def _minimal(extra_body="", bond_sites="[p.x, q.y]", quat="[1, 0, 0, 0]"):
    return f"""mlc_scene: 1
name: t
inputs: [m]
outputs: [o]
bodies:
  - name: p
    position: [0, 0, 0]
    orientation: {quat}
    boxes: [{{size: [1, 0.5, 0.01]}}]
    sites: {{x: [0.5, 0, 0]}}
  - name: q
    position: [1, 0, 0]
    boxes: [{{size: [1, 0.5, 0.01]}}]
    sites: {{y: [-0.5, 0, 0]}}
{extra_body}bonds:
  - {{name: b0, sites: {bond_sites}, kind: hinge}}
muscles:
  - {{name: m0, input: m, sites: [p.x, q.y], rest: 1, actuated: 1.5}}
probes:
  - {{name: o, output: o, sites: [p.x, q.y], rest: 1, actuated: 1.5}}
"""


def test_minimal_scene_parses():
    s = parse_scene(_minimal(), "t.yaml")
    assert [b.name for b in s.bodies] == ["p", "q"]


@pytest.mark.parametrize("text, line, words", ids=range(13), argvalues=[
    (_minimal(bond_sites="[p.x, q.nope]"), 16, "no site 'nope'"),
    (_minimal(bond_sites="[p.x, z.y]"), 16, "no body named 'z'"),
    (_minimal(quat="[1, 1, 0, 0]"), 6, "not a unit quaternion"),
    (_minimal().replace("size: [1, 0.5, 0.01]", "size: [1, -0.5, 0.01]", 1), 9, "must be > 0"),
    (_minimal().replace("kind: hinge", "kind: spring"), 16, "must be one of"),
    (_minimal().replace("rest: 1, actuated: 1.5}\nprobes", "rest: .nan, actuated: 1.5}\nprobes"), 18, "finite"),
    (_minimal().replace("input: m,", "input: w,"), 18, "not in inputs"),
    (_minimal().replace("name: t\n", "name: t\nextra: 1\n"), 3, "unknown key 'extra'"),
    (_minimal().replace("bonds:\n", "bonds:\n  - [\n"), 17, "YAML syntax error"),
    # an input no muscle follows was accepted: setting it moved nothing
    (_minimal().replace("inputs: [m]", "inputs: [m, n]"), 3, "input 'n' drives no muscle"),
    (_minimal().replace("inputs: [m]", "inputs:\n  - n\n  - m"), 4, "add a muscle with 'input: n'"),
    # truth-table rows were refused at the file alone, without a line
    (_minimal().replace("outputs: [o]\n", "outputs: [o]\ntruth_table:\n  '0': '1'\n  '01': '0'\n"), 7,
     "truth table row '01' is not 1 input bits"),
    (_minimal().replace("outputs: [o]\n", "outputs: [o]\ntruth_table:\n  '0': '1'\n  '1': '00'\n"), 7,
     "truth table value '00' for 1 is not 1 output bits"),
])
def test_malformed_scene_reports_file_line(text, line, words):
    assert text != _minimal()
    with pytest.raises(MlcError) as e:
        parse_scene(text, "bad.yaml")
    msg = str(e.value)
    assert words in msg
    assert msg.startswith(f"bad.yaml:{line}"), msg


def test_same_body_bond_rejected():
    with pytest.raises(MlcError, match="same body"):
        parse_scene(_minimal(bond_sites="[p.x, p.x]"), "t.yaml")


def test_load_scene_refuses_hostile_files_with_one_error(tmp_path):
    """load_scene reads through mlc.io.yamlsrc: non-UTF-8 bytes, alias bombs and directories are
    one MlcError at the file (and line:col where there is one)."""
    from mlc.scene.io import load_scene
    text = dump_scene(gate_scene("NAND", "expand"))
    cases = {
        "latin1.yaml": (text.replace("name: NAND_expand", "name: caf\u00e9").encode("latin-1"),
                        ["latin1.yaml:", "0xe9", "UTF-8"]),
        "bomb.yaml": (("a: &a [x, x, x, x, x, x, x, x, x, x]\n" + "".join(
            f"{c}: &{c} [" + ", ".join([f"*{p}"] * 10) + "]\n" for p, c in zip("abcdefg", "bcdefgh"))).encode(),
            ["alias", "bomb"]),
    }
    for name, (data, words) in cases.items():
        p = tmp_path / name
        p.write_bytes(data)
        with pytest.raises(MlcError) as e:
            load_scene(p)
        for w in words:
            assert w in str(e.value), (name, str(e.value))
    with pytest.raises(MlcError, match="it is a directory"):
        load_scene(tmp_path)


@pytest.mark.parametrize("old,new,words", [
    ("  k: 1.0", "  k: 2e6", ["must be <= 1e+06", "stiffness in k0/sigma^2"]),
    ("  actuated: 1.5", "  actuated: 1e308", ["must be <= 1000", "length in sigma"]),
    ("  k: 1.0", "  k: '3'", ["expected number, got str", "without quotes"]),
])
def test_scene_numbers_have_upper_bounds(old, new, words):
    text = dump_scene(gate_scene("NAND", "expand"))
    with pytest.raises(MlcError) as e:
        parse_scene(text.replace(old, new, 1), "s.yaml")
    assert str(e.value).startswith("s.yaml:")
    for w in words:
        assert w in str(e.value), str(e.value)
