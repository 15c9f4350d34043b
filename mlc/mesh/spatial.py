"""Which parts can meet: axis-aligned bounding boxes (mm) and the pairs of them that come close.

A compiled circuit has thousands of parts, and the trims and checks of :mod:`mlc.mesh.build`
and :mod:`mlc.mesh.checks` compare parts two by two: testing every pair (``n**2 / 2``: 750 000
pairs for 1223 bodies, in every logic state) costs far more than the few thousand pairs that
actually touch.  :func:`box_pairs` finds the pairs whose boxes come within a margin by sweep
and prune along one axis (sort the boxes by their lower end, each box against the boxes that
start before it ends, then the other two axes), in ``O(n log n + pairs)`` with numpy, and
returns them in the same order as a test of all pairs would (``i < j``, lexicographic).

:func:`posed_boxes` bounds the boxes of parts moved by rigid transforms without moving their
meshes: the box of a box's eight transformed corners contains the box of the moved part.  A
pair whose bounding boxes are apart is apart, so these boxes only ever *select* pairs; the
exact tests (manifold3d ``min_gap``, intersection volume) decide.  :func:`obb_overlap` narrows
them further with each part's box in its own body frame (oriented boxes, separating-axis test):
a slab tilted in a connector chain has a world box far larger than the slab.
"""
from __future__ import annotations

import numpy as np


def box_pairs(lo, hi, margin: float = 0.0) -> list[tuple[int, int]]:
    """Index pairs ``(i, j)``, ``i < j``, of boxes ``[lo, hi]`` (arrays ``(n, 3)``, mm) that come
    within ``margin`` of each other on every axis (touching counts), sorted lexicographically:
    exactly the pairs ``lo_i <= hi_j + margin and lo_j <= hi_i + margin`` on all three axes."""
    lo = np.asarray(lo, float).reshape(-1, 3)
    hi = np.asarray(hi, float).reshape(-1, 3)
    n = len(lo)
    if n < 2:
        return []
    best = None
    for ax in range(3):        # sweep along the axis that leaves the fewest candidates
        order = np.argsort(lo[:, ax], kind="stable")
        los = lo[order, ax]
        end = np.searchsorted(los, hi[order, ax] + margin, side="right")
        cnt = np.maximum(end - np.arange(1, n + 1), 0)
        total = int(cnt.sum())
        if best is None or total < best[0]:
            best = (total, order, cnt)
    total, order, cnt = best
    if total == 0:
        return []
    k = np.repeat(np.arange(n), cnt)
    start = np.repeat(np.cumsum(cnt) - cnt, cnt)
    m = k + 1 + (np.arange(total) - start)
    a, b = order[k], order[m]
    ok = np.all((lo[a] <= hi[b] + margin) & (lo[b] <= hi[a] + margin), axis=1)
    a, b = a[ok], b[ok]
    i, j = np.minimum(a, b), np.maximum(a, b)
    srt = np.lexsort((j, i))
    return list(zip(i[srt].tolist(), j[srt].tolist()))


def solid_boxes(solids) -> tuple[np.ndarray, np.ndarray]:
    """Bounding boxes ``(lo, hi)`` (arrays ``(n, 3)``, mm) of manifold3d solids."""
    b = np.array([np.asarray(s.bounding_box(), float) for s in solids]).reshape(-1, 6)
    return b[:, :3], b[:, 3:]


def posed_boxes(lo, hi, transforms, pad: float = 1e-6) -> tuple[np.ndarray, np.ndarray]:
    """Boxes containing the boxes ``[lo, hi]`` moved by the 4x4 ``transforms`` (one per box):
    the boxes of their eight transformed corners, grown by ``pad`` (mm) against rounding."""
    lo = np.asarray(lo, float).reshape(-1, 3)
    hi = np.asarray(hi, float).reshape(-1, 3)
    T = np.asarray(transforms, float).reshape(-1, 4, 4)
    sel = np.array([[(hi if (c >> a) & 1 else lo)[:, a] for a in range(3)] for c in range(8)])  # (8, 3, n)
    corners = np.transpose(sel, (2, 0, 1))                                                     # (n, 8, 3)
    moved = np.einsum("nij,nkj->nki", T[:, :3, :3], corners) + T[:, None, :3, 3]
    return moved.min(axis=1) - pad, moved.max(axis=1) + pad


def part_frames(asm) -> list[np.ndarray]:
    """A rest frame (4x4, mm) for each part of an assembly: its body's frame (orientation and
    position), for a joint part the frame of its two pin axes at the joint point."""
    from mlc.geometry.rotation import quat_to_matrix
    s = asm.profile.sigma_mm
    bodies = {b.name: b for b in asm.scene.bodies}
    joints = {u.part: u for u in asm.ujoints if getattr(u, "primary", True)}
    out = []
    for p in asm.parts:
        F = np.eye(4)
        if p.name in bodies:
            b = bodies[p.name]
            F[:3, :3] = quat_to_matrix(b.orientation)
            F[:3, 3] = s * np.asarray(b.position, float)
        elif p.name in joints:
            u = joints[p.name]
            a, b = np.asarray(u.axes[0], float), np.asarray(u.axes[1], float)
            a = a / np.linalg.norm(a)
            b = b - np.dot(b, a) * a
            b = b / np.linalg.norm(b)
            F[:3, :3] = np.column_stack([a, b, np.cross(a, b)])
            F[:3, 3] = u.center
        out.append(F)
    return out


def local_boxes(solids, frames) -> tuple[np.ndarray, np.ndarray]:
    """Each solid's bounding box in its own frame (an oriented box, tighter than the world box
    of a tilted slab): arrays ``(n, 3)`` of lower and upper corners in frame coordinates (mm)."""
    lo, hi = [], []
    for solid, F in zip(solids, frames):
        m = solid.to_mesh()
        V = np.asarray(m.vert_properties, float)[:, :3]
        if len(V) == 0:
            lo.append(np.full(3, np.inf))
            hi.append(np.full(3, -np.inf))
            continue
        L = (V - F[:3, 3]) @ F[:3, :3]
        lo.append(L.min(axis=0))
        hi.append(L.max(axis=0))
    return np.array(lo).reshape(-1, 3), np.array(hi).reshape(-1, 3)


def obb_overlap(pairs, frames, lo, hi, pad: float = 1e-6) -> list[tuple[int, int]]:
    """The pairs ``(i, j)`` whose oriented boxes (local boxes ``[lo, hi]`` in the 4x4 ``frames``,
    posed) are *not* separated by one of the 15 axes of the separating-axis test; boxes grown by
    ``pad`` (mm).  Only pairs that are certainly apart are dropped (separated boxes hold
    separated parts); the exact test decides the rest."""
    if not pairs:
        return []
    P = np.asarray(pairs, int)
    F = np.asarray(frames, float)
    lo = np.asarray(lo, float)
    hi = np.asarray(hi, float)
    e = 0.5 * (hi - lo) + pad
    cl = 0.5 * (hi + lo)
    c = np.einsum("nij,nj->ni", F[:, :3, :3], cl) + F[:, :3, 3]
    i, j = P[:, 0], P[:, 1]
    RA, RB = F[i, :3, :3], F[j, :3, :3]
    eA, eB = e[i], e[j]
    R = np.einsum("nki,nkj->nij", RA, RB)                  # B's axes in A's frame
    t = np.einsum("nki,nk->ni", RA, c[j] - c[i])           # B's centre in A's frame
    AR = np.abs(R) + 1e-9
    sep = np.zeros(len(P), bool)
    for k in range(3):
        sep |= np.abs(t[:, k]) > eA[:, k] + np.einsum("nj,nj->n", eB, AR[:, k, :])
        sep |= np.abs(np.einsum("ni,ni->n", t, R[:, :, k])) > np.einsum("ni,ni->n", eA, AR[:, :, k]) + eB[:, k]
    for a in range(3):
        a1, a2 = (a + 1) % 3, (a + 2) % 3
        for b in range(3):
            b1, b2 = (b + 1) % 3, (b + 2) % 3
            ra = eA[:, a1] * AR[:, a2, b] + eA[:, a2] * AR[:, a1, b]
            rb = eB[:, b1] * AR[:, a, b2] + eB[:, b2] * AR[:, a, b1]
            sep |= np.abs(t[:, a2] * R[:, a1, b] - t[:, a1] * R[:, a2, b]) > ra + rb
    ok = ~sep & np.all(np.isfinite(e[i]) & np.isfinite(e[j]), axis=1)
    return [(int(x), int(y)) for x, y in P[ok]]


def posed_pairs(Tp, frames, llo, lhi, plo, phi, margin: float = 0.0, keep=None,
                eps: float = 1e-6) -> list[tuple[int, int]]:
    """The pairs ``(i, j)`` (``i < j``) of parts moved by ``Tp`` (one 4x4 rest -> posed transform
    each) that may come within ``margin`` (mm) of each other: their posed world boxes ``plo``,
    ``phi`` (:func:`posed_boxes`) within it (:func:`box_pairs`), ``keep(i, j)`` true (None: every
    pair), and their oriented boxes (local boxes ``llo``, ``lhi`` in the rest ``frames``, posed)
    not separated with half the margin plus ``eps`` on each (:func:`obb_overlap`).  The one candidate search of
    the mesher's trims and of the states and clearance checks: only pairs certainly farther apart
    than ``margin`` are left out."""
    cand = box_pairs(plo, phi, margin)
    if keep is not None:
        cand = [ij for ij in cand if keep(*ij)]
    return obb_overlap(cand, [t @ f for t, f in zip(Tp, frames)], llo, lhi, pad=0.5 * margin + eps)


def pair_gaps(solids, Tp, pairs, search: float, posed: dict, cong=None) -> list[float]:
    """The gap (mm) of each pair ``(i, j)`` of ``pairs`` between ``solids`` moved by ``Tp``:
    manifold3d ``min_gap`` searched to ``search`` (a pair farther apart reads ``search``).
    ``posed``: the moved solids made so far, by index (filled in here, shared with the caller).
    ``cong`` (:class:`mlc.mesh.congruence.Congruence`, optional): congruent pairs in one relative
    pose are measured once, cached under ``("gap", search, shape key, shape key, relative pose)``,
    so that a trim and the check after it share their measurements."""
    def gap(i, j):
        for k in (i, j):
            if k not in posed:
                posed[k] = solids[k].transform(np.asarray(Tp[k], float)[:3, :4])
        return float(posed[i].min_gap(posed[j], search))
    if cong is None:
        return [gap(i, j) for i, j in pairs]
    rels = cong.rel_many(pairs, Tp)
    return [cong.lookup(("gap", search, cong.key(i, solids[i]), cong.key(j, solids[j]), rels[k]),
                        lambda: gap(i, j)) for k, (i, j) in enumerate(pairs)]


def posed_gaps(solids, frames, lo, hi, poses, clearance: float, eps: float = 1e-6,
               only=None) -> tuple[list, tuple | None]:
    """The gaps (mm) between solids moved into each of ``poses`` (a list of lists of 4x4 rest ->
    posed transforms, one per solid), where they come closer than ``clearance``.

    Returns ``(close, smallest)``: ``close[k]`` maps the pairs ``(i, j)`` closer than
    ``clearance - eps`` in pose ``k`` to their gap; ``smallest`` is ``(gap, i, j, k)`` of the
    smallest gap measured (None if no pair was measured).  Candidates are the pairs whose
    oriented boxes (local boxes ``[lo, hi]`` in their ``frames``, posed) come within the
    clearance.  Each is measured exactly (manifold3d ``min_gap``, searched to twice the
    clearance, or only to the clearance where it was last found at the clearance) unless a pose
    where it was measured proves it clear: a gap shrinks by at most the largest relative move of
    a point of the pair, and that move is largest at a corner of one solid's local box (the norm
    of an affine map is convex), so a pair measured at ``g`` in pose ``m`` is at least
    ``g - move`` apart in pose ``k``.  Poses along a path, in order, are measured only where the
    pair has come close.  ``only``: a set of solid indices; pairs with neither are not measured."""
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    F = np.asarray(frames, float).reshape(-1, 4, 4)
    sel = np.array([[(hi if (c >> a) & 1 else lo)[:, a] for a in range(3)] for c in range(8)])
    corners = np.einsum("nij,nkj->nki", F[:, :3, :3], np.transpose(sel, (2, 0, 1))) + F[:, None, :3, 3]
    wlo, whi = solid_boxes(solids)
    search = max(2.0 * clearance, 1e-3)
    last: dict = {}              # (i, j) -> (gap, j seen from i) where last measured
    close, smallest = [], None
    for k, Tp in enumerate(poses):
        Tp = [np.asarray(t, float) for t in Tp]
        plo, phi = posed_boxes(wlo, whi, Tp)
        pairs = posed_pairs(Tp, F, lo, hi, plo, phi, clearance,
                            None if only is None else (lambda i, j: i in only or j in only), eps)
        posed: dict = {}
        here = {}
        for i, j in pairs:
            M = np.linalg.solve(Tp[i], Tp[j])
            prev = last.get((i, j))
            if prev is not None:
                X = corners[j]
                move = float(np.linalg.norm(X @ (M[:3, :3] - prev[1][:3, :3]).T + (M[:3, 3] - prev[1][:3, 3]),
                                            axis=1).max())
                if prev[0] - move >= clearance + eps:
                    continue
            for q in (i, j):
                if q not in posed:
                    posed[q] = solids[q].transform(Tp[q][:3, :4])
            # a pair at the clearance (hinge partners: pin in hole, knuckle by knuckle, which
            # no pose changes) is asked only whether it is closer: five times faster
            near = prev is not None and prev[0] < 1.05 * clearance
            g = float(posed[i].min_gap(posed[j], clearance - eps if near else search))
            last[(i, j)] = (g, M)
            if smallest is None or g < smallest[0]:
                smallest = (g, i, j, k)
            if g < clearance - eps:
                here[(i, j)] = g
        close.append(here)
    return close, smallest


__all__ = ["box_pairs", "local_boxes", "obb_overlap", "pair_gaps", "part_frames", "posed_boxes", "posed_gaps",
           "posed_pairs", "solid_boxes"]
