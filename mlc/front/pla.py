"""Parser for Berkeley PLA files (the espresso format, binary-valued functions).

Grammar (``#`` starts a comment that runs to the end of the line)::

    file     := { line NEWLINE }
    line     := [ keyword | cube ] [ comment ]
    keyword  := ".i" INT                    -- number of inputs (required, before any cube)
              | ".o" INT                    -- number of outputs (required, before any cube)
              | ".ilb" NAME{.i}             -- input names (default x0, x1, ...)
              | ".ob" NAME{.o}              -- output names (default f0, f1, ...)
              | ".p" INT                    -- number of cubes (optional; checked)
              | ".type" ( "f" | "fd" | "fr" | "fdr" )   -- default fd
              | ".e" | ".end"               -- end of the description (the rest is ignored)
    cube     := IN{.i} OUT{.o}              -- blanks and one "|" between the parts are ignored
    IN       := "0" | "1" | "-"
    OUT      := "0" | "1" | "-" | "~"

The first input of ``.ilb`` is the leftmost column and the least significant bit of
the minterm numbering of :class:`~mlc.spec.TableSpec`.

Meaning of an output column, by ``.type`` (as in espresso(5)):

========  ==========  ==========  ==========  ==========
char      f           fd          fr          fdr
========  ==========  ==========  ==========  ==========
``1``     ON          ON          ON          ON
``0``     --          --          OFF         OFF
``-``     --          DC          --          DC
``~``     --          --          --          --
========  ==========  ==========  ==========  ==========

For ``f`` and ``fd`` everything not in ON or DC is OFF; for ``fr`` and ``fdr`` everything
not in ON or OFF is a don't care.  A minterm in both ON and DC is a don't care (as in
espresso); a minterm in both ON and OFF is an error naming both lines.
Multiple-valued (``.mv``) and symbolic PLAs, ``.phase`` and ``.pair`` are rejected.
"""
from __future__ import annotations

import re

from mlc.errors import Loc, MlcError
from mlc.front.lines import DIRECTIVE_RE, content_lines, tokens
from mlc.front.load import MAX_TABLE_INPUTS, cube_mask, full_mask, lowest_minterm, minterm_str
from mlc.spec import TableSpec

INT_RE = re.compile(r"[0-9]+")
NAME_RE = re.compile(r"[^\s|#]+")
IN_CHARS = frozenset("01-")
OUT_CHARS = frozenset("01-~")
TYPES = {"f": (True, False, False), "fd": (True, True, False), "fr": (True, False, True),
         "fdr": (True, True, True)}                     # which of ON, DC, OFF are given
UNSUPPORTED = {"mv", "phase", "pair", "symbolic", "symbolic-output", "kiss", "label", "check"}
ENUMERATE_LIMIT = 8      # cubes with at most this many '-' are enumerated minterm by minterm


def _int_arg(filename, lineno, line, start, word):
    toks = tokens(line, start)
    if len(toks) != 1 or not INT_RE.fullmatch(toks[0][1]):
        col = toks[0][0] if toks else len(line) + 1
        raise MlcError(f".{word} takes one non-negative integer", Loc(filename, lineno, col))
    return int(toks[0][1])


def parse(text: str, filename: str = "<input>") -> TableSpec:
    """Parse a Berkeley PLA into a :class:`TableSpec`."""
    n = m = None
    lines = {}                                  # keyword -> line number
    ilb = ob = None
    ob_cols = None
    p_count = None
    ptype = "fd"
    cubes: list[tuple[int, str, str, list[int]]] = []     # (line, inputs, outputs, output columns)
    for lineno, line, stripped, indent in content_lines(text):
        where = Loc(filename, lineno, indent + 1)
        k = DIRECTIVE_RE.match(stripped)
        if k:
            word = k.group(1)
            rest = indent + k.end()
            if word in ("e", "end"):
                break
            if word in lines and word != "p":
                raise MlcError(f"second .{word} line (the first is line {lines[word]})", where)
            if word in ("i", "o", "ilb", "ob", "type") and cubes:
                raise MlcError(f".{word} after the first cube", where, "put the keywords before the cubes")
            if word == "p" and "p" in lines:
                raise MlcError(f"second .p line (the first is line {lines['p']})", where)
            lines[word] = lineno
            if word == "i":
                n = _int_arg(filename, lineno, line, rest, word)
                if n > MAX_TABLE_INPUTS:
                    raise MlcError(f"{n} inputs is too many for a PLA (at most {MAX_TABLE_INPUTS})", where,
                                   "describe larger functions as BLIF, AIGER or expressions")
            elif word == "o":
                m = _int_arg(filename, lineno, line, rest, word)
                if m == 0:
                    raise MlcError(".o must be at least 1", where)
            elif word in ("ilb", "ob"):
                toks = tokens(line, rest)
                count = n if word == "ilb" else m
                if count is None:
                    raise MlcError(f".{word} before .{'i' if word == 'ilb' else 'o'}", where)
                if len(toks) != count:
                    col = toks[count][0] if len(toks) > count else len(line) + 1
                    raise MlcError(f".{word} lists {len(toks)} names, expected {count}", Loc(filename, lineno, col))
                seen = {}
                for col, tok in toks:
                    if not NAME_RE.fullmatch(tok):
                        raise MlcError(f"invalid name {tok!r}", Loc(filename, lineno, col))
                    if tok in seen:
                        raise MlcError(f"name {tok!r} appears twice in .{word}", Loc(filename, lineno, col))
                    seen[tok] = col
                if word == "ilb":
                    ilb = [t for _, t in toks]
                else:
                    ob, ob_cols = [t for _, t in toks], [c for c, _ in toks]
            elif word == "p":
                p_count = _int_arg(filename, lineno, line, rest, word)
            elif word == "type":
                toks = tokens(line, rest)
                if len(toks) != 1 or toks[0][1] not in TYPES:
                    col = toks[0][0] if toks else len(line) + 1
                    raise MlcError(".type must be f, fd, fr or fdr", Loc(filename, lineno, col))
                ptype = toks[0][1]
            elif word in UNSUPPORTED:
                raise MlcError(f".{word} (multiple-valued or symbolic PLA) is not supported", where,
                               "mlc reads binary-valued PLAs: .i .o .ilb .ob .p .type .e")
            else:
                raise MlcError(f"unknown keyword .{word}", where, "known: .i .o .ilb .ob .p .type .e")
            continue
        if n is None or m is None:
            raise MlcError(f"cube before the .{'i' if n is None else 'o'} line", where,
                           "start the file with .i N and .o M")
        cubes.append(_cube(filename, lineno, line, n, m))
    if n is None:
        raise MlcError("no .i line", Loc(filename, 1), "start the file with .i N")
    if m is None:
        raise MlcError("no .o line", Loc(filename, lines["i"]), "add .o M after .i")
    if p_count is not None and p_count != len(cubes):
        raise MlcError(f".p says {p_count} cubes but the file has {len(cubes)}", Loc(filename, lines["p"], 1),
                       "correct the .p line or remove it")
    inputs = ilb if ilb is not None else [f"x{i}" for i in range(n)]
    outputs = ob if ob is not None else [f"f{o}" for o in range(m)]
    both = set(inputs) & set(outputs)
    if both:
        name = sorted(both)[0]
        raise MlcError(f"{name!r} is both an input and an output name",
                       Loc(filename, lines["ob"], ob_cols[outputs.index(name)]))
    give_on, give_dc, give_off = TYPES[ptype]
    char_class = {"1": "on"}
    if give_dc:
        char_class["-"] = "dc"
    if give_off:
        char_class["0"] = "off"

    # Accumulate per output and class: small cubes minterm by minterm, large ones as bit sets.
    full = full_mask(n)
    size = ((1 << n) + 7) // 8
    acc = {c: [bytearray(size) for _ in range(m)] for c in ("on", "dc", "off")}
    big = {c: [0] * m for c in ("on", "dc", "off")}
    for lineno, ins, outs, _cols in cubes:
        classes = [(o, char_class[ch]) for o, ch in enumerate(outs) if ch in char_class]
        if not classes:
            continue
        free = [i for i, ch in enumerate(ins) if ch == "-"]
        if len(free) <= ENUMERATE_LIMIT:
            base = sum(1 << i for i, ch in enumerate(ins) if ch == "1")
            for j in range(1 << len(free)):
                mt = base
                for t, i in enumerate(free):
                    if (j >> t) & 1:
                        mt |= 1 << i
                byte, bit = mt >> 3, 1 << (mt & 7)
                for o, c in classes:
                    acc[c][o][byte] |= bit
        else:
            cm = cube_mask(n, ins)
            for o, c in classes:
                big[c][o] |= cm
    sets = {c: [int.from_bytes(acc[c][o], "little") | big[c][o] for o in range(m)] for c in acc}
    on, dc, off = sets["on"], sets["dc"], sets["off"]
    for o in range(m):
        clash = on[o] & off[o] & ~dc[o]
        if clash:
            mt = lowest_minterm(clash)
            l1 = _line_of(cubes, mt, o, "1")
            l0 = _line_of(cubes, mt, o, "0")
            later, ch = (l1, "1") if l1[0] > l0[0] else (l0, "0")
            earlier = l0 if later is l1 else l1
            raise MlcError(f"conflicting cubes: line {l1[0]} puts {outputs[o]}=1 and line {l0[0]} puts "
                           f"{outputs[o]}=0 for {minterm_str(inputs, mt)}", Loc(filename, later[0], later[1]),
                           f"make lines {earlier[0]} and {later[0]} agree")
    out_dc, out_on = [], []
    for o in range(m):
        if give_off:
            d = full & ~(on[o] | off[o]) | dc[o]
        else:
            d = dc[o]
        out_dc.append(d & full)
        out_on.append(on[o] & ~d & full)
    locs = ([Loc(filename, lines["ob"], c) for c in ob_cols] if ob is not None
            else [Loc(filename, lines["o"], 1)] * m)
    return TableSpec(inputs, outputs, out_on, out_dc, filename, locs)


def _cube(filename, lineno, line, n, m):
    bar = line.find("|")
    chars = []
    for i, ch in enumerate(line):
        if ch.isspace() or i == bar:
            continue
        chars.append((i + 1, ch))
    if len(chars) != n + m:
        col = chars[n + m][0] if len(chars) > n + m else (chars[-1][0] if chars else 1)
        raise MlcError(f"cube has {len(chars)} characters, expected {n + m} (.i {n} then .o {m})",
                       Loc(filename, lineno, col))
    for k, (col, ch) in enumerate(chars):
        allowed = IN_CHARS if k < n else OUT_CHARS
        if ch not in allowed:
            part = "input" if k < n else "output"
            raise MlcError(f"unexpected character {ch!r} in the {part} part of a cube", Loc(filename, lineno, col),
                           f"{part} columns use {' '.join(sorted(allowed))}")
    ins = "".join(c for _, c in chars[:n])
    outs = "".join(c for _, c in chars[n:])
    return lineno, ins, outs, [c for c, _ in chars[n:]]


def _line_of(cubes, mt, o, ch):
    for lineno, ins, outs, cols in cubes:
        if outs[o] == ch and all(c == "-" or int(c) == (mt >> i) & 1 for i, c in enumerate(ins)):
            return lineno, cols[o]
    return 0, 0


def print_pla(spec: TableSpec) -> str:
    """Write a TableSpec as a ``.type fd`` PLA with one cube per ON or DC minterm."""
    n, m = spec.n, len(spec.outputs)
    rows = []
    for mt in range(1 << n):
        outs = "".join("1" if v == 1 else "-" if v is None else "0"
                       for v in (spec.value(o, mt) for o in range(m)))
        if set(outs) <= {"0"}:
            continue
        rows.append("".join(str((mt >> i) & 1) for i in range(n)) + " " + outs)
    head = [f".i {n}", f".o {m}", ".ilb " + " ".join(spec.inputs), ".ob " + " ".join(spec.outputs),
            ".type fd", f".p {len(rows)}"]
    return "\n".join(head + rows + [".e"]) + "\n"
