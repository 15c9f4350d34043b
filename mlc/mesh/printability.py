"""How a print sits on the bed: bed contact, overhangs and support volume, in the print frame.

All lengths in millimetres; the print frame has the bed at z = 0 and "up" along +z.

* **footprint**: the area of the assembly's shadow on the bed (union of the parts'
  projections, manifold3d ``project``); **bed contact**: the area of the assembly's section
  just above the bed (``slice`` at half the first layer), i.e. what the first layer prints.
* **overhang**: downward faces steeper than the profile's ``overhang_deg`` from vertical (the
  angle a process prints without support; 45 degrees for FDM) that do not rest on the bed.
* **islands**: points of a part lower than the surface around them, in mid-air (a slab or a
  knuckle tilted onto a corner); a slicer supports each with a column whatever the angles of
  its faces (``bed_stats(island_mm=...)``: a square column of that side).
* **support volume**: under every overhang and island, the column of air down to the first surface
  below -- the bed, another part (support *inside the mechanism*: it would be printed
  between parts, squeezed into the gaps that let them move), or the same part (inside one of
  its holes or recesses: counted in the total, not as inside the mechanism).

The columns are sampled on a square grid of spacing ``h`` (every non-vertical triangle is
rasterised; a column's crossings sorted by height give the material intervals), so the
support volume is exact up to the grid spacing at the edges of the overhangs.  A slicer
draws fewer and thinner supports (sparse infill, a gap under the contact layer); this is the
volume the supports have to fill, the quantity the printability goals bound.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

#: an edge below both its faces and rising at less than this (degrees) is a ridge: an island along it
RIDGE_DEG = 20.0


@dataclass
class BedStats:
    footprint_mm2: float
    contact_mm2: float
    overhang_mm2: float
    support_mm3: float            # total support volume (to the bed or onto a part)
    support_inside_mm3: float     # of which resting on another part (inside the mechanism)
    part_volume_mm3: float
    grid_mm: float
    per_part: dict = field(default_factory=dict)   # name -> (overhang mm2, support mm3, inside mm3)
    lowest_mm: dict = field(default_factory=dict)  # name -> lowest z of the part (mm above the bed)
    support_self_mm3: float = 0.0  # of the total, resting on the same part (a hole or recess of it)
    islands: int = 0               # islands held by a column (bed_stats island_mm > 0)

    @property
    def contact_fraction(self) -> float:
        return self.contact_mm2 / self.footprint_mm2 if self.footprint_mm2 > 0 else 0.0

    @property
    def support_fraction(self) -> float:
        return self.support_mm3 / self.part_volume_mm3 if self.part_volume_mm3 > 0 else 0.0

    def to_dict(self) -> dict:
        return {"footprint_mm2": round(self.footprint_mm2, 3), "contact_mm2": round(self.contact_mm2, 3),
                "contact_fraction": round(self.contact_fraction, 4), "overhang_mm2": round(self.overhang_mm2, 3),
                "support_mm3": round(self.support_mm3, 3), "support_inside_mm3": round(self.support_inside_mm3, 3),
                "support_self_mm3": round(self.support_self_mm3, 3), "islands": self.islands,
                "support_fraction": round(self.support_fraction, 4), "part_volume_mm3": round(self.part_volume_mm3, 3),
                "grid_mm": self.grid_mm}


def _mesh_arrays(solid):
    m = solid.to_mesh()
    return np.asarray(m.vert_properties, float)[:, :3], np.asarray(m.tri_verts, np.int64)


def merged_mesh(named_solids):
    """One triangle soup of ``(name, solid)`` pairs: vertices (n,3) mm, faces (m,3) indexing
    them, and each face's owner (the solid's index in ``named_solids``)."""
    Vs, Fs, Os, off = [], [], [], 0
    for k, (_, s) in enumerate(named_solids):
        V, F = _mesh_arrays(s)
        Vs.append(V)
        Fs.append(F + off)
        Os.append(np.full(len(F), k))
        off += len(V)
    return np.concatenate(Vs), np.concatenate(Fs), np.concatenate(Os)


def bed_stats(named_solids, overhang_deg: float = 45.0, h: float = 0.5, first_layer: float = 0.2,
              island_mm: float = 0.0) -> BedStats:
    """Bed contact, overhang and support volume of print-frame solids ``[(name, manifold)]``
    (bed at z = 0).  ``h``: grid spacing of the support columns (mm); ``island_mm`` > 0: each
    island (a point of a part lower than the surface around it, in mid-air) is held by a square
    column of that side (mm), counted in the support volume."""
    import manifold3d as mf

    named_solids = [(n, s) for n, s in named_solids if not s.is_empty()]
    if not named_solids:
        return BedStats(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, h)
    shadows = mf.CrossSection.batch_boolean([s.project() for _, s in named_solids], mf.OpType.Add)
    z0 = 0.5 * first_layer
    sections = [s.slice(z0) for _, s in named_solids]
    contact = mf.CrossSection.batch_boolean(sections, mf.OpType.Add).area()
    lowest = {n: float(np.asarray(s.bounding_box())[2]) for n, s in named_solids}

    V, F, own = merged_mesh(named_solids)
    c = _columns(V, F, h, overhang_deg, z0, own, island_mm)
    overhang_area = c["overhang_area"]
    per_over = np.bincount(own[c["over_idx"]], weights=overhang_area, minlength=len(named_solids))
    # the columns under the overhangs, then the islands' columns
    vol = np.concatenate([c["vol"], c["island_vol"]])
    inside = np.concatenate([c["inside"], c["island_inside"]])
    on_self = np.concatenate([c["on_self"], c["island_self"]])
    who = np.concatenate([own[c["tri_idx"]], c["island_own"]])
    per_sup = np.bincount(who, weights=vol, minlength=len(named_solids))
    per_in = np.bincount(who, weights=np.where(inside, vol, 0.0), minlength=len(named_solids))
    total_vol = float(sum(s.volume() for _, s in named_solids))
    per_part = {n: (round(float(per_over[k]), 3), round(float(per_sup[k]), 3), round(float(per_in[k]), 3))
                for k, (n, _) in enumerate(named_solids)}
    return BedStats(float(shadows.area()), float(contact), float(overhang_area.sum()), float(vol.sum()),
                    float(vol[inside].sum()), total_vol, h, per_part, lowest, float(vol[on_self].sum()),
                    c.get("island_count", 0))


def _columns(V, F, h: float, overhang_deg: float, z0: float, own=None, island_mm: float = 0.0) -> dict:
    """The support columns of the triangles ``F`` of vertices ``V`` (mm, bed at z = 0) on a
    square grid of spacing ``h``: every non-vertical triangle rasterised, a column's crossings
    sorted by height; under each overhang crossing, the air down to the crossing below in the
    same column or to the bed.  ``own``: the part of each triangle; ``inside``: the crossing
    below is a surface of another part (support between two parts); ``on_self``: of the same
    part (support inside a hole or a recess of one part).  ``island_mm`` > 0: the islands too
    (:func:`_islands`), each a square column of that side down to the surface below (per grid
    column of it: ``island_vol``, its part ``island_own`` and ``island_pts``, the island it holds, mm)."""
    A, B, C = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]
    nrm = np.cross(B - A, C - A)
    area2 = np.linalg.norm(nrm, axis=1)
    ok = area2 > 1e-12
    nz = np.zeros(len(F))
    nz[ok] = nrm[ok, 2] / area2[ok]
    cos_lim = np.cos(np.radians(90.0 - overhang_deg))     # |n_z| above this: flatter than the limit
    # a face overhangs unless it lies on the bed; a face leaning on the bed at one edge still
    # needs its columns (their height goes to zero at the bed)
    over = (nz < -cos_lim) & (np.maximum(np.maximum(A[:, 2], B[:, 2]), C[:, 2]) > z0)
    lo = V[:, :2].min(0) - h
    keep = np.abs(nz) > 1e-9
    col, z, sgn, tri = _raster(A[keep], B[keep], C[keep], lo, h)
    tri_idx = np.nonzero(keep)[0][tri]
    nx = int(np.ceil((V[:, 0].max() - lo[0]) / h)) + 2
    key = col[:, 1] * nx + col[:, 0]
    order = np.lexsort((z, key))
    key, z, sgn, tri_idx = key[order], z[order], sgn[order], tri_idx[order]
    # support under each overhang crossing: down to the crossing below in the same column, or the bed
    down = (sgn < 0) & over[tri_idx]
    prev_same = np.zeros(len(key), bool)
    prev_same[1:] = key[1:] == key[:-1]
    below = np.where(prev_same, np.concatenate([[0.0], z[:-1]]), 0.0)
    height = np.where(down, np.maximum(z - below, 0.0), 0.0)
    if own is None:
        own = np.zeros(len(F), np.int64)
    o = own[tri_idx]
    same = np.zeros(len(key), bool)
    same[1:] = o[1:] == o[:-1]
    on_part = down & prev_same
    out = {"overhang_area": 0.5 * area2[over], "over_idx": np.nonzero(over)[0], "vol": height * h * h,
           "inside": on_part & ~same, "on_self": on_part & same, "tri_idx": tri_idx, "key": key, "z": z,
           "first": ~prev_same, "island_vol": np.zeros(0), "island_own": np.zeros(0, np.int64),
           "island_pts": np.zeros((0, 3)), "island_inside": np.zeros(0, bool), "island_self": np.zeros(0, bool)}
    if island_mm > 0:
        out.update(_islands(V, F, own, over, z0, island_mm, lo, h, nx, key, z, tri_idx))
    return out


def _islands(V, F, own, over, z0, side, lo, h, nx, key, z, tri_idx) -> dict:
    """Islands: points of a part lower than all the surface around them (a vertex no higher
    than any neighbour, where the surface faces down: the summed normals of its triangles point
    down), above the bed and not on an overhanging face (whose columns already hold it); and
    *ridges*, edges lower than both their faces, both facing down, rising at less than
    :data:`RIDGE_DEG` (a slab tilted onto an edge: each layer starts a new strip in mid-air),
    sampled every ``side``.  PrusaSlicer did not support the 35-degree edges of a corner-down
    cube beyond its corner, and supported a 20 mm slab edge rising at 20 degrees about as one
    island.  A slicer starts each as a small region in mid-air and supports it with a column
    (PrusaSlicer 2.5, 0.2 mm layers: 9 to 22 mm^3 of filament per mm of height for a 3 to 6 mm
    corner-down cube or a tilted slab edge-down, whatever its faces' angles).  Each island, one
    per part and cell of ``side`` (mm), gets a square column of that side centred on it: each
    grid column of the square down to the first surface below the island, or the bed."""
    zv = V[:, 2]
    nb = np.full(len(V), np.inf)
    for a, b in ((0, 1), (1, 2), (2, 0), (1, 0), (2, 1), (0, 2)):
        np.minimum.at(nb, F[:, a], zv[F[:, b]])
    covered = np.zeros(len(V), bool)
    covered[F[over].ravel()] = True
    vown = np.zeros(len(V), np.int64)
    vown[F.ravel()] = np.repeat(own, 3)
    # the surface there faces down (the material is above it): not the floor of a bore or a valley
    A, B, C = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]
    fz = np.cross(B - A, C - A)[:, 2]
    vz = np.zeros(len(V))
    for a in range(3):
        np.add.at(vz, F[:, a], fz)
    idx = np.nonzero((nb >= zv - 1e-9) & (zv > z0) & ~covered & (vz < 0))[0]
    pts, pown = V[idx], vown[idx]
    # ridges: an edge lower than both its faces, both facing down, rising at less than
    # RIDGE_DEG (a slab tilted onto an edge): an island along its length
    ea = np.concatenate([F[:, 0], F[:, 1], F[:, 2]])
    eb = np.concatenate([F[:, 1], F[:, 2], F[:, 0]])
    ec = np.concatenate([F[:, 2], F[:, 0], F[:, 1]])
    fo = np.concatenate([np.arange(len(F))] * 3)
    lo_v, hi_v = np.minimum(ea, eb), np.maximum(ea, eb)
    order = np.lexsort((hi_v, lo_v))
    lo_v, hi_v, ec, fo = lo_v[order], hi_v[order], ec[order], fo[order]
    pair = (lo_v[1:] == lo_v[:-1]) & (hi_v[1:] == hi_v[:-1])
    i1 = np.nonzero(pair)[0]
    i2 = i1 + 1
    if len(i1):
        a, b = V[lo_v[i1]], V[hi_v[i1]]
        e = b - a
        L = np.linalg.norm(e, axis=1)
        e = e / np.maximum(L, 1e-12)[:, None]

        def rises(i):
            d = V[ec[i]] - a
            p = d - np.sum(d * e, axis=1)[:, None] * e
            return p[:, 2] > 1e-6 * np.linalg.norm(p, axis=1)
        fn = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])[:, 2]
        ridge = (rises(i1) & rises(i2) & (fn[fo[i1]] < 0) & (fn[fo[i2]] < 0) & ~over[fo[i1]] & ~over[fo[i2]]
                 & (np.abs(e[:, 2]) < np.sin(np.radians(RIDGE_DEG))) & (np.minimum(a[:, 2], b[:, 2]) > z0) & (L > 0))
        for j in np.nonzero(ridge)[0]:
            t = np.linspace(0.0, L[j], int(np.ceil(L[j] / side)) + 1)
            pts = np.concatenate([pts, a[j] + t[:, None] * e[j]])
            pown = np.concatenate([pown, np.full(len(t), own[fo[i1[j]]])])
    if len(pts) == 0:
        return {}
    cell = np.floor(pts / side).astype(np.int64)
    _, first = np.unique(np.column_stack([pown, cell]), axis=0, return_index=True)
    first = np.sort(first)
    pts, pown = pts[first], pown[first]
    # under each island, every grid column of its square: down to the highest crossing below it
    n = max(1, int(round(side / h)))
    off = (np.arange(n) - (n - 1) / 2.0) * h
    dx, dy = [g.ravel() for g in np.meshgrid(off, off)]
    isl = np.repeat(np.arange(len(pts)), len(dx))
    px = pts[isl, 0] + np.tile(dx, len(pts))
    py = pts[isl, 1] + np.tile(dy, len(pts))
    ix = np.floor((px - lo[0]) / h).astype(np.int64)
    iy = np.floor((py - lo[1]) / h).astype(np.int64)
    k = iy * nx + ix
    top = pts[isl, 2]
    S = 2.0 * (float(np.max(np.abs(zv))) + 1.0)
    comb = key * S + z
    pos = np.searchsorted(comb, k * S + top - 1e-6) - 1
    ok = (pos >= 0) & (key[np.maximum(pos, 0)] == k)
    floor = np.where(ok, z[np.maximum(pos, 0)], 0.0)
    below = np.where(ok, own[tri_idx[np.maximum(pos, 0)]], -1)
    vol = np.maximum(top - floor, 0.0) * h * h
    io = pown[isl]
    m = len(pts)
    return {"island_vol": vol, "island_own": io,
            "island_inside": ok & (below != io), "island_self": ok & (below == io), "island_count": m,
            "island_pts": pts[isl]}


def quick_stats(V, F, h: float, overhang_deg: float = 45.0, first_layer: float = 0.2, own=None,
                island_mm: float = 0.0) -> dict:
    """A fast estimate of :func:`bed_stats` from the triangles alone (vertices ``V`` in mm, any
    height: the lowest vertex is put on the bed), for searching many print orientations:
    the support volumes exactly as :func:`bed_stats` computes them on the same grid; the
    footprint as the grid columns crossed by any triangle and the bed contact as the columns
    whose lowest crossing is within half the first layer of the bed (both in mm^2, to the grid
    spacing ``h`` at the edges).  ``own``: the part of each triangle (support between parts is
    told from support inside one part).  Returns ``support_mm3``, ``support_inside_mm3``,
    ``footprint_mm2``, ``contact_mm2``."""
    V = np.array(V, float)
    V[:, 2] -= V[:, 2].min()
    c = _columns(V, F, h, overhang_deg, 0.5 * first_layer, own, island_mm)
    first = c["first"]
    iv = c["island_vol"]
    return {"support_mm3": float(c["vol"].sum() + iv.sum()),
            "support_inside_mm3": float(c["vol"][c["inside"]].sum() + iv[c["island_inside"]].sum()),
            "footprint_mm2": float(first.sum() * h * h),
            "contact_mm2": float(np.sum(c["z"][first] < 0.5 * first_layer) * h * h)}


def _raster(A, B, C, lo, h):
    """Grid columns (ix, iy) whose centres lie in each triangle's xy projection, the height of
    the triangle there, the sign of its normal's z and the triangle index."""
    x = np.stack([A[:, 0], B[:, 0], C[:, 0]], 1)
    y = np.stack([A[:, 1], B[:, 1], C[:, 1]], 1)
    ix0 = np.ceil((x.min(1) - lo[0]) / h - 0.5).astype(np.int64)
    ix1 = np.floor((x.max(1) - lo[0]) / h - 0.5).astype(np.int64)
    iy0 = np.ceil((y.min(1) - lo[1]) / h - 0.5).astype(np.int64)
    iy1 = np.floor((y.max(1) - lo[1]) / h - 0.5).astype(np.int64)
    nxk = np.maximum(ix1 - ix0 + 1, 0)
    nyk = np.maximum(iy1 - iy0 + 1, 0)
    cnt = nxk * nyk
    if cnt.sum() == 0:
        e = np.zeros(0, np.int64)
        return np.zeros((0, 2), np.int64), np.zeros(0), e, e
    t = np.repeat(np.arange(len(A)), cnt)
    start = np.concatenate([[0], np.cumsum(cnt)[:-1]])
    r = np.arange(cnt.sum()) - np.repeat(start, cnt)
    ix = ix0[t] + r % nxk[t]
    iy = iy0[t] + r // nxk[t]
    px = lo[0] + (ix + 0.5) * h
    py = lo[1] + (iy + 0.5) * h
    # barycentric coordinates in the xy projection
    x0, y0 = A[t, 0], A[t, 1]
    e1x, e1y = B[t, 0] - x0, B[t, 1] - y0
    e2x, e2y = C[t, 0] - x0, C[t, 1] - y0
    det = e1x * e2y - e1y * e2x
    qx, qy = px - x0, py - y0
    with np.errstate(divide="ignore", invalid="ignore"):
        u = (qx * e2y - qy * e2x) / det
        v = (e1x * qy - e1y * qx) / det
    eps = 1e-9
    inside = (u >= -eps) & (v >= -eps) & (u + v <= 1 + eps) & (np.abs(det) > 1e-14)
    # a column through a shared edge must count once: keep the half-open side (tie-break on the edge)
    t, ix, iy, u, v, det = t[inside], ix[inside], iy[inside], u[inside], v[inside], det[inside]
    z = A[t, 2] + u * (B[t, 2] - A[t, 2]) + v * (C[t, 2] - A[t, 2])
    sgn = np.sign(det).astype(np.int64)          # +1: the face looks up (counter-clockwise seen from above)
    col = np.stack([ix, iy], 1)
    # drop duplicate crossings (a column through an edge or vertex shared by two triangles)
    key = np.stack([ix, iy, np.round(z / 1e-6).astype(np.int64), sgn], 1)
    _, first = np.unique(key, axis=0, return_index=True)
    first = np.sort(first)
    return col[first], z[first], sgn[first], t[first]


__all__ = ["BedStats", "bed_stats", "quick_stats"]
