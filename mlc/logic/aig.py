"""And-Inverter Graph with complemented edges: the synthesis IR of mlc.

In mlc's mechanical architecture a gate computes ``(a^p AND b^q)^r`` with every
inversion free, so a circuit costs exactly the number of AND nodes of an AIG whose
edges may be complemented; logic depth is the tie-breaker.

Numbering (the AIGER convention):

* a *literal* is ``2*node + c`` where ``c = 1`` means complemented;
* node 0 is the constant false (literal 0 = false, literal 1 = true);
* nodes ``1 .. n`` are the primary inputs, in the order of :attr:`AIG.inputs`;
* nodes ``n+1 ..`` are the AND nodes, ``ands[k]`` being the pair of fanin literals of
  node ``n+1+k``.
"""
from __future__ import annotations

from collections.abc import Sequence

from mlc.errors import InternalError
from mlc.logic import tt as _tt

FALSE = 0
TRUE = 1


def lit_not(a: int) -> int:
    return a ^ 1


def lit_node(a: int) -> int:
    return a >> 1


def balanced(f, xs):
    """Combine ``xs`` (at least one) with the binary ``f`` as a balanced tree: pairs first,
    so depth grows as log2(len(xs))."""
    xs = list(xs)
    while len(xs) > 1:
        nxt = [f(xs[i], xs[i + 1]) for i in range(0, len(xs) - 1, 2)]
        if len(xs) % 2:
            nxt.append(xs[-1])
        xs = nxt
    return xs[0]


class AIG:
    """A structurally hashed AIG.

    Invariants (checked by :meth:`check`):

    1. input names are non-empty and unique; output names are non-empty and unique,
       and ``len(outputs) == len(output_lits)``;
    2. every AND node's fanins ``(a, b)`` refer to earlier nodes (``a >> 1`` and
       ``b >> 1`` are smaller than the node's own index) and satisfy ``a < b``;
    3. no AND node is trivial: no constant fanin, and the two fanins are on
       different nodes (``a >> 1 != b >> 1``), so ``x & x`` and ``x & !x`` never appear;
    4. no two AND nodes have the same fanin pair (structural hashing);
    5. every output literal is a literal of an existing node.

    Build with :meth:`add_input`, :meth:`and_` (and the derived ``or_``, ``xor_``,
    ``mux_``, ``maj_``) and :meth:`add_output`; :meth:`and_` hashes, normalises the
    fanin order and folds constants and trivial cases, so the invariants hold by
    construction.
    """

    def __init__(self, inputs: Sequence[str] = ()):
        self.inputs: list[str] = []
        self.outputs: list[str] = []
        self.ands: list[tuple[int, int]] = []
        self.output_lits: list[int] = []
        self._hash: dict[tuple[int, int], int] = {}
        for name in inputs:
            self.add_input(name)

    # ---------------------------------------------------------------- construction
    @classmethod
    def from_parts(cls, inputs: Sequence[str], outputs: Sequence[str],
                   ands: Sequence[tuple[int, int]], output_lits: Sequence[int]) -> "AIG":
        """Assemble an AIG from raw lists and :meth:`check` it."""
        g = cls()
        g.inputs = list(inputs)
        g.outputs = list(outputs)
        g.ands = [tuple(x) for x in ands]
        g.output_lits = list(output_lits)
        g.check()
        n = len(g.inputs)
        g._hash = {pair: 2 * (n + 1 + k) for k, pair in enumerate(g.ands)}
        return g

    @property
    def num_inputs(self) -> int:
        return len(self.inputs)

    @property
    def num_nodes(self) -> int:
        """Number of nodes including the constant node 0."""
        return 1 + len(self.inputs) + len(self.ands)

    def input_lit(self, i: int) -> int:
        return 2 * (i + 1)

    def is_and(self, node: int) -> bool:
        return node > len(self.inputs)

    def fanins(self, node: int) -> tuple[int, int]:
        return self.ands[node - len(self.inputs) - 1]

    def add_input(self, name: str) -> int:
        if self.ands:
            raise InternalError("AIG.add_input after AND nodes were created")
        self.inputs.append(name)
        return 2 * len(self.inputs)

    def add_output(self, name: str, lit: int) -> None:
        self.outputs.append(name)
        self.output_lits.append(lit)

    def and_(self, a: int, b: int) -> int:
        """AND of two literals: folded or structurally hashed by :meth:`lookup` when
        possible, otherwise a new node."""
        r = self.lookup(a, b)
        if r is not None:
            return r
        if a > b:
            a, b = b, a
        r = 2 * self.num_nodes
        self.ands.append((a, b))
        self._hash[(a, b)] = r
        return r

    def lookup(self, a: int, b: int) -> int | None:
        """The literal ``and_(a, b)`` would return if it creates no node, else None."""
        if a > b:
            a, b = b, a
        if a == 0:
            return 0
        if a == 1:
            return b
        if a == b:
            return a
        if a ^ b == 1:
            return 0
        return self._hash.get((a, b))

    def or_(self, a: int, b: int) -> int:
        return self.and_(a ^ 1, b ^ 1) ^ 1

    def xor_(self, a: int, b: int) -> int:
        # a ^ b = !(a & b) & !(!a & !b): three ANDs, sharing a & b with carries
        return self.and_(self.and_(a, b) ^ 1, self.and_(a ^ 1, b ^ 1) ^ 1)

    def mux_(self, s: int, t: int, e: int) -> int:
        """``s ? t : e``."""
        return self.or_(self.and_(s, t), self.and_(s ^ 1, e))

    def maj_(self, a: int, b: int, c: int) -> int:
        return self.or_(self.and_(a, b), self.and_(c, self.or_(a, b)))

    def and_many(self, lits: Sequence[int]) -> int:
        """Balanced AND of several literals."""
        return balanced(self.and_, lits) if lits else TRUE

    def or_many(self, lits: Sequence[int]) -> int:
        return self.and_many([x ^ 1 for x in lits]) ^ 1

    def xor_many(self, lits: Sequence[int]) -> int:
        """Balanced XOR of several literals."""
        return balanced(self.xor_, lits) if lits else FALSE

    # ---------------------------------------------------------------- invariants
    def check(self) -> None:
        """Raise :class:`InternalError` unless every invariant of the class docstring holds."""
        def bad(msg: str) -> None:
            raise InternalError(f"malformed AIG: {msg}")

        if len(set(self.inputs)) != len(self.inputs):
            bad("duplicate input names")
        if any(not isinstance(s, str) or not s for s in self.inputs):
            bad("empty input name")
        if len(self.outputs) != len(self.output_lits):
            bad(f"{len(self.outputs)} outputs but {len(self.output_lits)} output literals")
        if len(set(self.outputs)) != len(self.outputs):
            bad("duplicate output names")
        if any(not isinstance(s, str) or not s for s in self.outputs):
            bad("empty output name")
        n = len(self.inputs)
        seen: set[tuple[int, int]] = set()
        for k, pair in enumerate(self.ands):
            node = n + 1 + k
            if len(pair) != 2 or not all(isinstance(x, int) for x in pair):
                bad(f"node {node}: fanins must be two int literals")
            a, b = pair
            if a < 0 or b < 0 or (a >> 1) >= node or (b >> 1) >= node:
                bad(f"node {node}: fanin ({a}, {b}) does not refer to an earlier node")
            if not a < b:
                bad(f"node {node}: fanins ({a}, {b}) not in increasing order")
            if (a >> 1) == 0:
                bad(f"node {node}: constant fanin")
            if (a >> 1) == (b >> 1):
                bad(f"node {node}: both fanins on node {a >> 1}")
            if pair in seen:
                bad(f"node {node}: duplicate of an earlier AND node ({a}, {b})")
            seen.add(pair)
        limit = 2 * self.num_nodes
        for name, lit in zip(self.outputs, self.output_lits):
            if not isinstance(lit, int) or lit < 0 or lit >= limit:
                bad(f"output {name}: literal {lit} out of range")

    # ---------------------------------------------------------------- measures
    def num_ands(self) -> int:
        return len(self.ands)

    def levels(self) -> list[int]:
        """Logic level of every node (inputs and constant 0)."""
        n = len(self.inputs)
        lev = [0] * self.num_nodes
        for k, (a, b) in enumerate(self.ands):
            lev[n + 1 + k] = 1 + max(lev[a >> 1], lev[b >> 1])
        return lev

    def depth(self) -> int:
        lev = self.levels()
        return max((lev[x >> 1] for x in self.output_lits), default=0)

    def fanout_counts(self) -> list[int]:
        fo = [0] * self.num_nodes
        for a, b in self.ands:
            fo[a >> 1] += 1
            fo[b >> 1] += 1
        for x in self.output_lits:
            fo[x >> 1] += 1
        return fo

    # ---------------------------------------------------------------- simulation
    def simulate_nodes(self, input_words: Sequence[int], width: int) -> list[int]:
        """Bit-parallel values of every node for ``width``-bit input words."""
        if len(input_words) != len(self.inputs):
            raise InternalError(f"simulate: {len(input_words)} words for {len(self.inputs)} inputs")
        full = (1 << width) - 1
        val = [0] * self.num_nodes
        for i, w in enumerate(input_words):
            val[i + 1] = w & full
        base = len(self.inputs) + 1
        for k, (a, b) in enumerate(self.ands):
            x = val[a >> 1]
            if a & 1:
                x ^= full
            y = val[b >> 1]
            if b & 1:
                y ^= full
            val[base + k] = x & y
        return val

    def simulate(self, input_words: Sequence[int], width: int) -> list[int]:
        """Bit-parallel output values for ``width``-bit input words (one int per input)."""
        full = (1 << width) - 1
        val = self.simulate_nodes(input_words, width)
        return [val[x >> 1] ^ (full if x & 1 else 0) for x in self.output_lits]

    def truth_tables(self) -> list[int]:
        """Exhaustive output truth tables (minterm numbering of :mod:`mlc.logic.tt`)."""
        n = len(self.inputs)
        return self.simulate([_tt.var(n, i) for i in range(n)], 1 << n)

    def node_tables(self) -> list[int]:
        n = len(self.inputs)
        return self.simulate_nodes([_tt.var(n, i) for i in range(n)], 1 << n)

    # ---------------------------------------------------------------- transforms
    def copy(self) -> "AIG":
        g = AIG()
        g.inputs = list(self.inputs)
        g.outputs = list(self.outputs)
        g.ands = list(self.ands)
        g.output_lits = list(self.output_lits)
        g._hash = dict(self._hash)
        return g

    def cleanup(self) -> "AIG":
        """A copy without the AND nodes that no output reaches, renumbered and re-hashed."""
        n = len(self.inputs)
        live = [False] * self.num_nodes
        for x in self.output_lits:
            live[x >> 1] = True
        for node in range(self.num_nodes - 1, n, -1):
            if live[node]:
                a, b = self.ands[node - n - 1]
                live[a >> 1] = True
                live[b >> 1] = True
        g = AIG(self.inputs)
        m = list(range(0, 2 * (n + 1), 2)) + [0] * len(self.ands)
        for k, (a, b) in enumerate(self.ands):
            node = n + 1 + k
            if live[node]:
                m[node] = g.and_(m[a >> 1] ^ (a & 1), m[b >> 1] ^ (b & 1))
        for name, x in zip(self.outputs, self.output_lits):
            g.add_output(name, m[x >> 1] ^ (x & 1))
        return g

    # ---------------------------------------------------------------- text
    def to_text(self) -> str:
        """Stable text form: header, one line per input, AND node and output."""
        def L(x: int) -> str:
            if x < 2:
                return "1" if x else "0"
            return ("!" if x & 1 else "") + f"n{x >> 1}"

        lines = [f"aig inputs={len(self.inputs)} ands={len(self.ands)} "
                 f"outputs={len(self.outputs)} depth={self.depth()}"]
        for i, name in enumerate(self.inputs):
            lines.append(f"input n{i + 1} {name}")
        base = len(self.inputs) + 1
        for k, (a, b) in enumerate(self.ands):
            lines.append(f"and n{base + k} = {L(a)} & {L(b)}")
        for name, x in zip(self.outputs, self.output_lits):
            lines.append(f"output {name} = {L(x)}")
        return "\n".join(lines) + "\n"

    def __repr__(self) -> str:
        return (f"AIG(inputs={len(self.inputs)}, outputs={len(self.outputs)}, "
                f"ands={len(self.ands)}, depth={self.depth()})")
