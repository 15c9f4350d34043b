"""Compound chain junctions (issue 13): at every junction of a connector chain the universal
joint's first pin lies on the line of a hinge of the lower half unit, past the end of its
knuckles.  The joint part then holds that hinge's pin (one knuckle in its stack) instead of a
yoke of its own that overlapped the hinge's end knuckles."""
import numpy as np
import pytest

from mlc.gates.connector import chain_scene
from mlc.mesh.build import build_assembly
from mlc.mesh.pipeline import export_assembly
from mlc.mesh.profiles import load_profile


@pytest.fixture(scope="module")
def chain():
    return export_assembly(chain_scene(1, stops=True), load_profile("mjp"))


def test_junctions_are_compound(chain):
    asm, _ = chain
    assert len(asm.ujoints) == 2
    for uj in asm.ujoints:
        ax = uj.host
        assert ax is not None and ax.joint == uj.part
        # the joint's first pin is the hinge's line, and every body of the hinge has a hole (no body pin)
        assert abs(abs(float(np.dot(uj.axes[0], ax.direction))) - 1) < 1e-9
        rel = uj.center - ax.origin
        assert np.linalg.norm(rel - np.dot(rel, ax.direction) * ax.direction) < 1e-6
        assert ax.pin_owner == uj.part
        # the joint's knuckle sits inside the stack, next to the end knuckle of the owner (captive)
        slots = sorted([(iv, b) for b, ivs in ax.intervals.items() for iv in ivs] + [(ax.joint_iv, uj.part)])
        names = [b for _, b in slots]
        assert names[0] == names[-1] == ax.owner and uj.part in names[1:-1]
        assert uj.part in {p.name for p in asm.parts}
        assert set(ax.bodies) <= set(asm.part(uj.part).partners)


def test_chain_junctions_print(chain):
    # the blocking checks that the old junction failed: one piece per part, the clearance as
    # printed, no intersection in the logic states, every part held by its joints
    _, rep = chain
    by = {c.name: c for c in rep.checks}
    for name in ("watertight", "part_count", "min_gap", "states", "retention", "features"):
        assert by[name].ok, (name, by[name].detail, by[name].failures[:5])


def test_chain_layout_clears_without_final_trims(chain):
    # the knuckle stacks as laid out keep clear of the next half unit: no final trim is needed
    # (compound stacks lengthened to the minimum wall met it in every logic state: 12 pairs)
    asm, _ = chain
    trims = [n for n in asm.notes if n.startswith("trimmed ")]
    assert not trims, trims[:3]


def test_joint_part_clear_of_hinge_bodies_as_printed(chain):
    # independent of the report: manifold3d distance between the joint part and each body of its hinge
    asm, _ = chain
    c = asm.profile.clearance
    for uj in asm.ujoints:
        J = asm.part(uj.part).solid
        for bn in uj.host.bodies + list(uj.bodies):
            assert J.min_gap(asm.part(bn).solid, 2 * c) >= c - 1e-6, (uj.part, bn)
            assert (J ^ asm.part(bn).solid).volume() < 1e-9


def test_library_gate_has_no_compound_junction():
    from mlc.gates.library import gate_scene
    asm = build_assembly(gate_scene("NAND"), load_profile("mjp"), None, resolve=False)
    assert all(uj.host is None for uj in asm.ujoints)
    assert all(ax.joint is None for ax in asm.axes)


def test_a_yoke_plate_into_a_rod_stops_over_the_knuckles_and_into_a_slab_reaches_on():
    """_yoke_plates: a plate from a joint's pin into a rod (two thin sides: the post that
    carries a circuit chain's end joint under a gate's input lever) reaches only
    ``rod_reach`` from the pin, not the full ``reach`` along the rod, where it was a fin
    that met the gate's core (session 44); a plate into a flat slab still reaches on."""
    from mlc.mesh.build import SlabBox, _yoke_plates
    t, reach, rod_reach = 0.6, 6.0, 2.3
    origin, d = np.zeros(3), np.array([1.0, 0, 0])               # the second pin along x
    R = np.eye(3)[:, [2, 1, 0]]                                  # box length along z, up from the pin
    rod = SlabBox(np.array([0.0, 0.0, 4.0]), R, np.array([7.6, 0.6, 0.6]), 2)
    flat = SlabBox(np.array([0.0, 0.0, 4.0]), R, np.array([7.6, 2.5, 0.6]), 2)
    for sb, want in ((rod, rod_reach), (flat, reach)):
        plates = _yoke_plates([sb], origin, d, [(-2.4, 2.4)], reach, t, rod_reach=rod_reach)
        assert len(plates) == 1
        p = plates[0]
        assert abs(p.size[1] - want) < 1e-9 and abs(p.center[2] - want / 2) < 1e-9, (p.size, p.center)
    # without rod_reach (every other caller) the rod's plate is as long as before
    assert abs(_yoke_plates([rod], origin, d, [(-2.4, 2.4)], reach, t)[0].size[1] - reach) < 1e-9


def test_a_yoke_plate_across_a_slab_stays_on_the_slab():
    """_yoke_plates with ``fin_min`` (a universal joint's yokes): where the joint's pin crosses the
    slab's plane (a circuit chain's first junction on a gate's output lever), the plate is a fin
    standing across the slab; it reaches only as far as its mid-line stays on the slab, at least
    ``fin_min``.  Past the slab's outline it was a free fin that met the fin of the other output
    lever's junction in the rows where the two levers turn against each other (``(a & b) | c``:
    g1_out_lo against g1_out_hi, 0.46 mm^3 in rows 110 and 111; session 45).  A plate whose pin
    lies in the slab's plane (a widened slab) is as before (mm)."""
    from mlc.mesh.build import SlabBox, _yoke_plates
    t, reach = 0.6, 6.4
    origin = np.zeros(3)                                       # the joint at the slab's tip
    slab = SlabBox(np.array([-2.8, 0.0, 0.0]), np.eye(3), np.array([5.6, 2.5, 0.6]), 2)   # along x, 2.5 wide (y)
    tilted = np.array([0.6, 0.5, 0.62])
    tilted /= np.linalg.norm(tilted)                           # the pin out of the slab's plane (z its normal)
    long_ = _yoke_plates([slab], origin, tilted, [(-2.6, 2.6)], reach, t)[0]
    got = _yoke_plates([slab], origin, tilted, [(-2.6, 2.6)], reach, t, fin_min=1.7)[0]
    w = got.R[:, 1]
    end = origin + w * got.size[1]                             # the end of the fin's mid-line
    assert got.size[1] < long_.size[1] - 1.0, (got.size, long_.size)
    assert abs(abs(end[1]) - 1.25) < 1e-9 and -5.6 <= end[0] <= 0.0, end      # it leaves the slab at its side
    assert np.allclose(got.center, origin + w * got.size[1] / 2)
    # at least fin_min, however soon the mid-line leaves the slab
    assert abs(_yoke_plates([slab], origin, tilted, [(-2.6, 2.6)], reach, t, fin_min=4.0)[0].size[1] - 4.0) < 1e-9
    # a body with a post (an input lever carrying a chain's end joint): the plate into its slab
    # is what joins the post's knuckles to it, so no limit (the Tetris circuit's g1_a_lo and
    # g2_b_lo came out in 3 pieces with it)
    post = SlabBox(np.array([0.0, 0.0, -1.0]), np.eye(3), np.array([0.4, 0.4, 2.0]), 2)
    a, b = (_yoke_plates([slab, post], origin, tilted, [(-2.6, 2.6)], reach, t, fin_min=f) for f in (None, 1.7))
    assert len(a) == len(b) >= 1 and all(np.allclose(x.size, y.size) for x, y in zip(a, b))
    assert any(abs(x.size[1] - long_.size[1]) < 1e-9 for x in b)
    # a pin in the slab's plane: the slab widened as before
    flat = np.array([0.0, 1.0, 0.0])
    a, b = (_yoke_plates([slab], origin, flat, [(-2.6, 2.6)], reach, t, fin_min=f)[0] for f in (None, 1.7))
    assert np.allclose(a.size, b.size) and np.allclose(a.center, b.center)


def test_a_free_second_pin_turns_its_yoke_away_from_a_part_it_would_meet():
    """_PinClearance: where the other body's hinges give no second pin, the joint keeps the
    first direction when its yoke knuckles clear every other part in every posed state, and
    otherwise takes the direction about the first pin that clears them (mm)."""
    from mlc.mesh.build import _PinClearance
    R, c, t, reach = 1.1, 0.2, 0.6, 5.0
    radii = np.array([1.3, 1.85, 2.4])
    center, u, v = np.zeros(3), np.array([0.0, 0, 1]), np.array([1.0, 0, 0])
    wall = np.array([[3.0, y, z] for y in np.linspace(-1, 1, 5) for z in np.linspace(-1, 1, 5)])   # a slab at x = 3
    eye = np.eye(4)
    moved = np.eye(4)
    moved[0, 3] = 2.0                                            # ... or at x = 5
    far = {"lever": np.zeros((0, 3)), "chain": np.zeros((0, 3)), "other": wall}
    pc = _PinClearance(far, [("0", {"lever": eye, "chain": eye, "other": moved}),
                             ("1", {"lever": eye, "chain": eye, "other": moved})], R, c, t, reach)
    assert np.allclose(pc.choose(center, u, v, "chain", "lever", radii), v)      # clear (2.6 mm): kept
    pc = _PinClearance(far, [("0", {"lever": eye, "chain": eye, "other": eye}),
                             ("1", {"lever": eye, "chain": eye, "other": moved})], R, c, t, reach)
    got = pc.choose(center, u, v, "chain", "lever", radii)
    assert abs(np.dot(got, u)) < 1e-12 and abs(np.linalg.norm(got) - 1) < 1e-12
    assert abs(got[0]) < 0.3                                     # turned across, away from the slab
    kn = np.outer(np.r_[radii, -radii], got)
    assert np.min(np.linalg.norm(kn[:, None] - wall[None], axis=2)) >= R + c + t / 2
    # a knuckle laid out before counts as a part to clear
    pc.add("neighbour", np.array([0.0, 3.0, 0.0]), np.array([1.0, 0, 0]), radii)
    pc.state_T = [("0", {"lever": eye, "chain": eye, "other": moved, "neighbour": eye})]
    got2 = pc.choose(center, u, np.array([0.0, 1.0, 0.0]), "chain", "lever", radii)
    kn2 = np.outer(np.r_[radii, -radii], got2)
    nb = np.array([0.0, 3.0, 0.0]) + np.outer(np.r_[radii, -radii], [1.0, 0, 0])
    assert np.min(np.linalg.norm(kn2[:, None] - nb[None], axis=2)) >= 2 * R + c
