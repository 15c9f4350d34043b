"""Verification of a whole scene (a compiled circuit, a connector, a gate) on every row of
its truth table, statically or by Brownian dynamics.

* **static**: for each row, the equilibrium reached from the scene's rest pose by moving
  the muscles (:func:`mlc.verify.static.equilibrium`, polished only where it stalled:
  ``polish`` below), every probe read; a row passes
  when every probe reads the expected bit with the length within ``tol_length`` of the
  ideal, the largest joint stretch is within ``tol_stretch`` (no gate strained by its
  wiring), and no two slabs of different bodies interpenetrate in that pose
  (:func:`mlc.verify.overlap.clearance`; the smallest clearance is reported).  Clearance
  is its own verdict (``clearance_ok``); it fails a row only with ``require_clearance``:
  the router does not yet keep every pair of wires apart (docs/circuits.md), and a
  crossing of two floppy chains does not change what the circuit computes;
* **dynamic**: :func:`mlc.verify.dynamic.check_scene_dynamic_multi`: Brownian dynamics
  from rest into each row over several seeds until every probe has relaxed (detected).

The result is a :class:`Report`: one entry per (row, output) and a per-row summary.
Units: sigma, k0, t0.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

from mlc.errors import MlcError
from mlc.scene.model import Scene

TOL_LENGTH = 0.05       # sigma: a read length must be this close to its ideal (static)
TOL_STRETCH = 1e-3      # sigma: largest joint stretch allowed in a row's equilibrium
THERMAL_SDS = 3.0       # a bit is read reliably at kT when its margin is at least this many thermal spreads
ROW_SHARES = (0.8, 0.9)  # progress within a static row: the equilibrium done, then the thermal spread
                         # (measured on a 5232-body circuit: 80 % of the row, 4 %, then the clearance 10 %)


@dataclass
class Report:
    scene: str
    mode: str                          # "static" or "dynamic"
    entries: list = field(default_factory=list)      # one dict per (row, output)
    rows: list = field(default_factory=list)         # one dict per row: state, ok, clearance, stretch...
    seconds: float = 0.0
    params: dict = field(default_factory=dict)

    @property
    def ok(self) -> bool:
        return all(r["ok"] for r in self.rows)

    def failures(self) -> list[dict]:
        return [e for e in self.entries if not e["ok"]]

    def as_dict(self) -> dict:
        return {"scene": self.scene, "mode": self.mode, "ok": self.ok, "seconds": round(self.seconds, 3),
                "params": self.params, "rows": self.rows, "entries": self.entries}


def select_rows(scene: Scene, rows=None) -> list[str]:
    """The rows to verify: all (default) or the given bit strings, checked."""
    if scene.truth_table is None:
        raise MlcError(f"scene {scene.name} has no truth table to verify against", scene.source or scene.name,
                       "add a truth_table mapping input bits to output bits")
    if not scene.probes:
        raise MlcError(f"scene {scene.name} has no probes to read", scene.source or scene.name,
                       "add a probe for each output")
    allrows = scene.states()
    if rows is None:
        return allrows
    out = []
    for r in rows:
        r = str(r).strip()
        if r not in allrows:
            raise MlcError(f"row {r!r} is not an input state of scene {scene.name} (inputs {scene.inputs})",
                           "--rows", f"give {len(scene.inputs)}-bit strings like {allrows[-1]!r}")
        out.append(r)
    return out


def verify_static(scene: Scene, rows=None, tol_length: float = TOL_LENGTH, tol_stretch: float = TOL_STRETCH,
                  clearance: bool = True, progress=None, require_clearance: bool = False,
                  kT: float | None = 1e-5, polish: bool | None = None, jobs: int = 1) -> Report:
    """Static check of every row in ``rows`` (default all), see the module docstring.  With
    ``kT`` (k0 sigma^2; None: skipped) each entry also gets ``thermal_sd``, the probe's
    harmonic thermal spread in that row's equilibrium (sigma,
    :func:`mlc.verify.dynamic.probe_thermal_sd`), and each row ``thermal_ok``: every
    expected bit read with a margin of at least ``THERMAL_SDS`` spreads.  Like clearance it
    is its own verdict and a warning: a row that fails it computes right at rest but not
    reliably at ``kT`` (docs/circuits.md, "Thermal spread").  ``polish``: that of
    :func:`mlc.verify.static.equilibrium`; by default (None) a row's equilibrium is polished
    only when its minimisation stalled with a joint stretched or a muscle strained by more
    than ``POLISH_ABOVE``.  A circuit's continuation goes level by level in logic depth
    (:func:`mlc.circuit.levels.body_levels`; docs/circuits.md, "Level by level").

    ``jobs``: rows solved at once, each in a process of its own (forked, so the scene is
    not copied up front; each process is single-threaded, as OpenBLAS is under mlc).  Every
    row starts from the scene's own pose, so the report is the same, number for number, for
    any ``jobs``; only the order in which rows finish changes.  Memory grows with ``jobs``:
    each process holds one row's solve.  Where processes cannot be forked (not Linux or
    macOS) rows run one at a time.

    ``progress(done, total)``: called as rows finish (``done`` whole rows of ``total``) and,
    with one job, within a row (``done`` fractional: ``ROW_SHARES`` of the row after its
    equilibrium's minimisations, its thermal spread and its clearance), so that one row of
    a large circuit, minutes long, moves its progress bar."""
    states = select_rows(scene, rows)
    t0 = time.perf_counter()
    rep = Report(scene.name, "static", params={"tol_length": tol_length, "tol_stretch": tol_stretch,
                                               "require_clearance": require_clearance, "kT": kT,
                                               "joint_k": scene.meta.get("connector", {}).get("joint_k", 1.0)})
    kw = dict(tol_length=tol_length, tol_stretch=tol_stretch, clearance=clearance,
              require_clearance=require_clearance, kT=kT, polish=polish)
    if int(jobs) > 1:
        results = map_rows(lambda state: _static_row(scene, state, **kw), states, jobs, progress)
    else:                   # one at a time, the progress bar moving within each row too
        index = {s: i for i, s in enumerate(states)}

        def row_with_progress(state):
            within = None if not progress else (lambda f: progress(index[state] + f, len(states)))
            return _static_row(scene, state, within=within, **kw)
        results = map_rows(row_with_progress, states, jobs, progress)
    for entries, row in results:
        rep.entries.extend(entries)
        rep.rows.append(row)
    rep.seconds = time.perf_counter() - t0
    return rep


def _static_row(scene: Scene, state: str, tol_length: float, tol_stretch: float, clearance: bool,
                require_clearance: bool, kT: float | None, polish: bool | None, within=None) -> tuple[list, dict]:
    """One row of :func:`verify_static`: its entries (one per probe) and its summary.
    ``within(f)``: the fraction ``f`` of the row done (``ROW_SHARES``)."""
    from mlc.verify.dynamic import probe_thermal_sd
    from mlc.verify.overlap import clearance as clear
    from mlc.verify.static import equilibrium

    t_row = time.perf_counter()
    eq = equilibrium(scene, state, polish=polish, levels="depth",
                     progress=None if not within else (lambda f: within(ROW_SHARES[0] * f)))
    row_ok = eq.max_joint_stretch <= tol_stretch
    sd = probe_thermal_sd(scene, kT, eq.pos, eq.quat) if kT is not None and kT > 0 else {}
    if within and clearance:
        within(ROW_SHARES[1])
    thermal_ok = True
    entries = []
    for pr in scene.probes:
        entry = probe_entry(scene, pr, state, eq.probes[pr.name], tol_length)
        row_ok &= entry["ok"]
        if pr.name in sd:
            entry["thermal_sd"] = float(sd[pr.name])
            if entry["margin"] is not None and not entry["margin"] >= THERMAL_SDS * sd[pr.name]:
                thermal_ok = False
        entries.append(entry)
    row = {"state": state, "joint_stretch": eq.max_joint_stretch, "muscle_strain": eq.max_muscle_strain,
           "iterations": eq.iterations, "converged": eq.converged, "seconds": 0.0}
    if sd:
        row["thermal_ok"] = thermal_ok
    if clearance:
        c = clear(scene, eq.pos, eq.quat)
        row["clearance"] = c.min_clearance
        row["clearance_pair"] = list(c.pair)
        row["overlaps"] = [list(o) for o in c.overlaps[:10]]
        row["n_overlaps"] = len(c.overlaps)
        row["clearance_ok"] = bool(c.ok())
        if require_clearance:
            row_ok &= c.ok()
    row["ok"] = bool(row_ok)
    row["seconds"] = time.perf_counter() - t_row
    return entries, row


def probe_entry(scene: Scene, pr, state: str, L: float, tol_length: float) -> dict:
    """Probe ``pr`` read at length ``L`` (sigma) in row ``state`` against the truth table:
    expected bit (None where the table says ``-``), the bit read, margin, distance from the
    ideal length, and ``ok`` (the right bit within ``tol_length`` of the ideal)."""
    want = scene.truth_table.get(state)
    k = scene.outputs.index(pr.output)
    bit = None if want is None or want[k] == "-" else int(want[k])
    ideal = None if bit is None else (pr.actuated if bit else pr.rest)
    ok = bit is None or (pr.bit(L) == bit and abs(L - ideal) <= tol_length)
    return {"state": state, "output": pr.output, "expected": bit, "measured": L, "bit": pr.bit(L),
            "margin": None if bit is None else float(pr.margin(L, bit)),
            "error": None if ideal is None else float(abs(L - ideal)), "ok": bool(ok)}


def _can_fork() -> bool:
    import multiprocessing
    return "fork" in multiprocessing.get_all_start_methods()


_FORKED = None            # the row function of map_rows, for its forked processes


def _forked_row(state: str):
    return _FORKED(state)


def map_rows(fn, states: list[str], jobs: int = 1, progress=None) -> list:
    """``[fn(s) for s in states]``, with ``jobs`` > 1 in that many forked processes (each
    inherits ``fn`` and what it holds, so nothing is copied up front; results come back
    pickled).  ``progress(done, total)`` after each row, as rows finish.  Where processes
    cannot be forked rows run one at a time.  A process that dies (out of memory, say) is
    reported as an MlcError naming ``--jobs``; a row's error, or Ctrl-C, drops the rows not
    yet started.  The rows of ``mlc verify --jobs N`` (circuits and robots)."""
    jobs = int(jobs)
    if jobs < 1:
        raise MlcError(f"--jobs must be at least 1, got {jobs}", "--jobs", "e.g. --jobs 2 on a 2-core machine")
    if jobs == 1 or len(states) < 2 or not _can_fork():
        out = []
        for i, state in enumerate(states):
            out.append(fn(state))
            if progress:
                progress(i + 1, len(states))
        return out
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor, as_completed
    from concurrent.futures.process import BrokenProcessPool

    global _FORKED
    _FORKED = fn
    out = [None] * len(states)
    try:
        with ProcessPoolExecutor(max_workers=min(jobs, len(states)),
                                 mp_context=multiprocessing.get_context("fork")) as ex:
            futures = {ex.submit(_forked_row, s): k for k, s in enumerate(states)}
            try:
                for done, fut in enumerate(as_completed(futures), 1):
                    out[futures[fut]] = fut.result()
                    if progress:
                        progress(done, len(states))
            except BaseException:            # a row's error or Ctrl-C: the rows not started are dropped
                ex.shutdown(wait=False, cancel_futures=True)
                raise
    except BrokenProcessPool:
        raise MlcError("a process verifying rows died (out of memory?)", "--jobs",
                       "run with fewer --jobs (each holds one row's solve)") from None
    finally:
        _FORKED = None
    return out


def verify_dynamic(scene: Scene, rows=None, kT: float = 1e-5, seeds: int = 3, scheme: str = "stiff",
                   progress=None, tau: float | None = None, dt: float | None = None) -> Report:
    """Brownian-dynamics check of every row in ``rows`` (default all) over ``seeds`` seeds at
    ``kT`` (k0 sigma^2): :func:`mlc.verify.dynamic.check_scene_dynamic_multi`.  ``tau`` (t0):
    the relaxation time a run lasts at least 3 times (default computed per row, see there);
    ``dt`` (t0): the integrator's step (default mlc.verify.dynamic.DT_LARGE for a circuit of
    more than DENSE_MAX / 6 bodies, else the scheme's own, mlc.verify.dynamic.DT)."""
    from mlc.verify.dynamic import check_scene_dynamic_multi

    states = select_rows(scene, rows)
    if int(seeds) < 1:
        raise MlcError(f"need at least one seed, got {seeds}", "--seeds")
    t0 = time.perf_counter()
    entries = check_scene_dynamic_multi(scene, kT=kT, seeds=int(seeds), scheme=scheme, rows=states,
                                        progress=progress, tau=tau, dt=dt)
    rep = Report(scene.name, "dynamic", params={"kT": kT, "seeds": int(seeds), "scheme": scheme,
                                                "tau": tau, "dt": entries[0]["dt"] if entries else dt})
    for e in entries:
        rep.entries.append({"state": e["state"], "output": e["output"], "expected": e["expected"],
                            "measured": e["measured"], "bit": e.get("bit"), "margin": e["margin"],
                            "relax_time": e.get("relax_time"), "per_seed": e.get("per_seed"), "tau": e.get("tau"),
                            "ok": bool(e["ok"])})
    for s in states:
        es = [e for e in rep.entries if e["state"] == s]
        rts = [e["relax_time"] for e in es]
        rep.rows.append({"state": s, "ok": all(e["ok"] for e in es),
                         "relax_time": None if any(r is None for r in rts) else max(rts, default=0.0)})
    rep.seconds = time.perf_counter() - t0
    return rep


def suggest_joint_k(sd: float, margin: float, params: dict) -> float:
    """A ``--joint-k`` to recompile with so that ``margin`` holds THERMAL_SDS spreads: the
    spread of a width carried by a chain falls as 1/sqrt(k) (docs/circuits.md, "Thermal
    spread"), so k must grow by (THERMAL_SDS sd / margin)^2; doubled, because the gates keep
    part of the compliance, times the scene's present joint_k, rounded up to a power of 10."""
    have = float(params.get("joint_k") or 1.0)
    need = 2.0 * (THERMAL_SDS * sd / max(margin, 1e-9)) ** 2 * have
    return float(min(10.0 ** math.ceil(math.log10(max(need, 10.0))), 1e4))


def format_report(rep: Report) -> str:
    """A table of rows by outputs: the read length (sigma) and margin, then a verdict."""
    outs = list(dict.fromkeys(e["output"] for e in rep.entries))
    by = {(e["state"], e["output"]): e for e in rep.entries}
    head = f"{'row':>8} | " + " | ".join(f"{o:>14}" for o in outs)
    extra = " | clearance   stretch" if rep.mode == "static" else " | relax (t0)"
    lines = [f"{rep.scene}: {rep.mode} verification, {len(rep.rows)} rows x {len(outs)} outputs "
             f"(cells: length sigma / margin; * = wrong)", head + extra, "-" * (len(head) + len(extra))]
    for row in rep.rows:
        cells = []
        for o in outs:
            e = by.get((row["state"], o))
            if e is None:
                cells.append(f"{'':>14}")
                continue
            m = "   dc" if e["margin"] is None else f"{e['margin']:+.3f}"
            cells.append(f"{e['measured']:.3f}/{m}{'*' if not e['ok'] else ' '}".rjust(14))
        if rep.mode == "static":
            tail = f" | {row.get('clearance', float('nan')):+.4f}   {row['joint_stretch']:.1e}"
        else:
            rt = row.get("relax_time")
            tail = f" | {'not relaxed' if rt is None else f'{rt:.2f}'}"
        lines.append(f"{row['state']:>8} | " + " | ".join(cells) + tail + ("" if row["ok"] else "   WRONG"))
    bad = rep.failures()
    bad_rows = [r for r in rep.rows if not r["ok"]]
    if not bad_rows:
        lines.append(f"all {len(rep.rows)} rows correct ({rep.seconds:.1f} s)")
    else:
        for e in bad[:10]:
            want = "don't care" if e["expected"] is None else e["expected"]
            if e["bit"] == e["expected"] and e.get("error") is not None:
                lines.append(f"WRONG: row {e['state']}, output {e['output']}: bit {e['bit']} as expected, but "
                             f"read {e['measured']:.4f} sigma, {e['error']:.4f} sigma from its length (tolerance "
                             f"{rep.params.get('tol_length', TOL_LENGTH)})")
            else:
                lines.append(f"WRONG: row {e['state']}, output {e['output']}: expected {want}, read "
                             f"{e['measured']:.4f} sigma (bit {e['bit']})")
        for r in bad_rows:
            if rep.mode == "static" and not r.get("converged", True):
                lines.append(f"row {r['state']}: the static minimisation ended with energy left in the bonds "
                             f"(joint stretch {r['joint_stretch']:.2e} sigma after {r.get('iterations')} "
                             f"iterations): it stopped short of equilibrium, or the mechanism is jammed; "
                             f"`mlc verify SCENE --dynamic --rows {r['state']}` checks the row by Brownian "
                             f"dynamics (docs/circuits.md, 'Scaling')")
            if rep.mode == "static" and r["joint_stretch"] > rep.params.get("tol_stretch", TOL_STRETCH):
                lines.append(f"WRONG: row {r['state']}: joint stretch {r['joint_stretch']:.2e} sigma "
                             f"(bound {rep.params.get('tol_stretch', TOL_STRETCH)})")
    thermal = [e for e in rep.entries if e.get("thermal_sd") is not None and e["margin"] is not None
               and not e["margin"] >= THERMAL_SDS * e["thermal_sd"]]
    floppy = [e for e in thermal if not math.isfinite(e["thermal_sd"])]
    thermal = [e for e in thermal if math.isfinite(e["thermal_sd"])]
    if floppy:
        rows_f = sorted({e["state"] for e in floppy})
        lines.append(f"WARNING: row {floppy[0]['state']}, output {floppy[0]['output']} (and {len(floppy) - 1} more "
                     f"entries, in {len(rows_f)} rows) sits on a mode of zero stiffness in the pose found: its "
                     f"harmonic thermal spread is unbounded")
    if thermal:
        w = min(thermal, key=lambda e: e["margin"] / e["thermal_sd"] if e["thermal_sd"] > 0 else -1.0)
        rows_t = sorted({e["state"] for e in thermal})
        z = w["margin"] / w["thermal_sd"] if w["thermal_sd"] > 0 else 0.0
        past = 100.0 * 0.5 * math.erfc(z / math.sqrt(2.0))
        lines.append(f"WARNING: thermal spread at kT {rep.params.get('kT')}: row {w['state']}, output {w['output']} "
                     f"fluctuates by {w['thermal_sd']:.3f} sigma (harmonic) against a margin of {w['margin']:.3f} "
                     f"sigma (less than {THERMAL_SDS:g} spreads, in {len(rows_t)} of {len(rep.rows)} rows): its "
                     f"instantaneous length is past the threshold about {past:.2g} % of the time, though a "
                     f"time average reads right; stiffer connector joints narrow it: recompile with "
                     f"`mlc compile --joint-k {suggest_joint_k(w['thermal_sd'], w['margin'], rep.params):g}` "
                     f"(docs/circuits.md, 'Thermal spread')")
    for r in rep.rows:
        if rep.mode == "static" and r.get("overlaps"):
            a, b, d = r["overlaps"][0]
            word = "WRONG" if rep.params.get("require_clearance") else "WARNING"
            lines.append(f"{word}: row {r['state']}: slabs {a} and {b} interpenetrate by {d:.4f} sigma "
                         f"({r.get('n_overlaps', len(r['overlaps']))} pairs); smallest clearance "
                         f"{r['clearance']:+.4f} sigma")
    return "\n".join(lines)


__all__ = ["Report", "format_report", "select_rows", "verify_dynamic", "verify_static"]
