"""The first simulation after installing (or updating) mlc compiles its Numba kernels: about
20 s of silence on the reference machine, cached on disk afterwards.  :func:`notice` says so,
once, before that happens; it says nothing when the compiled kernels are already cached.

The check reads Numba's cache index of the time-loop kernels (the index is empty or missing
when the cache is cold or stale).  It uses Numba internals, so any surprise there means
"do not know" and no message."""
from __future__ import annotations

import sys

_said = False


def kernels_cached(scheme: str = "stiff", parallel: bool = False) -> bool | None:
    """True when the kernels of ``scheme`` are in Numba's on-disk cache, False when they will be
    compiled, None when that cannot be told."""
    try:
        from mlc.sim import kernels as k
        d = k.kernels(parallel)[{"euler": "euler", "implicit": "eval"}.get(scheme or "stiff", "skrock")]
        return bool(d._cache._cache_file._load_index())
    except Exception:
        return None


def notice(scheme: str = "stiff", parallel: bool = False, stream=None, show: bool | None = None) -> bool:
    """Write one line to ``stream`` (standard error) if the kernels are about to be compiled;
    only when ``stream`` is a terminal unless ``show``.  Returns whether it wrote."""
    global _said
    stream = stream or sys.stderr
    if show is None:
        try:
            show = bool(stream.isatty())
        except (AttributeError, ValueError):
            show = False
    if _said or not show or kernels_cached(scheme, parallel) is not False:
        return False
    try:
        stream.write("mlc: compiling the simulation kernels (first run after installing or updating mlc: "
                     "about 20 s, cached afterwards)\n")
        stream.flush()
    except (OSError, ValueError):
        return False
    _said = True
    return True
