"""Scene builders a sweep can name (``scene:`` in a sweep spec), with their parameters.

Every builder takes keyword parameters from the spec's grid and returns a
:class:`~mlc.scene.model.Scene` plus the names of the inputs the sweep drives.
Units: sigma (length), k0 (stiffness), radians.

* ``and_chain_and`` (paper Fig. 5B-C): an AND gate whose two muscles are both input
  ``in``; its output pair carries a straight connector chain of ``units`` full units up
  (+z) to the input lever ``a`` of a second AND gate (that lever's muscle removed, the
  chain drives it); the second gate's input ``b`` is the input ``hold``.  Probes:
  ``out`` (the second gate's output, what Fig. 5C plots), ``chain`` (the chain's far
  end) and ``gate1`` (the first gate's output).  ``tolerance`` loosens every joint.
* ``gate_chain`` (paper Fig. 5D): an AND gate (``gate`` may name another library gate)
  with both inputs on input ``in``; a straight chain of ``units`` full units on its
  output; probes ``u0`` (the gate's output) and ``u1 .. u{units}`` (after each unit).
  Built in the state ``state`` (0 or 1: gate and chain posed in that row, so a constant
  drive of that value starts at equilibrium).  ``tolerance`` (sigma) loosens **every**
  joint of the scene, gate included, as in the paper.
* ``chain``: :func:`mlc.gates.connector.chain_scene` (input ``a``), probes after every unit.
* ``gate``: a library gate (:func:`mlc.gates.library.gate_scene`), inputs ``a``, ``b``.
"""
from __future__ import annotations

import numpy as np

from mlc.gates.connector import Pair, Parts, connector_geometry, half_unit_parts, join
from mlc.scene.model import Body, Bond, Muscle, Probe, Scene

_EZ = np.array([0.0, 0.0, 1.0])
TERMINAL_POST = 0.6     # sigma: the last layer of a chain stays this far below the lever plane it drives


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


def _placed(prefix: str, sc: Scene, pos, quat, R=None, T=None):
    """The gate's bodies/bonds/muscles renamed ``{prefix}_...``, turned by ``R`` and moved by ``T``."""
    from mlc.geometry.rotation import matrix_to_quat, quat_to_matrix
    R = np.eye(3) if R is None else R
    T = np.zeros(3) if T is None else T
    bodies = [Body(f"{prefix}_{b.name}", R @ np.asarray(p, float) + T, matrix_to_quat(R @ quat_to_matrix(q)),
                   b.boxes, dict(b.sites)) for b, p, q in zip(sc.bodies, pos, quat)]

    def ref(s):
        body, site = s.split(".", 1)
        return f"{prefix}_{body}.{site}"
    bonds = [Bond(f"{prefix}_{b.name}", ref(b.a), ref(b.b), b.k, b.rest, b.tolerance, b.kind,
                  f"{prefix}_{b.joint}" if b.joint else None) for b in sc.bonds]
    muscles = [Muscle(f"{prefix}_{m.name}", m.input, ref(m.a), ref(m.b), m.rest, m.actuated, m.k)
               for m in sc.muscles]
    return bodies, bonds, muscles


def _pair(bodies: list[Body], lo: str, hi: str) -> Pair:
    by = {b.name: b for b in bodies}
    p = by[lo.split(".")[0]].world(lo.split(".", 1)[1])
    q = by[hi.split(".")[0]].world(hi.split(".", 1)[1])
    L = float(np.linalg.norm(q - p))
    return Pair(lo, hi, 0.5 * (p + q), (q - p) / L, L)


def _straight_chain(prefix: str, start: Pair, tangent, n_half: int, state: int, geo, last_post: float | None = None):
    """``n_half`` half units in a straight line along ``tangent`` from pair ``start`` (which
    carries ``state``), joined to it and to each other; the last one's output post may be
    longer (``last_post``).  Returns (parts, pairs after each half unit)."""
    parts, pairs = Parts(), []
    cur = start
    t = np.asarray(tangent, float)
    t = t - float(t @ cur.axis) * cur.axis          # perpendicular to the first pair's axis
    t /= np.linalg.norm(t)
    for i in range(n_half):
        p, pin, pout = half_unit_parts(f"{prefix}_{i}", cur.centre, cur.axis, t, (state + i) % 2, geo,
                                       out_post=last_post if (i == n_half - 1 and last_post) else None)
        parts.add(p)
        parts.bonds += join(f"{prefix}_j{i}", cur, pin, geo.k)
        pairs.append(pout)
        cur = pout
    return parts, pairs


def and_chain_and(units: int = 5, signal: str = "expand", tolerance: float = 0.0, gate: str = "AND",
                  gap: float = 0.5, hold_state: int = 1) -> Scene:
    """Paper Fig. 5B: gate -> ``units``-unit chain -> the second gate's input ``a`` (see module doc).
    The scene is posed with ``in`` = 0 and ``hold`` = ``hold_state``."""
    geo = connector_geometry(signal, gap=gap)
    sc1, pos1, quat1 = _posed_gate(gate, signal, "00")
    b1, bd1, m1 = _placed("g1", sc1, pos1, quat1)
    for m in m1:
        m.input = "in"
    tap = _pair(b1, "g1_out_lo.out", "g1_out_hi.out")
    ext = TERMINAL_POST - 0.5 * geo.gap
    cparts, pairs = _straight_chain("c", tap, _EZ, 2 * units, 0, geo, last_post=0.5 * geo.gap + ext)
    end = pairs[-1]
    sc2, pos2, quat2 = _posed_gate(gate, signal, f"0{int(hold_state)}")
    b2, bd2, m2 = _placed("g2", sc2, pos2, quat2)
    tgt = _pair(b2, "g2_a_lo.in", "g2_a_hi.in")
    # turn gate 2 about z so that its input pair's axis is the chain end's axis (both are
    # horizontal), then move it onto the chain's end: the chain arrives from below (+z)
    a, u = tgt.axis.copy(), end.axis.copy()
    a[2] = u[2] = 0.0
    a /= np.linalg.norm(a)
    u /= np.linalg.norm(u)
    c, s = float(a @ u), float(np.cross(a, u)[2])
    R = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    T = end.centre - R @ tgt.centre
    b2, bd2, m2 = _placed("g2", sc2, pos2, quat2, R, T)
    m2 = [m for m in m2 if m.input != "a"]
    for m in m2:
        m.input = "hold"
    bodies = b1 + cparts.bodies + b2
    bonds = bd1 + cparts.bonds + bd2
    bonds.append(Bond("c_end_lo", end.lo, "g2_a_lo.in", geo.k, 0.0, 0.0, "universal", "c_end_lo"))
    bonds.append(Bond("c_end_hi", end.hi, "g2_a_hi.in", geo.k, 0.0, 0.0, "universal", "c_end_hi"))
    if tolerance:
        for b in bonds:
            b.tolerance = float(tolerance)
    probes = [Probe("out", "out", "g2_out_lo.out", "g2_out_hi.out", geo.L0, geo.L1),
              Probe("chain", "chain", end.lo, end.hi, geo.L0, geo.L1),
              Probe("gate1", "gate1", "g1_out_lo.out", "g1_out_hi.out", geo.L0, geo.L1)]
    from mlc.gates.library import get_gate
    gd = get_gate(gate)
    tt = {}
    for i in (0, 1):
        for h in (0, 1):
            o1 = gd.evaluate(i, i)
            tt[f"{i}{h}"] = f"{gd.evaluate(o1, h)}{o1}{o1}"
    scene = Scene(name=f"and_chain{units}_and_{signal}", bodies=bodies, bonds=bonds, muscles=m1 + m2,
                  probes=probes, inputs=["in", "hold"], outputs=["out", "chain", "gate1"], truth_table=tt,
                  meta={"element": "sweep_and_chain_and", "units": units, "signal": signal, "gate": gate,
                        "tolerance": tolerance, "gap": gap})
    return scene.check()


def gate_chain(units: int = 10, signal: str = "expand", tolerance: float = 0.0, gate: str = "AND",
               gap: float = 0.5, state: int = 1) -> Scene:
    """Paper Fig. 5D: a gate with both muscles on input ``in`` and a ``units``-unit chain on
    its output, probed after every unit (see module doc); posed in row ``state``."""
    geo = connector_geometry(signal, gap=gap)
    st = f"{int(state)}{int(state)}"
    sc, pos, quat = _posed_gate(gate, signal, st)
    b1, bd1, m1 = _placed("g", sc, pos, quat)
    for m in m1:
        m.input = "in"
    tap = _pair(b1, "g_out_lo.out", "g_out_hi.out")
    from mlc.gates.library import get_gate
    out_bit = get_gate(gate).evaluate(int(state), int(state))
    cparts, pairs = _straight_chain("c", tap, _EZ, 2 * units, out_bit, geo)
    bonds = bd1 + cparts.bonds
    if tolerance:
        for b in bonds:
            b.tolerance = float(tolerance)
    probes = [Probe("u0", "u0", tap.lo, tap.hi, geo.L0, geo.L1)]
    probes += [Probe(f"u{k}", f"u{k}", pairs[2 * k - 1].lo, pairs[2 * k - 1].hi, geo.L0, geo.L1)
               for k in range(1, units + 1)]
    outs = [p.name for p in probes]
    tt = {"0": str(get_gate(gate).evaluate(0, 0)) * len(outs), "1": str(get_gate(gate).evaluate(1, 1)) * len(outs)}
    scene = Scene(name=f"{gate.lower()}_chain{units}_{signal}", bodies=b1 + cparts.bodies, bonds=bonds, muscles=m1,
                  probes=probes, inputs=["in"], outputs=outs, truth_table=tt,
                  meta={"element": "sweep_gate_chain", "units": units, "signal": signal, "gate": gate,
                        "tolerance": tolerance, "gap": gap, "state": int(state)})
    return scene.check()


def chain(units: int = 5, signal: str = "expand", tolerance: float = 0.0, bend: float = 0.0,
          gap: float = 0.5) -> Scene:
    from mlc.gates.connector import chain_scene
    return chain_scene(units, signal, bend, tolerance=tolerance, gap=gap, probe_every_unit=True)


def gate(gate: str = "AND", signal: str = "expand", tolerance: float = 0.0) -> Scene:
    from mlc.gates.library import gate_scene
    sc = gate_scene(gate, signal)
    if tolerance:
        for b in sc.bonds:
            b.tolerance = float(tolerance)
    return sc


#: builder name -> (function, its parameters with their defaults)
BUILDERS = {
    "and_chain_and": (and_chain_and, {"units": 5, "signal": "expand", "tolerance": 0.0, "gate": "AND", "gap": 0.5,
                                      "hold_state": 1}),
    "gate_chain": (gate_chain, {"units": 10, "signal": "expand", "tolerance": 0.0, "gate": "AND", "gap": 0.5,
                                "state": 1}),
    "chain": (chain, {"units": 5, "signal": "expand", "tolerance": 0.0, "bend": 0.0, "gap": 0.5}),
    "gate": (gate, {"gate": "AND", "signal": "expand", "tolerance": 0.0}),
}
