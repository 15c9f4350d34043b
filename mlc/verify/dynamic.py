"""Dynamic verification of any scene with a truth table: Brownian dynamics from rest into
every input row, every probe read once the mechanism has relaxed.

For each input row and seed the scene starts from its own poses (the all-zero row,
at rest), the inputs switch to the row at t = 0 (constant drives) and the Brownian
dynamics runs (:class:`mlc.sim.integrator.Simulation`, stiff scheme by default) until
**every** probe has relaxed.  Relaxation is detected, not assumed, by two conditions:

1. **plateau**: the last third of the run (at least ``MIN_WINDOWS`` windows of
   ``window`` t0), cut into three equal blocks, has block means of every probe that
   agree within :func:`plateau_tol`: ``2e-3 + 3 sqrt(kT/k0)`` sigma plus three standard
   deviations of the difference of two block means, from the probe's harmonic thermal
   spread ``sd`` (:func:`probe_thermal_sd`, at the row's static equilibrium) and its
   correlation time (at most ``tau``).  Block means, not single windows, and a
   tolerance that knows the probe's own noise: the far end of a 20-unit contracting
   chain fluctuates by sd = 0.08 sigma with a correlation time of ~40 t0, so a fixed
   0.01-sigma test never passes however long the run;
2. **time scale**: when the row's inputs differ from the starting row, the run has
   lasted at least ``tau_factor`` times the mechanism's slowest relaxation time
   ``tau`` (:func:`relaxation_time`, the larger of its values at the starting pose and
   at the row's static equilibrium: a NAND's output lever relaxes with 0.13 t0 in row
   01 but 0.086 t0 about the rest pose).

The plateau alone is not enough.  A signal crosses a long connector chain by
diffusion (``tau`` grows as the square of the length: 0.04, 0.96, 3.8, 15 t0 for
1, 5, 10, 20 full units of an expanding chain, three times that contracting), and the far end of a 20-unit chain sits still, within
0.02 sigma of its old length, for the first ~1 t0 after the input switched: a
plateau test run alone declares it relaxed and reads the wrong bit.  ``tau`` comes
from the linearised overdamped dynamics about the starting pose,

    d x/dt = -M H x,    H = J^T J (k0/sigma^2),   M = diag(1/gamma, 1/gamma_r)

(``J``: the Jacobian of the bond and muscle residuals of :mod:`mlc.verify.static`, per
body a translation and a rotation vector), ``tau = 1 / lambda_min`` with
``lambda_min`` the smallest non-zero eigenvalue of ``M^(1/2) H M^(1/2)``; the zero
eigenvalues (rigid-body motion and floppy modes such as a connector's bending) have
no restoring force and do not move a probe.  After ``tau_factor = 3`` times ``tau``
the slowest mode has fallen to e^-3 = 5% of its start and the plateau test over the
last third of the run then bounds what is left by about ``tol``.

The measured value of a probe is the mean of its window means over the plateau
(averaged over seeds); the margin is its signed distance from the probe's threshold
towards the expected bit (the smallest over seeds).  A row is ``ok`` when every seed
relaxed and read the expected bit with a positive margin.  Units: lengths sigma,
times t0 = gamma / (1e-3 k0), energies k0 sigma^2.
"""
from __future__ import annotations

import math
import sys

import numpy as np

from mlc.errors import MlcError
from mlc.sim.drive import Drive
from mlc.sim.integrator import SimOptions, Simulation, check_kT

WINDOW = 0.05          # t0: shortest window
MIN_WINDOWS = 3        # windows on the plateau, at least
PLATEAU = 1.0 / 3.0    # the plateau spans this fraction of the run
TAU_FACTOR = 3.0       # the run lasts at least this many slowest relaxation times
MAX_TIME = 20.0        # t0: the run stops here (or at MAX_TAUS tau if longer) unrelaxed
MAX_TAUS = 12.0
DT = {"stiff": 0.01, "euler": None}      # t0; None: the integrator's own (half the Euler limit)
DT_LARGE = {"stiff": 0.2}  # t0: circuits (more than DENSE_MAX / 6 bodies); measured against the static
                           # equilibrium at 0.01-0.2 t0 (benchmarks/circuit_dt.py, docs/circuits.md)
SLOW_STEPS = 1e8       # Euler steps a run beyond which the check warns before it starts
DENSE_MAX = 1800       # degrees of freedom up to which the spectrum is computed densely
ZERO = 1e-9            # eigenvalues below ZERO * lambda_max count as zero modes
DENSE_ROBOT = 6000     # ... and for a robot's --tau compute (6000: 288 MB; a 524-body robot's 3144 took
                       # 4.5 s, where the sparse Lanczos did not converge in 10 minutes, session 47)
SIGNAL_MIN = 0.01      # probes answering less than this fraction of the largest answer are left out of signal_time


def relaxation_time(scene, pos=None, quat=None, gamma_r: float | None = None,
                    dense_max: int = DENSE_MAX) -> float:
    """Slowest relaxation time (t0) of the linearised overdamped dynamics of ``scene``
    about the pose ``pos``/``quat`` (default: the scene's own): 1 / the smallest non-zero
    eigenvalue of ``M^(1/2) J^T J M^(1/2)`` (see the module docstring).  0 for a scene
    with no bonds or muscles.  ``gamma_r``: rotational drag (default gamma, as
    :class:`SimOptions`).  Dense eigenvalues up to ``dense_max`` degrees of freedom, a
    sparse shift-invert Lanczos above."""
    from mlc.verify.static import _Problem

    A = scene.arrays()
    prob = _Problem(scene, A.pos if pos is None else pos, A.quat if quat is None else quat, pin_first=False)
    if prob.m == 0 or prob.n == 0:
        return 0.0
    u = scene.units
    gamma, k0 = float(u.get("gamma", 1.0)), float(u.get("k0", 1.0))
    gr = gamma if gamma_r is None else float(gamma_r)
    mob = np.tile(np.r_[np.full(3, 1.0 / gamma), np.full(3, 1.0 / gr)], prob.N)
    J = prob.jacobian()
    Js = J @ _diag(np.sqrt(mob))
    H = (Js.T @ Js).tocsc()            # rate matrix, k0/gamma units (bond k in k0)
    if prob.n <= dense_max:
        ev = np.linalg.eigvalsh(H.toarray())
        nz = ev[ev > ZERO * max(ev[-1], 1e-300)]
        lam = float(nz[0]) if len(nz) else 0.0
    else:
        from scipy.sparse.linalg import ArpackNoConvergence
        try:
            lam = _smallest_nonzero_sparse(H)
        except ArpackNoConvergence:
            # many zero modes (the floppy bends of chains) can keep the shift-invert Lanczos from
            # converging: the 524-body Tetris robot with a muscle per lever has 150 against the 16
            # eigenvalues first asked for (session 47, after 31441 iterations; its dense spectrum: 4.5 s)
            raise MlcError(f"the slowest relaxation time could not be computed: the Lanczos iteration for the "
                           f"smallest non-zero rate of this {prob.n}-coordinate scene did not converge", "--tau",
                           "give the relaxation time in t0 (--tau T)") from None
    if lam <= 0.0:
        return 0.0
    t_unit = gamma / (1e-3 * k0)       # the integrator's time per t0
    return 1.0 / lam / t_unit


def _probe_gradients(prob, scene):
    """Gradient of every probe's length (sigma) with respect to each body's translation
    and rotation vector, one column per probe: shape (6 N, P)."""
    A = scene.arrays()
    p, rs = prob.sites()
    G = np.zeros((prob.n, len(scene.probes)))
    for k in range(len(scene.probes)):
        i, j = A.probe_i[k], A.probe_j[k]
        d = p[i] - p[j]
        n = d / max(float(np.linalg.norm(d)), 1e-300)
        for site, sign in ((i, 1.0), (j, -1.0)):
            b = A.site_body[site]
            G[6 * b:6 * b + 3, k] += sign * n
            G[6 * b + 3:6 * b + 6, k] += sign * np.cross(rs[site], n)
    return G


def signal_time(scene, start: str, state: str, pos=None, quat=None, gamma_r: float | None = None,
                min_response: float = SIGNAL_MIN) -> float:
    """Mean time (t0) for the inputs' switch from row ``start`` to row ``state`` to reach
    the probes, in the linearised overdamped dynamics about ``pos``/``quat`` (default: the
    scene's own): the largest over probes of

        T = y_g^T M^-1 y_f / g^T y_f,    y_g = H^+ g,  y_f = H^+ f,

    the integral of the probe's remaining step response ``1 - a(t)/a(inf)`` after the
    muscles' rest lengths change (``f = J_m^T sqrt(k) dL``, ``g``: the probe's gradient,
    ``H = J^T J``, ``M = diag(1/gamma, 1/gamma_r)``): for one mode it is the mode's
    relaxation time, for a diffusing chain it grows as the square of its length.  Probes
    whose linear response ``g^T y_f`` is under ``min_response`` times the largest one (a
    probe behind a gate: the gate's switch is not linear about its rest pose) are left out.
    A large switch is faster than its linearisation: the far end of a 5-unit chain answers
    a full switch in 0.85 (expanding) to 0.89 (contracting) of ``T``, a 1 % one in 0.99.  Two sparse solves per row and probe,
    where the smallest non-zero eigenvalue of :func:`relaxation_time` needs an iterative
    eigensolver that the hundreds of near-zero bending modes of a circuit's connector
    chains slow to minutes.  0 when no probe responds."""
    from mlc.verify.static import _Problem

    A = scene.arrays()
    prob = _Problem(scene, A.pos if pos is None else pos, A.quat if quat is None else quat, pin_first=False)
    if prob.m == 0 or prob.n == 0 or not scene.probes or not len(A.muscle_i):
        return 0.0
    u = scene.units
    gamma, k0 = float(u.get("gamma", 1.0)), float(u.get("k0", 1.0))
    gr = gamma if gamma_r is None else float(gamma_r)
    J, lu, _ = _factorised(prob)
    a = np.asarray([int(c) for c in start], float)[A.muscle_input]
    b = np.asarray([int(c) for c in state], float)[A.muscle_input]
    dL = np.array([(m.actuated - m.rest) for m in scene.muscles]) * (b - a)
    if not np.any(dL):
        return 0.0
    r = np.zeros(prob.m)
    r[prob.m - len(A.muscle_i):] = np.sqrt(A.muscle_k) * dL
    yf = lu.solve(J.T @ r)
    G = _probe_gradients(prob, scene)
    Yg = lu.solve(G)
    minv = np.tile(np.r_[np.full(3, gamma), np.full(3, gr)], prob.N)
    resp = G.T @ yf
    num = Yg.T @ (minv * yf)
    keep = np.abs(resp) >= min_response * float(np.max(np.abs(resp)))
    if not np.any(keep) or not np.max(np.abs(resp)) > 0:
        return 0.0
    t_unit = gamma / (1e-3 * k0)       # the integrator's time per t0
    return float(np.max(np.abs(num[keep] / resp[keep]))) / t_unit


def probe_thermal_sd(scene, kT: float, pos=None, quat=None) -> dict:
    """Equilibrium thermal standard deviation (sigma) of every probe of ``scene`` about the
    pose ``pos``/``quat`` (default: the scene's own), in the harmonic approximation: the
    poses fluctuate with covariance ``kT H^+`` (``H = J^T J``, the bond and muscle
    stiffness, k0/sigma^2, zero modes left out), so a probe with gradient ``g`` (per body
    translation and rotation vector) has variance ``kT g^T H^+ g``.  A probe that a zero
    mode moves (``g`` not orthogonal to the null space) has no finite variance: inf."""
    from mlc.verify.static import _Problem

    A = scene.arrays()
    prob = _Problem(scene, A.pos if pos is None else pos, A.quat if quat is None else quat, pin_first=False)
    out = {p.name: 0.0 for p in scene.probes}
    if prob.m == 0 or prob.n == 0 or kT <= 0 or not scene.probes:
        return out
    _, lu, eps = _factorised(prob)
    G = _probe_gradients(prob, scene)
    for k, pr in enumerate(scene.probes):
        g = G[:, k]
        if float(np.linalg.norm(g)) < 1e-9:  # both ends on one body: rigid, no spread
            out[pr.name] = 0.0
            continue
        y = lu.solve(g)
        # a component of g along a zero mode shows up as a 1/eps blow-up: no finite variance
        # (g . y = sum c^2/(lambda + eps); eps |y|^2 is about eps/lambda of it for the stiff
        # modes, and about all of it for a zero mode)
        gy = float(g @ y)
        out[pr.name] = float(np.sqrt(kT * gy)) if eps * float(y @ y) < 0.1 * gy else float("inf")
    return out


def _factorised(prob):
    """(J, LU of H + eps I, eps) for the harmonic analyses: ``H = J^T J`` about the
    problem's poses, regularised by ``eps`` = 1e-10 of its largest diagonal entry so that
    the zero modes (rigid motion, floppy bends) do not make it singular."""
    import scipy.sparse as sp

    from mlc.verify.static import spd_lu

    J = prob.jacobian().tocsr()
    H = (J.T @ J).tocsc()
    eps = 1e-10 * max(float(H.diagonal().max()), 1e-300)
    return J, spd_lu(H + sp.identity(prob.n, format="csc") * eps), eps


def _diag(v):
    import scipy.sparse as sp

    return sp.diags(v, format="csr")


def _smallest_nonzero_sparse(H) -> float:
    """Smallest eigenvalue of the symmetric positive semi-definite ``H`` above its cluster
    of zero modes (shift-invert Lanczos, asking for more eigenvalues until a non-zero
    one shows up)."""
    import scipy.sparse as sp
    from scipy.sparse.linalg import LinearOperator, eigsh

    from mlc.verify.static import spd_lu

    n = H.shape[0]
    lam_max = float(eigsh(H, k=1, which="LA", return_eigenvectors=False, tol=1e-3)[0])
    shift = 1e-7 * lam_max
    lu = spd_lu(H + sp.identity(n, format="csc") * shift)
    op = LinearOperator((n, n), matvec=lu.solve, dtype=float)
    k = 16
    while True:
        k = min(k, n - 2)
        vals = eigsh(op, k=k, which="LM", return_eigenvectors=False)
        ev = np.sort(1.0 / vals - shift)
        nz = ev[ev > ZERO * lam_max]
        if len(nz) or k >= n - 2:
            return float(nz[0]) if len(nz) else 0.0
        k *= 2


def _seed_list(seeds) -> list[int]:
    if isinstance(seeds, (int, np.integer)):
        if seeds < 1:
            raise MlcError(f"seeds must be >= 1, got {seeds}", "--seeds", "give at least one seed")
        return list(range(int(seeds)))
    out = [int(s) for s in seeds]
    if not out:
        raise MlcError("no seeds given", "--seeds", "give at least one seed")
    return out


def plateau_tol(kT: float, k0: float = 1.0, sd: float = 0.0, tau: float = 0.0, block: float = 1.0) -> float:
    """How far (sigma) two block means of a relaxed probe may differ: ``2e-3 + 3 sqrt(kT/k0)``
    plus three standard deviations of the difference of two block means of length
    ``block`` t0 of a probe with thermal standard deviation ``sd`` (sigma) and correlation
    time at most ``tau`` t0: ``3 sqrt(2) sd sqrt(min(1, 2 tau / block))``."""
    base = 2e-3 + 3.0 * math.sqrt(max(kT, 0.0) / k0)
    if not sd:
        return base
    if not math.isfinite(sd):
        return math.inf
    return base + 3.0 * math.sqrt(2.0) * sd * math.sqrt(min(1.0, 2.0 * tau / max(block, 1e-300)))


def plateau_start(ends: list, window: float, t: float) -> int:
    """The index of the first window on the plateau of a run at time ``t`` (t0) whose windows of
    ``window`` t0 ended at ``ends``: the windows that started in the last ``PLATEAU`` of the run,
    at least ``MIN_WINDOWS`` of them (negative while fewer windows have run)."""
    first = len(ends) - MIN_WINDOWS
    cut = (1.0 - PLATEAU) * t
    while first > 0 and ends[first - 1] - window >= cut - 1e-12:
        first -= 1
    return first


def relax_all(sim: Simulation, probes: list[str], kT: float, t_min: float = 0.0, window: float = WINDOW,
              max_time: float = MAX_TIME, sd: dict | None = None, tau: float = 0.0, on_window=None):
    """Run ``sim`` until every probe in ``probes`` has relaxed: time >= ``t_min`` t0, and the
    three block means of the last third of the run (at least ``MIN_WINDOWS`` windows of
    ``window`` t0) agree within :func:`plateau_tol` (``sd``: probe -> thermal standard
    deviation in sigma, ``tau``: slowest relaxation time in t0).  Returns (means: probe ->
    plateau mean in sigma, time t0, relaxed).  ``on_window(t)``, if given, is called after
    every window with the time run so far (t0)."""
    sd = sd or {}
    ends, means = [], {p: [] for p in probes}
    t = 0.0
    start = sim.t / sim.t_unit
    while True:
        res = sim.run(window, record_interval=window / 10, quiet=True)
        if getattr(res, "interrupted", False):      # Ctrl-C inside the run
            raise KeyboardInterrupt
        t = res.time - start
        ends.append(t)
        if on_window is not None:
            on_window(t)
        for p in probes:
            v = res.probes[p]
            means[p].append(float(np.mean(v[1:] if len(v) > 1 else v)))
        first = plateau_start(ends, window, t)          # the plateau: the last third of the run
        if first >= 0 and t >= t_min - 1e-12:
            block = (len(ends) - first) * window / MIN_WINDOWS
            flat = all(np.ptp([np.mean(b) for b in np.array_split(means[p][first:], MIN_WINDOWS)])
                       < plateau_tol(kT, sim.k0, sd.get(p, 0.0), tau, block) for p in probes)
            if flat:
                return {p: float(np.mean(means[p][first:])) for p in probes}, t, True
        if t >= max_time - 1e-12:
            k = max(len(ends) - MIN_WINDOWS, 0)
            return {p: float(np.mean(means[p][k:])) for p in probes}, t, False


def check_scene_dynamic_multi(scene, kT: float = 1e-5, seeds=3, scheme: str = "stiff", rows=None,
                              progress=None, dt: float | None = None, tau_factor: float = TAU_FACTOR,
                              max_time: float | None = None, window: float | None = None,
                              tau: float | None = None, cache: dict | None = None) -> list[dict]:
    """Brownian-dynamics check of ``scene`` against its truth table (any number of inputs,
    outputs and probes).  For each input row (``rows``: bit strings in ``scene.inputs``
    order, default all) and seed (``seeds``: a count, meaning seeds 0..n-1, or a list),
    start from the scene's poses at rest, switch the inputs to the row and run until every
    probe has relaxed (see the module docstring).

    Returns one row per (input row, probe), in row then probe order, with keys: state,
    output, probe, expected (0/1, or None for a don't-care), measured (sigma, mean over
    seeds), bit, margin (sigma, smallest over seeds; None for a don't-care), ok,
    relaxed, relax_time (t0, largest over seeds; None if a seed did not relax),
    per_seed (the measured value of each seed), seeds, tau (t0), scheme, kT, dt (t0: the
    step asked of the integrator, None for its own; a run's steps are at most one averaging window).

    ``progress``: None (a bar on a terminal for long runs), False (silent), True (a
    bar) or a callable ``f(done, total)`` called after each (row, seed) run.  ``dt`` (t0):
    default ``DT_LARGE`` for a scene of more than ``DENSE_MAX`` / 6 bodies, else ``DT``.  ``tau``
    (t0): the slowest relaxation time, if already known, used for every row (default
    :func:`relaxation_time` at the starting pose and at each row's static equilibrium,
    the larger of the two; for a scene of more than ``DENSE_MAX`` / 6 bodies, a circuit,
    :func:`signal_time` of the row's switch at the same two poses, the larger of the two:
    a circuit's chains have hundreds of near-zero bending modes that slow the sparse
    eigensolver to minutes, while the step response needs two solves per probe; on
    connector chains it is pi^2/8 times the slowest relaxation time, the ratio for a
    diffusing line driven at one end).
    ``max_time`` (t0): give up on a run after this long (default the larger of 20 t0 and
    12 tau of the row).  ``window`` (t0): averaging window (default the larger of 0.05 t0 and tau/20).
    ``cache``: a dict kept by a caller that checks the same scene row by row or seed by seed
    in several calls (a campaign): each row's static preparation (its equilibrium, the
    probes' thermal spread and its signal times, all deterministic) is stored there and
    reused, so a later call on the same row and kT gives the same numbers without redoing it
    (a fifth of a 4-to-1 multiplexer's run).  Only for one scene: the keys do not name it."""
    from mlc.io.progress import Progress
    from mlc.verify.static import equilibrium

    from mlc.verify.circuit import select_rows

    states = select_rows(scene, rows)          # truth table, probes and the rows, checked
    check_kT(kT)
    seed_list = _seed_list(seeds)
    opt0 = SimOptions(scheme=scheme)
    tau_given = tau is not None
    large = 6 * len(scene.bodies) > DENSE_MAX      # a circuit: signal_time, not the spectrum
    if dt is None:     # the step: 0.2 t0 for a circuit with the stiff scheme, else the scheme's own
        dt = (DT_LARGE if large else DT).get(scheme)
    if tau_given:
        tau = float(tau)
    elif large:   # the rest row has no switch of its own: its floor is the slowest of all rows
        rows_t = select_rows(scene) if "0" * len(scene.inputs) in states else states
        memo = cache.setdefault("t_start", {}) if cache is not None else {}
        for s in rows_t:
            if s not in memo:
                memo[s] = signal_time(scene, "0" * len(scene.inputs), s, gamma_r=opt0.gamma_r)
        t_start = {s: memo[s] for s in rows_t}
        tau = max(list(t_start.values()) + [0.0])
    else:
        tau = relaxation_time(scene, gamma_r=opt0.gamma_r)
    max_time_given = max_time is not None
    max_time = float(max_time) if max_time_given else None
    window = max(WINDOW, tau / 20.0) if window is None else float(window)
    rest = "0" * len(scene.inputs)
    names = [p.name for p in scene.probes]
    total = len(states) * len(seed_list)
    out = []
    show = None if progress is None else (progress if isinstance(progress, bool) else False)
    bar = Progress(f"dynamic check of {scene.name}", total=total, show=show)
    done = 0
    warned = False
    with bar:
        for state in states:
            want = scene.truth_table.get(state)
            drives = {inp: Drive.constant(int(bit)) for inp, bit in zip(scene.inputs, state)}
            # the row's static equilibrium: the probes' thermal spread and the relaxation time
            # there (the slowest of start and end pose sets the time floor)
            key = ("row", state, kT, tau if tau_given or (large and state == rest) else None)
            if cache is not None and key in cache:
                sd, tau_row = cache[key]
            else:
                try:
                    eq = equilibrium(scene, state, levels="depth")   # as the static check solves it
                    sd = probe_thermal_sd(scene, kT, eq.pos, eq.quat)
                    if tau_given:
                        tau_row = tau
                    elif large and state == rest:     # no switch: the probes' correlation time
                        tau_row = tau
                    elif large:
                        tau_row = max(t_start[state], signal_time(scene, rest, state, eq.pos, eq.quat, opt0.gamma_r))
                    else:
                        tau_row = max(tau, relaxation_time(scene, eq.pos, eq.quat, opt0.gamma_r))
                except (MlcError, ValueError, RuntimeError, np.linalg.LinAlgError):
                    sd, tau_row = probe_thermal_sd(scene, kT), tau
                if cache is not None:
                    cache[key] = (sd, tau_row)
            t_min = tau_factor * tau_row if state != rest else 0.0
            per = []
            # within a run the bar moves with the time run over the time it usually takes:
            # the floor t_min, or MIN_WINDOWS windows (runs relax at the floor as a rule)
            t_expect = max(t_min, MIN_WINDOWS * window)
            for seed in seed_list:
                opt = SimOptions(scheme=scheme, kT=kT, seed=seed, dt=dt)
                sim = Simulation(scene, drives, opt)
                t_max = max_time if max_time_given else max(MAX_TIME, MAX_TAUS * tau_row)
                if scheme == "euler" and not warned and show is not False and t_expect / sim.dt > SLOW_STEPS:
                    warned = True
                    print(f"mlc: warning: --scheme euler: this scene's stiffest bonds allow dt = {sim.dt:.2g} t0, "
                          f"so row {state} needs about {t_expect / sim.dt:.1e} steps (at least {t_expect:.3g} t0); "
                          "that can take days: use --scheme stiff (the default), or --rows to check fewer rows",
                          file=sys.stderr, flush=True)
                inner = bar.within(done, t_expect)
                means, t_rel, relaxed = relax_all(sim, names, kT, t_min, window, t_max, sd, tau_row, inner)
                per.append((means, t_rel, relaxed))
                done += 1
                bar.update(done)
                if callable(progress):
                    progress(done, total)
            for pr in scene.probes:
                idx = scene.outputs.index(pr.output)
                bit = None if want is None or want[idx] == "-" else int(want[idx])
                vals = [m[pr.name] for m, _, _ in per]
                mean = float(np.mean(vals))
                relaxed = all(r for _, _, r in per)
                margins = None if bit is None else [float(pr.margin(v, bit)) for v in vals]
                ok = relaxed and (bit is None or all(pr.bit(v) == bit and m > 0 for v, m in zip(vals, margins)))
                out.append({"state": state, "output": pr.output, "probe": pr.name, "expected": bit,
                            "measured": mean, "bit": pr.bit(mean),
                            "margin": None if margins is None else min(margins), "ok": bool(ok),
                            "relaxed": relaxed,
                            "relax_time": max(t for _, t, _ in per) if relaxed else None,
                            "per_seed": vals, "seeds": seed_list, "tau": tau_row, "thermal_sd": sd[pr.name],
                            "scheme": scheme, "kT": kT, "dt": dt})
    return out


__all__ = ["check_scene_dynamic_multi", "plateau_tol", "probe_thermal_sd", "relax_all", "relaxation_time",
           "signal_time"]
