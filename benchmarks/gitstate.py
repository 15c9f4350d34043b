"""The commit a benchmark ran on, for its results file: one helper for every script.

``commit()`` is the short hash of HEAD, with ``-dirty`` appended (as ``git describe
--dirty`` does) when a file under ``mlc/`` differs from it, so that a figure measured on
uncommitted code says so; ``"?"`` where git or the repository is not there (a copy of
the scripts outside a checkout).  ``dirty()`` lists those files, ``head()`` is HEAD alone
(for a script that records the list itself).
"""
from __future__ import annotations

import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _git(*args: str) -> str | None:
    try:
        r = subprocess.run(["git", "-C", str(ROOT), *args], capture_output=True, text=True, check=True)
    except (OSError, subprocess.CalledProcessError):
        return None
    return r.stdout


def dirty(paths: tuple[str, ...] = ("mlc",)) -> list[str]:
    """The files under ``paths`` (relative to the checkout) that differ from HEAD or are
    not tracked, sorted; empty when git is not there."""
    out = _git("status", "--porcelain", "--", *paths)
    return sorted(line[3:] for line in (out or "").split("\n") if line.strip())


def head() -> str | None:
    """The short hash of HEAD; None without git."""
    out = _git("rev-parse", "--short", "HEAD")
    return None if out is None else out.strip()


def commit(paths: tuple[str, ...] = ("mlc",)) -> str:
    """Short HEAD, ``-dirty`` when :func:`dirty` lists a file; ``"?"`` without git."""
    h = head()
    if h is None:
        return "?"
    return h + ("-dirty" if dirty(paths) else "")
