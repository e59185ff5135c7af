"""Argument types the commands share: output paths, checked as soon as the command line is read
(before any work), and durations scales that are finite and positive."""

from __future__ import annotations

import argparse
import math
from pathlib import Path

from vsim_core.errors import InputError
from vsim_core.files import check_output


def output_file(text: str) -> Path:
    """A file path an output can be written to (:func:`vsim_core.files.check_output`)."""
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
