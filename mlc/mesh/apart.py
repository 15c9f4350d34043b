"""An exact, cheap proof that two closed triangle meshes share no volume (mm).

The states check of the printability report (:mod:`mlc.mesh.checks`) asks manifold3d for the
intersection volume of every posed pair of parts whose boxes meet: about 0.6 ms a pair for parts
of ~1250 triangles, whatever the pair, and in a compiled circuit 99.5 % of those pairs come out
empty (``(a & b) | c``: 2985 of 3000 sampled).  :func:`surfaces_apart` proves such a pair empty
from the triangles alone, in a few tens of microseconds:

* every pair of triangles, one of each mesh, whose boxes come within ``margin`` is separated by
  more than ``margin`` along one of the axes of the separating-axis test (the two normals, the
  nine edge-edge cross products, the six in-plane edge normals); a projection onto a unit axis
  shortens distances, so the two surfaces are then more than ``margin`` apart everywhere;
* two closed surfaces apart bound solids that are either disjoint or nested, and a nested solid
  has its box inside the other's box: with neither box inside the other, the solids are disjoint,
  and manifold3d's intersection is empty (volume 0).

The proof is one-sided: ``True`` means apart (certainly); ``False`` means only that it was not
proven (the pair touches, intersects, comes within ``margin``, or one box holds the other) and
the caller computes the exact boolean.  Triangle pairs are found by a sweep along the longest
side of the overlap of the two meshes' boxes.
"""
from __future__ import annotations

import numpy as np
from numba import njit

#: mm: surfaces proven farther apart than this (far above the float64 rounding of posed
#: vertices, ~1e-13 mm, far below the report's clearances and VOL_EPS^(1/3))
MARGIN = 1e-6


@njit(cache=True)
def _tri_boxes(V, F, pad):
    m = F.shape[0]
    lo = np.empty((m, 3))
    hi = np.empty((m, 3))
    for t in range(m):
        for a in range(3):
            x0 = V[F[t, 0], a]
            x1 = V[F[t, 1], a]
            x2 = V[F[t, 2], a]
            lo[t, a] = min(x0, min(x1, x2)) - pad
            hi[t, a] = max(x0, max(x1, x2)) + pad
    return lo, hi


@njit(cache=True, inline="always")
def _gap_on(ax0, ax1, ax2, P, Q, margin):
    """True when triangles P and Q (3x3) are more than ``margin`` apart along the axis (not unit;
    degenerate axes prove nothing)."""
    n2 = ax0 * ax0 + ax1 * ax1 + ax2 * ax2
    if n2 < 1e-24:
        return False
    s = 1.0 / np.sqrt(n2)
    p0 = (P[0, 0] * ax0 + P[0, 1] * ax1 + P[0, 2] * ax2) * s
    p1 = p0
    q0 = (Q[0, 0] * ax0 + Q[0, 1] * ax1 + Q[0, 2] * ax2) * s
    q1 = q0
    for k in range(1, 3):
        p = (P[k, 0] * ax0 + P[k, 1] * ax1 + P[k, 2] * ax2) * s
        q = (Q[k, 0] * ax0 + Q[k, 1] * ax1 + Q[k, 2] * ax2) * s
        p0 = min(p0, p)
        p1 = max(p1, p)
        q0 = min(q0, q)
        q1 = max(q1, q)
    return p1 + margin < q0 or q1 + margin < p0


@njit(cache=True)
def _separated(P, Q, margin):
    """True when triangles P and Q (3x3 rows) are more than ``margin`` apart along one of the
    separating-axis candidates: the two normals, the nine edge-edge cross products, the six
    in-plane edge normals (axes normalised; degenerate axes skipped)."""
    ua = P[1] - P[0]
    va = P[2] - P[0]
    ub = Q[1] - Q[0]
    vb = Q[2] - Q[0]
    na0 = ua[1] * va[2] - ua[2] * va[1]
    na1 = ua[2] * va[0] - ua[0] * va[2]
    na2 = ua[0] * va[1] - ua[1] * va[0]
    if _gap_on(na0, na1, na2, P, Q, margin):
        return True
    nb0 = ub[1] * vb[2] - ub[2] * vb[1]
    nb1 = ub[2] * vb[0] - ub[0] * vb[2]
    nb2 = ub[0] * vb[1] - ub[1] * vb[0]
    if _gap_on(nb0, nb1, nb2, P, Q, margin):
        return True
    for i in range(3):
        e0 = P[(i + 1) % 3, 0] - P[i, 0]
        e1 = P[(i + 1) % 3, 1] - P[i, 1]
        e2 = P[(i + 1) % 3, 2] - P[i, 2]
        for j in range(3):
            f0 = Q[(j + 1) % 3, 0] - Q[j, 0]
            f1 = Q[(j + 1) % 3, 1] - Q[j, 1]
            f2 = Q[(j + 1) % 3, 2] - Q[j, 2]
            if _gap_on(e1 * f2 - e2 * f1, e2 * f0 - e0 * f2, e0 * f1 - e1 * f0, P, Q, margin):
                return True
        if _gap_on(na1 * e2 - na2 * e1, na2 * e0 - na0 * e2, na0 * e1 - na1 * e0, P, Q, margin):
            return True
    for j in range(3):
        f0 = Q[(j + 1) % 3, 0] - Q[j, 0]
        f1 = Q[(j + 1) % 3, 1] - Q[j, 1]
        f2 = Q[(j + 1) % 3, 2] - Q[j, 2]
        if _gap_on(nb1 * f2 - nb2 * f1, nb2 * f0 - nb0 * f2, nb0 * f1 - nb1 * f0, P, Q, margin):
            return True
    return False


@njit(cache=True)
def _apart(VA, FA, VB, FB, margin):
    # boxes of the whole meshes; nested boxes: no proof (one solid could hold the other)
    alo = np.empty(3)
    ahi = np.empty(3)
    blo = np.empty(3)
    bhi = np.empty(3)
    for a in range(3):
        alo[a] = VA[:, a].min()
        ahi[a] = VA[:, a].max()
        blo[a] = VB[:, a].min()
        bhi[a] = VB[:, a].max()
    a_in_b = True
    b_in_a = True
    for a in range(3):
        if alo[a] < blo[a] or ahi[a] > bhi[a]:
            a_in_b = False
        if blo[a] < alo[a] or bhi[a] > ahi[a]:
            b_in_a = False
    if a_in_b or b_in_a:
        return False
    olo = np.empty(3)
    ohi = np.empty(3)
    for a in range(3):
        olo[a] = max(alo[a], blo[a]) - margin
        ohi[a] = min(ahi[a], bhi[a]) + margin
        if olo[a] > ohi[a]:
            return True         # the boxes are apart
    tla, tha = _tri_boxes(VA, FA, margin)
    tlb, thb = _tri_boxes(VB, FB, 0.0)
    # triangles whose box meets the overlap region
    ia = np.empty(FA.shape[0], np.int64)
    na = 0
    for t in range(FA.shape[0]):
        ok = True
        for a in range(3):
            if tla[t, a] > ohi[a] or tha[t, a] < olo[a]:
                ok = False
        if ok:
            ia[na] = t
            na += 1
    ib = np.empty(FB.shape[0], np.int64)
    nb = 0
    size = 0.0
    for t in range(FB.shape[0]):
        ok = True
        for a in range(3):
            if tlb[t, a] > ohi[a] or thb[t, a] < olo[a]:
                ok = False
        if ok:
            ib[nb] = t
            nb += 1
            for a in range(3):
                size += thb[t, a] - tlb[t, a]
    if na == 0 or nb == 0:
        return True
    # sweep along the axis of the overlap's longest side: B's triangles sorted by their low end;
    # the B boxes that can meet an A box start within [lo_A - widest B box, hi_A]
    ax = 0
    for a in range(1, 3):
        if ohi[a] - olo[a] > ohi[ax] - olo[ax]:
            ax = a
    keys = np.empty(nb)
    wide = 0.0
    for k in range(nb):
        keys[k] = tlb[ib[k], ax]
        wide = max(wide, thb[ib[k], ax] - tlb[ib[k], ax])
    order = np.argsort(keys)
    sb = ib[order]
    sk = keys[order]
    # unit normals and plane offsets (for the first two axes, the cheap ones)
    nA = _normals(VA, FA, ia[:na])
    nB = _normals(VB, FB, ib[:nb])
    P = np.empty((3, 3))
    Q = np.empty((3, 3))
    for k in range(na):
        s = ia[k]
        r0 = np.searchsorted(sk, tla[s, ax] - wide)
        r1 = np.searchsorted(sk, tha[s, ax], side="right")
        for r in range(r0, r1):
            t = sb[r]
            if (tla[s, 0] > thb[t, 0] or tha[s, 0] < tlb[t, 0] or tla[s, 1] > thb[t, 1]
                    or tha[s, 1] < tlb[t, 1] or tla[s, 2] > thb[t, 2] or tha[s, 2] < tlb[t, 2]):
                continue
            # B's triangle on one side of A's plane, or A's on one side of B's
            if nA[s, 3] > 0.0:
                d0 = VB[FB[t, 0], 0] * nA[s, 0] + VB[FB[t, 0], 1] * nA[s, 1] + VB[FB[t, 0], 2] * nA[s, 2] - nA[s, 4]
                d1 = VB[FB[t, 1], 0] * nA[s, 0] + VB[FB[t, 1], 1] * nA[s, 1] + VB[FB[t, 1], 2] * nA[s, 2] - nA[s, 4]
                d2 = VB[FB[t, 2], 0] * nA[s, 0] + VB[FB[t, 2], 1] * nA[s, 1] + VB[FB[t, 2], 2] * nA[s, 2] - nA[s, 4]
                if (d0 > margin and d1 > margin and d2 > margin) or (d0 < -margin and d1 < -margin and d2 < -margin):
                    continue
            if nB[t, 3] > 0.0:
                d0 = VA[FA[s, 0], 0] * nB[t, 0] + VA[FA[s, 0], 1] * nB[t, 1] + VA[FA[s, 0], 2] * nB[t, 2] - nB[t, 4]
                d1 = VA[FA[s, 1], 0] * nB[t, 0] + VA[FA[s, 1], 1] * nB[t, 1] + VA[FA[s, 1], 2] * nB[t, 2] - nB[t, 4]
                d2 = VA[FA[s, 2], 0] * nB[t, 0] + VA[FA[s, 2], 1] * nB[t, 1] + VA[FA[s, 2], 2] * nB[t, 2] - nB[t, 4]
                if (d0 > margin and d1 > margin and d2 > margin) or (d0 < -margin and d1 < -margin and d2 < -margin):
                    continue
            for i in range(3):
                for a in range(3):
                    P[i, a] = VA[FA[s, i], a]
                    Q[i, a] = VB[FB[t, i], a]
            if not _separated(P, Q, margin):
                return False
    return True


@njit(cache=True)
def _normals(V, F, which):
    """Per triangle of ``which`` (rows of the others stay 0): unit normal (3), 1 where it is
    defined else 0, plane offset n . v0 (mm)."""
    out = np.zeros((F.shape[0], 5))
    for t in which:
        u0 = V[F[t, 1], 0] - V[F[t, 0], 0]
        u1 = V[F[t, 1], 1] - V[F[t, 0], 1]
        u2 = V[F[t, 1], 2] - V[F[t, 0], 2]
        v0 = V[F[t, 2], 0] - V[F[t, 0], 0]
        v1 = V[F[t, 2], 1] - V[F[t, 0], 1]
        v2 = V[F[t, 2], 2] - V[F[t, 0], 2]
        n0 = u1 * v2 - u2 * v1
        n1 = u2 * v0 - u0 * v2
        n2 = u0 * v1 - u1 * v0
        L = np.sqrt(n0 * n0 + n1 * n1 + n2 * n2)
        if L > 1e-12:
            out[t, 0] = n0 / L
            out[t, 1] = n1 / L
            out[t, 2] = n2 / L
            out[t, 3] = 1.0
            out[t, 4] = (n0 * V[F[t, 0], 0] + n1 * V[F[t, 0], 1] + n2 * V[F[t, 0], 2]) / L
    return out


def surfaces_apart(VA, FA, VB, FB, margin: float = MARGIN) -> bool:
    """True when the closed meshes A and B (vertices (n, 3) in mm, triangles (m, 3)) certainly
    share no volume: their surfaces are more than ``margin`` mm apart and neither box holds the
    other.  False: not proven (see the module docstring)."""
    return bool(_apart(np.ascontiguousarray(VA, np.float64), np.ascontiguousarray(FA, np.int64),
                       np.ascontiguousarray(VB, np.float64), np.ascontiguousarray(FB, np.int64), float(margin)))


def mesh_arrays(solid, cache: dict | None = None):
    """Vertices (n, 3, float64, mm) and triangles (m, 3, int64) of a manifold3d solid; ``cache``
    (a dict) keeps them per solid object for the caller's lifetime of that dict."""
    if cache is not None:
        got = cache.get(id(solid))
        if got is not None and got[0] is solid:
            return got[1]
    m = solid.to_mesh64()
    out = (np.asarray(m.vert_properties, float)[:, :3], np.asarray(m.tri_verts, np.int64))
    if cache is not None:
        cache[id(solid)] = (solid, out)
    return out


def min_gap(a, b, search: float, cache: dict | None = None) -> float:
    """``a.min_gap(b, search)`` of manifold3d (mm): the gap up to ``search``, and ``search`` itself
    when nothing comes closer.  Answered ``search`` without manifold3d when the triangles prove the
    surfaces more than ``search`` apart and neither box holds the other (nested solids have gap 0
    in manifold3d; they go to manifold3d): a third of a millisecond against two (``(a & b) | c``:
    571 of the 572 box-near pairs at least 2 x clearance apart proven, none wrongly)."""
    if search > 0 and surfaces_apart(*mesh_arrays(a, cache), *mesh_arrays(b, cache), margin=search):
        return float(search)
    return float(a.min_gap(b, search))


__all__ = ["MARGIN", "mesh_arrays", "min_gap", "surfaces_apart"]
