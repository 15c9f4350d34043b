"""The shipped exact NPN table of 4-input functions."""
import random

from mlc.logic import npn
from mlc.logic import tt as T
from mlc.logic.aig import AIG


def test_table_covers_all_classes_and_is_correct():
    tab = npn.table()
    reps = npn.classes()
    assert len(reps) == 222 and set(tab) == set(reps)
    for R, ent in tab.items():
        g = AIG(["a", "b", "c", "d"])
        lits = [2, 4, 6, 8]
        for j, l, fj, fl, fo in ent["gates"]:
            lits.append(g.and_(lits[j] ^ fj, lits[l] ^ fl) ^ fo)
        node, c = ent["out"]
        lit = c if node < 0 else lits[node] ^ c
        g.add_output("f", lit)
        assert g.truth_tables() == [R], hex(R)
        assert len(ent["gates"]) == ent["ands"]


def test_known_costs():
    a, b, c, d = (T.var(4, i) for i in range(4))
    assert npn.cost4(a & b) == 1
    assert npn.cost4(a ^ b) == 3
    assert npn.cost4(a ^ b ^ c ^ d) == 9
    assert npn.cost4((a & b) | (a & c) | (b & c)) == 4


def test_canon_and_build_random():
    rng = random.Random(3)
    for _ in range(300):
        f = rng.getrandbits(16)
        R, perm, neg, out = npn.canon(f)
        assert npn.canon(R)[0] == R
        g = AIG(["a", "b", "c", "d"])
        g.add_output("f", npn.build4(g, f, [2, 4, 6, 8]))
        assert g.truth_tables() == [f]
        assert g.cleanup().num_ands() <= npn.cost4(f)


def test_sat_proves_small_minima():
    """The exact engine proves the full adder (7) and majority-3 (4) minimal and its
    circuits simulate correctly."""
    from mlc.logic import exactsat, library
    for spec, k in ((library.full_adder(), 7), (library.majority(3), 4)):
        full = T.mask(spec.n)
        targets = [(f, full) for f in spec.on]
        assert exactsat.synthesize_exact(spec.n, targets, k - 1) is None
        r = exactsat.synthesize_exact(spec.n, targets, k)
        assert r is not None
        got = exactsat.circuit_tables(spec.n, *r)
        assert got == list(spec.on)


def test_table_metadata():
    import json
    data = json.loads(npn.TABLE_PATH.read_text())
    cls = data["classes"]
    assert all(isinstance(v.get("proven"), bool) for v in cls.values())
    assert sorted(k for k, v in cls.items() if not v["proven"]) == data["unproven"]
    assert sum(v["proven"] for v in cls.values()) >= 171
    assert cls["6996"]["ands"] == 9 and cls["6996"]["proven"]       # parity-4
