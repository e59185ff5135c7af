"""Writing a run's blocks of samples on a thread of its own while the car runs the next ones: the
compiled stepping and measuring loops release the GIL (elastokin.vehicle.simulation.stepping.run_sampled,
run_road_sampled), so on a machine with two cores the recording costs a run almost no time.
Blocks are written in the order they are given, by one thread: the file is the same, byte for
byte, as one written in line."""

from __future__ import annotations

import queue
import threading
from types import TracebackType

import numpy as np

from elastokin.vehicle.simulation.outputs import SampleBlock
from elastokin.recordings.road_signals import RoadSignalLayout
from elastokin.recordings.run_signals import SignalLayout
from elastokin.recordings.run_writer import RunWriter

#: Blocks waiting to be written at most (the car waits beyond: memory stays bounded).
QUEUE_BLOCKS = 4
_END = None


class BackgroundWriter:
    """Writes the blocks :meth:`put` gives to ``writer`` (their values by ``layout``) on a thread;
    keeps their times [ns, as the file holds them], values and body poses for the run in memory. Leaving the
    ``with`` block writes what is queued; an error of the writing thread is raised in the caller,
    at its next :meth:`put` or on leaving."""

    def __init__(self, writer: RunWriter, layout: SignalLayout | RoadSignalLayout):
        self.writer, self.layout = writer, layout
        #: The blocks' log times [ns] and values (samples, signals), in order.
        self.times_ns: list[np.ndarray] = []
        self.values: list[np.ndarray] = []
        self.body_pos: list[np.ndarray] = []
        self.body_quat_wxyz: list[np.ndarray] = []
        self._queue: queue.Queue[SampleBlock | None] = queue.Queue(maxsize=QUEUE_BLOCKS)
        self._error: BaseException | None = None
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._work, name="vsim-recording", daemon=True)
        self._thread.start()

    def put(self, block: SampleBlock) -> None:
        """Queue ``block`` for writing (waits while the queue is full)."""
        self._raise()
        self._queue.put(block)

    def _work(self) -> None:
        while (block := self._queue.get()) is not _END:
            if self._error is not None or self._stop.is_set():
                continue   # drain: the caller stops at its next put, or has stopped
            try:
                values = self.layout.values(block)
                self.times_ns.append(self.writer.write_block(block.time_s, values, block.body_pos,
                                                             block.body_quat_wxyz))
                self.values.append(values)
                self.body_pos.append(block.body_pos)
                self.body_quat_wxyz.append(block.body_quat_wxyz)
            except BaseException as exc:  # noqa: BLE001 (handed to the caller)
                self._error = exc

    def _raise(self) -> None:
        if self._error is not None:
            raise self._error

    def __enter__(self) -> BackgroundWriter:
        return self

    def __exit__(self, exc_type: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        try:
            self._queue.put(_END)
            self._thread.join()
        except KeyboardInterrupt:
            # a second Ctrl-C: drop what is queued, but let the block being written finish before
            # the file is closed (the writer is not made for two threads at once)
            self._stop.set()
            while self._thread.is_alive():
                try:
                    self._queue.put(_END, timeout=0.1)   # a second end mark is never read
                    self._thread.join()
                except (KeyboardInterrupt, queue.Full):
                    pass
            raise
        if exc_type is None:
            self._raise()
        elif self._error is not None and exc is not None:
            exc.add_note(f"the recording also failed: {type(self._error).__name__}: {self._error}")
