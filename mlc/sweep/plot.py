"""Plots and summaries of a finished sweep (``mlc sweep plot DIR``).

* ``response_grid`` (paper Fig. 5C): one panel per (chain length ``units``, drive
  ``frequency``): rows are chain lengths, columns frequencies from fast to slow; in each,
  the normalised output y(t) = (L - L0)/(L1 - L0) of the lowest seed against time (t0,
  solid) beside the drive (dotted), and the RMS deviation from the drive averaged over
  seeds with its standard deviation.  Any other varied parameter (e.g. ``scheme``)
  draws one line per value.
* ``signal_vs_length`` (paper Fig. 5D): signal length (the probe's length, rest length +
  signal, sigma) after each unit against the number of units, one line per tolerance
  (and per value of any other varied parameter), points at the mean over seeds and time,
  bars of +- the variance over seeds and time (as the paper draws them; the variance is
  also in the summary).
* ``reliability_map`` (beyond the paper, issue 11): the probability that the output reads
  the wrong bit against kT and joint tolerance, pooled over input rows and seeds, with
  the failure boundary (P >= 1 % or a failed run) marked.

The summary (JSON) holds the numbers behind each plot.
"""
from __future__ import annotations

import json
import math
from collections import defaultdict
from pathlib import Path

import numpy as np

from mlc.errors import MlcError
from mlc.sweep.run import TABLE, read_table

_NON_PARAMS = {"run_id", "index", "status", "error", "scene", "measure", "seed", "wall_s"}


def _num(s):
    try:
        return float(s)
    except (TypeError, ValueError):
        return s


def _read(d: Path):
    """(meta, columns, rows) of the sweep results directory ``d``."""
    meta_p = d / "sweep.json"
    if not (d / TABLE).exists() or not meta_p.exists():
        raise MlcError("not a sweep results directory (no results.csv and sweep.json)", str(d),
                       "give the directory `mlc sweep SPEC -o DIR` wrote")
    meta = json.loads(meta_p.read_text("utf-8"))
    cols, rows = read_table(d / TABLE)
    return meta, cols, rows


def _load(d: Path):
    meta, cols, rows = _read(d)
    ok = [r for r in rows if r["status"] == "ok"]
    if not ok:
        raise MlcError("the sweep has no successful runs to plot", str(d / TABLE))
    from mlc.sweep.spec import MEASURE_PARAMS, SIM_PARAMS
    from mlc.sweep.scenes import BUILDERS
    params = list(BUILDERS[meta["scene"]][1]) + list(SIM_PARAMS) + list(MEASURE_PARAMS[meta["measure"]])
    varied = [p for p in params if p in cols and len({r[p] for r in rows}) > 1]
    return meta, ok, varied, len(rows) - len(ok)


def _groups(rows, keys):
    g = defaultdict(list)
    for r in rows:
        g[tuple(r[k] for k in keys)].append(r)
    return g


def _label(keys, vals):
    return ", ".join(f"{k}={v}" for k, v in zip(keys, vals))


def response_grid(d: Path, png: Path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    meta, rows, varied, nfail = _load(d)
    for need in ("units", "frequency"):
        if need not in rows[0]:
            raise MlcError(f"a response grid needs the parameter {need!r} in the table", str(d / TABLE))
    units = sorted({int(r["units"]) for r in rows})
    freqs = sorted({float(r["frequency"]) for r in rows}, reverse=True)
    extra = [k for k in varied if k not in ("units", "frequency")]
    combos = sorted({tuple(r[k] for k in extra) for r in rows})
    colours = ["#1f4e8c", "#c0392b", "#2e8b57", "#8e44ad", "#d68910"]
    fig, axes = plt.subplots(len(units), len(freqs), figsize=(3.6 * len(freqs), 2.5 * len(units)), squeeze=False)
    summary = []
    for i, n in enumerate(units):
        for j, f in enumerate(freqs):
            ax = axes[i][j]
            text = []
            for c, combo in enumerate(combos):
                sel = [r for r in rows if int(r["units"]) == n and float(r["frequency"]) == f
                       and tuple(r[k] for k in extra) == combo]
                if not sel:
                    continue
                rms = np.array([float(r["rms_dev"]) for r in sel])
                ent = {"units": n, "frequency": f, **dict(zip(extra, map(_num, combo))), "seeds": len(sel),
                       "rms_dev_mean": float(rms.mean()), "rms_dev_sd": float(rms.std(ddof=1)) if len(rms) > 1 else 0.0,
                       "rms_dev_l1_mean": float(np.mean([float(r["rms_dev_l1"]) for r in sel])),
                       "rms_dev_all_mean": float(np.mean([float(r["rms_dev_all"]) for r in sel])),
                       "y_high_mean": float(np.mean([float(r["y_high"]) for r in sel])),
                       "y_low_mean": float(np.mean([float(r["y_low"]) for r in sel])),
                       "wall_s_mean": float(np.mean([float(r["wall_s"]) for r in sel]))}
                summary.append(ent)
                first = min(sel, key=lambda r: int(r["seed"]))
                tp = d / "traces" / f"{first['run_id']}.npz"
                if tp.exists():
                    z = np.load(tp)
                    probe = first.get("probe") or "out"
                    if c == 0:
                        ax.plot(z["time"], z["drive"], ls=":", color="k", lw=1.2)
                    ax.plot(z["time"], z[f"y_{probe}"], color=colours[c % len(colours)], lw=1.1,
                            label=_label(extra, combo) if extra else None)
                sd = f" ± {ent['rms_dev_sd'] * 100:.1f}" if len(sel) > 1 else ""
                text.append(f"{(_label(extra, combo) + ': ') if extra else ''}RMS {ent['rms_dev_mean'] * 100:.1f}{sd} %")
            ax.text(0.02, 0.97, "\n".join(text), transform=ax.transAxes, va="top", fontsize=7.5,
                    bbox=dict(facecolor="white", alpha=0.8, edgecolor="none"))
            ax.set_ylim(-0.25, 1.45)
            if i == 0:
                ax.set_title(f"{f:g} $t_0^{{-1}}$", fontsize=10)
            if j == 0:
                ax.set_ylabel(f"{n} unit{'s' if n > 1 else ''}\noutput state", fontsize=9)
            if i == len(units) - 1:
                ax.set_xlabel("time ($t_0$)", fontsize=9)
            ax.tick_params(labelsize=8)
    if extra:
        axes[0][0].legend(fontsize=7, loc="lower right")
    fig.suptitle(f"{meta['name']}: output state (L - L0)/(L1 - L0) (solid, lowest seed) and drive (dotted)\n"
                 f"RMS deviation from the drive over seeds (mean ± sd), first period excluded", fontsize=9)
    fig.tight_layout(rect=(0, 0, 1, 0.93 if len(units) > 1 else 0.8))
    fig.savefig(png, dpi=100)
    plt.close(fig)
    return {"kind": "response_grid", "normalisation": "deviation of (L - L0)/(L1 - L0) from the drive (0/1), "
            "i.e. a fraction of the signal swing |L1 - L0| = 0.5 sigma; rms_dev_l1: as a fraction of L1",
            "failed_runs": nfail, "rows": summary}


def signal_vs_length(d: Path, png: Path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    meta, rows, varied, nfail = _load(d)
    cols = rows[0].keys()
    units = sorted(int(c[1:-5]) for c in cols if c.startswith("u") and c.endswith("_mean") and c[1:-5].isdigit())
    if not units:
        raise MlcError("a signal-vs-length plot needs probes u0, u1, ... (scene gate_chain)", str(d / TABLE))
    keys = varied or []
    groups = _groups(rows, keys)
    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    markers = "osD^vP*X"
    summary = []
    for c, (combo, sel) in enumerate(sorted(groups.items(), key=lambda kv: [_num(v) for v in kv[0]])):
        means, var_tot, var_t, var_s, drift = [], [], [], [], []
        us = [u for u in units if all(r.get(f"u{u}_mean", "") != "" for r in sel)]
        for u in us:
            m = np.array([float(r[f"u{u}_mean"]) for r in sel])
            v = np.array([float(r[f"u{u}_var"]) for r in sel])
            means.append(float(m.mean()))
            var_t.append(float(v.mean()))
            var_s.append(float(m.var()))
            var_tot.append(float(v.mean() + m.var()))     # variance over seeds and time (equal samples per seed)
            if all(r.get(f"u{u}_drift", "") not in ("", "nan") for r in sel):
                drift.append(float(np.mean([float(r[f"u{u}_drift"]) for r in sel])))
        ent = {**dict(zip(keys, map(_num, combo))), "seeds": len(sel), "units": us, "mean": means,
               "var": var_tot, "var_time": var_t, "var_seed_means": var_s,
               "sem": [math.sqrt(v / len(sel)) for v in var_s], "drift": drift}
        summary.append(ent)
        ax.errorbar(us, means, yerr=var_tot, marker=markers[c % len(markers)], ms=4, capsize=2.5, lw=1,
                    label=_label(keys, combo) or "all runs")
    ax.set_xlabel("transmission length (connector units)")
    ax.set_ylabel("signal length ($\\sigma$)")
    ax.set_title(f"{meta['name']}: mean over seeds and time, bars ± variance", fontsize=10)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(png, dpi=100)
    plt.close(fig)
    return {"kind": "signal_vs_length", "failed_runs": nfail,
            "bars": "variance over seeds and time (sigma^2) = mean per-seed time variance + variance of the seed means",
            "sem": "standard error of the mean over seeds (sigma), from the spread of the seed means",
            "drift": "mean over seeds of (second half - first half of the measured window) (sigma)",
            "rows": summary}


#: the failure boundary: a cell fails when its probability of a wrong bit reaches this, or a run failed
FAIL_P = 0.01


def _wrong_probe(cols) -> tuple[str, str]:
    """(probe, column suffix) the map shows: ``out`` if the scene has it, else the last
    probe (``u{n}``: the far end of a chain); ``_off`` (not the right bit: wrong or no bit)
    where the table has it, else ``_wrong`` (tables of older sweeps)."""
    suffix = "_off" if any(c.endswith("_off") for c in cols) else "_wrong"
    probes = [c[:-len(suffix)] for c in cols if c.endswith(suffix)]
    if not probes:
        raise MlcError("a reliability map needs wrong-bit columns ({probe}_wrong: measure steady on a scene "
                       "with a truth table)", "results.csv")
    if "out" in probes:
        return "out", suffix
    return max(probes, key=lambda p: (p[1:].isdigit(), int(p[1:]) if p[1:].isdigit() else 0, p)), suffix


def reliability_map(d: Path, png: Path):
    """Probability of reading the wrong bit against kT (columns) and joint tolerance (rows).

    Per cell (kT, tolerance): every run (seeds x input rows) is pooled; P(wrong) is the
    mean over runs of the fraction of the measured window's samples in which the probe
    (``out``, or the chain's far end) is not the right bit (column ``{probe}_off``: farther
    than half the swing from the expected state's length, so a wrong bit or no bit; tables
    without it use ``{probe}_wrong``, the threshold alone), with the worst single run
    beside it.  A run that failed (the integrator's stability error: bonds torn) counts
    as a failure of the cell.  A cell fails when P(wrong) >= FAIL_P (1 %) or a run failed;
    the failure boundary is drawn, for each tolerance, between the largest kT below every
    failing cell and the next one.  P = 0 is shown as "< 1/n" (n = samples pooled), the
    resolution of the measurement; samples within a run are correlated, so the number of
    independent readings is smaller."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.colors import LogNorm
    meta, cols, allrows = _read(d)
    for need in ("kT", "tolerance"):
        if need not in cols:
            raise MlcError(f"a reliability map needs the parameter {need!r} in the table", str(d / TABLE))
    probe, suffix = _wrong_probe(cols)
    col = probe + suffix
    kts = sorted({float(r["kT"]) for r in allrows})
    tols = sorted({float(r["tolerance"]) for r in allrows})
    P = np.full((len(tols), len(kts)), np.nan)
    worst = np.full_like(P, np.nan)
    nfail = np.zeros(P.shape, int)
    nruns = np.zeros(P.shape, int)
    floor = np.full_like(P, np.nan)
    cells = []
    for i, tol in enumerate(tols):
        for j, kT in enumerate(kts):
            sel = [r for r in allrows if float(r["kT"]) == kT and float(r["tolerance"]) == tol]
            good = [r for r in sel if r["status"] == "ok" and r.get(col, "") not in ("", "nan")]
            nruns[i, j] = len(sel)
            nfail[i, j] = len(sel) - len(good)
            samples = sum(int(float(r.get("samples") or 0)) for r in good)
            if good:
                w = np.array([float(r[col]) for r in good])
                P[i, j], worst[i, j] = float(w.mean()), float(w.max())
                floor[i, j] = 1.0 / max(samples, 1)
            fails = bool(nfail[i, j]) or (good and P[i, j] >= FAIL_P)
            cells.append({"tolerance": tol, "kT": kT, "runs": len(sel), "failed_runs": int(nfail[i, j]),
                          "p_wrong": None if not good else float(P[i, j]),
                          "p_wrong_worst_run": None if not good else float(worst[i, j]),
                          "samples": samples, "resolution": None if not good else float(floor[i, j]),
                          "fails": bool(fails),
                          "errors": sorted({r["error"][:160] for r in sel if r["status"] != "ok"})[:3]})
    fails = np.array([[c["fails"] for c in cells[i * len(kts):(i + 1) * len(kts)]] for i in range(len(tols))])
    # boundary: per tolerance, the first failing kT (all cells from there on are counted failing)
    boundary = []
    for i, tol in enumerate(tols):
        jf = next((j for j in range(len(kts)) if fails[i, j]), None)
        boundary.append({"tolerance": tol, "last_ok_kT": kts[jf - 1] if jf else (kts[-1] if jf is None else None),
                         "first_failing_kT": kts[jf] if jf is not None else None})
    fig, ax = plt.subplots(figsize=(1.0 * len(kts) + 2.8, 0.62 * len(tols) + 2.2))
    shown = np.where(np.isnan(P), np.nan, np.maximum(P, np.nan_to_num(floor, nan=1e-6) * 0.5))
    vmin = max(1e-5, float(np.nanmin(shown)) if np.isfinite(shown).any() else 1e-5)
    im = ax.imshow(shown, origin="lower", aspect="auto", cmap="viridis_r",
                   norm=LogNorm(vmin=min(vmin, 1e-3), vmax=1.0))
    for i in range(len(tols)):
        for j in range(len(kts)):
            if nfail[i, j] and np.isnan(P[i, j]):
                txt = f"failed\n{nfail[i, j]}/{nruns[i, j]}"
            elif np.isnan(P[i, j]):
                txt = "-"
            elif P[i, j] == 0:
                txt = f"<{floor[i, j]:.1e}"
            else:
                txt = f"{100 * P[i, j]:.2g} %"
                if nfail[i, j]:
                    txt += f"\n{nfail[i, j]} failed"
            dark = np.isfinite(shown[i, j]) and shown[i, j] > 0.05
            ax.text(j, i, txt, ha="center", va="center", fontsize=7, color="white" if dark else "black")
            if nfail[i, j]:
                ax.add_patch(plt.Rectangle((j - 0.5, i - 0.5), 1, 1, fill=False, hatch="///", ec="0.4", lw=0))
    # the failure boundary: a staircase between the last good and the first failing column
    xs, ys = [], []
    for i, b in enumerate(boundary):
        x = (kts.index(b["first_failing_kT"]) - 0.5) if b["first_failing_kT"] is not None else len(kts) - 0.5
        xs += [x, x]
        ys += [i - 0.5, i + 0.5]
    ax.plot(xs, ys, color="red", lw=2.5, label=f"failure boundary (P(wrong) >= {100 * FAIL_P:g} % or a failed run)")
    ax.set_xticks(range(len(kts)), [f"{k:g}" for k in kts], fontsize=8)
    ax.set_yticks(range(len(tols)), [f"{t:g}" for t in tols], fontsize=8)
    ax.set_xlabel("kT ($k_0\\sigma^2$)")
    ax.set_ylabel("joint tolerance ($\\sigma$)")
    what = "is not the right bit (wrong or no bit)" if suffix == "_off" else "reads the wrong bit"
    ax.set_title(f"{meta.get('name', d.name)}: probability that {probe} {what}\n"
                 f"(pooled over input rows and seeds)", fontsize=9)
    fig.colorbar(im, ax=ax, label="P(wrong bit)")
    ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.22))
    fig.tight_layout()
    fig.savefig(png, dpi=110)
    plt.close(fig)
    return {"kind": "reliability_map", "probe": probe, "column": col, "fail_p": FAIL_P,
            "definition": "P(wrong) = mean over the cell's runs (input rows x seeds) of the fraction of the "
                          "measured window's samples in which the probe is not the right bit (column); a cell fails at P >= fail_p or when a "
                          "run failed; resolution = 1/(samples pooled) (samples are correlated in time)",
            "failed_runs": int(nfail.sum()), "boundary": boundary, "rows": cells}


PLOTS = {"response_grid": response_grid, "signal_vs_length": signal_vs_length, "reliability_map": reliability_map}


def plot_sweep(d, png=None, kind=None) -> tuple[dict, str]:
    d = Path(d)
    if not d.is_dir():
        raise MlcError("no such sweep results directory", str(d), "run `mlc sweep SPEC -o DIR` first")
    meta = json.loads((d / "sweep.json").read_text("utf-8")) if (d / "sweep.json").exists() else {}
    kind = kind or meta.get("plot")
    if kind not in PLOTS:
        raise MlcError(f"unknown plot {kind!r}", "--kind", f"use one of {', '.join(PLOTS)}")
    return kind, PLOTS[kind]


__all__ = ["PLOTS", "plot_sweep", "reliability_map", "response_grid", "signal_vs_length"]
