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
exact tests (manifold3d ``min_gap``, intersection volume) decide.
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


__all__ = ["box_pairs", "posed_boxes", "solid_boxes"]
