"""YAML loading that remembers where every value came from, and refuses hostile input.

``load(text, filename)`` returns plain Python data in which every mapping is a
:class:`LocDict` and every sequence a :class:`LocList`.  Both behave as ``dict`` and
``list`` and also know the :class:`~mlc.errors.Loc` of themselves (``.loc``) and of
each of their items (``.loc_of(key_or_index)``), so that later validation errors
can quote ``file:line``.

Every way a file can go wrong is one :class:`~mlc.errors.MlcError` at ``file:line:col``:

* bytes that are not UTF-8 (:func:`load_file`, :func:`read_text`, or ``load`` given bytes);
* YAML syntax errors and characters YAML does not allow;
* nesting deeper than :data:`MAX_DEPTH` (PyYAML's composer recurses once per level);
* aliases that expand the document by more than :data:`MAX_ALIAS_NODES` nodes (the
  "billion laughs" bomb: nine levels of ten aliases are 10**9 nodes), or that refer to
  the node they are inside of;
* inputs larger than :data:`MAX_BYTES` (64 MB; scenes: ``mlc.scene.io.MAX_SCENE_BYTES``);
* integers too large for a float (``float(10**400)`` overflows; Python refuses to
  convert more than 4300 digits at all).

Numbers follow YAML 1.2 where YAML 1.1 is surprising: ``1e308`` and ``2E-3`` (an
exponent but no dot) are floats, not strings.
"""
from __future__ import annotations

import re

import yaml
from yaml.events import AliasEvent

from mlc.errors import Loc, MlcError

#: Deepest nesting of lists and mappings accepted (mlc's own files nest about 5 deep).
MAX_DEPTH = 100
#: Nodes that aliases may add to a document beyond the ones written out.
MAX_ALIAS_NODES = 1_000_000
#: Largest YAML input accepted, in bytes (PyYAML reads roughly 0.1 to 1 MB/s; a scene of
#: 20000 bodies is about 20 MB).
MAX_BYTES = 64 * 2 ** 20
#: Largest integer accepted (anything larger is not a finite float either).
_MAX_INT = 2 ** 1024


# LocDict and LocList: ``__slots__`` (no dictionary per object: a scene has millions of
# them) and ``loc`` a property, which :mod:`mlc.io.yamlfast` sets to a plain
# ``(file, line, col)`` tuple that becomes a Loc when first read.
def _get_loc(self) -> Loc:
    v = self._loc
    if type(v) is tuple:               # (file, line, col) from mlc.io.yamlfast: made when asked for
        v = self._loc = Loc(*v)
    return v


def _set_loc(self, v) -> None:
    self._loc = v


class LocDict(dict):
    __slots__ = ("_loc", "item_locs")
    loc = property(_get_loc, _set_loc)
    item_locs: dict

    def loc_of(self, key) -> Loc:
        return self.item_locs.get(key, self.loc)


class LocList(list):
    __slots__ = ("_loc", "item_locs")
    loc = property(_get_loc, _set_loc)
    item_locs: list

    def loc_of(self, index) -> Loc:
        try:
            return self.item_locs[index]
        except (IndexError, TypeError):
            return self.loc


def locations(data) -> list:
    """Every :class:`~mlc.errors.Loc` a loaded document records, depth first (to compare two
    loaders)."""
    out, stack = [], [data]
    while stack:
        x = stack.pop()
        if isinstance(x, dict):
            out += [x.loc, *x.item_locs.values()]
            stack.extend(reversed(list(x.values())))
        elif isinstance(x, list):
            out += [x.loc, *x.item_locs]
            stack.extend(reversed(x))
    return out


def same_data(a, b) -> bool:
    """``a`` and ``b`` equal with equal types throughout (``1 == 1.0 == True`` in Python, not
    here) and their keys in the same order (to compare two readers)."""
    if type(a) is not type(b):
        return False
    if isinstance(a, dict):
        return list(a) == list(b) and all(same_data(a[k], b[k]) for k in a)
    if isinstance(a, list):
        return len(a) == len(b) and all(same_data(x, y) for x, y in zip(a, b))
    return a == b or (a != a and b != b)


def _at(filename, mark) -> Loc:
    return Loc(filename, mark.line + 1, mark.column + 1) if mark is not None else Loc(filename)


class _Limits:
    """The composer's limits on depth and alias expansion, and the file name, for both loaders.

    It also constructs as it composes.  PyYAML composes a whole document into nodes (each
    scalar a node with two marks) before it constructs any data: a circuit scene's nodes
    take more memory than its data (benchmarks/results/scene_io.json: a read's peak is 2.3
    to 2.6 times lower this way).  Each item of a top-level list or mapping
    (a body, a bond: depth ``STREAM_DEPTH``) is therefore constructed as soon as it is
    composed, and its nodes dropped; the document's node tree keeps only the empty shell of
    each item, which the constructor then finds in its table of constructed objects.  An
    item is kept as nodes when anchors could reach into it (the document has an anchor) or
    when it is a merge key's value (``<<``), whose nodes the constructor of its parent
    reads."""

    filename = "<input>"

    def _start(self, filename: str):
        self.filename = filename
        self._depth = 0
        self._count = 0          # nodes of the document with every alias expanded
        self._written = 0        # nodes written out in the text
        self._size: dict = {}    # id(anchored node) -> expanded size of its subtree

    def compose_node(self, parent, index):
        if self.check_event(AliasEvent):
            event = self.peek_event()
            node = super().compose_node(parent, index)
            size = self._size.get(id(node))
            if size is None:
                raise MlcError(f"alias *{event.anchor} refers to a node that contains it",
                               _at(self.filename, event.start_mark), "a YAML input cannot be recursive")
            self._count += size
            if self._count - self._written > MAX_ALIAS_NODES:
                raise MlcError(f"aliases expand this document to more than {self._written + MAX_ALIAS_NODES:,} "
                               f"nodes (an alias bomb?)", _at(self.filename, event.start_mark),
                               f"aliases may add at most {MAX_ALIAS_NODES:,} nodes; write the data out")
            return node
        event = self.peek_event()
        self._depth += 1
        if self._depth > MAX_DEPTH:
            raise MlcError(f"lists and mappings nested more than {MAX_DEPTH} deep",
                           _at(self.filename, event.start_mark), "flatten the data")
        before = self._count
        self._count += 1
        self._written += 1
        try:
            node = super().compose_node(parent, index)
            if self._depth == STREAM_DEPTH and not self.anchors and not _is_merge_key(index) \
                    and isinstance(node, (yaml.MappingNode, yaml.SequenceNode)):
                self._construct_now(node)
        finally:
            self._depth -= 1
        if getattr(event, "anchor", None) is not None:
            self._size[id(node)] = self._count - before
        return node

    def _construct_now(self, node):
        """Construct ``node``'s data now, in a table of its own (no alias can reach into it),
        and keep only its empty shell and its data."""
        table, self.constructed_objects = self.constructed_objects, {}
        try:
            data = self.construct_object(node, deep=True)
        finally:
            self.constructed_objects = table
        table[node] = data
        node.value = []


#: Depth (the document's root is 1) of the nodes :class:`_Limits` constructs as it composes.
STREAM_DEPTH = 3


def _is_merge_key(index) -> bool:
    return isinstance(index, yaml.ScalarNode) and index.tag == "tag:yaml.org,2002:merge"


class _Loader(_Limits, yaml.SafeLoader):
    """SafeLoader with source locations and limits on depth, alias expansion and integers."""

    def __init__(self, stream, filename: str):
        super().__init__(stream)
        self._start(filename)


if yaml.__with_libyaml__:
    from yaml.composer import Composer
    from yaml.constructor import SafeConstructor
    from yaml.cyaml import CParser
    from yaml.resolver import Resolver

    class _CLoader(_Limits, Composer, CParser, SafeConstructor, Resolver):
        """:class:`_Loader` on libyaml's scanner and parser: the same composer (so the same
        limits), constructors and marks, 2.9 to 3.3 times faster on circuit scenes
        (benchmarks/results/scene_io.json; a 200-gate one is 184 MB).  Only for reading:
        any error is reported again by :class:`_Loader`, in its words (:func:`load`)."""

        def __init__(self, stream, filename: str):
            CParser.__init__(self, stream)
            Composer.__init__(self)
            SafeConstructor.__init__(self)
            Resolver.__init__(self)
            self._start(filename)
else:  # pragma: no cover - PyYAML built without libyaml
    _CLoader = None


def _construct_mapping(loader, node):
    loader.flatten_mapping(node)
    out = LocDict()
    out.loc = _at(loader.filename, node.start_mark)
    out.item_locs = {}
    for key_node, value_node in node.value:
        key = loader.construct_object(key_node, deep=True)
        try:
            hash(key)
        except TypeError:
            raise MlcError("mapping key is not a scalar", _at(loader.filename, key_node.start_mark)) from None
        if key in out:
            raise MlcError(f"duplicate key {key!r}", _at(loader.filename, key_node.start_mark),
                           f"first given at line {out.item_locs[key].line}")
        out[key] = loader.construct_object(value_node, deep=True)
        out.item_locs[key] = _at(loader.filename, value_node.start_mark)
    return out


def _construct_sequence(loader, node):
    out = LocList(loader.construct_object(child, deep=True) for child in node.value)
    out.loc = _at(loader.filename, node.start_mark)
    out.item_locs = [_at(loader.filename, child.start_mark) for child in node.value]
    return out


def _construct_int(loader, node):
    value = loader.construct_scalar(node)
    digits = sum(c.isdigit() for c in value)
    if digits > 400:   # int() of more than 4300 digits raises; anything over 309 digits is > 1e308
        raise MlcError(f"integer with {digits} digits is too large", _at(loader.filename, node.start_mark),
                       "numbers must be below 1.8e308")
    n = yaml.SafeLoader.construct_yaml_int(loader, node)
    if abs(n) >= _MAX_INT:
        raise MlcError(f"integer {value[:20]}{'...' if len(value) > 20 else ''} is too large",
                       _at(loader.filename, node.start_mark), "numbers must be below 1.8e308")
    return n


for _cls in (_Loader, _CLoader):
    if _cls is None:
        continue
    _cls.add_constructor(yaml.resolver.BaseResolver.DEFAULT_MAPPING_TAG, _construct_mapping)
    _cls.add_constructor(yaml.resolver.BaseResolver.DEFAULT_SEQUENCE_TAG, _construct_sequence)
    _cls.add_constructor("tag:yaml.org,2002:int", _construct_int)
    # YAML 1.2 floats that YAML 1.1 reads as strings: an exponent without a dot (1e308, -2E-3).
    _cls.add_implicit_resolver("tag:yaml.org,2002:float",
                               re.compile(r"^[-+]?[0-9][0-9_]*[eE][-+]?[0-9]+$"), list("-+0123456789"))


def decode(data: bytes, filename: str = "<input>") -> str:
    """UTF-8 bytes -> text; any other encoding is an :class:`MlcError` at the first bad byte."""
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as e:
        head = data[:e.start]
        line = head.count(b"\n") + 1
        col = len(head) - (head.rfind(b"\n") + 1) + 1
        raise MlcError(f"byte 0x{data[e.start]:02x} is not UTF-8 text", Loc(filename, line, col),
                       "save the file as UTF-8") from None


def read_text(path, what: str = "file", max_bytes: int | None = None) -> str:
    """Read a UTF-8 text file; a missing, unreadable, non-UTF-8 or larger than ``max_bytes``
    file is an :class:`MlcError`.

    ``what`` names the file in the message ("scene", "profile", ...); ``max_bytes``: default
    :data:`MAX_BYTES`."""
    max_bytes = MAX_BYTES if max_bytes is None else max_bytes
    if str(path).strip() == "":
        raise MlcError(f"empty {what} file name", None, f"give the path of a {what} file")
    try:
        with open(path, "rb") as f:
            data = f.read(max_bytes + 1)
        if len(data) > max_bytes:
            raise MlcError(f"{what} is larger than {max_bytes // 2 ** 20} MB", str(path),
                           f"mlc reads {what} files up to that size")
    except IsADirectoryError:
        raise MlcError(f"cannot read {what}: it is a directory", str(path)) from None
    except OSError as e:
        raise MlcError(f"cannot read {what}: {e.strerror}", str(path)) from None
    return decode(data, str(path))


def load(text, filename: str = "<input>", max_bytes: int | None = None):
    """Parse YAML ``text`` (str, or UTF-8 bytes) of at most ``max_bytes`` characters; every
    error is an :class:`MlcError` at ``file:line:col``; ``max_bytes``: default :data:`MAX_BYTES`."""
    max_bytes = MAX_BYTES if max_bytes is None else max_bytes
    if isinstance(text, (bytes, bytearray)):
        text = decode(bytes(text), filename)
    if len(text) > max_bytes:
        raise MlcError(f"YAML input is larger than {max_bytes // 2 ** 20} MB", Loc(filename),
                       "mlc reads YAML files up to that size")
    printable = not yaml.reader.Reader.NON_PRINTABLE.search(text)
    if printable:          # the block YAML mlc writes, read line by line (mlc.io.yamlfast)
        from mlc.io import yamlfast
        data = yamlfast.parse(text, filename)
        if data is not None:
            return data
    if _CLoader is not None and printable:
        loader = _CLoader(text, filename)
        try:
            return loader.get_single_data()
        except (yaml.YAMLError, MlcError, RecursionError):
            pass                    # reported below, in the words of the Python parser
        finally:
            loader.dispose()
    loader = None
    try:
        loader = _Loader(text, filename)
        return loader.get_single_data()
    except yaml.MarkedYAMLError as e:
        mark = e.problem_mark or e.context_mark
        raise MlcError(f"YAML syntax error: {e.problem or e.context}", _at(filename, mark)) from None
    except yaml.reader.ReaderError as e:
        pos = e.position if isinstance(e.position, int) else 0
        head = text[:pos]
        loc = Loc(filename, head.count("\n") + 1, pos - (head.rfind("\n") + 1) + 1)
        c = e.character if isinstance(e.character, int) else 0
        raise MlcError(f"character U+{c:04X} is not allowed in YAML ({e.reason})", loc,
                       f"remove it, or write it as the escape \\x{c:02x} inside double quotes") from None
    except yaml.YAMLError as e:  # pragma: no cover - other pyyaml errors carry no mark
        raise MlcError(f"YAML error: {e}", Loc(filename)) from None
    except RecursionError:  # pragma: no cover - the depth limit stops this first
        raise MlcError(f"nesting too deep (limit {MAX_DEPTH})", Loc(filename), "flatten the data") from None
    finally:
        if loader is not None:
            loader.dispose()


def load_json(text, filename: str = "<input>"):
    """Parse JSON ``text`` with the same limits as YAML: one :class:`MlcError` for a syntax error
    (``file:line:col``), nesting deeper than the interpreter can follow, or an integer too large."""
    import json

    if isinstance(text, (bytes, bytearray)):
        text = decode(bytes(text), filename)

    def parse_int(v: str) -> int:
        digits = sum(c.isdigit() for c in v)
        if digits > 400:
            raise MlcError(f"integer with {digits} digits is too large", Loc(filename), "numbers must be below 1.8e308")
        n = int(v)
        if abs(n) >= _MAX_INT:
            raise MlcError(f"integer {v[:20]}... is too large", Loc(filename), "numbers must be below 1.8e308")
        return n

    try:
        return json.loads(text, parse_int=parse_int)
    except json.JSONDecodeError as e:
        raise MlcError(f"JSON syntax error: {e.msg}", Loc(filename, e.lineno, e.colno)) from None
    except RecursionError:
        raise MlcError("lists and mappings nested too deep", Loc(filename), "flatten the data") from None


def load_file(path, what: str = "file") -> object:
    """Read and parse a YAML file; a missing, unreadable or non-UTF-8 file is an :class:`MlcError`."""
    return load(read_text(path, what), str(path))


def loc_of(container, key) -> Loc | None:
    """Location of ``container[key]`` if the container came from :func:`load`."""
    getter = getattr(container, "loc_of", None)
    return getter(key) if getter else None
