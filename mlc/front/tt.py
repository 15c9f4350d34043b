"""Parser for ``.tt``, mlc's truth-table format (documented in docs/formats.md).

Grammar (one rule per line; ``#`` starts a comment that runs to the end of the line)::

    file      := { line NEWLINE }
    line      := [ directive | row ] [ comment ]
    directive := ".inputs" { NAME }                  -- exactly once, before any row
               | ".outputs" NAME { NAME }            -- exactly once, before any row
               | ".unlisted" ( "dc" | "0" | "1" )    -- optional, before any row; default dc
    row       := BITS [ "|" ] BITS                   -- inputs then outputs
    BITS      := { "0" | "1" | "-" | blank }         -- blanks inside BITS are ignored
    NAME      := [A-Za-z_][A-Za-z0-9_.]* ( "[" [0-9]+ "]" )?
    comment   := "#" { any character }

A row lists the values of the inputs (in ``.inputs`` order) and then of the outputs
(in ``.outputs`` order).  ``-`` in the input part matches both values (the row then
stands for several input combinations); ``-`` in the output part makes that output a
don't care for the row.  Without ``|`` the row must have exactly ``#inputs + #outputs``
values; with ``|`` each side is checked separately.

Input combinations that no row lists take the ``.unlisted`` value: don't care by
default, or an error when ``strict=True`` (``mlc compile --strict``) and the file has
no ``.unlisted`` line.  Two rows that give the same output opposite values on a common
input combination are an error that names both lines.  So is an output that no row sets
to 0 or 1 while unlisted rows are don't cares (a table with no rows, say): any constant
would match it, which is never what was meant.

Minterm numbering is that of :class:`mlc.spec.TableSpec`: the first input is the
least significant bit.
"""
from __future__ import annotations

import re

from mlc.errors import Loc, MlcError
from mlc.front.lines import DIRECTIVE_RE, content_lines, tokens
from mlc.front.load import MAX_TABLE_INPUTS, cube_mask, full_mask, lowest_minterm, minterm_str
from mlc.spec import TableSpec

NAME_RE = re.compile(r"[A-Za-z_][A-Za-z0-9_.]*(?:\[[0-9]+\])?")
BIT_CHARS = frozenset("01-")


def _names(filename, lineno, line, start, what, seen, allow_empty):
    names, cols = [], []
    for col, tok in tokens(line, start):
        if not NAME_RE.fullmatch(tok):
            raise MlcError(f"invalid {what} name {tok!r}", Loc(filename, lineno, col),
                           "names are letters, digits, _ and . starting with a letter or _, optionally with an index like a[3]")
        if tok in seen:
            raise MlcError(f"name {tok!r} is declared twice (first at line {seen[tok]})", Loc(filename, lineno, col))
        seen[tok] = lineno
        names.append(tok)
        cols.append(col)
    if not names and not allow_empty:
        raise MlcError(f".{what}s needs at least one name", Loc(filename, lineno, 1))
    return names, cols


def _row_bits(filename, lineno, line, n, m):
    """Split a row into (input bits, output bits, column of each output bit)."""
    bar = line.find("|")
    if bar >= 0 and line.find("|", bar + 1) >= 0:
        raise MlcError("a row has at most one '|'", Loc(filename, lineno, line.find("|", bar + 1) + 1))
    chars = []          # (col, ch)
    for i, ch in enumerate(line):
        if ch.isspace() or i == bar:
            continue
        if ch not in BIT_CHARS:
            raise MlcError(f"unexpected character {ch!r} in a row", Loc(filename, lineno, i + 1),
                           "rows contain only 0, 1, - and an optional | between inputs and outputs")
        chars.append((i + 1, ch))
    if bar >= 0:
        left = [c for c in chars if c[0] <= bar]
        right = [c for c in chars if c[0] > bar + 1]
        if len(left) != n:
            raise MlcError(f"row has {len(left)} input values before '|', expected {n}", Loc(filename, lineno, bar + 1))
        if len(right) != m:
            col = right[m][0] if len(right) > m else bar + 1
            raise MlcError(f"row has {len(right)} output values after '|', expected {m}", Loc(filename, lineno, col))
    else:
        if len(chars) != n + m:
            col = chars[n + m][0] if len(chars) > n + m else (chars[-1][0] if chars else 1)
            raise MlcError(f"row has {len(chars)} values, expected {n + m} ({n} inputs then {m} outputs)",
                           Loc(filename, lineno, col), "separate inputs from outputs with | to be explicit")
        left, right = chars[:n], chars[n:]
    return "".join(c for _, c in left), "".join(c for _, c in right), [col for col, _ in right]


def parse(text: str, filename: str = "<input>", strict: bool = False) -> TableSpec:
    """Parse a ``.tt`` file into a :class:`TableSpec`."""
    inputs = outputs = None
    out_cols: list[int] = []
    in_line = out_line = 0
    unlisted = None
    seen: dict[str, int] = {}
    full_rows: dict[int, tuple[int, str, list[int]]] = {}   # minterm -> (line, outputs, cols)
    dup_rows: list[tuple[int, int, str, list[int]]] = []    # further rows of an already listed minterm
    cube_rows: list[tuple[int, str, str, list[int]]] = []   # (line, input cube, outputs, cols)
    for lineno, line, stripped, indent in content_lines(text):
        d = DIRECTIVE_RE.match(stripped)
        if d:
            word = d.group(1)
            rest = indent + d.end()
            where = Loc(filename, lineno, indent + 1)
            if inputs is not None and outputs is not None and (full_rows or cube_rows):
                raise MlcError(f".{word} after the first row", where, "put directives before the rows")
            if word == "inputs":
                if inputs is not None:
                    raise MlcError(f"second .inputs line (the first is line {in_line})", where)
                (inputs, _), in_line = _names(filename, lineno, line, rest, "input", seen, True), lineno
                if len(inputs) > MAX_TABLE_INPUTS:
                    raise MlcError(f"{len(inputs)} inputs is too many for a truth table (at most {MAX_TABLE_INPUTS})",
                                   where, "describe larger functions as BLIF, AIGER or expressions")
            elif word == "outputs":
                if outputs is not None:
                    raise MlcError(f"second .outputs line (the first is line {out_line})", where)
                (outputs, out_cols), out_line = _names(filename, lineno, line, rest, "output", seen, False), lineno
            elif word == "unlisted":
                toks = tokens(line, rest)
                if len(toks) != 1 or toks[0][1] not in ("dc", "0", "1"):
                    col = toks[0][0] if toks else len(line) + 1
                    raise MlcError(".unlisted takes one value: dc, 0 or 1", Loc(filename, lineno, col))
                if unlisted is not None:
                    raise MlcError("second .unlisted line", where)
                unlisted = toks[0][1]
            else:
                raise MlcError(f"unknown directive .{word}", where, "known: .inputs, .outputs, .unlisted")
            continue
        if inputs is None or outputs is None:
            missing = ".inputs" if inputs is None else ".outputs"
            raise MlcError(f"row before the {missing} line", Loc(filename, lineno, indent + 1),
                           "start the file with .inputs NAMES and .outputs NAMES")
        n, m = len(inputs), len(outputs)
        cube, outs, cols = _row_bits(filename, lineno, line, n, m)
        if "-" in cube:
            cube_rows.append((lineno, cube, outs, cols))
        else:
            mt = int(cube[::-1], 2) if cube else 0
            if mt in full_rows:
                dup_rows.append((mt, lineno, outs, cols))
            else:
                full_rows[mt] = (lineno, outs, cols)
    if inputs is None:
        raise MlcError("no .inputs line", Loc(filename, 1), "start the file with .inputs NAMES")
    if outputs is None:
        raise MlcError("no .outputs line", Loc(filename, in_line), "add .outputs NAMES after .inputs")
    n, m = len(inputs), len(outputs)
    full = full_mask(n)

    # Fully specified rows: collect per-output minterm lists, then turn them into bit sets.
    size = ((1 << n) + 7) // 8
    on_b = [bytearray(size) for _ in range(m)]
    off_b = [bytearray(size) for _ in range(m)]
    dc_b = [bytearray(size) for _ in range(m)]
    listed_b = bytearray(size)
    for mt, (_line, outs, _cols) in full_rows.items():
        byte, bit = mt >> 3, 1 << (mt & 7)
        listed_b[byte] |= bit
        for o, ch in enumerate(outs):
            (on_b if ch == "1" else off_b if ch == "0" else dc_b)[o][byte] |= bit
    for mt, lineno, outs, cols in dup_rows:
        first_line, first_outs, _ = full_rows[mt]
        for o, ch in enumerate(outs):
            byte, bit = mt >> 3, 1 << (mt & 7)
            if ch == "1" and off_b[o][byte] & bit or ch == "0" and on_b[o][byte] & bit:
                other = _find_line(full_rows, dup_rows, [], mt, o, "0" if ch == "1" else "1", n, lineno)
                raise _conflict(filename, lineno, cols[o], outputs[o], ch, other, inputs, mt)
            if ch in "01":
                (on_b if ch == "1" else off_b)[o][byte] |= bit
            else:
                dc_b[o][byte] |= bit
    on = [int.from_bytes(b, "little") for b in on_b]
    off = [int.from_bytes(b, "little") for b in off_b]
    dcx = [int.from_bytes(b, "little") for b in dc_b]
    listed = int.from_bytes(listed_b, "little")

    # Rows with '-' in the input part: bit-set arithmetic, conflicts checked as they come.
    for k, (lineno, cube, outs, cols) in enumerate(cube_rows):
        c = cube_mask(n, cube)
        listed |= c
        for o, ch in enumerate(outs):
            if ch == "-":
                dcx[o] |= c
                continue
            clash = c & (off[o] if ch == "1" else on[o])
            if clash:
                mt = lowest_minterm(clash)
                other = _find_line(full_rows, dup_rows, cube_rows[:k], mt, o, "0" if ch == "1" else "1", n, lineno)
                raise _conflict(filename, lineno, cols[o], outputs[o], ch, other, inputs, mt)
            if ch == "1":
                on[o] |= c
            else:
                off[o] |= c

    missing = full & ~listed
    if missing and unlisted is None and strict:
        mt = lowest_minterm(missing)
        count = bin(missing).count("1")
        raise MlcError(f"{count} input combination(s) are not listed, the first is {minterm_str(inputs, mt)} (--strict)",
                       Loc(filename, in_line, 1),
                       "add the missing rows, add '.unlisted dc' (or 0 or 1), or drop --strict")
    if unlisted in (None, "dc"):
        for o in range(m):
            if not (on[o] | off[o]):            # no row gives it a value: any constant would do
                raise MlcError(f"output {outputs[o]} is a don't care on every input combination "
                               f"({'the table has no rows' if not listed else 'every row gives it -'})",
                               Loc(filename, out_line, out_cols[o]),
                               "add rows that set it to 0 or 1, or '.unlisted 0' (or 1) for a constant output")
    dc = []
    for o in range(m):
        if unlisted == "1":
            on[o] |= missing
        d = (dcx[o] | (missing if unlisted in (None, "dc") else 0)) & ~on[o] & ~off[o]
        dc.append(d & full)
        on[o] &= full
    out_locs = [Loc(filename, out_line, c) for c in out_cols]
    return TableSpec(inputs, outputs, on, dc, filename, out_locs)


def _find_line(full_rows, dup_rows, cube_rows, mt, o, ch, n, exclude):
    """(line, column) of a row that sets output ``o`` to ``ch`` on minterm ``mt``."""
    if mt in full_rows and full_rows[mt][1][o] == ch and full_rows[mt][0] != exclude:
        return full_rows[mt][0], full_rows[mt][2][o]
    for dmt, lineno, outs, cols in dup_rows:
        if dmt == mt and outs[o] == ch and lineno != exclude:
            return lineno, cols[o]
    for lineno, cube, outs, cols in cube_rows:
        if outs[o] == ch and all(c == "-" or int(c) == (mt >> i) & 1 for i, c in enumerate(cube)):
            return lineno, cols[o]
    return 0, 0


def _conflict(filename, lineno, col, name, ch, other, inputs, mt):
    """Both rows named; the error points at the later one."""
    (l1, c1, v1), (l2, c2, v2) = sorted([(lineno, col, ch), (other[0], other[1], str(1 - int(ch)))])
    return MlcError(f"conflicting rows: line {l2} sets {name}={v2} but line {l1} sets {name}={v1} "
                    f"for {minterm_str(inputs, mt) or 'the only input combination'}",
                    Loc(filename, l2, c2), f"make lines {l1} and {l2} agree")


def print_table(spec: TableSpec) -> str:
    """Write a TableSpec as ``.tt`` text, one fully specified row per input combination
    (rows whose outputs are all don't care are omitted)."""
    n, m = spec.n, len(spec.outputs)
    lines = [f"# {spec.source}", ".inputs " + " ".join(spec.inputs), ".outputs " + " ".join(spec.outputs)]
    for mt in range(1 << n):
        outs = "".join("-" if v is None else str(v) for v in (spec.value(o, mt) for o in range(m)))
        if set(outs) == {"-"}:
            continue
        ins = "".join(str((mt >> i) & 1) for i in range(n))
        lines.append(f"{ins} | {outs}")
    return "\n".join(lines) + "\n"
