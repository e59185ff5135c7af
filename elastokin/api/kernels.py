"""Compiling every kernel the simulator runs, once per machine, at a step of its own."""

from __future__ import annotations

import multiprocessing
import os
import sys
import time
from collections.abc import Callable
from concurrent.futures import ProcessPoolExecutor

from elastokin.api.simulation import Simulation
from elastokin.bushings.bench.bench_file import load_bench, run_bench
from elastokin.presentation.compile_notice import compile_notice

#: What is played, shortened, to compile each kind of kernel: (what, scenario or bench programme,
#: duration scale; None for a bench programme).
WARM_UPS = (
    ("the car on the K&C rig", "pumping", 0.005),
    ("the car on the road", "road/step_steer", 0.05),
    ("the bushing bench", "triangle_slow", None),
)


def _warm_up(name: str, scale: float | None, show: bool) -> int:
    """Play one warm-up (in a process of its own); the number of kernels it compiled."""
    with open(os.devnull, "w") as quiet, compile_notice(sys.stderr if show else quiet, why=False) as notice:
        if scale is None:
            run_bench(load_bench(name))
        else:
            Simulation(None, name, duration_scale=scale).run()
    return notice.count


def compile_kernels(progress: Callable[[str], None] | None = None, workers: int = 2) -> tuple[int, float]:
    """Compile (or load from numba's cache) every kernel the rig, the road and the bushing bench
    run, by playing each for a moment, ``workers`` at a time in processes of their own: the first
    run after an install then starts at once. Numba keeps what it compiled in its cache beside the
    installed package.

    Args:
        progress: called with a line as each part is handed to a process (and the compiles are shown
            on stderr).
        workers: processes at once (the rig's and the road's kernels take some 20 and 15 s each on
            one core).

    Returns:
        The number of kernels compiled (0 when the cache held them all) and the wall time [s].
    """
    started = time.perf_counter()
    with ProcessPoolExecutor(workers, mp_context=multiprocessing.get_context("spawn")) as pool:
        jobs = []
        for what, name, scale in WARM_UPS:
            if progress is not None:
                progress(f"{what} ({name})")
            jobs.append(pool.submit(_warm_up, name, scale, progress is not None))
        compiled = sum(job.result() for job in jobs)
    return compiled, time.perf_counter() - started
