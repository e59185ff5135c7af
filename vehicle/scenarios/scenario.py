"""A rig scenario as the simulation plays it: its cases, each a time history of the rig inputs (SI),
the rest phases before them, and the limits beyond which a run has diverged."""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any, Mapping

import numpy as np

from elastokin.vehicle.model.elements import BuildOptions, RigMechanics

#: Scenario types driving one input quantity with a triangle or a sine, and that quantity.
SIGNAL_TYPES = {"pumping": "pad_z", "roll": "pad_z", "lateral_force": "pad_fy",
                "longitudinal_force": "pad_fx", "aligning_torque": "pad_mz"}
#: What a bi-sine may drive: a signal type's pattern, or the rack.
BISINE_INPUTS = (*SIGNAL_TYPES, "rack")
TYPES = (*SIGNAL_TYPES, "rack_step", "double_rack_step", "bisine", "csv")
SHAPES = ("triangle", "sine")

#: The longest time step [s] of a run; each run takes the longest at most this that divides its
#: output interval and resolves its inputs (elastokin.vehicle.scenarios.schedule.timestep).
MAX_TIMESTEP_S = BuildOptions().timestep
#: The shortest time step [s] a run takes: an input faster than it asks for (a 1 µs ramp) is a
#: step to the car, not hours of run.
MIN_TIMESTEP_S = 1e-4
#: Time steps per sine period and per waypoint interval of an input, at least.
STEPS_PER_PERIOD, STEPS_PER_WAYPOINT = 20, 5
#: Largest sine frequency accepted [Hz] (its run steps at 1 ms, 20 steps a period).
MAX_FREQUENCY_HZ = 50.0
#: Largest output rate [Hz] (a run then steps at 1 ms).
MAX_OUTPUT_RATE_HZ = 1000.0
#: Longest input of one case and longest rest phase [s] of simulated time (about 4 min and 4 s of
#: wall time at the car's 15× real time): longer is a typing error.
MAX_INPUT_S, MAX_SETTLE_S = 3600.0, 60.0
#: A scenario's name: plain, for it names its run file out/<name>.mcap.
NAME_PATTERN = re.compile(r"[A-Za-z0-9_][A-Za-z0-9_.\-]*")


def shortest_gap_s(times_s) -> float:
    """The shortest positive interval [s] between successive ``times_s`` (inf if none)."""
    gaps = np.diff(np.asarray(times_s, dtype=float))
    return float(gaps[gaps > 0].min()) if np.any(gaps > 0) else math.inf


@dataclass(frozen=True)
class Waveform:
    """A scalar input against time since the input start: piecewise-linear waypoints plus sines.

    Beyond ``duration_s`` the value at ``duration_s`` is held. Values are SI.
    """

    times_s: tuple[float, ...]                     #: waypoint times, from 0, increasing [s]
    values: tuple[float, ...]                      #: waypoint values [SI]
    sines: tuple[tuple[float, float], ...] = ()    #: (amplitude [SI], frequency [Hz]) added

    @property
    def duration_s(self) -> float:
        """Time of the last waypoint [s]."""
        return self.times_s[-1]

    def longest_step_s(self) -> float:
        """The longest time step [s] that resolves the waveform: STEPS_PER_PERIOD steps per sine period
        and STEPS_PER_WAYPOINT per interval between waypoints (inf for a constant)."""
        return min([shortest_gap_s(self.times_s) / STEPS_PER_WAYPOINT]
                   + [1.0 / (STEPS_PER_PERIOD * f) for _, f in self.sines])

    def __call__(self, t_s: np.ndarray) -> np.ndarray:
        t = np.minimum(np.asarray(t_s, dtype=float), self.duration_s)
        out = np.interp(t, self.times_s, self.values)
        for amplitude, frequency in self.sines:
            out = out + amplitude * np.sin(2.0 * math.pi * frequency * t)
        return out


@dataclass(frozen=True)
class InputTable:
    """A CSV time series: every input channel at the listed times, linear in between (SI)."""

    times_s: np.ndarray        #: (N,), from 0, strictly increasing [s]
    values: np.ndarray         #: (N, len(INPUT_CHANNELS)) [m, N, N·m]


@dataclass(frozen=True)
class Case:
    """One run of a scenario: its label, its parameters as written and its rig inputs (SI)."""

    label: str
    parameters: Mapping[str, Any]     #: the case's keys merged over ``defaults``, file units
    cycles: int                       #: periods of a periodic input (1 otherwise); loops use the last
    waveform: Waveform | None = None  #: scalar input, spread over the channels by ``pattern``
    pattern: tuple[float, ...] = ()   #: gain of ``waveform`` on each of INPUT_CHANNELS
    table: InputTable | None = None   #: or a full time series (csv)

    @property
    def duration_s(self) -> float:
        """Length of the input phase [s] (settle phases not included)."""
        return float(self.table.times_s[-1]) if self.table is not None else self.waveform.duration_s

    def longest_step_s(self) -> float:
        """The longest time step [s] that resolves the input: its waveform's, or one step per sample
        of a table."""
        return self.waveform.longest_step_s() if self.table is None else shortest_gap_s(self.table.times_s)

    def without_last_step(self) -> "Case":
        """The control of a step experiment: this case with its last ramp taken out, the input held
        at the level before it. What its run does over the last hold (the car settling on bushings
        switched on shortly before, the earlier steps still relaxing) is what the run with the step
        does besides the step's own response. ValueError for an input that does not end with a ramp
        and a hold."""
        w = self.waveform
        if w is None or w.sines or len(w.values) < 3 or w.values[-1] != w.values[-2] or w.values[-2] == w.values[-3]:
            raise ValueError(f"case {self.label!r}: its input does not end with a step held, no last ramp to take out")
        return replace(self, waveform=replace(w, values=(*w.values[:-2], w.values[-3], w.values[-3])))

    def inputs(self, t_s: np.ndarray) -> np.ndarray:
        """Rig inputs (len(t_s), len(INPUT_CHANNELS)) at times since the input start [s], SI."""
        t = np.asarray(t_s, dtype=float)
        if self.table is not None:
            tt = np.minimum(t, self.table.times_s[-1])
            return np.column_stack([np.interp(tt, self.table.times_s, col) for col in self.table.values.T])
        return self.waveform(t)[:, None] * np.asarray(self.pattern)[None, :]


@dataclass(frozen=True)
class Settle:
    """Rest phases before the input (the thesis holds 1 s, switches the bushing laws on, holds 1 s)."""

    before_bushings_s: float = 1.0    #: bushing directions linear at their reference stiffness [s]
    before_input_s: float = 1.0       #: bushing laws on (virgin), inputs still at rest [s]


@dataclass(frozen=True)
class Limits:
    """Bounds beyond which a run is declared diverged."""

    translation_m: float = 0.02       #: largest bushing translational deflection [m]
    rotation_rad: float = math.radians(60.0)   #: largest bushing rotation [rad]
    closure_error_m: float = 1e-3     #: largest loop-closure position error [m]


@dataclass(frozen=True)
class Scenario:
    """A validated scenario file, SI inside."""

    name: str
    description: str
    path: Path
    text: str                         #: the file as written (stored in every recording)
    type: str                         #: one of TYPES
    vehicle: Path                     #: vehicle definition file
    bushing_model: str | None         #: read every named bushing set as this model (None: as filed)
    axles: tuple[str, ...]            #: axles receiving the input (rack inputs: ("front",))
    output_rate_hz: float             #: recorded samples per second of simulated time
    settle: Settle
    limits: Limits
    cases: tuple[Case, ...]
    #: the rig's own pads and body clamp as the car meets them (default: the ideal rig)
    rig: RigMechanics = RigMechanics()

    @property
    def x_quantity(self) -> str | None:
        """Per-corner signal that wheel outputs are plotted against (wheel travel, pad force or
        torque), or None for time-only scenarios (rack steps, CSV)."""
        kind = self.cases[0].parameters.get("input", self.type) if self.type == "bisine" else self.type
        driven = SIGNAL_TYPES.get(kind)
        return None if driven is None else ("wheel_travel" if driven == "pad_z" else driven)

    def with_inputs_scaled(self, scale: np.ndarray) -> "Scenario":
        """This scenario with each rig input channel's command (INPUT_CHANNELS order) multiplied by
        ``scale`` (len(INPUT_CHANNELS),): what the car gets from a servo whose own transducer
        misreads (a calibration gain)."""
        scale = np.asarray(scale, dtype=float)
        if np.all(scale == 1.0):
            return self
        return replace(self, cases=tuple(
            replace(c, table=replace(c.table, values=c.table.values * scale[None, :])) if c.table is not None
            else replace(c, pattern=tuple(np.asarray(c.pattern) * scale)) for c in self.cases))

    def without_last_steps(self) -> "Scenario":
        """The control of a step experiment: every case without its last step
        (:meth:`Case.without_last_step`)."""
        return replace(self, cases=tuple(c.without_last_step() for c in self.cases))
