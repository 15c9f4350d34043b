"""Chains kept apart for the print (docs/circuits.md, "Session 53"): the printed parts of a
chain (knuckles of radius 0.22 sigma at mjp, the junctions' joint parts) reach beyond the
scene's slabs, so two chains whose slabs pass 0.42-0.67 sigma apart in some row printed
intersecting (the Tetris circuit's ``w_b_0`` and ``w_y_3`` in row 11, session 52's print:
10 of its 24 ``states`` intersections, 1.43 of 2.04 mm^3).  When a build leaves two chains'
layers closer than ``PRINT_MARGIN`` over the rows' states, the builder tries the branch
leans of ``PRINT_LEANS`` (``_build_routed``), each chain's first junction held to the bend
it had at most before (``BRANCH_LEAN + END_BEND``)."""
import re
from types import SimpleNamespace

import numpy as np
from helpers import ROOT
from scipy.spatial import cKDTree

from mlc.circuit import build as B
from mlc.front.load import load
from mlc.pipeline import compile_spec
from mlc.verify.overlap import _world_boxes, box_clearance
from mlc.verify.static import equilibrium

CHAIN_SLAB = re.compile(r"^w_(.+)_(\d+)_(\d+)_(AB|BC|CD|DA)$")     # w_<net>_<chain>_<half unit>_<slab>


def _chain_clearances(sc) -> dict:
    """The smallest slab clearance of every two different chains closer than 2.5 sigma over the
    static equilibrium of every row of ``sc``'s truth table, measured on the posed scene alone
    (sigma): ``{(chain, chain): (clearance, row)}``, chains named ``w_<net>_<chain>``."""
    chain = {}
    for i, b in enumerate(sc.bodies):
        m = CHAIN_SLAB.match(b.name)
        if m:
            chain[i] = f"w_{m.group(1)}_{m.group(2)}"
    out: dict = {}
    for state in sc.states():
        eq = equilibrium(sc, state)
        C, A, H, body = _world_boxes(sc, np.asarray(eq.pos, float), np.asarray(eq.quat, float))
        idx = np.array([i for i, b in enumerate(body) if int(b) in chain], int)
        pairs = np.array(sorted(cKDTree(C[idx]).query_pairs(2.5)), int).reshape(-1, 2)
        I, J = idx[pairs[:, 0]], idx[pairs[:, 1]]
        other = np.array([chain[int(body[i])] != chain[int(body[j])] for i, j in zip(I, J)], bool)
        I, J = I[other], J[other]
        for i, j, c in zip(I, J, box_clearance(C[I], A[I], H[I], C[J], A[J], H[J])):
            key = tuple(sorted((chain[int(body[i])], chain[int(body[j])])))
            if key not in out or c < out[key][0]:
                out[key] = (float(c), state)
    return out


def _tetris(monkeypatch, leans):
    monkeypatch.setattr(B, "PRINT_LEANS", leans)
    spec = load(str(ROOT / "examples" / "tetris.tt"), None)
    return B.build_circuit(compile_spec(spec).netlist, spec)


def test_tetris_chains_from_facing_leaves_pass_a_print_margin_apart_in_every_row(monkeypatch):
    """Without ``PRINT_LEANS`` (the build before session 53) the Tetris circuit's chains
    ``w_b_0`` and ``w_y_3`` pass 0.42 sigma apart in row 11 (slabs, static equilibrium); the
    build kept now (lean 0.8) keeps them ``PRINT_MARGIN`` apart in every row, and no two chains
    come as close as they did (measured 0.643 sigma: ``w_b_1``/``w_y_2``, row 01)."""
    leans = B.PRINT_LEANS
    old = _tetris(monkeypatch, ())
    assert "branch_lean" not in old.scene.meta["connector"]
    c_old = _chain_clearances(old.scene)
    worst_old = min(c_old.values())
    assert c_old[("w_b_0", "w_y_3")] == worst_old and worst_old[0] < 0.5 and worst_old[1] == "11", worst_old
    assert min(k.clearance for k in old.print_contacts) < 0.5          # the builder's own measure

    new = _tetris(monkeypatch, leans)
    assert new.scene.meta["connector"]["branch_lean"] in leans
    assert new.scene.meta["connector"]["tight_chains"] == []
    assert "state_contacts" not in new.scene.meta["connector"]
    c_new = _chain_clearances(new.scene)
    assert c_new.get(("w_b_0", "w_y_3"), (np.inf,))[0] >= B.PRINT_MARGIN, c_new.get(("w_b_0", "w_y_3"))
    assert min(c_new.values())[0] > worst_old[0] + 0.15, min(c_new.values())
    assert min(k.clearance for k in new.print_contacts) > worst_old[0] + 0.15


def test_a_print_build_is_kept_only_if_no_worse_by_the_contacts_and_tight_chains():
    def r(clear, contact=1.0, tight=(), closest=np.inf):
        return SimpleNamespace(print_clear=clear, contacts=[SimpleNamespace(clearance=contact)],
                               tight=list(tight), closest=closest)
    old = r(0.42)
    assert B._print_better(r(0.9), old)
    assert B._print_better(r(0.6), old)                             # farther, if not yet the margin
    assert not B._print_better(r(0.42), old)                        # not farther
    assert not B._print_better(r(2.0), r(B.PRINT_MARGIN))           # both keep the margin: the first
    assert not B._print_better(r(0.9, contact=0.01), old)           # a contact in the scene
    assert not B._print_better(r(0.9, tight=[("w_a_0", 1.7)], closest=1.7), old)    # a chain tight
    assert B._print_better(r(0.9, tight=[("w_a_0", 1.7)], closest=1.7),
                           r(0.42, tight=[("w_a_0", 1.6)], closest=1.6))
