"""The standard gate library as data: schema, consistency checks, topology."""
import itertools
from importlib import resources

import numpy as np
import pytest

from mlc.errors import MlcError
from mlc.gates.library import GATE_NAMES, gate_geometry, gate_scene, lever_types, load_library, parse_gate


def test_library_complete_and_consistent():
    lib = load_library()
    assert set(lib) == set(GATE_NAMES)
    funcs = set()
    for g in lib.values():
        funcs.add(tuple(g.truth_table[f"{a}{b}"] for a, b in itertools.product((0, 1), (0, 1))))
    assert len(funcs) == 8     # eight distinct AND-class functions


def test_paper_lever_types():
    """Paper Fig. 2A/3: contracting NAND = open inputs, crossed output; expanding NAND switched;
    contracting OR inputs are crossed (they invert while keeping the direction)."""
    assert lever_types(0, 0, 1, "contract") == {"a": "open", "b": "open", "out": "crossed"}
    assert lever_types(0, 0, 1, "expand") == {"a": "crossed", "b": "crossed", "out": "open"}
    assert lever_types(1, 1, 1, "contract")["a"] == "crossed"


def test_installed_data_is_found():
    files = [f.name for f in resources.files("mlc.stdlib_gates").iterdir()]
    assert "nand.yaml" in files and "design.yaml" in files


def _text(name="nand.yaml"):
    return resources.files("mlc.stdlib_gates").joinpath(name).read_text("utf-8")


@pytest.mark.parametrize("old, new, line, words", [
    ('"11": 0', '"11": 1', 14, "truth_table[11]"),
    ("contract: {a: open, b: open, out: crossed}", "contract: {a: open, b: open, out: open}", 17, "levers.contract.out"),
    ("polarity: {a: 0, b: 0, out: 1}", "polarity: {a: 0, b: 2, out: 1}", 9, "must be one of"),
    ("name: NAND", "name: nand", 7, "does not match"),
    ("mlc_gate: 1", "mlc_gate: 2", 6, "must be 1"),
    ('  "11": 0\n', "", 11, "missing required key '11'"),
])
def test_malformed_gate_file(old, new, line, words):
    text = _text()
    assert old in text
    with pytest.raises(MlcError) as e:
        parse_gate(text.replace(old, new), "stdlib_gates/nand.yaml")
    msg = str(e.value)
    assert words in msg and msg.startswith(f"stdlib_gates/nand.yaml:{line}"), msg


def test_topology_8_slabs_7_hinge_axes_1_universal():
    s = gate_scene("NAND", "contract")
    assert len(s.bodies) == 8
    joints = s.joints()
    hinges = [j for j, bonds in joints.items() if bonds[0].kind == "hinge"]
    univ = [j for j, bonds in joints.items() if bonds[0].kind == "universal"]
    assert all(len(joints[j]) == 2 for j in hinges) and [len(joints[j]) for j in univ] == [1]
    # hinge axes: pairwise hinges that share an axis (the three-slab hinge at c) count once
    axes = set()
    for j in hinges:
        b0, b1 = joints[j]
        ends = tuple(sorted(tuple(np.round(s.site_world(b.a), 9)) for b in (b0, b1)))
        axes.add(ends)
    assert len(hinges) == 8 and len(axes) == 7
    # every pairwise hinge's two bonds close at build time
    for bonds in joints.values():
        for b in bonds:
            assert np.linalg.norm(s.site_world(b.a) - s.site_world(b.b)) < 1e-12


def test_slab_dimensions_and_design_parameters():
    geo = gate_geometry("NAND", "expand")
    assert geo.core.dout == pytest.approx(0.5573, abs=1e-4)
    assert geo.lever_a.l == 1.5 and geo.lever_out.l == 2.0
    s = gate_scene("NAND", "expand")
    for b in s.bodies:
        for box in b.boxes:
            assert box.size[1] == 0.5 and box.size[2] == 0.01
    # the output lever lies in the plane x = 0 (perpendicular to the core plane z = 0)
    for name in ("out_lo", "out_hi"):
        for v in s.body(name).sites.values():
            assert abs((s.body(name).position + v)[0]) <= 0.25 + 1e-12


def test_unknown_gate_and_signal():
    with pytest.raises(MlcError, match="choose one of"):
        gate_scene("XOR")
    with pytest.raises(MlcError, match="--signal"):
        gate_scene("AND", "wiggle")
