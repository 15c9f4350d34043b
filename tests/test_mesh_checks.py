"""Every printability check passes on a good mechanism and can fail."""
import manifold3d as mf
import numpy as np
import pytest

from mlc.mesh import examples as ex
from mlc.mesh.build import build_assembly
from mlc.mesh.checks import check_assembly
from mlc.mesh.profiles import load_profile

POSES = {"0": 0.0, "1": -0.7, "2": 0.8}


def _hinge(profile="mjp", overrides=None, poses=POSES):
    sc = ex.hinge_pair()
    return build_assembly(sc, load_profile(profile, overrides), ex.hinge_poses(sc, poses))


def _failed(rep):
    return {c.name for c in rep.checks if not c.ok and c.blocking}      # the goal checks: test_mesh_print.py


@pytest.mark.parametrize("profile", ["mjp", "sla", "fdm"])
def test_hinge_pair_passes(profile):
    rep = check_assembly(_hinge(profile))
    assert rep.ok, rep.text()
    assert rep.check("min_gap").value >= load_profile(profile).clearance - 1e-6
    assert rep.check("retention").value == 12
    assert any("slab thickness" in n and "0.1 mm" in n for n in rep.notes)   # the profile decides, and says so


def test_three_bodies_on_one_axis():
    sc = ex.three_on_axis()
    asm = build_assembly(sc, load_profile("mjp"), {"": (np.array([b.position for b in sc.bodies]),
                                                        np.array([b.orientation for b in sc.bodies]))})
    (ax,) = asm.axes
    assert len(ax.bodies) == 3 and len(ax.joints) == 2
    assert sum(len(v) for v in ax.intervals.values()) == 4          # owner, body, body, owner
    rep = check_assembly(asm)
    assert rep.ok, rep.text()


def test_universal_joint_is_a_separate_part():
    sc = ex.ujoint_pair()
    asm = build_assembly(sc, load_profile("mjp"), {"": (np.array([b.position for b in sc.bodies]),
                                                        np.array([b.orientation for b in sc.bodies]))})
    assert [p.kind for p in asm.parts] == ["body", "body", "joint"]
    (uj,) = asm.ujoints
    assert abs(np.dot(*uj.axes)) < 1e-9                              # two perpendicular hinges
    rep = check_assembly(asm)
    assert rep.check("part_count").value == 3
    assert rep.ok, rep.text()


def test_zero_clearance_fails():
    rep = check_assembly(_hinge(overrides={"clearance": 0.0, "knuckle_gap": 0.0}))
    assert {"min_gap", "retention"} <= _failed(rep)


def test_small_clearance_fails_min_gap():
    asm = _hinge(overrides={"clearance": 0.1, "knuckle_gap": 0.1})
    asm.profile = load_profile("mjp")         # judge a 0.1 mm build against the 0.2 mm profile
    rep = check_assembly(asm)
    assert "min_gap" in _failed(rep)


def test_part_posed_into_another_fails():
    sc = ex.hinge_pair()
    asm = _hinge()
    rep = check_assembly(asm, ex.hinge_poses(sc, {"0": 0.0, "bad": -2.0}))   # B folded onto A
    assert _failed(rep) == {"states"}
    assert any("state bad" in f for f in rep.check("states").failures)


def test_no_poses_fails_states():
    sc = ex.hinge_pair()
    rep = check_assembly(build_assembly(sc, load_profile("mjp"), None))
    assert "states" in _failed(rep)


def test_loose_knuckles_fail_retention():
    rep = check_assembly(_hinge(overrides={"knuckle_gap": 0.5}))
    assert "retention" in _failed(rep)
    assert any("axis" in f for f in rep.check("retention").failures)


def test_thin_slab_fails_features():
    rep = check_assembly(_hinge(overrides={"slab_thickness": 0.3}))
    assert "features" in _failed(rep)


def test_broken_part_fails_watertight_and_count():
    asm = _hinge()
    asm.parts[1].solid = mf.Manifold()
    rep = check_assembly(asm)
    assert {"watertight", "part_count"} <= _failed(rep)


def test_split_part_fails_count():
    asm = _hinge()
    a = asm.parts[0].solid
    asm.parts[0].solid = a + mf.Manifold.cube([1, 1, 1]).translate([50, 50, 50])
    rep = check_assembly(asm)
    assert "part_count" in _failed(rep)
    assert rep.check("part_count").value == 3


def test_report_json_round_trip():
    import json
    rep = check_assembly(_hinge())
    d = json.loads(json.dumps(rep.to_dict()))
    assert d["ok"] is True and [c["name"] for c in d["checks"]] == [
        "watertight", "part_count", "min_gap", "states", "motion_clearance", "retention", "features",
        "wall_thickness", "bed_contact", "supports"]
    assert [c["blocking"] for c in d["checks"]][-3:] == [False, False, False]
    # motion_clearance: without dense poses measured in the states check's poses, a goal there
    assert d["checks"][4]["blocking"] is False and "states check's poses" in d["checks"][4]["detail"]


@pytest.mark.parametrize("profile", ["mjp", "fdm"])
def test_cone_pins_pass(profile):
    asm = _hinge(profile, {"pin": "cone"})
    rep = check_assembly(asm)
    assert rep.ok, rep.text()
    assert any(f[0] == "cone pin diameter" for f in asm.features)


def test_coarse_polygons_keep_the_clearance():
    # inscribed-polygon cutters are scaled by 1/cos(pi/n): even 12-gons keep the full clearance
    rep = check_assembly(_hinge(overrides={"circular_segments": 12}))
    assert rep.ok, rep.text()
    assert rep.check("min_gap").value >= 0.2 - 1e-6


def test_motion_clearance_fails_within_the_clearance_without_meeting():
    """Two parallel slabs, no joint: posed so that their faces are half a clearance apart
    (measured on the meshes' own vertices, not by the check) the motion_clearance check fails,
    naming that pose and giving that gap, and fails the report, while the states check
    (intersection) passes on the same poses; 1.5 clearances apart both pass.  Not measured (no
    dense poses: a compiled circuit) it is reported and does not block."""
    from mlc.mesh.checks import motion_check
    from mlc.mesh.export import part_meshes
    from mlc.scene.model import Scene
    prof = load_profile("mjp")
    c, s = prof.clearance, prof.sigma_mm
    sc = Scene("two_slabs", [ex._slab("A", 0.0), ex._slab("B", 0.0, origin=(0.0, 1.0, 0.0))], []).check()
    rest = (np.array([b.position for b in sc.bodies], float), np.array([b.orientation for b in sc.bodies], float))
    meshes = dict(part_meshes(build_assembly(sc, prof, {"0": rest}, resolve=False)))
    g0 = meshes["B"].vertices[:, 1].min() - meshes["A"].vertices[:, 1].max()      # mm, faces normal to y

    def moved(gap):
        p = rest[0].copy()
        p[1, 1] -= (g0 - gap) / s
        return p, rest[1]

    poses = {"0": rest, "near": moved(0.5 * c), "clear": moved(1.5 * c)}
    asm = build_assembly(sc, prof, poses, resolve=False)
    rep = check_assembly(asm, walls=False, motion_poses=poses)
    mc = rep.check("motion_clearance")
    assert not mc.ok and mc.blocking                   # measured and short: the export fails
    assert len(mc.failures) == 1 and mc.failures[0].startswith("near: A - B"), mc.failures
    assert abs(mc.value - 0.5 * c) < 1e-6
    assert rep.check("states").ok and not rep.ok       # no intersection, but short of the clearance
    del poses["near"]
    mc = motion_check(asm, poses)
    assert mc.ok and (mc.value is None or mc.value >= c - 1e-6), mc.detail
    assert not motion_check(asm, None).ok and not motion_check(asm, None).blocking   # not measured: reported


def test_coarse_motion_clearance_without_dense_poses():
    """Without dense poses (a compiled circuit's case), ``motion_clearance`` is measured in the
    states check's own poses: the two slabs of the test above half a clearance apart in one of
    them fail it (that pose named, that gap), though the states check passes, and the report says
    so as a goal not met (not blocking); 1.5 clearances apart they pass."""
    from mlc.mesh.export import part_meshes
    from mlc.scene.model import Scene
    prof = load_profile("mjp")
    c, s = prof.clearance, prof.sigma_mm
    sc = Scene("two_slabs", [ex._slab("A", 0.0), ex._slab("B", 0.0, origin=(0.0, 1.0, 0.0))], []).check()
    rest = (np.array([b.position for b in sc.bodies], float), np.array([b.orientation for b in sc.bodies], float))
    meshes = dict(part_meshes(build_assembly(sc, prof, {"0": rest}, resolve=False)))
    g0 = meshes["B"].vertices[:, 1].min() - meshes["A"].vertices[:, 1].max()      # mm, on the meshes

    def moved(gap):
        p = rest[0].copy()
        p[1, 1] -= (g0 - gap) / s
        return p, rest[1]
    rep = check_assembly(build_assembly(sc, prof, {"0": rest, "near": moved(0.5 * c), "clear": moved(1.5 * c)},
                                        resolve=False), walls=False)
    mc = rep.check("motion_clearance")
    assert not mc.ok and not mc.blocking, mc.detail
    assert mc.failures == [f"near: A - B: {0.5 * c:.4f} mm"] and abs(mc.value - 0.5 * c) < 1e-6
    assert "states check's poses" in mc.detail
    assert rep.check("states").ok and "[GOAL NOT MET] motion_clearance" in rep.text()
    mc = check_assembly(build_assembly(sc, prof, {"0": rest, "clear": moved(1.5 * c)}, resolve=False),
                        walls=False).check("motion_clearance")
    assert mc.ok, mc.detail


def test_coarse_motion_clearance_leaves_jointed_parts_to_the_states_check():
    """Two slabs on one hinge, one moved across the axis by half the clearance: the pin sits off
    the middle of its hole, closer to its wall than the clearance (the dense check, which measures
    every pair, says so: the pose is what the test claims), without meeting it.  The coarse
    check leaves such jointed pairs to the states check (a twisted joint bears on its pin) and
    passes."""
    from mlc.mesh.checks import motion_check
    prof = load_profile("mjp")
    c, s = prof.clearance, prof.sigma_mm
    sc = ex.hinge_pair()
    (p0, q0), = ex.hinge_poses(sc, {"0": 0.0}).values()
    p1 = p0.copy()
    p1[1, 0] += 0.5 * c / s                   # across the hinge's axis (z)
    poses = {"0": (p0, q0), "off": (p1, q0)}
    asm = build_assembly(sc, prof, poses)
    rep = check_assembly(asm, walls=False)
    assert rep.check("states").ok, rep.check("states").failures
    dense = motion_check(asm, poses)
    assert not dense.ok and dense.value < c - 0.25 * c, dense.detail      # the jointed pair within the clearance
    assert rep.check("motion_clearance").ok, rep.check("motion_clearance").detail


def test_coarse_motion_clearance_of_circuit_pieces():
    """A piece of the Tetris robot (gate g2 with its couplings, the robot's 22 poses) has parts that
    share no joint closer than the clearance in its poses, which the coarse check names; outside
    mlc, trimesh samples of each named pair posed in that pose and a k-d tree (an upper bound of
    the gap) find them closer than the clearance too.  The README circuit's gate g3 with its
    chains' ends keeps the clearance in all 22 of its poses."""
    import re

    from helpers import mesh_piece, part_gaps
    # (without session 67's trims of bodies that only come near, which trim g2_a_lo clear of g2_out_hi)
    asm, rep = mesh_piece("robot_g2", walls=False, CLOSE_STROKES=False)
    mc = rep.check("motion_clearance")
    c = asm.profile.clearance
    assert not mc.ok and not mc.blocking, mc.detail
    named = {}
    for f in mc.failures:
        st, a, b, g = re.match(r"(\S+): (\S+) - (\S+): ([\d.]+) mm", f).groups()
        named.setdefault((a, b), []).append((st, float(g)))
    assert ("g2_a_lo", "g2_out_hi") in named or ("g2_out_hi", "g2_a_lo") in named, sorted(named)
    partners = {p.name: set(p.partners) for p in asm.parts}
    for (a, b), hits in named.items():
        assert b not in partners[a] and a not in partners[b]
        st, g = min(hits, key=lambda h: h[1])
        outside = part_gaps(asm, a, b, {st: asm.poses[st]})[st]
        assert g - 1e-6 <= outside < c, (a, b, st, g, outside)
    asm, rep = mesh_piece("circuit_g3", walls=False)
    mc = rep.check("motion_clearance")
    assert mc.ok and "22 poses" not in mc.detail and "18 poses on the way" in mc.detail, mc.detail


def _verts(asm, name):
    """The vertices of a part's solid in the scene's frame (mm; part_meshes are in the print frame)."""
    return np.asarray(asm.part(name).solid.to_mesh().vert_properties, float)[:, :3]


def test_motion_trims_clear_a_pair_within_the_clearance():
    """The two slabs of the test above, half a clearance apart in one pose even when each is
    printed from its far face (the slab offsets), given to the build as a motion pose (what ``mlc
    stl`` does with the dense paths): one slab is trimmed where it faces the other, and in that pose
    the faces (measured on the meshes' own vertices) are at least the clearance apart; the slab
    stays in one piece and loses only a layer of its face, and the motion_clearance check passes.
    Without the motion pose nothing is trimmed."""
    from mlc.scene.model import Scene
    prof = load_profile("mjp")
    c, s = prof.clearance, prof.sigma_mm
    sc = Scene("two_slabs", [ex._slab("A", 0.0), ex._slab("B", 0.0, origin=(0.0, 1.0, 0.0))], []).check()
    rest = (np.array([b.position for b in sc.bodies], float), np.array([b.orientation for b in sc.bodies], float))
    plain = build_assembly(sc, prof, {"0": rest})
    g0 = _verts(plain, "B")[:, 1].min() - _verts(plain, "A")[:, 1].max()      # mm, faces normal to y
    d0 = 0.5 * (prof.slab_thickness - 0.01 * s)       # each slab's offset (the scene's slabs: 0.01 sigma)
    p = rest[0].copy()
    p[1, 1] -= (g0 - 0.5 * c + 2 * d0) / s
    near = {"near": (p, rest[1])}
    asm = build_assembly(sc, prof, {"0": rest}, motion_poses=near)
    assert plain.motion_trims == [] and len(asm.motion_trims) == 1, asm.motion_trims
    t = asm.motion_trims[0]
    assert t["poses"] == ["near"] and t["settled"] and {t["part"], t["clear_of"]} == {"A", "B"}
    T = asm.part_transforms(*near["near"])
    posed = {n: _verts(asm, n) @ T[n][:3, :3].T + T[n][:3, 3] for n in ("A", "B")}
    assert posed["B"][:, 1].min() - posed["A"][:, 1].max() >= c - 1e-6
    X = asm.part(t["part"]).solid
    before = plain.part(t["part"]).solid.volume()
    assert len(X.decompose()) == 1 and 0 < before - X.volume() < 0.5 * before
    assert abs(before - X.volume() - t["removed_mm3"]) < 1e-5
    mc = check_assembly(asm, walls=False, motion_poses=near).check("motion_clearance")
    assert mc.ok, mc.detail


def test_slabs_grow_away_from_a_part_passing_their_face():
    """Printed thicker than in the scene, a slab grows from the face away from a part that passes
    close to its other face (build._offset_slabs): two slabs whose centred faces would be half a
    clearance apart in a motion pose are each printed from their far face, so they keep the
    clearance in that pose with no trim and their full thickness (a trim there shaved a slab under
    the minimum wall, issue 13).  Nothing moves without the pose."""
    from mlc.scene.model import Scene
    prof = load_profile("mjp")
    c, s, t = prof.clearance, prof.sigma_mm, prof.slab_thickness
    sc = Scene("two_slabs", [ex._slab("A", 0.0), ex._slab("B", 0.0, origin=(0.0, 1.0, 0.0))], []).check()
    rest = (np.array([b.position for b in sc.bodies], float), np.array([b.orientation for b in sc.bodies], float))
    plain = build_assembly(sc, prof, {"0": rest})
    assert not any("printed from one face" in n for n in plain.notes)
    g0 = _verts(plain, "B")[:, 1].min() - _verts(plain, "A")[:, 1].max()
    p = rest[0].copy()
    p[1, 1] -= (g0 - 0.5 * c) / s
    near = {"near": (p, rest[1])}
    asm = build_assembly(sc, prof, {"0": rest}, motion_poses=near)
    assert asm.motion_trims == [], asm.motion_trims
    assert sum("printed from one face" in n for n in asm.notes) == 2, asm.notes
    T = asm.part_transforms(*near["near"])
    posed = {n: _verts(asm, n) @ T[n][:3, :3].T + T[n][:3, 3] for n in ("A", "B")}
    assert posed["B"][:, 1].min() - posed["A"][:, 1].max() >= c - 1e-6
    for n in ("A", "B"):      # full thickness, each on the side away from the other
        y = _verts(asm, n)[:, 1]
        assert y.max() - y.min() == pytest.approx(t)
    assert _verts(asm, "A")[:, 1].max() < _verts(plain, "A")[:, 1].max() - 0.1
    assert _verts(asm, "B")[:, 1].min() > _verts(plain, "B")[:, 1].min() + 0.1
    assert check_assembly(asm, walls=False, motion_poses=near).check("motion_clearance").ok


def test_ring_lug_placement_keeps_the_clearance_in_motion():
    """An attachment ring lug placed after the motion trims (build._drill) must keep the clearance
    in the dense poses too: a ring on slab A's face is refused when slab B comes half a clearance
    from that face in a dense pose, and accepted when that pose is only a logic state (meeting
    nothing) or absent."""
    from mlc.mesh.build import _ring_clear, box
    from mlc.scene.model import Scene
    prof = load_profile("mjp")
    c, s = prof.clearance, prof.sigma_mm
    sc = Scene("two_slabs", [ex._slab("A", 0.0), ex._slab("B", 0.0, origin=(0.0, 1.0, 0.0))], []).check()
    rest = (np.array([b.position for b in sc.bodies], float), np.array([b.orientation for b in sc.bodies], float))
    asm = build_assembly(sc, prof, {"0": rest}, resolve=False)
    A = _verts(asm, "A")
    top = A[:, 1].max()
    g0 = _verts(asm, "B")[:, 1].min() - top
    p = rest[0].copy()
    p[1, 1] -= (g0 - 0.5 * c) / s
    T = asm.part_transforms(p, rest[1])
    ring = box(np.r_[A[:, 0].mean(), top - 0.1, A[:, 2].mean()], np.eye(3), [1.0, 0.2, 1.0])
    assert _ring_clear(asm, asm.part("A"), ring)                  # as printed and at rest: clear
    assert not _ring_clear(asm, asm.part("A"), ring, [T])         # within the clearance in motion
    asm.poses = {"0": rest, "near": (p, rest[1])}
    assert _ring_clear(asm, asm.part("A"), ring)                  # a logic state: only meeting counts
