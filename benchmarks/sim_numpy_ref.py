"""A plain-numpy Euler-Maruyama integrator of the same physics as mlc.sim (the baseline
of benchmarks/sim_throughput.py).  Bonds and muscles (flat-bottom harmonic between
body sites), WCA between body centres (pairs from scipy's cKDTree, bonded pairs
excluded), translation noise, torque-driven rotation by the exponential map."""
from __future__ import annotations

import mlc  # noqa: F401 -- before numpy: pins OpenBLAS's kernels (mlc/__init__.py)
import numpy as np
from scipy.spatial import cKDTree


class NumpyEuler:
    def __init__(self, sim):
        """Take the packed arrays of an ``mlc.sim.integrator.Simulation``."""
        self.s = sim
        self.pos = sim.pos.copy()
        self.quat = sim.quat.copy()
        self.rng = np.random.default_rng(sim.opt.seed)
        sb = sim.site_body
        bi, bj = sb[sim.sp_i], sb[sim.sp_j]
        self.bi, self.bj = bi, bj
        self.excl = set(zip(bi.tolist(), bj.tolist())) | set(zip(bj.tolist(), bi.tolist()))
        self.excl_keys = np.array(sorted(i * len(sim.pos) + j for i, j in self.excl), dtype=np.int64)

    @staticmethod
    def rotmats(q):
        w, x, y, z = q.T
        return np.stack([
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
            np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
            np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1)], 1)

    def forces(self, t):
        s = self.s
        N = len(self.pos)
        R = self.rotmats(self.quat)
        arm = np.einsum("sij,sj->si", R[s.site_body], s.site_local)
        ws = self.pos[s.site_body] + arm
        d = ws[s.sp_j] - ws[s.sp_i]
        dist = np.linalg.norm(d, axis=1)
        u = np.zeros(len(s.dkind))
        from mlc.sim.kernels import drive_values
        drive_values(t, s.dkind, s.dpar, s.tab_t, s.tab_v, u)
        uu = np.concatenate([u, [0.0]])            # index -1 (plain bonds) reads 0
        rest = s.sp_rest0 + uu[s.sp_inp] * (s.sp_rest1 - s.sp_rest0)
        dev = dist - rest
        e = np.maximum(np.abs(dev) - s.sp_tol, 0.0)
        c = np.where(dist > 0, s.sp_k * e * np.sign(dev) / np.where(dist > 0, dist, 1.0), 0.0)
        zero = (rest == 0) & (s.sp_tol == 0)
        c = np.where(zero, s.sp_k, c)
        f = c[:, None] * d                         # on the i end
        F = np.zeros((N, 3))
        T = np.zeros((N, 3))
        np.add.at(F, self.bi, f)
        np.add.at(F, self.bj, -f)
        np.add.at(T, self.bi, np.cross(arm[s.sp_i], f))
        np.add.at(T, self.bj, np.cross(arm[s.sp_j], -f))
        eps, sw, rc = s._wca()
        if eps > 0:
            pairs = cKDTree(self.pos).query_pairs(rc, output_type="ndarray")
            if len(pairs):
                keys = pairs[:, 0] * N + pairs[:, 1]
                keep = ~np.isin(keys, self.excl_keys)
                pairs = pairs[keep]
                dd = self.pos[pairs[:, 0]] - self.pos[pairs[:, 1]]
                r2 = np.sum(dd * dd, axis=1)
                ir6 = (sw * sw / r2) ** 3
                cc = 24 * eps * (2 * ir6 * ir6 - ir6) / r2
                np.add.at(F, pairs[:, 0], cc[:, None] * dd)
                np.add.at(F, pairs[:, 1], -cc[:, None] * dd)
        return F, T

    def step(self, n, dt, kT, t0=0.0):
        s = self.s
        amp = np.sqrt(2 * kT * dt / s.gamma)
        for k in range(n):
            F, T = self.forces(t0 + k * dt)
            self.pos += dt * F / s.gamma + amp * self.rng.standard_normal(self.pos.shape)
            w = dt * T / s.gamma_r
            th = np.linalg.norm(w, axis=1)
            safe = np.where(th > 0, th, 1.0)
            a = np.concatenate([np.cos(th / 2)[:, None], (np.sin(th / 2) / safe)[:, None] * w], 1)
            q = self.quat
            q = np.stack([a[:, 0] * q[:, 0] - np.sum(a[:, 1:] * q[:, 1:], 1),
                          *(a[:, 0:1] * q[:, 1:] + q[:, 0:1] * a[:, 1:] + np.cross(a[:, 1:], q[:, 1:])).T], 1)
            self.quat = q / np.linalg.norm(q, axis=1)[:, None]
