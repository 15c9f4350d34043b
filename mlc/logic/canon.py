"""Canonical input and output order of a table specification.

The synthesis passes look at inputs and outputs in index order (which variable a
decomposition peels first, which node a pass visits first), so without care the
AND count depends on how the specification happens to list them.  :func:`canonical`
puts a :class:`~mlc.spec.TableSpec` into an order that depends only on the
function: any listing of the same multi-output function (inputs and outputs
permuted) gives the same canonical table, so synthesis on it gives the same
circuit, and :func:`restore` maps that circuit back to the listing given.

How the order is found (colour refinement, then an exhaustive tie-break):

1. every input and output gets a colour from statistics that do not depend on the
   order: per output the sizes of its on- and don't-care sets; per input and output
   the on/dc counts of the two cofactors; per pair of inputs and output the on/dc
   counts of the four joint cofactors;
2. colours are refined (each input's colour absorbs the multiset of its neighbours'
   colours with the statistics on the edge, likewise outputs) until stable;
3. inputs are ordered by colour; inputs of equal colour are tried in every order
   (their product, up to :data:`MAX_TIES` orders; a class whose members are all
   interchangeable -- every adjacent transposition maps the set of output functions
   onto itself -- needs one order only), outputs sorted by (colour, table), and the
   least resulting list of output tables is the canonical form.

Above :data:`MAX_TIES` tied orders the tie-break keeps the given order within a
class (still a valid order, but then the result may depend on the listing); on the
benchmark and test functions this never happens.
"""
from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

from mlc.spec import TableSpec
from mlc.logic import tt as T
from mlc.logic.aig import AIG

MAX_TIES = 5040
MAX_INPUTS = 16


@dataclass
class Canon:
    spec: TableSpec            # the canonical specification
    in_perm: list[int]         # canonical input k = original input in_perm[k]
    out_perm: list[int]        # canonical output k = original output out_perm[k]
    exhaustive: bool           # False if the tie-break was cut at MAX_TIES


def _bits(t: int, n: int) -> np.ndarray:
    size = 1 << n
    nb = max(1, size // 8)
    a = np.frombuffer(t.to_bytes(nb, "little"), dtype=np.uint8)
    return np.unpackbits(a, bitorder="little")[:size].astype(bool)


def _int(b: np.ndarray) -> int:
    return int.from_bytes(np.packbits(b, bitorder="little").tobytes(), "little")


def _index(n: int, perm: list[int]) -> np.ndarray:
    """idx[m] = the original minterm read for new minterm m when new input k is
    original input perm[k]."""
    m = np.arange(1 << n, dtype=np.int64)
    idx = np.zeros(1 << n, dtype=np.int64)
    for k, p in enumerate(perm):
        idx |= ((m >> k) & 1) << p
    return idx


def _ranks(sigs: list) -> list[int]:
    order = sorted(set(sigs))
    r = {s: i for i, s in enumerate(order)}
    return [r[s] for s in sigs]


def _colours(spec: TableSpec) -> tuple[list[int], list[int]]:
    n, m = spec.n, len(spec.outputs)
    full = T.mask(n)
    xs = [T.var(n, i) for i in range(n)]
    nxs = [full & ~x for x in xs]
    on, dc = spec.on, spec.dc
    single = [[((on[o] & xs[i]).bit_count(), (on[o] & nxs[i]).bit_count(),
                (dc[o] & xs[i]).bit_count(), (dc[o] & nxs[i]).bit_count())
               for o in range(m)] for i in range(n)]
    pair = None
    if n <= 12:
        pair = {}
        for i in range(n):
            for j in range(i + 1, n):
                for o in range(m):
                    st = []
                    for a in (xs[i], nxs[i]):
                        for b in (xs[j], nxs[j]):
                            st.append((on[o] & a & b).bit_count())
                            st.append((dc[o] & a & b).bit_count())
                    pair[i, j, o] = tuple(st)
                    # seen from j: swap the roles of i and j (positions 1 <-> 2 of the 2x2)
                    s = st
                    pair[j, i, o] = (s[0], s[1], s[4], s[5], s[2], s[3], s[6], s[7])
    oc = _ranks([(on[o].bit_count(), dc[o].bit_count()) for o in range(m)])
    ic = [0] * n
    for _ in range(n + m + 1):
        nic = []
        for i in range(n):
            s = [ic[i], tuple(sorted((oc[o], single[i][o]) for o in range(m)))]
            if pair is not None:
                s.append(tuple(sorted((ic[j], oc[o], pair[i, j, o])
                                      for j in range(n) if j != i for o in range(m))))
            nic.append(tuple(s))
        noc = [(oc[o], tuple(sorted((ic[i], single[i][o]) for i in range(n))))
               for o in range(m)]
        nic, noc = _ranks(nic), _ranks(noc)
        if len(set(nic)) == len(set(ic)) and len(set(noc)) == len(set(oc)):
            ic, oc = nic, noc
            break
        ic, oc = nic, noc
    return ic, oc


def _swap_invariant(spec: TableSpec, i: int, j: int) -> bool:
    """Does exchanging inputs i and j map the set of (on, dc) output pairs onto itself?"""
    n = spec.n
    perm = list(range(n))
    perm[i], perm[j] = j, i
    idx = _index(n, perm)
    before = sorted(zip(spec.on, spec.dc))
    after = sorted((_int(_bits(f, n)[idx]), _int(_bits(d, n)[idx])) for f, d in zip(spec.on, spec.dc))
    return before == after


def canonical(spec: TableSpec) -> Canon:
    """The canonical form of ``spec`` (see the module docstring)."""
    n, m = spec.n, len(spec.outputs)
    if n > MAX_INPUTS or n == 0:
        return Canon(spec, list(range(n)), list(range(m)), False)
    ic, oc = _colours(spec)
    classes: list[list[int]] = []
    for c in sorted(set(ic)):
        classes.append([i for i in range(n) if ic[i] == c])
    options = []
    total = 1
    exhaustive = True
    for cls in classes:
        if len(cls) == 1 or all(_swap_invariant(spec, cls[a], cls[a + 1])
                                for a in range(len(cls) - 1)):
            options.append([tuple(cls)])
            continue
        k = 1
        for t in range(2, len(cls) + 1):
            k *= t
        if total * k > MAX_TIES:
            options.append([tuple(cls)])
            exhaustive = False
            continue
        total *= k
        options.append(list(itertools.permutations(cls)))
    onb = [_bits(f, n) for f in spec.on]
    dcb = [_bits(d, n) for d in spec.dc]
    best = None
    for choice in itertools.product(*options):
        perm = [i for part in choice for i in part]
        idx = _index(n, perm)
        outs = sorted((oc[o], _int(onb[o][idx]), _int(dcb[o][idx]), o) for o in range(m))
        key = tuple(x[:3] for x in outs)
        if best is None or key < best[0]:
            best = (key, perm, [x[3] for x in outs])
    key, perm, operm = best
    cs = TableSpec([spec.inputs[i] for i in perm], [spec.outputs[o] for o in operm],
                   [k[1] for k in key], [k[2] for k in key], spec.source)
    return Canon(cs, perm, operm, exhaustive)


def permuted(spec: TableSpec, in_perm: list[int], out_perm: list[int]) -> TableSpec:
    """``spec`` listed in another order: new input k is old input ``in_perm[k]``, new
    output k is old output ``out_perm[k]``."""
    n = spec.n
    idx = _index(n, in_perm)
    return TableSpec([spec.inputs[i] for i in in_perm], [spec.outputs[o] for o in out_perm],
                     [_int(_bits(spec.on[o], n)[idx]) for o in out_perm],
                     [_int(_bits(spec.dc[o], n)[idx]) for o in out_perm], spec.source,
                     [spec.output_locs[o] for o in out_perm] if spec.output_locs else [])


def restore(g: AIG, c: Canon, spec) -> AIG:
    """Circuit ``g`` of the canonical spec ``c.spec``, re-expressed over ``spec``'s
    input and output order (and names); ``spec`` is a table or a network."""
    n = len(spec.inputs)
    h = AIG(spec.inputs)
    m = [0] * g.num_nodes
    for k in range(n):
        m[k + 1] = 2 * (c.in_perm[k] + 1)
    for k, (a, b) in enumerate(g.ands):
        m[n + 1 + k] = h.and_(m[a >> 1] ^ (a & 1), m[b >> 1] ^ (b & 1))
    lit_of = {}
    for k, o in enumerate(c.out_perm):
        lit = g.output_lits[k]
        lit_of[o] = m[lit >> 1] ^ (lit & 1)
    for o, name in enumerate(spec.outputs):
        h.add_output(name, lit_of[o])
    return h.cleanup()


def to_canonical(g: AIG, c: Canon) -> AIG:
    """Circuit ``g`` over the original listing, re-expressed over the canonical order
    (inputs and outputs of ``c.spec``), its nodes numbered depth-first from the
    canonical outputs (so the numbering does not depend on the listing either)."""
    n = g.num_inputs
    pos = [0] * n
    for k, i in enumerate(c.in_perm):
        pos[i] = k
    h = AIG(c.spec.inputs)
    m: dict[int, int] = {0: 0}
    for i in range(n):
        m[i + 1] = 2 * (pos[i] + 1)
    stack_roots = [g.output_lits[o] >> 1 for o in c.out_perm]
    for root in stack_roots:
        stack = [root]
        while stack:
            x = stack[-1]
            if x in m:
                stack.pop()
                continue
            a, b = g.ands[x - n - 1]
            pend = [y for y in (a >> 1, b >> 1) if y not in m]
            if pend:
                stack.extend(pend)
                continue
            stack.pop()
            m[x] = h.and_(m[a >> 1] ^ (a & 1), m[b >> 1] ^ (b & 1))
    for k, o in enumerate(c.out_perm):
        lit = g.output_lits[o]
        h.add_output(c.spec.outputs[k], m[lit >> 1] ^ (lit & 1))
    return h
