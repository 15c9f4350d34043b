"""Chains that would touch in an input row other than the one they are built in (sigma).

The router keeps chains apart by their layers' centres, each layer bounded by a sphere of
``LAYER_RADIUS`` (:class:`mlc.circuit.lanes.Space`), in the pose they are built in: the
all-zero input row.  Two chains whose layer centres are closer than two such radii are
*tight*; they may still be clear, since a layer is a flat rhombus, not a ball.  But a
layer's rhombus changes when its wire switches: its input diagonal is the wire's length in
one state and its output diagonal the length in the other
(:func:`mlc.gates.connector.half_unit_parts`), so the long diagonal turns by 90 degrees
about the chain.  Two tight layers that clear each other as built can interpenetrate in a
row where either wire has switched.  Measured: the 5-bit ripple-carry adder's chains
``w_a2_1`` and ``w_b2_1`` (layers 45 and 38, centres 1.357 sigma apart) are clear as built
and interpenetrate by 0.065 sigma in row 1111111111 (static equilibrium,
``mlc verify``), while their centres move by less than 0.001 sigma.

:func:`state_contacts` tests every pair of layers of different chains whose centres are
within ``radius`` with the exact box clearance of :mod:`mlc.verify.overlap`, each layer a
rigid rhombus (its four slabs and their posts) where it is built, in both states of each
wire (two chains of one wire switch together, so they have two combinations, not four).
What it leaves out is how far the layers move from where they are built when the circuit
relaxes in a row: hence ``margin`` in the builder (``build.CONTACT_MARGIN``).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Contact:
    """Two layers of different chains and their smallest clearance over the wires' states
    (sigma; negative: interpenetration depth), and the flips (0: the state as built, 1:
    switched) of chain ``a``'s and chain ``b``'s wire where it is smallest."""

    clearance: float
    a: str
    i: int
    b: str
    j: int
    flips: tuple


def layer_boxes(bodies, tag: str) -> dict:
    """World boxes of a chain's bodies grouped by half unit: ``{i: (C (k,3), A (k,3,3),
    H (k,3))}`` for the bodies named ``{tag}_{i}_...`` (sigma; ``A``'s columns are the box
    axes, ``H`` the half extents)."""
    from mlc.geometry.rotation import quat_to_matrix
    out: dict = {}
    pre = f"{tag}_"
    for b in bodies:
        if not b.name.startswith(pre):
            continue
        head = b.name[len(pre):].split("_", 1)[0]
        if not head.isdigit():
            continue
        R = b.rotation()
        C, A, H = out.setdefault(int(head), ([], [], []))
        for box in b.boxes:
            C.append(b.position + R @ np.asarray(box.center, float))
            A.append(R @ quat_to_matrix(np.asarray(box.orientation, float)))
            H.append(0.5 * np.asarray(box.size, float))
    return {i: (np.array(C), np.array(A), np.array(H)) for i, (C, A, H) in out.items()}


def candidate_pairs(centres: dict, radius: float) -> list:
    """``(a, i, b, j)`` for every layer ``i`` of chain ``a`` and ``j`` of another chain ``b``
    whose centres (``centres[tag]`` (n,3)) are closer than ``radius``; ``a < b``."""
    from scipy.spatial import cKDTree
    tags = sorted(centres)
    if not tags:
        return []
    owner = np.concatenate([np.full(len(centres[t]), k) for k, t in enumerate(tags)])
    index = np.concatenate([np.arange(len(centres[t])) for t in tags])
    pts = np.concatenate([np.asarray(centres[t], float).reshape(-1, 3) for t in tags])
    out = []
    for p, q in sorted(cKDTree(pts).query_pairs(radius)):
        if owner[p] == owner[q]:
            continue
        if owner[p] > owner[q]:
            p, q = q, p
        out.append((tags[owner[p]], int(index[p]), tags[owner[q]], int(index[q])))
    return out


def state_contacts(pairs: list, boxes, wire_of: dict) -> list:
    """The clearance of every candidate pair (:func:`candidate_pairs`) over the states of
    its two wires: ``boxes(tag, flip)`` gives :func:`layer_boxes` of chain ``tag`` with its
    wire as built (flip 0) or switched (1); ``wire_of[tag]`` names its wire.  Returns one
    :class:`Contact` per pair, smallest clearance first (sigma)."""
    from mlc.verify.overlap import box_clearance
    best: dict = {}
    for a, i, b, j in pairs:
        combos = ((0, 0), (1, 1)) if wire_of[a] == wire_of[b] else ((0, 0), (0, 1), (1, 0), (1, 1))
        for fa, fb in combos:
            la, lb = boxes(a, fa).get(i), boxes(b, fb).get(j)
            if la is None or lb is None:
                continue
            na, nb = len(la[0]), len(lb[0])
            ia, ib = np.repeat(np.arange(na), nb), np.tile(np.arange(nb), na)
            c = float(box_clearance(la[0][ia], la[1][ia], la[2][ia], lb[0][ib], lb[1][ib], lb[2][ib]).min())
            key = (a, i, b, j)
            if key not in best or c < best[key].clearance:
                best[key] = Contact(c, a, i, b, j, (fa, fb))
    return sorted(best.values(), key=lambda k: (k.clearance, k.a, k.i, k.b, k.j))


__all__ = ["Contact", "candidate_pairs", "layer_boxes", "state_contacts"]
