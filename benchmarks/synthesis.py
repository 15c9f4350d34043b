"""Synthesis benchmark: mlc's AND count against Berkeley ABC, run in the same script.

    python benchmarks/synthesis.py [--quick] [--deepsyn-seconds 5] [--no-abc] [--listings 3]

Needs ``yosys-abc`` (Debian: ``apt-get install yosys``) for the ABC columns and
``python-sat`` for the proven minima of functions of up to 4 inputs; both are used
by this script only.  Writes benchmarks/results/synthesis.json, synthesis.md and
synthesis.png.

Each function is handed to ABC as a BLIF of its don't-care-minimised irredundant SOP
(mlc's own ISOP of the interval [on, on|dc]: ABC's PLA reader does not use don't
cares), then ``strash; compress2rs; compress2rs`` and, the number to beat,
``&deepsyn -T 5``.  mlc starts from the full specification (with don't cares).

Every function is run in several *listings* (issue 15): as given, with inputs and
outputs in reverse order, and in a random order (seeded by the function's name);
mlc and ABC get the same permuted specification.  Besides the standard suite, a
second group of multi-output functions whose outputs share XOR chains (Gray code
converters, parity prefixes, comparators, adders, each least and most significant
bit first) is measured.  ABC runs in a worker thread while mlc synthesises.
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import re
import shutil
import subprocess
import sys
import tempfile
import random
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from mlc.spec import TableSpec  # noqa: E402
from mlc.logic.aigio import write_blif  # noqa: E402
from mlc.logic.lower import from_spec  # noqa: E402
from mlc.logic import exactsat, library  # noqa: E402
from mlc.logic.canon import permuted  # noqa: E402
from mlc.logic import tt as T  # noqa: E402
from mlc.logic.synth import synthesize  # noqa: E402

RESULTS = ROOT / "benchmarks" / "results"

# yosys-abc ships without abc.rc; these are the standard aliases from ABC's abc.rc
# (&deepsyn calls compress2rs internally, so they must exist in the working directory)
ABC_RC = """alias b balance
alias rw rewrite
alias rwz rewrite -z
alias rf refactor
alias rfz refactor -z
alias rs resub
alias st strash
alias compress2rs "b -l; rs -K 6 -l; rw -l; rs -K 6 -N 2 -l; rf -l; rs -K 8 -l; b -l; rs -K 8 -N 2 -l; rw -l; rs -K 10 -l; rwz -l; rs -K 10 -N 2 -l; b -l; rs -K 12 -l; rfz -l; rs -K 12 -N 2 -l; rwz -l; b -l"
alias resyn2rs "b; rs -K 6; rw; rs -K 6 -N 2; rf; rs -K 8; b; rs -K 8 -N 2; rw; rs -K 10; rwz; rs -K 10 -N 2; b; rs -K 12; rfz; rs -K 12 -N 2; rwz; b"
"""
COMPRESS2RS = "compress2rs"


def spec_to_blif(spec: TableSpec) -> str:
    n = spec.n
    full = T.mask(n)
    lines = [".model f", ".inputs " + " ".join(spec.inputs), ".outputs " + " ".join(spec.outputs)]
    for name, on, dc in zip(spec.outputs, spec.on, spec.dc):
        cubes, _ = T.isop(on & full, (on | dc) & full, n)
        lines.append(f".names {' '.join(spec.inputs)} {name}")
        for p, q in cubes:
            lines.append("".join("1" if (p >> i) & 1 else "0" if (q >> i) & 1 else "-"
                                 for i in range(n)) + " 1")
    lines.append(".end")
    return "\n".join(lines) + "\n"


def run_abc(blif: str, script: str, timeout: float = 120) -> dict:
    exe = shutil.which("yosys-abc") or shutil.which("abc")
    if exe is None:
        return {"error": "yosys-abc not found"}
    with tempfile.TemporaryDirectory() as d:
        f = Path(d) / "f.blif"
        f.write_text(blif)
        (Path(d) / "abc.rc").write_text(ABC_RC)
        cmd = f"read_blif {f}; strash; {script}; print_stats"
        t = time.perf_counter()
        try:
            p = subprocess.run([exe, "-c", cmd], capture_output=True, text=True, timeout=timeout,
                               cwd=d)
        except subprocess.TimeoutExpired:
            return {"error": "timeout"}
        dt = time.perf_counter() - t
    m = re.search(r"and\s*=\s*(\d+)", p.stdout)
    lev = re.search(r"lev\s*=\s*(\d+)", p.stdout)
    if not m:
        return {"error": (p.stdout + p.stderr)[-300:]}
    return {"ands": int(m.group(1)), "depth": int(lev.group(1)) if lev else None,
            "seconds": round(dt, 3)}


def proven_minimum(spec: TableSpec, upper: int, time_limit: float = 30.0) -> dict:
    """Minimum ANDs by SAT (inputs <= 4): increasing k until SAT, each call time-limited."""
    n = spec.n
    full = T.mask(n)
    targets = []
    for on, dc in zip(spec.on, spec.dc):
        care = full & ~dc
        f = on & care
        if f in (0, care) or any(f == T.var(n, i) & care or f == ~T.var(n, i) & care
                                 for i in range(n)):
            continue
        if any(c == care and (g == f or g == care & ~f) for g, c in targets):
            continue
        targets.append((f, care))
    if not targets:
        return {"minimum": 0, "proven": True}
    k = len(targets)
    t0 = time.perf_counter()
    while k < upper:
        left = time_limit - (time.perf_counter() - t0)
        if left <= 0:
            return {"minimum": None, "lower_bound": k, "proven": False}
        r = exactsat.synthesize_exact(n, targets, k, time_limit=left)
        if r == "timeout":
            return {"minimum": None, "lower_bound": k, "proven": False}
        if r is not None:
            return {"minimum": k, "proven": True, "seconds": round(time.perf_counter() - t0, 2)}
        k += 1
    return {"minimum": upper, "proven": True, "seconds": round(time.perf_counter() - t0, 2)}


def timed_synth(spec, effort):
    st: dict = {}
    t = time.perf_counter()
    g = synthesize(spec, effort, stats=st)
    dt = time.perf_counter() - t
    return g, dt, st


def scaling(args) -> list[dict]:
    cases = [
        ("mult5x5 (10 in, 10 out, table)", library.multiplier(5), 1.0),
        ("rand10x10 (10 in, 10 out, random table)", library.random_function(10, 10, 11), 1.0),
        ("adder8 (16 in, 9 out, table)", library.adder(8), 10.0),
        ("adder8 (16 in, 9 out, network)", library.ripple_adder(8), 10.0),
        # wide networks: no goal in issue 4; shows the SAT-sweeping equivalence proof
        ("mult12x12 (24 in, 24 out, network)", library.array_multiplier(12), None),
        ("mult16x16 (32 in, 32 out, network)", library.array_multiplier(16), None),
    ]
    rows = []
    for label, spec, goal in cases:
        for effort in (2,):
            g, dt, st = timed_synth(spec, effort)
            row = {"function": label, "inputs": len(spec.inputs), "outputs": len(spec.outputs),
                   "effort": effort, "ands": g.num_ands(), "depth": g.depth(),
                   "seconds": round(dt, 3), "goal_seconds": goal,
                   "meets_goal": None if goal is None else dt < goal,
                   "equivalence": st["equivalence"]["method"],
                   "equivalence_seconds": round(st["equivalence_s"], 3)}
            if not args.no_abc:
                # tables: the don't-care-minimised SOP; networks: their structural AIG
                blif = (spec_to_blif(spec) if isinstance(spec, TableSpec)
                        else write_blif(from_spec(spec)))
                r = run_abc(blif, f"{COMPRESS2RS}; {COMPRESS2RS}", timeout=600)
                row["abc_compress2rs"] = r.get("ands")
                row["abc_seconds"] = r.get("seconds")
            rows.append(row)
            print(f"  scaling {label} -O{effort}: {g.num_ands()} ANDs, depth {g.depth()}, "
                  f"{dt:.2f}s ({'no goal' if goal is None else f'goal < {goal}s'}), equivalence {row['equivalence']} "
                  f"{row['equivalence_seconds']}s; ABC {row.get('abc_compress2rs')}", flush=True)
    return rows


def listings(spec: TableSpec, count: int) -> list[tuple[str, TableSpec]]:
    """The given listing, the reversed one and ``count - 2`` random ones (seeded by
    the function's name)."""
    import zlib
    n, m = spec.n, len(spec.outputs)
    out = [("given", spec)]
    if count >= 2:
        out.append(("reversed", permuted(spec, list(range(n - 1, -1, -1)),
                                         list(range(m - 1, -1, -1)))))
    rng = random.Random(zlib.crc32(spec.source.encode()))
    for k in range(count - 2):
        pi, po = list(range(n)), list(range(m))
        rng.shuffle(pi)
        rng.shuffle(po)
        out.append((f"random{k + 1}", permuted(spec, pi, po)))
    return out


def _abc_jobs(pool, spec, args) -> dict:
    """ABC runs for one listing, submitted to ``pool`` (futures)."""
    if args.no_abc:
        return {}
    blif = spec_to_blif(spec)
    jobs = {"abc_compress2rs": pool.submit(run_abc, blif, f"{COMPRESS2RS}; {COMPRESS2RS}")}
    if not args.quick:
        jobs["abc_deepsyn"] = pool.submit(
            run_abc, blif, f"&get -n; &deepsyn -T {args.deepsyn_seconds}; &put",
            args.deepsyn_seconds * 4 + 30)
    return jobs


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="skip &deepsyn and scaling")
    ap.add_argument("--no-abc", action="store_true")
    ap.add_argument("--deepsyn-seconds", type=int, default=5)
    ap.add_argument("--listings", type=int, default=3,
                    help="listings per function: given, reversed, then random ones")
    ap.add_argument("--proof-seconds", type=float, default=20.0,
                    help="time limit of the SAT minimality proof per function (<= 4 inputs)")
    ap.add_argument("--only", default=None, help="comma-separated function names")
    ap.add_argument("--out", default=str(RESULTS))
    ap.add_argument("--merge", action="store_true",
                    help="with --only: replace just the re-run functions' rows in the existing "
                         "results (the other rows, their date and the scaling table are kept)")
    args = ap.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    have_abc = not args.no_abc and (shutil.which("yosys-abc") or shutil.which("abc")) is not None
    if not args.no_abc and not have_abc:
        print("yosys-abc / abc not found: the ABC columns stay empty and no "
              "'mlc <= ABC' is counted (install Debian's yosys)", file=sys.stderr)
        args.no_abc = True
    rows = []
    t_all = time.perf_counter()
    funcs = [("standard", f) for f in library.suite()] + [("xor-sharing", f)
                                                           for f in library.xor_suite()]
    seen = set()
    uniq = []
    for grp, f in funcs:               # the xor group repeats some standard functions
        if f.source not in seen:
            seen.add(f.source)
            uniq.append((grp, f))
    funcs = uniq
    if args.only:
        keep = set(args.only.split(","))
        funcs = [(grp, f) for grp, f in funcs if f.source in keep]
    pool = ThreadPoolExecutor(max_workers=1)
    for group, spec in funcs:
        name = spec.source
        row = {"function": name, "group": group, "inputs": spec.n,
               "outputs": len(spec.outputs), "dont_cares": any(spec.dc), "listings": []}
        lst = listings(spec, args.listings)
        jobs = [_abc_jobs(pool, s, args) for _, s in lst]
        for (label, s), job in zip(lst, jobs):
            L = {"listing": label, "inputs_order": list(s.inputs),
                 "outputs_order": list(s.outputs)}
            for effort in (2, 3):
                g, dt, st = timed_synth(s, effort)
                L[f"mlc_O{effort}"] = g.num_ands()
                L[f"mlc_O{effort}_depth"] = g.depth()
                L[f"mlc_O{effort}_seconds"] = round(dt, 3)
                L[f"mlc_O{effort}_equivalence"] = st["equivalence"]["method"]
            L["mlc"] = min(L["mlc_O2"], L["mlc_O3"])
            row["listings"].append(L)
        for L, job in zip(row["listings"], jobs):
            for key, fut in job.items():
                r = fut.result()
                L[key] = r.get("ands")
                L[key + "_depth"] = r.get("depth")
                if r.get("error"):
                    L[key + "_error"] = r["error"]
            abc = L.get("abc_compress2rs")
            L["meets_abc"] = None if abc is None else L["mlc"] <= abc
        Ls = row["listings"]
        for key in ("mlc_O2", "mlc_O3", "mlc"):
            row[key] = max(L[key] for L in Ls)
            row[key + "_all"] = [L[key] for L in Ls]
        row["mlc_O2_depth"] = max(L["mlc_O2_depth"] for L in Ls)
        row["mlc_O3_depth"] = max(L["mlc_O3_depth"] for L in Ls)
        row["mlc_O3_seconds"] = max(L["mlc_O3_seconds"] for L in Ls)
        row["listing_independent"] = all(len(set(row[k + "_all"])) == 1
                                         for k in ("mlc_O2", "mlc_O3"))
        for key in ("abc_compress2rs", "abc_deepsyn"):
            vals = [L.get(key) for L in Ls]
            row[key + "_all"] = vals
            row[key] = min((v for v in vals if v is not None), default=None)
        row["abc_compress2rs_depth"] = Ls[0].get("abc_compress2rs_depth")
        row["abc_deepsyn_depth"] = Ls[0].get("abc_deepsyn_depth")
        m = [L["meets_abc"] for L in Ls]
        row["meets_abc"] = None if any(v is None for v in m) else all(m)
        if spec.n <= 4 and exactsat.available():
            row.update({f"exact_{k}": v for k, v in
                        proven_minimum(spec, row["mlc"], args.proof_seconds).items()})
        row["known_minimum"] = library.KNOWN_MINIMA.get(name)
        if row.get("exact_minimum") is not None:
            row["minimum"], row["minimum_source"] = row["exact_minimum"], "SAT proof (this run)"
        elif row["known_minimum"] is not None:
            row["minimum"], row["minimum_source"] = row["known_minimum"], "issue 4 (literature)"
        if row.get("minimum") is not None:
            row["meets_exact"] = row["mlc"] == row["minimum"]
        print(f"{name:22s} n={spec.n} mlc O2={row['mlc_O2_all']} O3={row['mlc_O3_all']} "
              f"abc={row['abc_compress2rs_all']} deepsyn={row['abc_deepsyn_all']} "
              f"exact={row.get('exact_minimum')} ({row['mlc_O3_seconds']:.2f}s)", flush=True)
        rows.append(row)
    pool.shutdown()
    partial = None
    old_json = out / "synthesis.json"
    if args.merge and old_json.exists():
        old = json.loads(old_json.read_text())
        fresh = {r["function"]: r for r in rows}
        rows = [fresh.pop(r["function"], r) for r in old["rows"]] + list(fresh.values())
        partial = {"rows_from": old.get("partial_rerun", {}).get("rows_from", old["date"]),
                   "rerun": sorted(set(old.get("partial_rerun", {}).get("rerun", []))
                                   | {r["function"] for r in rows if r["function"] in
                                      {f.source for _, f in funcs}}),
                   "rerun_seconds": round(time.perf_counter() - t_all, 1)}
        scal = old.get("scaling", [])
        args.listings = old["summary"]["listings_per_function"]
    else:
        scal = [] if args.quick else scaling(args)
    abc_version = None
    exe = None if args.no_abc else shutil.which("yosys-abc")
    if exe:
        try:
            p = subprocess.run([exe, "-c", "version"], capture_output=True, text=True, timeout=20)
            abc_version = p.stdout.strip().splitlines()[-1] if p.stdout.strip() else None
        except Exception:  # noqa: BLE001
            pass
    abc_rows = [r for r in rows if r["meets_abc"] is not None]
    summary = {
        "functions": len(rows),
        "listings_per_function": args.listings,
        "abc_run": not args.no_abc,
        "listing_independent": sum(1 for r in rows if r["listing_independent"]),
        "mlc_total": sum(r["mlc"] for r in rows),
        "abc_compress2rs_total": (sum(r.get("abc_compress2rs") or 0 for r in rows)
                                  if not args.no_abc else None),
        "abc_deepsyn_total": (sum(r.get("abc_deepsyn") or 0 for r in rows)
                              if not args.no_abc and not args.quick else None),
        "compared_with_abc": len(abc_rows),
        "mlc_le_abc": sum(1 for r in abc_rows if r["meets_abc"]),
        "mlc_lt_abc": sum(1 for r in abc_rows if r["mlc"] < r["abc_compress2rs"]),
        "listings_le_abc": sum(1 for r in rows for L in r["listings"] if L["meets_abc"]),
        "listings_compared": sum(1 for r in rows for L in r["listings"]
                                 if L["meets_abc"] is not None),
        "exact_checked": sum(1 for r in rows if "meets_exact" in r),
        "exact_met": sum(1 for r in rows if r.get("meets_exact")),
        "misses_abc": [r["function"] for r in abc_rows if not r["meets_abc"]],
        "misses_exact": [r["function"] for r in rows if r.get("meets_exact") is False],
        "behind_deepsyn": [f"{r['function']} ({r['mlc']} vs {r['abc_deepsyn']})" for r in rows
                           if r.get("abc_deepsyn") is not None and r["mlc"] > r["abc_deepsyn"]],
        "seconds": round(time.perf_counter() - t_all, 1),
    }
    from mlc.logic import npn
    table = json.loads(npn.TABLE_PATH.read_text())
    npn_info = {"classes": len(table["classes"]), "histogram": table.get("histogram"),
                "unproven": len(table.get("unproven", []))}
    data = {"benchmark": "synthesis", "date": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
            "npn4_table": npn_info,
            "machine": {"python": platform.python_version(), "cpus": os.cpu_count()},
            "abc": abc_version, "abc_input": "ISOP of [on, on|dc] as BLIF, same listing as mlc",
            "cost": "AND nodes of an AIG with free inversions", "rows": rows,
            "scaling": scal, "summary": summary}
    if partial is not None:
        data["partial_rerun"] = partial
    (out / "synthesis.json").write_text(json.dumps(data, indent=1) + "\n")
    write_markdown(out / "synthesis.md", data)
    try:
        plot(out / "synthesis.png", rows)
    except Exception as e:  # noqa: BLE001
        print(f"plot failed: {e}", file=sys.stderr)
    print(json.dumps(summary, indent=1))
    return 0


def _all(vals) -> str:
    """Per-listing values: one number when they agree, else ``a/b/c``."""
    vals = ["-" if v is None else str(v) for v in vals]
    return vals[0] if len(set(vals)) == 1 else "/".join(vals)


def _yes(v) -> str:
    return "-" if v is None else "yes" if v else "**no**"


def write_markdown(path: Path, data: dict) -> None:
    rows = data["rows"]
    s = data["summary"]
    L = ["# Synthesis benchmark: mlc vs Berkeley ABC", "",
         f"Generated by `benchmarks/synthesis.py` on {data['date']} ({data['abc'] or 'ABC n/a'}).",
         *([f"Rows from the full run of {data['partial_rerun']['rows_from']}, except "
            f"{', '.join(data['partial_rerun']['rerun'])}: re-run on {data['date']} "
            "(`--only ... --merge`); the summary's seconds are the re-run's."]
           if data.get("partial_rerun") else []),
         "Cost = AND nodes of an AIG with free inversions (one mechanical gate each); "
         "depth in parentheses (of the given listing).", "",
         f"Each function is run in {s['listings_per_function']} listings: as given, inputs and "
         "outputs reversed, and a random order; mlc and ABC get the same permuted file.  A "
         "cell shows one number when all listings agree, else the values per listing "
         "(given/reversed/random).  'mlc' is the better of -O2 and -O3 per listing; "
         "'mlc <= ABC' must hold in every listing.", ""]
    for group in ("standard", "xor-sharing"):
        grp = [r for r in rows if r.get("group", "standard") == group]
        if not grp:
            continue
        L += [f"## {'Standard functions' if group == 'standard' else 'Outputs sharing XOR chains (both bit orders; _msb = most significant bit first)'}", "",
              "| function | in | out | dc | mlc -O2 | mlc -O3 | ABC compress2rs x2 | ABC &deepsyn | "
              "proven min | mlc <= ABC | mlc = min |",
              "|---|---|---|---|---|---|---|---|---|---|---|"]
        for r in grp:
            if r.get("minimum_source", "").startswith("SAT"):
                exs = str(r["minimum"])
            elif r.get("minimum") is not None:
                exs = f"{r['minimum']} (lit.; SAT: >= {r.get('exact_lower_bound')} in time)"
            elif "exact_proven" in r:
                exs = f">= {r.get('exact_lower_bound')}"
            else:
                exs = ""
            L.append(f"| {r['function']} | {r['inputs']} | {r['outputs']} | "
                     f"{'yes' if r['dont_cares'] else ''} | {_all(r['mlc_O2_all'])} "
                     f"({r['listings'][0]['mlc_O2_depth']}) | {_all(r['mlc_O3_all'])} "
                     f"({r['listings'][0]['mlc_O3_depth']}) | {_all(r['abc_compress2rs_all'])} "
                     f"({r.get('abc_compress2rs_depth')}) | {_all(r['abc_deepsyn_all'])} | {exs} | "
                     f"{_yes(r['meets_abc'])} | "
                     f"{'' if 'meets_exact' not in r else _yes(r['meets_exact'])} |")
        L.append("")
    if s["abc_run"]:
        abc_line = (f"Totals (worst listing of each function): mlc {s['mlc_total']}, ABC "
                    f"compress2rs {s['abc_compress2rs_total']} (best listing), ABC &deepsyn "
                    f"{s['abc_deepsyn_total']} (best listing).  mlc <= ABC compress2rs on "
                    f"{s['mlc_le_abc']}/{s['compared_with_abc']} functions in every listing "
                    f"({s['listings_le_abc']}/{s['listings_compared']} listings; strictly "
                    f"better on {s['mlc_lt_abc']} functions).")
    else:
        abc_line = f"Totals: mlc {s['mlc_total']}.  ABC was not run: no comparison is counted."
    L += [abc_line,
          f"mlc gives the same count in every listing on {s['listing_independent']}/"
          f"{s['functions']} functions; it equals the minimum on {s['exact_met']}/"
          f"{s['exact_checked']} functions of <= 4 inputs whose minimum is known (proven by SAT "
          f"in this run, or quoted by issue 4).", ""]
    if s.get("behind_deepsyn"):
        L.append("Behind ABC &deepsyn: " + ", ".join(s["behind_deepsyn"]) + ".")
        L.append("")
    t = data.get("npn4_table")
    if t:
        L.append(f"Exact NPN table: {t['classes']} classes of 4-input functions; "
                 f"{t['classes'] - t['unproven']} entries proven minimum by SAT, "
                 f"{t['unproven']} best found within the generator's time limits.")
        L.append("")
    if s["misses_abc"]:
        L.append("Missed (mlc > ABC compress2rs): " + ", ".join(s["misses_abc"]) + ".")
    if s["misses_exact"]:
        L.append("Missed (mlc > proven minimum): " + ", ".join(s["misses_exact"]) + ".")
    if data["scaling"]:
        L += ["", "## Speed (default effort -O2, including the equivalence proof)", "",
              "| function | inputs | outputs | mlc ANDs | depth | seconds | goal | met | "
              "equivalence proof (s) | ABC compress2rs x2 (s) |",
              "|---|---|---|---|---|---|---|---|---|---|"]
        for r in data["scaling"]:
            abc = (f"{r['abc_compress2rs']} ({r['abc_seconds']} s)"
                   if r.get("abc_compress2rs") is not None else "-")
            goal = "-" if r["goal_seconds"] is None else f"< {r['goal_seconds']} s"
            met = "-" if r["meets_goal"] is None else "yes" if r["meets_goal"] else "**no**"
            L.append(f"| {r['function']} | {r['inputs']} | {r['outputs']} | {r['ands']} | "
                     f"{r['depth']} | {r['seconds']} | {goal} | {met} | "
                     f"{r['equivalence']} ({r['equivalence_seconds']}) | {abc} |")
        worse = [(r["function"], 100.0 * (r["ands"] / r["abc_compress2rs"] - 1))
                 for r in data["scaling"] if r.get("abc_compress2rs") and
                 r["ands"] > r["abc_compress2rs"]]
        if worse:
            L += ["", "On these larger functions (issue 4 sets no size goal for them) mlc uses "
                      "more ANDs than ABC compress2rs at the default 1-second budget: " +
                  "; ".join(f"{f}: +{p:.1f}% ANDs" for f, p in worse) + "."]
    path.write_text("\n".join(L) + "\n")


def plot(path: Path, rows: list[dict]) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    names = [r["function"] for r in rows]
    x = list(range(len(rows)))
    fig, (ax, ax2) = plt.subplots(2, 1, figsize=(max(8, len(rows) * 0.45), 7), sharex=True,
                                  gridspec_kw={"height_ratios": [3, 2]})
    w = 0.27
    ax.bar([i - w for i in x], [r["mlc"] for r in rows], w, label="mlc (best of -O2/-O3, worst listing)")
    ax.bar(x, [r.get("abc_compress2rs") or 0 for r in rows], w, label="ABC compress2rs x2 (best listing)")
    ax.bar([i + w for i in x], [r.get("abc_deepsyn") or 0 for r in rows], w, label="ABC &deepsyn (best listing)")
    ax.set_ylabel("AND gates (inversions free)")
    ax.set_yscale("log")
    ax.yaxis.set_major_formatter(matplotlib.ticker.ScalarFormatter())
    ax.legend()
    ax.set_title("mlc vs ABC: AND count per function (lower is better)")
    for key, label, mk in (("mlc_O2", "mlc -O2", "o"), ("mlc_O3", "mlc -O3", "s"),
                           ("abc_deepsyn", "ABC &deepsyn", "^")):
        ys = [(r[key] / r["abc_compress2rs"]) if r.get(key) and r.get("abc_compress2rs") else None
              for r in rows]
        ax2.plot([i for i, y in zip(x, ys) if y], [y for y in ys if y], mk, label=label)
    ax2.axhline(1.0, color="gray", lw=1)
    ax2.set_ylabel("ANDs / ABC compress2rs")
    ax2.legend(fontsize=8)
    ax2.set_xticks(x)
    ax2.set_xticklabels(names, rotation=70, ha="right", fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


if __name__ == "__main__":
    raise SystemExit(main())
