"""Technology mapping: an AIG with free inversions -> a :class:`~mlc.netlist.ir.Netlist`
of library gates.

* Every AND node that an output depends on becomes one library gate.  The gate's type
  follows from the inversions on its two fanin edges and on its output.
* Output inversions.  The AIG asks for an inversion on an edge by complementing it.
  For an AND node ``v`` whose fanout edges are complemented, the inversion goes into
  ``v``'s output lever (``pout = 1``) when every consumer wants it inverted; otherwise
  ``pout = 0`` and the consumers that want it inverted get it in their input levers.
  When ``v`` drives primary outputs, ``pout`` follows the majority of those outputs
  (ties: the rule above), because an output has no lever of its own: an output whose
  edge complement differs from ``pout`` gets an inverting connector half unit (an
  exact NOT, :mod:`mlc.gates.connector`).  The
  same holds for an output that is a complemented primary input (``f = !a``).  Gate
  inputs never need a half unit: their levers absorb any inversion.
* Primary inputs are muscles of the chosen convention (``signal``: expand or contract);
  every wire uses that convention, and the lever types (open / crossed hinge) follow
  from the inversions and the convention (:func:`mlc.gates.library.lever_types`).
* A wire that feeds more than one gate input or output splits into that many connector
  branches.
* A constant output, or one that is a plain primary input, is reported as such.
"""
from __future__ import annotations

from mlc.errors import InternalError, MlcError
from mlc.netlist.ir import Gate, Input, Netlist, Output, Pin


def map_aig(aig, signal: str = "expand", source: str = "<input>") -> Netlist:
    """Map ``aig`` (an :class:`mlc.logic.aig.AIG`) onto library gates."""
    from mlc.gates.library import SIGNALS, lever_types, load_library

    if signal not in SIGNALS:
        raise MlcError(f"unknown signal convention {signal!r}", "--signal", "use expand or contract")
    aig.check()
    lib = load_library()
    by_pol = {tuple(d.polarity[k] for k in ("a", "b", "out")): name for name, d in lib.items()}
    n = aig.num_inputs
    first_and = n + 1

    # live AND nodes and, per node, the complement bits of its fanout edges
    live = [False] * aig.num_nodes
    stack = [x >> 1 for x in aig.output_lits]
    while stack:
        v = stack.pop()
        if v < first_and or live[v]:
            continue
        live[v] = True
        a, b = aig.fanins(v)
        stack += [a >> 1, b >> 1]
    gate_edges: dict[int, list[int]] = {}
    out_edges: dict[int, list[int]] = {}
    for v in range(first_and, aig.num_nodes):
        if live[v]:
            for x in aig.fanins(v):
                gate_edges.setdefault(x >> 1, []).append(x & 1)
    for x in aig.output_lits:
        out_edges.setdefault(x >> 1, []).append(x & 1)

    pout: dict[int, int] = {}
    for v in range(first_and, aig.num_nodes):
        if not live[v]:
            continue
        ge, oe = gate_edges.get(v, []), out_edges.get(v, [])
        rule = int(all(c for c in ge + oe))
        if oe:
            ones = sum(oe)
            pout[v] = 1 if 2 * ones > len(oe) else 0 if 2 * ones < len(oe) else rule
        else:
            pout[v] = rule

    ids: dict[int, str] = {}
    gates: list[Gate] = []
    depth: dict[int, int] = {i: 0 for i in range(1, first_and)}

    def src_of(v: int) -> tuple[str, str]:
        if 1 <= v <= n:
            return ("input", aig.inputs[v - 1])
        if v in ids:
            return ("gate", ids[v])
        raise InternalError(f"mapper: node {v} used before it is mapped")

    for v in range(first_and, aig.num_nodes):
        if not live[v]:
            continue
        a, b = aig.fanins(v)
        if a >> 1 == 0 or b >> 1 == 0:
            raise InternalError(f"mapper: AND node {v} has a constant fanin")
        pa = (a & 1) ^ pout.get(a >> 1, 0)
        pb = (b & 1) ^ pout.get(b >> 1, 0)
        po = pout[v]
        lev = lever_types(pa, pb, po, signal)
        gid = f"g{len(gates) + 1}"
        ids[v] = gid
        depth[v] = 1 + max(depth[a >> 1], depth[b >> 1])
        gates.append(Gate(gid, by_pol[(pa, pb, po)], Pin(src_of(a >> 1), a & 1, pa, lev["a"]),
                          Pin(src_of(b >> 1), b & 1, pb, lev["b"]), po, lev["out"], depth[v], aig_node=v))

    outputs: list[Output] = []
    for name, x in zip(aig.outputs, aig.output_lits):
        v = x >> 1
        if v == 0:
            outputs.append(Output(name, "const", None, x & 1))
            continue
        src = src_of(v)
        outputs.append(Output(name, src[0], src, None, x & 1, bool((x & 1) ^ pout.get(v, 0))))

    inputs = [Input(name) for name in aig.inputs]
    nl = Netlist(inputs, outputs, gates, signal, source)
    fo = nl.fanouts()
    for w in inputs:
        w.fanout = fo[("input", w.name)]
        w.branches = w.fanout if w.fanout > 1 else 0
    for g in gates:
        g.fanout = fo[("gate", g.id)]
        g.branches = g.fanout if g.fanout > 1 else 0
    nl.stats = nl.compute_stats()
    nl.check()
    return nl
