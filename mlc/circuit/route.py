"""Routing: a connector chain from one signal pair to another, by inverse kinematics.

A chain of ``n`` half units is fixed by its start pair (centre ``c0``, axis ``u0``), its
first tangent and the bend at every junction (:func:`mlc.gates.connector.chain_frames`:
junction ``i`` turns the next tangent about the junction's pair axis).  Routing finds
bends such that the last pair lands on the target pair:

* centre ``c_n = P`` (3 equations) and axis ``u_n = +-a`` (2 equations), to within
  ``EXACT`` (1e-7 sigma; the closing passes stop at the first evaluation within a tenth of
  it): the joints close exactly when the scene is built;
* the last tangent points along ``approach`` (the side the target is open to), softly;
* the chain passes near ``waypoints`` (fractions of its length), softly;
* every bend within ``+-bend_max`` (bounds), so neighbouring layers never touch;
* smallest bends otherwise (a weak term).

``n`` has the parity the signal needs (every half unit is a NOT) and grows from the
steered guess until the equations close.  The solve is scipy's bounded trust region
(dense Jacobian, one SVD per iteration), so its cost grows faster than ``n``: the
reason circuit builds scale worse than linearly (docs/circuits.md).  Units: sigma, radians.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from numba import njit
from scipy.optimize import least_squares
from scipy.spatial import cKDTree

from mlc.gates.connector import ConnectorGeometry, max_bend

BEND_FRACTION = 0.75         # routing bends at most this fraction of the geometric largest bend
EXACT = 1e-7                 # sigma: the last pair must land this close
PASSES = (1.0, 1e-5)         # weights of the soft terms: shape the chain, then close it exactly
DEBUG = False
SHAPE_TOL = 1e-5           # relative cost change that ends the shaping pass
STATS = None               # a list to collect (n, pass, evaluations, status, closure) per solve
AVOID_WEIGHT = 30.0        # weight of the keep-away terms (``avoid``) against the waypoints' 1
EARLY_CLOSE = True         # the closing passes stop at the first evaluation that closes to CLOSE_MARGIN * EXACT
CLOSE_MARGIN = 0.1
MAX_HALF = 400             # half units of the longest chain tried (the steered guess is cut there)
POLISH_FROM = 1e-3         # sigma: when no length closes, those whose passes ended this close are polished
POLISH_STEPS = 12          # Newton steps of _polish at most


@dataclass
class Route:
    """A solved chain: start pair, first tangent (before bends[0]), bends (rad)."""

    centre: np.ndarray
    axis: np.ndarray
    tangent: np.ndarray
    bends: list
    error: float                 # distance of the last pair from the target (sigma)
    approach_error: float        # |t_last - approach| (0 = straight on)

    @property
    def n(self) -> int:
        return len(self.bends)


def _perp_basis(a):
    a = a / np.linalg.norm(a)
    h = np.array([1.0, 0, 0]) if abs(a[0]) < 0.9 else np.array([0, 1.0, 0])
    e1 = np.cross(a, h)
    e1 /= np.linalg.norm(e1)
    return e1, np.cross(a, e1)


def _project_perp(v, u):
    v = np.asarray(v, float) - float(np.dot(v, u)) * u
    n = np.linalg.norm(v)
    return v / n if n > 1e-9 else None


def _bezier(p0, d0, p3, d3, k=64):
    """Points of the cubic Bezier from p0 (leaving along d0) to p3 (arriving along d3)."""
    L = float(np.linalg.norm(p3 - p0))
    p1, p2 = p0 + 0.4 * L * d0, p3 - 0.4 * L * d3
    b0, b1, b2, b3 = _bernstein(k)
    return b0 * p0 + b1 * p1 + b2 * p2 + b3 * p3


@lru_cache(maxsize=4)
def _bernstein(k: int):
    """The cubic Bernstein weights at ``k`` points from 0 to 1, each a (k, 1) column, computed
    as the Bezier's expression computes them (the same numbers, made once)."""
    s = np.linspace(0.0, 1.0, k)[:, None]
    return (1 - s) ** 3, 3 * (1 - s) ** 2 * s, 3 * (1 - s) * s ** 2, s ** 3


def _steer(c0, u0, t0, guide, pitch, bmax, free_start, max_half):
    """Bends that make a chain follow the polyline ``guide`` (pure pursuit, one pitch of
    look-ahead); stops when the chain is within a pitch of the guide's end."""
    end = guide[-1]
    bends, c, u, t = [], np.array(c0, float), np.array(u0, float), np.array(t0, float)
    seg = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(guide, axis=0), axis=1))])
    for i in range(max_half):
        # closest guide point, then look ahead by 2 pitches
        j = int(np.argmin(np.linalg.norm(guide - c, axis=1)))
        s_goal = seg[j] + 2.0 * pitch
        k = int(np.searchsorted(seg, s_goal))
        goal = guide[min(k, len(guide) - 1)]
        d = goal - c
        dp = d - float(d @ u) * u
        lim = float(free_start) if i == 0 else bmax
        if np.linalg.norm(dp) > 1e-9 and lim > 0:
            dp /= np.linalg.norm(dp)
            ang = math.atan2(float(np.cross(t, dp) @ u), float(t @ dp))
            b = max(-lim, min(lim, ang))
        else:
            b = 0.0
        t = _rot(t, u, b)
        bends.append(b)
        c = c + pitch * t
        u = np.cross(t, u)
        if float(np.linalg.norm(end - c)) < 0.75 * pitch and seg[j] > seg[-1] - 3 * pitch:
            break
        if seg[j] >= seg[-1] - 1e-9 and float(np.linalg.norm(end - c)) < 3.0 * pitch:
            break                   # passed the guide's end close by: the solve closes the rest
        if i * pitch > 2.0 * seg[-1] + 20.0 * pitch:
            break                   # lost the guide: stop (the solve starts from here)
    return bends


@njit(cache=True)
def _steer_kernel(c0, u0, t0, guide, seg, pitch, bmax, lim0, m, eb, max_half, out):
    """:func:`_steer` for the fast method, compiled: the bound of junction i is ``lim0``
    for i = 0, ``eb`` for 1 <= i <= m, ``bmax`` after.  Writes the bends into ``out``
    and returns their count."""
    c = c0.copy()
    u = u0.copy()
    t = t0.copy()
    G = guide.shape[0]
    end = guide[G - 1]
    total = seg[G - 1]
    count = 0
    for i in range(max_half):
        j = 0
        best = np.inf
        for q in range(G):
            dd = (guide[q, 0] - c[0]) ** 2 + (guide[q, 1] - c[1]) ** 2 + (guide[q, 2] - c[2]) ** 2
            if dd < best:
                best, j = dd, q
        k = np.searchsorted(seg, seg[j] + 2.0 * pitch)
        if k > G - 1:
            k = G - 1
        d = guide[k] - c
        du = d[0] * u[0] + d[1] * u[1] + d[2] * u[2]
        dp = d - du * u
        ndp = math.sqrt(dp[0] ** 2 + dp[1] ** 2 + dp[2] ** 2)
        lim = lim0 if i == 0 else (eb if i <= m else bmax)
        b = 0.0
        if ndp > 1e-9 and lim > 0:
            dp = dp / ndp
            cx = t[1] * dp[2] - t[2] * dp[1]
            cy = t[2] * dp[0] - t[0] * dp[2]
            cz = t[0] * dp[1] - t[1] * dp[0]
            ang = math.atan2(cx * u[0] + cy * u[1] + cz * u[2], t[0] * dp[0] + t[1] * dp[1] + t[2] * dp[2])
            b = max(-lim, min(lim, ang))
        cb, sb = math.cos(b), math.sin(b)
        kx = u[1] * t[2] - u[2] * t[1]
        ky = u[2] * t[0] - u[0] * t[2]
        kz = u[0] * t[1] - u[1] * t[0]
        kd = u[0] * t[0] + u[1] * t[1] + u[2] * t[2]
        t = np.array([t[0] * cb + kx * sb + u[0] * kd * (1.0 - cb), t[1] * cb + ky * sb + u[1] * kd * (1.0 - cb),
                      t[2] * cb + kz * sb + u[2] * kd * (1.0 - cb)])
        out[count] = b
        count += 1
        c = c + pitch * t
        u = np.array([t[1] * u[2] - t[2] * u[1], t[2] * u[0] - t[0] * u[2], t[0] * u[1] - t[1] * u[0]])
        de = math.sqrt((end[0] - c[0]) ** 2 + (end[1] - c[1]) ** 2 + (end[2] - c[2]) ** 2)
        if de < 0.75 * pitch and seg[j] > total - 3.0 * pitch:
            break
        if seg[j] >= total - 1e-9 and de < 3.0 * pitch:
            break
        if i * pitch > 2.0 * total + 20.0 * pitch:
            break
    return count


_BLAS = None                # [(set, get)] of the OpenBLAS libraries loaded (see blas_single_thread)


def _blas_controls() -> list:
    """(set_num_threads, get_num_threads) of every OpenBLAS the process has loaded (numpy's
    and scipy's wheels each bundle one, with prefixed names); [] where none is found."""
    global _BLAS
    if _BLAS is None:
        import ctypes
        found = []
        try:
            with open("/proc/self/maps") as f:
                paths = sorted({ln.split()[-1] for ln in f if "openblas" in ln.lower() and ".so" in ln})
        except OSError:
            paths = []
        for path in paths:
            try:
                lib = ctypes.CDLL(path)
            except OSError:
                continue
            for pre, suf in (("scipy_", ""), ("scipy_", "64_"), ("", ""), ("", "64_")):
                st = getattr(lib, f"{pre}openblas_set_num_threads{suf}", None)
                gt = getattr(lib, f"{pre}openblas_get_num_threads{suf}", None)
                if st is not None and gt is not None:
                    st.argtypes, st.restype, gt.restype = [ctypes.c_int], None, ctypes.c_int
                    found.append((st, gt))
                    break
        _BLAS = found
    return _BLAS


class blas_single_thread:
    """Run the block with every loaded OpenBLAS on one thread, then restore its count.

    The solve's dense SVDs (scipy's trust region, 50-300 rows) gain nothing from a second
    thread, and on a shared, loaded machine OpenBLAS's threads wait for each other: a
    277 x 120 SVD took 1.77 s of wall time (0.88 s of CPU) with 2 threads while another
    process ran, against 6 ms with one.  One thread gives the same bits (the full adder's
    scene has the same sha256 either way).  Not re-entrant across threads."""

    def __enter__(self):
        self.saved = []
        for st, gt in _blas_controls():
            n = gt()
            self.saved.append((st, n))
            if n != 1:
                st(1)
        return self

    def __exit__(self, *exc):
        for st, n in self.saved:
            if n != 1:
                st(n)
        return False


CACHE_SIZE = 512            # solves remembered (see solve_route); 0: none
_CACHE: dict = {}
CACHE_HITS = [0, 0]        # [hits, misses] since import (benchmarks report them)
_PENDING: dict = {}        # key -> Future of the same solve started ahead in another process (Prefetch)
PREFETCH = [0, 0]          # [solves started ahead, of them taken by solve_route] since import


def _key(v):
    """An exact, hashable key of a solve's argument: arrays and numbers by their bytes (so
    -0.0 and 0.0, or two floats one ulp apart, are different keys), containers item by item."""
    if isinstance(v, (bool, int, str, type(None))):
        return v
    if isinstance(v, (float, np.floating)):
        return np.float64(v).tobytes()
    if isinstance(v, np.ndarray):
        return (v.dtype.str, v.shape, np.ascontiguousarray(v).tobytes())
    if isinstance(v, (list, tuple)):
        return tuple(_key(x) for x in v)
    if isinstance(v, dict):
        return tuple(sorted((k, _key(x)) for k, x in v.items()))
    if isinstance(v, ConnectorGeometry):
        return repr(v)              # a frozen dataclass of numbers: repr round-trips every float
    raise TypeError(type(v))


def solve_route(*args, **kw) -> Route | None:
    """See :func:`_solve_route`; a chain steered far off (a failed length) may overflow on
    the way, which only means that length does not close: the warnings are not shown.

    The solve is a pure function of its arguments, so a repeated solve with bit-identical
    arguments (the circuit builder's second build re-routes most wires exactly as the
    first did) returns the remembered result (a copy) instead of solving again: the same
    route, bit for bit.  So does a solve started ahead in another process (:class:`Prefetch`)."""
    key = None
    if CACHE_SIZE > 0:
        try:
            key = (_key(args), _key(kw))
        except TypeError:           # an argument of another kind: solve without the cache
            key = None
        if key is not None and key in _CACHE:
            CACHE_HITS[0] += 1
            r = _CACHE[key]
            return None if r is None else Route(r.centre.copy(), r.axis.copy(), r.tangent.copy(), list(r.bends),
                                                r.error, r.approach_error)
    fut = _PENDING.pop(key, None) if key is not None else None
    r = _taken(fut)
    if r is _NOT_TAKEN:
        r = _solve_plain(args, kw)
    if key is not None:
        CACHE_HITS[1] += 1
        if len(_CACHE) >= CACHE_SIZE:
            _CACHE.pop(next(iter(_CACHE)))          # oldest first
        _CACHE[key] = None if r is None else Route(r.centre.copy(), r.axis.copy(), r.tangent.copy(),
                                                   list(r.bends), r.error, r.approach_error)
    return r


_NOT_TAKEN = object()


def _taken(fut):
    """The result of a solve started ahead (:class:`Prefetch`), waiting for it if it runs;
    ``_NOT_TAKEN`` where there is none, where it has not started (it is cancelled), or where
    it failed (the caller then solves it here: the same pure function, so the same route)."""
    if fut is None or fut.cancel():     # none, or not started yet: quicker here than queued
        return _NOT_TAKEN
    try:
        r = fut.result()
    except BaseException as e:          # cancelled, or its process died: solve it here
        if isinstance(e, (KeyboardInterrupt, SystemExit)):
            raise
        return _NOT_TAKEN
    PREFETCH[1] += 1
    return r


def _solve_plain(args, kw):
    """:func:`_solve_route` itself, without the cache or the solves started ahead: what both
    :func:`solve_route` and the processes of :class:`Prefetch` run (these must bypass their
    copies of the cache and of the started solves: a copy of a running solve's Future would
    never end).  A chain steered far off may overflow on the way, which only means that
    length does not close: the warnings are not shown."""
    import warnings
    with np.errstate(all="ignore"), warnings.catch_warnings(), blas_single_thread():
        warnings.simplefilter("ignore", RuntimeWarning)
        return _solve_route(*args, **kw)


class Prefetch:
    """Solves started ahead, each in a forked process, while this one routes.

    The router is sequential: a chain's route depends on the chains placed before it (its
    plane, the layers it keeps away from).  But the first solve of a chain, in the plane
    the lanes would give it, depends only on its own geometry and that plane, so the
    builder starts it (:meth:`submit`) for the next ``jobs - 1`` chains while it routes the
    current one, guessing their planes from the lanes taken so far.  :func:`solve_route`
    takes a started solve only for bit-identical arguments (the cache's key): a wrong
    guess costs the other process's time, never a different route, so the scene is the
    same, bit for bit, for any ``jobs``.  ``jobs`` = 1, or where processes cannot be
    forked: nothing is started ahead."""

    def __init__(self, jobs: int = 1):
        self.jobs = max(int(jobs), 1)
        self.ex = None
        self.mine: dict = {}            # owner tag -> the keys it started

    def __enter__(self):
        from mlc.verify.circuit import _can_fork
        if self.jobs > 1 and CACHE_SIZE > 0 and _can_fork():
            import multiprocessing
            from concurrent.futures import ProcessPoolExecutor
            self.ex = ProcessPoolExecutor(max_workers=self.jobs - 1, mp_context=multiprocessing.get_context("fork"))
        return self

    def submit(self, owner: str, *args, **kw) -> None:
        """Start ``solve_route(*args, **kw)`` in another process (once per key) for ``owner``."""
        if self.ex is None:
            return
        try:
            key = (_key(args), _key(kw))
        except TypeError:
            return
        if key in _CACHE or key in _PENDING:
            return
        try:
            _PENDING[key] = self.ex.submit(_solve_plain, args, kw)
        except RuntimeError:            # the pool is broken (a process died): route without it
            self.ex = None
            return
        PREFETCH[0] += 1
        self.mine.setdefault(owner, []).append(key)

    def drop(self, owner: str) -> None:
        """``owner`` is routed: its solves not taken are of no more use (cancelled where not started)."""
        for key in self.mine.pop(owner, []):
            fut = _PENDING.pop(key, None)
            if fut is not None:
                fut.cancel()

    def __exit__(self, *exc):
        for owner in list(self.mine):
            self.drop(owner)
        if self.ex is not None:             # a solve still running ends on its own, unwaited for
            self.ex.shutdown(wait=False, cancel_futures=True)
        return False


def _solve_route(c0, u0, target_c, target_a, geo: ConnectorGeometry, parity: int, *,
                tangent=None, free_start: bool = True, approach=None, waypoints=(),
                min_half: int = 2, max_half: int = MAX_HALF, bend_max: float | None = None,
                last_pitch: float | None = None, start_bend_max: float = math.radians(50.0),
                extras=(0, 2, 4, 8, 12, 16, 24), end_bends: tuple[int, float] | None = None,
                 wp_weight: float = 0.3, avoid=(), avoid_from: int = 0, polish: bool = True,
                 method: str = "ik") -> Route | None:
    """A chain from pair (c0, u0) to pair (target_c, +-target_a) with ``n % 2 == parity``
    half units; None when no chain closes.

    ``tangent``: the first tangent (perpendicular to u0); with ``free_start`` the first
    bend may turn it about u0 (a chain hung on a floppy pair) by up to ``start_bend_max``,
    otherwise it is fixed.
    ``approach``: unit vector the last tangent should follow.  ``waypoints``: points the
    chain should pass (in order).  The bends are first found by steering along a smooth
    guide curve through the waypoints, then refined by inverse kinematics.  ``extras``:
    the chain lengths tried, in half units beyond the steered guess (fewer: faster failure).
    ``wp_weight``: weight of the waypoints against the exact equations (10).
    ``end_bends = (m, b)``: the ``m`` junctions after the first and the last ``m`` bend at
    most ``b`` (rad), leaving room for the levers at both ends to move the chain between
    rows.
    ``avoid``: ``(points, distance)`` sets (sigma): the soft passes push every layer
    centre from the ``avoid_from``-th on (see ``lanes.layer_centres``) towards at least
    ``distance`` from each set's points (a one-sided term of weight ``AVOID_WEIGHT``,
    scaled like the waypoints: the closing passes keep the shape but do not enforce it).
    ``polish``: when no length closes, the lengths whose passes ended within ``POLISH_FROM``
    of closing (approach kept) are closed by :func:`_polish`, shortest first; a route that
    closes without it is the same with or without it.
    ``method``: "ik", the whole chain solved by scipy's trust region as above; or "fast"
    (:func:`_solve_fast`): the steered chain closed by moving mostly its last bends, with
    the trust region as the fallback where that does not close; with ``avoid``, the fast
    route pushed away by :func:`_fast_avoid` (the trust region where that does not close)."""
    c0, u0 = np.asarray(c0, float), np.asarray(u0, float) / np.linalg.norm(u0)
    P, a = np.asarray(target_c, float), np.asarray(target_a, float) / np.linalg.norm(target_a)
    e1, e2 = _perp_basis(a)
    bmax = BEND_FRACTION * max_bend(geo) if bend_max is None else bend_max
    if tangent is None:
        tangent = _project_perp(P - c0, u0)
        if tangent is None:
            tangent = _perp_basis(u0)[0]
    t0 = _project_perp(tangent, u0)
    app = None if approach is None else np.asarray(approach, float) / np.linalg.norm(approach)
    guide = _guide(c0, t0, waypoints, P, app)
    if method == "fast":
        r = _solve_fast(c0, u0, t0, P, e1, e2, app, guide, waypoints, geo, parity, bmax,
                        free_start and start_bend_max, min_half, max_half, last_pitch, extras, end_bends,
                        wp_weight)
        if r is not None and len(avoid):
            r = _fast_avoid(r, P, e1, e2, app, geo, last_pitch, bmax, free_start and start_bend_max,
                            end_bends, avoid, avoid_from)
        if r is not None:
            return r
    guess = _steer(c0, u0, t0, guide, geo.pitch, bmax, free_start and start_bend_max, max_half)
    near = []                   # (n, pitches, route) of the lengths that nearly closed
    for extra in extras:
        n = max(min_half, len(guess) + extra)
        if n % 2 != parity:
            n += 1
        x0 = np.nan_to_num(np.array((guess + [0.0] * n)[:n]))
        pitches = np.full(n, geo.pitch)
        if last_pitch is not None:
            pitches[-1] = last_pitch
        cs_g, _, _ = _fk(c0, u0, t0, x0, pitches)
        wps = [(max(1, min(n - 1, int(np.argmin(np.linalg.norm(cs_g - np.asarray(w, float), axis=1))))),
                np.asarray(w, float)) for w in waypoints]
        try:
            r = _solve_n(n, c0, u0, t0, P, e1, e2, app, x0, pitches, bmax, free_start and start_bend_max, wps,
                         end_bends, wp_weight, avoid, avoid_from)
        except ValueError:          # a degenerate start (non-finite residuals): try the next length
            continue
        if DEBUG:
            print("len", n, "error", r.error, "approach", r.approach_error)
        if r.error < EXACT and r.approach_error < 0.5:
            return r
        if polish and r.error < POLISH_FROM and r.approach_error < 0.5:
            near.append((n, pitches, r))
    for n, pitches, r in near:
        lo, hi = _bounds(n, bmax, free_start and start_bend_max, end_bends)
        x = _polish(np.array(r.bends), lo, hi, c0, u0, t0, pitches, P, e1, e2)
        cs, us, ts = np.empty((n + 1, 3)), np.empty((n + 1, 3)), np.empty((n, 3))
        _fk_kernel(c0, u0, t0, x, pitches, cs, us, ts, True)
        err = _closure_error(cs, us, P, e1, e2)
        aerr = 0.0 if app is None else float(np.linalg.norm(ts[-1] - app))
        if DEBUG:
            print("polished", n, "error", r.error, "->", err, "approach", aerr)
        if err < EXACT and aerr < 0.5:
            return Route(c0, u0, t0, [float(v) for v in x], err, aerr)
    return None


def _solve_fast(c0, u0, t0, P, e1, e2, app, guide, waypoints, geo, parity, bmax, start_lim, min_half,
                max_half, last_pitch, extras, end_bends, wp_weight) -> Route | None:
    """The ``fast`` method: the chain steered along ``guide`` (every bend within its bound),
    then closed by :func:`_lm_close`, whose bend changes fall off as exp(-d / FAST_TAIL)
    with the distance d (half units) from the chain's end, in two passes: the last pair
    towards the target with the approach and the waypoints of the last ``FAST_HOLD`` half
    units holding the shape, then the closure alone, exactly.  Each pass solves a system
    of the equations' size (5 to ~70), not of the chain's, so a solve costs about as much
    for 400 half units as for 40.  The lengths tried: the steered one less 2 half units
    (the steering stops within a pitch past the target), then ``extras`` beyond it.  None
    when no length closes."""
    m, eb = end_bends if end_bends is not None else (0, bmax)
    lim0 = float(start_lim) if start_lim else 0.0

    guide = np.ascontiguousarray(guide, dtype=np.float64)
    seg = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(guide, axis=0), axis=1))])
    buf = np.empty(max_half)
    k = _steer_kernel(np.asarray(c0, float), np.asarray(u0, float), np.asarray(t0, float), guide, seg,
                      float(geo.pitch), float(bmax), lim0, int(m), float(eb), int(max_half), buf)
    guess = [float(v) for v in buf[:k]]
    tried = set()
    for extra in (-2,) + tuple(extras):
        n = max(min_half, len(guess) + extra)
        if n % 2 != parity:
            n += 1
        if n in tried:
            continue
        tried.add(n)
        x0 = np.nan_to_num(np.array((guess + [0.0] * n)[:n]))
        pitches = np.full(n, geo.pitch)
        if last_pitch is not None:
            pitches[-1] = last_pitch
        lo, hi = _bounds(n, bmax, start_lim, end_bends)
        x0 = np.clip(x0, lo, hi)
        scale = np.exp(-(n - 1 - np.arange(n)) / FAST_TAIL)
        cs, _, _ = _fk(c0, u0, t0, x0, pitches)
        wps = []
        for w in waypoints:
            w = np.asarray(w, float)
            k = max(1, min(n - 1, int(np.argmin(np.linalg.norm(cs - w, axis=1)))))
            if k >= n - FAST_HOLD:
                wps.append((k, w))
        x = _lm_close(x0, lo, hi, c0, u0, t0, pitches, P, e1, e2, app, scale, wps, 1.0, wp_weight)
        r = _close_exactly(x, lo, hi, c0, u0, t0, pitches, P, e1, e2, app, scale)
        if r is not None:
            return r
    return None


def _close_exactly(x, lo, hi, c0, u0, t0, pitches, P, e1, e2, app, scale) -> Route | None:
    """The fast method's last pass: :func:`_lm_close` on the closure alone from bends ``x``
    in the metric ``scale``, again with it three times wider where it stalled (bends at
    their bounds: let more bends move); the route if it closes within ``EXACT`` with the
    last tangent within 0.5 of ``app``, else None."""
    n = x.shape[0]
    cs, us, ts = np.empty((n + 1, 3)), np.empty((n + 1, 3)), np.empty((n, 3))
    for widen in (1.0, 3.0):
        x = _lm_close(x, lo, hi, c0, u0, t0, pitches, P, e1, e2, None, scale ** (1.0 / widen), (), 0.0)
        _fk_kernel(c0, u0, t0, x, pitches, cs, us, ts, True)
        err = _closure_error(cs, us, P, e1, e2)
        if err < EXACT:
            break
    aerr = 0.0 if app is None else float(np.linalg.norm(ts[-1] - app))
    if DEBUG:
        print("fast", n, "error", err, "approach", aerr)
    if err < EXACT and aerr < 0.5:
        return Route(c0, u0, t0, [float(v) for v in x], err, aerr)
    return None


def _closure_error(cs, us, P, e1, e2) -> float:
    """How far a chain's last pair is from closing: its centre's distance from ``P`` and
    its axis's components across the target axis (``e1``, ``e2``), the largest (sigma)."""
    return float(max(np.linalg.norm(cs[-1] - P), abs(us[-1] @ e1), abs(us[-1] @ e2)))


def _fast_avoid(route: Route, P, e1, e2, app, geo, last_pitch, bmax, start_lim, end_bends, avoid,
                avoid_from: int) -> Route | None:
    """The ``fast`` method's ``avoid``: the closed ``route`` pushed away from the ``avoid``
    sets, every bend free within its bounds (the push can be needed anywhere along the
    chain), by Levenberg-Marquardt in the row space of the closure and approach (weight
    ``AVOID_CLOSE`` over the trust region's) and of the keep-away rows of the layer
    centres from the ``avoid_from``-th on that are inside their set's distance (the
    trust region's one-sided term, ``AVOID_WEIGHT`` (D - d)), for ``AVOID_STEPS``
    iterations at most; then closed exactly as :func:`_solve_fast` closes (the last bends
    mostly).  None when that closure fails; the caller keeps the pushed route only if it
    is farther from what it avoids."""
    x = np.array(route.bends, float)
    n = x.shape[0]
    c0, u0, t0 = route.centre, route.axis, route.tangent
    pitches = np.full(n, geo.pitch)
    if last_pitch is not None:
        pitches[-1] = last_pitch
    lo, hi = _bounds(n, bmax, start_lim, end_bends)
    sets = [(cKDTree(np.asarray(p, float).reshape(-1, 3)), float(d)) for p, d in avoid if len(p)]
    j0 = min(max(int(avoid_from), 0), n)
    n_av = n - j0
    cs, us, ts = np.empty((n + 1, 3)), np.empty((n + 1, 3)), np.empty((n, 3))
    has_app = app is not None
    app_v = np.zeros(3) if app is None else np.asarray(app, float)
    no_k, no_p = np.zeros(0, np.int64), np.zeros((0, 3))
    head = 5 + (3 if has_app else 0)
    buf = np.empty(head + n - 1)
    Jb = np.empty((head, n))
    near_q = np.zeros((len(sets) * n_av, 3))
    near_d = np.full(len(sets) * n_av, np.inf)
    Ja = np.empty((near_d.size, n))

    def resid(b):
        _fk_kernel(c0, u0, t0, b, pitches, cs, us, ts, True)
        _resid_kernel(cs, us, ts, b, P, e1, e2, has_app, app_v, no_k, no_p, 1.0, 1.0, buf)
        m = 0.5 * (cs[1:] + cs[:-1])[j0:]
        gap = np.zeros(near_d.size)
        for k, (tree, d) in enumerate(sets):
            dist, idx = tree.query(m, distance_upper_bound=d)
            sl = slice(k * n_av, (k + 1) * n_av)
            ok = np.isfinite(dist)
            near_d[sl] = dist
            near_q[sl][ok] = tree.data[idx[ok]]
            gap[sl] = np.where(ok, d - dist, 0.0)
        return np.concatenate([AVOID_CLOSE * buf[:head], AVOID_WEIGHT * gap])

    x = np.clip(x, lo, hi)
    r = resid(x)
    f = float(r @ r)
    mu = 1e-4
    half = np.maximum(0.5 * (hi - lo), 1e-12)
    for _ in range(AVOID_STEPS):
        act = np.concatenate([np.arange(head), head + np.nonzero(r[head:])[0]])
        if act.size == head:
            break
        _jac_kernel(cs, us, ts, e1, e2, has_app, no_k, 1.0, 1.0, Jb)
        _avoid_jac_kernel(cs, us, j0, near_q, near_d, AVOID_WEIGHT, Ja)
        J = np.concatenate([AVOID_CLOSE * Jb[:head], Ja])[act]
        ra = r[act]
        g = J.T @ ra
        D = np.sqrt(np.clip(np.where(g < 0, hi - x, x - lo), 0.0, None) / half)
        A = J * D
        M = A @ A.T
        tr = float(np.trace(M)) / act.size
        while True:
            z = np.linalg.solve(M + mu * tr * np.eye(act.size), -ra)
            x_new = np.clip(x + D * (A.T @ z), lo, hi)
            r_new = resid(x_new)
            f_new = float(r_new @ r_new)
            if f_new < f:
                mu = max(mu / 4.0, 1e-9)
                break
            mu *= 8.0
            if mu > 1e6:
                break
        if mu > 1e6 or f - f_new < 1e-4 * f:
            if f_new < f:
                x = x_new
            break
        x, r, f = x_new, r_new, f_new
    return _close_exactly(x, lo, hi, c0, u0, t0, pitches, P, e1, e2, app,
                          np.exp(-(n - 1 - np.arange(n)) / FAST_TAIL))


AVOID_STEPS = 100           # iterations of the fast method's push away from ``avoid`` at most
AVOID_CLOSE = 1.0           # weight of the closure and approach in that push, over the trust region's
FAST_TAIL = 20.0            # half units: the fast method's bend changes fall off as exp(-d / FAST_TAIL) from the end
FAST_HOLD = 40              # half units: the waypoints this near the end hold the shape while it closes
CLOSE_STEPS = 40            # iterations of a pass of _lm_close at most


def _lm_close(x, lo, hi, c0, u0, t0, pitches, P, e1, e2, app, scale=None, wps=(), w_soft=1.0,
                  wp_weight=1.0) -> np.ndarray:
    """Levenberg-Marquardt on a few equations, in their row space: the closure (the last
    pair's position and axis, weight 10), with ``w_soft`` > 0 the approach (the last
    tangent, weight 2 w_soft) and the waypoints ``wps`` ((index, point), weight
    w_soft wp_weight), inside the bounds: each step is the smallest in the metric
    ``scale`` x the room towards the bound the descent heads for (Coleman and Li), then
    projected onto the bounds (:func:`_lm_close_kernel`, compiled).  Returns the bends (rad)."""
    n = x.shape[0]
    has_app = app is not None and w_soft > 0
    app_v = np.zeros(3) if app is None else np.asarray(app, float)
    wps = [(k, p) for k, p in wps if 0 < k <= n] if w_soft > 0 else []
    wp_k = np.array([k for k, _ in wps], dtype=np.int64)
    wp_p = np.array([p for _, p in wps], dtype=float).reshape(-1, 3)
    sc = np.ones(n) if scale is None else np.ascontiguousarray(scale, dtype=np.float64)
    return _lm_close_kernel(np.array(x, dtype=np.float64), np.asarray(lo, float), np.asarray(hi, float),
                            np.asarray(c0, float), np.asarray(u0, float), np.asarray(t0, float),
                            np.asarray(pitches, float), np.asarray(P, float), np.asarray(e1, float),
                            np.asarray(e2, float), has_app, app_v, wp_k, wp_p, float(w_soft), float(wp_weight), sc,
                            CLOSE_STEPS, 10.0 * EXACT * CLOSE_MARGIN)


@njit(cache=True)
def _lm_close_kernel(x, lo, hi, c0, u0, t0, pitches, P, e1, e2, has_app, app, wp_k, wp_p, w_soft, wp_weight, sc,
                     steps, close_tol):
    """:func:`_lm_close`'s iterations: at most ``steps``; the closure alone stops within
    ``close_tol`` (its rows' largest residual); with soft rows, at a relative decrease
    under 1e-6; a step refused until the damping passes 1e6 ends it."""
    n = x.shape[0]
    cs, us, ts = np.empty((n + 1, 3)), np.empty((n + 1, 3)), np.empty((n, 3))
    rows = 5 + (3 if has_app else 0) + 3 * wp_k.shape[0]
    J = np.empty((rows, n))                 # the rows used: not the small-bend rows
    out = np.empty(rows + (n - 1))
    half = np.empty(n)
    for i in range(n):
        half[i] = max(0.5 * (hi[i] - lo[i]), 1e-12)
        x[i] = min(max(x[i], lo[i]), hi[i])
    _fk_kernel(c0, u0, t0, x, pitches, cs, us, ts, True)
    _resid_kernel(cs, us, ts, x, P, e1, e2, has_app, app, wp_k, wp_p, w_soft, wp_weight, out)
    r = out[:rows].copy()
    f = 0.0
    for k in range(rows):
        f += r[k] * r[k]
    mu = 1e-6
    D = np.empty(n)
    A = np.empty((rows, n))
    M = np.empty((rows, rows))
    x_new = np.empty(n)
    for _ in range(steps):
        if rows == 5:
            big = 0.0
            for k in range(5):
                big = max(big, abs(r[k]))
            if big < close_tol:
                break
        _jac_kernel(cs, us, ts, e1, e2, has_app, wp_k, w_soft, wp_weight, J)
        for i in range(n):
            g = 0.0
            for k in range(rows):
                g += J[k, i] * r[k]
            room = hi[i] - x[i] if g < 0 else x[i] - lo[i]
            D[i] = sc[i] * math.sqrt(max(room, 0.0) / half[i])
            for k in range(rows):
                A[k, i] = J[k, i] * D[i]
        M[:, :] = np.dot(A, A.T)
        tr = 0.0
        for a in range(rows):
            tr += M[a, a]
        tr /= rows
        f_new = f
        while True:
            Md = M.copy()
            for a in range(rows):
                Md[a, a] += mu * tr
            z = np.linalg.solve(Md, -r)
            for i in range(n):
                st = 0.0
                for k in range(rows):
                    st += A[k, i] * z[k]
                x_new[i] = min(max(x[i] + D[i] * st, lo[i]), hi[i])
            _fk_kernel(c0, u0, t0, x_new, pitches, cs, us, ts, True)
            _resid_kernel(cs, us, ts, x_new, P, e1, e2, has_app, app, wp_k, wp_p, w_soft, wp_weight, out)
            f_new = 0.0
            for k in range(rows):
                f_new += out[k] * out[k]
            if f_new < f:
                mu = max(mu / 4.0, 1e-9)
                break
            mu *= 8.0
            if mu > 1e6:
                return x
        if rows > 5 and f - f_new < 1e-6 * f:
            return x_new.copy()
        x[:] = x_new
        r[:] = out[:rows]
        f = f_new
    return x


def _bounds(n: int, bmax: float, free_start, end_bends) -> tuple[np.ndarray, np.ndarray]:
    """Lower and upper bounds of the ``n`` bends (rad): ``bmax``; the ``end_bends = (m, b)``
    junctions after the first and the last ``m`` at most ``b``; the first bend (the turn
    about the tap's axis) at most ``free_start`` (rad), or fixed when it is False."""
    lo = np.full(n, -bmax)
    hi = np.full(n, bmax)
    if end_bends is not None:                  # (count, bound): the first and last junctions bend less
        m, eb = end_bends
        lo[-m:], hi[-m:] = -eb, eb
        lo[1:1 + m], hi[1:1 + m] = -eb, eb
    lim0 = float(free_start) if free_start else 1e-12      # free_start: the first bend's bound (rad)
    lo[0], hi[0] = -lim0, lim0
    return lo, hi


def _polish(x, lo, hi, c0, u0, t0, pitches, P, e1, e2, margin: float = 1e-9) -> np.ndarray:
    """Close a nearly closed chain exactly.  The passes of :func:`_solve_n` can stall a
    little short of ``EXACT`` (5e-7 sigma, say) on long chains: :func:`_fk_kernel`'s
    rounding error grows along the chain, and the trust region stops where it dominates.
    This closes the chain as assembled (``exact`` kinematics): Gauss-Newton on the five
    closure equations alone (the last pair's position, its axis across the target's),
    over the bends not on a bound.  Each step is the smallest that solves the linearised
    equations (least squares); the bends it would push through a bound are held there and
    the step solved again; it is halved until it lowers the closure error.  Returns the
    bends (rad), unchanged if no step helps."""
    n = x.shape[0]
    cs, us, ts = np.empty((n + 1, 3)), np.empty((n + 1, 3)), np.empty((n, 3))
    J = np.empty((5 + (n - 1), n))
    no_wp = np.zeros(0, dtype=np.int64)

    def error(b) -> float:
        _fk_kernel(c0, u0, t0, b, pitches, cs, us, ts, True)
        return _closure_error(cs, us, P, e1, e2)

    x = np.clip(np.ascontiguousarray(x, dtype=np.float64), lo, hi)
    err = error(x)
    for _ in range(POLISH_STEPS):
        if err < EXACT:
            break
        # cs, us, ts hold the frames of x: error() was last called on it
        _jac_kernel(cs, us, ts, e1, e2, False, no_wp, 0.0, 0.0, J)
        r = 10.0 * np.array([*(cs[-1] - P), us[-1] @ e1, us[-1] @ e2])
        free = (x > lo + margin) & (x < hi - margin)
        step = np.zeros(n)
        for _ in range(8):          # bends the step would push through a bound are held there
            if not free.any():
                break
            step[:] = 0.0
            step[free] = np.linalg.lstsq(J[:5, free], -r, rcond=None)[0]
            out = free & ((x + step < lo) | (x + step > hi))
            if not out.any():
                break
            free &= ~out
        if not free.any():
            break
        t = 1.0
        while t > 1e-3:
            x_new = np.clip(x + t * step, lo, hi)
            e_new = error(x_new)
            if e_new < err:
                break
            t *= 0.5
        else:
            break
        x, err = x_new, e_new
    return x


def _guide(c0, t0, waypoints, P, app) -> np.ndarray:
    """A dense polyline from c0 (leaving along t0) through the waypoints into P (arriving
    along ``app``, or straight): cubic Beziers between the knots."""
    knots = [np.asarray(c0, float)] + [np.asarray(w, float) for w in waypoints] + [np.asarray(P, float)]
    dirs = [np.asarray(t0, float)]

    def unit_or(d, fallback):
        n = float(np.linalg.norm(d))
        return d / n if n > 1e-9 else fallback

    for i in range(1, len(knots) - 1):
        dirs.append(unit_or(knots[i + 1] - knots[i - 1], dirs[-1]))
    dirs.append(app if app is not None else unit_or(knots[-1] - knots[-2], dirs[-1]))
    return np.concatenate([_bezier(knots[i], dirs[i], knots[i + 1], dirs[i + 1])[:-1]
                           for i in range(len(knots) - 1)] + [knots[-1][None]])


def _rot(v, k, th):
    c, s = math.cos(th), math.sin(th)
    return v * c + np.cross(k, v) * s + k * float(k @ v) * (1.0 - c)


@njit(cache=True)
def _fk_kernel(c0, u0, t0, b, pitch, cs, us, ts, exact=False):
    """Chain frames (see chain_frames) into cs (n+1,3), us (n+1,3), ts (n,3): arrays only.

    ``u <- t x u`` is unstable in floating point: an axis whose norm is off by e turns the
    next tangent into one off by about e sin(bend), so the error grows about 1.25 times a
    half unit (2e-6 sigma at the end of 150 half units, where ``chain_frames``, which builds
    the bodies with exact rotations, is right to 1e-12).  With ``exact`` each new axis and
    tangent is renormalised.  The inverse kinematics of ``_solve_n`` runs without it
    (renormalising there changes the last bits of every route, so every scene);
    ``_polish`` closes the chain with it, as assembled."""
    n = b.shape[0]
    for j in range(3):
        cs[0, j] = c0[j]
        us[0, j] = u0[j]
    t = np.empty(3)
    t[:] = t0
    k = np.empty(3)
    for i in range(n):
        # t <- R(k, b[i]) t with k = us[i]
        for j in range(3):
            k[j] = us[i, j]
        th = b[i]
        c, s = math.cos(th), math.sin(th)
        kx = k[1] * t[2] - k[2] * t[1]
        ky = k[2] * t[0] - k[0] * t[2]
        kz = k[0] * t[1] - k[1] * t[0]
        kd = k[0] * t[0] + k[1] * t[1] + k[2] * t[2]
        t0x = t[0] * c + kx * s + k[0] * kd * (1.0 - c)
        t0y = t[1] * c + ky * s + k[1] * kd * (1.0 - c)
        t0z = t[2] * c + kz * s + k[2] * kd * (1.0 - c)
        t[0], t[1], t[2] = t0x, t0y, t0z
        ts[i, 0], ts[i, 1], ts[i, 2] = t[0], t[1], t[2]
        for j in range(3):
            cs[i + 1, j] = cs[i, j] + pitch[i] * t[j]
        us[i + 1, 0] = t[1] * us[i, 2] - t[2] * us[i, 1]
        us[i + 1, 1] = t[2] * us[i, 0] - t[0] * us[i, 2]
        us[i + 1, 2] = t[0] * us[i, 1] - t[1] * us[i, 0]
        if exact:
            nu = math.sqrt(us[i + 1, 0] ** 2 + us[i + 1, 1] ** 2 + us[i + 1, 2] ** 2)
            nt = math.sqrt(t[0] ** 2 + t[1] ** 2 + t[2] ** 2)
            for j in range(3):
                us[i + 1, j] /= nu
                t[j] /= nt


def _fk(c0, u0, t0, b, pitch):
    """Frames of the chain (see chain_frames; ``pitch`` a number or one per half unit):
    arrays cs (n+1,3), us (n+1,3), ts (n,3)."""
    b = np.ascontiguousarray(b, dtype=np.float64)
    n = len(b)
    pitch = np.ascontiguousarray(np.broadcast_to(np.asarray(pitch, float), (n,)))
    cs, us, ts = np.empty((n + 1, 3)), np.empty((n + 1, 3)), np.empty((n, 3))
    _fk_kernel(np.asarray(c0, float), np.asarray(u0, float), np.asarray(t0, float), b, pitch, cs, us, ts)
    return cs, us, ts


def _solve_n(n, c0, u0, t0, P, e1, e2, app, x0, pitches, bmax, free_start, wps=(), end_bends=None,
             wp_weight=0.3, avoid=(), avoid_from=0, bounds=None) -> Route:
    lo, hi = _bounds(n, bmax, free_start, end_bends) if bounds is None else bounds

    wp_k = np.array([k for k, _ in wps], dtype=np.int64)
    wp_p = np.array([p for _, p in wps], dtype=float).reshape(-1, 3)
    has_app = app is not None
    app_v = np.zeros(3) if app is None else np.asarray(app, float)
    n_rows = 5 + (3 if has_app else 0) + 3 * len(wp_k) + (n - 1)
    cs, us, ts = np.empty((n + 1, 3)), np.empty((n + 1, 3)), np.empty((n, 3))
    avoid = [(cKDTree(np.asarray(p, float).reshape(-1, 3)), float(d)) for p, d in avoid if len(p)]
    n_avoid = n - min(max(int(avoid_from), 0), n)
    near_q = np.zeros((len(avoid) * n_avoid, 3))     # per avoid row: its nearest point ...
    near_d = np.full(len(avoid) * n_avoid, np.inf)   # ... its distance (inf: none within the set's distance)
    near_D = np.zeros(len(avoid) * n_avoid)          # ... and the set's distance

    def nearest():
        m = 0.5 * (cs[1:] + cs[:-1])[n - n_avoid:]
        for k_, (tree, d) in enumerate(avoid):
            dist, idx = tree.query(m, distance_upper_bound=d)
            sl = slice(k_ * n_avoid, (k_ + 1) * n_avoid)
            ok = np.isfinite(dist)
            near_d[sl] = dist
            q = near_q[sl]
            q[ok] = tree.data[idx[ok]]
            near_D[sl] = d

    def frames(b):
        _fk_kernel(c0, u0, t0, np.ascontiguousarray(b, dtype=np.float64), pitches, cs, us, ts)

    class _Closed(Exception):
        """Raised from the closing passes at the first evaluation that closes exactly."""

        def __init__(self, b):
            self.b = np.array(b, float)

    def resid(b, w_soft, stop=False):
        frames(b)
        out = np.empty(n_rows + near_d.size)
        _resid_kernel(cs, us, ts, b, P, e1, e2, has_app, app_v, wp_k, wp_p, w_soft, wp_weight, out)
        if near_d.size:
            nearest()
            out[n_rows:] = w_soft * AVOID_WEIGHT * np.where(np.isfinite(near_d), near_D - near_d, 0.0)
        if stop and max(abs(out[0]), abs(out[1]), abs(out[2]), abs(out[3]), abs(out[4])) < 10.0 * EXACT * CLOSE_MARGIN:
            if np.all(b >= lo) and np.all(b <= hi):
                raise _Closed(b)
        return out

    def jac(b, w_soft, stop=False):
        # bend i turns everything downstream of junction i rigidly about (c_i, u_i)
        frames(b)
        J = np.empty((n_rows + near_d.size, n))
        _jac_kernel(cs, us, ts, e1, e2, has_app, wp_k, w_soft, wp_weight, J)
        if near_d.size:
            nearest()
            _avoid_jac_kernel(cs, us, n - n_avoid, near_q, near_d, w_soft * AVOID_WEIGHT, J[n_rows:])
        return J

    x = np.clip(np.asarray(x0, float), lo + 1e-12, hi - 1e-12)

    def errors(x):
        cs, us, ts = _fk(c0, u0, t0, x, pitches)
        err = _closure_error(cs, us, P, e1, e2)
        return err, (0.0 if app is None else float(np.linalg.norm(ts[-1] - app)))

    # passes: soft terms on (shape the chain), then nearly off (close exactly); a last,
    # short polish with the soft terms all but gone where the closure is not yet exact
    for i, w_soft in enumerate(PASSES + (1e-7,)):
        if i == len(PASSES) and errors(x)[0] < EXACT:
            break
        tol = SHAPE_TOL if i == 0 else 1e-15      # the shaping pass need not converge: the next one moves it
        try:
            res = least_squares(resid, x, jac=jac, bounds=(lo, hi), args=(w_soft, EARLY_CLOSE and i > 0),
                                method="trf", xtol=tol, ftol=tol, gtol=1e-15,
                                max_nfev=300 if i == 0 else (200 if i < len(PASSES) else 50))
            x, nfev, status = res.x, res.nfev, res.status
        except _Closed as c:            # closed exactly: the soft terms are weak here, stop
            x, nfev, status = c.b, -1, 9
        if STATS is not None:
            STATS.append((n, i, nfev, status, errors(x)[0]))
        if status == 9:
            break
    err, aerr = errors(x)
    return Route(c0, u0, t0, [float(v) for v in x], err, aerr)


@njit(cache=True)
def _resid_kernel(cs, us, ts, b, P, e1, e2, has_app, app, wp_k, wp_p, w_soft, wp_weight, out):
    """The residuals of :func:`_solve_n` (closure, approach, waypoints, small bends) into out."""
    n = b.shape[0]
    N = cs.shape[0] - 1
    r = 0
    for j in range(3):
        out[r] = 10.0 * (cs[N, j] - P[j])
        r += 1
    out[r] = 10.0 * (us[N, 0] * e1[0] + us[N, 1] * e1[1] + us[N, 2] * e1[2])
    out[r + 1] = 10.0 * (us[N, 0] * e2[0] + us[N, 1] * e2[1] + us[N, 2] * e2[2])
    r += 2
    if has_app:
        for j in range(3):
            out[r] = w_soft * 2.0 * (ts[n - 1, j] - app[j])
            r += 1
    for w in range(wp_k.shape[0]):
        for j in range(3):
            out[r] = w_soft * wp_weight * (cs[wp_k[w], j] - wp_p[w, j])
            r += 1
    for i in range(1, n):
        out[r] = w_soft * 0.05 * b[i]
        r += 1


@njit(cache=True)
def _avoid_jac_kernel(cs, us, j0, near_q, near_d, w, J):
    """Jacobian of the avoid rows, w (D - d) for the layer centres m_j, j = j0 ..., with a
    point q within D (set after set; rows without one are 0): with n = (m_j - q) / d,
    d d / d b_i = n . (u_i x (m_j - c_i)) for i < j and n . (u_j x (c_{j+1} - c_j)) / 2 for i = j."""
    n_av = cs.shape[0] - 1 - j0
    J[:, :] = 0.0
    for r in range(near_d.shape[0]):
        if not math.isfinite(near_d[r]) or near_d[r] <= 0.0:
            continue
        j = j0 + r % n_av
        mx = 0.5 * (cs[j, 0] + cs[j + 1, 0])
        my = 0.5 * (cs[j, 1] + cs[j + 1, 1])
        mz = 0.5 * (cs[j, 2] + cs[j + 1, 2])
        nx = (mx - near_q[r, 0]) / near_d[r]
        ny = (my - near_q[r, 1]) / near_d[r]
        nz = (mz - near_q[r, 2]) / near_d[r]
        for i in range(j + 1):
            ux, uy, uz = us[i, 0], us[i, 1], us[i, 2]
            if i < j:
                dx, dy, dz = mx - cs[i, 0], my - cs[i, 1], mz - cs[i, 2]
            else:
                dx = 0.5 * (cs[j + 1, 0] - cs[j, 0])
                dy = 0.5 * (cs[j + 1, 1] - cs[j, 1])
                dz = 0.5 * (cs[j + 1, 2] - cs[j, 2])
            J[r, i] = -w * (nx * (uy * dz - uz * dy) + ny * (uz * dx - ux * dz) + nz * (ux * dy - uy * dx))


@njit(cache=True)
def _jac_kernel(cs, us, ts, e1, e2, has_app, wp_k, w_soft, wp_weight, J):
    """Jacobian of :func:`_resid_kernel`: bend i turns everything after junction i
    rigidly about the axis us[i] through cs[i] (d x = us[i] x (x - cs[i]))."""
    n = ts.shape[0]
    N = cs.shape[0] - 1
    J[:, :] = 0.0
    for i in range(n):
        ux, uy, uz = us[i, 0], us[i, 1], us[i, 2]
        dx, dy, dz = cs[N, 0] - cs[i, 0], cs[N, 1] - cs[i, 1], cs[N, 2] - cs[i, 2]
        J[0, i] = 10.0 * (uy * dz - uz * dy)
        J[1, i] = 10.0 * (uz * dx - ux * dz)
        J[2, i] = 10.0 * (ux * dy - uy * dx)
        vx, vy, vz = us[N, 0], us[N, 1], us[N, 2]
        cx, cy, cz = uy * vz - uz * vy, uz * vx - ux * vz, ux * vy - uy * vx
        J[3, i] = 10.0 * (cx * e1[0] + cy * e1[1] + cz * e1[2])
        J[4, i] = 10.0 * (cx * e2[0] + cy * e2[1] + cz * e2[2])
        r = 5
        if has_app:
            tx, ty, tz = ts[n - 1, 0], ts[n - 1, 1], ts[n - 1, 2]
            J[r, i] = w_soft * 2.0 * (uy * tz - uz * ty)
            J[r + 1, i] = w_soft * 2.0 * (uz * tx - ux * tz)
            J[r + 2, i] = w_soft * 2.0 * (ux * ty - uy * tx)
            r += 3
        for w in range(wp_k.shape[0]):
            k = wp_k[w]
            if i < k:
                dx, dy, dz = cs[k, 0] - cs[i, 0], cs[k, 1] - cs[i, 1], cs[k, 2] - cs[i, 2]
                J[r, i] = w_soft * wp_weight * (uy * dz - uz * dy)
                J[r + 1, i] = w_soft * wp_weight * (uz * dx - ux * dz)
                J[r + 2, i] = w_soft * wp_weight * (ux * dy - uy * dx)
            r += 3
        if i >= 1 and r + i - 1 < J.shape[0]:       # (a J of the first rows only: without them)
            J[r + i - 1, i] = w_soft * 0.05


__all__ = ["BEND_FRACTION", "Prefetch", "Route", "solve_route"]
