"""Saying so when numba compiles: the first run after an install compiles the stepping kernels for
this machine (about 20 s on 2 cores) and numba's cache keeps them for every later run; a line on
``stream`` at each kernel compiled, with its time, so that a first run does not look stuck."""

from __future__ import annotations

import sys
import time
from collections.abc import Iterator
from contextlib import contextmanager
from typing import TextIO

from numba.core import event


class CompileNotice(event.Listener):
    """Writes a line per kernel numba compiles (a callee compiled into its caller is not counted
    again), and keeps their number and time."""

    def __init__(self, stream: TextIO, why: bool = True):
        self.stream, self.why = stream, why
        self.started: list[float] = []
        self.count, self.seconds = 0, 0.0

    def on_start(self, e: event.Event) -> None:
        """A compile began: the first says why it happens."""
        if self.why and not self.started and self.count == 0:
            print("compiling the kernels for this machine: once after an install, then numba's cache keeps "
                  "them (`vsim compile` does it up front)", file=self.stream, flush=True)
        self.started.append(time.perf_counter())

    def on_end(self, e: event.Event) -> None:
        """A compile ended: the outermost ones are shown."""
        took = time.perf_counter() - self.started.pop()
        if not self.started:
            func = e.data["dispatcher"].py_func
            self.count += 1
            self.seconds += took
            print(f"  compiled {func.__module__}.{func.__qualname__} in {took:.1f} s", file=self.stream, flush=True)


@contextmanager
def compile_notice(stream: TextIO | None = None, why: bool = True) -> Iterator[CompileNotice]:
    """Show what numba compiles on ``stream`` (default stderr) while the block runs (``why``: with
    a first line saying why it happens)."""
    notice = CompileNotice(stream if stream is not None else sys.stderr, why)
    with event.install_listener("numba:compile", notice):
        yield notice
