"""Attachment holes across the layers print as teardrops (issue 13: prints that a slicer prints)."""
from __future__ import annotations

import numpy as np
import pytest

from mlc.mesh.build import HOLE_TEARDROP_DEG, TEARDROP_SIDE_DEG, cylinder, hole_kind, hole_shape
from mlc.mesh.checks import OVERHANG_DEG
from mlc.mesh.printability import bed_stats

from helpers import downward_faces

UP = np.array([0.0, 0.0, 1.0])


def _axis(elev_deg):
    e = np.radians(elev_deg)
    return np.array([0.0, np.cos(e), np.sin(e)])


def test_hole_kind_follows_the_overhang_limit():
    assert hole_kind(_axis(0.0), None) == "round"            # up not known: as before
    assert hole_kind(_axis(0.0), UP) == "teardrop"           # across the layers
    assert hole_kind(_axis(HOLE_TEARDROP_DEG - 3), UP) == "teardrop"
    assert hole_kind(_axis(HOLE_TEARDROP_DEG + 3), UP) == "round"
    assert hole_kind(_axis(90.0), UP) == "round"             # a vertical bore has no ceiling
    assert hole_kind(-_axis(10.0), UP) == "teardrop"         # either sign of the axis


def _down_faces(solid, centre, reach):
    """(normal z, area) of the downward faces of ``solid`` within ``reach`` of ``centre``."""
    nz, area, mid = downward_faces(solid)
    near = np.linalg.norm(mid - centre, axis=1) < reach
    return nz[near], area[near]


@pytest.mark.parametrize("elev", [0.0, 20.0, 40.0])
def test_a_teardrop_hole_has_no_ceiling_flatter_than_the_limit(elev):
    """A plate 1.2 mm thick with a 1 mm hole, its axis rising at ``elev`` degrees: drilled round,
    the hole's ceiling is flatter than 45 degrees and needs support (mlc's bed statistics; in a
    vertical plate, inside the hole); drilled as a teardrop, every downward face of the hole
    rises at 45 degrees or more, and the plate needs less support, none inside the hole."""
    import manifold3d as mf
    from mlc.mesh.build import _affine, _perp_frame
    nrm = _axis(elev)
    centre = np.array([0.0, 0.0, 15.0])     # the plate's centre, high above the bed
    plate = mf.Manifold.cube([16.0, 16.0, 1.2], True).transform(_affine(_perp_frame(nrm), centre))
    assert float(np.asarray(plate.bounding_box())[2]) > 1.0
    lim = np.cos(np.radians(90.0 - OVERHANG_DEG))
    out = {}
    for kind in ("round", "teardrop"):
        hole = (cylinder(centre, nrm, -2, 2, 1.0, 32, cutter=True) if kind == "round"
                else hole_shape(centre, nrm, UP, 1.0, 1.2, 32, 2.0, kind="teardrop"))
        part = plate - hole
        assert len(part.decompose()) == 1
        nz, area = _down_faces(part, centre, 2.2)
        out[kind] = (nz, area, bed_stats([("plate", part)], OVERHANG_DEG, 0.1, island_mm=0.0))
    nz, area, st0 = out["round"]
    assert area[nz < -lim - 1e-6].sum() > 0.1
    nz, area, st = out["teardrop"]
    assert np.all(nz >= -lim - 1e-6), nz.min()
    assert st.support_self_mm3 == pytest.approx(0.0, abs=1e-9)
    assert st.support_mm3 < st0.support_mm3 - 0.05, (st.support_mm3, st0.support_mm3)
    if elev == 0.0:         # a vertical plate: the round hole's support stands inside the hole
        assert st0.support_self_mm3 > 0.05


def test_a_teardrop_keeps_the_hole_and_points_up():
    """The teardrop holds the round hole (the clear opening is unchanged), its point lies up
    along the plate, 1/cos(side angle) radii from the centre, and a grown shape holds the hole's
    shape grown by as much (the wall the drill tests)."""
    nrm = np.array([0.0, 1.0, 0.0])         # a vertical plate, the hole across the layers
    c = np.zeros(3)
    tear = hole_shape(c, nrm, UP, 1.0, 1.2, 32, 0.6, kind="teardrop")
    rnd = cylinder(c, nrm, -0.6, 0.6, 1.0, 32, cutter=True)
    assert (rnd - tear).volume() < 1e-6
    top = float(np.asarray(tear.bounding_box())[5])
    k = 1 / np.cos(np.pi / 32)
    assert top == pytest.approx(k / np.cos(np.radians(TEARDROP_SIDE_DEG)), rel=1e-6)
    assert float(np.asarray(tear.bounding_box())[2]) == pytest.approx(-k * np.cos(np.pi / 32), abs=0.02)
    grown = hole_shape(c, nrm, UP, 1.0, 1.2, 32, 0.6, kind="teardrop", grow=1.2)
    assert (tear - grown).volume() < 1e-6
