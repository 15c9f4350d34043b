"""One-line progress on standard error for anything that can take more than a few seconds.

Silent when standard error is not a terminal (logs and pipes stay clean) and for work
that ends within ``delay`` seconds.  Two forms::

    with Progress("building meshes", total=len(parts)) as bar:   # a bar with an ETA
        for i, p in enumerate(parts):
            ...
            bar.update(i + 1)

    with Progress("computing the design space", expect=30.0):    # no count: a timer
        slow_call()        # a background thread redraws "label  12 s (about 18 s left)"

``expect`` (seconds) is the typical duration measured on a reference machine; the ETA
shown is ``expect - elapsed`` (never below zero), so it is an estimate and says so.

Work whose size is not known in advance but whose steps are (synthesis: the first
decompositions take from milliseconds to a minute with the table's size) names them::

    with Progress("synthesizing f.tt", steps=("decomposing", "improving", "proving")):
        synthesize(spec)   # inside: stage("improving", fraction) -> "...: step 2/3, improving  9 s (40 % of its budget...)"

:func:`stage` moves the open display to a later step; its optional ``fraction`` (a callable
giving how much of that step is done, 0..1: synthesis reads its work clock against the
budget) adds that step's ETA.
"""
from __future__ import annotations

import math
import sys
import threading
import time

_active = None          # the open Progress with steps, which stage() moves


def stage(name: str, fraction=None) -> None:
    """Move the open step display (a :class:`Progress` with ``steps``) to step ``name``, with
    ``fraction()`` (0..1, optional) telling how much of it is done.  Nothing happens without
    such a display, or when ``name`` is not one of its later steps (a nested call repeating one)."""
    p = _active
    if p is not None:
        p._move(name, fraction)


class Progress:
    def __init__(self, label: str, total: int | None = None, expect: float | None = None,
                 show: bool | None = None, delay: float = 2.0, stream=None, steps: tuple | None = None):
        self.label, self.total, self.expect, self.delay = label, total, expect, delay
        self.steps = tuple(steps or ())
        self.step = -1                # index of the current step; -1 before the first
        self.fraction = None
        self.step_t0 = None
        self._outer = None
        self._width = 0               # length of the line last drawn
        self.stream = stream or sys.stderr
        if show is None:
            try:
                show = bool(self.stream.isatty())
            except (AttributeError, ValueError):
                show = False
        self.show = show
        self.t0 = time.perf_counter()
        self.done = 0
        self.drawn = False
        self._stop = threading.Event()
        self._thread = None
        self._lock = threading.Lock()

    def __enter__(self) -> "Progress":
        global _active
        if self.steps:
            self._outer, _active = _active, self
        if self.show and self.total is None:
            self._thread = threading.Thread(target=self._tick, daemon=True)
            self._thread.start()
        return self

    def __exit__(self, *exc):
        self.close()
        return False

    def _tick(self):
        while not self._stop.wait(0.5):
            self._draw()

    def update(self, done: float) -> None:
        """``done`` of ``total`` items finished (a fraction counts the part of an item done
        so far: the bar and the ETA move within a long item, the count shows whole items)."""
        self.done = done
        if self.show:
            self._draw()

    def within(self, base: float, expect: float):
        """A callback ``f(t)`` for one long item after ``base`` finished ones: it moves the bar
        by ``t / expect`` of the item, at most 0.95 of it (``expect``, in the caller's units of
        ``t``, is an estimate; the item's own ``update(base + 1)`` completes it).  None when the
        bar is not shown, so a caller passes it on without a test."""
        if not self.show or not expect > 0:
            return None

        def f(t: float) -> None:
            self.update(base + min(t / expect, 0.95))
        return f

    def _move(self, name: str, fraction=None) -> None:
        k = self.steps.index(name) if name in self.steps else -1
        if k > self.step:
            self.step, self.fraction, self.step_t0 = k, fraction, time.perf_counter()

    def _step_note(self, now: float) -> str:
        """How far the current step is, when its ``fraction`` tells: '' otherwise."""
        try:
            frac = float(self.fraction()) if self.fraction else float("nan")
        except Exception:           # a reader that fails costs the ETA, never the work
            frac = float("nan")
        if not (math.isfinite(frac) and frac > 0):
            return ""
        if frac >= 1:
            return " (its budget spent, finishing)"
        if frac < 0.05:               # too early to extrapolate
            return f" ({100 * frac:.0f} % of its budget)"
        el = now - self.step_t0       # a step may end before its budget: the ETA is a ceiling
        return f" ({100 * frac:.0f} % of its budget, at most about {el / frac - el:.0f} s left)"

    def line(self) -> str:
        """The text of the progress line now (also used by the tests)."""
        now = time.perf_counter()
        el = now - self.t0
        if self.total:
            frac = min(self.done / self.total, 1.0)
            eta = el / frac - el if frac > 0 else float("nan")
            w = 24
            fill = int(w * frac)
            eta_s = f"ETA {eta:5.0f} s" if eta == eta else "ETA     ? s"
            return f"{self.label} [{'#' * fill}{'.' * (w - fill)}] {int(self.done)}/{self.total}  {eta_s}"
        if self.step >= 0:
            return (f"{self.label}: step {self.step + 1}/{len(self.steps)}, {self.steps[self.step]}  {el:4.0f} s"
                    + self._step_note(now))
        s = f"{self.label}  {el:4.0f} s"
        if self.expect:
            s += f" (about {max(self.expect - el, 0):.0f} s left)"
        return s

    def _padded(self) -> str:
        """The line, with blanks over what a longer line drawn before left on the terminal."""
        text = self.line() + "  "
        pad, self._width = max(0, self._width - len(text)), len(text)
        return text + " " * pad

    def _draw(self):
        el = time.perf_counter() - self.t0
        if el < self.delay and not self.drawn:
            return
        with self._lock:
            try:
                self.stream.write("\r" + self._padded())
                self.stream.flush()
            except (OSError, ValueError):
                self.show = False
                return
            self.drawn = True

    def close(self) -> None:
        global _active
        if _active is self:
            _active, self._outer = self._outer, None
        self._stop.set()
        if self._thread is not None:
            self._thread.join()
            self._thread = None
        with self._lock:
            if self.drawn:
                try:
                    self.stream.write("\r" + self._padded() + "\n")
                    self.stream.flush()
                except (OSError, ValueError):
                    pass
                self.drawn = False
