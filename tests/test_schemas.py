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
