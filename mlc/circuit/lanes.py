"""Lanes: which routing plane each connector chain runs in, and a check that chains keep apart.

Every chain from a tap (a gate's output pair, a source or a branch page) to a gate's input
lever follows one shape (docs/circuits.md, "Routing"):

    tap --(inward region)--> plane k: riser at x = x_r from z_a up to z_run,
                                      run along x at z_run to x_in --(inward region, rising
                                      to z_in)--> pin

The risers and runs of chain ``i`` lie in the vertical plane ``y = Y0 - k * PLANE_PITCH``
in front of the gates; the two *crossings* (tap to plane at ``(x_r, z_a)``, plane to pin
at ``x_in`` between ``z_run`` and ``z_in``) go straight through every plane closer to the gates.  So two chains
cannot meet when, in the x-z view:

* chains in the same plane keep their polylines ``SEP`` apart;
* a chain's crossings keep ``SEP`` from the polylines of every chain in a plane it
  crosses (the planes closer to the gates) and from every other chain's crossings.

:class:`Lanes` gives each chain the nearest plane that satisfies both (greedy, in the
order the chains are routed).  The inverse kinematics follows the lane only as closely
as its bends allow, so :class:`Space` then checks the solved chain against every chain
already placed (each half-unit layer bounded by a sphere, hashed on a grid) and the
builder tries the next plane when they come too close.  Units: sigma.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np

PLANE_Y0 = -5.0         # sigma: the plane nearest the gates (y)
PLANE_PITCH = 4.0       # sigma between routing planes
SEP = 3.0               # sigma: lanes of two chains keep this far apart in the x-z view
CROSS_BELOW = 2.0       # sigma: a tap crossing occupies z_a - CROSS_BELOW .. z_a + CROSS_ABOVE
CROSS_ABOVE = 1.0


def plane_y(k: int) -> float:
    return PLANE_Y0 - PLANE_PITCH * k


@dataclass
class Lane:
    """The x-z shape of one chain's route (sigma)."""

    x_r: float           # riser x
    z_a: float           # where the chain enters its plane from the tap
    z_run: float         # height of its run along x
    x_in: float          # where it leaves the plane for the pin
    z_in: float          # height at which it passes the nearest plane on its way to the pin
    x_end: float | None = None    # where it then heads, under the pin (x, z)
    z_end: float | None = None

    def polyline(self) -> np.ndarray:
        return np.array([[self.x_r, self.z_a], [self.x_r, self.z_run], [self.x_in, self.z_run],
                         [self.x_in, max(self.z_in, self.z_run)]])

    def crossings(self) -> list[np.ndarray]:
        return [np.array([[self.x_r, self.z_a - CROSS_BELOW], [self.x_r, self.z_a + CROSS_ABOVE]]),
                np.array([[self.x_in, self.z_in - CROSS_BELOW], [self.x_in, self.z_in + CROSS_ABOVE]]
                         + ([[self.x_end, self.z_end]] if self.x_end is not None else []))]

    @cached_property
    def shapes(self) -> tuple:
        """(polyline, its bounding box), [(crossing, its box)...], made once (the lane does
        not change once made): what :meth:`Lanes.conflicts` compares, lane by lane."""
        return (_boxed(self.polyline()), [_boxed(c) for c in self.crossings()])


def _seg_dist(p1, q1, p2, q2) -> float:
    """Smallest distance between 2-D segments p1q1 and p2q2."""
    def pt_seg(p, a, b):
        d = b - a
        L = float(d @ d)
        s = 0.0 if L == 0 else min(1.0, max(0.0, float((p - a) @ d) / L))
        return float(np.linalg.norm(a + s * d - p))
    d1, d2 = q1 - p1, q2 - p2
    den = d1[0] * d2[1] - d1[1] * d2[0]
    if abs(den) > 1e-12:          # proper crossing?
        w = p2 - p1
        s = (w[0] * d2[1] - w[1] * d2[0]) / den
        t = (w[0] * d1[1] - w[1] * d1[0]) / den
        if 0.0 <= s <= 1.0 and 0.0 <= t <= 1.0:
            return 0.0
    return min(pt_seg(p1, p2, q2), pt_seg(q1, p2, q2), pt_seg(p2, p1, q1), pt_seg(q2, p1, q1))


def _poly_dist(a: np.ndarray, b: np.ndarray) -> float:
    return min(_seg_dist(a[i], a[i + 1], b[j], b[j + 1]) for i in range(len(a) - 1) for j in range(len(b) - 1))


def _boxed(a: np.ndarray) -> tuple:
    """A polyline with its bounding box (x min, x max, z min, z max) as Python floats."""
    return a, (float(a[:, 0].min()), float(a[:, 0].max()), float(a[:, 1].min()), float(a[:, 1].max()))


def _near(a: np.ndarray, b: np.ndarray, sep: float) -> bool:
    """``_poly_dist(a, b) < sep``, without measuring where the polylines' bounding boxes
    are ``sep`` or more apart along x or z (then so are the polylines)."""
    return _near_boxed(_boxed(a), _boxed(b), sep)


def _near_boxed(a: tuple, b: tuple, sep: float) -> bool:
    """:func:`_near` of two :func:`_boxed` polylines (their boxes made once)."""
    (pa, (ax0, ax1, az0, az1)), (pb, (bx0, bx1, bz0, bz1)) = a, b
    if ax0 - bx1 >= sep or bx0 - ax1 >= sep or az0 - bz1 >= sep or bz0 - az1 >= sep:
        return False
    return _poly_dist(pa, pb) < sep


class Lanes:
    """Planes taken so far and the lanes in them."""

    def __init__(self, sep: float = SEP):
        self.sep = sep
        self.placed: list[tuple[int, Lane]] = []

    def conflicts(self, lane: Lane, k: int) -> int:
        """How many placed lanes ``lane`` would come too close to in plane ``k``."""
        poly, cross = lane.shapes
        n = 0
        sep = self.sep
        for k2, other in self.placed:
            opoly, ocross = other.shapes
            if ((k2 == k and _near_boxed(poly, opoly, sep))
                    or (k2 < k and any(_near_boxed(c, opoly, sep) for c in cross))      # mine pass its plane
                    or (k2 > k and any(_near_boxed(c, poly, sep) for c in ocross))     # its pass mine
                    or any(_near_boxed(c, oc, sep) for c in cross for oc in ocross)):
                n += 1
        return n

    def assign(self, lane: Lane, start: int = 0) -> int:
        """The first plane from ``start`` on where ``lane`` meets no placed lane; where
        every plane meets some (crossings pass all the planes nearer the gates), the first
        with the fewest."""
        top = 1 + max((k for k, _ in self.placed), default=-1)
        best = (math.inf, start)
        for k in range(start, max(start, top) + 1):
            n = self.conflicts(lane, k)
            if n == 0:
                return k
            best = min(best, (n, k))
        return best[1]

    def take(self, lane: Lane, k: int) -> None:
        self.placed.append((k, lane))


class Space:
    """Layers of the chains placed so far, for a quick keep-apart test.

    Each half-unit layer is bounded by a sphere of radius ``r`` about the midpoint of its
    two pairs; two layers of different chains cannot touch while their centres are more
    than ``2 r`` apart.  Centres are hashed on a grid of cell ``2 r``.  A chain's first
    layers may be marked as its branch's (``add``'s ``head`` and ``group``): a test that
    names that ``group`` (``nearest``'s ``exempt``) passes them by, so that sibling chains'
    first layers, side by side at their branch, are not held apart from each other while
    every other layer of theirs is."""

    def __init__(self, r: float):
        self.r = float(r)
        self.cell = 2.0 * self.r
        self.grid: dict[tuple, list] = {}
        self.cells_of: dict = {}             # owner -> the cells holding its layers

    def _keys(self, p):
        return tuple(int(math.floor(v / self.cell)) for v in p)

    def nearest(self, pts: np.ndarray, owner, exempt=None) -> float:
        """Smallest centre distance from ``pts`` to layers of other owners (inf if none
        within one cell), leaving out the first layers marked with group ``exempt``."""
        return self.nearest_owner(pts, owner, exempt)[0]

    def nearest_owner(self, pts: np.ndarray, owner, exempt=None) -> tuple[float, object]:
        """:meth:`nearest` and the owner of that layer (None if none within one cell)."""
        best, who = math.inf, None
        for p in pts:
            i, j, k = self._keys(p)
            for di in (-1, 0, 1):
                for dj in (-1, 0, 1):
                    for dk in (-1, 0, 1):
                        for q, o, g in self.grid.get((i + di, j + dj, k + dk), ()):
                            if o != owner and (exempt is None or g != exempt):
                                d = float(np.linalg.norm(q - p))
                                if d < best:
                                    best, who = d, o
        return best, who

    def nearest_chain(self, layers: np.ndarray, owner, head: int = 0, group=None) -> tuple[float, object]:
        """:meth:`nearest_owner` of a chain's ``layers`` as it keeps apart: its first ``head``
        layers (at its branch) leaving out group ``group``'s first layers, the rest none."""
        best = self.nearest_owner(layers[head:], owner)
        if head:
            first = self.nearest_owner(layers[:head], owner, group)
            if first[0] < best[0]:
                best = first
        return best

    def points(self, owner) -> np.ndarray:
        """Every layer centre of the other owners, (m, 3)."""
        pts = [q for cell in self.grid.values() for q, o, _ in cell if o != owner]
        return np.array(pts).reshape(-1, 3)

    def add(self, pts: np.ndarray, owner, head: int = 0, group=None) -> None:
        """Place ``owner``'s layer centres ``pts``; its first ``head`` marked as ``group``'s."""
        cells = self.cells_of.setdefault(owner, set())
        for n, p in enumerate(pts):
            key = self._keys(p)
            self.grid.setdefault(key, []).append((np.asarray(p, float), owner, group if n < head else None))
            cells.add(key)

    def remove(self, owner) -> None:
        """Forget every layer of ``owner`` (none placed: nothing to do)."""
        for key in self.cells_of.pop(owner, ()):
            kept = [e for e in self.grid[key] if e[1] != owner]
            if kept:
                self.grid[key] = kept
            else:
                del self.grid[key]


def rounded(points, radius: float, step: float) -> np.ndarray:
    """Points every ``step`` along the polyline ``points`` with its corners rounded (a
    quadratic Bezier between the points ``radius`` tan(angle/2) before and after each
    corner, at most half of either segment): a path a chain can follow (sigma)."""
    P = [np.asarray(p, float) for p in points]
    pieces = []                      # (kind, data) in order
    cur = P[0]
    for i in range(1, len(P) - 1):
        a, b = P[i] - P[i - 1], P[i + 1] - P[i]
        la, lb = float(np.linalg.norm(a)), float(np.linalg.norm(b))
        if la < 1e-9 or lb < 1e-9:
            continue
        cosang = float(np.clip(a @ b / (la * lb), -1.0, 1.0))
        turn = math.acos(cosang)
        d = min(radius * math.tan(0.5 * turn), 0.5 * la, 0.5 * lb)
        p_in, p_out = P[i] - d * a / la, P[i] + d * b / lb
        pieces.append(("line", (cur, p_in)))
        pieces.append(("arc", (p_in, P[i], p_out)))
        cur = p_out
    pieces.append(("line", (cur, P[-1])))
    out = []
    for kind, data in pieces:
        if kind == "line":
            p0, p1 = data
            L = float(np.linalg.norm(p1 - p0))
            m = max(1, int(round(L / step)))
            out += [p0 + (p1 - p0) * (j / m) for j in range(m)]
        else:
            p0, c, p1 = data
            L = float(np.linalg.norm(c - p0) + np.linalg.norm(p1 - c))
            m = max(1, int(round(L / step)))
            out += [(1 - s) ** 2 * p0 + 2 * (1 - s) * s * c + s ** 2 * p1 for s in (j / m for j in range(m))]
    out.append(P[-1])
    return np.array(out)


def layer_centres(cs: np.ndarray) -> np.ndarray:
    """Midpoints of consecutive pair centres: the layers' centres (sigma)."""
    cs = np.asarray(cs, float)
    return 0.5 * (cs[1:] + cs[:-1])


__all__ = ["CROSS_ABOVE", "CROSS_BELOW", "Lane", "Lanes", "PLANE_PITCH", "PLANE_Y0", "SEP", "Space",
           "layer_centres", "plane_y", "rounded"]
