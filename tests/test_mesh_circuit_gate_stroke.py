"""Session 56 (issue 13): a compiled circuit's gate keeps its input levers' tips clear of its
output lever along the whole stroke.

``circuit_g3`` (tests/data_mesh) is gate g3 (AND) of the README's Tetris circuit
(``mlc compile examples/tetris.tt``) with two bond hops around it (the last half unit of each of
the chains ``w_y_3`` and ``w_b_2`` whose end joints hang on its input levers: 16 bodies), and the
whole circuit's 22 print poses (``mlc.mesh.pipeline.state_poses`` of its largest mechanism: the 4
logic states and 6 poses on the way to each of 01, 10, 11).  A compiled circuit is posed
coarsely and got no motion trim (``_clear_motion``, the library gates' dense paths): on the way to
row 01 (10) the tip of ``g3_b_lo`` (``g3_a_lo``) ran into ``g3_out_hi`` at ``@0.71`` and
``@0.86`` (0.0204 and 0.0131 mm^3, the circuit's last four ``states`` failures) and cleared it in
every logic state.  Such a pair now gets the motion trim in poses interpolated along that stretch
of the path (``_clear_strokes``)."""
from __future__ import annotations

import numpy as np
import pytest

from mlc.mesh import build as B
from mlc.mesh.build import build_assembly, transform_solid
from mlc.mesh.checks import check_assembly
from mlc.mesh.profiles import load_profile

from helpers import load_piece, mesh_piece, part_gaps

RUBS = {"state 01@0.71: g3_b_lo intersects g3_out_hi", "state 10@0.71: g3_a_lo intersects g3_out_hi",
        "state 01@0.86: g3_b_lo intersects g3_out_hi", "state 10@0.86: g3_a_lo intersects g3_out_hi"}
BLOCKING = ("watertight", "part_count", "min_gap", "retention", "features")


@pytest.fixture(scope="module")
def piece():
    return load_piece("circuit_g3")


@pytest.fixture(scope="module")
def built(piece):
    sc, poses = piece
    asm = build_assembly(sc, load_profile("mjp"), poses, reuse=True)
    return asm, check_assembly(asm, walls=False)


def _slerp(q0, q1, f):
    q0, q1 = np.asarray(q0, float), np.asarray(q1, float)
    d = np.einsum("ni,ni->n", q0, q1)
    q1 = np.where(d[:, None] < 0, -q1, q1)
    d = np.clip(np.abs(d), -1.0, 1.0)
    th = np.arccos(d)[:, None]
    s = np.sin(th)
    w0 = np.where(s > 1e-9, np.sin((1 - f) * th) / np.where(s > 1e-9, s, 1), 1 - f)
    w1 = np.where(s > 1e-9, np.sin(f * th) / np.where(s > 1e-9, s, 1), f)
    q = w0 * q0 + w1 * q1
    return q / np.linalg.norm(q, axis=1)[:, None]


def test_the_input_levers_clear_the_output_lever_on_the_way(built):
    asm, rep = built
    by = {c.name: c for c in rep.checks}
    for name in BLOCKING + ("states",):
        assert by[name].ok, (name, by[name].detail, by[name].failures)
    trims = [t for t in asm.motion_trims if t.get("stroke")]
    assert {(t["part"], t["clear_of"]) for t in trims} == {("g3_a_lo", "g3_out_hi"), ("g3_b_lo", "g3_out_hi")}, trims
    for t in trims:
        assert t["settled"] and 0 < t["removed_mm3"] < 1.0, t
        assert any(p.startswith(("01@0.71", "10@0.71")) for p in t["poses"]), t
    # (and, since session 68's JOINT_STROKES, each lever trimmed 0.06 mm^3 clear of the joint part at d
    # in the poses interpolated between the coarse ones: other notes)
    assert sum("interpolated on the way to the states" in n and "from g3_out_hi" in n for n in asm.notes) == 2, \
        asm.notes


def test_the_tips_keep_clear_along_the_whole_stroke(built, piece):
    """Measured independently of the trim's own poses: the bodies' poses interpolated (positions
    on straight lines, orientations by slerp) in 24 steps between each two coarse poses from
    ``@0.57`` to the state; each lever keeps clear of ``out_hi`` in every one, and keeps the
    clearance in the coarse poses."""
    asm, _ = built
    _, poses = piece
    c = asm.profile.clearance
    for st, lever in (("01", "g3_b_lo"), ("10", "g3_a_lo")):
        seq = [f"{st}@0.57", f"{st}@0.71", f"{st}@0.86", st]
        for k in seq:
            T = asm.part_transforms(*poses[k])
            g = transform_solid(asm.part(lever).solid, T[lever]).min_gap(
                transform_solid(asm.part("g3_out_hi").solid, T["g3_out_hi"]), 2 * c)
            assert g >= c - 1e-5, (lever, k, g)
        for a, b in zip(seq, seq[1:]):
            (p0, q0), (p1, q1) = poses[a], poses[b]
            for f in np.arange(1, 24) / 24:
                T = asm.part_transforms((1 - f) * p0 + f * p1, _slerp(q0, q1, f))
                X = transform_solid(asm.part(lever).solid, T[lever]) ^ transform_solid(
                    asm.part("g3_out_hi").solid, T["g3_out_hi"])
                assert X.volume() < 1e-6, (lever, a, b, f, X.volume())


def test_what_the_trim_takes_is_the_levers_tip(built, piece, monkeypatch):
    """Without the trims (``STROKE_CLEAR`` off) the piece fails ``states`` with the circuit's four
    rubs and nothing else (the other blocking checks pass both ways); what the trim takes from
    each lever lies on its tip's side of its pivot, outside the pivot's knuckles."""
    asm, _ = built
    sc, poses = piece
    monkeypatch.setattr(B, "STROKE_CLEAR", False)
    old = build_assembly(sc, load_profile("mjp"), poses, reuse=True)
    rep = check_assembly(old, walls=False)
    by = {c.name: c for c in rep.checks}
    for name in BLOCKING:
        assert by[name].ok, (name, by[name].detail, by[name].failures)
    assert {f.split(" (")[0] for f in by["states"].failures} == RUBS, by["states"].failures
    assert not any(t.get("stroke") for t in old.motion_trims)
    axes = {a.name: a for a in asm.axes}
    for lever, pivot, hinge in (("g3_a_lo", "g3_pivot_a", "g3_hinge_a"), ("g3_b_lo", "g3_pivot_b", "g3_hinge_b")):
        gone = old.part(lever).solid - asm.part(lever).solid
        assert 0 < gone.volume() < 1.0
        V = np.asarray(gone.to_mesh().vert_properties)[:, :3]
        P, H = axes[pivot], axes[hinge]
        # along the lever, from its hinge on the core through its pivot: the cut is past the pivot
        d = P.origin - H.origin
        d = d - np.dot(d, P.direction) * P.direction
        d = d / np.linalg.norm(d)
        s = (V - P.origin) @ d
        assert s.min() > 0, (lever, s.min())          # on the tip's side of the pivot
        # the pivot's knuckles (radius R about its axis, over its span) keep all of their material
        knuckles = B.cylinder(P.origin, P.direction, -P.span / 2, P.span / 2, P.R, 48)
        assert (gone ^ knuckles).volume() < 1e-9, lever


def test_an_input_lever_that_only_comes_near_the_output_lever_is_trimmed_clear_too():
    """Session 67 (``CLOSE_STROKES``): the stroke trims acted only on pairs that meet.  In the Tetris
    robot, which turns its gates' levers further than the circuit does, g2's input lever ``a_lo``
    passes its output lever ``out_hi`` at 0.021 mm on the way to row 11 (``11@0.86``) without
    meeting it (``robot_g2``: the robot's g2 with two bond hops round it and the robot's 22 poses;
    the same pair in the README circuit's g1, session 65).  Two bodies that share no hinge and come
    within the clearance on the way, meeting nowhere, now get the same trim, the pairs printed
    farthest apart first, kept only if it settles the pair.  Outside mlc: trimesh samples of the two
    posed parts and a k-d tree (an upper bound of the gap) read them under 0.05 mm apart before and
    at the clearance after."""
    sc, poses = load_piece("robot_g2")
    way = {k: v for k, v in poses.items() if k == "11" or k.startswith("11@")}
    old, old_rep = mesh_piece("robot_g2", walls=False, CLOSE_STROKES=False)
    assert any(f.startswith("11@0.86: g2_a_lo - g2_out_hi") for f in old_rep.check("motion_clearance").failures)
    assert min(part_gaps(old, "g2_a_lo", "g2_out_hi", way).values()) < 0.05
    asm, rep = mesh_piece("robot_g2", walls=False)
    near = [t for t in asm.motion_trims if t.get("near")]
    assert [(t["part"], t["clear_of"]) for t in near] == [("g2_a_lo", "g2_out_hi")], asm.motion_trims
    assert near[0]["settled"] and 0 < near[0]["removed_mm3"] < 5.0, near
    assert not [f for f in rep.check("motion_clearance").failures if "g2_a_lo - g2_out_hi" in f]
    gaps = part_gaps(asm, "g2_a_lo", "g2_out_hi", way)
    assert min(gaps.values()) > 0.19, gaps
    # the blocking checks are those of the build without it (its states failures are the end
    # joint's under g2_a_lo, session 64, not this pair's)
    for name in BLOCKING:
        assert rep.check(name).ok == old_rep.check(name).ok, name
    assert set(rep.check("states").failures) <= set(old_rep.check("states").failures) | {
        f for f in rep.check("states").failures if "g2_out_hi" not in f}


def test_a_lever_passing_a_joint_part_not_its_own_is_trimmed():
    """Session 68 (``JOINT_STROKES``): the README circuit's ``g1_b_lo`` comes to 0.105 mm of the gate's
    joint part at d (``g1_ujoint_d``, which joins ``core_cd`` and ``out_hi``, not the lever) in row 11.
    Joint parts are never trimmed, and the stroke trims took pairs of bodies only; now a body and a
    joint part not its own get the same capped trim, of the body.  ``circuit_g1``: the README
    circuit's g1 with the last three half units of both input chains, its 22 poses."""
    _, poses = load_piece("circuit_g1")
    old, old_rep = mesh_piece("circuit_g1", walls=False, JOINT_STROKES=False)
    assert "11: g1_b_lo - g1_ujoint_d" in {f.rsplit(":", 1)[0] for f in old_rep.check("motion_clearance").failures}
    assert part_gaps(old, "g1_b_lo", "g1_ujoint_d", {"11": poses["11"]})["11"] < 0.12
    asm, rep = mesh_piece("circuit_g1", walls=True)
    for name in ("watertight", "part_count", "min_gap", "states", "retention", "features"):
        assert rep.check(name).ok, (name, rep.check(name).detail)
    assert rep.check("motion_clearance").ok, rep.check("motion_clearance").failures
    assert rep.check("wall_thickness").ok, rep.check("wall_thickness").failures
    assert any(t["part"] == "g1_b_lo" and t["clear_of"] == "g1_ujoint_d" for t in asm.motion_trims), asm.motion_trims
    gaps = part_gaps(asm, "g1_b_lo", "g1_ujoint_d", {k: poses[k] for k in ("11", "11@0.86")})
    assert min(gaps.values()) > 0.19, gaps
