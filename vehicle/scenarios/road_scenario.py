"""A road scenario (format: scenarios/README.md, "Road scenarios"): what the driver does on a flat
road, case by case, read from its file and checked, SI inside.

Types (ISO 7401 for the transient tests, ISO 4138 for the steady state):

* ``step_steer``: from straight running, the steering-wheel angle ramped to ``steering_wheel_deg``
  in ``rise_time_s`` (at most 0.15 s, ISO 7401) and held;
* ``double_step_steer``: a step of ``first_deg``, held ``rest_s``, then a second step of
  ``second_deg`` on top of it, held (fading memory on the road, as the thesis's double rack steps);
* ``sine_steer``: a sine of ``amplitude_deg`` at ``frequency_hz`` for ``cycles`` periods (one case a
  frequency: gain and phase of the responses to the steering);
* ``steady_state_circular``: ``method: constant_speed`` (the steering wheel turned slowly from 0 to
  ``steering_wheel_deg`` at constant speed) or ``constant_steering`` (the angle held, the speed
  raised slowly from ``speed_kmh`` to ``end_speed_kmh``), over ``duration_s``: quasi-steady states;
* ``measured_steer``: a test car's logged steering-wheel angle (and speed, or a constant
  ``speed_kmh``) from the CSV at ``path``, read and resampled as :mod:`elastokin.vehicle.scenarios.road_log`
  says; ``manoeuvre`` says which of the types above it performs, for its metrics (``none``: none).

Every case starts from the car settled at rest, then launched at ``speed_kmh`` and run straight
(:class:`RoadSettle`), the steering at the input's first angle. Angles are steering-wheel angles,
positive to the left (ISO 8855).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Mapping

import numpy as np

from elastokin.vehicle.model.definition import BUSHING_MODELS
from elastokin.vehicle.scenarios.road_log import LOG_KEYS, RoadLog, read_road_log
from elastokin.vehicle.scenarios.scenario import MAX_INPUT_S, MAX_SETTLE_S, Limits, Waveform
from elastokin.vehicle.scenarios.scenario_fields import LIMIT_KEYS, case_fields, limit_values, output_rate, scenario_name, vehicle_file
from elastokin.core.documents import Fields
from elastokin.core.units import DEG, si

#: The manoeuvres a road scenario's metrics know (``elastokin.analysis.road_metrics``).
MANOEUVRES = ("step_steer", "double_step_steer", "sine_steer", "steady_state_circular")
ROAD_TYPES = (*MANOEUVRES, "measured_steer")
#: What a measured_steer scenario's ``manoeuvre`` may say (``none``: no metrics).
MEASURED_MANOEUVRES = ("step_steer", "sine_steer", "steady_state_circular", "none")
#: Top-level keys of a road scenario file.
ROAD_TOP_KEYS = ("name", "description", "type", "vehicle", "bushings", "output_rate_hz", "throttle", "settle",
                 "limits", "defaults", "cases", "manoeuvre")
#: After the input starts, the driver holds the speed (its controller on), or holds the drive
#: torque it had (ISO 7401's fixed throttle).
THROTTLES = ("held_speed", "fixed")
METHODS = ("constant_speed", "constant_steering")
_CASE_KEYS = {
    "step_steer": ("speed_kmh", "steering_wheel_deg", "rise_time_s", "hold_s"),
    "double_step_steer": ("speed_kmh", "first_deg", "rest_s", "second_deg", "hold_s", "rise_time_s"),
    "sine_steer": ("speed_kmh", "amplitude_deg", "frequency_hz", "cycles"),
    "steady_state_circular": ("method", "speed_kmh", "end_speed_kmh", "steering_wheel_deg", "duration_s"),
    "measured_steer": (*LOG_KEYS, "speed_kmh", "frequency_hz"),
}
KMH = si("km/h")
MAX_SPEED_KMH = 250.0
#: Largest steering-wheel angle [deg] (two turns: beyond, a typing error) and sine frequency [Hz].
MAX_STEERING_DEG, MAX_SINE_HZ = 720.0, 5.0
#: ISO 7401's longest steering ramp [s] and the ramp when a file does not say.
MAX_RISE_TIME_S, DEFAULT_RISE_TIME_S = 0.15, 0.1
#: Lowest output rate of a road run [Hz]: the step responses are low-pass filtered at 10 Hz.
MIN_OUTPUT_RATE_HZ = 50.0
#: Time the steering takes to reach its angle before a constant-steering circle speeds up [s].
CIRCLE_STEER_IN_S = 1.0


@dataclass(frozen=True)
class RoadSettle:
    """What precedes each case's input: at rest with the bushings linear (the car settles on its
    tyres, braked), at rest with the bushing laws on, then launched at speed and run straight."""

    at_rest_s: float = 1.0            #: bushing directions linear at their reference stiffness [s]
    bushings_on_s: float = 0.5        #: bushing laws on (virgin), still at rest [s]
    straight_s: float = 2.0           #: at the case's speed, steering straight ahead [s]


@dataclass(frozen=True)
class RoadLimits(Limits):
    """Bounds beyond which a road run stops: the suspension's (:class:`Limits`), the body's
    sideslip (the car spun) and how long a wheel may stay off the ground."""

    sideslip_rad: float = math.radians(20.0)
    wheel_lift_s: float = 0.2


@dataclass(frozen=True)
class RoadCase:
    """One run of a road scenario: the steering-wheel angle and the target speed against time
    since the input started (SI)."""

    label: str
    parameters: Mapping[str, Any]      #: the case's keys merged over ``defaults``, file units
    speed_mps: float                   #: speed of the straight run before the input [m/s]
    steering: Waveform                 #: steering-wheel angle [rad], + to the left
    speed: Waveform                    #: target speed [m/s]
    cycles: int = 1                    #: sine periods (1 otherwise)
    log: RoadLog | None = None         #: a measured case's log (its steering and speed are those above)

    @property
    def duration_s(self) -> float:
        """Length of the input phase [s]."""
        return max(self.steering.duration_s, self.speed.duration_s)

    @property
    def waveform(self) -> Waveform:
        """The case's scalar input (as a rig case's): the steering-wheel angle."""
        return self.steering

    def longest_step_s(self) -> float:
        """The longest time step [s] that resolves the steering and the target speed."""
        return min(self.steering.longest_step_s(), self.speed.longest_step_s())


@dataclass(frozen=True)
class RoadScenario:
    """A validated road scenario file, SI inside."""

    name: str
    description: str
    path: Path
    text: str                          #: the file as written (stored in every recording)
    type: str                          #: one of ROAD_TYPES
    vehicle: Path
    bushing_model: str | None          #: read every bushing direction as this model (None: as filed)
    output_rate_hz: float
    throttle: str                      #: one of THROTTLES
    settle: RoadSettle
    limits: RoadLimits
    cases: tuple[RoadCase, ...]
    manoeuvre: str                     #: which of MANOEUVRES its metrics read it as, or none


def _speed(f: Fields, key: str = "speed_kmh") -> float:
    return f.number(key, positive=True, at_most=MAX_SPEED_KMH, unit="km/h") * KMH


def _angle(f: Fields, key: str) -> float:
    return f.number(key, nonzero=True, at_most=MAX_STEERING_DEG, unit="deg") * DEG


def _rise(f: Fields) -> float:
    rise = f.number("rise_time_s", DEFAULT_RISE_TIME_S, positive=True)
    if rise > MAX_RISE_TIME_S:
        raise f.fail("rise_time_s", f"expected a steering ramp of at most {MAX_RISE_TIME_S} s (ISO 7401), got {rise}")
    return rise


def _steps(rise: float, levels: list[tuple[float, float]]) -> Waveform:
    """From straight ahead, ramp to each (angle [rad], hold [s]) in turn over ``rise`` [s]."""
    times, values, t = [0.0], [0.0], 0.0
    for level, hold in levels:
        times += [t + rise, t + rise + hold]
        values += [level, level]
        t += rise + hold
    return Waveform(tuple(times), tuple(values))


def _measured(f: Fields, label: str, params: dict[str, Any], base_dir: Path, rate_hz: float,
              manoeuvre: str, throttle: str) -> RoadCase:
    """A measured_steer case: its log's steering, and its speed (its first, under a fixed
    throttle) or ``speed_kmh``."""
    log = read_road_log(f, base_dir, rate_hz)
    if "steering_wheel" not in log.channels:
        raise f.fail("columns" if f.has("columns") else "path",
                     f"{log.file}: expected a column of the steering-wheel angle (channel steering_wheel; "
                     f"steering_wheel_deg in the default header), got none")
    times = tuple(log.t_s.tolist())
    steering = Waveform(times, tuple((log.channels["steering_wheel"] * DEG).tolist()))
    if np.max(np.abs(steering.values)) > MAX_STEERING_DEG * DEG:
        raise f.fail("path", f"{log.file}: a steering-wheel angle beyond {MAX_STEERING_DEG:g} deg")
    if "speed" in log.channels:
        if f.has("speed_kmh"):
            raise f.fail("speed_kmh", f"{log.file} logs the speed; give speed_kmh only for a log without one")
        speeds = log.channels["speed"] * KMH
        if not np.all((speeds > 0.0) & (speeds <= MAX_SPEED_KMH * KMH)):
            raise f.fail("path", f"{log.file}: expected a logged speed above 0 and at most {MAX_SPEED_KMH:g} km/h, "
                                 f"got {np.min(speeds) / KMH:.4g} to {np.max(speeds) / KMH:.4g}")
        speed = (Waveform(times, tuple(speeds.tolist())) if throttle == "held_speed"
                 else Waveform((0.0, times[-1]), (float(speeds[0]),) * 2))
    else:
        speed = Waveform((0.0, times[-1]), (_speed(f),) * 2)
    cycles = 1
    if manoeuvre == "sine_steer":
        frequency = f.number("frequency_hz", positive=True, at_most=MAX_SINE_HZ, unit="Hz")
        cycles = int(math.floor(round(times[-1] * frequency, 6)))
        if cycles < 3:
            raise f.fail("frequency_hz", f"{log.file} lasts {times[-1]:.6g} s, {cycles} period(s) at {frequency:g} "
                                         f"Hz; expected at least 3 (the first settles)")
    elif f.has("frequency_hz"):
        raise f.fail("frequency_hz", f"a {manoeuvre} has no frequency; give frequency_hz with manoeuvre: sine_steer")
    return RoadCase(label, params, float(speed.values[0]), steering, speed, cycles, log)


def _case(f: Fields, kind: str, base_dir: Path, rate_hz: float, manoeuvre: str, throttle: str) -> RoadCase:
    params = {k: v for k, (v, _) in f.values.items() if k != "label"}
    label = f.text("label", ", ".join(f"{k}={v}" for k, (v, p) in f.values.items() if p[0] == "cases") or "case")
    if kind == "measured_steer":
        return _measured(f, label, params, base_dir, rate_hz, manoeuvre, throttle)
    speed = _speed(f)
    hold = lambda key: f.number(key, positive=True, at_most=MAX_INPUT_S, unit="s")
    cycles = 1
    if kind == "step_steer":
        steering = _steps(_rise(f), [(_angle(f, "steering_wheel_deg"), hold("hold_s"))])
    elif kind == "double_step_steer":
        first, second = _angle(f, "first_deg"), _angle(f, "second_deg")
        if abs(first + second) > MAX_STEERING_DEG * DEG:
            raise f.fail("second_deg", f"the two steps add up to {math.degrees(first + second):g} deg; expected at "
                                       f"most {MAX_STEERING_DEG:g} deg in magnitude")
        steering = _steps(_rise(f), [(first, hold("rest_s")), (first + second, hold("hold_s"))])
    elif kind == "sine_steer":
        frequency = f.number("frequency_hz", positive=True, at_most=MAX_SINE_HZ, unit="Hz")
        cycles = int(f.number("cycles", 5, positive=True, integer=True, at_most=MAX_INPUT_S * frequency))
        if cycles < 3:
            raise f.fail("cycles", f"expected at least 3 cycles (the first settles; gain and phase come from the "
                                   f"others), got {cycles}")
        steering = Waveform((0.0, cycles / frequency), (0.0, 0.0), ((_angle(f, "amplitude_deg"), frequency),))
    else:
        method = f.choice("method", METHODS)
        duration = hold("duration_s")
        if method == "constant_speed" and f.has("end_speed_kmh"):
            raise f.fail("end_speed_kmh", "a constant_speed circle keeps its speed; give end_speed_kmh only with "
                                          "constant_steering")
        angle = _angle(f, "steering_wheel_deg")
        if method == "constant_speed":
            steering = Waveform((0.0, duration), (0.0, angle))
        else:
            end = _speed(f, "end_speed_kmh")
            steering = Waveform((0.0, CIRCLE_STEER_IN_S), (0.0, angle))
            ramp = (0.0, 2.0 * CIRCLE_STEER_IN_S, 2.0 * CIRCLE_STEER_IN_S + duration)
            return RoadCase(label, params, speed, steering, Waveform(ramp, (speed, speed, end)))
    return RoadCase(label, params, speed, steering, Waveform((0.0, steering.duration_s), (speed, speed)), cycles)


def _road_rate(top: Fields) -> float:
    rate = output_rate(top)
    if rate < MIN_OUTPUT_RATE_HZ:
        raise top.fail("output_rate_hz", f"expected at least {MIN_OUTPUT_RATE_HZ:g} Hz on the road (the responses "
                                         f"are filtered at 10 Hz and timed to the millisecond), got {rate:g}")
    return rate


def parse_road_scenario(top: Fields, kind: str, path: Path, text: str) -> RoadScenario:
    """The road scenario of type ``kind`` whose top-level keys are ``top`` (read from ``path``,
    written as ``text``); InputError naming file:line, key and value."""
    top.check_keys(ROAD_TOP_KEYS, " in a road scenario")
    doc = top.doc
    s = top.fields("settle", ("at_rest_s", "bushings_on_s", "straight_s"), {})
    settle = RoadSettle(*(s.number(k, getattr(RoadSettle, k), nonneg=True, at_most=MAX_SETTLE_S, unit="s")
                          for k in ("at_rest_s", "bushings_on_s", "straight_s")))
    lim = top.fields("limits", (*LIMIT_KEYS, "sideslip_deg", "wheel_lift_s"), {})
    limits = RoadLimits(**limit_values(lim),
                        sideslip_rad=lim.number("sideslip_deg", math.degrees(RoadLimits.sideslip_rad), positive=True,
                                                at_most=90.0, unit="deg") * DEG,
                        wheel_lift_s=lim.number("wheel_lift_s", RoadLimits.wheel_lift_s, positive=True, unit="s"))
    throttle = top.choice("throttle", THROTTLES, "held_speed")
    if kind == "measured_steer":
        manoeuvre = top.choice("manoeuvre", MEASURED_MANOEUVRES)
    elif top.has("manoeuvre"):
        raise top.fail("manoeuvre", f"a {kind} scenario is its own manoeuvre; give manoeuvre only with "
                                    f"type: measured_steer")
    else:
        manoeuvre = kind
    rate = _road_rate(top)
    allowed = (*_CASE_KEYS[kind], "label")
    cases = []
    for i, fields in case_fields(top, allowed):
        case = _case(fields, kind, path.parent, rate, manoeuvre, throttle)
        if case.duration_s > MAX_INPUT_S:
            raise doc.error(("cases", i), f"its input lasts {case.duration_s:.6g} s; expected at most {MAX_INPUT_S:g} s "
                                          f"of simulated time per case")
        if throttle == "fixed" and len(set(case.speed.values)) > 1:
            raise doc.error(("cases", i), "its speed changes during the input; a fixed throttle cannot follow it "
                                          "(throttle: held_speed)")
        cases.append(case)
    return RoadScenario(
        name=scenario_name(top, path), description=top.text("description", ""), path=path, text=text, type=kind,
        vehicle=vehicle_file(top, path), bushing_model=top.choice("bushings", BUSHING_MODELS, None),
        output_rate_hz=rate, throttle=throttle, settle=settle, limits=limits, cases=tuple(cases), manoeuvre=manoeuvre)


def steering_and_speed(case: RoadCase, t_s: np.ndarray, throttle: str) -> tuple[np.ndarray, np.ndarray]:
    """The steering-wheel angle [rad] and the driver's target speed [m/s] (NaN: the throttle held)
    at times since the input started [s]."""
    speed = case.speed(t_s) if throttle == "held_speed" else np.full(len(t_s), np.nan)
    return case.steering(t_s), speed
