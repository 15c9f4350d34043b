"""Overdamped rigid-body Brownian dynamics of a :class:`~mlc.scene.model.Scene`.

    dr/dt = F/gamma + sqrt(2 kT/gamma) eta(t),      dtheta/dt = tau/gamma_r (+ optional noise)

Users give times in t0 = gamma/(1e-3 k0) (paper units); kernels work in gamma/k0
(1 t0 = 1000 gamma/k0 with the defaults).  See docs/simulation.md.

Typical use::

    sim = Simulation(scene, {"a": Drive.constant(1)}, SimOptions(kT=1e-5, seed=1))
    res = sim.run(5.0)            # 5 t0
    res.probes["out"][-1]
"""
from __future__ import annotations

import math
import sys
import time as _time
from dataclasses import dataclass, field

import numpy as np

from mlc.errors import MlcError
from mlc.scene.model import Scene
from mlc.sim import kernels as K
from mlc.sim import check_kT
from mlc.sim.drive import Drive, pack_drives

SCHEMES = ("euler", "stiff", "implicit")


@dataclass
class SimOptions:
    """Integrator options (times in t0, lengths in sigma, energies in k0 sigma^2)."""

    dt: float | None = None          # None: a default from the stiffness estimate (see default_dt)
    scheme: str = "stiff"            # "euler" (Euler-Maruyama, the reference), "stiff" (SK-ROCK) or
                                     # "implicit" (linearly implicit, one sparse solve per step: mlc/sim/implicit.py)
    kT: float = 1e-5
    seed: int = 0
    gamma_r: float | None = None     # rotational drag; None = gamma (the paper)
    rot_noise: bool = False          # rotational noise sqrt(2 kT/gamma_r) (HOOMD-blue option)
    wca_eps: float = 1e-4            # k0 sigma^2
    wca_r0: float = 0.1              # sigma; U = 4 eps[(2r0/r)^12 - (2r0/r)^6] + eps for r < 2 r0
    threads: int = 1                 # >1: parallel kernels (prange) on that many numba threads ...
    parallel_min_bodies: int = 20000  # ... for scenes at least this large (below, thread start-up costs more)
    # stability monitor
    stretch_thermal: float = 15.0    # bond extension bound: c_T sqrt(kT/k) + c_0 ...
    stretch_joint: float = 0.15      # ... c_0 for bonds (sigma)
    stretch_muscle: float = 0.6      # ... c_0 for muscles (sigma)
    max_disp: float = 1.0            # per-step displacement bound (sigma)
    max_rot: float = 1.0             # per-step rotation bound (rad)
    wca_min: float = 0.1             # minimum WCA centre distance (sigma)
    # stiff scheme
    eta: float = 0.05                # SK-ROCK damping
    rho_safety: float = 1.2
    rho_every: int = 50
    stages: int = 0                  # fixed number of SK-ROCK stages (0 = from the spectral estimate)
    accept: float = 1.0              # split a stiff step whose end state has a bond beyond this fraction of its bound
    rot_acc: float = 0.3             # ... or a body turned by more than this (rad) in a substep
    disp_acc: float = 0.01           # ... or drifted more than this (sigma; < r0/2: no tunnelling through WCA)
    rot_var_max: float = 0.1         # with rot_noise: substeps no longer than this rotational noise variance (rad^2)
    fluct: bool = False              # stiff scheme, fluctuation mode: eta = 0 and post-processed records
                                     # (exact stationary variance of linear modes; see docs/simulation.md)
    fluct_stages: float = 0.0        # fluctuation mode with noise: s = ceil(m sqrt(h rho/2)) stages, m this
                                     # factor (0 = auto: the stage rule of Simulation.fluct_stages_target)
    fluct_levels: int = 4            # fluctuation mode with noise: each step's least substep level random in
                                     # [0, fluct_levels) (1 = off: every mode's h lambda fixed; see docs/simulation.md)
    max_steps: float = 1e9           # refuse runs of more steps than this


# default time steps (t0); see docs/simulation.md and benchmarks/results/sim_speed_error.json
EULER_DT_FRACTION = 0.5      # of the estimated Euler limit 2/rho
STIFF_DT_DEFAULT = 0.05      # t0: the largest step; transients are resolved by adaptive substeps


@dataclass
class SimResult:
    scheme: str
    dt: float                    # t0
    steps: int
    time: float                  # t0 reached
    wall: float                  # seconds
    times: np.ndarray            # (R,) t0
    probes: dict                 # name -> (R,) length (sigma)
    pos: np.ndarray              # final (N,3)
    quat: np.ndarray             # final (N,4)
    frame_times: np.ndarray = field(default_factory=lambda: np.zeros(0))
    frame_pos: np.ndarray = field(default_factory=lambda: np.zeros((0, 0, 3)))
    frame_quat: np.ndarray = field(default_factory=lambda: np.zeros((0, 0, 4)))
    force_evals: int = 0
    stages: int = 1
    interrupted: bool = False        # stopped by Ctrl-C: everything up to ``time`` is valid
    warnings: list = field(default_factory=list)
    variance_bias: dict = field(default_factory=dict)

    def final_probes(self) -> dict:
        return {k: float(v[-1]) for k, v in self.probes.items() if len(v)}


class Simulation:
    """A scene, its drives and the integrator state (positions, orientations, time, step)."""

    def __init__(self, scene: Scene, drives: dict | None = None, options: SimOptions | None = None,
                 pos=None, quat=None):
        self.scene = scene
        self.opt = o = options or SimOptions()
        if o.scheme not in SCHEMES:
            raise MlcError(f"unknown scheme {o.scheme!r}", "--scheme", "use euler, stiff or implicit")
        if o.fluct and o.scheme != "stiff":
            raise MlcError("the fluctuation mode is a variant of the stiff scheme", "--fluct",
                           "use --scheme stiff, or Euler well below its limit (see docs/simulation.md)")
        check_kT(o.kT)
        if not (math.isfinite(o.fluct_stages) and (o.fluct_stages == 0 or o.fluct_stages >= 1)):
            raise MlcError(f"the fluctuation mode's stage factor must be 0 (auto) or >= 1, got {o.fluct_stages}",
                           "fluct_stages", "fewer stages than the stable minimum would be unstable")
        if not (isinstance(o.fluct_levels, (int, np.integer)) and 1 <= o.fluct_levels <= 8):
            raise MlcError(f"the fluctuation mode's random substep levels must be an integer from 1 to 8, got "
                           f"{o.fluct_levels!r}", "fluct_levels", "use 4 (the default) or 1 (off)")
        u = scene.units
        self.gamma = float(u.get("gamma", 1.0))
        self.k0 = float(u.get("k0", 1.0))
        self.t_unit = self.gamma / (1e-3 * self.k0)        # internal time per t0
        self.gamma_r = float(o.gamma_r) if o.gamma_r is not None else self.gamma
        a = scene.arrays()
        self.arrays = a
        N = len(scene.bodies)
        self.N = N
        self.pos = np.ascontiguousarray(a.pos if pos is None else pos, dtype=np.float64).copy()
        self.quat = np.ascontiguousarray(a.quat if quat is None else quat, dtype=np.float64).copy()
        if self.pos.shape != (N, 3) or self.quat.shape != (N, 4):
            raise MlcError(f"initial poses must have shapes ({N},3) and ({N},4)", "pos/quat")
        if not (np.all(np.isfinite(self.pos)) and np.all(np.isfinite(self.quat))):
            raise MlcError("initial poses must be finite numbers", "pos/quat")
        nq = np.linalg.norm(self.quat, axis=1)
        if np.any(np.abs(nq - 1) > 1e-6):
            b = int(np.argmax(np.abs(nq - 1)))
            raise MlcError(f"body {scene.bodies[b].name}: orientation is not a unit quaternion (norm {nq[b]:.6g})",
                           "quat", "normalise it")
        self.t = 0.0          # internal units
        self.step = 0
        self._trial = False   # a trial run of _suggest_euler_dt: its failure is not reported in full
        # sites
        self.site_body = a.site_body.astype(np.int64)
        self.site_local = np.ascontiguousarray(a.site_local)
        counts = np.bincount(self.site_body, minlength=N) if len(self.site_body) else np.zeros(N, np.int64)
        self.bsite0 = np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)
        # springs = bonds + muscles
        nb, nm = len(a.bond_i), len(a.muscle_i)
        self.spring_names = [f"bond {b.name}" for b in scene.bonds] + [f"muscle {m.name}" for m in scene.muscles]
        self.sp_i = np.concatenate([a.bond_i, a.muscle_i]).astype(np.int64)
        self.sp_j = np.concatenate([a.bond_j, a.muscle_j]).astype(np.int64)
        self.sp_k = np.concatenate([a.bond_k, a.muscle_k]).astype(np.float64)
        self.sp_rest0 = np.concatenate([a.bond_rest, a.muscle_rest]).astype(np.float64)
        self.sp_rest1 = np.concatenate([a.bond_rest, a.muscle_act]).astype(np.float64)
        self.sp_tol = np.concatenate([a.bond_tol, np.zeros(nm)]).astype(np.float64)
        self.sp_inp = np.concatenate([-np.ones(nb, np.int64), a.muscle_input]).astype(np.int64)
        c0 = np.concatenate([np.full(nb, o.stretch_joint), np.full(nm, o.stretch_muscle)])
        self.sp_bound = (o.stretch_thermal * np.sqrt(o.kT / self.sp_k) + c0).astype(np.float64)
        if np.any(self.sp_bound <= 0):
            raise MlcError("stretch bounds must be positive", "stretch_joint/stretch_muscle")
        # per-body spring ends (CSR)
        sb = self.site_body
        ends_body = np.concatenate([sb[self.sp_i], sb[self.sp_j]])
        ends_sp = np.concatenate([np.arange(nb + nm), np.arange(nb + nm)])
        ends_sign = np.concatenate([np.ones(nb + nm), -np.ones(nb + nm)])
        order = np.argsort(ends_body, kind="stable")
        self.end_sp = ends_sp[order].astype(np.int64)
        self.end_sign = ends_sign[order].astype(np.float64)
        self.end0 = np.concatenate([[0], np.cumsum(np.bincount(ends_body, minlength=N))]).astype(np.int64)
        # WCA exclusions: bodies joined by a bond or a muscle
        pairs = set()
        for i, j in zip(sb[self.sp_i], sb[self.sp_j]):
            pairs.add((int(i), int(j)))
            pairs.add((int(j), int(i)))
        ex = [[] for _ in range(N)]
        for i, j in sorted(pairs):
            ex[i].append(j)
        self.ex0 = np.concatenate([[0], np.cumsum([len(x) for x in ex])]).astype(np.int64)
        self.ex_list = np.array([j for x in ex for j in x], dtype=np.int64)
        # drives
        self.drives = self._drives(drives or {})
        self.dkind, self.dpar, self.tab_t, self.tab_v = pack_drives(self.drives, self.t_unit)
        # cell list
        size = 16
        while size < 2 * N:
            size *= 2
        self.head = np.full(size, -1, np.int64)
        self.nxt = np.zeros(N, np.int64)
        self.cell = np.zeros((N, 3), np.int64)
        # Verlet neighbour list for WCA (radius 1.5 rc, rebuilt when a body moved 0.25 rc)
        self.nl0 = np.zeros(N + 1, np.int64)
        self.nl = np.zeros(8 * N + 64, np.int64)
        self.pos_nl = np.zeros((N, 3))
        self.nlstate = np.zeros(4)
        # scratch
        S, B = len(self.site_body), nb + nm
        self.uval = np.zeros(len(self.drives))
        self.ws = np.zeros((S, 3))
        self.arm = np.zeros((S, 3))
        self.fsp = np.zeros((B, 3))
        self.ratio = np.zeros(B)
        self.dmin = np.zeros(N)
        self.dpart = np.zeros(N, np.int64)
        self.F = np.zeros((N, 3))
        self.T = np.zeros((N, 3))
        self.disp = np.zeros(N)
        self.mon = np.zeros(6)
        self.status = np.zeros(4, np.int64)
        self.stages_out = np.zeros(8)
        self.pv = np.random.default_rng(12345).standard_normal((N, 6))
        self.pw = np.zeros((N, 6))
        self.sp_tmp = np.zeros((B, 3))
        self.K0, self.K1, self.K2, self.Qn = (np.zeros((N, 6)) for _ in range(4))
        self.qn = np.zeros((N, 4))
        self.xs = np.zeros((N, 3))
        self.qs = np.zeros((N, 4))
        self.Bc, self.Bn, self.zb = (np.zeros((N, 6)) for _ in range(3))
        self.ppos = np.zeros((N, 3))
        self.pquat = np.zeros((N, 4))
        self._pos0, self._quat0 = self.pos.copy(), self.quat.copy()
        self._drive_arg = dict(drives or {})
        self.arm_max = float(np.max(np.linalg.norm(self.site_local, axis=1))) if S else 0.0
        threads = o.threads
        import numba
        if threads is None:
            threads = numba.config.NUMBA_NUM_THREADS
        self.threads = max(1, min(int(threads), numba.config.NUMBA_NUM_THREADS))
        self.parallel = self.threads > 1 and N >= o.parallel_min_bodies
        self._k = K.kernels(self.parallel)
        if self.parallel:
            numba.set_num_threads(self.threads)
        self._rho = None
        self.dt = self._choose_dt(o.dt)
        self._imp = None
        if o.scheme == "implicit":
            from mlc.sim.implicit import Implicit
            self._imp = Implicit(self)

    # -- set-up helpers -----------------------------------------------------------------
    def _drives(self, drives: dict) -> list[Drive]:
        out = []
        unknown = set(drives) - set(self.scene.inputs)
        if unknown:
            raise MlcError(f"no input named {sorted(unknown)[0]!r} in scene {self.scene.name}", "--set",
                           f"inputs are {', '.join(self.scene.inputs) or 'none'}")
        for name in self.scene.inputs:
            d = drives.get(name, Drive.constant(0.0))
            if isinstance(d, (int, float)):
                d = Drive.constant(d)
            out.append(d)
        return out

    def rho(self) -> float:
        """Largest eigenvalue estimate of the mobility-weighted stiffness (internal 1/time)."""
        if self._rho is None:
            self._eval()
            v = self.pv.copy()
            lam = self._k["spectral"](self.site_body, self.arm, self.sp_i, self.sp_j, self.sp_k, self.end0,
                                      self.end_sp, self.end_sign, self.sp_tmp, 1.0 / self.gamma,
                                      1.0 / self.gamma_r, v, self.pw, 60)
            self._rho = max(lam, 0.0) + 2.0 * self.mon[5] / self.gamma
        return self._rho

    def euler_limit(self) -> float:
        """Estimated largest stable Euler dt (t0): 2/rho."""
        r = self.rho()
        return math.inf if r <= 0 else 2.0 / r / self.t_unit

    def _choose_dt(self, dt):
        if dt is None:
            if self.opt.scheme == "euler":
                lim = self.euler_limit()
                dt = EULER_DT_FRACTION * lim if math.isfinite(lim) else STIFF_DT_DEFAULT
                dt = float(f"{dt:.1g}") if dt > 0 else dt
            else:
                dt = STIFF_DT_DEFAULT
            lim_r = self._euler_rot_limit()
            if dt > lim_r:
                dt = _floor1(lim_r)
        if not (math.isfinite(dt) and dt > 0):
            raise MlcError(f"dt must be a positive number of t0, got {dt}", "--dt")
        lim_r = self._euler_rot_limit()
        if dt > lim_r:
            raise MlcError(f"dt = {dt:g} t0 is too large for Euler with rotational noise at kT = {self.opt.kT:g}: "
                           f"its rotational noise variance per step 2 kT dt/gamma_r would exceed "
                           f"{self.opt.rot_var_max:g} rad^2 (the exponential map then biases D_r by more than 1 %)",
                           "--dt", f"use --dt {_floor1(lim_r):g} or less, or the stiff scheme (it substeps)")
        return float(dt)

    def _euler_rot_limit(self) -> float:
        """Largest Euler dt (t0) with rotational noise: one step's rotational noise variance
        2 kT h/gamma_r at most ``rot_var_max`` (rad^2).  The exponential map of a Gaussian
        rotation vector of per-axis variance s^2 turns a body axis by <u(h).u(0)> =
        1/3 + (2/3)(1 - s^2) exp(-s^2/2), against the exact exp(-s^2): D_r is overestimated
        by ~s^2/12 (+0.85 % at s^2 = 0.1, +10 % at s^2 = 1; tests/test_sim_stats.py).  No
        limit without rotational noise, at kT = 0, or for the stiff scheme (which substeps)."""
        o = self.opt
        if not (o.scheme == "euler" and o.rot_noise and o.kT > 0):
            return math.inf
        return o.rot_var_max * self.gamma_r / (2.0 * o.kT) / self.t_unit

    def _grow_nlist(self):
        """Enlarge the neighbour list after an overflow (the kernels stopped; the caller redoes the work)."""
        if self.nlstate[2] > 0:
            self.nl = np.zeros(int(2 * self.nlstate[3]) + 64, np.int64)
            self.nlstate[0] = 0.0
            self.nlstate[2] = 0.0

    def _eval(self):
        """Forces, torques, site positions and monitors at the current state (grows the
        neighbour list and re-evaluates when it overflowed)."""
        self._eval_once()
        while self.nlstate[2] > 0:
            self._grow_nlist()
            self._eval_once()

    def _eval_once(self, t: float | None = None):
        """One evaluation at (pos, quat) and time ``t`` (internal units; default the simulation's)."""
        eps, s, rc = self._wca()
        self._k["eval"](self.pos, self.quat, float(self.t if t is None else t), self.site_body, self.site_local, self.bsite0, self.sp_i,
                        self.sp_j, self.sp_k, self.sp_rest0, self.sp_rest1, self.sp_tol, self.sp_inp, self.sp_bound,
                        self.end0, self.end_sp, self.end_sign, self.dkind, self.dpar, self.tab_t, self.tab_v,
                        eps, s, rc, self.ex0, self.ex_list, self.head, self.nxt, self.cell, self.nl0, self.nl,
                        self.pos_nl, self.nlstate, self.uval, self.ws,
                        self.arm, self.fsp, self.ratio, self.dmin, self.dpart, self.F, self.T, self.mon)

    def _wca(self):
        o = self.opt
        return float(o.wca_eps), 2.0 * o.wca_r0, 2.0 * o.wca_r0

    def probe_lengths(self) -> dict:
        self._eval()
        a = self.arrays
        return {p.name: float(np.linalg.norm(self.ws[a.probe_j[k]] - self.ws[a.probe_i[k]]))
                for k, p in enumerate(self.scene.probes)}

    # -- running --------------------------------------------------------------------------
    def _lev_min(self, dt_int: float) -> int:
        """Smallest substep level of the stiff scheme: with rotational noise, substeps whose
        rotational noise variance 2 kT h / gamma_r stays below ``rot_var_max`` (the exponential
        map of a Gaussian rotation vector is accurate to ~0.08 sigma^2 in D_r); set before any
        noise is drawn, so it does not condition on the noise."""
        o = self.opt
        if not (o.rot_noise and o.kT > 0 and o.scheme in ("stiff", "implicit")):
            return 0
        var = 2.0 * o.kT * dt_int / self.gamma_r
        lev = max(0, math.ceil(math.log2(var / o.rot_var_max))) if var > o.rot_var_max else 0
        if lev > K.LMAX - 4:
            lim = o.rot_var_max * self.gamma_r / (2.0 * o.kT) * 2.0 ** (K.LMAX - 4) / self.t_unit
            raise MlcError(f"dt = {dt_int / self.t_unit:g} t0 is too large for rotational noise at kT = {o.kT:g}",
                           "--dt", f"use --dt {float(f'{lim:.1g}'):g} or less")
        return lev

    def advance(self, nsteps: int, rec_every: int = 0, frame_every: int = 0, rec_phase: int = 0,
                frame_phase: int = 0, dt: float | None = None, origin: tuple | None = None):
        """Run ``nsteps`` steps of ``dt`` t0 (default the simulation's) in one compiled call,
        recording probes at steps whose global index (``rec_phase`` + local) is a multiple of
        ``rec_every`` and frames likewise; returns (records, frames_pos, frames_quat, done).
        Step n of the call is at time t_o + (k_o + n) dt, with ``origin`` = (t_o internal
        time, k_o steps) (default: the simulation's time, 0), so that a run cut into calls
        has the same step times, bit for bit, however it is cut.
        A neighbour-list overflow grows the list and redoes the call from its start."""
        o = self.opt
        P = len(self.scene.probes)
        nrec = nsteps // rec_every + 1 if rec_every > 0 else 0
        nfr = nsteps // frame_every + 1 if frame_every > 0 else 0
        rec = np.zeros((nrec, 1 + P))
        fpos = np.zeros((nfr, self.N, 3))
        fquat = np.zeros((nfr, self.N, 4))
        eps, s, rc = self._wca()
        dt = (self.dt if dt is None else dt) * self.t_unit
        rph = rec_phase % rec_every if rec_every > 0 else 0       # global index = phase + local index
        fph = frame_phase % frame_every if frame_every > 0 else 0
        saved = (self.pos.copy(), self.quat.copy(), self.stages_out.copy(), self.pv.copy())
        a = self.arrays
        while True:
            self.status[:] = 0
            self._grow_nlist()
            t_o, k_o = origin if origin is not None else (self.t, 0)
            common = (self.pos, self.quat, float(t_o), int(k_o), int(self.step), int(nsteps), float(dt), float(o.kT),
                      float(self.gamma), float(self.gamma_r), bool(o.rot_noise),
                      np.uint64(int(o.seed) & 0xFFFFFFFFFFFFFFFF),
                      self.site_body, self.site_local, self.bsite0, self.sp_i, self.sp_j, self.sp_k, self.sp_rest0,
                      self.sp_rest1, self.sp_tol, self.sp_inp, self.sp_bound, self.end0, self.end_sp, self.end_sign,
                      self.dkind, self.dpar, self.tab_t, self.tab_v, eps, s, rc, float(o.wca_min), self.ex0,
                      self.ex_list, self.head, self.nxt, self.cell, self.nl0, self.nl, self.pos_nl, self.nlstate,
                      float(o.max_disp), float(o.max_rot), a.probe_i, a.probe_j,
                      int(rec_every), int(rph), rec, int(frame_every), int(fph), fpos, fquat, self.uval, self.ws,
                      self.arm, self.fsp, self.ratio, self.dmin, self.dpart, self.F, self.T, self.disp, self.mon,
                      self.status)
            try:
                if o.scheme == "euler":
                    done = self._k["euler"](*common)
                    self.stages_out[0] += done
                    self.stages_out[1] = 1
                elif o.scheme == "implicit":
                    done = self._imp.advance(int(nsteps), float(dt), float(t_o), int(k_o), int(rec_every), int(rph),
                                             rec, int(frame_every), int(fph), fpos, fquat)
                else:
                    eta = 0.0 if o.fluct else float(o.eta)
                    m = self.fluct_stage_factor(dt / self.t_unit)
                    done = self._k["skrock"](*common, eta, float(o.rho_safety) * m * m, int(o.rho_every), 60,
                                             self.pv, self.pw, self.sp_tmp, int(o.stages), self.stages_out, self.K0,
                                             self.K1, self.K2, self.Qn, self.qn, self.xs, self.qs, float(o.accept),
                                             float(o.rot_acc), float(o.disp_acc), self.arm_max, self.Bc, self.Bn,
                                             self.zb, self.ppos, self.pquat, bool(o.fluct), self._lev_min(dt),
                                             self.fluct_level_span(dt / self.t_unit))
            except (ZeroDivisionError, OverflowError, FloatingPointError) as e:
                # a stage inside a step ran to non-finite numbers before the step's checks could
                # reject it (seen: NAND contracting at kT = 1, seed 2, the stiff scheme's default dt)
                t0, t1 = self.t / self.t_unit, (self.t + nsteps * dt) / self.t_unit
                raise MlcError(f"unstable between t = {t0:.6g} and {t1:.6g} t0: the forces or positions became "
                               f"non-finite inside a step ({type(e).__name__} in the compiled kernel); at "
                               f"kT = {o.kT:g} the scene may be coming apart", "--dt",
                               "use a smaller --dt or a lower --kT") from None
            if self.status[0] != K.OVERFLOW:
                break
            # the neighbour list outgrew its buffer: grow it and redo the call from its start
            self.pos[:], self.quat[:], self.stages_out[:], self.pv[:] = saved
            rec[:] = 0.0
        self.step += done
        t_o, k_o = origin if origin is not None else (self.t, 0)
        self.t = t_o + (k_o + done) * dt
        if self.status[0] != K.OK:
            self._fail(dt / self.t_unit)
        nr, nf = _count(done, rec_every, rph), _count(done, frame_every, fph)
        return rec[:nr], fpos[:nf], fquat[:nf], done

    def fluct_stage_factor(self, dt: float | None = None) -> float:
        """Stage factor m of the fluctuation mode at step ``dt`` (t0; default the run's): the
        kernel takes s = ceil(m sqrt(h rho/2)) SK-ROCK stages (rho with its safety factor)
        instead of the fewest stable ones (m = 1; the plain stiff scheme and runs without noise
        always use m = 1).  With ``fluct_stages`` > 0, that factor.  Auto (0): m is set so that
        s = :meth:`fluct_stages_target` (see there)."""
        o = self.opt
        if not (o.fluct and o.kT > 0):
            return 1.0
        if o.fluct_stages > 0:
            return float(o.fluct_stages)
        return self.fluct_stages_target(dt)[0]

    def fluct_level_span(self, dt: float | None = None) -> int:
        """How many random least substep levels the fluctuation mode draws each step from at
        step ``dt`` (t0; default the run's): ``fluct_levels`` when a full step takes more than
        ``FLUCT_LEVELS_MIN_STAGES`` stages (:meth:`fluct_stages_target`), else 1 (full-size
        steps), and 1 without noise.  Measured (benchmarks/sim_fluct_bias.py,
        benchmarks/sim_fluct_modes.py): at 4 stages (dt = 0.01 t0 for k0 bonds), where the
        deeper levels fall to 2 and 3 stages, random levels gave the bonded pair 1.150 of exact
        at kT = 1e-2 (full-size steps 1.007)."""
        o = self.opt
        if not (o.fluct and o.kT > 0) or o.fluct_levels <= 1:
            return 1
        h = (self.dt if dt is None else dt) * self.t_unit
        q = math.sqrt(h * self.rho() * float(o.rho_safety) / 2.0)
        if not (q > 0 and math.isfinite(q)):
            return 1
        s0 = max(2, math.ceil(self.fluct_stage_factor(dt) * q))
        return int(o.fluct_levels) if s0 > FLUCT_LEVELS_MIN_STAGES else 1

    def fluct_stages_target(self, dt: float | None = None) -> tuple[float, int, float]:
        """The fluctuation mode's stage rule at step ``dt`` (t0): (m, s, R) with s the stages of a
        full step, m the factor that gives them, R = T_s(1 - h rho/s^2) the one-step factor of
        the stiffest mode (rate rho = :meth:`rho`, the estimate at the run's start, without the
        safety factor).  With eta = 0 and the post-processor every linear mode is exact for any
        s; the rule is about the nonlinearity (measured on bonded pairs, k = 1 k0, rest 1 sigma:
        benchmarks/sim_fluct_model.py, benchmarks/sim_fluct_bias.py, docs/simulation.md):
        a mode with R near -1 (an interior Chebyshev extremum) neither relaxes nor damps the
        noise the nonlinearity injects (+40 % at kT = 1e-3 k0 sigma^2, dt = 0.2 t0, R = -0.99)
        and one with R near +1 decorrelates over many steps.  Rule: base factor m0 =
        ``FLUCT_M_HI`` (3) when one step's noise variance per axis 2 kT h/gamma exceeds
        ``FLUCT_NOISE_HI`` (1.5e-3 sigma^2: a 1 sigma bond turns by ~0.05 rad a step), else 1;
        s0 = ceil(m0 sqrt(h rho 1.2/2)); s = the smallest s in [s0, 1.5 s0] with R in
        ``FLUCT_R_WINDOW`` ([-0.5, 0.5]), else the one there nearest that window.  This places
        the estimated stiffest mode of a full-size step; the scene's other modes are kept off
        the extrema by the random substep levels (``SimOptions.fluct_levels``; the kernel takes
        s stages at level 0 and m sqrt(h rho/2) rounded up at the deeper levels)."""
        o = self.opt
        h = (self.dt if dt is None else dt) * self.t_unit
        m0 = FLUCT_M_HI if 2.0 * o.kT * h / self.gamma > FLUCT_NOISE_HI else 1.0
        rho = self.rho()
        q = math.sqrt(h * rho * float(o.rho_safety) / 2.0)
        if not (q > 0 and math.isfinite(q)):
            return m0, 2, 1.0
        s0 = max(2, math.ceil(m0 * q))
        lo, hi = FLUCT_R_WINDOW
        cand = range(s0, math.ceil(FLUCT_SPAN * s0) + 1)
        s = next((k for k in cand if lo <= _cheb_factor(h * rho, k) <= hi), None)
        if s is None:
            s = min(cand, key=lambda k: max(lo - _cheb_factor(h * rho, k), _cheb_factor(h * rho, k) - hi))
        # the kernel rounds m q up: aim at the middle of (s - 1, s]
        m = m0 if s == s0 else (s - 0.5) / q
        return m, s, _cheb_factor(h * rho, s)

    # -- failures -------------------------------------------------------------------------
    def _check_initial(self):
        """The initial state's monitors (a bond beyond its bound, overlapping WCA centres):
        reported at t = 0, whatever the time step."""
        self._eval()
        self.status[:] = 0
        if K._failed(self.mon, float(self.opt.wca_min), self.status, 0):
            self._fail(initial=True)

    def _suggest_euler_dt(self, t_fail: float, dt_failed: float):
        """A dt for Euler computed from the scene at rest (its initial state, drives at t = 0),
        checked by running it from that state past the failure time (at most 2e5 steps);
        returns (dt or None, checked, Euler limit at rest in t0)."""
        o = self.opt
        trial_opt = SimOptions(**{**o.__dict__, "dt": None, "scheme": "euler"})
        try:
            rest = Simulation(self.scene, self._drive_arg, trial_opt, pos=self._pos0, quat=self._quat0)
            lim = rest.euler_limit()
        except MlcError:
            return None, False, math.nan
        if not math.isfinite(lim):
            return None, False, lim
        dt = float(f"{min(0.5 * lim, 0.5 * dt_failed):.1g}")
        horizon = t_fail + 20 * dt_failed
        for _ in range(3):
            if horizon / dt > 2e5:
                return dt, False, lim            # too long to check here
            try:
                trial = Simulation(self.scene, self._drive_arg, SimOptions(**{**trial_opt.__dict__, "dt": dt}),
                                   pos=self._pos0, quat=self._quat0)
                # a trial that fails does not search for a dt of its own: before session 47 each did,
                # recursively (a 2-body scene whose bond no dt keeps inside its bound took 228 s to say so)
                trial._trial = True
                trial.run(horizon, record_interval=horizon, quiet=True)
                return dt, True, lim
            except MlcError:
                dt = float(f"{dt / 4:.1g}")
        return None, False, lim

    def _fail(self, dt_t0: float | None = None, initial: bool = False):
        """Raise the monitors' failure as an MlcError.  ``initial``: found in the state at
        t = 0 (:meth:`_check_initial`), which no step can fix; else in a step (a failure in
        the first step also has step 0 in ``status``)."""
        st = self.status
        code, step = int(st[0]), int(st[1])
        dt_t0 = self.dt if dt_t0 is None else dt_t0
        t = self.t / self.t_unit - (self.step - step) * dt_t0
        names = [b.name for b in self.scene.bodies]
        o = self.opt
        if o.scheme == "euler":
            sug, checked, lim = ((None, False, math.nan) if initial or self._trial
                                 else self._suggest_euler_dt(t, dt_t0))
            if sug is not None:
                fix = (f"use --dt {sug:g} or less (from the scene at rest, where Euler's limit is about "
                       f"{lim:.2g} t0" + ("; checked: it runs past this point)" if checked else ")"))
            else:
                fix = ("use --scheme stiff: no Euler step checked from the scene at rest gets past this point, "
                       "so the scene itself may be at fault")
        else:
            lim = self.euler_limit()
            fix = (f"no time step helps: the {o.scheme} scheme refined this step 2^30-fold; the scene itself drives "
                   "it (a muscle pulling a joint apart, bodies pushed together), check it"
                   + (f"; --scheme euler --dt {float(f'{0.5 * lim:.1g}'):g} shows the motion up to here"
                      if math.isfinite(lim) else ""))
        if code == K.STRETCH:
            m = int(st[2])
            bound = self.sp_bound[m]
            if initial:
                raise MlcError(f"at t = 0: {self.spring_names[m]} is stretched beyond {bound:.3g} sigma in the "
                               "initial scene (with the drives' values at t = 0)", "scene",
                               "fix the poses or the rest lengths; no time step can fix this")
            msg = (f"unstable at t = {t:.6g} t0 (step {step}): {self.spring_names[m]} stretched beyond "
                   f"{bound:.3g} sigma (thermal bound {o.stretch_thermal:g} sqrt(kT/k) + static allowance)")
        elif code == K.WCA_CLOSE:
            i, j = int(st[2]), int(st[3])
            if initial:
                raise MlcError(f"at t = 0: bodies {names[i]} and {names[j]} have centres closer than "
                               f"{o.wca_min:g} sigma: their WCA cores overlap and would eject them",
                               "scene", "move the bodies apart (no time step can fix this)")
            msg = (f"unstable at t = {t:.6g} t0 (step {step}): bodies {names[i]} and {names[j]} came closer than "
                   f"{o.wca_min:g} sigma (WCA cores overlap)")
        elif code == K.DISPLACEMENT:
            b = int(st[2])
            msg = (f"unstable at t = {t:.6g} t0 (step {step}): body {names[b]} drifted more than "
                   f"{o.max_disp:g} sigma or {o.max_rot:g} rad in one step (deterministic part; noise not counted)")
        else:
            msg = f"unstable at t = {t:.6g} t0 (step {step}): non-finite forces or positions"
        raise MlcError(msg, "--dt", fix)

    # -- what a run can and cannot claim ------------------------------------------------------
    def variance_bias(self, dt: float | None = None) -> dict:
        """Linear-theory stationary variance of a harmonic mode over its exact value kT/(k),
        for the modes this scheme and dt integrate (the stiffest at rho, the estimate of
        :meth:`rho`): Euler 1/(1 - h lambda/2); SK-ROCK (eta > 0) oscillates with h lambda
        (min and max over the modes up to rho); the fluctuation mode is exact (1.0) for every
        mode.  Keys: scheme, h_rho (stiffest mode's h lambda), ratio_min, ratio_max; for the
        fluctuation mode also stage_factor, stages and R_stiffest (:meth:`fluct_stages_target`,
        a full-size step), substep_levels (:meth:`fluct_level_span`: each step's least substep
        level is random in [0, substep_levels)) and the measured pair bias (:func:`fluct_pair_bias`)."""
        dt = self.dt if dt is None else dt
        h = dt * self.t_unit
        r = self.rho()
        hr = h * r
        if self.opt.scheme == "euler":
            v = 1.0 / (1.0 - 0.5 * hr) if hr < 2 else math.inf
            return {"scheme": "euler", "h_rho": hr, "ratio_min": 1.0, "ratio_max": v,
                    "note": "stiffest mode 1/(1 - h lambda/2); softer modes lie between"}
        if self.opt.scheme == "implicit":
            if self.opt.rot_noise:
                return {"scheme": "implicit", "h_rho": hr, "ratio_min": 1.0, "ratio_max": 1.0,
                        "note": "exact for every linear mode (noise covariance 2 kT (D/h + H+/2))"}
            return {"scheme": "implicit", "h_rho": hr, "ratio_min": 1.0, "ratio_max": 1.0,
                    "note": "exact for a bond that is a mode by itself (translational noise only: each row's "
                            "correction scaled by its translational share, mlc/sim/implicit.py); approximate "
                            "where bonds couple"}
        if self.opt.fluct:
            out = {"scheme": "stiff-fluct", "h_rho": hr, "ratio_min": 1.0, "ratio_max": 1.0,
                   "stage_factor": self.fluct_stage_factor(dt),
                   "note": "post-processed SK-ROCK with eta = 0: exact for every linear mode"}
            if self.opt.kT > 0:
                out["substep_levels"] = self.fluct_level_span(dt)
            if self.opt.kT > 0 and self.opt.fluct_stages == 0:
                _, out["stages"], out["R_stiffest"] = self.fluct_stages_target(dt)
            out.update(fluct_pair_bias(self.opt.kT, dt))
            return out
        lo, hi = skrock_variance_range(hr, self.opt.eta, hr * self.opt.rho_safety)
        return {"scheme": "stiff", "h_rho": hr, "ratio_min": lo, "ratio_max": hi,
                "note": "SK-ROCK variance ratio over modes with h lambda in (0, h rho]"}

    def thermal_warnings(self, res) -> list[str]:
        """Warnings for a run whose thermal bond fluctuations reach the logic margin: the
        a-priori bond scale sqrt(kT/k) of the softest spring against half the smallest probe
        margin, and the measured probe readings (spread over the second half of the run, or
        a reading outside the probe's range by more than its margin)."""
        out = []
        kT = self.opt.kT
        probes = self.scene.probes
        if not probes or kT <= 0:
            return out
        margins = {p.name: 0.5 * abs(p.actuated - p.rest) for p in probes}
        mmin = min(margins.values())
        if len(self.sp_k):
            kmin = float(np.min(self.sp_k))
            th = math.sqrt(kT / kmin)
            if th >= 0.5 * mmin:
                out.append(f"kT = {kT:g}: thermal bond fluctuations sqrt(kT/k) = {th:.3g} sigma reach the logic "
                           f"margin ({mmin:.3g} sigma from a probe's threshold): the outputs are not bits")
        for p in probes:
            v = np.asarray(res.probes.get(p.name, []))
            if len(v) < 4:
                continue
            tail = v[len(v) // 2:]
            lo, hi = min(p.rest, p.actuated), max(p.rest, p.actuated)
            m = margins[p.name]
            sd = float(np.std(tail))
            mean = float(np.mean(tail))
            if 3.0 * sd >= m or mean < lo - m or mean > hi + m:
                out.append(f"probe {p.name}: reads {mean:.3g} +- {sd:.2g} sigma over the second half of the run, "
                           f"against a margin of {m:.3g} sigma around [{lo:.3g}, {hi:.3g}]: not a bit")
        return out

    def run(self, time: float, record_interval: float | None = None, frames: int = 0,
            progress: bool | None = None, quiet: bool = False) -> SimResult:
        """Advance by ``time`` t0 in steps of at most the simulation's dt (the last step ends
        exactly at ``time``: the run's step is time / ceil(time / dt)); record probes every
        ``record_interval`` t0 (default: about 2000 records) and ``frames`` snapshots.  Shows
        a progress bar on a TTY for long runs.  Ctrl-C stops within about a second and
        returns what was computed (``interrupted`` set); during the first chunk, which
        compiles the kernels on a cold cache (up to a minute), it raises KeyboardInterrupt
        at once: nothing has been computed yet."""
        if not (math.isfinite(time) and time >= 0):
            raise MlcError(f"time must be a finite number >= 0 of t0, got {time}", "--time")
        if record_interval is not None and not (math.isfinite(record_interval) and record_interval > 0):
            raise MlcError(f"record interval must be a positive number of t0, got {record_interval}", "--record")
        nsteps = math.ceil(time / self.dt - 1e-9) if time > 0 else 0
        if self.step == 0:
            self._check_initial()
        if nsteps > self.opt.max_steps:
            raise MlcError(f"--time {time:g} at --dt {self.dt:g} is {nsteps:.3g} steps (more than "
                           f"{self.opt.max_steps:.3g})", "--dt",
                           "use a larger --dt (the stiff scheme takes any dt) or a shorter --time")
        dt = time / nsteps if nsteps else self.dt
        if record_interval is None:
            rec_every = max(1, nsteps // 2000)
        else:
            rec_every = max(1, int(round(record_interval / dt)))
        # sampled frames plus the final state
        frame_every = max(1, -(-nsteps // max(frames - 1, 1))) if frames else 0
        show = progress if progress is not None else (not quiet and sys.stderr.isatty())
        bar = _Progress(nsteps, show)
        recs, fps, fqs, ftimes = [], [], [], []
        t_wall = _time.perf_counter()
        evals0 = self.stages_out[0]
        done_total = 0
        interrupted = False
        t_start = self.t
        chunk = 16
        stop = _Interrupt()
        with stop:
            while done_total < nsteps and not stop.hit:
                n = min(chunk, nsteps - done_total)
                c0 = _time.perf_counter()
                rec, fp, fq, done = self.advance(n, rec_every, frame_every, done_total, done_total, dt,
                                                 origin=(t_start, done_total))
                el = _time.perf_counter() - c0
                recs.append(rec)
                if len(fp):
                    fps.append(fp)
                    fqs.append(fq)
                    g = np.arange(done_total, done_total + done)
                    g = g[g % frame_every == 0]
                    ftimes.extend((t_start + g * dt * self.t_unit) / self.t_unit)
                done_total += done
                stop.arm()
                bar.update(done_total)
                # aim at ~0.25 s per chunk (Ctrl-C is seen between chunks)
                per = el / max(done, 1)
                target = int(0.25 / per) if per > 0 else chunk * 2
                chunk = max(1, min(max(target, chunk // 2), chunk * 4))
        interrupted = stop.hit
        if done_total == nsteps:
            self.t = t_start + time * self.t_unit          # exactly, without round-off of the step sum
        # final sample
        last = self.probe_lengths()
        if frames:
            fps.append(self.pos[None].copy())
            fqs.append(self.quat[None].copy())
            ftimes.append(self.t / self.t_unit)
        wall = _time.perf_counter() - t_wall
        bar.close()
        R = np.concatenate(recs) if recs else np.zeros((0, 1 + len(self.scene.probes)))
        times = np.concatenate([R[:, 0] / self.t_unit, [self.t / self.t_unit]])
        probes = {p.name: np.concatenate([R[:, 1 + k], [last[p.name]]]) for k, p in enumerate(self.scene.probes)}
        res = SimResult(
            scheme=self.opt.scheme, dt=self.dt, steps=done_total, time=self.t / self.t_unit, wall=wall,
            times=times, probes=probes, pos=self.pos.copy(), quat=self.quat.copy(),
            frame_times=np.array(ftimes), frame_pos=np.concatenate(fps) if fps else np.zeros((0, self.N, 3)),
            frame_quat=np.concatenate(fqs) if fqs else np.zeros((0, self.N, 4)),
            force_evals=int(self.stages_out[0] - evals0), stages=int(self.stages_out[1]), interrupted=interrupted)
        res.warnings = self.thermal_warnings(res)
        return res


def _count(done: int, every: int, phase: int) -> int:
    """How many local indices n in [0, done) have (n + phase) % every == 0."""
    if every <= 0 or done <= 0:
        return 0
    first = (-phase) % every
    return 0 if first >= done else (done - 1 - first) // every + 1


#: Fluctuation mode's stage rule (Simulation.fluct_stages_target; session 13, chosen on the
#: numpy model of the bonded pair, benchmarks/sim_fluct_model.py): base factor FLUCT_M_HI when
#: one step's noise variance per axis 2 kT h/gamma exceeds FLUCT_NOISE_HI (sigma^2), else 1;
#: then the fewest stages (up to FLUCT_SPAN times the base) whose stiffest-mode factor
#: T_s(1 - h rho/s^2) lies in FLUCT_R_WINDOW.
#: FLUCT_NOISE_HI was 0.5 sigma^2 (a radian a step) in sessions 13-16; 1.5e-3 since session 17: on
#: the scene of many stiff modes (benchmarks/sim_fluct_modes.py) groups read up to +8 % at
#: kT = 1e-3, dt = 0.05-0.2 t0 and +21 % at kT = 1e-2, dt = 0.01 t0 with m0 = 1 (noise variance
#: 0.02-0.4 sigma^2 a step), within 5 % with m0 = 3 (not a round 1e-3: that is the noise at
#: kT = 1e-5, dt = 0.05 t0, a measured point, where rounding would pick the factor); at kT = 0
#: (trajectories) nothing changes
FLUCT_M_HI = 3.0
FLUCT_NOISE_HI = 1.5e-3
FLUCT_R_WINDOW = (-0.5, 0.5)
FLUCT_SPAN = 1.5
#: ... and random least substep levels (SimOptions.fluct_levels, session 15) only where a full
#: step takes more than this many stages (Simulation.fluct_level_span)
FLUCT_LEVELS_MIN_STAGES = 4


def _cheb_factor(hr: float, s: int) -> float:
    """SK-ROCK's (eta = 0) one-step factor R_s(-hr) = T_s(1 - hr/s^2) of a mode with h lambda = hr
    (|x| > 1 outside the stability interval: cosh form)."""
    x = 1.0 - hr / (s * s)
    if abs(x) <= 1.0:
        return math.cos(s * math.acos(x))
    v = math.cosh(s * math.acosh(abs(x)))
    return v if x > 0 or s % 2 == 0 else -v


#: Fluctuation mode, measured bias beyond linear theory (benchmarks/sim_fluct_bias.py,
#: benchmarks/results/sim_fluct_bias.json): bond-length variance over its exact Boltzmann
#: value for 200 bonded pairs (one bond, k = 1 k0, rest 1 sigma, between the bodies'
#: centres, no rotational noise), per kT (k0 sigma^2): (dt in t0, ratio); 50 steps of
#: burn-in, 200 measured, sampling error ~0.01; the session-13 stage rule (before it, kT = 1e-3,
#: dt = 0.2 t0 gave +40 %: 16 stages put the pair's mode on an interior Chebyshev extremum) and
#: the session-15 random substep levels above 4 stages (SimOptions.fluct_levels); re-run in
#: session 17 with the base factor 3 from 1.5e-3 sigma^2 of noise a step (FLUCT_NOISE_HI).
FLUCT_PAIR_RATIO = {
    1e-05: ((0.01, 0.994), (0.05, 0.999), (0.2, 1.003), (0.5, 1.001), (2.0, 1.001), (5.0, 0.986),
            (20.0, 0.997), (100.0, 1.014)),
    0.0001: ((0.01, 0.977), (0.05, 1.004), (0.2, 0.987), (0.5, 0.986), (2.0, 1.004), (5.0, 0.999),
             (20.0, 1.000), (100.0, 1.004)),
    0.001: ((0.01, 0.979), (0.05, 0.998), (0.2, 1.000), (0.5, 1.002), (2.0, 1.015), (5.0, 0.992),
            (20.0, 0.981), (100.0, 1.009)),
    0.01: ((0.01, 1.010), (0.05, 1.011), (0.2, 1.027), (0.5, 1.029), (2.0, 1.008), (5.0, 1.007),
           (20.0, 1.019), (100.0, 1.009)),
}


def fluct_pair_bias(kT: float, dt: float) -> dict:
    """The fluctuation mode's measured bias on bonded pairs (:data:`FLUCT_PAIR_RATIO`) at the
    measured kT nearest ``kT`` (in log) and ``dt`` (t0) interpolated in log dt (clamped to the
    measured range), with the pair's noise turn per step phi^2 = 4 kT h/(gamma L^2)
    (h = dt in gamma/k0, L = 1 sigma).  Keys: pair_ratio_measured, pair_ratio_kT,
    noise_turn_rad2, pair_note.  Empty at kT = 0 (no fluctuations)."""
    if not (kT > 0 and dt > 0):
        return {}
    kk = min(FLUCT_PAIR_RATIO, key=lambda k: abs(math.log10(k) - math.log10(kT)))
    pts = FLUCT_PAIR_RATIO[kk]
    x = min(max(math.log10(dt), math.log10(pts[0][0])), math.log10(pts[-1][0]))
    ratio = pts[-1][1]
    for (d0, r0), (d1, r1) in zip(pts[:-1], pts[1:]):
        a, b = math.log10(d0), math.log10(d1)
        if a <= x <= b:
            ratio = r0 + (r1 - r0) * (x - a) / (b - a)
            break
    far = abs(math.log10(kk) - math.log10(kT)) > 0.5 or not (pts[0][0] <= dt <= pts[-1][0])
    return {"pair_ratio_measured": round(ratio, 3), "pair_ratio_kT": kk,
            "noise_turn_rad2": 4.0 * kT * dt * 1e3,
            "pair_note": "measured bond-length variance / exact of a bonded pair (k = 1 k0, rest 1 sigma) at this "
                         "dt and the nearest measured kT (benchmarks/sim_fluct_bias.py): the nonlinearity linear "
                         "theory misses: within 3 % at kT = 1e-5 to 1e-2 and dt = 0.01 to 100 t0 with the "
                         "stage rule (fluct_stages_target) and the random substep levels (fluct_level_span), "
                         "which keep the modes off the interior Chebyshev extrema (there the undamped scheme "
                         "neither relaxes nor damps nonlinear noise: +40 % at kT = 1e-3, dt = 0.2 t0 before); "
                         "one stiffness: a spread of stiff modes is measured in docs/simulation.md ('Many stiff "
                         "modes')" + ("; outside the measured range: an extrapolation" if far else "")}


def _floor1(x: float) -> float:
    """``x`` rounded down to one significant digit (a dt to suggest: never above ``x``)."""
    e = math.floor(math.log10(x))
    m = math.floor(x / 10.0 ** e * (1 + 1e-12))
    v = float(f"{m}e{e}")
    return v if v <= x else float(f"{m - 1}e{e}") if m > 1 else float(f"9e{e - 1}")


def skrock_variance_range(h_rho: float, eta: float, h_rho_max: float | None = None) -> tuple[float, float]:
    """Min and max over h lambda in (0, h_rho] of SK-ROCK's stationary variance of the mode
    dX = -lambda X dt + sqrt(2) dW over the exact 1/lambda, with the stage count the scheme
    uses for the bound ``h_rho_max`` (default h_rho): 2|p| S(p)^2 / (1 - R(p)^2),
    R = T_s(w0 + w1 p)/T_s(w0), S = U_{s-1}(w0 + w1 p)/U_{s-1}(w0) (1 + w1 p/2)."""
    if h_rho <= 0:
        return 1.0, 1.0
    hm = h_rho if h_rho_max is None else max(h_rho_max, h_rho)
    s = max(2, math.ceil(math.sqrt(hm / (2.0 - 4.0 * eta / 3.0))))
    w0 = 1.0 + eta / s ** 2

    def tu(n, x):
        t0, t1 = np.ones_like(x), x.copy()
        u0, u1 = np.ones_like(x), 2 * x
        for _ in range(2, n + 1):
            t0, t1 = t1, 2 * x * t1 - t0
            u0, u1 = u1, 2 * x * u1 - u0
        return t1, u0                  # T_n, U_{n-1} (n >= 2)

    x0 = np.array([w0])
    ts0, us10 = tu(s, x0)
    w1 = float(ts0[0] / (s * us10[0]))
    p = -np.linspace(1e-6 * h_rho, h_rho, 20001)
    x = w0 + w1 * p
    ts, us1 = tu(s, x)
    R = ts / ts0[0]
    S = us1 / us10[0] * (1 + w1 * p / 2)
    with np.errstate(divide="ignore", invalid="ignore"):
        r = 2 * (-p) * S * S / (1 - R * R)
    r = r[np.isfinite(r)]
    return float(np.min(r)), float(np.max(r))


class _Interrupt:
    """Within ``with``, once :meth:`arm` is called: Ctrl-C (SIGINT) sets ``hit`` instead of
    raising, so a run stops cleanly between two compiled chunks (each ~0.25 s).  Before
    ``arm`` (the first chunk, while Numba compiles the kernels) Ctrl-C raises
    KeyboardInterrupt at once, as without the handler.  Outside the main thread: no-op."""

    def __init__(self):
        self.hit = False
        self.armed = False
        self._old = None

    def arm(self):
        self.armed = True

    def __enter__(self):
        import signal
        import threading
        if threading.current_thread() is threading.main_thread():
            self._old = signal.signal(signal.SIGINT, self._handler)
        return self

    def _handler(self, signum, frame):
        if not self.armed:
            raise KeyboardInterrupt
        self.hit = True

    def __exit__(self, *exc):
        import signal
        if self._old is not None:
            signal.signal(signal.SIGINT, self._old)
        return False


class _Progress:
    """A one-line progress bar with ETA on stderr; silent unless ``show`` and the run is long."""

    def __init__(self, total: int, show: bool):
        self.total = max(total, 1)
        self.show = show
        self.t0 = _time.perf_counter()
        self.drawn = False

    def update(self, done: int):
        if not self.show:
            return
        el = _time.perf_counter() - self.t0
        if el < 2.0 and not self.drawn:
            eta = el / max(done, 1) * (self.total - done)
            if el + eta < 3.0:
                return
        frac = done / self.total
        eta = el / max(frac, 1e-9) - el
        w = 30
        fill = int(w * frac)
        sys.stderr.write(f"\r[{'#' * fill}{'.' * (w - fill)}] {100 * frac:5.1f}%  ETA {eta:6.1f} s ")
        sys.stderr.flush()
        self.drawn = True

    def close(self):
        if self.drawn:
            sys.stderr.write("\n")
            sys.stderr.flush()


def simulate(scene: Scene, time: float, drives: dict | None = None, options: SimOptions | None = None,
             **run_kw) -> SimResult:
    """One-call convenience: build a :class:`Simulation` and run it for ``time`` t0."""
    return Simulation(scene, drives, options).run(time, **run_kw)

