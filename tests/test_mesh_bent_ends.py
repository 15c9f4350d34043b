"""Session 55 (issue 13): the Tetris circuit's ``states`` intersections at its most bent junctions.

Two pieces of the README's Tetris circuit (``mlc compile examples/tetris.tt``), each with the whole
circuit's print poses (``mlc.mesh.pipeline.state_poses`` of its largest mechanism), in tests/data_mesh:

* ``circuit_junction``: half units 58 to 62 of the chain ``w_b_0`` (20 bodies, all 22 poses).  Its
  junction 60/61 bends by 33.2 degrees in row 10 (the junction stop; the scene's slabs still clear
  by 0.05 sigma there), and the end knuckles of the two layers' far corners (``w_b_0_60_AB`` on
  hinge ``60_hA``, ``w_b_0_61_AB`` on ``61_hB``) met end face to end face: 0.199 mm^3;
* ``circuit_leaf``: the y branch tree (``src_y`` and its six pages) with the first half unit of each
  of its four chains (44 bodies, rows 10 and 11): the leaf pages' junctions to their chains are bent
  by 29.5 degrees at rest, and their far-corner end knuckles met the same way.

Both intersections are the printed knuckles' (radius ``R`` = 1.1 mm round the corner's hinge), not
the scene's: the mesher bevels such facing end knuckles apart in the poses (``_bevel_facing_ends``).
At junction 60/61 the joint parts' first pins also met their host stacks' holes (0.0003 mm^3),
relieved by ``_relieve_host_holes``; and in row 11 the yoke of junction 61/62, tipped by the
junction's twist, grazed its host's slab face (2e-5 mm^3), cleared by ``_clear_tipped_yokes``."""
from __future__ import annotations

import numpy as np
import pytest

from mlc.mesh import build as B
from mlc.mesh.build import build_assembly
from mlc.mesh.checks import check_assembly
from mlc.mesh.profiles import load_profile

from helpers import load_piece



def _piece(name):
    return load_piece(name)


def _pairs(asm):
    rep = check_assembly(asm, walls=False)
    by = {c.name: c for c in rep.checks}
    for name in ("watertight", "part_count", "min_gap", "retention", "features"):
        assert by[name].ok, (name, by[name].detail)
    return by["states"], {f.split(": ", 1)[1].split(" (")[0] for f in by["states"].failures}


@pytest.fixture(scope="module")
def junction():
    return _piece("circuit_junction")


@pytest.fixture(scope="module")
def leaf():
    return _piece("circuit_leaf")


def test_a_leaf_pages_end_knuckles_clear_its_chains_first_half_unit(leaf, monkeypatch):
    sc, poses = leaf
    asm = build_assembly(sc, load_profile("mjp"), poses, reuse=True)
    states, pairs = _pairs(asm)
    assert states.ok, states.failures
    assert any(n.startswith("end knuckles facing another hinge's") for n in asm.notes)
    monkeypatch.setattr(B, "BEVEL_ENDS", False)
    states, pairs = _pairs(build_assembly(sc, load_profile("mjp"), poses, reuse=True))
    assert not states.ok
    assert pairs == {"w_y_p0_p0_CD intersects w_y_2_0_CD", "w_y_p0_p1_AB intersects w_y_0_0_AB",
                     "w_y_p1_p0_AB intersects w_y_3_0_AB", "w_y_p1_p1_CD intersects w_y_1_stub_CD"}, pairs


def test_the_far_corners_of_a_junction_bent_to_its_stop_clear(junction, monkeypatch):
    sc, poses = junction
    prof = load_profile("mjp")
    states, pairs = _pairs(build_assembly(sc, prof, poses, reuse=True))
    assert states.ok, states.failures
    # each of the three changes, left out alone, leaves its intersection (without the state trims
    # of session 66, which trim some of these pairs of bodies sharing no hinge in the state instead)
    monkeypatch.setattr(B, "STATE_CLEAR", False)
    monkeypatch.setattr(B, "BEVEL_ENDS", False)
    _, pairs = _pairs(build_assembly(sc, prof, poses, reuse=True))
    assert pairs == {"w_b_0_60_AB intersects w_b_0_61_AB"}, pairs
    monkeypatch.setattr(B, "BEVEL_ENDS", True)
    monkeypatch.setattr(B, "PIN_RELIEF", False)
    _, pairs = _pairs(build_assembly(sc, prof, poses, reuse=True))
    assert pairs == {"w_b_0_60_AB intersects w_b_0_j61_hi", "w_b_0_60_CD intersects w_b_0_j61_lo"}, pairs
    monkeypatch.setattr(B, "PIN_RELIEF", True)
    monkeypatch.setattr(B, "YOKE_TIP_CLEAR", False)
    # (with the host's slab trimmed a clearance farther about the first pin, session 67's
    # HOST_CUT_MARGIN, the tipped yoke clears it without this trim)
    monkeypatch.setattr(B, "HOST_CUT_MARGIN", 0.0)
    _, pairs = _pairs(build_assembly(sc, prof, poses, reuse=True))
    assert pairs == {"w_b_0_61_DA intersects w_b_0_62_AB"}, pairs


def test_the_bevel_is_of_the_end_knuckles_only(junction):
    # what the bevel takes from the two end knuckles that met lies inside them, near their end faces
    sc, poses = junction
    prof = load_profile("mjp")
    asm = build_assembly(sc, prof, poses, reuse=True)
    B.BEVEL_ENDS = False
    try:
        old = build_assembly(sc, prof, poses, reuse=True)
    finally:
        B.BEVEL_ENDS = True
    lost = {p.name: q.solid.volume() - p.solid.volume() for p, q in zip(asm.parts, old.parts)}
    cut = {n for n, v in lost.items() if v > 1e-6}
    assert {"w_b_0_60_AB", "w_b_0_61_AB"} <= cut, lost
    assert max(lost.values()) < 0.5, lost        # mm^3, of a knuckle of about 2 mm^3
    axes = {a.name: a for a in asm.axes}
    for name, ax, sg in (("w_b_0_60_AB", "w_b_0_60_hA", 1), ("w_b_0_61_AB", "w_b_0_61_hB", -1)):
        p, q = asm.part(name), old.part(name)
        gone = q.solid - p.solid
        V = np.asarray(gone.to_mesh().vert_properties)[:, :3]
        a = axes[ax]
        s = (V - a.origin) @ a.direction
        r = np.linalg.norm(V - a.origin - np.outer(s, a.direction), axis=1)
        depth = sg * a.span / 2 - s if sg > 0 else s + a.span / 2
        assert depth.min() > -0.06 and depth.max() < a.knuckle + 0.06, (name, depth.min(), depth.max())
        assert r.max() < a.R + 0.1, (name, r.max())
