"""Thin material the clearance trims leave on a body, away from its joints, removed (mm).

The trims that keep a body clear of its hinge partners and of the joint parts of its universal
joints are laid out each on its own, and where two of them pass close by they can leave a web of
the body between them that no printer at the profile's minimum wall makes.  Some such webs hold
nothing; some are the only link of a piece of the body, and those must stay (and be mended where
they are made): on a compiled circuit's connector chains, the 0.16 mm strip on most half units
(session 59's README circuit: 417 of its 1333 thin regions, on AB and CD) is what is left of the
compound junction's fin (O's yoke plate along the host's line) between the trim about the second
pin and the hinge partner's clearance, and it is the one link of the yoke knuckle on the side away
from the half unit's end knuckle (taken, the body falls in two, the knuckle a piece of a few mm^3:
tests/test_mesh_shave.py).

:func:`shave_thin` measures every body's finished solid as the ``wall_thickness`` check does
(:func:`mlc.mesh.walls.thin_walls`, the same cells) and takes a thin region away (its cells
farther from the thick part than a ball's rounding at an edge, a cube of two cells about each:
the stubs left within that rounding are no thin wall to the check) when

1. the cells are not joint material: those inside the cylinder of a hinge stack of the body (its
   knuckles and the pin) or of one of its yoke knuckles, two cells beyond, are kept (a
   region that is mostly such cells, a short stack's 0.5 mm knuckle, is left whole);
2. the body keeps as many pieces of at least ``min_wall ** 3`` as it had (the removal joins up
   nothing and cuts off nothing it holds; the crumbs of the cut under that size go); and
3. the body's joint cores (``asm.cores`` of a large assembly: its knuckles, pins and rings, which
   no trim takes from) are untouched.

A region that fails a test is left, and the ``wall_thickness`` check reports it as before.  Only
material is taken away, so no gap narrows and no state or pose meets anything new.  Large
assemblies: once per congruent shape, in the part's own frame (the shape key and the wall
results are the ``wall_thickness`` check's own, so a part with nothing thin is measured once).
"""
from __future__ import annotations

import numpy as np
import manifold3d as mf

#: cells (of the wall grid) of margin around a joint cylinder within which nothing is taken
JOINT_MARGIN = 2.0
#: the cube about a removed cell centre, in cells
CUT_CELLS = 2.0


def _joint_cells(asm, bn: str, X: np.ndarray, m: float) -> np.ndarray:
    """Which points ``X`` (world rest, mm) lie within ``m`` of the cylinder of one of body
    ``bn``'s hinge stacks (its whole span: its knuckles and any pin through the others') or of
    its yoke knuckles."""
    hit = np.zeros(len(X), bool)

    def cyl(o, d, s0, s1, R):
        v = X - o
        s = v @ d
        r = np.linalg.norm(v - np.outer(s, d), axis=1)
        return (s >= s0 - m) & (s <= s1 + m) & (r <= R + m)

    for ax in asm.axes:
        if bn in ax.bodies:
            hit |= cyl(ax.origin, ax.direction, -ax.span / 2, ax.span / 2, ax.R)
    for uj in asm.ujoints:
        if bn in uj.bodies:
            side = uj.bodies.index(bn)
            lay = uj.layouts[side]
            for s0, s1 in lay.own:
                hit |= cyl(uj.center, uj.axes[side], s0, s1, lay.r_own or uj.R)
    return hit


def _cubes(P: np.ndarray, g: float) -> mf.Manifold:
    return mf.Manifold.batch_boolean([mf.Manifold.cube([g, g, g], center=True).translate(tuple(c)) for c in P],
                                     mf.OpType.Add)


def _big(solid: mf.Manifold, v: float) -> list:
    return [x for x in solid.decompose() if x.volume() >= v]


def _shaved(solid: mf.Manifold, walls: list, protect, min_wall: float):
    """``solid`` less each region of ``walls`` that passes tests 1 and 2 (in the solid's frame;
    ``protect(X)`` marks joint cells), and the number of regions taken."""
    v = min_wall ** 3
    n_big = len(_big(solid, v))
    taken = 0
    for w in walls:
        if w.cells is None or not len(w.cells):
            continue
        keep = protect(w.cells, JOINT_MARGIN * w.h)
        if keep.mean() > 0.5:
            continue
        new = solid - _cubes(w.cells[~keep], CUT_CELLS * w.h)
        big = _big(new, v)
        if len(big) != n_big:
            continue
        solid = big[0] if len(big) == 1 else mf.Manifold.batch_boolean(big, mf.OpType.Add)
        taken += 1
    return solid, taken


def shave_thin(asm, log=None) -> None:
    """Take the thin regions off every body part of ``asm`` that :mod:`this module <mlc.mesh.shave>`'s
    three tests allow, with a note of how many and how much."""
    from mlc.mesh.build import transform_solid
    from mlc.mesh.walls import thin_walls

    mw = asm.profile.min_wall
    cong = getattr(asm, "congruence", None)
    done = {}           # shape key -> (local shaved solid, regions taken)
    n_parts = n_regions = 0
    removed = 0.0
    for i, p in enumerate(asm.parts):
        if p.kind != "body" or p.solid.is_empty():
            continue
        if cong is None:
            walls = thin_walls(p.name, p.solid, mw)
            if not walls:
                continue
            new, taken = _shaved(p.solid, walls, lambda X, m, bn=p.name: _joint_cells(asm, bn, X, m), mw)
        else:
            F = cong.frames[i]
            key = cong.key(i, p.solid)
            walls = cong.lookup(("walls", mw, key), lambda: thin_walls("", transform_solid(p.solid, np.linalg.inv(F)), mw))
            if not walls:
                continue
            if key not in done:
                def protect(X, m, bn=p.name, F=F):
                    return _joint_cells(asm, bn, X @ F[:3, :3].T + F[:3, 3], m)
                done[key] = _shaved(transform_solid(p.solid, np.linalg.inv(F)), walls, protect, mw)
            local, taken = done[key]
            new = transform_solid(local, F) if taken else p.solid
        if not taken:
            continue
        core = asm.cores.get(p.name) if asm.cores else None
        if core is not None and (core - new).volume() > (core - p.solid).volume() + 1e-6:
            continue
        removed += p.solid.volume() - new.volume()
        p.solid = new
        n_parts += 1
        n_regions += taken
        if log:
            log(f"shaved {p.name}: {taken} thin region(s)")
    if n_regions:
        asm.notes.append(f"walls: {n_regions} thin region(s) that hold nothing, away from the joints, taken off "
                         f"{n_parts} bodies ({removed:.3g} mm^3; mlc.mesh.shave)")
