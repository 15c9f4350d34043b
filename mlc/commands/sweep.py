"""``mlc sweep``: parameter sweeps of Brownian-dynamics runs on Dask, and their plots."""
from __future__ import annotations

import json
import sys


def register(sub):
    p = sub.add_parser(
        "sweep", help="run a parameter sweep (a spec file) on Dask, or plot one (mlc sweep plot DIR)",
        description="mlc sweep SPEC.yaml [-o DIR] [--scheduler ADDRESS] [--workers N]: run every run of the "
                    "spec not yet in DIR/results.csv (one row per run) on a local Dask cluster or an existing "
                    "one; the spec and versions are written beside the table (sweep.json). "
                    "mlc sweep plot DIR [-o PNG]: the spec's plot and its numbers (summary JSON). "
                    "Spec format: docs/reproduction.md and mlc/schemas/sweep.schema.json. Times in t0, lengths in sigma.")
    p.add_argument("spec", metavar="SPEC.yaml|plot", help="the sweep spec, or the word plot")
    p.add_argument("dir", nargs="?", metavar="DIR", help="with plot: the sweep's results directory")
    p.add_argument("-o", "--output", default=None,
                   help="sweep: results directory (default: SPEC's stem + _results); plot: the PNG "
                        "(default DIR/plot.png; the summary goes beside it as .json)")
    p.add_argument("--scheduler", default=None, metavar="ADDRESS",
                   help="address of a running Dask scheduler (tcp://HOST:PORT); default: a local cluster")
    p.add_argument("--workers", type=int, default=None,
                   help="worker processes of the local cluster (one thread each; default 1)")
    p.add_argument("--retry-failed", action="store_true", help="run failed runs of the table again")
    p.add_argument("--kind", default=None, help="plot: response_grid, signal_vs_length or reliability_map (default: the spec's)")
    p.add_argument("--json", action="store_true", help="print a JSON summary")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=run)


def run(args) -> int:
    from mlc.errors import MlcError
    if args.spec == "plot":
        if not args.dir:
            raise MlcError("mlc sweep plot needs the results directory", "DIR", "mlc sweep plot DIR [-o PNG]")
        return _plot(args)
    if args.dir:
        raise MlcError(f"unexpected argument {args.dir!r}", "DIR", "give the output directory as -o DIR")
    if args.kind:
        raise MlcError("--kind applies to mlc sweep plot", "--kind")
    from pathlib import Path

    from mlc.sweep.run import run_sweep
    from mlc.sweep.spec import load_spec
    spec = load_spec(args.spec)
    out = args.output or str(Path(args.spec).with_suffix("").name) + "_results"
    info = run_sweep(spec, out, scheduler=args.scheduler, workers=args.workers, retry_failed=args.retry_failed,
                     progress=False if (args.quiet or args.json) else None,
                     log=None if args.json else (lambda m: sys.stderr.write(f"mlc: warning: {m}\n")))
    if args.json:
        print(json.dumps(info))
    else:
        print(f"{spec.name}: {info['runs']} runs, {info['skipped']} already in the table, {info['ran']} run now "
              f"({info['failed']} failed); table {info['table']}")
    if info["ran"] and info["failed"] == info["ran"]:
        # each failure is a row of the table (issue 11), but a sweep of nothing but failures is not a result
        sys.stderr.write(f"mlc: error: every run of the sweep failed ({info['failed']} of {info['ran']}), "
                         f"the first: {info['first_error'][:300]} (see the error column of {info['table']}; "
                         f"fix the spec, then run it again with --retry-failed)\n")
        return 1
    return 0


def _plot(args) -> int:
    from pathlib import Path

    from mlc.io.outputs import Outputs
    from mlc.sweep.plot import plot_sweep
    d = Path(args.dir)
    kind, fn = plot_sweep(d, kind=args.kind)
    png_path = Path(args.output) if args.output else d / "plot.png"
    outs = Outputs()
    png = outs.file(str(png_path), "-o", suffixes=(".png",))
    js = outs.file(str(png_path.with_suffix(".json")), "-o (its .json)", suffixes=(".json",))
    with outs:
        summary = fn(d, png.tmp)
        js.write_text(json.dumps(summary, indent=1) + "\n")
    if args.json:
        print(json.dumps(summary))
    else:
        print(f"wrote {png_path} and {png_path.with_suffix('.json')}")
        for r in summary["rows"]:
            if kind == "response_grid":
                extra = {k: v for k, v in r.items() if k not in ("units", "frequency") and not k.startswith(("rms", "y_", "wall", "seeds"))}
                print(f"  units {r['units']:>2}  f {r['frequency']:<5g} {extra if extra else ''} RMS deviation "
                      f"{100 * r['rms_dev_mean']:.1f} ± {100 * r['rms_dev_sd']:.1f} % ({r['seeds']} seeds)")
            elif kind == "reliability_map":
                p = "failed" if r["p_wrong"] is None else f"{100 * r['p_wrong']:.3g} %"
                print(f"  tolerance {r['tolerance']:<6g} kT {r['kT']:<7g} P(wrong) {p}"
                      f"{' (' + str(r['failed_runs']) + ' failed runs)' if r['failed_runs'] else ''}"
                      f"{'  FAILS' if r['fails'] else ''}")
            else:
                head = {k: v for k, v in r.items() if k not in ("units", "mean", "var", "var_time", "var_seed_means", "sem", "drift")}
                print(f"  {head}: signal length " + ", ".join(f"{m:.4f}" for m in r["mean"]))
    return 0
