"""The standard gate library: data in ``stdlib_gates/*.yaml`` (installed as
``mlc.stdlib_gates``), geometry from the core and lever solvers.

Gate topology (paper Fig. 2A; derivation in docs/gates.md).  Eight rigid slabs:

* ``core_ab`` -- logic-core slab with core points a, b and the midpoint m of ab;
* ``core_cd`` -- logic-core slab with core points c and d;
* ``a_lo``, ``a_hi`` -- input lever of input a, replacing the core muscle ac:
  ``a_lo`` is hinged to core_ab at a, ``a_hi`` to core_cd at c;
* ``b_lo``, ``b_hi`` -- the same for input b (core muscle bc);
* ``out_lo``, ``out_hi`` -- output lever in the plane perpendicular to the core through
  the bisector of ab: ``out_lo`` is hinged to core_ab at m, ``out_hi`` meets d through
  the universal joint.

Joints: seven hinge axes -- at a, b, the shared axis at c (three slabs: core_cd, a_hi and
b_hi, modelled as two pairwise hinges on one axis), at m, and the three lever pivots --
and one universal joint at d.  A hinge is two zero-length bonds at the ends of its axis,
the universal joint one bond.  Muscles join the two input ends of each input lever; the
probe ``out`` is the distance between the output lever's two output ends.

Frame (sigma): core plane z = 0, ab along x centred at the origin, bisector = +y; input
levers lie in the core plane outside the triangle abc; the output lever lies in the
plane x = 0 and reaches out along +z.
"""
from __future__ import annotations

import itertools
from dataclasses import dataclass
from functools import lru_cache
from importlib import resources

import numpy as np

from mlc.errors import MlcError
from mlc.geometry.core import CoreSolution, solve_core
from mlc.geometry.lever import LeverSolution, lever_type_for, solve_lever
from mlc.io import yamlsrc
from mlc.io.schema import load_schema, validate
from mlc.gates.parts import axis_sites, hinge, slab_body, universal_joint
from mlc.scene.model import Body, Muscle, Probe, Scene

SIGNALS = ("expand", "contract")
GATE_NAMES = ("AND", "NAND", "OR", "NOR", "NIMPLY", "CNIMPLY", "IMPLY", "CIMPLY")
_EZ = np.array([0.0, 0.0, 1.0])
_EX = np.array([1.0, 0.0, 0.0])
CD_OFFSET = 0.6        # length (in units of Design.rest) of core_cd's offset end box at d


@dataclass(frozen=True)
class Design:
    """Shared design parameters (lengths in sigma, stiffness in k0)."""

    rest: float = 1.0
    signal: float = 0.5
    core_din: float = 0.5
    core_h: float = 2.0
    slab_width: float = 0.5
    slab_thickness: float = 0.01
    input_lever_l: float = 1.5
    output_lever_l: float = 2.0
    k: float = 1.0


@dataclass(frozen=True)
class GateDef:
    """One library gate: it computes (a^pa AND b^pb)^pout."""

    name: str
    function: str
    polarity: dict          # {"a": 0|1, "b": 0|1, "out": 0|1}
    truth_table: dict       # {"00": bit, ...} keyed by input bits "ab"
    levers: dict            # {"expand": {"a": type, "b": type, "out": type}, "contract": {...}}
    source: str = ""

    def evaluate(self, a: int, b: int) -> int:
        p = self.polarity
        return ((a ^ p["a"]) & (b ^ p["b"])) ^ p["out"]


def lever_types(pa: int, pb: int, pout: int, signal: str) -> dict:
    """Lever mechanisms of the gate (a^pa AND b^pb)^pout for a muscle convention.

    An input lever maps the muscle's change (+-signal) onto the core input's change
    (+din, or -din when it inverts); the output lever maps the core's rise onto the
    gate output's change (+-signal, negated when it inverts).  Same signs: crossed
    hinge; opposite signs: open hinge."""
    _check_signal(signal)
    dm = 1.0 if signal == "expand" else -1.0
    return {
        "a": lever_type_for(dm, -1.0 if pa else 1.0),
        "b": lever_type_for(dm, -1.0 if pb else 1.0),
        "out": lever_type_for(1.0, -dm if pout else dm),
    }


def _check_signal(signal: str) -> None:
    if signal not in SIGNALS:
        raise MlcError(f"unknown signal convention {signal!r}", "--signal", "use expand or contract")


def _data_files():
    return resources.files("mlc.stdlib_gates")


def parse_gate(text: str, filename: str) -> GateDef:
    """Parse and validate one gate file; every inconsistency is reported at file:line."""
    data = yamlsrc.load(text, filename)
    if not isinstance(data, dict):
        raise MlcError("a gate file must be a YAML mapping", filename)
    validate(data, load_schema("gate"), filename)
    pol = {k: int(v) for k, v in data["polarity"].items()}
    gate = GateDef(data["name"], data["function"], pol, {k: int(v) for k, v in data["truth_table"].items()},
                   {s: dict(v) for s, v in data["levers"].items()}, filename)
    tt = data["truth_table"]
    for a, b in itertools.product((0, 1), (0, 1)):
        key = f"{a}{b}"
        if gate.truth_table[key] != gate.evaluate(a, b):
            raise MlcError(f"truth_table[{key}] = {tt[key]} but polarity {pol} gives {gate.evaluate(a, b)}",
                           tt.loc_of(key), "fix the row or the polarity")
    for signal in SIGNALS:
        want = lever_types(pol["a"], pol["b"], pol["out"], signal)
        got = data["levers"][signal]
        for k in ("a", "b", "out"):
            if got[k] != want[k]:
                raise MlcError(f"levers.{signal}.{k} is {got[k]} but polarity {pol} needs {want[k]}",
                               got.loc_of(k), f"use {want[k]}")
    return gate


def parse_design(text: str, filename: str) -> Design:
    data = yamlsrc.load(text, filename)
    validate(data, load_schema("design"), filename)
    return Design(**{k: float(v) for k, v in data.items() if k != "mlc_design"})


@lru_cache(maxsize=None)
def load_design() -> Design:
    f = _data_files().joinpath("design.yaml")
    return parse_design(f.read_text("utf-8"), "stdlib_gates/design.yaml")


@lru_cache(maxsize=None)
def load_library() -> dict[str, GateDef]:
    """All library gates by name, validated."""
    out = {}
    for f in sorted(_data_files().iterdir(), key=lambda p: p.name):
        if f.name.endswith(".yaml") and f.name != "design.yaml":
            g = parse_gate(f.read_text("utf-8"), f"stdlib_gates/{f.name}")
            if g.name in out:
                raise MlcError(f"gate {g.name} is defined twice", g.source)
            out[g.name] = g
    missing = set(GATE_NAMES) - set(out)
    if missing:
        raise MlcError(f"the standard library lacks {sorted(missing)}", "stdlib_gates")
    return out


def get_gate(name: str) -> GateDef:
    lib = load_library()
    key = name.upper()
    if key not in lib:
        raise MlcError(f"no library gate named {name!r}", "GATE", f"choose one of {', '.join(lib)}")
    return lib[key]


# ---------------------------------------------------------------------------
# Geometry
# ---------------------------------------------------------------------------

@dataclass(frozen=True)
class GateGeometry:
    """Solved parts of a gate for one muscle convention."""

    gate: GateDef
    signal: str
    design: Design
    core: CoreSolution
    lever_a: LeverSolution
    lever_b: LeverSolution
    lever_out: LeverSolution


def gate_geometry(name: str, signal: str = "expand", design: Design | None = None) -> GateGeometry:
    _check_signal(signal)
    g = get_gate(name)
    d = design or load_design()
    core = solve_core(d.core_din / d.rest, d.core_h / d.rest)
    dout = core.dout * d.rest
    dm = d.signal if signal == "expand" else -d.signal
    p = g.polarity

    def input_lever(pol):
        # lever input = muscle (rest -> rest + dm); lever output = core input at muscle states 0 -> 1
        lout0 = d.rest + (d.core_din if pol else 0.0)
        return solve_lever(d.rest, lout0, dm, -d.core_din if pol else d.core_din, d.input_lever_l)

    # output lever: input = height of d (h -> h + dout); output = gate output at core states 0 -> 1
    out0 = d.rest + (dm if p["out"] else 0.0)
    lever_out = solve_lever(d.core_h, out0, dout, -dm if p["out"] else dm, d.output_lever_l)
    geo = GateGeometry(g, signal, d, core, input_lever(p["a"]), input_lever(p["b"]), lever_out)
    for key, lev in (("a", geo.lever_a), ("b", geo.lever_b), ("out", geo.lever_out)):
        if lev.type != g.levers[signal][key]:   # the data and the solver must agree
            raise MlcError(f"{g.name}: {key} lever solved as {lev.type} but the library says "
                           f"{g.levers[signal][key]}", g.source)
    return geo


def lever_local_points(lev: LeverSolution, actuated: bool) -> dict[str, np.ndarray]:
    """Lever points in its own 2D frame (pivot at the origin, +x from input to output,
    +y "up"): A_up, A_dn (input ends), B_up, B_dn (output ends) in the rest or
    actuated configuration."""
    dt = lev.dtheta if actuated else 0.0
    t1 = lev.theta1 + dt
    t2 = lev.theta2 + lev.sign * dt
    c1, s1 = lev.l1 * np.cos(t1), lev.l1 * np.sin(t1)
    c2, s2 = lev.l2 * np.cos(t2), lev.l2 * np.sin(t2)
    return {"P": np.zeros(2), "A_up": np.array([-c1, s1]), "A_dn": np.array([-c1, -s1]),
            "B_up": np.array([c2, s2]), "B_dn": np.array([c2, -s2])}


def _place_lever(lev: LeverSolution, actuated: bool, side: str, lo, hi, toward_out):
    """World positions of a lever whose ``side`` ends ("A" input or "B" output) sit at
    ``lo`` (the "dn" end) and ``hi`` (the "up" end); ``toward_out`` is the world
    direction of the lever's +x axis.  Returns (points, up_body_keys, dn_body_keys)."""
    pts = lever_local_points(lev, actuated)
    ey = (hi - lo) / np.linalg.norm(hi - lo)
    ex = toward_out - np.dot(toward_out, ey) * ey
    ex /= np.linalg.norm(ex)
    mid_local = 0.5 * (pts[f"{side}_up"] + pts[f"{side}_dn"])
    origin = 0.5 * (lo + hi) - mid_local[0] * ex - mid_local[1] * ey
    world = {k: origin + v[0] * ex + v[1] * ey for k, v in pts.items()}
    # body "up" carries A_up; it carries B_up for an open hinge, B_dn for a crossed one.
    b_of_up = "B_up" if lev.type == "open" else "B_dn"
    b_of_dn = "B_dn" if lev.type == "open" else "B_up"
    return world, ("A_up", b_of_up), ("A_dn", b_of_dn)


def _body(name, segments, sites, axis, d: Design) -> Body:
    return slab_body(name, segments, sites, axis, d.slab_width, d.slab_thickness)


def gate_scene(name: str, signal: str = "expand", design: Design | None = None) -> Scene:
    """The gate's scene, posed at rest (all inputs 0).  Units: sigma, k0."""
    geo = gate_geometry(name, signal, design)
    g, d, core = geo.gate, geo.design, geo.core
    p = g.polarity
    w = d.slab_width
    # Core points at the all-zero input state: an inverting input lever holds its core
    # input expanded (rest + din) while its muscle rests.
    la = d.rest + (d.core_din if p["a"] else 0.0)
    lb = d.rest + (d.core_din if p["b"] else 0.0)
    pts2 = core.points(la / d.rest, lb / d.rest)
    P = {k: np.array([v[0], v[1], 0.0]) * d.rest for k, v in pts2.items()}
    m = 0.5 * (P["a"] + P["b"])
    centroid = (P["a"] + P["b"] + P["c"]) / 3

    bodies, bonds = [], []
    bodies.append(_body("core_ab", [(P["a"], P["b"])],
                        {**axis_sites("a", P["a"], _EZ, w), **axis_sites("b", P["b"], _EZ, w),
                         **axis_sites("m", m, _EX, w)}, _EZ, d))
    # core_cd: full width at the hinge c; its last CD_OFFSET sigma towards d is shifted to
    # z <= 0 so that the output lever, which leaves d towards +z, never crosses it (the two
    # boxes overlap over w/2 along cd, so the body is one solid)
    ucd = (P["d"] - P["c"]) / np.linalg.norm(P["d"] - P["c"])
    q = P["d"] - CD_OFFSET * d.rest * ucd
    off = -0.5 * w * _EZ
    bodies.append(_body("core_cd", [(P["c"], q), (q - 0.5 * w * ucd + off, P["d"] + off)],
                        {**axis_sites("c", P["c"], _EZ, w), "d": P["d"]}, _EZ, d))

    muscles = []
    for inp, lev, corner in (("a", geo.lever_a, "a"), ("b", geo.lever_b, "b")):
        lo, hi = P[corner], P["c"]
        mid = 0.5 * (lo + hi)
        outward = np.cross(_EZ, hi - lo)
        if np.dot(outward, mid - centroid) < 0:
            outward = -outward
        world, up_keys, dn_keys = _place_lever(lev, False, "B", lo, hi, -outward)
        # the body holding B_dn is hinged at the core corner (lo), the one holding B_up at c (hi)
        lo_keys = up_keys if up_keys[1] == "B_dn" else dn_keys
        hi_keys = dn_keys if lo_keys is up_keys else up_keys
        for bname, (akey, bkey) in ((f"{inp}_lo", lo_keys), (f"{inp}_hi", hi_keys)):
            sites = {"in": world[akey], **axis_sites("piv", world["P"], _EZ, w),
                     **axis_sites("core", world[bkey], _EZ, w)}
            bodies.append(_body(bname, [(world[akey], world["P"]), (world["P"], world[bkey])], sites, _EZ, d))
        bonds += hinge(f"pivot_{inp}", f"{inp}_lo", f"{inp}_hi", "piv", "piv", d.k)
        bonds += hinge(f"hinge_{corner}", "core_ab", f"{inp}_lo", corner, "core", d.k)
        bonds += hinge(f"hinge_c_{inp}", "core_cd", f"{inp}_hi", "c", "core", d.k)
        act = d.rest + (d.signal if signal == "expand" else -d.signal)
        # muscle ends: A_up / A_dn, on whichever bodies carry them
        a_up_body = f"{inp}_lo" if lo_keys[0] == "A_up" else f"{inp}_hi"
        a_dn_body = f"{inp}_hi" if a_up_body == f"{inp}_lo" else f"{inp}_lo"
        muscles.append(Muscle(f"muscle_{inp}", inp, f"{a_dn_body}.in", f"{a_up_body}.in", d.rest, act, d.k))

    # Output lever: input ends at m (dn) and d (up), reaching out along +z, in the plane x = 0.
    core_on = bool(p["a"] and p["b"])            # core state at the all-zero input state
    world, up_keys, dn_keys = _place_lever(geo.lever_out, core_on, "A", m, P["d"], _EZ)
    bodies.append(_body("out_lo", [(world["A_dn"], world["P"]), (world["P"], world[dn_keys[1]])],
                        {**axis_sites("core", world["A_dn"], _EX, w), **axis_sites("piv", world["P"], _EX, w),
                         "out": world[dn_keys[1]]}, _EX, d))
    bodies.append(_body("out_hi", [(world["A_up"], world["P"]), (world["P"], world[up_keys[1]])],
                        {"core": world["A_up"], **axis_sites("piv", world["P"], _EX, w),
                         "out": world[up_keys[1]]}, _EX, d))
    bonds += hinge("pivot_out", "out_lo", "out_hi", "piv", "piv", d.k)
    bonds += hinge("hinge_m", "core_ab", "out_lo", "m", "core", d.k)
    bonds.append(universal_joint("ujoint_d", "core_cd.d", "out_hi.core", d.k))
    act = d.rest + (d.signal if signal == "expand" else -d.signal)
    probes = [Probe("out", "out", "out_lo.out", "out_hi.out", d.rest, act)]

    order = ["core_ab", "core_cd", "a_lo", "a_hi", "b_lo", "b_hi", "out_lo", "out_hi"]
    bodies.sort(key=lambda b: order.index(b.name))
    scene = Scene(
        name=f"{g.name}_{signal}", bodies=bodies, bonds=bonds, muscles=muscles, probes=probes,
        inputs=["a", "b"], outputs=["out"], truth_table={k: str(v) for k, v in g.truth_table.items()},
        meta={"gate": g.name, "function": g.function, "signal": signal, "polarity": dict(p),
              "levers": dict(g.levers[signal]),
              "core": {"din": d.core_din, "h": d.core_h, "x": float(core.x * d.rest), "phi": float(core.phi),
                       "dout": float(core.dout * d.rest)}},
    )
    return scene.check()
