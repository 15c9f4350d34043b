"""mlc.mesh.shave (issue 13, "meets the profile's minimum wall everywhere"): thin webs the trims
leave away from a body's joints are taken off, unless the body would lose a piece or joint
material.

Synthetic bodies (two blocks and the webs between them) test each of the module's three rules;
``circuit_leaf`` (tests/data_mesh: the README circuit's leaf pages with the circuit's 22 poses)
tests it on a compiled circuit: some regions go and every blocking check still passes.
(tests/test_mesh_fin.py: the 0.16 mm strip that was the only link of a half unit's far yoke
knuckle, which this pass must leave, and how it is mended at its source.)"""
from __future__ import annotations

from types import SimpleNamespace

import manifold3d as mf
import numpy as np
import pytest

from mlc.mesh import shave as S
from mlc.mesh.build import HingeAxis, Part
from mlc.mesh.walls import thin_walls

from helpers import mesh_piece

MW = 0.6
BLOCKING = ("watertight", "part_count", "min_gap", "states", "retention", "features")


def _box(lo, hi):
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    return mf.Manifold.cube(tuple(hi - lo)).translate(tuple(lo))


def _blocks(bar: bool, web: float = 0.2):
    """Two 3 mm blocks 3 mm apart along x, joined by a 0.2 mm web (z from 1 to 1 + web) and,
    with ``bar``, by a 1.5 mm bar too (y from 1.5 to 3)."""
    parts = [_box((0, 0, 0), (3, 3, 3)), _box((6, 0, 0), (9, 3, 3)), _box((2.5, 0, 1), (6.5, 1.2, 1 + web))]
    if bar:
        parts.append(_box((2.5, 1.5, 0.75), (6.5, 3, 2.25)))
    return mf.Manifold.batch_boolean(parts, mf.OpType.Add)


def _asm(solid, axes=()):
    return SimpleNamespace(parts=[Part("body", "body", solid)], axes=list(axes), ujoints=[],
                           profile=SimpleNamespace(min_wall=MW), notes=[], cores={}, congruence=None)


def test_a_web_beside_a_bar_is_taken():
    solid = _blocks(bar=True)
    assert len(thin_walls("body", solid, MW)) == 1
    asm = _asm(solid)
    S.shave_thin(asm)
    after = asm.parts[0].solid
    assert thin_walls("body", after, MW) == []
    assert len(after.decompose()) == 1
    # the web's 4 x 1.2 x 0.2 mm is what went (with at most a cell's skin of the blocks)
    lost = solid.volume() - after.volume()
    assert 0.8 * 3 * 1.2 * 0.2 < lost < 4 * 1.2 * 0.2 + 2 * 1.2 * 0.3 * 2 * 0.075 + 0.05
    assert any("1 thin region" in n for n in asm.notes)


def test_a_web_that_is_the_only_link_stays():
    solid = _blocks(bar=False)
    asm = _asm(solid)
    S.shave_thin(asm)
    assert asm.parts[0].solid is solid
    assert len(thin_walls("body", asm.parts[0].solid, MW)) == 1
    assert asm.notes == []


def test_a_web_in_a_hinge_cylinder_stays():
    solid = _blocks(bar=True)
    # a hinge of the body along x through the web: its cylinder (R 1 mm) holds the web's cells
    ax = HingeAxis("h", [], np.array([4.5, 0.6, 1.1]), np.array([1.0, 0.0, 0.0]), 5.0, ["body", "other"],
                   {"body": [(-2.5, 2.5)]}, 5.0, 1.0, 0.3, 0.35)
    asm = _asm(solid, [ax])
    S.shave_thin(asm)
    assert asm.parts[0].solid is solid
    # ... and a hinge elsewhere protects nothing here
    far = HingeAxis("h", [], np.array([4.5, 10.0, 10.0]), np.array([1.0, 0.0, 0.0]), 5.0, ["body", "other"],
                    {"body": [(-2.5, 2.5)]}, 5.0, 1.0, 0.3, 0.35)
    asm = _asm(solid, [far])
    S.shave_thin(asm)
    assert asm.parts[0].solid is not solid


def test_joint_cores_are_kept():
    solid = _blocks(bar=True)
    asm = _asm(solid)
    asm.cores = {"body": _box((3.5, 0.2, 1.02), (5.5, 1.0, 1.18))}    # a "core" inside the web
    S.shave_thin(asm)
    assert asm.parts[0].solid is solid


def _leaf(shave: bool):
    return mesh_piece("circuit_leaf", SHAVE_THIN=shave)


@pytest.fixture(scope="module")
def leaf():
    return _leaf(False), _leaf(True)


def _walls(rep):
    return next(c for c in rep.checks if c.name == "wall_thickness").failures


def test_leaf_shaved_passes_and_has_fewer_thin_regions(leaf):
    """(Session 60: 3 regions of 0.45 mm on w_y_3_0's AB and DA without, none with.)"""
    (a0, r0), (a1, r1) = leaf
    for c in r1.checks:
        if c.name in BLOCKING:
            assert c.ok, (c.name, c.detail)
    assert len(_walls(r1)) < len(_walls(r0))
    assert any(n.startswith("walls:") for n in a1.notes)
    assert not any(n.startswith("walls:") for n in a0.notes)
    v0 = {p.name: p.solid.volume() for p in a0.parts}
    for p in a1.parts:      # only ever material taken away
        assert p.solid.volume() <= v0[p.name] + 1e-6
