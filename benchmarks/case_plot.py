"""One bar chart of per-case figures beside a benchmark's results file: one helper for the
scripts that compare a few cases (pieces of a circuit, a scene) under two builds.

``case_bars(out_json, cases, series, ylabel)`` writes ``out_json`` with ``.png`` for its suffix:
one group of bars per case (labelled by the case's file stem, or its name), one bar per series
``(values, label)``, a reference line at ``ref`` when given, a text above each group from
``notes`` when given, a log scale with ``log``.  Written atomically, as the results file.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from mlc.io.atomic import atomic_path


def case_name(case: str) -> str:
    """A case's label: a scene file's stem, else the case's own name."""
    return Path(case).stem if case.endswith(".yaml") else case


def case_bars(out_json, cases: list, series: list, ylabel: str, *, ref: float | None = None,
              notes: list | None = None, log: bool = False, size=(6, 3.5)) -> str:
    """Draw the bars (see the module doc); returns the picture's path."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=size)
    x = np.arange(len(cases))
    w = 0.8 / max(len(series), 1) if len(series) > 1 else 0.5
    for k, (values, label) in enumerate(series):
        ax.bar(x + (k - 0.5 * (len(series) - 1)) * w, values, w, label=label)
    if notes:
        top = [max(s[0][k] for s in series) for k in range(len(cases))]
        for k, text in enumerate(notes):
            ax.text(k, top[k], text, ha="center", va="bottom", fontsize=8)
    if ref is not None:
        ax.axhline(ref, color="k", lw=0.8)
    if log:
        ax.set_yscale("log")
    ax.set_xticks(x, [case_name(c["case"]) for c in cases])
    ax.set_ylabel(ylabel)
    if len(series) > 1:
        ax.legend(fontsize=8)
    fig.tight_layout()
    png = str(Path(out_json).with_suffix(".png"))
    with atomic_path(png) as tmp:
        fig.savefig(tmp, format="png", dpi=120)
    plt.close(fig)
    return png
