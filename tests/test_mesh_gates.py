"""The library gates as printable meshes: golden part counts, and the paper's NAND passes
the printability report for every printer profile."""
import manifold3d as mf
import numpy as np
import pytest

from mlc.gates.library import GATE_NAMES, gate_scene
from mlc.mesh.build import build_assembly
from mlc.mesh.checks import check_assembly
from mlc.mesh.examples import gate_poses
from mlc.mesh.export import part_meshes, read_3mf, read_parts, stl_bytes, threemf_bytes
from mlc.mesh.profiles import load_profile

from helpers import web_sections

# 8 slabs + the universal joint at d; 7 hinge axes (the one at c joins three slabs)
GOLDEN = {"parts": 9, "bodies": 8, "joint_parts": 1, "hinge_axes": 7, "three_body_axes": 1}


@pytest.mark.parametrize("name", GATE_NAMES)
def test_golden_part_counts(name):
    asm = build_assembly(gate_scene(name, "expand"), load_profile("mjp"), None, resolve=False)
    assert len(asm.parts) == GOLDEN["parts"]
    assert sum(p.kind == "body" for p in asm.parts) == GOLDEN["bodies"]
    assert sum(p.kind == "joint" for p in asm.parts) == GOLDEN["joint_parts"]
    assert len(asm.axes) == GOLDEN["hinge_axes"]
    assert sum(len(ax.bodies) == 3 for ax in asm.axes) == GOLDEN["three_body_axes"]
    assert all(len(p.solid.decompose()) == 1 for p in asm.parts)


@pytest.mark.parametrize("profile", ["mjp", "sla", "fdm"])
def test_nand_passes_for_every_profile(profile, tmp_path):
    scene = gate_scene("NAND", "expand")
    asm = build_assembly(scene, load_profile(profile), gate_poses("NAND", "expand"))
    rep = check_assembly(asm, walls=False)     # the measured walls: tests/test_mesh_print.py
    # the mechanism checks pass; how it sits on the bed is reported (issue 13: the gates do not
    # meet the bed-contact and support goals yet, see docs/printing.md)
    for name in ("watertight", "part_count", "min_gap", "states", "retention", "features"):
        assert rep.check(name).ok, rep.text()
    assert not rep.check("bed_contact").ok and rep.check("bed_contact").value < 0.2
    assert rep.check("supports").value > 0
    assert rep.check("states").detail.startswith("4 logic states")
    assert rep.check("part_count").value == 9
    # the round trip through STL and 3MF keeps every part
    meshes = part_meshes(asm)
    (tmp_path / "n.stl").write_bytes(stl_bytes(meshes))
    (tmp_path / "n.3mf").write_bytes(threemf_bytes(meshes))
    pieces = read_parts(tmp_path / "n.stl")
    # with the dense path poses (issue 13) a trim can leave a zero-area two-triangle sliver that the
    # STL's welded vertices split off; known, reported; the 9 solid parts must all be there
    assert sum(len(m.faces) >= 4 for _, m in pieces) == 9
    assert all(len(m.faces) >= 4 or m.area < 1e-9 for _, m in pieces)
    back = read_3mf(tmp_path / "n.3mf")
    assert [n for n, _ in back] == [p.name for p in asm.parts]
    assert all(m.is_watertight and m.volume > 0 for _, m in back)


def test_axes_flat_lays_hinge_axes_flat():
    asm = build_assembly(gate_scene("NAND"), load_profile("fdm", {"orient": "axes_flat"}), None, resolve=False)
    R = asm.orient[:3, :3]
    dirs = [ax.direction for ax in asm.axes] + [a for uj in asm.ujoints for a in uj.axes]
    assert max(abs((R @ d)[2]) for d in dirs) < 1e-6      # every hinge axis parallel to the bed


def test_nand_keeps_the_clearance_in_motion_on_every_switch():
    """What ``mlc stl NAND`` runs (export_assembly, mjp): every path from rest and every switch from
    one state to another is posed densely -- no joint site of any body moves more than the
    clearance (in sigma) from one pose to the next on any path.  The expanding NAND's lower input
    levers come within the clearance of out_hi and of the universal joint on the way (without the
    motion trims: measured here); the motion trims clear them, and in every pose where a trim was
    made the two parts, measured directly (manifold3d, that pair in that pose, no bound), keep the
    clearance.  The goal is met and reports the gap measured directly."""
    from mlc.geometry.rotation import quat_to_matrix
    from mlc.mesh.pipeline import export_assembly, state_poses
    scene = gate_scene("NAND", "expand")
    prof = load_profile("mjp")
    c = prof.clearance
    asm, rep = export_assembly(scene, prof)
    assert rep.ok                                          # the blocking checks
    poses, _ = state_poses(scene, max_move=c / prof.sigma_mm)     # as export_assembly poses them
    states, rest = scene.states(), "00"
    assert all(f"{a}>{b}" in poses for a in states for b in states if a not in (b, rest))
    A = scene.arrays()

    def sites(pq):
        R = np.array([quat_to_matrix(q) for q in pq[1]])
        return pq[0][A.site_body] + np.einsum("nij,nj->ni", R[A.site_body], A.site_local)

    paths: dict = {}
    for key in poses:
        if "@" in key or ">" in key:
            name = key.split("@")[0]
            paths.setdefault(name, []).append((float(key.split("@")[1]) if "@" in key else 1.0, key))
    assert len(paths) == 3 + 9
    largest = 0.0
    for name, fk in paths.items():
        seq = [poses[name.split(">")[0] if ">" in name else rest]] + [poses[k] for _, k in sorted(fk)]
        for p, q in zip(seq, seq[1:]):
            largest = max(largest, float(np.linalg.norm(sites(q) - sites(p), axis=1).max()))
    assert 0.2 * c / prof.sigma_mm < largest <= c / prof.sigma_mm

    def gap(a, x, y, pose):             # parts x and y of assembly a in a dense pose, directly
        T = a.part_transforms(*poses[pose])
        return a.part(x).solid.transform(T[x][:3, :4]).min_gap(a.part(y).solid.transform(T[y][:3, :4]), 2 * c)

    plain = build_assembly(scene, prof, asm.poses)          # the same build without the motion trims
    assert {t["part"] for t in asm.motion_trims} >= {"a_lo", "b_lo"}
    assert {t["clear_of"] for t in asm.motion_trims} >= {"out_hi"}
    for t in asm.motion_trims:
        x_name, y_name = t["part"], t["clear_of"]
        assert t["settled"] and t["removed_mm3"] > 0
        before = min(gap(plain, x_name, y_name, k) for k in t["poses"])
        after = min(gap(asm, x_name, y_name, k) for k in t["poses"])
        assert before < c - 1e-6 <= after, (t, before, after)
    mc = rep.check("motion_clearance")
    assert mc.ok and "on the switches between them" in mc.detail and not mc.failures
    pose = mc.detail.split(", ")[1].split(")")[0]
    x_name, y_name = mc.detail.split("(")[1].split(",")[0].split(" - ")
    direct = gap(asm, x_name, y_name, pose)
    assert abs(direct - mc.value) < 1e-5 and c - 1e-5 <= mc.value


def test_knuckles_are_at_least_a_wall_long():
    """A knuckle is a ring: its length is a wall.  At mjp (minimum feature 0.5 mm, minimum wall
    0.6 mm) the NAND's knuckles were 0.5 mm long and the measured walls of core_cd and a_hi at
    hinge c were 0.37 mm (issue 13); they are now at least the minimum wall long, and the walls
    measured on the solids (a voxel grid, independent of the nominal sizes) pass."""
    from mlc.mesh.walls import thin_walls
    prof = load_profile("mjp")
    assert prof.min_feature < prof.min_wall             # the case where the rule matters
    asm = build_assembly(gate_scene("NAND", "expand"), prof, None, resolve=False)
    assert min(ax.knuckle for ax in asm.axes) >= prof.min_wall - 1e-9
    (c,) = [ax for ax in asm.axes if len(ax.bodies) == 3]
    for name in c.bodies:
        assert thin_walls(name, asm.part(name).solid, prof.min_wall) == [], name


def test_a_web_thinner_than_the_wall_is_carried_and_bridged():
    """core_cd of the contracting OR at mjp, between hinge c and its universal joint: the trim
    around a_hi's and b_hi's knuckles (1.36 mm) and the joint's (4.19 mm) left a 0.22 mm web
    (issue 13).  Built at rest (no poses: a bridge must keep clear of the other bodies in every
    pose given, and in the logic states and dense paths of this gate no direction does), the plate
    at the axis is carried along it beside the knuckle stack, the body bridges around the other
    knuckles and the thin web goes: core_cd stays one piece and its measured walls pass."""
    from mlc.mesh.walls import thin_walls
    prof = load_profile("mjp")
    asm = build_assembly(gate_scene("OR", "contract"), prof, None, resolve=False)
    notes = [n for n in asm.notes if "core_cd" in n and "thinner than the minimum wall" in n]
    assert any("carried along" in n for n in notes) and any("bridges" in n for n in notes), asm.notes
    (c,) = [ax for ax in asm.axes if len(ax.bodies) == 3]
    (uj,) = asm.ujoints
    u = uj.center - c.origin
    u -= np.dot(u, c.direction) * c.direction
    u /= np.linalg.norm(u)
    core = asm.part("core_cd").solid
    assert len(core.decompose()) == 1
    # the carried plate: material beside the stack, just outside the knuckles, towards the joint
    p = c.origin - c.direction * (c.span / 2 + 0.5) + u * (c.R + 0.3)
    probe = mf.Manifold.cube([0.1, 0.1, 0.1], True).translate(p.tolist())
    assert (core ^ probe).volume() > 0.9e-3
    assert thin_walls("core_cd", core, prof.min_wall) == []
    # with the logic states given, a_hi and b_hi swing through every direction about the axis but
    # the joint's: the bridge runs towards the joint, through the joint's trim of core_cd (set by
    # out_hi's slab in the logic states, not by the hub: test_the_web_at_hinge_c_is_bridged_towards_the_joint)
    posed = build_assembly(gate_scene("OR", "contract"), prof, gate_poses("OR", "contract"), resolve=False)
    notes = [n for n in posed.notes if "core_cd" in n and "thinner than the minimum wall" in n]
    assert any("carried along" in n for n in notes) and any("bridges" in n for n in notes), notes


@pytest.mark.parametrize("name,signal", [("AND", "expand"), ("NAND", "contract")])
def test_the_web_at_hinge_c_is_bridged_towards_the_joint(name, signal):
    """core_cd at mjp (issue 13, session 36): hinge c is 5.79 mm from the universal joint at d; the
    trim around a_hi's and b_hi's knuckles (1.3 mm) and the joint's trim of core_cd (4.26 mm: out_hi's
    lower arm crosses core_cd near d in the logic states) left a web of 0.22 mm (0.14 mm in some
    gates) against the 0.6 mm minimum.  a_hi and b_hi swing through every other direction about
    the axis, so the bridge goes towards d, through the joint's trim, which spares it: 0.6 mm of
    slab, kept clear of every other slab in every logic state (the dense paths: the benchmark,
    benchmarks/results/mesh_gates_walls_s36.json), and outside what the hub and the yoke knuckles
    sweep.  The web's walls measure at least the minimum; before, 0.22 mm."""
    from mlc.mesh.walls import thin_walls
    prof = load_profile("mjp")
    asm = build_assembly(gate_scene(name, signal), prof, gate_poses(name, signal), resolve=False)
    assert any("core_cd bridges" in n and "thinner than the minimum wall" in n for n in asm.notes), asm.notes
    (c,) = [ax for ax in asm.axes if len(ax.bodies) == 3]
    (uj,) = asm.ujoints
    u = uj.center - c.origin
    u -= np.dot(u, c.direction) * c.direction
    dist = float(np.linalg.norm(u))
    u /= dist
    core = asm.part("core_cd").solid
    assert len(core.decompose()) == 1
    # material of the bridge inside the joint's trim radius, at mid-stack, towards the joint
    r_in = dist - uj.rho[0]
    assert r_in < c.rho + prof.min_wall           # the joint's trim would have cut the bridge
    p = c.origin + u * (c.rho + prof.min_wall - 0.1)
    probe = mf.Manifold.cube([0.1, 0.1, 0.1], True).translate(p.tolist())
    assert (core ^ probe).volume() > 0.9e-3
    # and nothing of the hub's or the yoke knuckles' sweep
    sweep = float(np.hypot(uj.layouts[1].extent, uj.R)) + prof.clearance
    assert dist - sweep > c.rho + prof.min_wall
    assert thin_walls("core_cd", core, prof.min_wall) == []


def test_no_sheet_past_the_pivot_cut():
    """out_hi at sla (issue 13, session 36): the yoke plate at d widens out_hi's lower arm to the
    yoke's knuckles (6 mm across) up to the pivot, whose knuckle span is the slab's 4 mm; the cut
    around out_lo's knuckles ran 0.8 mm (one slab thickness) past the span's ends and left a sheet
    0.2 mm thick at each end, measured 0.19 mm against the 0.5 mm minimum in every contracting gate.
    The cut now runs past the plate where what it would leave is thinner than the minimum wall."""
    from mlc.mesh.walls import thin_walls
    prof = load_profile("sla")
    asm = build_assembly(gate_scene("NAND", "contract"), prof, gate_poses("NAND", "contract"), resolve=False)
    out_hi = asm.part("out_hi").solid
    (piv,) = [ax for ax in asm.axes if "out_hi" in ax.bodies]
    lo, hi = np.asarray(out_hi.bounding_box()[:3]), np.asarray(out_hi.bounding_box()[3:])
    ends = (lo @ piv.direction, hi @ piv.direction)
    assert max(abs(e - piv.origin @ piv.direction) for e in ends) > piv.span / 2 + prof.slab_thickness
    # nothing of out_hi within the trim radius of the pivot beyond out_hi's own knuckle
    own = piv.intervals["out_hi"]
    a1 = max(x for iv in own for x in iv) + prof.knuckle_gap
    from mlc.mesh.build import cylinder
    zone = cylinder(piv.origin, piv.direction, a1 + 0.05, max(ends) - piv.origin @ piv.direction + 1.0,
                    piv.rho - 0.05, 64)
    assert (out_hi ^ zone).volume() < 1e-6
    assert thin_walls("out_hi", out_hi, prof.min_wall) == []


def test_a_web_that_is_not_the_only_link_is_measured_and_bridged():
    """core_cd of the contracting AND at mjp (issue 13, session 37): between hinge c's trim (1.3 mm)
    and the universal joint's (3.87 mm, 5.79 mm away) a web 0.593 mm across was left, against the
    0.6 mm minimum.  It is not core_cd's only link (the cut grown by the minimum wall does not split
    the body), so the split test missed it; the web is now measured on sections across the other
    knuckles (mlc.mesh.build._web_thinner) and bridged like a severed one: every web at hinge c
    measures the minimum wall.  Without the measured test the web stays 0.593 mm."""
    import mlc.mesh.build as B
    prof = load_profile("mjp")
    scene, poses = gate_scene("AND", "contract"), gate_poses("AND", "contract")
    asm = build_assembly(scene, prof, poses, resolve=False)
    assert any("core_cd bridges" in n and "thinner than the minimum wall" in n for n in asm.notes), asm.notes
    webs = web_sections(asm, prof.min_wall)
    assert webs and min(webs) >= prof.min_wall - 1e-3, webs
    assert len(asm.part("core_cd").solid.decompose()) == 1
    # the same build with the split test alone: the web is left, thinner than the wall
    orig = B._web_thinner
    B._web_thinner = lambda *a: False
    try:
        old = build_assembly(scene, prof, poses, resolve=False)
    finally:
        B._web_thinner = orig
    assert not any("core_cd bridges" in n for n in old.notes)
    assert min(web_sections(old, prof.min_wall)) < prof.min_wall - 1e-3


def test_web_thinner_measures_a_web_beside_another_link():
    """The measured web test on a body built for it: a plate through an axis, cut around another
    body's knuckle (radius 1 mm, over the middle of the stack) and by a second cylinder beside it,
    which leaves a web 0.55 mm across; the plate above and below the cuts still joins the web to the
    rest (one piece: the split test sees nothing), yet the web is under 0.6 mm.  0.65 mm passes."""
    from types import SimpleNamespace
    from mlc.mesh.build import _web_thinner, cylinder
    d = np.array([0.0, 0.0, 1.0])
    ax = SimpleNamespace(origin=np.zeros(3), direction=d, rho=1.0, span=3.0,
                         intervals={"A": [(-1.5, -0.9), (0.9, 1.5)], "B": [(-0.7, 0.7)]})
    for web, thin in ((0.55, True), (0.65, False)):
        plate = mf.Manifold.cube([8.0, 0.6, 3.0], True).translate([4.0, 0.0, 0.0])
        body = plate + mf.Manifold.cube([0.6, 4.0, 3.0], True).translate([7.7, 2.0, 0.0]) \
            + mf.Manifold.cube([8.0, 0.6, 3.0], True).translate([4.0, 4.0, 0.0])
        # the knuckle trim, and a second cylinder parallel to it whose near side is `web` further out
        cut = body - cylinder(ax.origin, d, -0.9, 0.9, 1.0, 64, cutter=True) \
            - cylinder([1.0 + web + 2.0, 0, 0], d, -0.9, 0.9, 2.0, 64, cutter=True)
        assert len(cut.decompose()) == 1          # one piece: the web is not the only link
        assert _web_thinner(cut, ax, "A", 0.6) == thin, web
