"""``mlc lever``: solve a scissor lever (paper Eq. 2, half-length form)."""
from __future__ import annotations

import json


def register(sub):
    p = sub.add_parser("lever", help="solve a scissor lever (Eq. 2)",
                       description="Solve theta1, theta2, l1, l2 and dtheta of an open-hinge (inverting) or "
                                   "crossed-hinge (direction-keeping) lever. Lengths in sigma, angles in rad.")
    p.add_argument("--lin", type=float, required=True, help="input rest length")
    p.add_argument("--lout", type=float, required=True, help="output rest length")
    p.add_argument("--dlin", type=float, required=True, help="input signal (+ expansion, - contraction)")
    p.add_argument("--dlout", type=float, required=True, help="output signal")
    p.add_argument("--l", type=float, required=True, help="horizontal length of the lever at rest")
    p.add_argument("--type", choices=("open", "crossed"), help="lever type (default: the one the signs need)")
    p.add_argument("--json", action="store_true")
    p.set_defaults(func=run)


def run(args) -> int:
    import numpy as np

    from mlc.geometry.lever import solve_lever
    with np.errstate(all="ignore"):     # lengths near 1e308 overflow: reported as "no lever", not as warnings
        sol = solve_lever(args.lin, args.lout, args.dlin, args.dlout, args.l, args.type)
    d = sol.to_dict()
    d["residual"] = float(abs(sol.residuals()).max())
    if args.json:
        print(json.dumps(d))
    else:
        print(f"{sol.type}-hinge lever: {sol.lin} -> {sol.lin + sol.dlin} in, {sol.lout} -> {sol.lout + sol.dlout} out")
        for k in ("theta1", "theta2", "dtheta"):
            print(f"  {k:6s} = {d[k]:.6f} rad")
        print(f"  l1     = {sol.l1:.6f} sigma\n  l2     = {sol.l2:.6f} sigma\n  residual = {d['residual']:.1e}")
    return 0
