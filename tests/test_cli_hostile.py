"""Hostile inputs through the CLI (issue 14): bad output paths, hostile YAML, broken mesh
files, extreme parameters, closed or full standard output.

Every case must end in one clear line on stderr (``mlc: error: ...`` naming the file or
option), a non-zero exit, no traceback, and nothing written: the output directory holds
exactly what it held before (no partial file, no staging leftovers).  Commands run
in-process through ``mlc.cli.main``; only the standard-output cases need a subprocess.
"""
import json
import os
import random
import struct
import subprocess
import sys
from pathlib import Path

import pytest

from mlc.cli import main
from mlc.errors import MlcError
from mlc.io import yamlsrc
from mlc.io.outputs import Outputs

ROOT = Path(__file__).resolve().parents[1]


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out = capsys.readouterr()
    return code, out.out, out.err


def listing(d: Path) -> dict:
    return {str(p.relative_to(d)): p.read_bytes() for p in sorted(d.rglob("*")) if p.is_file()}


def assert_clean_failure(code, err, before, d, *words):
    """Exit 2, one line starting 'mlc: error:', containing ``words``, and ``d`` unchanged."""
    assert code == 2, err
    assert err.startswith("mlc: error: ") and err.count("\n") == 1, err
    assert "Traceback" not in err
    for w in words:
        assert w in err, (w, err)
    assert listing(d) == before, "something was written"


def tetra_stl() -> bytes:
    """A binary STL of one tetrahedron (4 triangles)."""
    v = [(0, 0, 0), (10, 0, 0), (0, 10, 0), (0, 0, 10)]
    tris = [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)]
    body = b"".join(struct.pack("<12fH", 0, 0, 0, *v[a], *v[b], *v[c], 0) for a, b, c in tris)
    return b"\0" * 80 + struct.pack("<I", len(tris)) + body


@pytest.fixture(scope="module")
def scene_text():
    from mlc.gates.library import gate_scene
    from mlc.scene.io import dump_scene
    return dump_scene(gate_scene("NAND", "expand"))


# ---------------------------------------------------------------------------------------
# hostile YAML: one file:line error from yamlsrc, for every loader (scene via `draw`)
# ---------------------------------------------------------------------------------------

def _bomb(levels=9, width=10):
    s = "meta:\n  l0: &l0 [" + ", ".join(["lol"] * width) + "]\n"
    for i in range(1, levels):
        s += f"  l{i}: &l{i} [" + ", ".join([f"*l{i - 1}"] * width) + "]\n"
    return s


def _insert_meta(scene_text, block: str) -> str:
    """Put ``block`` (a `meta:` mapping) in place of the scene's meta mapping."""
    head, rest = scene_text.split("\nmeta:\n", 1)
    lines = rest.splitlines(keepends=True)
    i = next(k for k, l in enumerate(lines) if not l.startswith(" "))
    return head + "\n" + block + "".join(lines[i:])


HOSTILE = {
    # name: (text maker, words expected in the error)
    "alias_bomb": (lambda t: _insert_meta(t, _bomb()), ["alias", "1,000,000"]),
    "recursive_alias": (lambda t: _insert_meta(t, "meta:\n  r: &r [1, *r]\n"), ["refers to a node that contains it"]),
    "deep_lists": (lambda t: _insert_meta(t, "meta:\n  d: " + "[" * 5000 + "]" * 5000 + "\n"), ["nested more than"]),
    "deep_maps": (lambda t: _insert_meta(t, "meta:\n  d: " + "{a: " * 3000 + "1" + "}" * 3000 + "\n"),
                  ["nested more than"]),
    "int_5000_digits": (lambda t: _insert_meta(t, "meta:\n  n: " + "7" * 5000 + "\n"), ["5000 digits"]),
    "int_over_float": (lambda t: _insert_meta(t, "meta:\n  n: 1" + "0" * 330 + "\n"), ["too large"]),
    "hex_int_huge": (lambda t: _insert_meta(t, "meta:\n  n: 0x" + "f" * 300 + "\n"), ["too large"]),
    "float_overflow": (lambda t: t.replace("  k: 1.0", "  k: 1e400", 1), ["finite"]),
    "nan": (lambda t: t.replace("  k: 1.0", "  k: .nan", 1), ["finite"]),
    "control_char": (lambda t: t.replace("name: NAND_expand", "name: NAND\x07", 1), ["U+0007"]),
    "tab_indent": (lambda t: t.replace("\n  sigma:", "\n\tsigma:", 1), ["YAML syntax error"]),
    "two_documents": (lambda t: t + "---\nmlc_scene: 1\n", ["YAML syntax error"]),
    "duplicate_key": (lambda t: t.replace("name: NAND_expand\n", "name: a\nname: b\n", 1), ["duplicate key"]),
    "not_a_mapping": (lambda t: "- 1\n- 2\n", ["mapping"]),
    "empty": (lambda t: "", ["mapping"]),
    "python_tag": (lambda t: t.replace("name: NAND_expand", "name: !!python/object:os.system x", 1),
                   ["YAML syntax error"]),
}


@pytest.mark.parametrize("case", sorted(HOSTILE))
def test_hostile_scene_yaml_through_draw(case, scene_text, tmp_path, capsys):
    make, words = HOSTILE[case]
    src = tmp_path / "in" / f"{case}.yaml"
    src.parent.mkdir()
    src.write_text(make(scene_text), encoding="utf-8")
    out = tmp_path / "out"
    out.mkdir()
    before = listing(out)
    code, _, err = run(capsys, "draw", src, "-o", out / "x.png")
    assert_clean_failure(code, err, before, out, f"{src}", *words)
    if case not in ("not_a_mapping", "empty"):
        assert f"{src}:" in err and err.split(f"{src}:")[1][0].isdigit(), err   # file:line


def test_non_utf8_scene_gives_line_and_column(scene_text, tmp_path, capsys):
    src = tmp_path / "latin1.yaml"
    src.write_bytes(scene_text.replace("name: NAND_expand", "name: NAND_\xe9", 1).encode("latin-1"))
    line = 1 + scene_text.split("name: NAND_expand")[0].count("\n")
    before = listing(tmp_path)
    code, _, err = run(capsys, "draw", src, "-o", tmp_path / "x.png")
    assert_clean_failure(code, err, before, tmp_path, f"{src}:{line}:12:", "0xe9", "UTF-8")
    # every loader that reads a scene file gets the same answer (simulate reads it itself)
    code, _, err = run(capsys, "simulate", src, "--time", "1")
    assert_clean_failure(code, err, before, tmp_path, f"{src}:{line}:12:", "0xe9")


def test_draw_refuses_a_scene_too_large_to_draw(scene_text, tmp_path, capsys):
    """A body 1e300 sigma away: refused by the scene format's coordinate bound (1e6 sigma), at file:line."""
    import re
    src = tmp_path / "far.yaml"
    src.write_text(re.sub(r"position: \[[^\]]*\]", "position: [1e300, 0, 0]", scene_text, count=1))
    before = listing(tmp_path)
    code, _, err = run(capsys, "draw", src, "-o", tmp_path / "x.png")
    assert_clean_failure(code, err, before, tmp_path, f"{src}:", "must be <= 1e+06, got 1e+300")


@pytest.mark.parametrize("old,new,words", [
    # every number of a scene has a sane range, and the error says what the value means
    (r"position: \[[^,]*,", "position: [1e300,", ["position[0]", "must be <= 1e+06", "coordinate in sigma"]),
    ("  k: 1.0", "  k: 1e308", ["k: must be <= 1e+06", "stiffness in k0/sigma^2"]),
    ("  actuated: 1.5", "  actuated: 1e308", ["actuated: must be <= 1000", "length in sigma"]),
    ("  rest: 1.0", "  rest: 5e3", ["rest: must be <= 1000"]),
    ("  tolerance: 0.0", "  tolerance: 1e9", ["tolerance: must be <= 1000", "flat-bottom"]),
    (r"size: \[[^,]*,", "size: [2e4,", ["size[0]: must be <= 10000", "edge length in sigma"]),
    ("  k: 1.0", "  k: '1.5'", ["expected number, got str", "without quotes, e.g. 1.5"]),
])
def test_scene_numbers_have_ranges_with_a_hint(old, new, words, scene_text, tmp_path, capsys):
    import re
    src = tmp_path / "s.yaml"
    text = re.sub(old if old.startswith(("position", "size")) else re.escape(old), new, scene_text, count=1)
    assert text != scene_text
    src.write_text(text)
    before = listing(tmp_path)
    code, _, err = run(capsys, "simulate", src, "--time", "1", "--out", tmp_path / "t.gsd")
    assert_clean_failure(code, err, before, tmp_path, f"{src}:", *words)


def test_yaml_1_2_floats_without_a_dot_are_numbers(scene_text):
    from mlc.scene.io import parse_scene
    s = parse_scene(scene_text.replace("  k: 1.0", "  k: 1e3", 1).replace("  k: 1.0", "  k: 2E-1", 1), "f.yaml")
    assert [b.k for b in s.bonds[:2]] == [1000.0, 0.2]
    assert yamlsrc.load("a: 1e308\nb: -2e-3\nc: +5E2\nd: 1e\ne: e5\n") == \
        {"a": 1e308, "b": -0.002, "c": 500.0, "d": "1e", "e": "e5"}


def test_alias_limit_allows_ordinary_reuse():
    # anchors used for reuse (not a bomb) still load, and share the value
    d = yamlsrc.load("base: &b {x: 1, y: [1, 2, 3]}\n" + "".join(f"k{i}: *b\n" for i in range(1000)))
    assert len(d) == 1001 and d["k999"]["y"] == [1, 2, 3]
    # a bomb just over the limit fails, at the line of the alias that crossed it
    with pytest.raises(MlcError) as e:
        yamlsrc.load(_bomb(levels=7, width=10), "b.yaml")      # 10**7 nodes
    assert str(e.value).startswith("b.yaml:7:")


@pytest.mark.skipif(not yamlsrc.yaml.__with_libyaml__, reason="PyYAML built without libyaml")
def test_libyaml_reads_what_the_python_loader_reads_and_errors_keep_its_words(scene_text, monkeypatch):
    text = scene_text + "extra: [1e308, 0x1f, -2E-3, ~, yes, '1']\n"
    fast = yamlsrc._CLoader(text, "s.yaml").get_single_data()
    slow = yamlsrc._Loader(text, "s.yaml").get_single_data()
    locs = yamlsrc.locations(fast)
    assert fast == slow and locs == yamlsrc.locations(slow) and len(locs) > 100
    assert locs[0] == yamlsrc.Loc("s.yaml", 3, 1) and len(set(locs)) > 100      # distinct places, after the header
    assert fast["extra"] == [1e308, 31, -2e-3, None, True, "1"]
    calls = []

    class Python(yamlsrc._Loader):
        def __init__(self, *a):
            calls.append(a[1])
            super().__init__(*a)
    monkeypatch.setattr(yamlsrc, "_Loader", Python)
    assert yamlsrc.load(text, "s.yaml") == slow and calls == []      # a good file: libyaml's parser only
    with pytest.raises(MlcError) as e:                                 # a bad one: the Python parser's words
        yamlsrc.load("a: [1, 2\nb: 3\n", "bad.yaml")
    assert calls == ["bad.yaml"] and str(e.value).startswith("bad.yaml:2:") and "expected ',' or ']'" in str(e.value)
    with pytest.raises(MlcError, match="duplicate key 'a'"):
        yamlsrc.load("a: 1\na: 2\n", "dup.yaml")
    assert calls == ["bad.yaml", "dup.yaml"]


def test_yaml_size_limit(scene_text, tmp_path, monkeypatch, capsys):
    from mlc.scene import io
    assert io.MAX_SCENE_BYTES > 184 * 2 ** 20 > yamlsrc.MAX_BYTES    # a 200-gate circuit's scene loads
    src = tmp_path / "s.yaml"
    src.write_text(scene_text)
    monkeypatch.setattr(io, "MAX_SCENE_BYTES", len(scene_text.encode()) - 1)   # one byte too many
    before = listing(tmp_path)
    code, _, err = run(capsys, "draw", src, "-o", tmp_path / "x.png")
    assert_clean_failure(code, err, before, tmp_path, str(src), "larger than")
    with pytest.raises(MlcError, match="larger than"):
        io.parse_scene(scene_text, "s.yaml")
    monkeypatch.setattr(io, "MAX_SCENE_BYTES", len(scene_text.encode()))
    assert io.load_scene(src).name == io.parse_scene(scene_text).name
    monkeypatch.setattr(yamlsrc, "MAX_BYTES", len(scene_text.encode()) - 1)   # other YAML: their own limit
    with pytest.raises(MlcError, match="larger than"):
        yamlsrc.read_text(src)
    monkeypatch.setattr(yamlsrc, "MAX_BYTES", len(scene_text.encode()))
    assert yamlsrc.read_text(src) == scene_text


def test_yaml_fuzz_only_mlc_errors(scene_text):
    """Seeded random damage to a valid scene: parse to a Scene or raise MlcError, nothing else."""
    from mlc.scene.io import parse_scene
    rng = random.Random(14)
    lines = scene_text.splitlines(keepends=True)
    values = ["-1", "0", "1e308", "1e400", ".nan", "-.inf", "null", "[]", "{}", "'x'", "9" * 400, "true",
              "[1e308, 1e308, 1e308]", "0x10", "*nope", "&a", "!!binary AAAA", "2001-12-14", "[[[[1]]]]"]
    errors = 0
    for i in range(60):
        kind = i % 4
        if kind == 0:          # a value replaced by a hostile one
            j = rng.randrange(len(lines))
            l = lines[j]
            k = l.find(":")
            l = (l[:k + 1] + " " + rng.choice(values) + "\n") if k >= 0 else rng.choice(values) + "\n"
            text = "".join(lines[:j] + [l] + lines[j + 1:])
        elif kind == 1:        # truncated
            text = scene_text[:rng.randrange(len(scene_text))]
        elif kind == 2:        # random bytes
            b = bytearray(scene_text.encode())
            for _ in range(3):
                b[rng.randrange(len(b))] = rng.randrange(256)
            text = bytes(b)
        else:                  # a line duplicated somewhere else
            j, k = rng.randrange(len(lines)), rng.randrange(len(lines))
            text = "".join(lines[:j] + [lines[k]] + lines[j:])
        try:
            parse_scene(text, "fuzz.yaml")
        except MlcError as e:
            errors += 1
            assert str(e).startswith("fuzz.yaml"), str(e)
    assert errors >= 30        # the damage is real: most mutants are refused


# ---------------------------------------------------------------------------------------
# output paths: checked before the work, all or nothing
# ---------------------------------------------------------------------------------------

@pytest.fixture
def mesh(tmp_path):
    p = tmp_path / "src" / "tetra.stl"
    p.parent.mkdir()
    p.write_bytes(tetra_stl())
    return p


def test_draw_mesh_writes_png(mesh, tmp_path, capsys):
    png = tmp_path / "t.png"
    code, out, err = run(capsys, "draw", "--mesh", mesh, "-o", png)
    assert code == 0 and png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and out == f"wrote {png}\n"
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".mlc-")]


BAD_OUTPUTS = {
    # name: (output path maker, words)
    "is_directory": (lambda d: d, ["is a directory"]),
    "missing_directory": (lambda d: d / "no" / "x.png", ["does not exist", "create it first"]),
    "read_only_fs": (lambda d: Path("/proc/mlc-test.png"), ["cannot write in /proc"]),
    "jpg_name": (lambda d: d / "x.jpg", ["must end in .png"]),
    "no_suffix": (lambda d: d / "x", ["must end in .png"]),
    "dev_full": (lambda d: Path("/dev/full"), ["No space left"]),
    "empty": (lambda d: "", ["empty output path"]),
    "parent_is_file": (lambda d: d / "f.txt" / "x.png", ["not a directory"]),
}


@pytest.mark.parametrize("case", sorted(BAD_OUTPUTS))
def test_draw_bad_output(case, mesh, tmp_path, capsys):
    out = tmp_path / "out"
    out.mkdir()
    (out / "f.txt").write_text("keep")
    before = listing(out)
    make, words = BAD_OUTPUTS[case]
    code, _, err = run(capsys, "draw", "--mesh", mesh, "-o", make(out))
    assert_clean_failure(code, err, before, out, "-o", *words)


@pytest.mark.parametrize("argv,words", [
    (["--plot", "{d}/a.png", "--data", "{d}/a.png"], ["must end in .json"]),
    (["--plot", "{d}/a.png", "--data", "{d}/sub/a.json"], ["--data", "does not exist"]),
    (["--plot", "/proc/fig.png"], ["--plot", "cannot write in /proc"]),
    (["--data", "{d}"], ["--data", "is a directory"]),
    (["--plot", "{d}/a.jpg"], ["--plot", "must end in .png"]),
    (["--plot", "{d}/a.png", "--din", "5"], ["accessible range"]),
    (["--plot", "{d}/a.png", "--din", "nan"], ["din"]),
])
def test_core_outputs_checked_before_the_work(argv, words, tmp_path, capsys):
    """Each fails at once (the design space takes ~30 s): the checks come first."""
    before = listing(tmp_path)
    code, _, err = run(capsys, "core", *[a.format(d=tmp_path) for a in argv])
    assert_clean_failure(code, err, before, tmp_path, *words)


def test_outputs_all_or_nothing(tmp_path):
    d = tmp_path
    (d / "old.json").write_text("old")
    # an exception during the work: nothing written, the old file kept, no staging left
    outs = Outputs()
    a = outs.file(d / "a.png", "--a")
    b = outs.file(d / "old.json", "--b")
    with pytest.raises(KeyboardInterrupt):
        with outs:
            a.write_bytes(b"A")
            b.write_text("new")
            raise KeyboardInterrupt
    assert listing(d) == {"old.json": b"old"}
    # a move that fails half way (the second target became a directory after the checks):
    # the first file is taken back and the overwritten one restored
    outs = Outputs()
    a = outs.file(d / "old.json", "--a")
    b = outs.file(d / "b.png", "--b")
    with pytest.raises(MlcError) as e:
        with outs:
            a.write_text("new")
            b.write_bytes(b"B")
            (d / "b.png").mkdir()
            (d / "b.png" / "x").write_text("blocks the rename")
    assert "--b" in str(e.value)
    assert listing(d) == {"old.json": b"old", "b.png/x": b"blocks the rename"}
    assert not [p for p in d.iterdir() if p.name.startswith(".mlc-")]


def test_outputs_directory_and_duplicates(tmp_path):
    inp = tmp_path / "scene.yaml"
    inp.write_text("x")
    with pytest.raises(MlcError, match="is an input"):
        o = Outputs(inputs=[inp])
        o.file(tmp_path / "." / "scene.yaml", "-o")
        o.check()
    with pytest.raises(MlcError, match="also the output of -o"):
        o = Outputs()
        o.file(tmp_path / "x.json", "-o")
        o.file(tmp_path / "sub" / ".." / "x.json", "--report", parents=True)
        o.check()
    # a directory output is created with its parents at the end; a file written into it by
    # another option as well is refused before anything moves
    o = Outputs()
    parts = o.directory(tmp_path / "p" / "q", "--parts")
    clash = o.file(tmp_path / "p" / "q" / "a.stl", "--stl", parents=True)
    with pytest.raises(MlcError, match="--stl also writes|--parts also writes"):
        with o:
            parts.write_bytes("a.stl", b"1")
            clash.write_bytes(b"2")
    assert listing(tmp_path) == {"scene.yaml": b"x"} and not (tmp_path / "p").exists()
    o = Outputs()
    parts = o.directory(tmp_path / "p" / "q", "--parts")
    with o:
        parts.write_bytes("a.stl", b"1")
        parts.write_bytes("sub/b.stl", b"2")
    assert listing(tmp_path / "p") == {"q/a.stl": b"1", "q/sub/b.stl": b"2"}
    assert sorted(o.written) == sorted([str(tmp_path / "p/q/a.stl"), str(tmp_path / "p/q/sub/b.stl")])


def test_outputs_special_files_are_written_not_replaced(tmp_path):
    st = os.stat("/dev/null")
    o = Outputs()
    f = o.file("/dev/null", "-o", suffixes=(".png",))      # special files need no suffix
    with o:
        f.write_bytes(b"x" * 1000)
    after = os.stat("/dev/null")
    assert (after.st_mode, after.st_rdev, after.st_ino) == (st.st_mode, st.st_rdev, st.st_ino)


# ---------------------------------------------------------------------------------------
# draw: target and mesh arguments
# ---------------------------------------------------------------------------------------

BAD_MESHES = {
    "random_bytes": (bytes(random.Random(3).randrange(256) for _ in range(3000)), ["not an STL or 3MF"]),
    "text": (b"hello world\n", ["not an STL or 3MF"]),
    "empty": (b"", ["not an STL or 3MF"]),
    "ascii_no_facets": (b"solid x\nendsolid x\n", ["no triangles"]),
    "ascii_with_binary": (b"solid x\n\xff\xfe\x00facet", ["binary bytes"]),
    "binary_zero_triangles": (b"\0" * 80 + b"\0\0\0\0", ["no triangles"]),
    "binary_too_many": (b"\0" * 80 + struct.pack("<I", 400_001) + b"\0" * 50 * 400_001, ["too many"]),
}


@pytest.mark.parametrize("case", sorted(BAD_MESHES))
def test_draw_bad_mesh(case, tmp_path, capsys):
    data, words = BAD_MESHES[case]
    src = tmp_path / f"{case}.stl"
    src.write_bytes(data)
    before = listing(tmp_path)
    code, _, err = run(capsys, "draw", "--mesh", src, "-o", tmp_path / "x.png")
    assert_clean_failure(code, err, before, tmp_path, str(src), *words)


def test_draw_argument_conflicts(mesh, tmp_path, capsys):
    before = listing(tmp_path)
    for argv, words in [
        (["NAND", "--mesh", mesh], ["--mesh", "not both"]),
        ([], ["nothing to draw"]),
        (["--mesh", tmp_path / "missing.stl"], ["not found"]),
        (["--mesh", tmp_path], ["directory"]),
        (["--mesh", tmp_path / "bad.3mf"], ["not found"]),
        (["XOR"], ["no library gate", "NAND"]),
        (["NAND", "--signal", "sideways"], ["invalid choice"]),
    ]:
        code, _, err = run(capsys, "draw", *argv, "-o", tmp_path / "x.png")
        assert code == 2 and "Traceback" not in err, (argv, err)
        assert err.strip().splitlines()[-1].startswith("mlc: error: "), (argv, err)
        for w in words:
            assert w in err, (argv, err)
        assert listing(tmp_path) == before
    bad3mf = tmp_path / "bad.3mf"
    bad3mf.write_bytes(b"PK\x03\x04 not really a zip")
    code, _, err = run(capsys, "draw", "--mesh", bad3mf, "-o", tmp_path / "x.png")
    assert code == 2 and "not a 3MF" in err and not (tmp_path / "x.png").exists()


@pytest.mark.parametrize("din,h", [("nan", "2"), ("inf", "2"), ("-1", "2"), ("1e308", "2"), ("0.5", "0"),
                                   ("0.5", "1e308"), ("0.5", "-inf")])
def test_core_extreme_parameters(din, h, capsys):
    code, out, err = run(capsys, "core", f"--din={din}", f"--h={h}")
    assert code == 2 and out == "" and err.startswith("mlc: error: --din/--h: ") and err.count("\n") == 1, err


# ---------------------------------------------------------------------------------------
# standard output: closed, full, broken pipe; unexpected exceptions
# ---------------------------------------------------------------------------------------

def _mlc(args, **kw):
    code = f"import sys; from mlc.cli import main; sys.exit(main({args!r}))"
    # -P: not the checkout on sys.path, the installed package (as CI's plain `pytest` does)
    return subprocess.run([sys.executable, "-P", "-c", code], capture_output=False, stderr=subprocess.PIPE,
                          text=True, timeout=120, **kw)


def test_stdout_closed_and_full():
    r = subprocess.run(["sh", "-c", f"'{sys.executable}' -P -c 'import sys; from mlc.cli import main; "
                                    f"sys.exit(main([\"info\"]))' >&-"], stderr=subprocess.PIPE, text=True,
                       timeout=120)
    assert r.returncode == 2 and r.stderr == "mlc: error: standard output is closed " \
                                             "(redirect it, e.g. >/dev/null)\n"
    with open("/dev/full", "w") as full:
        r = _mlc(["gate", "NAND"], stdout=full)
    assert r.returncode == 2 and "No space left on device" in r.stderr and r.stderr.count("\n") == 1, r.stderr


def test_broken_pipe_is_quiet(monkeypatch, capsys):
    class Gone:
        def write(self, s):
            raise BrokenPipeError(32, "Broken pipe")

        def flush(self):
            raise BrokenPipeError(32, "Broken pipe")

    monkeypatch.setattr(sys, "stdout", Gone())
    assert main(["info"]) == 0
    assert capsys.readouterr().err == ""


def test_unexpected_exception_is_one_line(monkeypatch, capsys):
    import mlc.commands.version as version

    def boom(args):
        raise ValueError("an mlc bug")

    monkeypatch.setattr(version, "run", boom)       # main() builds the parser, so it takes boom
    code, _, err = run(capsys, "info")
    assert code == 3 and err.count("\n") == 1 and "internal error: ValueError: an mlc bug" in err
    assert "MLC_TRACEBACK=1" in err


def test_info_json(capsys):
    code, out, _ = run(capsys, "info", "--json")
    d = json.loads(out)
    assert code == 0 and Path(d["stdlib_gates"], "nand.yaml").is_file()


def test_argparse_errors_return_2_in_process(capsys):
    code, _, err = run(capsys, "core", "--din", "half")
    assert code == 2 and "invalid float value" in err


# ---------------------------------------------------------------------------------------
# packaging: every data directory of mlc/ ships
# ---------------------------------------------------------------------------------------

def test_every_data_directory_is_a_listed_package():
    import tomllib
    conf = tomllib.loads((ROOT / "pyproject.toml").read_text())
    listed = set(conf["tool"]["setuptools"]["packages"])
    assert isinstance(conf["project"]["license"], str)      # SPDX string, not the deprecated table
    dirs = {".".join(p.parent.relative_to(ROOT).parts) for p in (ROOT / "mlc").rglob("*")
            if p.is_file() and "__pycache__" not in p.parts}
    assert dirs - listed == set(), "add these to [tool.setuptools] packages in pyproject.toml"


# ---------------------------------------------------------------------------------------
# progress: a line with an ETA on a terminal, nothing elsewhere
# ---------------------------------------------------------------------------------------

def test_progress_bar_and_timer():
    import io
    import time as _time
    from mlc.io.progress import Progress
    s = io.StringIO()
    with Progress("work", total=4, show=True, delay=0.0, stream=s) as bar:
        bar.update(1)
        _time.sleep(0.02)
        bar.update(2)
    text = s.getvalue()
    assert "work [" in text and "2/4" in text and "ETA" in text and text.endswith("\n")
    s = io.StringIO()
    with Progress("solve", expect=100.0, show=True, delay=0.0, stream=s):
        _time.sleep(0.7)                                     # the timer thread draws every 0.5 s
    assert "solve" in s.getvalue() and "s left)" in s.getvalue()
    s = io.StringIO()                                        # StringIO is not a terminal: silent
    with Progress("quiet", total=2, delay=0.0, stream=s) as bar:
        bar.update(2)
    assert s.getvalue() == ""


# ---------------------------------------------------------------------------------------
# stl, simulate, gate -o: every output checked before the work, all or nothing
# ---------------------------------------------------------------------------------------

@pytest.fixture
def hinge_scene(tmp_path):
    from mlc.mesh import examples as ex
    from mlc.scene.io import write_scene
    p = tmp_path / "in" / "hinge.yaml"
    p.parent.mkdir()
    write_scene(ex.hinge_pair(), p)
    return p


STL_BAD_OUTPUTS = [
    # each fails before any mesh is built (a second at most): argv, words
    (["--parts", "/proc/mlc-parts"], ["--parts", "cannot write in /proc"]),
    (["-o", "{d}/x.stl", "--3mf", "{d}/x.3mf", "--parts", "{d}/f.txt"], ["--parts", "exists and is not a directory"]),
    (["-o", "{d}"], ["-o", "is a directory"]),
    (["-o", "{d}/x.3mf"], ["-o", "must end in .stl"]),
    (["--3mf", "{d}/x.stl"], ["--3mf", "must end in .3mf"]),
    (["-o", "{d}/x.stl", "--report", "{d}/x.stl"], ["--report", "must end in .json"]),
    (["--report", "{d}/no/r.json"], ["--report", "does not exist"]),
    (["-o", "{d}/x.stl", "--3mf", "{d}/f.txt/x.3mf"], ["--3mf", "not a directory"]),
]


@pytest.mark.parametrize("k", range(len(STL_BAD_OUTPUTS)))
def test_stl_outputs_checked_before_the_work(k, hinge_scene, tmp_path, capsys):
    argv, words = STL_BAD_OUTPUTS[k]
    out = tmp_path / "out"
    out.mkdir()
    (out / "f.txt").write_text("keep")
    before = listing(out)
    code, stdout, err = run(capsys, "stl", hinge_scene, *[a.format(d=out) for a in argv])
    assert_clean_failure(code, err, before, out, *words)
    assert stdout == ""                        # refused before the report was computed


def test_stl_all_or_nothing(hinge_scene, tmp_path, capsys):
    """A failing check writes nothing (not even --report); --force writes every file, once."""
    out = tmp_path / "out"
    out.mkdir()
    argv = ["stl", hinge_scene, "--no-states", "-o", out / "x.stl", "--3mf", out / "x.3mf",
            "--parts", out / "P", "--report", out / "r.json"]
    code, stdout, err = run(capsys, *argv)
    assert_clean_failure(code, err, {}, out, "printability checks failed: states", "nothing written")
    assert "FAIL" in stdout                    # the report explains the failure
    code, stdout, err = run(capsys, *argv, "--force")
    assert code == 0 and "written anyway (--force)" in err, err
    files = sorted(listing(out))
    assert files == ["P/A.stl", "P/B.stl", "r.json", "x.3mf", "x.stl"], files
    assert json.loads((out / "r.json").read_text())["outputs"] == [str(out / f) for f in
                                                                   ("x.stl", "x.3mf", "P/A.stl", "P/B.stl")]
    assert stdout.count("wrote ") == 5


@pytest.mark.parametrize("argv,option,words", [
    # issue 14's runaway parameters: each refused at once, naming the option, the geometry and a fix
    (["--clearance", "1e9"], "--clearance", ["more than half the slab width", "use clearance <="]),
    (["--sigma-mm", "1e6"], "--sigma-mm", ["larger than 1000 mm"]),
    (["--slab-thickness", "100"], "--slab-thickness", ["more than half the slab width"]),
    (["--sigma-mm", "1e-6"], "--sigma-mm", ["wider than the slabs", "use sigma_mm >= 4.4"]),
    (["--sigma-mm", "4"], "--sigma-mm", ["hinges 2.2 mm across", "use sigma_mm >= 4.4"]),
    (["--pin-diameter", "50"], "--pin-diameter", ["wider than the slabs"]),
    (["--segments", "100000"], "--segments", ["more than 256"]),
    (["--knuckle-gap", "2"], "--knuckle-gap", ["more than half"]),
    (["--knuckle-gap", "0.19"], "--knuckle-gap", ["less than the clearance 0.2 mm", "use knuckle_gap >= 0.2"]),
    (["--clearance", "0.3"], "--clearance", ["knuckle_gap 0.2 mm is less than the clearance 0.3 mm"]),
    (["--min-wall", "inf"], "--profile", ["min_wall must be a positive number"]),
    (["--clearance", "nan"], "--profile", ["clearance must be a number >= 0"]),
    (["--segments", "-5"], "--profile", ["circular_segments must be an integer >= 8"]),
])
def test_stl_parameters_against_the_geometry(argv, option, words, tmp_path, capsys):
    before = listing(tmp_path)
    code, stdout, err = run(capsys, "stl", "NAND", *argv, "-o", tmp_path / "x.stl")
    assert_clean_failure(code, err, before, tmp_path, f"mlc: error: {option}: ", *words)


def test_stl_memory_estimate_refuses_with_the_estimate(monkeypatch):
    from mlc.gates.library import gate_scene
    from mlc.mesh import profiles
    sc = gate_scene("NAND", "expand")
    small = profiles.estimate_memory(profiles.PROFILES["mjp"], sc)
    big = profiles.estimate_memory(profiles.load_profile("mjp", {"sigma_mm": 1000}), sc)
    assert small["bytes"] < 0.5 * 2 ** 30 < 2 ** 31 < big["bytes"]     # grows with the size in mm
    monkeypatch.setattr(profiles, "memory_budget", lambda: 2.0 * 2 ** 30)
    with pytest.raises(MlcError, match=r"--sigma-mm: this export would need about [0-9.]+ GiB"):
        profiles.check_against_scene(profiles.load_profile("mjp", {"sigma_mm": 1000}), sc,
                                     options={"sigma_mm": "--sigma-mm"})
    for name in profiles.PROFILES:                  # the built-in profiles fit the library gates
        profiles.check_against_scene(profiles.PROFILES[name], sc)
    # repeated mechanisms are built once: a grid of 36 NAND fits, one of 900 (~0.8 MB a body) not in 2 GiB
    from mlc.mesh import examples as ex
    assert profiles.memory_budget() >= 2 * 2 ** 30
    monkeypatch.setattr(profiles, "memory_budget", lambda: 2.0 * 2 ** 30)
    profiles.check_against_scene(profiles.PROFILES["mjp"], ex.grid(sc, 6, 6, (6.0, 6.0)))
    with pytest.raises(MlcError, match="GiB of memory"):
        profiles.check_against_scene(profiles.PROFILES["mjp"], ex.grid(sc, 30, 30, (6.0, 6.0)))


def test_simulate_outputs_checked_before_the_run(scene_text, tmp_path, capsys):
    d = tmp_path
    src = d / "s.yaml"
    src.write_text(scene_text)
    (d / "s.gsd").write_text(scene_text)
    before = listing(d)
    for argv, words in [
        (["--out", d / "t.gsd", "--probes", d / "no" / "p.csv"], ["--probes", "does not exist"]),
        (["--out", d / "t.gsd", "--probes", "/proc/p.csv"], ["--probes", "cannot write in /proc"]),
        (["--out", d / "same.gsd", "--probes", d / "same.gsd"], ["--probes", "must end in .csv"]),
        (["--out", d / "t.gsd", "--probes", d / "p.npz"], ["--probes", "must end in .csv"]),
        (["--out", d / "s.yaml"], ["--out", "must end in .gsd"]),
        (["--out", d], ["--out", "is a directory"]),
        (["--out", d / "t.gsd", "--probes", d / "s.gsd" / "p.csv"], ["--probes", "not a directory"]),
    ]:
        code, _, err = run(capsys, "simulate", src, "--time", "1", *argv)
        assert_clean_failure(code, err, before, d, *words)
    # a scene file named like a trajectory cannot be overwritten by its own run
    code, _, err = run(capsys, "simulate", d / "s.gsd", "--time", "1", "--out", d / "s.gsd")
    assert_clean_failure(code, err, before, d, "--out", "is an input")


def test_scene_input_without_a_muscle_is_refused_on_load(scene_text, tmp_path, capsys):
    # both muscles follow input a: input b, declared, moved nothing when set (was accepted, exit 0)
    assert scene_text.count("  input: b\n") == 1
    src = tmp_path / "s.yaml"
    src.write_text(scene_text.replace("  input: b\n", "  input: a\n"))
    line = next(i for i, l in enumerate(src.read_text().splitlines(), 1) if l.startswith("inputs:"))
    before = listing(tmp_path)
    for argv in (["simulate", src, "--time", "0.1", "--set", "b=1", "--out", tmp_path / "t.gsd"],
                 ["verify", src], ["draw", src, "-o", tmp_path / "s.png"]):
        code, _, err = run(capsys, *argv)
        assert_clean_failure(code, err, before, tmp_path, f"{src}:{line}:", "input 'b' drives no muscle",
                             "add a muscle with 'input: b', or remove b from inputs")


def test_simulate_writes_all_outputs(scene_text, tmp_path, capsys):
    src = tmp_path / "s.yaml"
    src.write_text(scene_text)
    code, out, err = run(capsys, "simulate", src, "--time", "0.2", "--out", tmp_path / "t.gsd",
                         "--probes", tmp_path / "p.csv", "--quiet", "--frames", "3")
    assert code == 0, err
    assert sorted(listing(tmp_path)) == ["p.csv", "p.npz", "s.yaml", "t.gsd"]
    assert (tmp_path / "p.csv").read_text().startswith("time_t0,out\n")


def test_gate_output(tmp_path, capsys):
    (tmp_path / "f.txt").write_text("keep")
    before = listing(tmp_path)
    for path, words in [("/proc/g.yaml", ["cannot write in /proc"]), (tmp_path, ["is a directory"]),
                        (tmp_path / "g.txt", ["must end in .yaml or .yml"]),
                        (tmp_path / "f.txt" / "g.yaml", ["not a directory"]), ("", ["empty output path"])]:
        code, _, err = run(capsys, "gate", "NAND", "-o", path)
        assert_clean_failure(code, err, before, tmp_path, "-o", *words)
    code, out, _ = run(capsys, "gate", "NAND", "-o", tmp_path / "g.yaml")
    assert code == 0 and out == f"wrote {tmp_path / 'g.yaml'}\n"
    assert (tmp_path / "g.yaml").read_text().startswith("# mlc scene")


# ---------------------------------------------------------------------------------------
# profile files: the same limits as scene files
# ---------------------------------------------------------------------------------------

@pytest.mark.parametrize("name,data,words", [
    ("big.json", b'{"base": "mjp", "clearance": ' + b"7" * 5000 + b"}", ["5000 digits"]),
    ("deep.json", b"[" * 100000 + b"]" * 100000, ["nested too deep"]),
    ("comma.json", b'{"clearance": 0.3,}', ["comma.json:1:19:", "JSON syntax error"]),
    ("nan.json", b'{"clearance": NaN}', ["finite number"]),
    ("latin1.yaml", b"base: mjp\nname: caf\xe9\n", ["latin1.yaml:2:10:", "0xe9", "UTF-8"]),
    ("bomb.yaml", _bomb().replace("meta:", "description:").encode(), ["alias", "1,000,000"]),
    ("huge.yaml", b"clearance: " + b"9" * 400 + b"\n", ["too large"]),
    ("list.yaml", b"- 1\n", ["must be a mapping"]),
])
def test_hostile_profile_files(name, data, words, tmp_path, capsys):
    src = tmp_path / name
    src.write_bytes(data)
    before = listing(tmp_path)
    code, _, err = run(capsys, "stl", "NAND", "--profile", src, "-o", tmp_path / "x.stl")
    assert_clean_failure(code, err, before, tmp_path, str(src), *words)


def test_scene_file_that_is_a_directory_or_missing(tmp_path, capsys):
    for path, words in [(tmp_path, ["is a directory"]), (tmp_path / "none.yaml", ["No such file"])]:
        code, _, err = run(capsys, "simulate", path, "--time", "1")
        assert_clean_failure(code, err, listing(tmp_path), tmp_path, "cannot read scene", *words)


# ---------------------------------------------------------------------------------------
# what a newcomer sees: progress with an ETA, one table, a word before kernels compile
# ---------------------------------------------------------------------------------------

def test_design_space_reports_progress(monkeypatch):
    from mlc.geometry import core
    calls = []
    monkeypatch.setattr(core, "accessible_din_range", lambda h: (0.1, 0.5) if h < 3.5 else None)
    monkeypatch.setattr(core, "_solve", lambda din, h: type("S", (), {"dout": 0.1})())
    space = core.design_space(progress=lambda done, total: calls.append((done, total)))
    done = [c[0] for c in calls]
    assert done == sorted(done) and len(calls) > 29 and calls[-1][0] == calls[-1][1] == calls[0][1]
    assert len(space["curves"]) == 5 and space["boundary"]


def test_check_gate_dynamic_prints_each_row_once(capsys):
    code, out, err = run(capsys, "check-gate", "NAND", "--signal", "expand", "--dynamic", "--seeds", "1")
    assert code == 0 and err == "", err
    lines = out.splitlines()
    assert len(lines) == 6 and "relax (t0)" in lines[0] and lines[-1].startswith("dynamic check: 4 of 4")


def test_kernel_compile_notice_once(monkeypatch):
    import io
    from mlc.io import warmup
    assert warmup.kernels_cached("stiff") in (True, False, None)
    monkeypatch.setattr(warmup, "_said", False)
    monkeypatch.setattr(warmup, "kernels_cached", lambda scheme="stiff", parallel=False: False)
    s = io.StringIO()
    assert warmup.notice(stream=s, show=True) and not warmup.notice(stream=s, show=True)
    assert s.getvalue().count("\n") == 1 and "compiling the simulation kernels" in s.getvalue()
    s = io.StringIO()
    monkeypatch.setattr(warmup, "_said", False)
    assert not warmup.notice(stream=s) and s.getvalue() == ""          # not a terminal: silent
    monkeypatch.setattr(warmup, "kernels_cached", lambda scheme="stiff", parallel=False: True)
    assert not warmup.notice(stream=s, show=True)                       # cached: nothing to say


# ---------------------------------------------------------------------------------------
# found by the hostile sweep: runaway parameters, leftovers of abandoned or killed runs
# ---------------------------------------------------------------------------------------

@pytest.mark.parametrize("argv,words", [
    (["simulate", "{scene}", "--time", "1e308"], ["--time", "inf steps"]),
    (["simulate", "{scene}", "--time", "1", "--drift-tol", "inf"], ["--drift-tol", "positive number of sigma"]),
    (["simulate", "{scene}", "--time", "1", "--threads", "100000"], ["--threads", "cores of this machine"]),
    (["check-gate", "NAND", "--grid", "100000"], ["--grid", "2e+10 poses", "days"]),
    (["check-gate", "NAND", "--dynamic", "--seeds", "1000000000"], ["--seeds", "days", "at most 1000"]),
    (["check-gate", "NAND", "--branches", "--kT", "inf"], ["--kT", "finite kT > 0"]),
    (["stl", "NAND", "--min-wall", "1e-9"], ["min_wall 1e-09 mm is below 0.01 mm"]),
    (["core", "--data", "/dev/full"], ["--data", "/dev/full"]),
    (["simulate", "{scene}", "--time", "1", "--record", "1e308", "--probes", "{d}/p.csv"],
     ["--record", "longer than the run"]),
    (["simulate", "", "--time", "1"], ["empty scene file name"]),
    (["verify", ""], ["empty scene file name"]),
    (["verify", "{scene}", "--jobs", "0"], ["--jobs", "between 1 and 256"]),
    (["verify", "{scene}", "--dynamic", "--jobs", "2"], ["--jobs", "static check", "drop --jobs or --dynamic"]),
    (["compile", "-e", "y = a & b", "-o", "{d}/o", "--no-circuit", "--jobs", "2"],
     ["--jobs only applies to the circuit", "drop --no-circuit"]),
    (["compile", "-e", "y = a & b", "-o", "{d}/o", "--jobs", "0"], ["--jobs", "between 1 and 256"]),
    (["compile", "-e", "y = a & b", "-o", "{d}/o", "--no-circuit", "--router", "fast"],
     ["--router only applies to the circuit", "drop --no-circuit"]),
    (["gate", "NAND", "-o", "/dev/full"], ["-o", "/dev/full"]),
    # a step over 1e9 averaging windows made no step: the rest pose was reported as a wrong bit (exit 1)
    (["verify", "{scene}", "--dynamic", "--seeds", "1", "--dt", "1e308"], ["--dt", "longer than any run needs"]),
    (["verify", "{scene}", "--dynamic", "--seeds", "1", "--tau", "1", "--dt", "5"], ["--dt", "longer than --tau"]),
    # the last of two drives of one input won, silently
    (["simulate", "{scene}", "--time", "0.1", "--set", "a=1", "--set", "a=0"], ["--set a is given twice"]),
    # non-finite drive numbers ran (step:nan and square:inf exit 0, nan a dt instability, inf a stretched muscle)
    *[(["simulate", "{scene}", "--time", "0.1", "--out", "{d}/t.gsd", "--set", f"a={v}"],
       ["--set a: ", "drive", "finite", "give times in t0"])
      for v in ("nan", "inf", "-inf", "step:nan", "step:1:nan:1", "step:1:0:inf", "square:inf", "square:1:nan",
                "square:1:0.5:nan", "table:0=0,1=nan", "table:0=0,inf=1")],
    # a drive value outside 0 (rest) .. 1 (actuated) ran: a=-1 pushed the muscle past its rest length, exit 0
    *[(["simulate", "{scene}", "--time", "0.1", "--out", "{d}/t.gsd", "--set", f"a={v}"],
       ["--set a: ", f"drive value {bad} is outside 0..1", "0 holds the input's muscles at rest, 1 actuated"])
      for v, bad in (("-1", "-1"), ("1.5", "1.5"), ("step:1:0:2", "2"), ("step:1:-0.5:1", "-0.5"),
                     ("square:1:0.5:0:-1:1", "-1"), ("square:1:0.5:0:0:3", "3"), ("table:0=0,1=1.01", "1.01"))],
    # kT 1e308 overflowed the noise: the error named --dt ("no time step helps"), after the compile's work
    *[(argv + ["--kT", "1e308"], ["--kT", "from 0 to 10"])
      for argv in (["simulate", "{scene}", "--time", "0.1", "--out", "{d}/t.gsd"],
                   ["verify", "{scene}", "--dynamic", "--seeds", "1"],
                   ["compile", "-e", "f = a & b", "-o", "{d}/o", "--verify", "--dynamic", "--seeds", "1"],
                   ["check-gate", "NAND", "--dynamic", "--seeds", "1"])],
])
def test_refused_at_once(argv, words, scene_text, tmp_path, capsys):
    src = tmp_path / "s.yaml"
    src.write_text(scene_text)
    before = listing(tmp_path)
    code, _, err = run(capsys, *[a.format(scene=src, d=tmp_path) for a in argv])
    assert_clean_failure(code, err, before, tmp_path, *words)


def test_abandoned_outputs_leave_no_staging(tmp_path):
    """A command that checks its outputs, then fails outside the ``with`` block (mlc compile's
    pattern), leaves no staging directory: removed when collected, or at exit."""
    import gc
    from mlc.io import outputs
    outs = Outputs()
    outs.file(tmp_path / "a.png", "--a")
    outs.check()
    assert [p.name[:13] for p in tmp_path.iterdir()] == [".mlc-staging-"]
    del outs
    gc.collect()
    assert list(tmp_path.iterdir()) == []
    keep = Outputs()
    keep.file(tmp_path / "b.png", "--b")
    keep.check()
    outputs._discard_all()                     # what atexit runs
    assert list(tmp_path.iterdir()) == []


def test_sigterm_leaves_nothing(tmp_path):
    """`timeout` or `kill` during an export: handled like Ctrl-C, no staging directory left."""
    import signal
    import time as _time
    code = ("import sys; from mlc.cli import main; "
            f"sys.exit(main(['stl', 'NAND', '--min-wall', '0.01', '-o', {str(tmp_path / 'x.stl')!r}]))")
    p = subprocess.Popen([sys.executable, "-P", "-c", code], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                         text=True)
    deadline = _time.time() + 60
    while not any(tmp_path.iterdir()) and _time.time() < deadline:     # wait for the staging area
        _time.sleep(0.05)
    _time.sleep(0.5)            # past the handler's installation, which follows the mkdir; the export takes ~20 s
    p.send_signal(signal.SIGTERM)
    err = p.communicate(timeout=60)[1]
    assert p.returncode == 130 and "mlc: interrupted" in err, err
    assert list(tmp_path.iterdir()) == []


def test_ctrl_c_during_the_first_kernel_compile(scene_text, tmp_path):
    """A real Ctrl-C to `mlc simulate --out` while Numba compiles the stepping kernel (an
    empty NUMBA_CACHE_DIR forces the compile, ~20 s of it after the trigger): exit 130
    within a few seconds, nothing written (the handler that defers Ctrl-C to the end of a
    chunk held it until the compile and the first chunk were done: 26 s, files written)."""
    import signal
    import time as _time
    src, out, nc = tmp_path / "s.yaml", tmp_path / "out", tmp_path / "nc"
    src.write_text(scene_text)
    out.mkdir()
    code = ("import sys; from mlc.cli import main; sys.exit(main(['simulate', %r, '--time', '1', '--out', %r, "
            "'--probes', %r, '--quiet']))" % (str(src), str(out / "t.gsd"), str(out / "p.csv")))
    p = subprocess.Popen([sys.executable, "-P", "-c", code], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                         text=True, env=dict(os.environ, NUMBA_CACHE_DIR=str(nc)))
    # a helper of the stepping kernel (skrock_s) is cached: its own compile has begun (measured 12 s in, of 32)
    deadline = _time.time() + 120
    while not list(nc.glob("*/kernels._site_world-*.nbi")) and p.poll() is None and _time.time() < deadline:
        _time.sleep(0.05)
    assert p.poll() is None and not list(nc.glob("*/kernels.skrock_s-*.nbi")), "not caught inside the compile"
    sent = _time.time()
    p.send_signal(signal.SIGINT)
    err = p.communicate(timeout=120)[1]
    back = _time.time() - sent
    assert p.returncode == 130 and err == "mlc: interrupted\n", err
    assert back < 5.0, f"exit {back:.1f} s after Ctrl-C"         # measured 0.65-1.1 s
    assert list(out.iterdir()) == []


def test_stl_time_estimate():
    from mlc.gates.library import gate_scene
    from mlc.mesh.profiles import PROFILES, estimate_seconds, load_profile
    sc = gate_scene("NAND", "expand")
    t = estimate_seconds(PROFILES["mjp"], sc)
    fine = estimate_seconds(load_profile("mjp", {"min_wall": 0.01, "slab_thickness": 0.01}), sc)
    assert 2 < t < 10 and 15 < fine < 40           # measured: about 5 s and 22 s


def test_probes_to_redirected_stdout(scene_text, tmp_path):
    """`--probes /dev/stdout > file`: the CSV goes through standard output, in order with the
    summary (opening /dev/stdout anew would truncate the file), and /dev/stdout stays a link."""
    src = tmp_path / "s.yaml"
    src.write_text(scene_text)
    out = tmp_path / "o.txt"
    with open(out, "w") as f:
        r = _mlc(["simulate", str(src), "--time", "0.1", "--record", "0.05", "--probes", "/dev/stdout"], stdout=f)
    assert r.returncode == 0, r.stderr
    text = out.read_text()
    assert text.startswith("time_t0,out\n0,1.5\n") and "NAND_expand: 2 steps" in text, text
    assert sorted(p.name for p in tmp_path.iterdir()) == ["o.txt", "s.yaml"]          # no .npz anywhere
    assert not Path("/dev/stdout.npz").exists() and Path("/dev/stdout").is_symlink()


def test_scene_name_length_is_bounded(scene_text, tmp_path, capsys):
    src = tmp_path / "s.yaml"
    src.write_text(scene_text.replace("name: NAND_expand", "name: " + "x" * 100000, 1))
    before = listing(tmp_path)
    code, _, err = run(capsys, "draw", src, "-o", tmp_path / "x.png")        # took minutes to draw
    assert_clean_failure(code, err, before, tmp_path, f"{src}:", "100000 characters (at most 200)")


def test_posts_are_not_slabs():
    """Compiled circuits hang connector slabs on square posts (0.08 x 0.08 sigma): the profile
    checks measure the plates (0.5 sigma wide), so the built-in profiles still fit a circuit."""
    import numpy as np
    from mlc.gates.library import gate_scene
    from mlc.mesh import profiles
    from mlc.scene.model import Box
    sc = gate_scene("NAND", "expand")
    sc.bodies[0].boxes.append(Box(np.array([0.08, 0.08, 0.17]), np.array([0.3, 0.0, 0.0]),
                                  np.array([1.0, 0.0, 0.0, 0.0])))
    assert profiles._widths(sc)[0] == pytest.approx(0.5)
    for p in profiles.PROFILES.values():
        profiles.check_against_scene(p, sc)


# ---------------------------------------------------------------------------------------
# generated: every numeric option of every command against hostile numbers
# ---------------------------------------------------------------------------------------

BAD_NUMBERS = ["nan", "inf", "-inf", "-1", "0", "1e308", "-1e308", "1e-320", "", "x"]

NUMERIC_OPTIONS = {
    # command: (base argv, {option: (value used when another option is varied)}); "{scene}", "{d}" filled in
    "lever": (["lever"], {"--lin": "1", "--lout": "1", "--dlin": "0.3", "--dlout": "-0.3", "--l": "1"}),
    "core": (["core"], {"--din": "0.5", "--h": "2"}),
    "simulate": (["simulate", "{scene}", "--out", "{d}/t.gsd", "--probes", "{d}/p.csv", "--quiet"],
                 {"--time": "0.1", "--dt": None, "--kT": None, "--record": None, "--drift-tol": None,
                  "--frames": None, "--threads": None, "--seed": None}),
    "stl": (["stl", "{hinge}", "--no-states", "-o", "{d}/x.stl"],
            {"--sigma-mm": None, "--clearance": None, "--knuckle-gap": None, "--slab-thickness": None,
             "--min-wall": None, "--min-feature": None, "--pin-diameter": None, "--segments": None}),
    "check-gate": (["check-gate", "NAND", "--signal", "expand", "--dynamic"], {"--seeds": "1", "--kT": None}),
    "verify": (["verify", "{scene}", "--dynamic", "--rows", "11"],
               {"--seeds": "1", "--kT": None, "--tau": None, "--dt": None}),
}


def _numeric_cases():
    for cmd, (_base, opts) in NUMERIC_OPTIONS.items():
        for opt in opts:
            for v in BAD_NUMBERS:
                yield cmd, opt, v


@pytest.mark.parametrize("cmd,opt,value", list(_numeric_cases()))
def test_generated_hostile_numbers(cmd, opt, value, scene_text, hinge_scene, tmp_path, capsys):
    """A clear one-line error and nothing written, or a normal run (exit 0 or 1: a wrong bit);
    never a traceback, an internal error or a half-written output."""
    if cmd == "stl" and value == "0" and opt == "--clearance":
        pytest.skip("a valid profile: a full export, covered elsewhere")
    src = tmp_path / "s.yaml"
    src.write_text(scene_text)
    d = tmp_path / "out"
    d.mkdir()
    base, opts = NUMERIC_OPTIONS[cmd]
    argv = [a.format(scene=src, hinge=hinge_scene, d=d) for a in base]
    for o, default in opts.items():
        if o == opt:
            argv += [f"{o}={value}"]
        elif default is not None:
            argv += [o, default]
    import warnings
    with warnings.catch_warnings(record=True) as caught:      # a warning would be a second stderr line
        warnings.simplefilter("always")
        code, _, err = run(capsys, *argv)
    assert not [w for w in caught if issubclass(w.category, RuntimeWarning)], [str(w.message) for w in caught]
    assert "Traceback" not in err and "internal error" not in err, err
    if code == 2:
        lines = err.splitlines()
        assert lines[-1].startswith("mlc: error: ") and err.endswith("\n"), err
        # one line, after argparse's usage for a value that is not a number
        assert all(line.startswith(("usage: ", " ")) for line in lines[:-1]), err
        assert listing(d) == {}, "a failed run wrote something"
    else:
        assert code in (0, 1), (code, err)


# generated: every output option of every command against every kind of bad location
OUTPUT_OPTIONS = {
    # (argv before the output option, option, suffix the option writes)
    "draw -o": (["draw", "NAND"], "-o", ".png"),
    "gate -o": (["gate", "NAND"], "-o", ".yaml"),
    "core --plot": (["core"], "--plot", ".png"),
    "core --data": (["core"], "--data", ".json"),
    "simulate --out": (["simulate", "{scene}", "--time", "0.1", "--quiet"], "--out", ".gsd"),
    "simulate --probes": (["simulate", "{scene}", "--time", "0.1", "--quiet"], "--probes", ".csv"),
    "stl -o": (["stl", "{hinge}"], "-o", ".stl"),
    "stl --3mf": (["stl", "{hinge}"], "--3mf", ".3mf"),
    "stl --report": (["stl", "{hinge}"], "--report", ".json"),
    "compile --draw": (["compile", "-e", "f = a & b", "--no-circuit", "-o", "{d}/o"], "--draw", ".png"),
    "robot shapes -o": (["robot", "shapes", "{scene}"], "-o", ".png"),
    "robot fold --gif": (["robot", "fold", "{scene}", "--row", "1"], "--gif", ".gif"),
    "robot fold --gsd": (["robot", "fold", "{scene}", "--row", "1"], "--gsd", ".gsd"),
}
MAKES_PARENTS = {"compile --draw", "robot shapes -o", "robot fold --gif", "robot fold --gsd"}   # parents=True
BAD_LOCATIONS = {
    # name: (path maker given the output directory and the suffix, words)
    "directory": (lambda d, sfx: d, ["is a directory"]),
    "missing_directory": (lambda d, sfx: d / "no" / f"x{sfx}", ["does not exist"]),
    "parent_is_file": (lambda d, sfx: d / "f.txt" / f"x{sfx}", ["not a directory"]),
    "proc": (lambda d, sfx: Path(f"/proc/mlc-x{sfx}"), ["cannot write in /proc"]),
    "dev_full": (lambda d, sfx: Path("/dev/full"), ["/dev/full"]),
    "wrong_suffix": (lambda d, sfx: d / "x.txt", ["must end in {sfx}"]),
    "empty": (lambda d, sfx: "", ["empty output path"]),
    "the_input": (lambda d, sfx: "{input}", []),
}


@pytest.mark.parametrize("where", sorted(BAD_LOCATIONS))
@pytest.mark.parametrize("what", sorted(OUTPUT_OPTIONS))
def test_generated_bad_output_locations(what, where, scene_text, hinge_scene, tmp_path, capsys):
    """Refused before the work (fast), naming the option; nothing written anywhere."""
    pre, option, sfx = OUTPUT_OPTIONS[what]
    make, words = BAD_LOCATIONS[where]
    if where == "missing_directory" and what in MAKES_PARENTS:
        pytest.skip("this option creates a missing directory")
    src = tmp_path / f"s{sfx}"                 # an input named like the output, for "the_input"
    src.write_text(scene_text)
    d = tmp_path / "out"
    d.mkdir()
    (d / "f.txt").write_text("keep")
    before, before_top = listing(d), listing(tmp_path)
    inp = {"simulate": src, "stl": hinge_scene, "robot": src}.get(pre[0])
    if where == "the_input":
        if inp is None:
            pytest.skip("this command reads no input file")
        if pre[0] == "stl":
            target = hinge_scene.with_suffix(sfx)
            target.write_text(hinge_scene.read_text())
            inp = target
        out = inp
    else:
        out = make(d, sfx)
    argv = [a.format(scene=src, hinge=inp or hinge_scene, d=d) for a in pre] + [option, out]
    code, stdout, err = run(capsys, *argv)
    assert_clean_failure(code, err, before, d, f"mlc: error: {option}", *[w.format(sfx=sfx) for w in words])
    assert listing(tmp_path) == before_top or where == "the_input" and pre[0] == "stl"
    if where == "the_input":
        assert "is an input" in err or f"must end in {sfx}" in err, err


@pytest.mark.parametrize("seeds", ["0", "-3", "1000000000"])
def test_verify_and_compile_refuse_absurd_seed_counts(seeds, tmp_path, capsys):
    """--dynamic --seeds 1e9 used to start a run of years; now one error before any work."""
    scene = tmp_path / "nand.yaml"
    assert main(["gate", "NAND", "-o", str(scene)]) == 0
    capsys.readouterr()
    before = listing(tmp_path)
    code, _, err = run(capsys, "verify", scene, "--dynamic", "--seeds", seeds)
    assert_clean_failure(code, err, before, tmp_path, "--seeds")
    code, _, err = run(capsys, "compile", "-e", "z = a & b", "-o", tmp_path / "o", "--verify", "--dynamic",
                       "--seeds", seeds)
    assert_clean_failure(code, err, before, tmp_path, "--seeds")


def test_stl_refuses_a_mechanism_too_large_to_mesh(tmp_path, capsys, monkeypatch):
    """A mechanism of more bodies than MAX_MECHANISM_BODIES is refused before any work (the
    limit lowered to 150 here: a 40-unit connector chain stands for a larger circuit)."""
    from mlc.gates.connector import chain_scene
    from mlc.mesh import profiles
    from mlc.scene.io import write_scene
    monkeypatch.setattr(profiles, "MAX_MECHANISM_BODIES", 150)
    MAX_MECHANISM_BODIES = 150
    sc = chain_scene(40)
    assert len(sc.bodies) > MAX_MECHANISM_BODIES
    path = tmp_path / "chain.yaml"
    write_scene(sc, path)
    out = tmp_path / "out"
    out.mkdir()
    code, stdout, err = run(capsys, "stl", str(path), "-o", str(out / "x.stl"))
    assert_clean_failure(code, err, {}, out, f"{len(sc.bodies)} bodies", f"at most {MAX_MECHANISM_BODIES}",
                         "mlc stl NAND")


def _wide_table(path, n: int, rows: int, seed: int):
    """A .tt file of ``n`` inputs x0.. and outputs f, g on up to ``rows`` random rows (seeded)."""
    rng = random.Random(seed)
    rs = sorted({"".join(rng.choice("01") for _ in range(n)) for _ in range(rows)})
    path.write_text(f".inputs {' '.join(f'x{i}' for i in range(n))}\n.outputs f g\n"
                    + "".join(f"{r} | {rng.choice('01')}{rng.choice('01')}\n" for r in rs))
    return path


def test_compile_refuses_a_table_too_large_for_memory(tmp_path, capsys, monkeypatch):
    """A 24-input truth table (the format's maximum) peaked at 5.8 GB in synthesis, silently:
    the estimate is checked before any work, against the budget (lowered here to 1 GiB)."""
    from mlc.commands import compile as cc
    from mlc.mesh import profiles
    n = 22
    src = _wide_table(tmp_path / "wide.tt", n, 50, seed=14)
    monkeypatch.setattr(profiles, "memory_budget", lambda: 2.0 ** 30)
    before = listing(tmp_path)
    code, stdout, err = run(capsys, "compile", src, "-o", tmp_path / "o", "--no-circuit")
    assert_clean_failure(code, err, before, tmp_path, f"{src}: ", "22-input truth table", "GiB of memory",
                         "the limit is 1 GiB")
    assert stdout == ""
    # a network of as many inputs is not tabulated: no estimate, it compiles
    from mlc.front.load import load
    assert cc.table_memory(load(expr="f = " + " & ".join(f"x{i}" for i in range(n)))) == 0


def test_table_memory_estimate_covers_the_measured_peaks():
    """The estimate stays above each measured peak (mlc.commands.compile.TABLE_MEASURED_PEAKS),
    and within 1.5 times it."""
    from mlc.commands import compile as cc
    from mlc.spec import TableSpec
    for (n, m), peak in cc.TABLE_MEASURED_PEAKS.items():
        spec = TableSpec([f"x{i}" for i in range(n)], [f"f{j}" for j in range(m)], [0] * m, [0] * m)
        assert peak <= cc.table_memory(spec) <= 1.5 * peak, (n, m)
    # -O3 peaks higher: at 24 inputs it passed 23.9 GB and was killed (an estimate of 6.9 GB let it start)
    for (n, m), peak in cc.TABLE_MEASURED_PEAKS_O3.items():
        spec = TableSpec([f"x{i}" for i in range(n)], [f"f{j}" for j in range(m)], [0] * m, [0] * m)
        assert peak <= cc.table_memory(spec, 3) <= 6 * peak, (n, m)


def test_compile_O3_refuses_a_table_that_O2_takes(tmp_path, capsys, monkeypatch):
    """The 24-input 200-row table of 2 outputs: -O2 peaks under 6 GB, -O3 passed 23.9 GB and was
    killed after 7.7 min; with a 12 GiB budget (half this machine's memory) -O3 is refused at once."""
    from mlc.mesh import profiles
    n = 24
    src = _wide_table(tmp_path / "t24.tt", n, 20, seed=24)
    monkeypatch.setattr(profiles, "memory_budget", lambda: 12.0 * 2 ** 30)
    before = listing(tmp_path)
    code, stdout, err = run(capsys, "compile", src, "-o", tmp_path / "o", "--no-circuit", "-O3")
    assert_clean_failure(code, err, before, tmp_path, f"{src}: ", "24-input truth table at -O3", "GiB of memory",
                         "use -O2, which needs less")


def _wires_through_boxes(dot_text: str) -> list:
    """Graphviz's own layout (``dot -Tplain``) of a netlist graph: the (wire, box) pairs where a wire's
    spline passes inside a gate box that is not one of its two ends (boxes shrunk by 0.02 in)."""
    import shlex
    plain = subprocess.run(["dot", "-Tplain"], input=dot_text, capture_output=True, text=True, timeout=120,
                           check=True).stdout
    boxes, edges = {}, []
    for line in plain.splitlines():
        f = shlex.split(line)
        if f[0] == "node" and f[-3] == "box":
            x, y, w, h = map(float, f[2:6])
            boxes[f[1]] = (x - w / 2 + 0.02, x + w / 2 - 0.02, y - h / 2 + 0.02, y + h / 2 - 0.02)
        elif f[0] == "edge":
            n = int(f[3])
            pts = [(float(f[4 + 2 * i]), float(f[5 + 2 * i])) for i in range(n)]
            edges.append((f[1], f[2], pts))
    bad = []
    for tail, head, pts in edges:
        curve = []
        for k in range(0, len(pts) - 3, 3):                 # cubic Bezier pieces
            p0, p1, p2, p3 = pts[k:k + 4]
            for i in range(21):
                t = i / 20
                c = [(1 - t) ** 3, 3 * t * (1 - t) ** 2, 3 * t * t * (1 - t), t ** 3]
                curve.append((sum(w * p[0] for w, p in zip(c, (p0, p1, p2, p3))),
                              sum(w * p[1] for w, p in zip(c, (p0, p1, p2, p3)))))
        for name, (x0, x1, y0, y1) in boxes.items():
            if name not in (tail, head) and any(x0 < x < x1 and y0 < y < y1 for x, y in curve):
                bad.append((tail, head, name))
    return bad


@pytest.mark.skipif(not __import__("shutil").which("dot"), reason="Graphviz's dot is not installed")
@pytest.mark.parametrize("example", ["tetris.tt", "mux4.blif", "full_adder.tt", "random"])
def test_compile_draw_wires_go_around_gate_boxes(example, tmp_path, capsys):
    """compile --draw is Graphviz's drawing of OUTDIR/netlist.dot, and in Graphviz's layout of that
    graph no wire passes through a gate box (mlc's own layered drawing ran examples/tetris.tt's
    y -> u3_up wire behind two gate boxes; straight wires in the seeded random netlist of 88 gates
    cross 51 boxes)."""
    src = ROOT / "examples" / example
    if example == "random":
        from helpers import random_aig
        from mlc.logic.aigio import write_aiger
        src = tmp_path / "random.aag"
        src.write_text(write_aiger(random_aig(1, n_in=16, n_and=150, n_out=8, window=60)))
    png = tmp_path / "c.png"
    code, _, err = run(capsys, "compile", src, "-O0", "-o", tmp_path / "o", "--no-circuit", "--draw", png)
    assert code == 0 and err == "", err
    dot_text = (tmp_path / "o" / "netlist.dot").read_text()
    assert png.read_bytes() == subprocess.run(["dot", "-Tpng"], input=dot_text.encode(), capture_output=True,
                                              timeout=120, check=True).stdout
    assert dot_text.count("shape=box") >= 3 and _wires_through_boxes(dot_text) == []


def test_compile_draw_says_when_a_circuit_is_too_large(tmp_path, capsys, monkeypatch):
    from mlc.commands import compile as cc
    monkeypatch.setattr(cc, "DRAW_LEGIBLE_GATES", 2)
    png = tmp_path / "c.png"
    code, _, err = run(capsys, "compile", ROOT / "examples" / "tetris.tt", "-o", tmp_path / "o", "--no-circuit",
                       "--draw", png)
    assert code == 0 and err.startswith("mlc: warning: --draw: 3 gates are too many to read") and \
        err.count("\n") == 1, err
    assert png.read_bytes()[:4] == b"\x89PNG"


def test_compile_draw_of_a_large_circuit_shows_a_timer(tmp_path, capsys, monkeypatch):
    """A schematic past the legible size is drawn by mlc itself (20 s for 3000 gates): a timer
    with its estimate runs meanwhile (shown here as on a terminal)."""
    from mlc.commands import compile as cc
    from mlc.io import progress

    class Shown(progress.Progress):
        def __init__(self, label, total=None, expect=None, show=None, delay=2.0, stream=None, steps=None):
            super().__init__(label, total, expect, True, 0.0, stream, steps)

    from mlc.netlist.ir import Netlist
    render = Netlist.render_png

    def slow_render(self, *a, **k):      # as long as a large schematic: the timer ticks every 0.5 s
        import time
        time.sleep(1.2)
        return render(self, *a, **k)

    monkeypatch.setattr(cc, "DRAW_LEGIBLE_GATES", 2)
    monkeypatch.setattr(progress, "Progress", Shown)
    monkeypatch.setattr(Netlist, "render_png", slow_render)
    code, _, err = run(capsys, "compile", ROOT / "examples" / "tetris.tt", "-o", tmp_path / "o", "--no-circuit",
                       "--draw", tmp_path / "c.png")
    assert code == 0 and "drawing 3 gates" in err, err


def test_draw_shows_progress(tmp_path, capsys, monkeypatch):
    """mlc draw of a compiled circuit solves each input state for minutes (1328 bodies: ~3 min):
    a bar counts the states, then the picture (shown here as on a terminal)."""
    from mlc.io import progress

    class Shown(progress.Progress):
        def __init__(self, label, total=None, expect=None, show=None, delay=2.0, stream=None):
            super().__init__(label, total, expect, True, 0.0, stream)

    monkeypatch.setattr(progress, "Progress", Shown)
    code, out, err = run(capsys, "draw", "NAND", "-o", tmp_path / "n.png")
    assert code == 0 and out == f"wrote {tmp_path / 'n.png'}\n"
    assert "mlc draw: solving and drawing NAND_expand [" in err and "4/5" in err and err.endswith("5/5  ETA     0 s  \n")


def test_compile_synthesis_display_names_its_steps(tmp_path, capsys, monkeypatch):
    """The synthesis display was a bare timer (a 24-input table of 200 rows: 22 s of 'synthesizing
    and proving t24.tt  19 s', 20 s of them decomposing); it names the step it is in, 3 in all, and
    the improving step's share of its work budget."""
    from mlc.io import progress
    moves = []

    class Recorded(progress.Progress):
        def _move(self, name, fraction=None):
            super()._move(name, fraction)
            moves.append((self.label, self.line(), fraction))

    monkeypatch.setattr(progress, "Progress", Recorded)
    code, out, err = run(capsys, "compile", "-e", "inputs a, b, c; f = a ^ (b & c); g = a | c", "-o", tmp_path / "o",
                         "--no-circuit")
    assert code == 0, err
    shown = [(line, f) for label, line, f in moves if label.startswith("synthesizing and proving")]
    assert [line.split(": step ")[1].split(" ")[0] for line, _ in shown] == ["1/3,", "2/3,", "3/3,"], shown
    f = shown[1][1]                                  # improving: the work clock against its budget
    assert "improving" in shown[1][0] and 0 < f() < 1.5, shown


def test_compile_checks_the_mesh_profile_before_the_work(tmp_path, capsys, monkeypatch):
    """compile --stl with a bad --profile failed only after synthesis and place and route."""
    from mlc.commands import compile as cc

    def no_work(*a, **k):
        raise AssertionError("synthesis started before the profile was checked")

    monkeypatch.setattr(cc, "compile_spec", no_work)
    before = listing(tmp_path)
    for opt in ("--stl", "--3mf"):
        code, _, err = run(capsys, "compile", "-e", "f = a & b", "-o", tmp_path / "o", opt,
                           tmp_path / f"x{opt.replace('--', '.')}", "--profile", tmp_path / "missing.yaml")
        assert_clean_failure(code, err, before, tmp_path, "--profile", "unknown printer profile")


def test_robot_fold_interrupted_and_shapes_progress(tmp_path, tiny_robot_yaml, capsys, monkeypatch):
    """robot fold: a run cut short by Ctrl-C wrote the frames and printed the shape as if folded
    (exit 0); now exit 130 and nothing written.  robot shapes: a bar over the rows (silent before)."""
    from mlc.io import progress
    from mlc.sim.integrator import Simulation
    (tmp_path / "tiny.robot.yaml").write_text(tiny_robot_yaml)
    assert main(["compile", "-e", "u1_up = a; u2_dn = a", "--robot", str(tmp_path / "tiny.robot.yaml"),
                 "-o", str(tmp_path / "out")]) == 0
    robot = tmp_path / "out" / "robot.yaml"
    capsys.readouterr()
    before = listing(tmp_path)
    run_ = Simulation.run

    def cut_short(self, *a, **k):
        res = run_(self, *a, **k)
        res.interrupted = True               # what the Ctrl-C handler sets
        return res

    monkeypatch.setattr(Simulation, "run", cut_short)
    code, out, err = run(capsys, "robot", "fold", robot, "--row", "1", "--time", "0.5", "--frames", "3",
                         "--gif", tmp_path / "f.gif", "--gsd", tmp_path / "f.gsd", "--png-dir", tmp_path / "frames")
    assert code == 130 and out == "" and err == "mlc: interrupted\n", err
    assert listing(tmp_path) == before
    monkeypatch.setattr(Simulation, "run", run_)

    class Shown(progress.Progress):
        def __init__(self, label, total=None, expect=None, show=None, delay=2.0, stream=None):
            super().__init__(label, total, expect, True, 0.0, stream)

    monkeypatch.setattr(progress, "Progress", Shown)
    code, out, err = run(capsys, "robot", "shapes", robot, "-o", tmp_path / "s.png")
    assert code == 0 and "mlc robot shapes: the equilibrium of each row of" in err and "2/2" in err, err
    assert (tmp_path / "s.png").read_bytes()[:4] == b"\x89PNG"
    # fold: drawing the frames was a bare timer; a bar counts them (the count is known before)
    code, out, err = run(capsys, "robot", "fold", robot, "--row", "1", "--time", "0.5", "--frames", "3",
                         "--png-dir", tmp_path / "frames")
    assert code == 0 and "mlc robot fold: drawing the frames [" in err and "3/3  ETA" in err, err
    assert sorted(p.name for p in (tmp_path / "frames").iterdir()) == [f"frame_{k:03d}.png" for k in range(3)]


def test_draw_refuses_more_panels_than_a_picture_shows(scene_text, tmp_path, capsys):
    """A NAND scene declaring 8 inputs (6 without a muscle) drew 256 panels in 3 min, silently."""
    extra = "".join(f"- name: muscle_{x}\n  input: {x}\n  sites: [a_hi.in, a_lo.in]\n  rest: 1.0\n  actuated: 1.5\n"
                    for x in "cdefg")                 # an input no muscle follows is refused on load
    assert scene_text.count("\nprobes:\n") == 1
    text = scene_text.replace("inputs: [a, b]", "inputs: [a, b, c, d, e, f, g]", 1).replace("\nprobes:\n",
                                                                                           "\n" + extra + "probes:\n")
    lines = text.splitlines(keepends=True)
    i = lines.index("truth_table:\n")
    j = next(k for k in range(i + 1, len(lines)) if not lines[k].startswith(" "))
    src = tmp_path / "wide.yaml"
    src.write_text("".join(lines[:i] + lines[j:]))
    before = listing(tmp_path)
    code, _, err = run(capsys, "draw", src, "-o", tmp_path / "x.png")
    assert_clean_failure(code, err, before, tmp_path, f"{src}: 7 inputs make 128 input states", "at most 64")


def _ctrl_c_in_a_callback():
    """What Python does with a Ctrl-C that lands in a C callback (Numba's compiler, from LLVM):
    it hands the KeyboardInterrupt to sys.unraisablehook, and the C code goes on."""
    import types
    try:
        raise KeyboardInterrupt
    except KeyboardInterrupt as ki:
        sys.unraisablehook(types.SimpleNamespace(exc_type=KeyboardInterrupt, exc_value=ki,
                                                 exc_traceback=ki.__traceback__, err_msg=None, object=None))


def test_ctrl_c_swallowed_by_a_callback_still_stops_the_command(monkeypatch, capsys):
    """A Ctrl-C that lands in a callback which swallows it (Python reports it to
    sys.unraisablehook and the C code goes on) while the compile then succeeds: the command must
    still stop, not run to its end."""
    import time
    import mlc.commands.version as version
    finished = []

    def swallowed_then_work(args):
        _ctrl_c_in_a_callback()
        t = time.perf_counter()
        while time.perf_counter() - t < 2.0:     # the rest of the command, in Python
            pass
        finished.append(True)
        return 0

    monkeypatch.setattr(version, "run", swallowed_then_work)
    import signal
    # Ctrl-C handled as in a terminal (pytest-xdist's workers ignore SIGINT, and a process that
    # ignores it is rightly not stopped)
    old = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        code, _, err = run(capsys, "info")
    finally:
        signal.signal(signal.SIGINT, old)
    assert code == 130 and err == "mlc: interrupted\n" and not finished, (code, err)


def test_ctrl_c_inside_a_compiler_callback_is_an_interruption(monkeypatch, capsys):
    """Ctrl-C while Numba compiles lands in an LLVM callback: Python printed it as an ignored
    traceback, then Numba failed with "RuntimeError: no compiled object yet", reported as an mlc
    bug (exit 3; seen on a cold cache, simulate interrupted 17 s after its start)."""
    import types
    import mlc.commands.version as version

    def compile_interrupted(args):
        _ctrl_c_in_a_callback()
        raise RuntimeError("no compiled object yet for <Library 'eval_s'>")

    def chained(args):
        try:
            raise KeyboardInterrupt
        except KeyboardInterrupt:
            raise RuntimeError("cleanup failed")

    for fn in (compile_interrupted, chained):
        monkeypatch.setattr(version, "run", fn)
        code, _, err = run(capsys, "info")
        assert code == 130 and err == "mlc: interrupted\n", (fn.__name__, err)
    seen = []
    monkeypatch.setattr(sys, "unraisablehook", lambda u: seen.append(u.exc_type))

    def other(args):                 # any other unraisable still reaches the hook; a bug is still a bug
        sys.unraisablehook(types.SimpleNamespace(exc_type=ValueError, exc_value=ValueError("x"),
                                                 exc_traceback=None, err_msg=None, object=None))
        raise RuntimeError("an mlc bug")

    monkeypatch.setattr(version, "run", other)
    code, _, err = run(capsys, "info")
    assert code == 3 and "internal error: RuntimeError: an mlc bug" in err and seen == [ValueError]


def test_every_command_is_in_the_readme_table():
    """What a newcomer sees: `mlc info` was missing from the README's command table."""
    import argparse
    from mlc.cli import build_parser
    sub = next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction))
    table = [line for line in (ROOT / "README.md").read_text().splitlines() if line.startswith("| `mlc ")]
    listed = {line.split("`mlc ", 1)[1].split()[0].rstrip("`") for line in table}
    assert set(sub.choices) - listed == set(), "add these commands to the README's command table"
    assert "info" in sub.choices and len(sub.choices) >= 10
