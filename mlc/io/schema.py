"""Validate loaded data against the JSON Schemas shipped inside the package.

mlc ships real JSON Schema (draft 2020-12) documents, so other tools can use
them, and validates with this small implementation of the keywords those
schemas use, so that every error quotes ``file:line`` of the offending value
(the test-suite cross-checks the schemas with the ``jsonschema`` package).

Supported keywords: ``type``, ``properties``, ``required``,
``additionalProperties``, ``patternProperties``, ``items``, ``prefixItems``,
``minItems``, ``maxItems``, ``enum``, ``const``, ``minimum``, ``maximum``,
``exclusiveMinimum``, ``exclusiveMaximum``, ``maxLength``, ``pattern``, ``$ref`` (to
``#/$defs/...``), ``oneOf`` and ``anyOf`` (first branch error reported),
``description``/``title``/``$schema``/``$id``/``$comment`` (ignored).
"""
from __future__ import annotations

import json
import math
import re
from functools import lru_cache
from importlib import resources

from mlc.errors import InternalError, Loc, MlcError
from mlc.io.yamlsrc import loc_of

_TYPES = {
    "object": lambda v: isinstance(v, dict),
    "array": lambda v: isinstance(v, list),
    "string": lambda v: isinstance(v, str),
    "boolean": lambda v: isinstance(v, bool),
    "integer": lambda v: isinstance(v, int) and not isinstance(v, bool),
    "number": lambda v: isinstance(v, (int, float)) and not isinstance(v, bool),
    "null": lambda v: v is None,
}


@lru_cache(maxsize=None)
def load_schema(name: str) -> dict:
    """Load ``mlc/schemas/<name>.schema.json`` from the installed package."""
    text = resources.files("mlc").joinpath("schemas", f"{name}.schema.json").read_text("utf-8")
    return json.loads(text)


def _path_str(path) -> str:
    return "".join(f"[{p}]" if isinstance(p, int) else f".{p}" for p in path).lstrip(".") or "(top level)"


class _Fail(Exception):
    def __init__(self, msg, loc, path, fix=None):
        self.msg, self.loc, self.path, self.fix = msg, loc, path, fix


def validate(data, schema: dict, filename: str = "<input>") -> None:
    """Raise :class:`MlcError` at ``file:line`` if ``data`` does not match ``schema``.

    The data is first checked by the schema compiled into closures (:func:`_compiled`,
    which only says yes or no, about three times faster on a circuit's scene,
    benchmarks/results/scene_io.json); only data it
    refuses is walked again by :func:`_check`, which finds and words the first error."""
    root = schema
    if _compiled(schema)(data):
        return
    try:
        _check(data, schema, root, [], getattr(data, "loc", None) or Loc(filename))
    except _Fail as f:
        raise MlcError(f"{_path_str(f.path)}: {f.msg}", f.loc, f.fix) from None


def _check(v, s, root, path, loc):
    if "$ref" in s:
        ref = s["$ref"]
        if not ref.startswith("#/$defs/"):
            raise InternalError(f"unsupported $ref {ref}")
        _check(v, root["$defs"][ref[len("#/$defs/"):]], root, path, loc)
    if "type" in s:
        types = s["type"] if isinstance(s["type"], list) else [s["type"]]
        if not any(_TYPES[t](v) for t in types):
            raise _Fail(f"expected {' or '.join(types)}, got {_describe(v)}", loc, path, _type_fix(v, types, s))
    if isinstance(v, (int, float)) and not isinstance(v, bool):
        hint = s.get("description")
        if not math.isfinite(v):
            raise _Fail(f"expected a finite number, got {v}", loc, path, hint)
        if "minimum" in s and v < s["minimum"]:
            raise _Fail(f"must be >= {s['minimum']:g}, got {v:g}", loc, path, hint)
        if "maximum" in s and v > s["maximum"]:
            raise _Fail(f"must be <= {s['maximum']:g}, got {v:g}", loc, path, hint)
        if "exclusiveMinimum" in s and v <= s["exclusiveMinimum"]:
            raise _Fail(f"must be > {s['exclusiveMinimum']:g}, got {v:g}", loc, path, hint)
        if "exclusiveMaximum" in s and v >= s["exclusiveMaximum"]:
            raise _Fail(f"must be < {s['exclusiveMaximum']:g}, got {v:g}", loc, path, hint)
    if "enum" in s and v not in s["enum"]:
        raise _Fail(f"must be one of {', '.join(map(repr, s['enum']))}, got {v!r}", loc, path)
    if "const" in s and v != s["const"]:
        raise _Fail(f"must be {s['const']!r}, got {v!r}", loc, path)
    if isinstance(v, str) and "maxLength" in s and len(v) > s["maxLength"]:
        raise _Fail(f"a string of {len(v)} characters (at most {s['maxLength']})", loc, path, s.get("description"))
    if isinstance(v, str) and "pattern" in s and not re.search(s["pattern"], v):
        raise _Fail(f"{v!r} does not match the pattern {s['pattern']}", loc, path)
    if isinstance(v, dict):
        for key in s.get("required", []):
            if key not in v:
                raise _Fail(f"missing required key {key!r}", loc, path)
        props = s.get("properties", {})
        pats = s.get("patternProperties", {})
        addl = s.get("additionalProperties", True)
        for key, item in v.items():
            iloc = loc_of(v, key) or loc
            sub = path + [key]
            if key in props:
                _check(item, props[key], root, sub, iloc)
                continue
            matched = False
            for pat, ps in pats.items():
                if re.search(pat, str(key)):
                    matched = True
                    _check(item, ps, root, sub, iloc)
            if matched:
                continue
            if addl is False:
                allowed = ", ".join(sorted(props)) or "none"
                raise _Fail(f"unknown key {key!r} (allowed: {allowed})", iloc, path)
            if isinstance(addl, dict):
                _check(item, addl, root, sub, iloc)
    if isinstance(v, list):
        if "minItems" in s and len(v) < s["minItems"]:
            raise _Fail(f"expected at least {s['minItems']} item{'' if s['minItems'] == 1 else 's'}, got {len(v)}",
                        loc, path, s.get("description"))
        if "maxItems" in s and len(v) > s["maxItems"]:
            raise _Fail(f"expected at most {s['maxItems']} items, got {len(v)}", loc, path)
        prefix = s.get("prefixItems", [])
        for i, item in enumerate(v):
            iloc = loc_of(v, i) or loc
            if i < len(prefix):
                _check(item, prefix[i], root, path + [i], iloc)
            elif "items" in s and s["items"] is not False:
                _check(item, s["items"], root, path + [i], iloc)
    for key in ("oneOf", "anyOf"):
        if key in s:
            first = None
            for branch in s[key]:
                try:
                    _check(v, branch, root, path, loc)
                    break
                except _Fail as f:
                    first = first or f
            else:
                raise first


def _type_fix(v, types, s) -> str | None:
    """A hint for a value of the wrong type: a quoted number, or what the value means."""
    if isinstance(v, str) and ("number" in types or "integer" in types):
        try:
            float(v)
        except ValueError:
            return s.get("description")
        return f"write the number without quotes, e.g. {float(v)!r}"
    return s.get("description")


def _describe(v) -> str:
    if isinstance(v, bool):
        return f"boolean {v}"
    if v is None:
        return "null"
    if isinstance(v, dict):
        return "a mapping"
    if isinstance(v, list):
        return "a list"
    return f"{type(v).__name__} {v!r}"


_COMPILED: dict = {}


def _compiled(schema: dict):
    """``schema`` as one predicate ``ok(data)``, True exactly where :func:`_check` raises
    nothing (the same keywords in the same meaning; cached per schema object)."""
    fn = _COMPILED.get(id(schema))
    if fn is None or fn[0] is not schema:
        fn = _COMPILED[id(schema)] = (schema, _compile(schema, schema, {}))
    return fn[1]


def _compile(s: dict, root: dict, done: dict):
    """The predicate of subschema ``s`` (``done``: the predicates made so far, by id, so
    that a recursive ``$ref`` ends)."""
    if id(s) in done:
        cell = done[id(s)]
        return cell[0] if cell[0] is not None else (lambda v: cell[0](v))    # recursion: late bound
    cell = [None]
    done[id(s)] = cell
    fused = _fused(s)
    if fused is not None:
        cell[0] = fused
        return fused
    checks = []
    if "$ref" in s:
        ref = s["$ref"]
        if not ref.startswith("#/$defs/"):
            raise InternalError(f"unsupported $ref {ref}")
        checks.append(_compile(root["$defs"][ref[len("#/$defs/"):]], root, done))
    if "type" in s:
        preds = [_TYPES[t] for t in (s["type"] if isinstance(s["type"], list) else [s["type"]])]
        if len(preds) == 1:
            checks.append(preds[0])
        else:
            checks.append(lambda v: any(p(v) for p in preds))
    bounded = _bounded(*(s.get(k) for k in _BOUNDS))

    def number(v):              # a number must be finite and within the bounds; anything else passes
        return not isinstance(v, (int, float)) or isinstance(v, bool) or bounded(v)
    types = s.get("type")
    types = set(types if isinstance(types, list) else [types]) if types is not None else None
    pure_ref = "$ref" in s and not set(s) - {"$ref"} - _NOTES
    if not pure_ref and (types is None or types & {"number", "integer"}):
        checks.append(number)               # else the type or the $ref's own predicate decides it
    if "enum" in s:
        enum = s["enum"]
        checks.append(lambda v: v in enum)
    if "const" in s:
        const = s["const"]
        checks.append(lambda v: not (v != const))
    if "maxLength" in s:
        n_max = s["maxLength"]
        checks.append(lambda v: not isinstance(v, str) or len(v) <= n_max)
    if "pattern" in s:
        pat = re.compile(s["pattern"])
        checks.append(lambda v: not isinstance(v, str) or pat.search(v) is not None)
    if any(k in s for k in ("required", "properties", "patternProperties", "additionalProperties")):
        checks.append(_compile_object(s, root, done))
    if any(k in s for k in ("minItems", "maxItems", "prefixItems", "items")):
        checks.append(_compile_array(s, root, done))
    for key in ("oneOf", "anyOf"):
        if key in s:
            branches = [_compile(b, root, done) for b in s[key]]
            checks.append(lambda v, branches=branches: any(b(v) for b in branches))
    fn = checks[0]
    for c in checks[1:]:
        fn = (lambda f, g: lambda v: f(v) and g(v))(fn, c)
    cell[0] = fn
    return fn


_NOTES = {"description", "title", "$comment"}
_BOUNDS = ("minimum", "maximum", "exclusiveMinimum", "exclusiveMaximum")


def _number_leaf(s: dict):
    """``(lo, hi, xlo, xhi)`` when ``s`` is ``{"type": "number"}`` with bounds at most (and
    notes), else None."""
    if s.get("type") != "number" or set(s) - {"type", *_BOUNDS} - _NOTES:
        return None
    return tuple(s.get(k) for k in _BOUNDS)


def _fused(s: dict):
    """One predicate, one call per value, for the two shapes that make up most of a scene: a
    bounded number, and an array of them with a length range (a vector); None for any other
    schema.  The same verdict as the chained checks of :func:`_compile`."""
    if s.get("type") == "array" and isinstance(s.get("items"), dict) and not set(s) - {
            "type", "items", "minItems", "maxItems"} - _NOTES:
        leaf = _number_leaf(s["items"])
        if leaf is None:
            return None
        n_min, n_max = s.get("minItems"), s.get("maxItems")
    else:
        leaf = _number_leaf(s)
        if leaf is None:
            return None
        n_min = n_max = False                # not an array
    ok_number = _bounded(*leaf)
    if n_min is False:
        return ok_number

    def ok_vector(v) -> bool:
        return (isinstance(v, list) and not (n_min is not None and len(v) < n_min or n_max is not None and len(v) > n_max)
                and all(map(ok_number, v)))
    return ok_vector


def _bounded(lo, hi, xlo, xhi):
    """The predicate "a finite number (not a bool) within these bounds" (None: no bound), for
    :func:`_compile`'s ``number`` check and the fused predicates alike."""
    isfinite = math.isfinite

    def ok(x) -> bool:
        return (isinstance(x, (int, float)) and not isinstance(x, bool) and isfinite(x)
                and not (lo is not None and x < lo or hi is not None and x > hi)
                and not (xlo is not None and x <= xlo or xhi is not None and x >= xhi))
    return ok


def _compile_object(s: dict, root: dict, done: dict):
    required = list(s.get("required", []))
    props = {k: _compile(sub, root, done) for k, sub in s.get("properties", {}).items()}
    pats = [(re.compile(p), _compile(sub, root, done)) for p, sub in s.get("patternProperties", {}).items()]
    addl = s.get("additionalProperties", True)
    extra = _compile(addl, root, done) if isinstance(addl, dict) else None

    def ok(v):
        if not isinstance(v, dict):
            return True
        for key in required:
            if key not in v:
                return False
        for key, item in v.items():
            c = props.get(key)
            if c is not None:
                if not c(item):
                    return False
                continue
            matched = False
            for pat, c in pats:
                if pat.search(str(key)):
                    matched = True
                    if not c(item):
                        return False
            if matched:
                continue
            if addl is False:
                return False
            if extra is not None and not extra(item):
                return False
        return True
    return ok


def _compile_array(s: dict, root: dict, done: dict):
    n_min, n_max = s.get("minItems"), s.get("maxItems")
    prefix = [_compile(sub, root, done) for sub in s.get("prefixItems", [])]
    items = _compile(s["items"], root, done) if "items" in s and s["items"] is not False else None

    def ok(v):
        if not isinstance(v, list):
            return True
        if n_min is not None and len(v) < n_min or n_max is not None and len(v) > n_max:
            return False
        for i, item in enumerate(v):
            if i < len(prefix):
                if not prefix[i](item):
                    return False
            elif items is not None and not items(item):
                return False
        return True
    return ok
