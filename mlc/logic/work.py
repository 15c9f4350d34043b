"""A deterministic work clock for synthesis budgets.

Synthesis passes check a deadline once per node they visit.  Against the wall clock
that makes the result depend on the machine's speed and load; against this clock it
depends only on the input: every check advances the clock by one *tick* whose size
grows with the network being worked on (a check on a larger network stands for more
work), ``TICK_US * sqrt(1 + nodes / 256)`` microseconds of virtual time.  The
constants are calibrated so that virtual seconds track real seconds within about a
factor of two on this project's benchmark machine (90-970 us of real time per check,
from 20-node to 4000-node networks).  The clock is reset at the start of every
optimisation, so the same input gives the same network every time.

Only the -O3 exact-SAT step still uses real time (the SAT solver's time limit).
"""
from __future__ import annotations

import math

TICK_US = 200.0
_ticks = 0          # virtual microseconds (an integer: no rounding depends on history)


def reset() -> None:
    global _ticks
    _ticks = 0


def now(nodes: int = 0, weight: float = 1.0) -> float:
    """Advance the clock by one check on a network of ``nodes`` nodes (``weight`` times
    the usual tick, for a pass whose work per check is known to differ); virtual seconds."""
    global _ticks
    _ticks += int(round(TICK_US * weight * math.sqrt(1.0 + nodes / 256.0)))
    return _ticks * 1e-6
