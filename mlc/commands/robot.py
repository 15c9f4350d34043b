"""``mlc robot``: pictures and trajectories of a compiled robot (docs/robot.md).

* ``mlc robot shapes OUT/robot.yaml -o shapes.png``: the skeleton of every input row side
  by side (paper Fig. 6, top right), from the static equilibria (default) or from the
  final poses of a Brownian-dynamics run (``--dynamic``, one seed);
* ``mlc robot fold OUT/robot.yaml --row 11 --time T``: one fold by Brownian dynamics from
  rest: ``--gif``, ``--frames DIR`` (PNG sequence) and ``--gsd`` (a trajectory with slab
  shapes, for OVITO).

``mlc compile LOGIC --robot ROBOT.yaml`` uses :func:`robot_files`.  Units: sigma, t0.
"""
from __future__ import annotations

import json
import math


def robot_files(circuit_scene, robot_path, allow_overlap: bool = False):
    """(robot scene, {"robot.yaml": bytes}) for a built circuit and a robot file
    (``allow_overlap``: :func:`mlc.robot.build.build_robot`)."""
    from mlc.robot.build import build_robot
    from mlc.robot.spec import load_robot
    from mlc.scene.io import dump_scene

    spec = load_robot(robot_path, circuit_scene)
    robot = build_robot(circuit_scene, spec, allow_overlap=allow_overlap)
    return robot.scene, {"robot.yaml": dump_scene(robot.scene).encode()}


def register(sub):
    p = sub.add_parser("robot", help="pictures and trajectories of a compiled robot (OUT/robot.yaml)",
                       description="Pictures of a robot scene from mlc compile --robot: the folded shapes of every "
                                   "row, and one fold by Brownian dynamics as GIF, PNG frames and GSD. Units: sigma, t0.")
    rs = p.add_subparsers(dest="robot_cmd", metavar="{shapes,fold}")
    rs.required = True
    a = rs.add_parser("shapes", help="the skeleton of every row side by side (PNG)")
    a.add_argument("scene", metavar="ROBOT.yaml")
    a.add_argument("-o", "--out", required=True, metavar="PNG")
    a.add_argument("--dynamic", action="store_true", help="final poses of Brownian dynamics instead of statics")
    a.add_argument("--kT", type=float, default=1e-5)
    a.add_argument("--seed", type=int, default=0)
    a.add_argument("--dt", type=float, metavar="DT",
                   help="--dynamic: the integrator's step (t0; default mlc.robot.verify.ROBOT_DT = 0.8 with a drift "
                        "bound of ROBOT_DISP_ACC = 0.1 sigma: docs/robot.md 3.4)")
    a.add_argument("--json", metavar="JSON", help="also write the verification report here")
    a.set_defaults(func=run_shapes)
    b = rs.add_parser("fold", help="one fold by Brownian dynamics: GIF, PNG frames, GSD")
    b.add_argument("scene", metavar="ROBOT.yaml")
    b.add_argument("--row", required=True, metavar="BITS", help="input row (bits in input order)")
    b.add_argument("--time", type=float, default=30.0, help="simulated time (t0, default 30)")
    b.add_argument("--frames", type=int, default=40, help="frames (default 40)")
    b.add_argument("--kT", type=float, default=1e-5)
    b.add_argument("--seed", type=int, default=0)
    b.add_argument("--dt", type=float, metavar="DT",
                   help="the integrator's step (t0; default mlc.robot.verify.ROBOT_DT, the stiff scheme's for a "
                        "robot, shortened to divide the frame interval)")
    b.add_argument("--gif", metavar="GIF")
    b.add_argument("--png-dir", metavar="DIR", help="write the frames as DIR/frame_000.png ...")
    b.add_argument("--gsd", metavar="GSD", help="GSD trajectory of the whole robot (slab shapes)")
    b.set_defaults(func=run_fold)


def run_shapes(args) -> int:
    from mlc.io.outputs import Outputs
    from mlc.robot.draw import render_shapes
    from mlc.robot.verify import format_robot_report, verify_robot_dynamic, verify_robot_static
    from mlc.scene.io import load_scene

    from mlc.errors import MlcError

    if args.dt is not None:
        if not args.dynamic:
            raise MlcError("--dt needs --dynamic (it sets the Brownian-dynamics run)", "--dt",
                           "add --dynamic or leave --dt out")
        if not (args.dt > 0 and args.dt < float("inf")):
            raise MlcError(f"--dt must be a finite time > 0 (t0), got {args.dt}", "--dt", "e.g. --dt 0.2")
    outs = Outputs(inputs=[args.scene])
    png = outs.file(args.out, "-o", suffixes=(".png",), parents=True)
    js = outs.file(args.json, "--json", suffixes=(".json",), parents=True)
    outs.check()
    scene = load_scene(args.scene)
    if args.dynamic:
        rep = verify_robot_dynamic(scene, kT=args.kT, seeds=1, keep_poses=True, dt=args.dt, first_seed=args.seed)
        poses = {s: v for (s, seed), v in rep.poses.items()}
    else:
        from mlc.io.progress import Progress
        with Progress(f"mlc robot shapes: the equilibrium of each row of {scene.name}",
                      total=len(scene.states())) as bar:          # minutes on a robot of 2500 bodies
            rep = verify_robot_static(scene, keep_poses=True,
                                      progress=lambda done, total: (setattr(bar, "total", total), bar.update(done)))
        poses = rep.poses
    info = {r["state"]: r for r in rep.rows}
    data = render_shapes(scene, poses, info, f"{scene.name}: {rep.mode} ({'all rows fold correctly' if rep.ok else 'WRONG'})")
    with outs:
        png.write_bytes(data)
        if js is not None:
            js.write_text(json.dumps(rep.as_dict(), indent=1, default=float))
    print(format_robot_report(rep))
    print(f"wrote {', '.join(outs.written)}")
    return 0 if rep.ok else 1


def run_fold(args) -> int:
    from mlc.errors import MlcError
    from mlc.io.outputs import Outputs
    from mlc.robot.draw import gif_bytes, render_frames
    from mlc.robot.verify import ROBOT_DISP_ACC, ROBOT_DT, _shape_row, robot_meta
    from mlc.scene.io import load_scene
    from mlc.sim.drive import Drive
    from mlc.sim.integrator import SimOptions, Simulation
    from mlc.sim.output import write_gsd

    if not args.time > 0:
        raise MlcError(f"--time must be > 0, got {args.time}", "--time")
    if args.dt is not None and not (args.dt > 0 and args.dt < float("inf")):
        raise MlcError(f"--dt must be a finite time > 0 (t0), got {args.dt}", "--dt", "e.g. --dt 0.05")
    if args.frames < 2:
        raise MlcError(f"need at least 2 frames, got {args.frames}", "--frames")
    outs = Outputs(inputs=[args.scene])
    gif = outs.file(args.gif, "--gif", suffixes=(".gif",), parents=True)
    gsd = outs.file(args.gsd, "--gsd", suffixes=(".gsd",), parents=True)
    pdir = outs.directory(args.png_dir, "--png-dir") if args.png_dir else None
    outs.check()
    scene = load_scene(args.scene)
    rm = robot_meta(scene)
    if args.row not in scene.states():
        raise MlcError(f"row {args.row!r} is not an input state (inputs {scene.inputs})", "--row")
    drives = {n: Drive.constant(int(b)) for n, b in zip(scene.inputs, args.row)}
    # default step: the verifier's, shortened to divide the frame interval (a frame ends a step)
    gap = args.time / (args.frames - 1)
    dt = gap / math.ceil(gap / ROBOT_DT - 1e-9) if args.dt is None else args.dt
    # the stiff scheme, not the verifier's implicit one: a fold's path and timing are what this shows, and
    # the implicit scheme reaches the same end later (docs/robot.md 3.4, "Session 48")
    sim = Simulation(scene, drives, SimOptions(scheme="stiff", kT=args.kT, seed=args.seed, dt=dt,
                                               disp_acc=ROBOT_DISP_ACC))
    res = sim.run(args.time, frames=args.frames)         # a progress bar on a terminal
    if res.interrupted:          # Ctrl-C: a fold cut short is not the row's shape; nothing is written
        raise KeyboardInterrupt
    shape = _shape_row(scene, rm, args.row, res.frame_pos[-1], res.frame_quat[-1])
    title = f"{scene.name} row {args.row}"
    with outs:
        if gif is not None or pdir is not None:
            from mlc.io.progress import Progress
            with Progress("mlc robot fold: drawing the frames", total=len(res.frame_times)) as bar:
                pngs = render_frames(scene, res.frame_pos, res.frame_quat, res.frame_times, title,
                                     shape["cells_expected"], progress=bar.update)
            if gif is not None:
                gif.write_bytes(gif_bytes(pngs))
            if pdir is not None:
                for k, b in enumerate(pngs):
                    pdir.write_bytes(f"frame_{k:03d}.png", b)
        if gsd is not None:
            write_gsd(gsd.tmp, scene, res.frame_times, res.frame_pos, res.frame_quat)
    print(f"row {args.row}: after {args.time:g} t0 the skeleton reads {shape['shape_read']} (expected "
          f"{shape['shape_expected']}), turns {shape['turns_read']} deg, largest DOF error "
          f"{shape['max_dof_error_deg']:.2f} deg")
    shown = [w for w in outs.written if not (pdir is not None and w.startswith(str(args.png_dir)))]
    if pdir is not None:
        shown.append(f"{args.png_dir}/frame_*.png ({args.frames} frames)")
    print(f"wrote {', '.join(shown)}")
    return 0                 # a picture, not a check: mlc verify --dynamic is the check
