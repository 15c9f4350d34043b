"""Atomic file output: write to a temporary file beside the target, then rename.

A failed export leaves no partial file behind (the temporary is removed).  An output
location that cannot be written (read-only, a directory, no space) is an MlcError naming
the path.  For a command with several outputs use :mod:`mlc.io.outputs`, which checks
all of them before the work and writes all or none."""
from __future__ import annotations

import errno
import os
import shutil
import tempfile
from contextlib import contextmanager
from pathlib import Path

from mlc.errors import MlcError
from mlc.io.outputs import _fix_for


@contextmanager
def atomic_path(path, suffix: str | None = None):
    """Yield a temporary path in the target's directory; rename it onto ``path`` on success."""
    path = Path(path)
    directory = path.parent if str(path.parent) else Path(".")
    if not directory.is_dir():
        raise MlcError(f"output directory {directory} does not exist", str(path), "create it first")
    if path.is_dir():
        raise MlcError("output path is a directory", str(path), "give a file name")
    if path.exists() and not path.is_file():      # /dev/null, /dev/stdout, a FIFO: never rename over it
        yield from _special(path, suffix)
        return
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=suffix or path.suffix or ".tmp", dir=directory)
    except OSError as e:
        raise MlcError(f"cannot write in {directory}: {e.strerror}", str(path), _fix_for(e)) from None
    os.close(fd)
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(tmp, 0o666 & ~umask)       # mkstemp makes 0600; outputs follow the umask
    try:
        yield Path(tmp)
        try:
            os.replace(tmp, path)
        except OSError as e:
            raise MlcError(f"cannot write: {e.strerror}", str(path), _fix_for(e)) from None
    except OSError as e:
        _unlink(tmp)
        if e.errno in (errno.ENOSPC, errno.EDQUOT, errno.EFBIG):
            raise MlcError(f"cannot write: {e.strerror}", str(path), _fix_for(e)) from None
        raise
    except BaseException:
        _unlink(tmp)
        raise


def _unlink(tmp):
    try:
        os.unlink(tmp)
    except FileNotFoundError:
        pass


def _special(path: Path, suffix):
    """Stage in the temporary directory, then copy into the special file."""
    d = Path(tempfile.mkdtemp(prefix=".mlc-"))
    try:
        tmp = d / ("out" + (suffix or path.suffix or ".tmp"))
        yield tmp
        try:
            with open(path, "wb") as f:
                f.write(tmp.read_bytes())
        except OSError as e:
            raise MlcError(f"cannot write: {e.strerror}", str(path), _fix_for(e)) from None
    finally:
        shutil.rmtree(d, ignore_errors=True)


def write_text(path, text: str) -> None:
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding="utf-8")


def write_bytes(path, data: bytes) -> None:
    with atomic_path(path) as tmp:
        tmp.write_bytes(data)
