"""Run a sweep on Dask and keep its results table.

``run_sweep(spec, outdir, scheduler=None, workers=None)``: every run of the spec not yet
in ``outdir/results.csv`` is submitted to a Dask cluster (a :class:`LocalCluster` of
``workers`` single-threaded worker processes by default, or the scheduler at
``scheduler``); each finished run is added to the table at once (the whole table is
rewritten atomically, rows in the spec's order), so an interrupted sweep keeps every
finished run and a second call runs only the rest (resume).  Beside the table:
``spec.yaml`` (the spec as given), ``sweep.json`` (mlc, Python, numpy, numba and Dask
versions, the spec's sha256, scene, measure, run count) and ``traces/RUN_ID.npz`` (the
probe time series of square-response runs, for the plot).

A run that fails (an unstable dt, an exploding scene, any exception in the worker, a
worker that died) is a row with ``status`` = failed and its ``error``; it is not run again
on resume unless ``retry_failed``.
"""
from __future__ import annotations

import csv
import hashlib
import io
import json
import logging
import math
import platform
from pathlib import Path

import numpy as np

from mlc import __version__
from mlc.errors import Loc, MlcError
from mlc.io.atomic import write_bytes, write_text
from mlc.sweep.spec import SweepSpec

TABLE = "results.csv"
HEAD = ["run_id", "index", "status", "error", "scene", "measure"]


def _cell(v):
    if v is None:
        return ""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, dict):
        return json.dumps(v, sort_keys=True, separators=(",", ":"))
    if isinstance(v, float):
        return repr(v)
    return str(v)


def read_table(path: Path) -> tuple[list[str], list[dict]]:
    """(columns, rows as dicts of strings) of a results table; a missing file is empty."""
    if not path.exists():
        return [], []
    try:
        with open(path, newline="", encoding="utf-8") as f:
            r = csv.DictReader(f)
            rows = list(r)
            cols = list(r.fieldnames or [])
    except (OSError, UnicodeDecodeError, csv.Error) as e:
        raise MlcError(f"cannot read the results table: {e}", str(path),
                       "move it away to start the sweep afresh") from None
    if cols[:len(HEAD)] != HEAD:
        raise MlcError("this is not an mlc sweep results table (its header differs)", str(path),
                       "choose another output directory")
    return cols, rows


def _row_cells(spec: SweepSpec, run, result: dict) -> dict:
    row = {"run_id": run.run_id, "index": str(run.index), "status": result["status"], "error": result["error"],
           "scene": spec.scene, "measure": spec.measure}
    for k in spec.columns:
        row[k] = _cell(run.params.get(k))
    row["seed"] = str(run.seed)
    for k, v in result["row"].items():
        row[k] = _cell(v)
    row["wall_s"] = _cell(round(float(result["wall_s"]), 4))
    return row


def _write_table(path: Path, spec: SweepSpec, rows: dict, old_cols: list[str]) -> None:
    order = {r.run_id: r.index for r in spec.runs}
    cols = HEAD + list(spec.columns) + ["seed"]
    for c in old_cols:
        if c not in cols:
            cols.append(c)
    for r in rows.values():
        for c in r:
            if c not in cols:
                cols.append(c)
    if "wall_s" in cols:           # last
        cols.remove("wall_s")
        cols.append("wall_s")
    buf = io.StringIO()
    w = csv.DictWriter(buf, fieldnames=cols, restval="", lineterminator="\n")
    w.writeheader()
    for rid in sorted(rows, key=lambda k: (order.get(k, math.inf), k)):
        w.writerow(rows[rid])
    write_text(path, buf.getvalue())


def _versions() -> dict:
    import dask
    import distributed
    import numba
    return {"mlc": __version__, "python": platform.python_version(), "numpy": np.__version__,
            "numba": numba.__version__, "dask": dask.__version__, "distributed": distributed.__version__}


def _precheck(spec: SweepSpec) -> None:
    """Build each distinct scene once and check the inputs and probes the spec names."""
    from mlc.sweep.measure import _scene, check_names
    from mlc.sweep.scenes import BUILDERS
    seen = set()
    keys = list(BUILDERS[spec.scene][1])
    for run in spec.runs:
        key = tuple(_cell(run.params[k]) for k in keys) + (_cell(run.params.get("inputs")),
                                                            run.params.get("probe"), run.params.get("drive_input"))
        if key in seen:
            continue
        seen.add(key)
        try:
            sc = _scene(spec.scene, run.params)
        except MlcError:
            raise
        except ValueError as e:
            raise MlcError(f"scene {spec.scene} with {', '.join(f'{k}={run.params[k]}' for k in keys)}: {e}",
                           Loc(spec.source)) from None
        bad = check_names(sc, spec.measure, run.params)
        if bad:
            raise MlcError(bad[0][1], f"{spec.source}: {bad[0][0]}")


def _client(scheduler: str | None, workers: int):
    from dask.distributed import Client, LocalCluster
    if scheduler:
        try:
            client = Client(scheduler, timeout="10s")
        except (OSError, TimeoutError, ValueError, TypeError) as e:
            raise MlcError(f"cannot reach the Dask scheduler at {scheduler!r}: {' '.join(str(e).split())[:200]}",
                           "--scheduler", "start it (dask scheduler) or give its address as tcp://HOST:PORT") from None
        return client, None
    cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=":0",
                           silence_logs=logging.CRITICAL)
    return Client(cluster), cluster


def run_sweep(spec: SweepSpec, outdir, scheduler: str | None = None, workers: int | None = None,
              retry_failed: bool = False, progress: bool | None = None, log=None) -> dict:
    """Run the spec's missing runs; returns {"runs", "skipped", "ran", "failed", "table"} and, when a
    run failed, "first_error" (the first failure's error, in the order the runs finished)."""
    from mlc.io.progress import Progress
    try:
        import dask.distributed  # noqa: F401
    except ImportError:
        raise MlcError("mlc sweep runs on Dask, which is not installed", None,
                       "pip install 'mlc[sweep]' (or pip install 'dask[distributed]')") from None
    out = Path(outdir)
    if out.exists() and not out.is_dir():
        raise MlcError("the output location exists and is not a directory", "-o", "give a directory")
    if workers is not None and workers < 1:
        raise MlcError(f"--workers must be >= 1, got {workers}", "--workers")
    if scheduler and workers is not None:
        raise MlcError("--workers sizes the local cluster; an existing cluster (--scheduler) has its own workers",
                       "--workers", "drop --workers")
    table = out / TABLE
    old_cols, old_rows = read_table(table)
    _precheck(spec)
    rows = {r["run_id"]: r for r in old_rows}
    done = {rid for rid, r in rows.items() if r["status"] == "ok" or not retry_failed}
    todo = [r for r in spec.runs if r.run_id not in done]
    info = {"runs": len(spec.runs), "skipped": len(spec.runs) - len(todo), "ran": 0, "failed": 0, "table": str(table)}
    client = cluster = None
    if todo:                      # connect first: an unreachable scheduler leaves nothing written
        client, cluster = _client(scheduler, workers or 1)
    futures = []
    try:
        try:
            out.mkdir(parents=True, exist_ok=True)
        except OSError as e:
            raise MlcError(f"cannot create the output directory: {e.strerror}", "-o") from None
        write_text(out / "spec.yaml", spec.text)
        meta = {"versions": _versions(), "spec": spec.source, "spec_sha256": hashlib.sha256(spec.text.encode()).hexdigest(),
                "name": spec.name, "scene": spec.scene, "measure": spec.measure, "plot": spec.plot,
                "runs": len(spec.runs), "scheduler": scheduler or "local",
                "workers": None if scheduler else (workers or 1)}
        write_text(out / "sweep.json", json.dumps(meta, indent=1) + "\n")
        if not table.exists():
            _write_table(table, spec, rows, old_cols)
        if not todo:
            return info
        from mlc.sweep.measure import run_task
        by_id = {r.run_id: r for r in spec.runs}
        from dask.distributed import as_completed
        futures = [client.submit(run_task, r.task(spec.scene, spec.measure), key=f"mlc-sweep-{r.run_id}",
                                 pure=False) for r in todo]
        with Progress(f"mlc sweep {spec.name}", total=len(todo), show=progress) as bar:
            for k, fut in enumerate(as_completed(futures)):
                rid = fut.key[len("mlc-sweep-"):]
                try:
                    res = fut.result()
                except Exception as e:  # noqa: BLE001 - a worker that died: the run is a failed row
                    res = {"run_id": rid, "status": "failed", "error": f"worker failed: {type(e).__name__}: "
                           f"{' '.join(str(e).split())[:300]}", "row": {}, "trace": None, "wall_s": float("nan")}
                run = by_id[rid]
                if res.get("trace") is not None:
                    buf = io.BytesIO()
                    np.savez_compressed(buf, **{k2: np.asarray(v) for k2, v in res["trace"].items()})
                    (out / "traces").mkdir(exist_ok=True)
                    write_bytes(out / "traces" / f"{rid}.npz", buf.getvalue())
                rows[rid] = _row_cells(spec, run, res)
                _write_table(table, spec, rows, old_cols)
                info["ran"] += 1
                info["failed"] += res["status"] != "ok"
                if res["status"] != "ok" and "first_error" not in info:
                    info["first_error"] = res["error"]
                if log and res["status"] != "ok":
                    log(f"run {rid} ({', '.join(f'{a}={b}' for a, b in run.varied.items())}, seed {run.seed}) "
                        f"failed: {res['error'][:300]}")
                bar.update(k + 1)
    finally:
        for f in futures:
            if not f.done():
                f.cancel()
        if client is not None:
            client.close()
        if cluster is not None:
            cluster.close()
    return info
