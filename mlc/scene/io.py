"""Scene files: YAML, format version 1 (docs/scene-format.md, mlc/schemas/scene.schema.json).

``parse_scene(text, filename)`` is pure: text in, checked :class:`Scene` out, every
error at ``file:line``.  ``scene_to_data``/``dump_scene`` give the stable text form
(fixed key order, numbers at full precision) used for golden tests: PyYAML's text, written
by :mod:`mlc.io.yamlemit` and read by :mod:`mlc.io.yamlfast` (line by line, several times
faster; either gives way to PyYAML where it cannot be sure of PyYAML's result).
"""
from __future__ import annotations

import numpy as np
import yaml

from mlc.errors import MlcError
from mlc.io import yamlemit, yamlsrc
from mlc.io.atomic import write_text
from mlc.io.schema import load_schema, validate
from mlc.scene.model import Body, Bond, Box, Muscle, Probe, Scene, check_row

FORMAT_VERSION = 1
#: Largest scene file read, in bytes: a 200-gate circuit's scene is 184 MB (docs/circuits.md,
#: "Scaling"), well over the 64 MB other YAML inputs may have; this allows some 900 gates
#: (bodies grow as gates^1.17, benchmarks/results/circuit_scaling.json).
MAX_SCENE_BYTES = 2 ** 30
_IDQ = [1.0, 0.0, 0.0, 0.0]


def parse_scene(text: str, filename: str = "<scene>") -> Scene:
    data = yamlsrc.load(text, filename, MAX_SCENE_BYTES)
    if not isinstance(data, dict):
        raise MlcError("a scene file must be a YAML mapping", filename)
    if "mlc_scene" not in data:
        raise MlcError("not an mlc scene: missing 'mlc_scene: 1'", getattr(data, "loc", filename))
    validate(data, load_schema("scene"), filename)
    return scene_from_data(data, filename)


def load_scene(path) -> Scene:
    """Read and check a scene file; a missing, unreadable, non-UTF-8, oversized or hostile file
    (alias bomb, deep nesting, huge integers) is one :class:`MlcError` at ``file[:line:col]``."""
    return parse_scene(yamlsrc.read_text(path, "scene", MAX_SCENE_BYTES), str(path))


def scene_from_data(data, filename: str = "<scene>") -> Scene:
    def loc(container, key):
        return yamlsrc.loc_of(container, key)

    bodies = []
    for i, b in enumerate(data["bodies"]):
        boxes = [Box(np.array(x["size"], float), np.array(x.get("center", [0, 0, 0]), float),
                     np.array(x.get("orientation", _IDQ), float)) for x in b["boxes"]]
        sites = {k: np.array(v, float) for k, v in (b.get("sites") or {}).items()}
        bodies.append(Body(b["name"], np.array(b["position"], float),
                           np.array(b.get("orientation", _IDQ), float), boxes, sites, loc(data["bodies"], i)))
    bonds = [Bond(x["name"], x["sites"][0], x["sites"][1], float(x.get("k", 1.0)), float(x.get("rest", 0.0)),
                  float(x.get("tolerance", 0.0)), x.get("kind", "bond"), x.get("joint"), loc(data["bonds"], i))
             for i, x in enumerate(data.get("bonds") or [])]
    muscles = [Muscle(x["name"], x["input"], x["sites"][0], x["sites"][1], float(x["rest"]),
                      float(x["actuated"]), float(x.get("k", 1.0)), loc(data["muscles"], i))
               for i, x in enumerate(data.get("muscles") or [])]
    probes = [Probe(x["name"], x["output"], x["sites"][0], x["sites"][1], float(x["rest"]),
                    float(x["actuated"]), loc(data["probes"], i))
              for i, x in enumerate(data.get("probes") or [])]
    tt = data.get("truth_table")
    for key, val in (tt or {}).items():       # each row at its line (Scene.check has no lines for them)
        check_row(str(key), str(val), len(data.get("inputs") or []), len(data.get("outputs") or []),
                  loc(tt, key) or filename)
    scene = Scene(
        name=data["name"], bodies=bodies, bonds=bonds, muscles=muscles, probes=probes,
        inputs=list(data.get("inputs") or []), outputs=list(data.get("outputs") or []),
        truth_table=dict(tt) if tt is not None else None, meta=_plain(data.get("meta") or {}),
        units={"sigma": 1.0, "k0": 1.0, "gamma": 1.0, **(data.get("units") or {})}, source=filename,
    )
    scene.check()
    driven = {m.input for m in scene.muscles}
    for i, name in enumerate(scene.inputs):      # setting such an input would move nothing
        if name not in driven:
            raise MlcError(f"input {name!r} drives no muscle: setting it would move nothing",
                           loc(data["inputs"], i) or filename,
                           f"add a muscle with 'input: {name}', or remove {name} from inputs")
    return scene


def _plain(v):
    if isinstance(v, dict):
        return {k: _plain(x) for k, x in v.items()}
    if isinstance(v, list):
        return [_plain(x) for x in v]
    return v


def _num(x) -> float:
    x = float(x)
    return 0.0 if x == 0 else x    # no "-0.0" in the text form


def _vec(v) -> list[float]:
    return [_num(x) for x in np.asarray(v, float).ravel()]


def scene_to_data(scene: Scene) -> dict:
    """The scene as plain data with a fixed key order (the stable text form)."""
    out = {"mlc_scene": FORMAT_VERSION, "name": scene.name, "units": dict(scene.units),
           "inputs": list(scene.inputs), "outputs": list(scene.outputs)}
    if scene.truth_table is not None:
        out["truth_table"] = dict(sorted(scene.truth_table.items()))
    if scene.meta:
        out["meta"] = scene.meta
    out["bodies"] = [{
        "name": b.name, "position": _vec(b.position), "orientation": _vec(b.orientation),
        "boxes": [{"size": _vec(x.size), "center": _vec(x.center), "orientation": _vec(x.orientation)}
                  for x in b.boxes],
        "sites": {k: _vec(v) for k, v in b.sites.items()},
    } for b in scene.bodies]
    out["bonds"] = []
    for x in scene.bonds:
        d = {"name": x.name, "sites": [x.a, x.b], "k": _num(x.k), "rest": _num(x.rest),
             "tolerance": _num(x.tolerance), "kind": x.kind}
        if x.joint:
            d["joint"] = x.joint
        out["bonds"].append(d)
    out["muscles"] = [{"name": m.name, "input": m.input, "sites": [m.a, m.b], "k": _num(m.k),
                       "rest": _num(m.rest), "actuated": _num(m.actuated)} for m in scene.muscles]
    out["probes"] = [{"name": p.name, "output": p.output, "sites": [p.a, p.b],
                      "rest": _num(p.rest), "actuated": _num(p.actuated)} for p in scene.probes]
    return out


class _PyDumper(yaml.SafeDumper):
    """PyYAML's pure-Python emitter."""


def _repr_list(dumper, data):
    flow = all(isinstance(x, (int, float, str)) for x in data) and len(data) <= 4
    return dumper.represent_sequence("tag:yaml.org,2002:seq", data, flow_style=flow)


_PyDumper.add_representer(list, _repr_list)
if yaml.__with_libyaml__:
    class _CDumper(yaml.CSafeDumper):
        """libyaml's emitter behind the same representers: the same text as :class:`_PyDumper`
        (tests/test_scene.py and tests/test_circuit_examples.py compare them on every gate and
        example circuit), 2.7 to 3.3 times faster (benchmarks/results/scene_io.json); a
        200-gate circuit's 184 MB scene took 13 minutes with the other."""

    _CDumper.add_representer(list, _repr_list)
    _Dumper = _CDumper
else:
    _Dumper = _PyDumper


def dump_scene(scene: Scene) -> str:
    """Stable YAML text of a scene (round-trips through :func:`parse_scene`)."""
    scene.check()
    header = ("# mlc scene, format version 1 (docs/scene-format.md).\n"
              "# Units: sigma = 1 (length), k0 = 1 (stiffness), gamma = 1 (drag).\n")
    data = scene_to_data(scene)
    text = yamlemit.dump(data)                  # PyYAML's text, written faster (mlc.io.yamlemit)
    return header + (text if text is not None else _emit(data, _Dumper))


def _emit(data: dict, dumper) -> str:
    return yaml.dump(data, Dumper=dumper, sort_keys=False, width=120)


def write_scene(scene: Scene, path) -> None:
    write_text(path, dump_scene(scene))
