"""A run as the API hands it out: its signals as NumPy arrays in SI, its cases, metrics, figures and
recording."""

from __future__ import annotations

import difflib
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from matplotlib.figure import Figure

from elastokin.analysis.road_metrics import road_metrics
from elastokin.analysis.run_metrics import cases, is_road, run_metrics
from elastokin.api.vehicles import Vehicle
from elastokin.core.units import in_si
from elastokin.presentation.run_plots import pair_figures, time_figures
from elastokin.presentation.run_summary import summary
from elastokin.recordings import run_reader
from elastokin.recordings.run_reader import check_samples
from elastokin.recordings.run_format import Run as RecordedRun
from elastokin.recordings.run_writer import write_run
from elastokin.vehicle.simulation.unconverged import UnconvergedSteps

if TYPE_CHECKING:
    import pandas

#: What :meth:`Run.plot` draws.
PLOTS = ("pairs", "time", "all")


@dataclass(frozen=True)
class Timing:
    """How long a simulated run took: simulated time, wall-clock time of the whole run, and the
    part spent in the compiled stepping loop (its first call, which may compile, excepted) [s]."""

    simulated_s: float
    wall_s: float
    stepping_s: float

    @property
    def real_time_factor(self) -> float:
        """Simulated time per wall-clock time."""
        return self.simulated_s / self.wall_s


class Run:
    """A run of a scenario (simulated, or measured on a rig): N samples of S signals.

    ``run["camber_fl"]`` is a signal as a NumPy array (N,) in SI units (m, rad, N, N·m, s; the
    recording's own units, ``mm`` and ``deg``, are converted once here); :attr:`units` names each
    signal's SI unit, :attr:`recorded_units` the unit its recording holds. Made by
    :meth:`elastokin.Simulation.run` or :func:`load_run`.

    >>> import elastokin
    >>> run = elastokin.Simulation(None, "pumping", duration_scale=0.02).run()
    >>> run.recorded_units["toe_fl"], run.units["toe_fl"], run.units["wheel_travel_fl"]
    ('deg', 'rad', 'm')
    >>> float(run["wheel_travel_fl"].max()) <= 0.060 + 1e-9    # the largest pumping amplitude, 60 mm
    True
    """

    def __init__(self, recorded: RecordedRun, timing: Timing | None = None):
        #: The run as its recording holds it (:class:`elastokin.recordings.run_format.Run`: the
        #: recording's units, the body poses, the metadata).
        self.recorded = recorded
        #: How long the run took (None for a run read from a file).
        self.timing = timing

    @property
    def t_s(self) -> np.ndarray:
        """Time of each sample [s], (N,)."""
        return self.recorded.t_s

    @property
    def names(self) -> list[str]:
        """The signals' names, in the recording's order."""
        return [s.name for s in self.recorded.specs]

    @property
    def recorded_units(self) -> dict[str, str]:
        """Each signal's unit as its recording holds it (``mm``, ``deg``, ``N`` ...)."""
        return dict(self.recorded.units)

    @property
    def units(self) -> dict[str, str]:
        """Each signal's SI unit, as ``run[name]`` gives it."""
        return {n: in_si(u)[0] for n, u in self.recorded.units.items()}

    def __getitem__(self, name: str) -> np.ndarray:
        """The signal ``name`` in SI (``run.units[name]``), (N,).

        Raises:
            KeyError: no such signal (the closest names said).
        """
        if name not in self.recorded.signals:
            close = difflib.get_close_matches(name, self.names, n=5)
            raise KeyError(f"no signal {name!r} in this run" + (f"; did you mean {', '.join(close)}?" if close else
                                                                  f"; it has {len(self.names)}, see run.names"))
        return self.recorded.signals[name] * in_si(self.recorded.units[name])[1]

    def __contains__(self, name: object) -> bool:
        return name in self.recorded.signals

    def __len__(self) -> int:
        return len(self.recorded.t_s)

    def __repr__(self) -> str:
        extra = self.recorded.metadata.extra
        status = "complete" if self.complete else "incomplete"
        return (f"<Run {extra.get('scenario', '?')} ({extra.get('type', '?')}): {len(self.cases)} case(s), "
                f"{len(self)} samples of {len(self.names)} signals, {status}>")

    @property
    def cases(self) -> list[dict[str, Any]]:
        """The run's cases: number (1-based), label, parameters (scenario units), cycles, and their
        times [s] (``start_s``, ``bushings_on_s``, ``input_start_s``, ``end_s``)."""
        return cases(self.recorded)

    @property
    def complete(self) -> bool:
        """Whether the run ran to its end (false: stopped early or read from a damaged file; see :attr:`reason`)."""
        return self.recorded.complete

    @property
    def reason(self) -> str:
        """Why the run is incomplete ("" when complete)."""
        return self.recorded.reason

    @property
    def unconverged(self) -> tuple[UnconvergedSteps, ...]:
        """The bushing directions whose implicit solve stopped at its iteration cap in some steps:
        each one's count, worst residual [m or rad] against the tolerance, and the case and time
        window [s] of the worst (empty for a run without, as every shipped vehicle's runs are, and for
        a measured one). A run with some warns with
        :class:`~elastokin.vehicle.simulation.unconverged.UnconvergedBushingSteps` when it ends."""
        return self.recorded.unconverged

    @property
    def metadata(self) -> dict[str, Any]:
        """What the run says of itself: scenario, type, vehicle file, bushing model, time step,
        duration scale, software version (``software_version``) and revision (``git_revision``)."""
        m = self.recorded.metadata
        return {**m.extra, "source": m.source, "software_version": m.software_version, "git_revision": m.git_revision}

    def case(self, number: int) -> np.ndarray:
        """A mask (N,) of the samples of case ``number`` (1-based), from its start to its end.

        Raises:
            KeyError: no such case.
        """
        if number not in [c["case"] for c in self.cases]:
            raise KeyError(f"no case {number}; the run has cases 1 to {len(self.cases)}")
        return self.recorded.signals["case"] == number

    def metrics(self, vehicle: Vehicle | None = None) -> dict[int, dict[str, Any]]:
        """The metrics ``vsim run`` prints, as data, by case number.

        Args:
            vehicle: the car a rig recording measured: its tyre radius gives the design
                contact-point base that defines the roll angle and the contact points of the
                roll centres (a simulated run carries its own).

        Returns:
            On the road, ``{case: {metric: value}}`` (ISO 7401 / 4138 definitions,
            :data:`elastokin.analysis.road_metrics.METRICS` names their units); on the rig,
            ``{case: {axle: {metric: value}}}`` (the K&C metrics of ``vsim kc``,
            :data:`elastokin.analysis.kc_metrics.METRICS`), for the cases whose input gives them.

        Raises:
            InputError: roll metrics of a rig recording without its ``vehicle``.
        """
        if is_road(self.recorded):
            return _plain(road_metrics(self.recorded))
        return _plain(run_metrics(self.recorded, radius_m=self._radius(vehicle)))

    def summary(self, vehicle: Vehicle | None = None) -> str:
        """The text summary ``vsim run`` prints (gradients, loop widths, metrics, peak deflections);
        ``vehicle`` as for :meth:`metrics`."""
        return summary(self.recorded, self._radius(vehicle))

    @staticmethod
    def _radius(vehicle: Vehicle | None) -> float | None:
        return None if vehicle is None else vehicle.definition.tyre.radius

    def plot(self, what: str = "pairs", *, log_time: bool = False, t0_s: float = 0.0) -> dict[str, Figure]:
        """Matplotlib figures of the run, in the recording's units (as ``vsim plot`` draws them).

        Args:
            what: ``pairs`` (camber, toe ... against wheel travel or force, and every bushing's
                force-deflection loop), ``time`` (each signal group against time) or ``all``.
            log_time: time axes in log scale from ``t0_s`` on (relaxations).
            t0_s: time origin [s].

        Returns:
            ``{name: figure}``, the names ``vsim plot`` gives their PNGs (``pairs_camber``).

        Raises:
            ValueError: ``what`` is none of :data:`PLOTS`.
            InputError: the run holds no sample (a recording cut before its first).
        """
        if what not in PLOTS:
            raise ValueError(f"what={what!r}; expected one of {', '.join(PLOTS)}")
        check_samples(self.recorded, "plot")
        pairs = dict(pair_figures(self.recorded)) if what in ("pairs", "all") else {}
        times = dict(time_figures(self.recorded, log_time=log_time, t0_s=t0_s)) if what in ("time", "all") else {}
        return {**pairs, **times}

    def save(self, path: str | Path, *, overwrite: bool = False) -> Path:
        """Record the run in an MCAP file (the ``vsim run`` format: ``vsim plot``, ``vsim view``,
        Foxglove and Rerun open it); a run kept with its body poses gives the same bytes as ``vsim run``.

        Raises:
            InputError: ``path`` exists and not ``overwrite``, or cannot be written.
        """
        return write_run(self.recorded, Path(path), overwrite=overwrite)

    def to_pandas(self) -> pandas.DataFrame:
        """The signals as a pandas DataFrame in SI (a column per signal, indexed by ``t_s``).

        Raises:
            ImportError: pandas is not installed (``pip install "elastokin[pandas]"``).
        """
        try:
            import pandas
        except ImportError:
            raise ImportError('run.to_pandas() needs pandas: pip install "elastokin[pandas]"') from None
        frame = pandas.DataFrame({n: self[n] for n in self.names}, index=pandas.Index(self.t_s, name="t_s"))
        frame.attrs["units"] = self.units
        return frame


def _plain(value: Any) -> Any:
    """``value`` with NumPy scalars made Python floats, in nested mappings (JSON as it is)."""
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
    return float(value) if isinstance(value, np.floating) else value


def load_run(path: str | Path, *, strict: bool = False) -> Run:
    """Read a recorded run (an MCAP file of ``vsim run``, ``vsim rig import`` or :meth:`Run.save`).

    A damaged file (cut short, a chunk failing its CRC) is read as far as it goes, with a
    :class:`~elastokin.recordings.run_reader.DamagedRecording` warning for each part missing, and
    the run marked incomplete (:attr:`Run.reason` says what is missing).

    Args:
        path: the MCAP file.
        strict: refuse a damaged file instead.

    Raises:
        InputError: the file is missing, unreadable or not a run file; with ``strict``, damaged.
    """
    return Run(run_reader.load_run(path, strict=strict))

