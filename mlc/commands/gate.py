"""``mlc gate``, ``mlc check-gate``: library gate scenes and their verification."""
from __future__ import annotations

import json
import sys


def register(sub):
    p = sub.add_parser("gate", help="write a library gate's scene (YAML)")
    p.add_argument("name", help="library gate name (AND, NAND, OR, NOR, NIMPLY, CNIMPLY, IMPLY, CIMPLY)")
    p.add_argument("--signal", choices=("expand", "contract"), default="expand", help="muscle convention")
    p.add_argument("-o", "--output", metavar="YAML", help="scene file to write (default: print)")
    p.set_defaults(func=run_gate)

    c = sub.add_parser("check-gate", help="verify library gates (static equilibrium, or --dynamic Brownian dynamics)",
                       description="For every input state find the mechanical equilibrium and read the output "
                                   "probe; exit 1 on any wrong bit. Lengths in sigma.")
    c.add_argument("name", help="gate name, or 'all'")
    c.add_argument("--signal", choices=("expand", "contract", "both"), default="both")
    c.add_argument("--json", action="store_true")
    c.add_argument("--dynamic", action="store_true", help="verify by Brownian dynamics instead of statics")
    c.add_argument("--kT", type=float, default=1e-5, help="thermal energy for --dynamic (k0 sigma^2)")
    c.add_argument("--seeds", type=int, default=4, help="number of seeds for --dynamic")
    c.set_defaults(func=run_check)


def run_gate(args) -> int:
    from mlc.gates.library import gate_scene
    from mlc.scene.io import dump_scene, write_scene
    scene = gate_scene(args.name, args.signal)
    if args.output:
        write_scene(scene, args.output)
        print(f"wrote {args.output}")
    else:
        sys.stdout.write(dump_scene(scene))
    return 0


def _selection(args):
    from mlc.gates.library import GATE_NAMES, get_gate
    names = list(GATE_NAMES) if args.name.lower() == "all" else [get_gate(args.name).name]
    signals = ["expand", "contract"] if args.signal == "both" else [args.signal]
    return names, signals


def run_check(args) -> int:
    names, signals = _selection(args)
    if args.dynamic:
        from mlc.errors import MlcError
        if args.seeds < 1:
            raise MlcError(f"need at least one seed, got {args.seeds}", "--seeds")
        if not args.kT >= 0:
            raise MlcError(f"kT must be >= 0, got {args.kT}", "--kT")
        from mlc.sim.dynamic import check_gates_dynamic
        rows = check_gates_dynamic(names, signals, kT=args.kT, seeds=args.seeds, quiet=args.json)
        mode = "dynamic"
    else:
        from mlc.gates.library import gate_scene
        from mlc.verify.static import verify_scene
        rows = []
        for name in names:
            for signal in signals:
                for r in verify_scene(gate_scene(name, signal)):
                    rows.append({"gate": name, "signal": signal, **r})
        mode = "static"
    ok = all(r["ok"] for r in rows)
    if args.json:
        print(json.dumps({"mode": mode, "ok": ok, "rows": rows}))
    else:
        print(f"{'gate':8s} {'signal':8s} state exp  measured  margin    stretch   ok")
        for r in rows:
            st = r.get("joint_stretch")
            print(f"{r['gate']:8s} {r['signal']:8s} {r['state']:5s}  {r['expected']}  {r['measured']:8.5f}  "
                  f"{r['margin']:+.4f}  {'-' if st is None else format(st, '.1e'):>8s}  {'ok' if r['ok'] else 'WRONG'}")
        bad = sum(not r["ok"] for r in rows)
        print(f"{mode} check: {len(rows) - bad} of {len(rows)} gate states correct")
    return 0 if ok else 1
