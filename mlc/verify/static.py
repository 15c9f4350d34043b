"""Static verification: the mechanical equilibrium of a scene in an input state.

For an input state (a bit string in ``scene.inputs`` order) the muscles take their
rest or actuated lengths and the body poses minimise the total bond energy

    E = sum_bonds k/2 max(0, | |d| - rest | - tol)^2 + sum_muscles k/2 (|d| - L)^2

(units: sigma, k0).  The residual vector (zero-length bonds without tolerance contribute
their 3-vector, the others a scalar) is minimised by a damped Gauss-Newton
(Levenberg-Marquardt) iteration on the sparse normal equations, factorised by SuperLU:
each iteration linearises about the current poses, a body's update being a translation
and a rotation vector ``w`` (R <- exp(w) R, d site/d w = -[R s]x), so no rotation
parametrisation accumulates.  No body is pinned.  Zero-energy modes (the six rigid-body
modes, a connector chain's floppy bending) are fixed by a weak term
``REG/2 sum_bodies (|dx|^2 + |dw|^2)`` on each body's displacement since the start of the
continuation step: among all equilibria the solver takes the one reached by the least
motion, which is what overdamped dynamics does quasi-statically (a floppy mode has no
force on it, and the drag makes the least-dissipation path the one taken).  ``REG`` is
small enough (1e-9 k0) that it biases joint stretch by less than 1e-8 sigma in the
examples; its pull adds up along a circuit's chains, to a few 1e-6 sigma in a 200-gate
one, which the final polish removes.  The Jacobian is assembled with numpy, without Python loops over bonds,
so a circuit of ~10^4 bodies solves in seconds.  The muscles are moved from the starting
state to the target in a few continuation steps so that the solution stays on the
mechanism's physical branch.

Stiff joints (a circuit compiled with ``--joint-k``) make the least-squares problem
ill-conditioned: Levenberg-Marquardt then crawls along the joints' constraint surface and
its stall test stops it short of equilibrium.  The continuation is therefore run with every
bond softened to at most ``STIFF_CAP`` times the stiffest muscle (a homotopy in stiffness:
the equilibrium of a mechanism whose joints hold moves by O(load/k) with k, a fraction of
the joint stretch, below 1e-3 sigma), and the real stiffnesses are restored for the last
minimisations (the restoring one and the polish), which start next to their solution.
The restoring one can still stop short (bcd7seg's row 1111: joint stretch 4.4e-5 sigma,
benchmarks/results/static_polish.json, measured when one stalled iteration stopped a
minimisation; see :func:`_minimise`); the polish then finishes it, which is why
``equilibrium(polish=None)`` polishes exactly where a joint or muscle is left off.

A deep circuit's signal crosses every logic level within each continuation step, and the
minimisation of the whole scene then crawls along a long, soft valley (the 200-gate mesh's
all-ones row, docs/circuits.md).  Given the bodies' logic levels, :func:`_staged` solves one
level at a time with the levels before it held, so that the minimisation of the whole scene
starts at or next to its equilibrium, and is skipped when every bond is met
(``equilibrium(levels=...)``, what a circuit's static check uses).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp

from mlc.circuit.levels import body_levels
from mlc.errors import InternalError, MlcError
from mlc.geometry.rotation import matrix_to_quat
from mlc.scene.model import Scene, SceneArrays

CONTINUATION_STEPS = 4
GN_MAX_ITER = 60            # Gauss-Newton iterations per continuation step
GN_TOL = 1e-13              # converged when the largest update (sigma, rad) is below this
REG = 1e-9                  # k0: weight of the least-motion term on zero-energy modes
REG_POLISH = 1e-16          # k0: the same in the final polish (removes REG's bias on the pose)
ACCEL_H = 0.1               # finite-difference step (fraction of dx) for the geodesic acceleration
ACCEL_RATIO = 1.5           # the acceleration is used while |a| <= this |dx| (|a/2| <= 0.75 |dx|)
POLISH_ABOVE = 1e-7         # sigma: polish=None polishes only when a joint is stretched or a muscle strained more
STALL_GAIN = 1e-3           # an iteration that lowers the cost by less than this fraction of it has stalled
STALL_RUN = 3               # stalled iterations in a row that stop a minimisation whose bonds are still off,
STALL_CLOSED = 1e-7         # sigma: that is, with a joint stretched or a muscle strained by more than this
STIFF_CAP = 4.0             # bonds stiffer than this many times the stiffest muscle are softened to it
                            # for the continuation, then restored for the polish (see equilibrium)


@dataclass
class Equilibrium:
    state: str
    pos: np.ndarray                 # (N, 3)
    quat: np.ndarray                # (N, 4)
    probes: dict                    # probe name -> length (sigma)
    max_joint_stretch: float        # largest |d| - rest - tol over the scene's bonds (sigma)
    max_muscle_strain: float        # largest | |d| - L | over the muscles (sigma)
    energy: float                   # k0 sigma^2
    iterations: int = 0
    rows: list = field(default_factory=list)
    converged: bool = True          # False: stopped short, or jammed (see equilibrium)


def _expmap_batch(w: np.ndarray) -> np.ndarray:
    """Rotation matrices exp([w]x) for rotation vectors w of shape (N, 3)."""
    th = np.linalg.norm(w, axis=1)
    K = np.zeros((len(w), 3, 3))
    K[:, 0, 1], K[:, 0, 2], K[:, 1, 2] = -w[:, 2], w[:, 1], -w[:, 0]
    K[:, 1, 0], K[:, 2, 0], K[:, 2, 1] = w[:, 2], -w[:, 1], w[:, 0]
    small = th < 1e-8
    a = np.where(small, 1.0, np.sin(th) / np.where(small, 1.0, th))
    b = np.where(small, 0.5, (1 - np.cos(th)) / np.where(small, 1.0, th) ** 2)
    return np.eye(3)[None] + a[:, None, None] * K + b[:, None, None] * (K @ K)


def _quat_to_matrix_batch(q: np.ndarray) -> np.ndarray:
    q = q / np.linalg.norm(q, axis=1, keepdims=True)
    w, x, y, z = q.T
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
        np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
        np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1)], 1)


class _Problem:
    """Residuals and sparse Jacobian of the bond energy about the current poses."""

    def __init__(self, scene, pos0, quat0, pin_first: bool = True, free=None, R0=None):
        """``scene``: a Scene or its arrays (a :class:`SceneArrays`).  ``pin_first`` holds
        body 0 fixed (its columns dropped): the rigidity analysis uses that;
        :func:`equilibrium` pins nothing and uses the least-motion term.  ``free``, if given,
        lists the bodies that move (the others are held); ``R0`` gives the rotation
        matrices instead of ``quat0``."""
        self.A = A = scene.arrays() if isinstance(scene, Scene) else scene
        self.N = len(pos0)
        self.pos = np.array(pos0, float)
        if R0 is not None:
            self.R = np.array(R0, float)
        else:
            self.R = _quat_to_matrix_batch(np.asarray(quat0, float)) if self.N else np.zeros((0, 3, 3))
        self.vec = (A.bond_rest == 0) & (A.bond_tol == 0)   # zero-length bonds: vector residual
        self.iv = np.nonzero(self.vec)[0]
        self.bond_k = np.array(A.bond_k, float)       # k0: may be softened for a continuation (equilibrium)
        self.isc = np.nonzero(~self.vec)[0]
        self.m = 3 * len(self.iv) + len(self.isc) + len(A.muscle_i)
        if free is not None:
            self.free = np.asarray(free, dtype=np.int64)
        else:
            self.free = np.arange(1, self.N) if pin_first else np.arange(self.N)
        self.col = np.full(self.N, -1)
        self.col[self.free] = np.arange(len(self.free)) * 6
        self.n = 6 * len(self.free)
        self.set_reference()

    def set_reference(self):
        """Start of a continuation step: the least-motion term measures from here."""
        self.disp = np.zeros((self.N, 6))           # translation and rotation vector since then

    def sites(self):
        A = self.A
        rs = np.einsum("nij,nj->ni", self.R[A.site_body], A.site_local)
        return self.pos[A.site_body] + rs, rs

    def residuals(self, L_muscle, p=None):
        A = self.A
        if p is None:
            p, _ = self.sites()
        sk = np.sqrt(self.bond_k)
        d = p[A.bond_i] - p[A.bond_j]
        out = [(sk[self.iv, None] * d[self.iv]).ravel()]
        if len(self.isc):
            ds = d[self.isc]
            r = np.linalg.norm(ds, axis=1) - A.bond_rest[self.isc]
            out.append(sk[self.isc] * np.sign(r) * np.maximum(0.0, np.abs(r) - A.bond_tol[self.isc]))
        dm = p[A.muscle_i] - p[A.muscle_j]
        out.append(np.sqrt(A.muscle_k) * (np.linalg.norm(dm, axis=1) - L_muscle))
        return np.concatenate(out)

    def normal_matrix(self, J, reg: float):
        """The damped normal matrix J^T J + reg I (CSC) that each Levenberg-Marquardt step
        factorises, before its lam D damping (k0; ``reg`` the least-motion weight)."""
        return (J.T @ J + sp.identity(J.shape[1], format="csc") * reg).tocsc()

    def jacobian(self, x=None, L_muscle=None):
        """Sparse d residual / d (t, w) of the free bodies at the current poses (``x``, if
        given, must be zero: the linearisation is always about the current poses; the
        muscle lengths do not enter the Jacobian)."""
        if x is not None and np.any(x):
            raise ValueError("jacobian() linearises about the current poses: x must be 0")
        A = self.A
        p, rs = self.sites()
        S = len(A.site_body)
        blocks = np.zeros((S, 3, 6))                     # d p_site / d (t, w) of its body
        blocks[:, :, :3] = np.eye(3)
        blocks[:, 0, 4], blocks[:, 0, 5] = rs[:, 2], -rs[:, 1]     # -[Rs]x
        blocks[:, 1, 3], blocks[:, 1, 5] = -rs[:, 2], rs[:, 0]
        blocks[:, 2, 3], blocks[:, 2, 4] = rs[:, 1], -rs[:, 0]
        rows, cols, vals = [], [], []

        def add(row0, nrow, site, coef):
            """coef (E, nrow, 3) left factor on dp_site for E entries starting at rows row0."""
            body = A.site_body[site]
            keep = self.col[body] >= 0
            if not np.any(keep):
                return
            blk = np.einsum("eij,ejk->eik", coef[keep], blocks[site[keep]])      # (E, nrow, 6)
            r = row0[keep, None, None] + np.arange(nrow)[None, :, None]
            c = self.col[body[keep], None, None] + np.arange(6)[None, None, :]
            r, c = np.broadcast_arrays(r, c)
            rows.append(r.ravel()), cols.append(c.ravel()), vals.append(blk.ravel())

        sk = np.sqrt(self.bond_k)
        nv = len(self.iv)
        if nv:
            row0 = 3 * np.arange(nv)
            coef = sk[self.iv, None, None] * np.eye(3)[None]
            add(row0, 3, A.bond_i[self.iv], coef)
            add(row0, 3, A.bond_j[self.iv], -coef)
        base = 3 * nv
        if len(self.isc):
            b = self.isc
            d = p[A.bond_i[b]] - p[A.bond_j[b]]
            n = np.linalg.norm(d, axis=1)
            r = n - A.bond_rest[b]
            active = (n > 0) & (np.abs(r) > A.bond_tol[b])
            g = np.where(active[:, None], sk[b, None] * d / np.where(n > 0, n, 1.0)[:, None], 0.0)[:, None, :]
            row0 = base + np.arange(len(b))
            add(row0, 1, A.bond_i[b], g)
            add(row0, 1, A.bond_j[b], -g)
            base += len(b)
        if len(A.muscle_i):
            d = p[A.muscle_i] - p[A.muscle_j]
            n = np.maximum(np.linalg.norm(d, axis=1), 1e-300)
            g = (np.sqrt(A.muscle_k)[:, None] * d / n[:, None])[:, None, :]
            row0 = base + np.arange(len(A.muscle_i))
            add(row0, 1, A.muscle_i, g)
            add(row0, 1, A.muscle_j, -g)
        if rows:
            rows, cols, vals = np.concatenate(rows), np.concatenate(cols), np.concatenate(vals)
        else:
            rows = cols = np.zeros(0, int)
            vals = np.zeros(0)
        return sp.csr_matrix((vals, (rows, cols)), shape=(self.m, self.n))

    def apply(self, dx):
        """Move the bodies by dx = (t, w) per body (R <- exp(w) R)."""
        d = dx.reshape(-1, 6)
        f = self.free
        self.pos[f] += d[:, :3]
        self.R[f] = _expmap_batch(d[:, 3:]) @ self.R[f]
        self.disp[f] += d            # rotation vectors add to first order: enough for a weight

    def snapshot(self):
        return self.pos.copy(), self.R.copy(), self.disp.copy()

    def restore(self, snap):
        self.pos, self.R, self.disp = snap[0].copy(), snap[1].copy(), snap[2].copy()


def spd_lu(M):
    """SuperLU factorisation of a symmetric positive definite sparse matrix ``M`` in
    SuperLU's symmetric mode: a minimum-degree order of M + M^T and pivots on the diagonal,
    which is stable for such a matrix as Cholesky is.  On the examples' normal equations it
    keeps 64 to 76 % of COLAMD's fill and factorises 1.2 to 1.3 times faster
    (benchmarks/results/static_lu.json).  :mod:`mlc.verify.dynamic` takes it for its harmonic
    analyses (one factorisation, many solves).  The minimiser does not: its path depends on
    the last bits of each step, and on mux4's all-ones row it took 90 iterations with this
    order against 47 with COLAMD.  A matrix singular to working precision raises
    RuntimeError, as with any order."""
    from scipy.sparse.linalg import splu

    return splu(M.tocsc(), permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0, options={"SymmetricMode": True})


def colamd_lu(M):
    """The minimiser's factorisation (COLAMD order, partial pivoting).  Every routed scene
    depends on it through its gates' poses (:func:`mlc.circuit.build._posed_gate`): another
    factorisation moves them by ~1e-12 sigma, enough to change a scene's bits and so its
    key in the dynamic campaigns (benchmarks/circuit_dynamic.py)."""
    from scipy.sparse.linalg import splu

    return splu(M.tocsc(), permc_spec="COLAMD")


def _minimise(prob: _Problem, L, reg: float = None, lu_of=None) -> int:
    """Levenberg-Marquardt with geodesic acceleration on 0.5 |r|^2 from the current poses;
    returns the iteration count.

    The acceleration (Transtrum & Sethna, 2012) adds to each step dx the second-order
    correction a = -(J^T J + lam D)^-1 J^T r'', with r'' the residuals' second directional
    derivative along dx (a finite difference, one extra residual evaluation, the same
    factorisation): moving a floppy chain along its linearised zero mode stretches its
    joints quadratically, and without the correction the step is cut back to a crawl
    (module doc).  The corrected step dx + a/2 is tried when |a| <= ACCEL_RATIO |dx|,
    otherwise dx alone.  ``lu_of``: the factorisation (default :func:`colamd_lu`).

    It stops when the cost is below 1e-30, when the largest update is below ``GN_TOL``,
    when no damping gives a lower cost, after ``GN_MAX_ITER`` iterations, or when it stalls
    (an iteration lowers the cost by less than ``STALL_GAIN`` of it): at once if no joint is stretched
    nor any muscle strained by more than ``STALL_CLOSED``, otherwise after ``STALL_RUN``
    stalled iterations in a row.  In a deep circuit the cost falls along a long, soft valley
    in a sawtooth: an iteration whose damping was just raised gains little and the next
    ones gain a few per cent each (the 200-gate mesh's all-ones row, docs/circuits.md); one
    stalled iteration there is no sign of an equilibrium."""
    reg = REG if reg is None else reg
    lu_of = colamd_lu if lu_of is None else lu_of

    def total(rr):
        return 0.5 * float(rr @ rr) + 0.5 * reg * float(np.sum(prob.disp ** 2))

    prob.set_reference()
    r = prob.residuals(L)
    cost = total(r)
    lam = 1e-6
    it = stalls = 0
    for it in range(1, GN_MAX_ITER + 1):
        if cost < 1e-30:
            break
        J = prob.jacobian()
        g = J.T @ r + reg * prob.disp[prob.free].ravel()
        H = prob.normal_matrix(J, reg)
        diag = H.diagonal()
        scale = np.maximum(diag, 1e-12 * max(float(diag.max(initial=0.0)), 1.0))
        improved = stalled = False
        for _ in range(12):
            M = (H + sp.diags(lam * scale + 1e-14, format="csc")).tocsc()
            try:
                lu = lu_of(M)
            except RuntimeError:
                lam *= 10.0
                continue
            dx = -lu.solve(g)
            snap = prob.snapshot()
            prob.apply(ACCEL_H * dx)                     # r'' along dx, by a finite difference
            rpp = (2.0 / ACCEL_H) * ((prob.residuals(L) - r) / ACCEL_H - J @ dx)
            prob.restore(snap)
            acc = -lu.solve(J.T @ rpp)
            if np.linalg.norm(acc) <= ACCEL_RATIO * np.linalg.norm(dx):
                dx = dx + 0.5 * acc
            prob.apply(dx)
            r_new = prob.residuals(L)
            c_new = total(r_new)
            if c_new <= cost:
                improved = True
                stalled = (cost - c_new) < STALL_GAIN * cost
                r, cost = r_new, c_new
                lam = max(lam / 5.0, 1e-12)
                break
            prob.restore(snap)
            lam *= 10.0
        if not improved or float(np.abs(dx).max(initial=0.0)) < GN_TOL:
            break
        stalls = stalls + 1 if stalled else 0
        if stalls and (stalls >= STALL_RUN or max(_strains(prob, L)) <= STALL_CLOSED):
            break
    return it


def _sub_arrays(A, bodies: np.ndarray, bonds: np.ndarray, muscles: np.ndarray):
    """The arrays of the part of a scene made of ``bodies`` (sorted indices), the bonds and
    the muscles listed (each joins two of those bodies), numbered afresh."""
    local = np.full(len(A.pos), -1, dtype=np.int64)
    local[bodies] = np.arange(len(bodies))
    keep = np.nonzero(local[A.site_body] >= 0)[0]
    site_local = np.full(len(A.site_body), -1, dtype=np.int64)
    site_local[keep] = np.arange(len(keep))
    z = np.zeros(0)
    return SceneArrays(
        pos=A.pos[bodies], quat=A.quat[bodies], site_body=local[A.site_body[keep]], site_local=A.site_local[keep],
        bond_i=site_local[A.bond_i[bonds]], bond_j=site_local[A.bond_j[bonds]], bond_k=A.bond_k[bonds],
        bond_rest=A.bond_rest[bonds], bond_tol=A.bond_tol[bonds],
        muscle_i=site_local[A.muscle_i[muscles]], muscle_j=site_local[A.muscle_j[muscles]],
        muscle_k=A.muscle_k[muscles], muscle_rest=A.muscle_rest[muscles], muscle_act=A.muscle_act[muscles],
        muscle_input=A.muscle_input[muscles], probe_i=z.astype(np.int64), probe_j=z.astype(np.int64),
        probe_rest=z, probe_act=z, site_index={})


def _staged(prob: _Problem, levels: np.ndarray, L0, L1, steps: int, lu_of=None) -> int:
    """Move ``prob`` from the start state (muscles at ``L0``) to the target (``L1``) one
    level at a time; returns the iteration count.

    ``levels[b]`` is body b's place in the order (a circuit's logic depth,
    :func:`mlc.circuit.levels.body_levels`).  Level by level, in increasing order, the
    bodies of that level move and those of the levels before are held; the bonds and muscles
    that reach a later level are left out.  The held bodies next to the moving ones go from
    their start poses to the poses solved for them in ``steps`` continuation steps (the
    translation linearly, the rotation along its geodesic), the muscles of the level from
    ``L0`` to ``L1`` in the same steps.  In a feed-forward circuit each level is then a small
    problem whose inputs are already right, so the whole minimisation that follows starts
    next to its equilibrium instead of carrying the signal through every level at once
    (docs/circuits.md, "Level by level")."""
    from scipy.spatial.transform import Rotation

    A = prob.A
    levels = np.asarray(levels)
    sb = A.site_body
    bl_i, bl_j = levels[sb[A.bond_i]], levels[sb[A.bond_j]]
    ml_i, ml_j = levels[sb[A.muscle_i]], levels[sb[A.muscle_j]]
    pos0, R0 = prob.pos.copy(), prob.R.copy()
    ts = np.linspace(0.0, 1.0, steps + 1)[1:]
    nit = 0
    for lev in np.unique(levels):
        bonds = np.nonzero((np.maximum(bl_i, bl_j) == lev))[0]
        muscles = np.nonzero((np.maximum(ml_i, ml_j) == lev))[0]
        if not len(bonds) and not len(muscles):         # nothing pulls on this level's bodies
            continue
        moving = np.nonzero(levels == lev)[0]
        touched = np.concatenate([sb[A.bond_i[bonds]], sb[A.bond_j[bonds]],
                                  sb[A.muscle_i[muscles]], sb[A.muscle_j[muscles]], moving])
        bodies = np.unique(touched)
        held = levels[bodies] < lev
        sub = _sub_arrays(A, bodies, bonds, muscles)
        sp_ = _Problem(sub, prob.pos[bodies], None, free=np.nonzero(~held)[0], R0=prob.R[bodies])
        sp_.bond_k = prob.bond_k[bonds]                 # the continuation's (possibly softened) stiffness
        hb = bodies[held]
        p_a, p_b = pos0[hb], prob.pos[hb]
        rot = Rotation.from_matrix(prob.R[hb] @ np.transpose(R0[hb], (0, 2, 1))).as_rotvec() if len(hb) else None
        for t in ts:
            if len(hb):
                sp_.pos[held] = p_a + t * (p_b - p_a)
                sp_.R[held] = Rotation.from_rotvec(t * rot).as_matrix() @ R0[hb]
            Lm = L0[muscles] + t * (L1[muscles] - L0[muscles])
            nit += _minimise(sp_, Lm, lu_of=lu_of)
        free = bodies[~held]
        prob.pos[free], prob.R[free] = sp_.pos[~held], sp_.R[~held]
    return nit


def _state_bits(scene: Scene, state: str) -> np.ndarray:
    n = len(scene.inputs)
    if len(state) != n or set(state) - {"0", "1"}:
        raise MlcError(f"input state {state!r} is not {n} bits for inputs {scene.inputs}", "STATE")
    return np.array([int(c) for c in state], dtype=float)


def equilibrium(scene: Scene, state: str, start_state: str | None = None,
                steps: int = CONTINUATION_STEPS, pos=None, quat=None, lu_of=None, progress=None,
                polish: bool | None = True, levels=None) -> Equilibrium:
    """Equilibrium of ``scene`` with its inputs in ``state``, reached by continuation from
    the scene's own poses (or ``pos``/``quat``), taken to be the equilibrium of
    ``start_state`` (default all 0).  ``lu_of``: the factorisation of the normal equations
    (default :func:`colamd_lu`).  ``progress(f)``, if given, is called after each
    minimisation with the fraction ``f`` (0 < f <= 1) of the minimisations done (the
    continuation steps, the stiff joints' restoring one, the polish): a large circuit's row
    takes minutes, and its progress bar moves within it.

    ``polish``: end with a minimisation at ``REG_POLISH``, which takes the least-motion
    term's bias off the pose and finishes a minimisation that stalled short of equilibrium.
    In a connector circuit it crawls along the chains' floppy modes, a third of a row's
    factorisations (benchmarks/results/static_polish.json).  ``True``: always (the circuit
    builder poses its gates so, and the scenes it writes depend on those last bits);
    ``False``: never; ``None``: only when the pose before it has a joint stretched or a
    muscle strained by more than ``POLISH_ABOVE`` (sigma), that is, when the minimisation
    stalled; otherwise the pose is the one ``True`` starts its polish from (what the
    circuits' static verifier uses; docs/circuits.md, "Speed").

    The result's ``converged`` is False when the last minimisation ended with a joint
    stretched or a muscle strained by more than ``POLISH_ABOVE`` and more energy left in the
    bonds than the least-motion term (``REG``) holds on the motion of that minimisation.  At
    the regularised equilibrium of a mechanism that can meet all its bonds that term holds
    at least as much (its pull, summed along a deep circuit's chains, stretches joints by a
    few 1e-6 sigma); a minimisation that crawled along a long curved valley keeps most of
    its energy in the bonds (the 200-gate mesh's all-ones row, docs/circuits.md,
    "Scaling").  So does a jammed mechanism at its true equilibrium: False means one of the
    two, and only the dynamic check tells which.

    ``levels`` (one integer per body, ``"depth"`` or None): the continuation goes level by level
    (:func:`_staged`), and the minimisations of the whole scene at the target follow only
    when a joint is left stretched or a muscle strained by more than ``POLISH_ABOVE``: a
    pose with every bond met has zero energy, the least there is, so it is an equilibrium
    whatever the stiffnesses (the polish still runs when ``polish`` is True).  A circuit's
    static check passes ``"depth"``: its bodies' logic depths
    (:func:`mlc.circuit.levels.body_levels`), None for a scene that is not a circuit."""
    A = scene.arrays()
    if isinstance(levels, str):
        if levels != "depth":
            raise InternalError(f"equilibrium: levels={levels!r}, expected 'depth', an array or None")
        levels = body_levels(scene, A)
    target = _state_bits(scene, state)
    start = _state_bits(scene, start_state or "0" * len(scene.inputs))
    prob = _Problem(scene, A.pos if pos is None else pos, A.quat if quat is None else quat, pin_first=False)
    L0, L1 = A.muscle_lengths(start), A.muscle_lengths(target)
    nit = 0
    path = [1.0] if np.allclose(L0, L1) else np.linspace(0, 1, steps + 1)[1:]
    if prob.m and prob.n:
        k_cap = STIFF_CAP * float(np.max(A.muscle_k, initial=1.0))
        stiff = bool(np.any(prob.bond_k > k_cap))
        if stiff:                                       # stiffness homotopy (module docstring)
            prob.bond_k = np.minimum(prob.bond_k, k_cap)
        staged = levels is not None and len(np.unique(levels)) > 1 and len(path) > 1
        if staged:
            path = [1.0]
        total, done = len(path) + staged + stiff + (polish is not False), 0

        def tick():
            nonlocal done
            done += 1
            if progress is not None:
                progress(done / total)
        closed = False
        if staged:
            nit += _staged(prob, levels, L0, L1, steps, lu_of=lu_of)
            tick()
            closed = max(_strains(prob, L1)) <= POLISH_ABOVE      # every bond met: already an equilibrium
        for t in path:
            if not closed:
                nit += _minimise(prob, L0 + t * (L1 - L0), lu_of=lu_of)
            tick()
        if stiff:
            prob.bond_k = np.array(A.bond_k, float)
            if not closed:
                nit += _minimise(prob, L1, lu_of=lu_of)
            tick()
        if polish or (polish is None and not closed and max(_strains(prob, L1)) > POLISH_ABOVE):
            nit += _minimise(prob, L1, reg=REG_POLISH, lu_of=lu_of)     # the least-motion bias removed
        if polish is not False:
            tick()
    pos, R = prob.pos, prob.R
    p, _ = prob.sites()
    quat = np.array([matrix_to_quat(r) for r in R]) if len(R) else np.zeros((0, 4))
    stretch, strain = _strains(prob, L1)
    probes = {pr.name: float(np.linalg.norm(p[A.probe_i[i]] - p[A.probe_j[i]])) for i, pr in enumerate(scene.probes)}
    r = prob.residuals(L1) if prob.m else np.zeros(0)
    energy = float(0.5 * r @ r)
    converged = max(stretch, strain) <= POLISH_ABOVE or energy <= 0.5 * REG * float(np.sum(prob.disp ** 2))
    return Equilibrium(state, pos.copy(), quat, probes, stretch, strain, energy, nit, converged=converged)


def _strains(prob: _Problem, L_muscle) -> tuple[float, float]:
    """(largest joint stretch beyond its tolerance, largest | muscle length - L |) at the
    current poses (sigma)."""
    A = prob.A
    p, _ = prob.sites()
    d = np.linalg.norm(p[A.bond_i] - p[A.bond_j], axis=1) if len(A.bond_i) else np.zeros(0)
    stretch = np.maximum(0.0, np.abs(d - A.bond_rest) - A.bond_tol) if len(d) else np.zeros(0)
    dm = np.linalg.norm(p[A.muscle_i] - p[A.muscle_j], axis=1) if len(A.muscle_i) else np.zeros(0)
    return float(stretch.max(initial=0.0)), float(np.abs(dm - L_muscle).max(initial=0.0))


def solve_states(scene: Scene) -> dict[str, Equilibrium]:
    """Equilibria of every input state, each reached by continuation from the rest pose."""
    return {s: equilibrium(scene, s) for s in scene.states()}


def verify_scene(scene: Scene, tol_length: float = 0.05, tol_stretch: float = 1e-3) -> list[dict]:
    """Check every input state against ``scene.truth_table``: one row per (state, probe) with
    the expected bit, measured length (sigma), margin to the threshold, ideal length and
    residual joint stretch.  ``ok`` needs the right bit, the length within ``tol_length``
    of the ideal rest/actuated length and the stretch below ``tol_stretch``."""
    if scene.truth_table is None:
        raise MlcError(f"scene {scene.name} has no truth table to verify against", scene.source or scene.name,
                       "add a truth_table mapping input bits to output bits")
    rows = []
    for state in scene.states():
        eq = equilibrium(scene, state)
        want = scene.truth_table.get(state)
        for pr in scene.probes:
            idx = scene.outputs.index(pr.output)
            bit = None if want is None or want[idx] == "-" else int(want[idx])
            L = eq.probes[pr.name]
            ideal = None if bit is None else (pr.actuated if bit else pr.rest)
            ok = (bit is None or (pr.bit(L) == bit and abs(L - ideal) <= tol_length)) and \
                eq.max_joint_stretch <= tol_stretch
            rows.append({"state": state, "output": pr.output, "expected": bit, "measured": L,
                         "bit": pr.bit(L), "ideal": ideal,
                         "margin": None if bit is None else float(pr.margin(L, bit)),
                         "error": None if ideal is None else float(abs(L - ideal)),
                         "joint_stretch": eq.max_joint_stretch, "muscle_strain": eq.max_muscle_strain,
                         "ok": bool(ok)})
    return rows
