"""`vsim`: the command-line entry point.

Each command group lives in its own module exposing ``register(subparsers)``; the module adds its
sub-command with ``set_defaults(func=...)`` where ``func(args) -> int`` is the exit code.
"""

from __future__ import annotations

import argparse
import importlib
import sys

from vsim_core.errors import InputError

#: Modules that register sub-commands, in the order they appear in ``vsim --help``.
COMMAND_MODULES = (
    "vsim_cli.bushing",
    "vsim_cli.view",
    "vsim_cli.model",
    "vsim_cli.kc",
    "vsim_cli.run",
    "vsim_cli.diagnose",
    "vsim_cli.rig",
    "vsim_cli.compare",
)


def build_parser() -> argparse.ArgumentParser:
    """The full ``vsim`` argument parser with every registered command group."""
    parser = argparse.ArgumentParser(prog="vsim", description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True)
    for name in COMMAND_MODULES:
        importlib.import_module(name).register(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Run ``vsim`` with ``argv``; input errors print one clear line and exit with status 2."""
    args = build_parser().parse_args(argv)
    try:
        return int(args.func(args) or 0)
    except InputError as exc:
        print(f"vsim: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
