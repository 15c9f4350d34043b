"""Connector elements (paper Fig. 5A-B): the half unit, the full unit, chains and branches.

**Half unit.**  Four slabs hinged into a rhombus.  The input signal drives one diagonal
and the output is the other, perpendicular, diagonal.  With side ``s`` and diagonals
``p`` (input) and ``q`` (output), half of each diagonal and one side form a right
triangle:

    (p/2)**2 + (q/2)**2 = s**2,   so   q = sqrt(4 s**2 - p**2),

which falls as ``p`` grows: the half unit turns an expansion into a contraction and
rotates the signal axis by 90 degrees, as the paper says.  Choosing

    4 s**2 = L0**2 + L1**2

(``L0`` = the wire's length in state 0, ``L1`` = in state 1) makes it map L0 to L1 and
L1 to L0 *exactly*: a logical NOT between two wires of the same convention.  Expanding
wires (L0 = 1, L1 = 1.5 sigma) give s = 0.901 sigma; contracting ones (L0 = 1,
L1 = 0.5 sigma) give s = 0.559 sigma.

**Layers.**  The rhombus's four hinge axes are parallel to the chain's local *tangent*
``t``; the slabs are ``w`` wide along ``t`` and form a layer.  A *pair* is two points
``c -/+ (L/2) u`` (centre ``c``, unit axis ``u``, length ``L``: the signal).  A half unit
takes its input pair at its lower face (posts of length ``g/2`` carry the joint sites
off the slab) and gives its output pair, axis ``v = t x u``, at ``c + pitch t`` with
``pitch = w + g``.

**Full unit.**  Two half units, the second turned 90 degrees about the tangent (the
signal's direction of travel), joined by two universal joints at the shared pair.  The
two ball joints leave the second half unit one rotation relative to the first: about
the shared pair's axis.  That is the floppy bending mode; successive junctions bend
about perpendicular axes, so a chain bends in any direction while its diagonals carry
the signal.  Two NOTs make the full unit a buffer.  A junction bent by ``beta`` keeps
its two layers apart while ``g >= 2 r tan(beta/2)`` (``r``: the largest half diagonal),
so the gap sets the largest bend (:func:`max_bend`).

**Branch (fan-out).**  Several half units may hang on one pair, each turned about the
pair's axis by its own angle: a book's pages on its spine.  Their posts are made long
enough (``branch_post``) that the pages clear each other and the incoming layer.

Every element here is built from :mod:`mlc.gates.parts` (slab bodies, hinges, universal
joints, muscles).  Units: sigma (length), k0 (stiffness), radians.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from mlc.gates.library import SIGNALS, Design, _check_signal, load_design
from mlc.gates.parts import axis_sites, hinge, muscle, segment_box, slab_body, universal_joint
from mlc.geometry.rotation import cross3, expmap
from mlc.scene.model import Body, Bond, Muscle, Probe, Scene

_EX = np.array([1.0, 0.0, 0.0])
_EY = np.array([0.0, 1.0, 0.0])
_EZ = np.array([0.0, 0.0, 1.0])

DEFAULT_GAP = 0.5          # sigma: gap between two layers at a junction (posts of gap/2 each)
POST_WIDTH = 0.08          # sigma: cross-section of the posts that carry the joint sites
STOP_FRACTION = 0.9        # a junction stop engages at this fraction of the largest bend (max_bend)
STOP_ARM = 1.5             # sigma: its sites sit this far from the junction's joint, one on each layer's centre line


def wire_lengths(signal: str, design: Design | None = None) -> tuple[float, float]:
    """(state-0 length, state-1 length) of a wire in ``signal`` convention, sigma."""
    _check_signal(signal)
    d = design or load_design()
    return d.rest, d.rest + (d.signal if signal == "expand" else -d.signal)


def half_unit_side(signal: str = "expand", design: Design | None = None) -> float:
    """Rhombus side ``s`` (hinge to hinge, sigma) of a half unit that inverts wires of
    ``signal`` convention exactly: ``4 s^2 = L0^2 + L1^2``."""
    L0, L1 = wire_lengths(signal, design)
    return 0.5 * math.hypot(L0, L1)


def half_unit_out(p: float, signal: str = "expand", design: Design | None = None) -> float:
    """Output diagonal (sigma) for input diagonal ``p`` (sigma); the rhombus closes
    (no real output) for ``p >= 2 s``."""
    s = half_unit_side(signal, design)
    if not 0.0 < p < 2.0 * s:
        raise ValueError(f"input diagonal {p} outside (0, {2 * s}) for a rhombus of side {s}")
    return math.sqrt(4.0 * s * s - p * p)


@dataclass(frozen=True)
class ConnectorGeometry:
    """Sizes of the connector elements of one convention (sigma)."""

    signal: str
    L0: float               # wire length in state 0
    L1: float               # wire length in state 1
    side: float             # rhombus side
    width: float            # slab width along the tangent (layer thickness)
    thickness: float        # slab thickness
    gap: float              # junction gap between layers
    k: float                # joint stiffness (k0)

    @property
    def pitch(self) -> float:
        """Distance from a half unit's input pair to its output pair (sigma)."""
        return self.width + self.gap

    def length(self, state: int) -> float:
        return self.L1 if state else self.L0

    @property
    def reach(self) -> float:
        """The largest half diagonal of a layer (sigma)."""
        return 0.5 * max(self.L0, self.L1)

    @property
    def branch_post(self) -> float:
        """Post length that lets pages of a branch, turned 90 degrees apart about one pair,
        clear each other: a little more than the largest half diagonal (sigma)."""
        return self.reach + 0.25


def connector_geometry(signal: str = "expand", design: Design | None = None,
                       gap: float = DEFAULT_GAP) -> ConnectorGeometry:
    d = design or load_design()
    L0, L1 = wire_lengths(signal, d)
    return ConnectorGeometry(signal, L0, L1, half_unit_side(signal, d), d.slab_width, d.slab_thickness,
                             float(gap), d.k)


def max_bend(geo: ConnectorGeometry) -> float:
    """Largest bend (rad) of one junction before its two layers touch: 2 atan(g / 2r)."""
    return 2.0 * math.atan(geo.gap / (2.0 * geo.reach))


# ---------------------------------------------------------------------------
# Pairs and frames
# ---------------------------------------------------------------------------

@dataclass
class Pair:
    """A signal: two sites ``lo``/``hi`` ("body.site") at ``centre -/+ (length/2) axis``."""

    lo: str
    hi: str
    centre: np.ndarray
    axis: np.ndarray
    length: float

    def points(self) -> tuple[np.ndarray, np.ndarray]:
        return self.centre - 0.5 * self.length * self.axis, self.centre + 0.5 * self.length * self.axis


@dataclass
class Parts:
    """Bodies, bonds and muscles of a piece of mechanism, to be added to a scene."""

    bodies: list[Body] = field(default_factory=list)
    bonds: list[Bond] = field(default_factory=list)
    muscles: list[Muscle] = field(default_factory=list)

    def add(self, other: "Parts") -> "Parts":
        self.bodies += other.bodies
        self.bonds += other.bonds
        self.muscles += other.muscles
        return self


def rotate(v, axis, angle: float) -> np.ndarray:
    """``v`` turned by ``angle`` (rad) about the unit ``axis``."""
    return expmap(np.asarray(axis, float) * float(angle)) @ np.asarray(v, float)


def _unit(v) -> np.ndarray:
    v = np.asarray(v, float)
    return v / np.linalg.norm(v)


def half_unit_parts(prefix: str, centre, axis, tangent, state: int, geo: ConnectorGeometry,
                    in_post: float | None = None, out_post: float | None = None,
                    out_stop: float = POST_WIDTH, in_stop: float = POST_WIDTH) -> tuple[Parts, Pair, Pair]:
    """One half unit whose input pair (centre ``centre``, axis ``axis``) carries ``state``.

    Slabs ``{prefix}_AB, _BC, _CD, _DA``; A and C are the input vertices (``-/+ axis``),
    D and B the output vertices (``-/+ v``, ``v = tangent x axis``).  The layer spans
    ``in_post .. in_post + width`` along ``tangent`` from the input pair; the output pair
    sits ``out_post`` beyond it.  The output (input) posts stop ``out_stop`` (``in_stop``) short of their joint
    sites (where the joint part sits; longer where the pair meets a wide slab, such as a
    gate's lever).  Returns (parts, input pair, output pair)."""
    g2 = 0.5 * geo.gap
    in_post = g2 if in_post is None else float(in_post)
    out_post = g2 if out_post is None else float(out_post)
    c, u, t = np.asarray(centre, float), _unit(axis), _unit(tangent)
    if abs(float(u @ t)) > 1e-9:
        raise ValueError("a half unit's tangent must be perpendicular to its input axis")
    v = cross3(t, u)
    Lin, Lout = geo.length(state), geo.length(1 - state)
    w = geo.width
    mid = c + (in_post + 0.5 * w) * t              # layer mid-plane centre
    V = {"A": mid - 0.5 * Lin * u, "C": mid + 0.5 * Lin * u, "D": mid - 0.5 * Lout * v, "B": mid + 0.5 * Lout * v}
    out_c = c + (in_post + w + out_post) * t
    # joint sites (post ends): A, C below the layer; D, B above it
    J = {"A": V["A"] - (0.5 * w + in_post) * t, "C": V["C"] - (0.5 * w + in_post) * t,
         "D": V["D"] + (0.5 * w + out_post) * t, "B": V["B"] + (0.5 * w + out_post) * t}
    carrier = {"AB": "A", "CD": "C", "DA": "D", "BC": "B"}   # the slab that carries each post
    parts = Parts()
    for x, y in (("A", "B"), ("B", "C"), ("C", "D"), ("D", "A")):
        name = f"{prefix}_{x}{y}"
        post = carrier[x + y]
        sites = {**axis_sites(x, V[x], t, w), **axis_sites(y, V[y], t, w), post: J[post]}
        if x + y == "DA":                  # junction_stops: on the line through D along t, STOP_ARM below its joint
            sites["stop_out"] = J["D"] - STOP_ARM * t
        if x + y == "AB":                  # ... and through A, STOP_ARM above its joint
            sites["stop_in"] = J["A"] + STOP_ARM * t
        body = slab_body(name, [(V[x], V[y])], sites, t, w, geo.thickness)
        # the post: a thin rod from the layer face to the joint site (body frame)
        # (it stops POST_WIDTH short of the joint site, where the joint part sits)
        face = V[post] + (0.5 * w if post in "DB" else -0.5 * w) * t
        run = float(np.linalg.norm(J[post] - face))
        stop = out_stop if post in "DB" else in_stop
        end = J[post] + (face - J[post]) * (stop / run) if run > stop else face
        if np.linalg.norm(end - face) > 1e-6:
            body.boxes.append(segment_box(face - body.position, end - body.position, u if post in "DB" else v,
                                          POST_WIDTH, POST_WIDTH))
        parts.bodies.append(body)
    for x, (s1, s2) in {"A": ("DA", "AB"), "B": ("AB", "BC"), "C": ("BC", "CD"), "D": ("CD", "DA")}.items():
        parts.bonds += hinge(f"{prefix}_h{x}", f"{prefix}_{s1}", f"{prefix}_{s2}", x, x, geo.k)
    pin = Pair(f"{prefix}_AB.A", f"{prefix}_CD.C", c, u, Lin)
    pout = Pair(f"{prefix}_DA.D", f"{prefix}_BC.B", out_c, v, Lout)
    return parts, pin, pout


def join(name: str, a: Pair, b: Pair, k: float = 1.0, tolerance: float = 0.0) -> list[Bond]:
    """Two universal joints joining pair ``a`` to pair ``b`` end to end (lo-lo, hi-hi)."""
    return [universal_joint(f"{name}_lo", a.lo, b.lo, k, tolerance),
            universal_joint(f"{name}_hi", a.hi, b.hi, k, tolerance)]


def junction_stops(name: str, lower: str, upper: str, geo: "ConnectorGeometry", k: float = 1.0,
                   contact: float | None = None) -> list[Bond]:
    """A flat-bottom bond that stops the junction between half units ``lower`` and
    ``upper`` (prefixes; ``upper`` hangs on ``lower``'s output pair) before their layers
    touch (docs/circuits.md section 1.2, "Junction stops").

    The line through ``lower``'s output vertex D along its tangent t0 and the line through
    ``upper``'s input vertex A along t1 both pass through the joint that joins them.  A
    site on each line, ``STOP_ARM`` from the joint (into each layer), is therefore
    2 m cos(beta/2) apart when the junction bends by beta (either way): a distance that
    falls monotonically all the way to beta = 180 degrees and does not depend on the
    rhombi's opening (the wire's state), so no solver step can jump past the stop.  The
    bond (U = k/2 max(0, |d - rest| - tol)^2) is free down to the distance at
    ``STOP_FRACTION`` of :func:`max_bend` (the closing side's contact at the larger half
    diagonal) and stiff below.  ``contact``: the bend (rad) where the two layers meet, when not
    :func:`max_bend` (a page with long posts, ``mlc.robot.build.page_stop``).  Units: sigma, k0."""
    m = STOP_ARM
    d_stop = 2.0 * m * math.cos(0.5 * STOP_FRACTION * (max_bend(geo) if contact is None else contact))
    d_free = 2.0 * m + 0.5                          # never reached (d <= 2 m)
    rest, tol = 0.5 * (d_stop + d_free), 0.5 * (d_free - d_stop)
    return [Bond(f"{name}", f"{lower}_DA.stop_out", f"{upper}_AB.stop_in", k, rest, tol, "bond", None)]


def half_unit_prefix(pair: Pair) -> str | None:
    """The prefix of the half unit whose output pair is ``pair`` (None: not a half unit's)."""
    return pair.lo[:-len("_DA.D")] if pair.lo.endswith("_DA.D") and pair.hi.endswith("_BC.B") else None


def chain_frames(centre, axis, tangent, bends, pitch: float):
    """Forward kinematics of a chain of ``len(bends)`` half units.

    Half unit ``i`` has input pair (c_i, u_i) and tangent t_i; its output pair is
    c_{i+1} = c_i + pitch t_i with axis u_{i+1} = t_i x u_i, and the next tangent is
    t_{i+1} = R(u_{i+1}, bends[i+1]) t_i.  ``bends[0]`` turns the first tangent about the
    first axis.  Returns the lists (c_0..c_n, u_0..u_n, t_0..t_{n-1})."""
    u = _unit(axis)
    t = rotate(_unit(tangent), u, bends[0]) if len(bends) else _unit(tangent)
    cs, us, ts = [np.asarray(centre, float)], [u], []
    for i in range(len(bends)):
        ts.append(t)
        cs.append(cs[-1] + pitch * t)
        us.append(cross3(t, us[-1]))
        if i + 1 < len(bends):
            t = rotate(t, us[-1], bends[i + 1])
    return cs, us, ts


def chain_parts(prefix: str, centre, axis, tangent, bends, state: int, geo: ConnectorGeometry,
                k: float | None = None, tolerance: float = 0.0,
                in_stop: float = POST_WIDTH, stops: bool = False, only=None) -> tuple[Parts, list[Pair]]:
    """A chain of ``len(bends)`` half units (see :func:`chain_frames`), the first input pair
    carrying ``state``.  Consecutive half units are joined by two universal joints, and
    with ``stops`` by the :func:`junction_stops` bond that keeps their layers apart.
    ``in_stop``: how far the first half unit's input posts stop short of their joints (see
    :func:`half_unit_parts`).  Returns (parts, pairs) with pairs[0] the chain's input and
    pairs[-1] its output.  ``only`` (a set of indices): only those half units' bodies (the
    same bodies as in the whole chain; no bonds, no pairs): what a test of a few layers needs."""
    cs, us, ts = chain_frames(centre, axis, tangent, bends, geo.pitch)
    parts, pairs = Parts(), []
    k = geo.k if k is None else k
    if only is not None:
        for i in sorted(only):
            if 0 <= i < len(ts):
                parts.add(half_unit_parts(f"{prefix}_{i}", cs[i], us[i], ts[i], (state + i) % 2, geo,
                                          in_stop=in_stop if i == 0 else POST_WIDTH)[0])
        return parts, pairs
    for i, t in enumerate(ts):
        p, pin, pout = half_unit_parts(f"{prefix}_{i}", cs[i], us[i], t, (state + i) % 2, geo,
                                       in_stop=in_stop if i == 0 else POST_WIDTH)
        parts.add(p)
        if pairs:
            parts.bonds += join(f"{prefix}_j{i}", pairs[-1], pin, k)
            if stops:
                parts.bonds += junction_stops(f"{prefix}_s{i}", f"{prefix}_{i - 1}", f"{prefix}_{i}", geo, k)
        else:
            pairs.append(pin)
        pairs.append(pout)
    if tolerance:
        for b in parts.bonds:
            b.tolerance = tolerance
    return parts, pairs


# ---------------------------------------------------------------------------
# Scenes: one element each, with a muscle at the input and probes along the way
# ---------------------------------------------------------------------------

def _probe(name: str, output: str, pair: Pair, n_half: int, geo: ConnectorGeometry) -> Probe:
    """A probe across ``pair`` reading the wire's state there (L0 = 0, L1 = 1); the scene's
    truth table says what it should read after ``n_half`` half units (an odd count inverts)."""
    return Probe(name, output, pair.lo, pair.hi, geo.L0, geo.L1)


def half_unit_scene(signal: str = "expand", design: Design | None = None) -> Scene:
    """A half unit as a scene, posed at rest: a muscle across the input diagonal A-C (along
    x), the output probe across D-B (along y); hinge axes along z.  Truth table: NOT."""
    geo = connector_geometry(signal, design, gap=0.0)
    parts, pin, pout = half_unit_parts("slab", np.zeros(3), _EX, _EZ, 0, geo)
    muscles = [muscle("muscle_in", "a", pin.lo, pin.hi, geo.L0, geo.L1, geo.k)]
    probes = [Probe("out", "out", pout.lo, pout.hi, geo.L0, geo.L1)]
    scene = Scene(name=f"half_unit_{signal}", bodies=parts.bodies, bonds=parts.bonds, muscles=muscles,
                  probes=probes, inputs=["a"], outputs=["out"], truth_table={"0": "1", "1": "0"},
                  meta={"element": "connector_half_unit", "signal": signal, "side": round(geo.side, 6)})
    return scene.check()


def chain_scene(units: int, signal: str = "expand", bend: float = 0.0, design: Design | None = None,
                tolerance: float = 0.0, gap: float = DEFAULT_GAP, probe_every_unit: bool = False,
                stops: bool = False) -> Scene:
    """A chain of ``units`` full units (2 units half units) driven by a muscle across its
    first pair; the output probe ``out`` reads the far end (a buffer).  ``bend`` (rad) bends
    every other junction (the ones about the same axis), so the chain lies on a planar arc.
    With ``probe_every_unit`` the pair after each full unit is probed too (outputs
    ``u1 .. u{units}``; ``out`` is the last).  ``tolerance`` (sigma) loosens every joint;
    ``stops`` adds the :func:`junction_stops` (as compiled circuits have them)."""
    if units < 1:
        raise ValueError("a chain has at least one unit")
    geo = connector_geometry(signal, design, gap)
    n = 2 * units
    # the even junctions' axes alternate in sign (u_{i+2} = -u_i): alternate the bend to bend one way
    bends = [0.0] + [(bend if i % 4 == 2 else -bend) if i % 2 == 0 else 0.0 for i in range(1, n)]
    if abs(bend) > max_bend(geo) + 1e-12:
        raise ValueError(f"bend {bend:.3f} rad exceeds the junction's largest bend {max_bend(geo):.3f} rad "
                         f"at gap {gap} sigma")
    parts, pairs = chain_parts("c", np.zeros(3), _EX, _EZ, bends, 0, geo, tolerance=tolerance, stops=stops)
    muscles = [muscle("muscle_in", "a", pairs[0].lo, pairs[0].hi, geo.L0, geo.L1, geo.k)]
    outputs, probes = [], []
    if probe_every_unit:
        for u in range(1, units):
            outputs.append(f"u{u}")
            probes.append(_probe(f"u{u}", f"u{u}", pairs[2 * u], 2 * u, geo))
    outputs.append("out")
    probes.append(_probe("out", "out", pairs[-1], n, geo))
    tt = {"0": "0" * len(outputs), "1": "1" * len(outputs)}
    scene = Scene(name=f"chain{units}_{signal}", bodies=parts.bodies, bonds=parts.bonds, muscles=muscles,
                  probes=probes, inputs=["a"], outputs=outputs, truth_table=tt,
                  meta={"element": "connector_chain", "signal": signal, "units": units, "bend": bend,
                        "gap": gap, "tolerance": tolerance, "side": round(geo.side, 6)})
    return scene.check()


def full_unit_scene(signal: str = "expand", design: Design | None = None, bend: float = 0.0) -> Scene:
    """One full connector unit (two half units, the second turned 90 degrees about the
    tangent, joined by two universal joints): a buffer with one floppy bending mode."""
    sc = chain_scene(1, signal, 0.0, design)
    if bend:
        geo = connector_geometry(signal, design)
        parts, pairs = chain_parts("c", np.zeros(3), _EX, _EZ, [0.0, bend], 0, geo)
        sc = Scene(name=sc.name, bodies=parts.bodies, bonds=parts.bonds,
                   muscles=[muscle("muscle_in", "a", pairs[0].lo, pairs[0].hi, geo.L0, geo.L1, geo.k)],
                   probes=[_probe("out", "out", pairs[-1], 2, geo)], inputs=["a"], outputs=["out"],
                   truth_table={"0": "0", "1": "1"}, meta=dict(sc.meta, bend=bend)).check()
    sc.name = f"full_unit_{signal}"
    sc.meta["element"] = "connector_full_unit"
    return sc


def branch_angles(k: int) -> list[float]:
    """Turn angles (rad, about the pair axis, from straight on) of the pages of a ``k``-way
    branch: 0 for one page; spread over [-90, 90] degrees for more."""
    if k < 1:
        raise ValueError("a branch has at least one page")
    if k == 1:
        return [0.0]
    return [math.radians(-90.0 + 180.0 * i / (k - 1)) for i in range(k)]


def branch_parts(prefix: str, pair: Pair, tangent, state: int, k: int, geo: ConnectorGeometry,
                 angles=None) -> tuple[Parts, list[Pair], list[np.ndarray]]:
    """``k`` half units (pages) hung on ``pair`` (which carries ``state``), page ``i`` turned
    by ``angles[i]`` about the pair axis from ``tangent``; posts of ``geo.branch_post`` keep
    the pages clear of each other when ``k > 1``.  Returns (parts, page output pairs,
    page tangents)."""
    angles = branch_angles(k) if angles is None else list(angles)
    parts, outs, tans = Parts(), [], []
    post = geo.branch_post if k > 1 else 0.5 * geo.gap
    for i, a in enumerate(angles):
        t = rotate(tangent, pair.axis, a)
        p, pin, pout = half_unit_parts(f"{prefix}_p{i}", pair.centre, pair.axis, t, state, geo, in_post=post)
        p.bonds += join(f"{prefix}_p{i}_j", pair, pin, geo.k)
        parts.add(p)
        outs.append(pout)
        tans.append(t)
    return parts, outs, tans


def branch_scene(k: int = 3, signal: str = "expand", units: int = 1, design: Design | None = None) -> Scene:
    """A ``k``-way branch: a muscle drives one half unit whose output pair carries ``k``
    pages; each page continues as a chain so that every branch has ``2 units`` half units
    (page included) after the first one, and an odd total: the probes ``out0..`` read NOT
    of the input through the first half unit plus an even number of half units."""
    geo = connector_geometry(signal, design)
    parts, pin, pout = half_unit_parts("src", np.zeros(3), _EX, _EZ, 0, geo)
    bparts, pages, tans = branch_parts("br", pout, _EZ, 1, k, geo)
    parts.add(bparts)
    probes, outputs = [], []
    for i, (pg, t) in enumerate(zip(pages, tans)):
        n_more = 2 * units - 1            # half units after the page
        if n_more:
            cparts, pairs = chain_parts(f"b{i}", pg.centre, pg.axis, t, [0.0] * n_more, 0, geo)
            parts.add(cparts)
            parts.bonds += join(f"b{i}_j0", pg, pairs[0], geo.k)
            end = pairs[-1]
        else:
            end = pg
        outputs.append(f"out{i}")
        probes.append(_probe(f"out{i}", f"out{i}", end, 1 + 2 * units, geo))
    muscles = [muscle("muscle_in", "a", pin.lo, pin.hi, geo.L0, geo.L1, geo.k)]
    tt = {"0": "1" * k, "1": "0" * k}
    scene = Scene(name=f"branch{k}_{signal}", bodies=parts.bodies, bonds=parts.bonds, muscles=muscles,
                  probes=probes, inputs=["a"], outputs=outputs, truth_table=tt,
                  meta={"element": "connector_branch", "signal": signal, "pages": k, "units": units})
    return scene.check()


__all__ = ["SIGNALS", "ConnectorGeometry", "Pair", "Parts", "branch_angles", "branch_parts", "branch_scene",
           "chain_frames", "chain_parts", "chain_scene", "connector_geometry", "full_unit_scene", "half_unit_out",
           "half_unit_parts", "half_unit_prefix", "half_unit_scene", "half_unit_side", "join", "junction_stops", "max_bend", "rotate", "wire_lengths"]
