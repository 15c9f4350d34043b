"""Wall thickness of the finished solids, measured on a voxel grid and the surface itself (mm).

The nominal sizes of the design (slab thickness, knuckle wall) say nothing about what the
trims leave: a cut that clears another part can leave a web thinner than the printer's
minimum wall.  This module measures it on the solid itself, by a morphological *opening*
with a ball of diameter ``min_wall`` (the union of every such ball that fits inside the part):

1. the part is voxelised (cell ``h``; a cell is inside when its centre is);
2. the Euclidean distance transform gives, for each inside cell, about the radius of the largest
   ball centred there that stays inside (to the nearest outside cell centre: at least the
   distance to the surface, at most about two cells more);
3. the ball centres: a cell two cells deeper than ``r = min_wall / 2`` is one; a cell near that
   depth is measured from the surface (session 37; :class:`_Surface`: since session 38 the exact
   distance to the nearest triangle, through a bounding volume hierarchy compiled by Numba), and
   is one when a ball of radius
   ``r (1 - WALL_TOL)`` fits within a few cells of it (:func:`_ball`: from the cell, along the
   line away from the nearest surface point to where the distances to the two sides meet,
   three times: a plate's mid-plane, a square bar's axis).  Only the cells that can decide a
   thin region are measured (those near cells farther than the corner rounding from what the
   deep cells' balls cover);
4. the cells covered by a ball of radius ``r`` centred at a ball centre are the part "at least
   ``min_wall`` thick"; the rest is thinner;
5. every connected region of the rest that reaches deeper than the rounding a ball leaves at a
   right-angled edge (``(sqrt 3 - 1) r``, plus a cell) and holds more than ``r**3`` of material
   is a thin wall.  Its thickness is twice the largest ball centred in it (measured as in 3);
   its thinnest spot is the middle of the shortest chord through it (from a cell of the region
   farther than that rounding from the thick part, along the line away from its nearest surface
   point to the surface beyond: :func:`_chords`), and the chord's length is ``thinnest_mm``.

The distance transforms are only ever compared with lengths of a few cells (``r``, the
corner rounding), so they are computed exactly up to a few cells and no further
(:func:`_edt_upto`: the squared Euclidean distance is separable, a minimum over offsets
along each axis in turn; every distance up to the bound is the exact one, anything further
only known to be further): the same cells and the same thicknesses as scipy's full transform,
about 5 times faster.

Resolution: ``h = min_wall / 8`` by default.  Until session 37 the ball centres were the cells
within half a cell of ``r`` on the grid alone: a plate of ``min_wall`` or ``0.92 min_wall``
always passed, one of ``0.72 min_wall`` or less always failed, and in between it depended on the
grid (the 0.547 mm web of the expanding OR at mjp passed).  Session 37 measured them from samples
of the surface (a wall measured up to 0.0024 mm thicker than it is at mjp).  Now
(tests/test_mesh_walls.py, tests/test_mesh_print.py, plates and webs at random offsets and
angles) a wall 0.001 mm over ``(1 - WALL_TOL) min_wall`` passes and one 0.001 mm under it fails
(mjp: the pass mark is 0.591 mm), its thickness measured within 0.0005 mm.  ``WALL_TOL`` (1.5 %)
is for the facets of round features: a knuckle's ring drawn as a 32-gon is up to 1.3 % under its
nominal 0.6 mm wall at mjp.

Time: the surface samples and their k-d tree (session 37) made the measure about 10 times the
grid-only one; the exact distances (a query of about 2 microseconds, most of the time left) make
it 4 to 5 times faster again, the same parts measured by both in one run (``python
benchmarks/mesh_walls_speed.py``, ``benchmarks/results/mesh_walls_speed_s38.json``: a NAND's nine
parts at mjp 3.74 -> 0.69 s, every tenth part of the Tetris circuit 195 -> 45 s).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numba import njit, prange


#: cells of the largest grid measured at once (memory: about 40 bytes a cell during the transforms)
MAX_CELLS = 6e6


@dataclass
class ThinWall:
    part: str
    thickness_mm: float      # twice the largest ball that fits in the thin region
    volume_mm3: float        # material in the thin region
    where_mm: tuple          # the thinnest spot of the region: the middle of its shortest chord (print frame)
    thinnest_mm: float | None = None     # that chord's length: the wall's thickness at its thinnest
    # the centres (mm, (N, 3)) of its cells farther from the thick part than a ball's rounding at an
    # edge (those that make it a thin wall; its cells nearer the thick part can be a skin along a
    # face the grid's cells sit on), and the cell size (mm)
    cells: np.ndarray | None = field(default=None, repr=False, compare=False)
    h: float = 0.0

    def text(self, min_wall: float) -> str:
        x, y, z = self.where_mm
        at = f", {self.thinnest_mm:.2f} mm at its thinnest" if self.thinnest_mm is not None else ""
        return (f"{self.part}: wall {self.thickness_mm:.2f} mm < {min_wall:g} mm over {self.volume_mm3:.3g} mm^3{at} "
                f"near ({x:.1f}, {y:.1f}, {z:.1f}) mm")


def voxelize(solid, h: float):
    """Inside cells of a manifold on a grid of spacing ``h``: (bool array [ix, iy, iz], origin)
    where cell (i, j, k) has its centre at ``origin + h * (i, j, k)``."""
    from mlc.mesh.printability import _mesh_arrays, _raster

    V, F = _mesh_arrays(solid)
    lo = V.min(0) - 2 * h
    hi = V.max(0) + 2 * h
    n = np.ceil((hi - lo) / h).astype(int) + 1
    A, B, C = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]
    nz = np.cross(B - A, C - A)[:, 2]
    keep = np.abs(nz) > 1e-14
    # _raster puts cell centres at lo + (i + 0.5) h: shift so they land on lo + i h
    col, z, sgn, _ = _raster(A[keep], B[keep], C[keep], lo[:2] - 0.5 * h, h)
    grid = np.zeros(n, bool)
    if len(z) == 0:
        return grid, lo
    key = col[:, 1] * (n[0] + 2) + col[:, 0]
    order = np.lexsort((z, key))
    key, z, sgn, col = key[order], z[order], sgn[order], col[order]
    # in each column, material runs from a downward face (entering, going up) to the next upward one
    enter = (sgn < 0)
    nxt_same = np.zeros(len(key), bool)
    nxt_same[:-1] = key[:-1] == key[1:]
    start = np.nonzero(enter & nxt_same)[0]
    start = start[sgn[start + 1] > 0]
    if len(start) == 0:       # a sliver no column centre crosses
        return grid, lo
    z0, z1 = z[start], z[start + 1]
    k0 = np.ceil((z0 - lo[2]) / h).astype(int)
    k1 = np.floor((z1 - lo[2]) / h).astype(int)
    cnt = np.maximum(k1 - k0 + 1, 0)
    rep = np.repeat(np.arange(len(start)), cnt)
    off = np.arange(cnt.sum()) - np.repeat(np.concatenate([[0], np.cumsum(cnt)[:-1]]), cnt)
    ix, iy = col[start][rep, 0], col[start][rep, 1]
    iz = k0[rep] + off
    ok = (ix >= 0) & (ix < n[0]) & (iy >= 0) & (iy < n[1]) & (iz >= 0) & (iz < n[2])
    grid[ix[ok], iy[ok], iz[ok]] = True
    return grid, lo


#: squared distance (cells^2) standing for "further than the bound" in :func:`_edt_upto`
_FAR = 1 << 20
_FAR_16 = 30000


def _edt_upto(mask: np.ndarray, R: int) -> np.ndarray:
    """Euclidean distance (in cells) from each cell of ``mask`` to the nearest False cell of the
    array, exact wherever it is at most ``R`` cells, and more than ``R`` (not exact) elsewhere.

    Same values as ``scipy.ndimage.distance_transform_edt`` up to ``R`` (the square root of an
    integer sum of squares) for an array that has a False cell: the squared distance is
    ``min over offsets (dx^2 + dy^2 + dz^2)``, a minimum along x, then y, then z, and a False cell
    within ``R`` has each offset within ``R``."""
    # int16 while the bound's squares fit beside _FAR_16 (half the memory traffic), else int32
    far, dt = (_FAR_16, np.int16) if _FAR_16 + 3 * R * R < 32000 else (_FAR, np.int32)
    f = np.where(mask, far, 0).astype(dt)
    for ax in range(3):
        n = f.shape[ax]
        out = f.copy()
        for d in range(1, min(R, n - 1) + 1):
            a = [slice(None)] * 3
            b = [slice(None)] * 3
            a[ax], b[ax] = slice(d, None), slice(None, n - d)
            a, b = tuple(a), tuple(b)
            np.minimum(out[a], f[b] + dt(d * d), out=out[a])
            np.minimum(out[b], f[a] + dt(d * d), out=out[b])
        f = out
    return np.sqrt(np.minimum(f, far).astype(float))


#: a wall passes from ``(1 - WALL_TOL) * min_wall``: the facets of a round feature drawn as an
#: n-gon (its radius at the corners, a cutter's at the flats) take up to ``(R + r)(1 - cos pi/n)``
#: of a ring's wall (mjp's knuckles, 32 segments: 0.0077 mm, 1.3 % of its 0.6 mm)
WALL_TOL = 0.015
#: a thin region's thinnest spot is looked for among at most this many of its cells
MAX_CHORDS = 1000
#: triangles in a leaf of the bounding volume hierarchy of :func:`_bvh_build`
LEAF = 4


@njit(cache=True)
def _bvh_build(V, F):
    """A bounding volume hierarchy of the triangles ``F`` of ``V``: a node's box holds its
    triangles; a node splits them at the median of their centroids along the longest side of
    the centroids' box, down to ``LEAF`` triangles.  (node boxes lo, hi, left and right child
    (-1: a leaf), first triangle and count of a leaf in ``perm``, perm)."""
    m = F.shape[0]
    tlo = np.empty((m, 3))
    thi = np.empty((m, 3))
    cen = np.empty((m, 3))
    for t in range(m):
        for a in range(3):
            x0 = V[F[t, 0], a]
            x1 = V[F[t, 1], a]
            x2 = V[F[t, 2], a]
            tlo[t, a] = min(x0, x1, x2)
            thi[t, a] = max(x0, x1, x2)
            cen[t, a] = (x0 + x1 + x2) / 3.0
    perm = np.arange(m)
    cap = 2 * m + 1
    nlo = np.empty((cap, 3))
    nhi = np.empty((cap, 3))
    left = np.full(cap, -1, np.int64)
    right = np.full(cap, -1, np.int64)
    start = np.zeros(cap, np.int64)
    count = np.zeros(cap, np.int64)
    stack = np.empty((cap, 3), np.int64)
    sp = 0
    stack[0, 0], stack[0, 1], stack[0, 2] = 0, 0, m
    sp = 1
    nn = 1
    while sp > 0:
        sp -= 1
        node, s, e = stack[sp, 0], stack[sp, 1], stack[sp, 2]
        clo = np.full(3, np.inf)
        chi = np.full(3, -np.inf)
        for a in range(3):
            nlo[node, a] = np.inf
            nhi[node, a] = -np.inf
        for k in range(s, e):
            t = perm[k]
            for a in range(3):
                nlo[node, a] = min(nlo[node, a], tlo[t, a])
                nhi[node, a] = max(nhi[node, a], thi[t, a])
                clo[a] = min(clo[a], cen[t, a])
                chi[a] = max(chi[a], cen[t, a])
        if e - s <= LEAF:
            start[node], count[node] = s, e - s
            continue
        ax = 0
        for a in range(1, 3):
            if chi[a] - clo[a] > chi[ax] - clo[ax]:
                ax = a
        sub = perm[s:e].copy()
        order = np.argsort(cen[sub, ax])
        perm[s:e] = sub[order]
        mid = (s + e) // 2
        l, r = nn, nn + 1
        nn += 2
        left[node], right[node] = l, r
        stack[sp, 0], stack[sp, 1], stack[sp, 2] = l, s, mid
        sp += 1
        stack[sp, 0], stack[sp, 1], stack[sp, 2] = r, mid, e
        sp += 1
    return nlo[:nn].copy(), nhi[:nn].copy(), left[:nn].copy(), right[:nn].copy(), start[:nn].copy(), count[:nn].copy(), perm


@njit(cache=True, inline='always')
def _closest(px, py, pz, ax, ay, az, bx, by, bz, cx, cy, cz):
    """Closest point of triangle abc to p (Ericson, Real-Time Collision Detection 5.1.5)."""
    abx, aby, abz = bx - ax, by - ay, bz - az
    acx, acy, acz = cx - ax, cy - ay, cz - az
    apx, apy, apz = px - ax, py - ay, pz - az
    d1 = abx * apx + aby * apy + abz * apz
    d2 = acx * apx + acy * apy + acz * apz
    if d1 <= 0.0 and d2 <= 0.0:
        return ax, ay, az
    bpx, bpy, bpz = px - bx, py - by, pz - bz
    d3 = abx * bpx + aby * bpy + abz * bpz
    d4 = acx * bpx + acy * bpy + acz * bpz
    if d3 >= 0.0 and d4 <= d3:
        return bx, by, bz
    vc = d1 * d4 - d3 * d2
    if vc <= 0.0 and d1 >= 0.0 and d3 <= 0.0:
        v = d1 / (d1 - d3) if d1 - d3 > 0.0 else 0.0
        return ax + v * abx, ay + v * aby, az + v * abz
    cpx, cpy, cpz = px - cx, py - cy, pz - cz
    d5 = abx * cpx + aby * cpy + abz * cpz
    d6 = acx * cpx + acy * cpy + acz * cpz
    if d6 >= 0.0 and d5 <= d6:
        return cx, cy, cz
    vb = d5 * d2 - d1 * d6
    if vb <= 0.0 and d2 >= 0.0 and d6 <= 0.0:
        w = d2 / (d2 - d6) if d2 - d6 > 0.0 else 0.0
        return ax + w * acx, ay + w * acy, az + w * acz
    va = d3 * d6 - d5 * d4
    if va <= 0.0 and (d4 - d3) >= 0.0 and (d5 - d6) >= 0.0:
        s_ = (d4 - d3) + (d5 - d6)
        w = (d4 - d3) / s_ if s_ > 0.0 else 0.0
        return bx + w * (cx - bx), by + w * (cy - by), bz + w * (cz - bz)
    if not va + vb + vc > 0.0:       # a degenerate (zero-area) triangle: its vertex a
        return ax, ay, az
    den = 1.0 / (va + vb + vc)
    v = vb * den
    w = vc * den
    return ax + abx * v + acx * w, ay + aby * v + acy * w, az + abz * v + acz * w


#: points per block of :func:`_nearest`: the blocks run in parallel, the points of a block in
#: order (a fixed size: the same results whatever the thread count)
NEAR_BLOCK = 64


@njit(cache=True, parallel=True)
def _nearest(P, V, F, N, nlo, nhi, left, right, start, count, perm):
    """For each row of P: distance to the mesh, nearest point, and the triangle whose plane
    is farthest among those at that distance (the one whose normal tells the side).  Blocks
    of ``NEAR_BLOCK`` points run in parallel threads."""
    n = P.shape[0]
    D = np.empty(n)
    Q = np.empty((n, 3))
    T = np.empty(n, np.int64)
    nblk = (n + NEAR_BLOCK - 1) // NEAR_BLOCK
    for blk in prange(nblk):
        _nearest_block(blk * NEAR_BLOCK, min(n, (blk + 1) * NEAR_BLOCK), P, V, F, N, nlo, nhi,
                       left, right, start, count, perm, D, Q, T)
    return D, Q, T


@njit(cache=True)
def _nearest_block(i0, i1, P, V, F, N, nlo, nhi, left, right, start, count, perm, D, Q, T):
    """:func:`_nearest` for the points ``i0 <= i < i1``, in order."""
    stack = np.empty(256, np.int64)
    for i in range(i0, i1):
        px, py, pz = P[i, 0], P[i, 1], P[i, 2]
        best = np.inf
        bq0 = bq1 = bq2 = np.nan
        bt = -1
        bplane = -1.0
        if i > i0:      # the previous point's nearest triangle first (the points come in runs of
            t = T[i - 1]    # neighbours): a tight bound from the start, the same result
            a, b, c = F[t, 0], F[t, 1], F[t, 2]
            qx, qy, qz = _closest(px, py, pz, V[a, 0], V[a, 1], V[a, 2], V[b, 0], V[b, 1], V[b, 2],
                                  V[c, 0], V[c, 1], V[c, 2])
            ex, ey, ez = px - qx, py - qy, pz - qz
            best = ex * ex + ey * ey + ez * ez
            bq0, bq1, bq2, bt = qx, qy, qz, t
            bplane = abs(ex * N[t, 0] + ey * N[t, 1] + ez * N[t, 2])
        sp = 0
        stack[0] = 0
        sp = 1
        while sp > 0:
            sp -= 1
            node = stack[sp]
            dx = max(nlo[node, 0] - px, 0.0, px - nhi[node, 0])
            dy = max(nlo[node, 1] - py, 0.0, py - nhi[node, 1])
            dz = max(nlo[node, 2] - pz, 0.0, pz - nhi[node, 2])
            if dx * dx + dy * dy + dz * dz > best * (1.0 + 1e-9) + 1e-24:
                continue
            if left[node] < 0:
                for k in range(start[node], start[node] + count[node]):
                    t = perm[k]
                    a, b, c = F[t, 0], F[t, 1], F[t, 2]
                    qx, qy, qz = _closest(px, py, pz, V[a, 0], V[a, 1], V[a, 2], V[b, 0], V[b, 1], V[b, 2],
                                          V[c, 0], V[c, 1], V[c, 2])
                    ex, ey, ez = px - qx, py - qy, pz - qz
                    d2 = ex * ex + ey * ey + ez * ez
                    pl = abs(ex * N[t, 0] + ey * N[t, 1] + ez * N[t, 2])
                    if d2 < best * (1.0 - 1e-9) - 1e-24 or (d2 <= best * (1.0 + 1e-9) + 1e-24 and pl > bplane):
                        if d2 < best:
                            best = d2
                        bq0, bq1, bq2, bt, bplane = qx, qy, qz, t, pl
            else:
                l, r = left[node], right[node]
                # the nearer child on top of the stack
                dl = 0.0
                dr = 0.0
                for a in range(3):
                    u = max(nlo[l, a] - P[i, a], 0.0, P[i, a] - nhi[l, a])
                    dl += u * u
                    u = max(nlo[r, a] - P[i, a], 0.0, P[i, a] - nhi[r, a])
                    dr += u * u
                if dl < dr:
                    stack[sp] = r
                    stack[sp + 1] = l
                else:
                    stack[sp] = l
                    stack[sp + 1] = r
                sp += 2
        D[i] = np.sqrt(best)
        Q[i, 0], Q[i, 1], Q[i, 2] = bq0, bq1, bq2
        T[i] = bt


class _Surface:
    """Distance to the surface of a solid (mm): the exact distance to its nearest triangle
    (:func:`_nearest`, a bounding volume hierarchy of the triangles, compiled by Numba).
    Session 37 took the nearest of samples of the triangles at most half a cell apart (a k-d
    tree; up to 0.0012 mm more than the distance at mjp), 2 to 7 microseconds a query."""

    def __init__(self, V, F, grid, lo, h):
        V = np.ascontiguousarray(V, float)
        F = np.ascontiguousarray(F, np.int64)
        N = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
        N /= np.maximum(np.linalg.norm(N, axis=1), 1e-300)[:, None]
        self.V, self.F, self.N = V, F, N
        self.bvh = _bvh_build(V, F) if len(F) else None
        self.grid, self.lo, self.h = grid, lo, h
        #: a point closer to the surface than this is not moved off it (its direction is unsure)
        self.rho = 1e-6 * h

    def _near(self, P):
        return _nearest(np.ascontiguousarray(P, float), self.V, self.F, self.N, *self.bvh)

    def query(self, P):
        """(distance, nearest surface point) for each row of ``P``."""
        if self.bvh is None:
            return np.full(len(P), np.inf), np.full_like(P, np.nan)
        d, Q, _ = self._near(P)
        return d, Q

    def inside(self, P):
        """(distance, nearest surface point, whether the point is inside: behind the nearest
        triangle's face, of those at that distance the one whose plane is farthest; a point on
        the surface, or past it, has distance 0)."""
        if self.bvh is None:
            return np.full(len(P), np.inf), np.full_like(P, np.nan), np.ones(len(P), bool)
        d, Q, T = self._near(P)
        ins = np.einsum("ij,ij->i", P - Q, self.N[T]) < 0
        # (and in an inside cell, as before)
        ijk = np.rint((P - self.lo) / self.h).astype(np.int64)
        ok = np.all((ijk >= 0) & (ijk < np.asarray(self.grid.shape)), axis=1)
        ins &= ok
        ins[ok] &= self.grid[ijk[ok, 0], ijk[ok, 1], ijk[ok, 2]]
        return np.where(ins, d, 0.0), Q, ins


def _ball(surf: _Surface, P, h, need=None, rounds=3):
    """The largest ball radius found near each point of ``P`` (mm), and its centre: the distance
    at the point, then along the line away from the nearest surface point, where the distances
    to the faces on either side meet (for a plate, its mid-plane: one distance a cell further on,
    then one where the two slopes cross); again from there, ``rounds`` times (a bar of square
    section: its middle across, then along the other side).  A point past the surface (behind
    no face) does not count.  ``need`` (mm): only whether a ball of that radius is found
    matters: a point is measured no further once it has one, or once it is more than a cell
    short of it."""
    D, Fc, _ = surf.inside(P)       # (and the nearest surface point of each centre so far)
    C = P.copy()
    for _ in range(rounds):
        # (from a point within a hair of the surface, the direction away from it is unsure:
        # not moved)
        go = D > 2 * surf.rho if need is None else (D > 2 * surf.rho) & (D < need) & (D + h >= need)
        if not go.any():
            break
        idx = np.flatnonzero(go)
        X = C[idx]
        D0, F0 = D[idx], Fc[idx]        # (inside: its distance is the distance to F0)
        u = (X - F0) / np.maximum(D0, 1e-12)[:, None]
        P1 = X + h * u
        D1, F1, _ = surf.inside(P1)
        sm = np.clip(0.5 * (D1 - D0 + h), 0.0, h)
        Ps = X + sm[:, None] * u
        Ds, Fs, _ = surf.inside(Ps)
        moved = False
        for Dn, Pn, Fn in ((D1, P1, F1), (Ds, Ps, Fs)):
            better = Dn > D[idx] + 1e-9
            D[idx[better]], C[idx[better]], Fc[idx[better]] = Dn[better], Pn[better], Fn[better]
            moved |= bool(better.any())
        if not moved:
            break
    return D, C


def _chords(surf: _Surface, P, limit, eps):
    """The chord through each point of ``P`` along the line from its nearest surface point:
    (length, middle) (mm); the far end found by steps of the distance to the surface (never past
    it), stopped within ``eps`` of it and the last step added (the exact distance: a face square
    to the chord is reached to float rounding); ``inf`` where it is not reached within ``limit``."""
    D0, F0 = surf.query(P)
    u = (P - F0) / np.maximum(D0, 1e-12)[:, None]
    s = np.zeros(len(P))
    alive = np.ones(len(P), bool)
    for _ in range(80):
        if not alive.any():
            break
        X = P[alive] + s[alive, None] * u[alive]
        d, Fx = surf.query(X)
        # arrived: within eps of the surface, and the nearest surface ahead (not the near face),
        # or on it
        ahead = np.einsum("ij,ij->i", Fx - X, u[alive]) > 0
        there = (d <= eps) & (ahead | (d <= 1e-9))
        s[alive] += np.where(there, d, np.maximum(d, eps))
        alive[alive] = ~there & (s[alive] < limit)
    w = np.where(s < limit, D0 + s, np.inf)
    mid = P + (0.5 * (s - D0))[:, None] * u
    return w, mid


def thin_walls(name: str, solid, min_wall: float, h: float | None = None) -> list[ThinWall]:
    """The regions of ``solid`` thinner than ``min_wall`` (mm), measured on a voxel grid, the
    ball centres near the threshold placed to within the sampling error (:class:`_Surface`)."""
    from scipy import ndimage
    from mlc.mesh.printability import _mesh_arrays

    pieces = solid.decompose()
    if len(pieces) > 1:       # each piece on its own grid (pieces far apart would make one huge grid)
        return [w for piece in pieces for w in thin_walls(name, piece, min_wall, h)]
    h = h or min_wall / 8
    bb = np.asarray(solid.bounding_box(), float)
    cells = float(np.prod((bb[3:] - bb[:3]) / h + 5))
    if cells > MAX_CELLS:     # a very large part: a coarser grid (less exact), bounded memory
        h *= (cells / MAX_CELLS) ** (1 / 3)
    grid, lo = voxelize(solid, h)
    if not grid.any():
        return []
    V, F = _mesh_arrays(solid)
    r = min_wall / 2
    edge = (np.sqrt(3) - 1) * r + 1.01 * h     # the rounding a ball leaves in a box corner, plus a cell
    # every distance below is compared with r or edge only (and a thin cell's depth is under r):
    # exact up to a bound past both is all it takes
    R = int(np.ceil(max(r, edge) / h)) + 3
    surf = None       # the surface (exact distances), built when first needed
    # distance from each inside cell centre to the nearest outside cell centre: at least the
    # distance to the surface (the segment crosses it), at most about two cells more
    depth = _edt_upto(grid, R) * h
    # the ball centres: a cell two cells deeper than r is one; a cell within a cell's half diagonal
    # of r, or above it, is measured: the largest ball within its cell, from the surface itself
    # (the grid alone passed or failed a wall between 0.72 and 0.92 min_wall with its position)
    centres = depth >= r + 2 * h
    band = grid & ~centres & (depth >= r - 0.87 * h)
    if band.any():
        # only where it can matter: a thin region is reported for its cells farther than the
        # corner rounding from the thick part, and that part only grows with the measured
        # centres: the band cells within r of a cell that far from what the sure centres cover
        cov = (_edt_upto(~centres, R) * h <= r + 1e-9) & grid if centres.any() else np.zeros_like(grid)
        far = grid & ~cov & ((_edt_upto(~cov, R) * h > edge) if cov.any() else True)
        # (a cell near one of those is covered by a ball up to r + the corner rounding away)
        band &= (_edt_upto(~far, int(np.ceil((r + edge + h) / h)) + 1) * h <= r + edge + h) if far.any() else False
    if band.any():
        surf = surf or _Surface(V, F, grid, lo, h)
        ib = np.argwhere(band)
        D, _ = _ball(surf, lo + h * ib, h, r * (1 - WALL_TOL))
        ok = D >= r * (1 - WALL_TOL)
        centres[tuple(ib[ok].T)] = True
    if centres.any():
        covered = (_edt_upto(~centres, R) * h <= r + 1e-9) & grid
    else:     # no ball fits anywhere: scipy's transform of an array with no zero, as it always was
        covered = (ndimage.distance_transform_edt(~centres) * h <= r + 1e-9) & grid
    rest = grid & ~covered
    if not rest.any():
        return []
    # how far a thin cell is from the thick part (a part with no thick part at all is all thin)
    away = _edt_upto(~covered, R) * h if covered.any() else np.full(grid.shape, np.inf)
    # the regions, labelled in the box of the thin cells only (the same regions: no thin cell
    # lies outside it); per-region maxima and counts over the thin cells alone
    box = tuple(slice(int(a.min()), int(a.max()) + 1) for a in np.nonzero(rest))
    labels, nlab = ndimage.label(rest[box], structure=np.ones((3, 3, 3)))
    out = []
    if nlab == 0:
        return out
    sel = labels > 0
    lab = labels[sel]
    idx = np.arange(1, nlab + 1)
    deep = np.full(nlab + 1, -np.inf)
    np.maximum.at(deep, lab, away[box][sel])
    thick = np.full(nlab + 1, -np.inf)
    np.maximum.at(thick, lab, depth[box][sel])
    size = np.bincount(lab, minlength=nlab + 1).astype(float) * h ** 3
    corner = np.array([b.start for b in box])
    found = [(k, v, t) for k, d, v, t in zip(idx, deep[1:], size[1:], thick[1:]) if d > edge and v > r ** 3]
    if not found:
        return out
    # the thickness and the thinnest spot of each thin region, from the surface itself
    surf = surf or _Surface(V, F, grid, lo, h)
    rng = np.random.default_rng(0)
    for k, v, t in found:
        cells = np.argwhere(labels == k) + corner
        q = depth[tuple(cells.T)]
        # its thickness: twice the largest ball in it (the cells within two cells of the deepest)
        top = cells[q >= t - 2 * h]
        D, Cb = _ball(surf, lo + h * top, h)
        # (a centre moved out of the region, into the thick part next to it, does not count)
        ijk = np.rint((Cb - lo) / h).astype(np.int64) - corner
        ok = np.all((ijk >= 0) & (ijk < np.asarray(labels.shape)), axis=1)
        ok[ok] &= labels[ijk[ok, 0], ijk[ok, 1], ijk[ok, 2]] == k
        D = np.where(ok, D, surf.inside(lo + h * top)[0])
        thickness = float(2 * min(D.max(), r))
        # its thinnest spot: the shortest chord through a cell farther from the thick part than
        # a ball's rounding (the cells that make it a thin wall, not an edge of a thick one)
        far = cells[away[tuple(cells.T)] > edge]
        far_mm = lo + h * far
        # (from a cell near the surface, the direction to its nearest sample is not the normal)
        d0, _ = surf.query(lo + h * far)
        far = far[d0 >= 0.4 * min(D.max(), r)] if (d0 >= 0.4 * min(D.max(), r)).any() else far
        if len(far) > MAX_CHORDS:
            far = far[rng.choice(len(far), MAX_CHORDS, replace=False)]
        w, mid = _chords(surf, lo + h * far, 4 * min_wall, 0.25 * h)
        j = int(np.argmin(w))
        if np.isfinite(w[j]):
            where, thin = mid[j], float(min(w[j], thickness))
        else:
            where, thin = lo + h * cells[len(cells) // 2], None
        out.append(ThinWall(name, thickness, float(v), tuple(float(x) for x in where), thin, far_mm, h))
    return out


__all__ = ["ThinWall", "thin_walls", "voxelize"]
