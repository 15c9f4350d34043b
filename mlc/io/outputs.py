"""All outputs of a command, or none: declare them up front, check them before the work,
stage them beside their targets, move them into place only when everything succeeded.

Usage (a command that writes a picture, a JSON file and a directory of parts)::

    from mlc.io.outputs import Outputs

    outs = Outputs(inputs=[args.scene])                       # outputs may not overwrite these
    png = outs.file(args.output, "-o", suffixes=(".png",))    # None when args.output is None
    rep = outs.file(args.report, "--report", suffixes=(".json",))
    parts = outs.directory(args.parts, "--parts")
    with outs:            # checks every location (MlcError naming option, path and fix) before any work
        ...the work...
        draw(..., png.tmp)                 # write each file to its staged path .tmp
        rep.write_text(json.dumps(...))
        parts.write_bytes("hinge.stl", data)
    print("wrote", ", ".join(outs.written))   # all moved into place when the block ended normally

An exception (MlcError, Ctrl-C, a bug) inside the ``with`` block removes the staging area:
nothing is written.  Checks made by :meth:`Outputs.check` (also run by ``with``):

* the path is not empty, not an existing directory (for a file), not a file (for a directory);
* its directory exists (or ``parents=True``) and a file can be created there: a real
  temporary directory is made beside the target (same file system, so the final move is a
  rename), so read-only directories and file systems fail here, before the work;
* its name ends in one of ``suffixes`` (``--draw x.jpg`` cannot get PNG bytes);
* it is not one of the ``inputs`` and no two outputs are the same file;
* the file system has free space.

Special files (``/dev/null``, ``/dev/stdout``, a FIFO) are written directly, first, at
commit time (``/dev/full`` itself is refused by the check).  A staging area left by a command
that called :meth:`Outputs.check` and then failed outside the ``with`` block is removed when the
object is collected or at exit; SIGTERM while outputs are staged is handled like Ctrl-C.  If a
move fails half way, the files already moved are put back as they were.  An output that
is a symbolic link is replaced by the new file (the link's target is left alone), as
with any write-then-rename.
"""
from __future__ import annotations

import atexit
import errno
import os
import shutil
import signal
import stat
import tempfile
import threading
import weakref
from pathlib import Path

from mlc.errors import InternalError, MlcError

_STAGING_PREFIX = ".mlc-staging-"
#: Outputs with a staging area on disk; removed at exit if a command never committed or discarded
_LIVE: "weakref.WeakSet[Outputs]" = weakref.WeakSet()


@atexit.register
def _discard_all() -> None:
    for outs in list(_LIVE):
        outs.discard()


class Terminated(KeyboardInterrupt):
    """SIGTERM (``timeout``, ``kill``) while outputs are staged: handled like Ctrl-C, so the
    staging area is removed and nothing is written."""


def _on_sigterm(signum, frame):
    raise Terminated()


#: /dev/full: a character device that takes no data (found by its device number, Linux 1:7)
_DEV_FULL = os.makedev(1, 7) if hasattr(os, "makedev") else None


def _why(e: OSError) -> str:
    return e.strerror or str(e)


def _fix_for(e: OSError) -> str:
    if e.errno in (errno.EACCES, errno.EPERM):
        return "check its permissions or choose another location"
    if e.errno == errno.EROFS:
        return "it is on a read-only file system; choose another location"
    if e.errno in (errno.ENOSPC, errno.EDQUOT):
        return "free some space or choose another location"
    return "choose another location"


def is_special(path) -> bool:
    """True for an output written in place rather than renamed over: an existing file that is not
    a regular file (a device, a FIFO), and anything under /dev or /proc (``/dev/stdout`` redirected
    to a regular file is a link that a rename would replace)."""
    p = Path(path)
    try:
        st = os.stat(p)
    except OSError:
        return False
    return not stat.S_ISREG(st.st_mode) or str(p.absolute()).startswith(("/dev/", "/proc/"))


def _std_stream(path):
    """sys.stdout or sys.stderr if ``path`` is the file behind it (``/dev/stdout``, ``/dev/fd/2``):
    opening it anew would truncate a redirected file and write over what the command prints."""
    import sys
    try:
        st = os.stat(path)
    except OSError:
        return None
    for stream in (sys.stdout, sys.stderr):
        try:
            fst = os.fstat(stream.fileno())
        except (OSError, ValueError, AttributeError):
            continue
        if (fst.st_dev, fst.st_ino) == (st.st_dev, st.st_ino) and hasattr(stream, "buffer"):
            return stream
    return None


def _existing_ancestor(p: Path) -> Path:
    p = p.absolute()
    while not p.exists() and p != p.parent:
        p = p.parent
    return p


def _key(p: Path) -> str:
    """A canonical name for a (possibly not yet existing) path."""
    return os.path.normcase(os.path.realpath(p))


class _Output:
    def __init__(self, owner: "Outputs", path: Path, option: str):
        self.owner, self.path, self.option = owner, path, option
        self._tmp: Path | None = None
        self.special = False

    @property
    def tmp(self) -> Path:
        """Where to write this output while the command runs (exists after :meth:`Outputs.check`)."""
        if self._tmp is None:
            raise InternalError(f"output {self.path} used before Outputs.check()")
        return self._tmp

    def error(self, message: str, fix: str | None = None) -> MlcError:
        return MlcError(f"{self.path}: {message}", self.option, fix)


class OutputFile(_Output):
    """One output file; write it at :attr:`tmp`, or with :meth:`write_bytes`/:meth:`write_text`."""

    def __init__(self, owner, path, option, suffixes, parents):
        super().__init__(owner, path, option)
        self.suffixes = tuple(s.lower() for s in suffixes) if suffixes else None
        self.parents = parents

    def write_bytes(self, data: bytes) -> None:
        self.tmp.write_bytes(data)

    def write_text(self, text: str) -> None:
        self.tmp.write_text(text, encoding="utf-8")


class OutputDir(_Output):
    """An output directory (created if missing); files in it are written with :meth:`file`."""

    def file(self, name: str) -> Path:
        """Staged path of ``name`` inside the directory (subdirectories are created)."""
        rel = Path(name)
        if rel.is_absolute() or ".." in rel.parts or not rel.parts:
            raise InternalError(f"bad file name {name!r} for output directory {self.path}")
        p = self.tmp / rel
        p.parent.mkdir(parents=True, exist_ok=True)
        return p

    def write_bytes(self, name: str, data: bytes) -> None:
        self.file(name).write_bytes(data)

    def write_text(self, name: str, text: str) -> None:
        self.file(name).write_text(text, encoding="utf-8")


class Outputs:
    """The set of files a command writes; see the module docstring."""

    def __init__(self, inputs=()):
        self.inputs = [Path(p) for p in inputs if p not in (None, "", "-")]
        self.items: list[_Output] = []
        self.written: list[str] = []
        self._staging: dict[str, Path] = {}     # staging root key -> staging directory
        self._checked = False
        self._done = False
        self._old_sigterm = None

    # -- declaring ---------------------------------------------------------------------
    def file(self, path, option: str, suffixes=None, parents: bool = False) -> OutputFile | None:
        """Declare an output file given by ``option``; ``None`` for an absent option (returns None).

        ``suffixes``: allowed name endings, e.g. ``(".png",)``.  ``parents``: create missing
        parent directories (otherwise a missing directory is an error)."""
        if path is None:
            return None
        self._declare_check(path, option)
        out = OutputFile(self, Path(path), option, suffixes, parents)
        self.items.append(out)
        return out

    def directory(self, path, option: str) -> OutputDir | None:
        """Declare an output directory (created with its parents at commit if missing)."""
        if path is None:
            return None
        self._declare_check(path, option)
        out = OutputDir(self, Path(path), option)
        self.items.append(out)
        return out

    def _declare_check(self, path, option):
        if self._checked:
            raise InternalError("outputs declared after Outputs.check()")
        if str(path).strip() == "":
            raise MlcError("empty output path", option, "give a file name")

    # -- checking and staging ------------------------------------------------------------
    def check(self) -> "Outputs":
        """Check every declared output and create the staging area; raise MlcError on the first problem."""
        if self._checked:
            return self
        try:
            self._check_all()
        except BaseException:
            self.discard()
            raise
        self._checked = True
        return self

    def _check_all(self):
        seen: dict[str, _Output] = {}
        for out in self.items:
            p = out.path
            if isinstance(out, OutputFile):
                self._check_file(out)
            elif p.exists() and not p.is_dir():
                raise out.error("exists and is not a directory", "give a directory, or remove the file")
            key = _key(p)
            if key in seen:
                raise out.error(f"is also the output of {seen[key].option}", "give each output its own name")
            seen[key] = out
            for inp in self.inputs:
                if (inp.exists() and p.exists() and os.path.samefile(inp, p)) or _key(inp) == key:
                    raise out.error("is an input of this command; writing it would destroy the input",
                                    "choose another output name")
        for k, out in enumerate(self.items):
            if out.special:
                root = Path(tempfile.gettempdir())
            elif isinstance(out, OutputFile):
                root = out.path.parent if out.path.parent.exists() else _existing_ancestor(out.path.parent)
            else:
                root = _existing_ancestor(out.path)
            stage = self._stage_root(root, out)
            slot = stage / str(k)
            slot.mkdir()
            out._tmp = slot / out.path.name if isinstance(out, OutputFile) else slot

    def _check_file(self, out: OutputFile):
        p = out.path
        try:
            st = os.stat(p)
        except FileNotFoundError:
            st = None
        except NotADirectoryError:
            blocker = next(a for a in reversed(p.absolute().parents) if a.exists() and not a.is_dir())
            raise out.error(f"{blocker} is not a directory", "choose another location") from None
        except OSError as e:
            raise out.error(f"cannot use: {_why(e)}", _fix_for(e)) from None
        if st is not None and stat.S_ISDIR(st.st_mode):
            raise out.error("is a directory", f"give a file name, e.g. {p / ('output' + (out.suffixes or ('',))[0])}")
        out.special = st is not None and is_special(p)
        if out.special:
            if not os.access(p, os.W_OK):
                raise out.error("special file is not writable", "choose another location")
            if stat.S_ISCHR(st.st_mode) and _DEV_FULL is not None and st.st_rdev == _DEV_FULL:
                raise out.error("cannot write: No space left on device (it is /dev/full)", "choose another location")
            return
        if out.suffixes and not p.name.lower().endswith(out.suffixes):
            raise out.error(f"the file name must end in {' or '.join(out.suffixes)}",
                            f"this output is written in that format, e.g. {p.with_suffix(out.suffixes[0]).name}")
        parent = p.parent
        if not parent.exists():
            if out.parents:
                anc = _existing_ancestor(parent)
                if not anc.is_dir():
                    raise out.error(f"{anc} is not a directory", "choose another location")
                return
            raise out.error(f"directory {parent} does not exist", "create it first")
        if not parent.is_dir():
            raise out.error(f"{parent} is not a directory", "choose another location")

    def _stage_root(self, root: Path, out: _Output) -> Path:
        key = _key(root)
        if key not in self._staging:
            try:
                vfs = os.statvfs(root)
                if vfs.f_bavail == 0 and vfs.f_blocks > 0:
                    raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
                self._staging[key] = Path(tempfile.mkdtemp(prefix=_STAGING_PREFIX, dir=root))
            except OSError as e:
                raise out.error(f"cannot write in {root}: {_why(e)}", _fix_for(e)) from None
            _LIVE.add(self)
            self._catch_sigterm()
        return self._staging[key]

    def _catch_sigterm(self) -> None:
        """While outputs are staged, SIGTERM raises :class:`Terminated` (so they are removed)."""
        if self._old_sigterm is not None or threading.current_thread() is not threading.main_thread():
            return
        try:
            if signal.getsignal(signal.SIGTERM) is signal.SIG_DFL:
                signal.signal(signal.SIGTERM, _on_sigterm)
                self._old_sigterm = signal.SIG_DFL
        except (ValueError, OSError, AttributeError):
            pass

    def _release_sigterm(self) -> None:
        if self._old_sigterm is None:
            return
        try:
            if threading.current_thread() is threading.main_thread() and \
                    signal.getsignal(signal.SIGTERM) is _on_sigterm:
                signal.signal(signal.SIGTERM, self._old_sigterm)
        except (ValueError, OSError, AttributeError):
            pass
        self._old_sigterm = None

    # -- the context manager -------------------------------------------------------------
    def __enter__(self) -> "Outputs":
        return self.check()

    def __exit__(self, exc_type, exc, tb):
        if exc_type is None:
            self.commit()
        else:
            self.discard()
        return False

    # -- committing ----------------------------------------------------------------------
    def _moves(self) -> list[tuple[_Output, Path, Path]]:
        moves = []
        for out in self.items:
            if isinstance(out, OutputFile):
                if out.tmp.exists():
                    moves.append((out, out.tmp, out.path))
            else:
                for dirpath, _dirs, files in os.walk(out.tmp):
                    for f in sorted(files):
                        src = Path(dirpath) / f
                        moves.append((out, src, out.path / src.relative_to(out.tmp)))
        return moves

    def commit(self) -> list[str]:
        """Move every staged file into place (special files first); return the paths written."""
        if self._done:
            return self.written
        self.check()
        try:
            moves = self._moves()
            seen: dict[str, _Output] = {}
            for out, _src, dst in moves:
                k = _key(dst)
                if k in seen and seen[k] is not out:
                    raise out.error(f"writes {dst}, which {seen[k].option} also writes",
                                    "give each output its own name")
                seen[k] = out
            for out, src, dst in moves:          # devices and FIFOs: no rename, no undo
                if out.special:
                    try:
                        std = _std_stream(dst)
                        if std is not None:          # /dev/stdout: through the stream, in order
                            std.flush()
                            with open(src, "rb") as g:
                                shutil.copyfileobj(g, std.buffer)
                            std.flush()
                            continue
                        with open(dst, "wb") as f:
                            with open(src, "rb") as g:
                                shutil.copyfileobj(g, f)
                    except OSError as e:
                        raise out.error(f"cannot write: {_why(e)}", _fix_for(e)) from None
            self._move_all([m for m in moves if not m[0].special])
            self.written = [str(dst) for _out, _src, dst in moves]
        finally:
            self.discard()
        return self.written

    def _move_all(self, moves):
        undo: list = []        # ("rmdir", path) | ("unlink", path) | ("restore", backup, path)
        try:
            for out, src, dst in moves:
                missing = []
                d = dst.parent
                while not d.exists():
                    missing.append(d)
                    d = d.parent
                for d in reversed(missing):
                    try:
                        d.mkdir()
                    except OSError as e:
                        raise out.error(f"cannot create directory {d}: {_why(e)}", _fix_for(e)) from None
                    undo.append(("rmdir", d))
                backup = None
                if dst.is_file() and not dst.is_symlink():
                    backup = src.with_name(src.name + ".previous")
                    try:
                        os.link(dst, backup)
                    except OSError:
                        backup = None          # no hard links here: the old file cannot be restored
                try:
                    os.replace(src, dst)
                except OSError as e:
                    raise out.error(f"cannot write {dst}: {_why(e)}", _fix_for(e)) from None
                undo.append(("restore", backup, dst) if backup else ("unlink", dst))
        except BaseException:
            for step in reversed(undo):
                try:
                    if step[0] == "rmdir":
                        step[1].rmdir()
                    elif step[0] == "unlink":
                        step[1].unlink()
                    else:
                        os.replace(step[1], step[2])
                except OSError:
                    pass
            raise

    def discard(self) -> None:
        """Remove the staging area (nothing staged reaches its target)."""
        for d in self._staging.values():
            shutil.rmtree(d, ignore_errors=True)
        self._staging.clear()
        self._done = True
        _LIVE.discard(self)
        self._release_sigterm()

    def __del__(self):          # checked, then abandoned by an exception outside a ``with``
        try:
            if self._staging:
                self.discard()
        except Exception:
            pass
