"""mlc.circuit.contact: layers of two chains tested in every state of their wires."""
import numpy as np
import pytest

from mlc.circuit.contact import candidate_pairs, layer_boxes, state_contacts
from mlc.gates.connector import connector_geometry, half_unit_parts

GEO = connector_geometry("expand")      # L0 = 1, L1 = 1.5 sigma


def _layer(tag, centre, axis, state):
    """One half unit, tangent +z: its input diagonal (L of ``state``) along ``axis``, its
    output diagonal (L of the other state) along z x axis."""
    parts, _, _ = half_unit_parts(f"{tag}_0", centre, axis, [0, 0, 1.0], state, GEO)
    return parts.bodies


def _pair(d):
    """Chain a at the origin, input axis y: as built (state 0) its long diagonal (1.5) lies
    along x, switched along y.  Chain b at x = d, input axis x: as built its short
    diagonal (1.0) lies along x, switched its long one.  Their facing vertices are, along
    x, d - 0.75 - 0.5 apart as built and d - 0.75 - 0.75 with b switched."""
    bodies = {("a", f): _layer("a", [0, 0, 0], [0, 1.0, 0], f) for f in (0, 1)}
    bodies.update({("b", f): _layer("b", [d, 0, 0], [1.0, 0, 0], f) for f in (0, 1)})
    return lambda tag, flip: layer_boxes(bodies[(tag, flip)], tag), bodies


def _manifold_overlap(bodies_a, bodies_b) -> float:
    """Volume common to the two layers' boxes, by manifold3d (an independent check of the
    separating-axis test)."""
    from manifold3d import Manifold

    from mlc.geometry.rotation import quat_to_matrix

    def solid(bodies):
        out = None
        for b in bodies:
            R = b.rotation()
            for box in b.boxes:
                A = R @ quat_to_matrix(np.asarray(box.orientation, float))
                c = b.position + R @ np.asarray(box.center, float)
                m = Manifold.cube(list(map(float, box.size)), True).transform(np.hstack([A, c[:, None]]).tolist())
                out = m if out is None else out + m
        return out
    return float((solid(bodies_a) ^ solid(bodies_b)).volume())


def test_a_layer_pair_clear_as_built_interpenetrates_when_a_wire_switches():
    d = 1.36
    boxes, bodies = _pair(d)
    pairs = candidate_pairs({"a": np.array([[0, 0, 0.5]]), "b": np.array([[d, 0, 0.5]])}, 1.85)
    assert pairs == [("a", 0, "b", 0)]
    (k,) = state_contacts(pairs, boxes, {"a": "x", "b": "y"})
    assert k.flips == (0, 1) and k.clearance < -0.05          # b switched: 1.36 - 1.5 = -0.14 along x
    # each combination on its own, against the volume manifold3d finds common to the layers
    for fa, fb in ((0, 0), (1, 0), (0, 1), (1, 1)):
        (c,) = state_contacts(pairs, lambda t, f: boxes(t, fa if t == "a" else fb), {"a": "x", "b": "y"})
        vol = _manifold_overlap(bodies[("a", fa)], bodies[("b", fb)])
        assert (c.clearance < 0) == (vol > 1e-9), (fa, fb, c.clearance, vol)
    assert _manifold_overlap(bodies[("a", 0)], bodies[("b", 1)]) > 1e-6


@pytest.mark.parametrize("d", [1.2, 1.5, 1.6])
def test_the_sign_of_each_state_agrees_with_manifold3d(d):
    """Near contact (1.5: about 0.005 sigma deep with b switched) and on either side."""
    boxes, bodies = _pair(d)
    signs = []
    for fa, fb in ((0, 0), (1, 0), (0, 1), (1, 1)):
        (c,) = state_contacts([("a", 0, "b", 0)], lambda t, f: boxes(t, fa if t == "a" else fb), {"a": "x", "b": "y"})
        vol = _manifold_overlap(bodies[("a", fa)], bodies[("b", fb)])
        assert (c.clearance < 0) == (vol > 1e-9), (fa, fb, c.clearance, vol)
        signs.append(c.clearance < 0)
    assert signs[2] == (d < 1.55)           # b switched: its long diagonal faces a's


def test_two_chains_of_one_wire_switch_together():
    boxes, _ = _pair(1.36)
    pairs = [("a", 0, "b", 0)]
    (k,) = state_contacts(pairs, boxes, {"a": "w", "b": "w"})     # (0, 1) cannot happen
    assert k.flips in ((0, 0), (1, 1)) and k.clearance > 0.05


@pytest.mark.parametrize("d", [1.6, 1.9])
def test_far_layers_clear_in_every_state(d):
    boxes, _ = _pair(d)
    pairs = candidate_pairs({"a": np.array([[0, 0, 0.5]]), "b": np.array([[d, 0, 0.5]])}, 1.85)
    if d > 1.85:
        assert pairs == []
        pairs = [("a", 0, "b", 0)]
    (k,) = state_contacts(pairs, boxes, {"a": "x", "b": "y"})
    assert k.clearance > 0


def test_candidate_pairs_leave_out_a_chains_own_layers():
    c = {"a": np.array([[0, 0, 0], [0, 0, 1.0]]), "b": np.array([[0.5, 0, 0], [9, 9, 9]])}
    assert candidate_pairs(c, 1.2) == [("a", 0, "b", 0), ("a", 1, "b", 0)]


def test_mlc_compile_warns_of_layers_left_touching(tmp_path, capsys):
    """The summary names the closest pair that the builder left (scene meta
    connector.state_contacts); Tetris has none, so its summary has no warning."""
    import json
    from pathlib import Path

    from mlc.cli import main
    from mlc.commands.compile import format_summary
    root = Path(__file__).resolve().parents[1]
    assert main(["compile", str(root / "examples" / "tetris.tt"), "-o", str(tmp_path / "out"), "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert "state_contacts" not in d["circuit"] and "warning" not in format_summary(d)
    d["circuit"]["state_contacts"] = [["w_a_0", 3, "w_b_1", 7, -0.0312], ["w_a_0", 4, "w_b_1", 7, 0.01]]
    text = format_summary(d)
    assert "warning: 2 pair(s)" in text and "w_a_0 half unit 3 and w_b_1 half unit 7, -0.031 sigma" in text
