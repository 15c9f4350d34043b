"""Session 58 (issue 13, "meets the profile's minimum wall everywhere", compiled circuits): two
walls of a circuit gate that were thinner than mjp's 0.6 mm minimum.

*core_cd's web at hinge c* (``WEB_BRIDGES``).  In a library gate ``core_cd`` is cut twice round
hinge c's middle (the trim for ``a_hi``'s and ``b_hi``'s knuckles and the universal joint's trim
towards d), and the web left between the two cuts is bridged where no other body swings
(``_bridge``, session 36).  Compiled circuits (``reuse``) were built without that step, and every
gate of the README's Tetris circuit kept a web of 0.21-0.24 mm (its report: ``g1_core_cd: wall
0.24 mm ... 0.23 mm at its thinnest``).  The step now runs for a circuit's three-body hinges too,
the bridge kept clear of the other bodies in the circuit's print poses.

*The posts under the input levers* (``ROD_WALL``).  A chain hangs its end joint under a gate's input
lever on a post, a rod of ``POST_WIDTH`` (0.08 sigma) square (mlc.circuit.build).  The print raised
a slab box's thinnest side to the profile's slab thickness; the rod's second thin side stayed 0.4 mm
at mjp (sigma 5 mm): every input lever had a region of 0.40 mm over 1.5-1.8 mm^3 along its post.
Both thin sides of a rod are now printed at the slab thickness.

``circuit_g3`` (tests/data_mesh) is gate g3 of that circuit with the chains' last half units around
it and the whole circuit's 22 poses (see tests/test_mesh_circuit_gate_stroke.py)."""
from __future__ import annotations

import numpy as np
import pytest

from mlc.geometry.rotation import quat_to_matrix
from mlc.mesh import build as B
from mlc.mesh.build import build_assembly
from mlc.mesh.checks import check_assembly
from mlc.mesh.profiles import load_profile
from mlc.mesh.walls import thin_walls

from helpers import largest_disc, load_piece, mesh_piece, part_gaps, web_sections

LEVERS = ("g3_a_lo", "g3_a_hi", "g3_b_lo", "g3_b_hi")
BLOCKING = ("watertight", "part_count", "min_gap", "states", "retention", "features")


@pytest.fixture(scope="module")
def piece():
    return load_piece("circuit_g3")


def _build(piece, **flags):
    """The piece at mjp, with mlc.mesh.build's flags (``WEB_BRIDGES``, ``ROD_WALL``) set as given."""
    sc, poses = piece
    with B.flags(**flags):
        return build_assembly(sc, load_profile("mjp"), poses, reuse=True)


@pytest.fixture(scope="module")
def built(piece):
    return _build(piece)


def test_a_circuit_gates_web_at_hinge_c_is_bridged_to_the_full_wall(built):
    asm = built
    prof = asm.profile
    assert any(n.startswith("hinge g3_hinge_c") and "g3_core_cd bridges" in n
               and "thinner than the minimum wall" in n for n in asm.notes), asm.notes
    # outside mlc.mesh.walls: sections across the other knuckles, the largest disc in each web
    webs = web_sections(asm, prof.min_wall, owner="g3_core_cd")
    assert webs and min(webs) >= prof.min_wall - 1e-3, webs
    # and the report's own measure of the finished part
    assert thin_walls("g3_core_cd", asm.part("g3_core_cd").solid, prof.min_wall) == []
    assert len(asm.part("g3_core_cd").solid.decompose()) == 1


def test_the_bridged_piece_passes_every_blocking_check_in_the_circuits_poses(built):
    rep = check_assembly(built, walls=False)
    by = {c.name: c for c in rep.checks}
    for name in BLOCKING:
        assert by[name].ok, (name, by[name].detail, by[name].failures)


def test_without_the_bridge_the_web_is_thinner_than_the_wall(piece):
    """The same piece as compiled circuits were built before: the web is under the minimum wall,
    by the sections and by the report's wall measure (so the test above can fail).  (Without
    SHAVE_THIN too: the web holds nothing, and mlc.mesh.shave would take it off instead.)"""
    old = _build(piece, WEB_BRIDGES=False, SHAVE_THIN=False)
    prof = old.profile
    assert not any("g3_core_cd bridges" in n for n in old.notes)
    webs = web_sections(old, prof.min_wall, owner="g3_core_cd")
    assert webs and min(webs) < 0.5 * prof.min_wall, webs
    thin = thin_walls("g3_core_cd", old.part("g3_core_cd").solid, prof.min_wall)
    assert thin and min(w.thickness_mm for w in thin) < 0.5 * prof.min_wall, thin


def _post_sections(asm, sc):
    """For each input lever, the post's cross-section half-way along it (the lever's box with two
    sides under 0.1 sigma, from the scene, not from the mesher): the diameter of the largest disc
    in it (manifold3d slice, Clipper2 offsets, 0.001 mm) and its two side lengths (mm)."""
    s = asm.profile.sigma_mm
    out = {}
    for b in sc.bodies:
        if b.name not in LEVERS:
            continue
        (bx,) = [bx for bx in b.boxes if sorted(bx.size)[1] < 0.1]
        Rb = quat_to_matrix(b.orientation)
        R = Rb @ quat_to_matrix(bx.orientation)
        c = s * (np.asarray(b.position, float) + Rb @ np.asarray(bx.center, float))
        ia = int(np.argmax(bx.size))
        others = [i for i in range(3) if i != ia]
        # a frame with the post's length along z, its two thin sides along x and y
        F = np.vstack([R[:, others[0]], R[:, others[1]], R[:, ia]])
        M = np.hstack([F, (-F @ c)[:, None]])
        cs = asm.part(b.name).solid.transform(M.tolist()).slice(0.0)
        (piece,) = [p for p in cs.decompose() if p.bounds()[0] <= 0 <= p.bounds()[2] and p.bounds()[1] <= 0 <= p.bounds()[3]]
        x0, y0, x1, y1 = piece.bounds()
        out[b.name] = (largest_disc(piece), x1 - x0, y1 - y0)
    return out


def test_posts_are_printed_at_the_slab_thickness_both_ways(built, piece):
    prof = built.profile
    posts = _post_sections(built, piece[0])
    assert set(posts) == set(LEVERS)
    for name, (disc, a, b) in posts.items():
        assert disc >= prof.min_wall - 2e-3 and min(a, b) >= prof.slab_thickness - 2e-3, (name, posts)


def test_without_rod_walls_the_posts_are_thinner_than_the_wall(piece):
    old = _build(piece, ROD_WALL=False)
    posts = _post_sections(old, piece[0])
    for name, (disc, a, b) in posts.items():
        assert disc < old.profile.min_wall - 0.1, (name, posts)      # 0.4 mm: POST_WIDTH at sigma 5 mm
        assert abs(min(a, b) - 0.08 * old.profile.sigma_mm) < 0.01, (name, posts)


def _yoke_plate_sections(asm):
    """For each input lever, its yoke plate into the post (the chain's end joint, whose second
    pin ``v`` is the lever's): sections of the finished part across ``v`` at 0.6 and 0.9 mm either
    side of the joint's centre (inside the trim about the pin, clear of the yoke knuckles), and in
    each the diameter of the largest disc in the pieces that reach the trim about ``v`` (manifold3d
    slice, Clipper2 offsets, 0.001 mm): the band that trim leaves of the plate."""
    out = {}
    for bn in LEVERS:
        (uj,) = [u for u in asm.ujoints if u.bodies[1] == bn]
        v = np.asarray(uj.axes[1], float)
        e = np.cross(uj.axes[0], v)
        e /= np.linalg.norm(e)
        F = np.vstack([e, np.cross(v, e), v])
        discs = []
        for a in (-0.9, -0.6, 0.6, 0.9):
            M = np.hstack([F, (-F @ (uj.center + a * v))[:, None]])
            cs = asm.part(bn).solid.transform(M.tolist()).slice(0.0)
            for p in cs.decompose():
                x0, y0, x1, y1 = p.bounds()
                if np.hypot(np.clip(0.0, x0, x1), np.clip(0.0, y0, y1)) >= uj.rho[1] + 0.1:
                    continue        # not on the trim: the post itself, cut across
                discs.append(largest_disc(p))
        out[bn] = discs
    return out


def test_the_yoke_plate_into_a_post_is_a_full_wall_past_the_trim_about_its_pin(built):
    """Session 63 (``ROD_PLATE_WALL``): the yoke plate that joins the chain's end joint to the
    post under each input lever reached ``max(R, hub) + 2 t`` = 2.3 mm from the pin, and the trim
    about the pin (1.865 mm here) left a band of 0.43 mm: the circuit's last thin regions on its
    gates (the README job's report: ``g3_a_lo: wall 0.44 mm ... 0.43 mm at its thinnest``).  The
    plate now reaches the slab thickness past that trim's polygon."""
    prof = built.profile
    secs = _yoke_plate_sections(built)
    assert all(secs.values()), secs
    assert min(min(d) for d in secs.values()) >= prof.min_wall - 3e-3, secs
    # and the report's own measure of the finished levers
    for bn in LEVERS:
        assert thin_walls(bn, built.part(bn).solid, prof.min_wall) == [], bn


def test_without_rod_plate_walls_the_band_past_the_trim_is_thin(piece):
    old = _build(piece, ROD_PLATE_WALL=False)
    secs = _yoke_plate_sections(old)
    assert all(secs.values()) and max(max(d) for d in secs.values()) < old.profile.min_wall - 0.1, secs
    thin = [w for bn in LEVERS for w in thin_walls(bn, old.part(bn).solid, old.profile.min_wall)]
    assert len(thin) == 4 and all(w.thickness_mm < old.profile.min_wall - 0.1 for w in thin), thin


def test_the_yoke_plate_into_a_post_stays_short_where_a_longer_one_would_meet_the_core():
    """Session 64 (``ROD_PLATE_CLEAR``): the Tetris robot's gates turn their input levers further
    than the circuit's (``g2_a_lo`` 73 degrees from ``core_ab`` in state 11), and there the longer
    plate of ``ROD_PLATE_WALL`` met ``core_cd``: on ``robot_g2`` (the robot's gate g2 with two bond
    hops round it and the robot's 22 poses) ``g2_core_cd`` intersected ``g2_a_lo`` in states 11 and
    11@0.86.  The plate's stretch past the old reach is now tested against the other bodies in
    every pose and kept back (to 2.3 mm here) where it comes near one; the circuit's gate keeps
    its full wall (the test above).  Outside mlc: trimesh samples of the two finished parts posed
    in the 22 poses, a k-d tree's nearest pairs (an upper bound of the gap)."""
    sc, poses = load_piece("robot_g2")
    asm, rep = mesh_piece("robot_g2", walls=False)
    assert not [f for f in rep.check("states").failures if "g2_core_cd intersects g2_a_lo" in f]
    (uj,) = [u for u in asm.ujoints if u.name == "w_y_2_end_lo"]
    t, n = asm.slab_thickness, asm.profile.circular_segments
    old, full = B._rod_reaches(uj, t, n)
    assert full > old + 0.1 and uj.rod_wall is not None and old <= uj.rod_wall < full, (old, full, uj.rod_wall)
    assert any(nt.startswith("universal joint w_y_2_end_lo: g2_a_lo's yoke plate into its rod reaches")
               for nt in asm.notes), asm.notes
    gaps = part_gaps(asm, "g2_core_cd", "g2_a_lo", poses)
    assert len(gaps) == 22 and min(gaps.values()) > 0.05, gaps
    # the full reach in every pose: the two meet in state 11 (and share no hinge: without the
    # state trims of session 66, which would trim them there instead of keeping the plate short)
    asm2, rep2 = mesh_piece("robot_g2", walls=False, ROD_PLATE_CLEAR=False, STATE_CLEAR=False)
    fails = [f for f in rep2.check("states").failures if "g2_core_cd intersects g2_a_lo" in f]
    assert any(f.startswith("state 11:") for f in fails), rep2.check("states").failures
    assert min(part_gaps(asm2, "g2_core_cd", "g2_a_lo", poses).values()) < 0.02
