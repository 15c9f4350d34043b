"""Where Numba keeps mlc's compiled kernels when mlc is installed read-only.

Numba caches a ``cache=True`` kernel beside its source file (``__pycache__``) or, failing
that, in the user's cache directory (``~/.cache/numba``).  With neither writable -- a
system-wide install run by a user whose home is missing or read-only -- decorating the first
kernel fails with "RuntimeError: cannot cache function ...: no locator available for file".

:func:`ensure` (called by ``import mlc``, before Numba is loaded) finds that out with a few
system calls and then points ``NUMBA_CACHE_DIR`` at a private directory under the system's
temporary directory (``mlc-numba-cache-UID``, mode 0700, reused while it exists), saying so
once, when it creates it.  A ``NUMBA_CACHE_DIR`` set by the user is left as it is.
"""
from __future__ import annotations

import os
import sys

KERNEL_PACKAGES = ("sim", "logic", "mesh", "circuit")   # mlc's subpackages with cache=True kernels


def _writable(d: str) -> bool:
    """Whether files can be created in directory ``d`` (made if missing), as Numba checks it."""
    try:
        os.makedirs(d, exist_ok=True)
        probe = os.path.join(d, f".mlc-probe-{os.getpid()}")
        os.close(os.open(probe, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o600))
        os.unlink(probe)
        return True
    except OSError:
        return False


def user_cache_dir() -> str:
    """Numba's user-wide cache directory (its appdirs' ``user_cache_dir`` for "numba")."""
    if sys.platform == "darwin":
        return os.path.expanduser("~/Library/Caches/numba")
    return os.path.join(os.environ.get("XDG_CACHE_HOME") or os.path.expanduser("~/.cache"), "numba")


def _private_dir(path: str) -> bool:
    """Whether ``path`` is a real directory of this user that no one else may write or read."""
    try:
        st = os.lstat(path)
    except OSError:
        return False
    import stat
    return stat.S_ISDIR(st.st_mode) and st.st_uid == os.getuid() and not st.st_mode & 0o077


def ensure(package_dir: str | None = None, stream=None) -> str | None:
    """Set ``NUMBA_CACHE_DIR`` to a private temporary directory when Numba could cache mlc's
    kernels neither in the package (``package_dir``, default mlc's own) nor in the user's cache
    directory; return that directory, or None when nothing needed doing."""
    if os.environ.get("NUMBA_CACHE_DIR") or not hasattr(os, "getuid"):
        return None
    package_dir = package_dir or os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    if all(_writable(os.path.join(package_dir, p, "__pycache__")) for p in KERNEL_PACKAGES
           if os.path.isdir(os.path.join(package_dir, p))):
        return None
    if _writable(user_cache_dir()):
        return None
    import tempfile
    path = os.path.join(tempfile.gettempdir(), f"mlc-numba-cache-{os.getuid()}")
    created = False
    try:
        os.mkdir(path, 0o700)
        created = True
    except OSError:
        pass
    if not (_private_dir(path) and _writable(path)):    # someone else's, or not a directory: one of our own
        try:
            path, created = tempfile.mkdtemp(prefix="mlc-numba-cache-"), True
        except OSError:
            return None                                 # nowhere to write: Numba will say so
    os.environ["NUMBA_CACHE_DIR"] = path
    if "numba" in sys.modules:                          # loaded already: its config has read the environment
        sys.modules["numba"].config.CACHE_DIR = path
    if created:
        try:
            (stream or sys.stderr).write(f"mlc: note: mlc's folder and {user_cache_dir()} are not writable; "
                                         f"compiled kernels are cached in {path} (NUMBA_CACHE_DIR chooses)\n")
        except (OSError, ValueError, AttributeError):
            pass
    return path
