"""Synthesis on the EPFL combinational benchmarks: mlc against Berkeley ABC in one run.

    python benchmarks/synthesis_epfl.py [--timeout 150] [--circuits ctrl,router] [--no-abc]
    python benchmarks/synthesis_epfl.py --profile [--circuits ctrl,router]

Reads the binary AIGER circuits of ``../shared/benchmarks/epfl/`` (relative to the
repository; the script says so and exits 0 where that folder is absent) and, per circuit:

* **mlc**: ``compile_spec(load(file))`` at the default level -- what ``mlc compile``
  runs: synthesis (its result proven equivalent to the file by
  :func:`mlc.logic.equiv.check_equivalent`), mapping onto gates, and a second proof of
  the mapped netlist.  Each circuit runs in its own process under a time limit
  (``--timeout`` seconds, wall clock); a circuit over it is recorded as a timeout, not
  dropped.  Memory is that process's peak resident set (``ru_maxrss``, Python and its
  imports included).
* **ABC** (``berkeley-abc``, Debian package of that name, else ``yosys-abc``), where
  installed: ``read_aiger; strash; compress2rs; compress2rs`` with the aliases of ABC's
  ``abc.rc``; its time is ABC's own ``time`` around the two scripts.  ABC's ``cec``
  checks its result against the file, and is also a second, independent opinion on
  mlc's AIG and mlc's mapped netlist (both written as binary AIGER by mlc).

A circuit's mlc numbers count only when its proof succeeded (and, with ABC present,
ABC's ``cec`` agrees).  Writes ``benchmarks/results/synthesis_epfl.json``, ``.md`` and
``.png``.  Times in seconds, memory in MiB.  numba's kernels are loaded (compiled, on a
fresh clone) once before the run, outside every limit and time (``numba_cache_s``); each
row records the md5 of mlc's AIG (``to_text()``), to compare networks across runs.

``--profile`` instead measures where mlc's synthesis CPU time goes, by pass and by numba
kernel (:func:`profile`), into ``benchmarks/results/synthesis_epfl_profile.json``.
"""
from __future__ import annotations

import argparse
import hashlib
import json
import os
import platform
import re
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from gitstate import commit as git_commit      # benchmarks/gitstate.py

ROOT = Path(__file__).resolve().parents[1]
EPFL = ROOT.parent / "shared" / "benchmarks" / "epfl"
RESULTS = ROOT / "benchmarks" / "results"
CIRCUITS = ["adder", "bar", "max", "sin", "cavlc", "ctrl", "dec", "i2c", "int2float", "priority", "router"]

# The aliases of ABC's abc.rc (Debian's berkeley-abc and yosys-abc ship without it).
ABC_RC = """alias b balance
alias rw rewrite
alias rwz rewrite -z
alias rf refactor
alias rfz refactor -z
alias rs resub
alias compress2rs "b -l; rs -K 6 -l; rw -l; rs -K 6 -N 2 -l; rf -l; rs -K 8 -l; b -l; rs -K 8 -N 2 -l; rw -l; rs -K 10 -l; rwz -l; rs -K 10 -N 2 -l; b -l; rs -K 12 -l; rfz -l; rs -K 12 -N 2 -l; rwz -l; b -l"
"""
STATS_RE = re.compile(r"i/o\s*=\s*(\d+)/\s*(\d+).*?and\s*=\s*(\d+)\s+lev\s*=\s*(\d+)")
ELAPSE_RE = re.compile(r"elapse:\s*([0-9.]+) seconds")


# ----------------------------------------------------------------------------- mlc, in a child

def worker(path: str, outdir: str) -> dict:
    """Compile one circuit as ``mlc compile`` does; write mlc's AIG and netlist as .aig.

    Times are wall clock (``*_s``) and CPU time of this process (``*_cpu_s``); the CPU
    time of the optimisation alone is taken by wrapping :func:`mlc.logic.opt.optimize`,
    which :func:`mlc.logic.synth.synthesize` calls (None if it was not called); the
    modules it imports are imported before, so that Python's imports are not counted."""
    sys.path.insert(0, str(ROOT))
    from mlc.commands.compile import compile_spec
    from mlc.front.load import load
    from mlc.logic import opt
    from mlc.logic.aigio import aag_to_aig, write_aiger_binary

    # The modules the optimisation imports on its first call (numpy among them, about
    # 0.1 s) are imported here, outside the timed call: ABC's time likewise leaves out
    # its start-up and the reading of the file.  Tables built on first use (the NPN
    # lookup tables, the exact 4-input library) stay inside it.
    from mlc.logic import canon, cofexact, decomp, equiv, exactsat, kern, npn  # noqa: F401

    # numba's start-up likewise: loading the cached kernels of mlc.logic.kern (compiling
    # them on a cold cache) is done here and reported as numba_warm_s, not timed inside
    # the synthesis (ABC's time leaves out its own start-up)
    warm_s = kern.warm()

    opt_cpu = []
    inner = opt.optimize

    def timed(*a, **k):
        c0 = time.process_time()
        try:
            return inner(*a, **k)
        finally:
            opt_cpu.append(time.process_time() - c0)
    opt.optimize = timed

    t0 = time.perf_counter()
    spec = load(path)
    t1, c1 = time.perf_counter(), time.process_time()
    c = compile_spec(spec)                    # default level, as `mlc compile`
    t2, c2 = time.perf_counter(), time.process_time()
    Path(outdir, "mlc.aig").write_bytes(write_aiger_binary(c.aig))
    Path(outdir, "netlist.aig").write_bytes(aag_to_aig(c.netlist.to_aiger(), "netlist.aag"))
    st = c.synth_stats
    return {
        "read_s": t1 - t0,
        "numba_warm_s": warm_s,                     # kernel loading, outside the timed call
        "synthesis_s": st["synthesis_s"],           # optimisation only, wall clock
        "synthesis_cpu_s": sum(opt_cpu) if opt_cpu else None,
        "equivalence_s": st["equivalence_s"],       # the proof of the synthesized AIG
        "compile_s": t2 - t1,                       # synthesis + proof + mapping + second proof
        "compile_cpu_s": c2 - c1,
        "ands": c.aig.num_ands(),
        "depth": c.aig.depth(),
        "aig_md5": hashlib.md5(c.aig.to_text().encode()).hexdigest(),   # to compare networks across runs
        "gates": c.netlist.stats["gates"],
        "gate_depth": c.netlist.stats["depth"],
        "equivalence": st["equivalence"].get("method"),
        "netlist_equivalence": c.proof.get("method"),
        "proven": bool(st["equivalence"].get("equivalent")) and bool(c.proof.get("equivalent")),
        "max_rss_mib": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
    }


def run_mlc(path: Path, tmp: Path, timeout: float) -> dict:
    t0 = time.perf_counter()
    cmd = [sys.executable, str(Path(__file__).resolve()), "--worker", str(path), str(tmp)]
    try:
        p = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout,
                           env={**os.environ, "PYTHONPATH": str(ROOT)})
    except subprocess.TimeoutExpired:
        return {"status": "timeout", "wall_s": time.perf_counter() - t0, "timeout_s": timeout}
    wall = time.perf_counter() - t0
    if p.returncode != 0:
        err = (p.stderr.strip().splitlines() or ["?"])[-1]
        return {"status": "error", "wall_s": wall, "error": err}
    d = json.loads(p.stdout.strip().splitlines()[-1])
    d.update(status="ok" if d["proven"] else "unproven", wall_s=wall)
    return d


# ----------------------------------------------------------------------------- ABC

def find_abc() -> str | None:
    return shutil.which("berkeley-abc") or shutil.which("yosys-abc")


def abc_cmd(abc: str, script: str, cwd: Path, timeout: float) -> str:
    p = subprocess.run([abc, "-c", script], cwd=cwd, capture_output=True, text=True, timeout=timeout)
    return p.stdout + p.stderr


def run_abc(abc: str, path: Path, tmp: Path, timeout: float) -> dict:
    """ABC's compress2rs x2 on the file; its own ``time`` (``seconds``), the process's
    wall and CPU time (reading included), then ABC's ``cec`` of its result against the file."""
    (tmp / "abc.rc").write_text(ABC_RC)
    shutil.copy(path, tmp / "in.aig")
    t0, r0 = time.perf_counter(), resource.getrusage(resource.RUSAGE_CHILDREN)
    try:
        out = abc_cmd(abc, "read_aiger in.aig; strash; print_stats; time; compress2rs; compress2rs; time; "
                           "print_stats; write_aiger -s abc.aig", tmp, timeout)
    except subprocess.TimeoutExpired:
        return {"status": "timeout", "timeout_s": timeout}
    wall, r1 = time.perf_counter() - t0, resource.getrusage(resource.RUSAGE_CHILDREN)
    stats = STATS_RE.findall(out)
    el = ELAPSE_RE.findall(out)
    if len(stats) < 2 or len(el) < 2:
        return {"status": "error", "error": (out.strip().splitlines() or ["?"])[-1]}
    return {"status": "ok", "strash_ands": int(stats[0][2]), "ands": int(stats[1][2]), "depth": int(stats[1][3]),
            "seconds": float(el[1]), "wall_s": wall,
            "cpu_s": (r1.ru_utime + r1.ru_stime) - (r0.ru_utime + r0.ru_stime),
            "cec": abc_cec(abc, tmp, "abc.aig", timeout)}


def abc_cec(abc: str, tmp: Path, name: str, timeout: float) -> bool | None:
    """ABC's verdict on in.aig == NAME (both binary AIGER), None if it did not finish."""
    try:
        out = abc_cmd(abc, f"cec in.aig {name}", tmp, timeout)
    except subprocess.TimeoutExpired:
        return None
    return "Networks are equivalent" in out


# ----------------------------------------------------------------------------- report

def mlc_time(m: dict) -> float:
    """mlc's optimisation time for the comparison: CPU seconds (wall if not measured)."""
    return m["synthesis_cpu_s"] if m.get("synthesis_cpu_s") is not None else m["synthesis_s"]


def markdown(res: dict) -> str:
    lines = [
        "# Synthesis on the EPFL benchmarks: mlc against ABC",
        "",
        f"Run {res['date']} on {res['machine']} (load average {res['load_before']} before, "
        f"{res['load_after']} after); tree: git {res['git_head'] or '?'} {res['note']}".rstrip() + ".",
        f"ABC: {res['abc'] or 'not installed'}, `strash; compress2rs; compress2rs` (abc.rc aliases); its "
        "time is ABC's own `time` around the two scripts.",
        f"mlc: `compile_spec` at the default level, as `mlc compile`; limit {res['timeout_s']:.0f} s wall "
        f"per circuit (less once the run's {res['budget_s']:.0f} s budget runs low).",
        "`mlc synth` = the optimisation alone, CPU s (wall s in brackets; other processes shared the "
        "2 cores, so CPU time is the fairer measure); `compile` = synthesis, proof, mapping and second proof, "
        "wall s. MiB = peak RSS of mlc's process. ANDs/ABC and time/ABC: mlc over ABC "
        "(goals: <= 1 and <= 2). `proof`: mlc's own equivalence proof of its result against the file; "
        "`ABC cec`: ABC's verdict on mlc's AIG and mapped netlist.",
    ]
    warm = [r["mlc"]["numba_warm_s"] for r in res["circuits"] if r["mlc"].get("numba_warm_s") is not None]
    if warm:
        lines.append(f"Not in mlc's times, as ABC's start-up is not in ABC's: Python's imports and numba's "
                     f"start-up (loading the cached kernels of `mlc.logic.kern`, {min(warm):.2f}-"
                     f"{max(warm):.2f} s per process in this run).")
    lines += [
        "",
        "| circuit | in/out | shipped | ABC ANDs | ABC depth | ABC s | mlc ANDs | mlc depth | mlc synth s "
        "| compile s | MiB | ANDs/ABC | time/ABC | proof | ABC cec | status |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in res["circuits"]:
        a, m = r.get("abc") or {}, r["mlc"]
        ok = m["status"] == "ok"

        def f(x, fmt="{}"):
            return fmt.format(x) if x is not None else "–"
        ratio_n = m["ands"] / a["ands"] if ok and a.get("ands") else None
        ratio_t = mlc_time(m) / a["seconds"] if ok and a.get("seconds") else None
        status = m["status"] if m["status"] != "timeout" else f"timeout ({m['timeout_s']:.0f} s)"
        if m["status"] == "error":
            status += ": " + m["error"][:60].replace("|", "/")
        synth = f"{mlc_time(m):.2f} ({m['synthesis_s']:.2f})" if ok else "–"
        cec = None
        if "abc_cec_mlc" in r:
            cec = "yes" if r["abc_cec_mlc"] and r["abc_cec_netlist"] else "NO" if False in (
                r["abc_cec_mlc"], r["abc_cec_netlist"]) else "undecided"
        lines.append(
            f"| {r['name']} | {r['inputs']}/{r['outputs']} | {r['shipped_ands']} | {f(a.get('ands'))} "
            f"| {f(a.get('depth'))} | {f(a.get('seconds'), '{:.2f}')} | {f(m.get('ands') if ok else None)} "
            f"| {f(m.get('depth') if ok else None)} | {synth} "
            f"| {f(m.get('compile_s') if ok else None, '{:.2f}')} | {f(m.get('max_rss_mib'), '{:.0f}')} "
            f"| {f(ratio_n, '{:.3f}')} | {f(ratio_t, '{:.1f}')} | {m.get('equivalence') or '–'} "
            f"| {f(cec)} | {status} |")
    s = res["summary"]
    lines += [
        "",
        f"mlc proven on {s['proven']} of {s['circuits']} circuits; timeouts: {', '.join(s['timeouts']) or 'none'}; "
        f"errors: {', '.join(s['errors']) or 'none'}.",
    ]
    if s.get("compared"):
        lines += [f"On the {s['compared']} circuits both finished: AND count <= ABC on {s['and_goal_met']}, "
                  f"synthesis time <= 2x ABC on {s['time_goal_met']}; total ANDs mlc {s['mlc_ands_total']} "
                  f"vs ABC {s['abc_ands_total']}; peak memory {s['max_rss_mib']:.0f} MiB; ABC's own results "
                  f"proven equivalent to the file by its cec on {s['abc_self_cec']} of {s['compared']}."]
    return "\n".join(lines) + "\n"


def plot(res: dict, path: Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = [r for r in res["circuits"] if r["mlc"]["status"] == "ok" and (r.get("abc") or {}).get("ands")]
    if not rows:
        return
    names = [r["name"] for r in rows]
    ands = [r["mlc"]["ands"] / r["abc"]["ands"] for r in rows]
    times = [mlc_time(r["mlc"]) / max(r["abc"]["seconds"], 1e-3) for r in rows]
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4))
    ax1.bar(names, ands, color=["tab:green" if x <= 1 else "tab:red" for x in ands])
    ax1.axhline(1, color="k", lw=0.8)
    ax1.set_ylabel("mlc ANDs / ABC compress2rs x2 ANDs")
    ax2.bar(names, times, color=["tab:green" if x <= 2 else "tab:red" for x in times])
    ax2.axhline(2, color="k", lw=0.8, ls="--")
    ax2.set_yscale("log")
    ax2.set_ylabel("mlc synthesis CPU time / ABC time")
    for ax in (ax1, ax2):
        ax.tick_params(axis="x", rotation=60)
    fig.suptitle(f"EPFL benchmarks, mlc (default level) vs ABC, {res['date']}")
    fig.tight_layout()
    fig.savefig(path, dpi=110)


# ----------------------------------------------------------------------------- profile

PASSES = {
    "opt": ["sweep", "fraig", "resub", "resub_odc", "resub_window", "resub_dc", "rewrite", "refactor",
            "balance", "balance_xor", "extract_and", "reorder", "initial_candidates", "improve", "_restarts"],
    "decomp": ["from_table"],
    "canon": ["canonical", "restore", "to_canonical", "permuted"],
    "equiv": ["spec_tables"],
}


class Meter:
    """CPU seconds charged to the innermost open call (self) and to all open calls (incl)."""

    def __init__(self):
        self.self_s, self.incl_s, self.calls, self.min_s = {}, {}, {}, {}
        self.stack = []                 # [name, start, child seconds]

    def wrap(self, name, fn):
        clock = time.process_time
        st = self

        def wrapped(*a, **k):
            st.stack.append([name, clock(), 0.0])
            try:
                return fn(*a, **k)
            finally:
                nm, t0, child = st.stack.pop()
                dt = clock() - t0
                st.incl_s[nm] = st.incl_s.get(nm, 0.0) + dt
                st.self_s[nm] = st.self_s.get(nm, 0.0) + dt - child
                st.calls[nm] = st.calls.get(nm, 0) + 1
                if dt < st.min_s.get(nm, 1e9):
                    st.min_s[nm] = dt
                if st.stack:
                    st.stack[-1][2] += dt
        return wrapped


def profile_worker(path: str) -> dict:
    """One run of ``opt.optimize(spec, 2)`` with every pass and kernel under a :class:`Meter`."""
    sys.path.insert(0, str(ROOT))
    from numba.core.registry import CPUDispatcher

    from mlc.front.load import load
    from mlc.logic import canon, cofexact, decomp, equiv, exactsat, kern, npn, opt  # noqa: F401

    kern.warm()
    spec = load(path)
    m = Meter()
    for mod_name, names in PASSES.items():
        mod = {"opt": opt, "decomp": decomp, "canon": canon, "equiv": equiv}[mod_name]
        for nm in names:
            setattr(mod, nm, m.wrap(nm if mod_name == "opt" else f"{mod_name}.{nm}", getattr(mod, nm)))
    kernels = [nm for nm, v in vars(kern).items() if isinstance(v, CPUDispatcher)]
    for nm in kernels:
        setattr(kern, nm, m.wrap(f"kern.{nm}", getattr(kern, nm)))
    c0 = time.process_time()
    g = opt.optimize(spec, 2)
    total = time.process_time() - c0
    other = total - sum(m.self_s.values())
    return {"cpu_s": total, "ands": g.num_ands(), "depth": g.depth(), "other_s": other,
            "aig_md5": hashlib.md5(g.to_text().encode()).hexdigest(),
            "self_s": m.self_s, "incl_s": m.incl_s, "calls": m.calls, "min_s": m.min_s,
            "kernel_calls": sum(v for k, v in m.calls.items() if k.startswith("kern.")),
            "kernel_s": sum(v for k, v in m.self_s.items() if k.startswith("kern."))}


def dispatch_cost() -> dict:
    """numba's fixed cost of a call: a kernel that does nothing, with 0 and with 12 array
    arguments (rewrite_node takes 20 arguments), CPU seconds a call over 2e5 calls."""
    import numpy as np
    from numba import njit

    @njit(cache=False)
    def nop0():
        return 0

    @njit(cache=False)
    def nop12(a, b, c, d, e, f, g, h, i, j, k, l):
        return a[0]

    arrs = [np.zeros(8, np.int64) for _ in range(12)]
    nop0(), nop12(*arrs)
    out = {}
    for name, call in (("0 args", lambda: nop0()), ("12 arrays", lambda: nop12(*arrs))):
        n = 200_000
        c0 = time.process_time()
        for _ in range(n):
            call()
        out[name] = (time.process_time() - c0) / n
    n = 200_000
    c0 = time.process_time()
    for _ in range(n):
        (lambda: None)()
    out["python call"] = (time.process_time() - c0) / n
    return out


def profile(names: list[str]) -> int:
    """``--profile``: where mlc's synthesis time goes, one run per circuit in its own process.

    The passes of :mod:`mlc.logic.opt` (with the decomposition, the canonical ordering and
    the restarts) and every numba kernel of :mod:`mlc.logic.kern` are wrapped by a timer
    (``time.process_time``, after ``kern.warm`` as above) that charges each CPU second to
    the innermost wrapped call running (``self_s``) and to every wrapped call open
    (``incl_s``); per wrapped function also its calls and its shortest call.  The wrappers
    cost about 1 us a call (part of ``cpu_s``).  ``dispatch_s``: the fixed CPU cost of a
    call to a numba kernel that does nothing (no arguments, 12 arrays) and of a Python
    call, for comparison.  Writes ``benchmarks/results/synthesis_epfl_profile.json``."""
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    me = str(Path(__file__).resolve())
    res = {"benchmark": "synthesis_epfl --profile", "date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()),
           "machine": f"{platform.machine()}, {os.cpu_count()} cores, Python {platform.python_version()}",
           "load_before": [round(x, 1) for x in os.getloadavg()], "circuits": {}}
    p = subprocess.run([sys.executable, me, "--dispatch"], capture_output=True, text=True, env=env, check=True)
    res["dispatch_s"] = json.loads(p.stdout.strip().splitlines()[-1])
    print("fixed CPU s a call:", res["dispatch_s"], flush=True)
    for name in names:
        p = subprocess.run([sys.executable, me, "--profile-worker", str(EPFL / f"{name}.aig")],
                           capture_output=True, text=True, env=env)
        if p.returncode != 0:
            print(f"{name}: error {(p.stderr.strip().splitlines() or ['?'])[-1]}", flush=True)
            continue
        d = json.loads(p.stdout.strip().splitlines()[-1])
        res["circuits"][name] = d
        top = sorted(d["self_s"].items(), key=lambda kv: -kv[1])[:5]
        print(f"{name:10s} {d['cpu_s']:6.2f} s CPU, {d['ands']} ANDs, kernels {d['kernel_s']:.2f} s in "
              f"{d['kernel_calls']} calls; " + ", ".join(f"{k} {v:.2f}" for k, v in top), flush=True)
    res["load_after"] = [round(x, 1) for x in os.getloadavg()]
    res["git_head"] = git_commit()
    RESULTS.mkdir(parents=True, exist_ok=True)
    stem = "synthesis_epfl_profile" if len(names) == len(CIRCUITS) else "synthesis_epfl_profile_subset"
    (RESULTS / f"{stem}.json").write_text(json.dumps(res, indent=1) + "\n")
    return 0


# ----------------------------------------------------------------------------- main

def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--timeout", type=float, default=300.0, help="per-circuit limit for mlc, wall seconds (default 300)")
    ap.add_argument("--budget", type=float, default=1080.0,
                    help="wall seconds for the whole run; once it runs low, the per-circuit limit shrinks "
                         "to what is left (at least 60 s) (default 1080)")
    ap.add_argument("--circuits", help="comma-separated subset (default: all eleven)")
    ap.add_argument("--no-abc", action="store_true", help="do not run ABC even if installed")
    ap.add_argument("--note", default="", help="free text stored in the JSON (e.g. which tree was measured)")
    ap.add_argument("--profile", action="store_true",
                    help="instead of the comparison: where mlc's synthesis CPU time goes, by pass and numba "
                         "kernel (writes benchmarks/results/synthesis_epfl_profile.json)")
    ap.add_argument("--worker", nargs=2, metavar=("AIG", "OUTDIR"), help=argparse.SUPPRESS)
    ap.add_argument("--profile-worker", metavar="AIG", help=argparse.SUPPRESS)
    ap.add_argument("--dispatch", action="store_true", help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.worker:
        print(json.dumps(worker(*args.worker)))
        return 0
    if args.profile_worker:
        print(json.dumps(profile_worker(args.profile_worker)))
        return 0
    if args.dispatch:
        print(json.dumps(dispatch_cost()))
        return 0
    if not EPFL.is_dir():
        print(f"skipped: {EPFL} is absent (the EPFL circuits live in ../shared/benchmarks/epfl/)")
        return 0
    if args.circuits and set(args.circuits.split(",")) - set(CIRCUITS):
        bad = sorted(set(args.circuits.split(",")) - set(CIRCUITS))
        print(f"--circuits: unknown {', '.join(bad)}; choose from {', '.join(CIRCUITS)}", file=sys.stderr)
        return 2
    if args.profile:
        return profile(args.circuits.split(",") if args.circuits else CIRCUITS)
    sys.path.insert(0, str(ROOT))
    from mlc.front.aiger import read

    names = args.circuits.split(",") if args.circuits else CIRCUITS
    abc = None if args.no_abc else find_abc()
    abc_version = None
    if abc:
        with tempfile.TemporaryDirectory() as t:
            v = abc_cmd(abc, "version", Path(t), 30)
        m = re.search(r"UC Berkeley, (ABC [^\n]*)", v)
        abc_version = f"{Path(abc).name}: {m.group(1) if m else '?'}"
    else:
        print("ABC not found (apt-get install berkeley-abc): mlc only")
    # numba compiles the kernels on first use and caches them beside the sources; on a
    # fresh clone that takes minutes (more on a loaded machine), which would count
    # against the first circuit's time limit: load (or compile) them once here, untimed
    t0 = time.perf_counter()
    p = subprocess.run([sys.executable, "-c", "from mlc.logic import kern; print(kern.warm())"],
                       capture_output=True, text=True, env={**os.environ, "PYTHONPATH": str(ROOT)})
    if p.returncode != 0:
        print(f"numba kernels failed to load: {(p.stderr.strip().splitlines() or ['?'])[-1]}", file=sys.stderr)
        return 1
    cache_s = time.perf_counter() - t0
    print(f"numba kernels loaded (compiled if not cached) in {cache_s:.1f} s wall", flush=True)
    out = []
    start = time.perf_counter()
    load_before = [round(x, 1) for x in os.getloadavg()]
    for name in names:
        path = EPFL / f"{name}.aig"
        if not path.exists():
            print(f"{name}: {path} missing, skipped")
            continue
        raw, spec = read(path.read_bytes(), str(path))
        row = {"name": name, "inputs": len(spec.inputs), "outputs": len(spec.outputs), "shipped_ands": len(raw.ands)}
        with tempfile.TemporaryDirectory() as t:
            tmp = Path(t)
            if abc:
                row["abc"] = run_abc(abc, path, tmp, 600)
            left = args.budget - (time.perf_counter() - start)
            row["mlc"] = run_mlc(path, tmp, min(args.timeout, max(60.0, left)))
            if abc and row["mlc"]["status"] in ("ok", "unproven"):
                row["abc_cec_mlc"] = abc_cec(abc, tmp, "mlc.aig", 600)
                row["abc_cec_netlist"] = abc_cec(abc, tmp, "netlist.aig", 600)
                if row["abc_cec_mlc"] is False or row["abc_cec_netlist"] is False:
                    row["mlc"]["status"] = "ABC cec disagrees"
        out.append(row)
        m, a = row["mlc"], row.get("abc") or {}
        print(f"{name:10s} shipped {row['shipped_ands']:5d}  ABC {a.get('ands', '-')!s:>5} "
              f"({a.get('seconds', float('nan')):.2f} s)  mlc {m.get('ands', '-')!s:>5} "
              f"({mlc_time(m) if m['status'] == 'ok' else m.get('wall_s', 0):.2f} s synth, "
              f"{m.get('max_rss_mib', 0):.0f} MiB) "
              f"{m['status']} {m.get('equivalence', '')} ABC-cec {row.get('abc_cec_mlc')}", flush=True)

    both = [r for r in out if r["mlc"]["status"] == "ok" and (r.get("abc") or {}).get("ands")]
    summary = {
        "circuits": len(out),
        "proven": sum(r["mlc"]["status"] == "ok" for r in out),
        "timeouts": [r["name"] for r in out if r["mlc"]["status"] == "timeout"],
        "errors": [r["name"] for r in out if r["mlc"]["status"] not in ("ok", "timeout")],
    }
    if both:
        summary.update(
            compared=len(both),
            and_goal_met=sum(r["mlc"]["ands"] <= r["abc"]["ands"] for r in both),
            time_goal_met=sum(mlc_time(r["mlc"]) <= 2 * r["abc"]["seconds"] for r in both),
            max_rss_mib=max(r["mlc"]["max_rss_mib"] for r in both),
            abc_self_cec=sum(bool(r["abc"].get("cec")) for r in both),
            mlc_ands_total=sum(r["mlc"]["ands"] for r in both),
            abc_ands_total=sum(r["abc"]["ands"] for r in both),
        )
    commit = git_commit()
    res = {
        "benchmark": "synthesis_epfl",
        "date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()),
        "machine": f"{platform.machine()}, {os.cpu_count()} cores, Python {platform.python_version()}",
        "git_head": commit,
        "note": args.note,
        "abc": abc_version,
        "abc_script": "read_aiger; strash; compress2rs; compress2rs",
        "mlc_api": "mlc.commands.compile.compile_spec(load(file)), default level",
        "timeout_s": args.timeout,
        "budget_s": args.budget,
        "wall_s": time.perf_counter() - start,
        "numba_cache_s": cache_s,                   # kernels loaded or compiled before the run, wall
        "load_before": load_before,
        "load_after": [round(x, 1) for x in os.getloadavg()],
        "units": {"time": "s", "memory": "MiB"},
        "circuits": out,
        "summary": summary,
    }
    RESULTS.mkdir(parents=True, exist_ok=True)
    stem = "synthesis_epfl" if not args.circuits else "synthesis_epfl_subset"
    (RESULTS / f"{stem}.json").write_text(json.dumps(res, indent=1) + "\n")
    (RESULTS / f"{stem}.md").write_text(markdown(res))
    plot(res, RESULTS / f"{stem}.png")
    print(markdown(res))
    return 0


if __name__ == "__main__":
    sys.exit(main())
