"""Circuit back end: cost against circuit size, and dynamic verification per scheme.

* Ripple-carry adders of growing width (1 to 7 bits, 7 gates per full-adder bit; a scene
  lists every row of its truth table, so at most 14 inputs) and array multipliers (6 x 6
  would be 222 gates on 12 inputs; from 4 x 4 on, a wire is longer than any chain the
  router closes, the build refuses them, and the results record the refusal): netlist gates, scene
  bodies, build time (placement + routing + assembly), static verification time of one
  row (the all-ones row: every muscle moves), the smallest slab clearance and whether
  every probe read right.  Goals (issue 9): build of 200 gates under 2 s, static
  verification of one row of a 200-gate circuit under 10 s, build cost no worse than
  linear in bodies.
* NAND meshes of width 7 and growing depth (``--meshes``; ``mlc.logic.library.nand_mesh``,
  compiled at -O0 so that it keeps 7 gates a level; depth 29 is 203 gates on 14 inputs):
  every wire runs one level up and one column across, so unlike the adders and multipliers
  the family reaches 200 gates within the router's reach and the scene's 14 inputs.
* The full adder verified by Brownian dynamics on one row with each scheme: the cost of a
  t0 measured over a short run, times the row's floor (``dynamic_per_scheme``; Euler's row
  is ~2.5e8 steps, so it is never run whole).

    python benchmarks/circuit_scaling.py [--widths 1 2 3] [--skip-dynamic]   (adders; keeps the multipliers)
    python benchmarks/circuit_scaling.py --multipliers 2 3 4 5 6     (merged into the JSON point by point)
    python benchmarks/circuit_scaling.py --meshes 1 2 4 8 16 29      (the same)
    python benchmarks/circuit_scaling.py --meshes 29 --verify-budget 1800   (the build saved first;
                                                    a check stopped at 1800 s is a lower bound)
    python benchmarks/circuit_scaling.py --meshes 29 --save-scenes S    (and the scene, to S/mesh_29.yaml)
    python benchmarks/circuit_scaling.py --meshes 29 --check-saved S    (no build: the check again)
    python benchmarks/circuit_scaling.py --dynamic-only     (the per-scheme part alone)
    python benchmarks/circuit_scaling.py --refit            (fit and goals from the JSON)

Writes benchmarks/results/circuit_scaling.json and .png.  Times are wall seconds on this
machine in one run; compare ratios, not absolute numbers across machines.  ``build_cpu_s``
is the build's CPU time (process_time) and ``load`` the 1-minute load average when the
build started: on a shared machine wall time is CPU time over the share of a core the
process gets.  ``route_solves``/``route_repeats``: chains solved / served by the router's
cache (build_circuit's second build repeats some of the first's solves).  A point whose
check records ``polish: auto`` ran it as ``mlc verify`` does since session 29: the
equilibrium polished only where its minimisation stalled (benchmarks/static_polish.py); the
points without the field ran it with the polish always.
"""
from __future__ import annotations

import argparse
import json
import math
import os
import platform
import signal
import time
from pathlib import Path

import mlc  # noqa: F401 -- before numpy: pins OpenBLAS's kernels (mlc/__init__.py)
import numpy as np

from gitstate import commit
from mlc.circuit.build import CircuitOptions, build_circuit
from mlc.errors import MlcError
from mlc.io.atomic import atomic_path
from mlc.logic.library import array_multiplier, nand_mesh, ripple_adder
from mlc.pipeline import compile_spec
from mlc.verify.circuit import verify_static

OUT = Path(__file__).resolve().parent / "results"
MESH_WIDTH = 7        # nand_mesh's width: 14 inputs, 7 gates a level (depth 29: 203 gates)


def scene_path(folder: Path, family: str, w: int) -> Path:
    """Where ``--save-scenes`` writes a point's scene and ``--check-saved`` reads it."""
    return Path(folder) / f"{family}_{w}.yaml"


def scene_digest(text: str) -> str:
    """A saved scene's ``scene_sha``: the sha256 prefix of its text (``dump_scene``)."""
    import hashlib
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def save_scene(sc, path: Path) -> str:
    """Write ``sc`` to ``path``; returns :func:`scene_digest` of the text written."""
    from mlc.scene.io import dump_scene
    text = dump_scene(sc)
    with atomic_path(path) as tmp:
        Path(tmp).write_text(text)
    return scene_digest(text)


def adder_point(w: int, family: str = "adder", on_built=None, verify_budget: float | None = None,
                save_to: Path | None = None, jobs: int = 1, router: str = "ik") -> dict:
    """One circuit of the series: the ``w``-bit ripple-carry adder, or (``family`` "multiplier")
    the ``w`` x ``w`` array multiplier (2w inputs: 6 bits are 222 gates on 12 inputs), or
    (``family`` "mesh") ``nand_mesh(MESH_WIDTH, w)``, compiled at -O0 (depth 29: 203 gates).  The
    refusal of netlists whose build estimate passes an hour (``MAX_GATES``) is lifted here:
    measuring beyond it is the point.  A multiplier the build refuses (from 4 x 4 on, a wire
    longer than any chain) is returned as a record of the refusal: inputs, gates, ``refused``.

    ``on_built(point)`` is called with the point as built, before its static check (its
    ``verify_row_s`` None), so that a long series keeps the build it measured.  A static check
    that passes ``verify_budget`` seconds of wall time is stopped (SIGALRM, between two Python
    steps of the minimiser) and recorded as ``verify_stopped_after_s``, ``verify_row_s`` None.
    ``save_to`` (a folder): the scene is written there before the check (:func:`scene_path`;
    ``scene_sha`` in the point), so that a check stopped at its budget can be run again
    without the build (``--check-saved``).  ``router``: the chains' solver
    (``CircuitOptions.router``; "ik" for the series committed before the fast router)."""
    if family == "mesh":            # structure kept: -O2 would merge what repeats
        spec, level = nand_mesh(MESH_WIDTH, w), 0
    else:
        spec, level = (ripple_adder(w) if family == "adder" else array_multiplier(w)), 2
    c = compile_spec(spec, level, "expand")
    from mlc.circuit import route
    hits0 = list(route.CACHE_HITS)
    load0 = os.getloadavg()[0]
    t0, c0 = time.perf_counter(), time.process_time()
    try:
        circ = build_circuit(c.netlist, spec, CircuitOptions(max_gates=len(c.netlist.gates), jobs=jobs,
                                                             router=router))
    except MlcError as e:
        if family == "adder":
            raise
        return {"family": family, "width": w, "inputs": len(spec.inputs), "gates": len(c.netlist.gates),
                "refused": str(e)}
    t_build, c_build = time.perf_counter() - t0, time.process_time() - c0
    sc = circ.scene
    row = "1" * len(sc.inputs)
    point = {"family": family, "width": w, "gates": len(c.netlist.gates), "bodies": len(sc.bodies), "chains": circ.chains,
            "half_units": circ.half_units, "build_s": t_build, "build_cpu_s": c_build, "load": load0, "jobs": jobs,
            "router": router, "commit": commit(),
            "route_solves": route.CACHE_HITS[1] - hits0[1], "route_repeats": route.CACHE_HITS[0] - hits0[0],
            "tight_chains": sc.meta["connector"]["tight_chains"], "build_parts_s": circ.seconds,
            "state_contacts": sc.meta["connector"].get("state_contacts", []),
            "rerouted_contacts": sc.meta["connector"].get("rerouted_contacts", []),
            "contact_min": min((k.clearance for k in circ.contacts), default=None),
            "verify_row_s": None, "row": row}
    if save_to is not None:
        point["scene_sha"] = save_scene(sc, scene_path(save_to, family, w))
    if on_built is not None:
        on_built(dict(point))
    del circ
    return check_point(point, sc, verify_budget)


def check_point(point: dict, sc, verify_budget: float | None = None) -> dict:
    """``point`` with the static check of its row on scene ``sc`` (see :func:`adder_point`)."""
    row = point["row"]
    point.pop("verify_stopped_after_s", None)

    def stop(signum, frame):
        raise TimeoutError
    old = signal.signal(signal.SIGALRM, stop) if verify_budget else None
    t0 = time.perf_counter()
    try:
        if verify_budget:
            signal.setitimer(signal.ITIMER_REAL, verify_budget)
        rep = verify_static(sc, rows=[row])
    except TimeoutError:
        point["verify_stopped_after_s"] = time.perf_counter() - t0
        return point
    finally:
        if verify_budget:
            signal.setitimer(signal.ITIMER_REAL, 0)
            signal.signal(signal.SIGALRM, old)
    r = rep.rows[0]
    point.update({"verify_row_s": r["seconds"], "ok": rep.ok, "clearance": r.get("clearance"),
                  "joint_stretch": r["joint_stretch"], "muscle_strain": r["muscle_strain"],
                  "iterations": r["iterations"], "polish": "auto",
                  "outputs": {e["output"]: e["measured"] for e in rep.entries},
                  "failures": [{k: e[k] for k in ("output", "expected", "bit", "measured", "margin", "error")}
                               for e in rep.failures()]})
    return point


def checked_saved(point: dict | None, folder: Path, family: str, w: int, verify_budget: float | None) -> dict:
    """The committed ``point`` with its static check run again on the scene saved for it."""
    from mlc.scene.io import dump_scene, load_scene
    path = scene_path(folder, family, w)
    if point is None or "scene_sha" not in point:
        raise SystemExit(f"{family} {w}: no committed point with a saved scene (build it with --save-scenes)")
    if not path.is_file():
        raise SystemExit(f"{path}: no such scene (build it with --save-scenes {folder})")
    t0 = time.perf_counter()
    sc = load_scene(path)
    t1 = time.perf_counter()
    if scene_digest(dump_scene(sc)) != point["scene_sha"]:
        raise SystemExit(f"{path} is not the scene of the committed {family} {w} point (scene_sha differs)")
    point = dict(point, scene_load_s=t1 - t0, scene_dump_s=time.perf_counter() - t1)
    return check_point(point, sc, verify_budget)


def fit_and_goals(points: list[dict]):
    """(fit, goals, extrapolated): power-law exponents of build CPU/wall time and one row's
    static check against bodies, and of bodies against gates; the goals (None when no point
    has 200 gates); and, when no point reaches 200 gates, the power laws carried to 200
    gates (bodies, build CPU s, one row's check s, and each time over its goal).  A straight
    line in log-log through a few small adders: an order of magnitude, not a prediction.
    No points (a series that starts with another family): no fit, no goals."""
    if not points:
        return {}, {"build_200_gates_under_2s": None, "verify_row_200_gates_under_10s": None}, None
    g = np.array([p["gates"] for p in points], float)
    b = np.array([p["bodies"] for p in points], float)
    tb = np.array([p["build_s"] for p in points])
    cb = np.array([p["build_cpu_s"] for p in points])
    checked = [p for p in points if p.get("verify_row_s") is not None]
    bv = np.array([p["bodies"] for p in checked], float)
    tv = np.array([p["verify_row_s"] for p in checked])
    fit, extra = {}, None
    if len(points) >= 3:
        fit["build_exponent_in_bodies"] = float(np.polyfit(np.log(b), np.log(tb), 1)[0])
        fit["build_cpu_exponent_in_bodies"] = float(np.polyfit(np.log(b), np.log(cb), 1)[0])
        if len(checked) >= 3:
            fit["verify_exponent_in_bodies"] = float(np.polyfit(np.log(bv), np.log(tv), 1)[0])
        fit["bodies_exponent_in_gates"] = float(np.polyfit(np.log(g), np.log(b), 1)[0])
    biggest = max(points, key=lambda p: p["gates"])
    goals = {"build_200_gates_under_2s": None, "verify_row_200_gates_under_10s": None}
    if biggest["gates"] >= 200:
        goals = {"build_200_gates_under_2s": biggest["build_s"] < 2.0,
                 "verify_row_200_gates_under_10s": _verify_goal(biggest)}
    elif len(points) >= 3 and len(checked) >= 3:
        lb = np.polyval(np.polyfit(np.log(g), np.log(b), 1), math.log(200.0))
        build_cpu = float(np.exp(np.polyval(np.polyfit(np.log(b), np.log(cb), 1), lb)))
        verify = float(np.exp(np.polyval(np.polyfit(np.log(bv), np.log(tv), 1), lb)))
        extra = {"from_gates": [int(x) for x in g], "bodies": float(np.exp(lb)), "build_cpu_s": build_cpu,
                 "verify_row_s": verify, "build_over_goal": build_cpu / 2.0, "verify_over_goal": verify / 10.0}
    return fit, goals, extra


def dynamic_per_scheme(row: str = "111", probe_t0: float = 2.0, euler_steps: int = 2000) -> list[dict]:
    """The full adder (``mlc compile`` defaults: 100 k0 joints) verified by Brownian dynamics
    on one row with each scheme, as wall/CPU time a row.  A row runs at least its floor of
    3 signal times (t0; the verifier relaxes there as a rule: circuit_dynamic.json), so the
    cost of a row is the cost of a t0 times the floor: measured here over ``probe_t0`` t0
    (stiff) or ``euler_steps`` steps (Euler: a row is ~1e8 steps, days) after a warm-up,
    from rest into the row, kT = 1e-5, seed 0.  The stiff scheme's whole rows, measured
    by benchmarks/circuit_dynamic.py on the same build, are quoted beside the estimate
    (``measured_row_wall_s``, runs at the same dt) as its check."""
    from mlc.pipeline import build, load
    from mlc.sim.drive import Drive
    # the stiff scheme at DT_LARGE, the step mlc verify --dynamic takes on a circuit (0.2 t0;
    # DT, 0.01 t0, before session 23), Euler at its own half stability limit
    from mlc.sim.integrator import SimOptions, Simulation
    from mlc.verify.dynamic import DT, DT_LARGE, TAU_FACTOR, signal_time
    root = Path(__file__).resolve().parents[1]
    sc = build(compile_spec(load(str(root / "examples" / "full_adder.expr")))).circuit.scene
    rest = "0" * len(sc.inputs)
    floor = TAU_FACTOR * signal_time(sc, rest, row)
    drives = {i: Drive.constant(int(b)) for i, b in zip(sc.inputs, row)}
    measured = []
    for dyn_file in sorted(OUT.glob("circuit_dynamic*.json")):     # the same build's runs (by body count)
        d = json.loads(dyn_file.read_text())
        same = {k for k, v in d.get("scenes", {}).items() if v.get("bodies") == len(sc.bodies)}
        measured += [r["wall_s"] for r in d.get("runs", [])
                     if r["example"] == "full_adder.expr" and r.get("joint_k") == 100.0 and r["state"] == row
                     and r.get("scene") in same and r.get("dt") == DT_LARGE["stiff"]]
    out = []
    for scheme in ("stiff", "euler"):
        dt = DT_LARGE["stiff"] if scheme == "stiff" else DT.get(scheme)     # the steps mlc verify --dynamic takes
        sim = Simulation(sc, drives, SimOptions(scheme=scheme, kT=1e-5, seed=0, dt=dt))
        span = probe_t0 if scheme == "stiff" else euler_steps * sim.dt
        sim.run(span / 10, quiet=True)                       # warm-up: kernels compiled, caches hot
        t0, c0 = time.perf_counter(), time.process_time()
        sim.run(span, quiet=True)
        wall, cpu = time.perf_counter() - t0, time.process_time() - c0
        out.append({"scheme": scheme, "row": row, "bodies": len(sc.bodies), "dt_t0": sim.dt,
                    "probe_t0": span, "probe_wall_s": wall, "probe_cpu_s": cpu, "floor_t0": floor,
                    "steps_per_row": floor / sim.dt, "estimated_row_cpu_s": cpu / span * floor,
                    "estimated_row_wall_s": wall / span * floor,
                    "measured_row_wall_s": measured if scheme == "stiff" else [],
                    "load": os.getloadavg()[0]})
        print(json.dumps(out[-1]), flush=True)
    return out


def _verify_goal(p: dict):
    """One row's static check under 10 s: True or False when it finished, False when it was
    stopped after 10 s or more (``verify_stopped_after_s``), None when it never ran."""
    if p.get("verify_row_s") is not None:
        return p["verify_row_s"] < 10.0
    return False if p.get("verify_stopped_after_s", 0.0) >= 10.0 else None


def refit(res: dict) -> dict:
    """Fit (per family), goals and extrapolation of ``res`` from its built points.  The goals are
    read off the smallest circuit of 200 gates or more when one was built, else carried to 200
    gates from the adders' power laws (``extrapolated_200_gates``)."""
    fams = {"adder": res.get("adders", []), "multiplier": [p for p in res.get("multipliers", []) if "bodies" in p],
            "mesh": res.get("meshes", [])}
    res["fit"], res["goals"], res["extrapolated_200_gates"] = fit_and_goals(fams["adder"])
    res["fit_multipliers"] = fit_and_goals(fams["multiplier"])[0] if len(fams["multiplier"]) >= 3 else {}
    res["fit_meshes"] = fit_and_goals(fams["mesh"])[0] if len(fams["mesh"]) >= 3 else {}
    big = [p for p in fams["adder"] + fams["multiplier"] + fams["mesh"] if p["gates"] >= 200]
    if big:
        p = min(big, key=lambda p: p["gates"])
        size = f"depth {p['width']}" if p.get("family") == "mesh" else f"{p['width']} bits"
        res["goals"] = {"circuit": f"{p.get('family', 'adder')} {size}, {p['gates']} gates, "
                                   f"{p['bodies']} bodies",
                        "build_200_gates_under_2s": p["build_s"] < 2.0, "build_s": p["build_s"],
                        "build_over_goal": p["build_s"] / 2.0,
                        "verify_row_200_gates_under_10s": _verify_goal(p),
                        "verify_row_s": p["verify_row_s"],
                        "verify_over_goal": None if p["verify_row_s"] is None else p["verify_row_s"] / 10.0}
        if p.get("verify_stopped_after_s") is not None:
            res["goals"]["verify_stopped_after_s"] = p["verify_stopped_after_s"]
            res["goals"]["verify_over_goal_at_least"] = p["verify_stopped_after_s"] / 10.0
    return res


PNG = OUT / "circuit_scaling.png"


def plot(res: dict, png: Path = PNG, compare: dict | None = None) -> None:
    """Bodies against gates, and build and one row's check time against bodies; with
    ``compare`` (another series' results, the ik router's), its build times in grey."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(1, 2, figsize=(10, 4))
    for fam, key, col in (("ripple-carry adders", "adders", "C0"), ("array multipliers", "multipliers", "C2"),
                          (f"NAND meshes, width {MESH_WIDTH}", "meshes", "C3")):
        pts = [p for p in res.get(key, []) if "bodies" in p]
        if not pts:
            continue
        g = [p["gates"] for p in pts]
        b = [p["bodies"] for p in pts]
        ax[0].loglog(g, b, "o-", color=col, label=fam)
        ax[1].loglog(b, [p["build_s"] for p in pts], "o-", color=col, label=f"{fam}: build, wall")
        ax[1].loglog(b, [p["build_cpu_s"] for p in pts], "o--", color=col, alpha=0.5, label=f"{fam}: build, CPU")
        chk = [p for p in pts if p.get("verify_row_s") is not None]
        ax[1].loglog([p["bodies"] for p in chk], [p["verify_row_s"] for p in chk], "s:", color=col,
                     label=f"{fam}: static check, one row")
        for p in pts:
            if p.get("verify_stopped_after_s"):      # a lower bound: stopped, not finished
                ax[1].plot([p["bodies"]], [p["verify_stopped_after_s"]], "^", color=col, mfc="none")
        old = [p for p in (compare or {}).get(key, []) if "bodies" in p]
        if old:
            ax[1].loglog([p["bodies"] for p in old], [p["build_s"] for p in old], "o-", color="0.6", alpha=0.7,
                         label=f"{fam}: build, wall, ik router")
    ax[0].set_xlabel("gates")
    ax[0].set_ylabel("bodies in the scene")
    ax[0].legend(fontsize=8)
    ax[1].axhline(2.0, color="k", ls=":", lw=0.8)
    ax[1].axhline(10.0, color="k", ls="-.", lw=0.8)
    ax[1].set_xlabel("bodies")
    ax[1].set_ylabel("time (s)")
    ax[1].set_title("goals at 200 gates: build 2 s (dotted), one row 10 s (dash-dot)", fontsize=9)
    from matplotlib.ticker import NullFormatter
    for a in ax:
        a.xaxis.set_minor_formatter(NullFormatter())
        a.yaxis.set_minor_formatter(NullFormatter())
    ax[1].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(png, dpi=110)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--max-width", type=int, default=7)
    ap.add_argument("--widths", type=int, nargs="*",
                    help="measure these adder widths and merge them into the committed series (the other widths "
                         "are kept; with --skip-dynamic so is the dynamic part)")
    ap.add_argument("--multipliers", type=int, nargs="*",
                    help="measure these w x w array multipliers and merge them into the committed JSON "
                         "(the adders and the dynamic part are kept)")
    ap.add_argument("--meshes", type=int, nargs="*",
                    help=f"measure nand_mesh({MESH_WIDTH}, depth) for these depths (depth 29: 203 gates, short wires) "
                         "and merge them into the committed JSON (the adders and the dynamic part are kept)")
    ap.add_argument("--verify-budget", type=float, default=None,
                    help="s (wall): stop a point's static check after this long and record it as stopped "
                         "(--multipliers and --meshes; default: no limit)")
    ap.add_argument("--save-scenes", type=Path, metavar="DIR",
                    help="--multipliers, --meshes: write each point's scene to DIR before its check")
    ap.add_argument("--check-saved", type=Path, metavar="DIR",
                    help="--multipliers, --meshes: no build; run the static check of each point on the scene "
                         "--save-scenes wrote to DIR (it must be the one the point records, scene_sha)")
    ap.add_argument("--skip-dynamic", action="store_true")
    ap.add_argument("--budget", type=float, default=1800.0, help="stop growing after this many seconds")
    ap.add_argument("--jobs", type=int, default=1,
                    help="processes that route (mlc compile --jobs: the same scenes; build_cpu_s is then this "
                         "process's CPU only)")
    ap.add_argument("--dynamic-only", action="store_true",
                    help="only the full adder's per-scheme dynamic cost, into the committed JSON")
    ap.add_argument("--refit", action="store_true",
                    help="recompute fit, goals and extrapolation from the committed JSON's points; run nothing")
    ap.add_argument("--router", choices=("ik", "fast"), default="ik",
                    help="the chains' solver (CircuitOptions.router); with fast, write --json "
                         "circuit_scaling_fast.json (its plot beside it, the ik series' builds in grey)")
    ap.add_argument("--json", type=Path, default=OUT / "circuit_scaling.json",
                    help="results file read and written (another name lets two series run at once)")
    args = ap.parse_args()
    if args.router == "fast" and args.json == OUT / "circuit_scaling.json":     # never over the ik series
        args.json = OUT / "circuit_scaling_fast.json"
    if args.save_scenes is not None:              # before the build: an hour's build lost to a missing folder
        args.save_scenes.mkdir(parents=True, exist_ok=True)
    path = args.json
    old = json.loads(path.read_text()) if path.exists() else {}

    def save(res):
        refit(res)
        OUT.mkdir(exist_ok=True)
        with atomic_path(path) as tmp:
            tmp.write_text(json.dumps(res, indent=1))
        if path == OUT / "circuit_scaling.json":
            plot(res)
        elif args.router == "fast":
            ik = OUT / "circuit_scaling.json"
            plot(res, path.with_suffix(".png"), json.loads(ik.read_text()) if ik.exists() else None)
        print(json.dumps({k: res.get(k) for k in ("fit", "fit_multipliers", "goals", "extrapolated_200_gates")},
                         indent=1), flush=True)

    if args.refit or args.dynamic_only:
        if args.dynamic_only:
            old["dynamic_full_adder"] = dynamic_per_scheme()
        save(old)
        return
    for fam, key, sizes in (("multiplier", "multipliers", args.multipliers), ("mesh", "meshes", args.meshes)):
        if not sizes:
            continue
        pts = {p["width"]: p for p in old.get(key, [])}
        def built(p):                                   # the build kept before the (long) static check
            pts[p["width"]] = p
            old[key] = [pts[k] for k in sorted(pts)]
            save(old)

        for w in sizes:
            if args.check_saved:
                p = checked_saved(pts.get(w), args.check_saved, fam, w, args.verify_budget)
            else:                                        # a refusal: its reason
                p = adder_point(w, fam, on_built=built, verify_budget=args.verify_budget, save_to=args.save_scenes,
                                jobs=args.jobs, router=args.router)
            pts[w] = p
            print(json.dumps({k: (round(v, 3) if isinstance(v, float) else v) for k, v in p.items()
                              if k != "build_parts_s"}), flush=True)
            old[key] = [pts[k] for k in sorted(pts)]
            save(old)                                    # after every point: a long series keeps what it measured
    if args.multipliers or args.meshes:
        return
    widths = args.widths or [w for w in range(1, 8) if w <= args.max_width]
    points = []
    t_all = time.perf_counter()
    for w in widths:
        p = adder_point(w, jobs=args.jobs, router=args.router)
        points.append(p)
        if args.router == "fast":           # a long series keeps what it measured (the meshes kept)
            save(dict(old, adders=list(points) if not args.widths else
                      [q for q in old.get("adders", []) if q["width"] not in {x["width"] for x in points}] + points))
        print(json.dumps({k: (round(v, 3) if isinstance(v, float) else v) for k, v in p.items()
                          if k != "build_parts_s"}), flush=True)
        if time.perf_counter() - t_all > args.budget:
            print(f"budget of {args.budget} s reached; stopping at width {w}")
            break
    if args.widths:         # merged into the committed series: the other widths are kept
        keep = {p["width"]: p for p in old.get("adders", [])}
        keep.update({p["width"]: p for p in points})
        points = [keep[w] for w in sorted(keep)]
    dyn = old.get("dynamic_full_adder", []) if args.skip_dynamic else dynamic_per_scheme()
    res = {"machine": {"platform": platform.platform(), "cpus": os.cpu_count(),
                       "load": os.getloadavg()[0] if hasattr(os, "getloadavg") else None},
           "adders": points, "multipliers": old.get("multipliers", []), "meshes": old.get("meshes", []),
           "dynamic_full_adder": dyn}
    save(res)


if __name__ == "__main__":
    main()
