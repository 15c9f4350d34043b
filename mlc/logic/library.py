"""Standard small functions as :class:`~mlc.spec.TableSpec`: the synthesis
benchmark's suite (benchmarks/synthesis.py) and the tests' reference functions;
wide arithmetic as :class:`~mlc.spec.NetworkSpec` (:func:`ripple_adder`,
:func:`array_multiplier`)."""
from __future__ import annotations

import random
from collections.abc import Callable

from mlc.spec import NetworkSpec, Node, TableSpec


def table(name: str, inputs: list[str], outputs: list[str],
          fn: Callable[[list[int]], list[int | None]]) -> TableSpec:
    """Tabulate ``fn`` (input bits -> output bits, None = don't care)."""
    n = len(inputs)
    on = [0] * len(outputs)
    dc = [0] * len(outputs)
    for m in range(1 << n):
        bits = [(m >> i) & 1 for i in range(n)]
        vals = fn(bits)
        for o, v in enumerate(vals):
            if v is None:
                dc[o] |= 1 << m
            elif v:
                on[o] |= 1 << m
    return TableSpec(inputs, outputs, on, dc, source=name)


def _num(bits):
    return sum(b << i for i, b in enumerate(bits))


def _bits(x, w):
    return [(x >> i) & 1 for i in range(w)]


def half_adder():
    return table("half_adder", ["a", "b"], ["s", "c"], lambda x: [x[0] ^ x[1], x[0] & x[1]])


def full_adder():
    return table("full_adder", ["a", "b", "cin"], ["s", "cout"],
                 lambda x: [x[0] ^ x[1] ^ x[2], int(x[0] + x[1] + x[2] >= 2)])


def adder(w: int, carry_in: bool = False):
    ins = [f"a{i}" for i in range(w)] + [f"b{i}" for i in range(w)] + (["cin"] if carry_in else [])
    outs = [f"s{i}" for i in range(w + 1)]

    def fn(x):
        a, b = _num(x[:w]), _num(x[w:2 * w])
        c = x[2 * w] if carry_in else 0
        return _bits(a + b + c, w + 1)
    return table(f"adder{w}" + ("c" if carry_in else ""), ins, outs, fn)


def multiplier(w: int, v: int | None = None):
    v = w if v is None else v
    ins = [f"a{i}" for i in range(w)] + [f"b{i}" for i in range(v)]
    outs = [f"p{i}" for i in range(w + v)]
    return table(f"mult{w}x{v}", ins, outs, lambda x: _bits(_num(x[:w]) * _num(x[w:]), w + v))


def ripple_adder(w: int) -> NetworkSpec:
    """A ``w``-bit ripple-carry adder as a network (XOR/MAJ per bit), inputs
    ``a0.. b0..``, outputs ``s0 .. sw`` (``sw`` the carry out)."""
    ins = [f"a{i}" for i in range(w)] + [f"b{i}" for i in range(w)]
    nodes = [Node("input", name=x) for x in ins]
    carry = None
    outs = []
    for i in range(w):
        a, b = i, w + i
        if carry is None:
            nodes.append(Node("xor", (a, b)))
            outs.append(len(nodes) - 1)
            nodes.append(Node("and", (a, b)))
        else:
            nodes.append(Node("xor", (a, b, carry)))
            outs.append(len(nodes) - 1)
            nodes.append(Node("maj", (a, b, carry)))
        carry = len(nodes) - 1
    outs.append(carry)
    return NetworkSpec(ins, [f"s{i}" for i in range(w + 1)], nodes, outs, source=f"ripple_adder({w})")


def array_multiplier(w: int, swap: bool = False) -> NetworkSpec:
    """A ``w`` x ``w``-bit unsigned array multiplier as a network (ripple-carry rows of
    full adders over the partial products ``a_i & b_j``), inputs ``a0.. b0..``,
    outputs ``p0 .. p(2w-1)``.  ``swap`` builds the same function with the operands'
    roles exchanged (``b * a``): a structurally different network, hard to prove
    equivalent to the unswapped one."""
    if w < 2:
        raise ValueError("array_multiplier needs w >= 2")
    ins = [f"a{i}" for i in range(w)] + [f"b{i}" for i in range(w)]
    nodes = [Node("input", name=x) for x in ins]
    x, y = (range(w, 2 * w), range(w)) if swap else (range(w), range(w, 2 * w))
    x, y = list(x), list(y)

    def add(op: str, *args: int) -> int:
        nodes.append(Node(op, args))
        return len(nodes) - 1

    rows = [[add("and", x[i], y[j]) for i in range(w)] for j in range(w)]
    outs = [rows[0][0]]
    acc = rows[0][1:]                      # running sum, bit 1 upwards
    for j in range(1, w):
        carry, new = None, []
        for i in range(w):
            s_in = acc[i] if i < len(acc) else None
            terms = [t for t in (s_in, rows[j][i], carry) if t is not None]
            if len(terms) == 1:
                new.append(terms[0])
                continue
            new.append(add("xor", *terms))
            carry = add("maj" if len(terms) == 3 else "and", *terms)
        new.append(carry)
        outs.append(new[0])
        acc = new[1:]
    outs += acc
    return NetworkSpec(ins, [f"p{k}" for k in range(2 * w)], nodes, outs,
                       source=f"array_multiplier({w})")


def nand_mesh(width: int, depth: int) -> NetworkSpec:
    """A mesh of ``depth`` levels of ``width`` gates, each fed by two neighbours of the level
    below: level 1 is ``NAND(x2i, x2i+1)``; above it gate i is ``NAND(g_i, g_i+1)`` of the
    level below, the last ``NOR(g_w-1, g_w-2)`` (a NAND there would repeat its neighbour).
    Inputs ``x0 .. x(2 width - 1)``, outputs ``y0 ..`` the top level.  Every wire runs one
    level up and at most one column across, so a circuit of many gates keeps short wires;
    at width 7 (14 inputs) it keeps ``width * depth`` gates when compiled at -O0 (narrower
    meshes repeat their functions after a few levels and synthesis merges them)."""
    if width < 2 or depth < 1:
        raise ValueError("nand_mesh needs width >= 2 and depth >= 1")
    ins = [f"x{i}" for i in range(2 * width)]
    nodes = [Node("input", name=x) for x in ins]

    def add(op: str, *args: int) -> int:
        nodes.append(Node(op, args))
        return len(nodes) - 1

    level = [add("nand", 2 * i, 2 * i + 1) for i in range(width)]
    for _ in range(depth - 1):
        level = [add("nand", level[i], level[i + 1]) if i + 1 < width else add("nor", level[i], level[i - 1])
                 for i in range(width)]
    return NetworkSpec(ins, [f"y{i}" for i in range(width)], nodes, level, source=f"nand_mesh({width},{depth})")


SEG = {0: "abcdef", 1: "bc", 2: "abdeg", 3: "abcdg", 4: "bcfg", 5: "acdfg", 6: "acdefg",
       7: "abc", 8: "abcdefg", 9: "abcdfg"}


def bcd7seg():
    ins = ["d0", "d1", "d2", "d3"]
    outs = list("abcdefg")

    def fn(x):
        v = _num(x)
        if v > 9:
            return [None] * 7
        return [int(s in SEG[v]) for s in outs]
    return table("bcd7seg", ins, outs, fn)


def comparator(w: int):
    ins = [f"a{i}" for i in range(w)] + [f"b{i}" for i in range(w)]

    def fn(x):
        a, b = _num(x[:w]), _num(x[w:])
        return [int(a < b), int(a == b), int(a > b)]
    return table(f"cmp{w}", ins, ["lt", "eq", "gt"], fn)


def parity(n: int):
    return table(f"parity{n}", [f"x{i}" for i in range(n)], ["p"], lambda x: [sum(x) & 1])


def majority(n: int):
    return table(f"maj{n}", [f"x{i}" for i in range(n)], ["m"], lambda x: [int(2 * sum(x) > n)])


def mux(k: int):
    """2**k-to-1 multiplexer: k select lines then 2**k data inputs."""
    ins = [f"s{i}" for i in range(k)] + [f"d{i}" for i in range(1 << k)]
    return table(f"mux{1 << k}", ins, ["y"], lambda x: [x[k + _num(x[:k])]])


def decoder(k: int):
    ins = [f"a{i}" for i in range(k)]
    outs = [f"y{i}" for i in range(1 << k)]
    return table(f"dec{k}to{1 << k}", ins, outs, lambda x: [int(_num(x) == j) for j in range(1 << k)])


def priority_encoder(n: int = 4):
    w = max(1, (n - 1).bit_length())
    ins = [f"r{i}" for i in range(n)]

    def fn(x):
        hi = max((i for i in range(n) if x[i]), default=None)
        if hi is None:
            return [None] * w + [0]
        return _bits(hi, w) + [1]
    return table(f"prio{n}", ins, [f"y{i}" for i in range(w)] + ["valid"], fn)


def gray(n: int = 4):
    ins = [f"b{i}" for i in range(n)]

    def fn(x):
        v = _num(x)
        return _bits(v ^ (v >> 1), n)
    return table(f"bin2gray{n}", ins, [f"g{i}" for i in range(n)], fn)


def gray_to_bin(n: int = 4):
    ins = [f"g{i}" for i in range(n)]

    def fn(x):
        v = _num(x)
        r = 0
        while v:
            r ^= v
            v >>= 1
        return _bits(r, n)
    return table(f"gray2bin{n}", ins, [f"b{i}" for i in range(n)], fn)


def parity_prefix(n: int):
    """Prefix parities ``p_k = x0 ^ ... ^ xk``, k = 0 .. n-1 (outputs share an XOR chain)."""
    ins = [f"x{i}" for i in range(n)]
    return table(f"parity_prefix{n}", ins, [f"p{k}" for k in range(n)],
                 lambda x: [sum(x[:k + 1]) & 1 for k in range(n)])


def reversed_bits(spec: TableSpec) -> TableSpec:
    """``spec`` with its inputs and its outputs listed in reverse order (most
    significant bit first, for the library's least-significant-first functions)."""
    from mlc.logic.canon import permuted
    n, m = spec.n, len(spec.outputs)
    r = permuted(spec, list(range(n - 1, -1, -1)), list(range(m - 1, -1, -1)))
    r.source = spec.source + "_msb"
    return r


def xor_suite() -> list[TableSpec]:
    """Multi-output functions whose outputs share XOR chains (issue 15): code
    converters, parity prefixes, comparators and adders, in both bit orders."""
    base = [gray(4), gray_to_bin(4), gray(6), gray_to_bin(6), gray_to_bin(8),
            parity_prefix(4), parity_prefix(6), parity_prefix(8),
            comparator(2), comparator(3), comparator(4), adder(2), adder(3), adder(4)]
    return [f for b in base for f in (b, reversed_bits(b))]


def random_function(n: int, m: int, seed: int, dc_fraction: float = 0.0):
    rng = random.Random(seed)
    ins = [f"x{i}" for i in range(n)]
    outs = [f"y{i}" for i in range(m)]
    tag = f"_dc{int(dc_fraction * 100)}" if dc_fraction else ""
    return table(f"rand{n}x{m}_s{seed}{tag}", ins, outs,
                 lambda x: [None if rng.random() < dc_fraction else rng.getrandbits(1)
                            for _ in range(m)])


def suite() -> list[TableSpec]:
    """The benchmark suite (small functions)."""
    return [
        half_adder(), full_adder(), adder(2), adder(2, carry_in=True), multiplier(2),
        bcd7seg(), comparator(1), comparator(2), parity(3), parity(4), parity(5),
        majority(3), majority(5), mux(1), mux(2), decoder(2), decoder(3),
        priority_encoder(4), gray(4), gray_to_bin(4),
        random_function(4, 1, 1), random_function(4, 2, 2, 0.25),
        random_function(5, 1, 3), random_function(5, 1, 4, 0.3),
        random_function(6, 1, 5), random_function(6, 2, 6, 0.3),
        random_function(7, 1, 7), random_function(7, 1, 8, 0.3),
    ]


# proven minima (AND gates, inversions free) quoted by issue 4
KNOWN_MINIMA = {"full_adder": 7, "adder2": 10, "mult2x2": 8, "maj3": 4, "parity4": 9}
