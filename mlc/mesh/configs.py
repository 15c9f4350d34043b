"""Configurations of a printed mechanism: the poses its joints reach without muscles (issue 13,
item 1: "a configuration of the mechanism (any pose its joints reach, not only a logic state)").

All lengths in mm (the assembly's parts, rest world frame); angles in radians unless named
``_deg``.  A configuration is one rigid transform per body (4 x 4, rest -> posed, as
:meth:`mlc.mesh.build.Assembly.part_transforms` returns), the first body held fixed (the ground;
the print pose's orientation is searched separately).

The joints are those of the *printed* parts, not the scene's bonds: every hinge axis
(``asm.axes``) keeps its bodies on one line (two points of the axis, at the ends of its knuckle
span, coincide for every body on it: a revolute joint, its knuckles and pin turning about the
line), and every universal joint (``asm.ujoints``) keeps its point and its two pins crossed
(u fixed in body C, v fixed in body O, u . v = 0).  Muscles are not printed and constrain nothing.

* :class:`Kinematics` holds these constraints, their residual and Jacobian (analytic: a body
  moved by a small rotation w and translation d moves a point x by w x x + d);
* :meth:`Kinematics.project` puts a configuration back on the constraint manifold
  (Gauss-Newton, least-norm steps);
* :meth:`Kinematics.freedoms` is the dimension of the joint space at a configuration (the null
  space of the Jacobian): the number of independent motions of the printed mechanism;
* :func:`scan` maps the reachable joint space of a mechanism whose freedoms are its input
  levers' hinges (a library gate: 2) on a grid of hinge angles: a flood fill from rest, a node
  kept only if the joints close there and on the way from its neighbour and no two parts come
  closer than the clearance (manifold3d ``min_gap`` through :func:`mlc.mesh.spatial.posed_gaps`),
  so every kept configuration is joined to rest by a path of such poses;
* :class:`Evaluator` scores a configuration's best print orientation by the report's support
  model (the candidates: world axes, the posed slab normals, a Fibonacci lattice).
"""
from __future__ import annotations

import numpy as np

#: projection: residual (mm, and the cosine of the ujoint's pins) below which a pose is on the joints
TOL = 1e-7
#: singular values below this fraction of the largest are the joint space's directions
NULL_TOL = 1e-7


def _skew(v):
    return np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0.0]])


def _expm(w) -> np.ndarray:
    """Rotation matrix of the rotation vector ``w`` (Rodrigues)."""
    th = float(np.linalg.norm(w))
    if th < 1e-15:
        return np.eye(3)
    K = _skew(np.asarray(w, float) / th)
    return np.eye(3) + np.sin(th) * K + (1 - np.cos(th)) * K @ K


class Kinematics:
    """The joints of an assembly's printed parts as equality constraints on body transforms."""

    def __init__(self, asm, ground: str | None = None):
        self.asm = asm
        self.names = [b.name for b in asm.scene.bodies]
        self.index = {n: i for i, n in enumerate(self.names)}
        self.ground = self.index[ground] if ground else 0
        # (body i, body j, point x (rest world, mm)): T_i x = T_j x
        self.points = []
        for ax in asm.axes:
            if any(b not in self.index for b in ax.bodies):
                continue            # a joint part's own hinge (compound junction): not in a gate
            d = np.asarray(ax.direction, float)
            ends = [np.asarray(ax.origin, float) + s * 0.5 * max(ax.span, 1.0) * d for s in (-1.0, 1.0)]
            for b in ax.bodies[1:]:
                for x in ends:
                    self.points.append((self.index[ax.bodies[0]], self.index[b], x))
        # (body C, body O, u, v): (R_C u) . (R_O v) = 0; the point is a coincident point above
        self.crossed = []
        for u in asm.ujoints:
            if not getattr(u, "primary", True) or any(b not in self.index for b in u.bodies):
                continue
            c, o = self.index[u.bodies[0]], self.index[u.bodies[1]]
            self.points.append((c, o, np.asarray(u.center, float)))
            self.crossed.append((c, o, np.asarray(u.axes[0], float), np.asarray(u.axes[1], float)))
        self.n = len(self.names)
        self.free = [i for i in range(self.n) if i != self.ground]

    # -- configurations: list of 4x4 rest -> posed transforms, one per body ----------------------
    def rest(self) -> list:
        return [np.eye(4) for _ in range(self.n)]

    def residual(self, T) -> np.ndarray:
        r = []
        for i, j, x in self.points:
            r.append(T[i][:3, :3] @ x + T[i][:3, 3] - T[j][:3, :3] @ x - T[j][:3, 3])
        for c, o, u, v in self.crossed:
            r.append([float((T[c][:3, :3] @ u) @ (T[o][:3, :3] @ v))])
        return np.concatenate(r) if r else np.zeros(0)

    def jacobian(self, T) -> np.ndarray:
        """d residual / d (w_k, d_k) for every free body k (w: small rotation about the world
        origin applied after T_k, d: translation; 6 columns a body)."""
        col = {k: 6 * m for m, k in enumerate(self.free)}
        rows = []
        for i, j, x in self.points:
            J = np.zeros((3, 6 * len(self.free)))
            for k, sg in ((i, 1.0), (j, -1.0)):
                if k in col:
                    p = T[k][:3, :3] @ x + T[k][:3, 3]
                    J[:, col[k]:col[k] + 3] = -sg * _skew(p)
                    J[:, col[k] + 3:col[k] + 6] = sg * np.eye(3)
            rows.append(J)
        for c, o, u, v in self.crossed:
            J = np.zeros((1, 6 * len(self.free)))
            a, b = T[c][:3, :3] @ u, T[o][:3, :3] @ v
            if c in col:
                J[0, col[c]:col[c] + 3] = np.cross(a, b)
            if o in col:
                J[0, col[o]:col[o] + 3] = np.cross(b, a)
            rows.append(J)
        return np.vstack(rows) if rows else np.zeros((0, 6 * len(self.free)))

    def move(self, T, dq) -> list:
        """The configuration ``T`` moved by ``dq`` (6 a free body: rotation vector about the
        world origin, then translation; mm)."""
        out = [t.copy() for t in T]
        for m, k in enumerate(self.free):
            w, d = dq[6 * m:6 * m + 3], dq[6 * m + 3:6 * m + 6]
            R = _expm(w)
            out[k][:3, :3] = R @ T[k][:3, :3]
            out[k][:3, 3] = R @ T[k][:3, 3] + d
        return out

    def project(self, T, iters: int = 30) -> tuple[list, float]:
        """Gauss-Newton onto the joints; returns the configuration and its largest residual."""
        for _ in range(iters):
            r = self.residual(T)
            e = float(np.max(np.abs(r))) if len(r) else 0.0
            if e < TOL:
                return T, e
            dq = np.linalg.lstsq(self.jacobian(T), -r, rcond=None)[0]
            T = self.move(T, dq)
        r = self.residual(T)
        return T, float(np.max(np.abs(r))) if len(r) else 0.0

    def null_space(self, T) -> np.ndarray:
        """Columns: an orthonormal basis of the joint space's tangent at ``T`` (in dq)."""
        J = self.jacobian(T)
        if J.shape[0] == 0:
            return np.eye(J.shape[1])
        _, s, Vt = np.linalg.svd(J)
        rank = int(np.sum(s > NULL_TOL * max(s[0], 1e-12)))
        return Vt[rank:].T

    def freedoms(self, T=None) -> int:
        return int(self.null_space(self.rest() if T is None else T).shape[1])

    def hinge_angles(self, T) -> dict:
        """Each hinge axis's relative rotation (degrees) of each body from the axis owner, from rest."""
        out = {}
        for ax in self.asm.axes:
            if any(b not in self.index for b in ax.bodies):
                continue
            d = np.asarray(ax.direction, float)
            i = self.index[ax.bodies[0]]
            for b in ax.bodies[1:]:
                j = self.index[b]
                Rrel = T[i][:3, :3].T @ T[j][:3, :3]
                w = _logm(Rrel)
                out[f"{ax.name}:{b}"] = round(float(np.degrees(w @ d)), 3)
        return out


def _logm(R) -> np.ndarray:
    c = np.clip((np.trace(R) - 1) / 2, -1, 1)
    th = np.arccos(c)
    if th < 1e-12:
        return np.zeros(3)
    v = np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])
    if np.sin(th) < 1e-9:
        # 180 degrees: the axis from R + I
        M = (R + np.eye(3)) / 2
        a = np.sqrt(np.clip(np.diag(M), 0, None))
        k = int(np.argmax(a))
        a = M[k] / a[k]
        return th * a / np.linalg.norm(a)
    return th * v / (2 * np.sin(th))


class Clearance:
    """Whether a configuration keeps every pair of parts at least the clearance apart (pairs
    already closer at rest, as built, are held to their rest gap instead)."""

    def __init__(self, asm, kin: Kinematics):
        from mlc.mesh.spatial import local_boxes, part_frames
        self.asm, self.kin = asm, kin
        self.solids = [p.solid for p in asm.parts]
        self.frames = part_frames(asm)
        self.lo, self.hi = local_boxes(self.solids, self.frames)
        self.c = asm.profile.clearance
        self.allow = {}
        rest = self.gaps(kin.rest())
        self.allow = {k: g for k, g in rest.items()}

    def part_T(self, T) -> list:
        """Every part's transform (a body's own; a universal-joint part follows its two bodies)."""
        d = self.asm.part_transforms(None, None, body_T={n: T[k] for k, n in enumerate(self.kin.names)})
        return [d.get(p.name, np.eye(4)) for p in self.asm.parts]

    def gaps(self, T) -> dict:
        """{(i, j): gap} of the part pairs closer than the clearance in configuration ``T``."""
        from mlc.mesh.spatial import posed_gaps
        close, _ = posed_gaps(self.solids, self.frames, self.lo, self.hi, [self.part_T(T)], self.c)
        return close[0]

    def ok(self, T, eps: float = 1e-4) -> tuple[bool, dict]:
        g = self.gaps(T)
        bad = {k: v for k, v in g.items() if v < self.allow.get(k, self.c) - eps}
        return not bad, bad




def angle_targets(kin: Kinematics, T, targets: dict, iters: int = 40) -> tuple[list, float]:
    """Project ``T`` onto the joints with some hinge angles prescribed: ``targets`` maps
    ``"axis:body"`` (as :meth:`Kinematics.hinge_angles` names them) to degrees from rest."""
    axes = {}
    for ax in kin.asm.axes:
        for b in ax.bodies[1:]:
            axes[f"{ax.name}:{b}"] = (kin.index[ax.bodies[0]], kin.index[b], np.asarray(ax.direction, float))
    extra = []
    for k, deg in targets.items():
        i, j, d = axes[k]
        e1 = np.cross(d, np.eye(3)[int(np.argmin(np.abs(d)))])
        e1 /= np.linalg.norm(e1)
        extra.append((i, j, _expm(np.radians(deg) * d) @ e1, e1))
    col = {k: 6 * m for m, k in enumerate(kin.free)}
    for _ in range(iters):
        r = [kin.residual(T)]
        J = [kin.jacobian(T)]
        for i, j, a, e1 in extra:
            pa, pb = T[j][:3, :3] @ e1, T[i][:3, :3] @ a
            r.append(pa - pb)
            Jx = np.zeros((3, J[0].shape[1]))
            if j in col:
                Jx[:, col[j]:col[j] + 3] = -_skew(pa)
            if i in col:
                Jx[:, col[i]:col[i] + 3] = _skew(pb)
            J.append(Jx)
        r = np.concatenate(r)
        e = float(np.max(np.abs(r)))
        if e < TOL:
            break
        T = kin.move(T, np.linalg.lstsq(np.vstack(J), -r, rcond=None)[0])
    r = np.concatenate([kin.residual(T)] + [T[j][:3, :3] @ e1 - T[i][:3, :3] @ a for i, j, a, e1 in extra])
    return T, float(np.max(np.abs(r)))


def input_axes(kin: Kinematics) -> list:
    """The hinge of each muscle's lever (the axis joining the two bodies a muscle pulls on), as
    ``"axis:body"`` keys of :meth:`Kinematics.hinge_angles`: a 2-input gate's two freedoms."""
    out = []
    for m in kin.asm.scene.muscles:
        pair = {m.a.split(".")[0], m.b.split(".")[0]}
        for ax in kin.asm.axes:
            if pair <= set(ax.bodies):
                other = [b for b in ax.bodies if b in pair and b != ax.bodies[0]]
                key = f"{ax.name}:{other[0]}"
                if key not in out:
                    out.append(key)
                break
    return out


def scan(kin: Kinematics, clear: Clearance, step_deg: float = 5.0, limit_deg: float = 90.0,
         substeps: int = 2) -> dict:
    """The reachable part of the joint space of a mechanism whose freedoms are its input levers'
    hinges (:func:`input_axes`; the library gates: 2), on a grid of ``step_deg`` up to
    ``limit_deg`` from rest: a flood fill from rest in which a grid node is reached from a
    reached neighbour when the joints close there and at ``substeps - 1`` points on the way and
    every part keeps the clearance at each.  Returns ``{(i, j, ...): configuration}`` (grid
    indices: angle = index x step_deg) and the nodes tried and refused."""
    keys = input_axes(kin)
    dim = len(keys)
    nmax = int(round(limit_deg / step_deg))
    reached = {tuple([0] * dim): kin.rest()}
    refused = {}
    todo = [tuple([0] * dim)]
    while todo:
        node = todo.pop(0)
        for d in range(dim):
            for sg in (-1, 1):
                nb = list(node)
                nb[d] += sg
                nb = tuple(nb)
                if abs(nb[d]) > nmax or nb in reached or nb in refused:
                    continue
                T = reached[node]
                good = True
                for s in range(1, substeps + 1):
                    f = s / substeps
                    tgt = {k: step_deg * (node[q] + f * (nb[q] - node[q])) for q, k in enumerate(keys)}
                    T, e = angle_targets(kin, T, tgt)
                    if e > 1e-5:
                        good = False
                        refused[nb] = "joints do not close"
                        break
                    okk, bad = clear.ok(T)
                    if not okk:
                        good = False
                        (i, j), g = min(bad.items(), key=lambda x: x[1])
                        refused[nb] = f"{clear.asm.parts[i].name}/{clear.asm.parts[j].name} {g:.2f} mm"
                        break
                if good:
                    reached[nb] = T
                    todo.append(nb)
    # a node refused from one neighbour may be reached from another: refused keeps the last reason
    return {"keys": keys, "step_deg": step_deg, "reached": reached,
            "refused": {k: v for k, v in refused.items() if k not in reached}}


def slab_normals(kin: Kinematics, T) -> list:
    """The unit normal (the thinnest side) of every slab box of the scene, posed by ``T``."""
    from mlc.geometry.rotation import quat_to_matrix
    out = []
    for k, b in enumerate(kin.asm.scene.bodies):
        Rb = quat_to_matrix(b.orientation)
        for bx in b.boxes:
            R = Rb @ quat_to_matrix(bx.orientation)
            out.append(T[k][:3, :3] @ R[:, int(np.argmin(bx.size))])
    return out


class Evaluator:
    """The bed of a configuration in its best orientation, by the report's support model: the
    parts posed (:meth:`Clearance.part_T`), each candidate up scored on a coarse grid
    (:func:`mlc.mesh.printability.quick_stats`, longest side / ``coarse_cells``), the ``exact``
    best measured with :func:`mlc.mesh.printability.bed_stats` on the report's grid."""

    def __init__(self, asm, clear: Clearance, n_sphere: int = 60, coarse_cells: int = 40, exact: int = 2):
        from mlc.mesh.checks import island_side
        from mlc.mesh.printability import _mesh_arrays
        self.asm, self.clear = asm, clear
        self.meshes = [_mesh_arrays(p.solid) for p in asm.parts]
        self.names = [p.name for p in asm.parts]
        self.n_sphere, self.cells, self.n_exact = n_sphere, coarse_cells, exact
        self.first_layer = min(0.2, asm.profile.min_wall / 2)
        self.island = island_side(asm.profile)
        self.volume = float(sum(p.solid.volume() for p in asm.parts))

    def ups(self, T) -> list:
        from mlc.mesh.pose import _unique, fibonacci_sphere
        c = [np.array(v, float) for v in np.eye(3)] + slab_normals(self.clear.kin, T)
        c = [s * v / np.linalg.norm(v) for v in c for s in (1.0, -1.0)]
        return _unique(c + list(fibonacci_sphere(self.n_sphere)))

    def __call__(self, T, ups=None) -> dict:
        from mlc.geometry.rotation import rotation_between
        from mlc.mesh.build import _h, transform_solid
        from mlc.mesh.checks import OVERHANG_DEG
        from mlc.mesh.pose import pose_key, report_grid
        from mlc.mesh.printability import bed_stats, quick_stats
        PT = self.clear.part_T(T)
        Vs, Fs, Os, off = [], [], [], 0
        for k, ((V, F), P) in enumerate(zip(self.meshes, PT)):
            Vs.append(V @ P[:3, :3].T + P[:3, 3])
            Fs.append(F + off)
            Os.append(np.full(len(F), k))
            off += len(V)
        V, F, own = np.concatenate(Vs), np.concatenate(Fs), np.concatenate(Os)
        h = max(float(np.max(V.max(0) - V.min(0))) / self.cells, 0.05)
        scored = []
        for u in (self.ups(T) if ups is None else ups):
            R = rotation_between(u, [0, 0, 1.0])
            q = quick_stats(V @ R.T, F, h, OVERHANG_DEG, self.first_layer, own, self.island)
            cf = q["contact_mm2"] / q["footprint_mm2"] if q["footprint_mm2"] > 0 else 0.0
            scored.append((pose_key(q["support_mm3"] / self.volume, q["support_inside_mm3"] / self.volume, cf),
                           cf, u))
        scored.sort(key=lambda x: x[0])
        best = None
        for key, _, u in scored[:self.n_exact]:
            R = rotation_between(u, [0, 0, 1.0])
            posed = [(n, transform_solid(p.solid, _h(R, np.zeros(3)) @ P))
                     for n, p, P in zip(self.names, self.asm.parts, PT)]
            lo = np.min([np.asarray(s.bounding_box())[:3] for _, s in posed], axis=0)
            hi = np.max([np.asarray(s.bounding_box())[3:] for _, s in posed], axis=0)
            posed = [(n, s.translate([-float(lo[0] + hi[0]) / 2, -float(lo[1] + hi[1]) / 2, -float(lo[2])]))
                     for n, s in posed]
            st = bed_stats(posed, OVERHANG_DEG, report_grid(hi - lo, self.asm.profile.min_wall),
                           first_layer=self.first_layer, island_mm=self.island)
            k = pose_key(st.support_fraction, st.support_inside_mm3 / max(st.part_volume_mm3, 1e-12),
                         st.contact_fraction)
            if best is None or k < best["key"]:
                best = {"key": k, "up": u, "stats": st}
        best["coarse_best_contact"] = max(cf for _, cf, _ in scored)
        best["n_ups"] = len(scored)
        return best


#: orient: auto_config: the grid of the input levers' hinge angles (degrees), its reach from rest
SCAN_STEP_DEG = 5.0
SCAN_LIMIT_DEG = 90.0
#: ... every EVAL_EVERY-th grid node is evaluated (10 degrees apart), then the SCAN_STEP_DEG
#: neighbours of the REFINE best
EVAL_EVERY = 2
REFINE = 3


def applicable(asm) -> str | None:
    """Why ``orient: auto_config`` cannot search this assembly's configurations (None: it can):
    one mechanism of fewer than REUSE_MIN_PARTS parts, driven by muscles, whose every freedom is
    an input lever's hinge."""
    from mlc.mesh.build import REUSE_MIN_PARTS
    from mlc.mesh.pipeline import split_mechanisms
    if len(asm.parts) >= REUSE_MIN_PARTS:
        return f"{len(asm.parts)} parts (a configuration search is for fewer than {REUSE_MIN_PARTS})"
    if len(split_mechanisms(asm.scene)) != 1:
        return "several mechanisms"
    kin = Kinematics(asm)
    keys = input_axes(kin)
    if not keys:
        return "no muscle drives a hinge"
    f = kin.freedoms()
    if f != len(keys):
        return f"{f} freedoms, {len(keys)} of them input levers' hinges"
    return None


def best_configuration(asm) -> dict | None:
    """The reachable configuration other than rest with the best bed by :class:`Evaluator`
    (:func:`scan` on the SCAN_STEP_DEG grid, every EVAL_EVERY-th node evaluated, then the
    neighbours of the REFINE best).  Returns ``{"T" (body transforms), "part_T" ({part: 4x4}),
    "angles_deg" ({hinge: degrees}), "key", "reached", "evaluated"}``, or None when no node but
    rest is reached."""
    kin = Kinematics(asm)
    clear = Clearance(asm, kin)
    sc = scan(kin, clear, step_deg=SCAN_STEP_DEG, limit_deg=SCAN_LIMIT_DEG)
    reached = sc["reached"]
    rest = tuple([0] * len(sc["keys"]))
    if len(reached) < 2:
        return None
    ev = Evaluator(asm, clear)
    res = {n: ev(T) for n, T in reached.items() if n != rest and all(x % EVAL_EVERY == 0 for x in n)}
    for n, _ in sorted(res.items(), key=lambda x: x[1]["key"])[:REFINE]:
        for d in range(len(n)):
            for sg in (-1, 1):
                nb = tuple(x + (sg if q == d else 0) for q, x in enumerate(n))
                if nb in reached and nb != rest and nb not in res:
                    res[nb] = ev(reached[nb])
    if not res:
        return None
    n = min(res, key=lambda m: (res[m]["key"], m))
    T = reached[n]
    return {"T": T, "part_T": {p.name: P for p, P in zip(asm.parts, clear.part_T(T))},
            "angles_deg": {k: SCAN_STEP_DEG * x for k, x in zip(sc["keys"], n)}, "key": res[n]["key"],
            "reached": len(reached), "evaluated": len(res), "kin": kin}


def posed_directions(asm, kin: Kinematics, T) -> tuple[list, list]:
    """The candidate ups of :func:`mlc.mesh.pose.search_up` in configuration ``T``: the world
    axes and every posed slab normal (both signs), and the posed hinge and pin directions."""
    from mlc.mesh.pose import _unique
    c = [np.array(v, float) for v in np.eye(3)] + slab_normals(kin, T)
    ups = _unique([s * v / np.linalg.norm(v) for v in c for s in (1.0, -1.0)])
    dirs = [T[kin.index[ax.bodies[0]]][:3, :3] @ np.asarray(ax.direction, float) for ax in asm.axes
            if ax.bodies[0] in kin.index]
    for u in asm.ujoints:
        if u.bodies[0] in kin.index and u.bodies[1] in kin.index:
            dirs += [T[kin.index[u.bodies[0]]][:3, :3] @ np.asarray(u.axes[0], float),
                     T[kin.index[u.bodies[1]]][:3, :3] @ np.asarray(u.axes[1], float)]
    return ups, dirs


__all__ = ["Clearance", "Evaluator", "Kinematics", "angle_targets", "applicable", "best_configuration",
           "input_axes", "posed_directions", "scan", "slab_normals"]
