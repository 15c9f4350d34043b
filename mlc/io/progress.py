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
"""
from __future__ import annotations

import sys
import threading
import time


class Progress:
    def __init__(self, label: str, total: int | None = None, expect: float | None = None,
                 show: bool | None = None, delay: float = 2.0, stream=None):
        self.label, self.total, self.expect, self.delay = label, total, expect, delay
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

    def line(self) -> str:
        """The text of the progress line now (also used by the tests)."""
        el = time.perf_counter() - self.t0
        if self.total:
            frac = min(self.done / self.total, 1.0)
            eta = el / frac - el if frac > 0 else float("nan")
            w = 24
            fill = int(w * frac)
            eta_s = f"ETA {eta:5.0f} s" if eta == eta else "ETA     ? s"
            return f"{self.label} [{'#' * fill}{'.' * (w - fill)}] {int(self.done)}/{self.total}  {eta_s}"
        s = f"{self.label}  {el:4.0f} s"
        if self.expect:
            s += f" (about {max(self.expect - el, 0):.0f} s left)"
        return s

    def _draw(self):
        el = time.perf_counter() - self.t0
        if el < self.delay and not self.drawn:
            return
        with self._lock:
            try:
                self.stream.write("\r" + self.line() + "  ")
                self.stream.flush()
            except (OSError, ValueError):
                self.show = False
                return
            self.drawn = True

    def close(self) -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join()
            self._thread = None
        with self._lock:
            if self.drawn:
                try:
                    self.stream.write("\r" + self.line() + "  \n")
                    self.stream.flush()
                except (OSError, ValueError):
                    pass
                self.drawn = False
