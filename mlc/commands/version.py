"""``mlc info``: versions and where the standard library lives."""
from __future__ import annotations

import json


def register(sub):
    p = sub.add_parser("info", help="print the version and the data paths of this installation")
    p.add_argument("--json", action="store_true")
    p.set_defaults(func=run)


def run(args) -> int:
    from importlib import resources

    import mlc
    info = {"version": mlc.__version__, "stdlib_gates": str(resources.files("mlc.stdlib_gates"))}
    print(json.dumps(info) if args.json else "\n".join(f"{k}: {v}" for k, v in info.items()))
    return 0
