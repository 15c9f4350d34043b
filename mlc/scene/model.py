"""In-memory scene model (units: sigma = 1 length, k0 = 1 stiffness, gamma = 1 drag).

A :class:`Scene` is

* ``bodies`` -- rigid bodies.  Each has a pose (``position``, unit quaternion
  ``orientation`` = [w, x, y, z] taking body-frame vectors to the world frame), one
  or more ``boxes`` (the slabs it is made of, in the body frame: a bent lever arm is
  two boxes of one body) and named ``sites`` (body-frame points where bonds attach).
  The body centre (its position) is where the WCA volume exclusion acts.
* ``bonds`` -- harmonic bonds between two sites of different bodies,
  ``U = k/2 * max(0, | |d| - rest | - tolerance)^2``.  A hinge is two zero-rest bonds
  at the two ends of its axis, a universal joint one; bonds of one joint share a
  ``joint`` name and ``kind`` ("hinge" or "universal"; "bond" for a plain bond).
* ``muscles`` -- harmonic bonds whose rest length follows the named ``input``:
  ``rest`` when the input is 0, ``actuated`` when it is 1.
* ``probes`` -- named ``output`` signals: the distance between two sites, ``rest``
  in state 0 and ``actuated`` in state 1; the threshold is their midpoint.
* ``inputs``/``outputs`` -- the ordered signal names; ``truth_table`` optionally maps
  an input bit string (in ``inputs`` order) to the expected output bit string.

Invariants (:meth:`Scene.check`): unique names; every site reference ``body.site``
exists; bond ends on different bodies; unit quaternions; positive box sizes and
stiffnesses; non-negative rest lengths and tolerances; finite numbers; every muscle
input is in ``inputs``, every probe output in ``outputs``; truth-table keys and
values have the right widths.
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass, field

import numpy as np

from mlc.errors import Loc, MlcError
from mlc.geometry.rotation import quat_to_matrix


NAME_RE = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")


@dataclass
class Box:
    """A slab of a body: full edge lengths ``size``, centre and orientation in the body frame."""

    size: np.ndarray
    center: np.ndarray = field(default_factory=lambda: np.zeros(3))
    orientation: np.ndarray = field(default_factory=lambda: np.array([1.0, 0, 0, 0]))


@dataclass
class Body:
    name: str
    position: np.ndarray
    orientation: np.ndarray
    boxes: list[Box]
    sites: dict[str, np.ndarray]
    loc: Loc | None = None

    def rotation(self) -> np.ndarray:
        return quat_to_matrix(self.orientation)

    def world(self, site: str) -> np.ndarray:
        return self.position + self.rotation() @ self.sites[site]


@dataclass
class Bond:
    name: str
    a: str            # "body.site"
    b: str
    k: float = 1.0
    rest: float = 0.0
    tolerance: float = 0.0
    kind: str = "bond"        # hinge | universal | bond
    joint: str | None = None  # name of the joint this bond belongs to
    loc: Loc | None = None


@dataclass
class Muscle:
    name: str
    input: str
    a: str
    b: str
    rest: float
    actuated: float
    k: float = 1.0
    loc: Loc | None = None

    def length(self, state: int) -> float:
        return self.actuated if state else self.rest


@dataclass
class Probe:
    name: str
    output: str
    a: str
    b: str
    rest: float
    actuated: float
    loc: Loc | None = None

    @property
    def threshold(self) -> float:
        return 0.5 * (self.rest + self.actuated)

    def bit(self, length: float) -> int:
        """Read a length as a bit: 1 when it is on the actuated side of the threshold."""
        return int((length - self.threshold) * (self.actuated - self.rest) > 0)

    def margin(self, length: float, expected: int) -> float:
        """Signed distance (sigma) from the threshold towards the expected state's side."""
        side = 1.0 if expected else -1.0
        return side * (length - self.threshold) * np.sign(self.actuated - self.rest)


@dataclass
class SceneArrays:
    """Contiguous arrays of a scene: the boundary to compiled kernels (no Python objects).

    Sites are numbered in body order; ``site_body[s]`` is the body of site ``s`` and
    ``site_local[s]`` its body-frame position.  Bonds, muscles and probes index sites.
    """

    pos: np.ndarray            # (N, 3) float64 body positions
    quat: np.ndarray           # (N, 4) float64 unit quaternions [w, x, y, z]
    site_body: np.ndarray      # (S,) int64
    site_local: np.ndarray     # (S, 3) float64
    bond_i: np.ndarray         # (B,) int64 site index
    bond_j: np.ndarray
    bond_k: np.ndarray         # (B,) float64
    bond_rest: np.ndarray
    bond_tol: np.ndarray
    muscle_i: np.ndarray       # (M,) int64 site index
    muscle_j: np.ndarray
    muscle_k: np.ndarray
    muscle_rest: np.ndarray    # length at input 0
    muscle_act: np.ndarray     # length at input 1
    muscle_input: np.ndarray   # (M,) int64 index into Scene.inputs
    probe_i: np.ndarray        # (P,) int64 site index
    probe_j: np.ndarray
    probe_rest: np.ndarray
    probe_act: np.ndarray
    site_index: dict           # "body.site" -> site index (not for kernels)

    def muscle_lengths(self, state) -> np.ndarray:
        """Muscle rest lengths for an input state (sequence of 0/1 in ``Scene.inputs`` order)."""
        s = np.asarray(state, dtype=float)[self.muscle_input] if len(self.muscle_input) else np.zeros(0)
        return self.muscle_rest + s * (self.muscle_act - self.muscle_rest)


@dataclass
class Scene:
    name: str
    bodies: list[Body]
    bonds: list[Bond] = field(default_factory=list)
    muscles: list[Muscle] = field(default_factory=list)
    probes: list[Probe] = field(default_factory=list)
    inputs: list[str] = field(default_factory=list)
    outputs: list[str] = field(default_factory=list)
    truth_table: dict[str, str] | None = None
    meta: dict = field(default_factory=dict)
    units: dict = field(default_factory=lambda: {"sigma": 1.0, "k0": 1.0, "gamma": 1.0})
    source: str | None = None

    # -- lookup -------------------------------------------------------------
    def body(self, name: str) -> Body:
        """The body named ``name`` (KeyError if none); O(1) through a name index that is
        rebuilt whenever ``bodies`` has changed."""
        idx = self.__dict__.get("_by_name")
        key = (id(self.bodies), len(self.bodies))
        if idx is None or idx[0] != key or name not in idx[1] or idx[1][name].name != name:
            idx = (key, {b.name: b for b in self.bodies})
            self.__dict__["_by_name"] = idx
        return idx[1][name]

    def site_world(self, ref: str) -> np.ndarray:
        body, site = ref.split(".", 1)
        return self.body(body).world(site)

    def joints(self) -> dict[str, list[Bond]]:
        """Bonds grouped by joint name (hinges have 2, universal joints 1)."""
        out: dict[str, list[Bond]] = {}
        for b in self.bonds:
            if b.joint:
                out.setdefault(b.joint, []).append(b)
        return out

    def expected(self, state: str) -> str | None:
        return None if self.truth_table is None else self.truth_table.get(state)

    def states(self) -> list[str]:
        n = len(self.inputs)
        return [format(i, f"0{n}b") if n else "" for i in range(2**n)]

    # -- invariants ---------------------------------------------------------
    def check(self) -> "Scene":
        """Enforce the invariants listed in the module docstring; raise MlcError at the item."""
        where = self.source or self.name
        names = set()
        for b in self.bodies:
            loc = b.loc or where
            if not NAME_RE.match(b.name):
                raise MlcError(f"body name {b.name!r} is not an identifier", loc)
            if b.name in names:
                raise MlcError(f"duplicate body name {b.name!r}", loc)
            names.add(b.name)
            _finite(b.position, 3, f"body {b.name}: position", loc)
            _unit_quat(b.orientation, f"body {b.name}: orientation", loc)
            if not b.boxes:
                raise MlcError(f"body {b.name} has no box", loc, "give it at least one slab")
            for box in b.boxes:
                if min(_finite(box.size, 3, f"body {b.name}: box size", loc)) <= 0:
                    raise MlcError(f"body {b.name}: box sizes must be positive, got {list(box.size)}", loc)
                _finite(box.center, 3, f"body {b.name}: box center", loc)
                _unit_quat(box.orientation, f"body {b.name}: box orientation", loc)
            for sname, sv in b.sites.items():
                if not NAME_RE.match(sname):
                    raise MlcError(f"body {b.name}: site name {sname!r} is not an identifier", loc)
                _finite(sv, 3, f"body {b.name}: site {sname}", loc)
        inputs, outputs = set(self.inputs), set(self.outputs)
        if len(inputs) != len(self.inputs) or len(outputs) != len(self.outputs):
            raise MlcError("duplicate signal name in inputs/outputs", where)
        seen = set()
        for kind, items in (("bond", self.bonds), ("muscle", self.muscles), ("probe", self.probes)):
            for it in items:
                loc = it.loc or where
                if it.name in seen:
                    raise MlcError(f"duplicate {kind} name {it.name!r}", loc)
                seen.add(it.name)
                ba = self._resolve(it.a, loc)
                bb = self._resolve(it.b, loc)
                if kind != "probe" and ba == bb:
                    raise MlcError(f"{kind} {it.name} joins two sites of the same body {ba}", loc)
                if kind == "bond":
                    if it.kind not in ("hinge", "universal", "bond"):
                        raise MlcError(f"bond {it.name}: unknown kind {it.kind!r}", loc, "use hinge, universal or bond")
                    for f, v in (("k", it.k), ("rest", it.rest), ("tolerance", it.tolerance)):
                        _finite([v], 1, f"bond {it.name}: {f}", loc)
                    if it.k <= 0 or it.rest < 0 or it.tolerance < 0:
                        raise MlcError(f"bond {it.name}: need k > 0, rest >= 0, tolerance >= 0", loc)
                elif kind == "muscle":
                    if it.input not in inputs:
                        raise MlcError(f"muscle {it.name}: input {it.input!r} is not in inputs {self.inputs}", loc)
                    _finite([it.k, it.rest, it.actuated], 3, f"muscle {it.name}", loc)
                    if it.k <= 0 or it.rest <= 0 or it.actuated <= 0:
                        raise MlcError(f"muscle {it.name}: need k, rest and actuated > 0", loc)
                else:
                    if it.output not in outputs:
                        raise MlcError(f"probe {it.name}: output {it.output!r} is not in outputs {self.outputs}", loc)
                    _finite([it.rest, it.actuated], 2, f"probe {it.name}", loc)
                    if it.rest == it.actuated:
                        raise MlcError(f"probe {it.name}: rest and actuated lengths are equal", loc)
        if self.truth_table is not None:
            for key, val in self.truth_table.items():
                check_row(key, val, len(self.inputs), len(self.outputs), where)
        return self

    def _resolve(self, ref: str, loc) -> str:
        if not isinstance(ref, str) or "." not in ref:
            raise MlcError(f"site reference {ref!r} is not of the form body.site", loc)
        body, site = ref.split(".", 1)
        try:
            b = self.body(body)
        except KeyError:
            raise MlcError(f"site reference {ref!r}: no body named {body!r}", loc) from None
        if site not in b.sites:
            raise MlcError(f"site reference {ref!r}: body {body} has no site {site!r}", loc,
                           f"its sites are {', '.join(b.sites) or 'none'}")
        return body

    # -- arrays -------------------------------------------------------------
    def arrays(self) -> SceneArrays:
        """Flatten to contiguous arrays for kernels (see :class:`SceneArrays`)."""
        site_index, site_body, site_local = {}, [], []
        for bi, b in enumerate(self.bodies):
            for sname, sv in b.sites.items():
                site_index[f"{b.name}.{sname}"] = len(site_body)
                site_body.append(bi)
                site_local.append(np.asarray(sv, float))
        inp = {n: i for i, n in enumerate(self.inputs)}

        def idx(items, attr):
            return np.array([site_index[getattr(it, attr)] for it in items], dtype=np.int64)

        def flt(items, attr):
            return np.array([float(getattr(it, attr)) for it in items], dtype=np.float64)

        return SceneArrays(
            pos=np.ascontiguousarray([b.position for b in self.bodies], dtype=np.float64).reshape(-1, 3),
            quat=np.ascontiguousarray([b.orientation for b in self.bodies], dtype=np.float64).reshape(-1, 4),
            site_body=np.array(site_body, dtype=np.int64),
            site_local=np.ascontiguousarray(site_local, dtype=np.float64).reshape(-1, 3),
            bond_i=idx(self.bonds, "a"), bond_j=idx(self.bonds, "b"),
            bond_k=flt(self.bonds, "k"), bond_rest=flt(self.bonds, "rest"), bond_tol=flt(self.bonds, "tolerance"),
            muscle_i=idx(self.muscles, "a"), muscle_j=idx(self.muscles, "b"), muscle_k=flt(self.muscles, "k"),
            muscle_rest=flt(self.muscles, "rest"), muscle_act=flt(self.muscles, "actuated"),
            muscle_input=np.array([inp[m.input] for m in self.muscles], dtype=np.int64),
            probe_i=idx(self.probes, "a"), probe_j=idx(self.probes, "b"),
            probe_rest=flt(self.probes, "rest"), probe_act=flt(self.probes, "actuated"),
            site_index=site_index,
        )

    def with_poses(self, pos, quat) -> "Scene":
        """A copy of this scene with body poses replaced (arrays of shape (N,3) and (N,4))."""
        import copy
        out = copy.copy(self)
        out.bodies = [Body(b.name, np.array(p, float), np.array(q, float), b.boxes, b.sites, b.loc)
                      for b, p, q in zip(self.bodies, pos, quat)]
        return out


def check_row(key: str, val: str, n_inputs: int, n_outputs: int, where) -> None:
    """One truth-table row: ``key`` of ``n_inputs`` input bits, ``val`` of ``n_outputs`` output bits
    ("-" = don't care); an :class:`MlcError` at ``where`` otherwise."""
    if len(key) != n_inputs or set(key) - {"0", "1"}:
        raise MlcError(f"truth table row {key!r} is not {n_inputs} input bits", where)
    if len(val) != n_outputs or set(val) - {"0", "1", "-"}:
        raise MlcError(f"truth table value {val!r} for {key} is not {n_outputs} output bits", where)


def _finite(v, n, what, loc) -> list:
    """``v`` as a list of ``n`` finite floats (scalar tests: a scene checks hundreds of
    thousands of these small vectors)."""
    vals = np.asarray(v, dtype=float).ravel().tolist()
    if len(vals) != n or not all(map(math.isfinite, vals)):
        raise MlcError(f"{what} must be {n} finite number(s), got {list(np.asarray(v).ravel())}", loc)
    return vals


def _unit_quat(q, what, loc):
    nrm = math.sqrt(sum(x * x for x in _finite(q, 4, what, loc)))
    if abs(nrm - 1.0) > 1e-6:
        raise MlcError(f"{what} is not a unit quaternion (norm {nrm:.6g})", loc,
                       "normalise it: [w, x, y, z] / |q|")
