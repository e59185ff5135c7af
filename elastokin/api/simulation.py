"""A simulation: a vehicle, a scenario and a bushing model, run on the K&C rig or on the road."""

from __future__ import annotations

import math
from contextlib import nullcontext
from dataclasses import replace
from pathlib import Path
from typing import Callable

from elastokin.api.runs import Run, Timing
from elastokin.api.scenarios import load_scenario
from elastokin.api.vehicles import Vehicle, check_bushing_model, load_vehicle
from elastokin.core.errors import InputError
from elastokin.presentation.compile_notice import compile_notice
from elastokin.presentation.progress_bar import ProgressBar
from elastokin.recordings.recorder import play_in_memory, run_scenario
from elastokin.vehicle.scenarios.road_scenario import RoadScenario
from elastokin.vehicle.scenarios.scenario import Scenario
from elastokin.vehicle.scenarios.schedule import Progress

#: What ``progress`` may be: a progress line on stderr (True), none (False), or a function given
#: each :class:`~elastokin.vehicle.scenarios.schedule.Progress`.
ProgressArg = bool | Callable[[Progress], None]


class Simulation:
    """A vehicle made to do a scenario, its bushings read as one model or as their file says.

    Args:
        vehicle: a :class:`~elastokin.api.vehicles.Vehicle`, a vehicle file or a built-in name;
            None: the vehicle the scenario names.
        scenario: a scenario (:func:`~elastokin.api.scenarios.load_scenario`,
            :func:`~elastokin.api.scenarios.scenario_from`), a scenario file or a built-in name
            (``pumping``, ``road/step_steer``).
        bushings: one bushing model on every bushing direction (``linear``, ``sts``, ``rt``,
            ``stvs`` ...: :data:`elastokin.vehicle.model.definition.BUSHING_MODELS`); None: the
            scenario's choice, else as the vehicle file says.
        duration_scale: every duration (settle phases, periods, holds) times this, e.g. 0.1 for
            a quick run (rates then differ from the scenario's, and so do rate-dependent loops).

    Raises:
        InputError: an unknown file or name, a bad ``bushings`` or ``duration_scale``.

    >>> import elastokin
    >>> run = elastokin.Simulation("c_segment", "pumping", duration_scale=0.02).run()
    >>> run.units["camber_fl"], run["camber_fl"].shape == run.t_s.shape
    ('rad', True)
    """

    def __init__(self, vehicle: Vehicle | str | Path | None = None, scenario: Scenario | RoadScenario | str | Path = "pumping",
                 *, bushings: str | None = None, duration_scale: float = 1.0):
        self.scenario = scenario if isinstance(scenario, (Scenario, RoadScenario)) else load_scenario(scenario)
        if vehicle is None:
            vehicle = load_vehicle(self.scenario.vehicle)
        self.vehicle = vehicle if isinstance(vehicle, Vehicle) else load_vehicle(vehicle)
        check_bushing_model(bushings)
        if isinstance(duration_scale, bool) or not isinstance(duration_scale, (int, float)) \
                or not math.isfinite(duration_scale) or duration_scale <= 0:
            raise InputError(f"expected a positive number, got {duration_scale!r}", key="duration_scale")
        self.bushings = bushings
        self.duration_scale = float(duration_scale)

    def __repr__(self) -> str:
        return (f"Simulation({self.vehicle.name!r}, {self.scenario.name!r}, bushings={self.bushings!r}, "
                f"duration_scale={self.duration_scale:g})")

    def run(self, *, progress: ProgressArg = False, output: str | Path | None = None, overwrite: bool = False) -> Run:
        """Play every case of the scenario.

        Args:
            progress: a progress line on stderr (True: with a line for each kernel numba compiles,
                on a first run after an install), or a function called with each
                :class:`~elastokin.vehicle.scenarios.schedule.Progress`.
            output: record the run in this MCAP file while it runs (as ``vsim run`` does), with
                the bodies' poses; None: keep it in memory (:meth:`Run.save` records it later,
                the same bytes).
            overwrite: replace an existing ``output``.

        Returns:
            The :class:`~elastokin.api.runs.Run`.

        Raises:
            InputError: ``output`` exists and not ``overwrite``.
            elastokin.vehicle.simulation.runner.DivergenceError: the simulation diverged (a
                recording is kept, incomplete).

        Warns:
            elastokin.vehicle.simulation.unconverged.UnconvergedBushingSteps: some bushing steps
                did not converge to the solve's tolerance (where and by how much:
                :attr:`Run.unconverged <elastokin.api.runs.Run.unconverged>`).
        """
        scenario = self.scenario if self.bushings is None else replace(self.scenario, bushing_model=self.bushings)
        bar = ProgressBar() if progress is True else None
        call = bar if bar is not None else (progress or None)
        with compile_notice() if bar is not None else nullcontext():
            return self._play(scenario, call, bar, output, overwrite)

    def _play(self, scenario: Scenario | RoadScenario, call: Callable[[Progress], None] | None, bar: ProgressBar | None,
              output: str | Path | None, overwrite: bool) -> Run:
        try:
            if output is None:
                result = play_in_memory(scenario, self.vehicle.definition, duration_scale=self.duration_scale,
                                        progress=call, poses=True)
            else:
                result = run_scenario(scenario, Path(output), overwrite=overwrite, duration_scale=self.duration_scale,
                                      progress=call, vehicle=self.vehicle.definition)
        finally:
            if bar is not None:
                bar.close()
        return Run(result.run, Timing(result.simulated_s, result.wall_s, result.stepping_s))
