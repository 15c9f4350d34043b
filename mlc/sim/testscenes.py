"""Small synthetic scenes for tests and benchmarks (built with the scene dataclasses).

* :func:`chain_scene` -- n slabs in a row, neighbours joined by hinges (two zero-rest
  bonds at the ends of the hinge axis): 4 sites per slab, the benchmark workload of
  the issue (HOOMD-blue anchor numbers were measured on the same).
* :func:`tongs_scene` -- lazy tongs (scissor chain) of ``cells`` cells, 2 slabs each,
  driven by one muscle across the first cell; probe ``span`` = total length.  A
  one-degree-of-freedom mechanism whose motion is slow (drag grows as cells^3).
* :func:`lever_scene` -- two slabs joined by a hinge and opened by a muscle to a
  given angle; ``angle`` near pi gives a nearly flat lever.
* :func:`bonded_pairs` -- n independent pairs of bodies, each joined by one bond between
  their centres (no torques): the bond-length statistics workload; its exact length
  variance: :func:`bond_length_var` (quadrature) and :func:`bond_length_var_closed`.
"""
from __future__ import annotations

import math

import numpy as np

from mlc.geometry.rotation import matrix_to_quat
from mlc.scene.model import Body, Bond, Box, Muscle, Probe, Scene

W = 0.5      # slab width (sigma), paper
TH = 0.01    # slab thickness


def _slab(name, p, q, length, sites):
    return Body(name, np.asarray(p, float), np.asarray(q, float),
                [Box(np.array([length, W, TH]))], {k: np.asarray(v, float) for k, v in sites.items()})


def _hinge(name, a, b, k=1.0, tol=0.0):
    """Two bonds a.l/b.l over the two ends of a hinge axis: a = (body, suffix) pairs."""
    (ba, sa1, sa2), (bb, sb1, sb2) = a, b
    return [Bond(f"{name}_1", f"{ba}.{sa1}", f"{bb}.{sb1}", k, 0.0, tol, "hinge", name),
            Bond(f"{name}_2", f"{ba}.{sa2}", f"{bb}.{sb2}", k, 0.0, tol, "hinge", name)]


def chain_scene(n: int, length: float = 1.0, k: float = 1.0, tol: float = 0.0, universal: bool = False,
                check: bool = True) -> Scene:
    """``n`` slabs along x, hinged end to end (axis along y); universal=True: one bond per joint.
    ``check=False`` skips :meth:`Scene.check` (valid by construction; the check looks bodies
    up by a linear scan, so it costs O(bodies x bonds): minutes at 100,000 bodies)."""
    h = length / 2
    sites = {"lt": [-h, W / 2, 0], "lb": [-h, -W / 2, 0], "rt": [h, W / 2, 0], "rb": [h, -W / 2, 0]}
    bodies = [_slab(f"s{i}", [i * length, 0, 0], [1, 0, 0, 0], length, sites) for i in range(n)]
    bonds = []
    for i in range(n - 1):
        if universal:
            bonds.append(Bond(f"u{i}", f"s{i}.rt", f"s{i + 1}.lt", k, 0.0, tol, "universal", f"u{i}"))
        else:
            bonds += _hinge(f"h{i}", (f"s{i}", "rt", "rb"), (f"s{i + 1}", "lt", "lb"), k, tol)
    sc = Scene(f"chain{n}", bodies, bonds)
    return sc.check() if check else sc


def tongs_scene(cells: int, w: float = 0.7, h: float = 0.5, k: float = 1.0, stroke: float = 0.3) -> Scene:
    """Lazy tongs in the x-y plane (hinge axes along z); muscle ``m`` across the first
    cell's left ends (rest 2h, actuated 2h - stroke: contracting extends the tongs)."""
    L = math.hypot(w, 2 * h)
    ang = math.atan2(2 * h, w)
    sites = {"l1": [-L / 2, 0, W / 2], "l2": [-L / 2, 0, -W / 2], "r1": [L / 2, 0, W / 2],
             "r2": [L / 2, 0, -W / 2], "c1": [0, 0, W / 2], "c2": [0, 0, -W / 2]}
    bodies, bonds = [], []
    for c in range(cells):
        x = c * w + w / 2
        for name, a in ((f"A{c}", ang), (f"B{c}", -ang)):
            R = np.array([[math.cos(a), -math.sin(a), 0], [math.sin(a), math.cos(a), 0], [0, 0, 1]])
            bodies.append(_slab(name, [x, 0, 0], matrix_to_quat(R), L, sites))
        bonds += _hinge(f"x{c}", (f"A{c}", "c1", "c2"), (f"B{c}", "c1", "c2"), k)
        if c:
            # A_{c-1} right end (top) to B_c left end (top); B_{c-1} right (bottom) to A_c left (bottom)
            bonds += _hinge(f"t{c}", (f"A{c - 1}", "r1", "r2"), (f"B{c}", "l1", "l2"), k)
            bonds += _hinge(f"b{c}", (f"B{c - 1}", "r1", "r2"), (f"A{c}", "l1", "l2"), k)
    muscles = [Muscle("m", "a", "A0.l1", "B0.l1", 2 * h, 2 * h - stroke, k)]
    wl = math.sqrt(L * L - (2 * h - stroke) ** 2)
    probes = [Probe("span", "out", "A0.l1", f"A{cells - 1}.r1", cells * w, cells * wl)]
    return Scene(f"tongs{cells}", bodies, bonds, muscles, probes, ["a"], ["out"]).check()


def lever_scene(angle: float = 2.0, k: float = 1.0, tol: float = 0.0) -> Scene:
    """Two unit slabs hinged at the origin (axis z), opened to ``angle`` between them;
    a muscle between their free ends holds the angle (input ``a`` opens it by 0.1 sigma)."""
    bodies = []
    sites = {"h1": [-0.5, 0, W / 2], "h2": [-0.5, 0, -W / 2], "e": [0.5, 0, 0]}
    for name, a in (("p", angle / 2), ("q", -angle / 2)):
        d = np.array([math.cos(a), math.sin(a), 0])
        R = np.array([[d[0], -d[1], 0], [d[1], d[0], 0], [0, 0, 1]])
        bodies.append(_slab(name, 0.5 * d, matrix_to_quat(R), 1.0, sites))
    bonds = _hinge("hinge", ("p", "h1", "h2"), ("q", "h1", "h2"), k, tol)
    span = 2 * math.sin(angle / 2)
    muscles = [Muscle("m", "a", "p.e", "q.e", span, span + 0.1, k)]
    probes = [Probe("span", "out", "p.e", "q.e", span, span + 0.1)]
    return Scene("lever", bodies, bonds, muscles, probes, ["a"], ["out"]).check()


def bonded_pairs(n: int, rest: float = 1.0, tol: float = 0.0, k=1.0, spacing: float = 4.0) -> Scene:
    """n pairs of bodies on a square grid ``spacing`` sigma apart, each pair joined by one
    bond (rest length ``rest``, tolerance ``tol``, sigma; stiffness ``k``, k0, or a sequence
    of n stiffnesses, one a pair) between their centres, so no torque acts."""
    bodies, bonds = [], []
    side = int(math.ceil(math.sqrt(n)))
    ks = np.broadcast_to(np.asarray(k, dtype=float), (n,))
    for i in range(n):
        c = spacing * np.array([i % side, i // side, 0.0])
        for tag, dx in (("a", -0.5 * rest), ("b", 0.5 * rest)):
            bodies.append(Body(f"{tag}{i}", c + [dx, 0, 0], np.array([1.0, 0, 0, 0]),
                               [Box(np.array([0.3, 0.3, 0.01]))], {"c": np.zeros(3)}))
        bonds.append(Bond(f"u{i}", f"a{i}.c", f"b{i}.c", float(ks[i]), rest, tol, "universal", f"u{i}"))
    return Scene("pairs", bodies, bonds).check()


def bond_length_var_closed(kT: float, L: float = 1.0, k: float = 1.0) -> float:
    """The same variance in closed form: with s^2 = kT/k and x = r - L, the weight
    (L + x)^2 exp(-x^2/2s^2) (extended to r < 0, which changes nothing above double
    precision while s < L/8) has Z = L^2 + s^2, Z <x> = 2 L s^2, Z <x^2> = L^2 s^2 + 3 s^4, so

        Var r = s^2 (L^4 + 3 s^4) / (L^2 + s^2)^2 = s^2 (1 - 2 s^2/L^2 + O(s^4/L^4)),

    below kT/k by 2 kT/(k L^2): 0.98059 kT/k at kT = 1e-2 k0 sigma^2, L = 1 sigma, k = 1 k0.
    (The mean length is L + 2 L s^2/(L^2 + s^2): the r^2 of the 3-D shell pushes it out.)"""
    s2 = kT / k
    return s2 * (L ** 4 + 3.0 * s2 * s2) / (L * L + s2) ** 2


def bond_length_var(kT: float, L: float = 1.0, k: float = 1.0) -> float:
    """Exact equilibrium variance (sigma^2) of a harmonic bond's length in 3D (rest ``L``
    sigma, stiffness ``k`` k0, ``kT`` k0 sigma^2): r^2 exp(-k (r-L)^2 / 2kT), by quadrature
    (the theory the simulator's bond fluctuations are checked against)."""
    from scipy.integrate import quad
    w = lambda r: r * r * math.exp(-k * (r - L) ** 2 / (2 * kT))  # noqa: E731
    lo, hi = max(0.0, L - 12 * math.sqrt(kT / k)), L + 12 * math.sqrt(kT / k)
    z = quad(w, lo, hi)[0]
    m1 = quad(lambda r: r * w(r), lo, hi)[0] / z
    m2 = quad(lambda r: r * r * w(r), lo, hi)[0] / z
    return m2 - m1 * m1
