"""Connector half unit (paper Fig. 5A): four slabs hinged into a rhombus.

The input signal drives one diagonal of the rhombus and the output is the other,
perpendicular, diagonal.  With side ``s`` and diagonals ``p`` (input) and ``q``
(output), the right triangle formed by half of each diagonal and one side gives

    (p/2)**2 + (q/2)**2 = s**2,   so   q = sqrt(4 s**2 - p**2),

which falls as ``p`` grows: the half unit turns an expansion into a contraction
and rotates the signal axis by 90 degrees, as the paper says.  Choosing

    4 s**2 = L0**2 + L1**2

(``L0`` = the wire's length in state 0, ``L1`` = in state 1) makes it map L0 to L1
and L1 to L0 *exactly*: it is a logical NOT between two wires of the same
convention, with the library's compatible rest length on both sides.
Expanding wires (L0 = 1, L1 = 1.5 sigma) give s = 0.901 sigma; contracting ones
(L0 = 1, L1 = 0.5 sigma) give s = 0.559 sigma.  Two half units in a row (the paper's
full connector unit) map every state to itself.  This is what makes the mapper's
"inversion on a wire goes into a connector half unit" physical
(:mod:`mlc.netlist.mapper`); see docs/gates.md, "Connector half unit".

Units: sigma (length), k0 (stiffness).
"""
from __future__ import annotations

import math

import numpy as np

from mlc.gates.library import SIGNALS, Design, _body, _check_signal, load_design
from mlc.gates.parts import axis_sites, hinge
from mlc.scene.model import Muscle, Probe, Scene

_EZ = np.array([0.0, 0.0, 1.0])


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


def half_unit_scene(signal: str = "expand", design: Design | None = None) -> Scene:
    """A half unit as a scene, posed at rest: a muscle of ``signal`` convention across
    the input diagonal A-C (along x), the output probe across B-D (along y); four
    slabs AB, BC, CD, DA with hinges along z at the corners.  Truth table: NOT."""
    d = design or load_design()
    L0, L1 = wire_lengths(signal, d)
    w = d.slab_width
    P = {"A": np.array([-0.5 * L0, 0.0, 0.0]), "C": np.array([0.5 * L0, 0.0, 0.0]),
         "B": np.array([0.0, 0.5 * L1, 0.0]), "D": np.array([0.0, -0.5 * L1, 0.0])}
    bodies, bonds = [], []
    for u, v in (("A", "B"), ("B", "C"), ("C", "D"), ("D", "A")):
        sites = {**axis_sites(u, P[u], _EZ, w), **axis_sites(v, P[v], _EZ, w), u: P[u], v: P[v]}
        bodies.append(_body(f"slab_{u}{v}", [(P[u], P[v])], sites, _EZ, d))
    for c, (b1, b2) in {"A": ("DA", "AB"), "B": ("AB", "BC"), "C": ("BC", "CD"),
                        "D": ("CD", "DA")}.items():
        bonds += hinge(f"hinge_{c}", f"slab_{b1}", f"slab_{b2}", c, c, d.k)
    muscles = [Muscle("muscle_in", "a", "slab_AB.A", "slab_BC.C", L0, L1, d.k)]
    probes = [Probe("out", "out", "slab_AB.B", "slab_CD.D", L0, L1)]
    scene = Scene(name=f"half_unit_{signal}", bodies=bodies, bonds=bonds, muscles=muscles,
                  probes=probes, inputs=["a"], outputs=["out"], truth_table={"0": "1", "1": "0"},
                  meta={"element": "connector_half_unit", "signal": signal,
                        "side": round(half_unit_side(signal, d), 6)})
    return scene.check()


__all__ = ["SIGNALS", "half_unit_out", "half_unit_scene", "half_unit_side", "wire_lengths"]
