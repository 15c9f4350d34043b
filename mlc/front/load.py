"""Reading a specification: dispatch by file extension (or ``-e EXPR``), plus the
helpers every parser shares.

* :func:`load` -- ``path`` or ``expr`` -> :class:`~mlc.spec.TableSpec` or
  :class:`~mlc.spec.NetworkSpec`.
* :func:`finish_network` -- put a parsed network into the canonical shape every
  consumer may rely on (input nodes first, in ``inputs`` order; then the other
  nodes in topological order) and check it.
* :func:`check_spec` -- the invariants of both spec forms (raises InternalError).
* :func:`truth_tables` -- exhaustive simulation of a spec: per output (on, dc) bit sets.
* :func:`var_mask` -- the bit set of the minterms in which input ``i`` is 1.

Extensions: ``.tt`` (mlc truth table), ``.pla`` (Berkeley PLA), ``.expr`` / ``.eqn``
(Boolean expressions), ``.blif`` (BLIF, combinational), ``.aag`` and ``.aig`` (AIGER,
ASCII or binary: the parser tells them apart by the header, so a misnamed one still
reads; a file with another extension whose first bytes are ``aag `` or ``aig `` is
read as AIGER too).
"""
from __future__ import annotations

from functools import lru_cache
from pathlib import Path

from mlc.errors import InternalError, MlcError
from mlc.spec import OPS, Node, NetworkSpec, Spec, TableSpec

# Largest number of inputs a truth table (or exhaustive simulation) may have:
# bit sets of 2**24 bits are 2 MiB each.
MAX_TABLE_INPUTS = 24

EXTENSIONS = {
    ".tt": "tt", ".pla": "pla", ".expr": "expr", ".eqn": "expr",
    ".blif": "blif", ".aag": "aiger", ".aig": "aiger",
}
AIGER_MAGIC = (b"aag ", b"aig ")


def parser_for(name: str):
    import importlib
    return importlib.import_module(f"mlc.front.{name}")


def parse_text(text: str | bytes, filename: str, fmt: str, strict: bool = False) -> Spec:
    """Parse ``text`` in format ``fmt`` (a value of :data:`EXTENSIONS`); ``aiger`` also
    takes ``bytes`` (binary AIGER)."""
    mod = parser_for(fmt)
    if fmt == "tt":
        return mod.parse(text, filename, strict=strict)
    return mod.parse(text, filename)


def load(path: str | None = None, expr: str | None = None, strict: bool = False) -> Spec:
    """Read a specification from ``path`` (format chosen by extension) or from the
    expression text ``expr`` (the ``-e`` option).  Exactly one must be given."""
    if path is not None and expr is not None:
        raise MlcError("give either an input file or -e EXPR, not both", "-e")
    if path is None and expr is None:
        raise MlcError("no input: give an input file or -e EXPR", "INPUT",
                       "for example: mlc compile examples/tetris.tt")
    if expr is not None:
        return parse_text(expr, "<-e>", "expr", strict)
    p = Path(path)
    fmt = EXTENSIONS.get(p.suffix.lower())
    if fmt is None and not (p.is_file() and _starts_with(p, AIGER_MAGIC)):
        known = ", ".join(sorted(EXTENSIONS))
        raise MlcError(f"unknown input format {p.suffix or '(no extension)'!r}", str(p),
                       f"use one of {known}, or -e EXPR")
    try:
        if fmt in (None, "aiger"):
            text = p.read_bytes()           # AIGER may be binary; the parser reads the header
            fmt = "aiger"
        else:
            text = p.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise MlcError("no such file", str(p)) from None
    except IsADirectoryError:
        raise MlcError("is a directory, not an input file", str(p)) from None
    except UnicodeDecodeError as e:
        raise MlcError(f"not UTF-8 text ({e.reason} at byte {e.start})", str(p)) from None
    except OSError as e:
        raise MlcError(f"cannot read: {e.strerror}", str(p)) from None
    return parse_text(text, str(path), fmt, strict)


def _starts_with(p: Path, prefixes: tuple[bytes, ...]) -> bool:
    try:
        with p.open("rb") as f:
            head = f.read(max(len(x) for x in prefixes))
    except OSError:
        return False
    return head.startswith(prefixes)


# --------------------------------------------------------------------------- bit sets

@lru_cache(maxsize=256)
def var_mask(n: int, i: int) -> int:
    """Bit set over the ``2**n`` minterms: bit ``m`` is set iff ``(m >> i) & 1``."""
    if not 0 <= i < n:
        raise InternalError(f"var_mask: input {i} out of range for {n} inputs")
    period = 1 << (i + 1)
    block = ((1 << (1 << i)) - 1) << (1 << i)          # the upper half of one period
    count = (1 << n) // period
    repunit = ((1 << (period * count)) - 1) // ((1 << period) - 1)
    return block * repunit


def full_mask(n: int) -> int:
    return (1 << (1 << n)) - 1


def cube_mask(n: int, cube: str) -> int:
    """Bit set of the minterms matched by ``cube`` ('0', '1', '-' per input, input 0 first)."""
    m = full_mask(n)
    for i, ch in enumerate(cube):
        if ch == "1":
            m &= var_mask(n, i)
        elif ch == "0":
            m &= ~var_mask(n, i)
    return m


def lowest_minterm(bits: int) -> int:
    return (bits & -bits).bit_length() - 1


def minterm_str(spec_inputs: list[str], m: int) -> str:
    return " ".join(f"{name}={(m >> i) & 1}" for i, name in enumerate(spec_inputs))


# --------------------------------------------------------------------------- networks

def postorder(nodes: list[Node], roots, on_cycle=None, follow=None) -> list[int]:
    """Iterative depth-first post-order of the nodes reachable from ``roots`` (each
    node once, arguments before the node).  ``follow(a)`` limits which arguments are
    entered (default: all).  A cycle calls ``on_cycle(path)`` with the nodes of the
    cycle, ending where it started; the callback must raise."""
    state = [0] * len(nodes)                 # 0 new, 1 on the current path, 2 done
    out: list[int] = []
    for root in roots:
        if state[root]:
            continue
        stack = [(root, 0)]
        path = [root]
        state[root] = 1
        while stack:
            k, j = stack[-1]
            args = nodes[k].args
            if j < len(args):
                stack[-1] = (k, j + 1)
                a = args[j]
                if follow is not None and not follow(a):
                    continue
                if state[a] == 1 and on_cycle is not None:
                    on_cycle(path[path.index(a):] + [a])
                if state[a] == 0:
                    state[a] = 1
                    stack.append((a, 0))
                    path.append(a)
            else:
                stack.pop()
                path.pop()
                state[k] = 2
                out.append(k)
    return out


def _internal_cycle(path):
    raise InternalError(f"network has a cycle through node {path[0]}")


def finish_network(inputs: list[str], outputs: list[str], nodes: list[Node], output_nodes: list[int],
                   source: str, output_locs, dc=None) -> NetworkSpec:
    """Renumber a parsed network into canonical order and check it.

    ``nodes`` must already be acyclic with every argument index valid; input nodes
    (``op == "input"``, ``name`` = the input's name) may be anywhere.  The result has
    the input nodes first, in ``inputs`` order, and the other nodes in a topological
    order that keeps their relative order whenever that order is already topological;
    nodes that no output depends on are dropped.
    """
    by_name = {}
    for k, nd in enumerate(nodes):
        if nd.op == "input":
            by_name[nd.name] = k
    missing = [x for x in inputs if x not in by_name]
    for x in missing:
        by_name[x] = len(nodes)
        nodes.append(Node("input", (), x))
    # live nodes: reachable from outputs
    order = [k for k in postorder(nodes, output_nodes, _internal_cycle) if nodes[k].op != "input"]
    order.sort()          # keep the parser's order where it is already topological
    order = _stable_topo(nodes, order)
    new_index = {}
    out_nodes: list[Node] = []
    for name in inputs:
        new_index[by_name[name]] = len(out_nodes)
        old = nodes[by_name[name]]
        out_nodes.append(Node("input", (), name, old.loc))
    for k in order:
        nd = nodes[k]
        new_index[k] = len(out_nodes)
        out_nodes.append(Node(nd.op, tuple(new_index[a] for a in nd.args), nd.name, nd.loc,
                              list(nd.cover) if nd.cover is not None else None))
    spec = NetworkSpec(list(inputs), list(outputs), out_nodes, [new_index[k] for k in output_nodes],
                       source, list(output_locs), dc)
    check_spec(spec)
    return spec


def _stable_topo(nodes: list[Node], order: list[int]) -> list[int]:
    """Topological order of ``order`` (which lists non-input nodes only), as close to the given order as possible."""
    pos = {k: i for i, k in enumerate(order)}
    if all(all(nodes[a].op == "input" or pos[a] < pos[k] for a in nodes[k].args) for k in order):
        return order
    return postorder(nodes, order, follow=lambda a: a in pos)


def check_spec(spec: Spec) -> None:
    """Raise InternalError unless ``spec`` satisfies the invariants of its form."""
    if len(set(spec.inputs)) != len(spec.inputs):
        raise InternalError("duplicate input names")
    if len(set(spec.outputs)) != len(spec.outputs):
        raise InternalError("duplicate output names")
    if spec.output_locs and len(spec.output_locs) != len(spec.outputs):
        raise InternalError("output_locs does not match outputs")
    if isinstance(spec, TableSpec):
        if len(spec.on) != len(spec.outputs) or len(spec.dc) != len(spec.outputs):
            raise InternalError("on/dc length does not match outputs")
        full = full_mask(spec.n)
        for o, (on, dc) in enumerate(zip(spec.on, spec.dc)):
            if on & dc or on < 0 or dc < 0 or on > full or dc > full:
                raise InternalError(f"output {spec.outputs[o]}: on/dc bit sets invalid")
        return
    n = len(spec.inputs)
    for k, nd in enumerate(spec.nodes):
        if nd.op not in OPS:
            raise InternalError(f"node {k}: unknown op {nd.op!r}")
        if k < n:
            if nd.op != "input" or nd.name != spec.inputs[k]:
                raise InternalError(f"node {k} should be input {spec.inputs[k]}")
            continue
        if nd.op == "input":
            raise InternalError(f"node {k}: input node after the first {n} nodes")
        arity = OPS[nd.op]
        if arity is None and len(nd.args) < 1 or arity is not None and len(nd.args) != arity:
            raise InternalError(f"node {k}: {nd.op} with {len(nd.args)} arguments")
        if nd.op == "maj" and len(nd.args) % 2 == 0:
            raise InternalError(f"node {k}: maj with an even number of arguments")
        if any(not 0 <= a < k for a in nd.args):
            raise InternalError(f"node {k}: argument not an earlier node")
        if nd.op == "sop":
            if nd.cover is None:
                raise InternalError(f"node {k}: sop without cover")
            bits = {b for _, b in nd.cover}
            if len(bits) > 1 or any(len(c) != len(nd.args) or set(c) - set("01-") for c, _ in nd.cover):
                raise InternalError(f"node {k}: malformed cover")
    if len(spec.output_nodes) != len(spec.outputs):
        raise InternalError("output_nodes does not match outputs")
    if any(not 0 <= k < len(spec.nodes) for k in spec.output_nodes):
        raise InternalError("output node index out of range")
    if spec.dc is not None and len(spec.dc) != len(spec.outputs):
        raise InternalError("dc does not match outputs")


def node_table(op: str, arity: int, cover=None) -> int:
    """Truth table (minterm bit set) of one operator over ``arity`` arguments."""
    from mlc.logic.netsim import simulate_network
    args = [f"x{i}" for i in range(arity)]
    nodes = [Node("input", name=x) for x in args] + [Node(op, tuple(range(arity)), cover=cover)]
    net = NetworkSpec(args, ["f"], nodes, [arity])
    return simulate_network(net, [var_mask(arity, i) for i in range(arity)], 1 << arity)[0]


def truth_tables(spec: Spec) -> tuple[list[int], list[int]]:
    """Exhaustively simulate ``spec``: per output, (on-set, dc-set) bit sets."""
    if isinstance(spec, TableSpec):
        return list(spec.on), list(spec.dc)
    n = len(spec.inputs)
    if n > MAX_TABLE_INPUTS:
        raise MlcError(f"{n} inputs is too many for exhaustive simulation (at most {MAX_TABLE_INPUTS})",
                       spec.source)
    from mlc.logic.equiv import spec_tables
    return spec_tables(spec)


def spec_text(spec: Spec) -> str:
    """A stable text dump of a spec (golden tests)."""
    lines = [f"{type(spec).__name__} source={spec.source}",
             "inputs " + " ".join(spec.inputs), "outputs " + " ".join(spec.outputs)]
    if isinstance(spec, TableSpec):
        for name, on, dc, loc in zip(spec.outputs, spec.on, spec.dc, spec.output_locs or [None] * len(spec.outputs)):
            lines.append(f"output {name} on={on:#x} dc={dc:#x} at {loc}")
        return "\n".join(lines) + "\n"
    for k, nd in enumerate(spec.nodes):
        s = f"n{k} = {nd.op}(" + ", ".join(f"n{a}" for a in nd.args) + ")"
        if nd.cover is not None:
            s += " cover " + " ".join(f"{c or '.'}:{b}" for c, b in nd.cover)
        if nd.name:
            s += f" name={nd.name}"
        if nd.loc:
            s += f" at {nd.loc}"
        lines.append(s)
    for name, k, loc in zip(spec.outputs, spec.output_nodes, spec.output_locs or [None] * len(spec.outputs)):
        lines.append(f"output {name} = n{k} at {loc}")
    if spec.dc is not None:
        lines.append("dc " + " ".join(f"{d:#x}" for d in spec.dc))
    return "\n".join(lines) + "\n"
