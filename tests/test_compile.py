"""``mlc compile``: every example end to end through the CLI, the JSON summary, the
written files, and that a failed run writes nothing."""
import json
from pathlib import Path

import pytest

from mlc.cli import main
from mlc.front.aiger import parse as parse_aag
from mlc.front.blif import parse as parse_blif
from mlc.front.load import load, truth_tables
from mlc.netlist.ir import Netlist

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = sorted(p.name for p in (ROOT / "examples").iterdir()
                  if p.suffix in (".tt", ".pla", ".expr", ".blif", ".aag"))


def run_json(capsys, *args):
    rc = main(["compile", *args, "--json"])
    out, err = capsys.readouterr()
    assert rc == 0, err
    return json.loads(out)


def agrees(spec, text, parser):
    back = parser(text, "written")
    on, dc = truth_tables(spec)
    got = truth_tables(back)[0]
    return back.outputs == spec.outputs and all((g ^ o) & ~d == 0 for g, o, d in zip(got, on, dc))


@pytest.mark.parametrize("example", EXAMPLES)
def test_every_example_compiles(example, tmp_path, capsys):
    src = ROOT / "examples" / example
    d = run_json(capsys, str(src), "-o", str(tmp_path / "out"), "-O1", "--no-circuit")
    assert d["equivalent"] is True and d["gates"] >= 0 and d["depth"] >= 0
    spec = load(str(src))
    nl = Netlist.loads((tmp_path / "out" / "netlist.json").read_text(), "netlist.json")
    assert nl.stats["gates"] == d["gates"] and nl.stats["depth"] == d["depth"]
    assert agrees(spec, (tmp_path / "out" / "netlist.blif").read_text(), parse_blif)
    assert agrees(spec, (tmp_path / "out" / "netlist.aag").read_text(), parse_aag)
    assert (tmp_path / "out" / "netlist.dot").read_text().startswith("digraph")


def test_tetris_done_when(tmp_path, capsys):
    """The issue's acceptance command."""
    d = run_json(capsys, str(ROOT / "examples" / "tetris.tt"), "-o", str(tmp_path / "out"), "--verify")
    assert d["equivalent"] is True
    assert d["gates"] == 3 and d["depth"] == 1          # !y&b, y&b, y&!b; u3_up is the muscle y itself
    assert d["const_outputs"] == {"u1_up": 0, "u1_dn": 0, "u2_dn": 0}
    assert d["input_outputs"] == {"u3_up": "y"}
    assert sorted(Path(f).name for f in d["files"]) == ["circuit.png", "circuit.yaml", "netlist.aag", "netlist.aig",
                                                        "netlist.blif", "netlist.dot", "netlist.json", "verify.json"]
    assert d["verification"]["ok"] is True and d["verification"]["rows"] == 4
    assert (tmp_path / "out" / "circuit.png").read_bytes().startswith(b"\x89PNG")
    # the scene loads and verifies again through the CLI
    assert main(["verify", str(tmp_path / "out" / "circuit.yaml"), "--rows", "01", "11"]) == 0


def test_expression_signal_draw_and_text_summary(tmp_path, capsys):
    png = tmp_path / "pics" / "fa.png"
    rc = main(["compile", "-e", "s = a ^ b ^ c; co = maj(a, b, c); n = !a", "-o", str(tmp_path / "o"),
               "--signal", "contract", "--draw", str(png), "--no-circuit"])
    out, err = capsys.readouterr()
    assert rc == 0, err
    assert "equivalence proven" in out and "gates: " in out and "depth" in out
    assert "n = !a" in out and "half units: 1" in out
    assert png.read_bytes()[:4] == b"\x89PNG"
    nl = Netlist.loads((tmp_path / "o" / "netlist.json").read_text())
    assert nl.signal == "contract"


def test_full_adder_is_seven_gates(tmp_path, capsys):
    d = run_json(capsys, str(ROOT / "examples" / "full_adder.tt"), "-o", str(tmp_path), "-O2", "--no-circuit")
    assert d["gates"] == 7


def test_strict_flag(tmp_path, capsys):
    f = tmp_path / "p.tt"
    f.write_text(".inputs a b\n.outputs f\n11 | 1\n")
    assert main(["compile", str(f), "-o", str(tmp_path / "o1"), "--no-circuit"]) == 0
    capsys.readouterr()
    assert main(["compile", str(f), "--strict", "-o", str(tmp_path / "o2")]) == 2
    assert "p.tt:1:1:" in capsys.readouterr().err
    assert not (tmp_path / "o2").exists()


@pytest.mark.parametrize("args,words", [
    (["-e", "f = a &"], "<-e>:1:8:"),
    (["nonexistent.tt"], "no such file"),
    (["x.vhd"], "unknown input format"),
    ([], "no input"),
    (["x.tt", "-e", "a"], "not both"),
])
def test_user_errors_exit_2_and_write_nothing(args, words, tmp_path, capsys):
    rc = main(["compile", *args, "-o", str(tmp_path / "out")])
    err = capsys.readouterr().err
    assert rc == 2 and words in err and err.count("\n") == 1
    assert not (tmp_path / "out").exists()


def test_internal_error_writes_nothing(tmp_path, capsys, monkeypatch):
    import mlc.logic.equiv as equiv
    from mlc.errors import InternalError

    def broken(aig, spec, seed=1):
        raise InternalError("simulated mismatch")
    monkeypatch.setattr(equiv, "check_equivalent", broken)
    rc = main(["compile", "-e", "f = a & b", "-o", str(tmp_path / "out")])
    assert rc == 3 and "simulated mismatch" in capsys.readouterr().err
    assert not (tmp_path / "out").exists() or not any((tmp_path / "out").iterdir())


# ---------------------------------------------------------------- property: random tables compile and map correctly

from hypothesis import given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402


@st.composite
def tables(draw):
    from mlc.spec import TableSpec
    n = draw(st.integers(0, 5))
    m = draw(st.integers(1, 3))
    full = (1 << (1 << n)) - 1
    on, dc = [], []
    for _ in range(m):
        d = draw(st.integers(0, full)) & draw(st.integers(0, full))     # sparse-ish don't cares
        on.append(draw(st.integers(0, full)) & ~d)
        dc.append(d)
    return TableSpec([f"x{i}" for i in range(n)], [f"f{o}" for o in range(m)], on, dc, "random")


@settings(max_examples=25, deadline=None)
@given(tables(), st.sampled_from(["expand", "contract"]), st.integers(0, 1))
def test_random_tables_compile_to_equivalent_netlists(spec, signal, level):
    from mlc.commands.compile import compile_spec
    c = compile_spec(spec, level, signal)
    assert c.proof["equivalent"] is True
    got = c.netlist.to_aig().truth_tables()
    for g, o, d in zip(got, spec.on, spec.dc):
        assert (g ^ o) & ~d == 0
    c.netlist.check()


# ---------------------------------------------------------------- interoperability: Yosys reads the exports

import shutil  # noqa: E402
import subprocess  # noqa: E402


def _yosys_roundtrip(read_cmd: str, path: Path, tmp: Path):
    """Read ``path`` with Yosys, write ASCII AIGER with a port map, return it parsed with names."""
    out, mp = tmp / "y.aag", tmp / "y.map"
    script = f"{read_cmd} {path}; techmap; aigmap; opt_clean; write_aiger -ascii -map {mp} {out}"
    subprocess.run(["yosys", "-q", "-p", script], check=True, timeout=60, capture_output=True)
    spec = parse_aag(out.read_text(), str(out))
    names = {}
    for line in mp.read_text().splitlines():
        kind, idx, _bit, name = line.split()
        names[(kind, int(idx))] = name
    tables = truth_tables(spec)[0]
    return ([names[("input", i)] for i in range(len(spec.inputs))],
            [names[("output", i)] for i in range(len(spec.outputs))], tables)


@pytest.mark.skipif(shutil.which("yosys") is None, reason="yosys is not installed")
@pytest.mark.parametrize("example", ["bcd7seg.pla", "compare2.aag"])
def test_yosys_reads_the_blif_and_aiger_exports(example, tmp_path, capsys):
    run_json(capsys, str(ROOT / "examples" / example), "-o", str(tmp_path / "o"), "-O1", "--no-circuit")
    spec = load(str(ROOT / "examples" / example))
    on, dc = truth_tables(spec)
    for cmd, name in (("read_blif", "netlist.blif"), ("read_aiger", "netlist.aag")):
        ins, outs, got = _yosys_roundtrip(cmd, tmp_path / "o" / name, tmp_path)
        # reorder to the spec's input and output order, then compare on the care set
        perm = [ins.index(x) for x in spec.inputs]
        n = len(spec.inputs)
        for o, out_name in enumerate(spec.outputs):
            g = got[outs.index(out_name)]
            for m in range(1 << n):
                if (dc[o] >> m) & 1:
                    continue
                mb = sum(((m >> i) & 1) << perm[i] for i in range(n))
                assert (g >> mb) & 1 == (on[o] >> m) & 1, (cmd, out_name, m)


@pytest.mark.skipif(shutil.which("dot") is None, reason="graphviz is not installed")
def test_graphviz_reads_the_dot(tmp_path, capsys):
    run_json(capsys, "-e", "s = a ^ b ^ c; co = maj(a, b, c); n = !a; k = 0", "-o", str(tmp_path))
    r = subprocess.run(["dot", "-Tsvg", str(tmp_path / "netlist.dot")], capture_output=True, timeout=60)
    assert r.returncode == 0 and b"<svg" in r.stdout, r.stderr


def test_compile_stl_failure_is_one_message_and_writes_nothing(tmp_path, capsys):
    """compile --stl through mlc stl: a mesh the profile cannot make is one message (not a
    nested 'mlc: error:'), exit 2, and no output directory."""
    prof = tmp_path / "thick.yaml"
    prof.write_text("base: mjp\nmin_wall: 1.2\nmin_feature: 1.2\n")
    out = tmp_path / "o"
    code = main(["compile", "-e", "a & b", "-o", str(out), "--stl", str(out / "c.stl"), "--profile", str(prof)])
    err = capsys.readouterr().err
    assert code == 2 and not out.exists()
    assert "meshing the circuit failed: --profile: hinges" in err and err.count("mlc: error:") == 1


def test_compile_force_reaches_mlc_stl(monkeypatch, tmp_path):
    """compile --stl --force passes --force to mlc stl (write despite a failed check)."""
    import mlc.cli
    from mlc.commands.compile import _mesh

    seen = []
    monkeypatch.setattr(mlc.cli, "main", lambda argv: seen.append(list(argv)) or 0)

    class Staged:
        tmp = tmp_path / "c.stl"

    _mesh(tmp_path / "circuit.yaml", Staged(), None, "mjp", True)
    _mesh(tmp_path / "circuit.yaml", Staged(), None, "mjp", False)
    assert "--force" in seen[0] and "--force" not in seen[1]


@pytest.mark.parametrize("k,words", [("0", "from 0.1 to 10000"), ("nan", "from 0.1"), ("1e5", "to 10000"),
                                     ("-3", "from 0.1"), ("1e-320", "from 0.1"), ("0.09", "got 0.09")])
def test_joint_k_is_checked_before_any_work(k, words, tmp_path, capsys):
    rc = main(["compile", "-e", "y = a & b", "-o", str(tmp_path / "out"), "--joint-k", k])
    err = capsys.readouterr().err
    assert rc == 2 and words in err and "--joint-k" in err and err.count("\n") == 1
    assert not (tmp_path / "out").exists()
