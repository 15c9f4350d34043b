"""Parser for AIGER, ASCII (``.aag``) and binary (``.aig``): combinational And-Inverter Graphs.

The variant is chosen by the header (``aag`` or ``aig``), not by the file name.

Grammar (AIGER 1.9)::

    file      := header NEWLINE body [ symbols ] [ comment ]
    header    := ( "aag" | "aig" ) M I L O A [ B [ C [ J [ F ] ] ] ]   -- non-negative integers
    symbols   := { ( "i" | "o" ) INT " " NAME NEWLINE }      -- names of inputs and outputs
    comment   := "c" NEWLINE { any line }

    ASCII body ("aag"):
    body      := { input } { latch } { output } { and }
    input     := LIT NEWLINE                                 -- I lines: even, non-zero, distinct
    latch     := LIT LIT [ LIT ] NEWLINE                     -- L lines: rejected (L must be 0)
    output    := LIT NEWLINE                                 -- O lines: any literal <= 2M+1
    and       := LIT LIT LIT NEWLINE                         -- A lines: lhs (even) = rhs0 & rhs1

    binary body ("aig"; M = I + L + A; the inputs are implicit: literals 2, 4, ..., 2I):
    body      := { output } { and }                          -- outputs: ASCII lines as above
    and       := DELTA DELTA                                 -- AND k: lhs = 2 (I + L + k + 1),
                                                             --   rhs0 = lhs - delta0 (delta0 >= 1),
                                                             --   rhs1 = rhs0 - delta1 (delta1 >= 0)
    DELTA     := { byte >= 0x80 } byte < 0x80                -- 7 bits per byte, lowest group first

A literal is ``2 * variable + complement``; variable 0 is the constant false (literal 0)
and true (literal 1).  In the ASCII format the AND lines may come in any order, but
they must not form a cycle; in the binary format every AND refers to smaller
literals only, so cycles cannot occur.  Unnamed inputs are called ``i0, i1, ...`` and
unnamed outputs ``o0, o1, ...``.  Latches, bad-state, constraint, justice and fairness
sections are rejected; mlc compiles combinational logic only.

Error locations: ``file:line:col`` in text (all of an ASCII file; the header and the
output lines of a binary one), ``file:byte N`` (offset from 0, as ``xxd`` and ``od``
count) in and after the binary AND section of a binary file, where lines mean nothing.

:func:`parse` returns a :class:`~mlc.spec.NetworkSpec`; :func:`read` also returns the
file's raw contents (:class:`Aiger`, used by the converters of :mod:`mlc.logic.aigio`).
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field

from mlc.errors import Loc, MlcError
from mlc.front.blif import _check_loops
from mlc.front.load import finish_network
from mlc.spec import Node, NetworkSpec

TOKEN_RE = re.compile(r"\S+")
INT_RE = re.compile(r"[0-9]+")
SYMBOL_RE = re.compile(r"([ilobcjf])([0-9]+) (.+)")
MAX_VARINT_BYTES = 10        # 70 bits: far beyond any literal; longer is a corrupt file


@dataclass(frozen=True)
class ByteLoc(Loc):
    """A location in a binary file: byte offset from 0 (printed ``file:byte N``)."""

    byte: int = 0

    def __str__(self) -> str:
        return f"{self.file}:byte {self.byte}"


@dataclass
class Aiger:
    """The raw contents of an AIGER file (literals as in the file)."""

    binary: bool
    M: int
    inputs: list[int]                                   # input literals
    outputs: list[int]                                  # output literals
    ands: list[tuple[int, int, int]]                    # (lhs, rhs0, rhs1)
    in_names: dict[int, str] = field(default_factory=dict)
    out_names: dict[int, str] = field(default_factory=dict)
    comment: list[str] | None = None                    # lines after "c", or None without a "c" line


class _Src:
    """Locations of the parts of one file, for the network builder's messages."""

    def __init__(self, filename: str):
        self.filename = filename
        self.header = Loc(filename, 1, 1)
        self.o_col = 1                 # column of O in the header
        self.input_locs: list[Loc] = []
        self.output_locs: list[Loc] = []
        self.and_locs: list[tuple[Loc, Loc, Loc]] = []


def parse(data: bytes | str, filename: str = "<input>") -> NetworkSpec:
    """Parse an AIGER file (ASCII or binary, chosen by the header) into a :class:`NetworkSpec`."""
    return read(data, filename)[1]


def read(data: bytes | str, filename: str = "<input>") -> tuple[Aiger, NetworkSpec]:
    """Parse and check an AIGER file: its raw contents and the network they define."""
    if isinstance(data, str):
        data = data.encode("utf-8", "surrogateescape")
    if not data.strip():
        raise MlcError("empty AIGER file", Loc(filename, 1),
                       "an AIGER file starts with 'aag M I L O A' (ASCII) or 'aig M I L O A' (binary)")
    first = data.split(None, 1)[0]
    if first == b"aig":
        raw, src = _read_binary(data, filename)
    elif first == b"aag":
        try:
            text = data.decode("utf-8")
        except UnicodeDecodeError as e:
            line = data.count(b"\n", 0, e.start) + 1
            col = e.start - (data.rfind(b"\n", 0, e.start) + 1) + 1
            raise MlcError(f"not UTF-8 text ({e.reason})", Loc(filename, line, col),
                           "an ASCII AIGER file ('aag') is text; a binary one starts with 'aig'") from None
        raw, src = _read_ascii(text, filename)
    else:
        raise MlcError("not an AIGER file: the first line must start with 'aag' (ASCII) or 'aig' (binary)",
                       Loc(filename, 1, 1))
    return raw, _network(raw, src)


# --------------------------------------------------------------------------- header

def _header(tokens, filename: str, src: _Src) -> list[int]:
    """Check ``[(token, col), ...]`` of the header line; return M I L O A (B C J F are 0)."""
    kind = tokens[0][0]
    if not 6 <= len(tokens) <= 10:
        raise MlcError(f"the header needs 5 to 9 numbers after '{kind}' (M I L O A [B C J F]), "
                       f"found {len(tokens) - 1}", Loc(filename, 1, 1))
    nums = []
    for s, col in tokens[1:]:
        if not INT_RE.fullmatch(s):
            raise MlcError(f"expected a non-negative integer, found {s!r}", Loc(filename, 1, col))
        nums.append(int(s))
    M, I, L, O, A = nums[:5]
    if L:
        raise MlcError(f"the file has {L} latch(es); latches (sequential logic) are not supported",
                       Loc(filename, 1, tokens[3][1]), "mlc compiles combinational logic only")
    for k, what in enumerate(("bad-state", "constraint", "justice", "fairness")):
        if len(nums) > 5 + k and nums[5 + k]:
            raise MlcError(f"{what} properties are not supported", Loc(filename, 1, tokens[6 + k][1]),
                           "mlc reads combinational AIGs: header B C J F must be 0")
    if kind == "aig" and M != I + L + A:
        raise MlcError(f"M = {M}, but a binary AIGER file needs M = I + L + A = {I + L + A}",
                       Loc(filename, 1, tokens[1][1]))
    if M < I + L + A:
        raise MlcError(f"M = {M} is smaller than I + L + A = {I + L + A}", Loc(filename, 1, tokens[1][1]))
    src.o_col = tokens[4][1]
    return [M, I, L, O, A]


# --------------------------------------------------------------------------- ASCII

def _read_ascii(text: str, filename: str) -> tuple[Aiger, _Src]:
    lines = text.split("\n")
    if lines and lines[-1] == "":
        lines.pop()
    src = _Src(filename)

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

    M, I, _L, O, A = _header(toks(0), filename, src)
    maxlit = 2 * M + 1
    defined: dict[int, Loc] = {}            # variable -> where defined
    raw = Aiger(False, M, [], [], [])
    row = 1
    for k in range(I):
        (lit, col), = ints(row, 1, f"input {k}")
        where = Loc(filename, row + 1, col)
        if lit & 1 or lit < 2 or lit > maxlit:
            raise MlcError(f"input literal must be even and between 2 and {2 * M}, found {lit}", where)
        if lit >> 1 in defined:
            raise MlcError(f"variable {lit >> 1} is defined twice (first at line {defined[lit >> 1].line})", where)
        defined[lit >> 1] = where
        raw.inputs.append(lit)
        src.input_locs.append(where)
        row += 1
    for k in range(O):
        (lit, col), = ints(row, 1, f"output {k}")
        where = Loc(filename, row + 1, col)
        if lit > maxlit:
            raise MlcError(f"output literal {lit} exceeds 2M+1 = {maxlit}", where)
        raw.outputs.append(lit)
        src.output_locs.append(where)
        row += 1
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
        raw.ands.append((lhs, r0, r1))
        src.and_locs.append((where, Loc(filename, row + 1, c1), Loc(filename, row + 1, c2)))
        row += 1

    rest = [(lines[r], (lambda col, r=r: Loc(filename, r + 1, col))) for r in range(row, len(lines))]
    _symbols(rest, raw, I, O)
    return raw, src


# --------------------------------------------------------------------------- binary

def _read_binary(data: bytes, filename: str) -> tuple[Aiger, _Src]:
    src = _Src(filename)
    pos = 0
    line = 0

    def text_line(what: str) -> tuple[str, int]:
        """The next line as text (the header and output lines are ASCII) and its number."""
        nonlocal pos, line
        if pos >= len(data):
            raise MlcError(f"file ends before the {what} line", Loc(filename, max(line, 1)))
        end = data.find(b"\n", pos)
        end = len(data) if end < 0 else end
        chunk = data[pos:end]
        line += 1
        bad = next((i for i, ch in enumerate(chunk) if ch >= 0x80 or (ch < 0x20 and ch not in b"\t\r")), None)
        if bad is not None:
            raise MlcError(f"unexpected byte 0x{chunk[bad]:02x} in the {what} line", Loc(filename, line, bad + 1),
                           "the header and output lines of a binary AIGER file are ASCII text")
        pos = end + 1
        return chunk.decode("ascii"), line

    head, _ = text_line("header")
    M, I, _L, O, A = _header([(m.group(), m.start() + 1) for m in TOKEN_RE.finditer(head)], filename, src)
    maxlit = 2 * M + 1
    raw = Aiger(True, M, [2 * (k + 1) for k in range(I)], [], [])
    src.input_locs = [Loc(filename, 1, 1)] * I
    for k in range(O):
        s, ln = text_line(f"output {k}")
        ts = [(m.group(), m.start() + 1) for m in TOKEN_RE.finditer(s)]
        if len(ts) != 1:
            col = ts[1][1] if len(ts) > 1 else len(s) + 1
            raise MlcError(f"output {k} line needs 1 number, found {len(ts)}", Loc(filename, ln, col))
        tok, col = ts[0]
        where = Loc(filename, ln, col)
        if not INT_RE.fullmatch(tok):
            raise MlcError(f"expected a non-negative integer, found {tok!r}", where)
        lit = int(tok)
        if lit > maxlit:
            raise MlcError(f"output literal {lit} exceeds 2M+1 = {maxlit}", where)
        raw.outputs.append(lit)
        src.output_locs.append(where)
    if A and pos > len(data):
        raise MlcError(f"file ends before the AND section ({A} AND{'s' if A > 1 else ''} declared)",
                       ByteLoc(filename, byte=len(data)))

    n = len(data)

    def varint(k: int, which: str) -> int:
        nonlocal pos
        start = pos
        x = shift = 0
        while True:
            if pos >= n:
                raise MlcError(f"file ends inside AND {k} of {A}: truncated {which} delta", ByteLoc(filename, byte=pos),
                               "the file is cut short or A in the header is too large")
            ch = data[pos]
            pos += 1
            x |= (ch & 0x7F) << shift
            if not ch & 0x80:
                return x
            shift += 7
            if pos - start >= MAX_VARINT_BYTES:
                raise MlcError(f"AND {k}: {which} delta runs over {MAX_VARINT_BYTES} bytes",
                               ByteLoc(filename, byte=start), "the file is corrupt")

    for k in range(A):
        lhs = 2 * (I + _L + k + 1)
        at = ByteLoc(filename, byte=pos)
        d0 = varint(k, "first")
        at1 = ByteLoc(filename, byte=pos)
        d1 = varint(k, "second")
        if d0 == 0:
            raise MlcError(f"AND {k} (literal {lhs}): first delta is 0, so rhs0 would be the AND itself", at,
                           "binary AIGER needs lhs > rhs0 >= rhs1")
        if d0 > lhs:
            raise MlcError(f"AND {k} (literal {lhs}): first delta {d0} underflows (rhs0 = {lhs} - {d0} < 0)", at)
        r0 = lhs - d0
        if d1 > r0:
            raise MlcError(f"AND {k} (literal {lhs}): second delta {d1} underflows (rhs1 = {r0} - {d1} < 0)", at1)
        raw.ands.append((lhs, r0, r0 - d1))
        src.and_locs.append((at, at, at1))

    rest = []
    while pos < n:
        end = data.find(b"\n", pos)
        end = n if end < 0 else end
        start = pos
        try:
            s = data[pos:end].decode("utf-8")
        except UnicodeDecodeError as e:
            raise MlcError(f"symbol table or comment is not UTF-8 text ({e.reason})",
                           ByteLoc(filename, byte=start + e.start)) from None
        s_bytes = [len(ch.encode("utf-8")) for ch in s]
        offs = [0]
        for b in s_bytes:
            offs.append(offs[-1] + b)

        def loc(col, start=start, offs=offs):
            return ByteLoc(filename, byte=start + offs[min(col - 1, len(offs) - 1)])
        rest.append((s, loc))
        pos = end + 1
    _symbols(rest, raw, I, O)
    return raw, src


# --------------------------------------------------------------------------- symbols and comment

def _symbols(rest, raw: Aiger, I: int, O: int) -> None:
    """Read the symbol table and comment from ``rest`` = [(line text, col -> location)]."""
    seen: dict[tuple[str, str], Loc] = {}
    for r, (line, loc) in enumerate(rest):
        if line.startswith("c"):
            raw.comment = [x.rstrip("\r") for x, _loc in rest[r + 1:]]
            break
        if not line.strip():
            continue
        m = SYMBOL_RE.fullmatch(line.rstrip("\r"))
        if not m:
            raise MlcError("expected a symbol line like 'i0 name' or 'o0 name', or 'c' to start the comment", loc(1))
        kind, idx, name = m.group(1), int(m.group(2)), m.group(3)
        where = loc(1)
        if not name.strip() or any(ch.isspace() for ch in name):
            raise MlcError(f"symbol name {name!r} is empty or contains blanks", loc(len(m.group(1) + m.group(2)) + 2),
                           "use names without blanks (they must survive BLIF export)")
        if kind not in "io":
            raise MlcError(f"symbol for a '{kind}' entry, but the file has none", where)
        count = I if kind == "i" else O
        if idx >= count:
            raise MlcError(f"symbol {kind}{idx} is out of range (the file has {count})", where)
        table = raw.in_names if kind == "i" else raw.out_names
        if idx in table:
            raise MlcError(f"{kind}{idx} is named twice", where)
        if (kind, name) in seen:
            raise MlcError(f"name {name!r} is used twice (first at {_at(seen[(kind, name)])})", where)
        seen[(kind, name)] = where
        table[idx] = name


def _at(loc: Loc) -> str:
    return f"byte {loc.byte}" if isinstance(loc, ByteLoc) else f"line {loc.line}"


# --------------------------------------------------------------------------- network

def _network(raw: Aiger, src: _Src) -> NetworkSpec:
    filename = src.filename
    I, O = len(raw.inputs), len(raw.outputs)
    inputs = [raw.in_names.get(k, f"i{k}") for k in range(I)]
    outputs = [raw.out_names.get(k, f"o{k}") for k in range(O)]
    for names, what in ((inputs, "input"), (outputs, "output")):
        if len(set(names)) != len(names):
            seen = set()
            dup = next(x for x in names if x in seen or seen.add(x))
            raise MlcError(f"two {what}s are called {dup!r} (a symbol clashes with a default name)",
                           Loc(filename, 1), "name every input and output in the symbol table")
    if O == 0:
        raise MlcError("the AIG has no outputs", Loc(filename, 1, src.o_col))

    nodes: list[Node] = []
    var_node: dict[int, int] = {}
    for k, lit in enumerate(raw.inputs):
        var_node[lit >> 1] = len(nodes)
        nodes.append(Node("input", (), inputs[k], src.input_locs[k]))
    for (lhs, _r0, _r1), (where, _l0, _l1) in zip(raw.ands, src.and_locs):
        var_node[lhs >> 1] = len(nodes)
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

    for (lhs, r0, r1), (_where, l0, l1) in zip(raw.ands, src.and_locs):
        nodes[var_node[lhs >> 1]].args = (lit_node(r0, l0), lit_node(r1, l1))
    output_nodes = [lit_node(lit, where) for lit, where in zip(raw.outputs, src.output_locs)]
    if not raw.binary:                      # binary ANDs refer to smaller literals only
        _check_loops(nodes, filename)
    return finish_network(inputs, outputs, nodes, output_nodes, filename, src.output_locs)
