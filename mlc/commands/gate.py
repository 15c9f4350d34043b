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
                                   "probe; then test the slabs for interpenetration over the input states and the "
                                   "half-way poses between them (oriented boxes, hinge contact within 0.05 sigma of "
                                   "a shared joint left out) and report the smallest clearance. Exit 1 on any wrong "
                                   "bit or interpenetration. Lengths in sigma.")
    c.add_argument("name", help="gate name, or 'all'")
    c.add_argument("--signal", choices=("expand", "contract", "both"), default="both")
    c.add_argument("--json", action="store_true")
    c.add_argument("--dynamic", action="store_true", help="verify by Brownian dynamics instead of statics")
    c.add_argument("--kT", type=float, default=1e-5,
                   help="thermal energy for --dynamic and the --branches risk (k0 sigma^2)")
    c.add_argument("--seeds", type=int, default=4, help="number of seeds for --dynamic")
    c.add_argument("--branches", action="store_true",
                   help="also estimate the energy barrier to each lever's other assembly branch in every state "
                        "(slow: about a minute per gate and convention) and the thermal escape risk at --kT")
    c.add_argument("--grid", type=int, default=3,
                   help="muscle-stroke lattice per input for the overlap sweep (3: states and half-way poses)")
    c.set_defaults(func=run_check)


def run_gate(args) -> int:
    from mlc.gates.library import gate_scene
    from mlc.io.outputs import Outputs
    from mlc.scene.io import dump_scene
    if args.output is None:
        sys.stdout.write(dump_scene(gate_scene(args.name, args.signal)))
        return 0
    outs = Outputs()
    out = outs.file(args.output, "-o", suffixes=(".yaml", ".yml"))
    with outs:              # the location is checked before the scene is built
        out.write_text(dump_scene(gate_scene(args.name, args.signal)))
    print(f"wrote {args.output}")
    return 0


def _selection(args):
    from mlc.gates.library import GATE_NAMES, get_gate
    names = list(GATE_NAMES) if args.name.lower() == "all" else [get_gate(args.name).name]
    signals = ["expand", "contract"] if args.signal == "both" else [args.signal]
    return names, signals


RISK_KT = 20.0     # a fold barrier below this many kT is reported as a risk
MAX_GRID = 100          # overlap sweep points per input (10^4 poses per gate and convention)
SECONDS_PER_POSE = 0.05  # one pose of the overlap sweep (NAND, --grid 10: 100 poses in 5 s)
MAX_SEEDS = 1000        # --dynamic seeds per state
SECONDS_PER_RUN = 0.1   # one seed of one state by Brownian dynamics (NAND, 8 seeds: 2 s)


def _duration(sec: float) -> str:
    if sec < 120:
        return f"{sec:.0f} s"
    if sec < 7200:
        return f"{sec / 60:.0f} min"
    if sec < 2 * 86400:
        return f"{sec / 3600:.1f} h"
    return f"{sec / 86400:.3g} days"


def _branch_risk(scene, name, signal, kT) -> dict:
    """Lowest barrier (k0 sigma^2) to fold a lever side (a, b, out output sides) to its
    other assembly branch over the input states (mlc.verify.branches.fold_barrier), and
    the Arrhenius escape rate exp(-barrier/kT) per t0 (attempt rate of order 1 per t0:
    overdamped Kramers sqrt(k_well k_saddle)/(2 pi gamma) with stiffnesses ~ sigma_min^2 k0
    ~ 0.01 k0, i.e. ~1.6e-3 per gamma/k0 = 1.6 per t0)."""
    import math

    from mlc.verify.branches import fold_barrier
    from mlc.verify.static import equilibrium
    best = None
    for state in scene.states():
        eq = equilibrium(scene, state)
        for ind in ("a.out", "b.out", "out.out"):
            fb = fold_barrier(scene, state, ind, eq.pos, eq.quat, steps=6)
            if best is None or fb.peak < best[0]:
                best = (fb.peak, ind, state)
    ratio = best[0] / kT
    rate = math.exp(-ratio)
    return {"gate": name, "signal": signal, "barrier": best[0], "indicator": best[1], "state": best[2],
            "kT": kT, "barrier_kT": ratio, "rate_per_t0": rate, "risk": ratio < RISK_KT}


def run_check(args) -> int:
    names, signals = _selection(args)
    clear, branch_rows = [], []
    if args.branches and args.dynamic:
        from mlc.errors import MlcError
        raise MlcError("--branches is part of the static check", "--branches", "drop --dynamic")
    if args.branches and not (args.kT > 0 and args.kT != float("inf")):
        from mlc.errors import MlcError
        raise MlcError(f"the branch risk needs a finite kT > 0, got {args.kT}", "--kT", "e.g. --kT 1e-5")
    if args.dynamic:
        from mlc.errors import MlcError
        if args.seeds < 1:
            raise MlcError(f"need at least one seed, got {args.seeds}", "--seeds")
        if args.seeds > MAX_SEEDS:
            est = args.seeds * 4 * len(names) * len(signals) * SECONDS_PER_RUN
            raise MlcError(f"{args.seeds} seeds would take about {_duration(est)} "
                           f"({SECONDS_PER_RUN:g} s per seed and state)", "--seeds",
                           f"use at most {MAX_SEEDS} seeds")
        if not args.kT >= 0:
            raise MlcError(f"kT must be >= 0, got {args.kT}", "--kT")
        from mlc.io.progress import Progress
        from mlc.io.warmup import notice
        from mlc.sim.dynamic import check_gates_dynamic
        if not args.json:
            notice("stiff")
        # one gate and convention at a time, so the bar has an ETA; the rows are printed once, below
        pairs = [(n, s) for n in names for s in signals]
        rows = []
        with Progress("mlc check-gate --dynamic", total=len(pairs)) as bar:
            for k, (n, s) in enumerate(pairs):
                rows += check_gates_dynamic([n], [s], kT=args.kT, seeds=args.seeds, quiet=True)
                bar.update(k + 1)
        mode = "dynamic"
    else:
        from mlc.errors import MlcError
        if args.grid < 2:
            raise MlcError(f"the overlap sweep needs at least 2 points per input, got {args.grid}", "--grid")
        if args.grid > MAX_GRID:
            poses = float(args.grid) ** 2 * len(names) * len(signals)
            raise MlcError(f"--grid {args.grid} is {poses:.3g} poses (every library gate has 2 inputs), about "
                           f"{_duration(poses * SECONDS_PER_POSE)} at {SECONDS_PER_POSE:g} s a pose", "--grid",
                           f"use at most {MAX_GRID} (3: the states and the half-way poses)")
        from mlc.gates.library import gate_scene
        from mlc.verify.overlap import sweep_clearance
        from mlc.verify.static import verify_scene
        from mlc.io.progress import Progress
        rows = []
        with Progress("mlc check-gate", total=len(names) * len(signals)) as bar:
            for name in names:
                for signal in signals:
                    bar.update(len(clear))
                    scene = gate_scene(name, signal)
                    worst, frac, poses = sweep_clearance(scene, grid=args.grid)
                    at_state = {"".join(str(int(v)) for v in f): rep for f, rep in poses
                                if all(v in (0.0, 1.0) for v in f)}
                    for r in verify_scene(scene):
                        rep = at_state[r["state"]]
                        rows.append({"gate": name, "signal": signal, **r, "clearance": rep.min_clearance,
                                     "ok": bool(r["ok"] and rep.ok())})
                    if args.branches:
                        branch_rows.append(_branch_risk(scene, name, signal, args.kT))
                    clear.append({"gate": name, "signal": signal, "min_clearance": worst.min_clearance,
                                  "pair": list(worst.pair), "strokes": list(frac), "poses": len(poses),
                                  "overlaps": [[a, b, d] for a, b, d in worst.overlaps], "ok": worst.ok()})
        mode = "static"
    ok = all(r["ok"] for r in rows) and all(c["ok"] for c in clear)
    if args.json:
        out = {"mode": mode, "ok": ok, "rows": rows}
        if clear:
            out["clearance"] = clear
        if branch_rows:
            out["branches"] = branch_rows
        print(json.dumps(out))
    else:
        cl = " clearance" if clear else ""
        rx = "  relax (t0)" if mode == "dynamic" else ""
        print(f"{'gate':8s} {'signal':8s} state exp  measured  margin    stretch{cl}{rx}   ok")
        for r in rows:
            st = r.get("joint_stretch")
            c = f"  {r['clearance']:+8.4f}" if "clearance" in r else ""
            if mode == "dynamic":
                c += f"  {'not relaxed' if r.get('relax_time') is None else format(r['relax_time'], '.2f'):>10s}"
            print(f"{r['gate']:8s} {r['signal']:8s} {r['state']:5s}  {r['expected']}  {r['measured']:8.5f}  "
                  f"{r['margin']:+.4f}  {'-' if st is None else format(st, '.1e'):>8s}{c}  {'ok' if r['ok'] else 'WRONG'}")
        bad = sum(not r["ok"] for r in rows)
        print(f"{mode} check: {len(rows) - bad} of {len(rows)} gate states correct")
        if clear:
            w = min(clear, key=lambda c: c["min_clearance"])
            nbad = sum(not c["ok"] for c in clear)
            print(f"slab overlap: smallest clearance {w['min_clearance']:+.4f} sigma ({w['pair'][0]}/{w['pair'][1]}, "
                  f"{w['gate']} {w['signal']}, strokes {tuple(w['strokes'])}) over {sum(c['poses'] for c in clear)} "
                  f"poses; {'no interpenetration' if not nbad else f'{nbad} gate(s) INTERPENETRATE'}")
            for c in clear:
                for a, b, d in c["overlaps"]:
                    print(f"  {c['gate']} {c['signal']}: {a} and {b} interpenetrate {d:.4f} sigma deep "
                          f"at strokes {tuple(c['strokes'])}")
        for b in branch_rows:
            print(f"branches: {b['gate']} {b['signal']}: lowest fold barrier {b['barrier']:.4f} k0 sigma^2 "
                  f"({b['indicator']}, state {b['state']}) = {b['barrier_kT']:.1f} kT at kT = {b['kT']:g}; "
                  f"escape rate ~ {b['rate_per_t0']:.1e} per t0{'  RISK' if b['risk'] else ''}")
    return 0 if ok else 1
