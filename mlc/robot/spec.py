"""Robot body files (``*.robot.yaml``, docs/robot.md, mlc/schemas/robot.schema.json).

A robot file says what a compiled circuit drives: a planar skeleton chain of ``units``
units after the robot's body (grid cell (0, 0)), each unit joined to the previous one by
two bending degrees of freedom (DOFs), ``up`` (turns the chain by +90 degrees,
counter-clockwise) and ``dn`` (-90 degrees); which circuit output drives which DOF; and
the pose expected in every input row, as turns or as grid cells.

:func:`load_robot` reads and checks a file against the JSON Schema and then against the
logic it is compiled with (inputs, outputs, truth table).  Every error is one
:class:`MlcError` at ``file:line``.  Units: sigma, degrees.
"""
from __future__ import annotations

from dataclasses import dataclass, field

from mlc.errors import Loc, MlcError
from mlc.io import yamlsrc
from mlc.io.schema import load_schema, validate

UNIT_LENGTH = 4.0       # sigma per unit (one grid cell)
WIDTH = 2.0             # sigma across the chain
THICKNESS = 0.2         # sigma
DOF_REST = 2.0          # sigma (paper, Fig. 6: "rest length 2 sigma, expands by sigma")
DOF_STROKE = 1.0        # sigma
HEIGHT = 10.0           # sigma between the circuit's top and the skeleton plane
TURN = 90.0             # degrees per driven DOF

_DIRS = [(1, 0), (0, 1), (-1, 0), (0, -1)]      # headings, counter-clockwise


@dataclass
class DofSpec:
    unit: int
    side: str                  # "up" | "dn"
    output: str
    coupling: str | None       # "lever" | "lock" | "muscle" | None (chosen by the builder)
    loc: Loc | None = None

    @property
    def name(self) -> str:
        return f"u{self.unit}_{self.side}"


@dataclass
class PoseSpec:
    row: str
    shape: str
    turns: list[int]            # -1, 0, +1 per unit (units of 90 degrees)
    loc: Loc | None = None

    @property
    def cells(self) -> list[tuple[int, int]]:
        return walk(self.turns)


@dataclass
class RobotSpec:
    name: str
    source: str
    inputs: list[str]
    units: int
    unit_length: float = UNIT_LENGTH
    width: float = WIDTH
    thickness: float = THICKNESS
    dof_rest: float = DOF_REST
    dof_stroke: float = DOF_STROKE
    height: float = HEIGHT
    dofs: list[DofSpec] = field(default_factory=list)
    poses: dict[str, PoseSpec] = field(default_factory=dict)
    logic: str | None = None
    description: str = ""

    def dof(self, unit: int, side: str) -> DofSpec | None:
        return next((d for d in self.dofs if d.unit == unit and d.side == side), None)

    def as_dict(self) -> dict:
        """Plain data (for the scene's meta)."""
        return {"name": self.name, "source": self.source, "inputs": list(self.inputs), "units": self.units,
                "unit_length": self.unit_length, "width": self.width, "thickness": self.thickness,
                "dof_rest": self.dof_rest, "dof_stroke": self.dof_stroke, "turn_deg": TURN,
                "poses": {r: {"shape": p.shape, "turns": [int(TURN) * t for t in p.turns],
                              "cells": [list(c) for c in p.cells]} for r, p in self.poses.items()}}


def walk(turns) -> list[tuple[int, int]]:
    """Grid cells of units 1..n: start in cell (0, 0) heading +x; at unit i turn by
    ``turns[i]`` quarter turns, then step into the unit's cell."""
    h, x, y, out = 0, 0, 0, []
    for t in turns:
        h = (h + int(t)) % 4
        x, y = x + _DIRS[h][0], y + _DIRS[h][1]
        out.append((x, y))
    return out


def cells_to_turns(cells, where) -> list[int]:
    """Quarter turns (-1, 0, +1) of a walk through ``cells``; an unreachable walk (a step
    that is not to a neighbouring cell, a U-turn) is an MlcError at ``where``."""
    h, x, y, turns = 0, 0, 0, []
    for i, (cx, cy) in enumerate(cells):
        d = (cx - x, cy - y)
        if d not in _DIRS:
            raise MlcError(f"cell {i + 1} {[cx, cy]} is not next to cell {i} {[x, y]}: a unit steps into a "
                           f"neighbouring cell", where, "list the cells of units 1..n in chain order, "
                           "starting next to the body at [0, 0]")
        nh = _DIRS.index(d)
        t = (nh - h) % 4
        if t == 2:
            raise MlcError(f"cell {i + 1} {[cx, cy]} would need a 180-degree turn at unit {i + 1}", where,
                           "a joint turns by at most 90 degrees")
        turns.append({0: 0, 1: 1, 3: -1}[t])
        h, x, y = nh, cx, cy
    return turns


def load_robot(path, logic=None) -> RobotSpec:
    """Read and check a robot file.  ``logic``: an object with ``inputs``, ``outputs`` and
    ``truth_table`` (row bits -> output bits; e.g. a circuit scene) to check the file
    against; None checks the file alone."""
    text = yamlsrc.read_text(path, "robot file")
    return parse_robot(text, str(path), logic)


def parse_robot(text: str, filename: str = "<robot>", logic=None) -> RobotSpec:
    data = yamlsrc.load(text, filename)
    if not isinstance(data, dict):
        raise MlcError("a robot file must be a YAML mapping", Loc(filename), "see docs/robot.md")
    if "mlc_robot" not in data:
        raise MlcError("not an mlc robot file: missing 'mlc_robot: 1'", getattr(data, "loc", Loc(filename)),
                       "see docs/robot.md")
    validate(data, load_schema("robot"), filename)

    def loc(c, k):
        return yamlsrc.loc_of(c, k) or getattr(c, "loc", None) or Loc(filename)

    sk = data["skeleton"]
    spec = RobotSpec(name=data["name"], source=filename, inputs=list(data["inputs"]), units=int(sk["units"]),
                     unit_length=float(sk.get("unit_length", UNIT_LENGTH)), width=float(sk.get("width", WIDTH)),
                     thickness=float(sk.get("thickness", THICKNESS)), dof_rest=float(sk.get("dof_rest", DOF_REST)),
                     dof_stroke=float(sk.get("dof_stroke", DOF_STROKE)), height=float(sk.get("height", HEIGHT)),
                     logic=data.get("logic"), description=data.get("description", ""))
    if len(set(spec.inputs)) != len(spec.inputs):
        raise MlcError(f"inputs {spec.inputs} name an input twice", loc(data, "inputs"))
    seen: dict[tuple, DofSpec] = {}
    by_output: dict[str, DofSpec] = {}
    for i, d in enumerate(data["dofs"]):
        where = loc(data["dofs"], i)
        ds = DofSpec(int(d["unit"]), d["side"], d["output"], d.get("coupling"), where)
        if ds.unit > spec.units:
            raise MlcError(f"dof {ds.name}: unit {ds.unit} does not exist (the skeleton has {spec.units} units)",
                           where, f"use a unit in 1..{spec.units}")
        if (ds.unit, ds.side) in seen:
            raise MlcError(f"dof {ds.name} is driven twice (also at line {seen[(ds.unit, ds.side)].loc.line})",
                           where, "give each DOF one output")
        if ds.output in by_output:
            raise MlcError(f"output {ds.output} drives two DOFs ({by_output[ds.output].name} and {ds.name})", where,
                           "give the second DOF its own output in the logic (a copy of the first)")
        seen[(ds.unit, ds.side)] = by_output[ds.output] = ds
        spec.dofs.append(ds)
    for i, p in enumerate(data["poses"]):
        where = loc(data["poses"], i)
        row = p["row"]
        if len(row) != len(spec.inputs):
            raise MlcError(f"pose row {row!r} is not {len(spec.inputs)} bits for inputs {spec.inputs}", where)
        if row in spec.poses:
            raise MlcError(f"row {row} has two poses (also at line {spec.poses[row].loc.line})", where)
        if ("turns" in p) == ("cells" in p):
            raise MlcError(f"pose of row {row}: give either turns or cells, not both", where)
        if "turns" in p:
            if len(p["turns"]) != spec.units:
                raise MlcError(f"pose of row {row}: {len(p['turns'])} turns for {spec.units} units", where,
                               "give one turn (-90, 0 or 90) per unit")
            turns = [int(t) // 90 for t in p["turns"]]
        else:
            if len(p["cells"]) != spec.units:
                raise MlcError(f"pose of row {row}: {len(p['cells'])} cells for {spec.units} units", where,
                               "give one cell [x, y] per unit")
            turns = cells_to_turns([tuple(c) for c in p["cells"]], where)
        cells = walk(turns)
        if len(set(cells) | {(0, 0)}) != len(cells) + 1:
            dup = next(c for c in cells if cells.count(c) > 1 or c == (0, 0))
            raise MlcError(f"pose of row {row} puts two units in cell {list(dup)}: the skeleton cannot reach it",
                           where, "a folded chain cannot overlap itself")
        for u, t in enumerate(turns, 1):
            if t and spec.dof(u, "up" if t > 0 else "dn") is None:
                raise MlcError(f"pose of row {row} turns unit {u} {'up' if t > 0 else 'down'}, but no output "
                               f"drives dof u{u}_{'up' if t > 0 else 'dn'}: the skeleton cannot reach it", where,
                               "add the DOF to dofs, or change the pose")
        spec.poses[row] = PoseSpec(row, str(p.get("shape", row)), turns, where)
    if logic is not None:
        check_against_logic(spec, logic, data)
    return spec


def check_against_logic(spec: RobotSpec, logic, data=None) -> None:
    """The file agrees with the logic: the same inputs, DOFs driven by existing outputs, a
    pose for every row, and every pose the one the logic's outputs make (a DOF is driven
    exactly when its output is 1)."""
    where_inputs = yamlsrc.loc_of(data, "inputs") if data is not None else spec.source
    if list(logic.inputs) != spec.inputs:
        raise MlcError(f"inputs {spec.inputs} are not the logic's inputs {list(logic.inputs)} (in that order)",
                       where_inputs or spec.source, "rows are bit strings in the logic's input order")
    outs = list(logic.outputs)
    for d in spec.dofs:
        if d.output not in outs:
            raise MlcError(f"dof {d.name}: the logic has no output {d.output!r} (outputs: {', '.join(outs)})", d.loc,
                           "name one of the logic's outputs")
    table = logic.truth_table or {}
    n = len(spec.inputs)
    for r in range(2 ** n):
        row = format(r, f"0{n}b")
        if row not in spec.poses:
            raise MlcError(f"row {row} has no pose", yamlsrc.loc_of(data, "poses") if data is not None else spec.source,
                           "give the expected pose of every input row")
    for row, p in spec.poses.items():
        bits = table.get(row)
        if bits is None:
            continue
        for d in spec.dofs:
            b = bits[outs.index(d.output)]
            t = p.turns[d.unit - 1]
            need = int(t == (1 if d.side == "up" else -1))
            if b == "-":
                raise MlcError(f"row {row}: output {d.output} (dof {d.name}) is a don't-care in the logic", p.loc,
                               "a DOF needs a definite bit in every row")
            if int(b) != need:
                raise MlcError(f"row {row} (pose {p.shape}): the pose needs {d.output} = {need} (dof {d.name}), "
                               f"but the logic gives {d.output} = {b}", p.loc, "correct the pose or the logic")


__all__ = ["DofSpec", "PoseSpec", "RobotSpec", "cells_to_turns", "check_against_logic", "load_robot",
           "parse_robot", "walk"]
