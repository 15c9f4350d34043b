"""The two error classes of mlc.

* :class:`MlcError` -- the user's input is wrong (a malformed file, an infeasible
  geometry, an unstable time step).  It carries a location (``file:line[:col]``)
  or the name of the offending parameter, and a fix.  The CLI prints it as one
  line and exits with status 2; no traceback, no half-written output.
* :class:`InternalError` -- mlc itself is wrong (a synthesized network that is
  not equivalent to its specification, an IR that fails its ``check()``).  The
  CLI prints it with a request to report it and exits with status 3.
"""
from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True, slots=True)
class Loc:
    """A source location: file name, 1-based line and column (0 = unknown)."""

    file: str = "<input>"
    line: int = 0
    col: int = 0

    def __str__(self) -> str:
        s = self.file
        if self.line:
            s += f":{self.line}"
            if self.col:
                s += f":{self.col}"
        return s


class MlcError(Exception):
    """An error in the user's input.

    ``where`` is a :class:`Loc`, a parameter name such as ``--dt``, or None.
    ``fix`` says what to do about it.
    """

    def __init__(self, message: str, where: "Loc | str | None" = None, fix: str | None = None):
        self.message = message
        self.where = where
        self.fix = fix
        super().__init__(self.format())

    def __reduce__(self):
        # pickled whole (from a worker process, say), not as the formatted text alone
        return (type(self), (self.message, self.where, self.fix))

    def format(self) -> str:
        s = f"{self.where}: " if self.where else ""
        s += self.message
        if self.fix:
            s += f" ({self.fix})"
        return s


class InternalError(Exception):
    """A bug in mlc: an invariant of one of its IRs does not hold."""
