"""mlc.io.yamlsrc: items constructed as they are composed (the memory of a large scene's read).

The hostile-input tests of the same module (limits, sizes, the two parsers) are in
tests/test_cli_hostile.py, beside the commands that read YAML."""
from __future__ import annotations

import pytest

from mlc.errors import MlcError
from mlc.io import yamlsrc

LOADERS = [yamlsrc._Loader] + ([yamlsrc._CLoader] if yamlsrc._CLoader is not None else [])

SCENE_LIKE = """\
name: x
inputs: [a, b]
bodies:
- name: g1
  position: [0.0, 1.5, -2]
  sites: {p: [1, 2, 3], q: [4, 5, 6]}
- {name: g2, position: [1, 2, 3]}
meta:
  gates:
    g1: {type: AND, origin: [0, 0, 38]}
  n: 7
"""


def _whole_tree(cls, text, monkeypatch):
    """The same loader composing the whole node tree before any data (PyYAML's order)."""
    monkeypatch.setattr(yamlsrc, "STREAM_DEPTH", 0)
    data = cls(text, "s.yaml").get_single_data()
    monkeypatch.undo()
    return data


def _shells(node, depth=1):
    """The collection nodes at ``STREAM_DEPTH`` under ``node``: (depth, emptied?)."""
    out = []
    kids = [v for kv in node.value for v in kv] if node.id == "mapping" else list(node.value)
    for k in kids:
        if k.id in ("mapping", "sequence"):
            if depth + 1 == yamlsrc.STREAM_DEPTH:
                out.append(k.value == [])
            else:
                out += _shells(k, depth + 1)
    return out


@pytest.mark.parametrize("cls", LOADERS, ids=lambda c: c.__name__)
def test_items_are_constructed_as_they_are_composed(cls, monkeypatch):
    loader = cls(SCENE_LIKE, "s.yaml")
    root = loader.get_single_node()
    shells = _shells(root)
    assert len(shells) == 3 and all(shells)            # the two bodies and the gates mapping
    data = loader.construct_document(root)
    ref = _whole_tree(cls, SCENE_LIKE, monkeypatch)
    assert data == ref and yamlsrc.locations(data) == yamlsrc.locations(ref)
    assert data["bodies"][0]["sites"]["q"] == [4, 5, 6]
    assert data["bodies"][1].loc == yamlsrc.Loc("s.yaml", 7, 3)
    assert data["bodies"][0]["position"].loc_of(2) == yamlsrc.Loc("s.yaml", 5, 24)


@pytest.mark.parametrize("cls", LOADERS, ids=lambda c: c.__name__)
@pytest.mark.parametrize("text", [
    # an anchor inside an item: a later alias reaches into it, so nothing after it is dropped
    "items:\n- {a: &x [1, 2]}\n- {b: *x}\n",
    # an anchor before the items
    "base: &b {x: 1, y: [1, 2, 3]}\nitems:\n- {c: *b}\n- [*b, *b]\n",
    # a merge key's value is read from its nodes by its parent's constructor
    "m:\n  <<: {x: 1, y: 2}\n  z: 3\nn:\n  <<: [{p: 1}, {q: 2}]\n",
    # a merge inside an item
    "items:\n- {<<: {x: 1}, y: 2}\n",
])
def test_anchors_and_merges_read_as_before(cls, text, monkeypatch):
    data = cls(text, "s.yaml").get_single_data()
    ref = _whole_tree(cls, text, monkeypatch)
    assert data == ref and yamlsrc.locations(data) == yamlsrc.locations(ref)
    if "<<" in text:
        assert "<<" not in str(data)
    if "*x" in text:
        assert data["items"][1]["b"] is data["items"][0]["a"]     # one object, as aliases give


@pytest.mark.parametrize("text, where, words", [
    ("items:\n- {a: 1}\n- {a: 1, a: 2}\n", "s.yaml:3:10", "duplicate key 'a'"),
    ("items:\n- [1, 2]\n- [3, " + "9" * 401 + "]\n", "s.yaml:3:7", "too large"),
    ("items:\n- &r [1, *r]\n", "s.yaml:2:10", "refers to a node that contains it"),
])
def test_errors_inside_an_item_keep_their_place(text, where, words):
    with pytest.raises(MlcError) as e:
        yamlsrc.load(text, "s.yaml")
    assert str(e.value).startswith(where) and words in str(e.value)


def test_a_scene_reads_the_same_item_by_item(monkeypatch):
    from mlc.gates.library import gate_scene
    from mlc.scene.io import dump_scene, parse_scene
    scene_text = dump_scene(gate_scene("NAND", "expand"))
    loader = yamlsrc._CLoader or yamlsrc._Loader           # PyYAML's reader (load reads a scene
    data = loader(scene_text, "s.yaml").get_single_data()  # with mlc.io.yamlfast first)
    ref = _whole_tree(loader, scene_text, monkeypatch)
    assert data == ref and yamlsrc.locations(data) == yamlsrc.locations(ref) and len(data["bodies"]) > 2
    assert parse_scene(scene_text, "s.yaml").bodies[1].loc == ref["bodies"].loc_of(1)
