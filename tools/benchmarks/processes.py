"""Running a command in a fresh process as a user would, with its wall time and peak memory (the
benchmarks' end-to-end figures)."""

from __future__ import annotations

import os
import subprocess
import tempfile
import time
from dataclasses import dataclass


@dataclass(frozen=True)
class Measured:
    """A finished process: its exit status, output, wall time [s] and peak resident memory [MB]."""

    returncode: int
    stdout: str
    stderr: str
    wall_s: float
    peak_rss_mb: float


def run_measured(command: list[str], cwd: str | None = None) -> Measured:
    """Run ``command``; its own peak RSS comes from wait4 (not the maximum over all children so far)."""
    with tempfile.TemporaryFile("w+") as err:
        started = time.perf_counter()
        process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=err, text=True, cwd=cwd)
        stdout = process.stdout.read()
        _, status, usage = os.wait4(process.pid, 0)
        wall = time.perf_counter() - started
        process.returncode = os.waitstatus_to_exitcode(status)   # reaped here: Popen must not wait again
        process.stdout.close()
        err.seek(0)
        return Measured(process.returncode, stdout, err.read(), wall, usage.ru_maxrss / 1024)
