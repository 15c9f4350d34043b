"""mlc.mesh.spatial: the pairs of parts that can meet, against brute force (sound: none missed)."""
import manifold3d as mf
import numpy as np
from scipy.spatial.transform import Rotation

from mlc.mesh.build import transform_solid
from mlc.mesh.spatial import box_pairs, local_boxes, obb_overlap, posed_boxes


def test_box_pairs_equal_all_pairs():
    rng = np.random.default_rng(1)
    for trial in range(30):
        n = int(rng.integers(0, 200))
        lo = rng.uniform(0, 10, (n, 3))
        hi = lo + rng.uniform(0, 2, (n, 3))
        if trial % 3 == 0:                         # ties on the sweep axis
            lo[:, 0] = np.round(lo[:, 0])
            hi[:, 0] = lo[:, 0] + 1
        m = float(rng.choice([0.0, 0.1, 1.0]))
        ok = np.all((lo[:, None] <= hi[None] + m) & (lo[None] <= hi[:, None] + m), axis=2)
        i, j = np.nonzero(np.triu(ok, 1))
        assert box_pairs(lo, hi, m) == list(zip(i.tolist(), j.tolist()))


def _random_boxes(n, seed):
    rng = np.random.default_rng(seed)
    solids, frames = [], []
    for k in range(n):
        F = np.eye(4)
        F[:3, :3] = Rotation.random(random_state=seed * 1000 + k).as_matrix()
        F[:3, 3] = rng.uniform(-3, 3, 3)
        local = mf.Manifold.cube(rng.uniform(0.05, 3, 3).tolist(), True).translate(rng.uniform(-1, 1, 3).tolist())
        solids.append(transform_solid(local, F))
        frames.append(F)
    return solids, frames


def test_posed_boxes_contain_the_moved_part():
    solids, frames = _random_boxes(20, 2)
    lo = np.array([np.asarray(s.bounding_box())[:3] for s in solids])
    hi = np.array([np.asarray(s.bounding_box())[3:] for s in solids])
    plo, phi = posed_boxes(lo, hi, frames)        # move each by its own frame once more
    for k, (s, T) in enumerate(zip(solids, frames)):
        b = np.asarray(transform_solid(s, T).bounding_box())
        assert np.all(plo[k] <= b[:3]) and np.all(phi[k] >= b[3:])


def test_oriented_boxes_drop_only_pairs_apart():
    solids, frames = _random_boxes(120, 3)
    lo, hi = local_boxes(solids, frames)
    pairs = [(i, j) for i in range(len(solids)) for j in range(i + 1, len(solids))]
    kept = set(obb_overlap(pairs, frames, lo, hi))
    meet = {(i, j) for i, j in pairs if (solids[i] ^ solids[j]).volume() > 1e-9}
    assert meet <= kept                            # sound: every intersecting pair is kept
    assert len(kept) < 0.5 * len(pairs)            # and it does narrow the candidates
    assert len(kept - meet) <= 0.05 * len(pairs)


def test_posed_gaps_against_every_pose_measured_and_the_distance():
    """Four balls that close in on the four vertical edges of a cube, each with its own step,
    from twice the clearance to under half of it (their boxes within the clearance well before
    the balls are: the bound decides those poses): posed_gaps, which skips the poses its bound
    proves clear, flags exactly the poses a measurement of every pose flags (manifold3d min_gap,
    no bound), and its gaps are the distance from each ball's centre to the cube less the
    radius (to the polygon's sagitta)."""
    from mlc.mesh.spatial import posed_gaps
    r, c, n = 0.3, 0.2, 128
    solids = [mf.Manifold.cube([1.0] * 3, True)] + [mf.Manifold.sphere(r, n) for _ in range(4)]
    frames = [np.eye(4)] * 5
    lo, hi = local_boxes(solids, frames)
    edges = [np.array([sx * 0.5, sy * 0.5, 0.0]) for sx, sy in ((1, 1), (-1, 1), (-1, -1), (1, -1))]
    dirs = [np.array([np.cos(a) * np.sign(e[0]), np.sin(a) * np.sign(e[1]), 0.0])
            for a, e in zip(np.radians([30, 45, 55, 65]), edges)]
    steps = [0.17, 0.29, 0.41, 0.53]                    # per pose, in clearances
    poses, gaps = [], []
    for k in range(40):
        T, g = [np.eye(4)], []
        for e, d, st in zip(edges, dirs, steps):
            gk = max(2.0 * c - k * st * c, 0.3 * c)
            M = np.eye(4)
            M[:3, 3] = e + (r + gk) * d
            T.append(M)
            g.append(gk)
        poses.append(T)
        gaps.append(g)
    close, smallest = posed_gaps(solids, frames, lo, hi, poses, c)
    brute = {(k, b) for k, T in enumerate(poses) for b in range(1, 5)
             if solids[0].min_gap(solids[b].translate(T[b][:3, 3].tolist()), 2 * c) < c - 1e-6}
    assert {(k, j) for k, here in enumerate(close) for (_, j) in here} == brute
    assert len(brute) > 100
    sag = r * (1 - np.cos(np.pi / n)) + 1e-9
    for k, here in enumerate(close):
        for (i, j), g in here.items():
            assert i == 0 and abs(g - gaps[k][j - 1]) < sag
    assert abs(smallest[0] - 0.3 * c) < sag


def test_posed_pairs_and_pair_gaps_against_every_pair_measured():
    """posed_pairs keeps every pair of moved parts closer than the margin (brute force: min_gap
    of every pair) and leaves out the pairs ``keep`` refuses; pair_gaps reads the gap min_gap
    reads, and with a congruence cache (here two copies of each shape, moved alike) measures
    congruent pairs in one relative pose once (most of the copies' pairs) and returns the same gaps."""
    from mlc.mesh.congruence import Congruence
    from mlc.mesh.spatial import pair_gaps, posed_pairs
    base, frames0 = _random_boxes(30, 5)
    far = np.eye(4)
    far[:3, 3] = [100.0, 0.0, 0.0]
    solids = base + [transform_solid(s, far) for s in base]     # part k + 30: part k moved far away
    frames = frames0 + [far @ F for F in frames0]
    lo, hi = local_boxes(solids, frames)
    wlo = np.array([np.asarray(s.bounding_box())[:3] for s in solids])
    whi = np.array([np.asarray(s.bounding_box())[3:] for s in solids])
    rng = np.random.default_rng(6)
    margin = 0.3
    for trial in range(3):
        Tp = []
        for k in range(30):
            M = np.eye(4)
            M[:3, :3] = Rotation.from_rotvec(rng.normal(0, 0.2, 3)).as_matrix()
            M[:3, 3] = rng.normal(0, 0.3, 3)
            Tp.append(M)
        Tp = Tp + [far @ M @ np.linalg.inv(far) for M in Tp]      # the copies moved alike
        plo, phi = posed_boxes(wlo, whi, Tp)
        posed = [transform_solid(s, T) for s, T in zip(solids, Tp)]
        n = len(solids)
        brute = {(i, j): float(posed[i].min_gap(posed[j], margin)) for i in range(n) for j in range(i + 1, n)}
        near = {ij for ij, g in brute.items() if g < margin - 1e-6}
        keep = (lambda i, j: (i + j) % 3 != 0)
        got = posed_pairs(Tp, frames, lo, hi, plo, phi, margin)
        assert near <= set(got) and len(near) > 10
        assert len(got) < 0.5 * len(brute)
        got_k = posed_pairs(Tp, frames, lo, hi, plo, phi, margin, keep)
        assert set(got_k) == {ij for ij in got if keep(*ij)} and len(got_k) < len(got)
        gaps = pair_gaps(solids, Tp, got, margin, {})
        assert all(abs(g - brute[ij]) < 1e-9 for ij, g in zip(got, gaps))
        cong = Congruence(frames)
        gaps_c = pair_gaps(solids, Tp, got, margin, {}, cong)
        assert np.allclose(gaps_c, gaps, atol=1e-6)
        twins = sum(1 for i, j in got if i >= 30 and (i - 30, j - 30) in set(got))
        # (a twin whose key rounds differently, its vertices moved 100 mm, is measured again)
        assert cong.hits + cong.misses == len(got) and twins > 10 and cong.hits >= 0.5 * twins
