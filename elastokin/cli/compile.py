"""`vsim compile`: compile the simulator's kernels for this machine, once after an install."""

from __future__ import annotations

import argparse
import sys

from elastokin.cli.arguments import positive_count


def _compile(args: argparse.Namespace) -> int:
    from elastokin.api.kernels import compile_kernels

    count, wall_s = compile_kernels(progress=lambda what: print(f"compiling for {what}", file=sys.stderr, flush=True),
                                    workers=args.workers)
    done = f"compiled {count} kernel(s)" if count else "every kernel was in numba's cache already"
    print(f"{done} in {wall_s:.1f} s; later runs load them from the cache")
    return 0


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``compile``."""
    cmd = subparsers.add_parser(
        "compile", help="compile the simulator's kernels for this machine (once after an install, ~20 s)",
        description="Play the rig, the road and the bushing bench for a moment, so that numba compiles every "
                    "kernel they run and keeps it in its cache beside the installed package: the first run "
                    "after an install then costs no more than the next. Without it, the first run of each kind "
                    "compiles its kernels itself (and says so).")
    cmd.add_argument("--workers", type=positive_count, default=2, metavar="N",
                     help="processes at once (default 2: the rig's kernels and the road's side by side)")
    cmd.set_defaults(func=_compile)
