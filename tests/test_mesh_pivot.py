"""Chamfered crossing arms and teardrop knuckles on flat hinges (mlc.mesh.pivot, issue 13's
supports goal): a two-body pivot shaped as the library gates' output lever, and the NAND's own."""
import types

import manifold3d as mf
import numpy as np
import pytest

from mlc.mesh import pivot as PV
from mlc.mesh.build import HingeAxis, Part, cylinder, subtract, transform_solid, union
from mlc.mesh.checks import OVERHANG_DEG, island_side
from mlc.mesh.printability import bed_stats
from mlc.mesh.profiles import load_profile

R, RHO, SPAN, T = 3.1, 3.5, 10.0, 1.2


def _arm(angle_deg, length=20.0):
    """A slab of thickness T along the axis (x), leaving it at ``angle_deg`` in the y-z plane."""
    a = np.radians(angle_deg)
    d = np.array([0.0, np.cos(a), np.sin(a)])
    n = np.array([0.0, -np.sin(a), np.cos(a)])
    box = mf.Manifold.cube([SPAN, length, T], True)
    M = np.column_stack([[1.0, 0, 0], d, n])
    c = d * length / 2
    return box.transform(np.column_stack([M, c]))


def _x_pivot():
    """Two bodies crossing at a pivot along x (the output lever's X, NAND fdm sizes): ``lo`` holds
    the end knuckles and arms up-left and down-left, ``hi`` the middle knuckle and arms up-right
    and down-right; each is cut back to ``rho`` around the other's knuckles, as the build does."""
    ivs = {"lo": [(-5.0, -1.9333), (1.9333, 5.0)], "hi": [(-1.5333, 1.5333)]}
    ax = HingeAxis("pivot", [], np.zeros(3), np.array([1.0, 0, 0]), SPAN, ["lo", "hi"], ivs, 3.0667, R,
                   1.0, 1.4, rho=RHO)
    x = np.array([1.0, 0, 0])
    solids = {}
    for b, arms in (("lo", (131.0, 229.0)), ("hi", (49.0, -49.0))):
        own = ivs[b]
        body = union([_arm(a) for a in arms])
        cuts = [cylinder(np.zeros(3), x, a0, a1, RHO, 32, cutter=True) for a0, a1 in
                ([(-1.9333, 1.9333)] if b == "lo" else [(-5 - T, -1.5333), (1.5333, 5 + T)])]
        body = subtract(body, cuts)
        body = union([body] + [cylinder(np.zeros(3), x, a0, a1, R, 32) for a0, a1 in own])
        solids[b] = body
    prof = load_profile("fdm")
    parts = [Part(b, "body", s) for b, s in solids.items()]
    T0 = np.eye(4)
    T0[2, 3] = 30.0                              # the pivot 30 mm over the bed, x flat on it
    return types.SimpleNamespace(axes=[ax], parts=parts, profile=prof, print_T=lambda name: T0), T0


def _support(asm, T0):
    sol = [(p.name, transform_solid(p.solid, T0)) for p in asm.parts]
    return bed_stats(sol, OVERHANG_DEG, 0.25, first_layer=0.2, island_mm=island_side(asm.profile))


def _turned_gap(asm, deg):
    """Smallest gap (mm, up to 1) between the two bodies with ``hi`` turned ``deg`` about the axis."""
    a = np.radians(deg)
    M = np.eye(4)
    M[1:3, 1:3] = [[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]]
    lo, hi = (p.solid for p in asm.parts)
    return float(lo.min_gap(transform_solid(hi, M), 1.0))


def test_chamfers_and_teardrops_take_the_support_from_the_pivot():
    """The X pivot flat on the bed: the arms cut off in mid-air beside the other knuckles are
    ridge islands and the knuckles hang on their undersides; chamfered and teardropped, the
    pivot needs less than a third of the support, no island is left, each body stays one piece,
    and the two keep the clearance in every turn of the hinge (they only lose material outside
    ``rho`` and gain it inside their own knuckle range, within the room the other's chamfer left)."""
    asm, T0 = _x_pivot()
    c = asm.profile.clearance
    before = _support(asm, T0)
    assert before.islands >= 2
    assert min(_turned_gap(asm, d) for d in (-30, 0, 30)) >= c - 1e-6
    notes = PV.chamfer_crossings(asm) + PV.teardrops(asm)
    assert any("chamfered" in n for n in notes) and any("teardrops" in n for n in notes), notes
    after = _support(asm, T0)
    assert after.islands == 0
    assert after.support_mm3 < 0.33 * before.support_mm3, (before.support_mm3, after.support_mm3)
    assert all(len(p.solid.decompose()) == 1 for p in asm.parts)
    for d in range(-30, 31, 5):         # (further, the toy's arms meet each other beyond rho)
        assert _turned_gap(asm, d) >= c - 1e-6, d


def test_off_changes_nothing():
    asm, _ = _x_pivot()
    vol = [p.solid.volume() for p in asm.parts]
    old = PV.CHAMFER, PV.TEARDROPS
    try:
        PV.CHAMFER = PV.TEARDROPS = False
        assert PV.chamfer_crossings(asm) == [] and PV.teardrops(asm) == []
    finally:
        PV.CHAMFER, PV.TEARDROPS = old
    assert [p.solid.volume() for p in asm.parts] == vol


def test_an_upright_hinge_is_left_alone():
    """A hinge axis standing up in the print (the lever loop's, on its feet) keeps its parts: a
    chamfer there would face down."""
    asm, T0 = _x_pivot()
    T1 = np.eye(4)
    T1[:3, :3] = [[0, 0, 1.0], [0, 1.0, 0], [-1.0, 0, 0]]     # x -> -z
    asm.print_T = lambda name: T1
    vol = [p.solid.volume() for p in asm.parts]
    assert PV.chamfer_crossings(asm) == [] and PV.teardrops(asm) == []
    assert [p.solid.volume() for p in asm.parts] == vol


@pytest.mark.parametrize("flat", [1.26, 2.0])
def test_deepest_teardrop_is_self_supporting(flat):
    """The teardrop's flanks lean FLANK_DEG from the bed, tangent to the knuckle; its flat is
    the width asked for."""
    depth, rc = PV.deepest(R, flat)
    th = np.radians(90 - PV.FLANK_DEG)
    tu, tw = R * np.cos(th), -R * np.sin(th)
    assert np.isclose(np.hypot(flat / 2, depth), rc)
    assert np.isclose(np.degrees(np.arctan2(depth + tw, tu - flat / 2)), PV.FLANK_DEG)
