"""Parser for ASCII AIGER (``.aag``), combinational And-Inverter Graphs.

Grammar (AIGER 1.9, ASCII variant)::

    file      := header NEWLINE { input } { latch } { output } { and } [ symbols ] [ comment ]
    header    := "aag" M I L O A [ B [ C [ J [ F ] ] ] ]     -- non-negative integers
    input     := LIT NEWLINE                                 -- I lines: even, non-zero, distinct
    latch     := LIT LIT [ LIT ] NEWLINE                     -- L lines: rejected (L must be 0)
    output    := LIT NEWLINE                                 -- O lines: any literal <= 2M+1
    and       := LIT LIT LIT NEWLINE                         -- A lines: lhs (even) = rhs0 & rhs1
    symbols   := { ( "i" | "o" ) INT " " NAME NEWLINE }      -- names of inputs and outputs
    comment   := "c" NEWLINE { any line }

A literal is ``2 * variable + complement``; variable 0 is the constant false (literal 0)
and true (literal 1).  In the ASCII format the AND lines may come in any order, but
they must not form a cycle.  Unnamed inputs are called ``i0, i1, ...`` and unnamed
outputs ``o0, o1, ...``.  Latches, bad-state, constraint, justice and fairness sections
are rejected; mlc compiles combinational logic only.
"""
from __future__ import annotations

import re

from mlc.errors import Loc, MlcError
from mlc.front.blif import _check_loops
from mlc.front.load import finish_network
from mlc.spec import Node, NetworkSpec

TOKEN_RE = re.compile(r"\S+")
INT_RE = re.compile(r"[0-9]+")
SYMBOL_RE = re.compile(r"([ilobcjf])([0-9]+) (.+)")


def parse(text: str, filename: str = "<input>") -> NetworkSpec:
    """Parse an ASCII AIGER file into a :class:`NetworkSpec`."""
    lines = text.split("\n")
    if lines and lines[-1] == "":
        lines.pop()

    def toks(i):
        return [(m.group(), m.start() + 1) for m in TOKEN_RE.finditer(lines[i])]

    def ints(i, count, what):
        if i >= len(lines):
            raise MlcError(f"file ends before the {what} line", Loc(filename, len(lines) or 1))
        ts = toks(i)
        if len(ts) != count:
            col = ts[count][1] if len(ts) > count else (len(lines[i]) + 1)
            raise MlcError(f"{what} line needs {count} number{'s' if count > 1 else ''}, found {len(ts)}",
                           Loc(filename, i + 1, col))
        out = []
        for s, col in ts:
            if not INT_RE.fullmatch(s):
                raise MlcError(f"expected a non-negative integer, found {s!r}", Loc(filename, i + 1, col))
            out.append((int(s), col))
        return out

    if not lines:
        raise MlcError("empty AIGER file", Loc(filename, 1), "an ASCII AIGER file starts with 'aag M I L O A'")
    head = toks(0)
    if not head or head[0][0] != "aag":
        if head and head[0][0] == "aig":
            raise MlcError("binary AIGER is not supported", Loc(filename, 1, 1),
                           "convert it to ASCII AIGER first: aigtoaig in.aig out.aag")
        raise MlcError("not an ASCII AIGER file: the first line must start with 'aag'", Loc(filename, 1, 1))
    if not 6 <= len(head) <= 10:
        raise MlcError(f"the header needs 5 to 9 numbers after 'aag' (M I L O A [B C J F]), found {len(head) - 1}",
                       Loc(filename, 1, 1))
    nums = []
    for s, col in head[1:]:
        if not INT_RE.fullmatch(s):
            raise MlcError(f"expected a non-negative integer, found {s!r}", Loc(filename, 1, col))
        nums.append(int(s))
    M, I, L, O, A = nums[:5]
    if L:
        raise MlcError(f"the file has {L} latch(es); latches (sequential logic) are not supported",
                       Loc(filename, 1, head[3][1]), "mlc compiles combinational logic only")
    for k, what in enumerate(("bad-state", "constraint", "justice", "fairness")):
        if len(nums) > 5 + k and nums[5 + k]:
            raise MlcError(f"{what} properties are not supported", Loc(filename, 1, head[6 + k][1]),
                           "mlc reads combinational AIGs: header B C J F must be 0")
    if M < I + L + A:
        raise MlcError(f"M = {M} is smaller than I + L + A = {I + L + A}", Loc(filename, 1, head[1][1]))
    maxlit = 2 * M + 1
    defined: dict[int, Loc] = {}            # variable -> where defined
    input_vars: list[int] = []
    row = 1
    for k in range(I):
        (lit, col), = ints(row, 1, f"input {k}")
        where = Loc(filename, row + 1, col)
        if lit & 1 or lit < 2 or lit > maxlit:
            raise MlcError(f"input literal must be even and between 2 and {2 * M}, found {lit}", where)
        if lit >> 1 in defined:
            raise MlcError(f"variable {lit >> 1} is defined twice (first at line {defined[lit >> 1].line})", where)
        defined[lit >> 1] = where
        input_vars.append(lit >> 1)
        row += 1
    out_lits = []
    for k in range(O):
        (lit, col), = ints(row, 1, f"output {k}")
        where = Loc(filename, row + 1, col)
        if lit > maxlit:
            raise MlcError(f"output literal {lit} exceeds 2M+1 = {maxlit}", where)
        out_lits.append((lit, where))
        row += 1
    ands = []
    for k in range(A):
        vals = ints(row, 3, f"AND {k}")
        (lhs, c0), (r0, c1), (r1, c2) = vals
        if lhs & 1 or lhs < 2 or lhs > maxlit:
            raise MlcError(f"AND output literal must be even and between 2 and {2 * M}, found {lhs}",
                           Loc(filename, row + 1, c0))
        for r, c in ((r0, c1), (r1, c2)):
            if r > maxlit:
                raise MlcError(f"literal {r} exceeds 2M+1 = {maxlit}", Loc(filename, row + 1, c))
        where = Loc(filename, row + 1, c0)
        if lhs >> 1 in defined:
            raise MlcError(f"variable {lhs >> 1} is defined twice (first at line {defined[lhs >> 1].line})", where)
        defined[lhs >> 1] = where
        ands.append((lhs >> 1, (r0, Loc(filename, row + 1, c1)), (r1, Loc(filename, row + 1, c2)), where))
        row += 1

    in_names: dict[int, str] = {}
    out_names: dict[int, str] = {}
    sym_seen: dict[str, int] = {}
    while row < len(lines):
        line = lines[row]
        if line.startswith("c"):
            break
        if not line.strip():
            row += 1
            continue
        m = SYMBOL_RE.fullmatch(line.rstrip("\r"))
        if not m:
            raise MlcError("expected a symbol line like 'i0 name' or 'o0 name', or 'c' to start the comment",
                           Loc(filename, row + 1, 1))
        kind, idx, name = m.group(1), int(m.group(2)), m.group(3)
        where = Loc(filename, row + 1, 1)
        if not name.strip() or any(ch.isspace() for ch in name):
            raise MlcError(f"symbol name {name!r} is empty or contains blanks", Loc(filename, row + 1, len(m.group(1) + m.group(2)) + 2),
                           "use names without blanks (they must survive BLIF export)")
        if kind not in "io":
            raise MlcError(f"symbol for a '{kind}' entry, but the file has none", where)
        count = I if kind == "i" else O
        if idx >= count:
            raise MlcError(f"symbol {kind}{idx} is out of range (the file has {count})", where)
        table = in_names if kind == "i" else out_names
        if idx in table:
            raise MlcError(f"{kind}{idx} is named twice", where)
        if (kind, name) in sym_seen:
            raise MlcError(f"name {name!r} is used twice (first at line {sym_seen[(kind, name)]})", where)
        sym_seen[(kind, name)] = row + 1
        table[idx] = name
        row += 1

    inputs = [in_names.get(k, f"i{k}") for k in range(I)]
    outputs = [out_names.get(k, f"o{k}") for k in range(O)]
    for names, what in ((inputs, "input"), (outputs, "output")):
        if len(set(names)) != len(names):
            dup = next(x for x in names if names.count(x) > 1)
            raise MlcError(f"two {what}s are called {dup!r} (a symbol clashes with a default name)",
                           Loc(filename, 1), "name every input and output in the symbol table")
    if O == 0:
        raise MlcError("the AIG has no outputs", Loc(filename, 1, head[4][1]))

    nodes: list[Node] = []
    var_node: dict[int, int] = {}
    for k, v in enumerate(input_vars):
        var_node[v] = len(nodes)
        nodes.append(Node("input", (), inputs[k], defined[v]))
    for v, _r0, _r1, where in ands:
        var_node[v] = len(nodes)
        nodes.append(Node("and", (), None, where))
    neg: dict[int, int] = {}
    const: list[int] = []

    def lit_node(lit: int, where: Loc) -> int:
        v = lit >> 1
        if v == 0:
            if not const:
                const.append(len(nodes))
                nodes.append(Node("const0", (), None, where))
            base = const[0]
        elif v in var_node:
            base = var_node[v]
        else:
            raise MlcError(f"literal {lit} refers to variable {v}, which is neither an input nor an AND",
                           where, "define it or fix the literal")
        if not lit & 1:
            return base
        if base not in neg:
            neg[base] = len(nodes)
            nodes.append(Node("not", (base,), None, where))
        return neg[base]

    for v, (r0, l0), (r1, l1), _where in ands:
        nodes[var_node[v]].args = (lit_node(r0, l0), lit_node(r1, l1))
    output_nodes = [lit_node(lit, where) for lit, where in out_lits]
    _check_loops(nodes, filename)
    locs = [where for _lit, where in out_lits]
    return finish_network(inputs, outputs, nodes, output_nodes, filename, locs)
