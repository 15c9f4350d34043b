"""Issue 13, item 4: the measured wall thickness (mlc.mesh.walls).  The voxel grid alone passed
or failed a wall between 0.72 and 0.92 x min_wall with its position on the grid; the ball centres
near the threshold are now placed from the surface itself (session 37), so a web just under the
minimum fails at any angle and offset, one at the minimum passes, and the report names the
thinnest spot of a thin region."""
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
