"""The ``mlc`` command line.

Subcommands live in :mod:`mlc.commands` (one module each, discovered at start-up).
User errors (:class:`~mlc.errors.MlcError`) print one line ``mlc: error: ...`` and exit 2;
internal errors (and any unexpected exception) print one line and exit 3; neither prints a
traceback (set ``MLC_TRACEBACK=1`` to get one for a bug report).  Ctrl-C exits 130.
Standard output that is closed, full (``>/dev/full``) or a broken pipe is handled too:
closed or full is an error (exit 2), a reader that went away (``| head``) is not.
"""
from __future__ import annotations

import argparse
import importlib
import os
import pkgutil
import sys

from mlc import __version__
from mlc.errors import InternalError, MlcError


class _Parser(argparse.ArgumentParser):
    def error(self, message):  # argparse's own errors: one line, exit 2
        self.print_usage(sys.stderr)
        sys.stderr.write(f"mlc: error: {message}\n")
        sys.exit(2)


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="mlc", description="mechanical logic compiler (units: sigma = k0 = gamma = 1)")
    parser.add_argument("--version", action="version", version=f"mlc {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    import mlc.commands as pkg
    for info in sorted(pkgutil.iter_modules(pkg.__path__), key=lambda m: m.name):
        mod = importlib.import_module(f"mlc.commands.{info.name}")
        mod.register(sub)
    return parser


class _Stdout:
    """Standard output whose write errors (other than a broken pipe) are MlcErrors."""

    def __init__(self, inner):
        self._inner = inner

    def _fail(self, e: OSError):
        return MlcError(f"cannot write to standard output: {e.strerror or e}", None,
                        "redirect it to a file or device that accepts data")

    def write(self, s):
        try:
            return self._inner.write(s)
        except BrokenPipeError:
            raise
        except OSError as e:
            raise self._fail(e) from None

    def flush(self):
        try:
            return self._inner.flush()
        except BrokenPipeError:
            raise
        except OSError as e:
            raise self._fail(e) from None

    def __getattr__(self, name):
        return getattr(self._inner, name)


def _quiet_stdout(stream) -> None:
    """After a broken pipe: point fd 1 at /dev/null so the interpreter's final flush is silent."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, stream.fileno())
        os.close(devnull)
    except (OSError, ValueError, AttributeError):
        pass


def _decode_error(e: UnicodeDecodeError) -> str:
    """One line for a non-UTF-8 input file: the file (when a caller frame names it), line, column."""
    data = e.object if isinstance(e.object, (bytes, bytearray)) else b""
    head = data[:e.start]
    line, col = head.count(b"\n") + 1, len(head) - (head.rfind(b"\n") + 1) + 1
    name = None
    tb = e.__traceback__
    while tb is not None:                   # innermost frame with a `path` local wins
        p = tb.tb_frame.f_locals.get("path")
        if isinstance(p, (str, os.PathLike)):
            name = os.fspath(p)
        tb = tb.tb_next
    where = f"{name}:{line}:{col}" if name else f"input file, line {line}, column {col}"
    byte = f"byte 0x{data[e.start]:02x}" if e.start < len(data) else "a byte"
    return f"{where}: {byte} is not UTF-8 text (save the file as UTF-8)"


class _Unraisable:
    """``sys.unraisablehook`` while a command runs: a Ctrl-C that lands in a callback (Numba's
    compiler calls back from LLVM) is noted, not printed as a traceback, and delivered again
    (SIGINT raised anew), so that it takes effect once control is back in Python code.  If the
    compiler fails with an error of its own first, :func:`_main` reports that as the
    interruption it is.  (Noting it alone would lose the Ctrl-C whenever the compile then
    succeeded.)"""

    def __init__(self, inner):
        self.inner, self.hit = inner, False

    def __call__(self, u):
        if isinstance(u.exc_value, KeyboardInterrupt):
            self.hit = True
            import signal
            if signal.getsignal(signal.SIGINT) not in (signal.SIG_IGN, signal.SIG_DFL, None):
                signal.raise_signal(signal.SIGINT)
        else:
            self.inner(u)


def _interrupted(e: BaseException, hook) -> bool:
    """Whether ``e`` comes of a Ctrl-C: one in its chain of causes, or one noted by ``hook``."""
    seen = set()
    while e is not None and id(e) not in seen:
        if isinstance(e, KeyboardInterrupt):
            return True
        seen.add(id(e))
        e = e.__cause__ or e.__context__
    return hook.hit


def main(argv=None) -> int:
    if sys.stdout is None:       # started as `mlc ... >&-`
        if sys.stderr is not None:
            sys.stderr.write("mlc: error: standard output is closed (redirect it, e.g. >/dev/null)\n")
        return 2
    real = sys.stdout
    sys.stdout = _Stdout(real)
    try:
        return _main(argv)
    except MlcError as e:        # from writing standard output while handling another error
        sys.stderr.write(f"mlc: error: {e.format()}\n")
        return 2
    except BrokenPipeError:
        _quiet_stdout(real)
        return 0
    finally:
        if sys.stdout.__class__ is _Stdout:
            sys.stdout = real


def _main(argv) -> int:
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as e:      # --help, --version, usage errors
        sys.stdout.flush()
        return e.code if isinstance(e.code, int) else (0 if e.code is None else 2)
    if not getattr(args, "func", None):
        parser.print_help()
        return 2
    hook = _Unraisable(sys.unraisablehook)
    sys.unraisablehook = hook
    try:
        code = int(args.func(args) or 0)
        sys.stdout.flush()
        return code
    except MlcError as e:
        sys.stderr.write(f"mlc: error: {e.format()}\n")
        return 2
    except InternalError as e:
        sys.stderr.write(f"mlc: internal error: {e} (this is a bug in mlc; please report it)\n")
        return 3
    except KeyboardInterrupt:
        sys.stderr.write("mlc: interrupted\n")
        return 130
    except BrokenPipeError:
        raise
    except UnicodeDecodeError as e:     # a file read as UTF-8 outside mlc.io.yamlsrc.read_text
        sys.stderr.write(f"mlc: error: {_decode_error(e)}\n")
        return 2
    except MemoryError:
        sys.stderr.write("mlc: error: out of memory (try a smaller input or fewer outputs)\n")
        return 2
    except Exception as e:
        if os.environ.get("MLC_TRACEBACK"):
            raise
        if _interrupted(e, hook):            # e.g. Numba's "no compiled object yet" after a Ctrl-C in a compile
            sys.stderr.write("mlc: interrupted\n")
            return 130
        where = ""
        tb = e.__traceback__
        while tb is not None and tb.tb_next is not None:
            tb = tb.tb_next
        if tb is not None:
            where = f" at {os.path.basename(tb.tb_frame.f_code.co_filename)}:{tb.tb_lineno}"
        sys.stderr.write(f"mlc: internal error: {type(e).__name__}: {e}{where} (this is a bug in mlc; please "
                         f"report it; MLC_TRACEBACK=1 shows the traceback)\n")
        return 3
    finally:
        sys.unraisablehook = hook.inner


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
