"""How many cores this process may use: the one answer shared by every command that sizes
its threads (``mlc simulate --threads``'s limit, the mesher's threaded minimisations)."""
from __future__ import annotations

import os


def usable_cores() -> int:
    """The cores this process may run on (its CPU affinity, which a container or ``taskset``
    narrows), else the machine's count; at least 1."""
    try:
        n = len(os.sched_getaffinity(0))
    except (AttributeError, OSError):       # no affinity on this platform
        n = os.cpu_count() or 1
    return max(1, n)
