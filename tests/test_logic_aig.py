"""The AIG IR: structural hashing, invariants (check), text form, simulation, writers."""
import pytest

from mlc.errors import InternalError
from mlc.logic import tt as T
from mlc.logic.aig import AIG
from mlc.logic.aigio import write_aiger, write_blif


def full_adder_aig() -> AIG:
    g = AIG(["a", "b", "c"])
    a, b, c = 2, 4, 6
    n1 = g.and_(a, b)
    n2 = g.and_(a ^ 1, b ^ 1)
    x = g.and_(n1 ^ 1, n2 ^ 1)          # a ^ b
    n3 = g.and_(x, c)
    n4 = g.and_(x ^ 1, c ^ 1)
    s = g.and_(n3 ^ 1, n4 ^ 1) ^ 1      # !(a^b^c)... complemented below
    cout = g.and_(n1 ^ 1, n3 ^ 1) ^ 1
    g.add_output("s", s ^ 1)
    g.add_output("cout", cout)
    return g


def test_and_folds_and_hashes():
    g = AIG(["a", "b"])
    a, b = 2, 4
    assert g.and_(a, 0) == 0 and g.and_(0, a) == 0
    assert g.and_(a, 1) == a and g.and_(1, a) == a
    assert g.and_(a, a) == a
    assert g.and_(a, a ^ 1) == 0
    x = g.and_(b, a)
    assert g.and_(a, b) == x                      # hashed, order normalised
    assert g.ands == [(a, b)]
    assert g.num_ands() == 1
    assert g.or_(a, b) == g.and_(a ^ 1, b ^ 1) ^ 1
    g.check()


def test_full_adder_simulation_and_depth():
    g = full_adder_aig()
    g.check()
    s, co = g.truth_tables()
    a, b, c = (T.var(3, i) for i in range(3))
    assert s == a ^ b ^ c
    assert co == (a & b) | (a & c) | (b & c)
    assert g.num_ands() == 7
    assert g.depth() == 4
    # word-level simulation agrees with exhaustive tables
    assert g.simulate([0b1010, 0b1100, 0b1111], 4) == [(0b1010 ^ 0b1100 ^ 0b1111), 0b1110]


def test_to_text_golden():
    g = full_adder_aig()
    assert g.to_text() == (
        "aig inputs=3 ands=7 outputs=2 depth=4\n"
        "input n1 a\n"
        "input n2 b\n"
        "input n3 c\n"
        "and n4 = n1 & n2\n"
        "and n5 = !n1 & !n2\n"
        "and n6 = !n4 & !n5\n"
        "and n7 = n3 & n6\n"
        "and n8 = !n3 & !n6\n"
        "and n9 = !n7 & !n8\n"
        "and n10 = !n4 & !n7\n"
        "output s = n9\n"
        "output cout = !n10\n")


@pytest.mark.parametrize("mutate, msg", [
    (lambda g: g.inputs.append("a"), "duplicate input"),
    (lambda g: g.outputs.append("x"), "outputs but"),
    (lambda g: g.ands.__setitem__(0, (2, 20)), "earlier node"),
    (lambda g: g.ands.__setitem__(0, (4, 2)), "increasing order"),
    (lambda g: g.ands.__setitem__(0, (1, 4)), "constant fanin"),
    (lambda g: g.ands.__setitem__(0, (4, 5)), "both fanins"),
    (lambda g: g.ands.__setitem__(1, g.ands[0]), "duplicate of an earlier"),
    (lambda g: g.output_lits.__setitem__(0, 99), "out of range"),
    (lambda g: g.outputs.__setitem__(1, "s"), "duplicate output"),
    (lambda g: g.inputs.__setitem__(0, ""), "empty input"),
])
def test_check_rejects_malformed(mutate, msg):
    g = full_adder_aig()
    g.check()
    mutate(g)
    with pytest.raises(InternalError, match=msg):
        g.check()


def test_from_parts_checks():
    with pytest.raises(InternalError):
        AIG.from_parts(["a", "b"], ["y"], [(4, 2)], [6])
    g = AIG.from_parts(["a", "b"], ["y"], [(2, 4)], [7])
    assert g.truth_tables() == [0b0111]
    assert g.and_(4, 2) == 6             # the hash table was rebuilt


def test_cleanup_removes_dangling():
    g = AIG(["a", "b", "c"])
    g.and_(2, 4)
    y = g.and_(4, 6)
    g.add_output("y", y)
    h = g.cleanup()
    assert h.num_ands() == 1 and h.truth_tables() == g.truth_tables()


def _parse_aag(text):
    lines = text.splitlines()
    _, M, I, L, O, A = lines[0].split()
    I, O, A = int(I), int(O), int(A)
    ins = [int(x) for x in lines[1:1 + I]]
    outs = [int(x) for x in lines[1 + I:1 + I + O]]
    ands = [tuple(int(v) for v in x.split()) for x in lines[1 + I + O:1 + I + O + A]]
    return ins, outs, ands


def test_write_aiger_simulates_back():
    g = full_adder_aig()
    ins, outs, ands = _parse_aag(write_aiger(g))
    assert write_aiger(g).startswith("aag 10 3 0 2 7\n")
    for m in range(8):
        val = {0: 0}
        for i, lit in enumerate(ins):
            val[lit] = (m >> i) & 1
        for lhs, r0, r1 in ands:
            assert lhs > r0 >= r1
            v = lambda x: val[x & ~1] ^ (x & 1)  # noqa: E731
            val[lhs] = v(r0) & v(r1)
        got = [val[o & ~1] ^ (o & 1) for o in outs]
        assert got == [bin(m).count("1") & 1, int(bin(m).count("1") >= 2)]
    assert "i0 a" in write_aiger(g) and "o1 cout" in write_aiger(g)


def test_write_blif_simulates_back():
    g = full_adder_aig()
    text = write_blif(g)
    assert text.startswith(".model mlc\n.inputs a b c\n.outputs s cout\n")
    # tiny BLIF evaluator: single-cube .names as written by mlc
    for m in range(8):
        val = {"a": m & 1, "b": (m >> 1) & 1, "c": (m >> 2) & 1, "$false": 0}
        lines = text.splitlines()
        i = 0
        while i < len(lines):
            ln = lines[i]
            if ln.startswith(".names"):
                sig = ln.split()[1:]
                if len(sig) == 1:
                    val[sig[0]] = 0
                    i += 1
                    continue
                cube = lines[i + 1].split()[0]
                val[sig[-1]] = int(all(val[s] == int(c) for s, c in zip(sig[:-1], cube)))
                i += 2
            else:
                i += 1
        k = bin(m).count("1")
        assert (val["s"], val["cout"]) == (k & 1, int(k >= 2))


def test_blif_and_aiger_accepted_by_abc_and_yosys(tmp_path):
    """With Yosys/ABC installed (optional): ABC proves our BLIF and Yosys' reading of
    our ASCII AIGER equivalent to the reference."""
    import shutil
    import subprocess
    abc, yosys = shutil.which("yosys-abc"), shutil.which("yosys")
    if abc is None or yosys is None:
        pytest.skip("yosys / yosys-abc not installed")
    from mlc.logic import library
    from mlc.logic.synth import synthesize
    spec = library.adder(2)
    g = synthesize(spec)
    ref = [".model ref", ".inputs " + " ".join(spec.inputs), ".outputs " + " ".join(spec.outputs)]
    for name, on in zip(spec.outputs, spec.on):
        ref.append(f".names {' '.join(spec.inputs)} {name}")
        for m in range(16):
            if (on >> m) & 1:
                ref.append("".join(str((m >> i) & 1) for i in range(4)) + " 1")
    ref.append(".end")
    (tmp_path / "ref.blif").write_text("\n".join(ref) + "\n")
    (tmp_path / "g.blif").write_text(write_blif(g))
    (tmp_path / "g.aag").write_text(write_aiger(g))
    subprocess.run([yosys, "-q", "-p", "read_aiger -module_name g g.aag; write_blif y.blif"],
                   cwd=tmp_path, check=True, capture_output=True, timeout=60)
    for f in ("g.blif", "y.blif"):
        p = subprocess.run([abc, "-c", f"read_blif ref.blif; cec {f}"], cwd=tmp_path,
                           capture_output=True, text=True, timeout=60)
        assert "Networks are equivalent" in p.stdout, p.stdout
