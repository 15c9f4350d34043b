"""Session 64 (issue 13, the robot's ``states`` failures; ``FIRST_PIN_CLEAR``): a universal
joint's second pin is chosen clear (``_PinClearance``) of the knuckles of the joints laid out
before it.  Those were the knuckles of their second pins only, and only the ones within the crop
of the joint point at rest.  In the Tetris robot's gates the lower input lever turns 73 degrees
(state 11) and carries the end joint of its input chain far from where it is at rest, into the end
of the first pin of the gate's joint part at d (its cap on ``core_cd``): ``g2_a_lo`` intersected
``g2_ujoint_d`` by 0.39 mm^3.  Now every joint's first pin (its knuckles and caps along ``u``, on
C) is registered too, and a knuckle counts where it comes within the crop in any pose.

``robot_g2`` (tests/data_mesh) is the robot's gate g2 with two bond hops round it and the whole
robot's 22 poses."""
from __future__ import annotations

import numpy as np

from helpers import load_piece, mesh_piece, part_gaps

PAIR = ("g2_a_lo", "g2_ujoint_d")


def _pair(rep):
    return [f for f in rep.check("states").failures if f"{PAIR[0]} intersects {PAIR[1]}" in f]


def test_an_end_joints_pin_turns_clear_of_the_gates_joint_part_in_every_pose():
    """With the flag the end joint under ``g2_a_lo`` takes another second pin and the lever and the
    joint part at d no longer meet; outside mlc (trimesh samples of the two finished parts posed in
    the 22 poses, a k-d tree) they stay apart in state 11, where without it they cross.  What the
    turn costs (documented, not hidden): the new pin twists further from square over the poses,
    and the end joint's own part meets its yokes by 0.03 mm^3 in state 11 (docs/printing.md,
    "Session 64")."""
    sc, poses = load_piece("robot_g2")
    asm, rep = mesh_piece("robot_g2", walls=False)
    assert _pair(rep) == [], rep.check("states").failures
    for name in ("watertight", "part_count", "min_gap", "retention", "features"):
        assert rep.check(name).ok, (name, rep.check(name).detail, rep.check(name).failures)
    gaps = part_gaps(asm, *PAIR, poses)
    assert len(gaps) == 22 and min(gaps.values()) > 0.05, gaps
    (uj,) = [u for u in asm.ujoints if u.name == "w_y_2_end_lo"]

    old, old_rep = mesh_piece("robot_g2", walls=False, FIRST_PIN_CLEAR=False)
    assert any(f.startswith("state 11:") for f in _pair(old_rep)), old_rep.check("states").failures
    assert min(part_gaps(old, *PAIR, poses).values()) < 0.02
    (ou,) = [u for u in old.ujoints if u.name == "w_y_2_end_lo"]
    # the pin the flag changes: a different direction about the same first pin
    assert abs(float(np.dot(uj.axes[1], ou.axes[1]))) < 0.95, (uj.axes[1], ou.axes[1])
    assert abs(float(np.dot(uj.axes[0], ou.axes[0]))) > 1 - 1e-9
