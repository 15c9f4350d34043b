"""_find_resub (the resubstitution search of resub, resub_window and resub_dc): every
answer equals the target on the care set and uses at most ``max_new`` new ANDs, and a
0-resub (a divisor or its complement equal to the target) is always found."""
import random

from mlc.logic.opt import _find_resub


def _ev(e, vals, full):
    """Table of a resub expression: 0/1 constants, literal 2*d+c, ("and", a, b, c)."""
    if isinstance(e, int):
        if e in (0, 1):
            return full if e else 0
        v = vals[e >> 1]
        return v ^ full if e & 1 else v
    _, a, b, c = e
    r = _ev(a, vals, full) & _ev(b, vals, full)
    return r ^ full if c else r


def _ands(e):
    return 0 if isinstance(e, int) else 1 + _ands(e[1]) + _ands(e[2])


def test_find_resub_answers_are_right():
    rng = random.Random(7)
    found = {0: 0, 1: 0, 2: 0}
    for _ in range(3000):
        k = rng.choice([3, 4, 5, 6])
        full = (1 << (1 << k)) - 1
        divs = sorted(rng.sample(range(1, 100), rng.randint(1, 20)))
        vals = {d: rng.getrandbits(1 << k) for d in divs}
        a, b, c = (vals[rng.choice(divs)] ^ (full if rng.random() < 0.5 else 0) for _ in range(3))
        care = full if rng.random() < 0.5 else rng.getrandbits(1 << k) | rng.getrandbits(1 << k)
        f = rng.choice([a, a & b, a & (b | c), a & b & c, a | b, rng.getrandbits(1 << k)]) & care
        max_new = rng.choice([0, 1, 2])
        e = _find_resub(f, care, full, divs, vals, max_new)
        zero = f in (0, care) or any(vals[d] & care == f or care & ~vals[d] == f for d in divs)
        if zero:
            assert e is not None, "a 0-resub exists"
            assert _ands(e) == 0
        if e is None:
            continue
        assert _ands(e) <= max_new
        assert _ev(e, vals, full) & care == f
        found[_ands(e)] += 1
    assert all(found[m] > 50 for m in found), found
