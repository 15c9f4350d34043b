"""``mlc compile``: Boolean logic in, a proven-equivalent netlist of mechanical gates out.

Pipeline (each step one call; the back end adds scene and mesh steps after ``map``)::

    spec    = load(INPUT or -e EXPR)                  mlc.front.load
    aig     = synthesize(spec, -O)                    mlc.logic.synth (proves aig == spec)
    netlist = map_aig(aig, --signal)                  mlc.netlist.mapper
    proof   = check_equivalent(netlist.to_aig(), spec)   the mapped gates, proven again
    files   = render(netlist, ...)                    everything in memory first
    write(OUTDIR, files)                              atomically, only after all of the above
"""
from __future__ import annotations

import json
import time
from dataclasses import dataclass, field
from pathlib import Path

from mlc.errors import MlcError


def register(sub):
    p = sub.add_parser("compile", help="compile Boolean logic (.tt .pla .expr .blif .aag or -e) into mechanical gates",
                       description="Synthesize a minimum-gate And-Inverter Graph, map it onto the library gates, "
                                   "prove it equivalent to the input, and write OUTDIR/netlist.json, .blif, .aag and .dot.")
    p.add_argument("input", nargs="?", metavar="INPUT", help="specification file (.tt .pla .expr .eqn .blif .aag)")
    p.add_argument("-e", "--expr", metavar="EXPR", help='expressions instead of a file, e.g. "s = a ^ b; c = a & b"')
    p.add_argument("-o", "--outdir", metavar="OUTDIR", default="out", help="output directory (default: out)")
    p.add_argument("-O", dest="level", metavar="LEVEL", type=int, default=2, choices=range(4),
                   help="synthesis effort 0..3 (default 2)")
    p.add_argument("--signal", choices=("expand", "contract"), default="expand",
                   help="muscle convention of the inputs and every wire (default expand)")
    p.add_argument("--strict", action="store_true", help=".tt: unlisted input combinations are an error")
    p.add_argument("--draw", metavar="PNG", help="also draw the circuit to this PNG file")
    p.add_argument("--json", action="store_true", help="print the summary as JSON")
    p.set_defaults(func=run)


@dataclass
class Compiled:
    spec: object
    aig: object
    netlist: object
    synth_stats: dict = field(default_factory=dict)
    proof: dict = field(default_factory=dict)
    seconds: float = 0.0


def compile_spec(spec, level: int = 2, signal: str = "expand") -> Compiled:
    """Synthesize, map and prove; raises InternalError if anything is not equivalent."""
    from mlc.netlist.mapper import map_aig
    from mlc.logic.equiv import check_equivalent
    from mlc.logic.synth import synthesize

    t0 = time.perf_counter()
    stats: dict = {}
    aig = synthesize(spec, level, stats)
    netlist = map_aig(aig, signal, spec.source)
    proof = check_equivalent(netlist.to_aig(), spec)
    return Compiled(spec, aig, netlist, stats, proof, time.perf_counter() - t0)


def render(c: Compiled, draw: bool = False) -> dict[str, bytes]:
    """All output files, by name, in memory."""
    nl = c.netlist
    files = {
        "netlist.json": nl.dumps().encode(),
        "netlist.blif": nl.to_blif().encode(),
        "netlist.aag": nl.to_aiger().encode(),
        "netlist.dot": nl.to_dot().encode(),
    }
    if draw:
        files["<draw>"] = nl.render_png()
    return files


def write(outdir: str, files: dict[str, bytes], draw_path: str | None = None) -> list[str]:
    from mlc.io.atomic import write_bytes

    out = Path(outdir)
    if out.exists() and not out.is_dir():
        raise MlcError("exists and is not a directory", "-o", "choose another output directory")
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as e:
        raise MlcError(f"cannot create output directory {out}: {e.strerror}", "-o") from None
    written = []
    for name, data in files.items():
        if name == "<draw>":
            continue
        write_bytes(out / name, data)
        written.append(str(out / name))
    if draw_path is not None:
        parent = Path(draw_path).parent
        if str(parent) and not parent.exists():
            parent.mkdir(parents=True, exist_ok=True)
        write_bytes(draw_path, files["<draw>"])
        written.append(str(draw_path))
    return written


def summary(c: Compiled, written: list[str], level: int) -> dict:
    nl, s = c.netlist, c.netlist.stats
    return {
        "source": c.spec.source,
        "inputs": len(c.spec.inputs),
        "outputs": len(c.spec.outputs),
        "gates": s["gates"],
        "depth": s["depth"],
        "equivalent": bool(c.proof.get("equivalent")),
        "equivalence_method": c.proof.get("method"),
        "signal": nl.signal,
        "level": level,
        "gate_types": s["gate_types"],
        "levers": s["levers"],
        "branches": s["branches"],
        "half_units": s["half_units"],
        "const_outputs": {o.name: o.value for o in nl.outputs if o.kind == "const"},
        "input_outputs": {o.name: ("!" if o.half_unit else "") + o.src[1] for o in nl.outputs if o.kind == "input"},
        "files": written,
        "seconds": round(c.seconds, 3),
    }


def format_summary(d: dict) -> str:
    types = ", ".join(f"{k} {v}" for k, v in d["gate_types"].items()) or "none"
    lines = [
        f"{d['source']}: {d['inputs']} inputs, {d['outputs']} outputs",
        f"gates: {d['gates']} ({types}), depth {d['depth']}",
        f"levers: {d['levers'].get('open', 0)} open, {d['levers'].get('crossed', 0)} crossed ({d['signal']}ing muscles); "
        f"connector branches: {d['branches']}; half units: {d['half_units']}",
    ]
    if d["const_outputs"]:
        lines.append("constant outputs: " + ", ".join(f"{k} = {v}" for k, v in d["const_outputs"].items()))
    if d["input_outputs"]:
        lines.append("outputs wired to an input: " + ", ".join(f"{k} = {v}" for k, v in d["input_outputs"].items()))
    lines.append(f"equivalence proven ({d['equivalence_method']}); compiled in {d['seconds']} s")
    lines.append("wrote " + ", ".join(d["files"]))
    return "\n".join(lines)


def run(args) -> int:
    from mlc.front.load import load

    spec = load(args.input, args.expr, strict=args.strict)
    c = compile_spec(spec, args.level, args.signal)
    files = render(c, draw=bool(args.draw))
    written = write(args.outdir, files, args.draw)
    d = summary(c, written, args.level)
    print(json.dumps(d) if args.json else format_summary(d))
    return 0
