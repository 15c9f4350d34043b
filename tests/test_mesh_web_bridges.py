"""Session 58 (issue 13, "meets the profile's minimum wall everywhere", compiled circuits): a
circuit gate's ``core_cd`` keeps a full wall at hinge c.

In a library gate ``core_cd`` is cut twice round hinge c's middle (the trim for ``a_hi``'s and
``b_hi``'s knuckles and the universal joint's trim towards d), and the web left between the two cuts
is bridged where no other body swings (``_bridge``, session 36).  Compiled circuits (``reuse``) were
built without that step, and every gate of the README's Tetris circuit kept a web of 0.21-0.24 mm
against mjp's 0.6 mm minimum wall (its report: ``g1_core_cd: wall 0.24 mm ... 0.23 mm at its
thinnest``).  ``WEB_BRIDGES`` runs the step for the three-body hinges of a circuit too, kept clear
of the other bodies in the circuit's print poses (the logic states and the points on the way to
them).

``circuit_g3`` (tests/data_mesh) is gate g3 of that circuit with the chains' last half units around
it and the whole circuit's 22 poses (see tests/test_mesh_circuit_gate_stroke.py)."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from mlc.mesh import build as B
from mlc.mesh.build import build_assembly
from mlc.mesh.checks import check_assembly
from mlc.mesh.profiles import load_profile
from mlc.mesh.walls import thin_walls
from mlc.scene.io import load_scene

from helpers import web_sections

DATA = Path(__file__).parent / "data_mesh"
BLOCKING = ("watertight", "part_count", "min_gap", "states", "retention", "features")


@pytest.fixture(scope="module")
def piece():
    z = np.load(DATA / "circuit_g3_poses.npz")
    return load_scene(DATA / "circuit_g3.yaml"), {str(k): (p, q) for k, p, q in zip(z["names"], z["pos"], z["quat"])}


def _build(piece, bridges: bool):
    sc, poses = piece
    old = B.WEB_BRIDGES
    B.WEB_BRIDGES = bridges
    try:
        return build_assembly(sc, load_profile("mjp"), poses, reuse=True)
    finally:
        B.WEB_BRIDGES = old


@pytest.fixture(scope="module")
def built(piece):
    return _build(piece, True)


def test_a_circuit_gates_web_at_hinge_c_is_bridged_to_the_full_wall(built):
    asm = built
    prof = asm.profile
    assert any(n.startswith("hinge g3_hinge_c") and "g3_core_cd bridges" in n
               and "thinner than the minimum wall" in n for n in asm.notes), asm.notes
    # outside mlc.mesh.walls: sections across the other knuckles, the largest disc in each web
    webs = web_sections(asm, prof.min_wall, owner="g3_core_cd")
    assert webs and min(webs) >= prof.min_wall - 1e-3, webs
    # and the report's own measure of the finished part
    assert thin_walls("g3_core_cd", asm.part("g3_core_cd").solid, prof.min_wall) == []
    assert len(asm.part("g3_core_cd").solid.decompose()) == 1


def test_the_bridged_piece_passes_every_blocking_check_in_the_circuits_poses(built):
    rep = check_assembly(built, walls=False)
    by = {c.name: c for c in rep.checks}
    for name in BLOCKING:
        assert by[name].ok, (name, by[name].detail, by[name].failures)


def test_without_the_bridge_the_web_is_thinner_than_the_wall(piece):
    """The same piece as compiled circuits were built before: the web is under the minimum wall,
    by the sections and by the report's wall measure (so the test above can fail)."""
    old = _build(piece, False)
    prof = old.profile
    assert not any("g3_core_cd bridges" in n for n in old.notes)
    webs = web_sections(old, prof.min_wall, owner="g3_core_cd")
    assert webs and min(webs) < 0.5 * prof.min_wall, webs
    thin = thin_walls("g3_core_cd", old.part("g3_core_cd").solid, prof.min_wall)
    assert thin and min(w.thickness_mm for w in thin) < 0.5 * prof.min_wall, thin
