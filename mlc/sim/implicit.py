"""The linearly implicit scheme (``SimOptions(scheme="implicit")``): one sparse solve per step.

Units as in :mod:`mlc.sim.kernels`: sigma, k0, gamma, time in gamma/k0 (1e-3 t0).

A body's coordinates are its centre ``r`` and a rotation vector ``w`` about world axes
(``R <- exp(w) R``, the static solver's chart).  With ``f = (F, T)`` the forces and torques
(the compiled ``eval`` kernel's), ``D = diag(gamma, gamma_r)`` the drag and ``H+`` the
positive part of the Hessian of the energy (below), a step of size ``h`` is

    (D/h + H+) dx = f(x_n, t_n) + b,        x_{n+1} = x_n (+) dx

a linearly implicit Euler step.  For a harmonic energy ``E = x^T H x / 2`` with ``H = H+``
its drift part is ``x_{n+1} = (D/h + H)^-1 (D/h) x_n``: every mode decays, the stiffest at
once (L-stable), so the step is not bounded by the stiffest spring as the explicit schemes
are (Euler: h < 2 gamma/lambda_max; SK-ROCK: stages growing as sqrt(h lambda_max)).  The
noise ``b`` has covariance ``2 kT (D/h + H+/2)``:

    b = sqrt(2 kT) D^1/2 h^-1/2 xi_1 + sqrt(kT) G^T xi_2,       G^T G = H+,

so that the stationary covariance of a harmonic scene is kT H^-1, exactly, at any h (a
short calculation: ``A V A = (D/h) V (D/h) + C`` with ``A = D/h + H``, ``V = kT H^-1`` gives
``C = kT (2 D/h + H)``); ``xi_1`` is the Brownian increment that the stiff scheme uses (the
same path for the same seed), ``xi_2`` fresh normals, one per row of ``G``.

Without rotational noise (the default, the paper's model: a body turns only as the bonds at
its sites turn it) the continuous dynamics' stationary state is not Boltzmann's: a mode whose
mobility is part rotational gets noise only through its translational part.  For one row ``g``
of ``G`` taken as a mode of its own (a bond at arms ``a``: ``g = (u, a x u)`` on each body) the
continuous variance is ``f kT/k``, ``f = g_t^T D_t^-1 g_t / g^T D^-1 g`` its share of
translational mobility, and the same calculation asks for ``C = H V H = f kT g g^T`` on top of
the translational Brownian term.  So each row's fresh normal is scaled by ``sqrt(f)``:

    b = sqrt(2 kT) D_t^1/2 h^-1/2 xi_1 + sqrt(kT) G^T (f^1/2 * xi_2),

exact for a row that is a mode by itself (a bond between centres, f = 1, gets kT/k; one at
arms of 0.5 sigma, f = 0.8, gets 0.8 kT/k, as Euler at a small step does:
``tests/test_sim_implicit.py``), an approximation where rows couple.  Its covariance is
below ``kT H+``, the rotational-noise case's, so it does not shake the soft modes.  Without
it (before session 49) a mode's variance was kT/lambda / (1 + h lambda/2): the locked joints
of the per-lever Tetris robot fluctuated 3-5 times less than with Euler (in std; docs/robot.md
3.4, "Session 49").  Keeping the correction for the translations alone, ``G``'s translational
columns, is wrong: they have a component of order sqrt(k) along the soft modes (the body
turning about the bonded site), which such a term shakes with a force sqrt(kT k) per step
(tried in session 48: the per-lever Tetris robot's stops were torn open within 170 t0).

``H+`` is built as ``G^T G`` from rows of ``G`` (one sparse row per row):

* a zero-length bond: ``sqrt(k)`` times each axis, on its two sites (``k I``: exact);
* a bond with a rest length or tolerance, or a muscle, outside its tolerance: ``sqrt(k) u``
  along the bond and, when it is stretched (tension), ``sqrt(k e / d)`` times two directions
  across it (the tension's transverse stiffness; a compressed bond's is negative, left out);
* each body's rotational geometric stiffness ``sum_s [ (g a^T + a g^T)/2 - (g.a) I ]`` over its
  sites (arm ``a``, energy gradient ``g`` at the site), its negative eigenvalues left out;
* a WCA contact: ``sqrt(U'')`` along the centres' line (the transverse part is negative).

A site row ``r`` acts on a body as ``(r, a x r)`` (``dp = dr + dw x a``).  What is left out
of ``H+`` is negative semidefinite and taken explicitly: for a step with ``H = H+ - H-``,
the iteration ``(D/h + H+)^-1 (D/h + H-)`` has every eigenvalue in (-1, 1) wherever ``H`` is
positive definite, whatever h (a symmetric-definite pencil: the eigenvalue along a
generalised eigenvector v is (1 + h v.H-v) / (1 + h v.H+v) in D-units).

Accuracy is first order (Euler's): a step slows a mode by 1/(1 + h lambda), so motions made
of modes about as fast as the step arrive late (docs/simulation.md).  The step is split
(levels as the stiff scheme's: h/2, h/4, ... on the same Brownian path) while a body's drift
(the part of ``dx`` from ``f``) exceeds ``disp_acc`` or ``rot_acc`` plus 3 times a free body's
noise in the substep (the stiff scheme's allowance), or the end state has a bond beyond
``accept`` of its stability bound or centres inside ``wca_min``; it goes back up a level where
the grid allows.  The drift test does not look at this step's noise, so it does not condition
on it.
Cost per (sub)step: one force evaluation and one factorisation of ``D/h + H+``, assembled
straight into 6x6 blocks, one per body, and factorised by a block Cholesky whose pattern (a
minimum-degree order of the bond graph) is computed once per scene (:mod:`mlc.sim.blockchol`;
a WCA contact between bodies it does not join adds the pair).  ``rows()`` (the sparse ``G``)
with a SuperLU factorisation in symmetric mode (:func:`mlc.verify.static.spd_lu`) is the
reference, and what a matrix the block factor finds not positive definite falls back to
(``Implicit.backend = "superlu"`` takes it always): the same rows in the same order, so the
same normals and, to rounding, the same trajectory (``tests/test_sim_blockchol.py``).
"""
from __future__ import annotations

import math

import numpy as np
import scipy.sparse as sp
from numba import njit

from mlc.sim import kernels as K

NOISE_SEED_MIX = 0x6A09E667F3BCC909      # xi_2's counters: the seed mixed with this (not the Brownian path's)


@njit(cache=True)
def brownian_increments(seed, step, k, lev, N, rot, out, a, b, z):
    """Increments of the stiff scheme's Brownian path (:func:`kernels.brownian_at`) over
    substep k of level lev of macro step ``step``, every body: out (N, 6), variance 2^-lev."""
    for i in range(N):
        K.brownian_at(seed, step, k, lev, i, rot, a, z)
        K.brownian_at(seed, step, k + 1, lev, i, rot, b, z)
        for c in range(6):
            out[i, c] = b[c] - a[c]


@njit(cache=True)
def normals(seed, key, n, out):
    """n standard normals for counter (seed, key) into out[:n]."""
    for i in range((n + 1) // 2):
        x, y = K.gauss2(seed, key, i)
        out[2 * i] = x
        if 2 * i + 1 < n:
            out[2 * i + 1] = y


class Implicit:
    """The state that the linearly implicit steps of one :class:`Simulation` share."""

    def __init__(self, sim):
        self.sim = sim
        N = sim.N
        self.N = N
        self.sb = sim.site_body
        zero = (sim.sp_rest0 == 0) & (sim.sp_rest1 == 0) & (sim.sp_tol == 0)     # zero-length bonds
        self.iz = np.nonzero(zero)[0]
        self.isc = np.nonzero(~zero)[0]
        self.D = np.empty(6 * N)
        self.D.reshape(N, 6)[:, :3] = sim.gamma
        self.D.reshape(N, 6)[:, 3:] = sim.gamma_r
        self.inv_D = 1.0 / self.D
        self.inv_Dt = self.inv_D.copy()          # translational mobilities only
        self.inv_Dt.reshape(N, 6)[:, 3:] = 0.0
        self.incr = np.zeros((N, 6))
        self._a = np.zeros(6)
        self._b = np.zeros(6)
        self._z = np.zeros(6)
        self._pat = None                 # the block pattern (mlc.sim.blockchol.symbolic), made at the first step
        self._extra = set()              # body pairs the pattern joins for WCA contacts (it only grows)
        self._diag = None

    # -- the positive part of the Hessian, as rows of G -------------------------------------
    def rows(self):
        """G (CSR, rows x 6N) at the state of the simulation's last ``_eval``."""
        s = self.sim
        ws, arm, sb = s.ws, s.arm, self.sb
        R, C, V = [], [], []
        nrow = 0

        def put(r_site, site_i, site_j, row0):
            """rows r_site (E, 3) acting on sites i (+) and j (-), numbered from row0."""
            E = len(r_site)
            rows = row0 + np.arange(E)
            for site, sign in ((site_i, 1.0), (site_j, -1.0)):
                body = sb[site]
                vals = np.concatenate([r_site, np.cross(arm[site], r_site)], axis=1) * sign
                R.append(np.repeat(rows, 6))
                C.append((6 * body[:, None] + np.arange(6)[None, :]).ravel())
                V.append(vals.ravel())

        # zero-length bonds: sqrt(k) I
        iz = self.iz
        if len(iz):
            sk = np.sqrt(s.sp_k[iz])
            for c in range(3):
                r = np.zeros((len(iz), 3))
                r[:, c] = sk
                put(r, s.sp_i[iz], s.sp_j[iz], nrow)
                nrow += len(iz)
        # the others: along the bond, and across it under tension
        grad = np.zeros((len(ws), 3))              # dE/dp at every site
        if len(iz):
            d = ws[s.sp_i[iz]] - ws[s.sp_j[iz]]
            g = s.sp_k[iz, None] * d
            np.add.at(grad, s.sp_i[iz], g)
            np.add.at(grad, s.sp_j[iz], -g)
        isc = self.isc
        if len(isc):
            rest = s.sp_rest0[isc].copy()
            inp = s.sp_inp[isc]
            dr = inp >= 0
            rest[dr] += s.uval[inp[dr]] * (s.sp_rest1[isc][dr] - rest[dr])
            d = ws[s.sp_i[isc]] - ws[s.sp_j[isc]]
            n = np.linalg.norm(d, axis=1)
            dev = n - rest
            e = np.abs(dev) - s.sp_tol[isc]
            act = (e > 0) & (n > 1e-300)
            if np.any(act):
                a_ = isc[act]
                k = s.sp_k[a_]
                u = d[act] / n[act, None]
                sgn = np.sign(dev[act])
                g = (k * e[act] * sgn)[:, None] * u
                np.add.at(grad, s.sp_i[a_], g)
                np.add.at(grad, s.sp_j[a_], -g)
                put(np.sqrt(k)[:, None] * u, s.sp_i[a_], s.sp_j[a_], nrow)
                nrow += len(a_)
                c2 = k * e[act] * sgn / n[act]
                ten = c2 > 0
                if np.any(ten):
                    ut = u[ten]
                    # two unit vectors across u
                    helper = np.where(np.abs(ut[:, :1]) < 0.9, np.array([[1.0, 0, 0]]), np.array([[0, 1.0, 0]]))
                    t1 = np.cross(ut, helper)
                    t1 /= np.linalg.norm(t1, axis=1, keepdims=True)
                    t2 = np.cross(ut, t1)
                    sq = np.sqrt(c2[ten])[:, None]
                    for t in (t1, t2):
                        put(sq * t, s.sp_i[a_[ten]], s.sp_j[a_[ten]], nrow)
                        nrow += int(np.count_nonzero(ten))
        # rotational geometric stiffness per body
        lam, vec = self.rot_stiffness(grad)
        pos = lam > 1e-14 * max(1.0, float(np.abs(lam).max(initial=0.0)))
        if np.any(pos):
            bi, ci = np.nonzero(pos)
            vals = np.sqrt(lam[bi, ci])[:, None] * vec[bi, :, ci]
            rows = nrow + np.arange(len(bi))
            R.append(np.repeat(rows, 3))
            C.append((6 * bi[:, None] + 3 + np.arange(3)[None, :]).ravel())
            V.append(vals.ravel())
            nrow += len(bi)
        # WCA contacts (the neighbour list of the last evaluation)
        pi, pj, vals = self.contacts()
        if len(pi):
            rows = nrow + np.arange(len(pi))
            for body, sign in ((pi, 1.0), (pj, -1.0)):
                R.append(np.repeat(rows, 3))
                C.append((6 * body[:, None] + np.arange(3)[None, :]).ravel())
                V.append((sign * vals).ravel())
            nrow += len(rows)
        if R:
            R, C, V = np.concatenate(R), np.concatenate(C), np.concatenate(V)
        else:
            R = C = np.zeros(0, np.int64)
            V = np.zeros(0)
        return sp.csr_matrix((V, (R, C)), shape=(nrow, 6 * self.N))

    def contacts(self):
        """The WCA contacts' rows at the last evaluation (from its neighbour list): bodies pi < pj
        and ``sqrt(U'')`` times the unit vector from pj to pi, (n, 3), in the rows' order."""
        s = self.sim
        o = s.opt
        none = (np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros((0, 3)))
        if not (o.wca_eps > 0 and np.any(s.dmin < 2.0 * o.wca_r0)):
            return none
        eps, sg, rc = s._wca()
        ii = np.nonzero(s.dmin < rc)[0]
        pi, pj = [], []
        for b in ii:
            nb_ = s.nl[s.nl0[b]:s.nl0[b + 1]]
            pi.extend([b] * len(nb_))
            pj.extend(nb_.tolist())
        pi, pj = np.array(pi, np.int64), np.array(pj, np.int64)
        keep = pi < pj
        pi, pj = pi[keep], pj[keep]
        d = s.pos[pi] - s.pos[pj]
        r = np.linalg.norm(d, axis=1)
        near = r < rc
        if not np.any(near):
            return none
        pi, pj, d, r = pi[near], pj[near], d[near], r[near]
        u2 = 4.0 * eps * (156.0 * sg ** 12 / r ** 14 - 42.0 * sg ** 6 / r ** 8)
        ok = u2 > 0
        return pi[ok], pj[ok], np.sqrt(u2[ok])[:, None] * d[ok] / r[ok, None]

    def rot_stiffness(self, grad):
        """Each body's rotational geometric stiffness ``sum_s [(g a^T + a g^T)/2 - (g.a) I]`` over
        its sites (``grad`` dE/dp at every site, (S, 3)) as numpy's eigh gives it: (N, 3), (N, 3, 3)."""
        ga = np.einsum("si,sj->sij", grad, self.sim.arm)
        Qs = 0.5 * (ga + np.transpose(ga, (0, 2, 1))) - np.einsum("sii->s", ga)[:, None, None] * np.eye(3)[None]
        Q = np.zeros((self.N, 3, 3))
        np.add.at(Q, self.sb, Qs)
        return np.linalg.eigh(Q)

    # -- the step's linear system --------------------------------------------------------------
    backend = "block"       # "block": mlc.sim.blockchol; "superlu": rows() and SuperLU (the reference)

    def system(self, h, noisy, seed2, key, rot):
        """The step matrix ``D/h + H+`` at the state of the last ``_eval``, factorised, and this
        substep's row noise ``G^T (f^1/2 xi_2)`` (counter (seed2, key); without sqrt(kT)).  The
        block factor (:mod:`mlc.sim.blockchol`); if it finds the matrix not positive definite, or
        the backend is "superlu", then ``rows()`` and SuperLU, which
        draw the same normals for the same rows.  A WCA contact between bodies the pattern does not
        join adds the pair to it (a new symbolic factorisation, kept for the rest of the run)."""
        if self.backend == "block":
            out = self._block(h, noisy, seed2, key, rot)
            if out is not None:
                return out
        G = self.rows()
        return _LU(self, G, self.solve(G, h), seed2, key, rot)

    def _block(self, h, noisy, seed2, key, rot):
        from mlc.sim import blockchol as BC

        s = self.sim
        ci, cj, cv = self.contacts()
        if len(ci) and self._pat is not None and not self._pat.holds(ci, cj):
            self._pat = None             # a contact between bodies the pattern does not join
        if self._pat is None:
            # the contact's pairs, and every pair its bodies' neighbour lists hold (within the WCA
            # range plus the list's skin): contacts that come next are likely among them
            self._extra |= set(zip(ci.tolist(), cj.tolist()))
            for b in set(ci.tolist()) | set(cj.tolist()):
                for c in s.nl[s.nl0[b]:s.nl0[b + 1]].tolist():
                    self._extra.add((min(b, c), max(b, c)))
            ex = np.array(sorted(self._extra), np.int64).reshape(-1, 2)
            self._pat = BC.symbolic(self.N, self.sb[s.sp_i], self.sb[s.sp_j], ex[:, 0], ex[:, 1])
            self._blk = np.zeros((self._pat.nblk, 6, 6))
        if self._diag is None:
            self._diag = np.zeros((self.N, 6, 6))
            self._grad = np.zeros((len(self.sb), 3))
            self._bvec = np.zeros((self.N, 6))
            self._lam = np.zeros((self.N, 3))
            self._vec = np.zeros((self.N, 3, 3))
        P = self._pat
        nrow = BC.assemble_bonds(s.ws, s.arm, self.sb, s.sp_i, s.sp_j, s.sp_k, s.sp_rest0, s.sp_rest1, s.sp_tol,
                                 s.sp_inp, s.uval, self.iz, self.isc, P.bond_blk, P.bond_flip, P.pos, self.D / h,
                                 self._diag, self._blk, self._grad, bool(noisy), seed2, key, bool(rot),
                                 float(s.gamma), float(s.gamma_r), self._bvec)
        BC.rot_eig(self._grad, s.arm, self.sb, self.N, self._lam, self._vec)
        lam, vec = self._lam, self._vec
        thresh = 1e-14 * max(1.0, float(np.abs(lam).max(initial=0.0)))
        nrow += BC.assemble_rot(lam, vec, thresh, P.pos, self._diag, nrow, bool(noisy), seed2, key, bool(rot),
                                self._bvec)
        if len(ci):
            BC.assemble_contacts(ci, cj, cv, P.pair_blk(ci, cj), P.pos[ci] < P.pos[cj], P.pos, self._diag, self._blk,
                                 nrow, bool(noisy), seed2, key, self._bvec)
        if BC.factor(self._diag, self._blk, P.colptr, P.rowidx, P.upd_ptr, P.upd_tgt) >= 0:
            return None                  # not positive definite to working precision: SuperLU decides
        return _Block(self)

    # -- stepping ----------------------------------------------------------------------------
    def solve(self, G, h):
        """The factorised step matrix D/h + G^T G (SuperLU, symmetric mode)."""
        from mlc.verify.static import spd_lu

        A = (G.T @ G + sp.diags(self.D / h)).tocsc()
        return spd_lu(A)

    def advance(self, nsteps, dt, t_o, k_o, rec_every, rph, rec, frame_every, fph, fpos, fquat):
        """``nsteps`` macro steps of ``dt`` (internal units) from the simulation's state, step n
        at time t_o + (k_o + n) dt; records and frames as the compiled kernels do (before the
        step whose global index is due).  Returns the steps done; a failure leaves its code in
        the simulation's ``status`` (as the kernels do).  ``stages_out``: [0] force evaluations,
        [3] rejected substeps, [4] the substep size to go on with (as the stiff scheme's)."""
        s = self.sim
        o = s.opt
        N = self.N
        full = 1 << K.LMAX
        seed = np.uint64(int(o.seed) & 0xFFFFFFFFFFFFFFFF)
        seed2 = np.uint64((int(o.seed) ^ NOISE_SEED_MIX) & 0xFFFFFFFFFFFFFFFF)
        rot = bool(o.rot_noise)
        kT = float(o.kT)
        noisy = kT > 0
        amp = np.empty(6)
        amp[:3] = math.sqrt(2.0 * kT * dt / s.gamma)
        amp[3:] = math.sqrt(2.0 * kT * dt / s.gamma_r) if rot else 0.0
        lev_min = s._lev_min(dt)
        wca_min = float(o.wca_min)
        a = s.arrays
        nrec = nfr = 0
        for n in range(nsteps):
            t = t_o + (k_o + n) * dt
            step = s.step + n
            if not self._eval(t, step):
                return n
            nrec, nfr = K._record(n, t, rec_every, rph, rec, nrec, a.probe_i, a.probe_j, s.site_body, s.site_local,
                                  frame_every, fph, fpos, fquat, nfr, s.pos, s.quat)
            if K._failed(s.mon, wca_min, s.status, step):
                return n
            # the macro step starts at twice the last accepted substep (kept in stages_out[4], which
            # advance() saves and restores, so the trajectory does not depend on the chunking)
            h_last = s.stages_out[4]
            lev = min(max(int(round(math.log2(dt / h_last))), 0), K.LMAX) if h_last > 0 else lev_min
            lev = max(lev - 1, lev_min)
            u = 0
            fresh = True                  # F, T, arm, ws hold the state at the substep's start
            while u < full:
                hs = dt / (1 << lev)
                ts = t + u * (dt / full)
                if not fresh and not self._eval(ts, step):
                    return n
                k = u >> (K.LMAX - lev)
                key = np.uint64(step) * np.uint64(2147483648) + np.uint64((1 << lev) + k)
                system = self.system(hs, noisy, seed2, key, rot)
                dd = system.solve(np.concatenate([s.F, s.T], axis=1))
                dmax = float(np.sqrt(np.max(np.sum(dd[:, :3] ** 2, axis=1), initial=0.0)))
                amax = float(np.sqrt(np.max(np.sum(dd[:, 3:] ** 2, axis=1), initial=0.0)))
                # the drift bound plus 3 times a free body's noise in this substep, as the stiff scheme's:
                # a body the noise has moved against a bond drifts back by as much, and refining for that
                # would chase the noise (chain_scene(20) at kT = 1e-2: 411 s for 0.5 t0 without it)
                dlim = o.disp_acc + 3.0 * math.sqrt(3.0) * amp[0] * math.sqrt(1.0 / (1 << lev))
                alim = o.rot_acc + 3.0 * math.sqrt(3.0) * amp[3] * math.sqrt(1.0 / (1 << lev))
                if not (dmax <= dlim and amax <= alim) and lev < K.LMAX:
                    if not (np.isfinite(dmax) and np.isfinite(amax)):
                        s.status[0], s.status[1] = K.NONFINITE, step
                        return n
                    lev += 1
                    s.stages_out[3] += 1
                    continue
                dx = dd
                if noisy:
                    brownian_increments(seed, step, k, lev, N, rot, self.incr, self._a, self._b, self._z)
                    b = (self.D.reshape(N, 6) / hs) * amp[None, :] * self.incr
                    b += math.sqrt(kT) * system.noise()
                    dx = dd + system.solve(b)
                saved = (s.pos.copy(), s.quat.copy())
                _apply(s.pos, s.quat, dx)
                if not self._eval(ts + hs, step):
                    return n
                fresh = True
                bad = not (s.mon[0] <= o.accept and s.mon[2] >= wca_min)
                if bad and lev < K.LMAX:
                    s.pos[:], s.quat[:] = saved
                    fresh = False
                    lev += 1
                    s.stages_out[3] += 1
                    continue
                u += full >> lev
                if dmax < 0.5 * dlim and amax < 0.5 * alim and lev > lev_min and ((u >> (K.LMAX - lev)) & 1) == 0:
                    lev -= 1
                s.stages_out[4] = dt / (1 << lev)
                if bad and K._failed(s.mon, wca_min, s.status, step):
                    return n + 1
            s.stages_out[1] = 1
        return nsteps

    def _eval(self, t, step) -> bool:
        """Forces at (pos, quat, t) into the simulation's arrays; False (status OVERFLOW) when
        the neighbour list overflowed (the caller grows it and redoes the call)."""
        s = self.sim
        s._eval_once(t)
        s.stages_out[0] += 1
        if s.nlstate[2] > 0.0:
            s.status[0], s.status[1] = K.OVERFLOW, step
            return False
        return True


@njit(cache=True)
def _apply(pos, quat, dx):
    """Move each body by dx = (translation, rotation vector): r += t, q <- exp(w) q."""
    for b in range(pos.shape[0]):
        pos[b, 0] += dx[b, 0]
        pos[b, 1] += dx[b, 1]
        pos[b, 2] += dx[b, 2]
        q0, q1, q2, q3 = K.quat_exp_mul(dx[b, 3], dx[b, 4], dx[b, 5], quat[b, 0], quat[b, 1], quat[b, 2], quat[b, 3])
        quat[b, 0] = q0
        quat[b, 1] = q1
        quat[b, 2] = q2
        quat[b, 3] = q3


class _Block:
    """A factorised step matrix from :mod:`mlc.sim.blockchol` (valid until the next ``system``)."""

    def __init__(self, imp):
        self.imp = imp

    def solve(self, rhs):
        from mlc.sim import blockchol as BC

        i, P = self.imp, self.imp._pat
        out = np.empty((i.N, 6))
        BC.solve(i._diag, i._blk, P.colptr, P.rowidx, P.order, np.ascontiguousarray(rhs, dtype=np.float64), out)
        return out

    def noise(self):
        return self.imp._bvec


class _LU:
    """A step matrix factorised by SuperLU from the rows ``G`` (the reference path)."""

    def __init__(self, imp, G, lu, seed2, key, rot):
        self.imp, self.G, self.lu = imp, G, lu
        self.seed2, self.key, self.rot = seed2, key, rot

    def solve(self, rhs):
        return self.lu.solve(np.ascontiguousarray(rhs, dtype=np.float64).ravel()).reshape(self.imp.N, 6)

    def noise(self):
        G, imp = self.G, self.imp
        if not G.shape[0]:
            return np.zeros((imp.N, 6))
        x2 = np.zeros(G.shape[0])
        normals(self.seed2, self.key, G.shape[0], x2)
        if not self.rot:
            # each row's share of translational mobility (module doc: the noise of a row's mode is
            # translational only, so its exact variance is that share)
            G2 = G.multiply(G)
            x2 = x2 * np.sqrt((G2 @ imp.inv_Dt) / np.maximum(G2 @ imp.inv_D, 1e-300))
        return (G.T @ x2).reshape(imp.N, 6)
