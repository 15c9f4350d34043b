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

Locations are kept as numbers and made into :class:`~mlc.errors.Loc` objects only when
asked for (``.loc``, ``.loc_of``, ``item_locs``): a 200-gate scene has millions of them and
a reader asks for few.  Session 36 (``benchmarks/scene_read_ab.py``): that, one regular
expression for the plain scalars, the keys read once per text and the number lists of a
mapping read in place make this reader about 1.5 times faster than session 33's, with the
same data and locations.

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
    hundreds of thousands of them and reads few): a read-only list of :class:`Loc`, from
    the sequence's text ``s`` (its items separated by ``", "``) starting at 0-based column
    ``col``."""

    __slots__ = ("file", "line", "s", "col")

    def __init__(self, file: str, line: int, s: str, col: int):
        self.file, self.line, self.s, self.col = file, line, s, col

    @property
    def cols(self) -> list:
        c, out = self.col + 2, []
        for tok in self.s[1:-1].split(", "):
            out.append(c)
            c += len(tok) + 2
        return out

    def __getitem__(self, i):
        if isinstance(i, slice):
            return [Loc(self.file, self.line, c) for c in self.cols[i]]
        return Loc(self.file, self.line, self.cols[i])

    def __len__(self) -> int:
        return self.s.count(", ") + 1

    def __iter__(self):
        return (Loc(self.file, self.line, c) for c in self.cols)

    def __eq__(self, other) -> bool:
        return list(self) == list(other)

    __hash__ = None


class _SeqLocs:
    """The item locations of a block sequence, made when asked for: a read-only list of
    :class:`Loc` kept as ``(line, col)`` pairs."""

    __slots__ = ("file", "at")

    def __init__(self, file: str):
        self.file, self.at = file, []

    def __getitem__(self, i):
        if isinstance(i, slice):
            return [Loc(self.file, ln, c) for ln, c in self.at[i]]
        ln, c = self.at[i]
        return Loc(self.file, ln, c)

    def __len__(self) -> int:
        return len(self.at)

    def __iter__(self):
        return (Loc(self.file, ln, c) for ln, c in self.at)

    def __eq__(self, other) -> bool:
        return list(self) == list(other)

    __hash__ = None


class _KeyLocs:
    """The item locations of a block mapping, made when asked for: a read-only mapping
    from key to :class:`Loc`, kept as ``(line, col)`` pairs."""

    __slots__ = ("file", "at")

    def __init__(self, file: str):
        self.file, self.at = file, {}

    def get(self, key, default=None):
        v = self.at.get(key)
        return default if v is None else Loc(self.file, v[0], v[1])

    def __getitem__(self, key):
        ln, c = self.at[key]
        return Loc(self.file, ln, c)

    def __contains__(self, key) -> bool:
        return key in self.at

    def __iter__(self):
        return iter(self.at)

    def __len__(self) -> int:
        return len(self.at)

    def keys(self):
        return self.at.keys()

    def values(self) -> list:
        return [Loc(self.file, ln, c) for ln, c in self.at.values()]

    def items(self) -> list:
        return [(k, Loc(self.file, ln, c)) for k, (ln, c) in self.at.items()]

    def __eq__(self, other) -> bool:
        return hasattr(other, "items") and dict(self.items()) == dict(other.items())

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


#: the three plain scalars most lines hold, tried in _plain's order in one match: group 1 a
#: float, 2 an int, 3 a word
_SCALAR = re.compile(rf"({_FLOAT.pattern[:-2]})\Z|({_INT.pattern[:-2]})\Z|({_WORD.pattern[:-2]})\Z")
#: a flow sequence of words only (a bond's two sites): "[g1_a_lo.piv_0, g1_a_hi.piv_0]"
_WORDS = re.compile(rf"\[{_WORD.pattern[:-2]}(?:, {_WORD.pattern[:-2]})*\]\Z")
_WORD_CONSTANTS = {**_BOOL, **{k: None for k in _NULL}}


def _plain(s: str, flow: bool):
    """Value of the plain scalar ``s`` as PyYAML's SafeLoader (with mlc's resolvers) reads it."""
    m = _SCALAR.match(s)
    if m is not None:
        k = m.lastindex
        if k == 1:
            return float(s)
        if k == 2:
            return int(s)
        if s in _WORD_CONSTANTS:
            return _WORD_CONSTANTS[s]
        return s
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
    """One pass over the lines; ``self.i`` is the current line (0-based).  Locations are
    kept as plain tuples and made into :class:`Loc` only when asked for (``LocDict.loc``,
    :class:`_KeyLocs`, :class:`_SeqLocs`, :class:`_Cols`)."""

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
        self.keys: dict = {}                   # plain key text -> its value

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
        fn = self.fn
        i = self.i
        out._loc = (fn, i + 1, ind + 1)
        kl = out.item_locs = _KeyLocs(fn)
        locs = kl.at
        lines, inds = self.lines, self.ind
        key_match, inline, flow, scalar, keys = _KEY.match, self.inline, self.flow, _SCALAR.match, self.keys
        nums, LocList = _NUMS.match, self.LocList
        while True:
            if first is not None:
                content, first = first, None
            else:
                while inds[i] == -2:
                    i += 1
                if inds[i] != ind:
                    break
                content = lines[i][ind:]
            m = key_match(content)
            if m is None:
                raise _Refuse
            g1, g2 = m.groups()
            if g1 is None:
                key = keys.get(g2, keys)       # the same few keys on most lines: read once
                if key is keys:
                    key = keys[g2] = _plain(g2, False)
            else:
                key = g1.replace("''", "'")
            if key in out:
                raise _Refuse                  # PyYAML's reader names the duplicate
            e = m.end()
            if e < len(content):
                col = ind + e
                v = content[e:]
                if v[0] == "[":
                    if nums(v):                # numbers only (flow's first case, here without the call)
                        toks = v[1:-1].split(", ")
                        lst = LocList(map(float, toks)) if v.count(".") == len(toks) else LocList(
                            [float(t) if "." in t or "e" in t or "E" in t else int(t) for t in toks])
                        lst._loc = (fn, i + 1, col + 1)
                        lst.item_locs = _Cols(fn, i + 1, v, col)
                        out[key] = lst
                    else:
                        out[key] = flow(v, i, col)
                else:
                    sm = scalar(v)
                    if sm is None:
                        out[key] = inline(v, i, col)
                    else:
                        k = sm.lastindex
                        out[key] = (float(v) if k == 1 else int(v) if k == 2
                                    else _WORD_CONSTANTS[v] if v in _WORD_CONSTANTS else v)
                locs[key] = (i + 1, col + 1)
                i += 1
                continue
            i += 1
            while inds[i] == -2:
                i += 1
            sub = inds[i]
            self.i = i
            if not (sub > ind or (sub == ind and self._dash(ind))):
                raise _Refuse                  # an empty value (null): rare, let PyYAML read it
            locs[key] = (i + 1, sub + 1)
            out[key] = self.block(sub, depth + 1)
            i = self.i
        self.i = i
        return out

    def _dash(self, ind: int) -> bool:
        c = self.lines[self.i][ind:]
        return c.startswith("- ") or c == "-"

    def sequence(self, ind: int, depth: int, first: str | None = None):
        out = self.LocList()
        fn = self.fn
        out._loc = (fn, self.i + 1, ind + 1)
        sl = out.item_locs = _SeqLocs(fn)
        locs = sl.at
        lines = self.lines
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
            locs.append((self.i + 1, col + 1))
            if item.startswith("- ") or _KEY.match(item):     # a sequence or mapping begins on this line
                out.append(self.block(col, depth + 1, item))
            else:
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
            d._loc, d.item_locs = (self.fn, line + 1, col + 1), {}
            return d
        return _plain(s, False)

    def flow(self, s: str, line: int, col: int):
        out = self.LocList()
        out._loc = (self.fn, line + 1, col + 1)
        if s[-1] != "]":
            raise _Refuse                      # continued on the next line, or trailing text
        if _NUMS.match(s):                     # the common case, numbers only
            toks = s[1:-1].split(", ")
            if s.count(".") == len(toks):      # a dot in every number (one at most each): floats
                out.extend(map(float, toks))
            else:
                out.extend([float(tok) if "." in tok or "e" in tok or "E" in tok else int(tok) for tok in toks])
            out.item_locs = _Cols(self.fn, line + 1, s, col)
            return out
        if _WORDS.match(s):                    # words only (a bond's sites)
            out.extend([_WORD_CONSTANTS[tok] if tok in _WORD_CONSTANTS else tok for tok in s[1:-1].split(", ")])
            out.item_locs = _Cols(self.fn, line + 1, s, col)
            return out
        locs = out.item_locs = []
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
