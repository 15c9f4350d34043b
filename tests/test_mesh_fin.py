"""Session 60 (issue 13, "meets the profile's minimum wall everywhere", compiled circuits): a
compound junction's fin holds the yoke knuckle on the far side with a full wall (``FIN_KEPT``).

At a chain's compound junction the other body O (a half unit's AB or CD) has yoke knuckles on
both sides of the joint part's ball along the second pin v, and a fin (its yoke plate along the
host's line u, ``t`` thick) from the pin out to its end knuckle.  O's trim about v had the radius
of the host collar's sweep all the way round (``hypot(reach, R) + c``, 1.69 mm at mjp), and the
fin reached 1.85 mm: between the knuckles only a 0.16 mm strip of it was left, and that strip was
the one link of the yoke knuckle away from O's end knuckle (session 59's README circuit: 417 thin
regions on AB and CD).  On the fin's side the joint part has nothing but its ball, and relative to
O it turns about v by about 11 degrees in the circuit's poses: the fin now stays from the ball's
clearance out (``mlc.mesh.build._fin_free``, ``_fin_keep``).

``circuit_leaf`` (tests/data_mesh): the README circuit's leaf pages with the circuit's 22 poses."""
from __future__ import annotations

import manifold3d as mf
import numpy as np
import pytest

from mlc.mesh import build as B
from mlc.mesh import shave as S
from mlc.mesh.build import transform_solid
from mlc.mesh.walls import thin_walls

from helpers import mesh_piece

BLOCKING = ("watertight", "part_count", "min_gap", "states", "retention", "features")


def _leaf(kept: bool):
    return mesh_piece("circuit_leaf", FIN_KEPT=kept)


@pytest.fixture(scope="module")
def kept():
    return _leaf(True)


@pytest.fixture(scope="module")
def cut():
    return _leaf(False)


def _fins(asm):
    return [uj for uj in asm.ujoints if uj.host is not None and uj.fin > 0]


def _fin_width(asm, uj) -> float:
    """Outside mlc.mesh.walls: O's sections across the pin between the ball and the knuckles
    (v = +-0.9 mm; the knuckles start at 1.27), the material in the fin's band (from the pin out to
    the fin's end along u, a slab thickness across) divided by that thickness: how wide the fin
    is there along u (mm), the narrower of the two sides (one side is O's end knuckle too)."""
    u, v = uj.axes
    e = np.cross(v, u)
    t = asm.slab_thickness
    band = mf.CrossSection.square((uj.fin, t)).translate((0.0, -t / 2))
    out = []
    for a in (-0.9, 0.9):
        T = np.eye(4)
        T[:3, :3] = np.array([u, e, v])
        T[:3, 3] = -T[:3, :3] @ (uj.center + a * v)
        sec = transform_solid(asm.part(uj.bodies[1]).solid, T).slice(0.0)
        out.append(float((sec ^ band).area()) / t)
    return min(out)


def test_the_fin_is_a_full_wall_between_the_knuckles(kept, cut):
    (a1, _), (a0, _) = kept, cut
    fins = _fins(a1)
    assert len(fins) == 8          # the leaf piece's four chains' first junctions, lo and hi
    mw = a1.profile.min_wall
    state_T = B._state_transforms(a1.scene, a1.profile, a1.poses)
    for uj in fins:
        assert B._fin_free(uj, state_T, a1.profile.clearance, a1.slab_thickness)
        assert _fin_width(a1, uj) >= mw, uj.name
        assert _fin_width(a0, uj) < 0.5 * mw, uj.name      # the strip, as before


def test_every_blocking_check_passes_and_no_strip_is_left(kept):
    asm, rep = kept
    by = {c.name: c for c in rep.checks}
    for name in BLOCKING:
        assert by[name].ok, (name, by[name].detail, by[name].failures)
    assert by["wall_thickness"].ok, by["wall_thickness"].failures


def test_the_strip_was_the_one_link_of_the_far_yoke_knuckle(cut):
    """Without FIN_KEPT: the 0.16 mm strip on each fin's O, under the wall; taken away (as
    mlc.mesh.shave would take a web that holds nothing), the body falls in two, the far yoke
    knuckle a piece of a few mm^3: so the shave pass leaves it, and the wall check fails."""
    asm, rep = cut
    mw = asm.profile.min_wall
    walls = next(c for c in rep.checks if c.name == "wall_thickness")
    assert not walls.ok
    for uj in _fins(asm):
        p = asm.part(uj.bodies[1])
        strips = [w for w in thin_walls(p.name, p.solid, mw) if w.thickness_mm < 0.3]
        assert len(strips) == 1, p.name
        w = strips[0]
        assert np.linalg.norm(np.asarray(w.where_mm) - uj.center) < uj.fin + uj.R
        keep = S._joint_cells(asm, p.name, w.cells, S.JOINT_MARGIN * w.h)
        left = p.solid - S._cubes(w.cells[~keep], S.CUT_CELLS * w.h)
        big = sorted(x.volume() for x in left.decompose() if x.volume() >= mw ** 3)
        assert len(big) == 2 and big[0] > 1.0, (p.name, big)


def _turned(uj, deg):
    """A pose with C turned about v (through the joint point) by ``deg`` degrees against O."""
    C, O = uj.bodies
    v = uj.axes[1]
    a = np.radians(deg)
    K = np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])
    T = np.eye(4)
    T[:3, :3] = np.eye(3) + np.sin(a) * K + (1 - np.cos(a)) * K @ K
    T[:3, 3] = uj.center - T[:3, :3] @ uj.center
    return [("turned", {C: T, O: np.eye(4)})]


def test_a_fin_is_not_kept_where_the_collar_turns_round_to_it(kept):
    """_fin_free measures the turn about v: 60 degrees leaves the fin, 80 (the collar's side
    within the fin's half thickness and 10 degrees of it) does not."""
    asm, _ = kept
    uj = _fins(asm)[0]
    c, t = asm.profile.clearance, asm.slab_thickness
    assert B._fin_free(uj, _turned(uj, 60.0), c, t)
    assert B._fin_free(uj, _turned(uj, -60.0), c, t)
    assert not B._fin_free(uj, _turned(uj, 80.0), c, t)
    assert not B._fin_free(uj, _turned(uj, -80.0), c, t)
