"""The print pose of an assembly: which way is up on the bed (issue 13, item 1).

All lengths in mm (the parts' meshes); directions are unit vectors of the model frame.

The print pose is a configuration of the mechanism, rotated so that a chosen "up" direction of
the model points along +z, then centred on the bed and put on z = 0
(``mlc.mesh.build._orientation``).  With ``orient: auto`` (and ``as_is``, ``axes_flat``) the
configuration is rest (the parts as built); with ``orient: auto_config`` the configurations the
printed joints reach are searched too (:func:`best_rotation`, :mod:`mlc.mesh.configs`) and each
part is first moved into the chosen one (``Assembly.print_pose``).  The STL/3MF writer, the
print size and the bed checks use ``Assembly.print_T`` (the configuration, then
``Assembly.orient``); the other checks stay in the model's rest frame (the states and motion
checks pose the parts themselves; retention and walls do not change under the joints' motion,
and the configuration search keeps every pair of parts at least the clearance apart, or no closer
than at rest, which the report's ``min_gap`` checks).

``orient: auto`` chooses up by :func:`search_up`:

1. *candidates*: :data:`SPHERE_DIRS` directions spread evenly over the sphere (a Fibonacci
   lattice, about 10 degrees apart at 400), the world axes and every slab's normal (both signs:
   the candidates of the first search, session 20);
2. each is scored by :func:`mlc.mesh.printability.quick_stats` on a coarse grid (the longest
   side of the assembly / :data:`COARSE_CELLS`): the support volume (overhangs and islands)
   exactly as the report computes it, bed contact and footprint from the grid columns;
3. the :data:`REFINE_STARTS` best (at least :data:`START_APART_DEG` apart) are refined by a
   pattern search on the sphere (8 directions at each of :data:`REFINE_STEPS_DEG` degrees,
   moving while the score falls by at least :data:`MIN_GAIN`);
4. the :data:`FINAL` best distinct directions, and the :data:`EXTRA_EXACT` best of the step-1
   axis and normal candidates, are measured with :func:`mlc.mesh.printability.bed_stats` on the report's own
   grid (``mlc.mesh.checks.bed_checks``); the :data:`EXACT_STARTS` best are refined again by
   the same pattern search on that grid (:data:`EXACT_STEPS_DEG`, at most :data:`EXACT_MAX`
   measurements: near the overhang limit a small tilt decides whether a column of support
   rests on a part), and the best by :func:`pose_key` is kept -- unless it fails as many goals
   as the best axis or slab normal (:data:`GOALS_TO_LEAVE`; with it off: and scores less than
   :data:`MIN_GAIN` better), then that one: mlc's support estimate was checked against
   PrusaSlicer near the axes and slab normals and at 45 degrees, and does not rank moderate tilts
   as the slicer does (docs/printing.md).

The score (:func:`pose_key`): first the number of the bed goals a pose fails (support resting on
a part, support over ``SUPPORT_MAX`` of the part volume, bed contact under ``BED_CONTACT_MIN``
of the footprint), then support fraction + inside-support fraction - contact fraction (support
between parts counted twice: it cannot be removed without freeing the joints).

The search costs about ``SPHERE_DIRS + 50 x REFINE_STARTS`` coarse evaluations (about 700 for a
library gate) and up to :data:`EXACT_MAX` exact ones; an assembly for which that many coarse
evaluations exceed :data:`SEARCH_TRIANGLES` triangle-evaluations (over about 67 000 triangles: a
compiled circuit) keeps the axis and slab-normal candidates, unrefined (the session-20 search).
"""
from __future__ import annotations

import numpy as np

from mlc.geometry.rotation import quat_to_matrix, rotation_between

#: directions of the Fibonacci lattice in the global stage
SPHERE_DIRS = 400
#: the assembly's longest side over this: the grid spacing (mm) of the coarse stage
COARSE_CELLS = 40
#: best coarse candidates refined by the pattern search
REFINE_STARTS = 4
#: the pattern search's steps (degrees), each kept while it improves the score
REFINE_STEPS_DEG = (8.0, 4.0, 2.0, 1.0, 0.5)
#: the given candidates (axes, slab normals) best on the coarse grid also measured exactly
EXTRA_EXACT = 4
#: refined starts at least this far apart (degrees)
START_APART_DEG = 15.0
#: best distinct directions measured exactly at the end
FINAL = 6
#: of those, the best refined again on the report's own grid (exact bed_stats), by these steps
EXACT_STARTS = 2
EXACT_STEPS_DEG = (2.0, 1.0, 0.5, 0.25)
#: leave the best axis or slab normal only for an up that fails fewer bed goals (True), or also
#: for one the estimate scores MIN_GAIN better (False).  PrusaSlicer 2.5 on the library gates in
#: fdm (benchmarks/results/slicer_gates.json, pose "estimate"): the estimate's tilted ups cut its
#: support figure by 8-42 % but PrusaSlicer's support changed by -1 % to +61 % (NOR fdm)
GOALS_TO_LEAVE = True
#: at most this many exact measurements in all
EXACT_MAX = 120
#: a refinement step is taken, and a direction other than the best axis or slab normal kept, only
#: if it lowers the score by this much (a fraction of the part volume) or fails fewer goals: the
#: estimate moved by up to 0.103 under tilts of 0.25-0.3 degrees on the library gates (fdm:
#: CIMPLY 114.8 -> 104.5 %, where PrusaSlicer's support grew 3 %), the grid's noise
MIN_GAIN = 0.15
#: the lattice and refinements only if triangles x (SPHERE_DIRS + 50 REFINE_STARTS) stays under this
SEARCH_TRIANGLES = 4.0e7


def fibonacci_sphere(n: int) -> np.ndarray:
    """``n`` unit vectors spread evenly over the sphere (deterministic)."""
    if n <= 0:
        return np.zeros((0, 3))
    i = np.arange(n) + 0.5
    phi = np.arccos(1 - 2 * i / n)
    th = np.pi * (1 + 5 ** 0.5) * i
    return np.stack([np.cos(th) * np.sin(phi), np.sin(th) * np.sin(phi), np.cos(phi)], 1)


def structural_ups(scene) -> list:
    """The world axes and every slab's normal (the thinnest side of each box), both signs,
    without repeats: the candidates of the first ``orient: auto`` (session 20)."""
    cands = [np.array(v, float) for v in np.eye(3)]
    for b in scene.bodies:
        Rb = quat_to_matrix(b.orientation)
        for bx in b.boxes:
            R = Rb @ quat_to_matrix(bx.orientation)
            cands.append(R[:, int(np.argmin(bx.size))])
    return _unique([sg * c / np.linalg.norm(c) for c in cands for sg in (1.0, -1.0)])


def hinge_ups(directions) -> list:
    """Up directions at 45 degrees from two hinge directions at once (both signs): a hinge axis
    at 45 degrees prints its knuckle ends and its bore each at the overhang limit.  For every
    pair of distinct lines among ``directions`` (unit vectors), the solutions of
    |u . d1| = |u . d2| = cos 45 degrees, |u| = 1; for a single line, the ups at 45 degrees from
    it in the planes of the world axes."""
    ds = _unique([np.asarray(d, float) / np.linalg.norm(d) for d in directions], tol=1e-6)
    lines = []
    for d in ds:
        if all(abs(np.dot(d, e)) < 1 - 1e-6 for e in lines):
            lines.append(d)
    c = np.cos(np.radians(45.0))
    out = []
    for i, d1 in enumerate(lines):
        for w in np.eye(3):
            p = w - np.dot(w, d1) * d1
            if np.linalg.norm(p) > 1e-6:
                p /= np.linalg.norm(p)
                out += [c * d1 + c * p, c * d1 - c * p, -c * d1 + c * p, -c * d1 - c * p]
        for d2 in lines[i + 1:]:
            g = float(np.dot(d1, d2))
            n = np.cross(d1, d2)
            n /= np.linalg.norm(n)
            G = np.array([[1.0, g], [g, 1.0]])
            for s1 in (1.0, -1.0):
                for s2 in (1.0, -1.0):
                    a, b = np.linalg.solve(G, [s1 * c, s2 * c])
                    r = 1.0 - (a * a + b * b + 2 * a * b * g)
                    if r >= 0:
                        for sg in (1.0, -1.0):
                            out.append(a * d1 + b * d2 + sg * np.sqrt(r) * n)
    return _unique([u / np.linalg.norm(u) for u in out])


def _unique(vs, tol=1e-6) -> list:
    out = []
    for v in vs:
        if all(np.dot(v, u) < 1 - tol for u in out):
            out.append(np.asarray(v, float))
    return out


def pose_key(support_fraction: float, inside_fraction: float, contact_fraction: float) -> tuple:
    """The order of print poses (smaller is better): the number of bed goals failed, then
    support + inside support - bed contact (fractions of the part volume and footprint)."""
    from mlc.mesh.checks import BED_CONTACT_MIN, SUPPORT_MAX
    bad = int(inside_fraction > 1e-9) + int(support_fraction > SUPPORT_MAX) + int(contact_fraction < BED_CONTACT_MIN)
    return (bad, round(support_fraction + inside_fraction - contact_fraction, 6))


def _better(a: tuple, b: tuple) -> bool:
    """Key ``a`` beats ``b``: fewer goals failed, or the score lower by at least :data:`MIN_GAIN`
    (smaller differences are the grid's noise, not a better print)."""
    return a[0] < b[0] or (a[0] == b[0] and a[1] < b[1] - MIN_GAIN)


def _ring(u, s: float, c: float) -> list:
    """The 8 directions a step (sine ``s``, cosine ``c``) from ``u``, 45 degrees apart around it."""
    e1, e2 = _frame(u)
    return [c * u + s * (np.cos(a) * e1 + np.sin(a) * e2) for a in np.radians(np.arange(0, 360, 45))]


def _frame(u):
    a = np.eye(3)[int(np.argmin(np.abs(u)))]
    e1 = np.cross(u, a)
    e1 /= np.linalg.norm(e1)
    return e1, np.cross(u, e1)


def search_up(V, F, part_volume: float, extra_ups=(), overhang_deg: float = 45.0, first_layer: float = 0.2,
              exact=None, seeds=(), own=None, island_mm: float = 0.0) -> dict:
    """The up direction of the print: vertices ``V`` (mm, model frame) and triangles ``F`` of
    all parts, ``own`` the part of each triangle, their total volume (mm^3); ``extra_ups``: candidate directions always tried
    (the structural ones); ``seeds``: more candidates of the global stage (:func:`hinge_ups`).
    ``exact(up) -> BedStats``, when given, measures the final
    candidates on the report's grid.  Returns ``{"up", "key", "stats", "evaluated"}``."""
    from mlc.mesh.printability import quick_stats
    V = np.asarray(V, float)
    F = np.asarray(F, np.int64)
    ext = float(np.max(V.max(0) - V.min(0)))
    h = max(ext / COARSE_CELLS, 0.05)
    # the lattice and the refinements only where they fit the budget (a library gate: ~10^4
    # triangles); a compiled circuit keeps the given candidates, unrefined
    n_sphere = SPHERE_DIRS if len(F) * (SPHERE_DIRS + 50 * REFINE_STARTS) <= SEARCH_TRIANGLES else 0
    vol = max(part_volume, 1e-12)
    cache: dict = {}

    def score(u):
        k = tuple(np.round(u, 9))
        if k not in cache:
            R = rotation_between(u, [0, 0, 1.0])
            q = quick_stats(V @ R.T, F, h, overhang_deg, first_layer, own, island_mm)
            cf = q["contact_mm2"] / q["footprint_mm2"] if q["footprint_mm2"] > 0 else 0.0
            cache[k] = pose_key(q["support_mm3"] / vol, q["support_inside_mm3"] / vol, cf)
        return cache[k]

    extra = _unique([np.asarray(u, float) / np.linalg.norm(u) for u in extra_ups])
    sphere = (list(fibonacci_sphere(n_sphere)) + [np.asarray(u, float) / np.linalg.norm(u) for u in seeds]
              if n_sphere else [])
    scored = sorted(((score(u), i, u) for i, u in enumerate(extra + sphere)), key=lambda x: (x[0], x[1]))
    starts = []
    for key, _, u in scored:
        if len(starts) >= (REFINE_STARTS if n_sphere else 0):
            break
        if all(np.dot(u, v) < np.cos(np.radians(START_APART_DEG)) for _, v in starts):
            starts.append((key, u))
    refined = []
    for key, u in starts:
        for step in REFINE_STEPS_DEG:
            s, c = np.sin(np.radians(step)), np.cos(np.radians(step))
            while True:
                best = min(_ring(u, s, c), key=score)
                if _better(score(best), key):
                    u, key = best / np.linalg.norm(best), score(best)
                else:
                    break
        refined.append((key, u))
    pool = sorted(refined + [(k, u) for k, _, u in scored], key=lambda x: x[0])
    final = _unique([u for _, u in pool], tol=1e-4)[:FINAL]
    # the given candidates (axes, slab normals) best on the coarse grid, measured exactly too: the
    # best of them by the report's own measure is the one the guard keeps
    top_extra = [u for k, _, u in scored if any(np.allclose(u, e) for e in extra)][:EXTRA_EXACT]
    for u in top_extra:
        if all(not np.allclose(u, v) for v in final):
            final.append(u)
    best_extra = top_extra[0] if top_extra else None
    if exact is None:
        u = final[0]
        return {"up": u, "key": score(u), "stats": None, "evaluated": len(cache), "grid_mm": h}
    memo: dict = {}

    def exact_key(u):
        k = tuple(np.round(u, 9))
        if k not in memo:
            st = exact(u)
            memo[k] = (pose_key(st.support_fraction, st.support_inside_mm3 / max(st.part_volume_mm3, 1e-12),
                                st.contact_fraction), st)
        return memo[k][0]

    ranked = sorted(((exact_key(u), i, u) for i, u in enumerate(final)), key=lambda x: (x[0], x[1]))
    if top_extra:
        best_extra = min(top_extra, key=exact_key)
    # the report's own grid decides near the overhang limit: refine the best few on it
    best = (ranked[0][0], ranked[0][2])
    for key, _, u in ranked[:EXACT_STARTS if n_sphere else 0]:
        for step in EXACT_STEPS_DEG:
            s, c = np.sin(np.radians(step)), np.cos(np.radians(step))
            while len(memo) < EXACT_MAX:
                nxt = min(_ring(u, s, c), key=exact_key)
                if _better(exact_key(nxt), key):
                    u, key = nxt / np.linalg.norm(nxt), exact_key(nxt)
                else:
                    break
        if key < best[0]:
            best = (key, u)
    if best_extra is not None:          # the best axis or slab normal, unless clearly beaten
        ke = exact_key(best_extra)
        if not _better(best[0], ke):
            best = (ke, best_extra)
    est = best
    # the estimate alone is not trusted away from the given candidates (PrusaSlicer did not
    # confirm its gains there): another up is kept only if it meets more bed goals
    if best_extra is not None and GOALS_TO_LEAVE and best[0][0] >= exact_key(best_extra)[0]:
        best = (exact_key(best_extra), best_extra)
    u, ue = best[1], est[1]
    return {"up": u, "key": best[0], "stats": memo[tuple(np.round(u, 9))][1], "evaluated": len(cache),
            "exact_evaluated": len(memo), "grid_mm": h,
            "estimate_up": ue, "estimate_key": est[0], "estimate_stats": memo[tuple(np.round(ue, 9))][1]}


def report_grid(size_mm, min_wall: float) -> float:
    """The grid spacing (mm) of the report's bed check for a print of extent ``size_mm``."""
    return max(0.05, min(min_wall, max(size_mm) / 150))


def _search_pose(asm, part_T: dict, ups, dirs) -> dict:
    """:func:`search_up` on the parts of ``asm`` moved by ``part_T`` ({part: 4x4}, missing: rest),
    the exact measure on the report's grid, centred on the bed as ``_orientation`` puts it."""
    from mlc.mesh.build import _h, transform_solid
    from mlc.mesh.checks import OVERHANG_DEG, island_side
    from mlc.mesh.printability import bed_stats, merged_mesh

    solids = [(p.name, p.solid if p.name not in part_T else transform_solid(p.solid, part_T[p.name]))
              for p in asm.parts if not p.solid.is_empty()]
    V, F, own = merged_mesh(solids)
    first_layer = min(0.2, asm.profile.min_wall / 2)
    part_volume = float(sum(s.volume() for _, s in solids))

    def exact(u):
        R = rotation_between(u, [0, 0, 1.0])
        posed = [(n, transform_solid(s, _h(R, np.zeros(3)))) for n, s in solids]
        lo = np.min([np.asarray(s.bounding_box())[:3] for _, s in posed], axis=0)
        hi = np.max([np.asarray(s.bounding_box())[3:] for _, s in posed], axis=0)
        # centred on the bed as _orientation puts it: the report's grid sees the same columns
        posed = [(n, s.translate([-float(lo[0] + hi[0]) / 2, -float(lo[1] + hi[1]) / 2, -float(lo[2])]))
                 for n, s in posed]
        return bed_stats(posed, OVERHANG_DEG, report_grid(hi - lo, asm.profile.min_wall), first_layer=first_layer,
                         island_mm=island_side(asm.profile))

    return search_up(V, F, part_volume, ups, OVERHANG_DEG, first_layer, exact=exact,
                     seeds=hinge_ups(dirs), own=own, island_mm=island_side(asm.profile))


def best_rotation(asm) -> np.ndarray:
    """``orient: auto``: the rotation (3 x 3, model -> print frame) taking the best "up" of
    :func:`search_up` to +z; a note says which and how it scored.

    ``orient: auto_config`` also searches the configurations of the mechanism
    (:func:`mlc.mesh.configs.best_configuration`: the input levers' hinge angles its printed joints
    reach with every part at least the clearance apart) and prints the best other configuration
    in its best up (``asm.print_pose``) when that up beats the rest configuration's best by the
    same rule as an up beats the best axis or slab normal (:func:`_better` on the report's own
    measure: fewer goals failed, or :data:`MIN_GAIN` of the part volume less)."""
    dirs = [ax.direction for ax in asm.axes] + [a for uj in asm.ujoints for a in uj.axes]
    res = _search_pose(asm, {}, structural_ups(asm.scene), dirs)
    asm.print_pose = {}
    if asm.profile.orient == "auto_config":
        from mlc.mesh import configs
        why = configs.applicable(asm)
        cfg = None if why else configs.best_configuration(asm)
        if why or cfg is None:
            asm.notes.append(f"configuration: the rest configuration is printed ({why or 'no other is reached'})")
        else:
            ups, cdirs = configs.posed_directions(asm, cfg["kin"], cfg["T"])
            rc = _search_pose(asm, cfg["part_T"], ups, cdirs)
            ang = ", ".join(f"{k.split(':')[0]} {v:+g}" for k, v in cfg["angles_deg"].items())
            sc, sr = rc["stats"], res["stats"]
            fig = (f"support {100 * sc.support_fraction:.1f} % of the part volume ({sc.support_inside_mm3:.1f} mm^3 "
                   f"between parts), bed contact {100 * sc.contact_fraction:.1f} %, against {100 * sr.support_fraction:.1f} % "
                   f"({sr.support_inside_mm3:.1f} mm^3), {100 * sr.contact_fraction:.1f} % at rest")
            if _better(rc["key"], res["key"]):
                asm.print_pose = cfg["part_T"]
                asm.print_config = cfg["angles_deg"]
                res = rc
                asm.notes.append(
                    f"configuration: printed with the input levers' hinges turned from rest ({ang} degrees; "
                    f"{cfg['reached']} configurations reached on a {configs.SCAN_STEP_DEG:g}-degree grid with every "
                    f"part at least the clearance apart, {cfg['evaluated']} measured): {fig}; turn them back to rest "
                    f"after printing")
            else:
                asm.notes.append(f"configuration: the rest configuration is printed; the best other ({ang} degrees) "
                                 f"is not {MIN_GAIN:g} of the part volume better: {fig}")
    u, st = res["up"], res["stats"]
    asm.pose_search = res
    ue, se = res["estimate_up"], res["estimate_stats"]
    if not np.allclose(u, ue):
        asm.notes.append(
            f"orientation: the best up by mlc's support estimate alone, the model's ({ue[0]:.3g}, {ue[1]:.3g}, "
            f"{ue[2]:.3g}) (support {100 * se.support_fraction:.1f} %), was not kept: it meets no more bed goals "
            f"than the axes and slab normals, and PrusaSlicer did not confirm such gains (docs/printing.md)")
    asm.notes.append(
        f"orientation: up is the model's ({u[0]:.3g}, {u[1]:.3g}, {u[2]:.3g}), the best bed of "
        f"{res['evaluated']} directions searched (sphere, axes and slab normals, refined; least support "
        f"resting on parts, support and bed contact goals): support {100 * st.support_fraction:.1f} % of the "
        f"part volume ({st.support_inside_mm3:.1f} mm^3 between parts), bed contact {100 * st.contact_fraction:.1f} %")
    return rotation_between(u, [0, 0, 1.0])


__all__ = ["best_rotation", "fibonacci_sphere", "hinge_ups", "pose_key", "search_up", "structural_ups"]
