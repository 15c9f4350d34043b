"""Scenes other than the library gates: odd joints are reported, not silently printed."""
import numpy as np
import pytest

from mlc.errors import MlcError
from mlc.mesh import examples as ex
from mlc.mesh.build import build_assembly
from mlc.mesh.profiles import load_profile
from mlc.scene.model import Bond


def test_plain_bond_is_noted_not_printed():
    sc = ex.hinge_pair()
    sc.bonds.append(Bond("spring", "A.tip", "B.tip", kind="bond", joint="spring", rest=1.0))
    asm = build_assembly(sc.check(), load_profile("mjp"), None)
    assert len(asm.parts) == 2
    assert any("spring" in n and "not printed" in n for n in asm.notes)


def test_hinge_needs_two_bonds():
    sc = ex.hinge_pair()
    sc.bonds = sc.bonds[:1]
    with pytest.raises(MlcError, match="two"):
        build_assembly(sc, load_profile("mjp"), None)


def test_hinge_with_bonds_at_one_point():
    sc = ex.hinge_pair()
    sc.bonds[1].a, sc.bonds[1].b = sc.bonds[0].a, sc.bonds[0].b
    with pytest.raises(MlcError, match="no axis"):
        build_assembly(sc, load_profile("mjp"), None)


def test_body_without_joints_is_a_part():
    sc = ex.hinge_pair()
    sc.bonds = []
    sc.muscles = []
    sc.inputs = []
    asm = build_assembly(sc.check(), load_profile("sla"), None)
    assert len(asm.parts) == 2 and not asm.axes
    assert all(float(p.solid.volume()) > 0 for p in asm.parts)


def test_nand_universal_joint_layout():
    from mlc.gates.library import gate_scene
    asm = build_assembly(gate_scene("NAND"), load_profile("mjp"), None, resolve=False)
    (uj,) = asm.ujoints
    assert uj.part == "ujoint_d" and uj.bodies == ("core_cd", "out_hi")
    assert np.allclose(uj.axes[0], [0, 0, 1]) and np.allclose(uj.axes[1], [1, 0, 0])


def _winding(points, V, F):
    """Generalised winding number of closed triangle mesh (V, F) at each point (1 inside, 0
    outside): the solid angles of the triangles (van Oosterom and Strackee) over 4 pi.  An
    independent inside test (numpy only), not manifold3d's."""
    A, B, C = (V[F[:, k]][None, :, :] - points[:, None, :] for k in range(3))
    a, b, c = (np.linalg.norm(X, axis=2) for X in (A, B, C))
    det = np.einsum("pti,pti->pt", A, np.cross(B, C))
    den = (a * b * c + np.einsum("pti,pti->pt", A, B) * c + np.einsum("pti,pti->pt", B, C) * a
           + np.einsum("pti,pti->pt", C, A) * b)
    return np.arctan2(det, den).sum(axis=1) / (2 * np.pi)


def test_compiled_circuit_parts_closed_and_apart():
    """A circuit compiled from an expression (mlc.pipeline) meshes into closed parts that do not
    overlap: checked with trimesh (watertight, volume) and an independent inside test on points
    sampled where two parts' boxes meet."""
    from mlc import pipeline
    from mlc.mesh.checks import check_assembly
    from mlc.mesh.export import part_meshes
    from mlc.mesh.pipeline import state_poses

    scene = pipeline.build(pipeline.compile_spec(pipeline.load(None, "a & b"))).circuit.scene
    prof = load_profile("mjp")
    poses, _ = state_poses(scene)
    asm = build_assembly(scene, prof, poses)
    rep = check_assembly(asm, walls=False)
    for name in ("watertight", "part_count", "min_gap", "states", "retention", "features"):
        assert rep.check(name).ok, (name, rep.check(name).detail, rep.check(name).failures[:3])
    meshes = part_meshes(asm)
    assert len(meshes) == len(scene.bodies) + len(asm.ujoints)
    for (name, m), p in zip(meshes, asm.parts):
        assert m.is_watertight and m.is_winding_consistent, name
        assert m.volume > 0 and abs(m.volume - p.solid.volume()) < 1e-6 * max(1.0, m.volume), name
    rng = np.random.default_rng(7)
    boxes = [(m.bounds[0], m.bounds[1]) for _, m in meshes]
    checked = 0
    for i in range(len(meshes)):
        for j in range(i + 1, len(meshes)):
            lo = np.maximum(boxes[i][0], boxes[j][0])
            hi = np.minimum(boxes[i][1], boxes[j][1])
            if np.any(hi <= lo):
                continue
            pts = lo + (hi - lo) * rng.random((300, 3))
            wi = _winding(pts, meshes[i][1].vertices, meshes[i][1].faces)
            wj = _winding(pts, meshes[j][1].vertices, meshes[j][1].faces)
            assert not np.any((wi > 0.5) & (wj > 0.5)), (meshes[i][0], meshes[j][0])
            checked += 1
    assert checked > 0


def test_a_circuits_gates_keep_their_library_configurations_and_print_alone():
    """In every row of a compiled circuit each gate sits where its library gate sits for the same
    physical inputs (read from its input tips' distance, 1.0 or 1.5 sigma): every pair of its
    parts turned alike to 0.05 degrees, against the library gate posed on its own.  So a gate's
    own parts, built alone with the circuit's poses, pass every blocking check, and what the
    circuit's report fails is where the chains meet the gates (docs/printing.md)."""
    from mlc import pipeline
    from mlc.commands.stl import load_target
    from mlc.geometry.rotation import quat_to_matrix
    from mlc.mesh.checks import check_assembly
    from mlc.mesh.pipeline import state_poses, sub_scene

    built = pipeline.build(pipeline.compile_spec(pipeline.load(None, "(a & b) | c")))
    scene = built.circuit.scene
    poses, _ = state_poses(scene)
    rows = {k: v for k, v in poses.items() if len(str(k)) == len(scene.inputs)}
    assert len(rows) == 8
    index = {b.name: i for i, b in enumerate(scene.bodies)}
    parts = ["core_ab", "core_cd", "a_lo", "a_hi", "b_lo", "b_hi", "out_lo", "out_hi"]

    def turn(ix, pq, a, b):
        _, q = pq
        return quat_to_matrix(q[ix[a]]).T @ quat_to_matrix(q[ix[b]])

    def tip(sc, ix, pq, ref):
        bn, site = ref.split(".", 1)
        p, q = pq
        return p[ix[bn]] + quat_to_matrix(q[ix[bn]]) @ np.asarray(sc.body(bn).sites[site], float)

    seen = set()
    for g in built.netlist.gates:
        lib = load_target(g.type, "expand")
        lib_poses, _ = state_poses(lib)
        lix = {b.name: i for i, b in enumerate(lib.bodies)}
        for row, pq in rows.items():
            state = ""
            for x in "ab":
                d = np.linalg.norm(tip(scene, index, pq, f"{g.id}_{x}_lo.in") - tip(scene, index, pq, f"{g.id}_{x}_hi.in"))
                assert min(abs(d - 1.0), abs(d - 1.5)) < 1e-3, (g.id, row, x, d)
                state += "1" if d > 1.25 else "0"
            seen.add((g.id, state))
            for i, A in enumerate(parts):
                for B in parts[i + 1:]:
                    dR = turn(lix, lib_poses[state], A, B).T @ turn(index, pq, f"{g.id}_{A}", f"{g.id}_{B}")
                    ang = np.degrees(np.arccos(np.clip((np.trace(dR) - 1) / 2, -1, 1)))
                    assert ang < 0.05, (g.id, g.type, row, state, A, B, ang)
    assert len(seen) >= 6          # the gates pass through most of their input states

    g = built.netlist.gates[-1]     # the gate a chain drives: its parts alone, in the circuit's poses
    idx = [i for i, b in enumerate(scene.bodies) if b.name.startswith(f"{g.id}_")]
    sub = sub_scene(scene, idx, "gate_alone")
    sub_poses = {k: (np.asarray(p)[idx], np.asarray(q)[idx]) for k, (p, q) in rows.items()}
    rep = check_assembly(build_assembly(sub, load_profile("mjp"), sub_poses), walls=False)
    for c in rep.checks:
        if c.blocking:
            assert c.ok, (c.name, c.detail, c.failures[:3])


def test_winding_inside_test_sees_an_overlap():
    """The inside test of the circuit test is not blind: two overlapping boxes share points."""
    import trimesh
    a = trimesh.creation.box((2, 2, 2))
    b = trimesh.creation.box((2, 2, 2))
    b.apply_translation((1.5, 0, 0))
    pts = np.random.default_rng(0).uniform(-1, 2.5, (2000, 3))
    wa, wb = _winding(pts, a.vertices, a.faces), _winding(pts, b.vertices, b.faces)
    both = (wa > 0.5) & (wb > 0.5)
    assert both.any()
    assert np.all(np.abs(pts[both][:, 0] - 0.75) <= 0.25 + 1e-9)
