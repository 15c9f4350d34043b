"""The router's solve cache (mlc.circuit.route.solve_route): a repeated solve with
bit-identical arguments returns the same route, as a copy; any bit of difference solves again."""
import numpy as np

from mlc.circuit import route as R
from mlc.gates.connector import connector_geometry


def _args():
    geo = connector_geometry("expand")
    c0, u0 = np.array([0.0, 0.0, 0.0]), np.array([1.0, 0.0, 0.0])
    P, a = np.array([0.0, -6.0, 9.0]), np.array([1.0, 0.0, 0.0])
    return (c0, u0, P, a, geo, 0), dict(tangent=np.array([0.0, 0.0, 1.0]), approach=np.array([0.0, 0.0, 1.0]),
                                        waypoints=[(0.0, -4.0, 4.0)])


def test_a_repeated_solve_is_the_same_route_and_a_copy():
    args, kw = _args()
    R._CACHE.clear()
    h0, m0 = R.CACHE_HITS
    first = R.solve_route(*args, **kw)
    assert first is not None and first.error < R.EXACT
    again = R.solve_route(*(np.array(v) if isinstance(v, np.ndarray) else v for v in args), **kw)
    assert R.CACHE_HITS == [h0 + 1, m0 + 1]
    assert again is not first and again.bends == first.bends and again.error == first.error
    assert np.array_equal(again.centre, first.centre) and np.array_equal(again.tangent, first.tangent)
    # the caller may edit what it got: the remembered route is not changed
    again.bends[0] += 1.0
    again.centre[0] += 1.0
    third = R.solve_route(*args, **kw)
    assert third.bends == first.bends and np.array_equal(third.centre, first.centre)
    # the same solve without the cache: bit for bit the same bends
    R._CACHE.clear()
    size, R.CACHE_SIZE = R.CACHE_SIZE, 0
    try:
        fresh = R.solve_route(*args, **kw)
    finally:
        R.CACHE_SIZE = size
    assert fresh.bends == first.bends


def test_one_ulp_or_a_signed_zero_is_another_solve():
    args, kw = _args()
    R._CACHE.clear()
    R.solve_route(*args, **kw)
    P = args[2].copy()
    P[2] = np.nextafter(P[2], 10.0)
    h = R.CACHE_HITS[0]
    R.solve_route(*args[:2], P, *args[3:], **kw)
    assert R.CACHE_HITS[0] == h
    assert R._key(0.0) != R._key(-0.0) and R._key(np.array([0.0])) != R._key(np.array([-0.0]))


def test_blas_single_thread_sets_one_thread_and_restores():
    ctl = R._blas_controls()
    before = [g() for _, g in ctl]
    with R.blas_single_thread():
        assert all(g() == 1 for _, g in ctl)
    assert [g() for _, g in ctl] == before


def _layer_dist(route, geo, pts):
    cs, _, _ = R._fk(route.centre, route.axis, route.tangent, route.bends, geo.pitch)
    m = 0.5 * (cs[1:] + cs[:-1])
    return np.sqrt(((m[:, None, :] - np.asarray(pts)[None]) ** 2).sum(-1)).min(axis=1)


def test_avoid_pushes_the_layers_from_the_points_and_still_closes():
    """``avoid``: a chain whose plain route passes through a set of points keeps its
    layers' centres about ``distance`` from them, still closing exactly on its target."""
    args, kw = _args()
    geo = args[4]
    plain = R.solve_route(*args, **kw)
    cs, _, _ = R._fk(plain.centre, plain.axis, plain.tangent, plain.bends, geo.pitch)
    mid = 0.5 * (cs[len(cs) // 2] + cs[len(cs) // 2 + 1])
    pts = mid + np.array([[0.0, 0.3, 0.0], [0.0, -0.3, 0.0], [0.3, 0.0, 0.0]])   # on the plain route
    D = 1.8
    assert _layer_dist(plain, geo, pts).min() < 0.5
    pushed = R.solve_route(*args, avoid=((pts, D),), **kw)
    assert pushed is not None and pushed.error < R.EXACT
    d = _layer_dist(pushed, geo, pts)
    print("nearest layer to the points: plain", _layer_dist(plain, geo, pts).min(), "avoid", d.min())
    assert d.min() > 0.8 * D
    # from avoid_from on only: the layers before it are not pushed
    n = len(pushed.bends)
    late = R.solve_route(*args, avoid=((pts, D),), avoid_from=n, **kw)
    assert late.bends == plain.bends


def test_polish_closes_a_near_miss_with_bends_on_their_bounds():
    """``_polish``: a chain 2e-5 sigma short of its target, half its bends pinned on their
    bounds (where the trust region stalls), is closed below EXACT by the free bends
    alone; no bend leaves its bounds and the pinned ones do not move."""
    args, kw = _args()
    c0, u0, P, a, geo, _ = args
    r = R.solve_route(*args, **kw)
    x = np.array(r.bends)
    n = len(x)
    pitches = np.full(n, geo.pitch)
    pinned = np.arange(n) % 2 == 1
    lo = np.where(pinned, x, x - 0.2)
    hi = np.where(pinned, x + 0.3, x + 0.2)
    e1, e2 = R._perp_basis(a / np.linalg.norm(a))
    target = P + np.array([2e-5, -1e-5, 1e-5])

    def err(b):
        cs, us, _ = R._fk(c0, u0, r.tangent, b, pitches)
        return max(np.linalg.norm(cs[-1] - target), abs(us[-1] @ e1), abs(us[-1] @ e2))
    assert err(x) > 1e-5
    y = R._polish(x.copy(), lo, hi, c0, u0, r.tangent, pitches, target, e1, e2)
    assert err(y) < R.EXACT
    assert np.all(y >= lo) and np.all(y <= hi)
    assert np.array_equal(y[pinned], x[pinned])
    # with every bend pinned there is nothing to move: returned unchanged
    z = R._polish(x.copy(), x.copy(), x + 0.1, c0, u0, r.tangent, pitches, target, e1, e2)
    assert np.array_equal(z, x)


def test_polish_leaves_a_route_that_closes_without_it_as_it_is():
    """``polish`` acts only where no length closes: a solve that closes gives the same bends
    with and without it."""
    args, kw = _args()
    size, R.CACHE_SIZE = R.CACHE_SIZE, 0
    try:
        a = R.solve_route(*args, polish=True, **kw)
        b = R.solve_route(*args, polish=False, **kw)
    finally:
        R.CACHE_SIZE = size
    assert a is not None and a.bends == b.bends


def test_exact_kinematics_agree_with_chain_frames_where_the_plain_kernel_drifts():
    """``_fk_kernel(..., exact=True)`` renormalises each axis: on a 200-half-unit chain it
    agrees with ``chain_frames`` (which turns by exact rotations, a second implementation)
    to 1e-9 sigma, where the plain recurrence u <- t x u has drifted by more than 1e-8."""
    from mlc.gates.connector import chain_frames
    rng = np.random.default_rng(3)
    n = 200
    b = rng.uniform(-0.35, 0.35, n)
    c0, u0, t0 = np.zeros(3), np.array([1.0, 0.0, 0.0]), np.array([0.0, 0.0, 1.0])
    pitch = np.ones(n)
    ref = np.array(chain_frames(c0, u0, t0, b, 1.0)[0])
    plain = R._fk(c0, u0, t0, b, 1.0)[0]
    cs, us, ts = np.empty((n + 1, 3)), np.empty((n + 1, 3)), np.empty((n, 3))
    R._fk_kernel(c0, u0, t0, b, pitch, cs, us, ts, True)
    print("end drift: plain", np.abs(plain - ref).max(), "exact", np.abs(cs - ref).max())
    assert np.abs(cs - ref).max() < 1e-9
    assert np.abs(plain - ref).max() > 1e-8
    assert np.allclose(np.linalg.norm(us, axis=1), 1.0, atol=1e-14)


def _long_args(parity=0):
    """A chain from a tap up and across to a lever 40 sigma away, along an L of waypoints."""
    geo = connector_geometry("expand")
    c0, u0 = np.array([0.0, 0.0, 0.0]), np.array([1.0, 0.0, 0.0])
    P, a = np.array([30.0, -3.0, 26.0]), np.array([1.0, 0.0, 0.0])
    wps = [(0.0, -6.0, 2.0 * k) for k in range(1, 8)] + [(2.0 * k, -6.0, 15.0) for k in range(1, 15)] + \
          [(30.0, -4.5, 20.0)]
    mb = R.max_bend(geo)
    return (c0, u0, P, a, geo, parity), dict(tangent=np.array([0.0, 0.0, 1.0]), approach=np.array([0.0, 0.0, 1.0]),
                                             waypoints=wps, bend_max=0.6 * mb, end_bends=(4, 0.2 * mb),
                                             start_bend_max=0.2 * mb, extras=(0, 4, 8), wp_weight=1.0)


def test_the_fast_method_closes_a_long_chain_exactly_within_its_bounds():
    """``method="fast"``: the route closes on the target pair (checked with the exact
    rotations that build the bodies, not the solver's recurrence), has the parity asked,
    keeps every bend within its bound (the end junctions' tighter one included), and
    arrives along the approach; without the trust region's fallback (a solve that needs it
    would not be the fast method's)."""
    from mlc.gates.connector import chain_frames
    for parity in (0, 1):
        args, kw = _long_args(parity)
        c0, u0, P, a, geo, _ = args
        called = []
        real = R._solve_n
        R._solve_n = lambda *x, **k: called.append(1) or real(*x, **k)
        try:
            r = R._solve_plain(args, dict(kw, method="fast"))
        finally:
            R._solve_n = real
        assert r is not None and not called
        assert r.n % 2 == parity and r.n > 50
        cs, us, ts = chain_frames(r.centre, r.axis, r.tangent, r.bends, geo.pitch)
        # the last pair is the solver's last pitch: last_pitch unset, so all pitches equal
        assert np.linalg.norm(cs[-1] - P) < 10 * R.EXACT
        assert abs(abs(float(us[-1] @ a)) - 1.0) < 1e-10
        assert float(np.linalg.norm(ts[-1] - kw["approach"])) < 0.5
        b = np.abs(np.array(r.bends))
        assert b[0] <= kw["start_bend_max"] + 1e-12
        assert b.max() <= kw["bend_max"] + 1e-12
        m, eb = kw["end_bends"]
        assert b[1:1 + m].max() <= eb + 1e-12 and b[-m:].max() <= eb + 1e-12


def test_the_fast_method_keeps_to_the_lane_as_the_whole_solve_does():
    """The fast route follows the waypoints about as closely as the whole-chain solve:
    the mean distance of its pairs from the waypoints' polyline is within 1.5 times the
    whole solve's (1.56 against 1.17 sigma when written; closing the steered chain with
    every bend free to move instead of mostly the last ones: 2.46)."""
    args, kw = _long_args(0)
    geo = args[4]
    ik = R._solve_plain(args, kw)
    fast = R._solve_plain(args, dict(kw, method="fast"))
    line = np.array([args[0]] + [np.array(w) for w in kw["waypoints"]] + [args[2]])
    dense = np.concatenate([np.linspace(line[i], line[i + 1], 20, endpoint=False) for i in range(len(line) - 1)])

    def far(route):
        cs, _, _ = R._fk(route.centre, route.axis, route.tangent, route.bends, geo.pitch)
        return float(np.sqrt(((cs[:, None, :] - dense[None]) ** 2).sum(-1)).min(axis=1).mean())
    assert far(fast) <= 1.5 * far(ik), (far(fast), far(ik))


def test_the_fast_method_pushes_a_chain_away_from_what_it_avoids_and_still_closes():
    """``method="fast"`` with ``avoid``: the route is pushed off a row of points laid 0.6
    sigma beside the middle of the plain fast route (keep-away distance 1.5 sigma), so its
    layers keep farther from them than the plain route's (which passes 0.6 away), and it
    still closes on the target (by the exact rotations), within every bound, with no call
    of the trust region."""
    from mlc.gates.connector import chain_frames
    args, kw = _long_args(0)
    c0, u0, P, a, geo, _ = args
    plain = R._solve_plain(args, dict(kw, method="fast"))
    cs, _, _ = R._fk(plain.centre, plain.axis, plain.tangent, plain.bends, geo.pitch)
    mid = 0.5 * (cs[1:] + cs[:-1])
    k = len(mid) // 2
    side = np.cross(cs[k + 1] - cs[k], [0.0, 1.0, 0.0])
    side /= np.linalg.norm(side)
    pts = mid[k - 6:k + 6] + 0.6 * side
    avoid = ((pts, 1.5),)

    def keep(route):
        cs, _, _ = R._fk(route.centre, route.axis, route.tangent, route.bends, geo.pitch)
        m = 0.5 * (cs[1:] + cs[:-1])[10:]
        return float(np.sqrt(((m[:, None] - pts[None]) ** 2).sum(-1)).min()) - 1.5
    called = []
    real = R._solve_n
    R._solve_n = lambda *x, **k: called.append(1) or real(*x, **k)
    try:
        r = R._solve_plain(args, dict(kw, method="fast", avoid=avoid, avoid_from=10))
    finally:
        R._solve_n = real
    assert r is not None and not called
    assert keep(plain) < -0.8 and keep(r) > keep(plain) + 0.5, (keep(plain), keep(r))
    cs, us, ts = chain_frames(r.centre, r.axis, r.tangent, r.bends, geo.pitch)
    assert np.linalg.norm(cs[-1] - P) < 10 * R.EXACT
    assert abs(abs(float(us[-1] @ a)) - 1.0) < 1e-10
    b = np.abs(np.array(r.bends))
    m, eb = kw["end_bends"]
    assert b.max() <= kw["bend_max"] + 1e-12 and b[0] <= kw["start_bend_max"] + 1e-12
    assert b[1:1 + m].max() <= eb + 1e-12 and b[-m:].max() <= eb + 1e-12
