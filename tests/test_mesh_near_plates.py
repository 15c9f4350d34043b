"""Session 69 (issue 13): a yoke plate that comes near another body as printed stops short of it
(``CLIP_NEAR_PLATES``, :func:`mlc.mesh.build._clip_near_plates`).

``tests/data_mesh/robot_skel``: the README robot's 13 bodies round ``skel_u2`` and ``skel_j3`` (the
skeleton's unit 2 and the joint piece after it, the end of both unit-3 couplings' wrists) with the
robot's 22 print poses.  Each coupling ends on two end joints, one on each side of a skeleton hinge,
hanging on posts 3 mm under the skeleton's slabs.  A yoke plate is laid in its joint's plane as far
as its slab is wide, so ``skel_j3``'s plate at ``rc_u3_up_end_hi`` reached 7.3 mm from its pin, over
the 5 mm to the next end joint's knuckle on ``skel_u2``: the two printed touching (``min_gap`` 0.0;
``states`` 0.0001446 mm^3 in rows 00 and 01, the whole robot's numbers in
``benchmarks/results/print_reports_s68.json``), and the final trims could cut neither (``skel_u2``'s
knuckle is guarded; trimmed, ``skel_j3`` fell in two).  Not asserted: ``part_count`` on the piece
(its wrists' half units, their neighbours outside the piece, come out in two), nor ``states``, which
fails on the piece for ``skel_u3`` against the wrist of ``rc_u3_dn`` as before."""
from __future__ import annotations

import pytest

from helpers import load_piece, mesh_piece, part_gaps


@pytest.fixture(scope="module")
def skel_before():
    return mesh_piece("robot_skel", walls=False, CLIP_NEAR_PLATES=False)


@pytest.fixture(scope="module")
def skel():
    return mesh_piece("robot_skel", walls=False)


def test_skeleton_plates_as_laid_touch(skel_before):
    _, rep = skel_before
    assert "skel_u2 - skel_j3: 0.0000 mm" in rep.check("min_gap").failures, rep.check("min_gap").failures
    assert any(f.startswith("state 00: skel_u2 intersects skel_j3") for f in rep.check("states").failures)


def test_skeleton_plate_stops_short(skel):
    asm, rep = skel
    assert rep.check("min_gap").ok, rep.check("min_gap").failures
    assert not [f for f in rep.check("states").failures if "skel_u2 intersects skel_j3" in f]
    # the skeleton's bodies stay in one piece (a plate cut in the logic states too split skel_u3)
    split = " ".join(rep.check("part_count").failures)
    assert not any(b in split for b in ("skel_u2", "skel_j3", "skel_u3", "skel_j2")), split
    assert any(n.startswith("universal joint rc_u3_up_end_hi: skel_j3's yoke plate stops") for n in asm.notes)


def test_skeleton_apart_outside_mlc(skel, skel_before):
    """trimesh surface samples and a k-d tree (an upper bound of the gap) in rows 00 and 01."""
    _, poses = load_piece("robot_skel")
    rows = {k: poses[k] for k in ("00", "01")}
    now = part_gaps(skel[0], "skel_u2", "skel_j3", rows)
    before = part_gaps(skel_before[0], "skel_u2", "skel_j3", rows)
    assert min(now.values()) > 0.15, now
    assert max(before.values()) < 0.05, before
