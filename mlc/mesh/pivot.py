"""Flat hinges made to print without support: crossing arms chamfered beside the knuckles,
teardrops under the knuckles (issue 13, the supports goal).  Print-only: the scene is unchanged.

All lengths in mm, in the model's rest frame (the parts as built).

*Why.* Along a hinge axis the knuckles alternate between its bodies, and each body's slab is cut
back to the trim radius ``rho = R + clearance`` around the other bodies' knuckles
(:mod:`mlc.mesh.build`, *Trimming*, 1): a cylinder, so where an arm of one body crosses the other
body's knuckle layers it ends there in a face parallel to the axis.  With the axis flat on the
bed, an arm that rises from the pivot ends in mid-air over the whole knuckle length: a horizontal
edge lower than both its faces, which a slicer starts as a strip in mid-air and mlc's estimate
supports as a ridge island (:mod:`mlc.mesh.printability`).  And each knuckle hangs on its round
underside, 2 R sin 45 wide between the tangents at the overhang limit.  In the NAND expanding in
fdm (the output lever's pivot, ``out_lo`` and ``out_hi``, lies along the bed) the ridges held
about 1340 mm^3 and the knuckles' undersides about 840 of the 2182 mm^3 of support mlc put under
the pivot (session 54; docs/printing.md).  A gusset from a knuckle down to its own arm cannot
stay above 45 degrees there (the arms leave at about 49 degrees, the knuckle is 2.6 times as wide
as the arm: session 40), so the knuckle keeps a small flat.

*What*, once the print's up is known (after the orientation), on every hinge axis flat on the bed
(:func:`flat_hinges`; ``mlc stl`` on a library gate, not on compiled circuits):

1. :func:`chamfer_crossings`: each body's cut around the other bodies' knuckles is a cone instead
   of a cylinder, from the face of the body's own knuckle, where it starts at the radius the other
   bodies' teardrops need plus the clearance (or at ``rho``, if that would thin the body), growing
   at :data:`SLOPE` per mm along the axis away from it.  The crossing arm is chamfered towards its
   own knuckle layer: it grows out of that layer with faces ``atan(1 / SLOPE)`` (22 degrees) from
   the radial direction, no edge in mid-air, a little wider each layer (PrusaSlicer supported the
   flatter chamfer of SLOPE 1.43 more than the arms cut off square: :data:`SLOPE`).  The arm in
   the other bodies' layers is taken away out to about 13 mm from the axis (NAND fdm): near the
   pivot the arm is as wide as its own knuckles.  Only material outside ``rho`` is taken away
   (pins, knuckles and holes are inside it), so no two parts come closer in any pose; the body
   stays joined through its own knuckle layers, and keeps its piece count and walls (measured,
   else not chamfered).
2. :func:`teardrops`: under each knuckle, within its own range along the axis, a truncated
   teardrop, flanks at :data:`FLANK_DEG` tangent to the knuckle down to a flat about one minimum
   wall wide, as deep as the other bodies' material (measured) leaves the clearance in any turn.

Measured (benchmarks/results/mesh_support_where_s54.json, fdm): mlc's support estimate 3862 ->
1106 mm^3 for the NAND expanding (58.2 -> 17.2 % of the part volume; under the pivot 2182 -> 276),
no island left, every blocking check passing; PrusaSlicer 2.5's support 3700 -> 3160 mm^3
(docs/printing.md, session 54).
"""
from __future__ import annotations

import numpy as np

#: chamfer the crossing arms (``mlc stl``'s library gates: a mechanism built with dense poses)
CHAMFER = True
#: a hinge axis within this many degrees of the bed (in the print frame) is chamfered
FLAT_DEG = 30.0
#: the chamfer's radius grows this much per mm along the axis away from the body's own knuckle.
#: An arm rising at a from the axis grows along the axis by 0.2 / (SLOPE sin a) mm a 0.2 mm layer:
#: PrusaSlicer 2.5 (NAND expanding, fdm, arms at 49 degrees) laid 3700 mm^3 of support without the
#: chamfers and teardrops, 4380 / 3940 / 3150 / 3160 / 3260 with them at SLOPE 1.43 / 1.75 / 2 /
#: 2.5 / 5 (0.185 to 0.05 mm a layer), while mlc's estimate was 1100-1113 at every one (session 54)
SLOPE = 2.5
#: teardrops under the knuckles of flat hinges (:func:`teardrops`)
TEARDROPS = True
#: ... of the hinges within this many degrees of the bed
TEARDROP_DEG = 5.0
#: the teardrop's flanks: this many degrees from the bed (45 is the overhang limit; the knuckle's
#: facet across the tangent stays clear of it)
FLANK_DEG = 50.0
#: the teardrop's flat at its narrowest: this many minimum walls wide (its depth below the axis is
#: tried from there up by TEARDROP_STEP mm to R, the deepest that keeps the clearance kept)
FLAT_WALLS = 1.05
TEARDROP_STEP = 0.05
#: mm beyond the clearance the other bodies' material must keep from the teardrop's corners
TEARDROP_MARGIN = 0.02


def _flat(asm, ax) -> bool:
    T = asm.print_T(ax.bodies[0])
    d = T[:3, :3] @ np.asarray(ax.direction, float)
    return abs(float(d[2])) / float(np.linalg.norm(d)) < np.sin(np.radians(FLAT_DEG))


def _tangent(R: float) -> tuple:
    """Where a teardrop's flank (:data:`FLANK_DEG` from the bed) touches a knuckle of radius
    ``R``: (across the axis, below it: negative), in the knuckle's cross-section."""
    th = np.radians(90.0 - FLANK_DEG)        # the tangent point's angle below the horizontal
    return R * np.cos(th), -R * np.sin(th)


def deepest(R: float, flat: float) -> tuple:
    """The teardrop (:func:`teardrop`) under a knuckle of radius ``R`` whose flat is ``flat``
    wide: (its depth below the axis, the radius of its lower corners)."""
    tu, tw = _tangent(R)
    uc = min(flat / 2, tu)
    depth = -tw + (tu - uc) * np.tan(np.radians(FLANK_DEG))
    return float(depth), float(np.hypot(uc, depth))


def chamfer_cuts(ax, body: str, segments: int, extra: float, r0: float = 0.0) -> list:
    """The chamfer cutters of ``body`` on hinge axis ``ax``: in each range of the axis where
    other bodies' knuckles are (gaps included), a cone from the trim radius at the face of the
    body's own knuckle, growing at :data:`SLOPE` away from it, less the cylinder of the trim radius
    (what the build keeps inside it: pins, knuckles, holes).  A range at the span's end runs
    ``extra`` mm on past it, as the build's cut does.  ``r0`` > ``rho``: the cone starts at that
    radius (room for the other bodies' teardrops, :func:`teardrops`)."""
    from mlc.mesh.build import _complement, cone, cylinder, subtract
    r_s = max(ax.rho, r0)
    own = ax.intervals.get(body) or []
    if not own or len(ax.bodies) < 2:
        return []
    half = ax.span / 2
    out = []
    for a0, a1 in _complement(own, -half, half):
        if a1 - a0 <= 1e-9:
            continue
        b0 = a0 - extra if abs(a0 + half) < 1e-9 else a0
        b1 = a1 + extra if abs(a1 - half) < 1e-9 else a1
        cones = []
        if any(abs(o1 - a0) < 1e-6 for _, o1 in own):     # own knuckle below: grow towards +s
            cones.append(cone(ax.origin, ax.direction, a0, b1, r_s, r_s + SLOPE * (b1 - a0), segments, cutter=True))
        if any(abs(o0 - a1) < 1e-6 for o0, _ in own):     # own knuckle above: grow towards -s
            cones.append(cone(ax.origin, ax.direction, b0, a1, r_s + SLOPE * (a1 - b0), r_s, segments, cutter=True))
        if not cones:
            continue
        # between two of its own knuckles: the nearer face's cone (the two cones' intersection)
        cut = cones[0] if len(cones) == 1 else cones[0] ^ cones[1]
        out.append(subtract(cut, [cylinder(ax.origin, ax.direction, b0 - 1.0, b1 + 1.0, ax.rho, segments,
                                           cutter=True)]))
    return out


def chamfer_crossings(asm) -> list:
    """Chamfer the arms that cross other bodies' knuckle layers on every flat hinge axis of ``asm``
    (module docstring); returns the notes.  A part's chamfer at one axis is kept only if the part
    stays in as many pieces and has no more regions under the minimum wall
    (:func:`mlc.mesh.walls.thin_walls`) than without it: a cone that meets a slab lying across the
    axis at a grazing angle leaves a knife edge (core_ab at hinge_m, NAND fdm: 0.0 mm), and the
    report's wall check must still pass."""
    from mlc.mesh.build import _clean, subtract
    from mlc.mesh.walls import thin_walls
    if not CHAMFER:
        return []
    prof = asm.profile
    n = prof.circular_segments
    extra = 2.0 * max(prof.slab_thickness, prof.min_wall)
    flat = [ax for ax in asm.axes if ax.joint is None and _flat(asm, ax)]
    notes = []
    for p in asm.parts:
        mine = [ax for ax in flat if p.name in ax.bodies]
        if not mine or p.solid.is_empty():
            continue
        pieces = len(p.solid.decompose())
        thin = len(thin_walls(p.name, p.solid, prof.min_wall))
        done, dv = [], 0.0
        for ax in mine:
            # first with room for the other bodies' teardrops, then at the trim radius
            r_room = deepest(ax.R, FLAT_WALLS * prof.min_wall)[1] + prof.clearance + 2 * TEARDROP_MARGIN
            for r0 in ([r_room] if TEARDROPS else []) + [0.0]:
                cuts = chamfer_cuts(ax, p.name, n, extra, r0)
                if not cuts:
                    break
                new = _clean(subtract(p.solid, cuts))
                if (new.is_empty() or len(new.decompose()) != pieces
                        or len(thin_walls(p.name, new, prof.min_wall)) > thin):
                    continue
                dv += float(p.solid.volume() - new.volume())
                p.solid = new
                done.append(ax.name + (f" (from {r0:.2f} mm)" if r0 > ax.rho else ""))
                break
            else:
                notes.append(f"hinge {ax.name}: {p.name}'s arms not chamfered (it would split or leave a wall "
                             "under the minimum)")
        if done:
            notes.append(f"hinge {', '.join(done)}: {p.name}'s arms chamfered beside the other knuckles "
                         f"({dv:.3g} mm^3 less; print-only, mlc.mesh.pivot)")
    return notes


def _up_in_plane(asm, ax, body):
    """The print's up seen in the plane across ``ax`` (unit, body frame), and its component
    along the axis."""
    T = asm.print_T(body)
    up = T[:3, :3].T @ np.array([0.0, 0.0, 1.0])
    d = np.asarray(ax.direction, float) / np.linalg.norm(ax.direction)
    w = up - float(up @ d) * d
    nw = float(np.linalg.norm(w))
    return (w / nw if nw > 1e-9 else w), float(up @ d)


def teardrop(ax, body_up, a0, a1, depth, segments):
    """The knuckle's underside as a truncated teardrop on ``[a0, a1]`` of ``ax``: flanks at
    :data:`FLANK_DEG` from the bed, tangent to the knuckle (radius ``ax.R``), down to a flat at
    ``depth`` below the axis (``body_up``: the print's up across the axis, unit).  Returns
    (solid, radius of its lower corners)."""
    import manifold3d as mf
    from mlc.mesh.build import _affine
    tu, tw = _tangent(ax.R)
    uc = tu - (depth + tw) / np.tan(np.radians(FLANK_DEG))
    if uc <= 0:
        return None, depth
    poly = [(0.0, 0.0), (-tu, tw), (-uc, -depth), (uc, -depth), (tu, tw)]     # counter-clockwise
    d = np.asarray(ax.direction, float) / np.linalg.norm(ax.direction)
    w = np.asarray(body_up, float)
    u = np.cross(w, d)
    # extrude along z, then place: x -> u, y -> w, z -> d (right-handed: u x w = d)
    sol = mf.Manifold.extrude(mf.CrossSection([poly]), float(a1 - a0))
    Rm = np.column_stack([u, w, d])
    return sol.transform(_affine(Rm, np.asarray(ax.origin, float) + a0 * d)), float(np.hypot(uc, depth))


def teardrops(asm) -> list:
    """Under every knuckle of a hinge axis flat on the bed (within :data:`TEARDROP_DEG`), a
    truncated teardrop (:func:`teardrop`): the knuckle's overhang shrinks from the arc between
    the tangents at 45 degrees (2 R sin 45 wide) to the flat at its foot.  The teardrop stays in
    its knuckle's own range along the axis, and its corners at least the clearance inside the
    nearest material of every other body of the axis in that range (measured: the other body's
    solid in the annulus from R out to the corners' radius plus the clearance must be empty), so
    it keeps the clearance from them in any turn of the hinge; the flat goes as deep as that
    allows (down to ``R``; a hinge whose other bodies are cut back only to ``rho = R + c`` gets
    none).  Needs the knuckle gap at least the clearance (the teardrop's end faces are as far
    from the next knuckle's body as the knuckle's own).  Parts not on the axis are left to the
    report's ``min_gap``, ``states`` and ``motion_clearance`` checks (passed in every library gate
    and profile measured, session 54)."""
    from mlc.mesh.build import _clean, cylinder, subtract, union
    if not TEARDROPS:
        return []
    prof = asm.profile
    c, n = prof.clearance, prof.circular_segments
    if prof.knuckle_gap < c - 1e-9:
        return []
    solids = {p.name: p.solid for p in asm.parts}
    add: dict = {}
    notes = []
    for ax in asm.axes:
        if ax.joint is not None or len(ax.bodies) < 2:
            continue
        for b in ax.bodies:
            w, along = _up_in_plane(asm, ax, b)
            if abs(along) > np.sin(np.radians(TEARDROP_DEG)):
                continue
            for a0, a1 in ax.intervals.get(b) or []:
                best = None
                for depth in np.arange(deepest(ax.R, FLAT_WALLS * prof.min_wall)[0], ax.R - 1e-9, -TEARDROP_STEP):
                    td, rc = teardrop(ax, w, a0, a1, float(depth), n)
                    if td is None:
                        continue
                    ring = subtract(cylinder(ax.origin, ax.direction, a0, a1, rc + c + TEARDROP_MARGIN, n, cutter=True),
                                    [cylinder(ax.origin, ax.direction, a0 - 1, a1 + 1, ax.R, n)])
                    if all((x := solids[o] ^ ring).is_empty() or x.volume() < 1e-9
                           for o in ax.bodies if o != b and o in solids):
                        best = (td, float(depth))
                        break
                if best is not None:
                    # outside the knuckle's hole or cone recess (both within R - min_wall)
                    core = cylinder(ax.origin, ax.direction, a0 - 1.0, a1 + 1.0, ax.R - prof.min_wall / 2, n)
                    add.setdefault(b, []).append((ax.name, (subtract(best[0], [core]), best[1])))
    for p in asm.parts:
        if p.name not in add:
            continue
        p.solid = _clean(union([p.solid] + [td for _, (td, _) in add[p.name]]))
        flats: dict = {}                     # hinge -> its knuckles' flats (a hinge named once)
        for a, (_, d) in add[p.name]:
            flats.setdefault(a, []).append(f"{d:.2f}")
        notes.append(f"{p.name}: teardrops under the knuckles of "
                     + ", ".join(f"{a} (flat{'s' if len(ds) > 1 else ''} {', '.join(ds)} mm below the axis)"
                                 for a, ds in flats.items())
                     + " (print-only, mlc.mesh.pivot)")
    return notes


def flat_hinges(asm) -> list:
    """:func:`chamfer_crossings`, then :func:`teardrops` in the room they leave; the notes.
    ``mlc stl`` (:func:`mlc.mesh.pipeline.export_assembly`) runs it on a mechanism of its own built
    with dense poses (a library gate), after the build and its orientation."""
    return chamfer_crossings(asm) + teardrops(asm)


__all__ = ["CHAMFER", "flat_hinges", "FLAT_DEG", "SLOPE", "TEARDROPS", "chamfer_crossings", "chamfer_cuts", "teardrop",
           "teardrops"]
