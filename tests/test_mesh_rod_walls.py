"""Session 58 (issue 13, "meets the profile's minimum wall everywhere", compiled circuits): a rod's
second thin side is printed at the slab thickness too.

A compiled circuit's chain hangs its end joint under a gate's input lever on a post, a rod of
``POST_WIDTH`` (0.08 sigma) square (mlc.circuit.build).  The print raises a slab box's thinnest
side to the profile's slab thickness; a rod has two thin sides, and the second stayed 0.4 mm at
mjp (sigma 5 mm) against the 0.6 mm minimum wall: in the README circuit every gate's four input
levers had a region of 0.40 mm over 1.5-1.8 mm^3 along the post.  ``ROD_WALL`` prints both thin
sides at the slab thickness.

``circuit_g3`` (tests/data_mesh): gate g3 of that circuit with the chains' last half units and the
whole circuit's 22 print poses (tests/test_mesh_circuit_gate_stroke.py)."""
from __future__ import annotations

from pathlib import Path

import manifold3d as mf
import numpy as np
import pytest

from mlc.geometry.rotation import quat_to_matrix
from mlc.mesh import build as B
from mlc.mesh.build import build_assembly
from mlc.mesh.checks import check_assembly
from mlc.mesh.profiles import load_profile
from mlc.scene.io import load_scene

DATA = Path(__file__).parent / "data_mesh"
LEVERS = ("g3_a_lo", "g3_a_hi", "g3_b_lo", "g3_b_hi")


@pytest.fixture(scope="module")
def piece():
    z = np.load(DATA / "circuit_g3_poses.npz")
    return load_scene(DATA / "circuit_g3.yaml"), {str(k): (p, q) for k, p, q in zip(z["names"], z["pos"], z["quat"])}


def _build(piece, rods: bool):
    sc, poses = piece
    old = B.ROD_WALL
    B.ROD_WALL = rods
    try:
        return build_assembly(sc, load_profile("mjp"), poses, reuse=True)
    finally:
        B.ROD_WALL = old


def _post_sections(asm, sc):
    """For each input lever, the post's cross-section half-way along it (the lever's box with two
    sides under 0.1 sigma, from the scene, not from the mesher): the diameter of the largest disc
    in it (manifold3d slice, Clipper2 offsets, 0.001 mm) and its two side lengths (mm)."""
    s = asm.profile.sigma_mm
    out = {}
    for b in sc.bodies:
        if b.name not in LEVERS:
            continue
        (bx,) = [bx for bx in b.boxes if sorted(bx.size)[1] < 0.1]
        Rb = quat_to_matrix(b.orientation)
        R = Rb @ quat_to_matrix(bx.orientation)
        c = s * (np.asarray(b.position, float) + Rb @ np.asarray(bx.center, float))
        ia = int(np.argmax(bx.size))
        others = [i for i in range(3) if i != ia]
        # a frame with the post's length along z, its two thin sides along x and y
        F = np.vstack([R[:, others[0]], R[:, others[1]], R[:, ia]])
        M = np.hstack([F, (-F @ c)[:, None]])
        cs = asm.part(b.name).solid.transform(M.tolist()).slice(0.0)
        (piece,) = [p for p in cs.decompose() if p.bounds()[0] <= 0 <= p.bounds()[2] and p.bounds()[1] <= 0 <= p.bounds()[3]]
        lo, hi = 0.0, 2.0
        while hi - lo > 5e-4:
            r = 0.5 * (lo + hi)
            lo, hi = (lo, r) if piece.offset(-r, mf.JoinType.Round).is_empty() else (r, hi)
        x0, y0, x1, y1 = piece.bounds()
        out[b.name] = (2 * lo, x1 - x0, y1 - y0)
    return out


def test_posts_are_printed_at_the_slab_thickness_both_ways(piece):
    asm = _build(piece, True)
    prof = asm.profile
    posts = _post_sections(asm, piece[0])
    assert set(posts) == set(LEVERS)
    for name, (disc, a, b) in posts.items():
        assert disc >= prof.min_wall - 2e-3 and min(a, b) >= prof.slab_thickness - 2e-3, (name, posts)
    rep = check_assembly(asm, walls=False)
    for c in rep.checks:
        if c.name in ("watertight", "part_count", "min_gap", "states", "retention", "features"):
            assert c.ok, (c.name, c.detail, c.failures)


def test_without_rod_walls_the_posts_are_thinner_than_the_wall(piece):
    old = _build(piece, False)
    posts = _post_sections(old, piece[0])
    for name, (disc, a, b) in posts.items():
        assert disc < old.profile.min_wall - 0.1, (name, posts)      # 0.4 mm: POST_WIDTH at sigma 5 mm
        assert abs(min(a, b) - 0.08 * old.profile.sigma_mm) < 0.01, (name, posts)
