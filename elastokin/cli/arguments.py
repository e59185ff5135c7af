"""Argument types the commands share: output paths, checked as soon as the command line is read
(before any work), and durations scales that are finite and positive."""

from __future__ import annotations

import argparse
import math
from pathlib import Path

from elastokin.core.errors import InputError
from elastokin.core.files import check_output


def output_file(text: str) -> Path:
    """A file path an output can be written to (:func:`elastokin.core.files.check_output`)."""
    return _output(text, folder=False)


def output_folder(text: str) -> Path:
    """A folder path outputs can be written into."""
    return _output(text, folder=True)


def _output(text: str, folder: bool) -> Path:
    try:
        return check_output(text, folder=folder)
    except InputError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def positive_scale(text: str) -> float:
    """A finite factor > 0 (``--duration-scale``)."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
    if not (math.isfinite(value) and value > 0.0):
        raise argparse.ArgumentTypeError(f"expected a finite number > 0, got {text!r}")
    return value


def add_scheduler_options(parser: argparse.ArgumentParser, scope: str = "") -> None:
    """``--scheduler`` and ``--workers``: where a command's runs execute (:mod:`elastokin.cluster.executor`)."""
    parser.add_argument("--scheduler", metavar="ADDRESS",
                        help=f"{scope}the runs on a running Dask scheduler (tcp://HOST:8786), 'local' (a cluster on "
                             f"this machine for the command) or 'serial' (this process); default: $VSIM_SCHEDULER, "
                             f"else local")
    parser.add_argument("--workers", type=positive_count, metavar="N",
                        help="worker processes of a local cluster (default: one per core)")


def positive_count(text: str) -> int:
    """A whole number >= 1 (``--workers``)."""
    if not text.strip().isdigit() or int(text) < 1:
        raise argparse.ArgumentTypeError(f"expected a whole number >= 1, got {text!r}")
    return int(text)


def add_strict_option(parser: argparse.ArgumentParser) -> None:
    """``--strict``: a damaged recording refused rather than read as far as it goes."""
    parser.add_argument("--strict", action="store_true",
                        help="refuse a damaged recording (cut short, a chunk failing its CRC) instead of reading it "
                             "as far as it goes with a warning")


def add_vehicle_options(parser: argparse.ArgumentParser, scope: str = "") -> None:
    """``--vehicle`` (a file or a built-in name) and ``--bushing-model`` (one model on every
    bushing direction); ``scope`` prefixes their help (``with --kc: ``)."""
    from elastokin.core.shipped import DEFAULT_VEHICLE
    from elastokin.vehicle.model.definition import BUSHING_MODELS

    parser.add_argument("--vehicle", default=DEFAULT_VEHICLE.stem, metavar="VEHICLE",
                        help=f"{scope}vehicle file, or the name of a built-in one (default: %(default)s)")
    parser.add_argument("--bushing-model", choices=BUSHING_MODELS, default=None,
                        help=f"{scope}put this model on every bushing direction (models/vehicles/README.md)")
