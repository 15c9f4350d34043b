"""Truth tables as Python ints.

A truth table over ``n`` variables is an int of ``2**n`` bits; bit ``m`` is the value
on minterm ``m``, where variable ``i`` has the value ``(m >> i) & 1`` (the numbering
of :class:`mlc.spec.TableSpec`).  Python's big ints make every Boolean
operation bit-parallel over all minterms at once.
"""
from __future__ import annotations

from functools import lru_cache


@lru_cache(maxsize=None)
def mask(n: int) -> int:
    """All-ones truth table over ``n`` variables."""
    return (1 << (1 << n)) - 1


@lru_cache(maxsize=None)
def var(n: int, i: int) -> int:
    """Truth table of variable ``i`` over ``n`` variables."""
    if i >= n:
        raise ValueError(f"variable {i} out of range for {n} variables")
    s = 1 << i
    block = ((1 << s) - 1) << s          # 2s bits: s zeros then s ones
    width = 2 * s
    t = block
    total = 1 << n
    while width < total:
        t |= t << width
        width *= 2
    return t


@lru_cache(maxsize=None)
def nvar(n: int, i: int) -> int:
    """Truth table of the complement of variable ``i`` over ``n`` variables."""
    return mask(n) & ~var(n, i)


@lru_cache(maxsize=None)
def var_tables(n: int) -> tuple[tuple[int, ...], tuple[int, ...]]:
    """``(var(n, i) for all i, nvar(n, i) for all i)``: for inner loops."""
    return tuple(var(n, i) for i in range(n)), tuple(nvar(n, i) for i in range(n))


def cof0(t: int, n: int, i: int) -> int:
    """Negative cofactor w.r.t. variable ``i``, as a full-width table independent of ``i``."""
    lo = t & nvar(n, i)
    return lo | (lo << (1 << i))


def cof1(t: int, n: int, i: int) -> int:
    """Positive cofactor w.r.t. variable ``i``, as a full-width table independent of ``i``."""
    x = var(n, i)
    hi = t & x
    return hi | (hi >> (1 << i))


def depends(t: int, n: int, i: int) -> bool:
    return ((t & var(n, i)) >> (1 << i)) != (t & nvar(n, i))


def support(t: int, n: int) -> list[int]:
    return [i for i in range(n) if depends(t, n, i)]


def popcount(x: int) -> int:
    return x.bit_count()


# ----------------------------------------------------------------------------------------
# Irredundant sum of products (Minato-Morreale) on an interval [L, U]
# ----------------------------------------------------------------------------------------

Cube = tuple[int, int]   # (positive-literal mask, negative-literal mask) over variables


def isop(lower: int, upper: int, n: int) -> tuple[list[Cube], int]:
    """An irredundant SOP cover ``C`` with ``lower <= C <= upper`` (as sets of minterms).

    Returns ``(cubes, table_of_cover)``.  ``upper`` must contain ``lower``.
    """
    full = mask(n)
    if lower & ~upper & full:
        raise ValueError("isop: lower bound not contained in upper bound")
    memo: dict[tuple[int, int, int], tuple[object, int]] = {}
    pos, neg = var_tables(n)
    taut = ()                    # the cover of the tautology: one empty cube

    # A cover is built as a tree (None: empty; taut; (c0, c1, c2, bit): the cubes of
    # c0 with !x_bit, of c1 with x_bit, then c2's) and listed once at the end: the same
    # cubes in the same order as concatenating the lists at every level, without
    # copying them once per level.
    def rec(L: int, U: int, top: int) -> tuple[object, int]:
        if L == 0:
            return None, 0
        if U == full:
            return taut, full
        key = (L, U, top)
        r = memo.get(key)
        if r is not None:
            return r
        v = top - 1
        while v >= 0:
            s, x, nx = 1 << v, pos[v], neg[v]
            if ((L & x) >> s) != (L & nx) or ((U & x) >> s) != (U & nx):
                break
            v -= 1
        assert v >= 0
        t = L & nx
        L0 = t | (t << s)
        t = L & x
        L1 = t | (t >> s)
        t = U & nx
        U0 = t | (t << s)
        t = U & x
        U1 = t | (t >> s)
        c0, f0 = rec(L0 & ~U1 & full, U0, v)
        c1, f1 = rec(L1 & ~U0 & full, U1, v)
        Ln = (L0 & ~f0 | L1 & ~f1) & full
        c2, f2 = rec(Ln, U0 & U1, v)
        f = f2 | (f0 & nx) | (f1 & x)
        r = memo[key] = ((c0, c1, c2, 1 << v), f)
        return r

    tree, f = rec(lower, upper, n)
    cubes: list[Cube] = []
    stack = [(tree, 0, 0)]
    while stack:
        c, p, q = stack.pop()
        if c is None:
            continue
        if c is taut:
            cubes.append((p, q))
            continue
        c0, c1, c2, bit = c
        stack.append((c2, p, q))
        stack.append((c1, p | bit, q))
        stack.append((c0, p, q | bit))
    return cubes, f


def cube_tt(c: Cube, n: int) -> int:
    t = mask(n)
    p, q = c
    for i in range(n):
        if (p >> i) & 1:
            t &= var(n, i)
        elif (q >> i) & 1:
            t &= ~var(n, i)
    return t & mask(n)


# ----------------------------------------------------------------------------------------
# Small tables (<= 6 variables): permutation / negation, NPN canonical form
# ----------------------------------------------------------------------------------------

def flip(t: int, n: int, i: int) -> int:
    """Complement variable ``i``."""
    x = var(n, i)
    s = 1 << i
    return ((t & x) >> s) | ((t & ~x & mask(n)) << s)


def swap_adjacent(t: int, n: int, i: int) -> int:
    """Swap variables ``i`` and ``i+1``."""
    # minterms with x_i=1, x_{i+1}=0 exchange with x_i=0, x_{i+1}=1
    a = var(n, i) & ~var(n, i + 1) & mask(n)
    b = var(n, i + 1) & ~var(n, i) & mask(n)
    s = 1 << i
    return (t & ~(a | b)) | ((t & a) << s) | ((t & b) >> s)


def permute(t: int, n: int, perm: list[int]) -> int:
    """Table ``g`` with ``g(y) = t(x)`` where ``y[perm[i]] = x[i]``, i.e. variable i moves to perm[i]."""
    res = 0
    for m in range(1 << n):
        if (t >> m) & 1:
            mm = 0
            for i in range(n):
                if (m >> i) & 1:
                    mm |= 1 << perm[i]
            res |= 1 << mm
    return res


def stretch(t: int, k: int, n: int, vars_: list[int]) -> int:
    """Lift a table over ``k`` local variables to ``n`` variables: local i := global vars_[i]."""
    res = 0
    for m in range(1 << n):
        lm = 0
        for i, g in enumerate(vars_):
            if (m >> g) & 1:
                lm |= 1 << i
        if (t >> lm) & 1:
            res |= 1 << m
    return res


@lru_cache(maxsize=4096)
def _shrink_minterms(vars_: tuple[int, ...]) -> tuple[int, ...]:
    """The global minterm of every local minterm of :func:`shrink`."""
    out = []
    for lm in range(1 << len(vars_)):
        m = 0
        for i, g in enumerate(vars_):
            if (lm >> i) & 1:
                m |= 1 << g
        out.append(m)
    return tuple(out)


def shrink(t: int, n: int, vars_: list[int]) -> int:
    """Restrict a table over ``n`` variables that only depends on ``vars_`` to those variables."""
    res = 0
    for lm, m in enumerate(_shrink_minterms(tuple(vars_))):
        if (t >> m) & 1:
            res |= 1 << lm
    return res
