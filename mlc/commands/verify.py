"""``mlc verify SCENE.yaml``: every row of a scene's truth table, statically or by
Brownian dynamics; exit 1 on a wrong bit (naming the row and the output)."""
from __future__ import annotations

import json


MAX_SEEDS = 1000            # seeds per row for --dynamic
MAX_DT = 1e3          # --dt upper bound (t0): the slowest rows relax in about 100 t0 (the Tetris robot)
MIN_DT = 1e-6         # --dt lower bound (t0): a run of 20 t0 is then 2e7 steps
MAX_TAU = 1e4         # --tau upper bound (t0): a run lasts several tau; the Tetris robot's is 100 t0
MAX_JOBS = 256        # --jobs upper bound: rows verified at once, one process each


def register(sub):
    p = sub.add_parser("verify", help="verify a scene (compiled circuit, connector, gate) on every row of its truth table",
                       description="For every row of the scene's truth table: the static equilibrium (default; with the "
                                   "joint stretch and the smallest slab clearance) or Brownian dynamics from rest until "
                                   "every probe has relaxed (--dynamic). Prints a table of rows by outputs with the read "
                                   "length and margin (sigma); exit 1 on a wrong bit. Units: sigma, k0, t0.")
    p.add_argument("scene", metavar="SCENE", help="scene file (.yaml), e.g. OUT/circuit.yaml from mlc compile")
    p.add_argument("--dynamic", action="store_true", help="Brownian dynamics instead of statics")
    p.add_argument("--kT", type=float, default=1e-5,
                   help="thermal energy (k0 sigma^2, default 1e-5): the Brownian dynamics' (--dynamic), or the one "
                        "the static check's thermal spread of every probe is computed at (0: skip that)")
    p.add_argument("--seeds", type=int, default=3, help="seeds per row for --dynamic (default 3)")
    p.add_argument("--scheme", choices=("stiff", "euler", "implicit"), default=None,
                   help="integrator for --dynamic (default: stiff for a circuit, implicit for a robot)")
    p.add_argument("--tau", type=float, metavar="T",
                   help="--dynamic: the slowest relaxation time (t0); a run lasts at least 3 T and ends at the first "
                        "plateau (robots: or the fold time). Default for a robot: mlc.robot.verify.ROBOT_TAU "
                        "(docs/robot.md section 3); for a circuit, computed per row (mlc.verify.dynamic.signal_time)")
    p.add_argument("--dt", type=float, metavar="DT",
                   help="--dynamic: the integrator's step (t0). Default for a robot: mlc.robot.verify.ROBOT_DT; "
                        "for a circuit of more than 300 bodies, mlc.verify.dynamic.DT_LARGE (0.2 t0 with the stiff scheme), "
                        "else mlc.verify.dynamic.DT (0.01 t0)")
    p.add_argument("--rows", metavar="BITS", nargs="+", help="verify only these rows (bit strings in input order)")
    p.add_argument("--require-clearance", action="store_true",
                   help="also fail a row whose slabs interpenetrate (reported as a warning otherwise): static, "
                        "in the row's pose; a robot's --dynamic check, in any seed's final pose")
    add_jobs(p)
    p.add_argument("--json", action="store_true", help="print the report as JSON")
    p.set_defaults(func=run)


def add_jobs(p, compile_: bool = False) -> None:
    """The ``--jobs`` option (``mlc verify``; ``mlc compile``, where it also routes)."""
    what = ("routing: the next chains' first solves start in N-1 other processes, and with --verify the static "
            "check runs N rows at once (default 1; the scene and the report are the same" if compile_ else
            "static check: N rows at once, each in a process of its own (default 1; the report is the same")
    p.add_argument("--jobs", type=int, default=1, metavar="N",
                   help=what + " for any N; memory grows with N). --dynamic runs use the integrator's threads instead")


def check_jobs(jobs: int, dynamic: bool) -> None:
    """--jobs is a whole number of at least 1, and only for the static check."""
    from mlc.errors import MlcError
    if jobs < 1 or jobs > MAX_JOBS:
        raise MlcError(f"--jobs must be between 1 and {MAX_JOBS}, got {jobs}", "--jobs",
                       "e.g. --jobs 2 on a 2-core machine")
    if jobs > 1 and dynamic:
        raise MlcError("--jobs applies to the static check; Brownian dynamics (--dynamic) already runs on the "
                       "integrator's threads (NUMBA_NUM_THREADS)", "--jobs", "drop --jobs or --dynamic")


def verify_scene_file(scene, dynamic: bool = False, kT: float = 1e-5, seeds: int = 3, scheme: str | None = None,
                      rows=None, require_clearance: bool = False, tau: float | None = None, dt: float | None = None,
                      jobs: int = 1):
    """The report for an already loaded scene (used by ``mlc compile --verify`` too).  ``tau``
    and ``dt`` (t0, dynamic only): the relaxation time a run lasts at least 3 times and the
    integrator's step; None (and ``scheme`` None): the robot's or the verifier's defaults.  ``jobs``: rows of the
    static check solved at once (:func:`mlc.verify.circuit.map_rows`)."""
    from mlc.io.progress import Progress
    from mlc.verify.circuit import select_rows, verify_dynamic, verify_static

    if isinstance(scene.meta, dict) and scene.meta.get("element") == "robot":     # docs/robot.md
        from mlc.robot.verify import verify_robot
        return verify_robot(scene, dynamic, kT, seeds, scheme, rows, tau=tau, dt=dt, jobs=jobs,
                            require_clearance=require_clearance)
    n = len(select_rows(scene, rows))
    if dynamic:
        return verify_dynamic(scene, rows, kT=kT, seeds=seeds, scheme=scheme or "stiff", tau=tau, dt=dt)
    with Progress(f"static verification of {scene.name}", total=n) as bar:
        return verify_static(scene, rows, progress=lambda done, total: bar.update(done),
                             require_clearance=require_clearance, kT=kT, jobs=jobs)


def run(args) -> int:
    from mlc.errors import MlcError
    from mlc.scene.io import load_scene
    from mlc.verify.circuit import format_report

    from mlc.sim import check_kT
    check_kT(args.kT)
    check_jobs(args.jobs, args.dynamic)
    if args.dynamic and not 1 <= args.seeds <= MAX_SEEDS:
        raise MlcError(f"--seeds must be between 1 and {MAX_SEEDS}, got {args.seeds} (each seed of each row is a "
                       f"Brownian-dynamics run of minutes on a circuit)", "--seeds")
    for opt, v in (("--tau", args.tau), ("--dt", args.dt)):
        if v is None:
            continue
        if not args.dynamic:
            raise MlcError(f"{opt} needs --dynamic (it sets the Brownian-dynamics run)", opt, f"add --dynamic or leave {opt} out")
        if not (v > 0 and v < float("inf")):
            raise MlcError(f"{opt} must be a finite time > 0 (t0), got {v}", opt,
                           "e.g. --tau 100 --dt 0.2 for the Tetris robot (docs/robot.md section 3)")
    if args.tau is not None and args.tau > MAX_TAU:         # 1e308 overflowed the step count (an internal error)
        raise MlcError(f"--tau {args.tau:g} t0 is longer than any relaxation mlc checks (at most {MAX_TAU:g} t0)",
                       "--tau", "e.g. --tau 100 for the Tetris robot (docs/robot.md section 3)")
    if args.dt is not None and args.dt < MIN_DT:
        raise MlcError(f"--dt {args.dt:g} t0 is below {MIN_DT:g} t0 (a run of 20 t0 would be over 2e7 steps)", "--dt",
                       "e.g. --dt 0.2 (circuits' default); the stiff scheme takes any step")
    if args.dt is not None and args.dt > min(args.tau or MAX_DT, MAX_DT):
        # a run advances one averaging window (0.05 t0 to tau/20) at a time, so a longer step is cut to
        # it; a step over 1e9 windows made no step at all, and the rest pose was read as a wrong bit
        raise MlcError(f"--dt {args.dt:g} t0 is longer than {'--tau' if args.tau else 'any run needs'} "
                       f"({min(args.tau or MAX_DT, MAX_DT):g} t0)", "--dt",
                       "e.g. --dt 0.2 (circuits' default); steps longer than the averaging window are cut to it")
    scene = load_scene(args.scene)
    if args.dynamic:
        from mlc.io.warmup import notice
        notice(args.scheme)
    rep = verify_scene_file(scene, args.dynamic, args.kT, args.seeds, args.scheme, args.rows,
                            args.require_clearance, tau=args.tau, dt=args.dt, jobs=args.jobs)
    fmt = format_report
    if isinstance(scene.meta, dict) and scene.meta.get("element") == "robot":
        from mlc.robot.verify import format_robot_report as fmt
    print(json.dumps(rep.as_dict()) if args.json else fmt(rep))
    return 0 if rep.ok else 1
