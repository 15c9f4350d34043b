"""Parser for combinational BLIF (Berkeley Logic Interchange Format).

Grammar (``#`` starts a comment; a line ending in ``\\`` continues on the next)::

    file      := { line NEWLINE }
    line      := ".model" NAME
               | ".inputs" { NAME }               -- may repeat
               | ".outputs" { NAME }              -- may repeat
               | ".names" { NAME } NAME           -- inputs of the cover, then the signal it drives
               | cover_row                        -- rows of the preceding .names
               | ".conn" NAME NAME                -- Yosys extension: the second signal is a copy of the first
               | ".end"
               | ignored
    cover_row := CUBE BIT                         -- CUBE: one of 0 1 - per cover input
               | BIT                              -- for a .names without inputs (a constant)
    BIT       := "0" | "1"                        -- all rows of one cover use the same BIT
    ignored   := ".attr" ... | ".cname" ... | ".param" ... | ".default_input_arrival" ...   (and other timing keywords)

A cover whose rows end in 1 lists the on-set, one whose rows end in 0 the off-set; a
cover without rows is constant 0.  Signals may be used before the ``.names`` that drives
them; combinational loops, undriven signals and signals driven twice are errors.
Sequential and hierarchical constructs (``.latch``, ``.mlatch``, ``.subckt``, ``.gate``,
``.exdc``, a second ``.model``) are rejected.
"""
from __future__ import annotations

import re

from mlc.errors import Loc, MlcError
from mlc.front.load import finish_network
from mlc.spec import Node, NetworkSpec

TOKEN_RE = re.compile(r"\S+")
CUBE_RE = re.compile(r"[01-]*")
IGNORED = {"attr", "cname", "param", "area", "delay", "wire_load_slope", "wire", "input_arrival",
           "output_required", "default_input_arrival", "default_output_required", "input_drive",
           "default_input_drive", "output_load", "default_output_load", "max_input_load", "clock"}
REJECTED = {
    "latch": "latches (sequential logic) are not supported",
    "mlatch": "latches (sequential logic) are not supported",
    "subckt": "hierarchical BLIF (.subckt) is not supported",
    "gate": "mapped BLIF (.gate) is not supported",
    "exdc": "external don't cares (.exdc) are not supported",
    "search": ".search is not supported",
    "start_kiss": "state machines (.start_kiss) are not supported",
    "blackbox": "black boxes are not supported",
}
FIXES = {
    "latch": "mlc compiles combinational logic only",
    "mlatch": "mlc compiles combinational logic only",
    "subckt": "flatten the design first (yosys: flatten; write_blif)",
    "gate": "write the netlist with .names covers (ABC: write_blif after strash)",
}


def _logical_lines(text: str):
    """Yield (tokens, first physical line) with ``\\`` continuations joined and comments removed.
    ``tokens`` is a list of (text, Loc-without-file as (line, col))."""
    toks: list[tuple[str, int, int]] = []
    start = None
    for lineno, raw in enumerate(text.splitlines(), 1):
        line = raw.split("#", 1)[0]
        cont = line.rstrip().endswith("\\")
        if cont:
            line = line.rstrip()[:-1]
        if start is None:
            start = lineno
        toks.extend((m.group(), lineno, m.start() + 1) for m in TOKEN_RE.finditer(line))
        if not cont:
            if toks:
                yield toks, start
            toks, start = [], None
    if toks:
        yield toks, start


def parse(text: str, filename: str = "<input>") -> NetworkSpec:
    """Parse a combinational BLIF model into a :class:`NetworkSpec`."""
    def loc(tok):
        return Loc(filename, tok[1], tok[2])

    inputs: list[str] = []
    outputs: list[str] = []
    output_locs: list[Loc] = []
    declared: dict[str, Loc] = {}           # input name -> where
    out_seen: dict[str, Loc] = {}
    drivers: dict[str, tuple[Loc, list[tuple], list[tuple[str, str]] | None, str | None]] = {}
    current = None                          # the .names whose rows we are reading
    model_seen = None
    ended = False
    for toks, _start in _logical_lines(text):
        head = toks[0][0]
        if ended:
            if head == ".model":
                raise MlcError("a second .model (hierarchical BLIF) is not supported", loc(toks[0]),
                               "flatten the design into one model first (yosys: flatten)")
            continue
        if head.startswith("."):
            word = head[1:]
            current = None
            if word == "model":
                if model_seen is not None:
                    raise MlcError("a second .model (hierarchical BLIF) is not supported", loc(toks[0]),
                                   "flatten the design into one model first (yosys: flatten)")
                model_seen = loc(toks[0])
            elif word == "inputs":
                for tok in toks[1:]:
                    name = tok[0]
                    if name in declared:
                        raise MlcError(f"input {name!r} is declared twice (first at line {declared[name].line})",
                                       loc(tok))
                    declared[name] = loc(tok)
                    inputs.append(name)
            elif word == "outputs":
                for tok in toks[1:]:
                    name = tok[0]
                    if name in out_seen:
                        raise MlcError(f"output {name!r} is declared twice (first at line {out_seen[name].line})",
                                       loc(tok))
                    out_seen[name] = loc(tok)
                    outputs.append(name)
                    output_locs.append(loc(tok))
            elif word == "names":
                if len(toks) < 2:
                    raise MlcError(".names needs at least the name of the signal it drives", loc(toks[0]))
                out = toks[-1]
                _drive(drivers, declared, out, loc, filename)
                current = [loc(out), toks[1:-1], [], None]
                drivers[out[0]] = current
            elif word == "conn":
                if len(toks) != 3:
                    raise MlcError(".conn takes two signal names", loc(toks[0]))
                _drive(drivers, declared, toks[2], loc, filename)
                drivers[toks[2][0]] = [loc(toks[2]), [toks[1]], [("1", "1")], "1"]
            elif word == "end":
                ended = True
            elif word in REJECTED:
                raise MlcError(REJECTED[word], loc(toks[0]), FIXES.get(word))
            elif word in IGNORED:
                pass
            else:
                raise MlcError(f"unknown BLIF keyword {head}", loc(toks[0]),
                               "mlc reads .model .inputs .outputs .names .conn .end")
            continue
        if current is None:
            raise MlcError(f"unexpected {head!r} outside a .names cover", loc(toks[0]),
                           "cover rows follow a .names line")
        k = len(current[1])
        if k == 0:
            if len(toks) != 1 or toks[0][0] not in ("0", "1"):
                raise MlcError("a .names without inputs takes rows of a single 0 or 1", loc(toks[0]))
            cube, bit = "", toks[0][0]
        else:
            if len(toks) != 2:
                bad = toks[2] if len(toks) > 2 else toks[0]
                raise MlcError(f"a cover row is CUBE BIT (here the cube has {k} columns)", loc(bad))
            cube, bit = toks[0][0], toks[1][0]
            if not CUBE_RE.fullmatch(cube):
                col = next(i for i, ch in enumerate(cube) if ch not in "01-")
                raise MlcError(f"unexpected character {cube[col]!r} in a cube", Loc(filename, toks[0][1], toks[0][2] + col),
                               "cubes use 0, 1 and -")
            if len(cube) != k:
                raise MlcError(f"cube has {len(cube)} columns but .names has {k} inputs", loc(toks[0]))
            if bit not in ("0", "1"):
                raise MlcError(f"output column must be 0 or 1, found {bit!r}", loc(toks[1]))
        if current[3] is not None and bit != current[3]:
            raise MlcError("a cover mixes on-set rows (ending in 1) and off-set rows (ending in 0)",
                           loc(toks[-1]), "use one kind of row per .names")
        current[3] = bit
        current[2].append((cube, bit))
    if model_seen is None and not (inputs or outputs or drivers):
        raise MlcError("empty BLIF file", Loc(filename, 1), "a BLIF model needs .model, .inputs, .outputs, .names")
    if not outputs:
        raise MlcError("no .outputs", Loc(filename, 1), "declare the outputs with .outputs NAMES")

    # Build nodes: inputs, then one node per driven signal; resolve names.
    nodes: list[Node] = []
    index: dict[str, int] = {}
    for name in inputs:
        index[name] = len(nodes)
        nodes.append(Node("input", (), name, declared[name]))
    for name, (where, _ins, cover, bit) in drivers.items():
        index[name] = len(nodes)
        if not _ins:
            op = "const1" if cover and bit == "1" else "const0"
            nodes.append(Node(op, (), name, where))
        else:
            nodes.append(Node("sop", (), name, where, list(cover)))
    for name, (where, ins, _cover, _bit) in drivers.items():
        args = []
        for tok in ins:
            if tok[0] not in index:
                raise MlcError(f"signal {tok[0]!r} is used but never driven", loc(tok),
                               "declare it in .inputs or drive it with .names")
            args.append(index[tok[0]])
        nodes[index[name]].args = tuple(args)
    output_nodes = []
    for name, where in zip(outputs, output_locs):
        if name not in index:
            raise MlcError(f"output {name!r} is never driven", where, "drive it with .names")
        output_nodes.append(index[name])
    _check_loops(nodes, filename)
    return finish_network(inputs, outputs, nodes, output_nodes, filename, output_locs)


def _drive(drivers, declared, tok, loc, filename):
    name = tok[0]
    if name in declared:
        raise MlcError(f"signal {name!r} is a primary input and cannot be driven", loc(tok))
    if name in drivers:
        raise MlcError(f"signal {name!r} is driven twice (first at line {drivers[name][0].line})", loc(tok))


def _label(nd: Node) -> str:
    if nd.name:
        return nd.name
    return f"line {nd.loc.line}" if nd.loc else "?"


def _check_loops(nodes: list[Node], filename: str) -> None:
    from mlc.front.load import postorder

    def loop(cyc):
        names = " -> ".join(_label(nodes[c]) for c in cyc)
        raise MlcError(f"combinational loop: {names}", nodes[cyc[-1]].loc,
                       "mlc compiles combinational logic only; break the loop")

    postorder(nodes, range(len(nodes)), loop)


def print_blif(spec: NetworkSpec, model: str = "mlc") -> str:
    """Write a NetworkSpec as BLIF (every node becomes one .names cover)."""
    from mlc.front.load import node_table
    names = {}
    used = set(spec.inputs) | set(spec.outputs)
    for k, nd in enumerate(spec.nodes):
        if nd.op == "input":
            names[k] = nd.name
    first_out = {}
    for name, k in zip(spec.outputs, spec.output_nodes):
        if spec.nodes[k].op != "input":
            first_out.setdefault(k, name)
    j = 0
    for k, nd in enumerate(spec.nodes):
        if k in names:
            continue
        if k in first_out:
            names[k] = first_out[k]
            continue
        if nd.name and TOKEN_RE.fullmatch(nd.name) and nd.name not in used:
            names[k] = nd.name
        else:
            while f"n{j}" in used:
                j += 1
            names[k] = f"n{j}"
        used.add(names[k])
    lines = [f".model {model}", ".inputs " + " ".join(spec.inputs), ".outputs " + " ".join(spec.outputs)]
    for k, nd in enumerate(spec.nodes):
        if nd.op == "input":
            continue
        args = [names[a] for a in nd.args]
        lines.append(".names " + " ".join(args + [names[k]]))
        if nd.op == "sop":
            lines.extend(f"{c} {b}" if c else b for c, b in nd.cover)
            continue
        # tabulate the node's function over its arguments (arities here are small)
        a = len(args)
        if a > 16:
            raise MlcError(f"node with {a} arguments is too wide to write as a BLIF cover", spec.source)
        f = node_table(nd.op, a)
        for mt in range(1 << a):
            if (f >> mt) & 1:
                lines.append("".join(str((mt >> i) & 1) for i in range(a)) + (" 1" if a else "1"))
    for name, k in zip(spec.outputs, spec.output_nodes):
        if names[k] != name:
            lines.append(f".names {names[k]} {name}")
            lines.append("1 1")
    lines.append(".end")
    return "\n".join(lines) + "\n"
