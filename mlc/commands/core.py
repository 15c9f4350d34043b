"""``mlc core``: solve the logic core (paper Eq. 1) or plot its design space (Fig. 1B)."""
from __future__ import annotations

import json


def register(sub):
    p = sub.add_parser("core", help="solve the logic core (Eq. 1) or plot its design space (Fig. 1B)",
                       description="Solve x, phi, dout and the internal angles of the logic core from "
                                   "din and h (lengths in sigma), or plot dout vs din (Fig. 1B).")
    p.add_argument("--din", type=float, default=0.5, help="core input signal din/sigma (default 0.5)")
    p.add_argument("--h", type=float, default=2.0, help="core height h/sigma (default 2)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.add_argument("--plot", metavar="PNG", help="write the Fig. 1B design-space plot to PNG")
    p.add_argument("--data", metavar="JSON", help="write the Fig. 1B design space as JSON data")
    p.set_defaults(func=run)


def run(args) -> int:
    from mlc.geometry.core import design_space, solve_core
    if args.plot is not None or args.data is not None:
        from mlc.io.outputs import Outputs
        from mlc.io.progress import Progress
        outs = Outputs()
        plot = outs.file(args.plot, "--plot", suffixes=(".png",))
        data = outs.file(args.data, "--data", suffixes=(".json",))
        with outs:                       # every output checked before the ~30 s of work
            if plot:
                solve_core(args.din, args.h)          # the marker must exist: fail before the work
            # about 30 s on the reference machine (29 accessible-range scans of 151 core solves)
            with Progress("mlc core: computing the Fig. 1B design space", total=1) as bar:
                def step(done, total):
                    bar.total = total
                    bar.update(done)
                space = design_space(progress=step)
            if data:
                data.write_text(json.dumps({
                    "units": "sigma", "curves": {str(h): pts for h, pts in space["curves"].items()},
                    "boundary": [{"h": h, "din_max": d, "dout": o} for h, d, o in space["boundary"]]}, indent=1))
            if plot:
                from mlc.draw import plot_design_space
                plot_design_space(space, plot.tmp, marker=(args.din, args.h))
        if not args.json:
            for f in outs.written:
                print(f"wrote {f}")
            return 0
    sol = solve_core(args.din, args.h)
    d = sol.to_dict()
    d["residual"] = float(abs(sol.residuals()).max())
    if args.json:
        print(json.dumps(d))
    else:
        print(f"logic core at din = {sol.din} sigma, h = {sol.h} sigma:")
        print(f"  x    = {sol.x:.6f} sigma   (slab cd)")
        print(f"  phi  = {sol.phi:.6f} rad   ({sol.phi * 57.29577951308232:.3f} deg; |ab| = {sol.ab:.6f} sigma)")
        print(f"  dout = {sol.dout:.6f} sigma")
        print(f"  gamma1, gamma2, gamma3, zeta = {sol.gamma1:.6f}, {sol.gamma2:.6f}, {sol.gamma3:.6f}, "
              f"{sol.zeta:.6f} rad")
        print(f"  Eq. 1 residual = {d['residual']:.1e}")
    return 0
