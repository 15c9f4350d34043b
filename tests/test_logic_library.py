"""mlc.logic.library: the benchmark families, checked against their definitions written
out independently of the network builders."""
import itertools

from mlc.logic.library import nand_mesh
from mlc.logic.lower import from_spec
from mlc.pipeline import compile_spec


def _mesh_by_hand(x, width, depth):
    """The mesh's outputs for input bits ``x``, level by level, straight from the definition."""
    g = [1 - (x[2 * i] & x[2 * i + 1]) for i in range(width)]
    for _ in range(depth - 1):
        g = [1 - (g[i] & g[i + 1]) if i + 1 < width else 1 - (g[i] | g[i - 1]) for i in range(width)]
    return g


def test_nand_mesh_computes_its_definition_on_every_row():
    width, depth = 3, 4
    spec = nand_mesh(width, depth)
    aig = from_spec(spec)
    assert spec.inputs == [f"x{i}" for i in range(6)] and spec.outputs == ["y0", "y1", "y2"]
    for x in itertools.product((0, 1), repeat=2 * width):
        assert aig.simulate(list(x), 1) == _mesh_by_hand(x, width, depth), x


def test_nand_mesh_of_width_7_keeps_its_gates_at_O0():
    """203 gates at depth 29, proven equivalent to the spec by compile_spec: the family the
    circuit scaling benchmark takes to 200 gates; -O2 merges levels (fewer gates)."""
    c = compile_spec(nand_mesh(7, 29), 0, "expand")
    assert len(c.netlist.gates) == 7 * 29
    assert max(g.depth for g in c.netlist.gates) == 29
    assert len(compile_spec(nand_mesh(7, 6), 2, "expand").netlist.gates) < 7 * 6
