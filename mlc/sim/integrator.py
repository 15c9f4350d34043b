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
from mlc.sim.drive import Drive, pack_drives

SCHEMES = ("euler", "stiff")


@dataclass
class SimOptions:
    """Integrator options (times in t0, lengths in sigma, energies in k0 sigma^2)."""

    dt: float | None = None          # None: a default from the stiffness estimate (see default_dt)
    scheme: str = "stiff"            # "euler" (Euler-Maruyama, the reference) or "stiff" (SK-ROCK)
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

    def final_probes(self) -> dict:
        return {k: float(v[-1]) for k, v in self.probes.items() if len(v)}


class Simulation:
    """A scene, its drives and the integrator state (positions, orientations, time, step)."""

    def __init__(self, scene: Scene, drives: dict | None = None, options: SimOptions | None = None,
                 pos=None, quat=None):
        self.scene = scene
        self.opt = o = options or SimOptions()
        if o.scheme not in SCHEMES:
            raise MlcError(f"unknown scheme {o.scheme!r}", "--scheme", "use euler or stiff")
        if not (math.isfinite(o.kT) and o.kT >= 0):
            raise MlcError(f"kT must be finite and >= 0, got {o.kT}", "--kT")
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
        self.stages_out = np.zeros(5)
        self.pv = np.random.default_rng(12345).standard_normal((N, 6))
        self.pw = np.zeros((N, 6))
        self.sp_tmp = np.zeros((B, 3))
        self.K0, self.K1, self.K2, self.Qn = (np.zeros((N, 6)) for _ in range(4))
        self.qn = np.zeros((N, 4))
        self.xs = np.zeros((N, 3))
        self.qs = np.zeros((N, 4))
        self.xl = np.zeros((N, 3))
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
        if not (math.isfinite(dt) and dt > 0):
            raise MlcError(f"dt must be a positive number of t0, got {dt}", "--dt")
        return float(dt)

    def _grow_nlist(self):
        """Enlarge the neighbour list after an overflow (the kernels fell back to the cell list)."""
        if self.nlstate[2] > 0:
            self.nl = np.zeros(int(2 * self.nlstate[3]) + 64, np.int64)
            self.nlstate[0] = 0.0
            self.nlstate[2] = 0.0

    def _eval(self):
        self._grow_nlist()
        eps, s, rc = self._wca()
        self._k["eval"](self.pos, self.quat, float(self.t), self.site_body, self.site_local, self.bsite0, self.sp_i,
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
    def advance(self, nsteps: int, rec_every: int = 0, frame_every: int = 0):
        """Run ``nsteps`` steps in one compiled call; returns (records, frames_pos, frames_quat, done)."""
        o = self.opt
        P = len(self.scene.probes)
        nrec = (nsteps + rec_every - 1) // rec_every if rec_every > 0 else 0
        nfr = (nsteps + frame_every - 1) // frame_every if frame_every > 0 else 0
        rec = np.zeros((nrec, 1 + P))
        fpos = np.zeros((nfr, self.N, 3))
        fquat = np.zeros((nfr, self.N, 4))
        eps, s, rc = self._wca()
        dt = self.dt * self.t_unit
        self.status[:] = 0
        self._grow_nlist()
        a = self.arrays
        common = (self.pos, self.quat, float(self.t), int(self.step), int(nsteps), float(dt), float(o.kT),
                  float(self.gamma), float(self.gamma_r), bool(o.rot_noise), np.uint64(int(o.seed) & 0xFFFFFFFFFFFFFFFF),
                  self.site_body, self.site_local, self.bsite0, self.sp_i, self.sp_j, self.sp_k, self.sp_rest0,
                  self.sp_rest1, self.sp_tol, self.sp_inp, self.sp_bound, self.end0, self.end_sp, self.end_sign,
                  self.dkind, self.dpar, self.tab_t, self.tab_v, eps, s, rc, float(o.wca_min), self.ex0, self.ex_list,
                  self.head, self.nxt, self.cell, self.nl0, self.nl, self.pos_nl, self.nlstate,
                  float(o.max_disp), float(o.max_rot), a.probe_i, a.probe_j,
                  int(rec_every), rec, int(frame_every), fpos, fquat, self.uval, self.ws, self.arm, self.fsp, self.ratio, self.dmin,
                  self.dpart, self.F, self.T, self.disp, self.mon, self.status)
        if o.scheme == "euler":
            done = self._k["euler"](*common)
            self.stages_out[0] += done
            self.stages_out[1] = 1
        else:
            done = self._k["skrock"](*common, float(o.eta), float(o.rho_safety), int(o.rho_every), 60, self.pv, self.pw,
                                     self.sp_tmp, int(o.stages), self.stages_out, self.K0, self.K1, self.K2,
                                     self.Qn, self.qn, self.xs, self.qs, float(o.accept), float(o.rot_acc),
                                     float(o.disp_acc), self.arm_max)
        self.step += done
        self.t += done * dt
        if self.status[0] != K.OK:
            self._fail()
        nr = (done + rec_every - 1) // rec_every if rec_every > 0 else 0
        nf = (done + frame_every - 1) // frame_every if frame_every > 0 else 0
        return rec[:nr], fpos[:nf], fquat[:nf], done

    def _fail(self):
        st = self.status
        code, step = int(st[0]), int(st[1])
        t = step * self.dt
        names = [b.name for b in self.scene.bodies]
        o = self.opt
        if o.scheme == "euler":
            try:
                self._rho = None
                lim = self.euler_limit()
            except Exception:  # noqa: BLE001 - the state may be garbage; the estimate is advisory
                lim = math.nan
            if math.isfinite(lim) and self.dt > 0.5 * lim:
                fix = f"use --dt {float(f'{0.5 * lim:.1g}'):g} or less (Euler's limit here is about {lim:.2g} t0)"
            else:
                fix = (f"use --dt {float(f'{self.dt / 4:.1g}'):g} or --scheme stiff; "
                       "if that fails too, the scene itself is at fault")
        else:
            lim = self.euler_limit()
            fix = ("no time step helps: the stiff scheme refined this step 2^20-fold; the scene itself drives "
                   "it (a muscle pulling a joint apart, bodies pushed together), check it"
                   + (f"; --scheme euler --dt {float(f'{0.5 * lim:.1g}'):g} shows the motion up to here"
                      if math.isfinite(lim) else ""))
        if code == K.STRETCH:
            m = int(st[2])
            bound = self.sp_bound[m]
            if step == 0:
                raise MlcError(f"at t = 0: {self.spring_names[m]} is stretched beyond {bound:.3g} sigma in the "
                               "initial scene (with the drives' values at t = 0)", "scene",
                               "fix the poses or the rest lengths; no time step can fix this")
            msg = (f"unstable at t = {t:.6g} t0 (step {step}): {self.spring_names[m]} stretched beyond "
                   f"{bound:.3g} sigma (thermal bound {o.stretch_thermal:g} sqrt(kT/k) + static allowance)")
        elif code == K.WCA_CLOSE:
            i, j = int(st[2]), int(st[3])
            if step == 0:
                raise MlcError(f"at t = 0: bodies {names[i]} and {names[j]} have centres closer than "
                               f"{o.wca_min:g} sigma: their WCA cores overlap and would eject them",
                               "scene", "move the bodies apart (no time step can fix this)")
            msg = (f"unstable at t = {t:.6g} t0 (step {step}): bodies {names[i]} and {names[j]} came closer than "
                   f"{o.wca_min:g} sigma (WCA cores overlap)")
        elif code == K.DISPLACEMENT:
            b = int(st[2])
            msg = (f"unstable at t = {t:.6g} t0 (step {step}): body {names[b]} moved more than "
                   f"{o.max_disp:g} sigma or {o.max_rot:g} rad in one step")
        else:
            msg = f"unstable at t = {t:.6g} t0 (step {step}): non-finite forces or positions"
        raise MlcError(msg, "--dt", fix)

    def run(self, time: float, record_interval: float | None = None, frames: int = 0,
            progress: bool | None = None, quiet: bool = False) -> SimResult:
        """Advance by ``time`` t0; record probes every ``record_interval`` t0 (default: about
        2000 records) and ``frames`` snapshots.  Shows a progress bar on a TTY for long runs."""
        if not (math.isfinite(time) and time >= 0):
            raise MlcError(f"time must be a finite number >= 0 of t0, got {time}", "--time")
        nsteps = int(round(time / self.dt))
        if nsteps == 0 and time > 0:
            nsteps = 1
        if record_interval is None:
            rec_every = max(1, nsteps // 2000)
        else:
            rec_every = max(1, int(round(record_interval / self.dt)))
        # sampled frames plus the final state
        frame_every = max(1, -(-nsteps // max(frames - 1, 1))) if frames else 0
        show = progress if progress is not None else (not quiet and sys.stderr.isatty())
        bar = _Progress(nsteps, show)
        recs, fps, fqs, ftimes = [], [], [], []
        t_wall = _time.perf_counter()
        evals0 = self.stages_out[0]
        done_total = 0
        # chunks are whole multiples of the record and frame intervals (sampling indices are chunk-local)
        lcm = rec_every * (frame_every or 1) // math.gcd(rec_every, frame_every or 1)
        chunk = lcm * max(1, -(-16 // lcm))
        while done_total < nsteps:
            n = min(chunk, nsteps - done_total)
            t_before = self.t
            c0 = _time.perf_counter()
            rec, fp, fq, done = self.advance(n, rec_every, frame_every)
            el = _time.perf_counter() - c0
            recs.append(rec)
            if len(fp):
                fps.append(fp)
                fqs.append(fq)
                ftimes.extend((t_before + np.arange(len(fp)) * frame_every * self.dt * self.t_unit) / self.t_unit)
            done_total += done
            bar.update(done_total)
            # aim at ~0.25 s per chunk
            per = el / max(done, 1)
            target = int(0.25 / per) if per > 0 else chunk * 2
            chunk = max(lcm, (min(max(target, chunk // 2), chunk * 4) // lcm) * lcm)
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
        return SimResult(
            scheme=self.opt.scheme, dt=self.dt, steps=done_total, time=self.t / self.t_unit, wall=wall,
            times=times, probes=probes, pos=self.pos.copy(), quat=self.quat.copy(),
            frame_times=np.array(ftimes), frame_pos=np.concatenate(fps) if fps else np.zeros((0, self.N, 3)),
            frame_quat=np.concatenate(fqs) if fqs else np.zeros((0, self.N, 4)),
            force_evals=int(self.stages_out[0] - evals0), stages=int(self.stages_out[1]))


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

