"""Scene -> printable assembly + printability report, for one gate or many.

A scene is split into *mechanisms* (bodies connected by bonds or muscles).  Mechanisms
that are copies of each other up to a translation (a grid of gates, repeated cells) are
built and checked once and the result is translated: the parts, the poses of every
logic state and the report are the same.  Each mechanism is posed at the equilibrium of
every input state of its own inputs (static verification), so a scene of many
independent gates costs the sum, not the product, of their state counts.  Between
different mechanisms, the parts must keep the clearance as printed and must not meet in
any combination of their states (checked where their swept bounding boxes meet).
"""
from __future__ import annotations

import copy
import itertools
import time
from dataclasses import dataclass, field

import numpy as np

from mlc.io.cores import usable_cores
from mlc.mesh.build import Assembly, Part, _log, _orientation, build_assembly, transform_solid
from mlc.mesh.checks import (GAP_EPS, VOL_EPS, Check, Report, _bbox, _pairs, bed_checks,
                             check_assembly, print_size)
from mlc.mesh.profiles import Profile
from mlc.scene.model import Scene

#: input states of one mechanism beyond which only a sample of states is posed
MAX_STATES = 64
#: poses checked on the way from rest to each state (besides the states themselves)
PATH_STEPS = 6
#: dense paths (state_poses ``max_move``): mechanisms with at most this many input states are
#: also posed on every switch between two states
TRANSITION_STATES = 8
#: dense paths: at most this many poses on one path
MAX_PATH_POSES = 400
#: sigma added to a body's reach (state_poses ``max_move``) for its knuckles and yokes
PART_MARGIN = 0.25


@dataclass
class Mechanism:
    scene: Scene              # the sub-scene (bodies of this mechanism, original names)
    bodies: list              # indices into the full scene
    shift: np.ndarray = field(default_factory=lambda: np.zeros(3))   # sigma, from its representative
    rep: int = -1             # index of the representative mechanism (-1: itself)


def split_mechanisms(scene: Scene) -> list[Mechanism]:
    n = len(scene.bodies)
    idx = {b.name: i for i, b in enumerate(scene.bodies)}
    parent = list(range(n))

    def find(i):
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    for it in list(scene.bonds) + list(scene.muscles):
        a, b = idx[it.a.split(".")[0]], idx[it.b.split(".")[0]]
        parent[find(a)] = find(b)
    groups: dict[int, list[int]] = {}
    for i in range(n):
        groups.setdefault(find(i), []).append(i)
    if len(groups) == 1:
        return [Mechanism(scene, list(range(n)))]
    return [Mechanism(sub_scene(scene, members, f"{scene.name}[{scene.bodies[members[0]].name}]"), members)
            for members in sorted(groups.values())]


def sub_scene(scene: Scene, members: list[int], name: str) -> Scene:
    """The bodies ``members`` (indices into ``scene.bodies``, kept in that order) with every bond,
    muscle and probe between two of them, and the inputs and outputs those still carry."""
    names = {scene.bodies[i].name for i in members}

    def inside(x):
        return x.a.split(".")[0] in names and x.b.split(".")[0] in names
    sub = Scene(name=name, bodies=[scene.bodies[i] for i in members],
                bonds=[x for x in scene.bonds if inside(x)], muscles=[x for x in scene.muscles if inside(x)],
                probes=[x for x in scene.probes if inside(x)], units=scene.units, source=scene.source)
    sub.inputs = [s for s in scene.inputs if any(m.input == s for m in sub.muscles)]
    sub.outputs = [s for s in scene.outputs if any(p.output == s for p in sub.probes)]
    return sub


def _signature(scene: Scene):
    """Geometry and topology of a mechanism, up to a translation and renaming."""
    p0 = np.asarray(scene.bodies[0].position, float)
    local = {b.name: i for i, b in enumerate(scene.bodies)}

    def r(x):
        return tuple(np.round(np.asarray(x, float).ravel(), 9).tolist())

    def ref(s):
        b, site = s.split(".", 1)
        return (local[b], site)

    sig = [tuple((r(np.asarray(b.position) - p0), r(b.orientation),
                  tuple((r(x.size), r(x.center), r(x.orientation)) for x in b.boxes),
                  tuple(sorted((k, r(v)) for k, v in b.sites.items())))) for b in scene.bodies]
    inputs = {s: i for i, s in enumerate(scene.inputs)}
    sig.append(tuple((ref(x.a), ref(x.b), x.kind, round(x.rest, 9), round(x.tolerance, 9), round(x.k, 9))
                     for x in scene.bonds))
    sig.append(tuple((ref(x.a), ref(x.b), inputs[x.input], round(x.rest, 9), round(x.actuated, 9))
                     for x in scene.muscles))
    sig.append(tuple((ref(x.a), ref(x.b)) for x in scene.probes))
    return tuple(sig)


def _reach(scene: Scene) -> np.ndarray:
    """Per body, the largest distance (sigma) from its centre of a point of its slabs or sites,
    plus ``PART_MARGIN`` for the knuckles and yokes a printed part adds."""
    out = np.zeros(len(scene.bodies))
    for k, b in enumerate(scene.bodies):
        r = [float(np.linalg.norm(s)) for s in b.sites.values()]
        r += [float(np.linalg.norm(bx.center) + 0.5 * np.linalg.norm(bx.size)) for bx in b.boxes]
        out[k] = max(r, default=0.0) + PART_MARGIN
    return out


def _moves(p, q, reach) -> float:
    """The largest move (sigma) of a point of any body from pose ``p`` to pose ``q``
    (``(pos, quat)``): |dx| + |R_q - R_p| r, with |R_q - R_p| = 2 sin(angle / 2)."""
    from mlc.geometry.rotation import quat_to_matrix
    (x1, q1), (x2, q2) = p, q
    d = np.linalg.norm(np.asarray(x2) - np.asarray(x1), axis=1)
    rot = np.array([np.linalg.norm(quat_to_matrix(b) - quat_to_matrix(a), 2) for a, b in zip(q1, q2)])
    return float(np.max(d + rot * reach, initial=0.0))


def _with_muscles(scene: Scene, rest, actuated) -> Scene:
    """A copy of ``scene`` whose muscles have these rest and actuated lengths (sigma)."""
    part = copy.copy(scene)
    part.muscles = [copy.copy(m) for m in scene.muscles]
    for m, r, a in zip(part.muscles, rest, actuated):
        m.rest, m.actuated = float(r), float(a)
    return part


#: bodies from which :func:`state_poses` runs its minimisations side by side (:func:`_in_threads`)
THREADS_MIN_BODIES = 64


def _in_threads(fn, jobs, threads: bool = True):
    """``fn(*job)`` for each job of ``jobs``, in order, on up to one thread per core the process
    may use (one when ``threads`` is False).  For the minimisations of :func:`state_poses`: each
    is independent of the others and gives the same poses on any thread; in a large scene most
    of its time is in SuperLU and NumPy, which release the GIL (the Tetris robot's rows 01 and
    10 took 73 s one after the other and 47 s side by side on 2 cores, the same bits; scratch,
    session 42), in a library gate's in Python, which does not (the NAND's dense paths took
    longer side by side: 7.9 s against 6.2)."""
    jobs = list(jobs)
    workers = min(len(jobs), usable_cores() if threads else 1)
    if workers <= 1:
        return [fn(*job) for job in jobs]
    from concurrent.futures import ThreadPoolExecutor
    with ThreadPoolExecutor(workers) as ex:
        return list(ex.map(lambda job: fn(*job), jobs))


def state_poses(scene: Scene, max_states: int = MAX_STATES, path_steps: int = PATH_STEPS,
                max_move: float | None = None) -> tuple[dict, str | None]:
    """Body poses (sigma) at the equilibrium of the input states: ``{state: (pos, quat)}``,
    plus ``path_steps`` points on the way from rest to each state (keys ``"01@0.50"``: the
    equilibrium with the muscles that state actuates half-way there), and a note when only a
    sample of the states was posed.

    ``max_move`` (sigma; ``mlc stl`` passes the profile's clearance for a mechanism of fewer
    than ``REUSE_MIN_PARTS`` parts, such as a library gate, for its motion trims and its
    ``motion_clearance`` check)
    makes the paths dense and adds the switches between states (for at most
    ``TRANSITION_STATES`` states; keys ``"01@0.500"`` on the paths from rest):

    * every path is followed quasi-statically, each pose solved from the one before, with
      poses added until no point of any body (``_reach``) moves more than ``max_move`` from one
      to the next (at most ``MAX_PATH_POSES`` a path);
    * besides the paths from rest, every switch from a state ``a`` other than rest to any other
      state ``b``: every muscle moved on a straight line from its length in ``a`` to its length
      in ``b``, from ``a``'s pose (keys ``"01>10@0.500"``, and ``"01>10"`` for the end: the pose
      of ``b`` reached from ``a``, which a floppy mode can leave apart from ``b`` reached from
      rest).  With the paths from rest these are all the moves between logic states in which
      the inputs switch together."""
    try:
        from mlc.verify.static import equilibrium
    except ImportError:  # pragma: no cover - static verification ships with mlc
        return {}, "static verification is not available: logic states not posed"
    states = scene.states()
    note = None
    if len(states) > max_states:
        n = len(scene.inputs)
        pick = {"0" * n, "1" * n}
        for i in range(n):
            pick.add("".join("1" if j == i else "0" for j in range(n)))
            pick.add("".join("0" if j == i else "1" for j in range(n)))
        rng = np.random.default_rng(0)
        while len(pick) < max_states:
            pick.add("".join(rng.choice(["0", "1"], n)))
        states = sorted(pick)[:max(max_states, 2 * n + 2)]
        note = (f"{scene.name}: {len(scene.inputs)} inputs; posed {len(states)} of {2 ** n} input states "
                f"(all zero, all one, each input alone on and off, then a fixed random sample)")
    rest = "0" * len(scene.inputs)
    if max_move is not None and not max_move > 0:
        raise ValueError(f"max_move must be positive, not {max_move}")
    jobs = [(st, scene, st) for st in states]
    big = len(scene.bodies) >= THREADS_MIN_BODIES
    if max_move is None:
        for k in range(1, path_steps + 1):
            f = k / (path_steps + 1)
            part = _with_muscles(scene, [m.rest for m in scene.muscles],
                                 [m.rest + f * (m.actuated - m.rest) for m in scene.muscles])
            jobs += [(f"{st}@{f:.2f}", part, st) for st in states if st != rest]
    eqs = dict(zip([key for key, _, _ in jobs], _in_threads(equilibrium, [(sc, st) for _, sc, st in jobs], big)))
    out = {key: (np.asarray(eq.pos, float), np.asarray(eq.quat, float)) for key, eq in eqs.items()}
    if max_move is None:
        return out, note

    A = scene.arrays()
    reach = _reach(scene)

    def follow(a, La, Lb, fs):
        """Poses at the fractions ``fs`` (ascending, the last 1) of the straight move of the
        muscles from ``La`` to ``Lb``, each solved from the one before, from ``a``'s pose."""
        poses, pq = [], (eqs[a].pos, eqs[a].quat)
        for f in fs:
            L = La + f * (Lb - La)          # held there in every state
            eq = equilibrium(_with_muscles(scene, L, L), a, pos=pq[0], quat=pq[1])
            pq = (np.asarray(eq.pos, float), np.asarray(eq.quat, float))
            poses.append(pq)
        return poses

    def path(a, b):
        """(its name, its fractions, their poses, its largest step) for the move from ``a`` to ``b``."""
        La = A.muscle_lengths(np.array([int(x) for x in a], float))
        Lb = A.muscle_lengths(np.array([int(x) for x in b], float))
        fs = list(np.arange(1, path_steps + 2) / (path_steps + 1))
        poses = follow(a, La, Lb, fs)
        for refined in range(4):    # refine (three times at most) until every step moves at most max_move
            seq = [(eqs[a].pos, eqs[a].quat)] + poses
            mv = [_moves(p, q, reach) for p, q in zip(seq, seq[1:])]
            if max(mv) <= max_move or refined == 3:
                break
            f0 = [0.0] + fs
            new = sorted(set(fs) | {f0[i] + (fs[i] - f0[i]) * j / m for i, m in
                                    enumerate(int(np.ceil(1.1 * d / max_move)) for d in mv)
                                    for j in range(1, m)})
            if len(new) > MAX_PATH_POSES:
                break
            fs, poses = new, follow(a, La, Lb, new)
        return (b if a == rest else f"{a}>{b}"), fs, poses, max(mv)

    coarse = []
    moves = [(a, b) for a, b in itertools.product(states, states) if scene.muscles and a != b
             and not (a != rest and len(states) > TRANSITION_STATES)]
    for (a, _), (name, fs, poses, worst) in zip(moves, _in_threads(path, moves, big)):
        if worst > max_move:
            coarse.append(f"{name} ({worst:.3g} sigma)")
        for f, pq in zip(fs, poses):
            out[f"{name}@{f:.3f}" if f < 1.0 or a == rest else name] = pq
    if coarse:
        extra = (f"{scene.name}: poses on the way more than {max_move:.3g} sigma apart on "
                 + ", ".join(coarse[:4]) + (" ..." if len(coarse) > 4 else ""))
        note = extra if note is None else note + "; " + extra
    return out, note


def _dense_poses(scene: Scene, profile: Profile, notes: list) -> dict | None:
    """The dense poses of the motion trims (mlc.mesh.build._clear_motion) and of the
    ``motion_clearance`` check (mlc.mesh.checks.motion_check): for a mechanism
    of fewer than ``REUSE_MIN_PARTS`` parts, :func:`state_poses` with ``max_move`` the clearance in
    sigma (two parts that keep the clearance in two consecutive poses, each point moving at most
    that much, cannot meet between them); None for a larger one (a compiled circuit: too many; its
    ``motion_clearance`` is measured in its coarse poses, mlc.mesh.checks._CoarseClearance)."""
    from mlc.mesh.build import reuses
    if reuses(scene) or profile.clearance <= 0:
        return None          # (no clearance: nothing to keep; min_gap fails the export)
    _log("static verification: dense paths and switches for the clearance in motion")
    dense, note = state_poses(scene, max_move=profile.clearance / profile.sigma_mm)
    if note and note not in notes:
        notes.append(note)
    return dense


def export_assembly(scene: Scene, profile: Profile, poses: dict | None = None,
                    solve: bool = True) -> tuple[Assembly, Report]:
    """Build every part of ``scene`` for ``profile`` and run the printability checks.

    ``poses`` (``{state: (pos, quat)}`` for the whole scene) skips static verification;
    otherwise each mechanism is posed at the equilibrium of its own input states
    (``solve=False``: no states are posed, and the states check fails)."""
    t0 = time.perf_counter()
    mechs = split_mechanisms(scene)
    if poses is not None or len(mechs) == 1:
        notes = []
        dense = None
        if poses is None and solve:
            _log("static verification: posing every logic state")
            poses, note = state_poses(scene)
            if note:
                notes.append(note)
            dense = _dense_poses(scene, profile, notes)
        _log("building parts")
        asm = build_assembly(scene, profile, poses, motion_poses=dense)
        if dense:
            # a mechanism of its own with dense poses (a library gate): its hinges flat on the bed
            # made to print with less support, after the orientation that says which are flat
            # (mlc.mesh.pivot: print-only; compiled circuits are built as before)
            from mlc.mesh.pivot import flat_hinges
            _log("flat hinges: chamfers and teardrops")
            asm.notes += flat_hinges(asm)
        asm.notes[:0] = notes
        _log("printability checks")
        rep = check_assembly(asm, motion_poses=dense)
        rep.seconds = time.perf_counter() - t0
        _log("checks done")
        return asm, rep

    # many mechanisms: build each distinct one once
    classes: dict = {}
    for k, m in enumerate(mechs):
        sig = _signature(m.scene)
        if sig in classes:
            r = classes[sig]
            m.rep = r
            m.shift = np.asarray(m.scene.bodies[0].position, float) - np.asarray(
                mechs[r].scene.bodies[0].position, float)
        else:
            classes[sig] = k
    s = profile.sigma_mm
    built: dict[int, tuple] = {}
    notes: list[str] = []
    for k in classes.values():
        sub = mechs[k].scene
        p, note = state_poses(sub) if solve else ({}, None)
        if note:
            notes.append(note)
        dense = _dense_poses(sub, profile, notes) if solve else None
        a = build_assembly(sub, profile, p or None, motion_poses=dense)
        r = check_assembly(a, motion_poses=dense)
        built[k] = (a, r)

    # the full assembly: representative parts, translated for the copies
    parts: list[Part] = []
    owner: list[int] = []          # mechanism index of each part
    axes, ujoints, features = [], [], []
    for k, m in enumerate(mechs):
        rk = k if m.rep < 0 else m.rep
        a, _ = built[rk]
        shift = m.shift * s
        rename = {rb.name: b.name for rb, b in zip(mechs[rk].scene.bodies, m.scene.bodies)}
        for p in a.parts:
            name = rename.get(p.name, p.name if m.rep < 0 else f"{p.name}__{k}")
            solid = p.solid if m.rep < 0 else p.solid.translate(shift.tolist())
            parts.append(Part(name, p.kind, solid, [rename.get(x, x) for x in p.partners]))
            owner.append(k)
        if m.rep < 0:
            axes += a.axes
            ujoints += a.ujoints
            features += a.features
            notes += [x for x in a.notes if x not in notes]
    n_joint = sum(len({u.part for u in built[k if m.rep < 0 else m.rep][0].ujoints}) for k, m in enumerate(mechs))
    full = Assembly(scene, profile, parts, axes, ujoints, notes, features, built[next(iter(built))][0].slab_thickness)
    full.orient = _orientation(full)
    full.n_joint_parts = n_joint

    report = _merge_reports(scene, profile, mechs, built, full, owner)
    report.seconds = time.perf_counter() - t0
    return full, report


def _swept_box(asm: Assembly, part: Part, mech_poses, shift, Ts=None):
    """The box a part sweeps over its mechanism's poses (``Ts``: each pose's part transforms,
    computed once per pose by the caller; a mechanism of thousands of parts took minutes
    when every part recomputed them)."""
    lo, hi = _bbox(part.solid)
    if Ts is None:
        Ts = [asm.part_transforms(pos, quat) for pos, quat in mech_poses.values()]
    for T in Ts:
        l2, h2 = _bbox(part.solid, T[part.name])
        lo, hi = np.minimum(lo, l2), np.maximum(hi, h2)
    return lo + shift, hi + shift


def _merge_reports(scene, profile, mechs, built, full, owner) -> Report:
    c = profile.clearance
    s = profile.sigma_mm
    reps = {k: r for k, (_, r) in built.items()}
    members = {k: [i for i, m in enumerate(mechs) if (i if m.rep < 0 else m.rep) == k] for k in built}
    checks = []
    for name in ("watertight", "part_count", "min_gap", "states", "retention", "features"):
        subs = [(k, reps[k].check(name)) for k in reps]
        ok = all(ch.ok for _, ch in subs)
        fails = [f"{mechs[k].scene.name}: {f}" for k, ch in subs for f in ch.failures]
        if name in ("watertight", "part_count", "retention", "features"):
            val = sum((ch.value or 0) * len(members[k]) for k, ch in subs)
            lim = sum((ch.limit or 0) * len(members[k]) for k, ch in subs)
            detail = f"{val}/{lim} over {len(mechs)} mechanisms ({len(reps)} distinct)"
            if name == "part_count":
                detail = (f"{val} pieces printed, expected {len(scene.bodies)} bodies + "
                          f"{full.n_joint_parts} joint parts = {lim}")
        elif name == "min_gap":
            vals = [ch.value for _, ch in subs if ch.value is not None]
            val, lim = (min(vals) if vals else None), c
            detail = f"within mechanisms: smallest gap {val} mm" if vals else "no close parts within mechanisms"
        else:
            val = max((ch.value or 0) for _, ch in subs)
            lim = VOL_EPS
            nst = sum(len(built[k][0].poses or {}) for k in reps)
            detail = f"{nst} poses (logic states and points on the way) over {len(reps)} distinct mechanisms"
            if any(not (built[k][0].poses) for k in reps):
                detail += "; some mechanisms were not posed"
        checks.append(Check(name, ok, val, lim, detail, fails))

    # between mechanisms: clearance as printed, and no contact in any states
    boxes = [_bbox(p.solid) for p in full.parts]
    gap_fail, gmin = [], None
    for i, j in _pairs(boxes, 2 * c + 1e-3):
        if owner[i] == owner[j]:
            continue
        g = float(full.parts[i].solid.min_gap(full.parts[j].solid, max(2 * c, 1e-3)))
        gmin = g if gmin is None else min(gmin, g)
        if g < c - GAP_EPS or g <= GAP_EPS:
            gap_fail.append(f"{full.parts[i].name} - {full.parts[j].name}: {g:.4f} mm")
    mg = checks[2]
    mg.failures += gap_fail
    mg.ok = mg.ok and not gap_fail
    if gmin is not None:
        mg.value = min(mg.value, gmin) if mg.value is not None else gmin
        mg.detail += f"; between mechanisms {gmin:.3f} mm"
    else:
        mg.detail += f"; mechanisms at least {2 * c:g} mm apart"

    # swept boxes of each mechanism over its states
    swept = []
    for k, m in enumerate(mechs):
        rk = k if m.rep < 0 else m.rep
        a = built[rk][0]
        poses = a.poses or {}
        lo = np.full(3, np.inf)
        hi = np.full(3, -np.inf)
        Ts = [a.part_transforms(pos, quat) for pos, quat in poses.values()]
        for p in a.parts:
            l2, h2 = _swept_box(a, p, poses, m.shift * s, Ts)
            lo, hi = np.minimum(lo, l2), np.maximum(hi, h2)
        swept.append((lo, hi))
    st = checks[3]
    close = _pairs(swept, 0.0)
    for i, j in close:
        fails = _cross_states(mechs, built, i, j, s)
        st.failures += fails
        st.ok = st.ok and not fails
    st.detail += (f"; {len(close)} pairs of mechanisms sweep through shared space (checked in every state "
                  f"combination)" if close else "; mechanisms never share space")
    # the clearance in motion, within each distinct mechanism (not between mechanisms: the states
    # check above sees those in every combination of their states, for intersection)
    subs = [(k, reps[k].check("motion_clearance")) for k in reps]
    vals = [ch.value for _, ch in subs if ch.value is not None]
    checks.append(Check("motion_clearance", all(ch.ok for _, ch in subs), min(vals) if vals else None, c,
                        "; ".join(f"{mechs[k].scene.name}: {ch.detail}" for k, ch in subs)[:2000],
                        [f"{mechs[k].scene.name}: {f}" for k, ch in subs for f in ch.failures],
                        # a mechanism short of the clearance on dense poses blocks; coarse or not measured does not
                        any(not ch.ok and ch.blocking for _, ch in subs) or all(ch.ok for _, ch in subs)))
    # measured walls: per distinct mechanism (copies are translated, their walls the same)
    walls = [(k, reps[k].check("wall_thickness")) for k in reps if "wall_thickness" in
             {c.name for c in reps[k].checks}]
    vals = [ch.value for _, ch in walls if ch.value is not None]
    checks.append(Check("wall_thickness", all(ch.ok for _, ch in walls), min(vals) if vals else None,
                        profile.min_wall, "; ".join(f"{mechs[k].scene.name}: {ch.detail}" for k, ch in walls)[:2000],
                        [f"{mechs[k].scene.name}: {f}" for k, ch in walls for f in ch.failures],
                        all(ch.blocking for _, ch in walls)))
    # the bed: the whole assembly as printed
    checks += bed_checks(full)
    rep = Report(scene.name, profile.to_dict(),
                 [{"name": p.name, "kind": p.kind, "volume_mm3": round(float(p.solid.volume()), 4), "pieces": 1}
                  for p in full.parts], checks, list(full.notes))
    rep.size_mm = print_size(full)
    return rep


def _cross_states(mechs, built, i, j, s) -> list[str]:
    from mlc.mesh.spatial import box_pairs, posed_boxes, solid_boxes
    out = []
    A = [(mechs[i], built[i if mechs[i].rep < 0 else mechs[i].rep][0]),
         (mechs[j], built[j if mechs[j].rep < 0 else mechs[j].rep][0])]
    posed, boxes = [], []
    for m, a in A:
        # each part's transform in each state (shift included) and the box of its moved rest box;
        # a part is moved (a new mesh) only for a pair whose boxes touch: moving every part of a
        # mechanism of thousands in every state held gigabytes
        per, bx = {}, {}
        lo, hi = solid_boxes([p.solid for p in a.parts])
        for st, pq in (a.poses or {"rest": None}).items():
            T = {p.name: np.eye(4) for p in a.parts} if pq is None else a.part_transforms(*pq)
            Ts = []
            for p in a.parts:
                Tm = np.array(T[p.name], float)
                Tm[:3, 3] += m.shift * s
                Ts.append(Tm)
            per[st] = Ts
            bx[st] = posed_boxes(lo, hi, Ts)
        posed.append(per)
        boxes.append(bx)
    parts = [a.parts for _, a in A]
    for (s1, P1), (s2, P2) in itertools.product(posed[0].items(), posed[1].items()):
        # only parts whose posed boxes touch can meet (thousands of parts: not every pair)
        (l1, h1), (l2, h2) = boxes[0][s1], boxes[1][s2]
        n1 = len(P1)
        cand = [(x, y - n1) for x, y in box_pairs(np.vstack([l1, l2]), np.vstack([h1, h2]), 0.0)
                if x < n1 <= y]
        hit = set()
        for x, y in cand:          # as before: one line for each part of the first that meets one of the second
            if x not in hit and (transform_solid(parts[0][x].solid, P1[x])
                                 ^ transform_solid(parts[1][y].solid, P2[y])).volume() > VOL_EPS:
                hit.add(x)
                out.append(f"{mechs[i].scene.name} in state {s1} meets {mechs[j].scene.name} in state {s2}")
    return out


__all__ = ["export_assembly", "split_mechanisms", "state_poses"]
