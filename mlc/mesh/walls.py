"""Wall thickness of the finished solids, measured on a voxel grid (mm).

The nominal sizes of the design (slab thickness, knuckle wall) say nothing about what the
trims leave: a cut that clears another part can leave a web thinner than the printer's
minimum wall.  This module measures it on the solid itself, by a morphological *opening*
with a ball of diameter ``min_wall`` (the union of every such ball that fits inside the part):

1. the part is voxelised (cell ``h``; a cell is inside when its centre is);
2. the Euclidean distance transform gives, for each inside cell, the radius of the largest
   ball centred there that stays inside;
3. the cells covered by a ball of radius ``min_wall / 2`` (measured between cell centres: the
   surface lies half a cell beyond the last inside centre) centred where one fits are the part
   "at least ``min_wall`` thick"; the rest is thinner;
4. every connected region of the rest that reaches deeper than the rounding a ball leaves at a
   right-angled edge (``(sqrt 2 - 1) r``, plus a cell) and holds more than ``r**3`` of material is a thin wall; its thickness is twice the largest ball inside it.

The three distance transforms are only ever compared with lengths of a few cells (``r``, the
corner rounding), so they are computed exactly up to a few cells and no further
(:func:`_edt_upto`: the squared Euclidean distance is separable, a minimum over offsets
along each axis in turn; every distance up to the bound is the exact one, anything further
only known to be further): the same cells and the same thicknesses as scipy's full transform,
about 5 times faster (the wall check was the largest stage of a compiled circuit's report).

Resolution: ``h = min_wall / 8`` by default.  Calibrated on plates at random offsets and angles
(tests/test_mesh_walls.py): a plate of ``min_wall`` or ``0.92 min_wall`` always passes, one of
``0.72 min_wall`` (0.43 mm of 0.6) or less always fails; in between it depends on the grid.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


#: cells of the largest grid measured at once (memory: about 40 bytes a cell during the transforms)
MAX_CELLS = 6e6


@dataclass
class ThinWall:
    part: str
    thickness_mm: float      # twice the largest ball that fits in the thin region
    volume_mm3: float        # material in the thin region
    where_mm: tuple          # a point of the region (print frame of the solid given)

    def text(self, min_wall: float) -> str:
        x, y, z = self.where_mm
        return (f"{self.part}: wall {self.thickness_mm:.2f} mm < {min_wall:g} mm over {self.volume_mm3:.3g} mm^3 "
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


def thin_walls(name: str, solid, min_wall: float, h: float | None = None) -> list[ThinWall]:
    """The regions of ``solid`` thinner than ``min_wall`` (mm), measured on a voxel grid."""
    from scipy import ndimage

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
    r = min_wall / 2
    edge = (np.sqrt(3) - 1) * r + 1.01 * h     # the rounding a ball leaves in a box corner, plus a cell
    # every distance below is compared with r or edge only (and a thin cell's depth is under r):
    # exact up to a bound past both is all it takes
    R = int(np.ceil(max(r, edge) / h)) + 2
    # distance from each inside cell centre to the nearest outside cell centre: the radius of the
    # largest ball centred there, plus half a cell on average (the surface lies between the two)
    depth = _edt_upto(grid, R) * h
    centres = depth >= r - 0.5 * h - 1e-9     # half a cell of tolerance for the staircase of a tilted wall
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
    for k, d, v, t in zip(idx, deep[1:], size[1:], thick[1:]):
        if d > edge and v > r ** 3:
            where = np.argwhere(labels == k) + corner
            p = lo + h * where[len(where) // 2]
            out.append(ThinWall(name, float(2 * t - h), float(v), tuple(float(x) for x in p)))
    return out


__all__ = ["ThinWall", "thin_walls", "voxelize"]
