"""Session 67 (issue 13): a chain's compound junctions keep the clearance in motion.

Session 65's ``motion_clearance`` on the README circuit found 809 of its 844 close pairs between one
chain's neighbouring half units, at the compound junctions.  Two places, both square corners built
exactly one clearance apart (``tests/data_mesh/circuit_junction``: ``w_b_0``, half units 58-62, with
the circuit's 22 print poses):

- the host stack's knuckle that ends nearest the joint point (its end face towards it, along the
  first pin) and the other body's yoke knuckle (its inner end, along the second pin): their rims
  were 0.2 mm apart at mjp, and the junction's bend and twist in the poses (the scene's ball joint)
  took them to 0.03 mm.  Now both rims are chamfered at 45 degrees (``RIM_CHAMFER``, 0.16 mm at mjp);
- the host's body (C) was trimmed about the first pin to ``R + c`` on each side of the joint
  point, where the other body's yoke knuckles reach ``R``: 0.2 mm, down to 0.10 in the poses.  Now
  ``R + 2c`` (``HOST_CUT_MARGIN``; C alone: on the hinge's other bodies it left a 0.4 mm web).

The square build is session 66's: both flags off, and ``CLOSE_STROKES`` (the stroke trims of bodies
that only come near, tests/test_mesh_circuit_gate_stroke.py) off too."""
from __future__ import annotations

import numpy as np
import pytest


from helpers import load_piece, mesh_piece, part_gaps

BLOCKING = ("watertight", "part_count", "min_gap", "states", "retention", "features")


def test_a_chamfered_knuckle_is_the_cylinder_less_its_rims():
    """The revolved knuckle's volume against the 32-gon prism less two 45-degree rim rings (exact
    for the polygon: each ring is the prism's rim triangle swept round), and its ends."""
    from mlc.mesh.build import cylinder, knuckle
    R, L, lo, hi, n = 1.1, 1.3, 0.16, 0.1, 32
    d = np.array([0.3, -0.5, 0.8])
    d /= np.linalg.norm(d)
    o = np.array([1.0, 2.0, -3.0])
    k = knuckle(o, d, 0.0, L, R, n, lo=lo, hi=hi)
    plain = cylinder(o, d, 0.0, L, R, n)
    # a polygon of apothem a = R cos(pi/n) and perimeter P = 2 n R sin(pi/n): a rim chamfer of x
    # (measured at the vertices) removes the frustum-shaped ring between the prism and the cone
    a, P = R * np.cos(np.pi / n), 2 * n * R * np.sin(np.pi / n)

    def ring(x):   # prism slice of height x less the frustum from (R - x) to R, both n-gons
        area = lambda r: 0.5 * (r / R) ** 2 * P * a        # noqa: E731
        frustum = x / 3 * (area(R) + area(R - x) + np.sqrt(area(R) * area(R - x)))
        return x * area(R) - frustum
    assert k.volume() == pytest.approx(plain.volume() - ring(lo) - ring(hi), rel=1e-9)
    assert k.genus() == 0
    # its end faces: the discs out to R less each chamfer (the vertices farthest along the axis)
    v = np.asarray(k.to_mesh().vert_properties)[:, :3] - o
    s = v @ d
    r = np.linalg.norm(v - np.outer(s, d), axis=1)
    assert r[np.abs(s) < 1e-5].max() == pytest.approx(R - lo, abs=1e-5)
    assert r[np.abs(s - L) < 1e-5].max() == pytest.approx(R - hi, abs=1e-5)
    assert r.max() == pytest.approx(R, abs=1e-5)


def test_a_chamfered_ring_of_the_minimum_wall_measures_whole():
    """A knuckle ring of exactly the minimum wall (mjp: R 1.1, hole 0.5 mm) chamfered at one or
    both ends: the wall measure finds no thin region, at any orientation.  (A cone unioned to the
    cylinder, the first try, left slivers of triangles along the seam where 9 of 16 such rings
    measured thin; so did a plain cylinder unioned from two.)"""
    from mlc.mesh.build import cylinder, knuckle, subtract, union
    from mlc.mesh.walls import thin_walls
    rng = np.random.default_rng(1)
    seams = 0
    for trial in range(8):
        d = rng.normal(size=3)
        d /= np.linalg.norm(d)
        o = rng.normal(size=3)
        hole = [cylinder(o, d, -0.1, 1.2, 0.5, 32, cutter=True)]
        ring = subtract(knuckle(o, d, 0.0, 1.1, 1.1, 32, lo=0.16, hi=0.16 * (trial % 2)), hole)
        assert thin_walls("k", ring, 0.6) == [], trial
        split = subtract(union([cylinder(o, d, 0.0, 0.16, 1.1, 32), cylinder(o, d, 0.16, 1.1, 1.1, 32)]), hole)
        seams += bool(thin_walls("k", split, 0.6))
    # the measure can tell: the seam's slivers (the same solid) do read thin at some orientation
    assert seams > 0


@pytest.fixture(scope="module")
def square():
    return mesh_piece("circuit_junction", walls=False, RIM_CHAMFER=0.0, HOST_CUT_MARGIN=0.0, CLOSE_STROKES=False)


@pytest.fixture(scope="module")
def chamfered():
    return mesh_piece("circuit_junction", walls=True)


def _close(rep):
    return {f.split(": ", 1)[0] + ": " + f.split(": ")[1] for f in rep.check("motion_clearance").failures}


def test_square_junctions_come_within_the_clearance(square):
    asm, rep = square
    close = _close(rep)
    # the two corners: a host knuckle against the next half unit's yoke knuckle, and C's slab
    assert "01: w_b_0_60_CD - w_b_0_61_AB" in close, sorted(close)[:20]
    assert "01: w_b_0_59_BC - w_b_0_60_CD" in close, sorted(close)[:20]
    assert len(close) > 100
    # outside mlc (trimesh samples, a k-d tree: an upper bound of the gap) they are that close too
    _, poses = load_piece("circuit_junction")
    assert part_gaps(asm, "w_b_0_60_CD", "w_b_0_61_AB", {"01": poses["01"]})["01"] < 0.1
    assert part_gaps(asm, "w_b_0_59_BC", "w_b_0_60_CD", {"01": poses["01"]})["01"] < 0.15


def test_chamfered_junctions_keep_the_clearance_and_every_check(chamfered, square):
    asm, rep = chamfered
    for name in BLOCKING:
        assert rep.check(name).ok, (name, rep.check(name).detail)
    close = _close(rep)
    assert not any(p.endswith("w_b_0_60_CD - w_b_0_61_AB") or p.endswith("w_b_0_59_BC - w_b_0_60_CD")
                   for p in close), sorted(close)
    assert len(close) <= 4, sorted(close)
    assert rep.check("motion_clearance").value > 0.14
    # the chamfers take no wall: no more thin regions than the square build's
    _, sq_rep = square
    assert len(rep.check("wall_thickness").failures) <= 4, rep.check("wall_thickness").failures
    # outside mlc: the sampled gap (an upper bound, within the samples' spacing of the true one)
    _, poses = load_piece("circuit_junction")
    for a, b in (("w_b_0_60_CD", "w_b_0_61_AB"), ("w_b_0_59_BC", "w_b_0_60_CD")):
        gaps = part_gaps(asm, a, b, {k: poses[k] for k in ("01", "10", "11")})
        assert min(gaps.values()) > 0.19, (a, b, gaps)


@pytest.fixture(scope="module")
def twist():
    return mesh_piece("circuit_twist", walls=True)


@pytest.fixture(scope="module")
def owner_margin():
    return mesh_piece("circuit_twist", walls=True, OWNER_CUT_MARGIN=True)


def test_the_owner_cut_face_meets_the_twisted_yoke(twist, owner_margin):
    """Session 68: what is left of the README circuit's close neighbours (``circuit_twist``:
    ``w_b_1``, half units 108-113, the circuit's 22 poses).  At junction ``j111_hi`` the stack's
    owner (``110_AB``, the hinge's other body: its end knuckle captures the joint's collar) is cut
    to ``R + c`` about the first pin, and the yoke knuckle of ``111_CD`` stands ``c`` from that face;
    the scene's ball joint turns it about the third axis in row 10 (about 3 degrees, which the
    printed cardan takes up in its play), to 0.10 mm, the owner not turning about the first pin there.  Trimming the owner with the margin too
    (``OWNER_CUT_MARGIN``) clears it, outside mlc as well, but leaves the owner's end knuckle on a
    web under the minimum wall: off by default."""
    asm, rep = twist
    for name in BLOCKING:
        assert rep.check(name).ok, (name, rep.check(name).detail)
    close = _close(rep)
    assert "10: w_b_1_110_AB - w_b_1_111_CD" in close, sorted(close)
    assert rep.check("motion_clearance").value < 0.11
    assert not rep.check("wall_thickness").failures
    _, poses = load_piece("circuit_twist")
    assert part_gaps(asm, "w_b_1_110_AB", "w_b_1_111_CD", {"10": poses["10"]})["10"] < 0.12
    # the scene's turn of the yoke body relative to the owner, in the junction's frame: about the
    # second pin (the cardan's own) and about the third axis, which the printed cardan cannot make
    (uj,) = [u for u in asm.ujoints if u.name == "w_b_1_j111_hi"]
    T = asm.part_transforms(*poses["10"])
    F = np.column_stack([uj.axes[0], uj.axes[1], np.cross(uj.axes[0], uj.axes[1])])
    M = np.linalg.solve(T["w_b_1_110_AB"], T["w_b_1_111_CD"])[:3, :3]
    Rl = F.T @ M @ F                                   # a small turn: its skew part is the rotation vector
    turn = np.degrees([Rl[2, 1] - Rl[1, 2], Rl[0, 2] - Rl[2, 0], Rl[1, 0] - Rl[0, 1]]) / 2
    assert abs(turn[0]) < 0.5 and 2.5 < abs(turn[2]) < 4.0, turn

    asm_o, rep_o = owner_margin
    for name in BLOCKING:
        assert rep_o.check(name).ok, (name, rep_o.check(name).detail)
    assert not any(p.endswith("w_b_1_110_AB - w_b_1_111_CD") for p in _close(rep_o))
    gaps = part_gaps(asm_o, "w_b_1_110_AB", "w_b_1_111_CD", {k: poses[k] for k in ("10", "11")})
    assert min(gaps.values()) > 0.19, gaps
    thin = rep_o.check("wall_thickness")
    assert len(thin.failures) >= 2 and thin.value < 0.5, thin.failures
    assert any("w_b_1_111_AB" in f for f in thin.failures), thin.failures
