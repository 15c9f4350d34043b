"""The whole flow of mlc, one call per stage (each stage's folder is named after it):

    spec     = load(path or expression)          mlc.front    parse a truth table, PLA, expression, BLIF, AIGER
    aig      = synthesize(spec, level)           mlc.logic    smallest AND-inverter graph, proven equal to spec
    netlist  = map_aig(aig, signal)              mlc.netlist  library gates and lever types, proven again
    circuit  = build_circuit(netlist, spec)      mlc.circuit  placement, connector chains and branches: one scene
    report   = verify_static(circuit.scene)      mlc.verify   every row: equilibrium, bits, stretch, clearance
    report   = verify_dynamic(circuit.scene)     mlc.verify   every row by Brownian dynamics (mlc.sim)
    meshes   = mlc stl circuit.yaml              mlc.mesh     printable meshes with hinge tolerances

Units: sigma = 1 (muscle rest length), k0 = 1, gamma = 1; time in t0 = gamma/(1e-3 k0).
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field


@dataclass
class Compiled:
    """Everything the front end and the back end made of one specification."""

    spec: object
    aig: object
    netlist: object
    synth_stats: dict = field(default_factory=dict)
    proof: dict = field(default_factory=dict)
    seconds: float = 0.0
    circuit: object = None          # mlc.circuit.build.Circuit, when built


def load(path: str | None, expr: str | None = None, strict: bool = False):
    from mlc.front.load import load as _load
    return _load(path, expr, strict=strict)


def compile_spec(spec, level: int = 2, signal: str = "expand") -> Compiled:
    """Synthesize, map and prove: the netlist is checked equivalent to ``spec`` before use
    (raises InternalError if it is not)."""
    from mlc.logic.equiv import check_equivalent
    from mlc.logic.synth import synthesize
    from mlc.netlist.mapper import map_aig

    t0 = time.perf_counter()
    stats: dict = {}
    aig = synthesize(spec, level, stats)
    netlist = map_aig(aig, signal, spec.source)
    proof = check_equivalent(netlist.to_aig(), spec)
    return Compiled(spec, aig, netlist, stats, proof, time.perf_counter() - t0)


def build(compiled: Compiled, progress=None, options=None) -> Compiled:
    """Place and route the netlist into one circuit scene (posed in the all-zero row);
    ``options``: a :class:`mlc.circuit.build.CircuitOptions` (default: its defaults)."""
    from mlc.circuit.build import build_circuit
    compiled.circuit = build_circuit(compiled.netlist, compiled.spec, options=options, progress=progress)
    return compiled


def verify(scene, dynamic: bool = False, **kw):
    """Verify every row of ``scene``'s truth table (static, or Brownian dynamics)."""
    from mlc.verify.circuit import verify_dynamic, verify_static
    return verify_dynamic(scene, **kw) if dynamic else verify_static(scene, **kw)


def run(path: str | None, expr: str | None = None, level: int = 2, signal: str = "expand",
        dynamic: bool = False, **verify_kw):
    """The whole flow in memory: load, synthesize, map, place and route, verify."""
    c = build(compile_spec(load(path, expr), level, signal))
    return c, verify(c.circuit.scene, dynamic, **verify_kw)


__all__ = ["Compiled", "build", "compile_spec", "load", "run", "verify"]
