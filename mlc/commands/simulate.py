"""``mlc simulate``: Brownian dynamics of a scene with the bundled Numba integrator."""
from __future__ import annotations

import json
import math
import sys


def register(sub):
    p = sub.add_parser(
        "simulate", help="run Brownian dynamics of a scene (times in t0 = gamma/(1e-3 k0))",
        description="Overdamped rigid-body Brownian dynamics of a scene file (docs/simulation.md). "
                    "Times are in t0 = gamma/(1e-3 k0); lengths in sigma.")
    p.add_argument("scene", metavar="SCENE.yaml")
    p.add_argument("--time", type=float, required=True, help="simulated time (t0)")
    p.add_argument("--dt", type=float, default=None,
                   help="time step (t0); euler: default half the estimated stability limit; "
                        "stiff, implicit: the largest step (default 0.05), split adaptively in transients")
    p.add_argument("--scheme", choices=("euler", "stiff", "implicit"), default="stiff",
                   help="euler: Euler-Maruyama (the reference, HOOMD-blue's); stiff: SK-ROCK (default); "
                        "implicit: linearly implicit, one sparse solve per step (large scenes of stiff joints)")
    p.add_argument("--kT", type=float, default=1e-5, help="thermal energy (k0 sigma^2), default 1e-5")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--set", action="append", default=[], metavar="INPUT=VALUE",
                   help="drive an input: 0, 1, step:T[:BEFORE:AFTER], square:PERIOD[:DUTY[:START]], "
                        "table:T0=V0,T1=V1,... (values from 0, muscles at rest, to 1, actuated; times in t0; "
                        "repeatable; unset inputs stay at 0)")
    p.add_argument("--drift-tol", type=float, default=0.01, metavar="SIGMA",
                   help="stiff scheme: largest drift of a body per substep (sigma, default 0.01); "
                        "probe errors come out about a tenth of it")
    p.add_argument("--fluct", action="store_true",
                   help="stiff scheme, fluctuation mode: SK-ROCK without damping and post-processed records, "
                        "so bond fluctuations have their exact variance (linear theory) at any dt, and random "
                        "substep levels so that no stiff mode stays on a Chebyshev extremum; about twice the "
                        "force evaluations of --scheme stiff at small noise (docs/simulation.md)")
    p.add_argument("--rot-noise", action="store_true", help="add rotational noise (off in the paper)")
    p.add_argument("--threads", type=int, default=1, help="numba threads for scenes of 20000 bodies or more (default 1)")
    p.add_argument("--out", default=None, metavar="traj.gsd", help="write a GSD trajectory")
    p.add_argument("--frames", type=int, default=200, help="at most this many evenly spaced frames in the GSD trajectory, the last one final (default 200)")
    p.add_argument("--probes", default=None, metavar="probes.csv",
                   help="write probe time series as CSV (and .npz beside it)")
    p.add_argument("--record", type=float, default=None, metavar="DT",
                   help="probe sampling interval (t0); default about 2000 samples")
    p.add_argument("--json", action="store_true", help="print a JSON summary")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=run)


def parse_sets(items, scene) -> dict:
    from mlc.errors import MlcError
    from mlc.sim.drive import Drive

    drives = {}
    for item in items:
        if "=" not in item:
            raise MlcError(f"--set {item!r} is not INPUT=VALUE", "--set", "e.g. --set a=1")
        name, val = item.split("=", 1)
        name = name.strip()
        if name not in scene.inputs:
            raise MlcError(f"no input named {name!r} in scene {scene.name}", "--set",
                           f"inputs are {', '.join(scene.inputs) or 'none'}")
        if name in drives:
            raise MlcError(f"--set {name} is given twice", "--set", "drive each input once")
        drives[name] = Drive.parse(val, f"--set {name}")
    return drives


def run(args) -> int:
    from mlc.scene.io import load_scene
    from mlc.sim.integrator import SimOptions, Simulation
    from mlc.sim.output import write_gsd, write_probes_csv, write_probes_npz
    from mlc.errors import MlcError

    scene = load_scene(args.scene)
    drives = parse_sets(args.set, scene)
    if args.frames < 1:
        raise MlcError("--frames must be >= 1", "--frames")
    if not (math.isfinite(args.drift_tol) and args.drift_tol > 0):
        raise MlcError(f"--drift-tol must be a positive number of sigma, got {args.drift_tol}", "--drift-tol",
                       "the default 0.01 keeps probe errors near 0.001 sigma")
    if not (math.isfinite(args.time) and args.time > 0):
        raise MlcError(f"--time must be a positive number of t0, got {args.time}", "--time")
    if args.dt is not None and not (math.isfinite(args.dt) and 0 < args.dt <= args.time):
        raise MlcError(f"--dt must be a positive number of t0 no larger than --time ({args.time:g}), got {args.dt}",
                       "--dt", f"e.g. --dt {args.time / 10:g}; the last step ends exactly at --time")
    if args.record is not None and not (math.isfinite(args.record) and args.record > 0):
        raise MlcError(f"--record must be a positive number of t0, got {args.record}", "--record")
    if args.record is not None and args.record > args.time:
        raise MlcError(f"--record {args.record:g} is longer than the run (--time {args.time:g})", "--record",
                       "give a sampling interval of at most --time (t0); the default takes about 2000 samples")
    if args.threads < 1:
        raise MlcError(f"--threads must be >= 1, got {args.threads}", "--threads")
    from mlc.io.cores import usable_cores
    cores = usable_cores()
    if args.threads > cores:
        raise MlcError(f"--threads {args.threads} is more than the {cores} cores of this machine", "--threads",
                       f"use at most {cores}")
    if args.fluct and args.scheme != "stiff":
        raise MlcError("--fluct is a mode of the stiff scheme", "--fluct", "drop --scheme euler")
    from mlc.io.outputs import Outputs, is_special
    outs = Outputs(inputs=[args.scene])
    gsd = outs.file(args.out, "--out", suffixes=(".gsd",))
    csv = outs.file(args.probes, "--probes", suffixes=(".csv",))
    npz = None
    if csv is not None and not is_special(csv.path):          # no .npz beside /dev/stdout
        npz = outs.file(csv.path.with_suffix(".npz"), "--probes (its .npz)", suffixes=(".npz",))
    opt = SimOptions(dt=args.dt, scheme=args.scheme, kT=args.kT, seed=args.seed, rot_noise=args.rot_noise,
                     threads=args.threads, disp_acc=args.drift_tol, fluct=args.fluct)
    with outs:          # every output location checked before the run; all written, or none
        sim = Simulation(scene, drives, opt)
        steps = args.time / sim.dt
        if not (math.isfinite(steps) and steps <= sim.opt.max_steps):
            raise MlcError(f"--time {args.time:g} at a step of {sim.dt:g} t0 is {steps:.3g} steps (more than "
                           f"{sim.opt.max_steps:.3g})", "--time", "use a shorter --time or a larger --dt")
        if not (args.quiet or args.json):
            from mlc.io.warmup import notice
            notice(args.scheme, sim.parallel)
        res = sim.run(args.time, record_interval=args.record, frames=args.frames if args.out else 0,
                      quiet=args.quiet or args.json)
        if gsd:
            write_gsd(gsd.tmp, scene, res.frame_times, res.frame_pos, res.frame_quat)
        if csv:
            write_probes_csv(csv.tmp, res.times, res.probes)
        if npz:
            write_probes_npz(str(npz.tmp), res.times, res.probes,
                             {"scene": scene.name, "scheme": res.scheme, "dt": res.dt, "kT": args.kT,
                              "seed": args.seed})
    bias = sim.variance_bias()
    summary = {"scene": scene.name, "scheme": res.scheme, "fluct": bool(args.fluct), "dt": res.dt,
               "steps": res.steps, "time": res.time, "wall": round(res.wall, 4), "force_evals": res.force_evals,
               "kT": args.kT, "seed": args.seed, "probes": res.final_probes(),
               "variance_bias": bias, "warnings": res.warnings, "interrupted": res.interrupted}
    for w in res.warnings:
        sys.stderr.write(f"mlc: warning: {w}\n")
    if args.json:
        print(json.dumps(summary))
    else:
        out = sys.stdout
        out.write(f"{scene.name}: {res.steps} steps of {res.dt:g} t0 ({res.scheme}"
                  f"{', fluctuation mode' if args.fluct else ''}) to t = {res.time:g} t0 in {res.wall:.2f} s\n")
        for k, v in summary["probes"].items():
            out.write(f"  {k} = {v:.6f} sigma\n")
        if args.kT > 0:
            out.write(f"  stationary variance of harmonic modes / exact (linear theory, this dt): "
                      f"{bias['ratio_min']:.3g} .. {bias['ratio_max']:.3g}\n")
    if res.interrupted:
        sys.stderr.write(f"mlc: interrupted at t = {res.time:g} t0; outputs hold the run up to there\n")
        return 130
    return 0
