"""Line-level lexing shared by the line-oriented parsers (``.tt``, PLA).

``#`` starts a comment that runs to the end of the line; blank lines are skipped;
columns are 1-based, as in every ``file:line:col`` error.
"""
from __future__ import annotations

import re
from collections.abc import Iterator

COMMENT_RE = re.compile(r"#.*$")
DIRECTIVE_RE = re.compile(r"\.([A-Za-z_]+)")
TOKEN_RE = re.compile(r"\S+")


def content_lines(text: str) -> Iterator[tuple[int, str, str, int]]:
    """``(lineno, line, stripped, indent)`` for every line with content: ``line`` without
    its comment and trailing blanks, ``stripped`` without leading blanks either, and
    ``indent`` the number of leading blanks."""
    for lineno, raw in enumerate(text.splitlines(), 1):
        line = COMMENT_RE.sub("", raw).rstrip()
        stripped = line.lstrip()
        if stripped:
            yield lineno, line, stripped, len(line) - len(stripped)


def tokens(line: str, start: int) -> list[tuple[int, str]]:
    """(column, token) pairs of the blank-separated tokens of ``line`` from index ``start``."""
    return [(m.start() + 1, m.group()) for m in TOKEN_RE.finditer(line, start)]
