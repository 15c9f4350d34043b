"""Branch trees (docs/circuits.md, "Branch trees (session 52)"): a fan-out to more than two
consumers is built as a tree of 2-way branches, every junction carrying two pages turned
-90 and +90 degrees about its pair, so the two pages' tangents lie on one line.  The mesher
prints all the pages of one junction on one joint part, a cardan cross whose second pin
carries every page's knuckle: it follows the scene only if the pages turn relative to each
other about that one pin, which pages at -90/+90 do (and pages at 0 or +-30 degrees of the
old k-way branch did not: 19-22 degrees off the pin in the Tetris circuit)."""
import numpy as np
import pytest
from helpers import ROOT

from mlc.circuit import build as B
from mlc.front.load import load
from mlc.geometry.rotation import quat_to_matrix
from mlc.pipeline import compile_spec
from mlc.scene.io import dump_scene
from mlc.verify.circuit import format_report, verify_static
from mlc.verify.static import equilibrium

FOUR = "p = a; q = a; r = a; s = a"       # four outputs on one input: a 4-way fan-out, no chain
THREE = "p = a; q = a; r = a & b"         # a 3-way fan-out, one consumer a gate (a chain)


def _build(expr: str, tree: bool, monkeypatch):
    monkeypatch.setattr(B, "BRANCH_TREE", tree)
    spec = load(None, expr)
    return B.build_circuit(compile_spec(spec).netlist, spec).scene


def _junctions(sc) -> list:
    """Branch junctions: universal joints at one point on one body that join two or more other
    bodies there (as the mesher's ``_branch_groups``): [(shared body, [other bodies])]."""
    by: dict = {}
    for bd in sc.bonds:
        if bd.kind != "universal":
            continue
        key = tuple(np.round(0.5 * (sc.site_world(bd.a) + sc.site_world(bd.b)), 6))
        for me, other in ((bd.a, bd.b), (bd.b, bd.a)):
            by.setdefault((me.split(".")[0], key), []).append(other.split(".")[0])
    return [(body, others) for (body, _), others in by.items() if len(others) >= 2]


def _tangent(sc, page_slab: str) -> np.ndarray:
    """The tangent of the page (half unit) that ``page_slab`` belongs to: from its input joint
    site A to its stop site, STOP_ARM along it."""
    b = sc.body(page_slab[:-3] + "_AB")
    t = b.world("stop_in") - b.world("A")
    return t / np.linalg.norm(t)


def _pages_on_one_line(sc) -> list[str]:
    """What is wrong with ``sc``'s branch junctions (empty: each has two pages, tangents antiparallel)."""
    bad = []
    for body, others in _junctions(sc):
        if len(others) != 2 or not all(o.endswith(("_AB", "_CD")) for o in others):
            bad.append(f"{body}: {others}")
            continue
        c = float(_tangent(sc, others[0]) @ _tangent(sc, others[1]))
        if c > -1.0 + 1e-9:
            bad.append(f"{body}: {others} tangents at cos {c:.6f}")
    return bad


@pytest.mark.parametrize("expr, pages", [(FOUR, 6), (THREE, 4)])
def test_every_branch_junction_has_two_pages_on_one_line_and_the_circuit_computes(expr, pages, monkeypatch):
    sc = _build(expr, True, monkeypatch)
    names = {b.name[:-3] for b in sc.bodies if b.name.startswith("w_a_p") and b.name.endswith("_AB")}
    assert len(names) == pages                  # a tree: 2 (k - 1) pages for k consumers
    assert len(_junctions(sc)) == pages         # pages // 2 pairs, each with a lo and a hi junction
    assert _pages_on_one_line(sc) == []
    rep = verify_static(sc)
    assert rep.ok, format_report(rep)
    assert all(row["clearance"] > 0 for row in rep.rows), [(r["state"], r["clearance_pair"]) for r in rep.rows]


def test_the_old_k_way_branch_puts_pages_off_that_line(monkeypatch):
    """BRANCH_TREE = False keeps the k-way branch (pages at -90..90 degrees about one pair):
    the check above fails on it."""
    for expr in (FOUR, THREE):
        assert _pages_on_one_line(_build(expr, False, monkeypatch)), expr


def test_two_pages_turn_about_their_common_line_when_the_signal_switches(monkeypatch):
    """In the switched row every two sibling pages' slabs AB have turned relative to each other
    about the pages' common line only (the cardan cross's second pin), as the rhombi open."""
    sc = _build(FOUR, True, monkeypatch)
    eq = equilibrium(sc, "1")
    ix = {b.name: i for i, b in enumerate(sc.bodies)}
    turned = 0.0
    for _, (p, q) in _junctions(sc):       # (each junction's two input slabs, AB or CD)
        R = [quat_to_matrix(eq.quat[ix[n]]) @ quat_to_matrix(sc.bodies[ix[n]].orientation).T for n in (p, q)]
        M = R[0].T @ R[1]                                  # q relative to p, in rest-world axes
        ang = np.arccos(np.clip(0.5 * (np.trace(M) - 1.0), -1.0, 1.0))
        axis = np.array([M[2, 1] - M[1, 2], M[0, 2] - M[2, 0], M[1, 0] - M[0, 1]])
        rv = ang * axis / max(np.linalg.norm(axis), 1e-300)
        v = _tangent(sc, p)
        off = np.linalg.norm(rv - (rv @ v) * v)
        assert off < np.radians(0.5), (p, q, np.degrees(off))
        turned = max(turned, abs(float(rv @ v)))
    assert turned > np.radians(10.0)                     # and they did turn (the rhombi opened)


def test_two_consumers_build_the_same_scene_with_or_without_the_tree(monkeypatch):
    expr = "p = a; q = a & b"
    assert dump_scene(_build(expr, True, monkeypatch)) == dump_scene(_build(expr, False, monkeypatch))


def test_the_full_adders_two_way_branches_are_built_as_before(monkeypatch):
    """The full adder fans out to two consumers only, from sources and from gates; gate g3's
    output pair is posed tilted off x, so its two pages lead to different x: they keep the
    k-way branch's order all the same (the scene is the same, bit for bit)."""
    from mlc.circuit import build as B
    spec = load(str(ROOT / "examples" / "full_adder.tt"), None)
    netlist = compile_spec(spec).netlist
    scenes = []
    for tree in (True, False):
        monkeypatch.setattr(B, "BRANCH_TREE", tree)
        scenes.append(dump_scene(B.build_circuit(netlist, spec).scene))
    assert scenes[0] == scenes[1]
