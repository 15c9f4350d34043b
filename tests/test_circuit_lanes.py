"""Routing lanes (mlc/circuit/lanes.py): plane assignment, rounded guides, the keep-apart test."""
import numpy as np

from mlc.circuit.lanes import SEP, Lane, Lanes, Space, layer_centres, plane_y, rounded


def test_a_lane_on_top_of_another_goes_to_the_next_plane():
    lanes = Lanes()
    a = Lane(0.0, 5.0, 20.0, 10.0, 30.0)
    assert lanes.assign(a) == 0
    lanes.take(a, 0)
    # its riser passes a's run: not in plane 0; its crossings stay clear of a, so plane 1
    assert lanes.assign(Lane(5.0, 10.0, 21.0, -5.0, 25.0)) == 1
    far = Lane(40.0, 5.0, 20.0, 50.0, 30.0)                         # far away in x: shares plane 0
    assert lanes.assign(far) == 0
    assert plane_y(1) < plane_y(0) < 0


def test_a_crossing_through_a_nearer_plane_is_a_conflict():
    lanes = Lanes()
    riser = Lane(0.0, 0.0, 40.0, 0.0, 40.0)          # plane 0: a riser at x = 0 from z 0 to 40
    lanes.take(riser, 0)
    # a chain entering at (x = 1, z = 20) crosses plane 0 right through that riser
    through = Lane(1.0, 20.0, 30.0, 20.0, 35.0)
    assert lanes.conflicts(through, 1) >= 1
    assert lanes.conflicts(through, 0) >= 1
    # moved 2 SEP along x it crosses clear of it
    assert lanes.conflicts(Lane(1.0 + 2 * SEP, 20.0, 30.0, 20.0, 35.0), 1) == 0


def test_rounded_guide_keeps_ends_and_spacing_and_cuts_corners_by_at_most_the_radius():
    pts = [(0, 0, 0), (0, 0, 10), (10, 0, 10), (10, 5, 10)]
    g = rounded(pts, 4.0, 2.0)
    assert np.allclose(g[0], pts[0]) and np.allclose(g[-1], pts[-1])
    steps = np.linalg.norm(np.diff(g, axis=0), axis=1)
    assert steps.max() < 2.0 * 1.5 and steps.min() > 0.2
    # every guide point is near the polyline (a corner cut by less than the radius)
    def dist(p):
        best = np.inf
        for a, b in zip(pts[:-1], pts[1:]):
            a, b = np.array(a, float), np.array(b, float)
            s = np.clip((p - a) @ (b - a) / ((b - a) @ (b - a)), 0, 1)
            best = min(best, np.linalg.norm(a + s * (b - a) - p))
        return best
    assert max(dist(p) for p in g) < 4.0


def test_space_nearest_matches_brute_force():
    rng = np.random.default_rng(3)
    sp = Space(0.9)
    placed = []
    for owner in range(5):
        pts = rng.uniform(0, 8, (30, 3))
        sp.add(pts, owner)
        placed += [(p, owner) for p in pts]
    q = rng.uniform(0, 8, (20, 3))
    got = sp.nearest(q, 2)
    brute = min(np.linalg.norm(p - x) for x in q for p, o in placed if o != 2)
    # the grid looks one cell (1.8) around: it is exact whenever the answer is below that
    assert brute < 1.8 and abs(got - brute) < 1e-12
    assert sp.nearest(np.array([[100.0, 100, 100]]), 0) == np.inf
    # the owner of that nearest layer, and forgetting an owner
    d, who = sp.nearest_owner(q, 2)
    brute_who = min(((np.linalg.norm(p - x), o) for x in q for p, o in placed if o != 2), key=lambda t: t[0])[1]
    assert d == got and who == brute_who
    sp.remove(who)
    assert all(o != who for cell in sp.grid.values() for _, o, _ in cell)
    assert sp.nearest(q, 2) > got and len(sp.points(2)) == 30 * 3
    assert np.allclose(layer_centres([[0, 0, 0], [0, 0, 1], [0, 0, 3]]), [[0, 0, 0.5], [0, 0, 2]])


def test_the_bounding_box_shortcut_gives_the_measured_answer():
    """``_near`` skips the measurement where the bounding boxes are ``sep`` apart: on
    random polylines (many near the threshold) it answers as ``_poly_dist(a, b) < sep``."""
    from mlc.circuit.lanes import _near, _poly_dist
    rng = np.random.default_rng(7)
    skipped = 0
    for _ in range(3000):
        a = rng.uniform(0, 10, (int(rng.integers(2, 5)), 2))
        b = rng.uniform(0, 10, (int(rng.integers(2, 5)), 2)) + rng.uniform(-12, 12, 2)
        sep = float(rng.uniform(0.5, 4.0))
        d = _poly_dist(a, b)
        if rng.random() < 0.2:
            sep = d            # exactly at the threshold: not near
        assert _near(a, b, sep) == (d < sep)
        skipped += d >= sep
    assert skipped > 500


def test_a_branchs_first_layers_are_exempt_only_from_each_other():
    """Sibling chains' first layers (``head`` layers of one ``group``) pass each other by
    in a test that names the group; every other pair of their layers is measured, and
    ``remove`` forgets exactly one owner's layers (its cells' index kept with them)."""
    sp = Space(0.9)
    # chain "a" of wire W: two head layers at the branch, then a layer far along
    sp.add(np.array([[0.0, 0, 0], [1, 0, 0], [5, 0, 0]]), "a", head=2, group="W")
    sib_head = np.array([[0.0, 0.5, 0]])            # sibling's first layer, beside a's head
    assert sp.nearest(sib_head, "b", exempt="W") == np.inf
    assert sp.nearest(sib_head, "b") == 0.5          # not exempt: measured
    # a sibling's later layer beside a's head: measured, whatever the group
    assert abs(sp.nearest(np.array([[1.0, 0.7, 0]]), "b") - 0.7) < 1e-12
    # a sibling's head beside a's layer far along (not a head): measured, exempt or not
    assert abs(sp.nearest(np.array([[5.0, 0.6, 0]]), "b", exempt="W") - 0.6) < 1e-12
    # a whole chain as it keeps apart: its head passes a's head by, its later layer does not
    chain = np.array([[0.0, 0.5, 0], [5.0, 0.8, 0]])
    assert sp.nearest_chain(chain, "b", 1, "W") == (sp.nearest(chain[1:], "b"), "a")
    assert abs(sp.nearest_chain(chain, "b", 1, "W")[0] - 0.8) < 1e-12
    assert sp.nearest_chain(chain, "b")[0] == 0.5 and sp.nearest_chain(chain[:1], "b", 1, "W") == (np.inf, None)
    # another wire's head layers are not exempt from W's test
    sp.add(np.array([[0.0, -0.4, 0]]), "c", head=1, group="V")
    assert abs(sp.nearest(sib_head, "b", exempt="W") - 0.9) < 1e-12
    sp.remove("c")
    assert sp.nearest(sib_head, "b", exempt="W") == np.inf and "c" not in sp.cells_of
    assert sorted(sp.cells_of) == ["a"] and sum(len(c) for c in sp.grid.values()) == 3
    sp.remove("nobody")                              # nothing placed: nothing to do
    assert sum(len(c) for c in sp.grid.values()) == 3
