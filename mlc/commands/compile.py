"""``mlc compile``: Boolean logic in, a proven-equivalent netlist of mechanical gates and the
whole circuit as one mechanism out.  The stages are those of :mod:`mlc.pipeline`::

    spec    = load(INPUT or -e EXPR)                  mlc.front
    c       = compile_spec(spec, -O, --signal)        mlc.logic + mlc.netlist (netlist proven == spec)
    circuit = build_circuit(c.netlist, spec)          mlc.circuit (one scene, posed in the all-zero row)
    report  = verify(circuit.scene)                   mlc.verify (--verify; --dynamic for Brownian dynamics)
    meshes  = mlc stl OUT/circuit.yaml                mlc.mesh (--stl / --3mf)
    files   = render(...)                             everything in memory (staged) first
    commit                                            all outputs moved into place, or none
"""
from __future__ import annotations

import json
import sys

from mlc.commands.verify import add_jobs, check_jobs
from mlc.errors import MlcError

MAX_JOINT_K = 1e4          # --joint-k upper bound (k0); the stiff scheme's stages grow as sqrt(k)
MIN_JOINT_K = 0.1          # --joint-k lower bound (k0): a tenth of the paper's joints; circuits were measured at
                           # 1 to 100 (docs/circuits.md), and 1e-320 was accepted (joints of no stiffness at all)

# Peak memory of synthesizing a truth table grows with its 2**n input combinations (bit sets of
# 2**n bits, many alive at once): bytes = TABLE_BASE + 2**n (TABLE_PER_MINTERM + TABLE_PER_OUTPUT m).
# TABLE_MEASURED_PEAKS: (n, m) -> bytes, ru_maxrss of load + synthesize + map + prove in one
# process, 200 seeded random rows, the larger of -O0 and -O2 (-O0 peaks higher from 22 inputs).
TABLE_BASE = 0.2e9
TABLE_PER_MINTERM = 300
TABLE_PER_OUTPUT = 50
TABLE_MEASURED_PEAKS = {(18, 2): 0.260e9, (20, 2): 0.448e9, (22, 2): 1.611e9, (22, 6): 2.373e9, (24, 2): 5.815e9}
# -O3 peaks higher (mlc compile -O3, max RSS, same tables): (16, 2) 1.0 GB, (18, 2) 0.44, (20, 2) 1.33,
# (22, 2) 4.51 GB in 96 s; (24, 2) passed 23.9 GB and was killed by the kernel after 7.7 min
TABLE_O3_FACTOR = 5.0
TABLE_MEASURED_PEAKS_O3 = {(16, 2): 1.0e9, (18, 2): 0.44e9, (20, 2): 1.33e9, (22, 2): 4.51e9, (24, 2): 23.9e9}


def table_memory(spec, level: int = 2) -> float:
    """Estimated peak bytes of compiling ``spec`` at -O``level`` if it is a truth table (0 for a network)."""
    from mlc.spec import TableSpec
    if not isinstance(spec, TableSpec):
        return 0.0
    need = TABLE_BASE + 2.0 ** spec.n * (TABLE_PER_MINTERM + TABLE_PER_OUTPUT * len(spec.outputs))
    return need * TABLE_O3_FACTOR if level >= 3 else need


def check_table_memory(spec, level: int = 2) -> None:
    """Refuse a truth table whose synthesis would need more than the memory budget (half the
    memory available, at least 2 GiB: :func:`mlc.mesh.profiles.memory_budget`)."""
    from mlc.mesh.profiles import memory_budget
    need, budget = table_memory(spec, level), memory_budget()
    if need > budget:
        lower = level >= 3 and table_memory(spec, 2) <= budget
        raise MlcError(f"synthesizing this {spec.n}-input truth table at -O{level} would need about "
                       f"{need / 2 ** 30:.3g} GiB of memory ({len(spec.outputs)} outputs over 2^{spec.n} input "
                       f"combinations); the limit is {budget / 2 ** 30:.3g} GiB (half the memory available, "
                       f"at least 2 GiB)", spec.source,
                       "use -O2, which needs less" if lower else
                       "describe the function with fewer inputs, or as BLIF, AIGER or expressions (not tabulated)")


def register(sub):
    p = sub.add_parser("compile", help="compile Boolean logic (.tt .pla .expr .blif .aag .aig or -e) into mechanical gates",
                       description="Synthesize a minimum-gate And-Inverter Graph, map it onto the library gates, "
                                   "prove it equivalent to the input, and write OUTDIR/netlist.json, .blif, .aag, .aig and .dot.")
    p.add_argument("input", nargs="?", metavar="INPUT", help="specification file (.tt .pla .expr .eqn .blif .aag .aig)")
    p.add_argument("-e", "--expr", metavar="EXPR", help='expressions instead of a file, e.g. "s = a ^ b; c = a & b"')
    p.add_argument("-o", "--outdir", metavar="OUTDIR", default="out", help="output directory (default: out)")
    p.add_argument("-O", dest="level", metavar="LEVEL", type=int, default=2, choices=range(4),
                   help="synthesis effort 0..3 (default 2)")
    p.add_argument("--signal", choices=("expand", "contract"), default="expand",
                   help="muscle convention of the inputs and every wire (default expand)")
    p.add_argument("--strict", action="store_true", help=".tt: unlisted input combinations are an error")
    p.add_argument("--draw", metavar="PNG", help="also draw the gate schematic to this PNG file")
    p.add_argument("--no-circuit", action="store_true",
                   help="stop at the netlist (no circuit scene OUTDIR/circuit.yaml and picture OUTDIR/circuit.png)")
    p.add_argument("--joint-k", dest="joint_k", type=float, default=None, metavar="K",
                   help="connector joints' stiffness in units of the design k0 (default 100; 1 is the paper's, "
                        "whose long chains spread thermally over a third of the logic margin, docs/circuits.md)")
    p.add_argument("--max-gates", dest="max_gates", type=int, default=None, metavar="N",
                   help="build circuits of up to N gates (default: about an hour of place-and-route CPU by the "
                        "adders' fit; docs/circuits.md)")
    p.add_argument("--router", choices=("auto", "ik", "fast"), default="auto",
                   help="how connector chains are solved: ik (each chain whole, by inverse kinematics), fast "
                        "(steered along its lane, closed at its end; docs/circuits.md, 'The fast router'), auto "
                        "(default: fast from 17 gates on)")
    p.add_argument("--direct", action="store_true",
                   help="join a gate whose output feeds exactly one gate input by one full connector unit, "
                        "the sink placed on it (docs/circuits.md section 3, 'Direct connection')")
    p.add_argument("--muscle-per-lever", dest="muscle_per_lever", action="store_true",
                   help="every gate input lever a circuit input drives carries its own muscle of that input "
                        "(a global stimulus, as the paper's colours), instead of one muscle per input and "
                        "connector chains to the levers (docs/circuits.md, 'A muscle per lever')")
    p.add_argument("--verify", action="store_true",
                   help="verify the circuit on every row of its truth table (static; with --dynamic by Brownian dynamics)")
    p.add_argument("--dynamic", action="store_true", help="with --verify: Brownian dynamics from rest, until relaxed")
    p.add_argument("--kT", type=float, default=1e-5, help="thermal energy for --dynamic (k0 sigma^2, default 1e-5)")
    p.add_argument("--seeds", type=int, default=3, help="seeds per row for --dynamic (default 3)")
    p.add_argument("--scheme", choices=("stiff", "euler", "implicit"), default=None,
                   help="integrator for --dynamic (default: stiff for a circuit, implicit for a robot)")
    add_jobs(p, compile_=True)
    p.add_argument("--stl", metavar="STL", help="printable mesh of the whole circuit (through mlc stl)")
    p.add_argument("--3mf", dest="threemf", metavar="3MF", help="3MF of the circuit with named parts (through mlc stl)")
    p.add_argument("--profile", default="mjp", help="printer profile for --stl/--3mf (mjp, sla, fdm or a file)")
    p.add_argument("--force", action="store_true",
                   help="with --stl/--3mf: write the meshes even if a printability check fails (mlc stl --force)")
    p.add_argument("--robot", metavar="ROBOT.yaml",
                   help="also build the robot body the circuit drives (docs/robot.md): OUTDIR/robot.yaml, one scene; "
                        "--verify, --stl and --3mf then apply to the robot")
    p.add_argument("--allow-overlap", action="store_true",
                   help="with --robot: keep a coupling chain whose every start interpenetrates another slab (the "
                        "least overlapping; mlc verify reports the clearance) instead of refusing the robot")
    p.add_argument("--json", action="store_true", help="print the summary as JSON")
    p.set_defaults(func=run)


def compile_spec(spec, level: int = 2, signal: str = "expand"):
    """Synthesize, map and prove (:func:`mlc.pipeline.compile_spec`)."""
    from mlc.pipeline import compile_spec as _compile
    return _compile(spec, level, signal)


def render(c, draw: bool = False) -> dict[str, bytes]:
    """All output files, by name, in memory."""
    from mlc.logic.aigio import aag_to_aig
    nl = c.netlist
    files = {
        "netlist.json": nl.dumps().encode(),
        "netlist.blif": nl.to_blif().encode(),
        "netlist.aag": nl.to_aiger().encode(),
        "netlist.aig": aag_to_aig(nl.to_aiger(), "netlist.aag"),
        "netlist.dot": nl.to_dot().encode(),
    }
    if draw:
        files["<draw>"] = schematic_png(nl)
    return files


# A schematic of more gates than this is not legible at any size (a warning says so); it is
# also where Graphviz's layout stops being quick (measured, dot -Tpng of random netlists: 88 gates
# 0.7 s, 172 gates 1.7 s, 360 gates 12 s CPU; 2002 gates did not finish in 5 min).
DRAW_LEGIBLE_GATES = 150
DOT_TIMEOUT = 60.0           # seconds for Graphviz's layout; then the plain layered drawing


def schematic_png(nl, stream=None) -> bytes:
    """The gate schematic (--draw) as PNG bytes: Graphviz's ``dot`` layout of OUTDIR/netlist.dot
    when ``dot`` is installed and the circuit is legible (its splines go around the gate boxes),
    else mlc's own layered drawing (:meth:`mlc.netlist.ir.Netlist.render_png`, whose straight
    wires may pass behind boxes), with a warning on ``stream`` (standard error) that says why."""
    import shutil
    import subprocess
    stream = stream or sys.stderr
    n = len(nl.gates)
    if n > DRAW_LEGIBLE_GATES:
        stream.write(f"mlc: warning: --draw: {n} gates are too many to read in one drawing (about "
                     f"{DRAW_LEGIBLE_GATES} at most); a plain layered drawing is written, whose wires may pass "
                     f"behind gate boxes (OUTDIR/netlist.dot holds the graph)\n")
        from mlc.io.progress import Progress
        # a timer with an estimate: the issue measured 20 s for 3000 gates, taken as linear in gates
        with Progress(f"drawing {n} gates", expect=20.0 * n / 3000, stream=stream):
            return nl.render_png()
    dot = shutil.which("dot")
    if dot is None:
        return nl.render_png()
    try:
        r = subprocess.run([dot, "-Tpng"], input=nl.to_dot().encode(), capture_output=True, timeout=DOT_TIMEOUT)
        if r.returncode == 0 and r.stdout.startswith(b"\x89PNG"):
            return r.stdout
    except (OSError, subprocess.TimeoutExpired):
        pass
    stream.write("mlc: warning: --draw: Graphviz's dot failed; a plain layered drawing is written, whose wires "
                 "may pass behind gate boxes\n")
    return nl.render_png()


def summary(c, written: list[str], level: int) -> dict:
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
        "circuit": None if c.circuit is None else {
            "bodies": len(c.circuit.scene.bodies), "chains": c.circuit.chains, "half_units": c.circuit.half_units,
            "seconds": {k: round(v, 3) for k, v in c.circuit.seconds.items()},
            **{k: c.circuit.scene.meta["connector"][k] for k in ("direct", "direct_dropped", "state_contacts")
               if k in c.circuit.scene.meta["connector"]}},
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
    if d.get("circuit"):
        ci = d["circuit"]
        lines.append(f"circuit: {ci['bodies']} bodies, {ci['chains']} connector chains, {ci['half_units']} half units "
                     f"(placed and routed in {sum(ci['seconds'].values()):.1f} s)")
        if "direct" in ci:
            lines.append(f"direct connections: {len(ci['direct'])}"
                         + "".join(f", {d} -> {s}.{p}" for d, s, p in ci["direct"])
                         + (f"; chained instead, as a chain crossed their column: {', '.join(ci['direct_dropped'])}"
                            if ci.get("direct_dropped") else ""))
        if ci.get("state_contacts"):
            a, i, b, j, cl = ci["state_contacts"][0]
            lines.append(f"warning: {len(ci['state_contacts'])} pair(s) of chain layers may touch in a row where their "
                         f"wires switch (closest: {a} half unit {i} and {b} half unit {j}, {cl:+.3f} sigma as rigid "
                         f"layers; scene meta connector.state_contacts); mlc verify reports the clearance of every row")
    if d.get("verification"):
        v = d["verification"]
        lines.append(f"verification ({v['mode']}): {'all ' + str(v['rows']) + ' rows correct' if v['ok'] else 'FAILED'}"
                     f" in {v['seconds']:.1f} s")
    if d.get("robot"):
        r = d["robot"]
        lines.append(f"robot: {r['units']} skeleton units, {r['chains']} coupling chains ({r['half_units']} half units), "
                     f"{r['bodies']} bodies in robot.yaml")
    lines.append("wrote " + ", ".join(d["files"]))
    return "\n".join(lines)


def run(args) -> int:
    from mlc.front.load import load
    from mlc.io.outputs import Outputs
    from mlc.io.progress import Progress

    want_circuit = not args.no_circuit
    if not want_circuit and (args.verify or args.stl or args.threemf):
        raise MlcError("--verify, --stl and --3mf need the circuit", "--no-circuit", "drop --no-circuit")
    if args.dynamic and not args.verify:
        raise MlcError("--dynamic only applies to --verify", "--dynamic", "add --verify")
    if args.jobs != 1 and not want_circuit:
        raise MlcError("--jobs only applies to the circuit (routing, --verify)", "--no-circuit", "drop --no-circuit")
    check_jobs(args.jobs, False)                    # with --dynamic it routes; the runs take the integrator's threads
    if not 1 <= args.seeds <= 1000:
        raise MlcError(f"--seeds must be between 1 and 1000, got {args.seeds}", "--seeds")
    from mlc.sim import check_kT
    check_kT(args.kT)
    joint_k = getattr(args, "joint_k", None)
    if joint_k is not None:
        if not want_circuit:
            raise MlcError("--joint-k only applies to the circuit", "--no-circuit", "drop --no-circuit")
        if not (MIN_JOINT_K <= joint_k <= MAX_JOINT_K):
            raise MlcError(f"--joint-k must be from {MIN_JOINT_K:g} to {MAX_JOINT_K:g} (k0), got {joint_k}",
                           "--joint-k", "use e.g. --joint-k 1 (the paper's joints) or 100 (the default)")
    max_gates = getattr(args, "max_gates", None)
    if max_gates is not None:
        if not want_circuit:
            raise MlcError("--max-gates only applies to the circuit", "--no-circuit", "drop --no-circuit")
        if max_gates < 1:
            raise MlcError(f"--max-gates must be at least 1, got {max_gates}", "--max-gates",
                           "give the largest gate count to build, e.g. --max-gates 250")
    if getattr(args, "router", "auto") != "auto" and not want_circuit:
        raise MlcError("--router only applies to the circuit", "--no-circuit", "drop --no-circuit")
    if getattr(args, "direct", False) and not want_circuit:
        raise MlcError("--direct only applies to the circuit", "--no-circuit", "drop --no-circuit")
    if getattr(args, "muscle_per_lever", False) and not want_circuit:
        raise MlcError("--muscle-per-lever only applies to the circuit", "--no-circuit", "drop --no-circuit")
    if getattr(args, "allow_overlap", False) and not getattr(args, "robot", None):
        raise MlcError("--allow-overlap only applies to a robot's coupling chains", "--allow-overlap",
                       "add --robot ROBOT.yaml or drop --allow-overlap")
    if getattr(args, "robot", None):
        if not want_circuit:
            raise MlcError("--robot needs the circuit", "--no-circuit", "drop --no-circuit")
        from mlc.robot.spec import load_robot
        load_robot(args.robot)                      # the file alone, before the work
    if args.stl or args.threemf:
        from mlc.mesh.profiles import load_profile
        load_profile(args.profile)                  # a bad profile fails now, not after the circuit is built
    outs = Outputs(inputs=[args.input, getattr(args, "robot", None)])
    outdir = outs.directory(args.outdir, "-o")
    draw = outs.file(args.draw, "--draw", suffixes=(".png",), parents=True)
    stl = outs.file(args.stl, "--stl", suffixes=(".stl",), parents=True)
    threemf = outs.file(args.threemf, "--3mf", suffixes=(".3mf",), parents=True)
    outs.check()                                    # every output location, before the work

    spec = load(args.input, args.expr, strict=args.strict)
    check_table_memory(spec, args.level)
    from mlc.logic.synth import STEPS
    with Progress(f"synthesizing and proving {spec.source}", steps=STEPS):   # 24-input tables take ~1 min
        c = compile_spec(spec, args.level, args.signal)
    files = render(c, draw=bool(args.draw))
    report = None
    if want_circuit:
        from mlc.circuit.build import CircuitOptions
        from mlc.pipeline import build
        from mlc.scene.io import dump_scene
        extra = {} if joint_k is None else {"joint_k": joint_k}
        if args.robot:
            from mlc.robot.build import CIRCUIT_END_DROP, CIRCUIT_PRINT_LEANS
            extra["end_drop"] = CIRCUIT_END_DROP
            extra["print_leans"] = CIRCUIT_PRINT_LEANS
        opts = CircuitOptions(direct=bool(getattr(args, "direct", False)), max_gates=max_gates, jobs=args.jobs,
                              router=getattr(args, "router", "auto"),
                              muscle_per_lever=bool(getattr(args, "muscle_per_lever", False)), **extra)
        with Progress("placing and routing", total=1) as bar:
            build(c, progress=lambda done, total: (setattr(bar, "total", total), bar.update(done)), options=opts)
        scene = c.circuit.scene
        files["circuit.yaml"] = dump_scene(scene).encode()
        from mlc.circuit.draw import render_circuit
        files["circuit.png"] = render_circuit(scene)
        if args.robot:                              # docs/robot.md
            from mlc.commands.robot import robot_files
            robot_scene, robot_out = robot_files(scene, args.robot, allow_overlap=bool(getattr(args, "allow_overlap", False)))
            files.update(robot_out)
            scene = robot_scene
        if args.verify:
            from mlc.commands.verify import verify_scene_file
            if args.dynamic:
                from mlc.io.warmup import notice
                notice(args.scheme)
            report = verify_scene_file(scene, args.dynamic, args.kT, args.seeds, args.scheme,
                                       jobs=1 if args.dynamic else args.jobs)
    with outs:
        for name, data in files.items():
            if name == "<draw>":
                draw.write_bytes(data)
            else:
                outdir.write_bytes(name, data)
        if report is not None:
            outdir.write_text("verify.json", json.dumps(report.as_dict(), indent=1))
        if stl is not None or threemf is not None:
            _mesh(outdir.file("robot.yaml" if args.robot else "circuit.yaml"), stl, threemf, args.profile,
                  args.force)
        if report is not None and not report.ok:
            from mlc.robot.verify import format_any as format_report
            sys.stdout.write(format_report(report) + "\n")
            raise MlcError(f"the circuit failed {args.dynamic and 'dynamic' or 'static'} verification "
                           f"(rows {', '.join(r['state'] for r in report.rows if not r['ok'])})",
                           f"{spec.source}", "this is a bug in mlc's circuit back end: please report it")
    written = outs.written
    d = summary(c, written, args.level)
    if args.robot:
        rm = scene.meta["robot"]
        d["robot"] = {"units": rm["units"], "chains": rm["chains"], "half_units": rm["half_units"],
                      "bodies": len(scene.bodies)}
    if report is not None:
        d["verification"] = {"mode": report.mode, "ok": report.ok, "rows": len(report.rows),
                             "seconds": report.seconds, **report.params}
    if args.json:
        print(json.dumps(d))
    else:
        print(format_summary(d))
        if report is not None:
            from mlc.robot.verify import format_any as format_report
            print(format_report(report))
    return 0


def _mesh(scene_path, stl, threemf, profile: str, force: bool = False) -> None:
    """Printable meshes of the circuit through ``mlc stl`` (staged paths; its limits and
    checks apply, ``force`` passes its ``--force``)."""
    from mlc.cli import main as cli
    argv = ["stl", str(scene_path), "--profile", profile] + (["--force"] if force else [])
    if stl is not None:
        argv += ["-o", str(stl.tmp)]
    if threemf is not None:
        argv += ["--3mf", str(threemf.tmp)]
    import contextlib
    import io
    err = io.StringIO()
    with contextlib.redirect_stderr(err):
        rc = cli(argv)
    if rc != 0:
        from mlc.errors import MlcError
        msg = err.getvalue().strip().splitlines()
        last = msg[-1] if msg else f"exit {rc}"
        last = last[len("mlc: error: "):] if last.startswith("mlc: error: ") else last
        raise MlcError(f"meshing the circuit failed: {last}", "--stl",
                       "see mlc stl OUTDIR/circuit.yaml for the printability report; --force writes the meshes "
                       "even if a printability check fails")
