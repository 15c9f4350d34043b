"""Issue 13, item 1: the configurations a printed mechanism reaches (mlc.mesh.configs).
Lengths in mm, angles in degrees."""
import types

import numpy as np
import pytest

from mlc.mesh.configs import Clearance, Evaluator, Kinematics, angle_targets, input_axes, scan


def _linkage(points, closed: bool):
    """A planar chain of rigid links joined by hinges along z at ``points`` (mm), the last link
    hinged back to the first when ``closed``: an assembly with only what Kinematics reads."""
    n = len(points) - (0 if closed else 1)
    names = [f"l{i}" for i in range(n if closed else n + 1)]
    axes = []
    for k, p in enumerate(points):
        if closed:
            pair = [names[k - 1], names[k]]
        elif k == 0:
            continue
        else:
            pair = [names[k - 1], names[k]]
        axes.append(types.SimpleNamespace(name=f"h{k}", bodies=pair, origin=np.array(p, float),
                                          direction=np.array([0, 0, 1.0]), span=10.0))
    scene = types.SimpleNamespace(bodies=[types.SimpleNamespace(name=x) for x in names], muscles=[])
    return types.SimpleNamespace(scene=scene, axes=axes, ujoints=[])


def test_freedoms_of_known_linkages():
    # an open chain of 3 links on 2 hinges: 2 freedoms; a planar four-bar: 1; a triangle: rigid
    assert Kinematics(_linkage([[0, 0, 0], [10, 0, 0], [20, 0, 0]], closed=False)).freedoms() == 2
    four = _linkage([[0, 0, 0], [0, 10, 0], [30, 10, 0], [30, 0, 0]], closed=True)
    assert Kinematics(four).freedoms() == 1
    assert Kinematics(_linkage([[0, 0, 0], [10, 0, 0], [0, 10, 0]], closed=True)).freedoms() == 0


def test_a_parallelogram_turns_both_cranks_alike():
    """Crank the parallelogram four-bar by 25 degrees: the joints close, and the other crank
    turns by the same angle (the coupler translates)."""
    four = _linkage([[0, 0, 0], [0, 10, 0], [30, 10, 0], [30, 0, 0]], closed=True)
    kin = Kinematics(four)
    # links: l0 the crank (h0 -> h1), l1 the coupler, l2 the rocker, l3 the ground (h3 -> h0)
    T, e = angle_targets(kin, kin.rest(), {"h0:l0": 25.0})
    assert e < 1e-7
    ang = kin.hinge_angles(T)
    assert abs(ang["h0:l0"] - 25.0) < 1e-6
    assert abs(ang["h3:l3"] + 25.0) < 1e-5          # the ground seen from the rocker: -25
    R_coupler = T[kin.index["l1"]][:3, :3] @ T[kin.index["l3"]][:3, :3].T
    assert np.allclose(R_coupler, np.eye(3), atol=1e-7)


def _fdm_gate(name: str):
    """(assembly, kinematics, clearance) of library gate ``name`` (expanding) in the fdm
    profile, at rest and unrotated."""
    from mlc.gates.library import gate_scene
    from mlc.mesh.build import build_assembly
    from mlc.mesh.profiles import load_profile
    asm = build_assembly(gate_scene(name, "expand"), load_profile("fdm", {"orient": "as_is"}))
    kin = Kinematics(asm)
    return asm, kin, Clearance(asm, kin)


@pytest.fixture(scope="module")
def nand_fdm():
    return _fdm_gate("NAND")


def test_a_gate_has_its_two_input_levers_as_freedoms(nand_fdm):
    asm, kin, _ = nand_fdm
    assert np.max(np.abs(kin.residual(kin.rest()))) == 0
    assert kin.freedoms() == 2
    assert input_axes(kin) == ["pivot_a:a_hi", "pivot_b:b_hi"]
    T, e = angle_targets(kin, kin.rest(), {"pivot_a:a_hi": 20.0, "pivot_b:b_hi": -10.0})
    assert e < 1e-7
    ang = kin.hinge_angles(T)
    assert abs(ang["pivot_a:a_hi"] - 20) < 1e-5 and abs(ang["pivot_b:b_hi"] + 10) < 1e-5
    assert kin.freedoms(T) == 2
    # the lever loop's hinges all stay along z (the loop is planar) and the output lever's along x:
    # no configuration turns a slab of the loop out of the vertical planes
    zs = [ax for ax in asm.axes if abs(ax.direction[2]) > 0.99]
    assert len(zs) == 5
    for ax in asm.axes:
        i = kin.index[ax.bodies[0]]
        assert abs(abs((T[i][:3, :3] @ ax.direction) @ ax.direction) - 1) < 1e-9


def test_the_clearance_refuses_parts_that_meet(nand_fdm):
    asm, kin, clear = nand_fdm
    assert clear.ok(kin.rest())[0]
    T, e = angle_targets(kin, kin.rest(), {"pivot_a:a_hi": 10.0, "pivot_b:b_hi": 0.0})
    assert e < 1e-7 and clear.ok(T)[0]
    # pivot b closed by 60 degrees (in steps, the joints followed): lever b_lo runs into core_cd
    T = kin.rest()
    for a in range(-10, -61, -10):
        T, e = angle_targets(kin, T, {"pivot_a:a_hi": 0.0, "pivot_b:b_hi": float(a)})
    ok, bad = clear.ok(T)
    assert not ok
    names = {asm.parts[i].name + "/" + asm.parts[j].name for i, j in bad}
    assert "core_cd/b_lo" in names


def test_scan_floods_from_rest_and_stops_at_collisions(nand_fdm):
    asm, kin, clear = nand_fdm
    sc = scan(kin, clear, step_deg=15.0, limit_deg=45.0)
    assert (0, 0) in sc["reached"] and sc["refused"]
    assert all(abs(x) <= 3 for n in sc["reached"] for x in n)
    for n, T in sc["reached"].items():
        ang = kin.hinge_angles(T)
        assert abs(ang["pivot_a:a_hi"] - 15 * n[0]) < 1e-4 and abs(ang["pivot_b:b_hi"] - 15 * n[1]) < 1e-4
        assert clear.ok(T)[0]
    # every reached node has a reached neighbour nearer rest (connected to rest)
    for n in sc["reached"]:
        if n != (0, 0):
            assert any(tuple(x - (np.sign(x) if q == d else 0) for q, x in enumerate(n)) in sc["reached"]
                       for d in range(2) if n[d] != 0)


def test_the_evaluator_measures_what_the_report_measures(nand_fdm):
    """At rest with up = z, the evaluator's exact figures are bed_stats of the parts as the
    report poses them (the same transform, the same grid)."""
    from mlc.mesh.checks import bed_checks
    from mlc.mesh.build import _orientation
    asm, kin, clear = nand_fdm
    r = Evaluator(asm, clear)(kin.rest(), ups=[np.array([0, 0, 1.0])])
    asm.orient = _orientation(asm)                    # as_is: the model's z, centred, on the bed
    bed_checks(asm)
    assert abs(r["stats"].contact_fraction - asm.bed.contact_fraction) < 1e-9
    # (the same grid; the vertices moved by other floating-point steps: 0.4 of 5300 mm^3)
    assert abs(r["stats"].support_mm3 - asm.bed.support_mm3) < 1e-3 * asm.bed.support_mm3


def _nor_at(asm, kin, a, b, step=10.0):
    """NOR's configuration with the input levers' hinges at ``a`` and ``b`` degrees, reached from
    rest in steps (the joints followed)."""
    T = kin.rest()
    n = int(max(abs(a), abs(b)) / step)
    for k in range(1, n + 1):
        T, e = angle_targets(kin, T, {"pivot_a:a_hi": a * k / n, "pivot_b:b_hi": b * k / n})
        assert e < 1e-7
    return T


@pytest.fixture(scope="module")
def nor_fdm():
    return _fdm_gate("NOR")


def test_the_writers_and_the_bed_check_print_the_configuration(nor_fdm):
    """With a print pose set, the STL/3MF meshes, the print size and the bed checks are the
    parts moved into that configuration, then oriented; without one, the rest configuration."""
    from mlc.mesh.build import _orientation, transform_solid
    from mlc.mesh.checks import bed_checks, print_size
    from mlc.mesh.export import part_meshes
    from mlc.mesh.printability import bed_stats
    asm, kin, clear = nor_fdm
    T = _nor_at(asm, kin, -60.0, 60.0)
    assert clear.ok(T)[0]
    rest_size = print_size(asm)
    asm.print_pose = {p.name: P for p, P in zip(asm.parts, clear.part_T(T))}
    try:
        asm.orient = _orientation(asm)               # as_is: z up, centred, on the bed
        meshes = dict(part_meshes(asm))
        for p in asm.parts:
            posed = transform_solid(p.solid, asm.orient @ asm.print_pose[p.name])
            lo = np.asarray(posed.bounding_box())[:3]
            assert np.allclose(meshes[p.name].bounds[0], lo, atol=1e-6)
        assert min(float(m.bounds[0][2]) for m in meshes.values()) == pytest.approx(0.0, abs=1e-6)
        assert print_size(asm) != rest_size
        bed_checks(asm)
        st = bed_stats([(p.name, transform_solid(p.solid, asm.orient @ asm.print_pose[p.name])) for p in asm.parts],
                       h=asm.bed.grid_mm, first_layer=0.2, island_mm=6.0)
        assert st.support_mm3 == pytest.approx(asm.bed.support_mm3, rel=1e-9)
        # the parts as printed keep the clearance (min_gap of every pair of distinct parts)
        solids = [transform_solid(p.solid, asm.orient @ asm.print_pose[p.name]) for p in asm.parts]
        gaps = [solids[i].min_gap(solids[j], 1.0) for i in range(len(solids)) for j in range(i + 1, len(solids))]
        assert min(gaps) >= asm.profile.clearance - 1e-4
    finally:
        asm.print_pose = {}
        asm.orient = _orientation(asm)


def test_best_configuration_beats_rest_by_its_own_measure(nor_fdm, monkeypatch):
    """NOR fdm on a 30-degree grid: a configuration other than rest, reached with the
    clearance kept, whose bed the evaluator scores better than rest's."""
    from mlc.mesh import configs
    asm, kin, clear = nor_fdm
    monkeypatch.setattr(configs, "SCAN_STEP_DEG", 30.0)
    monkeypatch.setattr(configs, "SCAN_LIMIT_DEG", 60.0)
    monkeypatch.setattr(configs, "EVAL_EVERY", 1)
    monkeypatch.setattr(configs, "REFINE", 0)
    assert configs.applicable(asm) is None
    cfg = configs.best_configuration(asm)
    assert cfg is not None and any(v != 0 for v in cfg["angles_deg"].values())
    assert clear.ok(cfg["T"])[0] and np.max(np.abs(kin.residual(cfg["T"]))) < 1e-6
    ang = kin.hinge_angles(cfg["T"])
    assert all(abs(ang[k] - v) < 1e-4 for k, v in cfg["angles_deg"].items())
    rest = Evaluator(asm, clear)(kin.rest())
    assert cfg["key"] < rest["key"]


def test_auto_config_prints_another_configuration_only_when_it_is_better(nor_fdm, monkeypatch):
    from dataclasses import replace

    from mlc.mesh import configs, pose
    from mlc.mesh.build import _orientation
    asm, kin, clear = nor_fdm
    for k, v in (("SCAN_STEP_DEG", 30.0), ("SCAN_LIMIT_DEG", 60.0), ("EVAL_EVERY", 1), ("REFINE", 0)):
        monkeypatch.setattr(configs, k, v)
    prof0 = asm.profile
    try:
        asm.profile = replace(prof0, orient="auto_config")
        n0 = len(asm.notes)
        asm.orient = _orientation(asm)
        assert asm.print_pose and set(asm.print_pose) == {p.name for p in asm.parts}
        assert any(v != 0 for v in asm.print_config.values())
        assert any(x.startswith("configuration: printed with") for x in asm.notes[n0:])
        # the same search when nothing may beat rest: rest is printed, and the note says why
        monkeypatch.setattr(pose, "MIN_GAIN", 100.0)
        monkeypatch.setattr(pose, "GOALS_TO_LEAVE", True)
        n0 = len(asm.notes)
        asm.orient = _orientation(asm)
        assert asm.print_pose == {} and any("is not 100 of the part volume better" in x for x in asm.notes[n0:])
    finally:
        asm.profile = prof0
        asm.print_pose = {}
        asm.orient = _orientation(asm)


def test_auto_config_searches_only_a_small_mechanism_driven_by_its_levers(nand_fdm):
    """The configuration search is refused (rest printed) for an assembly of 64 parts or more
    (a compiled circuit) and for a mechanism no muscle drives; a gate is searched."""
    import copy
    from mlc.mesh import configs
    asm, _, _ = nand_fdm
    assert configs.applicable(asm) is None
    big = copy.copy(asm)
    big.parts = asm.parts * 8
    assert "parts" in configs.applicable(big)
    loose = copy.copy(asm)
    loose.scene = copy.copy(asm.scene)
    loose.scene.muscles = []
    assert configs.applicable(loose) == "no muscle drives a hinge"
