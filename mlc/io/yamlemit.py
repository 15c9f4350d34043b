"""A fast writer of the block YAML that PyYAML's emitter writes for mlc's data (scenes).

``yaml.dump`` writes a compiled circuit's scene at about 0.3 to 0.9 MB/s even with libyaml's
emitter (a 200-gate circuit's 184 MB scene took 493 s, benchmarks/results/circuit_scaling.json):
its representer and serializer are Python calls per node.  :func:`dump` writes the same text
(character for character: ``tests/test_yamlemit.py`` compares it with both of PyYAML's
emitters) for data made of dicts, lists, strings, ints, floats, bools and None, as
``yaml.dump(data, Dumper, sort_keys=False, width=120)`` writes it with mlc's list
representer (a list of at most 4 scalars in flow style, ``[a, b]``; every other list and
every dict in block style).  Where it cannot be sure of PyYAML's choice it returns None and
the caller runs ``yaml.dump``:

* a string that plain style cannot carry and single quotes cannot either (line breaks,
  characters PyYAML escapes), or a key PyYAML would not write as a simple key;
* a line longer than the width (PyYAML would fold it);
* any other type (numpy scalars, tuples, ...).

Plain or single-quoted: the choice is PyYAML's own (its dumper's resolver and ``analyze_scalar``),
cached per string, except for identifiers (``[A-Za-z_][A-Za-z0-9_.]*`` other than YAML
1.1's booleans and nulls), which are always plain.
"""
from __future__ import annotations

import re

import yaml

from mlc.io.yamlfast import _BOOL, _NULL

WIDTH = 120
_IDENT = re.compile(r"[A-Za-z_][A-Za-z0-9_.]*\Z")
_RESERVED = set(_BOOL) | _NULL         # the words YAML 1.1 reads as booleans and nulls
_STR_TAG = "tag:yaml.org,2002:str"


class _Fallback(Exception):
    """Leave this document to yaml.dump."""


class _Strings:
    """PyYAML's rendering of strings: (block, flow, key) forms, cached."""

    def __init__(self):
        self.resolver = yaml.resolver.Resolver()        # the dumper's (YAML 1.1's rules only)
        self.emitter = yaml.emitter.Emitter.__new__(yaml.emitter.Emitter)
        self.emitter.allow_unicode = False              # yaml.dump's default
        self.cache: dict = {}

    def forms(self, s: str) -> tuple:
        f = self.cache.get(s)
        if f is None:
            f = self.cache[s] = self._forms(s)
        return f

    def _forms(self, s: str) -> tuple:
        if any(not (" " <= c <= "~") for c in s):         # escapes, line breaks, non-ASCII
            return (None, None, None)
        a = self.emitter.analyze_scalar(s)
        if a.multiline:
            return (None, None, None)
        implicit = self.resolver.resolve(yaml.ScalarNode, s, (True, False)) == _STR_TAG
        quoted = "'" + s.replace("'", "''") + "'" if a.allow_single_quoted else None
        block = s if implicit and a.allow_block_plain else quoted
        flow = s if implicit and a.allow_flow_plain else quoted
        key = None if a.empty or len(s) > 100 else block
        return (block, flow, key)


_STRINGS: list = []


def _strings() -> _Strings:
    if not _STRINGS:
        _STRINGS.append(_Strings())
    return _STRINGS[0]


def _float(x: float) -> str:
    if x != x:
        return ".nan"
    if x == float("inf"):
        return ".inf"
    if x == float("-inf"):
        return "-.inf"
    v = repr(x).lower()
    if "." not in v and "e" in v:
        v = v.replace("e", ".0e", 1)
    return v


class _Writer:
    def __init__(self):
        self.out: list = []
        self.strings = _strings()

    def scalar(self, v, form: int) -> str:
        """``form``: 0 block value, 1 flow item, 2 key."""
        t = type(v)
        if t is str:
            if _IDENT.match(v) and v not in _RESERVED:
                if form == 2 and len(v) > 100:
                    raise _Fallback
                return v
            r = self.strings.forms(v)[form]
            if r is None:
                raise _Fallback
            return r
        if t is float:
            return _float(v)
        if t is bool:
            return "true" if v else "false"
        if t is int:
            return str(v)
        if v is None:
            return "null"
        raise _Fallback

    def flow(self, v) -> bool:
        """Written on one line: mlc's list representer's flow lists, and empty collections."""
        t = type(v)
        if t is list:
            return len(v) <= 4 and all(type(x) in (int, float, str, bool) for x in v)
        if t is dict:
            return not v
        return True

    def inline(self, v) -> str:
        t = type(v)
        if t is list:
            return "[" + ", ".join(self.scalar(x, 1) for x in v) + "]"
        if t is dict:
            return "{}"
        return self.scalar(v, 0)

    def mapping(self, d: dict, ind: int, lead: str) -> None:
        out = self.out
        pad = " " * ind
        for i, (k, v) in enumerate(d.items()):
            head = (lead if i == 0 else pad) + self.scalar(k, 2) + ":"
            if self.flow(v):
                out.append(head + " " + self.inline(v))
            elif type(v) is dict:
                out.append(head)
                self.mapping(v, ind + 2, " " * (ind + 2))
            elif type(v) is list:
                out.append(head)
                self.sequence(v, ind, pad)
            else:
                raise _Fallback

    def sequence(self, seq: list, ind: int, lead: str) -> None:
        out = self.out
        pad = " " * ind
        for j, v in enumerate(seq):
            head = (lead if j == 0 else pad) + "- "
            if self.flow(v):
                out.append(head + self.inline(v))
            elif type(v) is dict:
                self.mapping(v, ind + 2, head)
            elif type(v) is list:
                self.sequence(v, ind + 2, head)
            else:
                raise _Fallback


def dump(data) -> str | None:
    """The text ``yaml.dump`` writes for ``data`` (a non-empty dict), or None (module doc)."""
    if type(data) is not dict or not data:
        return None
    w = _Writer()
    try:
        w.mapping(data, 0, "")
    except (_Fallback, RecursionError):
        return None
    if any(len(line) > WIDTH for line in w.out):
        return None
    w.out.append("")
    return "\n".join(w.out)
