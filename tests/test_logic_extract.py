"""opt._extract_pairs (extract_and's greedy pair extraction with counts kept up to
date) against the plain algorithm that recounts every pair at every step."""
import copy
import random

from mlc.logic import opt


def _recounting(roots: dict) -> list:
    virt = []
    while True:
        cnt = {}
        for s in roots.values():
            if len(s) < 2:
                continue
            ls = sorted(s, key=repr)
            for i in range(len(ls)):
                for j in range(i + 1, len(ls)):
                    p = (ls[i], ls[j])
                    cnt[p] = cnt.get(p, 0) + 1
        if not cnt:
            break
        p, c = max(cnt.items(), key=lambda kv: (kv[1], repr(kv[0])))
        if c < 2:
            break
        v = ("v", len(virt))
        virt.append(p)
        for s in roots.values():
            if p[0] in s and p[1] in s:
                s.discard(p[0])
                s.discard(p[1])
                s.add(v)
    return virt


def test_extract_pairs_same_as_recounting():
    rng = random.Random(3)
    total = 0
    for _ in range(300):
        lits = rng.randint(3, 40)           # literals 2..: reprs of different lengths
        roots = {y: {rng.randrange(2, 2 + 2 * lits) for _ in range(rng.randint(1, 9))}
                 for y in range(rng.randint(1, 30))}
        ref_roots = copy.deepcopy(roots)
        ref = _recounting(ref_roots)
        got = opt._extract_pairs(roots)
        assert got == ref
        assert roots == ref_roots
        total += len(got)
    assert total > 300                       # the cases do extract pairs


def test_extract_and_keeps_function():
    from mlc.logic.aig import AIG
    rng = random.Random(4)
    g = AIG([f"i{i}" for i in range(12)])
    lits = [g.input_lit(i) for i in range(12)]
    while g.num_ands() < 300:
        a, b = rng.choice(lits[-30:]), rng.choice(lits)
        r = g.and_(a ^ rng.randint(0, 1), b ^ (rng.random() < 0.2))
        if r > 1:
            lits.append(r & ~1)
    for k in range(8):
        g.add_output(f"o{k}", lits[-1 - 5 * k])
    h = opt.extract_and(g)
    assert h.num_ands() < g.cleanup().num_ands()         # pairs were shared
    assert h.truth_tables() == g.truth_tables()
