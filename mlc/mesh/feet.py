"""Print-only feet: the parts that move in one plane are carried down to the bed (issue 13, item 1).

All lengths in mm, in the model's rest frame (the parts as built).

*Why.* In a library gate the lever loop (core_ab, the four input levers, core_cd) turns only
about its five hinges, all parallel to the model's z: its parts keep their heights along z in
every pose of the mechanism.  With the model's z up the loop stands on its slab edges and
knuckle ends 5.0 mm above the bed (fdm), held up by core_cd's end box at d (shifted down by half
a slab width in the simulation geometry, ``mlc.gates.library.CD_OFFSET``) and the universal
joint: the first layer is under 1 % of the footprint, while the loop's own section there is
40-44 % of it (docs/printing.md, *What holds the print off the bed*).

*What.* :func:`add_feet` gives each such part a **foot**: its own section just above the level
its slabs start at (:data:`FOOT_EPS` above the median lowest point of those parts, or above the
part's own lowest point where that is higher), extruded
straight down to the lowest point of the assembly (the bed, with the model's z up).  A part that
moves in a plane moves its foot in the same plane, so two feet keep the gap of the two sections
they come from.  Everything else that can come near a foot -- another part's material in the
foot's height band (down to a clearance below it and up to a clearance above it), in the rest
pose as printed and in every given pose (the logic states and the dense paths and switches of the
``motion_clearance`` goal), moved into the foot's part's frame and projected on the plane -- is
taken out of the section, grown by the clearance x (1 + :data:`FOOT_MARGIN`) plus the slack of
two economies (poses that move the other part by at most :data:`FOOT_MERGE_MM` from one already
taken share its shadow; the shadows' union and the foot's outline are simplified to
:data:`FOOT_SIMPLIFY_MM`: 12 s for NAND fdm's 814 poses, not minutes).  So each foot
keeps the clearance from every other part in every one of those poses (the ``min_gap``,
``states`` and ``motion_clearance`` checks measure it again on the finished parts).  The
section is simplified, slivers narrower than :data:`FOOT_OPEN` x the minimum wall (a
morphological opening) and pieces under :data:`FOOT_MIN_AREA` x min_feature^2 are dropped, and
what is left grows by :data:`FOOT_GROW` x the minimum wall (the shadows were grown by twice that
more): every foot is at least (FOOT_OPEN + 2 FOOT_GROW) x the minimum wall across, wider by
FOOT_GROW on each side than a slab of the minimum wall it carries, and passes the measured wall
check (session 38; until then the opened section was simplified after, which left feet under the
minimum: 0.515-0.591 mm at mjp, 0.903-1.183 mm at fdm, ``mesh_gates_walls_s37*.json``).

The feet are real solid material of the part (the slicer prints them; they are vertical prisms,
so they need no support of their own), unioned with it before the orientation is chosen.  The
simulation scene is unchanged: the feet are print-only, a few millimetres of extra slab under the
loop that moves with it.  Parts are *planar* when, in every pose, their motion relative to one of
them keeps the direction ``d`` (a hinge direction) and moves nothing along ``d``
(:data:`PLANAR_RAD`, :data:`PLANAR_MM`; relative, since the mechanism floats and each pose also
moves it as a whole); :func:`plan_feet` takes the hinge direction and sign whose planar parts have
the largest section to carry down.  Only mechanisms built with dense poses get feet (a library
gate in ``mlc stl``; compiled circuits, and ``build_assembly`` without ``motion_poses``, do not).
Measured on the 8 library gates (benchmarks/mesh_bed_feet.py, docs/printing.md): bed contact
0.6-0.9 % -> 35-39 % of the footprint in fdm, every blocking check still passing.
"""
from __future__ import annotations

import numpy as np

#: add the feet (``mlc stl`` for a mechanism with dense poses); False: the parts as before
BED_FEET = True
#: the section is taken this far (mm) above the level the planar parts' slabs start at
FOOT_EPS = 0.05
#: the other parts' shadows are grown by the clearance x (1 + this): the round offset's polygon
#: lies inside the circle, and the check must find at least the clearance
FOOT_MARGIN = 0.05
#: poses that move another part by at most this (mm, relative to the foot's part) from a pose
#: already taken give one shadow, grown by this much more
FOOT_MERGE_MM = 0.1
#: the shadows' union and a foot's outline are simplified to this (mm; the shadows are grown by
#: twice as much more)
FOOT_SIMPLIFY_MM = 0.02
#: a grown foot's outline is simplified to this (mm): its near-duplicate vertices merged, the foot
#: thinner by at most twice this, far inside FOOT_GROW's margin over the minimum wall
FOOT_DEDUP_MM = 0.001
#: slivers narrower than this many minimum walls are dropped from a foot's section
FOOT_OPEN = 0.9
#: ... and what is left is grown by this many minimum walls (the other parts' shadows by twice as
#: much more): every point of a foot's section lies in a disc of (FOOT_OPEN + 2 FOOT_GROW) minimum
#: walls inside it, so the foot's walls are at least that (session 38: opened at FOOT_OPEN alone
#: and then simplified, a foot under a slab of the minimum wall measured 0.515-0.591 mm at mjp)
FOOT_GROW = 0.1
#: pieces of a foot's section smaller than this many min_feature^2 are dropped
FOOT_MIN_AREA = 1.0
#: a part is planar when its rotation turns d by less than this (rad) in every pose ...
PLANAR_RAD = 1e-5
#: ... and it moves along d by less than this (mm)
PLANAR_MM = 1e-3
#: the foot must gain at least this (mm) of height to be worth adding
MIN_DROP_MM = 0.1


def _frame(d) -> np.ndarray:
    """4x4 rotation taking ``d`` to +z (model -> the frame the feet are cut in)."""
    from mlc.geometry.rotation import rotation_between
    T = np.eye(4)
    T[:3, :3] = rotation_between(np.asarray(d, float), [0.0, 0.0, 1.0])
    return T


def planar_parts(asm, Ts: list, d) -> list:
    """Names of the body parts that move in planes normal to ``d`` relative to one another: of
    every body part taken as reference, the largest set of body parts whose transforms relative
    to it (``Ts``: part transforms, :meth:`Assembly.part_transforms`; the mechanism floats, so
    each pose also moves it as a whole) keep the direction ``d`` and move nothing along it."""
    d = np.asarray(d, float) / np.linalg.norm(d)
    bodies = [p.name for p in asm.parts if p.kind == "body"]
    best: list = []
    for ref in bodies:
        out = []
        for n in bodies:
            ok = True
            for T in Ts:
                M = np.linalg.solve(T[ref], T[n])
                if np.linalg.norm(M[:3, :3] @ d - d) > PLANAR_RAD or abs(float(d @ M[:3, 3])) > PLANAR_MM:
                    ok = False
                    break
            if ok:
                out.append(n)
        if len(out) > len(best):
            best = out
    return best


def _directions(asm) -> list:
    """Candidate plane normals: the hinge directions, one of each line up to sign."""
    out = []
    for ax in asm.axes:
        d = np.asarray(ax.direction, float)
        d = d / np.linalg.norm(d)
        if not any(abs(abs(float(d @ e)) - 1) < 1e-6 for e in out):
            out.append(d)
    return out


def _low(solid, F) -> float:
    from mlc.mesh.build import transform_solid
    return float(np.asarray(transform_solid(solid, F).bounding_box())[2])


def plan_feet(asm, Ts: list) -> tuple | None:
    """(up direction ``d``, planar part names, level, bed) of the feet, or None.

    The feet go down along ``-d``, so ``d`` must be a direction the print can have up: with
    ``orient: as_is`` only the model's +z (the bed is the model's lowest z), with ``axes_flat``
    none (every hinge axis lies on the bed, so no plane of motion is parallel to it); with
    ``auto`` and ``auto_config`` any hinge direction, either sign (the orientation search, run
    after the feet, chooses up).  Of those, the one with the most planar parts (at least two), then
    the largest section at ``level``, with the bed (the assembly's lowest point along ``d``) at
    least :data:`MIN_DROP_MM` below the level."""
    import manifold3d as mf
    from mlc.mesh.build import transform_solid
    orient = getattr(asm.profile, "orient", "auto")
    if orient == "axes_flat":
        return None
    best = None
    by = {p.name: p for p in asm.parts}
    z = np.array([0.0, 0.0, 1.0])
    for d0 in _directions(asm):
        if orient == "as_is" and abs(abs(float(d0 @ z)) - 1) > 1e-6:
            continue
        names = planar_parts(asm, Ts, d0)
        if len(names) < 2:
            continue
        for d in (d0, -d0):
            if orient == "as_is" and float(d @ z) < 0:
                continue
            F = _frame(d)
            bed = min(_low(p.solid, F) for p in asm.parts if not p.solid.is_empty())
            lows = sorted(_low(by[n].solid, F) for n in names)
            level = float(np.median(lows))
            if level - bed < MIN_DROP_MM:
                continue
            area = mf.CrossSection.batch_boolean(
                [transform_solid(by[n].solid, F).slice(level + FOOT_EPS) for n in names], mf.OpType.Add).area()
            if best is None or (len(names), area) > best[0]:
                best = ((len(names), area), d, names, level, bed)
    return None if best is None else best[1:]


def _shadow(solid, z0, z1):
    """The projection on the plane of the part of ``solid`` (already in the feet frame) between
    heights ``z0`` and ``z1``; None if there is none."""
    import manifold3d as mf
    b = np.asarray(solid.bounding_box())
    if b[2] > z1 or b[5] < z0:
        return None
    lo = [b[0] - 1, b[1] - 1, z0]
    box = mf.Manifold.cube([b[3] - b[0] + 2, b[4] - b[1] + 2, z1 - z0]).translate(lo)
    cut = solid ^ box
    if cut.is_empty():
        return None
    return cut.project()


def _planar_2x3(M) -> np.ndarray:
    """The in-plane part (2x3) of a feet-frame transform that keeps z."""
    return np.hstack([M[:2, :2], M[:2, 3:4]])


def add_feet(asm, Ts: list, names: list | None = None) -> list:
    """Add a foot to every planar part of ``asm`` (module docstring), keeping the clearance from
    every other part as printed and in every pose of ``Ts`` (part transforms); returns the notes
    (also appended to ``asm.notes``) and records ``asm.feet`` = ``{part: foot volume mm^3}``."""
    import manifold3d as mf
    from mlc.mesh.build import transform_solid, _clean
    notes: list = []
    asm.feet = {}
    asm.feet_free = {}
    if not BED_FEET or not asm.parts:
        return notes
    eye = {p.name: np.eye(4) for p in asm.parts}
    Ts = [eye] + list(Ts)
    plan = plan_feet(asm, Ts)
    if plan is None:
        return notes
    d, planar, level, bed = plan
    prof = asm.profile
    c = prof.clearance
    grow = c * (1 + FOOT_MARGIN)
    F = _frame(d)
    Fi = np.linalg.inv(F)
    local = {p.name: transform_solid(p.solid, F) for p in asm.parts}
    # each part's foot starts at the level, or at its own lowest point if that is higher (a part
    # that starts above the level has no section there: mjp NAND's first run gave only three feet)
    tops = {n: max(level, float(np.asarray(local[n].bounding_box())[2])) + FOOT_EPS for n in planar}
    z0, z1 = bed - c, max(tops.values()) + c   # the band another part must keep out of (with its margin)
    # the planar parts' own shadows in the band: moved in the plane, pose by pose
    shadows = {n: _shadow(local[n], z0, z1) for n in planar}
    seg = max(32, int(prof.circular_segments))
    # the shadows: of poses that move a part by at most FOOT_MERGE_MM (relative to the foot's
    # part) from one already taken, one is taken and every shadow grown by that much more
    slack = FOOT_MERGE_MM + 2 * FOOT_SIMPLIFY_MM
    for X in planar:
        top = tops[X]
        sec = local[X].slice(top)
        if sec.is_empty():
            continue
        keep_out = []
        TX = np.array([T[X] for T in Ts])
        sb = np.asarray(sec.bounds(), float).ravel()          # only shadows near the section matter
        g = FOOT_GROW * prof.min_wall
        reach = grow + slack + 2 * g + 1e-3

        def near(b):
            return bool(b[0] <= sb[2] + reach and sb[0] <= b[2] + reach and b[1] <= sb[3] + reach
                        and sb[1] <= b[3] + reach)

        for Y in asm.parts:
            if Y.name == X:
                continue
            if Y.name in planar and shadows[Y.name] is None:
                continue
            V = np.asarray(local[Y.name].to_mesh().vert_properties, float)[:, :3]
            r = float(np.max(np.linalg.norm(V, axis=1)))      # moves bounded on Y's points
            Ms = F @ np.linalg.solve(TX, np.array([T[Y.name] for T in Ts])) @ Fi   # Y into X's frame
            taken = np.zeros((0, 4, 4))
            for M in Ms:
                # |(M - K) p| <= |dR|_F |p| + |dt| for every point p of Y
                if len(taken) and np.min(np.linalg.norm(taken[:, :3, :3] - M[:3, :3], axis=(1, 2)) * r
                                         + np.linalg.norm(taken[:, :3, 3] - M[:3, 3], axis=1)) <= FOOT_MERGE_MM:
                    continue
                W = V @ M[:3, :3].T + M[:3, 3]
                if W[:, 2].min() > z1 or W[:, 2].max() < z0:
                    continue
                lo, hi = W.min(axis=0), W.max(axis=0)
                if not near([lo[0], lo[1], hi[0], hi[1]]):
                    continue
                taken = np.concatenate([taken, M[None]])
                if Y.name in planar:
                    keep_out.append(shadows[Y.name].transform(_planar_2x3(M)))
                else:
                    sh = _shadow(transform_solid(local[Y.name], M), z0, z1)
                    if sh is not None:
                        keep_out.append(sh)
        if keep_out:
            # (grown by 2 g more: this foot grows by g below, and so may the other's)
            away = mf.CrossSection.batch_boolean(keep_out, mf.OpType.Add).simplify(FOOT_SIMPLIFY_MM).offset(
                grow + slack + 2 * g, mf.JoinType.Round, 2.0, seg)
            sec = sec - away
        # simplified first, then opened and grown: nothing thins the section after
        sec = sec.simplify(FOOT_SIMPLIFY_MM)
        w = FOOT_OPEN * prof.min_wall / 2
        if w > 0 and not sec.is_empty():
            sec = sec.offset(-w, mf.JoinType.Round, 2.0, seg).offset(w, mf.JoinType.Round, 2.0, seg) ^ sec
        pieces = [x for x in sec.decompose() if x.area() >= FOOT_MIN_AREA * prof.min_feature ** 2]
        if not pieces:
            continue
        sec = mf.CrossSection.batch_boolean(pieces, mf.OpType.Add)
        if g > 0:
            # (then the grown outline's near-duplicate vertices merged, FOOT_DEDUP_MM: left in,
            # they extrude into walls of zero width that float32 STL splits off the part)
            sec = sec.offset(g, mf.JoinType.Round, 2.0, seg).simplify(FOOT_DEDUP_MM)
        # from the bed up into the part (FOOT_EPS of overlap: one solid after the union)
        foot = mf.Manifold.extrude(sec, top - bed).translate([0.0, 0.0, bed])
        foot = transform_solid(foot, Fi)
        part = asm.part(X)
        asm.feet_free[X] = part.solid
        before = float(part.solid.volume())
        part.solid = _clean(part.solid + foot)
        asm.feet[X] = round(float(part.solid.volume()) - before, 3)
    if asm.feet:
        du = ", ".join(f"{x:.3g}" for x in d)
        drop = ", ".join(f"{tops[n] - FOOT_EPS - bed:.2f}" for n in asm.feet)
        notes.append(f"feet (print only): {', '.join(asm.feet)} carried {drop} mm down to the bed "
                     f"along the model's ({du}) ({sum(asm.feet.values()):.0f} mm^3), clear of the other parts by "
                     f"the clearance as printed and in {len(Ts) - 1} poses (mlc.mesh.feet)")
    asm.notes += notes
    return notes


__all__ = ["add_feet", "plan_feet", "planar_parts", "BED_FEET"]
