"""The proof that two posed parts share no volume (mlc.mesh.apart; states check, min_gap): it never
calls a pair apart that manifold3d finds intersecting, it does prove interleaved parts apart,
and the report is the same with and without it."""
import numpy as np

from mlc.geometry.rotation import quat_to_matrix
from mlc.mesh.apart import surfaces_apart
from mlc.mesh.build import box, cylinder, transform_solid, union


def _arrays(solid):
    m = solid.to_mesh64()
    return np.asarray(m.vert_properties, float)[:, :3], np.asarray(m.tri_verts, np.int64)


def _comb(teeth, offset, side):
    """Plates 8 x 8 x 0.6 mm, 1.6 mm apart along z from ``offset``, joined by a spine at x =
    4.5 ``side`` (mm): two combs offset by 0.8 mm with opposite spines interleave 0.2 mm apart."""
    plates = [box([0, 0, offset + 1.6 * k], np.eye(3), [8.0, 8.0, 0.6]) for k in range(teeth)]
    span = 1.6 * (teeth - 1) + 0.6
    return union(plates + [box([4.5 * side, 0, offset + 0.8 * (teeth - 1)], np.eye(3), [0.6, 8.0, span])])


def test_never_apart_when_manifold_finds_volume():
    """Seeded random poses of a knuckle-like part against a slab-like one: every pair proven
    apart has an empty intersection, and the proof finds most empty ones."""
    rng = np.random.default_rng(7)
    a = union([box([0, 0, 0], np.eye(3), [4.0, 2.0, 0.6]), cylinder([2.0, 0, 0], [0, 1, 0], -1.0, 1.0, 0.8, 24)])
    b = union([box([0, 0, 0], np.eye(3), [3.0, 3.0, 0.6]), cylinder([0, 0, 0], [0, 0, 1], -0.3, 1.5, 0.5, 20)])
    VA, FA = _arrays(a)
    proven = empty = hit = 0
    for _ in range(300):
        q = rng.normal(size=4)
        F = np.eye(4)
        F[:3, :3] = quat_to_matrix(q / np.linalg.norm(q))
        F[:3, 3] = rng.uniform(-4.5, 4.5, 3)
        bb = transform_solid(b, F)
        v = float((a ^ bb).volume())
        ok = surfaces_apart(VA, FA, *_arrays(bb))
        proven += ok
        empty += v == 0.0
        hit += v > 0.0
        assert not (ok and v != 0.0), (v, F)
    assert hit > 30 and empty > 30
    assert proven >= 0.9 * empty


def test_interleaved_and_nested():
    """Two combs whose plates interleave 0.2 mm apart are proven apart (their boxes overlap); the
    same combs touching, one plate into another, or a part inside another are not."""
    a = _comb(3, 0.0, 1)
    b = _comb(3, 0.8, -1)                   # teeth between a's, spine on the other side
    assert float((a ^ b).volume()) == 0.0
    assert surfaces_apart(*_arrays(a), *_arrays(b))
    into = b.translate([0, 0, 0.3])
    assert float((a ^ into).volume()) > 0
    assert not surfaces_apart(*_arrays(a), *_arrays(into))
    big = box([0, 0, 0], np.eye(3), [10.0, 10.0, 10.0])
    small = box([0, 0, 0], np.eye(3), [1.0, 1.0, 1.0])
    assert not surfaces_apart(*_arrays(big), *_arrays(small))       # nested: surfaces apart, solids not
    assert not surfaces_apart(*_arrays(small), *_arrays(big))
    far = small.translate([3.0, 3.0, 0.0])
    touching = small.translate([1.0, 0.0, 0.0])                    # faces in contact
    assert surfaces_apart(*_arrays(small), *_arrays(far))
    assert not surfaces_apart(*_arrays(small), *_arrays(touching))


def test_states_check_same_with_and_without_the_proof(monkeypatch):
    """A connector chain with the large-assembly path (congruence cache): every check is the same
    with the proof on and off, and the proof spared booleans."""
    from mlc.gates.connector import chain_scene
    from mlc.mesh import apart, checks
    from mlc.mesh.build import build_assembly
    from mlc.mesh.congruence import Congruence
    from mlc.mesh.pipeline import state_poses
    from mlc.mesh.profiles import load_profile
    from mlc.mesh.spatial import part_frames
    scene = chain_scene(2, "expand")
    poses, _ = state_poses(scene, path_steps=1)
    asm = build_assembly(scene, load_profile("mjp"), poses, resolve=False, reuse=False)
    calls = []
    real = apart.surfaces_apart
    monkeypatch.setattr(apart, "surfaces_apart", lambda *a, **k: calls.append(real(*a, **k)) or calls[-1])
    out = {}
    for on in (False, True):
        monkeypatch.setattr(checks, "APART", on)
        asm.congruence = Congruence(part_frames(asm))
        out[on] = checks.check_assembly(asm, walls=False)
    for a, b in zip(out[False].checks, out[True].checks):
        assert (a.name, a.ok, a.value, a.detail, a.failures) == (b.name, b.ok, b.value, b.detail, b.failures)
    assert out[False].parts == out[True].parts
    assert sum(calls) > 10


def test_min_gap_equals_manifold():
    """apart.min_gap answers as manifold3d's min_gap on seeded random poses (near, far, touching,
    intersecting) and on nested solids (gap 0 in manifold3d), and skipped manifold3d for far pairs."""
    from mlc.mesh import apart
    rng = np.random.default_rng(11)
    a = union([box([0, 0, 0], np.eye(3), [4.0, 2.0, 0.6]), cylinder([2.0, 0, 0], [0, 1, 0], -1.0, 1.0, 0.8, 24)])
    b = box([0, 0, 0], np.eye(3), [1.5, 1.0, 0.6])
    cache = {}
    proven = 0
    for _ in range(200):
        q = rng.normal(size=4)
        F = np.eye(4)
        F[:3, :3] = quat_to_matrix(q / np.linalg.norm(q))
        F[:3, 3] = rng.uniform(-3.5, 3.5, 3)
        bb = transform_solid(b, F)
        search = float(rng.choice([0.2, 0.4, 1.0]))
        want = float(a.min_gap(bb, search))
        assert apart.min_gap(a, bb, search, cache) == want
        proven += apart.surfaces_apart(*apart.mesh_arrays(a), *apart.mesh_arrays(bb), margin=search)
    assert proven > 50
    big = box([0, 0, 0], np.eye(3), [10.0, 10.0, 10.0])
    assert apart.min_gap(big, b, 0.4) == float(big.min_gap(b, 0.4)) == 0.0
