"""Synthesis results do not depend on the wall clock (mlc/logic/work.py)."""
import time

from mlc.logic import library as L
from mlc.logic.synth import synthesize


def test_result_independent_of_wall_clock(monkeypatch):
    spec = L.random_function(6, 1, 5)
    ref = synthesize(spec, 2).to_text()
    real = time.perf_counter
    state = {"t": real()}

    def slow_clock():          # a machine on which every reading is a second later
        state["t"] += 1.0
        return state["t"]

    monkeypatch.setattr(time, "perf_counter", slow_clock)
    monkeypatch.setattr(time, "time", slow_clock)
    assert synthesize(spec, 2).to_text() == ref


def test_budget_still_bounds_work():
    """A tiny budget on the work clock stops the search early (a worse, but repeatable, result)."""
    spec = L.random_function(7, 1, 7)
    full = synthesize(spec, 2).num_ands()
    short = [synthesize(spec, 2, time_budget=0.01).num_ands() for _ in range(2)]
    assert short[0] == short[1] > full
