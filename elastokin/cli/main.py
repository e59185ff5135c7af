"""`vsim`: the command-line entry point: the parser of every command, and input errors as one line.

Each command lives in its own module exposing ``register(subparsers)``, which adds the command with
``set_defaults(func=...)`` where ``func(args) -> int`` is the exit code (and ``compiles=True`` for a
command that simulates: it says so on stderr when numba compiles). Commands import what they
run when they run, so that ``vsim --help`` loads neither MuJoCo nor matplotlib.
"""

from __future__ import annotations

import argparse
import sys
import warnings
from types import ModuleType

from elastokin.cli import (built_ins, bushing_export, bushing_fit, bushing_import, bushing_run, bushings_on_road,
                           compare, compile, diagnose, kc, model_export, plot, rig_dataset, rig_export, rig_import,
                           rig_measure, road_import, run, sweep, view)
from elastokin.core.provenance import software_version
from elastokin.cli.interrupts import handle_sigterm, status
from elastokin.core.errors import ElastokinWarning, InputError

#: Command groups: name -> (help, description, their commands' modules).
GROUPS: dict[str, tuple[str, str, tuple[ModuleType, ...]]] = {
    "bushing": ("virtual bushing bench, identification, Adams property files",
                "Rubber-bushing models (STS, RT, STVS, ...) on a virtual bench; Adams bushing property files (.bus) "
                "in and out.",
                (bushing_run, bushing_fit, bushing_import, bushing_export)),
    "model": ("vehicle models", "Vehicle models.", (model_export,)),
    "rig": ("measured data: import a K&C rig's CSV exports as a dataset, or measure on the virtual rig",
            "Measured K&C rig data (data/README.md).", (rig_import, rig_dataset, rig_export, rig_measure)),
    "road": ("measured data: a test car's logged road runs", "Measured road runs (scenarios/README.md, "
             "\"Measured manoeuvres\").", (road_import,)),
}
#: Commands and groups in the order of ``vsim --help``.
ORDER: tuple[ModuleType | str, ...] = (built_ins, compile, "bushing", view, plot, "model", kc, run, bushings_on_road, sweep,
                                        diagnose, "rig", "road", compare)


def build_parser() -> argparse.ArgumentParser:
    """The full ``vsim`` argument parser with every command."""
    parser = argparse.ArgumentParser(prog="vsim", description="Full-vehicle transient simulation with hysteretic, "
                                                              "viscoelastic rubber bushings.",
                                     epilog="Built-in vehicles, scenarios and data: `vsim list`. From Python: "
                                            "`import elastokin` (README: From Python).")
    parser.add_argument("--version", action="version", version=f"vsim (elastokin) {software_version()}")
    sub = parser.add_subparsers(dest="command", required=True)
    for entry in ORDER:
        if isinstance(entry, str):
            help_, description, modules = GROUPS[entry]
            group = sub.add_parser(entry, help=help_, description=description)
            commands = group.add_subparsers(dest=f"{entry}_command", required=True)
            for module in modules:
                module.register(commands)
        else:
            entry.register(sub)
    return parser


def _show_warning(message, category, filename, lineno, file=None, line=None) -> None:
    """The product's own warnings (a damaged recording, unconverged bushing steps) as one line of
    vsim's (``vsim: warning: FILE: what is missing``); any other as Python shows it."""
    if issubclass(category, ElastokinWarning):
        print(f"vsim: warning: {message}", file=sys.stderr, flush=True)
    else:
        _python_warning(message, category, filename, lineno, file, line)


_python_warning = warnings.showwarning


def main(argv: list[str] | None = None) -> int:
    """Run ``vsim`` with ``argv``; input errors print one clear line and exit with status 2, Ctrl-C
    and SIGTERM one line and 128 + the signal's number; the product's warnings one line each."""
    warnings.showwarning = _show_warning
    args = build_parser().parse_args(argv)
    handle_sigterm()
    try:
        if getattr(args, "compiles", False):   # a command that simulates says so when numba compiles
            from elastokin.presentation.compile_notice import compile_notice

            with compile_notice():
                return int(args.func(args) or 0)
        return int(args.func(args) or 0)
    except InputError as exc:
        print(f"vsim: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt as exc:
        print(f"vsim: interrupted ({exc or 'SIGINT'}); outputs are as they were, a run's recording is kept incomplete",
              file=sys.stderr)
        return status(exc)


if __name__ == "__main__":
    sys.exit(main())
