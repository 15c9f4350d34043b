"""Printable meshes of compiled circuits: ``mlc stl`` of a whole circuit, timed by stage.

    python benchmarks/mesh_circuit.py [--cases tetris,full_adder,expr] [--profile mjp]

For each case the circuit is compiled (``mlc.pipeline``: load, synthesize, map, place and route)
and meshed as ``mlc stl`` does it (``mlc.mesh.export_scene``: static verification of the logic
states, build, printability report, STL + 3MF written with ``force`` so that the files exist
even when a check fails).  Stages: ``poses_s`` (static verification: equilibrium poses of every
mechanism, the same solves ``mlc stl`` makes), ``build_s`` (parts), ``report_s`` (checks),
``write_s`` (STL + 3MF); ``mesh_cpu_s``: CPU seconds of the mesh stages (this process and
the final trims' forked children), the figure the machine's other jobs disturb least.  The files are then read back independently with trimesh: STL pieces,
3MF named volumes, each watertight with its volume.

Cases: ``tetris`` (examples/tetris.tt, the README's main job), ``tetris_robot`` (the same with
examples/tetris.robot.yaml: ``mlc compile --robot``'s scene), ``full_adder``
(examples/full_adder.tt), ``expr`` (the expression ``(a & b) | c``: two gates and one chain).
Writes benchmarks/results/mesh_circuit.json (one row per case; a case that hits ``--limit``
seconds is recorded as not finished).  Wall-clock seconds on the shared 2-core machine.

Each row also sorts every failure of the blocking checks ``part_count``, ``min_gap`` and
``states`` (the full lists, not the report's first 20) by where it is (``failure_kinds``): a
body's kind from its name (``g<n>_`` gate, ``w_`` circuit wire, ``src_`` input source, ``rc_``
robot coupling chain, ``skel_`` skeleton), a pair by its two kinds, and within a gate by its
two library parts (``a_lo-a_hi``).  ``--outside``: the written 3MF read by third-party clients
when installed, lib3mf (the 3MF Consortium's library, strict mode: its warnings counted) and
PrusaSlicer's command line (``--info``: objects, parts, manifold).
"""
from __future__ import annotations

import argparse
import json
import multiprocessing as mp
import os
import platform
import sys
import tempfile
import time
from pathlib import Path

import mlc  # noqa: F401 -- before numpy: pins OpenBLAS's kernels (mlc/__init__.py)

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

RESULTS = ROOT / "benchmarks" / "results"
CASES = {"tetris": ("examples/tetris.tt", None), "full_adder": ("examples/full_adder.tt", None),
         "expr": (None, "(a & b) | c"), "ab": (None, "a & b"),
         # the README's robot: mlc compile examples/tetris.tt --robot examples/tetris.robot.yaml
         "tetris_robot": ("examples/tetris.tt", None)}
ROBOTS = {"tetris_robot": "examples/tetris.robot.yaml"}


def run_case(name: str, profile: str, queue, keep: str | None = None, outside: bool = False) -> None:
    import numpy as np
    import trimesh

    from mlc import pipeline
    from mlc.mesh import build as mbuild
    from mlc.mesh import checks as mchecks
    from mlc.mesh.export import part_meshes, read_3mf, write_outputs
    from mlc.mesh.pipeline import export_assembly, split_mechanisms, state_poses
    from mlc.mesh.profiles import load_profile

    path, expr = CASES[name]
    t0 = time.perf_counter()
    from mlc.circuit.build import CircuitOptions
    from mlc.robot.build import CIRCUIT_END_DROP, CIRCUIT_PRINT_LEANS
    opts = CircuitOptions(end_drop=CIRCUIT_END_DROP, print_leans=CIRCUIT_PRINT_LEANS) if name in ROBOTS else None     # as mlc compile --robot
    scene = pipeline.build(pipeline.compile_spec(pipeline.load(str(ROOT / path) if path else None, expr)),
                           options=opts).circuit.scene
    if name in ROBOTS:       # the circuit, the skeleton and the levers as one scene (mlc compile --robot)
        from mlc.commands.robot import robot_files
        scene, _ = robot_files(scene, str(ROOT / ROBOTS[name]))
    compile_s = time.perf_counter() - t0
    prof = load_profile(profile)
    mechs = split_mechanisms(scene)
    # stage timers: wrap the two library stages export_assembly calls
    timers = {"poses_s": 0.0, "build_s": 0.0, "report_s": 0.0}

    def timed(fn, key):
        def f(*a, **k):
            t = time.perf_counter()
            try:
                return fn(*a, **k)
            finally:
                timers[key] += time.perf_counter() - t
        return f

    import mlc.mesh.pipeline as mp_
    mp_.state_poses = timed(state_poses, "poses_s")
    mp_.build_assembly = timed(mbuild.build_assembly, "build_s")
    mp_.check_assembly = timed(mchecks.check_assembly, "report_s")
    import resource

    def cpu():      # user + system seconds of this process and of its finished children (the trims)
        a, b = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
        return a.ru_utime + a.ru_stime + b.ru_utime + b.ru_stime
    c1 = cpu()
    t1 = time.perf_counter()
    asm, rep = export_assembly(scene, prof)
    t2 = time.perf_counter()
    mesh_cpu = cpu() - c1
    with tempfile.TemporaryDirectory() as d:
        d = keep or d
        Path(d).mkdir(parents=True, exist_ok=True)
        stl, mf3 = Path(d) / f"{name}.stl", Path(d) / f"{name}.3mf"
        (Path(d) / f"{name}_report.json").write_text(json.dumps(rep.to_dict(), indent=1) + "\n")
        meshes = part_meshes(asm)
        write_outputs(asm, stl=stl, threemf=mf3, meshes=meshes)
        t3 = time.perf_counter()
        # independent read-back: trimesh on the STL (connected pieces) and the 3MF (named volumes)
        whole = trimesh.load(str(stl), force="mesh")
        pieces = whole.split(only_watertight=False)
        vols = read_3mf(mf3)
        sizes = {"stl_bytes": stl.stat().st_size, "threemf_bytes": mf3.stat().st_size}
        reads = outside_reads(mf3) if outside else None
    row = {"case": name, "source": path or expr, "profile": profile, "bodies": len(scene.bodies),
           "mechanisms": len(mechs), "inputs": len(scene.inputs), "parts": len(asm.parts),
           "triangles": int(sum(len(m.faces) for _, m in meshes)), **sizes,
           "ok": rep.ok, "failed_checks": [c.name for c in rep.checks if not c.ok],
           "compile_s": round(compile_s, 2), **{k: round(v, 2) for k, v in timers.items()},
           "mesh_s": round(t2 - t1, 2), "mesh_cpu_s": round(mesh_cpu, 2), "write_s": round(t3 - t2, 2), "total_s": round(t3 - t1, 2),
           "readback": {"stl_pieces": len(pieces), "stl_pieces_watertight": int(sum(p.is_watertight for p in pieces)),
                        "threemf_volumes": len(vols),
                        "threemf_volumes_watertight": int(sum(m.is_watertight for _, m in vols)),
                        "threemf_volume_mm3": round(float(sum(m.volume for _, m in vols)), 2),
                        "report_volume_mm3": round(float(sum(p["volume_mm3"] for p in rep.parts)), 2),
                        "smallest_part_mm3": round(float(np.min([m.volume for _, m in vols])), 4)},
           "finished": True}
    row["peak_rss_mb"] = round(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024, 1)
    cg = getattr(asm, "congruence", None)
    if cg is not None:
        row["reuse"] = {"hits": cg.hits, "misses": cg.misses}
    row["report"] = {c.name: {"ok": c.ok, "blocking": c.blocking, "detail": c.detail[:300],
                              "failures": len(c.failures)} for c in rep.checks}
    row["failure_kinds"] = failure_kinds(rep)
    if reads is not None:
        row["outside"] = reads
    queue.put(row)


KINDS = (("g", r"g\d+_"), ("wire", r"w_"), ("source", r"src_"), ("coupling", r"rc_"), ("skeleton", r"skel_"))


def kind_of(body: str) -> str:
    import re
    for k, pat in KINDS:
        if re.match(pat, body):
            return "gate" if k == "g" else k
    return "other"


def failure_kinds(rep) -> dict:
    """Every failure of part_count, min_gap and states, counted by the kinds of its bodies (and,
    inside one gate, by its two library parts); states by distinct pairs and summed mm^3."""
    import collections
    import re
    out = {}
    for c in rep.checks:
        if c.name not in ("part_count", "min_gap", "states") or c.ok:
            continue
        kinds, inside, pairs, vol = collections.Counter(), collections.Counter(), {}, collections.Counter()
        for f in c.failures:
            f = re.sub(r"^\S+\[[^]]*\]: ", "", f)          # the mechanism's name
            m = re.search(r"(\S+) is in \d+ pieces", f)
            names = [m.group(1)] if m else list(re.findall(r"(\S+) (?:-|intersects) (\S+?):?(?: |$)", f)[:1] or [()])[0]
            if not names:
                kinds["unparsed"] += 1
                continue
            key = "-".join(sorted(kind_of(n) for n in names))
            kinds[key] += 1
            gates = {n.split("_", 1)[0] for n in names}
            if key in ("gate", "gate-gate") and len(gates) == 1:
                inside["-".join(sorted(n.split("_", 1)[1] for n in names))] += 1
            v = re.search(r"\(([0-9.e+-]+) mm\^3\)", f)
            if v:
                pairs.setdefault(key, set()).add(tuple(sorted(names)))
                vol[key] += float(v.group(1))
        out[c.name] = {"failures": len(c.failures), "by_kind": dict(kinds.most_common()),
                       "inside_one_gate": dict(inside.most_common())}
        if pairs:
            out[c.name]["distinct_pairs_by_kind"] = {k: len(v) for k, v in pairs.items()}
            out[c.name]["mm3_by_kind"] = {k: round(v, 3) for k, v in vol.most_common()}
    return out


def outside_reads(mf3: Path) -> dict:
    """The 3MF as third-party clients read it: lib3mf (strict) and ``prusa-slicer --info``."""
    import shutil
    res = {}
    try:
        import lib3mf
        w = lib3mf.get_wrapper()
        model = w.CreateModel()
        reader = model.QueryReader("3mf")
        reader.SetStrictModeActive(True)
        t = time.perf_counter()
        reader.ReadFromFile(str(mf3))
        objs = model.GetObjects()
        n_mesh = n_comp = tris = 0
        while objs.MoveNext():
            o = objs.GetCurrentObject()
            if o.IsMeshObject():
                n_mesh += 1
                tris += model.GetMeshObjectByID(o.GetResourceID()).GetTriangleCount()
            elif o.IsComponentsObject():
                n_comp += 1
        items = model.GetBuildItems()
        n_items = 0
        while items.MoveNext():
            n_items += 1
        res["lib3mf"] = {"version": ".".join(str(x) for x in w.GetLibraryVersion()[:3]), "strict": True,
                         "warnings": reader.GetWarningCount(), "mesh_objects": n_mesh,
                         "components_objects": n_comp, "build_items": n_items, "triangles": tris,
                         "seconds": round(time.perf_counter() - t, 1)}
    except ImportError:
        res["lib3mf"] = "not installed"
    except Exception as e:        # a reader error is the finding
        res["lib3mf"] = {"error": str(e)[:300]}
    exe = shutil.which("prusa-slicer")
    if exe:
        from slicer_gates import info        # benchmarks/slicer_gates.py: its --info reader
        t = time.perf_counter()
        res["prusa_slicer_info"] = {**info(exe, mf3), "seconds": round(time.perf_counter() - t, 1)}
    else:
        res["prusa_slicer_info"] = "not installed"
    return res


def plot(rows, path: Path) -> None:
    """Time and peak memory against bodies, one point per finished case."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    done = sorted((r for r in rows if r.get("finished") and not r.get("superseded") and r.get("total_s")),
                  key=lambda r: r["bodies"])
    if not done:
        return
    fig, ax = plt.subplots(1, 2, figsize=(9, 3.6))
    x = [r["bodies"] for r in done]
    ax[0].loglog(x, [r["total_s"] for r in done], "o-", label="mesh + files")
    pz = [(r["bodies"], r["poses_s"]) for r in done if r.get("poses_s")]
    if pz:
        ax[0].loglog(*zip(*pz), "s--", label="static poses")
    ax[0].set_xlabel("bodies")
    ax[0].set_ylabel("wall-clock s (shared 2-core machine)")
    ax[0].legend()
    ax[1].loglog(x, [r["peak_rss_mb"] for r in done], "o-")
    ax[1].set_xlabel("bodies")
    ax[1].set_ylabel("peak resident memory, MB")
    for a in ax:
        for r in done:
            a.annotate(r["case"], (r["bodies"], a.get_lines()[0].get_ydata()[done.index(r)]), fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--cases", default="expr,tetris,full_adder")
    ap.add_argument("--profile", default="mjp")
    ap.add_argument("--limit", type=float, default=1800.0, help="seconds per case before it is recorded unfinished")
    ap.add_argument("--out", default=str(RESULTS / "mesh_circuit.json"))
    ap.add_argument("--keep", metavar="DIR", help="keep the STL, 3MF and JSON report of each case in DIR")
    ap.add_argument("--outside", action="store_true", help="read the 3MF back with lib3mf and prusa-slicer --info")
    args = ap.parse_args()
    rows = []
    for name in args.cases.split(","):
        q = mp.get_context("fork").Queue()
        t = time.perf_counter()
        p = mp.get_context("fork").Process(target=run_case, args=(name, args.profile, q, args.keep, args.outside))
        p.start()
        peak = 0        # resident memory of the case's process, polled every second (MB)
        while p.is_alive() and time.perf_counter() - t < args.limit:
            try:
                for line in open(f"/proc/{p.pid}/status"):
                    if line.startswith("VmRSS"):
                        peak = max(peak, int(line.split()[1]) // 1024)
            except OSError:
                pass
            p.join(1.0)
        if p.is_alive():
            p.terminate()
            p.join()
            row = {"case": name, "profile": args.profile, "finished": False,
                   "note": f"stopped after {args.limit:g} s", "peak_rss_polled_mb": peak}
        else:
            row = q.get() if not q.empty() else {"case": name, "finished": False, "note": f"exit {p.exitcode}"}
            row["peak_rss_polled_mb"] = peak
        row["wall_s"] = round(time.perf_counter() - t, 1)
        rows.append(row)
        print(json.dumps(row), flush=True)
    from gitstate import commit
    out = {"benchmark": "mesh_circuit", "commit": commit(), "python": platform.python_version(), "machine": platform.machine(),
           "cpus": os.cpu_count(), "load_average": [round(x, 2) for x in os.getloadavg()],
           "note": "wall-clock seconds on a shared 2-core machine (other jobs running); mesh_s = mlc stl's "
                   "export_assembly (poses + build + report), write_s = STL + 3MF", "rows": rows}
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    from mlc.io.atomic import atomic_path
    with atomic_path(args.out) as tmp:
        Path(tmp).write_text(json.dumps(out, indent=2) + "\n")
    with atomic_path(Path(args.out).with_suffix(".png")) as tmp:
        plot(rows, Path(tmp))
    return 0 if all(r.get("finished") for r in rows) else 1


if __name__ == "__main__":
    sys.exit(main())
