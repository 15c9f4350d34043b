r"""The logic core of paper Eq. 1 / Fig. 1A, derived from first principles.

Geometry (all lengths in sigma, the muscle rest length).  Slab ``ab`` is a rigid
link of length ``2 sin(phi)``; ``a = (-sin phi, 0)``, ``b = (sin phi, 0)``.  The two
core inputs are the lengths ``|ac|`` and ``|bc|`` (1 at rest, ``1 + din`` when
actuated).  Slab ``cd`` is a rigid link of length ``x`` hinged at ``c``; the output
lever keeps ``d`` on the perpendicular bisector of ``ab`` (the y axis).  At rest
``c = (0, cos phi)`` and ``d = (0, h)`` with ``h = x + cos phi``.

Design condition (paper Eq. 1, lines 1-4): with one input actuated and the other
at rest, ``d`` sits at the same height ``h`` as at rest.  ``c`` then follows from
the triangle with sides ``1, 1+din, 2 sin phi`` (angles gamma1 at ``a`` and gamma2
at ``b`` above ``ab``) and ``d`` lies on the bisector at distance ``x`` from ``c``
(angle gamma3 of ``cd`` from vertical).  Eliminating the gammas leaves one equation
in ``phi``:

    f(phi) = c_y + sqrt(x^2 - (sin phi - c_x)^2) - h = 0,
    c_x = (1 + 4 sin^2 phi - (1+din)^2) / (4 sin phi),  c_y = sqrt(1 - c_x^2),

solved by bracketing on the physical branch 0 < phi < pi/2 (``c`` above ``ab``,
``d`` above ``c``).  With both inputs actuated (Eq. 1, lines 5-6) ``c`` rises to
``(1+din) cos zeta`` with ``sin zeta = sin phi / (1+din)`` and
``dout = (1+din) cos zeta - cos phi``.  For din = 0.5, h = 2: phi = 0.5682,
x = 1.1572, dout = 0.5573 (paper: 0.56).
"""
from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from mlc.errors import MlcError

_SCAN = 2048


@dataclass(frozen=True)
class CoreSolution:
    """Solved logic core (lengths in sigma, angles in radians)."""

    din: float
    h: float
    x: float          # length of slab cd
    phi: float        # half-angle at c between the rest muscles; |ab| = 2 sin(phi)
    dout: float       # rise of d when both inputs are actuated
    gamma1: float     # one input actuated: angle of the rest input ac above ab
    gamma2: float     # one input actuated: angle of the actuated input bc above ab
    gamma3: float     # one input actuated: tilt of cd from the vertical
    zeta: float       # both inputs actuated: angle of the inputs from the vertical

    @property
    def ab(self) -> float:
        return 2.0 * np.sin(self.phi)

    def points(self, la: float = 1.0, lb: float = 1.0) -> dict[str, np.ndarray]:
        """Planar positions of a, b, c, d for input lengths ``la = |ac|``, ``lb = |bc|``
        (upper branch: c above ab, d above c on the bisector)."""
        s = np.sin(self.phi)
        a, b = np.array([-s, 0.0]), np.array([s, 0.0])
        cx = (la**2 - lb**2) / (4 * s)          # from |ac| = la, |bc| = lb
        cy2 = la**2 - (cx + s) ** 2
        if cy2 < 0:
            raise MlcError(f"inputs la={la}, lb={lb} cannot close the triangle with |ab|={2*s:.4f}")
        c = np.array([cx, np.sqrt(cy2)])
        q = self.x**2 - cx**2
        if q < 0:
            raise MlcError(f"inputs la={la}, lb={lb} move c beyond the reach of slab cd")
        d = np.array([0.0, c[1] + np.sqrt(q)])
        return {"a": a, "b": b, "c": c, "d": d}

    def residuals(self) -> np.ndarray:
        """The six equations of paper Eq. 1 (lengths in sigma) at this solution."""
        p, g1, g2, g3, z, x, L = self.phi, self.gamma1, self.gamma2, self.gamma3, self.zeta, self.x, 1 + self.din
        return np.array([
            np.sin(p) - np.cos(g1) - x * np.sin(g3),
            np.sin(g1) + x * np.cos(g3) - x - np.cos(p),
            np.cos(g1) + L * np.cos(g2) - 2 * np.sin(p),
            np.sin(g1) - L * np.sin(g2),
            L * np.cos(z) - np.cos(p) - self.dout,
            np.sin(p) / L - np.sin(z),
        ])

    def to_dict(self) -> dict:
        return {k: float(v) for k, v in asdict(self).items()}


def _f(phi, din: float, h: float):
    """Height of d above h with one input actuated (vectorised over ``phi``; NaN where
    the linkage cannot close)."""
    phi = np.asarray(phi, dtype=float)
    with np.errstate(all="ignore"):      # huge din or h overflow to inf: no solution there, no warning
        s = np.sin(phi)
        x = h - np.cos(phi)
        L = 1.0 + din
        cx = (1 + 4 * s * s - L * L) / (4 * s)      # from a, |ac| = 1 (rest input), |bc| = L
        cy2 = 1 - cx * cx
        q = x * x - (s - cx) ** 2
        bad = (x <= 0) | (cy2 < 0) | (q < 0) | ~np.isfinite(q) | ~np.isfinite(cy2)
        out = np.sqrt(cy2) + np.sqrt(q) - h
    out = np.where(bad, np.nan, out)
    return float(out) if out.ndim == 0 else out


def _roots(din: float, h: float) -> list[float]:
    from scipy.optimize import brentq  # lazy: keeps `import mlc...` fast
    ph = np.linspace(1e-6, np.pi / 2 - 1e-6, _SCAN)
    v = _f(ph, din, h)
    roots = []
    for i in range(len(ph) - 1):
        if np.isfinite(v[i]) and np.isfinite(v[i + 1]) and v[i] * v[i + 1] < 0:
            roots.append(brentq(_f, ph[i], ph[i + 1], args=(din, h), xtol=1e-15, maxiter=200))
    return roots


_RANGE_GRID = 121      # din samples of an accessible-range scan
_EDGE_STEPS = 30       # bisection steps refining its upper edge


def accessible_din_range(h: float) -> tuple[float, float] | None:
    """The (min, max) of din/sigma for which a core of height h has a physical solution."""
    grid = np.linspace(1e-3, 3.0, _RANGE_GRID)
    ok = [d for d in grid if _physical(d, h)]
    if not ok:
        return None
    return float(min(ok)), _refine_edge(h, float(max(ok)))


def _physical(din, h) -> bool:
    return _solve(din, h) is not None


def solve_core(din: float, h: float) -> CoreSolution:
    """Solve the logic core for input signal ``din`` and height ``h`` (both in sigma).

    Returns the physical branch (0 < phi < pi/2, dout > 0).  Raises :class:`MlcError`
    naming the accessible range when there is none.
    """
    if not (np.isfinite(din) and np.isfinite(h)) or din <= 0 or h <= 0:
        raise MlcError(f"need din > 0 and h > 0 (got din={din}, h={h})", "--din/--h")
    sol = _solve(din, h)
    if sol is None:
        rng = accessible_din_range(h)
        acc = (f"for h={h} the accessible range is 0 < din <= {rng[1]:.3f}"
               if rng else f"no din is accessible for h={h}; try h between 1.05 and 4")
        raise MlcError(f"the logic core has no physical solution at din={din}, h={h}", "--din/--h", acc)
    return sol


def _solve(din: float, h: float) -> CoreSolution | None:
    roots = [p for p in _roots(din, h) if 0 < p < np.pi / 2]
    sols = []
    for p in roots:
        s = np.sin(p)
        x = h - np.cos(p)
        L = 1 + din
        cx = (1 + 4 * s * s - L * L) / (4 * s)
        g1 = np.arctan2(np.sqrt(max(0.0, 1 - cx * cx)), cx)
        g2 = np.arcsin(np.sin(g1) / L)
        g3 = np.arcsin(np.clip((s - cx) / x, -1, 1))
        z = np.arcsin(s / L)
        dout = L * np.cos(z) - np.cos(p)
        if dout > 0 and x > 0:
            sols.append(CoreSolution(din, h, x, p, dout, g1, g2, g3, z))
    if not sols:
        return None
    # Several roots can exist near the edge of the region: take the one with the largest output.
    return max(sols, key=lambda s: s.dout)


def design_space(hs=(1.25, 1.5, 2.0, 2.5, 3.0), n: int = 60, progress=None) -> dict:
    """Fig. 1B as data: dout(din) for each h, and the accessible boundary.

    The boundary is, for each h, the largest accessible din (and its dout).  ``progress``,
    if given, is called as ``progress(done, total)`` in units of core solves (an accessible-range
    scan counts as its 151 solves), so a caller can show a bar with an ETA."""
    curves = {}
    boundary = []
    hgrid = np.linspace(1.1, 4.0, 24)
    per_range = _RANGE_GRID + _EDGE_STEPS
    total = len(hs) * (per_range + n) + len(hgrid) * per_range
    done = 0

    def tick(k):
        nonlocal done
        done += k
        if progress is not None:
            progress(done, total)

    for h in hs:
        rng = accessible_din_range(h)
        tick(per_range)
        pts = []
        if rng:
            for i, din in enumerate(np.linspace(rng[0], rng[1], n)):
                s = _solve(din, h)
                if s is not None:
                    pts.append((float(din), float(s.dout)))
                if i % 10 == 9:
                    tick(10)
            tick(n % 10)
        else:
            tick(n)
        curves[float(h)] = pts
    for h in hgrid:
        rng = accessible_din_range(h)
        if rng:
            hi = rng[1]
            boundary.append((float(h), hi, float(_solve(hi, h).dout)))
        tick(per_range)
    return {"curves": curves, "boundary": boundary}


def _refine_edge(h: float, lo: float) -> float:
    hi = lo + 0.025
    for _ in range(_EDGE_STEPS):
        mid = 0.5 * (lo + hi)
        if _physical(mid, h):
            lo = mid
        else:
            hi = mid
    return float(lo)
