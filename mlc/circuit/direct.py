"""Gate-to-gate connection (``CircuitOptions.direct``, ``mlc compile --direct``).

The paper lets "the output of one gate be directly connected to the input of another".
mlc does it in the short form docs/circuits.md section 3 derives: a net whose driver is a
gate and whose only consumer is one input pin of another gate (no fan-out, no output, no
inversion: a pin's inversion is in its lever) is joined by **one full connector unit**
(two half units, an even count: the signal passes unchanged), built straight up from the
driver's output pair, and the sink gate is placed on it: its input pair's two ends on the
unit's output pair's two ends (two universal joints, lo-lo and hi-hi), its core plane
normal to the unit's tangent, in the all-zero row's pose.  Why not the pure form (the
sink's input pair on the driver's output pair itself): the levers are 0.5 sigma wide slabs
that meet at their tips, and over every turn about the pair's axis and both end pairings
the two gates' slabs overlap (by up to 0.43 sigma; at best +0.006 sigma clear in a 2
degree window that moves with the row), measured by :func:`pure_clearance`.

Each of the unit's three junctions (driver lever / half unit, half unit / half unit, half
unit / sink lever) has a ball-joint pair, free to bend about the pair's axis, and gets a
stop (:func:`swing_stop`): a flat-bottom bond between a site on either side, on the lines
through the junction's joint along each side's tangent, free for bends up to
``DIRECT_FREE`` (``+ LEVER_TILT`` at the driver's lever, whose line tilts with it).  Those three stops are what holds the sink (with its other wires).

Units: sigma, k0, radians.
"""
from __future__ import annotations

import math

import numpy as np

from mlc.gates.connector import STOP_ARM, ConnectorGeometry, Pair, Parts, half_unit_parts, join
from mlc.geometry.rotation import matrix_to_quat, quat_to_matrix
from mlc.scene.model import Body, Bond

__all__ = ["DIRECT_FREE", "direct_nets", "moved_bodies", "place_on_pair", "place_direct", "pure_clearance", "swing_stop", "unit_parts"]

DIRECT_FREE = math.radians(10.0)   # each junction of a direct connection swings freely this far from built
LEVER_TILT = math.radians(15.0)    # ... plus this at the driver's lever: its line tilts with the lever (12.4 deg
                                   # between the states of a NAND's output, which the stop must not resist)


def direct_nets(netlist, consumers: dict, skip=()) -> dict:
    """{sink gate id: (driver gate id, pin)} of the nets made direct: driver a gate, exactly
    one consumer, a gate pin; each sink takes at most one (the first pin, a then b, whose
    driver qualifies); sinks in ``skip`` take none.  ``consumers``: wire -> [("pin", gid,
    pin) | ("out", ...)]."""
    out: dict = {}
    for g in netlist.gates:
        for pin, p in (("a", g.a), ("b", g.b)):
            if g.id in out or g.id in skip or p.src[0] != "gate":
                continue
            cons = consumers.get(p.src, [])
            if len(cons) == 1 and cons[0] == ("pin", g.id, pin):
                out[g.id] = (p.src[1], pin)
    return out


def crossed_direct(scene, direct: dict) -> set:
    """Sinks of the direct nets (``direct``: sink -> (driver, pin)) whose unit, sink or
    driver a slab of another element passes through in the built pose: the exact
    oriented-box test (:func:`mlc.verify.overlap.clearance`, joined hinge contact left out)."""
    from mlc.verify.overlap import clearance
    hit = set()
    for a, b, _ in clearance(scene).overlaps:
        for sid, (drv, _pin) in direct.items():
            mine = (f"d_{drv}_", f"{sid}_", f"{drv}_")
            if a.startswith(mine) != b.startswith(mine):
                hit.add(sid)
    return hit


def _frame(a, n) -> np.ndarray:
    a = np.asarray(a, float) / np.linalg.norm(a)
    n = np.asarray(n, float) - float(np.dot(n, a)) * a
    n /= np.linalg.norm(n)
    return np.column_stack([a, n, np.cross(a, n)])


def place_on_pair(inp: Pair, up_local, end: Pair, up_world) -> tuple[np.ndarray, np.ndarray]:
    """Rotation R and translation t that put a gate's input pair ``inp`` (its own frame;
    ``up_local``: the gate's core normal there) onto ``end`` (world), lo on lo, with the
    gate's core normal along ``up_world``.  World point = R p + t."""
    R = _frame(end.axis, up_world) @ _frame(inp.axis, up_local).T
    return R, end.centre - R @ inp.centre


def moved_bodies(gid: str, sc, pos, quat, R, t) -> tuple[list[Body], list[Bond]]:
    """The gate ``sc`` posed at ``pos``/``quat`` (its frame), renamed ``{gid}_{name}`` and
    moved by R, t (like :func:`mlc.circuit.build._gate_bodies`, with any rotation)."""
    bodies = [Body(f"{gid}_{b.name}", R @ np.asarray(p, float) + t, matrix_to_quat(R @ quat_to_matrix(q)),
                   b.boxes, dict(b.sites)) for b, p, q in zip(sc.bodies, pos, quat)]
    bonds = []
    for b in sc.bonds:
        ba, sa = b.a.split(".", 1)
        bb, sb = b.b.split(".", 1)
        bonds.append(Bond(f"{gid}_{b.name}", f"{gid}_{ba}.{sa}", f"{gid}_{bb}.{sb}", b.k, b.rest, b.tolerance,
                          b.kind, f"{gid}_{b.joint}" if b.joint else None))
    return bodies, bonds


def swing_stop(name: str, lower: Body, joint_lower: np.ndarray, t_lower, upper: Body, joint_upper: np.ndarray,
               t_upper, k: float, free: float = DIRECT_FREE) -> Bond:
    """A flat-bottom bond holding the bend of one junction within ``free`` (rad) of straight.

    Site ``direct_lo`` on ``lower``, STOP_ARM before its joint along its tangent ``t_lower``,
    and ``direct_hi`` on ``upper``, STOP_ARM beyond its joint along ``t_upper``: both on lines
    through the (one) joint of the pair, so they are 2 m cos(beta/2) apart for a bend beta,
    whatever the rhombi's opening and the levers' turn about those lines (as
    :func:`mlc.gates.connector.junction_stops`).  Free from 2 m cos(free/2) up; built
    straight (2 m).  Units: sigma, k0."""
    m = STOP_ARM
    tl = np.asarray(t_lower, float) / np.linalg.norm(t_lower)
    tu = np.asarray(t_upper, float) / np.linalg.norm(t_upper)
    pl = np.asarray(joint_lower, float) - m * tl
    pu = np.asarray(joint_upper, float) + m * tu
    lower.sites["direct_lo"] = lower.rotation().T @ (pl - lower.position)
    upper.sites["direct_hi"] = upper.rotation().T @ (pu - upper.position)
    d_stop, d_free = 2.0 * m * math.cos(0.5 * free), 2.0 * m + 0.5
    return Bond(name, f"{lower.name}.direct_lo", f"{upper.name}.direct_hi", k, 0.5 * (d_stop + d_free),
                0.5 * (d_free - d_stop), "bond", None)


def unit_parts(tag: str, tap: Pair, up, state: int, geo: ConnectorGeometry, lever_stop: float,
               terminal_post: float) -> tuple[Parts, Pair, Pair, Pair]:
    """The full unit of a direct connection: two half units straight along ``up`` from the
    driver's output pair ``tap`` (carrying ``state``), the first one's input posts stopping
    ``lever_stop`` short of the lever's joints, the second's output layer ``terminal_post``
    below the sink's lever plane.  Returns (parts, first's input pair, middle pair, end pair);
    the joints to the tap and the stop of the middle junction are included."""
    up = np.asarray(up, float) / np.linalg.norm(up)
    p0, in0, out0 = half_unit_parts(f"{tag}_0", tap.centre, tap.axis, up, state, geo, in_stop=lever_stop)
    p1, in1, out1 = half_unit_parts(f"{tag}_1", out0.centre, out0.axis, up, 1 - state, geo,
                                    out_post=terminal_post, out_stop=lever_stop)
    parts = Parts()
    parts.add(p0)
    parts.add(p1)
    parts.bonds += join(f"{tag}_j0", tap, in0, geo.k)
    parts.bonds += join(f"{tag}_j1", out0, in1, geo.k)
    return parts, in0, out0, out1


def pure_clearance(drv_type: str, drv_state: str, snk_type: str, snk_state: str, pin: str, signal: str = "expand",
                   step_deg: float = 15.0) -> list[tuple[int, float, float]]:
    """The pure direct form, measured: the sink's input pair ``pin`` put on the driver's
    output pair (lo-lo, sign +1, or lo-hi, -1), turned about that pair by phi; returns
    (sign, phi in degrees, smallest clearance between the two gates' slabs, sigma) for
    every phi on a ``step_deg`` grid.  Used for docs/circuits.md; not by the builder."""
    from mlc.circuit.build import _gate_bodies, _pair, _posed_gate
    from mlc.gates.connector import rotate
    from mlc.scene.model import Scene
    from mlc.verify.overlap import clearance
    sc, pos, quat = _posed_gate(drv_type, signal, drv_state)
    db, dbond = _gate_bodies("g1", sc, pos, quat, np.zeros(3))
    out = _pair({b.name: b for b in db}, "g1_out_lo.out", "g1_out_hi.out")
    sc2, pos2, quat2 = _posed_gate(snk_type, signal, snk_state)
    by2 = {f"g2_{b.name}": Body(b.name, np.asarray(p, float), np.asarray(q, float), b.boxes, dict(b.sites))
           for b, p, q in zip(sc2.bodies, pos2, quat2)}
    inp = _pair(by2, f"g2_{pin}_lo.in", f"g2_{pin}_hi.in")
    z = np.array([0.0, 0.0, 1.0])
    res = []
    for sign in (1, -1):
        ends = ("g1_out_lo.out", "g1_out_hi.out")[::sign]
        for phi in np.arange(-180.0, 180.0, step_deg):
            a = sign * out.axis
            end = Pair(*ends, out.centre, a, out.length)
            R, t = place_on_pair(inp, z, end, rotate(z - (z @ a) * a, a, math.radians(phi)))
            sb, sbond = moved_bodies("g2", sc2, pos2, quat2, R, t)
            bonds = dbond + sbond + [Bond("d_lo", ends[0], f"g2_{pin}_lo.in", 1.0, 0.0, 0.0, "universal", "d_lo"),
                                     Bond("d_hi", ends[1], f"g2_{pin}_hi.in", 1.0, 0.0, 0.0, "universal", "d_hi")]
            s = Scene(name="pure", bodies=db + sb, bonds=bonds, muscles=[], probes=[], inputs=[], outputs=[])
            res.append((sign, int(round(phi)), float(clearance(s).min_clearance)))
    return res


def place_direct(sid: str, drv: str, pin: str, sc, pos, quat, by_name: dict, state: int, geo: ConnectorGeometry,
                 lever_stop: float, drop: float) -> tuple[Parts, np.ndarray, np.ndarray]:
    """The direct connection from gate ``drv`` (already in ``by_name``) to input ``pin`` of
    gate ``sid`` (library scene ``sc`` posed at ``pos``/``quat``, its frame): the full unit
    straight up (+z) from the driver's output pair carrying ``state``, the sink on its end
    pair (lo-lo, hi-hi) with its core plane horizontal, and the three junction stops.
    The unit ends where a chain does (``drop``, sigma; :func:`mlc.circuit.build.end_site`):
    on the sink's input levers' ``in_end`` sites, ``drop`` under ``in`` on their pivot
    axis, its last layer :func:`mlc.circuit.build.end_post` below them (``drop`` 0: on
    ``in``).  Returns (parts: the unit's and the sink's bodies and bonds, R, t: the sink's
    frame)."""
    from mlc.circuit.build import _pair, end_post, end_site
    tap = _pair(by_name, f"{drv}_out_lo.out", f"{drv}_out_hi.out")
    z = np.array([0.0, 0.0, 1.0])
    up = z - float(z @ tap.axis) * tap.axis        # up, normal to the pair (a posed pair may tilt a little)
    up /= np.linalg.norm(up)
    tag = f"d_{drv}"
    parts, in0, mid, end = unit_parts(tag, tap, up, state, geo, lever_stop, end_post(drop))
    site = "in_end" if drop > 0.0 else "in"
    local = {b.name: Body(b.name, np.asarray(p, float), np.asarray(q, float), b.boxes, dict(b.sites))
             for b, p, q in zip(sc.bodies, pos, quat)}
    if drop > 0.0:                       # body-local: the same site and post in any frame
        for e in ("lo", "hi"):
            end_site(local[f"{pin}_{e}"], drop)
    inp = _pair(local, f"{pin}_lo.{site}", f"{pin}_hi.{site}")
    R, t = place_on_pair(inp, z, end, up)
    bodies, bonds = moved_bodies(sid, sc, pos, quat, R, t)
    if drop > 0.0:                       # the posed levers take the local ones' site and post
        for b in bodies:
            if b.name in (f"{sid}_{pin}_lo", f"{sid}_{pin}_hi"):
                src = local[b.name[len(sid) + 1:]]
                b.sites, b.boxes = dict(src.sites), list(src.boxes)
    parts.bodies += bodies
    parts.bonds += bonds
    names = {b.name: b for b in parts.bodies}
    for e in ("lo", "hi"):
        parts.bonds.append(Bond(f"{tag}_end_{e}", getattr(end, e), f"{sid}_{pin}_{e}.{site}", geo.k, 0.0, 0.0,
                                "universal", f"{tag}_end_{e}"))
    lever = by_name[tap.lo.split(".")[0]]
    body = lambda ref: names[ref.split(".")[0]]
    world = lambda ref: body(ref).world(ref.split(".")[1])
    parts.bonds.append(swing_stop(f"{tag}_s0", lever, lever.world(tap.lo.split(".")[1]),
                                  up, body(in0.lo), world(in0.lo), up, geo.k, DIRECT_FREE + LEVER_TILT))
    parts.bonds.append(swing_stop(f"{tag}_s1", body(mid.lo), world(mid.lo), up,
                                  body(f"{tag}_1_AB.A"), world(f"{tag}_1_AB.A"), up, geo.k))
    sink_lever = names[f"{sid}_{pin}_lo"]
    parts.bonds.append(swing_stop(f"{tag}_s2", body(end.lo), world(end.lo), up,
                                  sink_lever, sink_lever.world(site), up, geo.k))
    return parts, R, t
