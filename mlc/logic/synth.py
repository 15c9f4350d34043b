"""Synthesis driver: specification -> minimum-AND AIG (inversions free), depth tie-break.

See docs/synthesis.md for the passes and effort levels.
"""
from __future__ import annotations

import time

from mlc.errors import MlcError
from mlc.logic import equiv
from mlc.logic.aig import AIG

MAX_EFFORT = 3
STEPS = ("decomposing", "improving", "proving")     # the steps a progress display names (mlc.io.progress.stage)


def synthesize(spec, effort: int = 2, stats: dict | None = None,
               time_budget: float | None = None) -> AIG:
    """Synthesize ``spec`` at ``effort`` 0..3 (= -O0..-O3); the result is proven
    equivalent to ``spec`` (don't cares respected) before it is returned.

    ``stats`` (optional dict) receives timing and the equivalence report;
    ``time_budget`` (seconds) overrides the effort level's default optimisation time.
    """
    if not 0 <= effort <= MAX_EFFORT:
        raise MlcError(f"optimisation level {effort} out of range", "-O", fix="use -O0 .. -O3")
    t0 = time.perf_counter()
    from mlc.logic import opt
    g = opt.optimize(spec, effort, time_budget)
    t1 = time.perf_counter()
    from mlc.io.progress import stage
    stage("proving")
    report = equiv.check_equivalent(g, spec)
    t2 = time.perf_counter()
    if stats is not None:
        stats.update({"synthesis_s": t1 - t0, "equivalence_s": t2 - t1, "equivalence": report,
                      "ands": g.num_ands(), "depth": g.depth()})
    return g
