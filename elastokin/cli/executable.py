"""The ``vsim`` executable (and ``python -m elastokin``): :func:`elastokin.cli.main.main` in a process of
its own, with the interpreter's housekeeping set for a process that ends with its command.

The imports (numba's compiler above all) make some 10^5 objects that live as long as the process:
Python's garbage collector walked them again and again while they were made (0.07 s) and once more
in the interpreter's teardown (0.2 s), a tenth of the README's main job
(``tools/benchmarks/vehicle_speed.py``: ``end_to_end_ratio``). Here they are made with the
collector off and then set aside (``gc.freeze``): cycles made later are collected as usual.
"""

from __future__ import annotations

import gc
import os
import signal


def main() -> int:
    """Run ``vsim`` on the command line's arguments; its exit status."""
    # Nothing of vsim renders through MuJoCo (replays are Rerun's): MuJoCo's OpenGL back end is not
    # imported (40 ms). A user's own setting stands.
    if not os.environ.get("MUJOCO_GL"):
        os.environ["MUJOCO_GL"] = "disable"
    gc.disable()
    from elastokin.cli.main import main as vsim

    gc.freeze()
    gc.enable()
    try:
        return vsim()
    except BrokenPipeError:
        # the reader of stdout left (`vsim list | head`): nothing more to say to it, no traceback, and
        # the status of a process ended by SIGPIPE, as the shell's tools give
        os.dup2(os.open(os.devnull, os.O_WRONLY), 1)
        return 128 + signal.SIGPIPE
    finally:
        # what is left is freed by the process's exit, not walked by the teardown's collections (so a
        # __del__ in a reference cycle does not run then: every file and cluster is closed by now)
        gc.freeze()
