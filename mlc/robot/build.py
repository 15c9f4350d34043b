"""A circuit scene plus a robot body (:mod:`mlc.robot.spec`) becomes one robot scene.

**Skeleton** (docs/robot.md, section 2).  A planar chain in a horizontal plane (normal
+z) ``height`` sigma above the circuit's top, heading +x.  Local coordinates: x along
the chain, y towards the "up" side.  The body (unit 0, cell (0, 0)) is a slab over
x in [-l/2, l/2]; unit i (l = ``unit_length``, a_i = (i - 1/2) l) is two bodies: a
joint piece ``skel_j{i}`` over [a_i, a_i + s] (s = ``JOINT_LENGTH``) and a link
``skel_u{i}`` over [a_i + s, a_i + l].  The up hinge sits at (a_i, +w/2) between the
previous link and the joint piece; the down hinge at (a_i + s, -w/2) between the joint
piece and the link.  Both hinges have their axis along +z.

**A DOF** is a hinge with two lever arms of length r, one on each body, at the angle
theta0 apart when straight.  The distance of the arm tips, 2 r sin(theta/2), is the
DOF's length: ``dof_rest`` (d0) straight, d0 + ``dof_stroke`` (d1) turned by 90 degrees.
With x = theta0/2 the two conditions give

    cot x = (d1/d0 - cos 45deg) / sin 45deg,     r = d0 / (2 sin x)

(d0 = 2, d1 = 3 sigma: x = 41.72 deg, theta0 = 83.4 deg, r = 1.503 sigma).

**Coupling** ("lever").  The circuit's output pair (length L0 at 0, L1 at 1) is carried
by a connector chain (routed by :func:`mlc.circuit.route.solve_route`, an even number of
half units, so it arrives with the output's own state) to two sites on the arms at
distance r L0/d0 from the hinge.  By similar triangles the sites' distance is L0/d0
times the tips' distance, so the pair's L0 -> L1 is the DOF's d0 -> d1 exactly when
L1/L0 = d1/d0 (1.5 for the paper's numbers and expanding wires): the arms are levers of
gain d0/L0 = 2.  The sites sit ``POST`` sigma below the skeleton plane, so the chain's
last layer stays under the skeleton.  "lock": a constant output (its probe spans one
rigid slab) holds its DOF with a plain bond between the tips at its constant length.
"muscle": in a circuit compiled with a muscle per lever (``mlc compile --muscle-per-lever``),
an output that is a circuit input itself (recorded in ``meta["connector"]["input_outputs"]``)
drives its DOF by a muscle of that input between the two sites where a chain would end
(in the skeleton's plane, not under it): the circuit's own muscle (L0 -> L1, k0) on the
same levers of gain d0/L0, as the input's gate levers are driven, instead of a chain from
the input's source (docs/robot.md 3.4).

**Joint stops** (docs/robot.md section 2.3).  Every DOF hinge also gets two flat-bottom
bonds (:func:`dof_stops`) that leave it free over [-15, 105] degrees of turn and close
the lever triangle's mirror equilibria at 180 and -90 degrees.

**Wrist** (docs/robot.md section 2.2; ``WRIST``, on since session 10).  A chain does not end
on the lever sites itself: it ends on ``WRIST_UNITS`` = 3 straight half units going up (+z)
whose input posts are ``WRIST_POST`` = 1.5 sigma long, so each of their junctions bends up to
2 atan((WRIST_POST + gap/2) / 2 reach) = 99 degrees before its layers touch (a chain
junction: 37).  Three such junctions about alternating axes (x, y, x) make any rotation,
so the wrist takes the lever's turn about z as the skeleton folds (up to 106 degrees in
the Tetris O pose), which a chain of 37-degree junctions could take only by bending
past its largest bend.

**Chain stops** (docs/robot.md section 2.2; ``CHAIN_STOPS``, on since session 10: without the
wrist the Tetris couplings cannot reach the O pose with them).  Every junction of a coupling chain has the
circuit's junction stop (:func:`mlc.gates.connector.junction_stops`); a chain's first
junction gets one too when it hangs on a half unit, or a tap stop (:func:`_lever_stop`)
when it hangs on a gate's output lever.  ``SLACK_FRACTION`` > 0 lengthens the chains so
that none spans more than that fraction of its length in any row (section 2.4; off).

**Two chains on one output** (docs/robot.md section 2.2).  The second chain leaves on a page: a
half unit with long input posts, turned about its pair's axis.  With ``PAGE_ON_CHAIN`` (session 51)
the page hangs on the first chain's first half unit's output pair, beside that chain's next half
unit (a branch on a half unit, as the circuit's pages hang on a source half unit), so the gate's
output lever carries the joints of one chain only; the page then gets NOT the output (the half unit
inverts), and its chain is even.  Off, the page hangs on the output pair itself (session 8).

**Chains kept apart** (docs/robot.md section 2.6; ``AVOID_CHAINS`` = 1.5 sigma, on since
session 11).  Every chain after the first is routed with the router's ``avoid`` term, at least
``AVOID_CHAINS`` from the body centres of the chains placed before; if no start gives a
kept-apart route whose slabs are clear of the bodies near it and of itself
(:func:`_chain_overlap`), the chain is routed as without it (``meta.robot.dofs[].chain.avoid``
records which).

**Stiffness.**  The coupling chains are connector chains like the circuit's: every bond
of theirs (half-unit hinges, joins, the universal joints on the lever sites, junction and
tap stops) gets the circuit's joint stiffness (``mlc compile --joint-k K``, recorded in the
circuit scene's ``meta["connector"]["joint_k"]``).  The skeleton keeps the design k (k0):
its hinges, joint stops (``STOP_K`` k0) and locks; the lever arms are rigid parts of its
bodies.  The circuit's muscles keep k0 too (docs/robot.md section 2.5).

Every DOF has a probe across its tips, named ``dof_u{i}_{side}``, reading the DOF's
own output (rest d0, actuated d1): the circuit verifier checks the DOF lengths like any
output, and :mod:`mlc.robot.verify` reads the shape.  Units: sigma, k0, radians.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from mlc.errors import MlcError
from mlc.gates.connector import (POST_WIDTH, STOP_ARM, Pair, chain_parts, connector_geometry, half_unit_parts,
                                 half_unit_prefix, join,
                                 junction_stops, max_bend)
from mlc.gates.parts import axis_sites, hinge, segment_box, slab_body
from mlc.geometry.rotation import matrix_to_quat
from mlc.robot.spec import RobotSpec
from mlc.scene.model import Body, Bond, Muscle, Probe, Scene

JOINT_LENGTH = 2.0       # sigma: length of a unit's joint piece (between its up and down hinges)
POST = 0.6               # sigma: the lever sites sit this far below the skeleton plane
#: sigma: the circuit a robot is built on ends its chains this far under the gates' input levers
#: (mlc.circuit.build.CircuitOptions.end_drop), less than a circuit's END_DROP (1.5): with the
#: ends 1.5 sigma under them the Tetris circuit's chains change so that the coupling to u3_up
#: found no route clear of them ("cannot route output u3_up"); with 1.0 every coupling routes
#: clear, and the end joints still keep 0.48 sigma from the gate's joint at d (docs/robot.md 6)
CIRCUIT_END_DROP = 1.0
#: the branch leans the circuit a robot is built on tries for the print's margin
#: (mlc.circuit.build.CircuitOptions.print_leans): none. With PRINT_LEANS (0.8, session 53) the
#: Tetris robot's circuit changed (1675 bodies) and its couplings with it: every start of the
#: coupling to u4_dn then met another body (the builder kept the least overlapping, through gate g2
#: and against rc_u4_up, -0.229 sigma as built) and the static row 10 (S) stopped 12.6 degrees short
#: of its turn; without the lean the robot (2672 bodies) folds all four rows statically with no DOF
#: error and is clear as built (docs/robot.md 6, session 54)
CIRCUIT_PRINT_LEANS: tuple = ()
HINGE_WIDTH = 0.5        # sigma between the two bonds of a skeleton hinge (along z)
APPROACH_RUN = 4.0       # sigma: the chain's last stretch rises straight into the skeleton
FAN_ANGLES = (0.0, 70.0, -70.0, 140.0, -140.0, 180.0)   # deg: a chain's first tangent turned about its output pair
PAGE_FANS = (90.0, -90.0, 120.0, -120.0, 150.0, -150.0, 180.0, 60.0, -60.0)   # deg: a second chain's page, the same
PAGE_CLEAR = 0.2         # sigma: extra page post beyond the branch's (as mlc.circuit.build.PAGE_CLEAR)
CLEAR = 0.3              # sigma: a chain's body centres keep this far from every body placed before
SLACK = 0.0              # sigma: a sideways bulge half way up each chain (tried 4: no faster, docs/robot.md 3.1)
BACK = 4.0               # sigma behind the circuit (+y) where a chain from inside the circuit rises
STOP_MARGIN = math.radians(15.0)   # rad: a DOF swings freely from -15 to 90 + 15 degrees (its stops)
STOP_R_OVER = (1.8, 1.2)           # sigma: the over-turn stop's sites, on both bodies along one ray
STOP_R_UNDER = 1.2                 # sigma: the under-turn stop's sites
STOP_UNDER_LOW = math.radians(52.5)  # rad: the under-turn stop's arms this far apart at its lower limit
STOP_K = 4.0                       # k0: the stops' stiffness once engaged (a wire joint's is 1)
LEVER_STOP = 0.35                  # sigma: a chain's first posts stop this short of a gate lever's joints (as in circuits)
SLACK_FRACTION = 0.0               # >0: a chain spans at most this fraction of its length in any row (2.4; 0.6 tried: no faster)
WRIST = True                       # each chain ends on a wrist of WRIST_UNITS long-post half units (docs/robot.md 2.2)
WRIST_UNITS = 3
WRIST_POST = 1.5                   # sigma: the wrist half units' input posts (the junction gap grows to WRIST_POST + gap/2)
WRIST_POSTS: dict = {}             # DOF name -> its own wrist posts (sigma), e.g. {"u4_up": 1.0} (probe)
AVOID_CHAINS = 1.5                 # sigma, >0: routes pushed this far from the chains placed before, a start whose route
                                   # is not clear (of the others or of itself) falling back to the plain route (docs/robot.md 2.6)
PAGE_ON_CHAIN = True               # a second chain on one output pair leaves on a page hung on the first chain's first
                                   # half unit (a branch on a half unit, which the mesher prints as one joint part),
                                   # not on the output pair itself (session 51; False: the session-8 page on the pair)
CHAIN_STOPS = True                 # junction stops in the coupling chains (session 10, with the wrist; without
                                   # the wrist static row 11 of the Tetris robot folds wrong: docs/robot.md 2.2, 2.4, 6)


@dataclass
class DofGeometry:
    """The lever triangle of a DOF (sigma, rad): arms from the hinge at the angle theta0
    apart (theta0 + 90 deg when turned); the output pair joins them at ``p`` (first body)
    and ``q`` (second body) from the hinge, the DOF's tips sit at ``gain`` times that."""

    L0: float
    L1: float
    theta0: float
    p: float
    q: float
    gain: float
    alpha1: float           # direction of the first arm (rad from +x, up hinge; mirrored for dn)

    @property
    def d0(self) -> float:
        return self.gain * self.L0

    @property
    def d1(self) -> float:
        return self.gain * self.L1


def dof_geometry(L0: float, L1: float, d0: float, turn: float = math.pi / 2,
                 alpha1: float = math.radians(-130.0)) -> DofGeometry:
    """Arms at theta0 = 90 deg - turn/2 apart, so the mechanism swings from 45 to 135 deg
    (far from the dead points 0 and 180 deg, where the pair length stops depending on
    the angle).  With P = p q and S = p^2 + q^2 the law of cosines at theta0 and
    theta0 + turn gives

        L1^2 - L0^2 = 2 P (cos theta0 - cos(theta0 + turn)),   S = L0^2 + 2 P cos theta0,

    p, q = (sqrt(S + 2P) +- sqrt(S - 2P)) / 2; the tips are at gain = d0/L0 times p, q."""
    th0 = math.pi / 2 - turn / 2
    P = (L1 * L1 - L0 * L0) / (2.0 * (math.cos(th0) - math.cos(th0 + turn)))
    S = L0 * L0 + 2.0 * P * math.cos(th0)
    if P <= 0 or S < 2 * P:
        raise MlcError(f"no lever triangle turns a {L0} -> {L1} sigma signal into a {math.degrees(turn):.0f}-degree "
                       "turn", "dof_stroke", "use expanding wires (mlc compile --signal expand)")
    a, b = math.sqrt(S + 2 * P), math.sqrt(S - 2 * P)
    return DofGeometry(L0, L1, th0, 0.5 * (a + b), 0.5 * (a - b), d0 / L0, alpha1)


@dataclass
class DofStop:
    """A joint stop: a flat-bottom bond (``U = k/2 max(0, |d - rest| - tol)^2``) between a
    site on each body of a DOF, at ``r1`` and ``r2`` sigma from the hinge, on rays at
    ``beta1`` and ``beta2`` (rad from +x, up hinge; mirrored for dn).  The rays are
    ``psi0 = beta2 - beta1`` apart when straight and ``psi0 + t`` at a turn t, so the
    bond's length is ``sqrt(r1^2 + r2^2 - 2 r1 r2 cos(psi0 + t))``; it is force-free while
    t lies in [t_lo, t_hi] (and in that band's mirror psi -> -psi, which the other stop
    closes; docs/robot.md section 2.3)."""

    name: str
    r1: float
    r2: float
    beta1: float
    beta2: float
    t_lo: float
    t_hi: float

    def length(self, t: float) -> float:
        psi = self.beta2 - self.beta1 + t
        return math.sqrt(max(0.0, self.r1 ** 2 + self.r2 ** 2 - 2 * self.r1 * self.r2 * math.cos(psi)))

    @property
    def band(self) -> tuple[float, float]:
        """(rest, tol) of the flat-bottom bond: free between its lengths at t_lo and t_hi."""
        a, b = sorted((self.length(self.t_lo), self.length(self.t_hi)))
        if self.t_lo < -(self.beta2 - self.beta1) < self.t_hi:   # the rays cross inside the band
            a = self.length(-(self.beta2 - self.beta1))
        return 0.5 * (a + b), 0.5 * (b - a)


def dof_stops(margin: float = STOP_MARGIN) -> list[DofStop]:
    """The two stops of every DOF hinge (docs/robot.md section 2.3): the DOF swings freely
    over [-margin, 90 deg + margin].

    * ``over``: both rays straight into the bodies (beta = -90 deg, psi0 = 0), so the bond
      length grows with |t|; free for |t| <= 90 deg + margin.  It closes the lever
      triangle's mirror equilibrium at t = 180 deg (and everything past 90 + margin).
    * ``under``: rays psi0 = a + margin apart (a = ``STOP_UNDER_LOW``), free for psi in
      [a, a + 90 deg + 2 margin], a band of increasing length inside (0, 180 deg).  It
      closes t < -margin, in particular the triangle's other mirror at t = -90 deg.  Its
      own mirror band, t in [-2a - 90 - 3 margin, -2a - margin] = [120, 240] deg for
      a = 52.5, margin = 15 deg, lies beyond the over-turn stop's limit of 105 deg, so
      the two stops together leave exactly [-margin, 90 deg + margin]."""
    h = math.pi / 2
    psi0 = STOP_UNDER_LOW + margin
    if not (h / 2 < STOP_UNDER_LOW < h - 2 * margin):
        raise MlcError(f"stop margin {math.degrees(margin):.1f} deg leaves no under-turn stop", "STOP_MARGIN")
    r1, r2 = STOP_R_OVER
    return [DofStop("over", r1, r2, -h, -h, -(h + margin), h + margin),
            DofStop("under", STOP_R_UNDER, STOP_R_UNDER, -h - psi0 / 2, -h + psi0 / 2, -margin, h + margin)]


@dataclass
class Robot:
    scene: Scene
    chains: int
    half_units: int
    seconds: float


def _rotz(a):
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _pair_tangent(scene: Scene, lo: str, hi: str, centre, axis):
    """The side a pair is open to: from its carrier bodies' centres to the pair, across its axis."""
    cb = 0.5 * (scene.body(lo.split(".")[0]).position + scene.body(hi.split(".")[0]).position)
    t = centre - cb
    t = t - float(t @ axis) * axis
    n = float(np.linalg.norm(t))
    if n < 1e-6:
        t = np.array([0.0, 0.0, 1.0]) - axis[2] * axis
        n = float(np.linalg.norm(t))
    return t / n


def _lever_stop(name: str, lever: Body, site: str, axis, t_first, first: str, k: float) -> tuple[Body, Bond]:
    """The first junction of a coupling chain hung on a gate's output lever (pair axis
    ``axis``): a flat-bottom bond like the circuit's tap stop (``mlc.circuit.build._tap_stop``,
    docs/circuits.md "Junction stops"), from a site ``STOP_ARM`` behind the lever's joint
    ``site`` along the chain's built first tangent ``t_first`` to the first half unit's
    ``stop_in``.  The two are 2 m cos(phi/2) apart for a swing phi of the chain from its
    built direction; the bond is free up to TAP_CONTACT minus the built lean from the
    pair's upward normal (clamped to TAP_FREE).  Returns a copy of ``lever`` with the site
    (named after the chain: two chains may hang on one lever) and the bond.  Units: sigma, k0."""
    import copy

    from mlc.circuit.build import TAP_CONTACT, TAP_FREE
    m = STOP_ARM
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    t_first = np.asarray(t_first, float) / np.linalg.norm(t_first)
    up = np.array([0.0, 0.0, 1.0])
    t_up = up - float(up @ axis) * axis
    t_up /= np.linalg.norm(t_up)
    lean = math.acos(float(np.clip(t_first @ t_up, -1.0, 1.0)))
    free = min(max(TAP_CONTACT - lean, TAP_FREE[0]), TAP_FREE[1])
    lev = copy.deepcopy(lever)
    sname = f"stop_{name}"
    lev.sites[sname] = lev.rotation().T @ (lev.world(site) - m * t_first - lev.position)
    d_stop, d_free = 2.0 * m * math.cos(0.5 * free), 2.0 * m + 0.5
    return lev, Bond(name, f"{lev.name}.{sname}", f"{first}_AB.stop_in", k, 0.5 * (d_stop + d_free),
                     0.5 * (d_free - d_stop), "bond", None)


def _end_bonds(tag: str, lout: Pair, target: Pair, tax, k: float) -> list[Bond]:
    """The two universal joints from a chain's last pair ``lout`` to its DOF's lever sites."""
    same = float(lout.axis @ tax) > 0
    ends = (lout.lo, lout.hi) if same else (lout.hi, lout.lo)
    return [Bond(f"{tag}_end_lo", ends[0], target.lo, k, 0.0, 0.0, "universal", f"{tag}_end_lo"),
            Bond(f"{tag}_end_hi", ends[1], target.hi, k, 0.0, 0.0, "universal", f"{tag}_end_hi")]


def _join_aligned(name: str, a: Pair, b: Pair, k: float) -> list[Bond]:
    """Two universal joints from pair ``a`` to pair ``b``, lo to the nearer end."""
    if float(a.axis @ b.axis) > 0:
        return join(name, a, b, k)
    return [Bond(f"{name}_lo", a.lo, b.hi, k, 0.0, 0.0, "universal", f"{name}_lo"),
            Bond(f"{name}_hi", a.hi, b.lo, k, 0.0, 0.0, "universal", f"{name}_hi")]


def page_contact_bend(geo, post: float, lower_post: float | None = None, step: float = 0.25) -> float:
    """The bend (rad) at which a page hung on a half unit's output pair, its input posts
    ``post`` long, first meets that half unit's layer (whose output posts are ``lower_post``,
    g/2 when None), both turning about the pair's axis.  In the plane normal to the axis each
    layer is a rectangle: ``width`` thick along its tangent, from its post's end, and the
    layer's reach (the largest half diagonal) to either side; the two are tested by
    separating axes every ``step`` degrees.  For ``post`` = ``lower_post`` = g/2 this is the
    junction's :func:`mlc.gates.connector.max_bend` (to the step)."""
    a = 0.5 * geo.gap if lower_post is None else float(lower_post)
    r, w = geo.reach, geo.width
    low = np.array([[-a - w, -r], [-a, -r], [-a, r], [-a - w, r]])
    up0 = np.array([[post, -r], [post + w, -r], [post + w, r], [post, r]])

    def apart(P, Q):
        for poly in (P, Q):
            for i in range(4):
                e = poly[(i + 1) % 4] - poly[i]
                n = np.array([-e[1], e[0]])
                if (P @ n).max() <= (Q @ n).min() + 1e-12 or (Q @ n).max() <= (P @ n).min() + 1e-12:
                    return True
        return False

    for deg in np.arange(0.0, 180.0 + 1e-9, step):
        b = math.radians(deg)
        R = np.array([[math.cos(b), -math.sin(b)], [math.sin(b), math.cos(b)]])
        if not apart(low, up0 @ R.T):
            return b
    return math.pi


def page_stop(name: str, lower: str, page: str, geo, post: float, k: float) -> list[Bond]:
    """A junction stop (:func:`mlc.gates.connector.junction_stops`: a flat-bottom bond between
    ``lower``'s ``stop_out`` and ``page``'s ``stop_in``, 2 m cos(beta/2) apart at a bend beta) for
    a page hung on half unit ``lower``'s output pair with input posts ``post`` long: free up to
    STOP_FRACTION of the bend at which the page meets ``lower``'s layer
    (:func:`page_contact_bend`), where a chain junction's is free up to STOP_FRACTION of
    :func:`mlc.gates.connector.max_bend`.  Units: sigma, k0."""
    return junction_stops(name, lower, page, geo, k, contact=page_contact_bend(geo, post))


def _wrist(tag: str, tc, tax, state: int, geo, post: float | None = None):
    """WRIST_UNITS straight half units with long input posts, going up (+z) and ending on the
    lever pair (centre ``tc``, axis ``tax``): each of their junctions can bend far further than
    a chain's (gap WRIST_POST + gap/2 instead of gap), so together they can take the lever's
    turn about z.  ``state``: the signal state at the wrist's input; ``post``: the input posts
    (sigma; WRIST_POST when None).  Returns (parts, pin, pout)."""
    from mlc.gates.connector import Parts
    ez = np.array([0.0, 0.0, 1.0])
    post = WRIST_POST if post is None else post
    pitch = post + geo.width + 0.5 * geo.gap
    u = np.asarray(tax, float) / np.linalg.norm(tax)
    for _ in range(WRIST_UNITS):                       # back down: u_out = ez x u_in, so u_in = -ez x u_out
        u = -np.cross(ez, u)
    c = np.asarray(tc, float) - WRIST_UNITS * pitch * ez
    parts, pin, prev = Parts(), None, None
    for i in range(WRIST_UNITS):
        p, pi_, po = half_unit_parts(f"{tag}_w{i}", c, u, ez, (state + i) % 2, geo, in_post=post)
        parts.add(p)
        if prev is None:
            pin = pi_
        else:
            parts.bonds += join(f"{tag}_wj{i}", prev, pi_, geo.k)
        prev, c, u = po, po.centre, po.axis
    return parts, pin, prev


def _chain_overlap(placed: list[Body], placed_bonds: list[Bond], parts, new_bonds: list[Bond],
                   radius: float = 4.0) -> float:
    """Deepest interpenetration (sigma; 0 when clear) between a new chain's slabs and the
    bodies placed before, by the oriented-box test :func:`mlc.verify.overlap.clearance`
    (contact at shared joints left out, as there) on the placed bodies within ``radius``
    sigma of a new body centre."""
    from scipy.spatial import cKDTree

    from mlc.verify.overlap import clearance

    new_names = {b.name for b in parts.bodies}
    pc = np.array([b.position for b in placed])
    nc = np.array([b.position for b in parts.bodies])
    near = sorted({i for lst in cKDTree(pc).query_ball_point(nc, radius) for i in lst})
    sub = [placed[i] for i in near] + list(parts.bodies)
    keep = {b.name for b in sub}
    bonds = [bd for bd in list(placed_bonds) + list(parts.bonds) + list(new_bonds)
             if bd.a.split(".")[0] in keep and bd.b.split(".")[0] in keep]
    rep = clearance(Scene(name="chain_clearance", bodies=sub, bonds=bonds))
    return max((d for a, b, d in rep.overlaps if a in new_names or b in new_names), default=0.0)


def build_robot(circuit: Scene, spec: RobotSpec, allow_overlap: bool = False) -> Robot:
    """One scene: the circuit, the skeleton and a coupling per DOF (see the module doc),
    posed in the all-zero input row.

    A coupling chain whose every start (fan turn, page turn, kept apart or not) interpenetrates
    a slab placed before is refused (:class:`MlcError` naming the DOF's line in the robot file),
    unless ``allow_overlap``: then the least overlapping start is kept and its depth (sigma)
    recorded in ``meta.robot.dofs[].chain.overlap`` (``mlc verify`` reports the clearance)."""
    import time

    from mlc.circuit.route import BEND_FRACTION, solve_route

    t0 = time.perf_counter()
    meta = circuit.meta if isinstance(circuit.meta, dict) else {}
    signal = meta.get("signal", "expand")
    conn = meta.get("connector", {})
    design = connector_geometry(signal, gap=float(conn.get("gap", 0.5)))
    # the circuit's connector stiffness (mlc compile --joint-k): its meta records the joints' k
    # (design k times K); the coupling chains' bonds get the same, the skeleton keeps the design k
    joint_k = float(conn.get("joint_k", design.k)) / design.k
    if not (joint_k > 0 and math.isfinite(joint_k)):
        raise MlcError(f"the circuit scene records connector joint_k {joint_k * design.k}", "circuit meta",
                       "recompile the circuit (mlc compile --joint-k K, K > 0)")
    k_skel = design.k                                   # skeleton hinges, joint stops and locks (k0)
    geo = replace(design, k=design.k * joint_k)         # every coupling-chain bond (hinges, joins, stops, ends)
    if abs(geo.L1 / geo.L0 - (spec.dof_rest + spec.dof_stroke) / spec.dof_rest) > 1e-9:
        need = spec.dof_rest * (geo.L1 / geo.L0 - 1.0)
        raise MlcError(f"the circuit's wires go {geo.L0} -> {geo.L1} sigma ({signal}ing), a ratio the DOFs "
                       f"({spec.dof_rest} -> {spec.dof_rest + spec.dof_stroke}) must share for the lever coupling", f"{spec.source}: dof_stroke",
                       f"use dof_stroke: {need:g} with dof_rest: {spec.dof_rest:g}" if need > 0 else
                       "compile with --signal expand")
    dg = dof_geometry(geo.L0, geo.L1, spec.dof_rest)
    stops = dof_stops()
    l, w, s, th = spec.unit_length, spec.width, JOINT_LENGTH, spec.thickness
    tip1 = dg.gain * dg.p * np.array([math.cos(dg.alpha1), math.sin(dg.alpha1)])
    if w + tip1[1] < 0.1:
        raise MlcError(f"width {w} is too narrow for the lever arms (they reach {-tip1[1]:.2f} sigma across)",
                       f"{spec.source}: width", f"use at least {-tip1[1] + 0.1:.1f}")
    if min(s, l - s) + tip1[0] < 0.1:
        raise MlcError(f"unit_length {l} leaves no room for the lever arms", f"{spec.source}: unit_length",
                       f"use at least {2 * (-tip1[0] + 0.1):.1f}")
    A = circuit.arrays()
    lo_c, hi_c = A.pos.min(0), A.pos.max(0)
    zs = float(hi_c[2]) + spec.height
    driven = [p for p in circuit.probes if p.output in {d.output for d in spec.dofs}
              and p.a.split(".")[0] != p.b.split(".")[0]]
    xc = float(np.mean([circuit.site_world(p.a)[0] for p in driven])) if driven else 0.5 * (lo_c[0] + hi_c[0])
    origin = np.array([xc - 0.5 * spec.units * l, 0.5 * (lo_c[1] + hi_c[1]), zs])

    def W(x, y, z=0.0):
        return origin + np.array([x, y, z])

    zrow = "0" * len(circuit.inputs)
    table = circuit.truth_table or {}
    outs = circuit.outputs
    bits0 = table.get(zrow, "0" * len(outs))

    # ---- skeleton bodies, straight, in the local frame ---------------------------------
    ey, ez = np.array([0.0, 1.0, 0]), np.array([0.0, 0, 1.0])
    segs = {"skel_u0": (-0.5 * l, 0.5 * l)}
    for i in range(1, spec.units + 1):
        a = (i - 0.5) * l
        segs[f"skel_j{i}"] = (a, a + s)
        segs[f"skel_u{i}"] = (a + s, a + l)
    sites: dict[str, dict] = {k: {} for k in segs}
    bonds: list[Bond] = []
    probes: list[Probe] = []
    dofs_meta = []
    targets = []           # (dof spec, pair sites lo/hi, centre, axis) to route to
    dof_muscles: list[Muscle] = []
    # a circuit with a muscle per lever: an output that is a circuit input drives its DOF by a muscle
    wired = dict(conn.get("input_outputs") or {}) if conn.get("muscle_per_lever") else {}
    posts = {k: [] for k in segs}
    for i in range(1, spec.units + 1):
        a = (i - 0.5) * l
        for side in ("up", "dn"):
            if side == "up":
                O, b1, b2, sgn = np.array([a, w / 2]), f"skel_u{i - 1}", f"skel_j{i}", 1.0
            else:
                O, b1, b2, sgn = np.array([a + s, -w / 2]), f"skel_j{i}", f"skel_u{i}", -1.0
            a1, a2 = dg.alpha1, dg.alpha1 + dg.theta0
            dir1 = np.array([math.cos(a1), sgn * math.sin(a1)])
            dir2 = np.array([math.cos(a2), sgn * math.sin(a2)])
            name = f"u{i}_{side}"
            hw = HINGE_WIDTH
            sites[b1].update(axis_sites(f"h_{name}", W(*O), ez, hw))
            sites[b2].update(axis_sites(f"h_{name}", W(*O), ez, hw))
            bonds += hinge(f"skel_h_{name}", b1, b2, f"h_{name}", f"h_{name}", k_skel)
            for st in stops:                        # the joint's range of motion (section 2.3)
                for b, r, beta in ((b1, st.r1, st.beta1), (b2, st.r2, st.beta2)):
                    sites[b][f"stop_{st.name}_{name}"] = W(*(O + r * np.array([math.cos(beta), sgn * math.sin(beta)])))
                rest, tol = st.band
                bonds.append(Bond(f"skel_stop_{st.name}_{name}", f"{b1}.stop_{st.name}_{name}",
                                  f"{b2}.stop_{st.name}_{name}", STOP_K * k_skel, rest, tol, "bond", None))
            sites[b1][f"tip_{name}"] = W(*(O + dg.gain * dg.p * dir1))
            sites[b2][f"tip_{name}"] = W(*(O + dg.gain * dg.q * dir2))
            ds = spec.dof(i, side)
            dofs_meta.append({"name": name, "unit": i, "side": side, "hinge": f"skel_h_{name}",
                              "bodies": [b1, b2], "output": ds.output if ds else None})
            if ds is None:                                  # not in the file: locked straight
                bonds.append(Bond(f"skel_lock_{name}", f"{b1}.tip_{name}", f"{b2}.tip_{name}", k_skel, dg.d0,
                                  0.0, "bond", None))
                dofs_meta[-1]["coupling"] = "lock"
                dofs_meta[-1]["value"] = 0
                continue
            pr = next((p for p in circuit.probes if p.output == ds.output), None)
            if pr is None:
                raise MlcError(f"dof {name}: the circuit has no probe for output {ds.output}", ds.loc)
            const = pr.a.split(".")[0] == pr.b.split(".")[0]
            inp = wired.get(ds.output)
            coupling = ds.coupling or ("lock" if const else "muscle" if inp else "lever")
            if coupling == "lock" and not const:
                raise MlcError(f"dof {name}: output {ds.output} is not constant, so it cannot be a lock", ds.loc,
                               "use coupling: lever (or leave coupling out)")
            if coupling == "muscle" and inp is None:
                raise MlcError(f"dof {name}: output {ds.output} is not a circuit input in a circuit compiled with "
                               "a muscle per lever, so it cannot carry a muscle", ds.loc,
                               "compile with --muscle-per-lever, or use coupling: lever (or leave coupling out)")
            col = sorted({r[outs.index(ds.output)] for r in table.values()})
            dofs_meta[-1]["coupling"] = coupling
            probes.append(Probe(f"dof_{name}", ds.output, f"{b1}.tip_{name}", f"{b2}.tip_{name}", dg.d0, dg.d1))
            if coupling == "lock":
                v = int(col[0]) if len(col) == 1 and col[0] in "01" else 0
                bonds.append(Bond(f"skel_lock_{name}", f"{b1}.tip_{name}", f"{b2}.tip_{name}", k_skel,
                                  dg.d1 if v else dg.d0, 0.0, "bond", None))
                dofs_meta[-1]["value"] = v
                continue
            if coupling == "muscle":                # the DOF's own muscle of that input, on its lever arms
                sites[b1][f"muscle_{name}"] = W(*(O + dg.p * dir1))
                sites[b2][f"muscle_{name}"] = W(*(O + dg.q * dir2))
                dof_muscles.append(Muscle(f"muscle_{inp}_{name}", inp, f"{b1}.muscle_{name}", f"{b2}.muscle_{name}",
                                          geo.L0, geo.L1, next(m.k for m in circuit.muscles if m.input == inp)))
                dofs_meta[-1]["input"] = inp
                continue
            p1 = W(*(O + dg.p * dir1), -POST)
            p2 = W(*(O + dg.q * dir2), -POST)
            sites[b1][f"lever_{name}"] = p1
            sites[b2][f"lever_{name}"] = p2
            posts[b1].append(p1)
            posts[b2].append(p2)
            c = 0.5 * (p1 + p2)
            axis = (p2 - p1) / np.linalg.norm(p2 - p1)
            targets.append((ds, name, Pair(f"{b1}.lever_{name}", f"{b2}.lever_{name}", c, axis,
                                           float(np.linalg.norm(p2 - p1))), pr))
    bodies: list[Body] = []
    for k, (x0, x1) in segs.items():
        body = slab_body(k, [(W(x0, 0), W(x1, 0))], sites[k], ey, w, th)
        for p in posts[k]:                     # a post from the slab's underside down to each lever site
            top = p.copy()
            top[2] = zs - 0.5 * th
            body.boxes.append(segment_box(top - body.position, p + np.array([0, 0, 0.04]) - body.position,
                                          np.array([1.0, 0, 0]), 0.08, 0.08))
        bodies.append(body)
    # DOFs driven at the all-zero row: turn the bodies downstream of them
    order = list(segs)
    for dm in dofs_meta:
        out = dm["output"]
        on = dm.get("value", 0) if dm["coupling"] == "lock" else (int(bits0[outs.index(out)]) if out else 0)
        if not on:
            continue
        by = {b.name: b for b in bodies}
        hb = by[dm["bodies"][0]]
        O = hb.world(f"h_{dm['name']}_0")
        Rz = _rotz(math.pi / 2 if dm["side"] == "up" else -math.pi / 2)
        for name in order[order.index(dm["bodies"][1]):]:
            b = by[name]
            from mlc.geometry.rotation import quat_to_matrix
            b.position = O + Rz @ (b.position - O)
            b.orientation = matrix_to_quat(Rz @ quat_to_matrix(b.orientation))
    # ---- where each DOF's lever pair goes in every row (the body held still) ----------------
    def row_transforms(bits: str) -> dict:
        """Rigid motion (R, t) of each skeleton body from the built pose to row ``bits``'s
        target pose, the body unit held still (docs/robot.md 2.4)."""
        by = {b.name: b for b in bodies}
        tr = {n: (np.eye(3), np.zeros(3)) for n in order}
        for dm in dofs_meta:
            out = dm["output"]
            on = dm.get("value", 0) if dm["coupling"] == "lock" else (int(bits[outs.index(out)]) if out else 0)
            on0 = dm.get("value", 0) if dm["coupling"] == "lock" else (int(bits0[outs.index(out)]) if out else 0)
            if on == on0:
                continue
            R0, t0_ = tr[dm["bodies"][0]]
            O = R0 @ by[dm["bodies"][0]].world(f"h_{dm['name']}_0") + t0_
            ang = (math.pi / 2 if dm["side"] == "up" else -math.pi / 2) * (on - on0)
            Rz = _rotz(ang)
            for nm in order[order.index(dm["bodies"][1]):]:
                R, t_ = tr[nm]
                tr[nm] = (Rz @ R, Rz @ (t_ - O) + O)
        return tr
    row_tr = [row_transforms(bits) for bits in table.values() if len(bits) == len(outs)] if table else []
    # ---- couplings: a chain from each output pair to its DOF's lever sites ---------------
    parts_bodies, parts_bonds = [], []
    n_chains = n_half = 0
    cbyname = {b.name: b for b in circuit.bodies}
    sbyname = {b.name: b for b in bodies}
    placed = np.array([b.position for b in list(circuit.bodies) + bodies])
    by_body = {b.name: b for b in circuit.bodies}     # circuit bodies, some copied with a stop site
    used_pairs: set = set()                           # output pairs that already carry a chain
    # PAGE_ON_CHAIN: output pair -> (its first chain's first half unit, that half unit's output pair, the
    # state there, that half unit's tangent, the first chain's next half unit's): where a second chain's page hangs
    first_unit: dict = {}
    for ds, name, target, pr in targets:
        pa = cbyname[pr.a.split(".")[0]].world(pr.a.split(".", 1)[1])
        pb = cbyname[pr.b.split(".")[0]].world(pr.b.split(".", 1)[1])
        L = float(np.linalg.norm(pb - pa))
        start = Pair(pr.a, pr.b, 0.5 * (pa + pb), (pb - pa) / L, L)
        # the target as built (the skeleton may be turned at the zero row)
        ta = sbyname[target.lo.split(".")[0]].world(target.lo.split(".", 1)[1])
        tb = sbyname[target.hi.split(".")[0]].world(target.hi.split(".", 1)[1])
        tc, tax = 0.5 * (ta + tb), (tb - ta) / np.linalg.norm(tb - ta)
        t0v = _pair_tangent(circuit, pr.a, pr.b, start.centre, start.axis)
        sstate = int(bits0[outs.index(ds.output)])
        # slack (docs/robot.md 2.4): the chain's contour length is at least the farthest
        # start-to-end distance over the rows' poses divided by SLACK_FRACTION
        b_lo, b_hi = target.lo.split(".")[0], target.hi.split(".")[0]
        d_rows = [float(np.linalg.norm(0.5 * (tr[b_lo][0] @ ta + tr[b_lo][1] + tr[b_hi][0] @ tb + tr[b_hi][1])
                                       - start.centre)) for tr in row_tr] or [float(np.linalg.norm(tc - start.centre))]
        need = max(d_rows) / SLACK_FRACTION if SLACK_FRACTION else 0.0
        min_half = max(2, int(math.ceil(need / geo.pitch)))
        min_half += min_half % 2                       # even: the chain arrives with the output's state
        wps = []
        if start.centre[2] < hi_c[2] - 3.0:          # an output inside the circuit: out at the back, then up
            yb = float(hi_c[1]) + BACK
            wps = [(start.centre[0], yb, start.centre[2] + 2.0), (start.centre[0], yb, hi_c[2] + 2.0)]
        if SLACK > 0:                                 # a bulge to the DOF's own side: slack (docs/robot.md 2.4)
            a0 = wps[-1] if wps else start.centre
            mid = 0.5 * (np.asarray(a0, float) + tc)
            side = (1.0 if name.endswith("_up") else -1.0) * ey
            wps = wps + [tuple(mid + SLACK * side - np.array([0.0, 0.0, 0.0]))]
        tag = f"rc_{name}"
        tr = time.perf_counter()
        found = fallback = None
        on_lever = half_unit_prefix(start) is None     # a gate's output lever (else a half unit's pair)
        # a second chain on one output pair leaves on a page (docs/robot.md 2.2): a half unit with long
        # input posts, turned about the pair's axis like a branch's pages, so that its layer clears the
        # first chain's first layer; the chain goes on from the page's output pair
        shared = (pr.a, pr.b) in used_pairs
        used_pairs.add((pr.a, pr.b))
        # PAGE_ON_CHAIN (session 51): the page hangs on the first chain's first half unit, beside that chain's
        # next half unit (a branch on a half unit: the mesher prints the page's and the chain's junctions there
        # as one joint part), not on the output pair, where a gate lever would carry two joint parts at one point
        host = first_unit.get((pr.a, pr.b)) if (shared and PAGE_ON_CHAIN) else None
        # a chain on a half unit (a branch page): its first junction is a junction like any other, so it
        # may not be fanned out and its first bend stays within the routes' limit (past the largest
        # bend the two layers interpenetrate: 0.047 sigma in the tiny robot at a 50-degree limit)
        stop_first = not on_lever and not shared
        sbm = BEND_FRACTION * max_bend(geo) if stop_first else math.radians(50.0)
        fans = PAGE_FANS if shared else ((0.0,) if stop_first else FAN_ANGLES)
        # AVOID_CHAINS (docs/robot.md 2.6): first every start with the route pushed from the chains placed
        # before; only if none of those is clear (of the others and of itself), the plain routes as without it
        avoids = ((AVOID_CHAINS, 0.0) if AVOID_CHAINS > 0 and parts_bodies else (0.0,))
        for fan, avoid in ((f, av) for av in avoids for f in fans):
            from mlc.geometry.rotation import expmap
            tv = expmap(start.axis * math.radians(fan)) @ t0v
            pg = None
            if host is not None:
                # turned by fan about the half unit's output axis from the half unit's own tangent, as the
                # circuit's pages from their source's (at 90 degrees the page's arm then lies on the mesher's
                # branch-junction pin); its posts those of two pages as far apart as it and the first chain's
                # next half unit; the half unit inverts: the page gets NOT the output, gives the output, and
                # the chain from it is even (as an unshared chain)
                h_pre, h_pair, h_state, h_t0, h_t1 = host
                tv = expmap(h_pair.axis * math.radians(fan)) @ h_t0
                apart = math.acos(float(np.clip(tv @ h_t1, -1.0, 1.0)))
                post = max(geo.branch_post, geo.reach / math.tan(0.5 * max(apart, 1e-3)) + 0.25) + PAGE_CLEAR
                pg, pin, pout = half_unit_parts(f"{tag}_pg", h_pair.centre, h_pair.axis, tv, h_state, geo,
                                                in_post=post)
                pg.bonds += join(f"{tag}_pg_j", h_pair, pin, geo.k)
                c_start, parity, cstate, free, sb = pout, 0, 1 - h_state, True, BEND_FRACTION * max_bend(geo)
            elif shared:
                post = max(geo.branch_post, geo.reach / math.tan(0.5 * math.radians(abs(fan))) + 0.25) + PAGE_CLEAR
                pg, pin, pout = half_unit_parts(f"{tag}_pg", start.centre, start.axis, tv, sstate, geo, in_post=post,
                                                in_stop=LEVER_STOP if on_lever else POST_WIDTH)
                pg.bonds += join(f"{tag}_pg_j", start, pin, geo.k)
                c_start, parity, cstate, free, sb = pout, 1, 1 - sstate, True, BEND_FRACTION * max_bend(geo)
            else:
                c_start, parity, cstate, free, sb = start, 0, sstate, fan == 0, sbm
            rc, rax = tc, tax
            if WRIST:                                 # the chain ends on a wrist under the lever sites
                _, wpin0, _ = _wrist(tag, tc, tax, 0, geo, WRIST_POSTS.get(name))
                rc, rax, parity = wpin0.centre, wpin0.axis, (parity + WRIST_UNITS) % 2
            avoid_kw = ({"avoid": (([b.position for b in parts_bodies], avoid),), "avoid_from": 2}
                        if avoid > 0 else {})
            for wp in (wps, []):
                route = solve_route(c_start.centre, c_start.axis, rc, rax, geo, parity, waypoints=wp, tangent=tv,
                                    free_start=free, approach=ez, min_half=min_half + parity, start_bend_max=sb,
                                    **avoid_kw)
                if route is not None:
                    break
            if route is None:
                continue
            parts, pairs = chain_parts(tag, route.centre, route.axis, route.tangent, route.bends, cstate, geo,
                                       in_stop=LEVER_STOP if (on_lever and not shared) else POST_WIDTH,
                                       stops=CHAIN_STOPS)
            if pg is not None:
                parts.bodies = pg.bodies + parts.bodies
                parts.bonds = pg.bonds + parts.bonds
            if WRIST:
                wparts, wpin, wout = _wrist(tag, tc, tax, (cstate + len(route.bends)) % 2, geo,
                                             WRIST_POSTS.get(name))
                parts.bodies += wparts.bodies
                parts.bonds += wparts.bonds + _join_aligned(f"{tag}_wj0", pairs[-1], wpin, geo.k)
                pairs = pairs + [wout]
            new_c = np.array([b.position for b in parts.bodies])
            d2 = ((new_c[:, None, :] - placed[None, :, :]) ** 2).sum(-1)
            if float(d2.min()) < CLEAR ** 2:
                continue
            # the slabs too (oriented boxes): two chains on one pair whose first layers interpenetrate
            # are not printable, though their centres keep CLEAR apart (docs/robot.md 2.2)
            first = join(f"{tag}_j0", c_start, pairs[0], geo.k)
            ends = _end_bonds(tag, pairs[-1], target, tax, geo.k)
            depth = _chain_overlap(list(by_body.values()) + bodies + parts_bodies,
                                   list(circuit.bonds) + bonds + parts_bonds, parts, first + ends)
            if depth <= 0.0:
                found = (route, parts, pairs, c_start, pg is not None, tv, fan, avoid, post if pg else None)
                break
            if fallback is None or depth < fallback[0]:
                fallback = (depth, (route, parts, pairs, c_start, pg is not None, tv, fan, avoid, post if pg else None))
        kept = None
        if found is None and fallback is not None:      # every start overlaps: refused, unless allowed
            kept = fallback[0]
            if not allow_overlap:
                raise MlcError(f"cannot couple output {ds.output} to dof {name} clear of the other slabs: every "
                               f"start tried ({len(avoids) * len(fans)}) interpenetrates a body placed before, the "
                               f"least by {kept:.3f} sigma", ds.loc,
                               "a placement limit of mlc: try a larger skeleton height, or build it anyway with "
                               "mlc compile --allow-overlap and read the slab clearance mlc verify reports")
            found = fallback[1]
        if found is None:
            raise MlcError(f"cannot route output {ds.output} to dof {name}: no connector chain reaches it "
                           "clear of the others", ds.loc, "this is a placement limit of mlc; try a larger skeleton height")
        route, parts, pairs, c_start, paged, tv, fan, avoid, pg_post = found
        if not shared:
            first_unit[(pr.a, pr.b)] = (f"{tag}_0", pairs[1], 1 - sstate,      # (an unshared chain starts on the pair)
                                        (pairs[1].centre - pairs[0].centre) / geo.pitch,
                                        (pairs[2].centre - pairs[1].centre) / geo.pitch)
        new_c = np.array([b.position for b in parts.bodies])
        placed = np.vstack([placed, new_c])
        parts.bonds += join(f"{tag}_j0", c_start, pairs[0], geo.k)
        if CHAIN_STOPS and paged:                      # the junction after the page
            parts.bonds += junction_stops(f"{tag}_s0", f"{tag}_pg", f"{tag}_0", geo, geo.k)
        if CHAIN_STOPS and paged and host is not None:  # the page on the first chain's half unit: its stop
            parts.bonds += page_stop(f"{tag}_sp", host[0], f"{tag}_pg", geo, pg_post, geo.k)
        elif CHAIN_STOPS and not on_lever and not paged:  # on a half unit (a branch page): its junction stop
            parts.bonds += junction_stops(f"{tag}_s0", half_unit_prefix(start), f"{tag}_0", geo, geo.k)
        elif CHAIN_STOPS and on_lever:                 # on a gate's lever: the tap stop (of the page or the chain)
            lname = start.lo.split(".")[0]
            lev, bd = _lever_stop(f"{tag}_s{'p' if paged else '0'}", by_body[lname], start.lo.split(".", 1)[1],
                                  start.axis, tv if paged else pairs[1].centre - pairs[0].centre,
                                  f"{tag}_pg" if paged else f"{tag}_0", geo.k)
            by_body[lname] = lev
            parts.bonds.append(bd)
        parts.bonds += _end_bonds(tag, pairs[-1], target, tax, geo.k)
        parts_bodies += parts.bodies
        parts_bonds += parts.bonds
        n_chains += 1
        nh = len(route.bends) + (1 if paged else 0) + (WRIST_UNITS if WRIST else 0)
        contour = (len(route.bends) + (1 if paged else 0)) * geo.pitch + (
            WRIST_UNITS * (WRIST_POSTS.get(name, WRIST_POST) + geo.width + 0.5 * geo.gap) if WRIST else 0.0)   # sigma
        n_half += nh
        next(d for d in dofs_meta if d["name"] == name)["chain"] = {
            "half_units": nh, "prefix": tag, "page": paged,
            "page_on": (host[0] if host is not None else start.lo.split(".")[0]) if paged else None, "fan_deg": fan, "avoid": avoid, "route_seconds": round(time.perf_counter() - tr, 2),
            "reach_max": round(max(d_rows), 3), "wrist_units": WRIST_UNITS if WRIST else 0,
            "contour": round(contour, 3), "reach_fraction": round(max(d_rows) / contour, 3),
            "overlap": round(kept, 4) if kept is not None else 0.0}
    rmeta = spec.as_dict()
    rmeta.update({"origin": [float(v) for v in origin], "plane_normal": [0.0, 0.0, 1.0], "x_axis": [1.0, 0, 0],
                  "joint_length": s, "links": [f"skel_u{i}" for i in range(spec.units + 1)],
                  "dof_geometry": {"rest": dg.d0, "actuated": dg.d1, "p": dg.p, "q": dg.q, "gain": dg.gain,
                                   "theta0_deg": math.degrees(dg.theta0),
                                   "alpha1_deg": math.degrees(dg.alpha1)},
                  "stops": {"margin_deg": math.degrees(STOP_MARGIN),
                            "free_turn_deg": [-math.degrees(STOP_MARGIN), 90 + math.degrees(STOP_MARGIN)]},
                  "dofs": dofs_meta, "chains": n_chains, "half_units": n_half,
                  "k": {"chains": geo.k, "skeleton": k_skel, "joint_k": joint_k}})
    scene = Scene(name=f"robot_{spec.name}", bodies=[by_body[b.name] for b in circuit.bodies] + bodies + parts_bodies,
                  bonds=list(circuit.bonds) + bonds + parts_bonds, muscles=list(circuit.muscles) + dof_muscles,
                  probes=list(circuit.probes) + probes, inputs=list(circuit.inputs), outputs=list(circuit.outputs),
                  truth_table=dict(circuit.truth_table) if circuit.truth_table else None,
                  meta={"element": "robot", "robot": rmeta, "circuit": meta})
    scene.check()
    return Robot(scene, n_chains, n_half, time.perf_counter() - t0)


__all__ = ["DofGeometry", "DofStop", "Robot", "build_robot", "dof_geometry", "dof_stops"]
