"""The commit a benchmark ran on, for its results file: one helper for every script.

``commit()`` is the short hash of HEAD, with ``-dirty`` appended (as ``git describe
--dirty`` does) when a file under ``mlc/`` differs from it, so that a figure measured on
uncommitted code says so; ``"?"`` where git or the repository is not there (a copy of
the scripts outside a checkout).  ``dirty()`` lists those files.
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


def commit(paths: tuple[str, ...] = ("mlc",)) -> str:
    """Short HEAD, ``-dirty`` when :func:`dirty` lists a file; ``"?"`` without git."""
    head = _git("rev-parse", "--short", "HEAD")
    if head is None:
        return "?"
    return head.strip() + ("-dirty" if dirty(paths) else "")
