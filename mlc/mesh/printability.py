"""How a print sits on the bed: bed contact, overhangs and support volume, in the print frame.

All lengths in millimetres; the print frame has the bed at z = 0 and "up" along +z.

* **footprint**: the area of the assembly's shadow on the bed (union of the parts'
  projections, manifold3d ``project``); **bed contact**: the area of the assembly's section
  just above the bed (``slice`` at half the first layer), i.e. what the first layer prints.
* **overhang**: downward faces steeper than the profile's ``overhang_deg`` from vertical (the
  angle a process prints without support; 45 degrees for FDM) that do not rest on the bed.
* **support volume**: under every overhang, the column of air down to the first surface
  below -- the bed, or another part (support *inside the mechanism*: it would be printed
  between parts, squeezed into the gaps that let them move).

The columns are sampled on a square grid of spacing ``h`` (every non-vertical triangle is
rasterised; a column's crossings sorted by height give the material intervals), so the
support volume is exact up to the grid spacing at the edges of the overhangs.  A slicer
draws fewer and thinner supports (sparse infill, a gap under the contact layer); this is the
volume the supports have to fill, the quantity the printability goals bound.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass
class BedStats:
    footprint_mm2: float
    contact_mm2: float
    overhang_mm2: float
    support_mm3: float            # total support volume (to the bed or onto a part)
    support_inside_mm3: float     # of which resting on a part (inside the mechanism)
    part_volume_mm3: float
    grid_mm: float
    per_part: dict = field(default_factory=dict)   # name -> (overhang mm2, support mm3, inside mm3)
    lowest_mm: dict = field(default_factory=dict)  # name -> lowest z of the part (mm above the bed)

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
                "support_fraction": round(self.support_fraction, 4), "part_volume_mm3": round(self.part_volume_mm3, 3),
                "grid_mm": self.grid_mm}


def _mesh_arrays(solid):
    m = solid.to_mesh()
    return np.asarray(m.vert_properties, float)[:, :3], np.asarray(m.tri_verts, np.int64)


def bed_stats(named_solids, overhang_deg: float = 45.0, h: float = 0.5, first_layer: float = 0.2) -> BedStats:
    """Bed contact, overhang and support volume of print-frame solids ``[(name, manifold)]``
    (bed at z = 0).  ``h``: grid spacing of the support columns (mm)."""
    import manifold3d as mf

    named_solids = [(n, s) for n, s in named_solids if not s.is_empty()]
    if not named_solids:
        return BedStats(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, h)
    shadows = mf.CrossSection.batch_boolean([s.project() for _, s in named_solids], mf.OpType.Add)
    z0 = 0.5 * first_layer
    sections = [s.slice(z0) for _, s in named_solids]
    contact = mf.CrossSection.batch_boolean(sections, mf.OpType.Add).area()
    lowest = {n: float(np.asarray(s.bounding_box())[2]) for n, s in named_solids}

    # rasterise every non-vertical triangle onto the column grid
    cos_lim = np.cos(np.radians(90.0 - overhang_deg))     # |n_z| above this: flatter than the limit
    allV, allF, owner = [], [], []
    off = 0
    for k, (_, s) in enumerate(named_solids):
        V, F = _mesh_arrays(s)
        allV.append(V)
        allF.append(F + off)
        owner.append(np.full(len(F), k))
        off += len(V)
    V = np.concatenate(allV)
    F = np.concatenate(allF)
    own = np.concatenate(owner)
    A, B, C = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]
    nrm = np.cross(B - A, C - A)
    area2 = np.linalg.norm(nrm, axis=1)
    ok = area2 > 1e-12
    nz = np.zeros(len(F))
    nz[ok] = nrm[ok, 2] / area2[ok]
    over = (nz < -cos_lim) & (np.minimum(np.minimum(A[:, 2], B[:, 2]), C[:, 2]) > z0)
    overhang_area = 0.5 * area2[over]
    per_over = np.bincount(own[over], weights=overhang_area, minlength=len(named_solids))

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
    inside = down & prev_same
    vol = height * h * h
    per_sup = np.bincount(own[tri_idx], weights=vol, minlength=len(named_solids))
    per_in = np.bincount(own[tri_idx], weights=np.where(inside, vol, 0.0), minlength=len(named_solids))
    total_vol = float(sum(s.volume() for _, s in named_solids))
    per_part = {n: (round(float(per_over[k]), 3), round(float(per_sup[k]), 3), round(float(per_in[k]), 3))
                for k, (n, _) in enumerate(named_solids)}
    return BedStats(float(shadows.area()), float(contact), float(overhang_area.sum()), float(vol.sum()),
                    float(vol[inside].sum()), total_vol, h, per_part, lowest)


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


__all__ = ["BedStats", "bed_stats"]
