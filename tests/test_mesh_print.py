"""Issue 13: bed contact, overhangs and support volume, measured walls, the 3MF as one object,
stacked hinges on one line.  Each check is shown failing on a case built to break it."""
import types
import zipfile

import manifold3d as mf
import numpy as np
import pytest

from mlc.mesh import examples as ex
from mlc.mesh.build import build_assembly
from mlc.mesh.checks import BED_CONTACT_MIN, bed_checks, check_assembly, wall_check
from mlc.mesh.export import SLIC3R_CONFIG, part_meshes, read_3mf, threemf_bytes
from mlc.mesh.printability import bed_stats
from mlc.mesh.profiles import load_profile
from mlc.mesh.walls import thin_walls
from mlc.scene.model import Body, Bond, Scene


def _box(size, centre):
    return mf.Manifold.cube(list(size), True).translate(list(centre))


def test_bed_stats_of_a_cube_and_a_table():
    cube = bed_stats([("cube", _box([10, 10, 10], [0, 0, 5]))], h=0.25)
    assert abs(cube.footprint_mm2 - 100) < 1e-6 and abs(cube.contact_mm2 - 100) < 1e-6
    assert cube.overhang_mm2 == 0 and cube.support_mm3 == 0
    # a 10 x 10 x 1 table top at z 5..6 on a 2 x 2 leg: 96 mm^2 of overhang, 96 * 5 mm^3 of support
    table = _box([10, 10, 1], [0, 0, 5.5]) + _box([2, 2, 5.2], [0, 0, 2.6])
    st = bed_stats([("table", table)], h=0.25)
    assert abs(st.overhang_mm2 - 96) < 1e-3
    assert abs(st.support_mm3 - 480) < 0.05 * 480
    assert st.support_inside_mm3 == 0
    assert abs(st.contact_fraction - 0.04) < 1e-6
    # a box over another part: its support rests on that part (inside the mechanism)
    two = bed_stats([("low", _box([10, 10, 2], [0, 0, 1])), ("high", _box([4, 4, 1], [0, 0, 4.5]))], h=0.25)
    assert abs(two.support_inside_mm3 - 16 * 2) < 1.0 and two.per_part["high"][2] > 0
    # a slab at 60 degrees is self-supporting (only its 10 x 1 end face, 30 degrees from the bed,
    # overhangs), one at 30 degrees is not (its 10 x 10 underside overhangs; its end face does not)
    R60 = mf.Manifold.cube([10, 10, 1], True).rotate([0, 60, 0]).translate([0, 0, 6])
    R30 = mf.Manifold.cube([10, 10, 1], True).rotate([0, 30, 0]).translate([0, 0, 6])
    assert abs(bed_stats([("a", R60)]).overhang_mm2 - 10) < 1e-3
    assert abs(bed_stats([("b", R30)]).overhang_mm2 - 100) < 1e-3


def _fake(stats_solids, profile="fdm"):
    asm = types.SimpleNamespace(profile=load_profile(profile))
    return bed_checks(asm, bed_stats(stats_solids, h=0.25))


def test_bed_checks_pass_and_fail():
    ok = _fake([("cube", _box([10, 10, 10], [0, 0, 5]))])
    assert [c.ok for c in ok] == [True, True]
    table = _fake([("table", _box([10, 10, 1], [0, 0, 5.5]) + _box([2, 2, 5.2], [0, 0, 2.6]))])
    assert not table[0].ok and table[0].value < BED_CONTACT_MIN       # 4 % of the footprint on the bed
    assert not table[1].ok                                            # support 480 mm^3 for 153 mm^3 of part
    inside = _fake([("low", _box([10, 10, 2], [0, 0, 1])), ("high", _box([9, 9, 1], [0, 0, 4.5]))])
    assert inside[0].ok                                               # well on the bed ...
    assert not inside[1].ok and any("inside the mechanism" in f for f in inside[1].failures)   # ... but supported on a part


@pytest.mark.parametrize("k", range(4))
def test_wall_measure_calibration(k):
    """A plate of the minimum wall passes at any offset and angle; 0.43 mm of 0.6 fails."""
    rot, off = [7 * k, 11 * k, 3 * k], [0.013 * k, 0.007 * k, 0.031 * k]
    for t, thin in ((0.6, False), (0.43, True), (0.3, True)):
        w = thin_walls("p", mf.Manifold.cube([6, 4, t], True).rotate(rot).translate(off), 0.6)
        assert bool(w) == thin, (t, w)
        if w:
            assert abs(w[0].thickness_mm - t) < 0.1


def test_wall_measure_finds_a_web_between_thick_blocks():
    solid = _box([3, 3, 3], [0, 0, 0]) + _box([3, 3, 3], [5, 0, 0]) + _box([2.2, 3, 0.3], [2.5, 0, 0])
    (w,) = thin_walls("web", solid, 0.6)
    assert 0.15 < w.thickness_mm < 0.4 and 1.5 < w.where_mm[0] < 3.5
    assert thin_walls("blocks", _box([3, 3, 3], [0, 0, 0]) + _box([3, 3, 3], [5, 0, 0]), 0.6) == []


def test_bounded_distance_transform_is_scipys_up_to_its_bound():
    """The wall measure's distance transform (exact up to R cells, more than R beyond) gives
    scipy's full Euclidean transform wherever that is at most R, on random masks (seeded)."""
    from scipy import ndimage

    from mlc.mesh.walls import _edt_upto
    rng = np.random.default_rng(3)
    for k in range(6):
        shape = tuple(rng.integers(3, 30, 3))
        mask = ndimage.binary_dilation(rng.random(shape) < 0.02 * (k + 1), iterations=2)
        mask[0, 0, 0] = False           # scipy measures to a zero of the array: give it one
        R = int(rng.integers(1, 7))
        ref = ndimage.distance_transform_edt(mask)
        got = _edt_upto(mask, R)
        near = ref <= R
        assert np.array_equal(got[near], ref[near]), k
        assert np.all(got[~near] > R), k


def test_wall_check_on_an_assembly():
    sc = ex.hinge_pair()
    good = build_assembly(sc, load_profile("mjp"), None, resolve=False)
    assert wall_check(good).ok
    # slabs printed at 0.6 mm against a 0.9 mm minimum wall: the measured walls fail
    thin = build_assembly(sc, load_profile("mjp", {"min_wall": 0.9}), None, resolve=False)
    ch = wall_check(thin)
    assert not ch.ok and ch.value < 0.9 and {"A", "B"} <= {f.split(":")[0] for f in ch.failures}


def test_report_has_the_new_checks():
    sc = ex.hinge_pair()
    rep = check_assembly(build_assembly(sc, load_profile("sla"), ex.hinge_poses(sc, {"0": 0.0, "1": 0.7})))
    names = [c.name for c in rep.checks]
    assert {"wall_thickness", "bed_contact", "supports"} <= set(names)
    assert rep.check("wall_thickness").ok
    assert rep.check("bed_contact").ok, rep.text()     # two slabs standing on the bed


def test_3mf_is_one_object_with_named_volumes(tmp_path):
    asm = build_assembly(ex.ujoint_pair(), load_profile("mjp"), None, resolve=False)
    f = tmp_path / "u.3mf"
    f.write_bytes(threemf_bytes(part_meshes(asm), "u"))
    with zipfile.ZipFile(f) as z:
        model = z.read("3D/3dmodel.model").decode()
        cfg = z.read(SLIC3R_CONFIG).decode()
    assert model.count("<object ") == 1 and model.count("<item ") == 1
    assert cfg.count("<volume ") == 3
    back = read_3mf(f)
    assert [n for n, _ in back] == [p.name for p in asm.parts]
    for (_, m), p in zip(back, asm.parts):
        assert m.is_watertight and abs(m.volume - float(p.solid.volume())) < 1e-3


def test_stacked_hinges_on_one_line_stay_two_hinges():
    """Connector half units stack their layers along the hinge axes: two hinges on one line at
    different heights are two hinges, not one hinge of four bodies."""
    sc = ex.hinge_pair()
    up = np.array([0, 0, 1.0])
    bodies = list(sc.bodies) + [Body(b.name + "2", b.position + up, b.orientation.copy(), b.boxes, dict(b.sites))
                                for b in sc.bodies]
    bonds = list(sc.bonds) + [Bond(x.name + "2", x.a.replace(".", "2.", 1), x.b.replace(".", "2.", 1),
                                   kind="hinge", joint="h2") for x in sc.bonds]
    two = Scene("stacked", bodies, bonds).check()
    asm = build_assembly(two, load_profile("mjp"), None, resolve=False)
    assert sorted(len(ax.bodies) for ax in asm.axes) == [2, 2]
    assert len(asm.parts) == 4 and all(len(p.solid.decompose()) == 1 for p in asm.parts)


def test_goal_checks_are_reported_but_do_not_block():
    from mlc.mesh.checks import NON_BLOCKING, Check, Report
    rep = Report("x", load_profile("mjp").to_dict(), [], [Check("watertight", True),
                                                        Check("supports", False, blocking=False)], [])
    assert rep.ok and "GOAL NOT MET" in rep.text() and "supports" in NON_BLOCKING
    rep.checks.append(Check("min_gap", False))
    assert not rep.ok
