"""Junction stops in a robot's coupling chains (docs/robot.md section 2.2, ``CHAIN_STOPS``):
with the option on, every junction of every chain, the first included, has one flat-bottom
stop bond; none is engaged as built (the routes bend at most 0.75 of the largest bend);
each stop reads a junction's bend as 2 m cos(beta/2) between its sites; the wrist's junctions
(``WRIST``) have none.  Also the reach bookkeeping of section 2.4."""
import math

import numpy as np
import pytest

import mlc.robot.build as rb
from mlc.gates.connector import STOP_ARM, STOP_FRACTION, connector_geometry, max_bend

@pytest.fixture(scope="module")
def circuit(tmp_path_factory, tiny_robot_yaml):
    from mlc.cli import main
    d = tmp_path_factory.mktemp("tinystops")
    (d / "tiny.robot.yaml").write_text(tiny_robot_yaml)
    assert main(["compile", "-e", "u1_up = a; u2_dn = a", "-o", str(d / "out")]) == 0
    return d


def _build(d, monkeypatch, stops: bool):
    from mlc.robot.spec import load_robot
    from mlc.scene.io import load_scene
    monkeypatch.setattr(rb, "CHAIN_STOPS", stops)
    circ = load_scene(d / "out" / "circuit.yaml")
    return rb.build_robot(circ, load_robot(str(d / "tiny.robot.yaml"), circ)).scene


def _site(sc, by, s):
    b, n = s.split(".", 1)
    return by[b].world(n)


@pytest.mark.parametrize("stops", [True, False])
def test_chain_stops_one_per_junction_free_as_built(circuit, monkeypatch, stops):
    sc = _build(circuit, monkeypatch, stops)
    by = {b.name: b for b in sc.bodies}
    geo = connector_geometry("expand")
    for d in sc.meta["robot"]["dofs"]:
        if "chain" not in d:
            continue
        pre, n = d["chain"]["prefix"], d["chain"]["half_units"]
        st = [bd for bd in sc.bonds if bd.name.startswith(f"{pre}_s")]
        nw = d["chain"]["wrist_units"]                  # the wrist's long-post junctions have no stop
        assert len(st) == (n - nw if stops else 0)      # the chain's inner junctions + the first one
        for bd in st:
            dd = float(np.linalg.norm(_site(sc, by, bd.a) - _site(sc, by, bd.b)))
            assert abs(dd - bd.rest) <= bd.tolerance + 1e-9          # free as built
            if bd.a.split(".")[0].startswith(pre):                   # an inner junction: read its bend
                beta = 2 * math.degrees(math.acos(min(1.0, dd / (2 * STOP_ARM))))
                assert beta < STOP_FRACTION * math.degrees(max_bend(geo))
        # reach bookkeeping (section 2.4): the largest distance over the rows over the contour
        wp = rb.WRIST_POST + geo.width + 0.5 * geo.gap                # a wrist half unit's pitch
        contour = (n - nw) * geo.pitch + nw * wp
        assert d["chain"]["contour"] == pytest.approx(contour, abs=2e-3)
        assert d["chain"]["reach_fraction"] == pytest.approx(d["chain"]["reach_max"] / contour, abs=2e-3)
        assert 0 < d["chain"]["reach_fraction"] < 1.0


def test_avoid_chains_falls_back_to_the_plain_route(circuit, monkeypatch):
    """AVOID_CHAINS (docs/robot.md 2.6): a chain after the first is routed kept apart from the
    chains before it and records that; when no kept-apart route is found (or none is clear of
    the others and of itself) the chain is the plain build's, body for body."""
    import mlc.circuit.route as route
    monkeypatch.setattr(rb, "AVOID_CHAINS", 1.5)
    kept = _build(circuit, monkeypatch, True)
    avoid = [d["chain"]["avoid"] for d in kept.meta["robot"]["dofs"] if "chain" in d]
    assert avoid[0] == 0.0 and all(a == 1.5 for a in avoid[1:]) and len(avoid) >= 2
    plain_solve = route.solve_route
    monkeypatch.setattr(route, "solve_route", lambda *a, **k: None if "avoid" in k else plain_solve(*a, **k))
    fell = _build(circuit, monkeypatch, True)
    assert all(d["chain"]["avoid"] == 0.0 for d in fell.meta["robot"]["dofs"] if "chain" in d)
    monkeypatch.setattr(rb, "AVOID_CHAINS", 0.0)
    plain = _build(circuit, monkeypatch, True)
    assert [b.name for b in fell.bodies] == [b.name for b in plain.bodies]
    assert np.allclose([b.position for b in fell.bodies], [b.position for b in plain.bodies])
