"""Oriented-box overlap test over a scene's slabs (units: sigma).

The energy model has no box exclusion, so nothing in a simulation stops two slabs from
passing through each other; this module checks a pose for it.  Every body is the union
of its ``boxes`` (posed by the body's position and quaternion).  For two bodies the
**clearance** is the smallest distance between a box of one and a box of the other; when
two boxes interpenetrate it is minus their **penetration depth**, the length of the
shortest translation that separates them.  Both are exact (up to rounding):

* penetration depth: separating-axis test over the 15 candidate axes of two boxes (the
  3 + 3 face normals and the 9 edge-edge cross products).  These are all the facet
  normals of the Minkowski difference of two boxes, so the smallest overlap over them is
  the exact translational penetration depth, not a bound;
* distance of disjoint boxes: the closest pair of points of two disjoint convex
  polyhedra can always be taken on a vertex of one and the other box, or on an edge of
  each; so the distance is the minimum of 16 vertex-to-box and 144 edge-to-edge
  distances, each in closed form.

The tests check both against an independent computation (Qhull's hull of the Minkowski
difference, and trimesh's signed distance to it).

**Hinge contact.**  Slabs that share a joint meet at it by construction (a hinge is two
slab ends on one axis; the universal joint is a point), so their boxes overlap in a thin
wedge around the joint.  With ``skip_joined_contact`` (the default) that contact is
left out, and only that: for two bodies that share a joint (bonds of kind "hinge" or
"universal", or any zero-length bond; joints that share a site, like the three-slab
hinge at c, count as one joint of all their bodies), each box of either body that comes
within ``hinge_radius`` of the joint's sites loses the band of its long axis within
``hinge_radius`` of them (the band spans the projections of all the joint's sites, so a
hinge axis across a slab removes the knuckle across its whole width).  What is left of
the two bodies is tested like any other pair; a slab that passes through its neighbour
away from the joint is still reported.  Default ``hinge_radius`` = 0.05 sigma, five slab
thicknesses: two 0.01-sigma slabs meeting at an angle alpha overlap within about
0.01 / (2 tan(alpha / 2)) of their axis, which is below 0.05 sigma for alpha > 11 degrees.

**Scale.**  Broad phase: bounding spheres of the boxes, pairs found with a k-d tree
(scipy's cKDTree, a cell structure that adapts to the density) within ``2 r_max +
reach``, then filtered by sphere gap < ``reach``.  Narrow phase: the separating-axis
test vectorised over all candidate pairs; exact distances only for the disjoint pairs
whose separating-axis lower bound is below the best distance so far (in order of that
bound), so the minimum is exact at the cost of a few exact evaluations.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.spatial import cKDTree

from mlc.errors import MlcError
from mlc.scene.model import Scene

HINGE_RADIUS = 0.05     # sigma
REACH = 0.5             # sigma
_BATCH = 2048


@dataclass
class ClearanceReport:
    """Result of :func:`clearance` (lengths in sigma).

    ``min_clearance`` is the smallest clearance over all pairs of bodies (negative: the
    deepest interpenetration).  It is exact when it is below ``reach``; a value equal to
    ``reach`` means "at least reach" (no two boxes of different bodies come closer).
    ``pair`` names the two bodies of the smallest clearance (empty strings if none).
    ``overlaps`` lists every interpenetrating pair of bodies with its depth (> ``tol``),
    deepest first.
    """

    min_clearance: float
    pair: tuple[str, str]
    overlaps: list[tuple[str, str, float]] = field(default_factory=list)
    pairs_tested: int = 0          # box pairs that reached the narrow phase
    joined_pairs: int = 0          # body pairs whose hinge contact was left out
    reach: float = REACH
    hinge_radius: float = HINGE_RADIUS

    def ok(self, tol: float = 1e-6) -> bool:
        """True when no two bodies interpenetrate deeper than ``tol`` (sigma)."""
        return self.min_clearance >= -tol

    def as_dict(self) -> dict:
        return {"min_clearance": self.min_clearance, "pair": list(self.pair),
                "overlaps": [[a, b, d] for a, b, d in self.overlaps], "pairs_tested": self.pairs_tested,
                "joined_pairs": self.joined_pairs, "reach": self.reach, "hinge_radius": self.hinge_radius}


# ---------------------------------------------------------------------------
# geometry kernels (vectorised over leading axes)
# ---------------------------------------------------------------------------

def _quat_matrices(q: np.ndarray) -> np.ndarray:
    q = np.asarray(q, float)
    q = q / np.linalg.norm(q, axis=-1, keepdims=True)
    w, x, y, z = q[..., 0], q[..., 1], q[..., 2], q[..., 3]
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
        np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
        np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1),
    ], -2)


def box_separation(c1, A1, h1, c2, A2, h2) -> np.ndarray:
    """Separating-axis value of box pairs: the largest gap over the 15 axes.

    Boxes: centres ``c`` (P,3), axes as the columns of ``A`` (P,3,3), half extents ``h``
    (P,3).  Negative: the boxes interpenetrate and minus the value is their exact
    penetration depth.  Positive: a lower bound on their distance."""
    T = c2 - c1
    axes = [A1[:, :, k] for k in range(3)] + [A2[:, :, k] for k in range(3)]
    for i in range(3):
        for j in range(3):
            axes.append(np.cross(A1[:, :, i], A2[:, :, j]))
    L = np.stack(axes, 1)                                  # (P,15,3)
    n = np.linalg.norm(L, axis=-1)
    good = n > 1e-9
    L = L / np.where(good, n, 1.0)[..., None]
    r1 = np.abs(np.einsum("pax,pxk->pak", L, A1)) @ h1[:, :, None]
    r2 = np.abs(np.einsum("pax,pxk->pak", L, A2)) @ h2[:, :, None]
    gap = np.abs(np.einsum("pax,px->pa", L, T)) - r1[..., 0] - r2[..., 0]
    gap = np.where(good, gap, -np.inf)
    return gap.max(1)


_SIGNS = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], float)   # (8,3)


def _vertices(c, A, h):
    return c[:, None, :] + np.einsum("pxk,pvk->pvx", A, _SIGNS * h[:, None, :])     # (P,8,3)


def _point_box_dist(p, c, A, h):
    """Distance of points p (P,V,3) to boxes (P,...)."""
    loc = np.einsum("pvx,pxk->pvk", p - c[:, None, :], A)
    return np.linalg.norm(np.maximum(np.abs(loc) - h[:, None, :], 0.0), axis=-1)


_EDGE_SIGNS = np.array([(-1, -1), (-1, 1), (1, -1), (1, 1)], float)


def _edges(c, A, h):
    """The 12 edges of each box as segment ends (P,12,3) x 2."""
    p, q = [], []
    for k in range(3):
        i, j = [m for m in range(3) if m != k]
        for si, sj in _EDGE_SIGNS:
            mid = c + si * h[:, i, None] * A[:, :, i] + sj * h[:, j, None] * A[:, :, j]
            half = h[:, k, None] * A[:, :, k]
            p.append(mid - half)
            q.append(mid + half)
    return np.stack(p, 1), np.stack(q, 1)


def _segment_dist(p1, q1, p2, q2):
    """Distances between segments [p1,q1] and [p2,q2] (broadcast over leading axes), the
    clamped closest-point parametrisation (no zero-length segments)."""
    d1, d2, r = q1 - p1, q2 - p2, p1 - p2
    a = np.einsum("...x,...x->...", d1, d1)
    e = np.einsum("...x,...x->...", d2, d2)
    f = np.einsum("...x,...x->...", d2, r)
    c = np.einsum("...x,...x->...", d1, r)
    b = np.einsum("...x,...x->...", d1, d2)
    den = a * e - b * b
    par = den <= 1e-12 * a * e
    s = np.where(par, 0.0, np.clip((b * f - c * e) / np.where(par, 1.0, den), 0.0, 1.0))
    t = (b * s + f) / e
    s = np.where(t < 0, np.clip(-c / a, 0, 1), np.where(t > 1, np.clip((b - c) / a, 0, 1), s))
    t = np.clip(t, 0, 1)
    diff = (p1 + s[..., None] * d1) - (p2 + t[..., None] * d2)
    return np.linalg.norm(diff, axis=-1)


def box_distance(c1, A1, h1, c2, A2, h2) -> np.ndarray:
    """Exact distance between disjoint boxes (P pairs; zero or a small value for
    interpenetrating ones, use :func:`box_separation` for those)."""
    d = np.minimum(_point_box_dist(_vertices(c1, A1, h1), c2, A2, h2).min(1),
                   _point_box_dist(_vertices(c2, A2, h2), c1, A1, h1).min(1))
    p1, q1 = _edges(c1, A1, h1)
    p2, q2 = _edges(c2, A2, h2)
    ee = _segment_dist(p1[:, :, None], q1[:, :, None], p2[:, None, :], q2[:, None, :])
    return np.minimum(d, ee.reshape(len(d), -1).min(1))


def box_clearance(c1, A1, h1, c2, A2, h2) -> np.ndarray:
    """Signed clearance of box pairs: distance, or minus the penetration depth."""
    s = box_separation(c1, A1, h1, c2, A2, h2)
    out = s.copy()
    sep = s > 0
    if sep.any():
        out[sep] = box_distance(c1[sep], A1[sep], h1[sep], c2[sep], A2[sep], h2[sep])
    return out


# ---------------------------------------------------------------------------
# scene
# ---------------------------------------------------------------------------

def _world_boxes(scene: Scene, pos, quat):
    """World boxes: centres (K,3), axes as columns (K,3,3), half extents (K,3), body (K,)."""
    R = _quat_matrices(quat) if len(quat) else np.zeros((0, 3, 3))
    cen, qs, size, B = [], [], [], []
    for i, body in enumerate(scene.bodies):
        for box in body.boxes:
            cen.append(box.center)
            qs.append(box.orientation)
            size.append(box.size)
            B.append(i)
    if not cen:
        return np.zeros((0, 3)), np.zeros((0, 3, 3)), np.zeros((0, 3)), np.zeros(0, int)
    B = np.array(B, int)
    C = pos[B] + np.einsum("kxy,ky->kx", R[B], np.array(cen, float))
    A = np.einsum("kxy,kyz->kxz", R[B], _quat_matrices(np.array(qs, float)))
    return C, A, 0.5 * np.array(size, float), B


def _joint_groups(scene: Scene):
    """Site references of each joint, joints that share a site merged (union-find)."""
    parent: dict = {}

    def find(x):
        while parent.setdefault(x, x) != x:
            parent[x] = parent[parent[x]]
            x = parent[x]
        return x

    refs = []
    for bd in scene.bonds:
        if bd.kind in ("hinge", "universal") or bd.rest == 0.0:
            key = ("J", bd.joint or bd.name)
            for r in (bd.a, bd.b):
                parent[find(("S", r))] = find(key)
                refs.append(r)
    groups: dict = {}
    for r in refs:
        groups.setdefault(find(("S", r)), []).append(r)
    return [sorted(set(g)) for g in groups.values()]


def _joined_pieces(scene, pos, R, C, A, H, B, radius):
    """Box pairs of the body pairs that share a joint, with the band of each box within
    ``radius`` of the shared joints' sites (along its long axis) left out.  Returns the
    joined body pairs and the piece pairs as arrays (c1, A1, h1, c2, A2, h2, b1, b2)."""
    index = {b.name: i for i, b in enumerate(scene.bodies)}
    groups = _joint_groups(scene)
    if not groups:
        return set(), None
    gb, gp = [], []                                   # per group: bodies, world points
    for refs in groups:
        bi = [index[r.split(".", 1)[0]] for r in refs]
        loc = np.array([scene.bodies[i].sites[r.split(".", 1)[1]] for i, r in zip(bi, refs)], float)
        bi = np.array(bi)
        gp.append(pos[bi] + np.einsum("kxy,ky->kx", R[bi], loc))
        gb.append(sorted(set(bi.tolist())))
    shared: dict = {}
    for g, bodies in enumerate(gb):
        for x in range(len(bodies)):
            for y in range(x + 1, len(bodies)):
                shared.setdefault((bodies[x], bodies[y]), []).append(g)
    box_of: dict = {}
    for k, b in enumerate(B.tolist()):
        box_of.setdefault(b, []).append(k)
    # rows (pair, side, box, group): the band of the box around the group's sites
    rows = [(pid, side, k, g) for pid, (pair, gl) in enumerate(shared.items())
            for side in (0, 1) for k in box_of.get(pair[side], []) for g in gl]
    if not rows:
        return set(shared), None
    rows = np.array(rows, int)
    npts = max(len(p) for p in gp)
    G = np.full((len(gp), npts, 3), np.nan)
    for g, p in enumerate(gp):
        G[g, :len(p)] = p
    k, g = rows[:, 2], rows[:, 3]
    loc = np.einsum("rpx,rxk->rpk", G[g] - C[k][:, None, :], A[k])           # (r, npts, 3)
    valid = ~np.isnan(loc[..., 0])
    dist = np.where(valid, np.linalg.norm(np.maximum(np.abs(loc) - H[k][:, None, :], 0.0), axis=-1), np.inf)
    active = dist.min(1) <= radius
    kl = np.argmax(H[k], axis=1)
    s = np.take_along_axis(loc, kl[:, None, None], 2)[..., 0]
    lo = np.where(valid, s, np.inf).min(1) - radius
    hi = np.where(valid, s, -np.inf).max(1) + radius
    # subtract the active bands from each box's long-axis interval
    pieces: dict = {}                                    # (pid, side) -> list of (c, A, h)
    cut: dict = {}
    for r in range(len(rows)):
        key = (rows[r, 0], rows[r, 1], rows[r, 2])
        cut.setdefault(key, [])
        if active[r]:
            cut[key].append((lo[r], hi[r]))
    for (pid, side, kk), bands in cut.items():
        lst = pieces.setdefault((pid, side), [])
        if not bands:
            lst.append((C[kk], A[kk], H[kk]))
            continue
        ax = int(np.argmax(H[kk]))
        segs = [(-H[kk][ax], H[kk][ax])]
        for b0, b1 in bands:
            segs = [piece for a0, a1 in segs for piece in ((a0, min(a1, b0)), (max(a0, b1), a1))
                    if piece[1] - piece[0] > 1e-12]
        for a0, a1 in segs:
            h = H[kk].copy()
            h[ax] = 0.5 * (a1 - a0)
            lst.append((C[kk] + 0.5 * (a0 + a1) * A[kk][:, ax], A[kk], h))
    out = [[] for _ in range(8)]
    for pid, pair in enumerate(shared):
        for c1, a1, h1 in pieces.get((pid, 0), []):
            for c2, a2, h2 in pieces.get((pid, 1), []):
                for lst, v in zip(out, (c1, a1, h1, c2, a2, h2, pair[0], pair[1])):
                    lst.append(v)
    if not out[0]:
        return set(shared), None
    return set(shared), [np.array(v) for v in out]


def clearance(scene: Scene, pos=None, quat=None, *, skip_joined_contact: bool = True,
              hinge_radius: float = HINGE_RADIUS, reach: float = REACH, tol: float = 1e-6) -> ClearanceReport:
    """Smallest clearance between the slabs of different bodies of ``scene`` posed at
    ``pos`` (N,3) / ``quat`` (N,4) (default: the scene's own poses).  Lengths in sigma;
    see the module docstring for the hinge-contact rule and exactness."""
    N = len(scene.bodies)
    pos = np.array([b.position for b in scene.bodies], float) if pos is None else np.asarray(pos, float)
    quat = np.array([b.orientation for b in scene.bodies], float) if quat is None else np.asarray(quat, float)
    if pos.shape != (N, 3) or quat.shape != (N, 4):
        raise MlcError(f"poses must have shapes ({N}, 3) and ({N}, 4), got {pos.shape} and {quat.shape}",
                       "pos/quat", "pass one position and one quaternion per body")
    if not (hinge_radius >= 0 and reach > 0):
        raise MlcError(f"need hinge_radius >= 0 and reach > 0, got {hinge_radius}, {reach}", "hinge_radius/reach")
    C, A, H, B = _world_boxes(scene, pos, quat)
    names = [b.name for b in scene.bodies]
    if len(C) < 2:
        return ClearanceReport(reach, ("", ""), [], 0, 0, reach, hinge_radius)

    joined, extra = set(), None
    if skip_joined_contact:
        joined, extra = _joined_pieces(scene, pos, _quat_matrices(quat), C, A, H, B, hinge_radius)

    # broad phase: bounding spheres
    rad = np.linalg.norm(H, axis=1)
    pairs = cKDTree(C).query_pairs(2 * rad.max() + reach, output_type="ndarray")
    if len(pairs):
        i, j = pairs[:, 0], pairs[:, 1]
        keep = (B[i] != B[j]) & (np.linalg.norm(C[i] - C[j], axis=1) - rad[i] - rad[j] < reach)
        pairs = pairs[keep]
        if joined and len(pairs):
            lo, hi = np.minimum(B[pairs[:, 0]], B[pairs[:, 1]]), np.maximum(B[pairs[:, 0]], B[pairs[:, 1]])
            jkey = np.array(sorted(joined), np.int64)
            pairs = pairs[~np.isin(lo.astype(np.int64) * N + hi, jkey[:, 0] * N + jkey[:, 1])]
    pairs = pairs.reshape(-1, 2)
    parts = [C[pairs[:, 0]], A[pairs[:, 0]], H[pairs[:, 0]], C[pairs[:, 1]], A[pairs[:, 1]], H[pairs[:, 1]],
             B[pairs[:, 0]], B[pairs[:, 1]]]
    if extra is not None:
        parts = [np.concatenate([p, e.astype(p.dtype)]) for p, e in zip(parts, extra)]
    pc1, pa1, ph1, pc2, pa2, ph2, pb0, pb1 = parts
    pb = [pb0, pb1]
    P = len(pc1)
    if P == 0:
        return ClearanceReport(reach, ("", ""), [], 0, len(joined), reach, hinge_radius)

    # narrow phase: separating axes for all, exact distances lazily
    s = np.concatenate([box_separation(pc1[x:x + _BATCH], pa1[x:x + _BATCH], ph1[x:x + _BATCH],
                                       pc2[x:x + _BATCH], pa2[x:x + _BATCH], ph2[x:x + _BATCH])
                        for x in range(0, P, _BATCH)])
    overl: dict = {}
    for x in np.nonzero(s < -tol)[0]:
        key = (min(pb[0][x], pb[1][x]), max(pb[0][x], pb[1][x]))
        overl[key] = max(overl.get(key, 0.0), -float(s[x]))
    if (s <= 0).any():
        x = int(np.argmin(s))
        best, best_x = float(s[x]), x
    else:
        best, best_x = np.inf, -1
        order = np.argsort(s)
        for start in range(0, P, 256):
            idx = order[start:start + 256]
            idx = idx[s[idx] < best]
            if len(idx) == 0:
                break
            d = box_distance(pc1[idx], pa1[idx], ph1[idx], pc2[idx], pa2[idx], ph2[idx])
            k = int(np.argmin(d))
            if d[k] < best:
                best, best_x = float(d[k]), int(idx[k])
    overlaps = sorted(((names[a], names[b], d) for (a, b), d in overl.items()), key=lambda t: -t[2])
    if best > reach:
        best = reach
    i, j = sorted((int(pb[0][best_x]), int(pb[1][best_x])))
    return ClearanceReport(best, (names[i], names[j]), overlaps, P, len(joined), reach, hinge_radius)


# ---------------------------------------------------------------------------
# sweeps over quasi-static poses
# ---------------------------------------------------------------------------

def static_poses(scene: Scene, fractions):
    """Equilibrium poses of ``scene`` with every input's muscles at a fraction of their
    stroke (0 = rest, 1 = actuated), one pose per row of ``fractions`` (shape (F, inputs)),
    each reached from the scene's own (all-zero) pose by the static solver's continuation
    (mlc.verify.static.equilibrium on a copy whose actuated lengths are the partial
    strokes).  Returns a list of (pos, quat, max joint stretch in sigma)."""
    import copy
    import dataclasses

    from mlc.verify.static import equilibrium

    out = []
    for f in np.atleast_2d(np.asarray(fractions, float)):
        s = copy.copy(scene)
        frac = dict(zip(scene.inputs, f))
        s.muscles = [dataclasses.replace(m, actuated=m.rest + frac[m.input] * (m.actuated - m.rest))
                     for m in scene.muscles]
        eq = equilibrium(s, "1" * len(scene.inputs))
        out.append((eq.pos, eq.quat, eq.max_joint_stretch))
    return out


def sweep_clearance(scene: Scene, grid: int = 3, **kw):
    """Clearance of ``scene`` over the quasi-static poses with the input muscles on a
    ``grid`` x ... x ``grid`` lattice of stroke fractions (grid = 3: the input states and
    every half-way pose between them).  Returns (worst report, fractions of the worst
    pose, list of (fractions, report))."""
    n = len(scene.inputs)
    ticks = np.linspace(0, 1, grid)
    fr = np.array(np.meshgrid(*([ticks] * n), indexing="ij")).reshape(n, -1).T if n else np.zeros((1, 0))
    rows = []
    for f, (pos, quat, _) in zip(fr, static_poses(scene, fr)):
        rows.append((tuple(float(v) for v in f), clearance(scene, pos, quat, **kw)))
    worst = min(rows, key=lambda r: r[1].min_clearance)
    return worst[1], worst[0], rows
