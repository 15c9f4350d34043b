"""mlc.io.yamlfast: the line reader of mlc's own block YAML reads what PyYAML reads, with the
same locations, or refuses.

Every comparison is against PyYAML's reader under mlc's composer and constructors
(``yamlsrc._Loader``, the pure-Python one, and libyaml's ``_CLoader``), the reader
``yamlsrc.load`` falls back to."""
from __future__ import annotations

import random

import pytest

from mlc.errors import MlcError
from mlc.io import yamlfast, yamlsrc


def _pyyaml(text, loader=yamlsrc._Loader):
    ld = loader(text, "s.yaml")
    try:
        return ld.get_single_data()
    finally:
        ld.dispose()


def _agrees(text) -> bool:
    """yamlfast refuses ``text``, or reads the data and locations PyYAML reads."""
    fast = yamlfast.parse(text, "s.yaml")
    if fast is None:
        return True
    try:
        ref = _pyyaml(text)
    except (MlcError, Exception):
        return False                                 # fast read what PyYAML refuses
    return yamlsrc.same_data(fast, ref) and yamlsrc.locations(fast) == yamlsrc.locations(ref)


def _scene_texts():
    from mlc.gates.connector import branch_scene, chain_scene
    from mlc.gates.library import gate_scene
    from mlc.scene.io import dump_scene
    return {"NAND expand": dump_scene(gate_scene("NAND", "expand")),
            "NOR contract": dump_scene(gate_scene("NOR", "contract")),
            "chain bent": dump_scene(chain_scene(3, "expand", bend=0.3)),
            "branch": dump_scene(branch_scene(3, "contract"))}


SCENES = _scene_texts()


@pytest.mark.parametrize("name", sorted(SCENES))
def test_a_scene_mlc_writes_is_read_as_pyyaml_reads_it(name):
    text = SCENES[name]
    fast = yamlfast.parse(text, "s.yaml")
    assert fast is not None, "the reader refused a scene mlc wrote"
    for loader in filter(None, (yamlsrc._Loader, yamlsrc._CLoader)):
        ref = _pyyaml(text, loader)
        assert yamlsrc.same_data(fast, ref)
        assert yamlsrc.locations(fast) == yamlsrc.locations(ref)
    assert len(yamlsrc.locations(fast)) > 100
    # and yamlsrc.load, which every reader of mlc's files calls, gives the same
    assert yamlsrc.same_data(yamlsrc.load(text, "s.yaml"), fast)


@pytest.mark.parametrize("text", [
    "a: 1\nb: -0\nc: +5\nd: 1.5\ne: 1.\nf: 1e5\ng: 1.0e5\nh: 1.0e+5\ni: -2E-3\nj: 007\nk: 0x1F\nl: 1_000\n",
    "a: yes\nb: No\nc: ON\nd: off\ne: y\nf: n\ng: ~\nh: null\ni: Null\nj: nULL\nk: true\nl: .inf\nm: .nan\n",
    "a: 'x'\nb: 'it''s'\nc: ''\nd: '000'\ne: [a, 'b, c', 1, 'd''e', yes, null]\nf: []\ng: {}\nh: [ ]\n",
    "a: b c\nb: /p/q.r\nc: a:b\nd: x-y\ne: 2001-12-14\nf: 12:30\ng: =\nh: <<\ni: a#b\nj: http://x\n",
    "a: [1, 2]  \nb: x # note\nc: [1, 2] # note\nd: 'x' \ne: [1,2]\nf: [1 , 2]\ng: [1, 2,]\nh: [1, [2]]\n",
    "l:\n- 1\n- two\n- [3]\n- k: v\n  k2: v2\n- - nested\nm:\n  - deep\n  - er\nn: last\n",
    "k:\nnext: 1\n",
    "# c\n\n  # indented comment\na:\n  b:\n    c: 1\n  d: 2\n\ne: 3\n# end\n",
    "a: 1\n  b: 2\n",
    "a: 1\n b: 2\n",
    "- a\n- b: 1\n  c: [1, 2, 3]\n-\n",
    "a: 1\na: 2\n",
    "1: one\n1.5: x\nyes: y\nnull: z\n'q': w\n",
    "a: &x 1\nb: *x\n",
    "a: !!str 1\nb: \"q\"\nc: |\n  t\nd: >\n  u\n",
    "a: 'unterminated\n  more'\n",
    "--- \na: 1\n",
    "a: 1\n...\n",
    "%YAML 1.1\n---\na: 1\n",
    "a: [1, 2,\n  3]\n",
    "\ufeffa: 1\n",
    "a:\tb\n",
    "a: 1\r\nb: 2\r\n",
    "a: " + "9" * 300 + "\nb: " + "9" * 301 + "\n",
])
def test_scalars_and_structure_agree_with_pyyaml(text):
    assert _agrees(text)


def test_what_is_read_fast_is_what_pyyaml_resolves():
    """A few cases that must be read (not refused), with the values YAML 1.1 gives."""
    d = yamlfast.parse("a: 1.0e5\nb: 1e5\nc: yes\nd: '1'\ne: [x, 2, 2.5]\nf: 0\n", "s.yaml")
    assert d == {"a": "1.0e5", "b": 1e5, "c": True, "d": "1", "e": ["x", 2, 2.5], "f": 0}
    assert type(d["f"]) is int and type(d["b"]) is float
    assert d.loc_of("e") == yamlsrc.Loc("s.yaml", 5, 4) and d["e"].loc_of(2) == yamlsrc.Loc("s.yaml", 5, 11)


def test_lists_of_long_lists_are_read():
    """A circuit's meta lists its predicted contacts as lists of five items, which the
    emitter writes as block sequences inside a block sequence (``- - w_a``): the 200-gate
    scene has them, and refusing them left its read to PyYAML."""
    text = ("meta:\n  state_contacts:\n  - - w_a\n    - 3\n    - w_b\n    - 4\n    - -0.05\n"
            "  - - w_c\n    - 1\n    - - x\n      - y\n    - k: v\n      k2: [1, 2]\n  n: 1\nbodies: []\n")
    fast = yamlfast.parse(text, "s.yaml")
    assert fast is not None and fast["meta"]["state_contacts"][1][2] == ["x", "y"]
    assert _agrees(text)


def test_nesting_deeper_than_the_limit_is_left_to_pyyaml():
    deep = "".join(" " * i + f"k{i}:\n" for i in range(yamlsrc.MAX_DEPTH + 5)) + " " * (yamlsrc.MAX_DEPTH + 5) + "v: 1\n"
    assert yamlfast.parse(deep, "s.yaml") is None
    with pytest.raises(MlcError, match="nested more than"):
        yamlsrc.load(deep, "s.yaml")


def test_random_edits_of_a_scene_are_read_as_pyyaml_reads_them_or_refused():
    """Each of 400 edits (a character that means something in YAML inserted, deleted or
    replaced at a random place in a gate's scene) is either refused by the fast reader or
    read exactly as PyYAML reads it, data and locations; PyYAML refusing what the fast
    reader accepted fails.  Some edits must be read (the reader is not refusing everything)."""
    base = SCENES["NAND expand"]
    # cut the text to its first 120 lines (PyYAML's pure-Python reader is slow) at an item boundary
    lines = base.split("\n")
    cut = next(i for i in range(120, len(lines)) if lines[i].startswith("- ") or not lines[i].startswith(" "))
    base = "\n".join(lines[:cut]) + "\n"
    rng = random.Random(7)
    chars = list(" -:#'\"[],\n{}&*!|>%.e0x1yY~") + ["  ", "- ", ": ", "\t"]
    read = 0
    for _ in range(400):
        p = rng.randrange(len(base))
        op = rng.randrange(3)
        c = rng.choice(chars)
        text = base[:p] + c + base[p:] if op == 0 else base[:p] + base[p + 1:] if op == 1 else base[:p] + c + base[p + 1:]
        assert _agrees(text), repr(text[max(0, p - 60):p + 60])
        read += yamlfast.parse(text, "s.yaml") is not None
    assert read > 40


def test_a_scene_reads_through_the_fast_reader_and_errors_keep_their_lines():
    """yamlsrc.load takes the fast reader for a scene; a scene with a wrong value still gets
    its schema error at the value's line and column."""
    from mlc.scene.io import parse_scene
    text = SCENES["NAND expand"]
    lines = text.split("\n")
    i = next(k for k, ln in enumerate(lines) if ln.startswith("  position: ["))
    lines[i] = "  position: [0.0, .nan, 0.0]"
    bad = "\n".join(lines)
    assert yamlfast.parse(bad, "s.yaml") is None           # '.nan' is left to PyYAML ...
    lines[i] = "  position: [0.0, 1.0e+400, 0.0]"
    bad = "\n".join(lines)
    assert yamlfast.parse(bad, "s.yaml") is not None       # ... an overflowing float is not
    with pytest.raises(MlcError) as e:
        parse_scene(bad, "s.yaml")
    where = _pyyaml(bad)["bodies"][0]["position"].loc_of(1)     # where PyYAML puts the item
    assert (where.line, where.col) == (i + 1, 19)
    assert str(e.value).startswith(f"{where}: bodies[0].position[1]") and "finite" in str(e.value)


def test_locations_made_when_asked_for_are_pyyamls_whichever_way_they_are_asked():
    """The fast reader keeps its locations as numbers and makes a Loc only when one is asked
    for (a big scene asks for few of its millions); every way of asking gives what PyYAML's
    reader gives: a key's or an item's location, a missing key or index (the container's),
    slices, lengths, items, values."""
    text = SCENES["branch"]
    fast, ref = yamlfast.parse(text, "s.yaml"), _pyyaml(text)
    fb, rb = fast["bodies"], ref["bodies"]
    assert fb.loc == rb.loc and fb.loc_of(1) == rb.loc_of(1) and fb.loc_of(10 ** 6) == rb.loc
    assert fb.loc_of("x") == rb.loc                         # not an index: the list's own
    assert list(fb.item_locs[1:3]) == list(rb.item_locs[1:3]) and len(fb.item_locs) == len(rb.item_locs)
    body, rbody = fb[0], rb[0]
    assert body.loc_of("position") == rbody.loc_of("position") and body.loc_of("nope") == rbody.loc
    assert dict(body.item_locs.items()) == dict(rbody.item_locs.items())
    assert list(body.item_locs.values()) == list(rbody.item_locs.values()) and list(body.item_locs) == list(rbody)
    pos, rpos = body["position"], rbody["position"]         # a flow sequence of numbers
    assert [pos.loc_of(k) for k in range(3)] == [rpos.loc_of(k) for k in range(3)]
    assert pos.item_locs[0:2] == rpos.item_locs[0:2] and len(pos.item_locs) == 3
    bond, rbond = fast["bonds"][0]["sites"], ref["bonds"][0]["sites"]     # a flow sequence of names
    assert list(bond.item_locs) == list(rbond.item_locs) and bond.loc == rbond.loc
    # what holds the data has no per-object dictionary (a scene has millions of these)
    assert not hasattr(body, "__dict__") and not hasattr(pos, "__dict__")
