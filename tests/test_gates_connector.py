"""The connector half unit (mlc.gates.connector): a rhombus of four hinged slabs whose
diagonals map state 0 <-> state 1 of one convention, i.e. an exact logical NOT.
Checked against the formula, the static kinematics and Brownian dynamics."""
import math

import pytest

from mlc.gates.connector import half_unit_out, half_unit_scene, half_unit_side, wire_lengths
from mlc.sim.dynamic import check_scene_dynamic
from mlc.verify.static import verify_scene

SIGNALS = ("expand", "contract")


def test_side_from_the_diagonal_relation():
    assert half_unit_side("expand") == pytest.approx(math.sqrt(1 + 1.5 ** 2) / 2)
    assert half_unit_side("contract") == pytest.approx(math.sqrt(1 + 0.5 ** 2) / 2)


@pytest.mark.parametrize("signal", SIGNALS)
def test_formula_swaps_the_two_states_and_falls(signal):
    L0, L1 = wire_lengths(signal)
    assert half_unit_out(L0, signal) == pytest.approx(L1, abs=1e-12)
    assert half_unit_out(L1, signal) == pytest.approx(L0, abs=1e-12)
    # two half units in a row (a full connector unit) map every length to itself
    for p in (0.6, 0.9, L0, L1):
        if p < 2 * half_unit_side(signal) and half_unit_out(p, signal) < 2 * half_unit_side(signal):
            assert half_unit_out(half_unit_out(p, signal), signal) == pytest.approx(p)
    ps = [0.55 + 0.05 * i for i in range(20)]
    qs = [half_unit_out(p, signal) for p in ps if p < 2 * half_unit_side(signal)]
    assert all(a > b for a, b in zip(qs, qs[1:]))
    with pytest.raises(ValueError):
        half_unit_out(2.5 * half_unit_side(signal), signal)


@pytest.mark.parametrize("signal", SIGNALS)
def test_static_kinematics_is_an_exact_not(signal):
    rows = verify_scene(half_unit_scene(signal))
    assert [r["state"] for r in rows] == ["0", "1"]
    for r in rows:
        assert r["ok"], r
        assert r["error"] < 1e-9 and r["joint_stretch"] < 1e-9


def test_static_kinematics_refutes_a_buffer():
    sc = half_unit_scene("expand")
    sc.truth_table = {"0": "0", "1": "1"}
    assert not any(r["ok"] for r in verify_scene(sc))


@pytest.mark.parametrize("signal", SIGNALS)
def test_brownian_dynamics_reads_not(signal):
    rows = check_scene_dynamic(half_unit_scene(signal), kT=1e-5, seeds=2)
    assert len(rows) == 2
    for r in rows:
        assert r["ok"], r
        assert r["margin"] > 0.2 and r["relax_time"] is not None
