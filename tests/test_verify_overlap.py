"""Oriented-box overlap test (mlc.verify.overlap), checked against independent computations.

Reference for a box pair: the Minkowski difference of the two boxes is the convex hull
of the 64 vertex differences (Qhull via scipy); the boxes' distance is the distance of
the origin to that hull (closest points on its triangles by trimesh), and their
penetration depth is the distance of the origin to its boundary when the origin lies
inside (sign from Qhull's facet equations)."""
import numpy as np
import pytest
import trimesh
from scipy.spatial import ConvexHull
from helpers import ROOT

from mlc.gates.parts import EX, EZ, hinge, slab_body, universal_joint
from mlc.scene.model import Body, Box, Scene
from mlc.verify.overlap import _quat_matrices, box_clearance, box_separation, clearance


def _random_rotations(rng, n):
    q = rng.normal(size=(n, 4))
    return _quat_matrices(q / np.linalg.norm(q, axis=1)[:, None])


def _reference_clearance(c1, A1, h1, c2, A2, h2):
    signs = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float)
    v1 = c1 + (signs * h1) @ A1.T
    v2 = c2 + (signs * h2) @ A2.T
    diff = (v1[:, None, :] - v2[None, :, :]).reshape(-1, 3)
    hull = ConvexHull(diff)
    tri = diff[hull.simplices]
    cp = trimesh.triangles.closest_point(tri, np.zeros((len(tri), 3)))
    d = np.linalg.norm(cp, axis=1).min()
    inside = hull.equations[:, 3].max() < 0
    return -d if inside else d


def test_box_pairs_match_minkowski_hull_reference():
    rng = np.random.default_rng(12)
    n = 300
    # thin slabs like the library's, and chunkier boxes
    h1 = np.where(rng.random((n, 1)) < 0.5, [0.6, 0.25, 0.005], rng.uniform(0.05, 0.6, (n, 3)))
    h2 = np.where(rng.random((n, 1)) < 0.5, [0.5, 0.25, 0.005], rng.uniform(0.05, 0.6, (n, 3)))
    A1, A2 = _random_rotations(rng, n), _random_rotations(rng, n)
    c1 = np.zeros((n, 3))
    c2 = rng.normal(0, 0.6, (n, 3))
    got = box_clearance(c1, A1, h1, c2, A2, h2)
    ref = np.array([_reference_clearance(c1[i], A1[i], h1[i], c2[i], A2[i], h2[i]) for i in range(n)])
    n_in, n_out = int((ref < 0).sum()), int((ref > 0).sum())
    print(f"box pairs: {n_in} interpenetrating, {n_out} disjoint, max |error| {np.abs(got - ref).max():.2e} sigma")
    assert n_in > 50 and n_out > 50          # both regimes are exercised
    assert np.allclose(got, ref, atol=1e-9)


def test_parallel_and_touching_boxes():
    """Degenerate axes (parallel edges) and face contact."""
    I = np.eye(3)[None]
    h = np.array([[0.5, 0.25, 0.005]])
    for dz, want in ((0.02, 0.01), (0.01, 0.0), (0.004, -0.006)):
        got = box_clearance(np.zeros((1, 3)), I, h, np.array([[0.3, 0.1, dz]]), I, h)
        assert got[0] == pytest.approx(want, abs=1e-12)


def _two_slab_scene(p, q, r, s, joined=None, hi_axis=EZ):
    """Two single-slab bodies, ``lo`` from p to q (width along z) and ``hi`` from r to s
    (width along ``hi_axis``)."""
    lo = slab_body("lo", [(p, q)], {"j_0": np.array(q) - 0.25 * EZ, "j_1": np.array(q) + 0.25 * EZ,
                                   "pt": np.array(q)}, EZ, 0.5, 0.01)
    hi = slab_body("hi", [(r, s)], {"j_0": np.array(r) - 0.25 * EZ, "j_1": np.array(r) + 0.25 * EZ,
                                   "pt": np.array(r)}, hi_axis, 0.5, 0.01)
    bonds = []
    if joined == "hinge":
        bonds = hinge("h", "lo", "hi", "j", "j")
    elif joined == "universal":
        bonds = [universal_joint("u", "lo.pt", "hi.pt")]
    return Scene("two", [lo, hi], bonds).check()


def test_hinge_contact_is_left_out_only_near_the_joint():
    o = np.zeros(3)
    a = np.array([-1.0, 0, 0])
    b = np.array([np.cos(1.0), np.sin(1.0), 0.0])          # 57 degrees apart, hinged at the origin
    s = _two_slab_scene(a, o, o, b, joined="hinge")
    r = clearance(s)
    assert r.ok() and r.joined_pairs == 1 and r.min_clearance > 0
    raw = clearance(s, skip_joined_contact=False)           # the hinge wedge itself overlaps
    assert not raw.ok() and raw.overlaps[0][:2] == ("lo", "hi")
    # the same hinge with the second slab folded back through the first, 0.6 sigma past the joint
    back = np.array([-np.cos(0.004), np.sin(0.004), 0.0])
    s2 = _two_slab_scene(a, o, o, back, joined="hinge")
    r2 = clearance(s2)
    assert not r2.ok() and r2.overlaps and r2.overlaps[0][2] > 0.004


def test_universal_joint_pass_through_is_reported():
    """A slab that runs through its universal-joint partner (as the old out_hi through core_cd)."""
    o = np.zeros(3)
    end = np.array([0, -0.6, 0.8])
    s = _two_slab_scene(np.array([0, -1.0, 0]), o, o, end, joined="universal", hi_axis=EX)
    r = clearance(s)
    # lo is a plate in the plane x = 0 (y in [-1, 0], |z| <= 0.25); hi leaves the joint
    # inside it, 0.5 sigma wide along x, and crosses it until |z| = 0.25
    assert not r.ok() and r.pair == ("lo", "hi") and r.overlaps[0][:2] == ("lo", "hi")
    # by hand, for the centre planes: shifting hi by delta along its normal (0, 0.8, 0.6)
    # moves its centre line to (y, z) = (-0.6 t + 0.8 delta, 0.8 t + 0.6 delta); it leaves
    # lo (y <= y_top, z <= 0.25) once 0.8 (0.8 delta - y_top) / 0.6 + 0.6 delta = 0.25,
    # delta = 0.15 for the whole plate (y_top = 0) and 0.11 with the 0.05-sigma band at the
    # joint left out (y_top = -0.05); the 0.01-sigma thickness adds at most 0.01
    raw = clearance(s, skip_joined_contact=False)
    assert 0.15 <= -raw.min_clearance <= 0.16
    assert 0.11 <= -r.min_clearance <= 0.12



def test_poses_argument_moves_bodies():
    s = _two_slab_scene(np.array([-1.0, 0, 0]), np.array([-0.2, 0, 0]), np.array([0.2, 0, 0]), np.array([1.0, 0, 0]))
    r = clearance(s)
    assert r.min_clearance == pytest.approx(0.4, abs=1e-12)
    pos = np.array([b.position for b in s.bodies])
    quat = np.array([b.orientation for b in s.bodies])
    pos[1, 0] -= 0.7                                          # slide hi 0.3 into lo, end to end
    r2 = clearance(s, pos, quat)
    # exact: overlap along x is 0.3, across the thickness 0.01: the shortest way out is 0.01
    assert r2.min_clearance == pytest.approx(-0.01, abs=1e-12)


def _random_slab_scene(n, seed, box=6.0):
    rng = np.random.default_rng(seed)
    bodies = []
    for i in range(n):
        nb = rng.integers(1, 3)
        boxes = [Box(np.array([rng.uniform(0.3, 1.5), 0.5, 0.01]), rng.normal(0, 0.3, 3),
                     (lambda q: q / np.linalg.norm(q))(rng.normal(size=4))) for _ in range(nb)]
        q = rng.normal(size=4)
        bodies.append(Body(f"b{i}", rng.uniform(0, box, 3), q / np.linalg.norm(q), boxes, {}))
    return Scene("random", bodies)


def test_broad_phase_matches_all_pairs():
    s = _random_slab_scene(250, seed=3)
    r = clearance(s, tol=0.0)
    # all pairs of boxes of different bodies, no broad phase
    from mlc.verify.overlap import _world_boxes
    C, A, H, B = _world_boxes(s, np.array([b.position for b in s.bodies]), np.array([b.orientation for b in s.bodies]))
    i, j = np.triu_indices(len(C), 1)
    keep = B[i] != B[j]
    i, j = i[keep], j[keep]
    c = box_separation(C[i], A[i], H[i], C[j], A[j], H[j])      # exact where negative
    assert r.min_clearance == pytest.approx(c.min(), abs=1e-12) and c.min() < 0
    want = {}
    for x in np.nonzero(c < 0)[0]:
        key = tuple(sorted((s.bodies[B[i[x]]].name, s.bodies[B[j[x]]].name)))
        want[key] = max(want.get(key, 0.0), -c[x])
    got = {tuple(sorted(t[:2])): t[2] for t in r.overlaps}
    assert len(want) > 10 and got.keys() == want.keys()
    assert all(abs(got[k] - want[k]) < 1e-12 for k in want)
    # a sparse scene: the nearest pair is exact through the lazy distance evaluation
    s2 = _random_slab_scene(30, seed=4, box=20.0)
    r2 = clearance(s2)
    C, A, H, B = _world_boxes(s2, np.array([b.position for b in s2.bodies]), np.array([b.orientation for b in s2.bodies]))
    i, j = np.triu_indices(len(C), 1)
    keep = B[i] != B[j]
    c2 = box_clearance(C[i][keep], A[i][keep], H[i][keep], C[j][keep], A[j][keep], H[j][keep])
    assert c2.min() > 0 and r2.min_clearance == pytest.approx(min(c2.min(), r2.reach), abs=1e-12)


# ---------------------------------------------------------------------------
# the gate library (issue 12, item 5)
# ---------------------------------------------------------------------------

from mlc.gates.library import GATE_NAMES, gate_scene  # noqa: E402
from mlc.verify.overlap import static_poses, sweep_clearance  # noqa: E402


@pytest.mark.parametrize("signal", ["expand", "contract"])
def test_library_gates_do_not_interpenetrate(signal):
    """Every gate, every input state and every half-way pose between states: no two slabs
    of different bodies overlap beyond hinge contact."""
    worst = []
    for name in GATE_NAMES:
        rep, frac, rows = sweep_clearance(gate_scene(name, signal), grid=3)
        assert len(rows) == 9
        print(f"{name:8s} {signal:8s} smallest clearance {rep.min_clearance:+.4f} sigma "
              f"({rep.pair[0]}/{rep.pair[1]}) at strokes {frac}")
        assert rep.ok() and not rep.overlaps, (name, signal, rep)
        worst.append(rep.min_clearance)
    assert min(worst) > 0.01


def _old_core_cd(scene):
    """The former core_cd: its end box at d centred on the core plane again."""
    import copy
    s = copy.deepcopy(scene)
    body = s.body("core_cd")
    R = body.rotation()
    body.boxes[1].center = body.boxes[1].center + R.T @ np.array([0.0, 0.0, 0.25])
    return s


def test_output_lever_through_core_cd_is_caught():
    """The defect of issue 12: with core_cd's end box back in the core plane, out_hi runs
    through it from the universal joint at d, 0.1-0.2 sigma deep, in the rest pose."""
    s = _old_core_cd(gate_scene("NIMPLY", "expand"))
    r = clearance(s)
    assert not r.ok() and r.overlaps[0][:2] == ("core_cd", "out_hi") and 0.1 < r.overlaps[0][2] < 0.25
    # and in the actuated states (poses from the fixed gate: the kinematics is the same)
    pos, quat, stretch = static_poses(gate_scene("NIMPLY", "expand"), [[1, 0]])[0]
    assert stretch < 1e-6 and not clearance(s, pos, quat).ok()


def test_check_gate_reports_clearance_and_fails_on_interpenetration(capsys, monkeypatch):
    import json

    from mlc.cli import main
    import mlc.gates.library as lib
    assert main(["check-gate", "AND", "--signal", "contract", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["ok"] and d["clearance"][0]["min_clearance"] > 0 and d["clearance"][0]["poses"] == 9
    assert all(r["clearance"] > 0 for r in d["rows"])
    orig = lib.gate_scene
    monkeypatch.setattr(lib, "gate_scene", lambda name, signal="expand", design=None:
                        _old_core_cd(orig(name, signal, design)))
    assert main(["check-gate", "AND", "--signal", "contract"]) == 1
    out = capsys.readouterr().out
    assert "4 of 4 gate states correct" not in out or "INTERPENETRATE" in out
    assert "core_cd and out_hi interpenetrate" in out


def _boolean_contacts(scene, pos, quat, near=0.06, contact=None):
    """Independent of mlc.verify.overlap: manifold3d's boolean intersection of the boxes of
    different bodies (benchmarks/outside_overlap.py): the pairs (names, volume, farthest vertex
    from a joint the two bodies share) whose intersection is not within ``near`` sigma of such a
    joint."""
    import sys
    sys.path.insert(0, str(ROOT / "benchmarks"))
    from outside_overlap import boolean_contacts
    return boolean_contacts(scene, pos, quat, near=near, contact=contact)


@pytest.mark.parametrize("signal", ["expand", "contract"])
def test_library_gates_clear_by_an_independent_boolean_check(signal):
    """The library check above, confirmed without mlc.verify.overlap: at every pose of the 3 x 3
    stroke lattice of every gate, every intersection of two boxes of different bodies (manifold3d)
    lies within 0.06 sigma of a joint the two bodies share (hinge contact); the old core_cd is
    caught by the same check."""
    for name in GATE_NAMES:
        sc = gate_scene(name, signal)
        fr = np.array(np.meshgrid(*([np.linspace(0, 1, 3)] * 2), indexing="ij")).reshape(2, -1).T
        n_bad, contact = 0, [0.0]
        for pos, quat, _ in static_poses(sc, fr):
            n_bad += len(_boolean_contacts(sc, pos, quat, contact=contact))
        print(f"{name:8s} {signal:8s}: 9 poses, box intersections away from a shared joint: {n_bad}; hinge "
              f"contacts reach {contact[0]:.4f} sigma from their joint")
        assert n_bad == 0
    old = _old_core_cd(gate_scene("NIMPLY", signal))
    pos, quat, _ = static_poses(old, [[1.0, 0.0]])[0]
    bad = _boolean_contacts(old, pos, quat)
    print(f"old core_cd, NIMPLY {signal} 10: {[(a, b, round(f, 3)) for a, b, _, f in bad]}")
    assert any({a, b} == {"core_cd", "out_hi"} for a, b, _, _ in bad)
