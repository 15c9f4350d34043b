"""Print-only feet (mlc.mesh.feet): parts that move in one plane carried down to the bed, clear of
every other part as printed and in every pose."""
import types

import manifold3d as mf
import numpy as np
import pytest

from mlc.mesh import feet as FT
from mlc.mesh.build import Part, transform_solid
from mlc.mesh.profiles import load_profile

from helpers import downward_faces


def _box(lo, hi):
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    return mf.Manifold.cube((hi - lo).tolist()).translate(lo.tolist())


def _T(R=np.eye(3), t=(0, 0, 0)):
    T = np.eye(4)
    T[:3, :3] = R
    T[:3, 3] = t
    return T


def _rot_x(deg):
    a = np.radians(deg)
    return np.array([[1, 0, 0], [0, np.cos(a), -np.sin(a)], [0, np.sin(a), np.cos(a)]])


def _rot_z(deg):
    a = np.radians(deg)
    return np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]])


def _toy():
    """Two vertical plates A and B standing 5 mm above the bed (z = 0), B turning about a z axis
    relative to A; a block C on the bed under A that tilts about x (not planar) and slides
    along A: A's foot must go round C in every pose."""
    prof = load_profile("fdm")
    parts = [Part("A", "body", _box([0, 0, 5], [30, 1.2, 15])),
             Part("B", "body", _box([0, 6, 5], [30, 7.2, 15])),
             Part("C", "body", _box([10, -2, 0], [14, 3, 3]))]
    asm = types.SimpleNamespace(parts=parts, profile=prof, notes=[],
                                axes=[types.SimpleNamespace(direction=np.array([0, 0, 1.0]))])
    asm.part = lambda n: next(p for p in parts if p.name == n)
    Ts = []
    for k in range(9):
        Ts.append({"A": _T(), "B": _T(_rot_z(2 * k), (0.0, 0.0, 0.0)),
                   "C": _T(_rot_x(3 * k), (0.5 * k, 0.0, 0.0))})
    return asm, Ts


def test_planar_parts_are_found_up_to_a_motion_of_the_whole():
    asm, Ts = _toy()
    assert sorted(FT.planar_parts(asm, Ts, [0, 0, 1])) == ["A", "B"]
    # the mechanism floats: a common motion of every part changes nothing
    G = _T(_rot_x(25), (3, -2, 7))
    assert sorted(FT.planar_parts(asm, [{k: G @ v for k, v in T.items()} for T in Ts], [0, 0, 1])) == ["A", "B"]
    assert len(FT.planar_parts(asm, Ts, [1, 0, 0])) == 1          # B turns about z, C slides along x


def test_feet_reach_the_bed_and_keep_the_clearance_in_every_pose():
    asm, Ts = _toy()
    c = asm.profile.clearance
    before = {p.name: p.solid for p in asm.parts}
    lows = {n: float(np.asarray(s.bounding_box())[2]) for n, s in before.items()}
    first = mf.CrossSection.batch_boolean([p.solid.slice(0.1) for p in asm.parts], mf.OpType.Add).area()
    notes = FT.add_feet(asm, Ts)
    assert notes and set(asm.feet) == {"A", "B"}
    A, B, C = (asm.part(n).solid for n in "ABC")
    # both plates now start on the bed, in one piece, and the first layer grew
    assert lows["A"] == pytest.approx(5.0) and np.asarray(A.bounding_box())[2] == pytest.approx(0.0, abs=1e-9)
    assert len(A.decompose()) == 1 and len(B.decompose()) == 1
    after = mf.CrossSection.batch_boolean([p.solid.slice(0.1) for p in asm.parts], mf.OpType.Add).area()
    assert after > first + 0.5 * (30 * 1.2 * 2 - 5 * 1.2)
    # C untouched; A's foot goes round C: at least the clearance from C as printed and in every pose
    assert C.volume() == pytest.approx(before["C"].volume())
    for T in [{n: np.eye(4) for n in "ABC"}] + Ts:
        for X, Y in (("A", "C"), ("B", "C"), ("A", "B")):
            M = np.linalg.solve(T[X], T[Y])
            g = asm.part(X).solid.min_gap(transform_solid(asm.part(Y).solid, M), 2 * c)
            assert g >= c - 1e-6, (X, Y, g)
    # and the foot is not simply absent where C was: A keeps most of its bed section
    sec = A.slice(0.1).area()
    assert 0.5 * 30 * 1.2 < sec < 30 * 1.2


def test_feet_are_at_least_the_minimum_wall_where_a_shadow_narrows_them():
    """A plate exactly the minimum wall thick (fdm: 1.2 mm) with a block C on the bed beside it,
    C's shadow (grown by the clearance and the economies' slack) taking off all but 0.96 of the
    wall over 10 mm of the plate's length.  Opened at FOOT_OPEN (0.9 x the wall) alone and then
    simplified, as until session 38, that stretch of the foot stayed 1.15 mm wide, under the
    measured check's pass mark (0.985 x the wall), and the rest of the foot a little under the
    wall too.  Now every foot passes the measured wall check, A's still reaches the bed along most
    of the plate, and the feet keep the clearance from C and from each other in every pose."""
    from mlc.mesh.walls import thin_walls
    prof = load_profile("fdm")
    mw, c = prof.min_wall, prof.clearance
    edge = 0.96 * mw + c * (1 + FT.FOOT_MARGIN) + FT.FOOT_MERGE_MM + 2 * FT.FOOT_SIMPLIFY_MM
    parts = [Part("A", "body", _box([0, 0, 5], [30, mw, 15])),
             Part("B", "body", _box([0, 6, 5], [30, 6 + mw, 15])),
             Part("C", "body", _box([10, edge, 0], [20, 4, 3]))]
    asm = types.SimpleNamespace(parts=parts, profile=prof, notes=[],
                                axes=[types.SimpleNamespace(direction=np.array([0, 0, 1.0]))])
    asm.part = lambda n: next(p for p in parts if p.name == n)
    Ts = [{"A": _T(), "B": _T(_rot_z(0.5 * k), (0.0, 0.0, 0.0)), "C": _T()} for k in range(5)]
    FT.add_feet(asm, Ts)
    assert set(asm.feet) == {"A", "B"}
    A = asm.part("A").solid
    assert np.asarray(A.bounding_box())[2] == pytest.approx(0.0, abs=1e-9)
    assert 0.6 * 30 * mw < A.slice(0.1).area() < 30 * mw * 1.3
    for n in "AB":
        assert thin_walls(n, asm.part(n).solid, mw) == [], n
    for T in [{n: np.eye(4) for n in "ABC"}] + Ts:
        for X, Y in (("A", "C"), ("B", "C"), ("A", "B")):
            M = np.linalg.solve(T[X], T[Y])
            g = asm.part(X).solid.min_gap(transform_solid(asm.part(Y).solid, M), 2 * c)
            assert g >= c - 1e-6, (X, Y, g)


def test_without_feet_nothing_changes():
    asm, Ts = _toy()
    vol = [p.solid.volume() for p in asm.parts]
    old = FT.BED_FEET
    try:
        FT.BED_FEET = False
        assert FT.add_feet(asm, Ts) == [] and asm.feet == {}
    finally:
        FT.BED_FEET = old
    assert [p.solid.volume() for p in asm.parts] == vol


@pytest.fixture(scope="module")
def nand_fdm():
    from mlc.gates.library import gate_scene
    from mlc.mesh.pipeline import export_assembly
    return export_assembly(gate_scene("NAND", "expand"), load_profile("fdm"))


def test_nand_fdm_sits_on_the_bed_and_keeps_the_clearance_in_motion(nand_fdm):
    """``mlc stl``'s pipeline (dense poses, motion trims, feet, orientation, report): NAND's lever
    loop gets feet, its first layer reaches BED_CONTACT_MIN -- the same parts without their feet
    (the model's z up, the pose fdm printed before) do not -- and every check that blocks still
    passes, the clearance in every dense pose measured on the parts with their feet."""
    from mlc.mesh.checks import BED_CONTACT_MIN, OVERHANG_DEG, island_side
    from mlc.mesh.pose import report_grid
    from mlc.mesh.printability import bed_stats
    asm, rep = nand_fdm
    assert {"core_ab", "core_cd", "a_lo", "a_hi", "b_lo", "b_hi"} <= set(asm.feet)
    assert rep.ok, rep.text()
    mc = rep.check("motion_clearance")
    assert mc.ok and mc.blocking and mc.value >= asm.profile.clearance - 1e-6, mc.detail
    assert rep.check("min_gap").ok and rep.check("states").ok and rep.check("retention").ok
    assert all(len(p.solid.decompose()) == 1 for p in asm.parts)
    bc = rep.check("bed_contact")
    assert bc.ok and bc.value >= BED_CONTACT_MIN, bc.detail
    # without the feet, as fdm printed it before (the model's z up): far from the goal
    sol = [(p.name, asm.feet_free.get(p.name, p.solid)) for p in asm.parts]
    lo = np.min([np.asarray(s.bounding_box())[:3] for _, s in sol], 0)
    hi = np.max([np.asarray(s.bounding_box())[3:] for _, s in sol], 0)
    sol = [(n, s.translate([0.0, 0.0, -lo[2]])) for n, s in sol]
    before = bed_stats(sol, OVERHANG_DEG, report_grid(hi - lo, asm.profile.min_wall), first_layer=0.2,
                       island_mm=island_side(asm.profile))
    assert before.contact_fraction < 0.25 * BED_CONTACT_MIN
    # the loop's parts now start on the bed (the print frame)
    lows = asm.bed.lowest_mm
    assert all(lows[n] < 0.05 for n in asm.feet), lows


def test_feet_go_down_only_where_the_print_can_have_up():
    """``as_is`` prints the model's z up: feet only along -z; ``axes_flat`` lays every hinge axis
    on the bed: no feet.  (A hinge along x would carry the plates down along x, sideways on the
    printed model: mjp NAND's first run of the benchmark, before this rule.)"""
    from dataclasses import replace
    asm, Ts = _toy()
    asm.profile = replace(asm.profile, orient="as_is")
    assert FT.plan_feet(asm, [{n: np.eye(4) for n in "ABC"}] + Ts)[0] @ np.array([0, 0, 1.0]) > 0.999
    # a hinge along x, and C beyond the plates' ends along x: A and B could be carried along -x
    asm.axes = [types.SimpleNamespace(direction=np.array([1.0, 0, 0]))]
    asm.part("C").solid = _box([-5, -2, 0], [-1, 3, 3])
    still = [{"A": _T(), "B": _T(), "C": _T()}]
    assert FT.plan_feet(asm, still) is None
    asm.profile = replace(asm.profile, orient="auto")
    d = FT.plan_feet(asm, still)[0]                           # sideways is allowed when up is searched
    assert abs(d[0]) > 0.999
    asm, Ts = _toy()
    asm.profile = replace(asm.profile, orient="axes_flat")
    assert FT.add_feet(asm, Ts) == [] and asm.feet == {}


def test_nand_fdm_attachment_holes_are_teardrops_without_a_flat_ceiling(nand_fdm):
    """In ``mlc stl``'s fdm print (the feet's up, the model's z) every attachment hole inside a
    slab runs across the layers (the input levers' slabs stand vertical, the output lever's lean
    at about 48 degrees), so each is a teardrop pointing up: measured on the finished part in the
    print frame, no downward face within the hole's reach is flatter than the overhang limit.
    A round hole there (as before) has its ceiling flatter than the limit."""
    from mlc.mesh.build import TEARDROP_SIDE_DEG, cylinder, transform_solid
    from mlc.mesh.checks import OVERHANG_DEG
    asm, rep = nand_fdm
    holes = {name: (c, nrm, kind) for name, c, nrm, kind in asm.holes}
    assert set(holes) == {"a_lo", "a_hi", "b_lo", "b_hi", "out_lo", "out_hi"}, asm.holes
    assert all(kind == "teardrop" for _, _, kind in holes.values())
    lim = np.cos(np.radians(90.0 - OVERHANG_DEG))
    r = max(asm.profile.min_feature, 0.08 * asm.profile.sigma_mm) / 2
    reach = r / np.cos(np.radians(TEARDROP_SIDE_DEG)) + 0.3
    for name, (c, nrm, _) in holes.items():
        T = asm.print_T(name)
        part = transform_solid(asm.part(name).solid, T)
        pc = T[:3, :3] @ c + T[:3, 3]
        nz, area = _down_near(part, pc, T[:3, :3] @ nrm, reach, asm.slab_thickness)
        assert area.sum() > 0 and np.all(nz >= -lim - 1e-6), (name, nz.min())
        # the same part with a round hole there instead: a ceiling flatter than the limit
        t = asm.slab_thickness
        plug = cylinder(pc, T[:3, :3] @ nrm, -t / 2, t / 2, reach, 32)
        rnd = (part + plug) - cylinder(pc, T[:3, :3] @ nrm, -5, 5, r, 32, cutter=True)
        nz, area = _down_near(rnd, pc, T[:3, :3] @ nrm, r + 0.3, t)
        assert area[nz < -lim - 1e-6].sum() > 0.05, name


def _down_near(solid, centre, axis, reach, t):
    """(normal z, area) of the downward faces of ``solid`` within ``reach`` of the line through
    ``centre`` along ``axis`` and within the slab (``t`` thick) around ``centre``."""
    nz, area, mid = downward_faces(solid)
    q = mid - centre
    a = np.asarray(axis, float) / np.linalg.norm(axis)
    along = q @ a
    radial = np.linalg.norm(q - np.outer(along, a), axis=1)
    keep = (radial < reach) & (np.abs(along) < t)
    return nz[keep], area[keep]


def test_nand_fdm_output_lever_pivot_chamfered_and_teardropped(nand_fdm):
    """The output lever's pivot (out_lo, out_hi) lies flat in the fdm print: its crossing arms are
    chamfered beside the other knuckles and its knuckles get teardrops (mlc.mesh.pivot), every
    blocking check still passing.  mlc's support estimate was 3862 mm^3 (58.2 % of the part
    volume; 2182 of it under the pivot, session 40) and is about 1100 mm^3 (17 %) with them,
    no island left (session 54, docs/printing.md)."""
    asm, rep = nand_fdm
    assert rep.ok, rep.text()
    assert any("out_hi's arms chamfered" in n for n in asm.notes), asm.notes
    assert any(n.startswith("out_lo: teardrops under the knuckles of pivot_out") for n in asm.notes), asm.notes
    for n in asm.notes:                   # a hinge named once, with each knuckle's flat
        if ": teardrops under the knuckles of " in n:
            hinges = [h.split(" (flat")[0] for h in n.split(" of ", 1)[1].split(" mm below the axis), ")]
            assert len(hinges) == len(set(hinges)), n
    assert asm.bed.islands == 0
    assert asm.bed.support_fraction < 0.20, asm.bed.support_fraction
    lever = sum(asm.bed.per_part[n][1] for n in ("out_lo", "out_hi"))
    assert lever < 800.0, lever           # 3269 mm^3 before (session 40: pivot 2182, arms 1087)
