"""YAML loading that remembers where every value came from.

``load(text, filename)`` returns plain Python data in which every mapping is a
:class:`LocDict` and every sequence a :class:`LocList`.  Both behave as ``dict`` and
``list`` and also know the :class:`~mlc.errors.Loc` of themselves (``.loc``) and of
each of their items (``.loc_of(key_or_index)``), so that later validation errors
can quote ``file:line``.
"""
from __future__ import annotations

import yaml

from mlc.errors import Loc, MlcError


class LocDict(dict):
    loc: Loc
    item_locs: dict

    def loc_of(self, key) -> Loc:
        return self.item_locs.get(key, self.loc)


class LocList(list):
    loc: Loc
    item_locs: list

    def loc_of(self, index) -> Loc:
        try:
            return self.item_locs[index]
        except (IndexError, TypeError):
            return self.loc


def _mark(node, filename) -> Loc:
    return Loc(filename, node.start_mark.line + 1, node.start_mark.column + 1)


def _make_loader(filename: str):
    class _Loader(yaml.SafeLoader):
        pass

    def construct_mapping(loader, node):
        loader.flatten_mapping(node)
        out = LocDict()
        out.loc = _mark(node, filename)
        out.item_locs = {}
        for key_node, value_node in node.value:
            key = loader.construct_object(key_node, deep=True)
            try:
                hash(key)
            except TypeError:
                raise MlcError("mapping key is not a scalar", _mark(key_node, filename)) from None
            if key in out:
                raise MlcError(f"duplicate key {key!r}", _mark(key_node, filename),
                               f"first given at line {out.item_locs[key].line}")
            out[key] = loader.construct_object(value_node, deep=True)
            out.item_locs[key] = _mark(value_node, filename)
        return out

    def construct_sequence(loader, node):
        out = LocList(loader.construct_object(child, deep=True) for child in node.value)
        out.loc = _mark(node, filename)
        out.item_locs = [_mark(child, filename) for child in node.value]
        return out

    _Loader.add_constructor(yaml.resolver.BaseResolver.DEFAULT_MAPPING_TAG, construct_mapping)
    _Loader.add_constructor(yaml.resolver.BaseResolver.DEFAULT_SEQUENCE_TAG, construct_sequence)
    return _Loader


def load(text: str, filename: str = "<input>"):
    """Parse YAML ``text``; syntax errors become :class:`MlcError` at ``file:line:col``."""
    try:
        return yaml.load(text, Loader=_make_loader(filename))  # noqa: S506 (SafeLoader subclass)
    except yaml.MarkedYAMLError as e:
        mark = e.problem_mark or e.context_mark
        loc = Loc(filename, mark.line + 1, mark.column + 1) if mark else Loc(filename)
        raise MlcError(f"YAML syntax error: {e.problem or e.context}", loc) from None
    except yaml.YAMLError as e:  # pragma: no cover - other pyyaml errors carry no mark
        raise MlcError(f"YAML error: {e}", Loc(filename)) from None


def load_file(path) -> object:
    """Read and parse a YAML file; a missing or unreadable file is an :class:`MlcError`."""
    try:
        with open(path, encoding="utf-8") as f:
            text = f.read()
    except OSError as e:
        raise MlcError(f"cannot read file: {e.strerror}", str(path)) from None
    return load(text, str(path))


def loc_of(container, key) -> Loc | None:
    """Location of ``container[key]`` if the container came from :func:`load`."""
    getter = getattr(container, "loc_of", None)
    return getter(key) if getter else None
