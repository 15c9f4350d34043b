"""mlc.io.yamlemit: the fast writer writes PyYAML's text, character for character, or gives way.

Compared with ``yaml.dump(data, Dumper, sort_keys=False, width=120)`` under mlc's list
representer, for both of PyYAML's emitters (pure Python and libyaml), as ``dump_scene``
called it before."""
from __future__ import annotations

import random

import pytest
import yaml

from mlc.io import yamlemit
from mlc.scene import io


def _pyyaml(data, dumper=io._PyDumper):
    return io._emit(data, dumper)


DUMPERS = [io._PyDumper] + ([io._CDumper] if yaml.__with_libyaml__ else [])


def _scenes():
    from mlc.gates.connector import branch_scene, chain_scene
    from mlc.gates.library import gate_scene
    return {"NAND expand": gate_scene("NAND", "expand"), "OR contract": gate_scene("OR", "contract"),
            "chain bent": chain_scene(2, "contract", bend=0.4), "branch": branch_scene(3, "expand")}


@pytest.mark.parametrize("name, scene", sorted(_scenes().items()))
def test_a_scene_is_written_as_pyyaml_writes_it(name, scene):
    data = io.scene_to_data(scene)
    text = yamlemit.dump(data)
    assert text is not None, "the writer gave way on a scene"
    for dumper in DUMPERS:
        assert text == _pyyaml(data, dumper)
    assert io.dump_scene(scene).endswith(text)


STRINGS = ["a", "g1_core_ab", "a_lo.in", "yes", "No", "null", "~", "", " lead", "trail ", "it's", "a: b", "a:b",
           "#x", "a #b", "a#b", "-x", "- x", "--- x", "...", "[a]", "a,b", "{x}", "1.5", "1e5", "1.0e5", "0x1F",
           "007", "12:30", "2001-12-14", "ünï", "tab\there", "line\nbreak", "x" * 130, "a b " * 40, "=",
           "<<", "?x", "? x", "!t", "&a", "*a", "%p", "@x", "`x", "|", ">", "'q'", '"q"', "a\\b", ".inf", "-.5",
           "true false", "k" * 101, "path/to/file.yaml", "w_g118_2_75_AB"]


def _random(rng, depth=0):
    r = rng.random()
    if depth > 3 or r < 0.5:
        c = rng.randrange(6)
        if c == 0:
            return rng.choice(STRINGS)
        if c == 1:
            return rng.choice([0.0, 1.0, -0.25, 1e17, 1e-5, 1 / 3, 2.5e300, float("inf"), float("-inf"),
                               float("nan"), 123456789.123, -1e-300])
        if c == 2:
            return rng.choice([0, 1, -7, 10 ** 20])
        if c == 3:
            return rng.choice([True, False])
        if c == 4:
            return None
        return rng.choice([(1, 2), 1j])                     # types PyYAML's safe dumper refuses or tags
    if r < 0.75:
        return [_random(rng, depth + 1) for _ in range(rng.choice([0, 1, 2, 4, 5, 7]))]
    return {rng.choice(STRINGS + [1, 2.5, None, True]): _random(rng, depth + 1) for _ in range(rng.randrange(4))}


def test_random_data_is_written_as_pyyaml_writes_it_or_left_to_pyyaml():
    """400 random documents of nested dicts and lists with awkward strings (quotes, colons,
    YAML 1.1 booleans, numbers as text, long lines, line breaks, non-ASCII), every float
    kind and types the safe dumper refuses: the writer's text equals both emitters' or it
    returns None.  Most documents must be written (the writer is not giving way on all)."""
    rng = random.Random(11)
    written = 0
    for _ in range(400):
        data = {"k": _random(rng), "bodies": [_random(rng) for _ in range(rng.randrange(3))]}
        text = yamlemit.dump(data)
        for dumper in DUMPERS:
            try:
                ref = _pyyaml(data, dumper)
            except yaml.YAMLError:
                ref = None
            assert text is None or text == ref, (data, dumper)
        written += text is not None
    assert written > 150
