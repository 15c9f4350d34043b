"""Other assembly branches of a library gate, and the energy barrier that guards them.

Units: sigma (length), k0 (stiffness), k0 sigma^2 (energy), t0 (time).

A gate's joints and muscles fix its shape only locally: with the muscle lengths of an
input state there are other zero-energy poses (issue 12, item 6).  Each lever can fold
to its other assembly branch -- the half-angle theta of one of its sides goes to
pi - theta, which puts that side's ends on the same side of the pivot as the other
side's -- and the core can fold (c below ab, or d below c).  Every such change of branch
makes one of the **branch indicators** below change sign; the gate is built with all of
them on their design side:

* ``<lever>.in`` = (A - P) . u < 0 and ``<lever>.out`` = (B - P) . u > 0, for the levers
  ``a``, ``b`` and ``out``: P is the pivot, A and B the midpoints of the input and output
  ends, u the unit vector from A to B;
* ``core.abc`` = ((b - a) x (c - a)) . n > 0 (c above ab; n the hinge axis at a, +z as
  built, so that a rigid rotation of the whole gate changes nothing) and ``core.cd`` =
  (d - c) . (c - m) > 0 (d beyond c).

**Barrier.**  Any path from the design branch to a folded one crosses the surface where
that indicator is zero, so the energy barrier of the fold is at least the smallest
energy on that surface, F(0) = min {E(x) : s(x) = 0}.  :func:`fold_barrier` follows the
constrained minimum F(s) from the equilibrium to s = 0 by continuation (a least-squares
penalty on s - s_target, 1e4 times stiffer than the joints), and reports F(0) and the
largest F on the way.  A continuation finds a local constrained minimum, so the number
is the barrier along the lowest path it follows, and a lower bound only if no other
valley reaches the surface; the Brownian-dynamics runs of docs/gates.md check it.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares

from mlc.geometry.rotation import expmap, matrix_to_quat, quat_to_matrix
from mlc.scene.model import Scene

INDICATORS = ("a.in", "a.out", "b.in", "b.out", "out.in", "out.out", "core.abc", "core.cd")
DESIGN_SIGN = {"a.in": -1, "a.out": 1, "b.in": -1, "b.out": 1, "out.in": -1, "out.out": 1,
               "core.abc": 1, "core.cd": 1}
PENALTY = 1e4        # stiffness of the indicator constraint relative to k0


def _all_sites(scene: Scene, pos, R):
    A = scene.arrays()
    return np.asarray(pos)[A.site_body] + np.einsum("nij,nj->ni", np.asarray(R)[A.site_body], A.site_local)


def _mid(*p):
    return sum(p) / len(p)


def _indicators_from_sites(p, ix) -> dict:
    def W(ref):
        return p[ix[ref]]
    out = {}
    for X in ("a", "b"):
        P = _mid(W(f"{X}_lo.piv_0"), W(f"{X}_lo.piv_1"))
        A = _mid(W(f"{X}_lo.in"), W(f"{X}_hi.in"))
        B = _mid(W(f"{X}_lo.core_0"), W(f"{X}_lo.core_1"), W(f"{X}_hi.core_0"), W(f"{X}_hi.core_1"))
        u = (B - A) / np.linalg.norm(B - A)
        out[f"{X}.in"], out[f"{X}.out"] = float((A - P) @ u), float((B - P) @ u)
    P = _mid(W("out_lo.piv_0"), W("out_lo.piv_1"))
    A = _mid(_mid(W("out_lo.core_0"), W("out_lo.core_1")), W("out_hi.core"))
    B = _mid(W("out_lo.out"), W("out_hi.out"))
    u = (B - A) / np.linalg.norm(B - A)
    out["out.in"], out["out.out"] = float((A - P) @ u), float((B - P) @ u)
    a = _mid(W("core_ab.a_0"), W("core_ab.a_1"))
    b = _mid(W("core_ab.b_0"), W("core_ab.b_1"))
    c = _mid(W("core_cd.c_0"), W("core_cd.c_1"))
    d = W("core_cd.d")
    axis = W("core_ab.a_1") - W("core_ab.a_0")          # the core's hinge axis (+z as built)
    out["core.abc"] = float(np.cross(b - a, c - a) @ axis)
    out["core.cd"] = float((d - c) @ (c - _mid(a, b)))
    return out


def indicators(scene: Scene, pos, R) -> dict:
    """The branch indicators of a library gate scene (sigma or sigma^2) at poses ``pos``
    (N,3) and rotation matrices ``R`` (N,3,3)."""
    return _indicators_from_sites(_all_sites(scene, pos, R), scene.arrays().site_index)


def folded(ind: dict) -> list[str]:
    """Indicators off their design side."""
    return [k for k in INDICATORS if np.sign(ind[k]) != DESIGN_SIGN[k]]


def gate_energy(scene: Scene, pos, quat, state: str) -> float:
    """Bond and muscle energy (k0 sigma^2) of ``scene`` at poses ``pos``/``quat`` with the
    muscles of input ``state``."""
    A = scene.arrays()
    R = np.array([quat_to_matrix(q) for q in quat])
    p = np.asarray(pos)[A.site_body] + np.einsum("nij,nj->ni", R[A.site_body], A.site_local)
    n = np.linalg.norm(p[A.bond_i] - p[A.bond_j], axis=1)
    r = np.maximum(0.0, np.abs(n - A.bond_rest) - A.bond_tol)
    dm = np.linalg.norm(p[A.muscle_i] - p[A.muscle_j], axis=1) - A.muscle_lengths([int(c) for c in state])
    return float(0.5 * (A.bond_k @ r**2 + A.muscle_k @ dm**2))


# the two sites whose distance is a lever side's length, and the lever's arm on that side
_FLAT_SITES = {"a.out": ("a_lo.core_0", "a_hi.core_0"), "b.out": ("b_lo.core_0", "b_hi.core_0"),
               "a.in": ("a_lo.in", "a_hi.in"), "b.in": ("b_lo.in", "b_hi.in"),
               "out.in": ("out_lo.core_0", "out_hi.core"), "out.out": ("out_lo.out", "out_hi.out")}


@dataclass
class FlatBarrier:
    indicator: str
    state: str
    barrier: float          # k0 sigma^2: smallest energy found with that lever side flat
    stretch: float          # largest joint stretch there (sigma)
    flat_length: float      # the side's length when flat, 2 x arm (sigma)


def flat_barrier(scene: Scene, state: str, indicator: str, geometry=None, stiffness: float = 1e4) -> FlatBarrier:
    """Energy barrier (lower estimate) for folding one lever side of a library gate to its
    other branch in input ``state``.

    A lever side folds by passing its half-angle through pi/2, where the side is flat: its
    two ends are 2 x arm apart (2 l1 on the input side, 2 l2 on the output side).  The
    gate is held there by an extra, ``stiffness`` times stiffer muscle between the two
    ends, moved from its equilibrium length to 2 x arm by the static solver's
    continuation; the returned energy is that of the gate's own bonds and muscles in the
    pose reached (the constrained minimum nearest to the design pose, k0 sigma^2)."""
    import copy

    from mlc.gates.library import gate_geometry
    from mlc.scene.model import Muscle
    from mlc.verify.static import equilibrium

    geo = geometry or gate_geometry(scene.meta["gate"], scene.meta["signal"])
    lever, side = indicator.split(".")
    lev = {"a": geo.lever_a, "b": geo.lever_b, "out": geo.lever_out}[lever]
    flat = 2.0 * (lev.l1 if side == "in" else lev.l2)
    eq = equilibrium(scene, state)
    s = copy.copy(scene)
    s1, s2 = _FLAT_SITES[indicator]
    now = float(np.linalg.norm(s.with_poses(eq.pos, eq.quat).site_world(s1) -
                               s.with_poses(eq.pos, eq.quat).site_world(s2)))
    s.inputs = list(scene.inputs) + ["_fold"]
    s.muscles = list(scene.muscles) + [Muscle("_fold", "_fold", s1, s2, now, flat, stiffness)]
    s = s.with_poses(eq.pos, eq.quat)
    e = equilibrium(s, state + "1", start_state=state + "0", steps=16)
    return FlatBarrier(indicator, state, gate_energy(scene, e.pos, e.quat, state), e.max_joint_stretch, flat)


class _Energy:
    """Bond + muscle energy of a scene as least-squares residuals over body poses
    (translation and rotation vector per body relative to a reference pose; body 0
    fixed)."""

    def __init__(self, scene: Scene, pos, quat, L):
        self.scene = scene
        self.A = A = scene.arrays()
        self.pos0 = np.asarray(pos, float)
        self.R0 = np.array([quat_to_matrix(q) for q in quat])
        self.L = np.asarray(L, float)
        self.sk = np.sqrt(A.bond_k)
        self.mk = np.sqrt(A.muscle_k)

    def poses(self, x):
        d = np.zeros((len(self.pos0), 6))
        d[1:] = x.reshape(-1, 6)
        R = np.array([expmap(w) @ r for w, r in zip(d[:, 3:], self.R0)])
        return self.pos0 + d[:, :3], R

    def sites(self, x):
        A = self.A
        pos, R = self.poses(x)
        return pos[A.site_body] + np.einsum("nij,nj->ni", R[A.site_body], A.site_local)

    def residuals(self, x, p=None):
        A = self.A
        p = self.sites(x) if p is None else p
        dvec = p[A.bond_i] - p[A.bond_j]
        n = np.linalg.norm(dvec, axis=1)
        r = np.maximum(0.0, np.abs(n - A.bond_rest) - A.bond_tol)
        zero = (A.bond_rest == 0) & (A.bond_tol == 0)
        res = [(self.sk[zero, None] * dvec[zero]).ravel(), self.sk[~zero] * r[~zero]]
        dm = np.linalg.norm(p[A.muscle_i] - p[A.muscle_j], axis=1)
        res.append(self.mk * (dm - self.L))
        return np.concatenate(res)

    def energy(self, x):
        r = self.residuals(x)
        return 0.5 * float(r @ r)


@dataclass
class FoldBarrier:
    indicator: str
    start: float                  # indicator at the equilibrium
    barrier: float                # F(0), k0 sigma^2
    peak: float                   # largest F on the continuation path, k0 sigma^2
    profile: list                 # [(s, F(s))]
    pos: np.ndarray               # pose at s = 0
    quat: np.ndarray


def fold_barrier(scene: Scene, state: str, indicator: str, pos, quat, steps: int = 12,
                 target: float = 0.0) -> FoldBarrier:
    """Constrained-minimum energy profile of ``indicator`` from the equilibrium pose
    (``pos``, ``quat``) of input ``state`` to ``target`` (default the indicator's zero;
    see the module docstring), in ``steps`` equal steps.  Energies in k0 sigma^2;
    ``barrier`` is F at the target, ``peak`` the largest F on the way."""
    A = scene.arrays()
    L = A.muscle_lengths([int(c) for c in state])
    en = _Energy(scene, pos, quat, L)
    s0 = indicators(scene, en.pos0, en.R0)[indicator]
    x = np.zeros(6 * (len(scene.bodies) - 1))
    ix = A.site_index
    prof = [(s0, en.energy(x))]
    sq = np.sqrt(PENALTY)
    for t in np.linspace(0, 1, steps + 1)[1:]:
        target_t = s0 + t * (target - s0)

        def fun(y, tt=target_t):
            p = en.sites(y)
            return np.append(en.residuals(y, p), sq * (_indicators_from_sites(p, ix)[indicator] - tt))
        x = least_squares(fun, x, method="trf", xtol=1e-12, ftol=1e-12, gtol=1e-12, max_nfev=400).x
        pos_, R_ = en.poses(x)
        prof.append((indicators(scene, pos_, R_)[indicator], en.energy(x)))
    pos_, R_ = en.poses(x)
    return FoldBarrier(indicator, s0, prof[-1][1], max(f for _, f in prof), prof, pos_,
                       np.array([matrix_to_quat(r) for r in R_]))


def singular_values(scene: Scene, state: str, pos, quat, h: float = 1e-6) -> np.ndarray:
    """Singular values of the Jacobian of the gate's joint and muscle residuals (sqrt(k0)
    sigma per sigma or rad) with respect to the poses of all bodies but the first (held
    fixed), at poses ``pos``/``quat`` and the muscles of input ``state``; central
    differences, independent of the static solver's analytic Jacobian.  All positive:
    the equilibrium is isolated (no floppy mode) -- locally."""
    A = scene.arrays()
    en = _Energy(scene, pos, quat, A.muscle_lengths([int(c) for c in state]))
    n = 6 * (len(scene.bodies) - 1)
    J = np.empty((len(en.residuals(np.zeros(n))), n))
    for i in range(n):
        e = np.zeros(n)
        e[i] = h
        J[:, i] = (en.residuals(e) - en.residuals(-e)) / (2 * h)
    return np.linalg.svd(J, compute_uv=False)


def quench(scene: Scene, state: str, pos, quat, reference=None) -> dict:
    """Relax a pose (e.g. a Brownian-dynamics frame) to its local equilibrium with the
    muscles of input ``state`` and say whether that is the design equilibrium: same probe
    reading (within 1e-3 sigma) as ``reference`` (an Equilibrium; default the static
    solution), every branch indicator on its design side, zero joint stretch (1e-6 sigma)."""
    from mlc.verify.static import equilibrium

    ref = reference or equilibrium(scene, state)
    q = equilibrium(scene, state, start_state=state, pos=pos, quat=quat)
    R = np.array([quat_to_matrix(x) for x in q.quat])
    f = folded(indicators(scene, q.pos, R))
    name = scene.probes[0].name
    dev = abs(q.probes[name] - ref.probes[name])
    return {"design": bool(dev <= 1e-3 and not f and q.max_joint_stretch <= 1e-6), "probe": q.probes[name],
            "folded": f, "stretch": q.max_joint_stretch}
