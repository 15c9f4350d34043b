"""A fast reader for the block YAML that mlc writes (scenes: ``mlc.scene.io.dump_scene``).

PyYAML reads a compiled circuit's scene at about 0.1 to 0.6 MB/s, even on libyaml's
parser, because its composer and constructors are Python calls per node (a 200-gate
circuit's 184 MB scene took 755 s, benchmarks/results/circuit_scaling.json).  This module
reads the subset of YAML that PyYAML's emitter writes for such data, line by line, into the
same :class:`~mlc.io.yamlsrc.LocDict`/:class:`~mlc.io.yamlsrc.LocList` with the same
source locations (``file:line:col`` of every mapping, sequence and item, as PyYAML's
marks give them), and refuses (returns None) anything else, so that
:func:`mlc.io.yamlsrc.load` reads that text with PyYAML: this reader decides nothing a
full reader would decide otherwise.

Grammar accepted (one document; indentation by spaces)::

    document  := (comment | blank)* block (comment | blank)*
    block     := mapping | sequence
    mapping   := (KEY ':' (' ' inline | NEWLINE nested))+         at one indentation
    nested    := mapping (deeper) | sequence (deeper, or at the key's indentation)
    sequence  := ('- ' (inline | KEY ':' ... | '- ' ...: the item's mapping or sequence,
                        its next lines indented 2 more))+
    inline    := '[' [item (', ' item)*] ']' | '{}' | scalar     on one line
    scalar    := 'single-quoted' | plain

* a plain scalar is an int (``-12``), a float (``0.5``, ``1.0e-05``, ``1e5``), a bool or null
  as YAML 1.1 spells them, or a string that PyYAML's own resolver (with mlc's added float
  rule, :mod:`mlc.io.yamlsrc`) reads as a string and that cannot start or end a YAML
  construct (no ``: ``, ``' #'``, leading indicator, and in a flow sequence no ``,[]{}``);
* anything else (anchors, aliases, tags, double quotes, block scalars, flow mappings with
  items, multi-line scalars or flow sequences, tabs, carriage returns, document markers,
  directives, duplicate keys, integers of more than 300 digits, nesting deeper than
  ``yamlsrc.MAX_DEPTH``) makes :func:`parse` return None.

Pure: ``parse(text, filename)`` returns plain data or None.
"""
from __future__ import annotations

import re

import yaml

from mlc.errors import Loc

_FLOAT = re.compile(r"(?:[-+]?[0-9]+\.[0-9]*(?:[eE][-+][0-9]+)?|[-+]?[0-9]+[eE][-+]?[0-9]+)\Z")
_INT = re.compile(r"[-+]?(?:0|[1-9][0-9]{0,299})\Z")
_NUM = r"(?:[-+]?[0-9]+\.[0-9]*(?:[eE][-+][0-9]+)?|[-+]?[0-9]+[eE][-+]?[0-9]+|[-+]?(?:0|[1-9][0-9]{0,299}))"
#: a flow sequence of numbers only, as the emitter writes it: "[0.5, -1, 1.0e-05]"
_NUMS = re.compile(rf"\[{_NUM}(?:, {_NUM})*\]\Z")
_WORD = re.compile(r"[A-Za-z_/][A-Za-z0-9_./-]*\Z")
#: KEY ':' at the start of a line's content: a plain key of word characters or a
#: single-quoted one, then end of line or one space and the value.
_KEY = re.compile(r"(?:'((?:[^']|'')*)'|([A-Za-z0-9_][A-Za-z0-9_./-]*)):(?: |\Z)")
_SQ = re.compile(r"'((?:[^'\n]|'')*)'\Z")
#: one item of a flow sequence and what follows it
_FLOW_ITEM = re.compile(r"('(?:[^']|'')*'|[^,\[\]{}'\"]+?) *(,|\Z) *")
_BOOL = {"yes": True, "Yes": True, "YES": True, "no": False, "No": False, "NO": False,
         "true": True, "True": True, "TRUE": True, "false": False, "False": False, "FALSE": False,
         "on": True, "On": True, "ON": True, "off": False, "Off": False, "OFF": False}
_NULL = {"~", "null", "Null", "NULL"}
_INDICATORS = set("-?:,[]{}#&*!|>'\"%@`")


class _Cols:
    """The item locations of a one-line flow sequence, made when asked for (a scene has
    hundreds of thousands of them and reads few): a read-only list of :class:`Loc`."""

    __slots__ = ("file", "line", "cols")

    def __init__(self, file: str, line: int, cols: list):
        self.file, self.line, self.cols = file, line, cols

    def __getitem__(self, i):
        if isinstance(i, slice):
            return [Loc(self.file, self.line, c) for c in self.cols[i]]
        return Loc(self.file, self.line, self.cols[i])

    def __len__(self) -> int:
        return len(self.cols)

    def __iter__(self):
        return (Loc(self.file, self.line, c) for c in self.cols)

    def __eq__(self, other) -> bool:
        return list(self) == list(other)

    __hash__ = None


class _Refuse(Exception):
    """The text leaves the subset: let PyYAML read it."""


_RESOLVER = []


def _resolver():
    """A resolver with the implicit rules of :class:`mlc.io.yamlsrc._Loader` (made once)."""
    if not _RESOLVER:
        from mlc.io.yamlsrc import _Loader
        r = _Loader.__new__(_Loader)
        yaml.resolver.BaseResolver.__init__(r)
        _RESOLVER.append(r)
    return _RESOLVER[0]


def _plain(s: str, flow: bool):
    """Value of the plain scalar ``s`` as PyYAML's SafeLoader (with mlc's resolvers) reads it."""
    if _FLOAT.match(s):
        return float(s)
    if _INT.match(s):
        return int(s)
    if _WORD.match(s):
        if s in _BOOL:
            return _BOOL[s]
        return None if s in _NULL else s
    if s in _NULL:
        return None
    if (s[0] in _INDICATORS or s[0] == " " or s[-1] in " :" or ": " in s or " #" in s
            or (flow and any(c in s for c in ",[]{}"))):
        raise _Refuse
    tag = _resolver().resolve(yaml.ScalarNode, s, (True, False))
    if tag != "tag:yaml.org,2002:str":
        raise _Refuse
    return s


class _Reader:
    def __init__(self, text: str, filename: str):
        from mlc.io.yamlsrc import MAX_DEPTH, LocDict, LocList
        self.lines = lines = text.split("\n")
        # per line: its indentation, or -2 for a blank or comment line
        self.ind = [len(ln) - len(t) if t and t[0] != "#" else -2 for ln in lines for t in (ln.lstrip(" "),)]
        self.ind.append(-1)                    # the end
        self.fn = filename
        self.max_depth = MAX_DEPTH
        self.LocDict, self.LocList = LocDict, LocList
        self.i = 0

    # -- lines ------------------------------------------------------------------------
    def indent(self) -> int:
        """Move past blank and comment lines; the indentation of the line reached (-1 at
        the end)."""
        ind, i = self.ind, self.i
        while ind[i] == -2:
            i += 1
        self.i = i
        return ind[i]

    # -- nodes --------------------------------------------------------------------------
    def block(self, ind: int, depth: int, first: str | None = None):
        """The mapping or sequence whose first line is the current one, content at column
        ``ind`` (0-based); ``first``: that line's content when it follows a ``- `` on it."""
        if depth > self.max_depth - 2:         # PyYAML counts the scalars and flow items below too
            raise _Refuse
        content = self.lines[self.i][ind:] if first is None else first
        if content.startswith("- ") or content == "-":
            return self.sequence(ind, depth, first)
        return self.mapping(ind, depth, first)

    def mapping(self, ind: int, depth: int, first: str | None = None):
        out = self.LocDict()
        out.loc = Loc(self.fn, self.i + 1, ind + 1)
        locs = out.item_locs = {}
        lines, fn = self.lines, self.fn
        while True:
            if first is not None:
                content, first = first, None
            else:
                if self.indent() != ind:
                    break
                content = lines[self.i][ind:]
            m = _KEY.match(content)
            if m is None:
                raise _Refuse
            key = m.group(1).replace("''", "'") if m.group(1) is not None else _plain(m.group(2), False)
            if key in out:
                raise _Refuse                  # PyYAML's reader names the duplicate
            rest = content[m.end():]
            if rest:
                col = ind + m.end()
                out[key] = self.inline(rest, self.i, col)
                locs[key] = Loc(fn, self.i + 1, col + 1)
                self.i += 1
                continue
            self.i += 1
            sub = self.indent()
            if not (sub > ind or (sub == ind and self._dash(ind))):
                raise _Refuse                  # an empty value (null): rare, let PyYAML read it
            locs[key] = Loc(fn, self.i + 1, sub + 1)
            out[key] = self.block(sub, depth + 1)
        return out

    def _dash(self, ind: int) -> bool:
        c = self.lines[self.i][ind:]
        return c.startswith("- ") or c == "-"

    def sequence(self, ind: int, depth: int, first: str | None = None):
        out = self.LocList()
        out.loc = Loc(self.fn, self.i + 1, ind + 1)
        locs = out.item_locs = []
        lines, fn = self.lines, self.fn
        while True:
            if first is not None:
                content, first = first, None
            else:
                if self.indent() != ind or not self._dash(ind):
                    break
                content = lines[self.i][ind:]
            if not content.startswith("- "):
                raise _Refuse                  # "-" alone: a null item
            item = content[2:]
            col = ind + 2
            if not item or item[0] == " " or item == "-":
                raise _Refuse
            if item.startswith("- ") or _KEY.match(item):     # a sequence or mapping begins on this line
                locs.append(Loc(fn, self.i + 1, col + 1))
                out.append(self.block(col, depth + 1, item))
            else:
                locs.append(Loc(fn, self.i + 1, col + 1))
                out.append(self.inline(item, self.i, col))
                self.i += 1
        return out

    def inline(self, s: str, line: int, col: int):
        """The value written on one line from column ``col`` (0-based) of line ``line``."""
        c = s[0]
        if c == "[":
            return self.flow(s, line, col)
        if c == "'":
            m = _SQ.match(s)
            if m is None:
                raise _Refuse
            return m.group(1).replace("''", "'")
        if s == "{}":
            d = self.LocDict()
            d.loc, d.item_locs = Loc(self.fn, line + 1, col + 1), {}
            return d
        return _plain(s, False)

    def flow(self, s: str, line: int, col: int):
        out = self.LocList()
        out.loc = Loc(self.fn, line + 1, col + 1)
        locs = out.item_locs = []
        if s[-1] != "]":
            raise _Refuse                      # continued on the next line, or trailing text
        if _NUMS.match(s):                     # the common case, numbers only
            c = col + 2
            cols = []
            for tok in s[1:-1].split(", "):
                out.append(float(tok) if "." in tok or "e" in tok or "E" in tok else int(tok))
                cols.append(c)
                c += len(tok) + 2
            out.item_locs = _Cols(self.fn, line + 1, cols)
            return out
        inner = s[1:-1]
        pos, n = 0, len(inner)
        while pos < n and inner[pos] == " ":
            pos += 1
        fn, row = self.fn, line + 1
        while pos < n:
            m = _FLOW_ITEM.match(inner, pos)
            if m is None:
                raise _Refuse
            tok = m.group(1)
            if tok[0] == "'":
                out.append(tok[1:-1].replace("''", "'"))
            else:
                out.append(_plain(tok, True))
            locs.append(Loc(fn, row, col + 2 + pos))
            if not m.group(2) and m.end() != n:
                raise _Refuse
            if m.group(2) and m.end() == n:
                raise _Refuse                  # a trailing comma
            pos = m.end()
        return out


def parse(text: str, filename: str = "<input>"):
    """Data of ``text`` (mappings as ``LocDict``, sequences as ``LocList``, with their
    locations) when it is in the subset of the module docstring, else None."""
    if any(c in text for c in "\t\r\x85\u2028\u2029\ufeff"):   # tabs, other line breaks, a BOM
        return None
    r = _Reader(text, filename)
    try:
        ind = r.indent()
        if ind != 0:
            return None
        head = r.lines[r.i]
        if head.startswith(("---", "...", "%")):
            return None
        data = r.block(0, 1)
        if r.indent() != -1:
            return None                        # more text after the document's block
        return data
    except (_Refuse, RecursionError):
        return None
