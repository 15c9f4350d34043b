"""Scene -> printable parts: solids built with manifold3d CSG, in millimetres.

Every rigid body becomes one part: its slabs (thickened to the profile's slab thickness)
with the knuckles of its hinges and holes (or lugs) at its muscle/probe attachment sites.
Every universal joint becomes one more part: a hub with two perpendicular pins (paper
Fig. 4).  docs/printing.md describes the design for users.

Hinges (print-in-place, paper "3D printing of NAND gate")
--------------------------------------------------------
The hinge joints of a scene are grouped by axis: joints whose axes lie on one line form
one *hinge axis* (the hinge at point ``c`` of a gate joins three bodies and appears as
two pairwise joints).  Along the axis, knuckles alternate: the *pin owner* (the first
body of the axis) holds both end knuckles and a pin through the whole span; each other
body holds one knuckle between them with a hole of radius ``pin + clearance``:

    [owner | gap | body 2 | gap | body 3 | gap | owner]

With ``pin: cone`` each knuckle instead carries a 45 degree cone on its upper face, seated
in a recess (the cone offset by the clearance) of the next knuckle.  Knuckles are
cylinders of radius ``R = pin/2 + clearance + min_wall`` and at least ``min_feature`` and
``min_wall`` long (a knuckle is a ring: its length is a wall; the span grows past the slab
width if needed; the slab is widened by a *yoke plate* to carry it).

Trimming
--------
1. Around every knuckle of another body, a body's slab is cut back to the axis's *trim
   radius* ``rho >= R + clearance``: slab mid-planes are sampled and, in every logic state,
   each pair of points of two bodies closer than thickness + clearance must lose one point.
2. A slab running *along* an axis would be severed: it gets a bridge around the other
   knuckles, on the side no other body swings through.
3. What still comes closer than the clearance (as printed) or intersects (in a logic state)
   is trimmed last (:func:`_resolve`): one of the two parts loses the other's region, grown
   by 1.5 x clearance, never its knuckles or pins.
4. Attachment holes are drilled last, where the trimmed slab has room (:func:`_drill`).

Universal joint
---------------
A separate part at the bond point: a hub of two crossed cylinders and two crossed pins,
one along each body's hinge direction.  Each body holds a yoke: two knuckles with holes
at the ends of its pin, beyond the hub, or one knuckle on one side with a cap on the pin
when the other body's arm passes the other side.  Around the hub each body is trimmed to
the radius the other yoke sweeps.

Pitfalls handled here: every cylinder gets ``circular_segments`` explicitly; every hole
and clearance cutter is scaled by ``1/cos(pi/n)`` so the inscribed polygon keeps the full
clearance.
"""
from __future__ import annotations

import contextlib
import copy
import itertools
import math
import os
import sys
import time
from dataclasses import dataclass, field

import manifold3d as mf
import numpy as np

from mlc.errors import MlcError
from mlc.geometry.rotation import quat_to_matrix
from mlc.mesh.congruence import Congruence, points_key, pose_key, shape_key
from mlc.mesh.profiles import PAPER_SLAB_MM, Profile
from mlc.mesh.spatial import (box_pairs, local_boxes, pair_gaps, part_frames, posed_boxes, posed_pairs,
                               solid_boxes)
from mlc.scene.model import Scene

_TOL = 1e-3  # sigma: tolerance for "same point / same line"
#: assemblies with at least this many parts reuse results across congruent parts by default
REUSE_MIN_PARTS = 64
#: large assemblies (compiled circuits) too: a body's web thinner than the minimum wall where its
#: hinge's trim meets another trim (a gate's core_cd at hinge c) is bridged (issue 13, session 58)
WEB_BRIDGES = True
#: a slab box with two thin sides (a rod: the post under a circuit gate's input lever that carries a
#: chain's end joint, a branch page's arm) is printed at least the slab thickness both ways (session 58)
ROD_WALL = True
APART_GAP = True      # large assemblies: min_gap of pairs proven farther apart than the search skips manifold3d
GUARD_PAD = 0.005  # mm: protected material grown by this much for the final trims of large assemblies
#: branch junction: a page counts as stacked on the source's hinge line (the compound junction's
#: fin up that line into its own end knuckle) only when its hinge is within this cosine of the line;
#: a chain's next layer, bent at the junction, keeps 0.5 (_compound's o_cos)
O_COS = 0.95
#: large assemblies: a body whose own knuckles lie off its slab along a hinge crossing the slab
#: gets a fin across the slab that carries them (:func:`_knuckles_off_slab`; session 50)
OFF_SLAB_FINS = True
#: large assemblies: the final trims (:func:`_resolve`) never keep a trim that splits a part (session 50)
KEEP_WHOLE = True
SPLIT_TWIST = True    # compound junctions: the joint part posed with the twist shared by its pins (_split_twist)
PIN_TWIST = True      # compound junctions: the second pin turned about the first to the least twist (least_twist)
ONE_SIDED_TWIST = True   # ... with a one-sided yoke where both sides would not be clear (session 51)
ONE_SIDED_ABOVE = 4.0    # degrees: ... only when the least twist with both sides is more than this
ONE_SIDED_GAIN = 1.0     # degrees: ... and the one-sided yoke's twist less by at least this
TURNED_FREE_SIDE = True  # a turned one-sided compound yoke: no plate past the hub on its free side (session 55)
#: large assemblies: a yoke plate off its slab's layer (a joint on a post) that comes near a body
#: other than its joint's two as printed stops short of it (:func:`_clip_near_plates`; session 69:
#: the robot's skeleton)
CLIP_NEAR_PLATES = True
#: ... near in the logic states too, not only as printed: off (session 69: on the robot's skeleton
#: piece it stopped skel_u3's end-joint plates short of a wrist that passes in rows 01 and 11, and
#: skel_u3, whose two end joints' knuckles those plates hold, came out in 3 pieces)
NEAR_PLATES_STATES = False
CLIP_UJ_PLATES = True    # a yoke plate past the end of another hinge of its body stops at its trim radius (session 55)
UNTWIST_SPLIT = True     # ... not to a pin that cuts the other body in pieces (built again; session 52)
GROW_STACKS = True       # a compound junction's stack: knuckles of the minimum wall, grown on its far side (session 57)
#: _far_clear: where two stacks' axes come within both radii and the clearance, the solid knuckle
#: cylinders themselves are measured (session 58; off: such a stack never grows).  Off in session 58:
#: on the whole README circuit 721 of 866 stacks grew with it (251 without) and the thin regions
#: halved, but 60 pairs of a half unit's two slabs came 0.10-0.16 mm apart (min_gap): each slab
#: widened to its grown stack over the slab's whole length, the two met past their common hinge's
#: span.  On again with GROWN_CLEAR (session 59)
STACK_CYLINDERS = True
#: a grown stack's new stretch, knuckles and plates, must keep the clearance from every body but the
#: stack's own in every pose (:func:`_grown_near`), else the stack is built short (session 59): a
#: grown stack's plates met a half unit's hinge partner past that hinge's span, where no trim clears them
GROWN_CLEAR = True
#: a compound junction's yoke on both sides whose knuckle on one side comes within the clearance
#: of another joint's yoke plate on another body in some pose (where neither the pin choice, which
#: sees slabs and knuckles, nor the trims, which keep knuckles and would cut the plate off its
#: knuckles, clear it) is built again one-sided, on the other side (:func:`_knuckles_at_plates`;
#: session 66: the compiled (a & b) | c, the chain's first junctions on g1's two output levers)
KNUCKLE_PLATES = True
#: a compound junction's one-sided yoke: O is trimmed about the pin a knuckle gap past the joint
#: part's end cap, not to its end face (:func:`_compound_yoke_layout`; session 69: O's slab past the
#: cap was printed touching the cap, the README robot's ``w_y_3_3_CD`` - ``w_y_3_j3_hi``)
CAP_END_CUT = True
#: a compound junction's fin kept past the joint part's ball, clear of O's trim about the second pin, where
#: the collar never turns round to it (:func:`_fin_keep`; session 60)
FIN_KEPT = True
#: a compound junction's two knuckles that face across its joint point (the host stack's knuckle ending
#: nearest it, the other body's yoke knuckles' inner ends) have their rims there chamfered at 45
#: degrees by this fraction of the clearance, at most RIM_CAP of half the minimum wall
#: (:func:`_rim_chamfers`; session 67: square, their rims were 0.2 mm apart at mjp, and the
#: junction's bend and twist in the poses, the scene's ball joint, took them to 0.03 mm)
RIM_CHAMFER = 0.8
#: ... and its host body (C; not the hinge's other bodies) is trimmed about the first pin this many
#: clearances farther than the other body's yoke knuckles reach (R + c before; session 67: 0.2 mm,
#: 0.10 in the poses)
HOST_CUT_MARGIN = 1.0
#: ... and the hinge's other bodies (the stack's owner, whose end knuckle stands between the joint's
#: collar and the joint point) too: off.  Session 68 (``benchmarks/rim_chamfer.py --variants s67
#: owner_margin``): the README circuit's remaining pairs of neighbouring half units under the
#: clearance are that owner's cut face against the other body's yoke knuckle, which the scene's ball
#: joint turns about the third axis (a twist the printed cardan takes up in its play); the margin
#: clears them but leaves the end knuckle's web to the slab under the minimum wall (0.45 mm at mjp)
OWNER_CUT_MARGIN = False
SHAVE_THIN = True        # the thin webs the trims leave away from a body's joints, taken away (mlc.mesh.shave; session 60)
#: where a grown stack's coarse samples (:func:`_far_clear`, :func:`_grown_near`) come nearer than the
#: clearance plus their own reach but not nearer than the clearance, they are sampled again five
#: times finer before the stack is kept short (session 61)
FINE_GAPS = True
#: an ordinary hinge end to end with a compound stack that would grow (:func:`_far_clear`): its
#: facing end moves back by multiples of YIELD_STEP mm, its knuckles shortened alike down to the
#: minimum wall, where that lets the stack grow (session 62)
YIELD_ENDS = True
YIELD_STEP = 0.05
#: a universal joint's yoke plate into a rod (the post under a circuit gate's input lever) reaches at
#: least the trim radius about its pin plus the slab thickness, so that the band the trim leaves of it
#: is a full wall (session 63: it reached max(R, hub) + 2 t, 0.435 mm past a 1.865 mm trim at mjp)
ROD_PLATE_WALL = True
#: ... only as far as its stretch past the old reach (``max(R, hub) + 2 t``) keeps the slab thickness
#: and clearance from every other body's material in every pose (:func:`_rod_wall_reach`; session 64:
#: the Tetris robot's gates turn their input levers further than the circuit's, 73 degrees, and the
#: longer post plate met ``core_cd``, 0.01-0.13 mm^3 in g1, g2 and g3)
ROD_PLATE_CLEAR = True
#: a universal joint's second pin chosen clear (:class:`_PinClearance`) of the knuckles and pin caps
#: of the joints laid out before it on both their pins, not only on their second (session 64: the
#: cap of gate g2's joint d on ``core_cd`` met the yoke knuckle of the chain's end joint under
#: ``g2_a_lo`` in the Tetris robot's state 11, 0.39 mm^3)
FIRST_PIN_CLEAR = True


@contextlib.contextmanager
def flags(**values):
    """Set this module's build flags (``GROW_STACKS=False``, ...) for the duration of a ``with``
    block, restored after it, also when it raises: for measuring what a flag changes (tests,
    benchmarks).  An unknown flag's name is an error before anything is set."""
    g = globals()
    unknown = [k for k in values if k not in g or not k.isupper()]
    if unknown:
        raise AttributeError(f"mlc.mesh.build has no flag {', '.join(unknown)}")
    old = {k: g[k] for k in values}
    g.update(values)
    try:
        yield
    finally:
        g.update(old)


# --------------------------------------------------------------------------- primitives
def _perp_frame(d) -> np.ndarray:
    """A rotation matrix whose third column is the unit vector ``d``."""
    d = np.asarray(d, float) / np.linalg.norm(d)
    a = np.array([1.0, 0, 0]) if abs(d[0]) < 0.9 else np.array([0, 1.0, 0])
    e1 = np.cross(d, a)
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(d, e1)
    return np.column_stack([e1, e2, d])


#: large assemblies: the frame (inverse, 4x4) every primitive is built in while a body is built
#: in its own frame (see build_assembly), or None (the world)
_LOCAL: list = [None]
LOCAL_BUILD = True    # large assemblies: bodies built in their own frames (False: in the world, as before)
LOCAL_Q = 1e-12       # mm: rounding of a primitive's position in its body's frame
LOCAL_QR = 1e-14      # and of its rotation matrix's entries (coarser roundings leave slivers: 1e-9 gave 25 times the degenerate triangles)


def _affine(R, t) -> np.ndarray:
    """The 3x4 placement (R, t) of a primitive; while a body is built in its own frame, that
    placement seen from the frame, rounded to LOCAL_Q: congruent bodies give their booleans the
    same primitives to the last bit (an exact affine image of the same primitive: faces stay flat)."""
    Fi = _LOCAL[0]
    if Fi is not None:
        R = np.round(Fi[:3, :3] @ np.asarray(R, float) / LOCAL_QR) * LOCAL_QR
        t = np.round((Fi[:3, :3] @ np.asarray(t, float) + Fi[:3, 3]) / LOCAL_Q) * LOCAL_Q
    m = np.zeros((3, 4))
    m[:, :3] = R
    m[:, 3] = t
    return m


def cylinder(origin, direction, s0, s1, radius, segments, cutter=False) -> mf.Manifold:
    """A cylinder on the line ``origin + s*direction`` for ``s0 <= s <= s1``.

    ``cutter=True`` scales the radius by ``1/cos(pi/n)`` so the polygon's inscribed circle
    has the nominal radius (holes and clearance cuts never shrink)."""
    if s1 <= s0 or radius <= 0:
        return mf.Manifold()
    r = radius / np.cos(np.pi / segments) if cutter else radius
    d = np.asarray(direction, float) / np.linalg.norm(direction)
    c = mf.Manifold.cylinder(float(s1 - s0), float(r), -1.0, int(segments))
    return c.transform(_affine(_perp_frame(d), np.asarray(origin, float) + s0 * d))


def cone(origin, direction, s0, s1, r0, r1, segments, cutter=False) -> mf.Manifold:
    """A truncated cone on a line, radius ``r0`` at ``s0`` and ``r1`` at ``s1``."""
    k = 1 / np.cos(np.pi / segments) if cutter else 1.0
    d = np.asarray(direction, float) / np.linalg.norm(direction)
    if s1 < s0:
        s0, s1, r0, r1 = s1, s0, r1, r0
    c = mf.Manifold.cylinder(float(s1 - s0), float(r0 * k), float(r1 * k), int(segments))
    return c.transform(_affine(_perp_frame(d), np.asarray(origin, float) + s0 * d))


def knuckle(origin, direction, s0, s1, radius, segments, lo=0.0, hi=0.0) -> mf.Manifold:
    """:func:`cylinder` with its rim chamfered at 45 degrees by ``lo`` at ``s0`` and ``hi`` at ``s1``
    (mm; each at most a third of the length).  One revolved section, the same polygon as the
    cylinder's: a cone and a cylinder unioned leave slivers of triangles along their seam, where
    the wall measure (:mod:`mlc.mesh.walls`) found rings of the minimum wall thin."""
    lo, hi = (min(max(x, 0.0), (s1 - s0) / 3) for x in (lo, hi))
    if lo <= 0 and hi <= 0:
        return cylinder(origin, direction, s0, s1, radius, segments)
    L = float(s1 - s0)
    ring = [(0.0, 0.0)] + ([(radius - lo, 0.0), (radius, lo)] if lo > 0 else [(radius, 0.0)]) + \
        ([(radius, L - hi), (radius - hi, L)] if hi > 0 else [(radius, L)]) + [(0.0, L)]
    d = np.asarray(direction, float) / np.linalg.norm(direction)
    m = mf.CrossSection([[(float(x), float(y)) for x, y in ring]]).revolve(int(segments))
    return m.transform(_affine(_perp_frame(d), np.asarray(origin, float) + s0 * d))


def box(center, R, size) -> mf.Manifold:
    """A box of full edge lengths ``size`` with centre ``center`` and orientation ``R``."""
    c = mf.Manifold.cube([float(s) for s in size], True)
    return c.transform(_affine(R, center))


def union(items) -> mf.Manifold:
    items = [m for m in items if not m.is_empty()]
    if not items:
        return mf.Manifold()
    return mf.Manifold.batch_boolean(items, mf.OpType.Add) if len(items) > 1 else items[0]


def subtract(a, items) -> mf.Manifold:
    items = [m for m in items if not m.is_empty()]
    if not items or a.is_empty():
        return a
    return mf.Manifold.batch_boolean([a] + items, mf.OpType.Subtract)


# --------------------------------------------------------------------------- data
@dataclass
class SlabBox:
    center: np.ndarray   # world, mm (rest)
    R: np.ndarray        # world orientation of the box axes
    size: np.ndarray     # mm, thickness already replaced
    normal_axis: int     # index of the thickness axis
    offset: float = 0.0  # mm along the normal from the scene's mid-plane (_offset_slabs)
    off_layer: bool = False  # a yoke plate in its joint's plane, off its slab's layer (_yoke_plates)


@dataclass
class HingeAxis:
    name: str                 # joint names joined by "+"
    joints: list
    origin: np.ndarray        # mm, world rest: the span's midpoint
    direction: np.ndarray     # unit
    span: float               # mm, knuckle span along the axis
    bodies: list              # body names; bodies[0] owns the pin
    intervals: dict           # body -> list of (s0, s1) knuckle intervals (s from origin)
    knuckle: float            # knuckle length
    R: float                  # knuckle radius
    r_pin: float
    r_hole: float
    rho: float = 0.0          # trim radius around other bodies' knuckles
    layout: list = field(default_factory=list)   # body of each knuckle, in axis order
    scene_span: float = 0.0   # mm, span given by the scene (distance of the bond ends)
    joint: str | None = None  # compound junction: the universal joint part that holds this axis's pin
    joint_iv: tuple = ()      # ... and its knuckle in the stack (s0, s1)

    @property
    def owner(self) -> str:
        return self.bodies[0]

    @property
    def pin_owner(self) -> str:
        """The part whose pin runs through the stack: the first body, or the joint part of a
        compound junction."""
        return self.joint or self.bodies[0]


@dataclass
class YokeLayout:
    """One axis of a universal joint: intervals along the axis (mm from the joint point)."""

    mode: str                 # "both" (knuckles on both sides of the hub) or "+"/"-" (one side, capped)
    own: list                 # the body's knuckles
    caps: list                # the joint part's end caps (one-sided yokes)
    pin: tuple                # extent of the joint part's pin
    cut: tuple                # range where the body is trimmed away from the axis (except its knuckles)
    plate: tuple = (0.0, 0.0)  # range of the yoke plate joining the knuckles to the slab
    reach: float | None = None  # compound junction ("host"): how far the hub reaches along the axis
    holes: list | None = None  # branch junction: the body's pin holes, (s0, s1, radius)
    r_own: float | None = None  # branch junction: radius of the body's knuckle
    head: list = field(default_factory=list)  # the joint pin's head, (s0, s1, radius) (none so far)
    bridge: tuple = ()        # branch junction, outermost page: a plate over the cap, (s0, s1) along the pin

    @property
    def extent(self) -> float:
        if self.reach is not None:
            return self.reach
        return max(abs(x) for iv in self.own + self.caps for x in iv)


@dataclass
class UJoint:
    name: str                 # joint name in the scene
    part: str                 # name of the joint part
    center: np.ndarray        # mm
    bodies: tuple             # (C, O)
    axes: tuple               # (u, v): unit, u fixed in C, v fixed in O (rest world)
    layouts: tuple            # (YokeLayout of C along u, YokeLayout of O along v)
    hub: float                # hub length (both axes)
    R: float
    r_pin: float
    r_hole: float
    rho: tuple                # trim radius of C around u and of O around v
    host: HingeAxis | None = None  # compound junction: C's hinge axis that carries the hub (u on its line)
    hub_r: float = 0.0        # compound junction: radius of the ball hub and of its collar
    collar: float = 0.0       # compound junction: the collar runs from -collar to 0 along u (mm)
    fin: float = 0.0          # compound junction: O's yoke fin runs from 0 to fin along u (0: a plain plate)
    o_axis: HingeAxis | None = None  # compound junction: O's own hinge on the same line (re-laid), if any
    primary: bool = True      # branch junction: False for every page but the first (the part is the first's)
    mates: list = field(default_factory=list)  # branch junction: the other pages on the same joint part
    free_pin: bool = False    # O's hinges run along u, so _PinClearance chose v: its yoke plate into a
                              # rod stops over the knuckles (_yoke_plates' rod_reach)
    turned: bool = False      # compound junction: v turned about u by least_twist
    rod_wall: float | None = None  # (ROD_PLATE_CLEAR) how far (mm) the plate into a rod reaches, where
                                   # the full ROD_PLATE_WALL reach would come near another body


@dataclass
class Part:
    name: str
    kind: str                 # "body" | "joint"
    solid: mf.Manifold        # world rest frame, mm
    partners: list = field(default_factory=list)   # names of parts it is jointed to


@dataclass
class Assembly:
    scene: Scene
    profile: Profile
    parts: list
    axes: list
    ujoints: list
    notes: list
    features: list            # (what, value_mm, minimum_mm)
    slab_thickness: float
    poses: dict | None = None  # state -> (pos (N,3), quat (N,4)) in sigma, as given to build()
    orient: np.ndarray = field(default_factory=lambda: np.eye(4))  # world -> print frame (mm)
    congruence: Congruence | None = None   # shape keys and cached exact results (large assemblies)
    # large assemblies: each part's joint material (knuckles less their holes, pins, rings): a
    # subset of the finished part (no trim takes from it), for the retention check's first test
    cores: dict = field(default_factory=dict)
    cone_conflicts: list = field(default_factory=list)   # pin: cone: [(part, part, state or None)]
    axis_cores: dict = field(default_factory=dict)   # compound junction's joint part: its stack knuckle and pin
    # the motion trims (_clear_motion): {"part", "clear_of", "poses" (dense pose names where the
    # pair was closer than the clearance before the trim), "removed_mm3", "settled"}
    motion_trims: list = field(default_factory=list)
    # orient: auto_config (mlc.mesh.configs): the configuration printed, {part: 4x4 rest -> posed
    # (mm, model frame)}; empty: the rest configuration.  The print frame of a part is
    # orient @ print_pose[part] (print_T)
    print_pose: dict = field(default_factory=dict)
    print_config: dict = field(default_factory=dict)   # {input lever hinge: degrees from rest} printed
    # print-only feet (mlc.mesh.feet): {part: volume added, mm^3}; empty: none
    feet: dict = field(default_factory=dict)
    feet_free: dict = field(default_factory=dict)    # {part: its solid before the feet} (measurements)
    # attachment holes drilled inside slabs: (part, centre mm, axis, "round" or "teardrop"), rest frame
    holes: list = field(default_factory=list)

    def print_T(self, name: str) -> np.ndarray:
        """Model rest frame -> print frame (4x4, mm) of part ``name``: its configuration, then
        the orientation on the bed."""
        P = self.print_pose.get(name)
        return self.orient if P is None else self.orient @ P

    def part(self, name: str) -> Part:
        for p in self.parts:
            if p.name == name:
                return p
        raise KeyError(name)

    def body_transform(self, body_index: int, pos, quat) -> np.ndarray:
        """4x4 transform (mm) taking the rest pose of a body to the pose (pos, quat) in sigma."""
        return _body_T(self.scene.bodies[body_index], pos, quat, self.profile.sigma_mm)

    def part_transforms(self, pos, quat, body_T: dict | None = None) -> dict:
        """Rest -> posed 4x4 transforms (mm) of every part for body poses (pos, quat);
        ``body_T``: the bodies' transforms for these poses when already computed
        (:func:`_state_transforms`)."""
        idx = {b.name: i for i, b in enumerate(self.scene.bodies)}
        out = {}
        for p in self.parts:
            if p.kind == "body":
                i = idx[p.name]
                out[p.name] = body_T[p.name] if body_T is not None else self.body_transform(i, pos[i], quat[i])
        for u in self.ujoints:
            if not u.primary:       # branch junction: the shared joint part is posed by its first page
                continue
            Tc = out[u.bodies[0]]
            To = out[u.bodies[1]]
            uu = Tc[:3, :3] @ u.axes[0]
            vv = To[:3, :3] @ u.axes[1]
            if SPLIT_TWIST and u.host is not None:
                # compound junction (circuit chains): the twist is shared by the two pins
                F1 = _split_twist(uu, vv, max(abs(x) for x in u.layouts[0].pin), max(abs(x) for x in u.layouts[1].pin))
            else:
                F1 = _ortho(uu, vv)
            F0 = _ortho(u.axes[0], u.axes[1])
            # the hub sits where the two bodies' copies of the joint point are (their mean)
            c = 0.5 * (Tc[:3, :3] @ u.center + Tc[:3, 3] + To[:3, :3] @ u.center + To[:3, 3])
            T = np.eye(4)
            T[:3, :3] = F1 @ F0.T
            T[:3, 3] = c - T[:3, :3] @ u.center
            out[u.part] = T
        return out


def _ortho(u, v) -> np.ndarray:
    u = u / np.linalg.norm(u)
    v = v - np.dot(v, u) * u
    v = v / np.linalg.norm(v)
    return np.column_stack([u, v, np.cross(u, v)])


def _split_twist(uu, vv, Lu, Lv) -> np.ndarray:
    """The posed frame (u, v, u x v) of a universal joint part whose two bodies hold its pins
    along ``uu`` and ``vv`` (unit), when these are not square: the scene's universal joint is
    a ball joint, and a circuit chain's statics twist its junctions by up to about 13 degrees
    (session 49), which a printed cardan cannot follow.  The part floats in the clearance of its
    holes, so it is posed where both pins fit best: the twist (90 degrees less the angle between
    ``uu`` and ``vv``) is shared between the two pins in inverse proportion to their reach into
    their bodies' holes (``Lu``, ``Lv``, mm from the joint point), so that both pin ends move
    sideways in their holes by the same distance.  :func:`_ortho` kept ``uu`` and turned the
    other pin by the whole twist: its ends met the walls of their holes from 4.8 degrees on
    (0.2 mm of clearance over 2.4 mm of pin), where sharing takes 7.6 degrees."""
    uu = uu / np.linalg.norm(uu)
    e2 = vv - np.dot(vv, uu) * uu
    n2 = float(np.linalg.norm(e2))
    if n2 < 1e-12:
        return _ortho(uu, vv)
    e2 /= n2
    alpha = float(np.arctan2(n2, np.dot(vv, uu)))       # the angle between the pins
    tw = 0.5 * np.pi - alpha
    du = tw * Lv / (Lu + Lv) if Lu + Lv > 0 else 0.5 * tw
    dv = tw - du
    u = np.cos(du) * uu - np.sin(du) * e2
    v = np.cos(alpha + dv) * uu + np.sin(alpha + dv) * e2
    return np.column_stack([u, v, np.cross(u, v)])


def transform_solid(solid: mf.Manifold, T) -> mf.Manifold:
    return solid.transform(np.asarray(T, float)[:3, :4])


def reuses(scene: Scene) -> bool:
    """Whether :func:`build_assembly` reuses results across congruent parts by default: an
    assembly of at least :data:`REUSE_MIN_PARTS` parts (bodies and universal-joint parts)."""
    n_uj = sum(1 for bonds in scene.joints().values() if bonds[0].kind == "universal")
    return len(scene.bodies) + n_uj >= REUSE_MIN_PARTS


# --------------------------------------------------------------------------- build
def build_assembly(scene: Scene, profile: Profile, poses: dict | None = None,
                   resolve: bool = True, reuse: bool | None = None,
                   motion_poses: dict | None = None) -> Assembly:
    """Build the printable parts of ``scene`` (rest pose) for ``profile``.

    ``poses`` maps logic states to body poses ``(pos, quat)`` (sigma); hinge trim radii
    are chosen so that slabs clear each other in every one of them.  ``reuse``: test and trim
    each pair of congruent parts once per relative pose (:mod:`mlc.mesh.congruence`); by
    default on for assemblies of at least :data:`REUSE_MIN_PARTS` parts (compiled circuits),
    off for the library gates, whose meshes stay exactly as they were.

    ``motion_poses`` (``{name: (pos, quat)}``, sigma: the dense paths and switches of
    :func:`mlc.mesh.pipeline.state_poses` with ``max_move``): after the trims of the logic states,
    slabs that come closer than the clearance in any of these poses are trimmed too
    (:func:`_clear_motion`), as ``mlc stl`` does for a mechanism of fewer than
    :data:`REUSE_MIN_PARTS` parts; then the parts that move in one plane (a gate's lever loop) get
    print-only feet down to the bed, clear of the other parts in these poses
    (:func:`mlc.mesh.feet.add_feet`)."""
    untwist: set = set()
    try:
        while True:
            try:
                return _build_assembly(scene, profile, poses, resolve, reuse, motion_poses, untwist)
            except _Untwist as e:
                # a compound junction's turned pin left its other body in pieces: built again,
                # those joints' pins chosen among the ones that leave it whole (session 52, below)
                _log(f"universal joints {', '.join(sorted(map(str, e.joints)))}: the turned pin (or a "
                     "grown stack) cut the other body in pieces, or a knuckle met another joint's plate; built again")
                untwist |= e.joints
    finally:
        _LOCAL[0] = None     # primitives are built in the world again, whatever happened


class _Untwist(Exception):
    """Raised by :func:`_build_assembly` when the turned second pin (``least_twist``) of compound
    junctions left their other bodies in several pieces (the trim about the pin, with the yoke
    plates a fin across the slab: the robot's wrist slabs ``rc_u4_dn_w0_AB``/``_CD``, whose
    junctions' pins the one-sided yoke of the pair's other joint turned 40 degrees out of the
    slab, session 52); :func:`build_assembly` builds again, those ``joints`` turned only to pins
    that leave their other body whole (``least_twist``'s ``severs``; else as laid out)."""

    def __init__(self, joints: set):
        super().__init__(", ".join(sorted(map(str, joints))))
        self.joints = set(joints)


def _build_assembly(scene, profile, poses, resolve, reuse, motion_poses=None, untwist=frozenset()) -> Assembly:
    prof = profile
    _LOCAL[0] = None
    s = prof.sigma_mm
    n = prof.circular_segments
    c = prof.clearance
    g = prof.knuckle_gap
    notes: list[str] = []
    features: list = []
    bodies = {b.name: b for b in scene.bodies}

    # -- slab thickness: the profile decides -----------------------------------
    scene_t = min(float(np.min(bx.size)) for b in scene.bodies for bx in b.boxes) * s
    t = max(prof.slab_thickness, scene_t)
    if scene_t < prof.min_wall:
        notes.append(
            f"slab thickness: the scene's slabs are {scene_t:.3g} mm ({scene_t / s:.3g} sigma; the paper printed "
            f"{PAPER_SLAB_MM} mm), below this profile's minimum wall {prof.min_wall:g} mm: printed at {t:g} mm "
            f"(profile slab_thickness)")
    features.append(("slab thickness", t, prof.min_wall))

    # -- slab boxes in world (mm) ----------------------------------------------
    slabs: dict[str, list[SlabBox]] = {}
    for b in scene.bodies:
        Rb = quat_to_matrix(b.orientation)
        lst = []
        for bx in b.boxes:
            R = Rb @ quat_to_matrix(bx.orientation)
            size = np.asarray(bx.size, float) * s
            k = int(np.argmin(size))
            size[k] = max(size[k], t)
            if ROD_WALL:
                # a rod (a post carrying a joint site, a branch page's arm) has a second thin side:
                # printed at least as thick as the slab too (POST_WIDTH 0.08 sigma is 0.4 mm at mjp)
                j = [i for i in np.argsort(size) if i != k][0]
                if size[j] < t:
                    size[j] = t
            lst.append(SlabBox(s * (np.asarray(b.position, float) + Rb @ np.asarray(bx.center, float)), R, size, k))
        slabs[b.name] = lst

    r_pin = max(prof.pin_diameter, prof.min_feature) / 2
    r_hole = r_pin + c
    R = r_hole + prof.min_wall
    R = max(R, t / 2 + prof.min_wall / 2)
    # a knuckle's length is a wall of the ring: at least the minimum wall as well as the
    # minimum feature (mjp's 0.5 mm knuckles measured 0.37 mm walls against 0.6, issue 13).
    # Until session 57 only in a mechanism of its own: compiled circuits kept minimum-feature
    # knuckles, because stacks lengthened on both sides met the next half unit or a branch's
    # pages in every state.  A compound junction's stack now grows on its far side only, where
    # no other stack comes near in any pose (``far_ok`` below, :func:`_compound`)
    kmin = max(prof.min_feature, prof.min_wall)
    cones = prof.pin == "cone"
    r_cone = h_cone = 0.0
    if cones:
        # 45 degree cone pins: a cone on one knuckle in a conical recess of the next; the
        # recess is the cone offset by the clearance (its apex moves by c*sqrt(2))
        r_cone = max(prof.min_feature / 2 + g + c, r_pin)
        # truncated where its diameter is min_feature (the tip beyond is thinner than the
        # printer's smallest feature): a flat top h_cone above the face, still 45 degrees; the
        # recess is short by as much, and so are the knuckles that hold it (issue 14)
        h_cone = r_cone - prof.min_feature / 2
        R = max(R, r_cone + c * np.sqrt(2) + prof.min_wall)
        features.append(("cone pin diameter", 2 * r_cone, prof.min_feature))
        features.append(("knuckle wall around a cone recess", R - r_cone - c * np.sqrt(2), prof.min_wall))
    else:
        features.append(("pin diameter", 2 * r_pin, prof.min_feature))
        features.append(("knuckle wall", R - r_hole, prof.min_wall))

    # -- group hinge joints by axis ------------------------------------------
    joints = scene.joints()
    lines = []  # (p, d, [joint names], set(bodies), ends (sigma))
    for jname, bonds in joints.items():
        kind = bonds[0].kind
        if kind != "hinge":
            continue
        if len(bonds) != 2:
            raise MlcError(f"hinge {jname} has {len(bonds)} bonds; a printable hinge needs two (its axis ends)",
                           bonds[0].loc or scene.source or scene.name)
        ends = [0.5 * (scene.site_world(bd.a) + scene.site_world(bd.b)) for bd in bonds]
        d = ends[1] - ends[0]
        L = float(np.linalg.norm(d))
        if L < _TOL:
            raise MlcError(f"hinge {jname}: its two bonds are at the same point, so it has no axis",
                           bonds[0].loc or scene.source or scene.name, "place the bonds at the two ends of the axis")
        d = d / L
        pair = {bd.a.split(".")[0] for bd in bonds} | {bd.b.split(".")[0] for bd in bonds}
        for ln in lines:
            p, dd = ln[0], ln[1]
            if abs(abs(np.dot(d, dd)) - 1) < 1e-6 and np.linalg.norm(np.cross(ends[0] - p, dd)) < _TOL:
                # one line, but one hinge only where the spans meet: the hinges of stacked
                # layers (connector half units) lie on one line at different places along it
                mine = sorted(float(np.dot(e - p, dd)) for e in ends)
                theirs = [float(np.dot(e - p, dd)) for e in ln[4]]
                if mine[0] > max(theirs) + _TOL or mine[1] < min(theirs) - _TOL:
                    continue
                ln[2].append(jname)
                for bn in sorted(pair):
                    if bn not in ln[3]:
                        ln[3].append(bn)
                ln[4].extend(ends)
                break
        else:
            order = []
            for bd in bonds:
                for ref in (bd.a, bd.b):
                    bn = ref.split(".")[0]
                    if bn not in order:
                        order.append(bn)
            lines.append([ends[0], d, [jname], order, list(ends)])

    axes: list[HingeAxis] = []
    for p, d, jn, blist, ends in lines:
        proj = [float(np.dot(e - p, d)) for e in ends]
        lo, hi = min(proj), max(proj)
        mid = p + d * 0.5 * (lo + hi)
        L = (hi - lo) * s
        nk = len(blist) + (1 if len(blist) >= 2 else 0)
        S = max(L, nk * kmin + (nk - 1) * g)
        k = (S - (nk - 1) * g) / nk
        layout = [blist[0]] + blist[1:] + [blist[0]]
        if cones:
            # the recess of a cone (h_cone + c deep from the face below) must leave a wall at
            # the far end of its knuckle
            k_need = h_cone + c - g + prof.min_wall
            if k < k_need:
                S = nk * k_need + (nk - 1) * g
                k = k_need
        intervals: dict[str, list] = {bn: [] for bn in blist}
        for i, bn in enumerate(layout):
            a0 = -S / 2 + i * (k + g)
            intervals[bn].append((a0, a0 + k))
        ax = HingeAxis("+".join(jn), jn, mid * s, d, S, list(blist), intervals, k, R, r_pin, r_hole,
                       scene_span=L, layout=list(layout))
        axes.append(ax)
        features.append((f"knuckle length ({ax.name})", k, kmin))
        if S > L + 1e-9:
            notes.append(f"hinge {ax.name}: knuckles need {S:.3g} mm, more than the slab width {L:.3g} mm: "
                         f"the slabs are widened to the knuckle span there")

    state_T = _state_transforms(scene, prof, poses)

    grown: dict = {}      # id(axis) -> joint: compound stacks grown to the minimum wall (far side)
    grown_far: dict = {}  # id(axis) -> the stretch it grew into (mm from its origin; _compound's "far")
    posed_mid: list = []  # every hinge's midpoint in every pose, made on first use (_far_clear)

    def far_ok(ax, side, a0, a1):
        return _far_clear(ax, side, a0, a1, axes, slabs, state_T, t, c, posed_mid,
                          kmin=None if cones else kmin, g=g, notes=notes)

    if reuse is None:
        reuse = reuses(scene)
    memo: dict | None = {} if reuse else None      # sampled trim radii of congruent joints
    h = _sample_step(t, c, s)

    # -- universal joints: a hub with two crossed pins; each body a yoke --------------
    #    (both sides of the hub, or one side with a cap on the pin when the other body's
    #    arm passes the other side); the layout with the smallest trim radii wins
    ujoints: list[UJoint] = []
    reach = R + c + 2 * R + 0.25 * s
    base_samples = {bn: _slab_samples(slabs[bn], h) for bn in slabs}
    # branch junctions: several universal joints at one point of one body (a fan-out: the
    # pages of a connector branch on its source half unit) share one joint part
    groups = _branch_groups(joints, scene)
    done: set = set()
    pin_clear = _PinClearance(base_samples, state_T, R, c, t, reach)
    pin_clear.joint_points = [0.5 * (scene.site_world(b[0].a) + scene.site_world(b[0].b)) * s
                              for b in joints.values() if b[0].kind == "universal"]
    if PIN_TWIST:
        pin_clear.pending = _pending_yokes(joints, groups, scene, axes, slabs, s, g)
    for jname, bonds in joints.items():
        if bonds[0].kind != "universal" or jname in done:
            continue
        if jname in groups:
            S, members = groups[jname]
            made = _branch(members, S, joints, scene, bodies, axes, slabs, s, prof, R, r_pin, r_hole, kmin, t,
                           base_samples, reach, memo, state_T, h, notes,
                           far_ok if GROW_STACKS and ("short", jname) not in untwist else _never)
            if made is not None:
                br_uj, comp = made
                ujoints += br_uj
                done.update(members)
                hx = comp["axis"]
                hx.span, hx.knuckle, hx.intervals = comp["span"], comp["k"], comp["intervals"]
                hx.origin = comp["origin"]
                if comp["grown"]:
                    grown[id(hx)] = jname
                    grown_far[id(hx)] = comp["far"]
                hx.layout = [x if x is not None else br_uj[0].part for x in comp["stack"]]
                hx.joint, hx.joint_iv = br_uj[0].part, comp["joint_iv"]
                if comp["o_axis"] is not None:
                    _own_ends(comp["o_axis"], comp["o_body"])
                for u_ in br_uj:      # a page's arm runs along its own hinge's line to the joint point
                    for ax_ in axes:
                        if u_.bodies[1] in ax_.bodies:
                            _own_lines(u_.bodies[1], u_.center, ax_.direction, [ax_], s)
                features.append((f"knuckle length ({hx.name}, with joint {br_uj[0].part})", hx.knuckle,
                                 prof.min_feature))
                features.append((f"hub wall ({br_uj[0].part})", br_uj[0].hub_r - r_pin, prof.min_wall))
                ks = [iv[1] - iv[0] for uj in br_uj for iv in uj.layouts[1].own]
                features.append((f"yoke knuckle length ({br_uj[0].part})", min(ks), kmin))
                notes.append(f"branch junction {br_uj[0].part}: {len(br_uj)} universal joints "
                             f"({', '.join(u.name for u in br_uj)}) on one joint part, compound on hinge {hx.name}")
                continue
            notes.append(f"universal joints {', '.join(members)}: one point of {S}, but no branch junction fits")
            for m in members:
                groups.pop(m, None)
        bd = bonds[0]
        cb, ob = bd.a.split(".")[0], bd.b.split(".")[0]
        center = 0.5 * (scene.site_world(bd.a) + scene.site_world(bd.b)) * s
        # compound junction: the joint point lies on the line of a hinge of one body, past the
        # end of its knuckles (connector chains): the hub's first pin IS that hinge's pin
        # Its stack grows to knuckles of the minimum wall on its far side only (:func:`_compound`):
        # stacks lengthened on both sides met the next half unit in every logic state
        # (chain_scene(1) at mjp: 12 conflicting pairs, trims that did not settle and one boolean
        # of 20 GB, where there were none)
        compound = None
        kc = kmin
        for side_b, other_b in ((cb, ob), (ob, cb)):
            hx = _host_axis(side_b, axes, center, s, g)
            if hx is not None:
                compound = _compound(hx, center, side_b, other_b, axes, s, prof, R, r_pin, kc,
                                     far_ok=far_ok if GROW_STACKS and ("short", jname) not in untwist else _never)
                if compound is not None:
                    cb, ob = side_b, other_b
                    break
                notes.append(f"universal joint {jname}: no room for a compound junction on hinge {hx.name}")
        u = _hinge_dir(cb, axes, slabs, center) if compound is None else compound["u"]
        v, parallel = _second_pin(u, ob, axes, slabs, center)
        # ... and the joint hangs on a post, farther than ``reach`` from every hinge of O's (a
        # chain's junction is nearer its next half unit's hinges, whose trims settle it)
        free_v = parallel and all(_axis_distance(center, ax) > reach for ax in axes if ob in ax.bodies)
        hub = 2 * (R + c)
        ky = max(kmin, R)
        radii = (compound["hub_v"] if compound is not None else hub) / 2 + g + ky * np.array([0.0, 0.5, 1.0])
        if free_v:      # no hinge of its own gives the second pin: the one whose yoke stays clear
            v = pin_clear.choose(center, u, v, cb, ob, radii)
        # the yoke's span from the body's extent along the pin chosen so far: a compound
        # junction's second pin turned below keeps its knuckles where they were along it
        W = (_extent_along(slabs[cb], center, u), _extent_along(slabs[ob], center, v))
        cap = max(kmin, prof.min_wall)
        o_mode, cap_r = "both", radii[-1] + g + cap      # cap_r: a one-sided yoke's cap end (mm)
        v_laid = v
        part_name = jname if jname not in bodies else f"joint_{jname}"

        def make_uj(v_, lays, hub_):
            uj_ = UJoint(jname, part_name, center, (cb, ob), (u, v_), lays, hub_, R, r_pin, r_hole,
                         (float(np.hypot(lays[1].extent, R)) + c, float(np.hypot(lays[0].extent, R)) + c))
            uj_.free_pin = free_v
            uj_.turned = v_ is not v_laid
            if compound is not None:
                uj_.host, uj_.hub_r, uj_.collar = compound["axis"], compound["hub_r"], compound["collar"]
                if np.isfinite(compound["dO"]):
                    uj_.fin = compound["dO"] + t
                    uj_.o_axis = compound["o_axis"]
            return uj_
        if compound is not None and PIN_TWIST:
            # (ONE_SIDED_TWIST) or a one-sided yoke on the turned pin, its pin capped, where a yoke
            # on both sides would meet the pair's other joint or a slab.  Built again after its turned pin
            # left O in pieces (_Untwist): only a pin whose trim leaves O's slabs, yoke plates and
            # knuckles whole (:func:`_severs`; a model of the body, more cautious than the build,
            # so not asked first: asked of every pin, it refused pins at 13 other junctions of the
            # robot's couplings whose bodies the build keeps whole, their hinges' plates holding
            # them together, and 72 more intersections followed in the states check)
            def sev(pin, mode):
                uj_ = make_uj(pin, (compound["layout_c"], _compound_yoke_layout(
                    mode, compound["hub_v"], g, ky, cap, W[1], s)), compound["hub_v"])
                return _severs(uj_, slabs[ob], reach, t, n)
            sv = sev if jname in untwist else None
            if ONE_SIDED_TWIST:
                v, o_mode = pin_clear.least_twist(center, u, v, cb, ob, radii, jname, cap_r=cap_r, severs=sv)
            else:
                v = pin_clear.least_twist(center, u, v, cb, ob, radii, jname, severs=sv)
            if jname in untwist:
                notes.append(f"universal joint {jname}: its turned pin cut {ob} in pieces; "
                             + ("pin as laid out" if v is v_laid else "turned less"))
        forced = next((m for m in "+-" if ("side", jname, m) in untwist), None)
        if compound is not None and forced is not None:
            o_mode = forced
            notes.append(f"universal joint {jname}: one-sided yoke ({forced}) on {ob}, its knuckle on the other "
                         "side met another joint's yoke plate in a pose")
        pin_clear.add(ob, center, v, radii, jname,
                      r=None if o_mode == "both" else (1 if o_mode == "+" else -1) * np.r_[radii, cap_r])
        best = None
        mode_list = (("both", "both"), ("+", "both"), ("-", "both"), ("both", "+"), ("both", "-"))
        if compound is not None:
            mode_list = (("host", o_mode),)
            hub = compound["hub_v"]
        for modes in mode_list:
            if compound is not None:
                lays = (compound["layout_c"], _compound_yoke_layout(modes[1], hub, g, ky, cap, W[1], s,
                                                                    turned=TURNED_FREE_SIDE and v is not v_laid))
            else:
                lays = tuple(_yoke_layout(m, hub, g, ky, cap, W[i], s) for i, m in enumerate(modes))
            uj = make_uj(v, lays, hub)
            if best is not None and not (uj.rho[0] + uj.rho[1], modes != ("both", "both")) < best[0]:
                continue     # its trim radii are at least these: it cannot beat the best layout
            need = _ujoint_trim_memo(memo, uj, _uj_samples(uj, base_samples, slabs, reach, t, h, n), state_T, t, c, h)
            rho = (max(uj.rho[0], need[0]), max(uj.rho[1], need[1]))
            score = (rho[0] + rho[1], modes != ("both", "both"))
            if best is None or score < best[0]:
                uj.rho = rho
                best = (score, uj)
        uj = best[1]
        ujoints.append(uj)
        if FIRST_PIN_CLEAR and compound is None:
            # the first pin's knuckles and caps (on C, along u) for the joints after it too
            lay0 = uj.layouts[0]
            r0 = [x for a0, a1 in lay0.own + lay0.caps for x in (a0, 0.5 * (a0 + a1), a1)]
            if r0:
                pin_clear.add(cb, center, uj.axes[0], radii, r=np.array(r0))
        if compound is not None:
            hx = compound["axis"]
            hx.span, hx.knuckle, hx.intervals = compound["span"], compound["k"], compound["intervals"]
            hx.origin = compound["origin"]
            if compound["grown"]:
                grown[id(hx)] = jname
                grown_far[id(hx)] = compound["far"]
            hx.layout = [x if x is not None else uj.part for x in compound["stack"]]
            hx.joint, hx.joint_iv = uj.part, compound["joint_iv"]
            if compound["o_axis"] is not None:
                _own_ends(compound["o_axis"], ob)
            _own_lines(ob, center, uj.axes[1], axes, s)
            features.append((f"knuckle length ({hx.name}, with joint {jname})", hx.knuckle, prof.min_feature))
            features.append((f"hub wall ({jname})", uj.hub_r - r_pin, prof.min_wall))
            notes.append(f"universal joint {jname}: compound junction on hinge {hx.name} (its pin is the joint's)")
        if uj.layouts[0].mode not in ("both", "host") or uj.layouts[1].mode != "both":
            notes.append(f"universal joint {jname}: one-sided yoke ({uj.layouts[0].mode} on {cb}, "
                         f"{uj.layouts[1].mode} on {ob}) with a capped pin, clear of the other arm")
        ks = [iv[1] - iv[0] for lay in uj.layouts for iv in lay.own + lay.caps]
        features.append((f"yoke knuckle length ({jname})", min(ks), kmin))
        if compound is None:
            features.append((f"hub length ({jname})", hub, prof.min_feature))

    stacks = [ax for ax in axes if ax.joint is not None]
    if stacks and kmin > prof.min_feature + 1e-9:
        short = [ax for ax in stacks if id(ax) not in grown]
        notes.append(f"compound junctions: {len(grown)} of {len(stacks)} stacks with knuckles of the minimum wall "
                     f"{kmin:g} mm (grown on the side away from the joint)"
                     + (f"; {len(short)} with {min(ax.knuckle for ax in short):.3g} mm knuckles, where a longer "
                        "stack would come near another hinge's in some pose or leave a body in pieces" if short else ""))
    if memo is not None:
        _share_ujoint_radii(ujoints, base_samples, slabs)

    # -- which face of each slab the printed thickness grows from: away from the slabs and
    #    knuckles that pass close to it in the logic states and the dense paths (issue 13:
    #    trims that shaved a slab face left walls under the minimum)
    motion_ST = _state_transforms(scene, prof, motion_poses) if (resolve and motion_poses and not reuse) else []
    bridge_T = [T for _, T in state_T + motion_ST] or [None]     # a thin web's bridge keeps clear in these
    if resolve and not reuse and t > scene_t + 1e-9:
        # not the bodies at a universal joint: its trim cylinder then cut the moved slab and
        # its yoke plate into a 0.22 mm lip (out_hi at sla)
        at_uj = {bn for uj in ujoints for bn in uj.bodies}
        moved = _offset_slabs({bn: v for bn, v in slabs.items() if bn not in at_uj}, scene,
                              [T for _, T in state_T + motion_ST], t, scene_t, c, R, h, s,
                              _knuckle_samples(axes, ujoints, R, h), others=slabs)
        for bn, sb, o in moved:
            notes.append(f"slab of {bn} at ({', '.join(f'{x:.1f}' for x in sb.center)}) mm printed from one face "
                         f"of the scene's slab ({o:+.3g} mm along its normal): room for the part passing the "
                         "other side")
        if moved:     # the universal joints' trim radii, again for the slabs where they are now
            base_samples = {bn: _slab_samples(slabs[bn], h) for bn in slabs}
            for uj in ujoints:
                need = _ujoint_trim(uj, _uj_samples(uj, base_samples, slabs, reach, t, h, n), state_T, t, c, h)
                uj.rho = (max(uj.rho[0], need[0]), max(uj.rho[1], need[1]))

    # -- yoke plates: widen slabs to the knuckle span near an axis ------------------
    plates: dict[str, list[SlabBox]] = {b.name: [] for b in scene.bodies}
    for ax in axes:
        if ax.span > ax.scene_span + 1e-9:
            for bn in ax.bodies:
                if GROWN_CLEAR and id(ax) in grown_far:
                    # a grown stack: over the stretch it grew into, plates only as long as its
                    # knuckles need (_grown_plates); over the rest of the span, as before
                    a0, a1 = grown_far[id(ax)]
                    rest = (a1, ax.span / 2) if a0 <= -ax.span / 2 + 1e-9 else (-ax.span / 2, a0)
                    plates[bn] += _yoke_plates(slabs[bn], ax.origin, ax.direction, [rest], reach, t)
                    plates[bn] += _grown_plates(bn, slabs[bn], ax, (a0, a1), reach, t)
                else:
                    plates[bn] += _yoke_plates(slabs[bn], ax.origin, ax.direction, [(-ax.span / 2, ax.span / 2)],
                                               reach, t)
        elif reuse and OFF_SLAB_FINS:
            # an axis across a body's slab, longer than the slab is thick (the robot's skeleton: a
            # hinge normal to the unit plates, 2.5 mm of knuckles on a 1 mm plate): the body's own
            # knuckles that lie wholly off its slab get a fin across it (session 50)
            for bn in ax.bodies:
                if _knuckles_off_slab(slabs[bn], ax, bn, t):
                    plates[bn] += _yoke_plates(slabs[bn], ax.origin, ax.direction, [(-ax.span / 2, ax.span / 2)],
                                               reach, t)
                    notes.append(f"hinge {ax.name}: {bn}'s knuckles lie off its slab: a fin across the slab "
                                 "carries them")
    uj_plates = []      # (body, joint, plate): the universal joints' yoke plates (CLIP_UJ_PLATES)
    for uj in ujoints:
        for side, bn in enumerate(uj.bodies):
            for sb in _uj_plates(uj, side, slabs[bn], uj.rho[side] + reach, t, n):
                plates[bn].append(sb)
                uj_plates.append((bn, uj, sb))
    shapes = {bn: slabs[bn] + plates[bn] for bn in slabs}
    samples = {bn: _slab_samples(shapes[bn], h) for bn in shapes}
    if ROD_PLATE_CLEAR and ROD_PLATE_WALL:
        # a plate into a rod past the trim about its pin by a wall, where that stretch keeps the
        # slab thickness and the clearance from every other body in every pose (session 64)
        def rod_clash(bn, boxes):
            P = _slab_samples(boxes, h)
            return any(len(ii) for B in samples if B != bn
                       for ii, _ in _close_pairs_posed(P, samples[B], [_relative(bn, B, Ts) for Ts in bridge_T],
                                                       t + c + h))
        cut_back = []
        for uj in ujoints:
            bn = uj.bodies[1]
            r = _rod_wall_reach(uj, slabs[bn], uj.rho[1] + reach, t, n, h, lambda boxes, bn=bn: rod_clash(bn, boxes))
            if r is None or r >= _rod_reaches(uj, t, n)[1] - 1e-9:
                continue
            uj.rod_wall = r
            at = [i for i, (b, u, _) in enumerate(uj_plates) if u is uj and b == bn]
            for i, sb in zip(at, _uj_plates(uj, 1, slabs[bn], uj.rho[1] + reach, t, n), strict=True):
                plates[bn][next(k for k, x in enumerate(plates[bn]) if x is uj_plates[i][2])] = sb
                uj_plates[i] = (bn, uj, sb)
            cut_back.append((bn, uj.name, r))
        for bn, jn, r in cut_back:
            notes.append(f"universal joint {jn}: {bn}'s yoke plate into its rod reaches {r:.2f} mm from the pin, "
                         "short of a full wall past the trim about it, clear of the other bodies")
        if cut_back:
            shapes = {bn: slabs[bn] + plates[bn] for bn in slabs}
            samples = {bn: _slab_samples(shapes[bn], h) for bn in shapes}
    if KNUCKLE_PLATES and reuse and state_T:
        hit = _knuckles_at_plates(ujoints, uj_plates, state_T, R + c + t / 2, h)
        hit = {(jn, m) for jn, m in hit if ("side", jn, "+") not in untwist and ("side", jn, "-") not in untwist}
        _log(f"yoke knuckles at other joints' plates: {len(hit)} junction(s) built again one-sided")
        if hit:
            raise _Untwist({("side", jn, m) for jn, m in hit})
    if GROWN_CLEAR and grown:
        # a grown stack's new stretch (its knuckles and the plates widening its bodies' slabs to
        # them) clear of every other body in every pose; else built again with that stack short
        near = _grown_near([ax for ax in axes if id(ax) in grown], grown_far, shapes, axes, ujoints, slabs,
                           state_T, reach, t, c)
        _log(f"grown stacks: {len(near)} of {len(grown)} near another body's material (built again, short)")
        if near:
            raise _Untwist({("short", grown[id(ax)]) for ax in near})

    # -- trim radii: in every logic state, slabs of the bodies at an axis clear each other
    #    outside the radius inside which only the knuckle's own body has material
    for ax in axes:
        ax.rho = _trim_radius_memo(memo, ax, samples, state_T, t, c, h, s, notes, slabs)
    for uj in ujoints:
        # compound junction: the other body's own hinge on the line is re-laid so that body
        # holds the end knuckles; the bodies between them clear its yoke fin (which reaches
        # into the end knuckle) in every turn about the axis
        ox = uj.o_axis
        if ox is not None and uj.fin > 0:
            half = max(abs(x) for x in uj.layouts[1].plate)
            ox.rho = max(ox.rho, float(np.hypot(half, t / 2)) + c)
    if memo is not None:
        _share_hinge_radii(axes, samples, slabs)
    if CLIP_UJ_PLATES and uj_plates:
        # a yoke plate that runs down its body past the end of another hinge of the body stops
        # at that hinge's trim radius (session 55): the trims clear the other bodies only over
        # the hinge's span, and past it the plate met the other body's (a gate's two crossed
        # output levers, each carrying a universal joint with a plain yoke, at their pivot)
        # ... only where, past the span, it comes within the slab thickness and clearance of
        # another body's material past the span too, in a logic state (a gate whose output
        # levers carry no chain, as built before: the plate of its joint d on out_hi meets only
        # out_lo's slab at the span's end, which the hinge's own cuts clear)
        def past(ax, P):
            return P[np.abs(_axis_coords(ax.origin, ax.direction, P)[0]) > ax.span / 2 + 1e-6]

        def clash(bn, ax, cut_sb):
            P = past(ax, _slab_samples([cut_sb], h))
            states = state_T or [("rest", None)]
            return any(len(ii) for B in ax.bodies if B != bn
                       for ii, _ in _close_pairs_posed(P, past(ax, samples[B]),
                                                       [_relative(bn, B, Ts) for _, Ts in states], t + c + h))
        clipped = []
        for k, (bn, uj, sb) in enumerate(uj_plates):
            nb = _clip_at_axes(sb, [ax for ax in axes if bn in ax.bodies and ax is not uj.host],
                               max(uj.R, uj.hub_r) + t, t, lambda ax, cut_sb, bn=bn: clash(bn, ax, cut_sb))
            if nb is not sb:
                plates[bn][next(i for i, x in enumerate(plates[bn]) if x is sb)] = nb
                uj_plates[k] = (bn, uj, nb)
                clipped.append((bn, uj.name, float(sb.size[1] - nb.size[1])))
        if clipped:
            for bn, jn, cut in clipped:
                notes.append(f"universal joint {jn}: {bn}'s yoke plate stops {cut:.2f} mm short, at the trim "
                             "radius of its hinge whose span it ran past")
            shapes = {bn: slabs[bn] + plates[bn] for bn in slabs}
            samples = {bn: _slab_samples(shapes[bn], h) for bn in shapes}

    if CLIP_NEAR_PLATES and reuse and uj_plates:
        # a yoke plate off its slab's layer that comes near another body's material (not the
        # joint's own bodies) as printed stops short of it (session 69: the README robot's skeleton)
        cut_near = _clip_near_plates(uj_plates, samples, state_T, t, c, h)
        for k, nb, cut, other in cut_near:
            bn, uj, sb = uj_plates[k]
            plates[bn][next(i for i, x in enumerate(plates[bn]) if x is sb)] = nb
            uj_plates[k] = (bn, uj, nb)
            notes.append(f"universal joint {uj.name}: {bn}'s yoke plate stops {cut:.2f} mm short, clear of {other}")
        if cut_near:
            shapes = {bn: slabs[bn] + plates[bn] for bn in slabs}
            samples = {bn: _slab_samples(shapes[bn], h) for bn in shapes}

    # -- muscle and probe attachment holes -------------------------------------------
    lug_hole = max(prof.min_feature, 0.08 * s) / 2
    lug_out = lug_hole + prof.min_wall
    lugs: dict[str, list] = {b.name: [] for b in scene.bodies}
    for kind, items in (("muscle", scene.muscles), ("probe", scene.probes)):
        for it in items:
            for ref in (it.a, it.b):
                bn = ref.split(".")[0]
                p = scene.site_world(ref) * s
                if any(np.allclose(p, q[3]) for q in lugs[bn]):
                    continue
                if _near_axis(bn, p, axes, ujoints, R + c + lug_out):
                    notes.append(f"{kind} {it.name}: site {ref} is at a joint; no attachment hole there")
                    continue
                centre, nrm, ring, sb = _attachment(slabs[bn], p, lug_out, t)
                lugs[bn].append((centre, nrm, ring, p, sb, f"{kind} {it.name} ({ref})"))
    if any(lugs.values()):
        features.append(("attachment hole diameter", 2 * lug_hole, prof.min_feature))
        features.append(("attachment hole wall", lug_out - lug_hole, prof.min_wall))

    # -- assemble body solids ----------------------------------------------------------
    parts: list[Part] = []
    cores: dict[str, mf.Manifold] = {}
    protected: dict[str, mf.Manifold] = {}
    soft: dict[str, mf.Manifold] = {}
    fat_guard: dict[str, tuple] = {}     # reuse only: (hard, soft or None) guards grown by GUARD_PAD
    cone_cores: dict[str, mf.Manifold] = {}  # pin: cone: what the trims never touch (knuckles, cones, rings)
    pages = {uj.bodies[1] for uj in ujoints if uj.layouts[1].holes is not None}   # branch junctions' pages
    split_by: set = set()      # turned junctions whose other body came out in pieces (_Untwist)
    fin_free = {id(uj) for uj in ujoints if FIN_KEPT and _fin_free(uj, state_T, c, t)}
    for b in scene.bodies:
        bn = b.name
        # large assemblies: every primitive and boolean of the body in its own frame (its first
        # slab's), the results moved back at the end: congruent bodies come out as the same mesh
        # moved (the same triangles wherever they are) and share every cached exact result
        Fb = _frame(slabs[bn][0].center, slabs[bn][0].R) if reuse and LOCAL_BUILD and slabs.get(bn) else None
        _LOCAL[0] = None if Fb is None else np.linalg.inv(Fb)
        my_axes = [ax for ax in axes if bn in ax.bodies]
        # trims that would leave the body in several pieces (a connector half unit whose slab
        # the trim radii of its hinge and universal joint eat, issue 13, session 50): rebuilt
        # with those radii shrunk towards the least that keeps the knuckles clear (_Unsplit)
        my_uj = [(uj, 0 if uj.bodies[0] == bn else 1) for uj in ujoints if bn in uj.bodies]
        rims = _rim_chamfers(bn, my_axes, my_uj, ujoints, min(RIM_CHAMFER * c, RIM_CAP * prof.min_wall / 2)) \
            if RIM_CHAMFER else {}
        n_notes, shrink = len(notes), _Unsplit(reuse, joints=bool(my_uj))
        # a branch page's arm, which ends on the face of its own end knuckle, is carried into it
        links = _rod_links(shapes[bn], my_axes, bn, t, s) if bn in pages else []
        solid0 = union([box(sb.center, sb.R, sb.size) for sb in shapes[bn] + links] + _bend_fills(slabs[bn]))
        # (a mechanism of its own: a cut that ends at the span's end runs on past what is left of
        # the body along the axis when that would be thinner than the minimum wall; issue 13:
        # out_hi's yoke plate, 0.19 mm past the pivot's cut at sla)
        sheet = {ax.name: (None if reuse else _ext_ivs(shapes[bn], ax), prof.min_wall) for ax in my_axes}
        while True:     # once, or again at the next trim-radius fraction (_Unsplit)
            del notes[n_notes:]
            f, f_ax = shrink.f, shrink.f_axes
            solid = solid0
            # 1. clear the other bodies' knuckles

            def axis_cuts(ax, grow=0.0):
                return [cylinder(ax.origin, ax.direction, a0, a1, _toward(ax.R + c, ax.rho, f_ax) + grow, n, cutter=True)
                        for a0, a1 in _ext(_complement(ax.intervals[bn], -ax.span / 2, ax.span / 2), ax.span, t,
                                           *sheet[ax.name])]
            other_cuts, avoid, avoid_sweep = [], [], []
            for uj, side in my_uj:
                lay = uj.layouts[side]
                # the radius the joint's hub and the other body's yoke knuckles sweep about this axis:
                # the rest of uj.rho is for the other body's slabs in the logic states (_ujoint_trim)
                sweep = float(np.hypot(uj.layouts[1 - side].extent, uj.R)) + c
                rho_s = _toward(sweep, uj.rho[side], f)
                # (built here: in a large assembly the primitives are in the body's frame)
                keep = _fin_keep(uj, c, t, n) if side == 1 and id(uj) in fin_free else None
                for a0, a1 in _complement(lay.own, *lay.cut):
                    cyl_cut = cylinder(uj.center, uj.axes[side], a0, a1, rho_s, n, cutter=True)
                    other_cuts.append(cyl_cut if keep is None else subtract(cyl_cut, [keep]))
                    avoid.append((uj.center, uj.axes[side], a0, a1, rho_s))
                    avoid_sweep.append((uj.center, uj.axes[side], a0, a1, min(sweep, rho_s)))
            for uj in ujoints:      # compound junction: the other bodies of its hinge clear the yoke too
                if uj.host is not None and bn in uj.host.bodies and bn not in uj.bodies:
                    rho_h = _toward(float(np.hypot(uj.layouts[1].extent, uj.R)) + c, uj.rho[0], f)
                    h0, h1 = _host_cut(uj, bn, c)
                    other_cuts.append(cylinder(uj.center, uj.axes[0], h0, h1, rho_h, n, cutter=True))
                    avoid.append((uj.center, uj.axes[0], h0, h1, rho_h))
            cuts = [x for ax in my_axes for x in axis_cuts(ax)] + other_cuts
            cut_solid = _clean(subtract(solid, cuts))
            base_n = len(_clean(solid).decompose())
            cut_n = len(cut_solid.decompose())
            # a slab running along an axis is severed by the clearance around another body's
            # knuckle: bridge around it on the side no other body ever swings through.  For a
            # mechanism of its own (not reuse), also where that clearance and another trim leave
            # only a web thinner than the minimum wall (the cut grown by the minimum wall severs it:
            # core_cd between hinge c and its universal joint, 0.22 mm at mjp, issue 13)
            # The split alone misses a web that is not the body's only link (issue 13, session 37:
            # core_cd of the expanding OR at mjp, a 0.547 mm web between hinge c's trim and the
            # joint's, the body held on by its other slabs as well): the web is also measured, on
            # sections of the cut body across the other knuckles (:func:`_web_thinner`)
            def thin_at(ax):
                if len(_clean(subtract(
                        solid, [x for a in my_axes for x in axis_cuts(a, prof.min_wall if a is ax else 0.0)]
                        + other_cuts)).decompose()) > cut_n:
                    return True
                return _web_thinner(_clean(subtract(solid, cuts)), ax, bn, prof.min_wall)
            need = {}
            for ax in my_axes:
                if cut_n > base_n and len(_clean(subtract(solid, axis_cuts(ax))).decompose()) > base_n:
                    need[ax.name] = "severed"
                elif (not reuse or (WEB_BRIDGES and len(ax.bodies) == 3)) and thin_at(ax):
                    # (compiled circuits: the three-body hinges only, a gate's hinge c; a chain's
                    # two-body hinges bridged this way met the next chain's half unit in the logic
                    # states: tests/test_mesh_bent_ends.py's leaf piece, session 58)
                    # first the plates at the axis, carried along it as far as the body's slabs go
                    # (a slab beside the knuckle stack joins it there, clear of the other knuckles)
                    ext = _axis_extension(slabs[bn], ax, reach, t)
                    if ext:
                        solid = _clean(union([solid] + [box(sb.center, sb.R, sb.size) for sb in ext]))
                        base_n = len(solid.decompose())
                        cut_solid = _clean(subtract(solid, cuts))
                        cut_n = len(cut_solid.decompose())
                        notes.append(f"hinge {ax.name}: {bn}'s plate at the axis carried along it past the knuckles "
                                     f"({', '.join(f'{a0:.2f} to {a1:.2f}' for a0, a1 in _ext_ivs(slabs[bn], ax))} mm), "
                                     "where only a web thinner than the minimum wall was left")
                    if not ext or thin_at(ax):     # (without plates added, as just measured)
                        need[ax.name] = "thin"
            bridges, fins, through = [], [], []
            for ax in my_axes:
                if ax.name not in need:
                    continue
                own = ax.intervals[bn]
                mine = []
                for a0, a1 in _complement(own, -ax.span / 2, ax.span / 2):
                    if any(o1 <= a0 + 1e-9 for _, o1 in own) and any(o0 >= a1 - 1e-9 for o0, _ in own):
                        # a bridge over a thin web must keep clear of the other bodies in the dense
                        # paths too (bridge_T; a compiled circuit has none: its print poses only)
                        if need[ax.name] == "thin":
                            # the web's bridge may run into the universal joint's trim of this body
                            # (core_cd towards d: its trim radius is set by out_hi's slab in the logic
                            # states, and the bridge itself is kept clear of every other slab in every
                            # state and dense pose), not into what the hub and yoke knuckles sweep; the
                            # gap: the other slab's half thickness, the clearance, and half the diagonal
                            # of the sample grid (a point between samples is at most that much nearer)
                            br = _bridge(ax, bn, a0, a1, samples, state_T, t, prof, avoid_sweep,
                                         (bridge_T, t / 2 + c + h / np.sqrt(2)))
                        else:
                            br = _bridge(ax, bn, a0, a1, samples, state_T, t, prof, () if reuse else avoid)
                        if br is None:
                            continue
                        mine.append(br)
                        if need[ax.name] == "thin":
                            through.append(br[0])
                        notes.append(f"hinge {ax.name}: {bn} bridges around the other knuckles "
                                     f"({np.degrees(br[1]):.0f} degrees from them)"
                                     + (", where only a web thinner than the minimum wall was left" if need[ax.name] == "thin" else ""))
                if mine and need[ax.name] == "thin":
                    # the bridge carries the load now: the web around the other knuckles, thinner
                    # than the minimum wall, goes (the trim grown by the minimum wall, less the bridge)
                    fins.append(subtract(union(axis_cuts(ax, prof.min_wall)), [x for x, _ in mine]))
                bridges += mine
            if through and other_cuts:      # the joint's trims spare a thin web's bridge (checked clear above)
                cuts = [x for ax in my_axes for x in axis_cuts(ax)] + [subtract(union(other_cuts), through)]
            solid = _clean(subtract(union([solid] + [x for x, _ in bridges]), cuts + fins)) if bridges else cut_solid
            # 2. own knuckles, attachment rings
            keep = []
            for ax in my_axes:
                for a0, a1 in ax.intervals[bn]:
                    keep.append(knuckle(ax.origin, ax.direction, a0, a1, R, n, *rims.get((ax.name, a0, a1), (0, 0))))
            for uj, side in my_uj:
                for a0, a1 in uj.layouts[side].own:
                    keep.append(knuckle(uj.center, uj.axes[side], a0, a1, uj.layouts[side].r_own or R, n,
                                        *rims.get((uj.name, side, a0, a1), (0, 0))))
            # rings where the slab is too narrow for a hole; holes inside slabs are drilled last,
            # where the slab has room for them after trimming
            rings = [cylinder(x[0], x[1], -t / 2, t / 2, lug_out, n) for x in lugs[bn] if x[2]]
            male, recess = [], []
            if cones:
                cr = r_cone + c * np.sqrt(2)
                for ax in my_axes:
                    if ax.joint is not None:     # a compound junction's stack keeps the joint's straight pin
                        continue
                    seq = sorted((iv, b2) for b2, ivs in ax.intervals.items() for iv in ivs)
                    for (iv0, b0), (iv1, b1) in zip(seq, seq[1:]):
                        face = iv0[1]          # the cone grows from the end face of the lower knuckle
                        if b0 == bn:
                            male.append(cone(ax.origin, ax.direction, face - 1e-3, face + h_cone, r_cone + 1e-3,
                                             r_cone - h_cone, n))
                        if b1 == bn:      # the truncated cone offset by c: flat top c higher, side c out
                            recess.append(cone(ax.origin, ax.direction, face - 1e-3, face + h_cone + c, cr + 1e-3,
                                               cr - h_cone - c, n, cutter=True))
            keep += male
            solid = union([solid] + keep + rings)
            # 3. holes: non-owner knuckles, yoke knuckles, attachment holes
            holes = []
            holes += recess
            for ax in my_axes:
                if ax.pin_owner != bn and (not cones or ax.joint is not None):
                    for a0, a1 in ax.intervals[bn]:
                        holes.append(cylinder(ax.origin, ax.direction, a0 - g / 2, a1 + g / 2, r_hole, n, cutter=True))
            for uj, side in my_uj:
                lay = uj.layouts[side]
                for a0, a1, rh in (lay.holes if lay.holes is not None else [(a0 - g / 2, a1 + g / 2, r_hole)
                                                                            for a0, a1 in lay.own]):
                    holes.append(cylinder(uj.center, uj.axes[side], a0, a1, rh, n, cutter=True))
            for x in lugs[bn]:
                if x[2]:
                    holes.append(cylinder(x[0], x[1], -t - 1, t + 1, lug_hole, n, cutter=True))
            solid = subtract(solid, holes)
            # 4. the owner's pin
            pins = [cylinder(ax.origin, ax.direction, -ax.span / 2, ax.span / 2, r_pin, n)
                    for ax in my_axes if ax.pin_owner == bn and not cones]
            solid = _clean(union([solid] + pins))
            protected[bn] = union(keep + pins + rings)
            if reuse:
                cores[bn] = union([subtract(union(keep + rings), holes)] + pins)
            if cones:
                cone_cores[bn] = subtract(union(keep + rings), holes)
            solid = _drop_scraps(solid, protected[bn], bn, notes)
            if shrink.done(len(solid.decompose())):
                break
        if shrink.f < 1.0:
            which = "its universal joints (its hinges' kept)" if shrink.axes_full else "its joints"
            notes.append(f"{bn}: trim radii of {which} shrunk to {shrink.f:.3g} of the way from the least "
                         "that clears their knuckles to the sampled ones: at the full radii the body "
                         "was in several pieces")
        # the spot where the attachment hole would go (0.85 mm in from the site), kept if possible
        spots = [cylinder(_spot(x[4], x[0], lug_out), x[1], -t, t, lug_out + c, n) for x in lugs[bn] if not x[2]]
        soft[bn] = union([protected[bn]] + spots)
        if reuse:
            # the same protected material grown by GUARD_PAD: the final trims of large assemblies
            # subtract (cutter less guard), and a guard whose faces lie on the part's own faces
            # made one boolean of two 1000-vertex parts take minutes and gigabytes (issue 13)
            e = GUARD_PAD
            fat = [cylinder(ax.origin, ax.direction, a0 - e, a1 + e, R + e, n)
                   for ax in my_axes for a0, a1 in ax.intervals[bn]]
            fat += [cylinder(uj.center, uj.axes[side], a0 - e, a1 + e, (uj.layouts[side].r_own or R) + e, n)
                    for uj, side in my_uj for a0, a1 in uj.layouts[side].own]
            fat += [cylinder(ax.origin, ax.direction, -ax.span / 2 - e, ax.span / 2 + e, r_pin + e, n)
                    for ax in my_axes if ax.pin_owner == bn and not cones]
            fat += [cylinder(x[0], x[1], -t / 2 - e, t / 2 + e, lug_out + e, n) for x in lugs[bn] if x[2]]
            fat += male
            fat_guard[bn] = (union(fat), union(fat + spots) if spots else None)
        partners = sorted({o for ax in my_axes for o in ax.bodies if o != bn}
                          | {uj.part for uj, _ in my_uj} | {ax.joint for ax in my_axes if ax.joint is not None})
        _LOCAL[0] = None
        if Fb is not None:
            solid = transform_solid(solid, Fb)
            for tab in (protected, soft, cores, cone_cores):
                if bn in tab:
                    tab[bn] = transform_solid(tab[bn], Fb)
            if bn in fat_guard:
                fat_guard[bn] = tuple(None if x is None else transform_solid(x, Fb) for x in fat_guard[bn])
        parts.append(Part(bn, "body", solid, partners))
        if len(solid.decompose()) > 1:
            if UNTWIST_SPLIT:
                split_by.update(uj.name for uj, side in my_uj if side == 1 and uj.turned and uj.name not in untwist)
            # a grown stack left a knuckle apart: built again, short
            split_by.update(("short", grown[id(ax)]) for ax in my_axes
                            if id(ax) in grown and ("short", grown[id(ax)]) not in untwist)
    if split_by:
        raise _Untwist(split_by)

    for uj in ujoints:
        if not uj.primary:      # branch junction: built with its first page
            continue
        u, v = uj.axes
        partners = list(uj.bodies)
        if uj.host is None:
            pieces = [cylinder(uj.center, u, -uj.hub / 2, uj.hub / 2, R, n),
                      cylinder(uj.center, v, -uj.hub / 2, uj.hub / 2, R, n)]
        else:       # compound junction: ball hub, collar down to the stack, its knuckle in the stack
            hx = uj.host
            pieces = [mf.Manifold.sphere(uj.hub_r, n).translate(uj.center.tolist()),
                      cylinder(uj.center, u, -uj.collar, 0.0, uj.hub_r, n),
                      cylinder(hx.origin, hx.direction, hx.joint_iv[0], hx.joint_iv[1], R, n)]
            partners += [o for o in hx.bodies if o not in partners]
        for side, lay in enumerate(uj.layouts):
            pieces.append(cylinder(uj.center, uj.axes[side], lay.pin[0], lay.pin[1], r_pin, n))
            pieces += [cylinder(uj.center, uj.axes[side], a0, a1, R, n) for a0, a1 in lay.caps]
            pieces += [cylinder(uj.center, uj.axes[side], a0, a1, rr, n) for a0, a1, rr in lay.head]
        for mu in ujoints:      # branch junction: every page's pin and caps on the one part
            if mu is not uj and not mu.primary and mu.part == uj.part:
                lay = mu.layouts[1]
                pieces.append(cylinder(mu.center, mu.axes[1], lay.pin[0], lay.pin[1], r_pin, n))
                pieces += [cylinder(mu.center, mu.axes[1], a0, a1, R, n) for a0, a1 in lay.caps]
                pieces += [cylinder(mu.center, mu.axes[1], a0, a1, rr, n) for a0, a1, rr in lay.head]
                partners += [mu.bodies[1]]
        parts.append(Part(uj.part, "joint", union(pieces), partners))
        protected[uj.part] = parts[-1].solid

    for jname, bonds in joints.items():
        if bonds[0].kind not in ("hinge", "universal"):
            notes.append(f"joint {jname} ({bonds[0].kind}) is not printed as a joint")
    if cones and ujoints:
        notes.append("pin: cone pins on the hinges; the universal joint keeps straight pins in its yokes")

    asm = Assembly(scene, prof, parts, axes, ujoints, notes, features, t, poses)
    if reuse:
        asm.cores = dict(cores, **{uj.part: asm.part(uj.part).solid for uj in ujoints})
        asm.axis_cores = {uj.part: union([cylinder(uj.host.origin, uj.host.direction, *uj.host.joint_iv, R, n),
                                          cylinder(uj.center, uj.axes[0], *uj.layouts[0].pin, r_pin, n)])
                          for uj in ujoints if uj.host is not None and uj.primary}
    if reuse:
        asm.congruence = Congruence(_congruence_frames(asm, slabs))
    _log(f"{len(parts)} parts built ({sum(p.solid.num_vert() for p in parts)} vertices)")
    if cones:
        cone_cores.update({uj.part: protected[uj.part] for uj in ujoints if uj.primary})
        asm.cone_conflicts = _cone_conflicts(asm, cone_cores)
        if asm.cone_conflicts and resolve and not _CONE_PROBE[0]:
            _cone_refuse(asm, scene, prof, poses, r_cone, h_cone)
    # the part transforms of the dense poses: trimmed against, then kept clear by the ring lugs
    motion_T = [asm.part_transforms(*pq, body_T=Ts) for pq, (_, Ts) in zip((motion_poses or {}).values(), motion_ST)]
    if resolve:
        _resolve(asm, protected, soft, state_T, asm.congruence, fat_guard)
        if motion_T:
            _clear_motion(asm, protected, soft, list(motion_poses), motion_T)
        if reuse and poses and (BEVEL_ENDS or PIN_RELIEF or YOKE_TIP_CLEAR):
            # the parts' transforms in the logic states, once for the three steps (from state_T's bodies)
            posed_T = [asm.part_transforms(*pq, body_T=T) for pq, (_, T) in zip(poses.values(), state_T)]
            if BEVEL_ENDS:
                _log("bevels of facing end knuckles")
                _bevel_facing_ends(asm, notes, posed_T)
            if PIN_RELIEF:
                _relieve_host_holes(asm, notes, posed_T)
            if YOKE_TIP_CLEAR:
                _clear_tipped_yokes(asm, notes, posed_T)
            if STROKE_CLEAR:
                _clear_strokes(asm, protected, soft, posed_T)
        if SHAVE_THIN:
            from mlc.mesh.shave import shave_thin
            _log("thin regions off the bodies' joints")
            shave_thin(asm, _log)
    _log("final trims done; drilling")
    # attachment holes shaped for the print's up where it is known now: the feet's (fdm's
    # orient: auto; the as_is profiles, mjp and sla, print their own support and keep round holes)
    _drill(asm, lugs, lug_hole, lug_out, t, motion_T,
           up=_feet_up(asm, poses, motion_T) if resolve and motion_T and prof.orient in ("auto", "auto_config")
           else None)
    if resolve and motion_T:
        # print-only feet under the parts that move in one plane (mlc.mesh.feet): clear of every
        # other part as printed, in the logic states and in the dense poses; before the orientation
        from mlc.mesh.feet import add_feet
        _log("feet")
        add_feet(asm, [asm.part_transforms(*pq) for pq in (poses or {}).values()] + motion_T)
    asm.orient = _orientation(asm)
    _log("assembly done")
    return asm


# -- facing end knuckles of two hinges (session 55) -----------------------------------------
#: compiled circuits: the end knuckles of two hinges that face each other across a bent junction
#: (a chain's layers; a branch's leaf page and its chain's first half unit) bevelled apart
BEVEL_ENDS = True
BEVEL_FACING = 0.5        # end faces whose outward normals meet at more than 120 degrees face each other
BEVEL_RINGS = (0.0, 0.5, 1.0)   # ... sampled on these fractions of the knuckle radius


def _end_knuckles(axes) -> list:
    """(axis, sign, body, knuckle length) of every hinge's two end knuckles: the knuckle that
    ends on the span's end ``sign * span / 2`` and the body it belongs to."""
    out = []
    for ax in axes:
        for sg in (-1.0, 1.0):
            e = sg * ax.span / 2
            for bn, ivs in ax.intervals.items():
                for a0, a1 in ivs:
                    if abs((a1 if sg > 0 else a0) - e) < 1e-6:
                        out.append((ax, sg, bn, a1 - a0))
    return out


def _face_points(o, d, R, n_ang=16):
    """Points of an end face's disk (centre ``o``, normal ``d``, radius ``R``) on BEVEL_RINGS."""
    P = _perp_frame(d)
    a = np.linspace(0, 2 * np.pi, n_ang, endpoint=False)
    ring = np.cos(a)[:, None] * P[:, 0] + np.sin(a)[:, None] * P[:, 1]
    pts = [o[None, :]] + [o + f * R * ring for f in BEVEL_RINGS if f > 0]
    return np.vstack(pts)


def _to_cylinder(p, o, n, k, R):
    """Distance of points ``p`` to the knuckle whose end face is centred at ``o`` with outward
    normal ``n`` (unit), ``k`` long and of radius ``R`` (0 inside)."""
    v = p - o
    depth = -(v @ n)
    r = np.linalg.norm(v + np.outer(depth, n), axis=1)
    dz = np.maximum(np.maximum(-depth, depth - k), 0.0)
    return np.hypot(dz, np.maximum(r - R, 0.0))


def _bevel_facing_ends(asm: "Assembly", notes: list, Ts: list) -> None:
    """Bevel the end knuckles of two hinges of different bodies that face each other and come
    closer than the clearance in a pose.

    A connector's layers are a junction gap apart, and the scene stops a junction's bend where
    the layers' slabs would meet at the far corner (``mlc.gates.connector.max_bend``: 36.9
    degrees, the stop at 90 % of it).  The printed knuckles stand ``R`` (1.1 mm at mjp) round
    that corner's hinge, so the end faces of the two layers' far-corner knuckles met from about
    29 degrees on (the Tetris circuit: junctions bent by 29.5 to 33.2 degrees in its logic states,
    and a branch's leaf page against its chain's first half unit, bent by 29.5 degrees at rest).
    For every such pair and pose, the plane half way between the two posed end faces (the
    bisector of their planes) is found, and each knuckle loses what lies within half the
    clearance of it on its side, inside its own end knuckle only (a bevel of the far rim; the
    knuckle's inner faces, which hold the stack along the pin, are untouched).  A bevel that
    would leave the body in pieces is not made. ``Ts``: the parts' transforms in the logic
    states (:meth:`Assembly.part_transforms` of ``asm.poses``)."""
    if not asm.poses:
        return
    c = asm.profile.clearance
    n = asm.profile.circular_segments
    ends = _end_knuckles(asm.axes)
    if not ends:
        return
    from scipy.spatial import cKDTree
    R = max(ax.R for ax, _, _, _ in ends)
    bodies_of = [set(ax.bodies) for ax, _, _, _ in ends]
    O = np.array([ax.origin + sg * ax.span / 2 * ax.direction for ax, sg, _, _ in ends])
    N = np.array([sg * ax.direction for ax, sg, _, _ in ends])
    cuts: dict = {}      # end index -> [(m, h)]: cut where m . p > h (rest frame of its body)
    for T in Ts:
        Tb = [T[bn] for _, _, bn, _ in ends]
        Op = np.array([t[:3, :3] @ o + t[:3, 3] for t, o in zip(Tb, O)])
        Np = np.array([t[:3, :3] @ v for t, v in zip(Tb, N)])
        for i, j in cKDTree(Op).query_pairs(2 * R + 2 * c):
            if ends[i][2] == ends[j][2] or bodies_of[i] & bodies_of[j] or Np[i] @ Np[j] > -BEVEL_FACING:
                continue
            (ai, _, _, ki), (aj, _, _, kj) = ends[i], ends[j]
            near = min(_to_cylinder(_face_points(Op[i], Np[i], ai.R), Op[j], Np[j], kj, aj.R).min(),
                       _to_cylinder(_face_points(Op[j], Np[j], aj.R), Op[i], Np[i], ki, ai.R).min())
            if near >= c:
                continue
            w = Np[i] - Np[j]
            L = float(np.linalg.norm(w))
            m, h = w / L, (Op[i] @ Np[i] - Op[j] @ Np[j]) / L    # f(p) = m . p - h: + toward j
            for k, sgn in ((i, 1.0), (j, -1.0)):
                t = Tb[k]
                # the cut's plane in k's rest frame: sgn * f(p) > -c / 2
                mk = t[:3, :3].T @ (sgn * m)
                hk = sgn * h - c / 2 - (sgn * m) @ t[:3, 3]
                cuts.setdefault(k, []).append((mk, hk))
    if not cuts:
        return
    by = {p.name: p for p in asm.parts}
    per_body: dict = {}
    for k, planes in cuts.items():
        ax, sg, bn, kk = ends[k]
        o = O[k]
        zone = cylinder(o - N[k] * kk, N[k], 0.0, kk + 0.05, ax.R + 0.05, n)
        big = 4 * (ax.R + kk) + 1.0
        for mk, hk in planes:
            # the half space m . p > h, clipped to the end knuckle
            F = _perp_frame(mk)
            p0 = o + (hk - mk @ o) * mk          # on the plane, nearest the face centre
            half = box(p0 + mk * big / 2, F, np.array([big, big, big]))
            per_body.setdefault(bn, []).append(zone ^ half)
    done = []
    for bn, pieces in per_body.items():
        part = by[bn]
        cutter = union(pieces)
        new = part.solid - cutter
        removed = part.solid.volume() - new.volume()
        if removed <= 1e-9:
            continue
        if len(new.decompose()) != len(part.solid.decompose()):
            notes.append(f"{bn}: the bevel of its end knuckles facing another hinge's would leave it in pieces: not made")
            continue
        part.solid = new
        cores = getattr(asm, "cores", None)
        if cores and bn in cores:     # retention counts what is left of the knuckle
            cores[bn] = cores[bn] - cutter
        done.append((bn, removed))
    if done:
        notes.append(f"end knuckles facing another hinge's across a bent junction: {len(done)} bodies bevelled, "
                     f"{sum(r for _, r in done):.3g} mm^3 removed (largest {max(r for _, r in done):.3g} mm^3, "
                     f"{max(done, key=lambda x: x[1])[0]})")


def _cut_whole(asm: "Assembly", by: dict, cutters: dict) -> list:
    """Subtract ``cutters[body]`` from each named part, where that removes something and leaves
    the part in as many pieces as before; what is left of a knuckle core (``asm.cores``, for
    the retention check) loses the same.  Returns [(body, mm^3 removed)]."""
    done = []
    cores = getattr(asm, "cores", None)
    for bn, cutter in cutters.items():
        part = by[bn]
        new = part.solid - cutter
        removed = part.solid.volume() - new.volume()
        if removed <= 1e-9 or len(new.decompose()) != len(part.solid.decompose()):
            continue
        part.solid = new
        if cores and bn in cores:
            cores[bn] = cores[bn] - cutter
        done.append((bn, removed))
    return done


#: compiled circuits: a compound junction's pin relieved in the stack's holes where it swings (session 55)
PIN_RELIEF = True
PIN_RELIEF_MARGIN = 0.01  # mm: the relief clears the posed pin by this much
RELIEF_RETAINED = True    # ... only as far as every part of the hinge stays retained (session 56)


def _relieve_host_holes(asm: "Assembly", notes: list, Ts: list) -> None:
    """Relieve the holes of a compound junction's host stack where the joint part's pin,
    posed in a logic state, reaches the hole's wall.

    The joint part floats in its holes' clearance and is posed with the junction's twist shared
    between its two pins (``_split_twist``), its hub half way between the bodies' copies of the
    joint point: in the Tetris circuit's most bent junctions its first pin met the wall of the
    hole at the far end of the stack (0.0003 mm^3, `w_b_0_60_AB` against `w_b_0_j61_hi`, row 01).
    Each knuckle of the stack whose hole the posed pin comes within ``PIN_RELIEF_MARGIN`` of
    the wall loses the posed pin grown by that margin, inside that knuckle only: a relief of a
    few hundredths of a millimetre at the hole's mouth. ``Ts``: the parts' transforms in the logic
    states (:meth:`Assembly.part_transforms` of ``asm.poses``)."""
    if not asm.poses:
        return
    n = asm.profile.circular_segments
    e = PIN_RELIEF_MARGIN
    by = {p.name: p for p in asm.parts}
    per_body: dict = {}
    for uj in asm.ujoints:
        hx = uj.host
        if hx is None or not uj.primary or uj.part not in by:
            continue
        u = uj.axes[0]
        p0, p1 = uj.layouts[0].pin
        for bn in hx.bodies:
            if bn not in by or bn == uj.part:
                continue
            for a0, a1 in hx.intervals.get(bn, []):
                ends = hx.origin + np.outer([a0, a1], hx.direction)
                for T in Ts:
                    M = np.linalg.inv(T[bn]) @ T[uj.part]
                    c0 = M[:3, :3] @ uj.center + M[:3, 3]
                    d = M[:3, :3] @ u
                    # the posed pin's axis where it crosses the knuckle's end planes
                    den = d @ hx.direction
                    if abs(den) < 0.5:
                        continue
                    s = ((ends - c0) @ hx.direction) / den
                    if s.max() < p0 or s.min() > p1:
                        continue
                    q = c0 + np.outer(np.clip(s, p0, p1), d)
                    v = q - hx.origin
                    off = np.linalg.norm(v - np.outer(v @ hx.direction, hx.direction), axis=1)
                    if off.max() + uj.r_pin < hx.r_hole - e:
                        continue
                    zone = cylinder(hx.origin, hx.direction, a0 - 1e-3, a1 + 1e-3, hx.R + 0.05, n)
                    pin = cylinder(c0, d, p0 - 0.05, p1 + 0.05, uj.r_pin + e, n, cutter=True)
                    depth = float(off.max()) + uj.r_pin - hx.r_hole
                    per_body.setdefault((bn, hx.name), (hx, []))[1].append((depth, zone ^ pin))
    done, kept = [], []
    for (bn, _), (hx, pieces) in per_body.items():
        cutter, skipped = _retained_relief(asm, by, bn, hx, pieces)
        if skipped:
            kept.append((bn, hx.name, skipped, max(dp for dp, _ in pieces)))
        if cutter is not None:
            done += _cut_whole(asm, by, {bn: cutter})
    if done:
        notes.append(f"compound junctions' pins relieved in their stacks' holes where they swing: {len(done)} bodies, "
                     f"{sum(r for _, r in done):.3g} mm^3 removed (largest {max(r for _, r in done):.3g} mm^3, "
                     f"{max(done, key=lambda x: x[1])[0]})")
    if kept:
        notes.append(f"pin reliefs left out where they would free a part of the hinge (retention): {len(kept)} knuckle "
                     f"groups, {sum(k[2] for k in kept)} posed pins (deepest {max(k[3] for k in kept):.3g} mm past the "
                     f"hole; {', '.join(f'{b} at {h}' for b, h, _, _ in kept[:6])}{', ...' if len(kept) > 6 else ''})")


def _retained_relief(asm: "Assembly", by: dict, bn: str, hx: "HingeAxis", pieces: list):
    """The part of a pin relief (``pieces``: [(depth past the hole's wall, posed pin's cutter)])
    that body ``bn`` can lose while every part of its host hinge ``hx`` stays retained: the
    retention check's moves (:func:`mlc.mesh.checks.axis_free`) freed by no cut.  All pieces
    if that holds; else the shallowest ones, one at a time, up to the first that would free a
    part (session 56: the robot's poses put some joint parts' pins up to 0.75 mm past the wall of
    a 0.6 mm knuckle ring, and their relief opened the hole).  Returns (cutter or None, how many
    pieces were left out)."""
    from mlc.mesh.checks import axis_free
    if not RELIEF_RETAINED:
        return union([pc for _, pc in pieces]), 0
    c = asm.profile.clearance
    empty = mf.Manifold()

    def free(cut):
        new = by[bn].solid - cut if cut is not None else by[bn].solid
        return axis_free(hx, lambda o: new if o == bn else (by[o].solid if o in by else empty), c)

    base = free(None)

    def holds(cut):
        return not any(f and not b for f, b in zip(free(cut), base))

    pieces = sorted(pieces, key=lambda x: x[0])
    whole = union([pc for _, pc in pieces])
    if holds(whole):
        return whole, 0
    ok = []
    for dp, pc in pieces:
        if not holds(union(ok + [pc])):
            break
        ok.append(pc)
    return (union(ok) if ok else None), len(pieces) - len(ok)


#: compiled circuits: a compound junction's host hinge bodies cleared of the yoke where the posed
#: junction's twist tips it below the host's cut (session 55)
YOKE_TIP_CLEAR = True


def _clear_tipped_yokes(asm: "Assembly", notes: list, Ts: list) -> None:
    """Trim a compound junction's host-hinge bodies where the other body's yoke knuckles, posed,
    reach past the end of the cut that clears them (``layouts[0].cut``, along the first pin).

    The cut runs from just inside the host layer's face (0.05 mm) across the junction gap; the
    yoke's knuckles (radius ``R``, up to 2.4 mm along the second pin) clear it as long as the
    joint's twist stays under about 5 degrees, and the circuit's statics twist some junctions
    more (``_split_twist``): in the Tetris circuit ``w_b_0_62_AB``'s yoke grazed the face of
    ``w_b_0_61_DA`` (row 11) and ``w_b_1_111_AB``'s that of ``w_b_1_110_CD`` (row 01), 2e-5 and
    8e-5 mm^3.  Each host-hinge body loses those posed knuckles grown by half the clearance,
    outside its own stack on the host axis (radius ``R`` + clearance). ``Ts``: the parts' transforms in the logic
    states (:meth:`Assembly.part_transforms` of ``asm.poses``)."""
    if not asm.poses:
        return
    c = asm.profile.clearance
    n = asm.profile.circular_segments
    by = {p.name: p for p in asm.parts}
    per_body: dict = {}
    for uj in asm.ujoints:
        hx = uj.host
        if hx is None or not uj.primary:
            continue
        O = uj.bodies[1]
        lay, d = uj.layouts[1], hx.direction
        c_h = float((uj.center - hx.origin) @ d)
        sl = -np.sign(c_h) if c_h else 1.0   # toward the layer
        for X in hx.bodies:
            if X == O or X not in by or O not in by:
                continue
            ends = sorted(c_h + float(uj.axes[0] @ d) * np.array(_host_cut(uj, X, c)), key=abs)
            h_cut = ends[0]                  # the cut's end at the host layer
            for T in Ts:
                M = np.linalg.inv(T[X]) @ T[O]
                cc = M[:3, :3] @ uj.center + M[:3, 3]
                v = M[:3, :3] @ uj.axes[1]
                lean = float(np.sqrt(max(0.0, 1.0 - (v @ d) ** 2)))
                for a0, a1 in lay.own:
                    g = max(sl * ((cc + a * v - hx.origin) @ d) for a in (a0, a1)) + uj.R * lean
                    if g < sl * h_cut - c / 2:
                        continue
                    per_body.setdefault(X, []).append(cylinder(cc, v, a0 - c / 2, a1 + c / 2, uj.R + c / 2, n,
                                                               cutter=True))
    stacks: dict = {}
    for ax in asm.axes:
        for bn in ax.bodies:
            stacks.setdefault(bn, []).append(cylinder(ax.origin, ax.direction, -ax.span / 2 - c, ax.span / 2 + c,
                                                      ax.R + c, n))
    done = _cut_whole(asm, by, {bn: union(pieces) - union(stacks.get(bn, [])) for bn, pieces in per_body.items()})
    if done:
        notes.append(f"compound junctions' yokes tipped by the twist past their hosts' cut: {len(done)} host-hinge "
                     f"bodies trimmed, {sum(r for _, r in done):.3g} mm^3 removed (largest {max(r for _, r in done):.3g} "
                     f"mm^3, {max(done, key=lambda x: x[1])[0]})")


# --------------------------------------------------------------------------- helpers
_CONE_PROBE = [False]      # building to find the smallest sigma at which cones fit: never refuse


#: a yoke plate whose axis leaves the slab's plane by more than this (sine) is a fin across
#: the slab, kept on it (:func:`_yoke_plates`)
FIN_SIN = 0.05
SECOND_PIN_TRIES = 12      # second-pin directions tried, every 15 degrees about the first pin
TWIST_PIN_STEP = 1.0       # degrees: the second pins of a compound junction tried (_PinClearance.least_twist)


class _PinClearance:
    """Chooses a universal joint's second pin where no hinge of the other body gives it: its
    hinges run along the first pin and all of them are farther than the yoke's reach from the
    joint (the joint hangs on a post, as a circuit chain's end under a gate's input lever;
    not a chain's own junction, which is nearer the next half unit's hinges).  Of
    ``SECOND_PIN_TRIES`` directions about the first pin, the one whose yoke knuckles (axis
    points at ``radii`` mm either side of the joint) stay farthest, in every posed state,
    from the slabs of the other bodies and the knuckles of the joints laid out before,
    measured past what each needs (a slab: R + c + t/2; a knuckle: 2 R + c; mm).  The first
    direction (across the body's slabs, as before) is kept when it clears all of them.  Only
    parts within ``reach + 4 R`` of the joint at rest are looked at."""

    def __init__(self, base_samples: dict, state_T: list, R: float, c: float, t: float, reach: float):
        names = [bn for bn in base_samples if len(base_samples[bn])]
        self.state_T, self.crop = state_T, reach + 4 * R
        self.slab_need, self.knuckle_need = R + c + 0.5 * t, 2 * R + c
        self.names, self.base = names, base_samples
        self.knuckles: list = []        # (body, knuckle axis points)
        self.joint_points: list = []    # every universal joint's point (mm, rest): least_twist
        self.pending: dict = {}         # joint -> (body, point, untwisted second pin), mm,
                                        # until it is laid out: least_twist
        self._tree = None
        self._kbuf = None               # every knuckle item's points posed in every state, (states, cap, 3),
        self._kitem = None              # ... each point's item (cap,): filled up to _kn points,
        self._kn = self._kdone = 0      # ... from the first _kdone items (made on use)
        self._kposed_for = None         # ... for this state_T

    def add(self, body: str, center, v, radii, joint: str | None = None, r=None) -> None:
        """Knuckle axis points of a laid-out yoke (on ``body``), for the joints after it
        (``r``: their signed distances along ``v``, mm; both sides at ``radii`` by default)."""
        self.knuckles.append((body, center + np.outer(np.r_[radii, -radii] if r is None else r, v)))
        self.pending.pop(joint, None)

    def _knuckles_posed_near(self, center, ob: str) -> np.ndarray:
        """(FIRST_PIN_CLEAR) Which of ``knuckles`` come within the crop of the joint point in some
        posed state, seen from ``ob`` (its lever may turn a knuckle far from where it is at rest
        towards a joint part: the robot's gates turn their input levers 73 degrees)."""
        if not self.knuckles or not self.state_T:
            return np.zeros(len(self.knuckles), bool)
        if self._kposed_for is not self.state_T:
            self._kbuf, self._kitem, self._kn, self._kdone, self._kposed_for = None, None, 0, 0, self.state_T
        if self._kdone < len(self.knuckles):
            # each new knuckle item posed once, in every state, into a buffer that doubles when full
            new = [(i, np.stack([k @ Ts[bn][:3, :3].T + Ts[bn][:3, 3] for _, Ts in self.state_T]))
                   for i, (bn, k) in enumerate(self.knuckles[self._kdone:], self._kdone)]
            m = sum(q.shape[1] for _, q in new)
            if self._kbuf is None or self._kn + m > self._kbuf.shape[1]:
                cap = max(64, 2 * (self._kn + m))
                buf, item = np.empty((len(self.state_T), cap, 3)), np.empty(cap, dtype=int)
                if self._kbuf is not None:
                    buf[:, :self._kn], item[:self._kn] = self._kbuf[:, :self._kn], self._kitem[:self._kn]
                self._kbuf, self._kitem = buf, item
            for i, q in new:
                self._kbuf[:, self._kn:self._kn + q.shape[1]] = q
                self._kitem[self._kn:self._kn + q.shape[1]] = i
                self._kn += q.shape[1]
            self._kdone = len(self.knuckles)
        cs = np.array([Ts[ob][:3, :3] @ center + Ts[ob][:3, 3] for _, Ts in self.state_T])
        d = np.linalg.norm(self._kbuf[:, :self._kn] - cs[:, None, :], axis=2).min(axis=0)
        out = np.zeros(len(self.knuckles), bool)
        out[self._kitem[:self._kn][d < self.crop]] = True
        return out

    def _near(self, center, cb: str, ob: str) -> list:
        """[(body, points, need)] of the other bodies' slab samples and knuckles within the crop."""
        if self._tree is None:
            from scipy.spatial import cKDTree
            self._owner = np.concatenate([np.full(len(self.base[bn]), i) for i, bn in enumerate(self.names)])
            self._P = np.concatenate([self.base[bn] for bn in self.names])
            self._tree = cKDTree(self._P)
        ix = np.asarray(self._tree.query_ball_point(center, self.crop), dtype=int)
        out = []
        for i in np.unique(self._owner[ix]) if len(ix) else []:
            bn = self.names[i]
            if bn not in (cb, ob):
                out.append((bn, self._P[ix[self._owner[ix] == i]], self.slab_need))
        posed = self._knuckles_posed_near(center, ob) if FIRST_PIN_CLEAR else np.zeros(len(self.knuckles), bool)
        for (bn, k), near_posed in zip(self.knuckles, posed):
            if bn not in (cb, ob) and (near_posed or np.min(np.linalg.norm(k - center, axis=1)) < self.crop):
                out.append((bn, k, self.knuckle_need))
        return out

    def _score(self, center, v, ob: str, radii, near) -> float:
        return float(np.min(self._clearances(center, v, ob, radii, near), initial=np.inf))

    def _clearances(self, center, v, ob: str, radii, near) -> np.ndarray:
        """The smallest distance, past what it needs, of the yoke knuckles along ``v`` from
        each of ``near`` over the posed states (mm, one entry per item of ``near``)."""
        kn = center + np.outer(np.r_[radii, -radii], v)
        out = np.full(len(near), np.inf)
        for _, Ts in self.state_T:
            To = Ts[ob]
            k = kn @ To[:3, :3].T + To[:3, 3]
            for i, (bn, P, need) in enumerate(near):
                Tb = Ts[bn]
                q = P @ Tb[:3, :3].T + Tb[:3, 3]
                out[i] = min(out[i], float(np.linalg.norm(q[:, None, :] - k[None, :, :], axis=2).min()) - need)
        return out

    def _clearances_many(self, center, V, ob: str, radii, near, r=None) -> np.ndarray:
        """:meth:`_clearances` of the yokes along each row of ``V`` at once: (len(V), len(near)),
        mm, where they are negative (a positive clearance may read as inf: the points farther
        than the knuckles' reach plus the need are left out); ``r``: the knuckle points' signed
        distances along v (both sides at ``radii`` by default)."""
        r = np.r_[radii, -radii] if r is None else np.asarray(r, float)
        return self._clear_r(V, self._posed_near(center, ob, near, float(np.max(np.abs(r)))), len(near), r).min(axis=2)

    def _posed_near(self, center, ob: str, near, rmax: float) -> list:
        """[(item, points, need)]: the points of each of ``near`` in every posed state, in
        ``ob``'s rest frame from the joint point (mm), those within ``rmax`` plus the need."""
        out = []
        for _, Ts in self.state_T:
            To = Ts[ob]
            for i, (bn, P, need) in enumerate(near):
                Tb = Ts[bn]
                rel = ((P @ Tb[:3, :3].T + Tb[:3, 3]) - To[:3, 3]) @ To[:3, :3] - center   # (m, 3)
                rel = rel[np.einsum("ij,ij->i", rel, rel) <= (rmax + need) ** 2]
                if len(rel):
                    out.append((i, rel, need))
        return out

    @staticmethod
    def _clear_r(V, posed: list, n: int, r) -> np.ndarray:
        """(len(V), n, len(r)): the least distance, past the need, of each item's posed points
        (:meth:`_posed_near`) from the knuckle point at ``r`` along each row of ``V`` (mm; inf
        where none is near): |q - k|^2 = |q|^2 - 2 r q.v + r^2."""
        out = np.full((len(V), n, len(r)), np.inf)
        for i, rel, need in posed:
            A = rel @ V.T                                                                 # (m, k)
            d2 = np.einsum("ij,ij->i", rel, rel)[:, None, None] - 2 * A[:, :, None] * r + r * r
            out[:, i, :] = np.minimum(out[:, i, :], np.sqrt(np.maximum(d2.min(axis=0), 0.0)) - need)
        return out

    def least_twist(self, center, u, v, cb: str, ob: str, radii, joint: str | None = None,
                    cap_r: float | None = None, severs=None):
        """The second pin of a compound junction (circuit chains): of the directions about the
        first pin ``u`` every ``TWIST_PIN_STEP`` degrees from ``v``, the one whose largest
        *twist* over the posed states is least, among those whose yoke knuckles stay as clear
        of the other parts as ``v``'s (:meth:`_score`, or clear of all of them).

        The twist is 90 degrees less the angle between the pins, ``u`` fixed in ``cb`` and the
        second pin in ``ob``: the scene's universal joint is a ball joint, and the statics of a
        circuit chain turn its two layers relative to each other about all three axes, where a
        printed cardan keeps its pins square.  Its joint part floats in its holes' clearance up
        to about 7.6 degrees (:func:`_split_twist`); past that its pin ends cut into the yokes.
        The pin laid across the next layer's slab (``v``: ``u`` x the way to that body's slabs,
        as before session 50) is twisted by up to 12.8 degrees in the Tetris circuit's 22 poses
        (``g3`` with the last two half units of both chains into it, 24 bodies).  The twist is
        linear in the pin's direction (sin twist = (R_C u).(R_O v), over the poses), and one
        direction per joint keeps it small in every pose: there at most 1.42 degrees at the
        chains' own junctions; the chains' end joints on ``g3``'s input levers, whose knuckles
        the levers' neighbours bound, 12.34 -> 10.88 and 8.41 -> 6.62 degrees (states check:
        34 -> 9 intersections, 0.31 -> 0.10 mm^3; benchmarks/results/tetris_circuit_pins_s50.json).
        A first try that bounded the knuckles by their worst clearance only turned the two yokes
        of a pair towards each other (the pin along the pair's axis is the least twisted where
        the next layer turns about that axis), and they met as printed: hence the half-way rule.
        The half-way rule alone let one yoke of a pair turn into the line of the other's, laid
        out after it (``w_b_2_58_AB``-``w_b_2_58_CD``, 0.155 mm as printed in the Tetris
        circuit): the joints not yet laid out count with their untwisted yokes (``pending``,
        :func:`_pending_yokes`), which they keep unless a turn stays as clear of this one.

        With ``cap_r`` (the far end of a one-sided yoke's cap, mm; ``ONE_SIDED_TWIST``) it
        returns ``(pin, mode)``: ``"both"``, or ``"+"``/``"-"`` for a yoke on that side of the
        hub only (its knuckle and the pin's cap at ``radii`` and ``cap_r`` along ``mode * pin``),
        taken when the least twisted clear pin with a yoke on both sides twists by more than
        ``ONE_SIDED_ABOVE`` and the one-sided one by ``ONE_SIDED_GAIN`` less.  The least twisted
        pin of a chain's junction often points at the pair's other joint (the next layer bends
        about the pair's axis), where two yokes on both sides meet: the one-sided yoke turns
        away from it.  A 56-body sub-scene of the Tetris circuit (``w_b_2`` and ``w_y_3``,
        half units 55-61): largest junction twist 16.1 -> 7.3 deg, ``states`` 123 -> 3
        intersections (scratch; benchmarks/results/junction_kinematics.json: with the best pins,
        no junction of that circuit twists by more than 6.8 deg over its 22 poses).

        ``severs(pin, mode)``, if given, is true for a pin whose yoke's trim would cut ``ob`` in
        pieces; such a pin is passed over (session 52, :class:`_Untwist`)."""
        sides = cap_r is not None
        keep = (v, "both") if sides else v
        if not self.state_T:
            return keep
        w = np.cross(u, v)
        a = np.radians(np.arange(0.0, 180.0, TWIST_PIN_STEP))
        cand = np.outer(np.cos(a), v) + np.outer(np.sin(a), w)         # (n, 3), cand[0] = v
        worst = np.zeros(len(a))
        for _, Ts in self.state_T:
            U = Ts[cb][:3, :3] @ u
            worst = np.maximum(worst, np.abs(cand @ (Ts[ob][:3, :3].T @ U)))
        order = np.argsort(worst, kind="stable")
        if order[0] == 0 or worst[order[0]] >= worst[0] - 1e-12:
            return keep
        # (the joints not laid out yet: their untwisted yokes, at this one's radii)
        near = self._near(center, cb, ob) + [
            (bn, p + np.outer(np.r_[radii, -radii], pv), self.knuckle_need) for jn, (bn, p, pv) in self.pending.items()
            if jn != joint and bn not in (cb, ob) and np.linalg.norm(p - center) < self.crop]
        # each slab and knuckle near: as clear as from v's knuckles, or clear (a slab on the
        # same hinge as ob is always within reach of the knuckles, whatever their turn)
        # Knuckle points: both sides at radii (columns 0-5), and the one-sided yoke's cap (6, 7)
        r_all = np.r_[radii, -radii] if not sides else np.r_[radii, -radii, cap_r, -cap_r]
        nr = len(radii)
        cols = {"both": np.arange(2 * nr), "+": np.r_[np.arange(nr), 2 * nr], "-": np.r_[np.arange(nr, 2 * nr), 2 * nr + 1]}
        posed = self._posed_near(center, ob, near, float(np.max(np.abs(r_all))))
        floor = np.minimum(0.0, self._clear_r(v[None], posed, len(near), r_all)[0][:, cols["both"]].min(axis=1)) - 1e-9
        # ... and each knuckle within its own half of the way to every other joint point near
        # (the junction's other joint, whose yoke is laid out after this one: the two yokes of
        # a pair turned towards each other met as printed, min_gap 0 in the Tetris circuit)
        P = np.array([p for p in self.joint_points if 0 < np.linalg.norm(p - center) < self.crop])
        half = 0.5 * np.linalg.norm(P - center, axis=1) if len(P) else np.zeros(0)
        n = (P - center) / (2 * half[:, None]) if len(P) else np.zeros((0, 3))
        rm = float(np.max(radii))
        floor_p = np.minimum(0.0, half - rm * np.abs(n @ v) - self.knuckle_need / 2) - 1e-9
        better = [i for i in order if i != 0 and worst[i] < worst[0] - 1e-12]   # least twist first

        def deg(i):
            return math.degrees(math.asin(min(1.0, float(worst[i]))))
        # the least twisted clear pin with a yoke on both sides; on one side only (ONE_SIDED_TWIST),
        # taken when the first twists more than ONE_SIDED_ABOVE and it by ONE_SIDED_GAIN less
        both = one = None
        for b in range(0, len(better), 24):       # in batches: the first few usually settle it
            ix = np.array(better[b:b + 24])
            if one is not None and deg(ix[0]) > max(ONE_SIDED_ABOVE, deg(one[0]) + ONE_SIDED_GAIN):
                break               # no pin with both sides left to beat the one-sided one
            proj = cand[ix] @ n.T                                            # (k, len(P))
            cl = self._clear_r(cand[ix], posed, len(near), r_all)            # (k, near, r)
            oks = {}
            for mode in (("both", "+", "-") if sides and one is None else ("both",)):
                reach = rm * (np.abs(proj) if mode == "both" else np.maximum(0.0, proj if mode == "+" else -proj))
                ok = np.all(reach <= (half - self.knuckle_need / 2 - floor_p), axis=1)
                oks[mode] = ok & np.all(cl[:, :, cols[mode]].min(axis=2) >= floor, axis=1)
            if "+" in oks:      # the first clear in order, and not refused by severs
                one = next(((ix[j], m) for j in np.flatnonzero(oks["+"] | oks["-"]) for m in "+-"
                            if oks[m][j] and not (severs and severs(cand[ix[j]], m))), None)
            both = next((ix[j] for j in np.flatnonzero(oks["both"])
                         if not (severs and severs(cand[ix[j]], "both"))), None)
            if both is not None:
                break
        tb = deg(0) if both is None else deg(both)
        if one is not None and tb > ONE_SIDED_ABOVE and deg(one[0]) < tb - ONE_SIDED_GAIN:
            return cand[one[0]] / np.linalg.norm(cand[one[0]]), one[1]
        if both is None:
            return keep
        vv = cand[both] / np.linalg.norm(cand[both])
        return (vv, "both") if sides else vv

    def choose(self, center, u, v, cb: str, ob: str, radii) -> np.ndarray:
        if not self.state_T:
            return v
        near = self._near(center, cb, ob)
        if not near:
            return v
        best = (self._score(center, v, ob, radii, near), v)
        if best[0] >= 0.0:
            return v
        w = np.cross(u, v)
        for k in range(1, SECOND_PIN_TRIES):
            a = np.pi * k / SECOND_PIN_TRIES
            vk = np.cos(a) * v + np.sin(a) * w
            sc = self._score(center, vk, ob, radii, near)
            if sc > best[0] + 1e-9:
                best = (sc, vk)
        return best[1]


def _cone_conflicts(asm: "Assembly", cores: dict) -> list:
    """Pairs of parts whose untrimmable material (knuckles, cones, attachment rings, joint
    parts) comes closer than the clearance as printed, or meets in a logic state:
    ``[(part, part, state or None)]``.  The final trims never cut that material, so such
    a pair could never settle (pin: cone, issue 14)."""
    c, g = asm.profile.clearance, asm.profile.knuckle_gap
    names = [p.name for p in asm.parts if p.name in cores]
    sol = [cores[x] for x in names]
    shared = {frozenset((a, b)) for ax in asm.axes for a in ax.bodies for b in ax.bodies if a != b}
    lo, hi = solid_boxes(sol)
    out = []
    for i, j in box_pairs(lo, hi, c):
        thr = min(c, g) if frozenset((names[i], names[j])) in shared else c
        if float(sol[i].min_gap(sol[j], thr)) < thr - 1e-6:
            out.append((names[i], names[j], None))
    for st, (pos, quat) in (asm.poses or {}).items():
        T = asm.part_transforms(pos, quat)
        posed = [transform_solid(x, T[nm]) for x, nm in zip(sol, names)]
        plo, phi = solid_boxes(posed)
        for i, j in box_pairs(plo, phi, 0.0):
            if (names[i], names[j], None) not in out and (posed[i] ^ posed[j]).volume() > 1e-6:
                out.append((names[i], names[j], st))
    return out


def _cone_refuse(asm: "Assembly", scene, prof, poses, r_cone, h_cone) -> None:
    """Raise the one message for cone pins that cannot fit (before the final trims): the
    pairs, the knuckle sizes, and the smallest sigma (whole mm, up to 4 x) at which they do."""
    import dataclasses
    fit = None
    _CONE_PROBE[0] = True
    try:
        for s2 in range(int(np.floor(prof.sigma_mm)) + 1, int(np.ceil(4 * prof.sigma_mm)) + 1):
            p2 = dataclasses.replace(prof, sigma_mm=float(s2))
            if not build_assembly(scene, p2, poses, resolve=False).cone_conflicts:
                fit = s2
                break
    finally:
        _CONE_PROBE[0] = False
    pairs = ", ".join(f"{a}/{b}" + (" as printed" if st is None else f" in state {st}")
                      for a, b, st in asm.cone_conflicts[:6])
    more = f" and {len(asm.cone_conflicts) - 6} more" if len(asm.cone_conflicts) > 6 else ""
    c, n = prof.clearance, prof.circular_segments

    def stack(ax, bn):
        return union([cylinder(ax.origin, ax.direction, a0, a1, ax.R, n) for a0, a1 in ax.intervals[bn]])
    # the hinges whose knuckles (as cylinders) meet: a's knuckles on one, b's on another
    met = sorted({f"{a}'s on {A.name} and {b}'s on {B.name}" for a, b, _ in asm.cone_conflicts
                  for A in asm.axes if a in A.bodies for B in asm.axes if b in B.bodies and B is not A
                  and float(stack(A, a).min_gap(stack(B, b), c)) < c - 1e-6})
    used = {x for a, b, _ in asm.cone_conflicts for x in (a, b)}
    Rk = sorted({(round(ax.R, 3), round(ax.knuckle, 3), round(ax.span, 3)) for ax in asm.axes
                 if used & set(ax.bodies)})
    sizes = "; ".join(f"knuckle radius {R:g} mm, length {k:g} mm, stack {S:g} mm" for R, k, S in Rk)
    hinges = "; ".join(met) if met else "the universal joint"
    fix = "use --pin pin" + (f", or --sigma-mm >= {fit}" if fit is not None else
                             f" (no sigma up to {4 * prof.sigma_mm:g} mm fits the cones)")
    raise MlcError(
        f"pin: cone does not fit at sigma {prof.sigma_mm:g} mm: the knuckles or cones of {pairs}{more} come "
        f"closer than the clearance {prof.clearance:g} mm (or meet in a logic state), and the trims never cut "
        f"them (knuckles: {hinges}; {sizes or 'no hinge'}; cone diameter {2 * r_cone:g} mm, "
        f"{h_cone:g} mm high; the hinge spacing grows with sigma, these sizes do not)", "--pin", fix)


def _complement(own, lo, hi):
    """Intervals of ``[lo, hi]`` not covered by a body's own knuckles (gaps included): the
    cut reaches exactly to the faces of its own knuckles."""
    out = []
    cur = lo
    for a0, a1 in sorted(own):
        if a0 > cur:
            out.append((cur, a0))
        cur = max(cur, a1)
    if hi > cur:
        out.append((cur, hi))
    return out


def _state_transforms(scene, prof, poses):
    """[(state, {body: 4x4})] for the given poses (mm)."""
    if not poses:
        return []
    return [(st, {b.name: _body_T(b, pos[i], quat[i], prof.sigma_mm) for i, b in enumerate(scene.bodies)})
            for st, (pos, quat) in poses.items()]


def _body_T(b, pos, quat, s) -> np.ndarray:
    """4x4 transform (mm) taking body ``b``'s rest pose to the pose (pos, quat) in sigma;
    ``s``: mm per sigma."""
    R0 = quat_to_matrix(b.orientation)
    R1 = quat_to_matrix(quat)
    Rr = R1 @ R0.T
    T = np.eye(4)
    T[:3, :3] = Rr
    T[:3, 3] = s * np.asarray(pos, float) - Rr @ (s * np.asarray(b.position, float))
    return T


def _knuckle_samples(axes, ujoints, R, h) -> dict:
    """Points on the outer surface of every knuckle (radius ``R``), by body: hinge knuckles
    and the bodies' universal-joint yoke knuckles (mm, rest world)."""
    out: dict = {}

    def ring(bn, origin, d, a0, a1):
        E = _perp_frame(d)
        na = max(2, int(np.ceil((a1 - a0) / h)) + 1)
        nt = max(8, int(np.ceil(2 * np.pi * R / h)))
        a, th = np.meshgrid(np.linspace(a0, a1, na), np.linspace(0, 2 * np.pi, nt, endpoint=False), indexing="ij")
        P = (origin + a.reshape(-1, 1) * d + R * (np.cos(th).reshape(-1, 1) * E[:, 0]
                                                 + np.sin(th).reshape(-1, 1) * E[:, 1]))
        out.setdefault(bn, []).append(P)
    for ax in axes:
        for bn, ivs in ax.intervals.items():
            for a0, a1 in ivs:
                ring(bn, ax.origin, ax.direction, a0, a1)
    for uj in ujoints:
        for side, bn in enumerate(uj.bodies):
            for a0, a1 in uj.layouts[side].own:
                ring(bn, uj.center, uj.axes[side], a0, a1)
    return {bn: np.concatenate(v) for bn, v in out.items()}


def _offset_slabs(slabs, scene, Ts, t, scene_t, c, R, h, s, extra=None, others=None) -> list:
    """Move slab boxes along their normal so that the printed thickness ``t`` grows from one face
    of the scene's slab (``scene_t`` thick) instead of both, where that keeps other bodies
    farther away (all in mm, rest world).

    For each slab box of body B and each pose of ``Ts`` (``{body: 4x4}``), the mid-plane samples
    of every other body are moved into B's frame; those over the box (in its plane, within the
    clearance ``c`` of its outline) and within ``t + c`` of its mid-plane could come closer than
    the clearance when both are printed ``t`` thick (``extra``: more points by body, the
    knuckles of :func:`_knuckle_samples`; ``others``: every body's slabs, when ``slabs`` holds
    only the bodies that may move).  Points near B's own joints are left out
    (the trim radii clear the knuckles there).  The offset ``o`` in (-d, 0, +d), ``d = (t -
    scene_t) / 2``, that leaves the largest smallest estimated gap (``|dn - o| - t``: B's
    face to the other slab's face, both ``t`` thick) is kept.  It is chosen per body, for all
    its boxes at once: all centred, all towards the inside of the body's bends, or all towards
    the outside (coplanar boxes: the same side), so that bent boxes still meet along their
    whole thickness (one box moved alone left a 0.19 mm sliver at the bend of ``out_hi``); the
    centred slabs win ties, so a body with nothing near it, or as near on both sides, is printed
    as before.  Returns ``[(body, box, o)]`` for the boxes moved (their ``center`` is changed in
    place)."""
    d0 = 0.5 * (t - scene_t)
    if not Ts or d0 <= 1e-9:
        return []
    samples = {bn: _slab_samples(sbs, h) for bn, sbs in (others or slabs).items()}
    for bn, P in (extra or {}).items():
        if bn in samples:
            samples[bn] = np.concatenate([samples[bn], P])
    # B's joints: hinge axes (segments between the bond ends) and universal joint points
    near: dict = {bn: [] for bn in slabs}
    for bonds in scene.joints().values():
        ends = [0.5 * (scene.site_world(bd.a) + scene.site_world(bd.b)) * s for bd in bonds]
        for bn in {ref.split(".")[0] for bd in bonds for ref in (bd.a, bd.b)}:
            if bn in near:
                near[bn].append((ends[0], ends[-1]))
    reach = 2 * R + c + t           # a knuckle and the other body's next to it, plus a slab
    offs = np.array([0.0, -d0, d0])
    out = []
    for bn, sbs in slabs.items():
        if not sbs:
            continue
        mid = np.mean([sb.center for sb in sbs], axis=0)
        n0 = sbs[0].R[:, sbs[0].normal_axis]
        worsts, inner = [], []
        for sb in sbs:
            n = sb.R[:, sb.normal_axis]
            w_in = float(np.dot(n, mid - sb.center))
            inner.append(1 if (w_in if abs(w_in) > 1e-6 else float(np.dot(n, n0))) >= 0 else -1)
            inplane = [i for i in range(3) if i != sb.normal_axis]
            half = 0.5 * sb.size[inplane] + c
            worst = np.full(3, np.inf)
            for T in Ts:
                for on, pts in samples.items():
                    if on == bn or not len(pts):
                        continue
                    M = np.linalg.solve(T[bn], T[on])
                    q = pts @ M[:3, :3].T + M[:3, 3]
                    loc = (q - sb.center) @ sb.R
                    dn = loc[:, sb.normal_axis]
                    keep = (np.abs(dn) < t + c) & np.all(np.abs(loc[:, inplane]) <= half, axis=1)
                    if not keep.any():
                        continue
                    q = q[keep]
                    for a, b in near[bn]:
                        ab = b - a
                        u = np.clip((q - a) @ ab / max(float(ab @ ab), 1e-12), 0.0, 1.0)
                        far = np.linalg.norm(q - (a + u[:, None] * ab), axis=1) > reach
                        q = q[far]
                    if not len(q):
                        continue
                    dn = (q - sb.center) @ n
                    worst = np.minimum(worst, (np.abs(dn[None, :] - offs[:, None]) - t).min(axis=1))
            worsts.append(worst)
        # the body's options: centred, every box towards the inside of its bends, or the outside
        # (offs index 2 = +d along the box normal, 1 = -d)
        opts = [[0] * len(sbs), [2 if i > 0 else 1 for i in inner], [1 if i > 0 else 2 for i in inner]]
        score = [min(w[k] for w, k in zip(worsts, ks)) for ks in opts]
        best = int(np.argmax(score))        # the centred option first: it wins ties
        if best and score[best] > score[0] + 1e-9:
            for sb, k in zip(sbs, opts[best]):
                sb.center = sb.center + offs[k] * sb.R[:, sb.normal_axis]
                sb.offset = float(offs[k])
                out.append((bn, sb, float(offs[k])))
    return out


def _bend_fills(sbs) -> list:
    """Where two slab boxes of a body printed from one face (:func:`_offset_slabs`) meet at an
    angle, each moved along its own normal: the convex hull of the four corners of each box
    nearest the other box, which closes the step (a lip thinner than the wall, 0.22 mm at the
    bend of ``out_hi`` at sla) between their ends.  None for centred or coplanar boxes."""
    out = []
    for i, a in enumerate(sbs):
        for b in sbs[i + 1:]:
            if not (a.offset or b.offset):
                continue
            na, nb = a.R[:, a.normal_axis], b.R[:, b.normal_axis]
            if abs(float(np.dot(na, nb))) > 1 - 1e-6:
                continue      # coplanar or parallel: moved alike, no step
            ca, cb = _box_corners(a), _box_corners(b)
            near_a = ca[np.argsort(np.linalg.norm(ca - b.center, axis=1))[:4]]
            near_b = cb[np.argsort(np.linalg.norm(cb - a.center, axis=1))[:4]]
            if (box(a.center, a.R, a.size) ^ box(b.center, b.R, b.size)).is_empty():
                continue      # not joined to each other
            out.append(mf.Manifold.hull_points(np.vstack([near_a, near_b])))
    return out


def _box_corners(sb) -> np.ndarray:
    sgn = np.array(list(itertools.product((-0.5, 0.5), repeat=3)))
    return sb.center + (sgn * sb.size) @ sb.R.T


def _sample_step(t, c, s) -> float:
    """Spacing of the slab sample points: fine against the clearance and slab thickness."""
    return float(np.clip(max(min(t, c), 0.015 * s), 0.05, 0.5))


def _slab_samples(sbs, h) -> np.ndarray:
    """Points on the mid-planes of slab boxes, spaced at most ``h`` apart."""
    pts = []
    for sb in sbs:
        ax = [i for i in range(3) if i != sb.normal_axis]
        m0 = max(2, int(np.ceil(sb.size[ax[0]] / h)) + 1)
        m1 = max(2, int(np.ceil(sb.size[ax[1]] / h)) + 1)
        a, b = np.meshgrid(np.linspace(-0.5, 0.5, m0) * sb.size[ax[0]],
                           np.linspace(-0.5, 0.5, m1) * sb.size[ax[1]], indexing="ij")
        loc = np.zeros((a.size, 3))
        loc[:, ax[0]] = a.ravel()
        loc[:, ax[1]] = b.ravel()
        pts.append(sb.center + loc @ sb.R.T)
    return np.concatenate(pts) if pts else np.zeros((0, 3))


def _axis_coords(origin, d, pts):
    rel = pts - origin
    a = rel @ d
    r = np.linalg.norm(rel - a[:, None] * d, axis=1)
    return a, r


def _axis_angles(ax: HingeAxis, pts, r_lo, r_hi):
    E = _perp_frame(ax.direction)
    rel = pts - ax.origin
    a = rel @ ax.direction
    x, y = rel @ E[:, 0], rel @ E[:, 1]
    r = np.hypot(x, y)
    keep = (np.abs(a) <= ax.span / 2 + 1e-6) & (r >= r_lo) & (r <= r_hi)
    return np.arctan2(y[keep], x[keep])


def _in_frame_of(A, B, pts, Ts):
    """Points of body B (rest world) as seen in body A's rest frame in a posed state."""
    if Ts is None:
        return pts
    M = np.linalg.inv(Ts[A]) @ Ts[B]
    return pts @ M[:3, :3].T + M[:3, 3]


def _inside(s, intervals):
    out = np.zeros(len(s), bool)
    for a0, a1 in intervals:
        out |= (s >= a0) & (s <= a1)
    return out


def _close_pairs(pa, pb, thr, ta=None):
    """Pairs (i, j) of points of ``pa`` and ``pb`` closer than ``thr``: each point with its
    nearest partner (both ways) -- enough to see every point that has a close partner, and far
    fewer pairs than all of them (the final trims and the checks see the exact solids).
    ``ta``: a ``cKDTree`` of ``pa`` already built (``pa`` is the fixed side of many calls)."""
    from scipy.spatial import cKDTree
    if len(pa) == 0 or len(pb) == 0:
        return np.zeros(0, int), np.zeros(0, int)
    lo, hi = pb.min(axis=0), pb.max(axis=0)
    if np.any(pa.min(axis=0) > hi + thr) or np.any(pa.max(axis=0) < lo - thr):
        return np.zeros(0, int), np.zeros(0, int)      # the two point sets are farther apart than thr
    ta = cKDTree(pa) if ta is None else ta
    tb = cKDTree(pb)
    d1, j1 = tb.query(pa, k=1, distance_upper_bound=thr)
    d2, i2 = ta.query(pb, k=1, distance_upper_bound=thr)
    a = np.isfinite(d1)
    b = np.isfinite(d2)
    ii = np.concatenate([np.nonzero(a)[0], i2[b]]).astype(int)
    jj = np.concatenate([j1[a], np.nonzero(b)[0]]).astype(int)
    return ii, jj


def _close_pairs_posed(pa, pb, Ms, thr, ta=None, tb=None):
    """:func:`_close_pairs` of ``pa`` and ``pb`` moved by each rigid 4x4 ``M`` of ``Ms`` (``None``:
    not moved): ``[(ii, jj)]``, one per ``M``, in two tree queries in all.  ``pa`` is queried in
    ``pb``'s own frame (moved back by ``M``'s inverse), so neither tree is built per pose;
    ``ta``/``tb``: trees of ``pa``/``pb`` already built."""
    from scipy.spatial import cKDTree
    empty = (np.zeros(0, int), np.zeros(0, int))
    if len(pa) == 0 or len(pb) == 0 or not Ms:
        return [empty] * len(Ms)
    ta = cKDTree(pa) if ta is None else ta
    tb = cKDTree(pb) if tb is None else tb
    na, nb = len(pa), len(pb)
    PB = np.concatenate([pb if M is None else pb @ M[:3, :3].T + M[:3, 3] for M in Ms])
    PA = np.concatenate([pa if M is None else (pa - M[:3, 3]) @ M[:3, :3] for M in Ms])
    # only points within thr of the other set's box can have a partner: query those alone
    alo, ahi = pa.min(axis=0) - thr, pa.max(axis=0) + thr
    blo, bhi = pb.min(axis=0) - thr, pb.max(axis=0) + thr
    qb = np.nonzero(np.all((PB >= alo) & (PB <= ahi), axis=1))[0]
    qa = np.nonzero(np.all((PA >= blo) & (PA <= bhi), axis=1))[0]
    d1, j1 = np.full(len(PA), np.inf), np.full(len(PA), nb)
    d2, i2 = np.full(len(PB), np.inf), np.full(len(PB), na)
    if len(qb):
        d2[qb], i2[qb] = ta.query(PB[qb], k=1, distance_upper_bound=thr)
    if len(qa):
        d1[qa], j1[qa] = tb.query(PA[qa], k=1, distance_upper_bound=thr)
    out = []
    for k in range(len(Ms)):
        e1, f1 = d1[k * na:(k + 1) * na], j1[k * na:(k + 1) * na]
        e2, g2 = d2[k * nb:(k + 1) * nb], i2[k * nb:(k + 1) * nb]
        a, b = np.isfinite(e1), np.isfinite(e2)
        if not a.any() and not b.any():
            out.append(empty)
            continue
        out.append((np.concatenate([np.nonzero(a)[0], g2[b]]).astype(int),
                    np.concatenate([f1[a], np.nonzero(b)[0]]).astype(int)))
    return out


def _relative(A, B, Ts):
    """4x4 taking body B's rest frame to body A's in a posed state (None at rest)."""
    return None if Ts is None else np.linalg.inv(Ts[A]) @ Ts[B]


def _trim_radius(ax: HingeAxis, samples, state_T, t, c, h, s, notes) -> float:
    """Radius around the axis inside which only the knuckle's own body has material.

    In every state (bodies posed relative to each other), every pair of slab points of two
    bodies of the axis closer than ``t + c`` (mid-plane distance, plus the sampling step)
    must lose one of its points: a point is removed when it lies on another body's stretch
    of the axis and within the trim radius."""
    base = ax.R + c
    cap = ax.R + c + 0.5 * s
    thr = t + c + h
    need = 0.0
    states = state_T or [("rest", None)]
    near = {}
    for bn in ax.bodies:
        a, r = _axis_coords(ax.origin, ax.direction, samples[bn])
        keep = (np.abs(a) <= ax.span / 2 + thr) & (r <= cap + thr)
        near[bn] = (samples[bn][keep], a[keep], r[keep], ~_inside(a[keep], ax.intervals[bn]))
    from scipy.spatial import cKDTree
    trees = {bn: cKDTree(near[bn][0]) for bn in ax.bodies if len(near[bn][0])}
    for i, A in enumerate(ax.bodies):
        for B in ax.bodies[i + 1:]:
            pa, sa, ra, ea = near[A]
            pb, sb_, rb, eb = near[B]
            for ii, jj in _close_pairs_posed(pa, pb, [_relative(A, B, Ts) for _, Ts in states], thr,
                                             trees.get(A), trees.get(B)):
                if len(ii) == 0:
                    continue
                req = np.minimum(np.where(ea[ii], ra[ii], np.inf), np.where(eb[jj], rb[jj], np.inf))
                req = req[np.isfinite(req)]
                if len(req):
                    need = max(need, float(req.max()) + h)
    rho = max(base, need)
    if rho > cap:
        notes.append(f"hinge {ax.name}: slabs stay close far from the axis; trim radius capped at "
                     f"{cap:.3g} mm (needs {rho:.3g} mm)")
        rho = cap
    return float(rho)


def _axis_frame(ax: HingeAxis, slabs) -> np.ndarray:
    """A frame on a hinge axis that turns with its bodies: z along the axis, x the owner's first
    slab's first in-plane direction made perpendicular to it (the same for congruent hinges,
    whatever their orientation in the world)."""
    d = ax.direction
    R0 = slabs[ax.owner][0].R
    for k in range(3):
        x = R0[:, k] - np.dot(R0[:, k], d) * d
        if np.linalg.norm(x) > 0.1:
            break
    x = x / np.linalg.norm(x)
    return _frame(ax.origin, np.column_stack([x, np.cross(d, x), d]))


def _frame(origin, R) -> np.ndarray:
    F = np.eye(4)
    F[:3, :3] = R
    F[:3, 3] = origin
    return F


def _rel_keys(F, A, B, state_T) -> tuple:
    """Pose keys of B's motion relative to A in every state, seen in the frame ``F``."""
    Fi = np.linalg.inv(F)
    return tuple(pose_key(Fi @ np.linalg.inv(Ts[A]) @ Ts[B] @ F) for _, Ts in state_T)


def _congruence_frames(asm: "Assembly", slabs) -> list:
    """A frame per part that congruent parts share: a body's first slab (its world orientation
    and centre; the body's own frame is arbitrary with respect to its slabs), a joint part's
    frame of its two pin axes."""
    out = part_frames(asm)
    for k, p in enumerate(asm.parts):
        if p.kind == "body" and slabs.get(p.name):
            sb = slabs[p.name][0]
            out[k] = _frame(sb.center, sb.R)
    return out


def _trim_radius_memo(memo, ax: HingeAxis, samples, state_T, t, c, h, s, notes, slabs=None) -> float:
    """:func:`_trim_radius`, computed once per congruent hinge (``memo``: a dict, or None): the
    same knuckle layout, the same slab samples in the axis frame and the same relative poses."""
    if memo is None:
        return _trim_radius(ax, samples, state_T, t, c, h, s, notes)
    F = _axis_frame(ax, slabs)
    key = ("hinge", round(ax.span, 9), round(ax.R, 9), t, c, h, s,
           tuple((tuple(np.round(np.asarray(ax.intervals[bn], float).ravel(), 9).tolist()),
                  points_key(samples[bn], F)) for bn in ax.bodies),
           tuple(_rel_keys(F, A, B, state_T) for i, A in enumerate(ax.bodies) for B in ax.bodies[i + 1:]))
    if key not in memo:
        mine: list = []
        rho = _trim_radius(ax, samples, state_T, t, c, h, s, mine)
        memo[key] = (rho, [x.replace(ax.name, "\0") for x in mine])
    rho, extra = memo[key]
    notes += [x.replace("\0", ax.name) for x in extra]
    return rho


def _share_hinge_radii(axes, samples, slabs) -> None:
    """Congruent hinges (the same knuckles and the same slabs about the axis, as built) get the
    largest trim radius any of them needs: a larger radius only trims more, and the parts of
    congruent connector half units stay congruent, so their exact tests are shared."""
    groups: dict = {}
    for ax in axes:
        F = _axis_frame(ax, slabs)
        key = (round(ax.span, 9), round(ax.R, 9),
               tuple((tuple(np.round(np.asarray(ax.intervals[bn], float).ravel(), 9).tolist()),
                      points_key(samples[bn], F)) for bn in ax.bodies))
        groups.setdefault(key, []).append(ax)
    for members in groups.values():
        rho = max(ax.rho for ax in members)
        for ax in members:
            ax.rho = rho


def _share_ujoint_radii(ujoints, samples, slabs) -> None:
    """Each side of congruent universal joints (the same yoke layouts and the same slabs of that
    side's body about the joint, as built) gets the largest trim radius any of them needs on that
    side.  The other body does not enter the key: the bends of a routed chain differ from
    junction to junction, and a larger radius only trims more."""
    for side in (0, 1):
        groups: dict = {}
        for uj in ujoints:
            bn = uj.bodies[side]
            R = slabs[bn][0].R
            F = _frame(uj.center, R)
            lay = tuple((x.mode, tuple(np.round(np.asarray(x.own + x.caps + [x.pin, x.cut, x.plate], float).ravel(),
                                                9).tolist())) for x in uj.layouts)
            key = (side, lay, round(uj.hub, 9), round(uj.R, 9), points_key(samples[bn], F),
                   tuple(np.round(R.T @ uj.axes[side] / 1e-7).astype(np.int64).tolist()))
            groups.setdefault(key, []).append(uj)
        for members in groups.values():
            r = max(u.rho[side] for u in members)
            for uj in members:
                uj.rho = (r, uj.rho[1]) if side == 0 else (uj.rho[0], r)


def _ujoint_trim_memo(memo, uj: UJoint, samples, state_T, t, c, h):
    """:func:`_ujoint_trim`, computed once per congruent universal joint (``memo``: a dict, or None)."""
    if memo is None:
        return _ujoint_trim(uj, samples, state_T, t, c, h)
    F = _frame(uj.center, _ortho(uj.axes[0], uj.axes[1]))
    lay = tuple((x.mode, tuple(np.round(np.asarray(x.own + x.caps + [x.pin, x.cut, x.plate], float).ravel(),
                                        9).tolist())) for x in uj.layouts)
    C, O = uj.bodies
    key = ("ujoint", lay, round(uj.hub, 9), round(uj.R, 9), tuple(round(r, 9) for r in uj.rho), t, c, h,
           points_key(samples[C], F), points_key(samples[O], F),
           _rel_keys(F, C, O, state_T or [("rest", {C: np.eye(4), O: np.eye(4)})]))
    if key not in memo:
        memo[key] = _ujoint_trim(uj, samples, state_T, t, c, h)
    return memo[key]


#: large assemblies (reuse): a body that the trims of its joints leave in several pieces is rebuilt
#: with their radii shrunk; this many bisection steps between the least radii and the sampled ones
UNSPLIT_STEPS = 5
#: ... and first with its hinges' radii kept whole, its universal joints' alone shrunk; both only where
#: that still splits it (session 63: the robot's g2_out_lo, its pivot's cut shrunk with its coupling
#: junction's, met g2_out_hi)
UNSPLIT_JOINTS_FIRST = True


def _toward(least: float, rho: float, f: float) -> float:
    """A trim radius ``f`` of the way from ``least`` (what keeps the knuckles, hub and yokes of the
    joint clear) to the sampled ``rho`` (``f`` = 1: ``rho`` itself, as before session 50)."""
    return rho if f >= 1.0 or rho <= least else least + f * (rho - least)


class _Unsplit:
    """The trim-radius fraction ``f`` a body is built with (session 50, issue 13).

    The sampled trim radii of a hinge or universal joint clear the other bodies' slabs in every
    logic state; where those slabs pass close far from the joint (the robot's coupling chains,
    whose half units the skeleton bends), the radii reach across the whole slab (4.9 mm on a slab
    4.5 mm long) and leave only the knuckles, each a piece of its own.  A body of a large
    assembly (reuse) that comes out in several pieces is rebuilt with every trim radius of its
    own joints ``f`` of the way from the least one that keeps the knuckles clear to the sampled
    one: ``f`` = 0, then a bisection (:data:`UNSPLIT_STEPS`) for the largest ``f`` that keeps it in
    one piece; if even ``f`` = 0 splits it, it is built as before.  What the smaller radii leave
    close is left to the final trims (:func:`_resolve`, which never keep a split) and the
    ``states`` check.  A body whole at the sampled radii is built exactly as before; so is
    every body of a mechanism of its own (the library gates).

    With ``UNSPLIT_JOINTS_FIRST`` and universal joints on the body (``joints``), the search runs
    first on those joints' radii alone, its hinges' kept at the sampled ones (``f_axes`` 1: a
    lever's pivot cut stays whole where its coupling junction's shrinks), and on both only if the
    joints' least radii still leave it in pieces."""

    def __init__(self, reuse, joints: bool = False):
        self.on = bool(reuse) and UNSPLIT_STEPS > 0
        self.f, self.lo, self.hi, self.tries, self.final = 1.0, None, 1.0, 0, False
        self.joints_first = bool(joints) and UNSPLIT_JOINTS_FIRST
        self.axes_full = False      # the hinges' radii kept at f = 1 (the first search)

    @property
    def f_axes(self) -> float:
        """The fraction the body's hinges' trim radii are built with."""
        return 1.0 if self.axes_full else self.f

    def done(self, pieces: int) -> bool:
        """Whether the body just built (``pieces``, built at ``self.f``) is kept; else ``self.f``
        is the next fraction to try."""
        split = pieces > 1
        if not self.on or self.final or (self.f == 1.0 and not split):
            return True
        self.tries += 1
        if split:
            self.hi = self.f
        else:
            self.lo = self.f
        if self.lo is None:
            # f = 1 splits: try the least radii (the joints' alone first); if they split it too,
            # both, then build it as before
            if self.f == 1.0:
                self.f, self.axes_full = 0.0, self.joints_first
            elif self.axes_full:
                self.f, self.axes_full, self.hi, self.tries = 0.0, False, 1.0, 1
            else:
                self.f, self.final = 1.0, True
            return False
        if self.tries > UNSPLIT_STEPS:
            if self.f == self.lo:
                return True
            self.f, self.final = self.lo, True
            return False
        self.f = 0.5 * (self.lo + self.hi)
        return False


def _drop_scraps(solid: mf.Manifold, keep: mf.Manifold, bn: str, notes: list) -> mf.Manifold:
    """A body left in several pieces by the clearance cuts (a post on a hinge line cut off
    by the trim around the next knuckle, at a chain's open end) keeps its largest piece and
    every piece with knuckle or pin material; scraps under 5 % of its volume are dropped, with
    a note.  A body in one piece is returned as it is."""
    comps = solid.decompose()
    if len(comps) < 2:
        return solid
    total = sum(x.volume() for x in comps)
    big = max(comps, key=lambda x: x.volume())
    out, dropped = [], 0.0
    for x in comps:
        if x is big or x.volume() >= 0.05 * total or (x ^ keep).volume() > 1e-9:
            out.append(x)
        else:
            dropped += x.volume()
    if not dropped:
        return solid
    notes.append(f"{bn}: dropped {len(comps) - len(out)} scrap(s) of {dropped:.3g} mm^3 cut off by the clearance "
                 f"around a joint")
    return union(out)


def _host_axis(bn, axes, center, s, g):
    """The hinge axis of body ``bn`` whose line passes through the joint point ``center`` (mm)
    beyond the end of its knuckles (a connector junction), or None."""
    for ax in axes:
        if bn not in ax.bodies or ax.joint is not None:
            continue
        rel = center - ax.origin
        a = float(np.dot(rel, ax.direction))
        if np.linalg.norm(rel - a * ax.direction) < _TOL * s and abs(a) > ax.span / 2 + g:
            return ax
    return None


def _never(*_) -> bool:
    return False


def _posed_points(pts, hosts, Ts) -> np.ndarray:
    """Points (mm, rest world; ``hosts[i]``: the body point ``i`` is fixed in) in each pose of
    ``Ts`` (body -> 4x4; ``None``: at rest): an array ``(len(Ts), len(pts), 3)``."""
    pts = np.asarray(pts, float).reshape(-1, 3)
    out = []
    for T in Ts:
        if T is None:
            out.append(pts.copy())
            continue
        Rs = np.array([T[h][:3, :3] for h in hosts])
        out.append(np.einsum("nij,nj->ni", Rs, pts) + np.array([T[h][:3, 3] for h in hosts]))
    return np.stack(out)


def _far_clear(ax: HingeAxis, side, a0, a1, axes, slabs, state_T, t, c, posed_mid: list, kmin=None,
               g: float = 0.0, notes: list | None = None) -> bool:
    """Whether the knuckle stack of ``ax`` may grow on its ``side`` (+-1 along its direction)
    from ``a0`` to ``a1`` (mm from its origin): its bodies' slabs lie along the axis (a hinge in
    their plane, not across a plate), and no other hinge's stack (of bodies other than
    ``ax``'s) comes within both knuckle radii plus the clearance of that stretch, at rest or in
    any pose of ``state_T`` (both stacks sampled every quarter clearance along their axes); where
    the axes do come that near (in a chain, the previous half unit's stack, end to end with this
    one), with ``STACK_CYLINDERS`` the two solid knuckle cylinders themselves must keep the
    clearance (:func:`_cylinder_points` of each against :func:`_cylinder_distance` to the other).
    ``posed_mid``: an empty list the first time, then every hinge's midpoint in every pose (a
    prefilter, computed once per build and moved with each yield).

    With ``YIELD_ENDS`` and ``kmin`` (the shortest knuckle allowed, the minimum wall) an ordinary
    hinge (no joint part in its stack) whose cylinder is what keeps the stack short yields: its
    end facing the stretch moves back along its axis, every knuckle of its stack shortened alike
    (knuckle gaps ``g``), by the least multiple of ``YIELD_STEP`` that clears in every pose, down
    to knuckles of ``kmin``.  The hinges are changed (``span``, ``origin``, ``intervals``,
    ``knuckle``; a line in ``notes``) only when the stack may grow."""
    for bn in ax.bodies:
        if not any(e1 - e0 >= 0.9 * ax.scene_span for e0, e1 in _slab_extents_along(slabs[bn], ax, t)):
            return False
    Ts = [None] + [T for _, T in state_T]
    if not posed_mid:
        mids = np.array([bx.origin for bx in axes], float)
        hosts = [bx.bodies[0] for bx in axes]
        posed_mid.append(_posed_points(mids, hosts, Ts))
    d = np.asarray(ax.direction, float)
    p0 = np.asarray(ax.origin, float) + side * a0 * d
    p1 = np.asarray(ax.origin, float) + side * a1 * d
    step = 0.25 * c if c > 0 else 0.05
    P = p0 + np.linspace(0.0, 1.0, int(np.ceil(abs(a1 - a0) / step)) + 2)[:, None] * (p1 - p0)
    host = ax.bodies[0]
    pm = 0.5 * (p0 + p1)
    reach = 0.5 * abs(a1 - a0) + 2 * max(bx.R for bx in axes) + c + 0.5 * np.array([bx.span for bx in axes])
    near = set()
    for k, q in enumerate(_posed_points(pm, [host], Ts)[:, 0]):
        near.update(np.nonzero(np.linalg.norm(posed_mid[0][k] - q, axis=1) < reach)[0].tolist())
    yields: dict = {}       # id(hinge) -> (hinge, end (+-1 along it), mm): applied if the stack may grow
    for i in sorted(near):
        bx = axes[i]
        if bx is ax or set(bx.bodies) & set(ax.bodies):
            continue
        e = np.asarray(bx.direction, float)
        o = np.asarray(bx.origin, float)
        q0, q1 = o - 0.5 * bx.span * e, o + 0.5 * bx.span * e
        if _stacks_clear(ax, bx, p0, p1, P, q0, q1, Ts, host, step, c):
            continue
        nk = len(bx.layout)
        if not (YIELD_ENDS and STACK_CYLINDERS and kmin is not None and bx.joint is None and nk >= 2):
            return False
        end = 1.0 if np.linalg.norm(q1 - pm) < np.linalg.norm(q0 - pm) else -1.0
        most = nk * (bx.knuckle - kmin)
        for m in range(1, int(np.floor(most / YIELD_STEP + 1e-9)) + 1):
            dl = m * YIELD_STEP
            y0, y1 = (q0, q1 - dl * e) if end > 0 else (q0 + dl * e, q1)
            if _stacks_clear(ax, bx, p0, p1, P, y0, y1, Ts, host, step, c):
                yields[id(bx)] = (i, bx, end, dl)
                break
        else:
            return False
    for i, bx, end, dl in yields.values():
        nk = len(bx.layout)
        bx.span -= dl
        bx.origin = np.asarray(bx.origin, float) - 0.5 * end * dl * np.asarray(bx.direction, float)
        # the prefilter's midpoints move with it: a later stack near this hinge's other end must
        # still find it (its reach takes the new, shorter span)
        posed_mid[0][:, i] = _posed_points(bx.origin, [bx.bodies[0]], Ts)[:, 0]
        bx.knuckle = (bx.span - (nk - 1) * g) / nk
        bx.intervals = {bn: [] for bn in bx.bodies}
        for j, bn in enumerate(bx.layout):
            a_ = -bx.span / 2 + j * (bx.knuckle + g)
            bx.intervals[bn].append((a_, a_ + bx.knuckle))
        if notes is not None:
            notes.append(f"hinge {bx.name}: its end yields {dl:.3g} mm to the grown stack of {ax.name} "
                         f"(knuckles {bx.knuckle:.3g} mm)")
    return True


def _stacks_clear(ax: HingeAxis, bx: HingeAxis, p0, p1, P, q0, q1, Ts, host, step, c) -> bool:
    """Whether the stretch ``p0``-``p1`` of ``ax``'s stack (samples ``P``) keeps the clearance ``c``
    from ``bx``'s stack, the knuckle cylinder ``q0``-``q1``, at rest and in every pose ``Ts``
    (:func:`_far_clear`)."""
    e = (q1 - q0) / np.linalg.norm(q1 - q0)
    L = float(np.linalg.norm(q1 - q0))
    Q = q0 + np.linspace(0.0, L, int(np.ceil(L / step)) + 2)[:, None] * e
    lim = ax.R + bx.R + c
    S_own = S_other = None      # the cylinders' surface points, made when first needed
    fine_pts = None             # both cylinders' points five times finer (FINE_GAPS), made when first needed
    for T in Ts:
        M = _relative(host, bx.bodies[0], T)
        Qm = Q if M is None else Q @ M[:3, :3].T + M[:3, 3]
        if np.min(np.linalg.norm(P[:, None, :] - Qm[None, :, :], axis=2)) >= lim:
            continue            # the axes farther apart than both radii and the clearance
        if not STACK_CYLINDERS:
            return False
        # the two solid cylinders (the grown stretch, the other stack), each one's surface
        # points against the other: at least the clearance apart, plus the sampling's reach
        # (a surface point is within step / sqrt(2) of a sample)
        if S_other is None:
            S_own = _cylinder_points(p0, p1, ax.R, step)
            S_other = _cylinder_points(q0, q1, bx.R, step)
        Mi = None if M is None else np.linalg.inv(M)

        def gap(a, b):
            mine = a if Mi is None else a @ Mi[:3, :3].T + Mi[:3, 3]
            theirs = b if M is None else b @ M[:3, :3].T + M[:3, 3]
            return min(_cylinder_distance(mine, q0, q1, bx.R).min(), _cylinder_distance(theirs, p0, p1, ax.R).min())
        d_ = gap(S_own, S_other)
        if d_ < c + step / np.sqrt(2):
            # sampled nearer than the clearance and the sampling's reach: at least as near as
            # sampled; between the two, sampled again five times finer (FINE_GAPS)
            if not FINE_GAPS or d_ < c:
                return False
            fine = step / 5
            if fine_pts is None:
                fine_pts = (_cylinder_points(p0, p1, ax.R, fine), _cylinder_points(q0, q1, bx.R, fine))
            if gap(*fine_pts) < c + fine / np.sqrt(2):
                return False
    return True


def _knuckles_at_plates(ujoints, uj_plates, state_T, need, h) -> set:
    """(KNUCKLE_PLATES) ``{(joint, mode)}``: the compound junctions whose other body's yoke, on
    both sides of the hub, has its knuckles on one side only within ``need`` (mm: knuckle radius,
    half the plate thickness and the clearance) of the yoke plates of another joint on another
    body in some posed state (``state_T``), and the one-sided mode that keeps the other side.
    Knuckles: points on the pin at each knuckle's ends and middle; plates: the boxes of
    ``uj_plates`` (``(body, joint, box)``) sampled every ``h`` mm on their mid-planes."""
    from scipy.spatial import cKDTree
    items = []                 # (joint, body, points (k, 3), signs (k,))
    for uj in ujoints:
        lay = uj.layouts[1]
        if uj.host is None or lay.mode != "both":
            continue
        r = np.array([x for a0, a1 in lay.own for x in (a0, 0.5 * (a0 + a1), a1)])
        items.append((uj, uj.bodies[1], uj.center + np.outer(r, uj.axes[1]), np.sign(r)))
    if not items or not uj_plates:
        return set()
    P = [(bn, uj, _slab_samples([sb], h)) for bn, uj, sb in uj_plates]
    P = [(bn, uj, q) for bn, uj, q in P if len(q)]
    if not P:
        return set()
    owner = np.concatenate([np.full(len(q), k) for k, (_, _, q) in enumerate(P)])
    bad: dict = {}
    for _, Ts in state_T:
        if Ts is None:
            continue
        Q = np.concatenate([q @ Ts[bn][:3, :3].T + Ts[bn][:3, 3] for bn, _, q in P])
        tree = cKDTree(Q)
        for uj, bn, K, sg in items:
            Kp = K @ Ts[bn][:3, :3].T + Ts[bn][:3, 3]
            for k, near in enumerate(tree.query_ball_point(Kp, need)):
                if any(P[owner[i]][0] != bn and P[owner[i]][1] is not uj for i in near):
                    bad.setdefault(uj.name, set()).add(sg[k])
    return {(jn, "+" if sides == {-1.0} else "-") for jn, sides in bad.items() if len(sides) == 1 and 0.0 not in sides}


def _grown_near(grown_axes, far, shapes, axes, ujoints, slabs, state_T, reach, t, c) -> list:
    """The grown stacks (of ``grown_axes``; ``far``: ``{id(axis): (a0, a1)}``, the stretch each
    grew into, mm from its origin) whose new material comes nearer than the clearance ``c`` to a
    body other than the stack's own, at rest or in a pose of ``state_T``.  The new material: the
    knuckle cylinders over that stretch and the plates widening each body's slabs over it
    (:func:`_yoke_plates`), as surface points every ``c / 2`` (a surface point within
    ``c / (2 sqrt 2)`` of one).  The other bodies: their slab boxes and yoke plates (``shapes``,
    before any trim, so on the safe side) and their knuckles (hinges' and universal joints'
    yokes), as solids measured exactly.  A stack's growth is tested against other stacks' axes
    as it is laid out (:func:`_far_clear`); the plates come after every junction is laid out,
    and past the span of another hinge of the same body no trim clears them (the README circuit
    with ``STACK_CYLINDERS``: a half unit's slab DA widened to its grown stack D came 0.10-0.16
    mm from its hinge-A partner AB past that hinge's span, 60 such pairs; session 59).  Not
    tested: the universal joints' own parts (ball hubs, collars)."""
    step = 0.5 * c if c > 0 else 0.05
    need = c + step / np.sqrt(2)
    cyl: dict = {bn: [] for bn in shapes}
    for ax in axes:
        for bn, ivs in ax.intervals.items():
            cyl[bn] += [(ax.origin + a0 * ax.direction, ax.origin + a1 * ax.direction, ax.R) for a0, a1 in ivs]
    for uj in ujoints:
        for side, bn in enumerate(uj.bodies):
            lay = uj.layouts[side]
            cyl[bn] += [(uj.center + a0 * uj.axes[side], uj.center + a1 * uj.axes[side], lay.r_own or uj.R)
                        for a0, a1 in lay.own]
    names = list(shapes)
    # each body's bounding sphere (rest, mm): a prefilter in every pose
    ctr, rad = np.zeros((len(names), 3)), np.zeros(len(names))
    for i, bn in enumerate(names):
        P = [_box_corners(sb) for sb in shapes[bn]] + [np.array([p0, p1]) for p0, p1, _ in cyl[bn]]
        P = np.concatenate(P) if P else np.zeros((1, 3))
        ctr[i] = 0.5 * (P.min(axis=0) + P.max(axis=0))
        rad[i] = np.linalg.norm(P - ctr[i], axis=1).max() + max([r for *_, r in cyl[bn]], default=0.0)
    # ... and each of its shapes' (a prefilter within the body): ``(centres, radii, kinds)``
    each: dict = {}
    for bn in names:
        C = [sb.center for sb in shapes[bn]] + [0.5 * (p0 + p1) for p0, p1, _ in cyl[bn]]
        rr = [0.5 * float(np.linalg.norm(sb.size)) for sb in shapes[bn]] + \
             [0.5 * float(np.linalg.norm(p1 - p0)) + r for p0, p1, r in cyl[bn]]
        each[bn] = (np.array(C, float).reshape(-1, 3), np.array(rr, float), len(shapes[bn]))
    Ts = [None] + [T for _, T in state_T]
    posed = [ctr if T is None else np.einsum("nij,nj->ni", np.array([T[b][:3, :3] for b in names]), ctr)
             + np.array([T[b][:3, 3] for b in names]) for T in Ts]
    def near(ax, bn, X, need=need) -> bool:
        """Whether the points ``X`` (body ``bn``'s rest frame) come within ``need`` of a body
        other than those of ``ax``, at rest or in a pose."""
        xc = 0.5 * (X.min(axis=0) + X.max(axis=0))
        xr = float(np.linalg.norm(X - xc, axis=1).max())
        for k, T in enumerate(Ts):
            q = xc if T is None else T[bn][:3, :3] @ xc + T[bn][:3, 3]
            for i in np.nonzero(np.linalg.norm(posed[k] - q, axis=1) < rad + xr + need)[0]:
                ob = names[i]
                if ob in ax.bodies:
                    continue
                M = _relative(ob, bn, T)
                yc = xc if M is None else M[:3, :3] @ xc + M[:3, 3]
                C, rr, nb = each[ob]
                hit = np.nonzero(np.linalg.norm(C - yc, axis=1) < rr + xr + need)[0]
                if not len(hit):
                    continue            # no shape of ob within reach of the points' sphere
                Y = X if M is None else X @ M[:3, :3].T + M[:3, 3]
                if min([_box_distance(Y, shapes[ob][j]).min() if j < nb else
                        _cylinder_distance(Y, *cyl[ob][j - nb]).min() for j in hit]) < need:
                    return True
        return False

    def points(ax, bn, step_):
        a0, a1 = far[id(ax)]
        return np.concatenate([_cylinder_points(ax.origin + a0 * ax.direction, ax.origin + a1 * ax.direction, ax.R,
                                                step_)]
                              + [_box_points(sb, step_) for sb in _grown_plates(bn, slabs[bn], ax, (a0, a1), reach, t)])

    fine = step / 5
    out = []
    for ax in grown_axes:
        # sampled nearer than the clearance and the sampling's reach: at least as near as sampled;
        # between the two, sampled again five times finer (FINE_GAPS)
        for bn in ax.bodies:
            X = points(ax, bn, step)
            if near(ax, bn, X) and (not FINE_GAPS or near(ax, bn, X, c)
                                    or near(ax, bn, points(ax, bn, fine), c + fine / np.sqrt(2))):
                out.append(ax)
                break
    return out


def _grown_plates(bn, sbs, ax: HingeAxis, far, reach, t) -> list:
    """The plates (:func:`_yoke_plates`) widening the slabs ``sbs`` of body ``bn`` over the stretch
    ``far`` (mm from its origin) that the stack of ``ax`` grew into, if a knuckle of ``bn`` lies
    there: out from the axis to the knuckles' radius and a slab thickness, no farther.  Plates as
    long as the slab (before session 59) ran past the body's other hinges' spans, where no trim
    clears them: a half unit's DA, widened to its grown stack D, came 0.16 mm from AB's material
    past hinge A (AB's own plate to its grown stack B lies over the same stretch)."""
    if not any(k0 < far[1] and k1 > far[0] for k0, k1 in ax.intervals.get(bn, [])):
        return []       # none of its knuckles there: the plate would be a tab beside the other's knuckle
    return _yoke_plates(sbs, ax.origin, ax.direction, [far], min(reach, ax.R + t), t)


def _box_points(sb: SlabBox, step: float) -> np.ndarray:
    """Points on the surface of a slab box, at most ``step`` (mm) apart on each face."""
    out = []
    for i in range(3):
        j, k = [x for x in range(3) if x != i]
        u = np.linspace(-0.5, 0.5, max(2, int(np.ceil(sb.size[j] / step)) + 1)) * sb.size[j]
        v = np.linspace(-0.5, 0.5, max(2, int(np.ceil(sb.size[k] / step)) + 1)) * sb.size[k]
        a, b = np.meshgrid(u, v, indexing="ij")
        for sgn in (-0.5, 0.5):
            loc = np.zeros((a.size, 3))
            loc[:, i] = sgn * sb.size[i]
            loc[:, j], loc[:, k] = a.ravel(), b.ravel()
            out.append(sb.center + loc @ sb.R.T)
    return np.concatenate(out)


def _box_distance(X, sb: SlabBox) -> np.ndarray:
    """Distance (mm) of the points ``X`` from the solid slab box (0 inside)."""
    q = np.abs((X - sb.center) @ sb.R) - 0.5 * sb.size
    return np.linalg.norm(np.maximum(q, 0.0), axis=1)


def _cylinder_points(p0, p1, R: float, step: float) -> np.ndarray:
    """Points on the surface of the solid cylinder of radius ``R`` (mm) about the segment
    ``p0``-``p1``: rings every ``step`` along it and across both end faces, points every ``step``
    round each ring."""
    p0, p1 = np.asarray(p0, float), np.asarray(p1, float)
    d = p1 - p0
    L = float(np.linalg.norm(d))
    d = d / L
    U = _perp_frame(d)[:, :2]
    out = []
    for r, ts in [(R, np.linspace(0.0, 1.0, int(np.ceil(L / step)) + 1))] + \
            [(r, np.array([0.0, 1.0])) for r in np.arange(0.0, R, step)]:
        n = max(int(np.ceil(2 * np.pi * r / step)), 1)
        a = 2 * np.pi * np.arange(n) / n
        ring = r * (np.cos(a)[:, None] * U[:, 0] + np.sin(a)[:, None] * U[:, 1])
        out.append((p0[None, None] + ts[:, None, None] * (p1 - p0)[None, None] + ring[None]).reshape(-1, 3))
    return np.concatenate(out)


def _cylinder_distance(X, p0, p1, R: float) -> np.ndarray:
    """Distance (mm) of the points ``X`` from the solid cylinder of radius ``R`` about the
    segment ``p0``-``p1`` (0 inside)."""
    p0, p1 = np.asarray(p0, float), np.asarray(p1, float)
    d = p1 - p0
    L = float(np.linalg.norm(d))
    d = d / L
    a = (X - p0) @ d
    r = np.linalg.norm((X - p0) - a[:, None] * d, axis=1)
    return np.hypot(np.maximum(r - R, 0.0), np.maximum(np.maximum(-a, a - L), 0.0))


def _compound(ax: HingeAxis, center, host_body, other, axes, s, prof, R, r_pin, kmin, others=None, o_cos=0.5,
              far_ok=None):
    """A compound junction on hinge axis ``ax``: the universal joint part holds the pin of the
    whole knuckle stack and has one knuckle in it (next to the end knuckle of the pin owner,
    on the joint's side, so the stack is captive), a ball hub at the joint point with a collar
    down to the stack, and the second pin (the other body's yoke) through the ball.

        [owner | b2 .. | joint | owner] gap [collar + ball hub]   (along the axis, in mm)

    Relative to the bodies of ``ax`` the joint turns about the axis only (collar and stack
    stay coaxial); relative to ``other`` it turns about the second pin only, and the ball is
    the same in every such turn, so it keeps its distance (>= clearance) from ``other``'s own
    knuckles on the same line (the next layer's hinge: a hinge of ``other``, or of one of
    ``others``, through the joint point within ``o_cos`` (cosine) of the axis; a branch page
    whose hinge leaves the joint point 30 degrees off the axis is not one, session 49).
    Returns None when the ball would be
    thinner than the pin plus a minimum wall.

    Knuckles: ``kmin`` long (the minimum wall) when ``far_ok(ax, side, a0, a1)`` lets the stack
    grow on its far side from ``a0`` to ``a1`` (mm from ``ax.origin``); its end on the joint's side
    then stays where a stack of minimum-feature knuckles ends, so the collar, the ball and the
    yokes are that stack's, and the axis's origin moves by half the growth (``"origin"``,
    ``"grown"``).  Else (``far_ok`` None or false) knuckles of the minimum feature, as before
    session 57: four knuckles and three gaps in a 2.5 mm slab leave 0.5 mm at mjp, under its
    0.6 mm wall."""
    c, g = prof.clearance, prof.knuckle_gap
    a = float(np.dot(center - ax.origin, ax.direction))
    sg = 1.0 if a > 0 else -1.0
    blist = ax.bodies
    stack = ([blist[0]] + blist[1:] + [None] + [blist[0]]) if sg > 0 else ([blist[0], None] + blist[1:] + [blist[0]])
    nk = len(stack)
    L = ax.scene_span
    # knuckles of ``kmin`` (the minimum wall) where the stack may grow away from the joint: its
    # end on the joint's side stays where a stack of minimum-feature knuckles ends (so the collar,
    # the ball and the yokes are those of that stack) and the far end moves out, if no other
    # hinge's stack comes near that stretch in any pose (``far_ok``); else minimum-feature knuckles
    S0 = max(L, nk * min(kmin, prof.min_feature) + (nk - 1) * g)
    S = max(L, nk * kmin + (nk - 1) * g)
    if S > S0 + 1e-9 and (far_ok is None or not far_ok(ax, -sg, S0 / 2, S - S0 / 2)):
        S = S0
    k = (S - (nk - 1) * g) / nk
    shift = 0.5 * (S - S0)
    origin = ax.origin - sg * shift * ax.direction
    a = a + sg * shift
    intervals: dict = {bn: [] for bn in blist}
    joint_iv = ()
    for i, bn in enumerate(stack):
        a0 = -S / 2 + i * (k + g)
        if bn is None:
            joint_iv = (a0, a0 + k)
        else:
            intervals[bn].append((a0, a0 + k))
    d0 = abs(a) - S / 2                      # from the stack's end to the joint point
    dO = np.inf                              # ... and to the other body's own knuckles on this line
    o_axis = None
    o_body = None
    for bx in axes:
        if any(o in bx.bodies for o in (others or [other])) and abs(float(np.dot(bx.direction, ax.direction))) > o_cos:
            rel = center - bx.origin
            b = float(np.dot(rel, bx.direction))
            if np.linalg.norm(rel - b * bx.direction) < _TOL * s and abs(b) > bx.span / 2:
                if abs(b) - bx.span / 2 < dO:
                    dO, o_axis = abs(b) - bx.span / 2, bx
                    o_body = next(o for o in (others or [other]) if o in bx.bodies)
    hub_r = float(min(R, d0 - g, dO - c))
    if hub_r < r_pin + prof.min_wall:
        return None
    # the other body's yoke knuckles (radius R about the second pin, from +-v0 outwards) clear
    # the collar (axially, by the knuckle gap) and the corners of both stacks (by the clearance)
    v0 = hub_r + g
    for dd in (d0, dO):
        if np.isfinite(dd) and dd - R < c:
            v0 = max(v0, R + float(np.sqrt(c * c - max(0.0, dd - R) ** 2)))
    u = ax.direction * sg
    m = HOST_CUT_MARGIN * c
    lay = YokeLayout("host", [], [], (-(d0 + S), 0.0), (-(R + c + m), R + c + m), (0.0, 0.0), reach=max(d0 - g, hub_r))
    lay_c = lay
    # the stretch the stack grew into (mm from the new origin along the axis): past the far end
    # of the short stack, out to the grown stack's far end
    far = tuple(sorted((-sg * (S0 - S / 2), -sg * S / 2)))
    return {"axis": ax, "origin": origin, "grown": shift > 0, "far": far, "u": u.copy(), "span": S, "k": k,
            "intervals": intervals, "stack": stack,
            "joint_iv": joint_iv, "hub_r": hub_r, "collar": d0 - g, "hub_v": 2 * (v0 - g), "layout": lay,
            "o_axis": o_axis, "dO": dO, "layout_c": lay_c, "o_body": o_body}


def _branch_groups(joints, scene) -> dict:
    """Universal joints that share one point and one body (a connector branch: every page's
    junction on the source half unit): ``{joint: (shared body, [joints of the group])}``."""
    by: dict = {}
    for jname, bonds in joints.items():
        if bonds[0].kind != "universal":
            continue
        bd = bonds[0]
        p = 0.5 * (scene.site_world(bd.a) + scene.site_world(bd.b))
        key = tuple(np.round(p / _TOL).astype(np.int64).tolist())
        for bn in (bd.a.split(".")[0], bd.b.split(".")[0]):
            by.setdefault((bn, key), []).append(jname)
    out: dict = {}
    for (bn, _), members in by.items():
        if len(members) < 2 or any(m in out for m in members):
            continue
        for m in members:
            out[m] = (bn, list(members))
    return out


def _branch(members, S, joints, scene, bodies, axes, slabs, s, prof, R, r_pin, r_hole, kmin, t,
            base_samples, reach, memo, state_T, h, notes, far_ok=None):
    """A branch junction: the universal joints ``members`` of the pages of a connector branch,
    all at one point of the source body ``S``, as ONE joint part (their relative turns about
    the source's hinge line are the same: a page turns about that line with the source's
    half unit).  The part is a compound junction on ``S``'s hinge (its knuckle in the stack,
    ball hub, collar), with one second pin across it carrying every page's yoke knuckle, one
    knuckle per page, pages on the side of the pin where their arm leaves the joint, nearest
    first; the outermost knuckle of each side closes the pin's end (a blind hole), so every
    knuckle is held between the ball, its neighbours and that end:

        [end | page .. | page | ball | page | page .. | end]   (along the second pin)

    A page stacked on the source's hinge line (a chain's next layer) keeps the compound
    junction's fin into its own end knuckle.  Returns (UJoints, compound) or None when the
    pages' second pins are not one line or there is no room."""
    c, g = prof.clearance, prof.knuckle_gap
    pages = []
    for jn in members:
        bd = joints[jn][0]
        a, b = bd.a.split(".")[0], bd.b.split(".")[0]
        pages.append(b if a == S else a)
    bd = joints[members[0]][0]
    center = 0.5 * (scene.site_world(bd.a) + scene.site_world(bd.b)) * s
    hx = _host_axis(S, axes, center, s, g)
    if hx is None or len(set(pages)) != len(pages):
        return None
    comp = _compound(hx, center, S, pages[0], axes, s, prof, R, r_pin, kmin, others=pages, o_cos=O_COS,
                     far_ok=far_ok)
    if comp is None:
        return None
    u = comp["u"]
    vs = []
    for pg in pages:
        v = _hinge_dir(pg, axes, slabs, center)
        if abs(np.dot(u, v)) > 0.95:
            if len(vs) < len(pages) - 1 or vs:
                continue      # a page stacked on the source's line: any pin across u; the others' then
            w = np.mean([sb.center for sb in slabs[pg]], axis=0) - center
            v = np.cross(u, w)
            if np.linalg.norm(v) < 1e-9:
                v = _perp_frame(u)[:, 0]
        v = v - np.dot(v, u) * u
        vs.append(v / np.linalg.norm(v))
    v = vs[0]
    if any(abs(float(np.dot(v, x))) < 0.99 for x in vs):
        return None
    # sides: where each page's nearest slab (its arm) lies along the pin; a stacked page first
    sd = {}
    for pg in pages:
        near = min(slabs[pg], key=lambda sb: np.linalg.norm(sb.center - center))
        sd[pg] = float(np.dot(near.center - center, v))
    side: dict = {1: [], -1: []}
    for pg in sorted(pages, key=lambda p: (p != comp["o_body"], abs(sd[p]))):
        if pg == comp["o_body"] or abs(sd[pg]) < 0.1 * s:
            sg = 1 if len(side[1]) <= len(side[-1]) else -1
        else:
            sg = 1 if sd[pg] > 0 else -1
        side[sg].append(pg)
    ky = max(kmin, R)
    v0 = comp["hub_v"] / 2 + g
    # the outermost knuckle of a side is held by a cap on the pin; a page whose arm leaves
    # along the pin's line is joined to it by a bridge over the cap (:func:`_uj_plates`)
    cap = max(kmin, prof.min_wall)
    ivs, caps, ends = {}, {}, {1: 0.0, -1: 0.0}
    for sg, lst in side.items():
        a = v0
        for i, pg in enumerate(lst):
            ivs[pg] = (a, a + ky)
            a += ky + g
        if lst:
            caps[sg] = (a, a + cap)
            a += cap + g
        ends[sg] = a - g
    # room: no hinge of a page on the pin's line may come within the clearance of the yokes
    for ax in axes:
        if not any(pg in ax.bodies for pg in pages) or abs(abs(float(np.dot(ax.direction, v))) - 1) > 1e-6:
            continue
        rel = center - ax.origin
        b = float(np.dot(rel, ax.direction))
        if np.linalg.norm(rel - b * ax.direction) > _TOL * s:
            continue
        mid = float(np.dot(ax.origin - center, v))
        if mid + ax.span / 2 > -ends[-1] - c and mid - ax.span / 2 < ends[1] + c:
            return None
    part = members[0] if members[0] not in bodies else f"joint_{members[0]}"
    out = []
    for jn, pg in zip(members, pages):
        sg = 1 if pg in side[1] else -1
        last = side[sg][-1] == pg
        f = (lambda iv: (iv[0], iv[1])) if sg > 0 else (lambda iv: (-iv[1], -iv[0]))
        own = f(ivs[pg])
        plate = f((-min(R, v0 - c), ivs[pg][1])) if pg == comp["o_body"] else own
        lay_o = YokeLayout("+" if sg > 0 else "-", [own], [f(caps[sg])] if last else [], f((0.0, caps[sg][1])),
                           (-ends[-1] - g, ends[1] + g), plate, holes=[f((ivs[pg][0] - g / 2, ivs[pg][1] + g / 2)) + (r_hole,)],
                           bridge=f((ivs[pg][0], caps[sg][1] + g + t)) if last else ())
        lays = (comp["layout_c"], lay_o)
        uj = UJoint(jn, part, center, (S, pg), (u, v), lays, comp["hub_v"], R, r_pin, r_hole,
                    (float(np.hypot(lay_o.extent, R)) + c, float(np.hypot(lays[0].extent, R)) + c))
        uj.host, uj.hub_r, uj.collar = comp["axis"], comp["hub_r"], comp["collar"]
        if pg == comp["o_body"] and np.isfinite(comp["dO"]):
            uj.fin = comp["dO"] + t
            uj.o_axis = comp["o_axis"]
        uj.primary = not out
        uj.mates = [p for p in side[sg] if p != pg]
        need = _ujoint_trim_memo(memo, uj, _uj_samples(uj, base_samples, slabs, reach, t, h, prof.circular_segments), state_T, t, c, h)
        uj.rho = (max(uj.rho[0], need[0]), max(uj.rho[1], need[1]))
        out.append(uj)
    return out, comp


def _own_lines(bn, center, d, axes, s) -> None:
    """Re-lay (:func:`_own_ends`) every hinge of body ``bn`` on the line through ``center``
    along ``d``: a yoke whose arm runs along its own hinge's line joins that hinge's end knuckle."""
    for ax in axes:
        if bn not in ax.bodies or abs(float(np.dot(ax.direction, d))) < 0.9:
            continue
        rel = center - ax.origin
        b = float(np.dot(rel, ax.direction))
        if np.linalg.norm(rel - b * ax.direction) < _TOL * s and abs(b) > ax.span / 2:
            _own_ends(ax, bn)


def _own_ends(ax: HingeAxis, bn: str) -> None:
    """Re-lay hinge axis ``ax`` so that body ``bn`` holds its end knuckles and pin (the same
    knuckle slots, bodies in another order): the other body's yoke of a compound junction then
    joins its own end knuckle, not a slab trimmed back around another body's knuckle."""
    if ax.bodies[0] == bn or ax.joint is not None:
        return
    blist = [bn] + [b for b in ax.bodies if b != bn]
    layout = [blist[0]] + blist[1:] + [blist[0]]
    slots = sorted(iv for ivs in ax.intervals.values() for iv in ivs)
    if len(slots) != len(layout):
        return
    ax.bodies, ax.layout = blist, layout
    ax.intervals = {b: [] for b in blist}
    for b, iv in zip(layout, slots):
        ax.intervals[b].append(iv)


#: a rim chamfer is at most this fraction of half the minimum wall: a ball of the minimum wall still
#: fits in a knuckle's ring of that wall right to its end face (it does up to (2 - sqrt 2) = 0.586)
RIM_CAP = 0.55


def _host_cut(uj: UJoint, bn: str, c: float) -> tuple:
    """The range along a compound junction's first pin (mm from the joint point) over which host
    body ``bn`` is trimmed clear of the other body's yoke: the layout's (``R + c`` and
    :data:`HOST_CUT_MARGIN` clearances more) for C, the junction's own body; ``R + c`` for the
    hinge's other bodies (with the margin it cut the slab beside their end knuckle, between it and
    the cut round the joint's knuckle, to a 0.4 mm web: the robot's wrist, session 67), unless
    :data:`OWNER_CUT_MARGIN` gives them the margin too."""
    h0, h1 = uj.layouts[0].cut
    if bn == uj.bodies[0] or OWNER_CUT_MARGIN:
        return h0, h1
    m = HOST_CUT_MARGIN * c
    return h0 + m, h1 - m


def _rim_chamfers(bn, my_axes, my_uj, ujoints, ch) -> dict:
    """Rim chamfers (mm, at each end) of body ``bn``'s knuckles that face another knuckle across a
    compound junction's joint point (:data:`RIM_CHAMFER`): keyed ``(axis name, s0, s1)`` for a hinge's
    knuckle, ``(joint name, side, s0, s1)`` for a yoke knuckle; values ``(lo, hi)``.

    Square, the host stack's knuckle ending nearest the joint point (along the first pin, its end
    face towards the joint point) and the other body's yoke knuckle (along the second pin, its inner
    end face towards it) leave a corner gap of about the clearance between their rims: each stands
    the knuckle gap past the hub, and each reaches its radius R across the other's line.  A 45 degree
    chamfer of ``ch`` on both rims widens it by about ``sqrt 2 ch``; the faces' inner parts, which bear
    along the pins, stay."""
    out: dict = {}
    if ch <= 0:
        return out
    for uj, side in my_uj:
        lay = uj.layouts[side]
        if uj.host is None or side != 1 or lay.holes is not None:
            continue
        for a0, a1 in lay.own:
            out[(uj.name, side, a0, a1)] = (ch if a0 >= 0 else 0.0, ch if a1 <= 0 else 0.0)
    for ax in my_axes:
        if ax.joint is None:
            continue
        ivs = sorted([(iv, b) for b, lst in ax.intervals.items() for iv in lst]
                     + ([(tuple(ax.joint_iv), ax.joint)] if ax.joint_iv else []))
        for uj in ujoints:
            if uj.host is not ax:
                continue
            b = float(np.dot(uj.center - ax.origin, ax.direction))
            below = [(iv, o) for iv, o in ivs if iv[1] <= b + 1e-6]
            above = [(iv, o) for iv, o in ivs if iv[0] >= b - 1e-6]
            if below and below[-1][1] == bn:
                a0, a1 = below[-1][0]
                lo, hi = out.get((ax.name, a0, a1), (0.0, 0.0))
                out[(ax.name, a0, a1)] = (lo, ch)
            if above and above[0][1] == bn:
                a0, a1 = above[0][0]
                lo, hi = out.get((ax.name, a0, a1), (0.0, 0.0))
                out[(ax.name, a0, a1)] = (ch, hi)
    return out


def _compound_yoke_layout(mode, hub, g, k, cap, W, s, turned=False) -> YokeLayout:
    """:func:`_yoke_layout` of a compound junction's second pin: one-sided, it is trimmed where
    the joint part is (ball hub to cap), not along the whole line, which may run through O's
    slab (w_y_3_56_CD cut in two, session 51).  ``turned`` (the pin turned by least_twist): a
    one-sided yoke's plate stops at the hub on the side without a knuckle, where the other arm
    passes; it ran half the body's width past the hub along the turned pin, out of the body's
    slab (the Tetris robot's gate g2: both output levers' coupling junctions, their pins turned
    to point at each other across the levers' V, met there, 1.77 mm^3; session 55).  The trim
    runs a gap ``g`` past the cap's end: it stopped at the end face, and where O's slab goes on
    past the cap along the pin the two were printed touching (the README robot's ``w_y_3_j3_hi``,
    one-sided by KNUCKLE_PLATES: 0.0025 mm^3 in the states; session 69)."""
    ly = _yoke_layout(mode, hub, g, k, cap, W, s)
    if ly.mode != "both":
        end = g if CAP_END_CUT else 0.0
        ly.cut = (-(hub / 2 + g), ly.caps[0][1] + end) if ly.mode == "+" else (ly.caps[0][0] - end, hub / 2 + g)
        if turned:
            ly.plate = (max(ly.plate[0], ly.cut[0]), ly.plate[1]) if ly.mode == "+" else \
                (ly.plate[0], min(ly.plate[1], ly.cut[1]))
    return ly


def _severs(uj: UJoint, sbs, reach, t, n) -> bool:
    """Whether the trim about a universal joint's second pin, at its least radius, cuts the other
    body in pieces: a model of that body, its slabs ``sbs`` with the joint's yoke plates and
    knuckles only (the build adds the plates of its hinges, which may hold it together)."""
    lay = uj.layouts[1]
    knuckles = [cylinder(uj.center, uj.axes[1], a0, a1, uj.R, n) for a0, a1 in lay.own]
    body = union([box(sb.center, sb.R, sb.size) for sb in sbs + _uj_plates(uj, 1, sbs, uj.rho[1] + reach, t, n)]
                 + knuckles)
    cut = _clean(union([subtract(body, [cylinder(uj.center, uj.axes[1], a0, a1, uj.rho[1], n, cutter=True)
                                        for a0, a1 in _complement(lay.own, *lay.cut)])] + knuckles))
    return len(cut.decompose()) > len(_clean(body).decompose())


def _yoke_layout(mode, hub, g, k, cap, W, s) -> YokeLayout:
    if mode == "both":
        S = max(W, hub + 2 * g + 2 * k)
        k2 = (S - hub - 2 * g) / 2
        return YokeLayout(mode, [(-S / 2, -S / 2 + k2), (S / 2 - k2, S / 2)], [], (-S / 2, S / 2), (-S / 2, S / 2),
                          (-S / 2, S / 2))
    sg = 1.0 if mode == "+" else -1.0
    a0 = hub / 2 + g
    own = (a0, a0 + k)
    caps = (a0 + k + g, a0 + k + g + cap)
    f = (lambda iv: (iv[0], iv[1])) if sg > 0 else (lambda iv: (-iv[1], -iv[0]))
    big = 10 * s + 10 * (hub + k + cap)
    pin = f((-hub / 2, caps[1]))
    o = f(own)
    return YokeLayout(mode, [o], [f(caps)], pin, (-big, big), (min(o[0], -W / 2), max(o[1], W / 2)))


def _ujoint_trim(uj: UJoint, samples, state_T, t, c, h):
    """Trim radii of the two yokes of a universal joint so their slabs clear in every state:
    each pair of close slab points (C, O) loses the point that needs the smaller radius."""
    C, O = uj.bodies
    thr = t + c + h
    coords = []
    for side, bn in enumerate((C, O)):
        lay = uj.layouts[side]
        a, r = _axis_coords(uj.center, uj.axes[side], samples[bn])
        # only points a trim radius can reach matter here (the rest is left to the final trims)
        keep = np.linalg.norm(samples[bn] - uj.center, axis=1) <= 2 * lay.extent + uj.rho[side] + 4 * uj.R
        elig = (a >= lay.cut[0]) & (a <= lay.cut[1]) & ~_inside(a, lay.own)
        coords.append((samples[bn][keep], r[keep], elig[keep]))
    (pc, rc, ec), (po, ro, eo) = coords
    VC, VO = [], []
    Ms = [_relative(C, O, Ts) for _, Ts in (state_T or [("rest", None)])]
    for ii, jj in _close_pairs_posed(pc, po, Ms, thr):
        if len(ii):
            VC.append(np.where(ec[ii], rc[ii] + h, np.inf))
            VO.append(np.where(eo[jj], ro[jj] + h, np.inf))
    need = [0.0, 0.0]
    if not VC:
        return need[0], need[1]
    vc, vo = np.concatenate(VC), np.concatenate(VO)
    ok = np.isfinite(vc) | np.isfinite(vo)          # pairs no trim can separate are left to the checks
    vc, vo = vc[ok], vo[ok]
    if len(vc) == 0:
        return need[0], need[1]
    # every close pair is settled by C (need_c >= vc) or by O (need_o >= vo): choose the split
    # minimising need_c + need_o -- the k pairs with the largest vc go to O
    order = np.argsort(-vc, kind="stable")
    vcs, vos = vc[order], vo[order]
    pm = np.concatenate([[0.0], np.maximum.accumulate(vos)])      # need_o if the first k go to O
    nc = np.concatenate([vcs, [0.0]])                                # need_c for the rest
    cost = nc + pm
    k = int(np.argmin(cost))
    need = [float(nc[k]), float(pm[k])]
    return need[0], need[1]


def _ext_ivs(sbs, ax: HingeAxis) -> list:
    """The ranges along ``ax`` (from its origin, mm) beyond its knuckle span that the slab
    boxes ``sbs`` cover."""
    lo, hi = -ax.span / 2, ax.span / 2
    for sb in sbs:
        mid = float(np.dot(sb.center - ax.origin, ax.direction))
        half = 0.5 * float(np.sum(np.abs(sb.R.T @ ax.direction) * sb.size))
        lo, hi = min(lo, mid - half), max(hi, mid + half)
    return [(a0, a1) for a0, a1 in ((lo, -ax.span / 2), (ax.span / 2, hi)) if a1 - a0 > 1e-9]


def _axis_extension(sbs, ax: HingeAxis, reach, t) -> list:
    """Plates (slab boxes) that carry the slabs reaching ``ax`` along it beyond the knuckle
    span, as far as the body's slabs go (:func:`_ext_ivs`)."""
    ivs = _ext_ivs(sbs, ax)
    return _yoke_plates(sbs, ax.origin, ax.direction, ivs, reach, t) if ivs else []


def _bridge(ax: HingeAxis, bn, a0, a1, samples, state_T, t, prof, avoid=(), clear=None):
    """A plate carrying body ``bn`` around the other bodies' knuckles on ``[a0, a1]``:
    in the direction (about the axis) farthest from every other body in every state, and not
    into a cylinder of ``avoid`` (``(origin, direction, s0, s1, radius)``: the body's other
    trims, which would cut the plate away).  None if every direction runs into one.

    ``clear`` (``(poses, gap)``: ``[{body: 4x4}]`` and mm): the plate's material beyond the trim
    radius must also stay ``gap`` from every other body's mid-plane samples in each of those
    poses (the dense paths: a bridge placed for the logic states alone was then trimmed in
    motion); the first such direction of those ``avoid`` leaves, the farthest by angle first, else
    None (session 36: the 16 best only missed the two clear of a_hi, b_hi and out_hi in the
    expanding NOR at mjp, 60 degrees from a_hi and b_hi).  A thin web's bridge reaches the full
    minimum wall past the corners of the trim's polygon."""
    far = 3 * ax.R + 2 * t + 0.5 * prof.sigma_mm
    w = max(prof.min_wall, t)
    foreign = []
    for o in ax.bodies:
        if o == bn:
            continue
        for _, Ts in (state_T or [("rest", None)]):
            foreign.append(_axis_angles(ax, _in_frame_of(bn, o, samples[o], Ts), ax.R, far))
    fa = np.concatenate(foreign) if foreign else np.zeros(0)
    cand = np.linspace(-np.pi, np.pi, 144, endpoint=False)
    if len(fa):
        score = np.abs(((cand[:, None] - fa[None, :]) + np.pi) % (2 * np.pi) - np.pi).min(axis=1)
    else:
        score = np.full_like(cand, np.pi)
    E = _perp_frame(ax.direction)
    reach = ax.rho + w
    if clear is not None:
        # a thin web's bridge is the web: the full wall past the trim cylinder's corners (a
        # cutter's polygon has its corners at rho / cos(pi / n))
        reach = ax.rho / np.cos(np.pi / prof.circular_segments) + w
    if avoid:
        # the plate's material beyond the trim radius: along the axis, out to its end, across
        a, r, f = np.meshgrid(np.linspace(a0 - w, a1 + w, 7), np.linspace(ax.rho, reach, 4),
                              np.linspace(-0.5 * t, 0.5 * t, 3), indexing="ij")
        a, r, f = a.reshape(-1, 1), r.reshape(-1, 1), f.reshape(-1, 1)
        for i, th in enumerate(cand):
            e = np.cos(th) * E[:, 0] + np.sin(th) * E[:, 1]
            P = ax.origin + a * ax.direction + r * e + f * np.cross(ax.direction, e)
            for o, d, s0, s1, rad in avoid:
                sa, ra = _axis_coords(o, d, P)
                if np.any((sa >= s0) & (sa <= s1) & (ra < rad)):
                    score[i] = -1.0
                    break
        if score.max() < 0:
            return None
    k = int(np.argmax(score))
    if clear is not None:
        poses, gap = clear
        lo, hi = a0 - w, a1 + w
        A, X, Y = [], [], []        # other bodies' samples near the plate, in bn's frame, axis coords
        for Ts in poses:
            for o, pts in samples.items():
                if o == bn or not len(pts):
                    continue
                rel = _in_frame_of(bn, o, pts, Ts) - ax.origin
                aa, px, py = rel @ ax.direction, rel @ E[:, 0], rel @ E[:, 1]
                rr = np.hypot(px, py)
                m = (aa > lo - gap) & (aa < hi + gap) & (rr > ax.rho - gap) & (rr < reach + gap)
                A.append(aa[m]), X.append(px[m]), Y.append(py[m])
        A, X, Y = (np.concatenate(v) if v else np.zeros(0) for v in (A, X, Y))
        da = np.maximum(0.0, np.maximum(lo - A, A - hi))
        for k in [int(i) for i in np.argsort(-score, kind="stable") if score[i] >= 0]:
            c_, s_ = np.cos(cand[k]), np.sin(cand[k])
            x, y = X * c_ + Y * s_, -X * s_ + Y * c_
            dist = np.sqrt(np.maximum(0.0, np.abs(y) - t / 2) ** 2
                           + np.maximum(0.0, np.maximum(ax.rho - x, x - reach)) ** 2 + da ** 2)
            if not len(dist) or dist.min() >= gap:
                break
        else:
            return None
    th = float(cand[k])
    e = np.cos(th) * E[:, 0] + np.sin(th) * E[:, 1]
    Rm = np.column_stack([ax.direction, e, np.cross(ax.direction, e)])
    center = ax.origin + ax.direction * 0.5 * (a0 + a1) + e * reach / 2
    return box(center, Rm, [a1 - a0 + 2 * w, reach, t]), float(score[k])


#: mm: a web is thinner than the minimum wall when the largest disc in its section is more
#: than this under it (the polygons' own rounding: a slab exactly the minimum wall thick passes)
WEB_TOL = 1e-3


def _web_thinner(cut: mf.Manifold, ax: HingeAxis, bn: str, min_wall: float) -> bool:
    """Whether the body ``bn``, cut around the other bodies' knuckles on ``ax`` (``cut``: the
    body's solid after its trims), keeps a web there thinner than ``min_wall``, measured.

    The body is cut by planes normal to the axis in the middle of each stretch of the stack
    between two of its own knuckles (where the other bodies' knuckles are and a bridge can go);
    every piece of such a section that comes within the trim radius + the minimum wall of the
    axis is a web next to the trim, and it is thinner than the wall when no disc of diameter
    ``min_wall - WEB_TOL`` fits in it (Clipper2's inward offset of the polygon leaves nothing).
    Unlike the split (the cut grown by the minimum wall severs the body), this finds a web that
    is not the body's only link: core_cd of the expanding OR at mjp, 0.547 mm between hinge c's
    trim and the universal joint's, held on by its other slabs too (issue 13, session 37)."""
    if cut.is_empty():
        return False
    own = ax.intervals[bn]
    E = _perp_frame(ax.direction)
    Rm = E.T                                    # world -> (e1, e2, axis)
    M = np.hstack([Rm, (-Rm @ np.asarray(ax.origin, float))[:, None]])
    local = None
    near = ax.rho / np.cos(np.pi / 8) + min_wall
    for a0, a1 in _complement(own, -ax.span / 2, ax.span / 2):
        if not (any(o1 <= a0 + 1e-9 for _, o1 in own) and any(o0 >= a1 - 1e-9 for o0, _ in own)):
            continue
        if local is None:
            local = cut.transform(M.tolist())
        for piece in local.slice(0.5 * (a0 + a1)).decompose():
            x0, y0, x1, y1 = piece.bounds()
            # the nearest point of the piece's box to the axis
            dx, dy = max(x0, 0.0, -x1), max(y0, 0.0, -y1)
            if np.hypot(dx, dy) > near or piece.area() < 1e-9:
                continue
            if piece.offset(-(0.5 * min_wall - 0.5 * WEB_TOL), mf.JoinType.Round).is_empty():
                return True
    return False


def _ext(intervals, span, t, beyond=None, min_wall=0.0):
    """Extend cut intervals that end at the span's ends a little further (``t``, mm: no coplanar
    faces).  ``beyond`` (:func:`_ext_ivs`: the ranges along the axis, mm, that the body's slabs
    and plates cover past the span): where the body goes on past the extended end by less than
    ``min_wall``, the cut runs on past it (``t`` more) instead of leaving a sheet that thin."""
    lo = min([x for iv in beyond or [] for x in iv] + [-span / 2])
    hi = max([x for iv in beyond or [] for x in iv] + [span / 2])
    out = []
    for a0, a1 in intervals:
        if abs(a0 + span / 2) < 1e-9:
            a0 -= t
            if 0.0 < a0 - lo < min_wall:
                a0 = lo - t
        if abs(a1 - span / 2) < 1e-9:
            a1 += t
            if 0.0 < hi - a1 < min_wall:
                a1 = hi + t
        out.append((a0, a1))
    return out


def _clean(solid: mf.Manifold) -> mf.Manifold:
    """Drop slivers (pieces of negligible volume) left by booleans on touching faces."""
    if solid.is_empty():
        return solid
    pieces = solid.decompose()
    if len(pieces) <= 1:
        return solid
    vols = [p.volume() for p in pieces]
    big = max(vols)
    keep = [p for p, v in zip(pieces, vols) if v > max(1e-4, 2e-3 * big)]
    return union(keep)


def _attachment(sbs, p, lug_out, t):
    """Where the attachment hole for a site goes: inside the nearest slab when it is wide
    enough (ring=False; drilled last, at the free spot of that slab nearest to the site),
    else a ring around the site."""
    sb = min(sbs, key=lambda x: np.linalg.norm(x.center - p))
    nrm = sb.R[:, sb.normal_axis]
    inplane = [i for i in range(3) if i != sb.normal_axis]
    if all(sb.size[i] >= 2 * lug_out for i in inplane):
        return p, nrm, False, sb
    return p, nrm, True, sb


def _spot(sb, p, lug_out):
    """The point of a slab nearest to ``p`` with room for a hole ring of radius ``lug_out``."""
    q = sb.R.T @ (p - sb.center)
    for i in range(3):
        lim = max(sb.size[i] / 2 - lug_out, 0.0) if i != sb.normal_axis else 0.0
        q[i] = float(np.clip(q[i], -lim, lim))
    return sb.center + sb.R @ q


def _ring_clear(asm: "Assembly", part: "Part", ring, motion_T=()) -> bool:
    """True if ``ring`` (in ``part``'s rest frame) keeps the clearance from every other part as
    printed and meets none in any logic state; with ``motion_T`` (the part transforms of the dense
    poses, :func:`_clear_motion`) it also keeps the clearance in each of those."""
    c = asm.profile.clearance
    rb = np.asarray(ring.bounding_box())
    Ts = [(T, False) for T in (asm.part_transforms(pos, quat) for pos, quat in (asm.poses or {}).values())]
    Ts += [(T, True) for T in motion_T]
    for other in asm.parts:
        if other is part:
            continue
        ob = np.asarray(other.solid.bounding_box())
        if _bb_near(rb, ob, 2 * c) and ring.min_gap(other.solid, c) < c - 1e-6:
            return False
        for T, keep_clear in Ts:
            M = np.linalg.inv(T[part.name]) @ T[other.name]
            plo, phi = posed_boxes(ob[:3], ob[3:], [M])
            margin = c if keep_clear else 0.0
            if not _bb_near(rb, np.concatenate([plo[0], phi[0]]), margin):
                continue       # the moved part's box (which contains its exact box) misses the ring
            o = transform_solid(other.solid, M)
            if not _bb_near(rb, np.asarray(o.bounding_box()), margin):
                continue
            if keep_clear:
                if ring.min_gap(o, c) < c - 1e-6:
                    return False
            elif (ring ^ o).volume() > 1e-6:
                return False
    return True


#: attachment holes for a known print up (issue 13): a hole whose axis rises less than this
#: (degrees) from the bed has a ceiling flatter than the overhang limit (its ceiling rises as
#: much as its axis) and is drilled as a teardrop with its point up, the usual FDM rule
HOLE_TEARDROP_DEG = 45.0
#: ... whose two sides rise at this angle (degrees; 45 is the usual rule, a little more keeps
#: them off the limit on a polygon)
TEARDROP_SIDE_DEG = 50.0


def _feet_up(asm: "Assembly", poses, motion_T) -> np.ndarray | None:
    """The up direction the print-only feet will be made for (:func:`mlc.mesh.feet.plan_feet`),
    or None (no feet)."""
    from mlc.mesh import feet
    if not feet.BED_FEET:
        return None
    eye = {p.name: np.eye(4) for p in asm.parts}
    plan = feet.plan_feet(asm, [eye] + [asm.part_transforms(*pq) for pq in (poses or {}).values()] + list(motion_T))
    return None if plan is None else np.asarray(plan[0], float)


def hole_kind(nrm, up) -> str:
    """How an attachment hole of axis ``nrm`` is drilled for the print up ``up`` (None: not
    known): "round", or "teardrop" when its axis rises less than :data:`HOLE_TEARDROP_DEG`."""
    if up is None:
        return "round"
    c = abs(float(np.dot(nrm, up)) / (np.linalg.norm(nrm) * np.linalg.norm(up)))
    elev = 90.0 - np.degrees(np.arccos(min(1.0, c)))      # the axis's angle above the bed
    return "teardrop" if elev < HOLE_TEARDROP_DEG - 1e-9 else "round"


def hole_shape(c, nrm, up, r, t, n, half, kind=None, grow=0.0) -> mf.Manifold:
    """An attachment hole of radius ``r`` along ``nrm`` at ``c``, over ``|nrm . (p - c)| <=
    half``; a teardrop (:func:`hole_kind`) is the circle with a 90-degree point towards ``up``
    in the plane normal to ``nrm`` (its sides tangent to the circle, rising at
    :data:`TEARDROP_SIDE_DEG` in that plane): its ceiling is two faces that rise at 45 degrees or
    more.  ``grow``: the shape offset
    by that much (mm; the wall around the hole).  ``n`` segments, the circle's inscribed radius
    ``r + grow`` (as :func:`cylinder` with ``cutter``)."""
    nrm = np.asarray(nrm, float) / np.linalg.norm(nrm)
    kind = kind or hole_kind(nrm, up)
    k = 1 / np.cos(np.pi / n)
    r = r + grow
    if kind == "round":
        return cylinder(c, nrm, -half, half, r * k, n)
    up = np.asarray(up, float) / np.linalg.norm(up)
    v = up - np.dot(up, nrm) * nrm
    v /= np.linalg.norm(v)
    w = np.cross(v, nrm)
    ang = np.linspace(0.0, 2 * np.pi, int(n), endpoint=False)
    circ = [(r * k * np.cos(a), r * k * np.sin(a)) for a in ang]
    p = np.radians(TEARDROP_SIDE_DEG)       # the sides touch the circle (of the polygon's outer radius)
    tip = [(-r * k * np.sin(p), r * k * np.cos(p)), (r * k * np.sin(p), r * k * np.cos(p)), (0.0, r * k / np.cos(p))]
    cs = mf.CrossSection([circ]) + mf.CrossSection([tip if _ccw(tip) else tip[::-1]])
    F = np.column_stack([w, v, nrm])            # profile (x, y) -> w, v; extruded along nrm
    return mf.Manifold.extrude(cs, 2 * half).translate([0.0, 0.0, -half]).transform(
        _affine(F, np.asarray(c, float)))


def _ccw(poly) -> bool:
    a = 0.0
    for (x0, y0), (x1, y1) in zip(poly, poly[1:] + poly[:1]):
        a += x0 * y1 - x1 * y0
    return a > 0


def _drill(asm: "Assembly", lugs, lug_hole, lug_out, t, motion_T=(), up=None) -> None:
    """Drill each attachment hole inside its slab, at the spot nearest to the site where a
    full ring of material (``min_wall``) surrounds the hole; where there is no room, on a ring lug
    at the site or further along the arm: the first that keeps the clearance in the dense poses
    ``motion_T`` too, else the first that meets no part in a logic state (the ``motion_clearance``
    check then fails).  ``up`` (the print's up, when known before the orientation: the feet's):
    a hole inside a slab is shaped to print without support (:func:`hole_shape`), and its wall
    measured around that shape."""
    n = asm.profile.circular_segments
    for part in asm.parts:
        for site, nrm, ring, _, sb, label in lugs.get(part.name, []):
            if ring:
                continue
            inplane = [i for i in range(3) if i != sb.normal_axis]
            step = lug_out / 3
            axes_ = []
            for i in inplane:
                lim = sb.size[i] / 2 - lug_out
                axes_.append(np.linspace(-lim, lim, max(1, int(2 * lim / step) + 1)) if lim > 0 else np.zeros(1))
            g0, g1 = np.meshgrid(*axes_, indexing="ij")
            loc = np.zeros((g0.size, 3))
            loc[:, inplane[0]] = g0.ravel()
            loc[:, inplane[1]] = g1.ravel()
            cands = sb.center + loc @ sb.R.T
            order = np.argsort(np.linalg.norm(cands - site, axis=1))
            # the hole needs its wall in the slab's plane; a face shaved by a trim is acceptable,
            # so the test disc is the middle half of the slab's thickness
            kind = hole_kind(nrm, up)
            if kind == "round":
                disc = cylinder(np.zeros(3), nrm, -t / 4, t / 4, lug_out, n)
            else:       # the hole's shape grown by the wall, over the middle half of the slab
                disc = hole_shape(np.zeros(3), nrm, up, lug_hole, t, n, t / 4, kind, grow=lug_out - lug_hole)
            full = disc.volume()
            for k in order[:400]:
                c = cands[k]
                if (disc.translate(c.tolist()) - part.solid).volume() <= 1e-3 * full:
                    hole = (cylinder(c, nrm, -t - 1, t + 1, lug_hole, n, cutter=True) if kind == "round"
                            else hole_shape(c, nrm, up, lug_hole, t, n, t + 1, kind))
                    part.solid = subtract(part.solid, [hole])
                    asm.holes.append((part.name, c.copy(), np.asarray(nrm, float), kind))
                    off = float(np.linalg.norm(c - site))
                    if off > 1e-6:
                        asm.notes.append(f"{label}: attachment hole {off:.2f} mm from the site, inside the slab")
                    if kind != "round":
                        asm.notes.append(f"{label}: attachment hole drilled as a teardrop pointing up "
                                         "(a hole across the layers, to print without support)")
                    break
            else:
                # no room inside the trimmed slab: a ring (lug) of full thickness around the site,
                # or further along the arm, where it clears every other part in every state
                L = max(inplane, key=lambda i: sb.size[i])
                along = [c for c in cands[order] if abs((sb.R.T @ (c - sb.center))[[i for i in inplane
                                                                                      if i != L][0]]) < step]
                spots = [site] + along[:10]
                tries = [(c, m) for m in ((motion_T, ()) if motion_T else ((),)) for c in spots]
                for c, m in tries:
                    ringd = cylinder(c, nrm, -t / 2, t / 2, lug_out, n)
                    if _ring_clear(asm, part, ringd, m):
                        part.solid = subtract(union([part.solid, ringd]),
                                              [cylinder(c, nrm, -t - 1, t + 1, lug_hole, n, cutter=True)])
                        asm.notes.append(f"{label}: no room inside the trimmed slab; a ring lug "
                                         f"{np.linalg.norm(c - site):.2f} mm from the site instead"
                                         + (" (it does not keep the clearance in motion)" if motion_T and not m
                                            else ""))
                        break
                else:
                    asm.notes.append(f"{label}: no room for an attachment hole in the trimmed slab, "
                                     f"nor for a ring at the site")
                    asm.features.append((f"room for the attachment hole of {label}", 0.0, 2 * lug_out))


def _resolve(asm: "Assembly", protected: dict, soft_protected: dict, state_T, cong=None, fat=None) -> None:
    """Trim slabs that still come closer than the clearance (as printed) or intersect (in a
    logic state): from one of the two parts, cut the other part grown by the clearance, in
    every state where they meet, never touching knuckles, pins or attachment rings.  The part
    trimmed is one whose trim settles the conflict, stays in one piece and loses less."""
    c = asm.profile.clearance
    if c <= 0:
        return
    grow = 1.5 * c
    dirs = list(CUBE_DIRS)
    poses = asm.poses or {}
    parts = asm.parts
    # with reuse (compiled circuits) only what is too close as printed is trimmed here: the
    # sampled trim radii already clear the hinges in every pose, and the ``states`` check reports
    # what still meets in a pose (trimming every pose of thousands of parts took hours)
    Ts = [] if cong is not None else [asm.part_transforms(pos, quat) for pos, quat in poses.values()]

    def conflicts_of(filters):
        # the pairs of parts that can meet (bounding boxes, spatial.box_pairs) instead of all
        # pairs; ``filters``: sets of parts changed in earlier rounds (a pair must touch each)
        def wanted(i, j):
            return all(i in f or j in f for f in filters)

        out: dict = {}
        gap_meshes: dict = {}
        from mlc.mesh.apart import min_gap as _apart_gap
        lo, hi = solid_boxes([p.solid for p in parts])
        for i, j in box_pairs(lo, hi, 2 * c):
            if not wanted(i, j):
                continue
            if cong is None:
                near = parts[i].solid.min_gap(parts[j].solid, c) < c - 1e-6
            else:     # one exact test per pair of shapes in one relative pose
                # the gap itself, searched as far as the report's min_gap check searches and
                # cached under its key: the check finds every pair the trims left alone cached
                # (a gap under the clearance is the same number searched to c or to 2 c)
                # (pairs whose triangles prove them farther apart than the search: mlc.mesh.apart)
                search = max(2 * c, 1e-3)
                near = cong.lookup(("min_gap", search, cong.key(i, parts[i].solid), cong.key(j, parts[j].solid),
                                    cong.rel(i, j)),
                                   lambda: (_apart_gap(parts[i].solid, parts[j].solid, search, gap_meshes) if APART_GAP
                                            else float(parts[i].solid.min_gap(parts[j].solid, search)))) < c - 1e-6
            if near:
                out.setdefault((i, j), []).append(None)
        llo, lhi = local_boxes([p.solid for p in parts], frames)
        for T in Ts:
            Tp = [T[p.name] for p in parts]
            plo, phi = posed_boxes(lo, hi, Tp)
            posed = {}

            def meet(i, j):
                for k in (i, j):
                    if k not in posed:
                        posed[k] = transform_solid(parts[k].solid, Tp[k])
                bi, bj = np.asarray(posed[i].bounding_box()), np.asarray(posed[j].bounding_box())
                return bool(_bb_near(bi, bj, 0.0) and (posed[i] ^ posed[j]).volume() > 1e-6)

            for i, j in posed_pairs(Tp, frames, llo, lhi, plo, phi):
                if not wanted(i, j):
                    continue
                if cong is None:
                    hit = meet(i, j)
                else:
                    hit = cong.lookup(("meet", cong.key(i, parts[i].solid), cong.key(j, parts[j].solid),
                                       cong.rel(i, j, Tp[i], Tp[j])), lambda: meet(i, j))
                if hit:
                    out.setdefault((i, j), []).append(T)
            posed.clear()
        return out

    def settled(X, Xs, Y, sts):
        for T in sts:
            M = np.eye(4) if T is None else np.linalg.inv(T[X.name]) @ T[Y.name]
            Yp = transform_solid(Y.solid, M)
            if T is None:
                if Xs.min_gap(Yp, c) < c - 1e-6:
                    return False
            elif (Xs ^ Yp).volume() > 1e-6:
                return False
        return True

    filters: list[set] = []
    locked: set = set()        # pairs that overlap only inside both parts' guards
    frames = part_frames(asm) if cong is None else cong.frames
    guard_keys: dict = {}

    def guard_key(k, name, table):
        g = table.get(name)
        if g is None:
            return None
        if (id(table), name) not in guard_keys:
            guard_keys[(id(table), name)] = shape_key(g, frames[k])
        return guard_keys[(id(table), name)]
    for _round in range(4):
        _log(f"final trims round {_round}: finding conflicts")
        conflicts = conflicts_of(filters)
        _log(f"final trims round {_round}: {len(conflicts)} conflicting pair(s)")
        if not conflicts:
            return
        changed = set()
        for (i, j), sts in conflicts.items():
            A, B = parts[i], parts[j]
            if cong is not None:
                # the same two shapes in the same relative poses: the same trim (moved along)
                ck = ("trim", cong.key(i, A.solid), cong.key(j, B.solid),
                      guard_key(i, A.name, protected), guard_key(i, A.name, soft_protected),
                      guard_key(j, B.name, protected), guard_key(j, B.name, soft_protected),
                      tuple(cong.rel(i, j) if T is None else cong.rel(i, j, T[A.name], T[B.name]) for T in sts))
                got = cong.results.get(ck)
                if got is not None:
                    cong.hits += 1
                    if got == "none":
                        continue
                    side, local, removed = got
                    k = (i, j)[side]
                    X, Y = parts[k], parts[(j, i)[side]]
                    X.solid = transform_solid(local, frames[k])
                    changed.add(k)
                    asm.notes.append(f"trimmed {removed:.3g} mm^3 from {X.name} to clear {Y.name}"
                                     + (f" in {len([s for s in sts if s is not None])} logic state(s)"
                                        if any(s is not None for s in sts) else " as printed"))
                    continue
                cong.misses += 1
            _t0 = time.perf_counter()
            _log(f"trim {A.name} ({A.solid.num_vert()} v) / {B.name} ({B.solid.num_vert()} v), "
                 f"{len(sts)} state(s)")
            if (i, j) in locked:
                continue          # still locked: trims never take material from the guards
            if fat is not None and all(T is None for T in sts) and _locked(A, B, protected, fat):
                locked.add((i, j))
                # they overlap only where both must keep their material (knuckles, pins): no trim
                # can settle it, and every try costs booleans; the checks report the overlap
                asm.notes.append(f"{A.name} and {B.name} overlap inside their knuckles or pins as printed: "
                                 "not trimmed")
                _log("  locked: both keep the overlap")
                if cong is not None:
                    cong.results[ck] = "none"
                continue
            def candidates(A=A, B=B, sts=sts):
                cands = []
                for X, Y in ((A, B), (B, A)):
                    if X.kind == "joint":
                        continue
                    if cong is not None and cands and cands[0][:3] == (False, False, False):
                        break     # large assemblies: the first trim that settles, in one piece, is taken
                    hard = protected.get(X.name)
                    soft = soft_protected.get(X.name)
                    guards = ((False, soft), (True, hard))
                    if fat is not None and X.name in fat:
                        # large assemblies: the grown guards, each used as is (no intersection with X)
                        fh, fs = fat[X.name]
                        guards = ((False, fs), (True, fh)) if fs is not None else ((False, fh),)
                    # first keep the spot of the attachment hole too (soft), then only the joints (hard)
                    for lost, guard in guards:
                        if guard is None:
                            continue
                        keep = guard if fat is not None and X.name in fat else X.solid ^ guard
                        _log(f"  {X.name}: keep {keep.num_vert()} v")
                        for g_ in (grow, 2.0 * c, 2.5 * c):
                            trimmed = _trim_by(X, Y, sts, g_, dirs, keep, 0.5 * c, merged=cong is not None)
                            if trimmed is None:
                                break
                            _log(f"  trimmed by {g_:.3g}: {trimmed.num_vert()} v")
                            ok = settled(X, trimmed, Y, sts)
                            _log(f"  settled: {ok}")
                            if ok:
                                break
                        if trimmed is None:
                            continue
                        removed = X.solid.volume() - trimmed.volume()
                        if removed <= 1e-9:
                            continue
                        split = len(trimmed.decompose()) != 1
                        if split and cong is not None and KEEP_WHOLE:
                            # large assemblies: a trim that splits the part is never kept (it was
                            # when no other settled: the robot's skeleton units lost a knuckle or a
                            # lever post to a coupling's slab, session 50); the checks report the pair
                            continue
                        cands.append((not ok, split, lost, removed, X, trimmed, Y))
                        _log("  decomposed")
                        if ok:
                            break
                return cands

            if cong is None:
                cands = candidates()
            else:
                # large assemblies: each pair trimmed in a child process with a memory and time
                # cap (a boolean of two small parts has taken minutes and gigabytes), the result
                # sent back as a mesh; the parent keeps no boolean garbage
                got = _isolated(lambda: _best_mesh(candidates(), A), TRIM_SECONDS, TRIM_MEMORY)
                if got is None or got == "none":
                    _log(f"  done in {time.perf_counter() - _t0:.2f} s: " + ("capped" if got is None else "no trim"))
                    if got is None:
                        asm.notes.append(f"{A.name} and {B.name}: trim stopped (over {TRIM_SECONDS:g} s or "
                                         f"{TRIM_MEMORY / 2 ** 30:g} GiB), not trimmed")
                    cong.results[ck] = "none"
                    continue
                side, verts, tris, removed, ok = got
                X, Y = (A, B) if side == 0 else (B, A)
                cands = [(not ok, False, False, removed, X,
                          mf.Manifold(mf.Mesh64(vert_properties=verts, tri_verts=tris)), Y)]
            _log(f"  done in {time.perf_counter() - _t0:.2f} s, {len(cands)} candidate(s)")
            if not cands:
                if cong is not None:
                    cong.results[ck] = "none"
                continue
            unsettled, split, lost, removed, X, trimmed, Y = min(cands, key=lambda x: x[:4])
            if cong is not None:
                trimmed = _flat(trimmed)
            X.solid = trimmed
            changed.add(parts.index(X))
            if cong is not None:
                k = parts.index(X)
                cong.results[ck] = (0 if k == i else 1, transform_solid(trimmed, np.linalg.inv(frames[k])), removed)
            asm.notes.append(f"trimmed {removed:.3g} mm^3 from {X.name} to clear {Y.name}"
                             + (f" in {len([s for s in sts if s is not None])} logic state(s)"
                                if any(s is not None for s in sts) else " as printed"))
        if not changed:
            return
        filters.append(changed)


#: growths of the other part (times the clearance) tried in turn by the motion trims
MOTION_GROWS = (1.25, 1.5, 2.0)
#: rounds of motion trims, each measuring the dense poses again
MOTION_ROUNDS = 3
#: gap (mm) below which a pair is closer than the clearance (mlc.mesh.checks.GAP_EPS)
MOTION_EPS = 1e-6


def _clear_motion(asm: "Assembly", protected: dict, soft_protected: dict, names: list, Ts: list) -> None:
    """Trim slabs that come closer than the clearance in a pose of the dense paths and switches of
    the ``motion_clearance`` goal (:func:`mlc.mesh.checks.motion_check`): ``names`` the poses'
    names, ``Ts`` their part transforms (:meth:`Assembly.part_transforms`), after
    :func:`_resolve` has cleared the logic states.

    Every pair closer than the clearance in some of the poses (:func:`mlc.mesh.spatial.posed_gaps`)
    is settled by trimming one of its two parts, X (never a joint part), in X's rest frame: X loses,
    for each such pose, the other part Y moved relative to X, cropped to the region of Y within
    reach of X (:func:`_near_crop`), each connected piece replaced by its convex hull grown by
    ``g`` (the hull of the piece and its 26 translates by ``g`` along the directions of a cube's
    faces, edges and corners, which holds the piece grown by a ball of radius 0.886 ``g``), less
    X's guards (knuckles, pins; first also the attachment-hole
    spot, as in :func:`_resolve`).  Convex hulls keep the cost bounded: one union of a few convex
    solids a pose and one subtraction, never a union of near-coincident translates (which took
    gigabytes).  ``g`` is tried as :data:`MOTION_GROWS` times the clearance until every pose of the
    pair keeps the clearance.  The trim kept is the one that settles, stays in one piece, keeps the
    attachment spot and removes least; a trim that splits a part is never kept.  Trimming only
    takes material away, so no other gap shrinks.  Notes say what was trimmed and what was not
    settled (the ``motion_clearance`` check then fails)."""
    c = asm.profile.clearance
    if c <= 0 or not Ts:
        return
    parts = asm.parts
    frames = part_frames(asm)
    h = 0.5 * c                       # spacing of the surface samples that find the near region
    samples: dict = {}

    def pts(P):
        if samples.get(P.name, (None,))[0] is not P.solid:
            samples[P.name] = (P.solid, _surface_points(P.solid, h))
        return samples[P.name][1]

    from mlc.mesh.spatial import posed_gaps
    from scipy.spatial import cKDTree
    tried: set = set()
    version = {p.name: 0 for p in parts}      # trims of each part so far
    only = None           # after the first round only the pairs of a trimmed part can change
    for _round in range(MOTION_ROUNDS):
        lo, hi = local_boxes([p.solid for p in parts], frames)
        _log(f"motion trims round {_round}: measuring {len(Ts)} dense poses")
        close, _ = posed_gaps([p.solid for p in parts], frames, lo, hi,
                              [[T[p.name] for p in parts] for T in Ts], c, MOTION_EPS, only)
        pairs: dict = {}
        for k, here in enumerate(close):
            for ij in here:
                pairs.setdefault(ij, []).append(k)
        _log(f"motion trims round {_round}: {len(pairs)} pair(s) within the clearance")
        changed = set()
        for (i, j), ks in sorted(pairs.items()):
            A, B = parts[i], parts[j]
            key = (A.name, B.name, version[A.name], version[B.name], tuple(ks))
            if key in tried:
                continue              # the same pair, unchanged, in the same poses: no better now
            tried.add(key)
            if {i, j} & changed and all(
                    _posed_gap(A, B, Ts[k], c) >= c - MOTION_EPS for k in ks):
                continue              # settled by a trim of one of them earlier in this round
            cands = []
            for X, Y in ((A, B), (B, A)):
                if X.kind == "joint":
                    continue
                tree = cKDTree(pts(X))
                Ms = [np.linalg.solve(Ts[k][X.name], Ts[k][Y.name]) for k in ks]
                guards = [(lost, gd) for lost, gd in ((False, soft_protected.get(X.name)),
                                                       (True, protected.get(X.name))) if gd is not None]
                for lost, guard in guards or [(False, None)]:
                    keep = mf.Manifold() if guard is None else X.solid ^ guard
                    trimmed, ok, best = None, False, -1.0
                    for f in MOTION_GROWS:
                        g = f * c
                        _log(f"  {X.name} less {Y.name} grown by {g:.3g} in {len(Ms)} pose(s)")
                        tool = []
                        for M in Ms:
                            Yp = transform_solid(Y.solid, M)
                            crop = _near_crop(tree, pts(Y) @ M[:3, :3].T + M[:3, 3], g + 2 * h)
                            if crop is None:
                                continue
                            tool += _grown_hulls(Yp ^ crop, g)
                        if not tool:
                            break
                        _log(f"    {len(tool)} hulls")
                        trimmed = _clean(X.solid - (union(tool) - keep))
                        _log(f"    trimmed: {trimmed.num_vert()} v")
                        gaps = [_gap(trimmed, Y.solid, M, c) for M in Ms]
                        _log(f"    smallest gap {min(gaps):.5f} mm, {sum(x < c - MOTION_EPS for x in gaps)} pose(s) short")
                        ok = all(x >= c - MOTION_EPS for x in gaps)
                        if ok or min(gaps) <= best + MOTION_EPS:
                            break     # settled, or the guards hold the short gap: growing more cannot help
                        best = min(gaps)
                    if trimmed is None:
                        continue
                    removed = X.solid.volume() - trimmed.volume()
                    if removed <= 1e-9 or len(trimmed.decompose()) != 1:
                        continue
                    cands.append((not ok, lost, removed, X, trimmed, Y))
                    if ok:
                        break
                if cands and cands[0][:2] == (False, False):
                    break         # settled keeping the attachment spot: the other part is not tried
            if not cands:
                asm.notes.append(f"{A.name} and {B.name} come within the clearance in {len(ks)} pose(s) of the "
                                 "dense paths: no trim settles it (knuckles, pins or the joint part)")
                continue
            unsettled, lost, removed, X, trimmed, Y = min(cands, key=lambda x: x[:3])
            X.solid = trimmed
            version[X.name] += 1
            changed.add(parts.index(X))
            asm.motion_trims.append({"part": X.name, "clear_of": Y.name, "poses": [names[k] for k in ks],
                                     "removed_mm3": round(float(removed), 6), "settled": not unsettled})
            asm.notes.append(f"trimmed {removed:.3g} mm^3 from {X.name} to keep the clearance from {Y.name} in "
                             f"{len(ks)} pose(s) of the dense paths" + (" (not settled)" if unsettled else ""))
        if not changed:
            return
        only = changed


# -- rubs on the way to a state, in a compiled circuit (session 56) -----------------------------
#: compiled circuits: two bodies that meet on the way to a logic state (a coarse pose "st@f") but
#: in no logic state get the motion trim (_clear_motion) in poses interpolated along that stretch
STROKE_CLEAR = True
#: ... the interpolated poses: no corner of the second part's box moves more than this (times the
#: clearance) relative to the first from one pose to the next
STROKE_STEP = 0.5
#: ... at most this many pairs are trimmed so (the cost stays bounded on a large scene; a note says
#: how many were left)
STROKE_MAX_PAIRS = 32
#: ... and two bodies that share no hinge and meet in a logic state too (session 66): the final
#: trims of a large assembly (_resolve with reuse) trim only what is too close as printed, trusting
#: the sampled trim radii to clear every pose, and those clear only a hinge's own bodies (the
#: compiled (a & b) | c: g2's a_hi met out_hi in row 110, 0.012 mm^3); at most STATE_MAX_PAIRS
#: such pairs, and a trim that does not settle its pair is not kept
STATE_CLEAR = True
STATE_MAX_PAIRS = 4
#: ... each trimmed in a child process stopped after this long (s), with TRIM_MEMORY
STATE_TRIM_SECONDS = 20.0
#: ... and two bodies that share no hinge and come within the clearance on the way to a state
#: without meeting anywhere (session 67: a gate's input lever passing its output lever, 0.021 mm, in
#: the README circuit and the robot: the coarse ``motion_clearance`` goal), the pairs printed
#: farthest apart first (a stroke: a lever sweeping past another part, not a joint's play), at most
#: CLOSE_MAX_PAIRS, each as a state pair (capped, kept only if it settles the pair)
CLOSE_STROKES = True
CLOSE_MAX_PAIRS = 8
#: ... and a body and a joint part that is not its own (joint parts are never trimmed: the body is)
#: that meet in a logic state or come within the clearance in a pose, on the way or in a state, as
#: those pairs of bodies (session 68: the README circuit's g1_b_lo under g1_ujoint_d in row 11,
#: 0.19 mm), at most JOINT_MAX_PAIRS of them, beside the bodies' own caps
JOINT_STROKES = True
JOINT_MAX_PAIRS = 4
STROKE_EPS = 1e-6          # mm^3: the states check's VOL_EPS (mlc.mesh.checks)


def _part_boxes(asm: "Assembly") -> tuple:
    """The parts' frames, their boxes in those frames and their world boxes: (frames, llo, lhi,
    lo, hi), as the states check takes them."""
    parts = asm.parts
    frames = part_frames(asm) if asm.congruence is None else asm.congruence.frames
    llo, lhi = local_boxes([p.solid for p in parts], frames)
    lo, hi = solid_boxes([p.solid for p in parts])
    return frames, llo, lhi, lo, hi


def _meeting_pairs(asm: "Assembly", Ts: list, wanted=None, boxes=None) -> list:
    """For each part-transform dict of ``Ts``, the pairs ``(i, j)`` of parts that share more than
    :data:`STROKE_EPS` of volume there: the states check's own test (posed boxes, oriented boxes,
    the triangles' proof of apartness, then the boolean; its congruence cache: the same key, so
    the check finds the unchanged pairs measured).  ``wanted(i, j)``: which candidate pairs to test;
    ``boxes``: :func:`_part_boxes` of the parts as they are (computed here when not given)."""
    from mlc.mesh.apart import surfaces_apart
    parts = asm.parts
    cong = asm.congruence
    frames, llo, lhi, lo, hi = _part_boxes(asm) if boxes is None else boxes
    meshes: dict = {}
    out = []
    for T in Ts:
        Tp = [T[p.name] for p in parts]
        cand = posed_pairs(Tp, frames, llo, lhi, *posed_boxes(lo, hi, Tp), 0.0, wanted)
        posed: dict = {}

        def vol(i, j):
            for k in (i, j):
                if k not in meshes:
                    m = parts[k].solid.to_mesh64()
                    meshes[k] = (np.asarray(m.vert_properties, float)[:, :3], np.asarray(m.tri_verts, np.int64))
                if k not in posed:
                    V, F = meshes[k]
                    posed[k] = (V @ Tp[k][:3, :3].T + Tp[k][:3, 3], F)
            if surfaces_apart(*posed[i], *posed[j]):
                return 0.0
            return float((transform_solid(parts[i].solid, Tp[i]) ^ transform_solid(parts[j].solid, Tp[j])).volume())

        rels = cong.rel_many(cand, Tp) if cong is not None else None
        here = set()
        for k, (i, j) in enumerate(cand):
            v = (vol(i, j) if cong is None else
                 cong.lookup(("volume", cong.key(i, parts[i].solid), cong.key(j, parts[j].solid), rels[k]),
                             lambda: vol(i, j)))
            if v > STROKE_EPS:
                here.add((i, j))
        out.append(here)
    return out


def _near_pairs(asm: "Assembly", Ts: list, wanted, boxes, c: float) -> list:
    """For each part-transform dict of ``Ts``, the pairs ``(i, j)`` of parts (of those ``wanted(i,
    j)`` lets through) closer than ``c`` there: the coarse clearance check's own candidates and
    measure (:func:`mlc.mesh.spatial.posed_pairs`, :func:`mlc.mesh.spatial.pair_gaps`, its
    congruence cache), as in :func:`_meeting_pairs`."""
    parts = asm.parts
    solids = [p.solid for p in parts]
    frames, llo, lhi, lo, hi = boxes
    out = []
    for T in Ts:
        Tp = [T[p.name] for p in parts]
        cand = posed_pairs(Tp, frames, llo, lhi, *posed_boxes(lo, hi, Tp), c, wanted)
        gaps = pair_gaps(solids, Tp, cand, c, {}, asm.congruence)
        out.append({ij for ij, g in zip(cand, gaps) if g < c - 1e-6})
    return out


def _interpolated(M0, M1, step: float, corners) -> list:
    """Transforms from ``M0`` to ``M1`` (4x4; ``M0`` left out, ``M1`` last): the rotation turned
    about the fixed axis of ``M0^-1 M1``'s rotation at a constant rate, the translation moved on a
    straight line, in as many equal steps as keep every point of ``corners`` (a part's box
    corners, its own rest frame) within ``step`` of where the step before took it."""
    from mlc.geometry.rotation import expmap
    R0, R1 = M0[:3, :3], M1[:3, :3]
    dR = R0.T @ R1
    ang = float(np.arccos(np.clip((np.trace(dR) - 1) / 2, -1.0, 1.0)))
    if ang < 1e-12:
        w = np.zeros(3)
    else:
        w = np.array([dR[2, 1] - dR[1, 2], dR[0, 2] - dR[2, 0], dR[1, 0] - dR[0, 1]]) / (2 * np.sin(ang)) * ang
    X = np.c_[corners, np.ones(len(corners))]
    move = float(np.linalg.norm((X @ (M1 - M0).T)[:, :3], axis=1).max())
    n = max(1, int(np.ceil(move / step)))
    out = []
    for k in range(1, n + 1):
        f = k / n
        M = np.eye(4)
        M[:3, :3] = R0 @ expmap(w * f)
        M[:3, 3] = (1 - f) * M0[:3, 3] + f * M1[:3, 3]
        out.append(M)
    return out


def _clear_strokes(asm: "Assembly", protected: dict, soft_protected: dict, Ts: list) -> None:
    """A compiled circuit is posed coarsely (its logic states and ``PATH_STEPS`` poses on the way
    to each, ``"01@0.71"``), and gets no dense paths, so no motion trim (:func:`_clear_motion`):
    two bodies that rub on the way to a state and clear each other at its ends were left meeting
    (the README circuit's gate g3: the input levers' tips ran into ``out_hi`` at ``@0.71`` and
    ``@0.86``, issue 13, as in the library gates before their motion trims).

    ``Ts``: the parts' transforms in ``asm.poses`` (in order).  Every pair of two bodies that
    shares volume in a pose on the way to a state (:func:`_meeting_pairs`) and in none of the
    logic states is given the motion trim of :func:`_clear_motion`, for the clearance, in poses
    of the one relative to the other interpolated (:func:`_interpolated`, steps of
    :data:`STROKE_STEP` times the clearance) over that stretch of the path: from the coarse pose
    before the first where they meet to the one after the last (rest and the state itself at
    the ends).  The poses between the coarse ones are interpolated, not solved: the trim's growth
    (at least 1.25 times the clearance) is their margin.

    Four kinds of pair, each tagged in its trim's note:

    * *meeting on the way* (above): at most :data:`STROKE_MAX_PAIRS`, trimmed in this process;
    * *meeting in a state* (:data:`STATE_CLEAR`): two bodies that share no hinge and meet in a
      logic state, over the stretches of the paths that end there (on the way too), at most
      :data:`STATE_MAX_PAIRS`;
    * *near on the way* (:data:`CLOSE_STROKES`, "within the clearance on the way to ..."): two
      bodies that share no hinge and come within the clearance on the way to a state without
      meeting anywhere (:func:`_near_pairs`), those printed farthest apart first (a stroke past
      another part rather than a joint's play), at most :data:`CLOSE_MAX_PAIRS`, trimmed as
      state pairs;
    * *a body and a joint part not its own* (:data:`JOINT_STROKES`): meeting in a logic state, or
      within the clearance in any pose, at most :data:`JOINT_MAX_PAIRS` of each, trimmed as state
      pairs (the body: joint parts are never trimmed).

    State and near pairs are trimmed in a child process capped at :data:`STATE_TRIM_SECONDS` and
    ``TRIM_MEMORY`` (a trim that cannot settle its pair tries every growth) and kept only if the
    trim settles the pair; the states and ``motion_clearance`` checks report what is left."""
    poses = asm.poses or {}
    names = list(poses)
    c = asm.profile.clearance
    on_way = [k for k, n in enumerate(names) if "@" in n]
    if c <= 0 or not on_way:
        return
    parts = asm.parts
    body = [p.kind == "body" for p in parts]
    _log("rubs on the way to the states")
    boxes = _part_boxes(asm)         # the parts are not trimmed until every pair is found
    met = _meeting_pairs(asm, [Ts[k] for k in on_way], lambda i, j: body[i] and body[j], boxes)
    pairs: dict = {}
    for k, here in zip(on_way, met):
        for ij in here:
            pairs.setdefault(ij, []).append(k)
    ends = [k for k, n in enumerate(names) if "@" not in n]

    def one_body(i, j):
        # (JOINT_STROKES) a body and a joint part that is not its own
        return JOINT_STROKES and body[i] != body[j] and parts[j].name not in parts[i].partners
    met_end = _meeting_pairs(asm, [Ts[k] for k in ends], lambda i, j: (body[i] and body[j]) or one_body(i, j),
                             boxes)
    in_state = set().union(*met_end)
    pairs = {ij: ks for ij, ks in pairs.items() if ij not in in_state}
    state_pairs: dict = {}
    near_only: set = set()       # (CLOSE_STROKES) of state_pairs: those that only come near
    if STATE_CLEAR:
        # bodies that share no hinge and meet in a logic state: trimmed over the stretches of the
        # paths that end where they meet (on the way there too), if that settles them
        for k, here in zip(ends, met_end):
            for i, j in here:
                if parts[j].name not in parts[i].partners:
                    state_pairs.setdefault((i, j), []).append(k)
        # (pairs of bodies and pairs with a joint part each within their own cap)
        for ij in ([ij for ij in sorted(state_pairs) if body[ij[0]] and body[ij[1]]][STATE_MAX_PAIRS:]
                   + [ij for ij in sorted(state_pairs) if not (body[ij[0]] and body[ij[1]])][JOINT_MAX_PAIRS:]):
            del state_pairs[ij]
        if len(in_state) > len(state_pairs):
            asm.notes.append(f"bodies that meet in a logic state: {len(in_state)} pairs, {len(state_pairs)} of them "
                             f"(sharing no hinge, at most {STATE_MAX_PAIRS}) trimmed where that settles them")
        for ij, ks in state_pairs.items():
            ks += [k for k, here in zip(on_way, met) if ij in here]

    def take_near(ks, near, cap, what):
        # near pairs (``near[n]``: those of pose ``ks[n]``) become state pairs, printed farthest apart first
        close: dict = {}
        for k, here in zip(ks, near):
            for ij in here:
                close.setdefault(ij, []).append(k)
        printed = {ij: float(parts[ij[0]].solid.min_gap(parts[ij[1]].solid, 50 * c)) for ij in close}
        ranked = sorted(close, key=lambda ij: (-printed[ij], ij))
        if len(ranked) > cap:
            asm.notes.append(f"{what}: {len(ranked)} pairs, the {cap} printed farthest apart trimmed where that "
                             "settles them")
        for ij in ranked[:cap]:
            state_pairs[ij] = close[ij]
            near_only.add(ij)
    if CLOSE_STROKES:
        # bodies that share no hinge and come within the clearance on the way, meeting nowhere:
        # trimmed as a state pair (capped, kept if settled), those printed farthest apart first
        near = _near_pairs(asm, [Ts[k] for k in on_way], lambda i, j: body[i] and body[j] and (i, j) not in pairs
                            and (i, j) not in in_state and parts[j].name not in parts[i].partners, boxes, c)
        take_near(on_way, near, CLOSE_MAX_PAIRS, "bodies within the clearance on the way to the states")
    if CLOSE_STROKES and JOINT_STROKES:
        # a body and a joint part not its own within the clearance, in a state or on the way
        taken = set(state_pairs) | set(pairs) | in_state
        near = _near_pairs(asm, Ts, lambda i, j: one_body(i, j) and (i, j) not in taken, boxes, c)
        take_near(range(len(Ts)), near, JOINT_MAX_PAIRS, "bodies within the clearance of a joint part not their own")
    if not pairs and not state_pairs:
        return
    if len(pairs) > STROKE_MAX_PAIRS:
        asm.notes.append(f"rubs on the way to the states: {len(pairs)} pairs of bodies, the first "
                         f"{STROKE_MAX_PAIRS} trimmed")
    frames, llo, lhi = boxes[:3]
    for (i, j), ks in sorted(pairs.items())[:STROKE_MAX_PAIRS] + sorted(state_pairs.items()):
        A, B = parts[i], parts[j]
        sel = np.array([[(lhi if (q >> a) & 1 else llo)[j, a] for a in range(3)] for q in range(8)])
        corners = sel @ frames[j][:3, :3].T + frames[j][:3, 3]     # B's box corners, rest world
        step = STROKE_STEP * c
        dense_names, dense_T = [], []
        for st in sorted({names[k].split("@")[0] for k in ks}):
            rest = "0" * len(st)
            path = sorted((float(n.split("@")[1]), k) for k, n in enumerate(names) if n.split("@")[0] == st and "@" in n)
            seq = (([names.index(rest)] if rest in poses else []) + [k for _, k in path]
                   + ([names.index(st)] if st in poses else []))
            hit = [n for n, k in enumerate(seq) if k in ks]
            seq = seq[max(0, hit[0] - 1):hit[-1] + 2]
            rel = [np.linalg.solve(Ts[k][A.name], Ts[k][B.name]) for k in seq]
            dense_names.append(names[seq[0]])
            dense_T.append({A.name: np.eye(4), B.name: rel[0]})
            for (k0, M0), (k1, M1) in zip(zip(seq, rel), zip(seq[1:], rel[1:])):
                mid = _interpolated(M0, M1, step, corners)
                for q, M in enumerate(mid):
                    dense_names.append(names[k1] if q == len(mid) - 1 else f"{names[k0]}~{names[k1]}#{q + 1}")
                    dense_T.append({A.name: np.eye(4), B.name: M})
        _log(f"  {A.name} / {B.name}: meet in {', '.join(names[k] for k in ks)}; "
             f"{len(dense_T)} poses on the way")
        view = copy.copy(asm)
        view.parts = [A, B]
        view.congruence = None
        before, n_notes = len(asm.motion_trims), len(asm.notes)
        if (i, j) in state_pairs:
            # a pair that meets in a state: trimmed in a child process with a time and memory cap
            # (a trim that cannot settle it tries every growth, minutes on two gate parts), and
            # kept only if it settles it (the states check reports it otherwise)
            got = _isolated(lambda: _settled_motion(view, protected, soft_protected, dense_names, dense_T, before,
                                                    n_notes), STATE_TRIM_SECONDS, TRIM_MEMORY)
            where = ", ".join(names[k] for k in ks if "@" not in names[k])
            if (i, j) in near_only:
                where = ("within the clearance " + ("in or " if any("@" not in names[k] for k in ks) else "")
                         + "on the way to " + ", ".join(sorted({names[k].split("@")[0] for k in ks})))
            else:
                where = "meet in " + where
            if not isinstance(got, tuple):
                asm.notes.append(f"{A.name} and {B.name} {where}: "
                                 + ("no trim settles it" if got == "none" else
                                    f"trim stopped (over {STATE_TRIM_SECONDS:g} s or {TRIM_MEMORY / 2 ** 30:g} GiB)")
                                 + ", not trimmed")
                continue
            meshes, trims, notes_ = got
            del asm.motion_trims[before:], asm.notes[n_notes:]     # (what it left here, run without a fork)
            for P in (A, B):
                if P.name in meshes:
                    P.solid = mf.Manifold(mf.Mesh64(vert_properties=meshes[P.name][0], tri_verts=meshes[P.name][1]))
            asm.motion_trims += trims
            asm.notes += notes_
        else:
            _clear_motion(view, protected, soft_protected, dense_names, dense_T)
        for t in asm.motion_trims[before:]:
            t["near" if (i, j) in near_only else "state" if (i, j) in state_pairs else "stroke"] = True
        asm.notes[n_notes:] = [x.replace("of the dense paths", "interpolated on the way to the states")
                               for x in asm.notes[n_notes:]]


def _settled_motion(view: "Assembly", protected, soft_protected, names, Ts, before: int, n_notes: int):
    """:func:`_clear_motion` of ``view``'s parts in the poses ``Ts``, for a child process
    (:func:`_isolated`): ``({part: (vertices, triangles)}, motion_trims, notes)`` of what it
    trimmed if every trim settled its pair, else ``"none"`` (``before``/``n_notes``: the lengths
    of ``view.motion_trims``/``view.notes`` before)."""
    solids = {p.name: p.solid for p in view.parts}
    _clear_motion(view, protected, soft_protected, names, Ts)
    trims = view.motion_trims[before:]
    if not trims or not all(t["settled"] for t in trims):
        for p in view.parts:          # (run in this process where there is no fork)
            p.solid = solids[p.name]
        del view.motion_trims[before:], view.notes[n_notes:]
        return "none"
    out = {}
    for p in view.parts:
        if p.solid is not solids[p.name]:
            m = p.solid.to_mesh64()
            out[p.name] = (np.asarray(m.vert_properties, float)[:, :3].copy(), np.asarray(m.tri_verts, np.uint64).copy())
    return out, [dict(t) for t in trims], list(view.notes[n_notes:])


def _posed_gap(A: "Part", B: "Part", T: dict, search: float) -> float:
    """The gap (mm) between parts ``A`` and ``B`` moved by the part transforms ``T``, searched to
    ``search``."""
    return _gap(A.solid, B.solid, np.linalg.solve(T[A.name], T[B.name]), search)


def _gap(a: mf.Manifold, b: mf.Manifold, M, search: float) -> float:
    """The gap (mm) between solid ``a`` and solid ``b`` moved by ``M`` (4x4, into ``a``'s
    frame), searched to ``search`` (manifold3d ``min_gap``)."""
    return float(a.min_gap(transform_solid(b, M), search))


# 26 directions (a cube's faces, edges and corners): a close polyhedral stand-in for a ball
CUBE_DIRS = np.array([v for v in itertools.product((-1, 0, 1), repeat=3) if any(v)], float)
CUBE_DIRS /= np.linalg.norm(CUBE_DIRS, axis=1)[:, None]


def _grown_hulls(solid: mf.Manifold, g: float) -> list:
    """Each connected piece of ``solid`` as the convex hull of the piece and its 26 translates
    by ``g`` along :data:`CUBE_DIRS` (a superset of the piece grown by a ball of radius 0.886
    ``g``): bounded cost, where a union of the near-coincident translates took gigabytes."""
    off = np.vstack([np.zeros(3), g * CUBE_DIRS])
    hulls = []
    for piece in solid.decompose():
        V = np.asarray(piece.to_mesh().vert_properties, float)[:, :3]
        if len(V) >= 4:
            hulls.append(mf.Manifold.hull_points((V[None, :, :] + off[:, None, :]).reshape(-1, 3)))
    return hulls


def _surface_points(solid: mf.Manifold, h: float) -> np.ndarray:
    """Points on the surface of ``solid`` no farther than ``h`` (mm) from every surface point: each
    triangle's vertices and a regular barycentric grid of edge at most ``h`` (deterministic)."""
    m = solid.to_mesh()
    V = np.asarray(m.vert_properties, float)[:, :3]
    F = np.asarray(m.tri_verts, np.int64)
    if len(F) == 0:
        return V
    a, b, cc = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]
    edge = np.max([np.linalg.norm(b - a, axis=1), np.linalg.norm(cc - b, axis=1), np.linalg.norm(a - cc, axis=1)],
                  axis=0)
    n = np.maximum(1, np.ceil(edge / h).astype(int))
    out = [V]
    for k in np.unique(n):
        sel = n == k
        ij = np.array([(x, y) for x in range(k + 1) for y in range(k + 1 - x)], float) / k
        out.append((a[sel][:, None, :] + ij[None, :, 0, None] * (b[sel] - a[sel])[:, None, :]
                    + ij[None, :, 1, None] * (cc[sel] - a[sel])[:, None, :]).reshape(-1, 3))
    return np.concatenate(out)


def _near_crop(tree, Y_pts, reach: float):
    """A box (manifold, X's rest frame) holding every point of Y within ``reach - 2 h`` (mm) of X,
    ``h`` the spacing of the surface samples: X's in ``tree`` (a cKDTree), Y's in ``Y_pts`` (posed
    in X's frame).  A point y of Y within g of X has a surface point y' of Y on its way to X, as
    near to X and at most g from y; y' lies within h of a sample of Y, and that sample within
    g + 2 h of a sample of X; so the box of such samples grown by ``reach`` holds y.  None if no
    sample of Y comes within ``reach``."""
    d, _ = tree.query(Y_pts, distance_upper_bound=reach)
    near = Y_pts[np.isfinite(d)]
    if len(near) == 0:
        return None
    lo, hi = near.min(axis=0) - reach, near.max(axis=0) + reach
    return mf.Manifold.cube((hi - lo).tolist()).translate(lo.tolist())


TRIM_SECONDS = 30.0       # large assemblies: time cap of one pair's final trim (s)
TRIM_MEMORY = 2 * 2 ** 30  # and its memory cap above the parent's (bytes)


def _best_mesh(cands, A):
    """The trim :func:`_resolve` takes among ``cands`` as plain arrays: (0 if it trims ``A`` else 1,
    vertices, triangles, volume removed, settled), or ``"none"``."""
    if not cands:
        return "none"
    unsettled, split, lost, removed, X, trimmed, Y = min(cands, key=lambda x: x[:4])
    m = trimmed.to_mesh64() if hasattr(trimmed, "to_mesh64") else trimmed.to_mesh()
    return (0 if X is A else 1, np.asarray(m.vert_properties, float)[:, :3].copy(),
            np.asarray(m.tri_verts, np.uint64).copy(), removed, not unsettled)


#: a forked child that sleeps without using any CPU this long (s) is taken as deadlocked
STALL_SECONDS = 1.0
#: forks tried before a stalled pair counts as capped
FORK_TRIES = 6


def _cpu_state(pid: int):
    """(state letter, user + system clock ticks) of process ``pid`` from /proc, or None."""
    try:
        with open(f"/proc/{pid}/stat") as f:
            rest = f.read().rsplit(")", 1)[1].split()
        return rest[0], int(rest[11]) + int(rest[12])
    except (OSError, IndexError, ValueError):
        return None


def _isolated(fn, seconds: float, extra_bytes: float):
    """``fn()`` in a forked child whose address space may grow by ``extra_bytes`` and which may
    run ``seconds``; its (picklable) result, or None if it failed, ran out of memory or time.
    Without ``os.fork`` (not Linux) ``fn()`` runs in this process.

    A child forked while another thread of this process (manifold3d's or the BLAS thread pool)
    held a lock can wait on that lock forever: measured, about 1 fork in 30 after a large
    boolean, and 3 of the Tetris circuit's 34 final trims, each then capped at ``seconds`` and
    left untrimmed -- a different report from one run to the next.  A child asleep with no CPU
    time used for :data:`STALL_SECONDS` is killed and forked again (up to :data:`FORK_TRIES`
    times, within the same ``seconds``)."""
    import pickle
    import resource
    import select
    import signal
    if not hasattr(os, "fork"):
        return fn()
    vm = 0
    try:
        for ln in open("/proc/self/status"):
            if ln.startswith("VmSize"):
                vm = int(ln.split()[1]) * 1024
    except OSError:
        return fn()
    deadline = time.monotonic() + seconds
    for _try in range(FORK_TRIES):
        left = deadline - time.monotonic()
        if left <= 0:
            return None
        r, w = os.pipe()
        pid = os.fork()
        if pid == 0:       # child: never returns
            code = 1
            try:
                os.close(r)
                soft, hard = resource.getrlimit(resource.RLIMIT_AS)
                cap = int(vm + extra_bytes)
                if hard != resource.RLIM_INFINITY:
                    cap = min(cap, hard)
                resource.setrlimit(resource.RLIMIT_AS, (cap, hard))
                signal.alarm(max(1, int(np.ceil(left))))
                data = pickle.dumps(fn(), protocol=pickle.HIGHEST_PROTOCOL)
                with os.fdopen(w, "wb") as f:
                    f.write(data)
                code = 0
            except BaseException:
                pass
            finally:
                os._exit(code)
        os.close(w)
        chunks = []
        stalled = False
        last = (None, time.monotonic())      # (CPU ticks, since when)
        with os.fdopen(r, "rb", buffering=0) as f:
            while True:
                ready, _, _ = select.select([f], [], [], 0.2)
                if ready:
                    b = f.read(1 << 20)
                    if not b:
                        break                # end of file: the child is done
                    chunks.append(b)
                    last = (None, time.monotonic())
                    continue
                st = _cpu_state(pid)
                now = time.monotonic()
                if st is None or st[0] in "ZX":
                    continue                 # exiting: its end of file comes next
                if st[0] == "S" and st[1] == last[0]:
                    if now - last[1] >= STALL_SECONDS:
                        stalled = True
                        break
                elif st[1] != last[0] or st[0] != "S":
                    last = (st[1], now)
        if stalled:
            try:
                os.kill(pid, signal.SIGKILL)
            except OSError:
                pass
            os.waitpid(pid, 0)
            _log(f"  forked child stalled (no CPU for {STALL_SECONDS:g} s): forked again")
            continue
        data = b"".join(chunks)
        _, status = os.waitpid(pid, 0)
        if not (os.WIFEXITED(status) and os.WEXITSTATUS(status) == 0) or not data:
            return None
        return pickle.loads(data)
    return None


def _locked(A, B, protected: dict, fat: dict) -> bool:
    """True if parts ``A`` and ``B`` overlap (as printed) only inside the material both must keep:
    their grown guards (``fat``) or, for a joint part, the whole part."""
    inter = A.solid ^ B.solid
    if inter.volume() <= 1e-6:
        return False
    for P in (A, B):
        g = fat[P.name][0] if P.name in fat else protected.get(P.name)
        if g is None or (inter - g).volume() > 1e-6:
            return False
    return True


def _rss_gb() -> float:
    """Resident memory of this process now and at its peak (GB, from /proc/self/status)."""
    out = {}
    try:
        for ln in open("/proc/self/status"):
            if ln.startswith(("VmRSS", "VmHWM")):
                out[ln.split(":")[0]] = int(ln.split()[1]) / 2 ** 20
    except OSError:
        pass
    return out.get("VmRSS", 0.0), out.get("VmHWM", 0.0)


_T0 = time.perf_counter()


def _log(msg: str) -> None:
    """Progress of the build and its final trims on stderr when the environment variable
    ``MLC_MESH_LOG`` is set (diagnostics): seconds since import, resident and peak memory (GB)."""
    if os.environ.get("MLC_MESH_LOG"):
        r, p = _rss_gb()
        print(f"[mesh {time.perf_counter() - _T0:7.1f} s {r:.2f}/{p:.2f} GB] {msg}", file=sys.stderr, flush=True)


def _flat(solid: mf.Manifold) -> mf.Manifold:
    """The same solid as a fresh mesh (double precision): no boolean history kept with it, and
    the memory freed by the booleans handed back to the system (glibc ``malloc_trim``)."""
    out = mf.Manifold(solid.to_mesh64()) if hasattr(solid, "to_mesh64") else solid
    try:
        import ctypes
        ctypes.CDLL("libc.so.6").malloc_trim(0)
    except (OSError, AttributeError):
        pass
    return out


def _trim_by(X, Y, sts, grow, dirs, keep, state_grow, merged=False):
    """X less Y grown (union of translated copies) in each of the states ``sts`` -- by ``grow``
    as printed (None), by a third of it in a logic state -- restricted to where the two meet;
    X's protected material ``keep`` stays.

    ``merged``: the same set, built with bounded memory -- Y's cropped copies of all logic states
    are united first and that union is grown (27 copies in all instead of 27 per state: a compiled
    circuit has up to 50 poses, and 27 x 50 meshes in one boolean took gigabytes).  There
    ``keep`` may be any region (a guard grown around X's knuckles): X's material inside it stays,
    as X less (tool less keep) -- the same set as (X less tool) united with X's part of keep."""
    if merged:
        groups: dict = {}
    ks = []
    xb = np.asarray(X.solid.bounding_box())
    for T in sts:
        M = np.eye(4) if T is None else np.linalg.inv(T[X.name]) @ T[Y.name]
        Yp = transform_solid(Y.solid, M)
        yb = np.asarray(Yp.bounding_box())
        if T is None:
            lo, hi = np.maximum(xb[:3], yb[:3] - 2 * grow), np.minimum(xb[3:], yb[3:] + 2 * grow)
        else:
            ib = np.asarray((X.solid ^ Yp).bounding_box())
            lo, hi = ib[:3], ib[3:]
        lo, hi = lo - 3 * grow, hi + 3 * grow
        if np.any(hi <= lo):
            continue
        crop = mf.Manifold.cube((hi - lo).tolist()).translate(lo.tolist())
        Yc = Yp ^ crop                  # only the part of Y near the conflict matters
        if Yc.is_empty():
            continue
        # as printed the gap must reach the clearance; in a logic state it need only be positive
        g_ = grow if T is None else state_grow
        if merged:
            groups.setdefault(g_, []).append(Yc)
        else:
            ks += [Yc] + [Yc.translate((g_ * d).tolist()) for d in dirs]
    if merged:
        # bounded cost and memory: X less, state by state, the convex hull of each piece of Y's
        # cropped copy and its 26 translates (a superset of their union), each boolean evaluated
        # at once.  The union of the 27 copies themselves is one boolean of near-coincident
        # surfaces: for a gate body against a connector slab in 23 poses it took 18 GB and
        # minutes (the memory growth of issue 13).
        res = X.solid
        hit = False
        for g_, ys in groups.items():
            for Yc in ys:
                yb = np.asarray(Yc.bounding_box())
                if not _bb_near(np.asarray(res.bounding_box()), yb, 1.01 * g_):
                    continue
                hulls = _grown_hulls(Yc, g_)
                if not hulls:
                    continue
                _log(f"    hull {sum(h.num_vert() for h in hulls)} v, X {res.num_vert()} v")
                # ``keep`` (X's material to keep, or a guard around it) is taken out of the tool
                # rather than united back: one subtraction, no faces shared with X's own
                res = res - (union(hulls) - keep)
                res.num_tri()             # evaluate now (no deferred n-ary boolean)
                _log(f"    subtracted: {res.num_vert()} v")
                hit = True
        if not hit:
            return None
        return _clean(res)
    if not ks:
        return None
    return _clean(union([X.solid - union(ks), keep]))


def _bb_near(a, b, margin) -> bool:
    return bool(np.all(a[:3] <= b[3:] + margin) and np.all(b[:3] <= a[3:] + margin))


def _second_pin(u, ob, axes, slabs, center) -> tuple:
    """A universal joint's second pin (unit, square to the first pin ``u``) fixed in body
    ``ob``: along its hinge, or across its slabs when that hinge runs along ``u``; and whether
    it did (``parallel``)."""
    v = _hinge_dir(ob, axes, slabs, center)
    parallel = abs(np.dot(u, v)) > 0.95
    if parallel:
        w = np.mean([sb.center for sb in slabs[ob]], axis=0) - center
        v = np.cross(u, w)
        if np.linalg.norm(v) < 1e-9:
            v = _perp_frame(u)[:, 0]
    v = v - np.dot(v, u) * u
    return v / np.linalg.norm(v), parallel


def _pending_yokes(joints, groups, scene, axes, slabs, s, g) -> dict:
    """Every compound junction's yoke before any is laid out: joint -> (its yoke's body, the
    joint point in mm, its untwisted second pin :func:`_second_pin`).
    ``_PinClearance.least_twist`` keeps a joint's turned yoke clear of these for the joints
    after it; each is dropped when its joint is laid out."""
    out = {}
    for jname, bonds in joints.items():
        if bonds[0].kind != "universal" or jname in groups:
            continue
        bd = bonds[0]
        cb, ob = bd.a.split(".")[0], bd.b.split(".")[0]
        center = 0.5 * (scene.site_world(bd.a) + scene.site_world(bd.b)) * s
        for side_b, other_b in ((cb, ob), (ob, cb)):
            hx = _host_axis(side_b, axes, center, s, g)
            if hx is not None:
                v, _ = _second_pin(hx.direction, other_b, axes, slabs, center)
                out[jname] = (other_b, center, v)
                break
    return out


def _hinge_dir(bn, axes, slabs, center) -> np.ndarray:
    mine = [ax for ax in axes if bn in ax.bodies]
    if mine:
        return mine[0].direction.copy()
    near = min(slabs[bn], key=lambda sb: np.linalg.norm(sb.center - center))
    order = np.argsort(near.size)
    return near.R[:, order[1]].copy()   # the width direction (middle dimension)


def _axis_distance(p, ax: HingeAxis) -> float:
    """Distance of point ``p`` from hinge ``ax``'s knuckle span (the segment of its line)."""
    r = np.asarray(p, float) - ax.origin
    a = float(np.clip(np.dot(r, ax.direction), -ax.span / 2, ax.span / 2))
    return float(np.linalg.norm(r - a * ax.direction))


def _extent_along(sbs, center, d) -> float:
    near = min(sbs, key=lambda sb: np.linalg.norm(sb.center - center))
    return float(np.sum(np.abs(near.R.T @ d) * near.size))


def _uj_samples(uj: UJoint, base_samples, slabs, reach, t, h, n) -> dict:
    """The sample points (mm) of a universal joint's two bodies for its trim radii: their slabs'
    (``base_samples``) and the yoke plates that widen them to its knuckles (:func:`_uj_plates`)."""
    return {bn: np.concatenate([base_samples[bn], _slab_samples(_uj_plates(uj, k, slabs[bn], uj.rho[k] + reach, t, n), h)])
            for k, bn in enumerate(uj.bodies)}


def _fin_free(uj: UJoint, state_T, c, t) -> bool:
    """(FIN_KEPT) Whether a compound junction's fin (O's yoke plate along the host's line,
    :func:`_uj_plates`) can stay past the joint part's ball inside O's trim about the second pin
    (:func:`_fin_keep`).  That trim's full radius is the sweep of the host's collar all the way
    about the pin (``hypot(reach, R) + c``), and it took all but the fin's last 0.16 mm between
    the knuckles: the one link of the yoke knuckle away from O's end knuckle (session 60).  On
    the fin's side (+u) the joint part has nothing but its ball (its collar, pin and knuckle lie
    along -u), and relative to O it turns about v only, by the angle between the host's line in C
    and in O: free when that angle in every pose, plus the fin's half thickness seen from the
    ball and 10 degrees, stays under 90 degrees (the collar stays on its own side)."""
    if uj.host is None or uj.fin <= 0:
        return False
    u, v = uj.axes
    C, O = uj.bodies
    th = 0.0
    for _, Ts in state_T:
        if Ts is None:
            continue
        w = (np.linalg.inv(Ts[O]) @ Ts[C])[:3, :3] @ u
        th = max(th, abs(float(np.degrees(np.arctan2(np.cross(u, w) @ v, u @ w)))))
    return th + float(np.degrees(np.arctan2(t / 2, uj.hub_r + c))) + 10.0 < 90.0


def _fin_keep(uj: UJoint, c, t, n) -> mf.Manifold:
    """The part of a compound junction's fin that O's trim about the second pin leaves where
    :func:`_fin_free`: past the joint part's ball and the clearance."""
    fin = _uj_plates(uj, 1, [], 0.0, t, n)[0]
    r_keep = uj.hub_r + c
    big = 2 * float(np.max(fin.size)) + 4 * r_keep
    return subtract(box(fin.center, fin.R, fin.size), [cylinder(uj.center, uj.axes[1], -big, big, r_keep, n, cutter=True)])


def _uj_plates(uj: UJoint, side: int, sbs, reach, t, n):
    """The plates joining a universal joint's yoke knuckles to the body of ``side``: none for
    the host of a compound junction (its knuckles are in its hinge's stack); for the other body
    of a compound junction whose own hinge lies on the same line (the next layer), a fin across
    both knuckles, in the plane of u and v and ``t`` thick, from the second pin up into that
    body's end knuckle; else :func:`_yoke_plates` (into a rod, with ``ROD_PLATE_WALL``: at least
    the slab thickness past the trim about the pin, whose ``n``-gon reaches ``rho / cos(pi / n)``)."""
    lay = uj.layouts[side]
    if uj.host is not None and side == 0:
        return []
    if uj.host is not None and uj.fin > 0:
        u, v = uj.axes
        e = np.cross(u, v)
        a0, a1 = lay.plate
        Rm = np.column_stack([v, u, e])
        return [SlabBox(uj.center + v * 0.5 * (a0 + a1) + u * 0.5 * uj.fin, Rm, np.array([a1 - a0, uj.fin, t]), 2)]
    if lay.holes is not None:   # branch junction: only slabs that pass the knuckle (not the page's far slabs)
        out = _yoke_plates(sbs, uj.center, uj.axes[side], [lay.plate], reach, t, along=True)
        if lay.bridge:
            # over the cap, on the side away from the source (+u), out to the trim radius and
            # back to the line past the cap (where an arm along the line goes on)
            u, v = uj.axes
            b0, b1 = lay.bridge
            hgt = uj.rho[side] + t
            out.append(SlabBox(uj.center + v * 0.5 * (b0 + b1) + u * 0.5 * hgt, np.column_stack([v, u, np.cross(v, u)]),
                               np.array([abs(b1 - b0), hgt, t]), 2))
        return out
    rod_reach = None
    if side == 1 and uj.free_pin:
        # over the knuckles and the hub; with ROD_PLATE_WALL past the trim about the pin by a wall
        # (ROD_PLATE_CLEAR: as far as that keeps clear of the other bodies, uj.rod_wall)
        old, full = _rod_reaches(uj, t, n)
        rod_reach = full if uj.rod_wall is None else max(old, uj.rod_wall)
    return _yoke_plates(sbs, uj.center, uj.axes[side], [lay.plate], reach, t, rod_reach=rod_reach,
                        fin_min=uj.R + t)


def _rod_reaches(uj: UJoint, t, n) -> tuple:
    """(old, full): how far (mm) a universal joint's yoke plate into a rod reaches from its pin
    (``UJoint.free_pin``): over the knuckles and the hub, ``max(R, hub) + 2 t``; and with
    ``ROD_PLATE_WALL`` at least the slab thickness past the trim about the pin (an ``n``-gon of
    radius ``rho``, out to ``rho / cos(pi / n)``), else the old reach again."""
    old = max(uj.R, uj.hub_r) + 2 * t
    return old, max(old, uj.rho[1] / np.cos(np.pi / n) + t) if ROD_PLATE_WALL else old


def _rod_wall_reach(uj: UJoint, sbs, reach, t, n, h, clash) -> float | None:
    """(ROD_PLATE_CLEAR) How far (mm) the yoke plate into a rod of a universal joint's body O
    (``sbs``: its slabs) may reach: the full ``ROD_PLATE_WALL`` reach where its stretch past the
    old reach (:func:`_rod_reaches`) is clear (``clash(boxes)`` false of it), else the longest clear
    reach in steps of ``h`` down to the old one; ``None`` when nothing is to be chosen (not a joint
    into a rod, or the full reach is no longer than the old)."""
    if not (ROD_PLATE_WALL and uj.free_pin):
        return None
    old, full = _rod_reaches(uj, t, n)
    if full <= old + 1e-9:
        return None
    lay = uj.layouts[1]
    short = _yoke_plates(sbs, uj.center, uj.axes[1], [lay.plate], reach, t, rod_reach=old, fin_min=uj.R + t)
    long = _yoke_plates(sbs, uj.center, uj.axes[1], [lay.plate], reach, t, rod_reach=full, fin_min=uj.R + t)
    grew = [(a, b) for a, b in zip(short, long) if b.size[1] > a.size[1] + 1e-9]
    if not grew:
        return None

    def stretch(r):        # each grown plate's part from the old reach out to r
        out = []
        for a, b in grew:
            w = b.R[:, 1]
            start = b.center - w * b.size[1] / 2
            size = b.size.copy()
            size[1] = r - a.size[1]
            out.append(SlabBox(start + w * 0.5 * (a.size[1] + r), b.R, size, b.normal_axis, b.offset))
        return out
    r = full
    while r > old + 1e-9 and clash(stretch(r)):
        r = max(old, r - h)
    return r


def _knuckles_off_slab(sbs, ax: HingeAxis, bn: str, t) -> bool:
    """Whether a knuckle of body ``bn`` on hinge ``ax`` lies wholly beside (along the axis) every
    slab of ``bn`` that reaches the axis: a hinge whose axis crosses the slab, with a span longer
    than the slab is thick (the Tetris robot's skeleton: hinges normal to the unit plates, the
    owner's end knuckles 0.05 mm above and below its 1 mm plate, each stack a piece of its own,
    issue 13, session 50)."""
    ivs = ax.intervals.get(bn, [])
    if not ivs:
        return False
    ext = _slab_extents_along(sbs, ax, t)
    return any(not any(e0 < a1 and e1 > a0 for e0, e1 in ext) for a0, a1 in ivs)


def _slab_extents_along(sbs, ax: HingeAxis, t) -> list:
    """The intervals along ``ax`` (mm from its origin) of the slabs of ``sbs`` that reach its axis."""
    ext = []
    for sb in sbs:
        rel = sb.center - ax.origin
        mid = float(np.dot(rel, ax.direction))
        perp = rel - mid * ax.direction
        w = perp - np.dot(perp, sb.R[:, sb.normal_axis]) * sb.R[:, sb.normal_axis]
        if np.linalg.norm(w) > 1e-6:
            w = w / np.linalg.norm(w)
            if np.linalg.norm(perp) - 0.5 * np.sum(np.abs(sb.R.T @ w) * sb.size) > t:
                continue        # this slab does not reach the axis
        half = 0.5 * float(np.sum(np.abs(sb.R.T @ ax.direction) * sb.size))
        ext.append((mid - half, mid + half))
    return ext


def _is_rod(sb: SlabBox, t) -> bool:
    """A slab box with two thin sides (at most ``2 t`` mm), a rod rather than a plate: a page's
    arm, or the post that carries a circuit chain's end joint under a gate's input lever."""
    return sorted(sb.size)[1] <= 2 * t


def _rod_links(sbs, my_axes, bn, t, s) -> list:
    """Boxes that carry a rod (:func:`_is_rod`: a branch page's arm) lying on the line of one of
    body ``bn``'s hinges on into the knuckle of ``bn`` whose end face it ends on, half the
    knuckle's length deep (inside the knuckle: no material is added outside it).

    A page's arm runs along its own hinge's line from the joint point to the hinge's end
    knuckle (:func:`_own_lines`) and stops exactly on that knuckle's end face, where the slab
    and the pin stop too: the arm met the rest of its body face to face only.  Built in the
    world the coincident faces merged; built in the body's own frame (a large assembly, session
    9) their placements differ by rounding (3.5e-13 mm), and the union left the arm, its yoke
    knuckle and plate a separate piece (session 49: the Tetris circuit's page ``w_y_p1``'s
    slabs ``AB`` and ``CD`` in 2 pieces each, ``part_count``)."""
    out = []
    tol = _TOL * s
    for sb in sbs:
        if not _is_rod(sb, t):
            continue
        ia = int(np.argmax(sb.size))
        d = sb.R[:, ia]
        others = [i for i in range(3) if i != ia]
        for ax in my_axes:
            if abs(abs(float(np.dot(d, ax.direction))) - 1) > 1e-6:
                continue
            rel = sb.center - ax.origin
            a = float(np.dot(rel, ax.direction))
            if np.linalg.norm(rel - a * ax.direction) > tol:
                continue
            if float(np.hypot(*(0.5 * sb.size[others]))) >= ax.R:
                continue          # not inside the knuckle: a link would add material outside it
            lo, hi = a - 0.5 * sb.size[ia], a + 0.5 * sb.size[ia]
            for a0, a1 in ax.intervals.get(bn, []):
                k = a1 - a0
                if lo < a0 and abs(hi - a0) <= tol:          # ends on the knuckle's lower face
                    e0, e1 = max(lo, hi - t), a0 + k / 2
                elif hi > a1 and abs(lo - a1) <= tol:        # ... on its upper face
                    e0, e1 = a1 - k / 2, min(hi, lo + t)
                else:
                    continue
                size = sb.size.copy()
                size[ia] = e1 - e0
                out.append(SlabBox(ax.origin + ax.direction * (0.5 * (e0 + e1)) + (rel - a * ax.direction), sb.R,
                                   size, sb.normal_axis, sb.offset))
    return out


def _yoke_plates(sbs, origin, d, intervals, reach, t, along=False, rod_reach=None, fin_min=None):
    """Plates (as slab boxes) widening a body's slabs over ``intervals`` of an axis (``along``:
    only slabs whose extent along the axis overlaps the interval).  ``rod_reach`` (mm; given
    for the yoke of a body whose hinges run along the first pin, ``UJoint.free_pin``): a
    plate into a rod (a slab with two thin sides, such as the post that carries a circuit
    chain's end joint under a gate's input lever) reaches only this far from the axis, over
    the knuckles and the hub, and the rod carries it on; a plate as long as ``reach`` there
    was a fin along the rod that met the gate's core (session 44).

    ``fin_min`` (mm; given for a universal joint's yokes): a plate whose axis crosses the
    slab's plane (not a widened slab but a fin standing across it: a circuit chain's first
    junction on a gate's output lever, whose second pin is the lever's hinge made square to
    the chain's first hinge, 38 degrees out of the lever's plane in ``(a & b) | c``) reaches
    only as far as its mid-line stays on the slab, and at least ``fin_min``; past the slab's
    outline it was a free fin, off the lever's layer, that met the fin of the other output
    lever's junction where the two levers turn against each other (session 45)."""
    out = []
    # a body with a post (a rod: two thin sides), such as an input lever carrying a chain's end
    # joint: its plate into the slab is what joins the post's knuckles to it; no fin limit
    post = any(_is_rod(sb, t) for sb in sbs)
    for sb in sbs:
        rel = sb.center - origin
        if along:
            mid, half_d = float(np.dot(rel, d)), 0.5 * float(np.sum(np.abs(sb.R.T @ d) * sb.size))
            if not any(mid - half_d < a1 and mid + half_d > a0 for a0, a1 in intervals):
                continue
        perp = rel - np.dot(rel, d) * d
        nrm = sb.R[:, sb.normal_axis]
        # in the slab's plane; a rod (two thin sides: a page's arm) has no plane: straight at it
        rod = along and _is_rod(sb, t)
        w = perp if rod else perp - np.dot(perp, nrm) * nrm
        if np.linalg.norm(w) < 1e-6:
            continue
        w = w / np.linalg.norm(w)
        half = 0.5 * np.sum(np.abs(sb.R.T @ w) * sb.size)
        if np.linalg.norm(perp) - half > t:     # this slab does not reach the axis
            continue
        reach_b = min(reach, 2 * half)
        if rod_reach is not None and _is_rod(sb, t):
            reach_b = min(reach_b, rod_reach)
        if fin_min is not None and not post and not rod and abs(float(np.dot(d, nrm))) > FIN_SIN:
            reach_b = min(reach_b, max(_on_slab(sb, origin, w), fin_min))
        Rm = np.column_stack([d, w, np.cross(d, w)])
        # a slab printed from one face (_offset_slabs): its plate too, flush with it
        shift = 0.0 if rod else sb.offset * nrm
        # a joint on a post whose plate widens a slab whose layer lies off the joint (the robot's
        # skeleton: 3 mm over the couplings' end joints): the plate lies in the joint's plane
        off = (post and not _is_rod(sb, t) and
               abs(float(np.dot(rel, nrm))) > 0.5 * float(sb.size[sb.normal_axis]) + abs(sb.offset) + t)
        for a0, a1 in intervals:
            if a1 - a0 <= 0:
                continue
            out.append(SlabBox(origin + d * 0.5 * (a0 + a1) + w * reach_b / 2 + shift, Rm,
                               np.array([a1 - a0, reach_b, t]), 2, sb.offset, off))
    return out


def _clip_near_plates(uj_plates, samples, state_T, t, c, h) -> list:
    """(CLIP_NEAR_PLATES) The universal joints' yoke plates off their slab's layer (``uj_plates``:
    ``(body, joint, box)``; :func:`_yoke_plates`: along ``R[:, 1]`` away from the pin over
    ``size[1]``, ``SlabBox.off_layer``) that come within the slab thickness and the clearance
    (mid-planes ``t + c + h`` apart; ``samples``: every body's slab and plate points, rest frame)
    of a body other than their joint's two as printed (and, with ``NEAR_PLATES_STATES``, in a
    logic state of ``state_T``), beyond the knuckles and the hub (``max(R, hub) + t`` from the
    pin): ``[(index, shortened box, mm cut, that body)]``, each plate stopped that far short of
    the nearest such point, never shorter than the knuckles and the hub.  A yoke plate is laid in
    the joint's plane as far as its slab is wide: a joint on a post under a slab (the robot's
    skeleton, its couplings' end joints) gets a plate off the slab's layer that reached 7.3 mm
    from its pin, over the next end joint's knuckle on the neighbouring skeleton body
    (``skel_j3``'s over ``skel_u2``'s, printed touching; the final trims could cut neither:
    ``skel_u2``'s knuckle is guarded, ``skel_j3`` fell in two; session 69)."""
    from scipy.spatial import cKDTree
    cands = []
    for k, (bn, uj, sb) in enumerate(uj_plates):
        least = max(uj.R, uj.hub_r) + t
        L = float(sb.size[1])
        if not sb.off_layer or L <= least + h:
            continue
        w = sb.R[:, 1]
        start = sb.center - w * L / 2
        P = _slab_samples([sb], h)
        a = (P - start) @ w
        keep = a > least
        if keep.any():
            cands.append((k, bn, uj, sb, P[keep], a[keep], least))
    names = list(samples)
    if not cands or not sum(len(samples[bn]) for bn in names):
        return []
    index = {bn: i for i, bn in enumerate(names)}
    owner = np.concatenate([np.full(len(samples[bn]), i) for i, bn in enumerate(names)])
    hit: dict = {}
    for Ts in [None] + ([T for _, T in (state_T or [])] if NEAR_PLATES_STATES else []):
        if Ts is None:
            Q = np.concatenate([samples[bn] for bn in names])
        else:
            Q = np.concatenate([samples[bn] @ Ts[bn][:3, :3].T + Ts[bn][:3, 3] for bn in names])
        tree = cKDTree(Q)
        for k, bn, uj, sb, P, a, _ in cands:
            Pp = P if Ts is None else P @ Ts[bn][:3, :3].T + Ts[bn][:3, 3]
            mine = {index[x] for x in (bn, *uj.bodies) if x in index}
            for n, near in enumerate(tree.query_ball_point(Pp, t + c + h)):
                other = [owner[i] for i in near if owner[i] not in mine]
                if other and (k not in hit or a[n] < hit[k][0]):
                    hit[k] = (float(a[n]), names[other[0]])
    out = []
    for k, _, _, sb, _, _, least in cands:
        if k not in hit:
            continue
        L = float(sb.size[1])
        r = max(least, hit[k][0] - (t + c + h))
        if r >= L - 1e-9:
            continue
        out.append((k, _plate_cut(sb, r), L - r, hit[k][1]))
    return out


def _plate_cut(sb: SlabBox, r: float) -> SlabBox:
    """A yoke plate (:func:`_yoke_plates`: along ``R[:, 1]`` away from the pin over ``size[1]``)
    stopped ``r`` mm from the pin."""
    w = sb.R[:, 1]
    size = sb.size.copy()
    size[1] = r
    return SlabBox(sb.center - w * float(sb.size[1]) / 2 + w * r / 2, sb.R, size, sb.normal_axis, sb.offset,
                   sb.off_layer)


def _clip_at_axes(sb: SlabBox, axes, least, t, clash=None) -> SlabBox:
    """A universal joint's yoke plate (:func:`_yoke_plates`: along ``R[:, 0]`` the pin, along
    ``R[:, 1]`` away from it over ``size[1]``) shortened to stop at the trim radius ``rho`` of
    every hinge in ``axes`` (the body's other hinges) that runs parallel to the pin, lies in the
    plate's layer within its reach, and whose span the plate runs past; never shorter than
    ``least`` (mm); with ``clash(ax, cut)`` only where it is true of the plate's part cut off
    (a slab box).  The trims clear the other bodies of a hinge within ``rho`` only over its
    span (:func:`_trim_radius` takes the points past it as trimmed): a plate past the span's end
    is where the other body's material is too (six bodies of the Tetris robot's gate g2 and its
    coupling, tests/data_mesh/robot_g2_outputs: both crossed output levers' plates, 5.2 mm wide
    over a 2.5 mm pivot, met past its end, 0.16 mm^3; session 55)."""
    d, w, nrm = sb.R[:, 0], sb.R[:, 1], sb.R[:, 2]
    L = float(sb.size[1])
    start = sb.center - w * L / 2
    reach_b = L
    for ax in axes:
        if abs(abs(float(np.dot(ax.direction, d))) - 1) > 1e-6 or ax.rho <= 0:
            continue
        rel = ax.origin - start
        if abs(float(np.dot(rel, nrm))) > t / 2 + ax.R:
            continue          # not in the plate's layer
        a = float(np.dot(rel, w))
        if a <= 0 or a - ax.rho >= reach_b:
            continue          # behind the plate, or farther than it reaches
        ca = float(np.dot(sb.center - ax.origin, ax.direction))
        half = 0.5 * float(sb.size[0])
        if ca - half >= -ax.span / 2 - 1e-6 and ca + half <= ax.span / 2 + 1e-6:
            continue          # within the span: the hinge's trims clear it
        r = max(min(reach_b, a - ax.rho), min(L, least))
        if r >= reach_b - 1e-9:
            continue
        if clash is not None:
            size = sb.size.copy()
            size[1] = reach_b - r
            if not clash(ax, SlabBox(start + w * 0.5 * (r + reach_b), sb.R, size, sb.normal_axis, sb.offset)):
                continue      # nothing of the hinge's other bodies comes near it
        reach_b = r
    if reach_b >= L - 1e-9:
        return sb
    return _plate_cut(sb, reach_b)


def _on_slab(sb: SlabBox, p, w) -> float:
    """How far (mm) the line from ``p`` along ``w`` (a unit vector in the slab's plane) stays in
    the slab box ``sb``'s outline (0 when it is not in it there)."""
    o = sb.R.T @ (np.asarray(p, float) - sb.center)
    wl = sb.R.T @ w
    out = np.inf
    for i in range(3):
        if i == sb.normal_axis or abs(wl[i]) < 1e-9:
            continue
        out = min(out, (np.sign(wl[i]) * 0.5 * sb.size[i] - o[i]) / wl[i])
    return max(float(out), 0.0)


def _near_axis(bn, p, axes, ujoints, dist) -> bool:
    for ax in axes:
        if bn in ax.bodies:
            rel = p - ax.origin
            a = np.dot(rel, ax.direction)
            if abs(a) <= ax.span / 2 + dist and np.linalg.norm(rel - a * ax.direction) < dist:
                return True
    for uj in ujoints:
        if bn in uj.bodies and np.linalg.norm(p - uj.center) < dist + max(x.extent for x in uj.layouts):
            return True
    return False


def _orientation(asm: Assembly) -> np.ndarray:
    """World -> print frame: hinge axes flat on the bed (``axes_flat``) or as modelled;
    then the assembly is centred on the bed origin and rests on z = 0."""
    dirs = [ax.direction for ax in asm.axes] + [a for uj in asm.ujoints for a in uj.axes]
    Rm = np.eye(3)
    if asm.profile.orient == "axes_flat" and dirs:
        cands = [np.array(v, float) for v in np.eye(3)]
        for i in range(len(dirs)):
            for j in range(i + 1, len(dirs)):
                cr = np.cross(dirs[i], dirs[j])
                if np.linalg.norm(cr) > 1e-3:
                    cands.append(cr / np.linalg.norm(cr))
        for d in dirs[:8]:
            F = _perp_frame(d)
            cands += [F[:, 0], F[:, 1]]
        best = min(cands, key=lambda z: (round(sum(abs(float(np.dot(z, d))) for d in dirs), 6)))
        from mlc.geometry.rotation import rotation_between
        Rm = rotation_between(best, [0, 0, 1.0])
    if asm.profile.orient in ("auto", "auto_config") and asm.parts:
        Rm = _best_rotation(asm)
    lo = np.full(3, np.inf)
    hi = np.full(3, -np.inf)
    for p in asm.parts:
        if p.solid.is_empty():
            continue
        # (no transform when the rotation is the identity: the same box, without copying the mesh)
        T = _h(Rm, np.zeros(3)) @ asm.print_pose.get(p.name, np.eye(4))
        bb = np.asarray((p.solid if np.array_equal(T, np.eye(4)) else transform_solid(p.solid, T)).bounding_box())
        lo = np.minimum(lo, bb[:3])
        hi = np.maximum(hi, bb[3:])
    if not np.all(np.isfinite(lo)):
        return np.eye(4)
    shift = np.array([-(lo[0] + hi[0]) / 2, -(lo[1] + hi[1]) / 2, -lo[2]])
    return _h(Rm, shift)


def _best_rotation(asm: Assembly) -> np.ndarray:
    """``orient: auto``: the up direction with the best bed, searched over the sphere
    (:func:`mlc.mesh.pose.best_rotation`)."""
    from mlc.mesh.pose import best_rotation
    return best_rotation(asm)


def _h(R, t) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3] = R
    T[:3, 3] = t
    return T
