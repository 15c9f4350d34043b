"""Sweep specs: load, validate (``mlc/schemas/sweep.schema.json`` plus the checks a schema
cannot express), and expand into runs.

A spec (YAML) names a scene builder (:mod:`mlc.sweep.scenes`), a measurement
(:mod:`mlc.sweep.measure`), parameters common to all runs (``params``), a ``grid`` whose
every combination is run (and/or an explicit list ``runs``), and ``seeds``::

    scene: and_chain_and
    measure: square_response
    params: {scheme: stiff, dt: 0.01, kT: 1.0e-5, cycles: 3, inputs: {hold: 1}}
    grid: {units: [1, 5, 10], frequency: [5, 0.5, 0.05]}
    seeds: 4

Each run is one parameter point and one seed; its id is a hash of its resolved
parameters and seed, so the results table can be resumed and the same run has the same
id (and, the integrator being deterministic per seed, the same numbers) on any number
of workers.  Units: sigma, k0, t0 = gamma/(1e-3 k0).
"""
from __future__ import annotations

import hashlib
import itertools
import json
import math
import os
from dataclasses import dataclass, field

from mlc.errors import Loc, MlcError
from mlc.io.schema import load_schema, validate
from mlc.io.yamlsrc import loc_of
from mlc.sweep.scenes import BUILDERS

#: integrator parameters and their defaults (None: the integrator's own default)
SIM_PARAMS = {"scheme": "stiff", "dt": None, "kT": 1e-5, "fluct": False, "rot_noise": False, "drift_tol": 0.01}
#: measurement parameters and their defaults
MEASURE_PARAMS = {
    "square_response": {"frequency": 0.5, "cycles": 3, "duty": 0.5, "samples_per_cycle": 100, "probe": "out",
                        "drive_input": "in", "inputs": {}},
    "steady": {"time": 10.0, "window": 0.5, "record": None, "inputs": {}},
}
DEFAULT_PLOT = {"square_response": "response_grid", "steady": "signal_vs_length"}
MAX_RUNS = 100000


@dataclass
class Run:
    """One simulation of a sweep: its index in the spec's order, id, parameters and seed."""

    index: int
    run_id: str
    params: dict          # every parameter, resolved (scene + integrator + measurement)
    seed: int
    varied: dict = field(default_factory=dict)   # the grid/runs parameters of this point

    def task(self, scene: str, measure: str) -> dict:
        return {"run_id": self.run_id, "index": self.index, "scene": scene, "measure": measure,
                "params": self.params, "seed": self.seed}


@dataclass
class SweepSpec:
    name: str
    source: str
    text: str
    scene: str
    measure: str
    plot: str
    params: dict
    columns: list          # parameter columns of the table, in order
    runs: list


def _canon(v):
    if isinstance(v, dict):
        return {k: _canon(v[k]) for k in sorted(v)}
    if isinstance(v, list):
        return [_canon(x) for x in v]
    if isinstance(v, float) and v.is_integer():
        return v          # 1.0 stays 1.0; json prints it as 1.0
    return v


def run_id(scene: str, measure: str, params: dict, seed: int) -> str:
    key = json.dumps({"scene": scene, "measure": measure, "params": _canon(params), "seed": seed},
                     sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(key.encode()).hexdigest()[:16]


def _where(container, key, source):
    return loc_of(container, key) or Loc(source)


def load_spec(path: str) -> SweepSpec:
    """Read, validate and expand a sweep spec; errors are :class:`MlcError` at file:line."""
    from mlc.io.yamlsrc import read_text, load
    text = read_text(path, "sweep spec")
    data = load(text, str(path))
    if not isinstance(data, dict):
        raise MlcError("a sweep spec is a mapping (scene:, measure:, params:, grid:, seeds:)", Loc(str(path)),
                       "see docs/reproduction.md")
    validate(data, load_schema("sweep"), str(path))
    scene, measure = data["scene"], data["measure"]
    allowed = dict(BUILDERS[scene][1])
    allowed.update(SIM_PARAMS)
    allowed.update(MEASURE_PARAMS[measure])
    common = data.get("params", {}) or {}
    grid = data.get("grid", {}) or {}
    listed = data.get("runs", [{}]) or [{}]

    def check_keys(mapping, what):
        for k in mapping:
            if k not in allowed:
                raise MlcError(f"{what}: parameter {k!r} does not apply to scene {scene!r} with measure "
                               f"{measure!r}", _where(mapping, k, path),
                               f"parameters here: {', '.join(sorted(allowed))}")
    check_keys(common, "params")
    check_keys(grid, "grid")
    for i, r in enumerate(listed):
        check_keys(r, f"runs[{i}]")
        for k in r:
            if k in grid:
                raise MlcError(f"runs[{i}]: parameter {k!r} is also in the grid", _where(r, k, path),
                               "give it in one place")
    for k in grid:
        if k in common:
            raise MlcError(f"grid: parameter {k!r} is also in params", _where(grid, k, path), "give it in one place")
    seeds = data["seeds"]
    seeds = list(range(seeds)) if isinstance(seeds, int) else [int(s) for s in seeds]
    if len(set(seeds)) != len(seeds):
        raise MlcError("seeds: a seed is listed twice", _where(data, "seeds", path), "list each seed once")
    gkeys = list(grid)
    points = []
    for combo in itertools.product(*[grid[k] for k in gkeys]):
        for r in listed:
            points.append(({**dict(zip(gkeys, combo)), **r}, r))
    n = len(points) * len(seeds)
    if n > MAX_RUNS:
        raise MlcError(f"the sweep has {n} runs; at most {MAX_RUNS}", _where(data, "grid", path), "split it")
    varied_keys = gkeys + [k for r in listed for k in r if k not in gkeys]
    varied_keys = list(dict.fromkeys(varied_keys))
    runs = []
    for pt, src in points:
        p = {k: (dict(v) if isinstance(v, dict) else v) for k, v in allowed.items()}
        p.update({k: (dict(v) if isinstance(v, dict) else v) for k, v in common.items()})
        p.update(pt)
        _semantic(p, scene, measure, src if src else (grid or common), path)
        for s in seeds:
            runs.append(Run(len(runs), run_id(scene, measure, p, s), p, s, {k: p[k] for k in varied_keys}))
    ids = [r.run_id for r in runs]
    if len(set(ids)) != len(ids):
        raise MlcError("two runs of the sweep are identical (same parameters and seed)",
                       _where(data, "runs" if "runs" in data else "grid", path), "remove the duplicate")
    columns = [k for k in allowed]
    name = data.get("name") or os.path.splitext(os.path.basename(str(path)))[0]
    return SweepSpec(name, str(path), text, scene, measure, data.get("plot", DEFAULT_PLOT[measure]), dict(common),
                     columns, runs)


def _semantic(p: dict, scene: str, measure: str, where_map, path):
    """Checks across parameters (the schema checks each one alone)."""
    def fail(msg, key, fix=None):
        raise MlcError(msg, _where(where_map, key, path) if isinstance(where_map, dict) else Loc(str(path)), fix)
    if p.get("fluct") and p["scheme"] != "stiff":
        fail("fluct is a mode of the stiff scheme", "fluct", "use scheme: stiff")
    if measure == "square_response":
        period = 1.0 / p["frequency"]
        if p["dt"] is not None and p["dt"] > period / 4:
            fail(f"dt {p['dt']} t0 is more than a quarter of the drive period {period:g} t0", "dt",
                 "lower dt or the frequency")
        if period * p["cycles"] > 1e6:
            fail("the run would last more than 1e6 t0", "frequency")
    if measure == "steady" and p["dt"] is not None and p["dt"] > p["time"]:
        fail(f"dt {p['dt']} t0 is longer than the run ({p['time']} t0)", "dt")
    if measure == "steady" and p["record"] is not None and p["record"] > p["time"] * p["window"]:
        fail("record: the sampling interval is longer than the measured window", "record")
    for k, v in p.items():
        if isinstance(v, float) and not math.isfinite(v):
            fail(f"{k} must be finite", k)
    if p["dt"] is not None and p["dt"] > 0:
        # mlc simulate's rule (Simulation.run): more than max_steps steps is refused before the run
        from mlc.sim.integrator import SimOptions
        T = 1.0 / p["frequency"] * p["cycles"] if measure == "square_response" else p["time"]
        n = math.ceil(T / p["dt"] - 1e-9)
        if n > SimOptions.max_steps:
            fail(f"dt {p['dt']} t0 is {n:.3g} steps over the run's {T:g} t0 (more than {SimOptions.max_steps:.3g})",
                 "dt", "use a larger dt (the stiff scheme takes any dt) or a shorter run")
