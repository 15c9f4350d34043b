"""CLI subcommands.  Each module here defines ``register(subparsers)``, which adds one or
more subcommands whose ``func(args) -> int`` does the work; :mod:`mlc.cli` discovers them."""
