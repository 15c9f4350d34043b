"""A gate netlist becomes one circuit scene: placement, routing and assembly.

Rules (docs/circuits.md):

* **Signals.**  Every wire carries the netlist's physical signal (``netlist.signal``);
  a gate computes on the physical states of its input wires (its levers absorb the
  inversions).  The scene is built posed in the all-zero input row: each gate is posed
  in its own input state of that row (solved once per gate type and state).
* **Placement.**  Gates stand upright (core plane horizontal, output lever up) in
  levels along +z: level ``d`` at ``z ~ d * level_pitch``.  The levels (``place_levels``)
  keep every chain rising (a sink above its drivers) and make the chains' summed rise,
  in levels, the least (a linear programme; ties go to the lowest levels): a gate whose
  consumers sit far above it rises towards them, and a circuit input that needs a
  source (fan-out, or an output) has its source one level below its lowest consumer.
  A level's gates (and sources) are spread along x, ordered by the mean x of their
  drivers.
* **Inputs.**  One muscle per circuit input.  An input that feeds exactly one gate
  input drives that input lever directly (the library gate's own muscle); otherwise
  the muscle spans the input diagonal of a *source* half unit (at level 0, or one level
  below its lowest consumer), whose output pair (carrying the inverted signal) is the
  tap of the wire.  With ``CircuitOptions.muscle_per_lever`` (a global stimulus: every
  muscle of an input's material responds to it, as the paper's colours) every input
  lever an input drives carries a muscle of its own, and only an output that reads an
  input directly still needs the input's source.
* **Taps and fan-out.**  A wire's tap is a gate's output pair (or a source's).  One
  consumer: a chain hangs on the tap.  Several: a branch: half units (pages) hang on the
  tap, turned about the tap's axis, and each consumer's chain goes on from a page.  With
  ``BRANCH_TREE`` (the default) every branch has two pages, at -90 and +90 degrees, and a
  page that serves more than one consumer hangs two pages of its own (a tree,
  ``_branch_tree``); without it, one page per consumer hangs on the tap (``branch_angles``).
* **Chains** are routed by inverse kinematics (:mod:`mlc.circuit.route`) from the tap
  (or page) to the consumer's input lever, arriving from below, with the parity the
  signal needs: every half unit is a NOT, so a path has an even count of them, or an
  odd one where the netlist marks a half unit (an inverted output).
* **Outputs** are probes across a pair carrying the output's wire: a gate's output pair,
  a page or a stub half unit where an inversion is needed.  A constant output is a
  probe across two sites of one rigid slab, fixed at the state's length.

Units: sigma, k0.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from functools import lru_cache

import numpy as np

from mlc.errors import MlcError
from mlc.gates.connector import (POST_WIDTH, Pair, Parts, branch_angles, chain_frames, chain_parts,
                                 connector_geometry, half_unit_parts, half_unit_prefix, join, junction_stops,
                                 max_bend, rotate)
from mlc.gates.parts import segment_box, slab_body
from mlc.scene.model import Body, Bond, Muscle, Probe, Scene

# Build CPU grows as gates^2.18 (least-rise levels, session 23: bodies ~ gates^1.17, build CPU
# ~ bodies^1.78, more re-routes as the circuit gets denser; the 2- to 7-bit adders in
# benchmarks/results/circuit_scaling.json, 14 to 352 s for 10 to 45 gates): larger netlists
# are refused before the work, with the estimate (a 84-AND circuit routed for 45 min unasked).
BUILD_CPU_REF = (45, 347.0)      # (gates, CPU s) of the fit at the 7-bit adder
BUILD_CPU_EXPONENT = 2.18        # in gates
MAX_BUILD_CPU = 3600.0           # s: about 130 gates
MAX_GATES = int(BUILD_CPU_REF[0] * (MAX_BUILD_CPU / BUILD_CPU_REF[1]) ** (1 / BUILD_CPU_EXPONENT))
# The fast router: build CPU ~ gates^0.99, the least-squares fit (log-log) of the 2- to
# 7-bit adders (3.4 to 11.9 s for 10 to 45 gates; the 2-bit adder's 8.4 s is one chain that
# fell back to the whole-chain solve) and the 203-gate NAND mesh (98.5 s) of
# benchmarks/results/circuit_scaling_fast.json (session 39): every point within 0.37 to 1.52 of it.
FAST_BUILD_CPU_REF = (203, 60.2)      # (gates, CPU s) of the fit at 203 gates
FAST_BUILD_CPU_EXPONENT = 0.99        # in gates
MAX_FAST_GATES = int(FAST_BUILD_CPU_REF[0] * (MAX_BUILD_CPU / FAST_BUILD_CPU_REF[1]) ** (1 / FAST_BUILD_CPU_EXPONENT))


FAST_FROM = 17                  # gates: "auto" routes circuits of this many gates or more with the fast
                                # method (every example has at most 14: their scenes, and the dynamic
                                # campaigns keyed by them, stay those of the "ik" router)
ROUTERS = ("auto", "ik", "fast")


def router_of(opt, gates: int) -> str:
    """The routing method (``"ik"`` or ``"fast"``) that ``opt.router`` picks for ``gates`` gates."""
    if opt.router not in ROUTERS:
        raise ValueError(f"router {opt.router!r} is not one of {ROUTERS}")
    if opt.router == "auto":
        return "fast" if gates >= FAST_FROM else "ik"
    return opt.router


def build_cpu_estimate(gates: int, method: str = "ik") -> float:
    """CPU seconds to place and route a netlist of ``gates`` gates with the router ``method``
    (an order of magnitude: "ik", the fit of three adders, ``benchmarks/circuit_scaling.py
    --refit``; "fast", the fit of ``circuit_scaling_fast.json``)."""
    ref, ex = (BUILD_CPU_REF, BUILD_CPU_EXPONENT) if method == "ik" else (FAST_BUILD_CPU_REF, FAST_BUILD_CPU_EXPONENT)
    return ref[1] * (max(gates, 1) / ref[0]) ** ex
MAX_INPUTS = 14             # the scene's truth table lists every row
LEVEL_PITCH = 23.0          # sigma between logic levels (z), plus LAYER_PITCH per route arriving
GATE_PITCH = 12.0           # sigma between gates of one level (x)
TERMINAL_POST = 0.8         # sigma: the last half unit's layer stays this far below a lever's plane
END_DROP = 1.5              # sigma: a chain ends on its input levers' ``in`` sites moved this far down their
                            # pivot's axis (``_add_end_sites``), clear of the joint at d (docs/circuits.md)
END_POST_FROM = 0.75        # ... each on a post from this fraction of the way from the pivot to ``in``
END_POST = 0.3              # sigma: ... and the last half unit's layer stays at least this far below them
LEVER_STOP = 0.35           # sigma: the last posts stop this short of a lever's joint sites (the lever is 0.5 wide)
PAGE_CLEAR = 0.2           # sigma: extra post length that keeps a branch page clear of the driving lever
LAYER_PITCH = 2.5           # sigma between the horizontal layers of the routes into one level
RUN_BASE = 9.5              # sigma: the lowest run sits this far above the level below (3.5 clear of its taps' crossings)
PLANE_TRIES = 6             # routing planes tried per chain before keeping the best
LANE_BEND = 0.6             # bends of a routed chain stay within this fraction of the largest (floppy slack)
TURN_RADIUS = 5.0           # sigma: lane corners are rounded to this radius (a chain turns 90 degrees in ~6 sigma)
WAYPOINT_STEP = 2.0         # sigma between the lane points a chain is pulled towards
WAYPOINT_WEIGHT = 1.0       # their weight in the inverse kinematics
END_JUNCTIONS, END_BEND = 4, 0.2   # the 4 junctions at either end bend at most 0.2 of the largest (lever travel)
LANE_EXTRAS = (0, 4, 8)     # chain lengths (half units beyond the steered guess) tried in a plane before the next
CONTACT_MARGIN = 0.05       # sigma: layers of two chains must clear each other by this in every state of their wires
PRINT_MARGIN = 0.8          # sigma: ... and should by this for the printed parts (knuckles, joint parts) to clear
                            # (session 53: mjp parts of two Tetris chains met at scene clearances up to 0.67 sigma,
                            # none at 0.77 or more); _build_routed tries PRINT_LEANS for a build left closer
PRINT_LEANS = (0.8,)        # branch leans (BRANCH_LEAN) tried, in order, when a leaned build leaves chains closer
                            # than PRINT_MARGIN (_build_routed)
RIP_GAP = 1.2               # sigma: a chain this much closer to another is routed again with it (_rip_up);
                            # measured: chains 1.29 sigma apart and more were clear in every row of every
                            # example, one 0.93 apart (3-bit adder) overlapped by 0.23 sigma
BRANCH_LAYERS = 3           # layers of a chain next to its branch page, left out of the keep-apart test
LAYER_DRIFT = 1e-3           # _layers: an axis this far off unit length (squared norm) -> exact frames
LAYER_RADIUS = 0.9          # sigma: bounds a half unit's layer with its posts (reach 0.75, half pitch 0.5)
GATE_POINT_STEP = 0.25      # sigma between the points that stand for a gate's slab (along its length)
GATE_CLEAR = LAYER_RADIUS + 0.3   # sigma: a layer's centre stays this far from them (slab half width 0.25)
PIN_SPREAD = 2.5            # sigma: a gate's two input chains arrive this far apart in x
PIN_STAGGER = 2.5           # sigma: the far input's chain crosses under the gate this much lower than the near one's
PIN_END = 1.5               # sigma: and rises to its lever this far to its side of the gate (x)
TAP_LEAN = math.radians(45.0)   # a single chain leaves a gate's output pair this far from up, towards -y
TAP_TURN = math.radians(50.0)   # ... turned by at most this much about the pair's axis by the router
FAST_PAIR_PAGES = (0.0, math.radians(90.0))   # "fast": a 2-way branch's pages, up and towards the planes
PAGE_MIN_ANGLE = math.radians(60.0)            # ... held by a stop (_page_stop) from closing below this
TAP_CONTACT = math.radians(85.0)   # its first layer meets the output lever's slabs about 90 deg from up
TAP_FREE = (math.radians(10.0), math.radians(70.0))   # the tap stop's free swing about the built direction
SOURCE_LEAN, SOURCE_TURN = 0.5, 0.3   # a chain or stub on a source leans 0.5 max_bend, turned by at most 0.3
RISER_PITCH = 3.5           # sigma between the risers of the routes from one tap (x)
BRANCH_LEAN = 0.6           # a branch tree's chain on a page on a page (which leaves along +-x) leaves leaned by this
                            # fraction of max_bend, up where it heads +x and down where it heads -x (_branch_tree;
                            # with the "ik" router only)
BRANCH_TREE = True          # a fan-out to k > 2 consumers is a tree of 2-way branches, pages at -90/+90 degrees
                            # (_branch_tree; session 52: the printed branch joint's one cross pin); False: one
                            # k-way branch, pages at branch_angles(k) (-90..90 degrees)
# Gates are turned by +90 degrees about z (gate x -> world y): every output pair's axis is
# then along world x, so branch pages (turned about that axis) fan out towards -y, where
# the routes run, and a gate's input levers reach along +-y.
_ROT = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
_ROT_Q = np.array([np.cos(np.pi / 4), 0.0, 0.0, np.sin(np.pi / 4)])


@dataclass
class CircuitOptions:
    gap: float = 0.5                 # connector junction gap (sigma)
    level_pitch: float = LEVEL_PITCH
    gate_pitch: float = GATE_PITCH
    joint_k: float = 100.0           # connector joints' bond stiffness, in units of the design k (k0); 1 is
                                     # the paper's; muscles and gates keep the design k (docs/circuits.md,
                                     # "Thermal spread": 100 k0 joints give 12 spreads of margin, not 1.8)
    direct: bool = False             # join a gate's single-sink net by one full unit (mlc.circuit.direct)
    direct_skip: tuple = ()          # ... except into these sinks (build_circuit fills it: see there)
    max_gates: int | None = None     # refuse larger netlists before the work (None: MAX_GATES, or
                                     # MAX_FAST_GATES with the fast router)
    jobs: int = 1                    # processes that route: each chain's first solve is started ahead
                                     # (route.Prefetch); the scene is the same, bit for bit, for any jobs
    router: str = "auto"             # "ik": every chain solved whole (mlc.circuit.route); "fast": steered and
                                     # closed at its end; "auto": "fast" from FAST_FROM gates on, else "ik"
    muscle_per_lever: bool = False   # every input lever a circuit input drives carries its own muscle of that
                                     # input (a global stimulus); no chains from the inputs to the gates
    end_drop: float = END_DROP       # sigma: chains end this far under their input levers' in sites (_add_end_sites);
                                     # 0: on the in sites, as before session 44 (a robot's circuit
                                     # takes mlc.robot.build.CIRCUIT_END_DROP, 1.0)
    print_leans: tuple | None = None # branch leans tried for the print's margin (_build_routed); None:
                                     # PRINT_LEANS (a robot's circuit takes mlc.robot.build.CIRCUIT_PRINT_LEANS, none)


class _PrintContacts:
    """``print_contacts`` of a build (``near_print``: a function listing them, once, on first call)."""

    near_print: object = None

    @property
    def print_contacts(self) -> list:
        """The chains' layers' contacts closer than ``PRINT_MARGIN`` (the print's), smallest first."""
        return self.near_print() if self.near_print is not None else []


@dataclass
class Circuit(_PrintContacts):
    """The built scene plus what the builder knows about it."""

    scene: Scene
    gate_frames: dict = field(default_factory=dict)      # gate id -> world translation
    chains: int = 0
    half_units: int = 0
    seconds: dict = field(default_factory=dict)
    closest: float = float("inf")    # sigma: smallest layer-centre distance of a tight chain to another chain
    contacts: list = field(default_factory=list)   # contact.Contact of the chains' close layers, smallest first
    near_print: object = None      # () -> those closer than PRINT_MARGIN (listed on first read: print_contacts)


@lru_cache(maxsize=None)
def _posed_gate(gtype: str, signal: str, state: str):
    """(scene, pos, quat) of a library gate in input state ``state`` ("ab")."""
    from mlc.gates.library import gate_scene
    from mlc.verify.static import equilibrium
    sc = gate_scene(gtype, signal)
    if state == "00":
        A = sc.arrays()
        return sc, A.pos.copy(), A.quat.copy()
    eq = equilibrium(sc, state)
    return sc, eq.pos, eq.quat


def _tap_stop(name: str, lever: Body, site: str, t_up, t_first, first: str, k: float) -> list[Bond]:
    """A flat-bottom bond that keeps a chain's first half unit ``first``, hung on a gate's
    output pair and built along ``t_first``, off the output lever's slabs, which it meets
    about TAP_CONTACT from the pair's upward normal ``t_up`` (docs/circuits.md, "Junction
    stops").  One site on the lever body, STOP_ARM behind the joint ``site`` along
    ``t_first``; the other is the half unit's ``stop_in`` (STOP_ARM beyond the same joint
    along its tangent): they are 2 m cos(phi/2) apart for a swing phi from the built
    direction, free up to TAP_CONTACT minus the built lean (within TAP_FREE).  The swing
    takes no lever motion (the lever turns the pair about the vertical, which the next
    junction takes), only the chain's slack.  Units: sigma, k0."""
    from mlc.gates.connector import STOP_ARM
    m = STOP_ARM
    t_first = np.asarray(t_first, float) / np.linalg.norm(t_first)
    lean = math.acos(float(np.clip(t_first @ np.asarray(t_up, float), -1.0, 1.0)))
    free = min(max(TAP_CONTACT - lean, TAP_FREE[0]), TAP_FREE[1])
    p = lever.world(site) - m * t_first
    lever.sites["stop_tap"] = lever.rotation().T @ (p - lever.position)
    d_stop, d_free = 2.0 * m * math.cos(0.5 * free), 2.0 * m + 0.5
    return [Bond(name, f"{lever.name}.stop_tap", f"{first}_AB.stop_in", k, 0.5 * (d_stop + d_free),
                 0.5 * (d_free - d_stop), "bond", None)]


def _page_stop(name: str, parts0: Parts, parts1: Parts, page0: str, page1: str, spread: float, k: float) -> list[Bond]:
    """A flat-bottom bond that keeps two branch pages hung on one pair, built ``spread``
    apart, from closing on each other: their ``stop_in`` sites lie on the pages' centre
    lines, ``STOP_ARM`` (R) from the joint both pages' A vertices hang on, so
    2 R sin(theta/2) apart at an angle theta between the pages; the bond is free from
    ``PAGE_MIN_ANGLE`` up (the posts are long enough for that angle) and stiff below it.
    Units: sigma, k0."""
    from mlc.errors import InternalError
    from mlc.gates.connector import STOP_ARM
    b0 = next(b for b in parts0.bodies if b.name == f"{page0}_AB")
    b1 = next(b for b in parts1.bodies if b.name == f"{page1}_AB")
    R = STOP_ARM
    d_built = float(np.linalg.norm(b0.world("stop_in") - b1.world("stop_in")))
    if abs(d_built - 2.0 * R * math.sin(0.5 * spread)) > 1e-9:
        raise InternalError(f"pages {page0}, {page1}: stop sites {d_built} apart, not on one joint's lines")
    d_stop, d_free = 2.0 * R * math.sin(0.5 * PAGE_MIN_ANGLE), 2.0 * R + 0.5
    return [Bond(name, f"{page0}_AB.stop_in", f"{page1}_AB.stop_in", k, 0.5 * (d_stop + d_free),
                 0.5 * (d_free - d_stop), "bond", None)]


def _branch_split(n: int) -> tuple[int, int]:
    """How many of ``n`` consumers each page of a branch tree's node serves: the first page
    (-90 degrees) ``n // 2``, the second the rest."""
    return n // 2, n - n // 2


def _page_post(geo, spread: float) -> float:
    """A branch page's input post (sigma): long enough that two pages ``spread`` (rad) apart
    about the tap clear each other's reach, at least the connector's ``branch_post``, plus
    ``PAGE_CLEAR`` from the driving lever."""
    return max(geo.branch_post, geo.reach / math.tan(0.5 * spread) + 0.25) + PAGE_CLEAR


def _branch_tree(prefix: str, tap: Pair, t_ref, sgn: float, pol: int, zero_w: int, n: int, geo,
                 stop_at_tap: float, lean: float = BRANCH_LEAN) -> tuple[list, list]:
    """The pages of a fan-out to ``n`` consumers (``n >= 2``) as a tree of 2-way branches
    (``BRANCH_TREE``; docs/circuits.md, "Branch trees (session 52)"): two pages hang on
    ``tap`` (which carries polarity ``pol``; ``zero_w``: the wire's state in the all-zero row),
    turned -90 and +90 degrees about its axis from ``t_ref`` (``sgn``: the sign that turns
    towards -y); a page that serves more than one consumer (``_branch_split``) hangs two pages
    of its own on its output pair, -90 and +90 degrees about that pair's axis from its own
    tangent, and so on, so that every branch junction carries two pages whose tangents are
    antiparallel (the printed joint's one cross pin: both pages turn about it).  Pages are
    named ``{prefix}_p0``/``_p1`` at the tap and ``{parent}_p0``/``_p1`` below.

    A page on a page leaves along the tap's axis (world x: pages on the tap leave along
    +-y), where a wire's risers are spaced (``RISER_PITCH``, in the consumers' x order), so
    the leaves are handed to the consumers in the x order of the point ``RISER_PITCH`` on
    from each leaf's output along its tangent (ties in the tree's order): a leaf that leaves
    towards -x serves a consumer whose riser is on that side.  For 2 consumers: the k-way
    branch's order (page -90 degrees first).  A chain on a page on a page starts
    leaned (``BRANCH_LEAN``, below).  Returns (the starts of the consumers' chains in that
    order, ``(pair, polarity, free, tangent, None)`` as ``_build_circuit``'s ``starts``; the
    pages' Parts, parents first)."""
    angs = branch_angles(2)
    post = _page_post(geo, abs(angs[1] - angs[0]))
    leaves: list = []
    pages: list = []

    def hang(name, pair, tref, s, ppol, m, in_stop):
        subs = []
        for k, (a, mk) in enumerate(zip(angs, _branch_split(m))):
            pname = f"{name}_p{k}"
            t = rotate(tref, pair.axis, s * a)
            parts, pin, pout = half_unit_parts(pname, pair.centre, pair.axis, t, zero_w ^ ppol, geo,
                                               in_post=post, in_stop=in_stop)
            parts.bonds += join(f"{pname}_j", pair, pin, geo.k)
            pages.append(parts)
            subs.append((pname, pout, t, mk))
        for pname, pout, t, mk in subs:
            if mk > 1:
                hang(pname, pout, t, 1.0, ppol ^ 1, mk, POST_WIDTH)
                continue
            t0, leaned = t, None
            if pair is not tap and abs(float(t[0])) > 0.5 and lean:
                # a page on a page leaves along +-x, towards the chains of the next tap in its
                # level, whose facing pages head the other way: the chain's first half unit
                # leans by BRANCH_LEAN of the largest bend about the page's output axis, up
                # heading +x and down heading -x, so that the two pass at different heights
                # (the first END_JUNCTIONS junctions hardly bend: straight on they met)
                t0 = rotate(t, pout.axis, lean * max_bend(geo))
                if (t0[2] > t[2]) != (t[0] > 0):
                    t0 = rotate(t, pout.axis, -lean * max_bend(geo))
                leaned = lean
            leaves.append((pout, ppol ^ 1, True, t0, leaned))

    hang(prefix, tap, t_ref, sgn, pol, n, stop_at_tap)
    if n == 2:              # the k-way branch's order (a gate's output pair is not exactly along x)
        return leaves, pages
    key = [round(float(lf[0].centre[0] + RISER_PITCH * lf[3][0]), 1) for lf in leaves]     # (0.1 sigma: ties)
    return [leaves[i] for i in sorted(range(len(leaves)), key=lambda i: (key[i], i))], pages


def _wire_values(netlist, bits: dict) -> dict:
    """Physical state of every wire for input values ``bits`` (name -> 0/1)."""
    from mlc.gates.library import get_gate
    val = {("input", w.name): int(bits[w.name]) for w in netlist.inputs}
    for g in netlist.gates:
        gd = get_gate(g.type)
        val[("gate", g.id)] = gd.evaluate(val[g.a.src], val[g.b.src])
    return val


def place_levels(netlist, sources, muscled=()) -> dict[tuple, int]:
    """Level of every gate (``("gate", id)``) and of every input source (``("input", name)``
    for the inputs in ``sources``; the other inputs drive one lever directly and have no place).

    Every chain rises: a gate stands at least one level above each of its drivers (gates at
    level 1 and up, sources at 0 and up).  Of those placements, the one whose chains rise the
    least in all (the sum over chains of sink level minus driver level: a chain's length
    grows with its rise) is found as a linear programme (scipy's HiGHS dual simplex; the
    constraints are differences, so the optimal vertex is integral).  Among the least, the
    lowest levels win (a term ``eps * sum(levels)`` with ``eps`` too small to trade one level
    of rise).  A logic-depth placement (every gate at its depth, sources at 0) is a feasible
    point, so the rise is never more than that placement's.  ``muscled``: the (gate id, pin)s
    driven by a muscle of their own, which no chain reaches.  Returns ints; a result that
    is not integral or breaks a constraint is an internal error."""
    from scipy.optimize import linprog

    from mlc.errors import InternalError
    src_names = {w.name for w in sources}
    nodes = [("input", w.name) for w in netlist.inputs if w.name in src_names] + [("gate", g.id) for g in netlist.gates]
    ix = {n: i for i, n in enumerate(nodes)}
    n = len(nodes)
    if not netlist.gates:
        return {v: 0 for v in nodes}
    rows, rhs = [], []
    cost = np.zeros(n)
    for g in netlist.gates:
        v = ix[("gate", g.id)]
        for pin, p in (("a", g.a), ("b", g.b)):
            if p.src in ix and (g.id, pin) not in muscled:   # a chain from a source or a gate
                row = np.zeros(n)
                row[ix[p.src]], row[v] = 1.0, -1.0       # l(src) - l(g) <= -1
                rows.append(row)
                rhs.append(-1.0)
                cost[v] += 1.0
                cost[ix[p.src]] -= 1.0
    depth_max = max(g.depth for g in netlist.gates)
    cost += 1.0 / (n * (depth_max + 1) + 1)
    lo = [0.0 if v[0] == "input" else 1.0 for v in nodes]
    res = linprog(cost, A_ub=np.array(rows) if rows else None, b_ub=rhs if rows else None,
                  bounds=[(b, float(depth_max)) for b in lo], method="highs-ds")
    if res.status != 0:
        raise InternalError(f"placement levels: the linear programme failed ({res.message})")
    lv = np.rint(res.x)
    if np.max(np.abs(lv - res.x)) > 1e-6 or (rows and np.any(np.array(rows) @ lv > np.array(rhs) + 1e-9)):
        raise InternalError("placement levels: the linear programme's optimum is not an integral placement")
    return {v: int(lv[i]) for v, i in ix.items()}


def _truth_table(spec, netlist) -> dict[str, str]:
    """Expected outputs of every row, from the specification (the user's intent)."""
    from mlc.logic.equiv import spec_tables
    n = len(netlist.inputs)
    names = [w.name for w in netlist.inputs]
    if spec is not None:
        on, dc = spec_tables(spec)
        pos = {x: i for i, x in enumerate(spec.inputs)}
        oidx = {x: i for i, x in enumerate(spec.outputs)}
        table = {}
        for r in range(2 ** n):
            key = format(r, f"0{n}b")
            m = sum(int(key[i]) << pos[x] for i, x in enumerate(names))
            out = []
            for o in netlist.outputs:
                k = oidx[o.name]
                out.append("-" if (dc[k] >> m) & 1 else str((on[k] >> m) & 1))
            table[key] = "".join(out)
        return table
    table = {}
    for r in range(2 ** n):
        key = format(r, f"0{n}b")
        v = _wire_values(netlist, dict(zip(names, map(int, key))))
        table[key] = "".join(str(o.value) if o.kind == "const" else str(v[o.src] ^ int(o.half_unit))
                             for o in netlist.outputs)
    return table


def _gate_bodies(gid: str, sc: Scene, pos, quat, offset) -> tuple[list[Body], list[Bond]]:
    """The gate's bodies and bonds, renamed ``{gid}_{name}``, turned by the placement's
    rotation and moved by ``offset``."""
    from mlc.circuit.direct import moved_bodies
    return moved_bodies(gid, sc, pos, quat, _ROT, np.asarray(offset, float))


def _world(bodies_by_name, ref: str) -> np.ndarray:
    body, site = ref.split(".", 1)
    return bodies_by_name[body].world(site)


def _pair(bodies_by_name, lo: str, hi: str) -> Pair:
    p, q = _world(bodies_by_name, lo), _world(bodies_by_name, hi)
    L = float(np.linalg.norm(q - p))
    return Pair(lo, hi, 0.5 * (p + q), (q - p) / L, L)


def _add_end_sites(by_name, gid: str, pin: str, drop: float = END_DROP) -> None:
    """Give gate ``gid``'s two input levers of ``pin`` the sites a chain ends on (sigma):
    ``in_end``, their ``in`` sites moved ``drop`` along the levers' pivot axis towards
    ``piv_0``, the side the chains come from (-z), each carried by a post (``drop`` 0:
    nothing is added; chains end on ``in``).  Idempotent.

    A point on the pivot axis through ``in`` turns with the lever exactly as ``in`` does, so
    the gate's stroke and states stay as they are.  But the chain's end joints then sit
    under the gate, where there is room for a junction's ball and collar: at ``in`` itself
    the lower lever's tip passes 0.27 sigma from the gate's universal joint at d in one state
    of most library gates, and the ball needs 0.48 (docs/circuits.md, "Where a chain ends").
    The post (``POST_WIDTH`` square) runs from ``END_POST_FROM`` of the way out along the
    lever (the tip itself passes the joint at d) to ``POST_WIDTH`` short of the joint."""
    if drop > 0.0:
        for e in ("lo", "hi"):
            end_site(by_name[f"{gid}_{pin}_{e}"], drop)


def end_site(b: Body, drop: float) -> None:
    """Give one input lever ``b`` its site ``in_end`` and the post carrying it
    (:func:`_add_end_sites`; body-local, so the same in any pose).  Idempotent."""
    if "in_end" in b.sites:
        return
    down = b.sites["piv_0"] - b.sites["piv_1"]
    down /= np.linalg.norm(down)
    end = b.sites["in"] + drop * down
    mid = 0.5 * (b.sites["piv_0"] + b.sites["piv_1"])
    start = mid + END_POST_FROM * (b.sites["in"] - mid)
    run = (end - start) / np.linalg.norm(end - start)
    b.sites = {**b.sites, "in_end": end}
    b.boxes = [*b.boxes, segment_box(start, end - POST_WIDTH * run, np.cross(down, run), POST_WIDTH, POST_WIDTH)]


def end_post(drop: float) -> float:
    """How far (sigma) the last half unit's layer stays below the pair a chain ends on:
    ``TERMINAL_POST`` below the lever plane when it ends on ``in`` (``drop`` 0), else
    ``TERMINAL_POST - drop`` but at least ``END_POST`` below the ``in_end`` sites."""
    return max(TERMINAL_POST - drop, END_POST) if drop > 0.0 else TERMINAL_POST


def _pin_pair(by_name, gid: str, pin: str, drop: float = END_DROP) -> Pair:
    """The pair a chain into gate ``gid``'s input ``pin`` ends on (sigma): the levers'
    ``in_end`` sites (:func:`_add_end_sites`, which must have run), or with ``drop`` 0 their
    ``in`` sites.  Reads only."""
    site = "in_end" if drop > 0.0 else "in"
    return _pair(by_name, *(f"{gid}_{pin}_{e}.{site}" for e in ("lo", "hi")))


def build_circuit(netlist, spec=None, options: CircuitOptions | None = None, progress=None) -> Circuit:
    """One scene of the whole circuit, posed in the all-zero input row (see module doc).

    With ``options.direct``, a direct net whose unit, sink or driver another element's
    slab passes through in the built scene (``direct.crossed_direct``: a chain rising
    to a pin through the column a direct sink stands in) is routed as a chain instead,
    and the circuit built again, until no direct net is crossed (the dropped sinks are
    in ``meta.connector.direct_dropped``)."""
    opt = options or CircuitOptions()
    circ = _build_routed(netlist, spec, opt, progress)
    dropped: list = []
    while opt.direct and circ.scene.meta["connector"]["direct"]:
        from mlc.circuit.direct import crossed_direct
        direct = {s: (d, p) for d, s, p in circ.scene.meta["connector"]["direct"]}
        hit = sorted(crossed_direct(circ.scene, direct))
        if not hit:
            break
        dropped += hit
        opt = replace(opt, direct_skip=tuple(opt.direct_skip) + tuple(hit))
        circ = _build_routed(netlist, spec, opt, progress)
    if opt.direct:
        circ.scene.meta["connector"]["direct_dropped"] = dropped
    return circ


def _build_routed(netlist, spec, options: CircuitOptions, progress) -> Circuit:
    """One build, or two: when the router leaves chains it could not keep apart
    (``tight_chains``), the wires they belong to are routed again first, in a second
    build (once); the build kept is the one whose chains' layers would touch in no row
    (or less deeply), then whose tight chains come closest to another chain by the larger
    distance (:func:`_merit`; the first on a tie): one chain pressed into another is
    worse than several just inside the keep-apart distance.  When both leave chains tight
    and the circuit has branch trees whose chains lean (``BRANCH_LEAN``), the same one or
    two builds without the lean are tried too, and the best of all is kept (session 52: the
    lean kept the examples' chains apart, and pressed two chains of a 5-way fan-out into
    each other, which the unleaned build keeps apart).

    Then, when the build kept leaves two chains' layers closer than ``PRINT_MARGIN`` in some
    row (``print_contacts``: the printed parts' knuckles and joint parts would meet, session
    53) and its circuit has leaned branch trees, the build with each lean of ``PRINT_LEANS``
    in turn, kept instead if it is no worse by the above (no closer contact below
    ``CONTACT_MARGIN``, no more tight chains, none closer) and keeps those layers farther
    apart, until one keeps ``PRINT_MARGIN`` (session 53: Tetris's chains ``w_b_0`` and
    ``w_y_3``, from facing leaves of the y and b trees, passed 0.42 sigma apart in row 11
    with the lean 0.6, more than 1.2 with 0.8; its closest chains then 0.64 sigma apart).
    In such a build a leaned chain's first junction turns no farther from its leaf page than
    ``BRANCH_LEAN + END_BEND`` of the largest bend, as before (``_build_circuit``)."""
    def tight_wires(r):
        return tuple(dict.fromkeys(t[2:].rsplit("_", 1)[0] for t, _ in r.tight))

    first = _build_circuit(netlist, spec, options, progress)
    builds = [("first_build", first)]
    if first.tight:
        builds.append(("second_build", _build_circuit(netlist, spec, options, progress,
                                                      first_wires=tight_wires(first))))
    if first.leaned and all(r.tight for _, r in builds):
        third = _build_circuit(netlist, spec, options, progress, branch_lean=0.0)
        builds.append(("unleaned_build", third))
        if third.tight:
            builds.append(("unleaned_second_build", _build_circuit(netlist, spec, options, progress,
                                                                   first_wires=tight_wires(third), branch_lean=0.0)))
    best = max(range(len(builds)), key=lambda i: _merit(builds[i][1]))     # (the first on a tie)
    if first.leaned:
        for lean in (PRINT_LEANS if options.print_leans is None else options.print_leans):
            if builds[best][1].print_clear >= PRINT_MARGIN:
                break
            builds.append((f"print_lean_{lean:g}_build", _build_circuit(netlist, spec, options, progress,
                                                                         branch_lean=lean,
                                                                         contact_margin=PRINT_MARGIN)))
            if _print_better(builds[-1][1], builds[best][1]):
                best = len(builds) - 1
    c = builds[best][1].assemble()             # only the build kept is assembled
    for i, (key, r) in enumerate(builds):
        if i != best:
            c.seconds[key] = sum(r.seconds.values())
    return c


@dataclass
class _Routed(_PrintContacts):
    """One build routed, not yet assembled: its chains left tight (``(tag, gap)``, in
    assembly order), their smallest gap (``closest``, sigma), the contacts of its chains'
    layers (:func:`_state_contacts`, smallest first), the seconds so far, and ``assemble()``,
    which makes the :class:`Circuit` (once)."""

    tight: list
    closest: float
    contacts: list
    seconds: dict
    assemble: object
    leaned: bool = False             # its branch trees' chains on pages on pages lean (BRANCH_LEAN)
    near_print: object = None        # () -> contacts closer than PRINT_MARGIN, smallest first (listed once, on first call)

    @property
    def print_clear(self) -> float:
        """The smallest clearance of two chains' layers over the wires' states, up to
        ``PRINT_MARGIN`` (sigma; inf: none closer)."""
        return min((k.clearance for k in self.print_contacts), default=math.inf)


def _print_better(new, old) -> bool:
    """Whether build ``new`` keeps its chains' layers farther apart for the print than ``old``
    (``print_clear``, up to ``PRINT_MARGIN``) while no worse by :func:`_merit`'s measures: its
    smallest contact clearance up to ``CONTACT_MARGIN`` no smaller, no more tight chains, and
    its tight chains' smallest distance no smaller."""
    return (min(new.print_clear, PRINT_MARGIN) > min(old.print_clear, PRINT_MARGIN)
            and _merit(new)[0] >= _merit(old)[0] and len(new.tight) <= len(old.tight)
            and new.closest >= old.closest)


def _merit(c) -> tuple:
    """How well a build keeps its chains apart, larger is better: the smallest clearance of
    two chains' layers over the wires' states (up to ``CONTACT_MARGIN``: beyond it they
    are clear), then the smallest layer-centre distance of a tight chain (sigma)."""
    m = min((k.clearance for k in c.contacts), default=math.inf)
    return (min(m, CONTACT_MARGIN), c.closest)


def _build_circuit(netlist, spec=None, options: CircuitOptions | None = None, progress=None,
                   first_wires: tuple = (), branch_lean: float = BRANCH_LEAN,
                   contact_margin: float | None = None) -> _Routed:
    """One build, routed (its assembly deferred: :class:`_Routed`); ``first_wires`` (wire
    names: a gate id or a circuit input) are routed first; ``branch_lean``: the branch trees'
    lean (``_branch_tree``); ``contact_margin``: the clearance below which two chains' layers
    are routed again (``_rip_up_contacts``; None: ``CONTACT_MARGIN``, ``PRINT_MARGIN`` in a
    build for the print)."""
    import time

    from scipy.spatial import cKDTree

    from mlc.circuit.lanes import Lane, Lanes, Space

    opt = options or CircuitOptions()
    t_start = time.perf_counter()
    method = router_of(opt, len(netlist.gates))
    limit = (MAX_GATES if method == "ik" else MAX_FAST_GATES) if opt.max_gates is None else opt.max_gates
    if len(netlist.gates) > limit:
        n = len(netlist.gates)
        est = build_cpu_estimate(n, method)
        fit = (f"the ripple-carry adders' fit, gates^{BUILD_CPU_EXPONENT:g}" if method == "ik" else
               f"the fast router's fit, gates^{FAST_BUILD_CPU_EXPONENT:g}")
        raise MlcError(f"netlist has {n} gates; placing and routing it as one mechanism would take "
                       f"about {est / 3600:.2g} h of CPU ({fit}; "
                       f"short wires build faster); the circuit back end builds at most {limit} gates unless told",
                       netlist.source,
                       f"compile with --no-circuit for the netlist alone, split the design, or lift the limit "
                       f"with --max-gates {n}")
    if len(netlist.inputs) > MAX_INPUTS:
        raise MlcError(f"netlist has {len(netlist.inputs)} inputs; a circuit scene lists every row of its truth "
                       f"table and holds at most {MAX_INPUTS}", netlist.source,
                       "compile with --no-circuit for the netlist alone, or split the design")
    signal = netlist.signal
    design = connector_geometry(signal, gap=opt.gap)
    k_muscle = design.k                            # muscles: the design stiffness
    geo = replace(design, k=design.k * opt.joint_k)  # every connector bond (hinges, joints, stops)
    names = [w.name for w in netlist.inputs]
    zero = _wire_values(netlist, {x: 0 for x in names})

    # ---- consumers of every wire ---------------------------------------------------
    consumers: dict[tuple, list] = {}
    for g in netlist.gates:
        for pin, p in (("a", g.a), ("b", g.b)):
            consumers.setdefault(p.src, []).append(("pin", g.id, pin))
    for o in netlist.outputs:
        if o.kind != "const":
            consumers.setdefault(o.src, []).append(("out", o.name, int(o.half_unit)))
    # input levers driven by a muscle of their own: an input's one gate input, or with
    # muscle_per_lever every gate input it feeds (those leave the input's consumers)
    muscled: dict[tuple, str] = {}           # (gate id, pin) -> circuit input
    for w in netlist.inputs:
        cons = consumers.get(("input", w.name), [])
        pins = [c for c in cons if c[0] == "pin"]
        if pins and (opt.muscle_per_lever or len(cons) == 1):
            for c in pins:
                muscled[(c[1], c[2])] = w.name
            consumers[("input", w.name)] = [c for c in cons if c[0] != "pin"]
    consumers_all = consumers

    from mlc.circuit.direct import direct_nets
    direct = direct_nets(netlist, consumers, opt.direct_skip) if opt.direct else {}   # sink -> (driver, pin)

    # ---- placement -----------------------------------------------------------------
    sources = [w for w in netlist.inputs if consumers.get(("input", w.name)) or w.name not in muscled.values()]
    level = place_levels(netlist, sources, muscled=muscled)
    lvl = {g.id: level[("gate", g.id)] for g in netlist.gates}
    levels: dict[int, list] = {}
    for g in netlist.gates:
        if g.id not in direct:                   # a direct sink sits on its driver's unit
            levels.setdefault(lvl[g.id], []).append(g)
    xpos: dict[tuple, float] = {}
    # sources at level 0 in a row of their own; higher ones take a place in their level's row
    low = [w for w in sources if level[("input", w.name)] == 0]
    for i, w in enumerate(low):
        xpos[("input", w.name)] = (i - 0.5 * (len(low) - 1)) * opt.gate_pitch
    for w in sources:
        if level[("input", w.name)] > 0:
            levels.setdefault(level[("input", w.name)], []).append(w)
    for w in netlist.inputs:
        xpos.setdefault(("input", w.name), 0.0)
    # routes arriving at each level: each gets its own horizontal layer in the gap below it
    arriving: dict[int, int] = {}
    for g in netlist.gates:
        for pin, p in (("a", g.a), ("b", g.b)):
            if (g.id, pin) not in muscled and direct.get(g.id) != (p.src[1], pin):
                arriving[lvl[g.id]] = arriving.get(lvl[g.id], 0) + 1
    zlevel = {0: 0.0}
    for d in range(1, max(level.values(), default=0) + 1):
        zlevel[d] = zlevel[d - 1] + opt.level_pitch + LAYER_PITCH * arriving.get(d, 0)
    src_level = {w.name: level[("input", w.name)] for w in sources}

    def row_key(it):
        """A gate: the mean x of its drivers; a source: of its consumers' other drivers placed so far."""
        if not hasattr(it, "id"):
            xs = [xpos[p.src] for g in netlist.gates for p in (g.a, g.b)
                  if ("input", it.name) in (g.a.src, g.b.src) and p.src != ("input", it.name) and p.src in xpos]
            return (float(np.mean(xs)) if xs else 0.0, 1, it.name)
        return (0.5 * (xpos.get(it.a.src, 0.0) + xpos.get(it.b.src, 0.0)), 0, it.id)

    origin: dict[str, np.ndarray] = {}
    for d in sorted(levels):
        for _ in direct:                         # a direct sink stands over its driver; repeated
            for s_, (drv, _p) in direct.items():  # len(direct) times: a sink may drive another sink
                if ("gate", drv) in xpos:
                    xpos[("gate", s_)] = xpos[("gate", drv)]
        gs = levels[d]
        gs.sort(key=row_key)
        for i, g in enumerate(gs):
            x = (i - 0.5 * (len(gs) - 1) + 0.5 * (d % 2)) * opt.gate_pitch
            if not hasattr(g, "id"):
                xpos[("input", g.name)] = x
                continue
            xpos[("gate", g.id)] = x
            origin[g.id] = np.array([x, 0.0, zlevel[d]])
    layer_next = {d: 0 for d in zlevel}

    bodies: list[Body] = []
    bonds: list[Bond] = []
    muscles: list[Muscle] = []
    probes: list[Probe] = []
    by_name: dict[str, Body] = {}

    def add(parts: Parts):
        bodies.extend(parts.bodies)
        bonds.extend(parts.bonds)
        muscles.extend(parts.muscles)
        for b in parts.bodies:
            by_name[b.name] = b

    # ---- gates ---------------------------------------------------------------------
    n_direct_half = 0
    gate_owned: list[tuple[list[Body], frozenset]] = []   # bodies of each gate (and direct unit), their owners
    for g in [g for g in netlist.gates if g.id not in direct] + sorted(
            (g for g in netlist.gates if g.id in direct), key=lambda g: lvl[g.id]):
        state = f"{zero[g.a.src]}{zero[g.b.src]}"
        sc, pos, quat = _posed_gate(g.type, signal, state)
        if g.id in direct:
            from mlc.circuit.direct import place_direct
            parts, R, t = place_direct(g.id, *direct[g.id], sc, pos, quat, by_name, zero[("gate", direct[g.id][0])],
                                       geo, LEVER_STOP, opt.end_drop)
            add(parts)
            gate_owned.append((parts.bodies, frozenset((g.id, direct[g.id][0]))))
            n_direct_half += 2
            origin[g.id] = t
            xpos[("gate", g.id)] = float(t[0])
        else:
            bs, bd = _gate_bodies(g.id, sc, pos, quat, origin[g.id])
            add(Parts(bs, bd, []))
            gate_owned.append((bs, frozenset((g.id,))))
        for m in sc.muscles:                     # muscle_a / muscle_b: kept where an input drives the lever
            inp = muscled.get((g.id, m.input))
            if inp is not None:
                ba, sa = m.a.split(".", 1)
                bb, sb = m.b.split(".", 1)
                # one muscle per input as before; with a muscle per lever each named for its lever
                name = f"muscle_{inp}_{g.id}_{m.input}" if opt.muscle_per_lever else f"muscle_{inp}"
                muscles.append(Muscle(name, inp, f"{g.id}_{ba}.{sa}", f"{g.id}_{bb}.{sb}", m.rest, m.actuated, m.k))

    # ---- sources of inputs that fan out (or reach an output) --------------------------
    taps: dict[tuple, tuple[Pair, int]] = {}     # wire -> (tap pair, its polarity: 1 = carries NOT wire)
    for w in sources:
        src = ("input", w.name)
        c = np.array([xpos[src], 0.0, zlevel[src_level[w.name]]])
        parts, pin, pout = half_unit_parts(f"src_{w.name}", c, np.array([0.0, 1.0, 0]), np.array([0, 0, 1.0]),
                                           zero[src], geo)
        parts.muscles.append(Muscle(f"muscle_{w.name}", w.name, pin.lo, pin.hi, geo.L0, geo.L1, k_muscle))
        add(parts)
        if src_level[w.name] > 0:                # among a level's gates: the other chains keep from it
            gate_owned.append((parts.bodies, frozenset((f"src:{w.name}",))))
        taps[src] = (pout, 1)
        if not consumers.get(src):
            taps[src] = (pin, 0)
    for g in netlist.gates:
        taps[("gate", g.id)] = (_pair(by_name, f"{g.id}_out_lo.out", f"{g.id}_out_hi.out"), 0)

    # ---- wires: branches, chains, output probes ----------------------------------------
    t_route = time.perf_counter()
    n_chains = n_half = 0
    lanes = Lanes()
    space = Space(LAYER_RADIUS)
    space_clear = 2.0 * LAYER_RADIUS
    gate_pts = [(_slab_points(bs), owners) for bs, owners in gate_owned]
    tight: list = []                        # chains that could not be kept apart by the lanes
    routed: dict[str, _Chain] = {}         # chain tag -> its route and what assembling it needs
    deferred: list = []                     # pages and stubs (Parts) and chain tags, in routing order
    if direct:                                  # the direct nets need no chain
        consumers = {w: c for w, c in consumers_all.items()
                     if not (w[0] == "gate" and len(c) == 1 and c[0][0] == "pin"
                             and direct.get(c[0][1], (None,))[0] == w[1])}
    n_half += n_direct_half
    for wire in taps:                         # the sites chains end on (after gate_pts: their posts
        for c in consumers.get(wire, []):     # are not among the points other chains keep from)
            if c[0] == "pin":
                _add_end_sites(by_name, c[1], c[2], opt.end_drop)
    _check_reach(netlist, taps, consumers, by_name, level, geo, opt.end_drop)
    wires = [w for w in taps if consumers.get(w)]
    wires.sort(key=lambda w: w[1] not in first_wires)          # stable: the rest keep their order
    chains: list[_Chain] = []               # in routing order (routed after the loop, see _route_all)
    leaned = False                          # a branch tree has pages on pages (their chains lean)
    for wire in wires:
        tap, pol = taps[wire]
        cons = consumers[wire]
        wname = wire[1]
        state_at_tap = zero[wire] ^ pol
        stop_at_tap = LEVER_STOP if wire[0] == "gate" else POST_WIDTH     # a gate's tap is on its lever
        up = np.array([0.0, 0.0, 1.0])
        t_up = up - float(up @ tap.axis) * tap.axis
        t_up /= np.linalg.norm(t_up)
        # turning about the tap's axis by +ang must lean towards -y (the routing planes)
        sgn = 1.0 if rotate(t_up, tap.axis, 0.1)[1] < 0 else -1.0
        # where each consumer is (for the page order)
        def cx(c):
            if c[0] == "pin":
                return xpos[("gate", c[1])]
            return xpos[wire]
        cons = sorted(cons, key=cx)
        # an output that reads the tap's own polarity is a probe across the tap: no page
        for c in [c for c in cons if c[0] == "out" and c[2] == pol]:
            probes.append(Probe(c[1], c[1], tap.lo, tap.hi, geo.L0, geo.L1))
        cons = [c for c in cons if not (c[0] == "out" and c[2] == pol)]
        if not cons:
            continue
        if len(cons) == 1:
            # a gate's tap is a lever (free to ~85 deg); a source's is a half unit, whose
            # junction with the chain bends at most max_bend: lean less, turn less
            lean = TAP_LEAN if wire[0] == "gate" else SOURCE_LEAN * max_bend(geo)
            starts = [(tap, pol, True, rotate(t_up, tap.axis, sgn * lean), None)]
        elif BRANCH_TREE and not (method == "fast" and len(cons) == 2):
            # a tree of 2-way branches, pages at -90/+90 degrees (_branch_tree); for 2 consumers
            # the same two pages, built by the same calls, as the k-way branch below
            # (the lean with the whole solve only: the fast router's Tetris then bent a chain back
            # into its own leaf page, -0.05 sigma; unleaned it is clear, two chains tight)
            bl = branch_lean if method == "ik" else 0.0
            starts, pages = _branch_tree(f"w_{wname}", tap, t_up, sgn, pol, zero[wire], len(cons), geo, stop_at_tap,
                                         bl)
            leaned = leaned or (len(cons) > 2 and bl != 0.0)     # (pages on pages: leaves along +-x, leaned)
            deferred += pages
            n_half += len(pages)
        else:
            starts = []
            angs = branch_angles(len(cons))
            held = method == "fast" and len(cons) == 2
            if held:
                angs = list(FAST_PAIR_PAGES)
            spread = abs(angs[1] - angs[0])
            # (held pages: posts long enough for the smallest angle their stop lets them close to)
            post = _page_post(geo, PAGE_MIN_ANGLE if held else spread)
            # the pages' input posts meet at the tap's joint: their ends, d from it, are
            # 2 d sin(s/2) apart, a post's width w at d = w for 4 pages (s = 60 deg; measured
            # clear, +0.0107 sigma); 5 pages at d = w overlapped by 0.0117 sigma, so from 5
            # pages on d = w / (2 sin(s/2)) + 0.03 sigma
            page_stop = stop_at_tap if len(cons) <= 4 else max(
                stop_at_tap, 0.5 * POST_WIDTH / math.sin(0.5 * spread) + 0.03)
            for k, (c, ang) in enumerate(zip(cons, angs)):
                t = rotate(t_up, tap.axis, sgn * ang)
                parts, pin, pout = half_unit_parts(f"w_{wname}_p{k}", tap.centre, tap.axis, t, state_at_tap, geo,
                                                   in_post=post, in_stop=page_stop)
                parts.bonds += join(f"w_{wname}_p{k}_j", tap, pin, geo.k)
                if held and k == 1:
                    parts.bonds += _page_stop(f"w_{wname}_pp", deferred[-1], parts, f"w_{wname}_p0", f"w_{wname}_p1",
                                              spread, geo.k)
                deferred.append(parts)
                n_half += 1
                starts.append((pout, pol ^ 1, True, t, None))
        for k, (c, (start, spol, free, t0, lean_k)) in enumerate(zip(cons, starts)):
            sstate = zero[wire] ^ spol
            tag = f"w_{wname}_{k}"
            if c[0] == "out":
                need = c[2]                                   # 1: the output is inverted
                extra = spol ^ need
                end = start
                if extra:
                    parts, pin, pout = half_unit_parts(f"{tag}_stub", start.centre, start.axis, t0, sstate, geo,
                                                       in_stop=stop_at_tap if start is tap else POST_WIDTH)
                    parts.bonds += join(f"{tag}_stub_j", start, pin, geo.k)
                    if half_unit_prefix(start):     # on a page or a source: stop its junction
                        parts.bonds += junction_stops(f"{tag}_stub_s", half_unit_prefix(start), f"{tag}_stub", geo, geo.k)
                    elif start is tap and wire[0] == "gate":       # on a lever: the tap stop
                        parts.bonds += _tap_stop(f"{tag}_stub_s", by_name[tap.lo.split(".")[0]], tap.lo.split(".")[1],
                                                 t_up, t0, f"{tag}_stub", geo.k)
                    deferred.append(parts)
                    n_half += 1
                    end = pout
                probes.append(Probe(c[1], c[1], end.lo, end.hi, geo.L0, geo.L1))
                continue
            gid, pin_name = c[1], c[2]
            target = _pin_pair(by_name, gid, pin_name, opt.end_drop)
            ext = end_post(opt.end_drop) - 0.5 * geo.gap
            app = np.array([0.0, 0.0, 1.0])
            d_sink = lvl[gid]
            k_layer = layer_next[d_sink]
            layer_next[d_sink] += 1
            z_run = zlevel[d_sink - 1] + RUN_BASE + LAYER_PITCH * k_layer
            x_rise = tap.centre[0] + RISER_PITCH * (k - 0.5 * (len(starts) - 1))
            xp, yp, zp = _pair(by_name, f"{gid}_{pin_name}_lo.in", f"{gid}_{pin_name}_hi.in").centre   # the lane: as before
            # the two inputs of a gate are near one x and differ in y: come in from either side
            # (the input with the smaller x from -x), the far one (larger y) crossing lower
            other = _pair(by_name, *(f"{gid}_{'b' if pin_name == 'a' else 'a'}_{e}.in" for e in ("lo", "hi")))
            dx = xp - other.centre[0]
            side = float(np.sign(dx)) if abs(dx) > 1e-6 else (-1.0 if pin_name == "a" else 1.0)
            x_in = xp + side * PIN_SPREAD
            z_in = zp - 8.0 - (PIN_STAGGER if yp > other.centre[1] else 0.0)
            x_end = xp + side * PIN_END
            lane = Lane(x_rise, start.centre[2] + 3.0, z_run, x_in, z_in, x_end, zp - 6.0)
            sbm = (END_BEND * max_bend(geo) if len(starts) > 1 else TAP_TURN if wire[0] == "gate"
                   else SOURCE_TURN * max_bend(geo))
            if lean_k is not None and lean_k > BRANCH_LEAN:
                # a larger lean (PRINT_LEANS): the first junction bends no farther from its page than
                # BRANCH_LEAN + END_BEND, as before (session 53: lean 0.8 + 0.2 brought the chain's
                # first slab 0.05 sigma from its leaf page, 0.2 mm^3 into it in print)
                sbm = max(0.0, BRANCH_LEAN + END_BEND - lean_k) * max_bend(geo)
            # a branch's chains leave their pages side by side: their first layers are the branch's
            skip = BRANCH_LAYERS if start is not tap else 0
            # the gates this chain may touch: its driver's and its sink's (with their direct units)
            others = [p for p, owners in gate_pts
                      if gid not in owners and not (wire[0] == "gate" and wname in owners)
                      and not (wire[0] == "input" and f"src:{wname}" in owners)]
            others = np.concatenate(others) if others else np.zeros((0, 3))
            others_tree = cKDTree(others) if len(others) else None
            route_kw = dict(tangent=t0, free_start=free, approach=app, last_pitch=geo.pitch + ext,
                            start_bend_max=sbm, extras=LANE_EXTRAS, bend_max=LANE_BEND * max_bend(geo),
                            end_bends=(END_JUNCTIONS, END_BEND * max_bend(geo)), wp_weight=WAYPOINT_WEIGHT)
            if method == "fast":            # only then: an "ik" solve keeps its cache key (and its scene)
                route_kw["method"] = "fast"
            ch = _Chain(tag, lane, yp, (start.centre, start.axis, target.centre, target.axis, geo, spol), route_kw,
                        dict(tangent=t0, free_start=free, approach=app, last_pitch=geo.pitch + ext,
                             start_bend_max=sbm),
                        skip, others, _gap_fn(space, tag, skip, wire, others_tree, geo, ext, space_clear), (geo, ext),
                        (wire, start, tap, spol, sstate, stop_at_tap, t_up, target, ext))
            ch.sink = f"{gid}.{pin_name}"
            chains.append(ch)
            deferred.append(tag)
    _route_all(chains, routed, lanes, space, space_clear, opt.jobs, netlist.source, progress)
    t_rip = time.perf_counter()
    rip_ups = _rip_up(routed, lanes, space, space_clear)
    layer_cache: dict = {}      # the layers' boxes per chain and state, shared by both contact passes
    contact_rips, contacts = _rip_up_contacts(routed, lanes, space, space_clear, geo, margin=contact_margin,
                                              cache=layer_cache)
    t_done = time.perf_counter()
    printed: list = []

    def near_print() -> list:
        """The layers' contacts within the print's margin (PRINT_MARGIN), as the rows switch them,
        listed on the first call only (only a build choosing a print lean reads them; a build for
        the print has just listed them at that margin); the routes are not changed after this."""
        if not printed:
            near = contacts if contact_margin == PRINT_MARGIN else _state_contacts(routed, geo, cache=layer_cache,
                                                                                   margin=PRINT_MARGIN)
            printed.append([k for k in near if k.clearance < PRINT_MARGIN])
            layer_cache.clear()
        return printed[0]
    tight += [(t, round(float(routed[t].gap), 3)) for t in deferred
              if not isinstance(t, Parts) and routed[t].gap < space_clear]
    seconds = {"place": t_route - t_start, "route": t_rip - t_route, "rip_up": t_done - t_rip}

    def _assemble() -> Circuit:
        """The scene of this build, in routing order (pages and stubs where they were made),
        then the constant outputs, the probes and the meta."""
        t_asm = time.perf_counter()
        for item in deferred:
            _assemble_item(item)
        return _finish(t_asm)

    def _assemble_item(item) -> None:
        nonlocal n_chains, n_half
        if isinstance(item, Parts):
            add(item)
            return
        tag, ch = item, routed[item]
        wire, start, tap, spol, sstate, stop_at_tap, t_up, target, ext = ch.ctx
        route = ch.route
        parts, pairs, lout = _chain_parts(ch, geo)
        parts.bonds += join(f"{tag}_j0", start, pairs[0], geo.k)
        if start is not tap and half_unit_prefix(start):     # the junction after a branch page
            parts.bonds += junction_stops(f"{tag}_s0", half_unit_prefix(start), f"{tag}_0", geo, geo.k)
        if start is tap and wire[0] != "gate" and half_unit_prefix(start):   # on a source half unit
            parts.bonds += junction_stops(f"{tag}_s0", half_unit_prefix(start), f"{tag}_0", geo, geo.k)
        if start is tap and wire[0] == "gate":            # the chain hangs on the lever: its stop
            parts.bonds += _tap_stop(f"{tag}_s0", by_name[tap.lo.split(".")[0]], tap.lo.split(".")[1],
                                     t_up, pairs[1].centre - pairs[0].centre, f"{tag}_0", geo.k)
        add(parts)
        n_chains += 1
        n_half += len(route.bends)
        same = float(lout.axis @ target.axis) > 0
        ends = (lout.lo, lout.hi) if same else (lout.hi, lout.lo)
        bonds.append(Bond(f"{tag}_end_lo", ends[0], target.lo, geo.k, 0.0, 0.0, "universal", f"{tag}_end_lo"))
        bonds.append(Bond(f"{tag}_end_hi", ends[1], target.hi, geo.k, 0.0, 0.0, "universal", f"{tag}_end_hi"))

    def _finish(t_asm) -> Circuit:
        # ---- constant outputs ------------------------------------------------------------
        for i, o in enumerate(netlist.outputs):
            if o.kind == "const":
                L = geo.length(o.value)
                c = np.array([(i + 1) * opt.gate_pitch, -opt.gate_pitch, 0.0])
                p, q = c - [0.5 * L, 0, 0], c + [0.5 * L, 0, 0]
                body = slab_body(f"const_{o.name}", [(p, q)], {"lo": p, "hi": q}, np.array([0, 0, 1.0]),
                                 geo.width, geo.thickness)
                add(Parts([body], [], []))
                probes.append(Probe(o.name, o.name, f"const_{o.name}.lo", f"const_{o.name}.hi", geo.L0, geo.L1))

        # order probes as the outputs
        order = {o.name: i for i, o in enumerate(netlist.outputs)}
        probes.sort(key=lambda p: order[p.output])
        table = _truth_table(spec, netlist)
        scene = Scene(name=f"circuit_{_stem(netlist.source)}", bodies=bodies, bonds=bonds, muscles=muscles,
                      probes=probes, inputs=names, outputs=[o.name for o in netlist.outputs], truth_table=table,
                      meta={"element": "circuit", "signal": signal, "source": netlist.source,
                            "gates": {g.id: {"type": g.type, "origin": [float(v) for v in origin[g.id]],
                                             "depth": g.depth} for g in netlist.gates},
                            "connector": {"gap": geo.gap, "side": round(geo.side, 6), "joint_k": geo.k, "chains": n_chains,
                                          "half_units": n_half, "planes": 1 + max((k for k, _ in lanes.placed), default=-1),
                                          "tight_chains": [t for t, _ in tight]}})
        if method == "fast":            # (not written for "ik": the examples' scenes stay as they were)
            scene.meta["connector"]["router"] = method
        if rip_ups:
            scene.meta["connector"]["rerouted"] = [list(p) for p in rip_ups]
        if contact_rips:
            scene.meta["connector"]["rerouted_contacts"] = [list(p) for p in contact_rips]
        if leaned and branch_lean != BRANCH_LEAN:   # a lean of PRINT_LEANS (_build_routed)
            scene.meta["connector"]["branch_lean"] = branch_lean
        touching = [k for k in contacts if k.clearance < CONTACT_MARGIN]
        if touching:        # layers that may touch in some row: named, with their clearance (sigma)
            scene.meta["connector"]["state_contacts"] = [[k.a, k.i, k.b, k.j, round(k.clearance, 4)] for k in touching]
        if opt.muscle_per_lever:
            scene.meta["connector"]["muscle_per_lever"] = True
            # outputs that are a circuit input itself (no half unit): a robot gives the DOF such an
            # output drives a muscle of that input instead of a chain (mlc.robot.build, "muscle")
            wired = {o.name: o.src[1] for o in netlist.outputs if o.kind == "input" and not o.half_unit}
            if wired:
                scene.meta["connector"]["input_outputs"] = wired
        if opt.direct:
            scene.meta["connector"]["direct"] = [[d, s, p] for s, (d, p) in direct.items()]
        scene.check()
        t_end = time.perf_counter()
        return Circuit(scene, origin, n_chains, n_half, dict(seconds, assemble=t_end - t_asm),
                       min((g for _, g in tight), default=float("inf")), contacts, near_print)

    return _Routed(tight, min((g for _, g in tight), default=float("inf")), contacts, seconds, _assemble,
                   leaned, near_print)


def _check_reach(netlist, taps, consumers, by_name, level, geo, drop: float = END_DROP) -> None:
    """Refuse, before any routing, a wire whose sink is farther from its tap in a straight line
    than the longest chain the router tries (``route.MAX_HALF`` half units of ``geo.pitch``):
    no route can close it (a route is never shorter than the straight line), and finding
    that out chain by chain took 17 minutes on a 6 x 6 multiplier (sigma)."""
    from mlc.circuit.route import MAX_HALF
    reach = MAX_HALF * geo.pitch
    for wire, (tap, _) in taps.items():
        for c in consumers.get(wire, []):
            if c[0] != "pin":
                continue
            target = _pin_pair(by_name, c[1], c[2], drop)
            d = float(np.linalg.norm(target.centre - tap.centre))
            if d > reach:
                src = "input" if wire[0] == "input" else "gate"
                rise = level[("gate", c[1])] - level.get(wire, 0)
                raise MlcError(f"cannot route {src} {wire[1]} to {c[1]}.{c[2]}: the sink stands {d:.0f} sigma from "
                               f"the wire's tap ({rise} levels up), beyond the longest connector chain the router "
                               f"closes ({MAX_HALF} half units, {reach:.0f} sigma)", netlist.source,
                               "split the design into smaller circuits, or compile with --no-circuit for the "
                               "netlist alone")


@dataclass
class _Chain:
    """One chain to route (sigma): its lane, the y of its sink's pin (``yp``), the
    positional arguments of ``solve_route`` (``solve``) and its keywords in a lane
    (``kw``) and straight (``straight_kw``: when no lane closes), the layers left out of
    the keep-apart test at its start (``skip``), the other gates' points it keeps from,
    its keep-apart distance function (``_gap_fn``), ``(geo, ext)`` for its layers, what
    assembling it needs (``ctx``); then its route, distance and plane."""

    tag: str
    lane: object
    yp: float
    solve: tuple
    kw: dict
    straight_kw: dict
    skip: int
    others: np.ndarray
    gap_of: object
    geo_ext: tuple
    ctx: tuple
    route: object = None
    gap: float = -math.inf
    plane: int = 0
    sink: str = ""                   # "gate.pin" (for messages)

    def layers(self, route=None) -> np.ndarray:
        """Layer centres of ``route`` (default the chain's own) as this chain's layers."""
        return _layers(self.route if route is None else route, *self.geo_ext)


def _chain_parts(ch: _Chain, geo, flip: int = 0, only=None):
    """The half units of routed chain ``ch`` as assembled (bodies posed as built, the
    junction bonds and stops), each layer in its state of the all-zero row, or with
    ``flip`` in the other one (every layer of a chain flips when its wire does).  The last
    half unit's output post is longer, so that its layer clears the lever plane.
    Returns (parts, pairs, the last half unit's output pair).  ``only`` (a set of
    indices): the bodies of those half units alone, as in the whole chain (parts only)."""
    tag = ch.tag
    _, start, tap, _, sstate, stop_at_tap, _, _, ext = ch.ctx
    route = ch.route
    state = sstate ^ flip
    last = len(route.bends) - 1
    in0 = stop_at_tap if start is tap else POST_WIDTH
    if only is not None:
        parts, _ = chain_parts(tag, route.centre, route.axis, route.tangent, route.bends, state, geo,
                               in_stop=in0, only=set(only) - {last})
        if last in only:            # the last half unit from the same pairs as below
            cs, us, ts = chain_frames(route.centre, route.axis, route.tangent, route.bends, geo.pitch)

            def unit(i):
                return half_unit_parts(f"{tag}_{i}", cs[i], us[i], ts[i], (state + i) % 2, geo,
                                       in_stop=in0 if i == 0 else POST_WIDTH)
            cs_in = unit(last - 1)[2] if last > 0 else unit(0)[1]
            parts.add(_last_unit(tag, last, cs_in, unit(last)[2], state, geo, ext)[0])
        return parts, None, None
    parts, pairs = chain_parts(tag, route.centre, route.axis, route.tangent, route.bends, state, geo,
                               in_stop=in0, stops=True)
    for b in list(parts.bodies):
        if b.name.startswith(f"{tag}_{last}_"):
            parts.bodies.remove(b)
    parts.bonds = [bd for bd in parts.bonds if not bd.name.startswith(f"{tag}_{last}_")]
    lp, lin, lout = _last_unit(tag, last, pairs[-2], pairs[-1], state, geo, ext)
    parts.add(lp)
    return parts, pairs, lout


def _last_unit(tag: str, last: int, pair_in, pair_out, state: int, geo, ext: float):
    """The last half unit (index ``last``) of chain ``tag`` whose layers start in
    ``state``: from its input pair ``pair_in`` towards where the chain's frames put its
    output pair (``pair_out``), with an output post ``ext`` longer, so that its layer clears
    the lever plane.  Returns ``half_unit_parts``'s (parts, input pair, output pair)."""
    t_last = (pair_out.centre - pair_in.centre) / np.linalg.norm(pair_out.centre - pair_in.centre)
    return half_unit_parts(f"{tag}_{last}", pair_in.centre, pair_in.axis, t_last, state ^ (last % 2), geo,
                           out_post=0.5 * geo.gap + ext, out_stop=LEVER_STOP)


def _state_contacts(routed: dict, geo, tags=None, cache: dict | None = None, margin: float | None = None) -> list:
    """:func:`mlc.circuit.contact.state_contacts` of the routed chains (of those involving a
    chain of ``tags`` when given): every pair of layers of two chains within two bounding
    radii plus ``margin`` (None: ``CONTACT_MARGIN``; ``PRINT_MARGIN`` for the print's), tested as
    rigid layers in every state of their wires.  ``cache``: the layers' boxes of each chain
    and state, kept across calls while the chain keeps the same route (the caller's: one build)."""
    from mlc.circuit.contact import candidate_pairs, layer_boxes, state_contacts
    centres = {t: ch.layers() for t, ch in routed.items() if ch.route is not None}
    pairs = candidate_pairs(centres, 2.0 * LAYER_RADIUS + (CONTACT_MARGIN if margin is None else margin))
    if tags is not None:
        pairs = [p for p in pairs if p[0] in tags or p[2] in tags]
    cache = {} if cache is None else cache
    need: dict = {}
    for a, i, b, j in pairs:
        need.setdefault(a, set()).add(i)
        need.setdefault(b, set()).add(j)

    def boxes(tag, flip):           # the layers the pairs need, made once per route
        route = routed[tag].route
        hit = cache.get((tag, flip))
        if hit is None or hit[0] is not route:
            hit = cache[(tag, flip)] = (route, {}, set())
        missing = need[tag] - hit[2]
        if missing:
            hit[1].update(layer_boxes(_chain_parts(routed[tag], geo, flip, only=missing)[0].bodies, tag))
            hit[2].update(missing)
        return hit[1]
    return state_contacts(pairs, boxes, {t: routed[t].ctx[0] for t in centres})


def _layers(route, geo, ext: float) -> np.ndarray:
    """Layer centres of a routed chain whose last half unit's post is ``ext`` longer (sigma).

    By ``route._fk``'s recurrence, whose error grows along the chain (its docstring); where
    that has drifted (an axis off unit length by more than ``LAYER_DRIFT``, or not finite:
    session 39, a 129-half-unit chain of the fast-built 4-bit adder overflowed to NaN), the
    frames again with each axis and tangent renormalised (``exact``), as the bodies are built."""
    from mlc.circuit.lanes import layer_centres
    from mlc.circuit.route import _fk, _fk_kernel
    pitches = np.array([geo.pitch] * (len(route.bends) - 1) + [geo.pitch + ext], float)
    cs, us, _ = _fk(route.centre, route.axis, route.tangent, route.bends, pitches)
    with np.errstate(over="ignore", invalid="ignore"):
        drift = np.abs(np.einsum("ij,ij->i", us, us) - 1.0)
    if not np.all(drift <= LAYER_DRIFT):            # (NaN fails too)
        b = np.ascontiguousarray(route.bends, dtype=np.float64)
        n = len(b)
        cs, us, ts = np.empty((n + 1, 3)), np.empty((n + 1, 3)), np.empty((n, 3))
        _fk_kernel(np.asarray(route.centre, float), np.asarray(route.axis, float), np.asarray(route.tangent, float),
                   b, pitches, cs, us, ts, True)
    return layer_centres(cs)


def _gap_fn(space, tag: str, skip: int, group, others_tree, geo, ext: float, space_clear: float):
    """The keep-apart distance of a route of chain ``tag``: the smallest distance of its
    layers to the layers of the other chains in ``space``, its first ``skip`` layers (at
    its branch page) not to its sibling chains' first layers (``space`` group ``group``,
    the wire); a gate's points, from the ``skip``-th layer on, count as a layer nearer by
    the difference of the two clearances (sigma)."""
    def gap_of(r) -> float:
        layers = _layers(r, geo, ext)
        m = layers[skip:]
        g = space.nearest_chain(layers, tag, skip, group)[0]
        if others_tree is not None and len(m):
            g = min(g, float(others_tree.query(m)[0].min()) + space_clear - GATE_CLEAR)
        return g
    return gap_of


def _route_all(chains: list, routed: dict, lanes, space, space_clear: float, jobs: int, source, progress) -> None:
    """Route ``chains`` in order (:func:`_route_chain`) into ``routed``; with ``jobs`` > 1,
    while this process solves a chain, the first solves of the next ``jobs - 1`` chains, in
    the planes the lanes would give them were the chains before them in their first planes,
    run in other processes (:class:`mlc.circuit.route.Prefetch`: the routes are the same
    for any jobs); this process then takes those and solves the chain after them itself.
    (Starting the next chain's solve at every chain instead left this process waiting on
    one solve after another: measured, no faster than one process.)"""
    from mlc.circuit.lanes import Lanes
    from mlc.circuit.route import Prefetch
    ahead = max(int(jobs), 1) - 1
    started: set = set()                    # chains whose first solve was started ahead
    for ch in chains:
        if ch.skip:       # a branch's chain: its first layers are where they are, routed or not yet
            space.add(_head_layers(ch), ch.tag, ch.skip, ch.ctx[0])
    with Prefetch(jobs) as pf:
        for i, ch in enumerate(chains):
            if progress:
                progress(i, len(chains))
            if ahead and ch.tag not in started:     # this process solves this chain; the others the next ones
                started.update(nxt.tag for nxt in chains[i + 1:i + 1 + ahead])
                guess = Lanes(lanes.sep)
                guess.placed = list(lanes.placed)
                for nxt in chains[i:i + 1 + ahead]:
                    plane = guess.assign(nxt.lane)
                    if nxt is not ch:
                        pf.submit(nxt.tag, *nxt.solve, waypoints=_plane_waypoints(nxt, plane), **nxt.kw)
                    guess.take(nxt.lane, plane)
            _route_chain(ch, lanes, space, space_clear, pf)
            pf.drop(ch.tag)
            if ch.route is None:
                wire = ch.ctx[0]
                raise MlcError(f"cannot route wire {wire[1]} to {ch.sink}: no connector chain reaches it",
                               source, "this is a placement limit of mlc; please report the netlist")
            routed[ch.tag] = ch


def _head_layers(ch: _Chain) -> np.ndarray:
    """The first ``ch.skip`` layer centres of branch chain ``ch`` before it is routed: straight
    on from its branch page along its start tangent (its route may bend them by at most
    ``END_BEND`` of the largest bend).  Held in the keep-apart space until ``ch`` is routed,
    so that a sibling routed before it does not come back beside its start (session 39: in
    the fast-built 7-bit adder, chain 0 of ``g19`` ran beside chain 1's first layers, which
    a branch's floppy swing then pushed into it by 0.20 sigma in the all-ones row) (sigma)."""
    start, geo = ch.ctx[1], ch.geo_ext[0]
    t0 = np.asarray(ch.straight_kw["tangent"], float)
    cs = start.centre + geo.pitch * np.arange(ch.skip + 1)[:, None] * t0
    from mlc.circuit.lanes import layer_centres
    return layer_centres(cs)


def _plane_waypoints(ch: _Chain, plane: int) -> list:
    """The points ``ch`` is pulled towards in routing plane ``plane``: its lane's corners, rounded (sigma)."""
    from mlc.circuit.lanes import plane_y, rounded
    lane = ch.lane
    y_k = plane_y(plane)
    corners = [(lane.x_r, y_k, lane.z_a), (lane.x_r, y_k, lane.z_run), (lane.x_in, y_k, lane.z_run),
               (lane.x_in, y_k, lane.z_in), (lane.x_end, ch.yp - 1.0, lane.z_end)]
    return [tuple(p) for p in rounded(corners, TURN_RADIUS, WAYPOINT_STEP)]


def _route_chain(ch: _Chain, lanes, space, space_clear: float, pf=None) -> None:
    """Route ``ch`` and place it (``lanes``, ``space``): in up to PLANE_TRIES planes from
    the first its lane fits, pulled towards the lane's rounded corners, keeping the route
    farthest from the placed chains and gates (the first that keeps ``space_clear``); if
    none keeps it, that plane's route again pushed away from them (kept if farther); if no
    lane closes, a straight route.  ``ch.route`` stays None if nothing closes.  The planes
    depend on the lanes alone, so with a :class:`~mlc.circuit.route.Prefetch` ``pf``, once
    a plane has left the chain too close, the solve in the plane after the next one starts
    in another process while this one solves the next (most chains keep their first plane:
    starting its next one at once was measured to waste more than it saved; the caller
    drops what is not needed)."""
    from mlc.circuit.route import solve_route
    space.remove(ch.tag)                    # (a branch chain's head layers, held until now)
    lane = ch.lane
    plane = lanes.assign(lane)
    best = (-math.inf, None, plane, ())
    for k in range(PLANE_TRIES):
        after = None
        if pf is not None and 0 < k < PLANE_TRIES - 1:     # the plane before was too close: this one too?
            after = lanes.assign(lane, plane + 1)
            pf.submit(ch.tag, *ch.solve, waypoints=_plane_waypoints(ch, after), **ch.kw)
        wps = _plane_waypoints(ch, plane)
        r = solve_route(*ch.solve, waypoints=wps, **ch.kw)
        if r is not None:
            g = ch.gap_of(r)
            if g > best[0]:
                best = (g, r, plane, wps)
            if g >= space_clear:
                break
        plane = lanes.assign(lane, plane + 1) if after is None else after
    gap, route, plane, wps = best
    if route is not None and gap < space_clear:
        # no plane keeps it apart: the best plane's route again, pushed away from the
        # layers of the chains placed so far and from the other gates' slabs
        avoid = ((space.points(ch.tag), space_clear), (ch.others, GATE_CLEAR))
        r = solve_route(*ch.solve, waypoints=wps, avoid=avoid, avoid_from=ch.skip, **ch.kw)
        g = ch.gap_of(r) if r is not None else -math.inf
        if g > gap:
            gap, route = g, r
    if route is None:        # the lanes are a preference: route straight if they cannot be kept
        route = solve_route(*ch.solve, **ch.straight_kw)
        gap = ch.gap_of(route) if route is not None else -math.inf
    ch.route, ch.gap, ch.plane = route, gap, plane
    if route is not None:
        lanes.take(lane, plane)
        space.add(ch.layers(route), ch.tag, ch.skip, ch.ctx[0])


def _unplace(ch: _Chain, lanes, space) -> None:
    """Take ``ch``'s lane and layers out of ``lanes`` and ``space``."""
    space.remove(ch.tag)
    lanes.placed = [(k, ln) for k, ln in lanes.placed if ln is not ch.lane]


def _rip_up(routed: dict, lanes, space, space_clear: float) -> list:
    """Chains routed early cannot make room for later ones.  For each chain left closer
    than ``RIP_GAP`` to another (closest first), the chain it comes closest to is
    taken out and routed again (``_route_chain``: every plane, all other chains now in
    place), then the chain itself; the two new routes are kept if the smaller of the two
    chains' distances (each to every chain now placed) grew, else the old ones are put
    back.  Returns the (chain, other chain) pairs re-routed; updates ``routed``, ``lanes``
    and ``space``."""
    done = []
    for tag in sorted((t for t, ch in routed.items() if ch.gap < RIP_GAP), key=lambda t: routed[t].gap):
        ch = routed[tag]
        ch.gap = ch.gap_of(ch.route)             # other chains may have moved since
        if ch.gap >= RIP_GAP:
            continue
        _, owner = space.nearest_chain(ch.layers(), tag, ch.skip, ch.ctx[0])
        if owner not in routed:              # a gate's points are nearest: nothing to move
            continue
        pair = [routed[owner], ch]
        old = [(c.route, c.gap_of(c.route), c.plane) for c in pair]
        for c in pair:                       # the other chain first, around this one as it is
            _unplace(c, lanes, space)
            _route_chain(c, lanes, space, space_clear)
            if c.route is None:
                break
        if all(c.route is not None for c in pair) and min(c.gap_of(c.route) for c in pair) > min(o[1] for o in old):
            for c in pair:
                c.gap = c.gap_of(c.route)
            done.append((tag, owner))
            continue
        for c, (route, gap, plane) in zip(pair, old):          # put the old routes back
            _unplace(c, lanes, space)
            c.route, c.gap, c.plane = route, gap, plane
            lanes.take(c.lane, plane)
            space.add(c.layers(route), c.tag, c.skip, c.ctx[0])
    return done


def _rip_up_contacts(routed: dict, lanes, space, space_clear: float, geo,
                      margin: float | None = None, cache: dict | None = None) -> tuple[list, list]:
    """Chains whose layers would touch in some input row (:func:`_state_contacts` below
    ``margin``: None for ``CONTACT_MARGIN``, or ``PRINT_MARGIN`` in a build for the print,
    :func:`_build_routed`): for each such pair of chains (closest first), the one routed
    earlier, which did not see the other, is taken out and routed again with every other
    chain in place, then the other one; the new routes are kept if the pair's smallest
    clearance (each chain against every chain, in every state) grew, else the old ones are
    put back.  ``cache``: :func:`_state_contacts`'s, the caller's to reuse.  Returns (the pairs
    re-routed, the contacts left, smallest first)."""
    boxes: dict = {} if cache is None else cache
    margin = CONTACT_MARGIN if margin is None else margin
    contacts = _state_contacts(routed, geo, cache=boxes, margin=margin)
    order = {t: k for k, t in enumerate(routed)}
    done, seen = [], set()
    for k in list(contacts):
        if k.clearance >= margin:
            break
        if (k.a, k.b) in seen:
            continue
        seen.add((k.a, k.b))
        tags = {k.a, k.b}
        # (none left within reach: an earlier re-route moved them apart)
        old_score = min((c.clearance for c in _state_contacts(routed, geo, tags, boxes, margin)), default=math.inf)
        if old_score >= margin:          # an earlier re-route settled it
            continue
        pair = sorted((routed[k.a], routed[k.b]), key=lambda c: order[c.tag])
        old = [(c.route, c.gap, c.plane) for c in pair]
        for c in pair:
            _unplace(c, lanes, space)
            _route_chain(c, lanes, space, space_clear)
            if c.route is None:
                break
        if all(c.route is not None for c in pair):
            new_score = min((c.clearance for c in _state_contacts(routed, geo, tags, boxes, margin)), default=math.inf)
            if new_score > old_score:
                for c in pair:
                    c.gap = c.gap_of(c.route)
                done.append((k.a, k.b))
                continue
        for c, (route, gap, plane) in zip(pair, old):
            _unplace(c, lanes, space)
            c.route, c.gap, c.plane = route, gap, plane
            lanes.take(c.lane, plane)
            space.add(c.layers(route), c.tag, c.skip, c.ctx[0])
    if done:
        contacts = _state_contacts(routed, geo, cache=boxes, margin=margin)
    return done, contacts


def _slab_points(bodies: list[Body]) -> np.ndarray:
    """Points along the middle of every slab of ``bodies`` (world frame, sigma), at most
    ``GATE_POINT_STEP`` apart along each slab's longest edge: what the router keeps chains from."""
    from mlc.geometry.rotation import quat_to_matrix
    pts = []
    for b in bodies:
        R = b.rotation()
        for box in b.boxes:
            A = R @ quat_to_matrix(np.asarray(box.orientation, float))
            c = b.position + R @ np.asarray(box.center, float)
            k = int(np.argmax(box.size))
            L = float(box.size[k])
            m = max(1, int(math.ceil(L / GATE_POINT_STEP)))
            pts += [c + A[:, k] * (L * (j / m - 0.5)) for j in range(m + 1)]
    return np.array(pts).reshape(-1, 3)


def _stem(source: str) -> str:
    import os
    import re
    s = os.path.splitext(os.path.basename(source or "circuit"))[0]
    s = re.sub(r"[^A-Za-z0-9_]", "_", s) or "circuit"
    return s if re.match(r"[A-Za-z_]", s) else f"c_{s}"


__all__ = ["Circuit", "CircuitOptions", "build_circuit"]
