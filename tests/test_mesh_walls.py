"""Issue 13, item 4: the measured wall thickness (mlc.mesh.walls).  The voxel grid alone passed
or failed a wall between 0.72 and 0.92 x min_wall with its position on the grid; the ball centres
near the threshold are now placed from the surface itself (session 37), so a web just under the
minimum fails at any angle and offset, one at the minimum passes, and the report names the
thinnest spot of a thin region.  Since session 38 the distances to the surface are exact (the
nearest triangle), so the pass mark is sharp to 0.001 mm."""
import manifold3d as mf
import numpy as np
import pytest

from mlc.mesh.walls import WALL_TOL, thin_walls


def _box(size, centre):
    return mf.Manifold.cube(list(size), True).translate(list(centre))


def _web(t, rot, off):
    """Two 3 mm blocks joined by a web 2.2 x 3 mm and ``t`` thick, the whole turned by ``rot``
    (degrees) and moved by ``off`` (mm): an oblique web on the grid."""
    solid = _box([3, 3, 3], [0, 0, 0]) + _box([3, 3, 3], [5, 0, 0]) + _box([2.2, 3, t], [2.5, 0, 0])
    return solid.rotate(list(rot)).translate(list(off))


@pytest.mark.parametrize("k", range(3))
def test_a_web_just_under_the_minimum_fails_at_any_angle(k):
    """mjp's 0.6 mm minimum wall: the 0.547 mm web the outside check found at hinge c of the
    expanding OR (0.91 x min_wall, inside the band the grid alone could not tell) fails, its
    thickness measured within 0.01 mm; 0.62 mm passes, and so does the minimum itself."""
    rot, off = (23 + 17 * k, 31 + 7 * k, 11 * k), (0.011 * k, 0.029 * k, 0.017 * k)
    (w,) = thin_walls("web", _web(0.547, rot, off), 0.6)
    assert abs(w.thickness_mm - 0.547) < 0.01, w
    assert abs(w.thinnest_mm - 0.547) < 0.01, w
    assert thin_walls("web", _web(0.62, rot, off), 0.6) == []
    assert thin_walls("web", _web(0.6, rot, off), 0.6) == []


def test_the_pass_mark_is_within_the_tolerance_of_the_minimum():
    """Just past the tolerance (a wall passes from (1 - WALL_TOL) min_wall, for the facets of the
    round knuckles): 0.6 (1 - WALL_TOL) - 0.004 mm fails, 0.6 (1 - WALL_TOL) + 0.003 mm passes."""
    edge = 0.6 * (1 - WALL_TOL)
    rot, off = (19, 37, 5), (0.013, 0.007, 0.031)
    assert len(thin_walls("web", _web(edge - 0.004, rot, off), 0.6)) == 1
    assert thin_walls("web", _web(edge + 0.003, rot, off), 0.6) == []


@pytest.mark.parametrize("k", range(3))
def test_the_pass_mark_is_sharp(k):
    """With exact distances to the surface (session 38; the surface samples of session 37 measured
    a wall up to 0.0024 mm thicker than it is), a web 0.001 mm under the pass mark fails and one
    0.001 mm over it passes, at oblique angles, and the thin one is measured within 0.0005 mm."""
    edge = 0.6 * (1 - WALL_TOL)
    rot, off = (11 + 23 * k, 7 + 31 * k, 5 * k), (0.007 * k, 0.019 * k, 0.023 * k)
    (w,) = thin_walls("web", _web(edge - 0.001, rot, off), 0.6)
    assert abs(w.thickness_mm - (edge - 0.001)) < 5e-4, w
    assert thin_walls("web", _web(edge + 0.001, rot, off), 0.6) == []


def test_the_report_names_the_thinnest_spot():
    """A web 0.4 mm thick over most of its length with a 0.25 mm stretch at one end (x from 3.0
    to 3.6 mm): one thin region, measured 0.4 mm (its largest ball), whose thinnest spot is the
    0.25 mm stretch (thinnest_mm, where_mm: the middle of the shortest chord), not the middle
    cell of the region, which is where the report used to point (x = 2.6, on the 0.4 mm part)."""
    solid = (_box([3, 3, 3], [0, 0, 0]) + _box([3, 3, 3], [5, 0, 0]) + _box([1.6, 3, 0.4], [2.2, 0, 0])
             + _box([0.7, 3, 0.25], [3.25, 0, 0]))
    rot = (13, 29, 7)
    (w,) = thin_walls("web", solid.rotate(list(rot)), 0.6)
    assert abs(w.thickness_mm - 0.4) < 0.01, w
    assert abs(w.thinnest_mm - 0.25) < 0.01, w
    # back in the web's own frame: the spot is on the 0.25 mm stretch, mid-thickness
    p = _unrotate(np.asarray(w.where_mm), rot)
    assert 3.0 - 0.05 < p[0] < 3.6 + 0.05 and abs(p[2]) < 0.05, p
    assert "0.25 mm at its thinnest" in w.text(0.6)


def _unrotate(p, rot):
    """A point moved back by manifold3d's rotate(rot) (x, then y, then z, degrees)."""
    ax, ay, az = np.radians(rot)
    Rx = np.array([[1, 0, 0], [0, np.cos(ax), -np.sin(ax)], [0, np.sin(ax), np.cos(ax)]])
    Ry = np.array([[np.cos(ay), 0, np.sin(ay)], [0, 1, 0], [-np.sin(ay), 0, np.cos(ay)]])
    Rz = np.array([[np.cos(az), -np.sin(az), 0], [np.sin(az), np.cos(az), 0], [0, 0, 1]])
    return (Rz @ Ry @ Rx).T @ p


def test_the_surface_distance_is_exact():
    """The distances the measure places its balls with (session 38: the nearest triangle through a
    bounding volume hierarchy, no longer the nearest of surface samples) against the box's own
    distance, worked out from its size alone: points inside, outside, near faces, edges and
    corners of a turned and moved box (its faces cut into many triangles), and which side."""
    from mlc.mesh.walls import _Surface, voxelize
    from mlc.mesh.printability import _mesh_arrays
    size = np.array([2.0, 1.2, 0.7])
    rot, off = (17, 41, 8), np.array([0.3, -0.2, 0.11])
    solid = mf.Manifold.cube(list(size), True).refine(5).rotate(list(rot)).translate(list(off))
    V, F = _mesh_arrays(solid)
    assert len(F) > 12 * 20
    grid, lo = voxelize(solid, 0.05)
    surf = _Surface(V, F, grid, lo, 0.05)
    rng = np.random.default_rng(38)
    L = rng.uniform(-0.8, 0.8, (4000, 3)) * size          # in the box's frame, inside and out
    ax, ay, az = np.radians(rot)
    Rx = np.array([[1, 0, 0], [0, np.cos(ax), -np.sin(ax)], [0, np.sin(ax), np.cos(ax)]])
    Ry = np.array([[np.cos(ay), 0, np.sin(ay)], [0, 1, 0], [-np.sin(ay), 0, np.cos(ay)]])
    Rz = np.array([[np.cos(az), -np.sin(az), 0], [np.sin(az), np.cos(az), 0], [0, 0, 1]])
    P = L @ (Rz @ Ry @ Rx).T + off
    q = np.abs(L) - size / 2
    want = np.where((q < 0).all(1), -q.max(1), np.linalg.norm(np.maximum(q, 0), axis=1))
    d, Q = surf.query(P)
    assert np.abs(d - want).max() < 1e-6       # (the mesh is in float32)
    assert np.abs(np.linalg.norm(P - Q, axis=1) - d).max() < 1e-9
    D, _, ins = surf.inside(P)
    deep = (q < -0.06).all(1)          # inside by more than a cell: the grid agrees
    assert ins[deep].all() and np.abs(D[deep] - want[deep]).max() < 1e-6
    assert not ins[(q > 0).any(1)].any() and (D[(q > 0).any(1)] == 0).all()
