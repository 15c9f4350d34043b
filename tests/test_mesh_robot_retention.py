"""Session 56 (issue 13): four joints of the README's Tetris robot no longer retained after the
pin reliefs of session 55 (``_relieve_host_holes``).

``robot_relief`` (tests/data_mesh): the robot's coupling half unit ``rc_u2_up_0`` with one bond
hop around it (10 bodies: ``g1``'s output levers, the next half unit's slabs, the page slabs of
``rc_u3_dn``), with the whole robot's 22 print poses (``mlc.mesh.pipeline.state_poses`` of its
largest mechanism).  In those poses the joint parts ``rc_u2_up_j1_hi``/``_lo`` are posed with
their first pins up to 0.75 mm past the wall of the host stack's holes (hinges ``rc_u2_up_0_hB``
and ``_hD``; the knuckle ring is 0.6 mm thick), and relieving the holes for them opened the
holes: the stack's knuckles and the joint part then moved 0.3 mm (1.5 x clearance) freely, the
robot's ``retention`` failures.  The relief is now cut only as far as every part of the host
hinge stays retained (``RELIEF_RETAINED``)."""
from __future__ import annotations

import pytest

from mlc.mesh import build as B
from mlc.mesh.build import build_assembly
from mlc.mesh.checks import _retention, check_assembly
from mlc.mesh.profiles import load_profile

from helpers import load_piece



@pytest.fixture(scope="module")
def piece():
    return load_piece("robot_relief")


def _relieved(asm):
    notes = [n for n in asm.notes if n.startswith("compound junctions' pins relieved")]
    assert len(notes) <= 1
    return float(notes[0].split(" bodies, ")[1].split(" mm^3")[0]) if notes else 0.0


def test_the_pin_reliefs_keep_the_host_hinges_retained(piece, monkeypatch):
    sc, poses = piece
    prof = load_profile("mjp")
    # as printed since session 58 (rods at the slab thickness, ROD_WALL): retained
    asm = build_assembly(sc, prof, poses, reuse=True)
    by = {c.name: c for c in check_assembly(asm, walls=False).checks}
    for name in ("watertight", "retention", "features"):
        assert by[name].ok, (name, by[name].failures)
    # the case the limit was made for: rods of POST_WIDTH, as the robot was printed before
    monkeypatch.setattr(B, "ROD_WALL", False)
    asm = build_assembly(sc, prof, poses, reuse=True)
    by = {c.name: c for c in check_assembly(asm, walls=False).checks}
    for name in ("watertight", "retention", "features"):
        assert by[name].ok, (name, by[name].failures)
    # the reliefs are still cut where they keep the hinge, and left out where they would free it
    kept = _relieved(asm)
    assert kept > 0
    left = [n for n in asm.notes if n.startswith("pin reliefs left out")]
    assert len(left) == 1 and "rc_u2_up_0_" in left[0], asm.notes
    # without the limit: the joints of the robot's report are free again, and more is cut
    monkeypatch.setattr(B, "RELIEF_RETAINED", False)
    asm = build_assembly(sc, prof, poses, reuse=True)
    ret = _retention(asm)
    assert not ret.ok
    free = {f.split(" moves")[0] for f in ret.failures}
    assert {"rc_u2_up_0_BC at joint rc_u2_up_0_hB", "rc_u2_up_0_DA at joint rc_u2_up_0_hD"} <= free, free
    assert _relieved(asm) > kept
    assert not any(n.startswith("pin reliefs left out") for n in asm.notes)


def test_without_the_reliefs_the_piece_is_retained(piece, monkeypatch):
    # the piece itself holds its joints: the failures are the reliefs' alone
    sc, poses = piece
    monkeypatch.setattr(B, "PIN_RELIEF", False)
    asm = build_assembly(sc, load_profile("mjp"), poses, reuse=True)
    assert _retention(asm).ok
    assert _relieved(asm) == 0.0
