"""The order in which a circuit's bodies are solved: by logic depth.

:func:`body_levels` gives every body of a circuit scene (one written by
:mod:`mlc.circuit.build`) an integer level, used by the static solver's level-by-level
continuation (:func:`mlc.verify.static.equilibrium`, ``levels``):

* a gate's bodies (``{gate}_...``) take the gate's logic depth (``meta.gates[g].depth``);
* the other bodies (connector chains, branch pages, source half units) fall into pieces
  joined by bonds among themselves; a piece takes the smallest depth of the gates whose
  input levers (``{gate}_a_*``, ``{gate}_b_*``) it is bonded to, so that every gate is
  solved together with, or after, the wires that feed it.  A piece feeding no gate input
  takes the largest depth of the gates it touches, and a piece touching no gate (a constant
  output's bodies) the first level, 1.

Muscles do not join pieces (they are the inputs).
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from mlc.scene.model import Scene

INPUT_LEVERS = ("a_lo", "a_hi", "b_lo", "b_hi")


def body_levels(scene: Scene, arrays=None) -> np.ndarray | None:
    """Level of every body (int array in body order), or None when ``scene`` is not a
    circuit (no ``meta.gates`` with depths).  ``arrays``: ``scene.arrays()`` when the caller
    has it already."""
    gates = scene.meta.get("gates") if isinstance(scene.meta, dict) else None
    if not gates or any("depth" not in g for g in gates.values()):
        return None
    A = scene.arrays() if arrays is None else arrays
    N = len(A.pos)
    depth = np.full(N, -1, dtype=np.int64)            # the gate's depth for gate bodies
    is_input = np.zeros(N, dtype=bool)
    for b, body in enumerate(scene.bodies):
        g, _, part = body.name.partition("_")
        if g in gates:
            depth[b] = int(gates[g]["depth"])
            is_input[b] = part in INPUT_LEVERS
    bi, bj = A.site_body[A.bond_i], A.site_body[A.bond_j]
    wire = depth < 0
    both = wire[bi] & wire[bj]
    graph = sp.coo_matrix((np.ones(int(both.sum())), (bi[both], bj[both])), shape=(N, N))
    _, piece = connected_components(graph, directed=False)
    big = np.iinfo(np.int64).max
    sink = np.full(N, big, dtype=np.int64)            # per piece: smallest depth of a gate input it feeds
    touch = np.full(N, -1, dtype=np.int64)            # per piece: largest depth of any gate it touches
    for w, g in ((bi, bj), (bj, bi)):
        m = wire[w] & ~wire[g]
        np.minimum.at(sink, piece[w[m & is_input[g]]], depth[g[m & is_input[g]]])
        np.maximum.at(touch, piece[w[m]], depth[g[m]])
    lev = np.where(sink < big, sink, np.maximum(touch, 1))
    return np.where(wire, lev[piece], depth)
