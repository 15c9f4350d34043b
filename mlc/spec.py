"""Plain data produced by the front-end parsers: a logic *specification*.

Two forms:

* :class:`TableSpec` -- a multi-output function given by on-set and don't-care set
  (truth tables ``.tt``, Berkeley PLA).  Minterm numbering: in minterm ``m`` the
  input ``inputs[i]`` has the value ``(m >> i) & 1`` (the first input is the least
  significant bit, as in ABC and kitty).  ``on[o]`` and ``dc[o]`` are Python ints
  used as bit sets over the ``2**n`` minterms; ``on[o] & dc[o] == 0``.
* :class:`NetworkSpec` -- a Boolean network (expressions, BLIF, AIGER): nodes in
  topological order, each an operator over earlier nodes.

Every spec carries the source file name and, per output, the :class:`Loc` where it
was defined, so that later stages can quote ``file:line``.
"""
from __future__ import annotations

from dataclasses import dataclass, field

from mlc.errors import Loc

# Operators of NetworkSpec nodes and their arities (None = any >= 1).
OPS = {
    "input": 0, "const0": 0, "const1": 0,
    "buf": 1, "not": 1,
    "and": None, "or": None, "xor": None, "nand": None, "nor": None, "xnor": None,
    "implies": 2,     # a -> b
    "iff": 2,         # a <-> b
    "maj": None,      # odd arity: majority
    "mux": 3,         # mux(s, a, b) = s ? a : b   (also ite)
    "sop": None,      # BLIF .names cover over args: see Node.cover
}


@dataclass
class TableSpec:
    inputs: list[str]
    outputs: list[str]
    on: list[int]
    dc: list[int]
    source: str = "<input>"
    output_locs: list[Loc] = field(default_factory=list)

    @property
    def n(self) -> int:
        return len(self.inputs)

    def value(self, o: int, m: int) -> int | None:
        """Output ``o`` on minterm ``m``: 0, 1 or None (don't care)."""
        if (self.dc[o] >> m) & 1:
            return None
        return (self.on[o] >> m) & 1


@dataclass
class Node:
    op: str
    args: tuple[int, ...] = ()
    name: str | None = None
    loc: Loc | None = None
    # For op == "sop" (a BLIF .names cover): rows (cube, bit) with cube over args in
    # "01-" and bit "1" (on-set cover) or "0" (off-set cover); empty cover = constant 0.
    cover: list[tuple[str, str]] | None = None


@dataclass
class NetworkSpec:
    inputs: list[str]
    outputs: list[str]
    nodes: list[Node]
    output_nodes: list[int]      # node index driving each output
    source: str = "<input>"
    output_locs: list[Loc] = field(default_factory=list)
    # Optional don't cares: per output a bit set over minterms (same numbering as TableSpec).
    dc: list[int] | None = None


Spec = TableSpec | NetworkSpec
