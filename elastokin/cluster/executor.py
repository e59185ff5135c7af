"""Where a command's runs execute: on a Dask cluster started for it on this machine (the default), on
an existing Dask cluster named by its scheduler's address, or in this process.

Every task is a pure function of its arguments (a vehicle file's text, a scenario, values, a
seed), so any worker computes the bits a serial run computes (on workers of the same CPU type:
numba compiles for the CPU it runs on). A task that raises is an outcome with its reason, not the
end of the others; a worker that dies takes its tasks with it and the scheduler gives them to the
others (a task that was on more dead workers than Dask's ``distributed.scheduler.allowed-failures``,
3, fails with ``KilledWorker``: its reason starts with :data:`WORKERS_DIED`, the run's own fate
unknown). A cluster lost altogether (its scheduler gone) ends the session
with :class:`ClusterLost`: the tasks not finished are not outcomes.

The address comes from the command line (``--scheduler``), else :data:`SCHEDULER_ENV`, else a
local cluster of one single-threaded worker process per core. ``serial`` runs in this process
(no Dask: tests, debugging, profiling).
"""

from __future__ import annotations

import logging
import os
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Any, Callable, Iterator, Sequence

from distributed import Client, KilledWorker, LocalCluster, as_completed

from elastokin.core.errors import InputError

#: The environment variable naming the scheduler when the command line does not.
SCHEDULER_ENV = "VSIM_SCHEDULER"
#: The address that runs every task in this process, one after the other.
SERIAL = "serial"
#: The address that starts a cluster on this machine for the command (the default).
LOCAL = "local"
#: How the reason of a task begins when the workers running it kept dying (Dask's ``KilledWorker``):
#: the cluster's failure, not the task's, so that a resumed sweep makes it again.
WORKERS_DIED = "workers died"


@dataclass(frozen=True)
class Outcome:
    """A finished task: its index in the submitted list and its result, or why it failed."""

    index: int
    result: Any = None
    error: str = ""          #: "" when the task returned


class Executor:
    """Runs tasks; :meth:`each` yields outcomes as they finish, :meth:`map` returns results in order."""

    #: What the executor is, for progress lines and reports.
    description: str = ""

    def each(self, fn: Callable[[Any], Any], items: Sequence[Any]) -> Iterator[Outcome]:
        """``fn`` of every item, as the tasks finish (in any order)."""
        raise NotImplementedError

    def map(self, fn: Callable[[Any], Any], items: Sequence[Any]) -> list[Any]:
        """``fn`` of every item in the items' order; the first failure (in that order) is raised as
        :class:`TaskFailed` once all have finished."""
        out: list[Outcome | None] = [None] * len(items)
        for o in self.each(fn, items):
            out[o.index] = o
        failed = [o for o in out if o is not None and o.error]
        if failed:
            raise TaskFailed(f"task {failed[0].index + 1} of {len(items)} failed: {failed[0].error}")
        return [o.result for o in out if o is not None]


class TaskFailed(RuntimeError):
    """A task of :meth:`Executor.map` failed; the message carries its reason."""


class ClusterLost(RuntimeError):
    """The cluster stopped answering (its scheduler gone): the tasks not finished have no outcome."""


def reason(exc: BaseException) -> str:
    """Why a task failed, in one line: the exception's type and text (for Dask's ``KilledWorker``,
    :data:`WORKERS_DIED` and its text)."""
    text = " ".join(str(exc).split())   # one line, whatever the exception printed
    if isinstance(exc, KilledWorker):
        return f"{WORKERS_DIED} ({text})"
    return f"{type(exc).__name__}: {text}" if text else type(exc).__name__


class SerialExecutor(Executor):
    """Every task in this process, in order."""

    description = "in this process"

    def each(self, fn: Callable[[Any], Any], items: Sequence[Any]) -> Iterator[Outcome]:
        """``fn`` of every item, one after the other."""
        for i, item in enumerate(items):
            try:
                result = fn(item)
            except Exception as exc:  # a task's failure is its outcome (the sweep records it)
                yield Outcome(i, error=reason(exc))
            else:
                yield Outcome(i, result)


class DaskExecutor(Executor):
    """Tasks on a Dask cluster through a ``distributed.Client``."""

    def __init__(self, client: Any, description: str):
        self.client = client
        self.description = description

    def each(self, fn: Callable[[Any], Any], items: Sequence[Any]) -> Iterator[Outcome]:
        """``fn`` of every item as a task of the cluster, yielded as they finish; the tasks not
        finished are cancelled when the caller stops (Ctrl-C)."""
        # pure=False: a task is run even if an equal one ran before (results are not kept on workers)
        futures = self.client.map(fn, list(items), pure=False)
        index = {f.key: i for i, f in enumerate(futures)}
        try:
            for future in as_completed(futures):
                i = index[future.key]
                try:
                    if future.status not in ("finished", "error"):   # cancelled, or lost with the scheduler
                        raise ClusterLost(f"{self.description} stopped answering (task {i + 1} of "
                                          f"{len(futures)}: {future.status})")
                    outcome = (Outcome(i, future.result()) if future.status == "finished"
                               else Outcome(i, error=reason(future.exception())))
                except OSError as exc:   # the connection to the scheduler or a worker went down
                    raise ClusterLost(f"{self.description} stopped answering ({reason(exc)})") from None
                yield outcome
                future.release()
        finally:
            try:
                self.client.cancel([f for f in futures if not f.done()])
            except Exception:   # noqa: BLE001 - a client already cut off has nothing left to cancel
                pass


def scheduler_address(given: str | None) -> str:
    """The scheduler a command uses: ``given`` (the command line), else :data:`SCHEDULER_ENV`, else
    :data:`LOCAL`."""
    return given or os.environ.get(SCHEDULER_ENV) or LOCAL


@contextmanager
def executor(scheduler: str | None = None, workers: int | None = None) -> Iterator[Executor]:
    """An :class:`Executor` for a command (module docstring): ``scheduler`` is an address
    (``tcp://host:8786``), :data:`LOCAL` or :data:`SERIAL` (None: :func:`scheduler_address`);
    ``workers`` sizes a local cluster (default: the cores this process may use). A local cluster is
    closed on leaving; an existing one is left running."""
    address = scheduler_address(scheduler)
    if address == SERIAL:
        yield SerialExecutor()
        return
    if address == LOCAL:
        n = workers or len(os.sched_getaffinity(0)) or 1
        # one thread per worker process: a run holds the GIL outside its compiled stepping
        # the dashboard on a free port: a second cluster on the machine must not collide with the first
        with LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=":0",
                          silence_logs=logging.CRITICAL) as cluster, Client(cluster) as client:
            yield DaskExecutor(client, f"a local Dask cluster of {n} worker process{'es' if n > 1 else ''}")
        return
    try:
        client = Client(address, timeout="20s")
    except (OSError, ValueError, TypeError) as exc:   # nobody there, or not an address
        raise InputError(f"no Dask scheduler answers at {address!r} ({exc}); expected the address a running "
                         f"scheduler prints (tcp://HOST:8786), '{LOCAL}' or '{SERIAL}'",
                         key="--scheduler / " + SCHEDULER_ENV) from None
    # a lost scheduler is reported once, as ClusterLost, not by the client's reconnection attempts
    logging.getLogger("distributed.client").setLevel(logging.CRITICAL)
    with client:
        yield DaskExecutor(client, f"the Dask cluster at {address}")
