"""The ``mlc`` command line.

Subcommands live in :mod:`mlc.commands` (one module each, discovered at start-up).
User errors (:class:`~mlc.errors.MlcError`) print one line ``mlc: error: ...`` and exit 2;
internal errors print one line and exit 3; neither prints a traceback.
"""
from __future__ import annotations

import argparse
import importlib
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


def main(argv=None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if not getattr(args, "func", None):
        parser.print_help()
        return 2
    try:
        return int(args.func(args) or 0)
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
        return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
