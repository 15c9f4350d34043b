"""Session 57 (issue 13, item 4): a compiled circuit's compound junctions keep knuckles of the
minimum wall where their stacks can grow.

A compound junction's stack on a chain's hinge is four knuckles and three gaps (owner, the other
half unit, the joint part, owner) in the slab's 2.5 mm at mjp: knuckles of the minimum feature,
0.5 mm, under mjp's 0.6 mm wall: thin regions (``wall_thickness``, measured on the finished
parts) on every half unit and joint part of such a stack.  The stack now grows to knuckles of the
minimum wall on its far side only, where no other hinge's stack comes near in any pose
(``mlc.mesh.build._far_clear``); its end on the joint's side stays, so the joint's collar,
ball and yokes are those of the short stack.  A body that a grown stack leaves in pieces is
built again with that stack short.

``circuit_junction`` (tests/data_mesh): five half units of the README circuit's chain ``w_b_0``
with their four junctions (20 bodies, 8 joint parts) and the circuit's 22 print poses."""
from __future__ import annotations

import numpy as np
import pytest

from mlc.mesh import build as B
from mlc.mesh.build import build_assembly
from mlc.mesh.checks import check_assembly
from mlc.mesh.profiles import load_profile

from helpers import load_piece, posed_gaps

BLOCKING = ("watertight", "part_count", "min_gap", "states", "retention", "features")


def _piece(name):
    return load_piece(name)


def _build(grow: bool):
    sc, poses = _piece("circuit_junction")
    with B.flags(GROW_STACKS=grow):
        asm = build_assembly(sc, load_profile("mjp"), poses, reuse=True)
    return asm, check_assembly(asm)


@pytest.fixture(scope="module")
def grown():
    return _build(True)


@pytest.fixture(scope="module")
def short():
    return _build(False)


def _stacks(asm):
    return [ax for ax in asm.axes if ax.joint is not None]


def test_grown_stacks_have_knuckles_of_the_minimum_wall_and_keep_the_joint_side(grown, short):
    prof = load_profile("mjp")
    g, s = {ax.name: ax for ax in _stacks(grown[0])}, {ax.name: ax for ax in _stacks(short[0])}
    assert set(g) == set(s) and len(g) == 8
    long_ = [n for n in g if g[n].knuckle >= prof.min_wall - 1e-9]
    # most of the eight stacks have room to grow; the rest keep minimum-feature knuckles
    assert 4 <= len(long_) < 8, {n: g[n].knuckle for n in g}
    assert all(abs(s[n].knuckle - prof.min_feature) < 1e-9 for n in s)
    uj = {u.part: u for u in grown[0].ujoints}
    for n in long_:
        a, b = g[n], s[n]
        # the end nearer the joint point is where the short stack's is; the far end moved out
        c = uj[a.joint].center
        side = np.sign(np.dot(c - b.origin, b.direction))
        near_a = np.dot(a.origin - b.origin, b.direction) + side * a.span / 2
        assert abs(near_a - side * b.span / 2) < 1e-9
        assert a.span > b.span + 0.3
        # and the joint's ball is the short stack's
        u_short = {u.part: u for u in short[0].ujoints}[a.joint]
        assert abs(uj[a.joint].hub_r - u_short.hub_r) < 1e-9


def test_the_piece_still_passes_every_blocking_check(grown, short):
    for rep in (grown[1], short[1]):
        for name in BLOCKING:
            assert rep.check(name).ok, (name, rep.check(name).detail, rep.check(name).failures)


def test_fewer_walls_under_the_minimum(grown, short):
    # measured on the finished parts (mlc.mesh.walls): the 0.5 mm knuckles were thin regions of
    # every half unit and joint part on a short stack
    def thin(rep):
        return [f for f in rep.check("wall_thickness").failures]
    ng, ns = grown[1].check("wall_thickness").value, short[1].check("wall_thickness").value
    assert ng is not None and ns is not None
    assert len(thin(grown[1])) < len(thin(short[1])) - 8, (len(thin(grown[1])), len(thin(short[1])))
    # the joint parts of grown stacks have no thin region left
    long_joints = {ax.joint for ax in _stacks(grown[0]) if ax.knuckle >= 0.6 - 1e-9}
    assert long_joints
    assert not [f for f in thin(grown[1]) if f.split(":")[0] in long_joints]
    assert [f for f in thin(short[1]) if f.split(":")[0] in long_joints]


def test_stacks_grown_regardless_of_the_poses_meet(grown, monkeypatch):
    # without the pose tests (_far_clear as laid out, GROWN_CLEAR once every plate is) every
    # stack grows, and far ends meet their neighbours' parts in logic states (the guards are what
    # keep the blocking checks passing)
    monkeypatch.setattr(B, "_far_clear", lambda *a, **k: True)
    monkeypatch.setattr(B, "GROWN_CLEAR", False)
    sc, poses = _piece("circuit_junction")
    asm = build_assembly(sc, load_profile("mjp"), poses, reuse=True)
    assert all(ax.knuckle >= 0.6 - 1e-9 for ax in _stacks(asm))
    rep = check_assembly(asm, walls=False)
    assert not (rep.check("states").ok and rep.check("min_gap").ok)
    short = {ax.name for ax in _stacks(grown[0]) if ax.knuckle < 0.6 - 1e-9}
    assert short


def test_stacks_measured_as_cylinders_grow_where_their_axes_alone_kept_them_short(monkeypatch):
    """Session 58: ``_far_clear`` kept a stack short wherever another hinge's axis came within both
    knuckle radii and the clearance of the stretch it grows into, which in a chain is the previous
    half unit's stack, end to end with it (the README circuit: 574 of the 615 short stacks so
    blocked already at rest).  The two solid cylinders are now measured where the axes come that
    near (``STACK_CYLINDERS``): on the branch piece ``circuit_leaf`` every stack grows, every
    blocking check still passes, and fewer walls are thinner than the minimum."""
    sc, poses = _piece("circuit_leaf")
    prof = load_profile("mjp")

    def build(cyl):
        monkeypatch.setattr(B, "STACK_CYLINDERS", cyl)
        asm = build_assembly(sc, prof, poses, reuse=True)
        return asm, check_assembly(asm)
    new, old = build(True), build(False)
    k_new = [ax.knuckle for ax in _stacks(new[0])]
    k_old = [ax.knuckle for ax in _stacks(old[0])]
    assert len(k_new) == len(k_old) == 14
    assert all(k >= prof.min_wall - 1e-9 for k in k_new), k_new
    assert sum(k >= prof.min_wall - 1e-9 for k in k_old) < 12, k_old
    for name in BLOCKING:
        assert new[1].check(name).ok, (name, new[1].check(name).detail, new[1].check(name).failures)
    n_new, n_old = (len(r.check("wall_thickness").failures) for r in (new[1], old[1]))
    assert n_new < n_old - 10, (n_new, n_old)


def _sampled_gap(a, b, n=300_000):
    """The gap (mm) between two finished parts as built (:func:`helpers.posed_gaps`)."""
    return posed_gaps(a.solid, b.solid, [(None, None)], n)[0]


def test_grown_plates_stop_short_of_the_bodys_other_hinges(monkeypatch):
    """Session 59: with ``STACK_CYLINDERS`` the whole README circuit grew 721 of 866 stacks, but
    60 pairs of a half unit's two slabs came 0.10-0.16 mm apart (min_gap).  ``circuit_chain_y``
    (five half units of the chain ``w_y_0``, 19 to 23, cut from that circuit with its 22 poses)
    shows it: each half unit's stacks B and D grow on the same side; the plate widening DA to its
    grown stack D ran the slab's whole length, past hinge A's span, where no trim clears it from
    AB (its plate to stack B and its yoke for the previous junction lie there).  The plates over the grown stretch now reach only as far as the knuckles
    need, only on a body with a knuckle there (``_grown_plates``), and a stack whose new
    material still comes near another body is built short (``GROWN_CLEAR``)."""
    sc, poses = _piece("circuit_chain_y")
    prof = load_profile("mjp")
    monkeypatch.setattr(B, "STACK_CYLINDERS", True)

    def build(clear):
        monkeypatch.setattr(B, "GROWN_CLEAR", clear)
        asm = build_assembly(sc, prof, poses, reuse=True)
        return asm, check_assembly(asm)
    new, old = build(True), build(False)
    # as built in session 58: every stack grows and the two slabs of half unit 21 meet at hinge A
    assert all(ax.knuckle >= prof.min_wall - 1e-9 for ax in _stacks(old[0]))
    mg = old[1].check("min_gap")
    assert not mg.ok and any("w_y_0_21_AB - w_y_0_21_DA" in f for f in mg.failures), mg.failures
    parts = {p.name: p for p in old[0].parts}
    assert _sampled_gap(parts["w_y_0_21_AB"], parts["w_y_0_21_DA"]) < prof.clearance
    # now: every stack still grows, every blocking check passes, the pair keeps the clearance
    k_new = [ax.knuckle for ax in _stacks(new[0])]
    assert len(k_new) == 8 and all(k >= prof.min_wall - 1e-9 for k in k_new), k_new
    for name in BLOCKING:
        assert new[1].check(name).ok, (name, new[1].check(name).detail, new[1].check(name).failures)
    parts = {p.name: p for p in new[0].parts}
    # (hinge partners: their knuckles at hinge A sit at the clearance itself)
    assert _sampled_gap(parts["w_y_0_21_AB"], parts["w_y_0_21_DA"]) >= prof.clearance - 1e-4
    # and fewer walls under the minimum than with the stacks short (session 57's build)
    monkeypatch.setattr(B, "STACK_CYLINDERS", False)
    short = check_assembly(build_assembly(sc, prof, poses, reuse=True))
    assert len(new[1].check("wall_thickness").failures) < len(short.check("wall_thickness").failures) - 10


def test_a_grown_stack_near_another_body_is_built_short(monkeypatch):
    """``GROWN_CLEAR``'s own failing case: the grown stretch's plates as long as the slab again
    (the session-58 plates) come near the hinge-A partner in every half unit, so every such stack
    is built short (the pair then keeps the clearance)."""
    sc, poses = _piece("circuit_chain_y")
    prof = load_profile("mjp")
    monkeypatch.setattr(B, "STACK_CYLINDERS", True)
    monkeypatch.setattr(B, "_grown_plates", lambda bn, sbs, ax, far, reach, t:
                        B._yoke_plates(sbs, ax.origin, ax.direction, [far], reach, t))
    asm = build_assembly(sc, prof, poses, reuse=True)
    ks = [ax.knuckle for ax in _stacks(asm)]
    assert len(ks) == 8 and all(k < prof.min_wall - 1e-9 for k in ks), ks
    assert any("0 of 8 stacks" in n for n in asm.notes), [n for n in asm.notes if "compound" in n]
    assert check_assembly(asm, walls=False).check("min_gap").ok


def test_far_clear_samples_again_finer_where_the_coarse_samples_are_within_their_own_reach():
    """``_far_clear`` samples the two knuckle cylinders every quarter clearance: a pair sampled
    nearer than the clearance plus that sampling's reach (step / sqrt 2) was refused though it may
    keep the clearance.  With ``FINE_GAPS`` such a pair is sampled again five times finer.  Two
    coaxial stacks end to end (their gap is the distance of their end faces), the stack on x
    growing 0.3 mm towards the one on y: a gap between the clearance and the coarse bound is
    refused without, let grow with; a gap under the clearance is refused either way."""
    c, R = 0.2, 1.1
    x = np.array([1.0, 0.0, 0.0])

    def axis(name, bodies, at):
        return B.HingeAxis(name, [], np.array([at, 0.0, 0.0]), x.copy(), 2.5, bodies, {}, 0.7, R, 0.3, 0.5,
                           scene_span=2.5)
    slab = [B.SlabBox(np.zeros(3), np.eye(3), np.array([2.5, 4.0, 0.6]), 2)]
    slabs = {"x1": slab, "x2": slab}
    for gap, fine in ((0.21, True), (0.21, False), (0.19, True)):
        ax = axis("hx", ["x1", "x2"], 0.0)
        bx = axis("hy", ["y1", "y2"], 1.25 + 0.3 + gap + 1.25)
        with B.flags(FINE_GAPS=fine):
            ok = B._far_clear(ax, 1, 1.25, 1.55, [ax, bx], slabs, [], 0.6, c, [])
        assert ok == (gap > c and fine), (gap, fine, ok)


def test_an_ordinary_hinge_end_to_end_with_a_growing_stack_yields_its_end():
    """Session 62: most compound stacks left short met the previous half unit's ordinary hinge
    end to end.  With ``YIELD_ENDS`` that hinge's facing end moves back, its three knuckles
    shortened alike (not under ``kmin``, the minimum wall), by the least multiple of
    ``YIELD_STEP`` that keeps the clearance, and only once the stack may grow.  Two coaxial
    stacks end to end, the stack on x growing 0.3 mm towards the ordinary hinge on y."""
    c, R, g, kmin = 0.2, 1.1, 0.2, 0.6
    x = np.array([1.0, 0.0, 0.0])
    slab = [B.SlabBox(np.zeros(3), np.eye(3), np.array([2.5, 4.0, 0.6]), 2)]
    slabs = {"x1": slab, "x2": slab}

    def axis(name, bodies, at, joint=None, k=0.7, direction=x):
        span = 3 * k + 2 * g
        ax_ = B.HingeAxis(name, [], np.array(at, float), direction.copy(), span, bodies, {}, k, R, 0.3, 0.5,
                          layout=[bodies[0], bodies[1], bodies[0]], scene_span=2.5, joint=joint)
        ax_.intervals = {bodies[0]: [(-span / 2, -span / 2 + k), (span / 2 - k, span / 2)],
                         bodies[1]: [(-k / 2, k / 2)]}
        return ax_

    def grow(gap, others=(), **fl):
        ax = axis("hx", ["x1", "x2"], [0.0, 0.0, 0.0])
        bx = axis("hy", ["y1", "y2"], [1.25 + 0.3 + gap + 1.25, 0.0, 0.0])
        notes = []
        with B.flags(**fl):
            ok = B._far_clear(ax, 1, 1.25, 1.55, [ax, bx, *others], slabs, [], 0.6, c, [], kmin=kmin, g=g,
                              notes=notes)
        return ok, bx, notes

    # 0.1 mm apart: the hinge yields 0.15 mm (0.10 leaves the clearance itself, under its samples' reach)
    at = 1.25 + 0.3 + 0.1 + 1.25
    ok, bx, notes = grow(0.1)
    assert ok and len(notes) == 1 and "yields 0.15 mm" in notes[0], notes
    assert bx.span == pytest.approx(2.35) and bx.knuckle == pytest.approx(0.65)
    assert bx.origin[0] == pytest.approx(at + 0.075)            # its far end stays
    ends = sorted(a for ivs in bx.intervals.values() for iv in ivs for a in iv)
    assert bx.origin[0] + ends[0] == pytest.approx(at - 1.25 + 0.15) and bx.origin[0] + ends[-1] == pytest.approx(at + 1.25)
    assert all(b - a == pytest.approx(0.65) for ivs in bx.intervals.values() for a, b in ivs)
    # the knuckles' gaps stay the knuckle gap
    assert sorted(ends)[1:-1] == pytest.approx([ends[0] + 0.65, ends[0] + 0.85, ends[0] + 1.5, ends[0] + 1.7])
    # without the flag, or nearer than three knuckles can give (0.3 mm down to 0.6 mm knuckles): refused, unchanged
    for gap, fl in ((0.1, {"YIELD_ENDS": False}), (-0.15, {})):
        ok, bx, notes = grow(gap, **fl)
        assert not ok and not notes and bx.span == pytest.approx(2.5) and bx.knuckle == pytest.approx(0.7)
    # a compound stack never yields (its joint part's collar and ball are laid out from its end)
    cx = axis("hz", ["z1", "z2"], [1.25 + 0.3 + 0.1 + 1.25, 0.0, 0.0], joint="jz")
    ax = axis("hx", ["x1", "x2"], [0.0, 0.0, 0.0])
    assert not B._far_clear(ax, 1, 1.25, 1.55, [ax, cx], slabs, [], 0.6, c, [], kmin=kmin, g=g)
    # a yield is not made when another stack keeps the stack short: the hinge stays as it was
    y = np.array([0.0, 1.0, 0.0])
    side = axis("hs", ["s1", "s2"], [1.4, 2 * R + 0.1, 0.0], joint="js", direction=y)
    ok, bx, notes = grow(0.1, others=(side,))
    assert not ok and not notes and bx.span == pytest.approx(2.5)
    # the prefilter's midpoints (made once per build) move with the yield, at rest and in every
    # pose: a later stack near the yielded hinge's other end is measured against its new span
    th = 0.7
    T = np.eye(4)
    T[:3, :3] = [[np.cos(th), -np.sin(th), 0.0], [np.sin(th), np.cos(th), 0.0], [0.0, 0.0, 1.0]]
    T[:3, 3] = [0.4, -1.3, 2.0]
    pose = {b: T for b in ("x1", "x2", "y1", "y2")}         # the whole pair moved rigidly
    ax = axis("hx", ["x1", "x2"], [0.0, 0.0, 0.0])
    bx = axis("hy", ["y1", "y2"], [at, 0.0, 0.0])
    mids: list = []
    assert B._far_clear(ax, 1, 1.25, 1.55, [ax, bx], slabs, [("moved", pose)], 0.6, c, mids, kmin=kmin, g=g)
    assert bx.origin[0] == pytest.approx(at + 0.075)
    assert mids[0][0, 1] == pytest.approx(bx.origin)
    assert mids[0][1, 1] == pytest.approx(T[:3, :3] @ bx.origin + T[:3, 3])
    assert mids[0][1, 0] == pytest.approx(T[:3, 3])          # the growing stack's own stays


def test_fine_gaps_let_a_stack_grow_next_to_the_previous_unit_and_keep_the_clearance():
    """Session 61: ``circuit_fine`` (tests/data_mesh: half units ``w_b_0_25`` to ``_29`` of the
    README circuit with its 22 print poses, cut by ``mlc.mesh.pipeline.sub_scene``) holds one of
    the 11 stacks of that circuit that grow only with ``FINE_GAPS``: stack D of ``w_b_0_27``, whose
    grown far end comes within the coarse samples' reach of the clearance from the previous half
    unit.  With it every stack of the piece grows, every blocking check passes and no wall is
    under the minimum; without it that stack keeps 0.5 mm knuckles and thin regions.  The grown
    stack's bodies keep the clearance from the previous half unit's parts, measured outside mlc
    (trimesh samples, a k-d tree)."""
    prof = load_profile("mjp")
    sc, poses = _piece("circuit_fine")
    with B.flags(FINE_GAPS=True):
        asm = build_assembly(sc, prof, poses, reuse=True)
    with B.flags(FINE_GAPS=False):
        old = build_assembly(sc, prof, poses, reuse=True)
    k = {ax.name: ax.knuckle for ax in _stacks(asm)}
    k_old = {ax.name: ax.knuckle for ax in _stacks(old)}
    assert len(k) == 8 and all(v >= prof.min_wall - 1e-9 for v in k.values()), k
    assert k_old["w_b_0_27_hD"] < prof.min_wall - 1e-9, k_old
    assert all(v >= prof.min_wall - 1e-9 for n, v in k_old.items() if n != "w_b_0_27_hD"), k_old
    rep, rep_old = check_assembly(asm), check_assembly(old)
    for name in BLOCKING:
        assert rep.check(name).ok, (name, rep.check(name).detail, rep.check(name).failures)
    assert rep.check("wall_thickness").ok, rep.check("wall_thickness").failures
    assert not rep_old.check("wall_thickness").ok
    parts = {p.name: p for p in asm.parts}
    stack = [n for n in ("w_b_0_27_CD", "w_b_0_27_DA") if n in parts]
    prev = [n for n in parts if n.startswith("w_b_0_26_")]
    assert len(stack) == 2 and len(prev) == 4
    gaps = {(a, b): _sampled_gap(parts[a], parts[b], n=100_000) for a in stack for b in prev}
    assert min(gaps.values()) >= prof.clearance - 1e-3, gaps


def test_the_previous_units_hinge_yields_so_that_a_stack_grows_and_keeps_the_clearance(grown):
    """Session 62 on ``circuit_junction``: stack D of ``w_b_0_59`` met the previous half unit's
    ordinary hinge C end to end (its cylinders 0.165 mm apart where the stack would grow).  With
    ``YIELD_ENDS`` that hinge's facing end moves back 0.05 mm (knuckles of 0.683 mm, over the
    minimum wall) and the stack grows; without, it keeps 0.5 mm knuckles.  Every blocking check
    passes, fewer walls are thin, and the grown stack's bodies keep the clearance from the yielded
    hinge's, measured outside mlc (trimesh samples, a k-d tree)."""
    prof = load_profile("mjp")
    sc, poses = _piece("circuit_junction")
    with B.flags(YIELD_ENDS=False):
        old = build_assembly(sc, prof, poses, reuse=True)
    asm, rep = grown
    k = {ax.name: ax.knuckle for ax in _stacks(asm)}
    k_old = {ax.name: ax.knuckle for ax in _stacks(old)}
    assert k["w_b_0_59_hD"] >= prof.min_wall - 1e-9 and k_old["w_b_0_59_hD"] < prof.min_wall - 1e-9
    assert sum(v >= prof.min_wall - 1e-9 for v in k.values()) == sum(v >= prof.min_wall - 1e-9
                                                                     for v in k_old.values()) + 1
    yielded = {ax.name: ax for ax in asm.axes if ax.joint is None and ax.knuckle < 0.7 - 1e-9}
    assert list(yielded) == ["w_b_0_58_hC"], {n: a.knuckle for n, a in yielded.items()}
    assert yielded["w_b_0_58_hC"].knuckle >= prof.min_wall - 1e-9
    assert [n for n in asm.notes if "yields" in n] == [
        "hinge w_b_0_58_hC: its end yields 0.05 mm to the grown stack of w_b_0_59_hD (knuckles 0.683 mm)"]
    rep_old = check_assembly(old)
    for name in BLOCKING:
        assert rep.check(name).ok, (name, rep.check(name).detail, rep.check(name).failures)
    assert len(rep.check("wall_thickness").failures) < len(rep_old.check("wall_thickness").failures)
    parts = {p.name: p for p in asm.parts}
    gaps = {(a, b): _sampled_gap(parts[a], parts[b], n=100_000)
            for a in ("w_b_0_59_CD", "w_b_0_59_DA") for b in ("w_b_0_58_BC", "w_b_0_58_CD")}
    assert min(gaps.values()) >= prof.clearance - 1e-3, gaps
