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


# ---------------------------------------------------------------------------
# Full units, chains and branches (issue 9, item 1)
# ---------------------------------------------------------------------------

import numpy as np  # noqa: E402

from mlc.gates.connector import (branch_scene, chain_scene, connector_geometry, full_unit_scene,  # noqa: E402
                                 max_bend)
from mlc.verify.dynamic import check_scene_dynamic_multi, relaxation_time  # noqa: E402
from mlc.verify.overlap import clearance, static_poses, sweep_clearance  # noqa: E402
from mlc.verify.static import _Problem, equilibrium  # noqa: E402

BENT = 0.9          # bent chains: the junctions between units at this fraction of their largest bend ...


def _bend(signal: str, units: int = 2, frac: float = BENT) -> float:
    """... or less, so that the chain's planar arc turns by at most 180 degrees in all (a
    longer arc would come back onto itself)."""
    b = frac * max_bend(connector_geometry(signal))
    return b if units < 2 else min(b, math.pi / (units - 1))


def _chain(units: int, signal: str, bent: bool):
    """A chain with a probe after every unit; a bent 1-unit chain is the full unit bent at
    its one junction (chain_scene bends only the junctions between units)."""
    if units == 1 and bent:
        return full_unit_scene(signal, bend=_bend(signal))
    return chain_scene(units, signal, _bend(signal, units) if bent else 0.0, probe_every_unit=True)


def _null_dim(scene, pos, quat) -> tuple[int, np.ndarray, np.ndarray]:
    """Dimension of the null space of the constraint Jacobian (bonds and muscles, body 0
    pinned), its singular values and right singular vectors."""
    J = _Problem(scene, pos, quat, pin_first=True).jacobian().toarray()
    _, s, vt = np.linalg.svd(J)
    zero = int((s < 1e-9 * s[0]).sum()) + (J.shape[1] - len(s))
    return zero, s, vt


# -- statics ----------------------------------------------------------------

@pytest.mark.parametrize("bent", [False, True], ids=["straight", "bent"])
@pytest.mark.parametrize("units", [1, 5, 10, 20])
@pytest.mark.parametrize("signal", SIGNALS)
def test_chain_carries_the_signal_statically(signal, units, bent):
    """Every full unit is a buffer: the pair after each unit reads the input, straight or
    bent, exactly (the kinematics is exact: no joint is strained)."""
    sc = _chain(units, signal, bent)
    rows = verify_scene(sc)
    assert len(rows) == 2 * units
    for r in rows:
        assert r["ok"], r
        assert r["bit"] == int(r["state"]) and r["error"] < 1e-9 and r["joint_stretch"] < 1e-9


@pytest.mark.parametrize("signal", SIGNALS)
def test_three_way_branch_statically(signal):
    rows = verify_scene(branch_scene(3, signal))
    assert sorted({r["output"] for r in rows}) == ["out0", "out1", "out2"]
    for r in rows:
        assert r["ok"], r
        assert r["bit"] == 1 - int(r["state"]) and r["error"] < 1e-9 and r["joint_stretch"] < 1e-9


@pytest.mark.parametrize("signal", SIGNALS)
def test_a_bent_chain_is_a_planar_arc(signal):
    """Bending the junctions between units by b turns the chain's far end by (units - 1) b
    about one axis (an arc, not a zigzag), and keeps it in the plane of the first turn."""
    units, b = 5, _bend(signal, 5)
    straight, bent = chain_scene(units, signal), chain_scene(units, signal, b)
    from mlc.geometry.rotation import quat_to_matrix

    def rel(sc):       # the last slab's orientation relative to the first (bodies are built unrotated)
        return quat_to_matrix(sc.bodies[-1].boxes[0].orientation) @ quat_to_matrix(sc.bodies[0].boxes[0].orientation).T

    turn = rel(bent) @ rel(straight).T
    angle = np.arccos(np.clip((np.trace(turn) - 1) / 2, -1, 1))
    assert angle == pytest.approx((units - 1) * b, abs=1e-6)
    # every layer's centre lies in the plane through the first layer normal to the bend axis
    axis = np.array([1.0, 0.0, 0.0])          # the even junctions' axes are +-x (first input axis x, tangent z)
    assert max(abs(float(bd.position @ axis)) for bd in bent.bodies) < 1.0


def test_static_check_refutes_a_chain_claimed_to_invert():
    sc = _chain(5, "contract", True)
    sc.truth_table = {"0": "1" * 5, "1": "0" * 5}
    assert not any(r["ok"] for r in verify_scene(sc))


# -- clearance -----------------------------------------------------------------

ELEMENTS = {
    "half_unit": lambda s: half_unit_scene(s),
    "full_unit": lambda s: full_unit_scene(s),
    "full_unit_bent": lambda s: _chain(1, s, True),
    "chain5_bent": lambda s: _chain(5, s, True),
    "chain20_straight": lambda s: _chain(20, s, False),
    "chain20_bent": lambda s: _chain(20, s, True),
    "branch3": lambda s: branch_scene(3, s),
}


@pytest.mark.parametrize("element", sorted(ELEMENTS))
@pytest.mark.parametrize("signal", SIGNALS)
def test_no_two_slabs_touch_in_any_state(signal, element):
    """Oriented-box clearance over the static poses of both input states and the half-way
    pose between them: positive everywhere (hinge contact at shared joints left out)."""
    worst, where, rows = sweep_clearance(ELEMENTS[element](signal), grid=3)
    assert len(rows) == 3
    assert worst.min_clearance > 0.0, (where, worst.pair, worst.min_clearance)


@pytest.mark.parametrize("signal", SIGNALS)
def test_largest_bend_is_the_gap_formula(signal):
    """max_bend = 2 atan(g / 2r) (r: the largest half diagonal) is where the two layers of a
    junction meet: the overlap test finds the layers clear at 99% of it and touching at
    100% (the slabs' 0.01 sigma thickness reaches a little beyond the vertex)."""
    mb = max_bend(connector_geometry(signal))

    def worst(frac):
        sc = full_unit_scene(signal, bend=frac * mb)
        return min(clearance(sc, p, q).min_clearance for p, q, _ in static_poses(sc, [[0.0], [0.5], [1.0]]))

    assert worst(0.99) > 0.0
    assert worst(1.0) < 0.0
    with pytest.raises(ValueError, match="largest bend"):
        chain_scene(2, signal, 1.01 * mb)


@pytest.mark.parametrize("signal", SIGNALS)
def test_junction_stop_distance_is_the_bend_formula(signal):
    """A junction stop's two sites sit on the layers' centre lines through the joint, so
    they are 2 m cos(beta/2) apart (falling monotonically to 180 degrees, independent of
    the wire's state); the stop is free up to STOP_FRACTION of max_bend and engaged past it."""
    from mlc.gates.connector import STOP_ARM, STOP_FRACTION
    geo = connector_geometry(signal)
    mb = max_bend(geo)
    for frac in (0.0, 0.5, 0.85, 0.95, 1.0):
        sc = chain_scene(2, signal, frac * mb, stops=True)      # junction 2 (between the units) bent
        stops = {b.name: b for b in sc.bonds if b.tolerance > 0}
        assert sorted(stops) == ["c_s1", "c_s2", "c_s3"]        # one stop per junction
        b = stops["c_s2"]
        body = {x.name: x for x in sc.bodies}
        pa = body[b.a.split(".")[0]].world(b.a.split(".")[1])
        pb = body[b.b.split(".")[0]].world(b.b.split(".")[1])
        d = float(np.linalg.norm(pa - pb))
        assert d == pytest.approx(2 * STOP_ARM * math.cos(0.5 * frac * mb), abs=1e-9)
        assert (d < b.rest - b.tolerance) == (frac > STOP_FRACTION)


@pytest.mark.parametrize("signal", SIGNALS)
def test_junction_stop_holds_the_layers_apart(signal):
    """Independent check of the stop against the slab geometry: a 2-unit chain built bent to
    the layers' contact (max_bend) at its middle junction, with stops, relaxes statically along its floppy mode to
    the stop and the oriented-box test then finds the layers clear in both states; without
    stops the same pose stays in contact."""
    mb = max_bend(connector_geometry(signal))
    for stops in (True, False):
        sc = chain_scene(2, signal, mb, stops=stops)
        worst = min(clearance(sc, eq.pos, eq.quat).min_clearance
                    for eq in (equilibrium(sc, "0"), equilibrium(sc, "1")))
        if stops:
            assert worst > 0.0
        else:
            assert worst < 0.0


# -- the floppy mode --------------------------------------------------------------

@pytest.mark.parametrize("state", ["0", "1"])
@pytest.mark.parametrize("signal", SIGNALS)
def test_full_unit_has_exactly_one_floppy_mode(signal, state):
    """With body 0 pinned and the muscle holding the input, the 7 free bodies (42 degrees of
    freedom) keep one zero mode: the second half unit turning rigidly about the line
    through its two universal joints.  The next singular value is far from zero."""
    sc = full_unit_scene(signal)
    eq = equilibrium(sc, state)
    zero, s, vt = _null_dim(sc, eq.pos, eq.quat)
    assert zero == 1
    assert s[-2] > 1e-3 * s[0]
    # the null vector is a rotation about the junction axis
    view = sc.with_poses(eq.pos, eq.quat)
    a, b = view.site_world("c_0_DA.D"), view.site_world("c_0_BC.B")
    axis = (b - a) / np.linalg.norm(b - a)
    want = np.zeros((len(sc.bodies), 6))
    for i, body in enumerate(sc.bodies):
        if body.name.startswith("c_1_"):
            want[i, 3:] = axis
            want[i, :3] = np.cross(axis, eq.pos[i] - a)
    want = want[1:].ravel()
    got = vt[-1]
    assert abs(got @ want) / np.linalg.norm(want) == pytest.approx(1.0, abs=1e-8)


@pytest.mark.parametrize("units", [1, 2, 3, 4])
def test_chain_has_one_floppy_mode_per_junction(units):
    """n units: 2n half units, 2n-1 junctions, 2n-1 zero modes; without the muscle one more
    (the signal itself is then free)."""
    sc = chain_scene(units, "expand")
    eq = equilibrium(sc, "1")
    assert _null_dim(sc, eq.pos, eq.quat)[0] == 2 * units - 1
    sc.muscles = []
    assert _null_dim(sc, eq.pos, eq.quat)[0] == 2 * units


@pytest.mark.parametrize("signal", SIGNALS)
def test_bending_along_the_floppy_mode_keeps_the_signal(signal):
    """A finite turn of everything beyond one junction about that junction's axis costs no
    energy and leaves every probe unchanged; solving for the other input from the bent pose
    reads the right bit at every probe and keeps the bend."""
    sc = chain_scene(5, signal, probe_every_unit=True)
    eq = equilibrium(sc, "1")
    view = sc.with_poses(eq.pos, eq.quat)
    j = 5                                           # the junction between half units 4 and 5
    a, b = view.site_world(f"c_{j - 1}_DA.D"), view.site_world(f"c_{j - 1}_BC.B")
    axis = (b - a) / np.linalg.norm(b - a)
    from mlc.geometry.rotation import expmap, matrix_to_quat, quat_to_matrix
    R = expmap(0.3 * axis)
    pos, quat = eq.pos.copy(), eq.quat.copy()
    moved = [i for i, body in enumerate(sc.bodies) if int(body.name.split("_")[1]) >= j]
    for i in moved:
        pos[i] = a + R @ (pos[i] - a)
        quat[i] = matrix_to_quat(R @ quat_to_matrix(quat[i]))
    bent = equilibrium(sc, "1", start_state="1", pos=pos, quat=quat)
    assert bent.energy < 1e-20
    for k, v in eq.probes.items():
        assert bent.probes[k] == pytest.approx(v, abs=1e-9)
    # switch the input from the bent pose: the chain reads 0 everywhere and stays bent
    other = equilibrium(sc, "0", start_state="1", pos=bent.pos, quat=bent.quat)
    L0 = wire_lengths(signal)[0]
    assert all(abs(v - L0) < 1e-9 for v in other.probes.values())
    # the bend: the last body's orientation relative to the first, against a straight chain
    straight = equilibrium(sc, "0")

    def rel(e):
        return quat_to_matrix(e.quat[moved[-1]]) @ quat_to_matrix(e.quat[0]).T

    turn = rel(other) @ rel(straight).T
    angle = np.arccos(np.clip((np.trace(turn) - 1) / 2, -1, 1))
    assert angle == pytest.approx(0.3, abs=0.01)


# -- Brownian dynamics at kT = 1e-5 ------------------------------------------------

def _dynamic_ok(scene, seeds):
    tau = relaxation_time(scene)
    rows = check_scene_dynamic_multi(scene, kT=1e-5, seeds=seeds, tau=tau, progress=False)
    assert len(rows) == 2 * len(scene.probes)
    for r in rows:
        assert r["ok"] and r["relaxed"], r
        # the reading sits near the ideal length, within the probe's thermal spread (the far
        # end of a long chain fluctuates slowly: a single run's mean carries that spread)
        assert r["bit"] == r["expected"] and r["margin"] > max(0.1, 0.25 - 3 * r["thermal_sd"]), r
        if r["state"] == "1":
            assert r["relax_time"] >= 3 * tau * (1 - 1e-9)
    return rows


@pytest.mark.parametrize("bent", [False, True], ids=["straight", "bent"])
@pytest.mark.parametrize("units", [1, 5, 10])
@pytest.mark.parametrize("signal", SIGNALS)
def test_chain_carries_the_signal_in_brownian_dynamics(signal, units, bent):
    """Every probe along the chain reads the input once the chain has relaxed."""
    _dynamic_ok(_chain(units, signal, bent), seeds=2 if units < 10 else 1)


def test_twenty_unit_chain_bent_expanding_dynamics():
    _dynamic_ok(_chain(20, "expand", True), seeds=1)


def test_twenty_unit_chain_straight_contracting_dynamics():
    _dynamic_ok(_chain(20, "contract", False), seeds=1)


@pytest.mark.parametrize("signal", SIGNALS)
def test_three_way_branch_dynamics(signal):
    rows = _dynamic_ok(branch_scene(3, signal), seeds=2)
    assert {r["output"] for r in rows} == {"out0", "out1", "out2"}
    assert all(r["bit"] == 1 - int(r["state"]) for r in rows)
