"""The shipped JSON Schemas are valid draft 2020-12 and agree with mlc's own validator."""
import json
from importlib import resources

import jsonschema
import pytest

from mlc.gates.library import gate_scene
from mlc.io.schema import load_schema
from mlc.scene.io import scene_to_data


def _schemas():
    d = resources.files("mlc").joinpath("schemas")
    return sorted(f.name.split(".")[0] for f in d.iterdir() if f.name.endswith(".schema.json"))


@pytest.mark.parametrize("name", _schemas())
def test_schema_is_valid(name):
    jsonschema.Draft202012Validator.check_schema(load_schema(name))


def test_gate_scene_validates_with_jsonschema():
    data = json.loads(json.dumps(scene_to_data(gate_scene("NAND", "expand"))))
    jsonschema.validate(data, load_schema("scene"))


def test_library_files_validate_with_jsonschema():
    import yaml
    files = [f for f in resources.files("mlc.stdlib_gates").iterdir() if f.name.endswith(".yaml")]
    assert len(files) == 9, sorted(f.name for f in files)      # the 8 gates and design.yaml
    for f in files:
        data = yaml.safe_load(f.read_text("utf-8"))
        jsonschema.validate(data, load_schema("design" if f.name == "design.yaml" else "gate"))


def test_every_schema_is_found():
    # the parametrized check above passes vacuously when it finds no schema
    assert _schemas() == ["design", "gate", "netlist", "profile", "robot", "scene", "sweep"]


def _schema_cases():
    """(schema name, data) pairs of every kind mlc validates, as mlc reads them."""
    from pathlib import Path

    from mlc.front.load import load as load_spec
    from mlc.io import yamlsrc
    from mlc.pipeline import compile_spec
    from mlc.scene.io import dump_scene
    root = Path(__file__).resolve().parents[1]
    gates = resources.files("mlc.stdlib_gates")
    c = compile_spec(load_spec(str(root / "examples" / "full_adder.expr")), 2, "expand")
    return [("scene", yamlsrc.load(dump_scene(gate_scene("NOR", "contract")), "s.yaml")),
            ("robot", yamlsrc.load_file(root / "examples" / "tetris.robot.yaml")),
            ("sweep", yamlsrc.load_file(root / "examples" / "sweeps" / "fig5d.yaml")),
            ("gate", yamlsrc.load(gates.joinpath("nand.yaml").read_text("utf-8"), "nand.yaml")),
            ("design", yamlsrc.load(gates.joinpath("design.yaml").read_text("utf-8"), "design.yaml")),
            ("netlist", json.loads(json.dumps(c.netlist.to_json())))]


def _nodes(data, path=()):
    yield path
    if isinstance(data, dict):
        for k, v in data.items():
            yield from _nodes(v, path + (k,))
    elif isinstance(data, list):
        for i, v in enumerate(data):
            yield from _nodes(v, path + (i,))


def test_the_compiled_schemas_accept_exactly_what_the_checker_accepts():
    """mlc.io.schema validates with closures compiled from the schema and walks the data
    with its checker only to word an error.  On 3000 random edits of real data of every
    schema (a value replaced by one of another type or out of range, a key dropped or
    added, a list item dropped), the compiled predicate says yes exactly where the checker
    raises nothing; both kinds of outcome occur for every schema."""
    import copy
    import random

    from mlc.errors import MlcError
    from mlc.io import schema as sch
    rng = random.Random(3)
    pool = [-1, 0, 1, 2.5, 1e7, -1e7, float("inf"), float("nan"), "x", "1bad", "a.b", "", True, False,
            None, [], {}, [1, 2], [1.0, 2.0, 3.0], {"zz": 1}, "0101", "01-"]
    for name, data in _schema_cases():
        s = load_schema(name)
        ok = sch._compiled(s)
        assert ok(data), name
        paths = list(_nodes(data))
        seen = set()
        for _ in range(500):
            d = copy.deepcopy(data)
            path = rng.choice(paths)
            parent = d
            for p in path[:-1]:
                parent = parent[p]
            op = rng.randrange(4)
            if not path or op == 0 and isinstance(parent, (dict, list)):
                if path:
                    parent[path[-1]] = copy.deepcopy(rng.choice(pool))
            elif op == 1 and isinstance(parent, dict):
                del parent[path[-1]]
            elif op == 2 and isinstance(parent, dict):
                parent[rng.choice(["extra", "zz", "name", "k", "01", "k0"])] = copy.deepcopy(rng.choice(pool))
            elif op == 3 and isinstance(parent, list) and parent:
                del parent[path[-1]]
            try:
                sch._check(d, s, s, [], sch.Loc("x"))
                checked = True
            except sch._Fail:
                checked = False
            assert ok(d) == checked, (name, path, op)
            try:
                sch.validate(d, s, "x")
                assert checked
            except MlcError:
                assert not checked
            seen.add(checked)
        assert seen == {True, False}, name
