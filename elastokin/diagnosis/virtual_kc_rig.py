"""The virtual rig at the K&C level (spec measured-data §1): a truth vehicle = a baseline vehicle +
effects from the K&C catalogue (or outside it) + a rig's measurement imperfections, played through
the K&C campaign and written as a K&C dataset (:mod:`elastokin.recordings.kc_dataset`) that carries no
trace of the truth.

TRUTH.yaml (K&C level; paths relative to this file)::

    level: kc
    vehicle: ../../models/vehicles/c_segment.yaml   # the baseline (default: the default vehicle)
    scenarios: [../../scenarios/kc/pumping.yaml]     # default: scenarios/kc: pumping, roll, lateral_force, rack_step
    duration_scale: 1.0                              # optional, > 0 (quick runs)
    effects:                                         # zero or more; parameters in the catalogue's units
      - {cause: mullins, location: e1_rear.y, mullins: 0.15}            # a bushing cause: bushing.direction
      - {cause: coupling, location: e1_rear, directions: [x, z], stiffness: 70.0}   # N/mm
      - {cause: strut_friction, strut_friction: 200.0}                 # N, both struts
      - {cause: beam_torsion, beam_torsion_scale: 1.6}
      - {cause: spring_rate, location: front, spring_rate_scale: 0.9}  # also anti_roll_bar (front), damper_force
      - {cause: backlash, location: e1_front.y, backlash: 0.2}          # mm, outside the catalogue
    measurement: {angle_noise_deg: 0.003, ...}       # MEASUREMENT_DEFAULTS keys
    chain: {toe: {delay_ms: 15, low_pass_hz: 9}, ...}  # optional: elastokin/diagnosis/rig_chain.py
    rig: {pad_friction_n: 12, clamp_roll_deg_per_knm: 0.003}   # optional: the rig's own mechanics
    seed: 0

The rig measures what :func:`elastokin.recordings.rig_recordings.measured_channels` lists. Every measured channel gets
a zero error drawn once per dataset (uniform in ± its offset), Gaussian noise and the quantisation
of its sensor, by unit: deg (angle), mm (length), N (force), N·m (torque), after the truth's
measurement ``chain`` if it has one (gains, filters, lags, drifts, coloured noise: drawn from a
stream of their own, so that a truth without a chain measures as before). The rig inputs (pad
displacements, forces and torques, rack) are the commanded values and are written as commanded. A
truth's ``rig`` (:mod:`elastokin.vehicle.scenarios.rig_file`) gives the rig's pads friction and
compliance and its body clamp compliance: the car plays every scenario on that rig (on the
scenario's own ``rig`` where the truth has none), the recordings saying nothing of it.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, Callable, Mapping

import numpy as np

from elastokin.vehicle.model.definition import VehicleDefinition
from elastokin.vehicle.model.elements import RigMechanics
from elastokin.vehicle.model.vehicle_file import load_vehicle
from elastokin.vehicle.scenarios.channels import INPUT_CHANNELS
from elastokin.vehicle.scenarios.rig_file import parse_rig
from elastokin.vehicle.scenarios.scenario import Scenario
from elastokin.vehicle.scenarios.scenario_file import load_scenario
from elastokin.core.documents import Document
from elastokin.core.errors import InputError
from elastokin.core.files import atomic_directory, is_file
from elastokin.core.shipped import DEFAULT_VEHICLE, KC_SCENARIO_DIR
from elastokin.diagnosis.kc_catalogue import (BUSHING_CAUSES, DIRECTIONS, VEHICLE_CAUSES, Hypothesis, extended_vehicle,
                                         locations, parameters)
from elastokin.diagnosis.measurement import parse_measurement, quantise, required, truth_number, truth_values
from elastokin.diagnosis.rig_chain import ChannelChain, parse_chain, seen, servoed
from elastokin.recordings.kc_dataset import write_kc_rig_yaml
from elastokin.recordings.recorder import simulate
from elastokin.recordings.rig_recordings import measured_channels, write_rig_recording

#: The K&C campaign the virtual rig plays when a truth names no scenarios, in this order.
DEFAULT_SCENARIOS = tuple(KC_SCENARIO_DIR / f"{name}.yaml" for name in ("pumping", "roll", "lateral_force",
                                                                          "rack_step"))
#: Measurement imperfections of a K&C rig: key -> default.
MEASUREMENT_DEFAULTS = {
    "angle_noise_deg": 0.003,         # camber, toe, steer sensor noise, standard deviation [deg]
    "length_noise_mm": 0.02,          # wheel travel, wheel centre, half-track, pad height [mm]
    "force_noise_n": 5.0,             # pad load cells [N]
    "torque_noise_nm": 0.5,           # torque channels [N·m]
    "angle_offset_deg": 0.01,         # zero errors, each drawn once per channel in ± this
    "length_offset_mm": 0.1,
    "force_offset_n": 10.0,
    "torque_offset_nm": 1.0,
    "angle_resolution_deg": 0.001,    # quantisation steps
    "length_resolution_mm": 0.01,
    "force_resolution_n": 1.0,
    "torque_resolution_nm": 0.1,
}
#: Run unit of a channel -> (sensor kind, key suffix) in MEASUREMENT_DEFAULTS.
SENSORS = {"deg": ("angle", "deg"), "mm": ("length", "mm"), "N": ("force", "n"), "N·m": ("torque", "nm")}
RIG_NAME = "virtual K&C rig"
_KEYS = ("level", "vehicle", "scenarios", "duration_scale", "effects", "measurement", "chain", "rig", "seed")
#: The chain's random stream: apart from the noise's, which stays as it was without a chain.
_CHAIN_STREAM = 53
#: Causes the K&C virtual rig can hide: the catalogue's, and backlash (outside it).
CAUSES = (*BUSHING_CAUSES, *VEHICLE_CAUSES, "backlash")


@dataclass(frozen=True)
class KCTruth:
    """A validated K&C truth file."""

    source: str
    baseline: VehicleDefinition
    scenarios: tuple[Scenario, ...]
    effects: tuple[Hypothesis, ...]
    measurement: Mapping[str, float]
    seed: int
    duration_scale: float = 1.0
    chain: Mapping[str, ChannelChain] = field(default_factory=dict)   #: measured channel -> its chain
    rig: RigMechanics = RigMechanics()   #: the rig's own pads and body clamp

    @property
    def vehicle(self) -> VehicleDefinition:
        """The truth: the baseline with every effect switched on."""
        return extended_vehicle(self.baseline, list(self.effects))


def _path(value: Any, base_dir: Path | None) -> Path:
    path = Path(value)
    return path if path.is_absolute() or base_dir is None else base_dir / path


def _label(location: tuple[str, ...], cause: str) -> str:
    return location[0] if len(location) == 1 else ".".join(location) if len(location) == 2 or cause == "hardpoint" \
        else f"{location[0]} [{location[1]}, {location[2]}]"


def _location(entry: Mapping[str, Any], cause: str, baseline: VehicleDefinition, source: str,
              key: str) -> tuple[str, ...]:
    """The location tuple of an effect, checked against the places the cause can sit in the baseline."""
    valid = locations(baseline, cause)
    if valid == [()]:
        return ()
    if cause == "coupling":
        where = entry.get("location")
        dirs = entry.get("directions")
        bushings = ", ".join(dict.fromkeys(loc[0] for loc in valid))
        if not isinstance(where, str):
            raise InputError(f"expected a bushing name, got {where!r}; valid: {bushings}", source=source,
                             key=f"{key}.location")
        if (not isinstance(dirs, list) or len(dirs) != 2 or len(set(map(str, dirs))) != 2
                or any(d not in DIRECTIONS for d in dirs)):
            raise InputError(f"expected two distinct directions of {', '.join(DIRECTIONS)}, got {dirs!r}",
                             source=source, key=f"{key}.directions")
        location = (where, *sorted(dirs, key=DIRECTIONS.index))
        if location not in valid:
            raise InputError(f"coupling cannot sit in {_label(location, cause)}; valid bushings: {bushings}", source=source,
                             key=f"{key}.location")
        return location
    where = entry.get("location")
    location = tuple(where.split(".")) if isinstance(where, str) else ()
    if location not in valid:
        choices = ", ".join(_label(loc, cause) for loc in valid) if valid else \
            f"none: {cause} applies to no bushing direction of {baseline.name}"
        form = "an axle" if all(len(loc) == 1 for loc in valid) else \
            "axle.hardpoint.coordinate" if cause == "hardpoint" else "bushing.direction"
        raise InputError(f"{cause} cannot sit in {where!r}; expected {form}, one of: {choices}",
                         source=source, key=f"{key}.location")
    return location


def _effect(entry: Any, baseline: VehicleDefinition, source: str, key: str) -> Hypothesis:
    if not isinstance(entry, Mapping):
        raise InputError(f"expected a mapping {{cause: ID, location: ..., parameters}}, got {entry!r}", source=source,
                         key=key)
    cause = entry.get("cause")
    if cause == "self_heating":
        raise InputError("self_heating is not a K&C cause: the rig's slow triangles warm a bushing by far less "
                         "than its resolution; it belongs to the bench level (level: bench)", source=source,
                         key=f"{key}.cause")
    if cause not in CAUSES:
        raise InputError(f"unknown cause {cause!r}; expected one of {', '.join(CAUSES)}", source=source,
                         key=f"{key}.cause")
    params = parameters(cause)
    located = locations(baseline, cause) != [()]
    names = {p.name for p in params}
    allowed = ["cause", *(["location"] if located else []), *(["directions"] if cause == "coupling" else []),
               *(p.name for p in params)]
    extra = [k for k in entry if k not in allowed]
    if extra:
        raise InputError(f"unknown key {extra[0]!r} for {cause}; expected {', '.join(allowed)}", source=source,
                         key=f"{key}.{extra[0]}")
    missing = [k for k in allowed if k not in entry and (k not in names or k in required(params))]
    if missing:
        what = "parameter" if missing[0] in names else "key"
        raise InputError(f"missing {what} {missing[0]!r} for {cause}; expected {', '.join(allowed)}", source=source,
                         key=f"{key}.{missing[0]}")
    location = _location(entry, cause, baseline, source, key)
    values = truth_values(entry, params, source, key)
    hypothesis = Hypothesis(cause, location, values)
    try:
        extended_vehicle(baseline, [hypothesis])
    except InputError as exc:
        raise InputError(f"{cause} at {hypothesis.label}: {exc}", source=source, key=key) from None
    return hypothesis


def _scenarios(raw: Any, source: str, base_dir: Path | None) -> tuple[Scenario, ...]:
    if raw is None:
        paths = list(DEFAULT_SCENARIOS)
    elif isinstance(raw, list) and raw and all(isinstance(p, str) for p in raw):
        paths = [_path(p, base_dir) for p in raw]
    else:
        raise InputError(f"expected a non-empty list of scenario files (relative to this file), got {raw!r}",
                         source=source, key="scenarios")
    out = []
    for i, path in enumerate(paths):
        key = f"scenarios[{i}]"
        if not is_file(path):
            raise InputError(f"no such scenario file {str(path)!r}", source=source, key=key)
        try:
            out.append(load_scenario(path))
        except InputError as exc:
            raise InputError(f"bad scenario: {exc}", source=source, key=key) from None
    return tuple(out)


def parse_kc_truth(data: Any, source: str, base_dir: Path | None = None) -> KCTruth:
    """Validate a K&C truth mapping (paths relative to ``base_dir``); errors name the file and key."""
    if not isinstance(data, Mapping):
        raise InputError("expected a mapping", source=source)
    unknown = [k for k in data if k not in _KEYS]
    if unknown:
        raise InputError(f"unknown key {unknown[0]!r}; expected {', '.join(_KEYS)}", source=source, key=str(unknown[0]))
    if data.get("level") != "kc":
        raise InputError(f"expected level: kc, got {data.get('level')!r}", source=source, key="level")
    raw_vehicle = data.get("vehicle", None)
    if raw_vehicle is not None and not isinstance(raw_vehicle, str):
        raise InputError(f"expected a vehicle file (relative to this file), got {raw_vehicle!r}", source=source,
                         key="vehicle")
    vehicle_path = DEFAULT_VEHICLE if raw_vehicle is None else _path(raw_vehicle, base_dir)
    if not is_file(vehicle_path):
        raise InputError(f"no such vehicle file {str(vehicle_path)!r}", source=source, key="vehicle")
    try:
        baseline = load_vehicle(vehicle_path)
    except InputError as exc:
        raise InputError(f"bad vehicle: {exc}", source=source, key="vehicle") from None
    scenarios = _scenarios(data.get("scenarios"), source, base_dir)
    duration_scale = truth_number(data.get("duration_scale", 1.0), source, "duration_scale", positive=True)
    raw = data.get("effects") or []
    if not isinstance(raw, list):
        raise InputError(f"expected a list of {{cause: ID, location: ..., parameters}}, got {raw!r}", source=source,
                         key="effects")
    effects = tuple(_effect(entry, baseline, source, f"effects[{i}]") for i, entry in enumerate(raw))
    measurement = parse_measurement(data.get("measurement"), MEASUREMENT_DEFAULTS, source)
    seed = data.get("seed", 0)
    if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
        raise InputError(f"expected a whole number >= 0, got {seed!r}", source=source, key="seed")
    chain = parse_chain(data.get("chain"), measured_channels(), INPUT_CHANNELS, source)
    rig = parse_rig(Document.of_data(data, source), ("rig",), data.get("rig", {}))
    truth = KCTruth(source, baseline, scenarios, effects, measurement, seed, duration_scale, chain, rig)
    try:
        truth.vehicle  # every effect together (e.g. two couplings of one bushing)
    except InputError as exc:
        raise InputError(f"the effects together: {exc}", source=source, key="effects") from None
    return truth


# -- measuring --------------------------------------------------------------------------------------
def sensor(unit: str, measurement: Mapping[str, float]) -> tuple[float, float, float]:
    """(noise standard deviation, offset bound, resolution) of the rig's sensor for a channel in ``unit``."""
    kind, suffix = SENSORS[unit]
    return tuple(measurement[f"{kind}_{what}_{suffix}"] for what in ("noise", "offset", "resolution"))


def rig_description(measurement: Mapping[str, float], chain: bool = False, mechanics: bool = False
                    ) -> dict[str, Any]:
    """What ``rig.yaml`` and every recording say about the rig: its name, notes and sensor accuracy
    (a ``chain`` and the rig's own ``mechanics`` are said to be there, not what they are: a rig does
    not know its own errors)."""
    return {"name": RIG_NAME,
            "notes": "simulated K&C rig (vsim): body clamped, pads driven; every measured channel carries a "
                     "zero error drawn once per dataset, Gaussian noise and the sensor's quantisation"
                     + ("; some pass a chain of calibration errors, filters, lags, drifts and coloured noise, "
                        "not stated" if chain else "")
                     + ("; its pads' friction and compliance and its body clamp's compliance, not stated"
                        if mechanics else "") + "; the rig inputs are written as commanded",
            "accuracy": {k: float(v) for k, v in measurement.items()}}


def measure_kc(truth: KCTruth, output: str | os.PathLike[str], *, overwrite: bool = False,
               progress: Callable[[int, int, str], None] | None = None) -> Path:
    """Play the truth's scenarios on the truth vehicle and write the measured K&C dataset to ``output``.

    Each scenario is simulated with the vehicle's own bushing laws (a scenario's ``bushings`` key is
    ignored: a rig cannot choose them); the rig keeps the channels of
    :func:`elastokin.recordings.rig_recordings.measured_channels`, adds to each measured one its zero error (drawn once
    per dataset), noise and quantisation, and writes the inputs as commanded (a truth's ``chain``
    goes before those on the channels it names; a servoed input's transducer gain g gives the car
    the command / (1 + g); the car stands on the truth's ``rig``, or the scenario's if the truth's is
    ideal). Recordings are ``NN_<scenario name>.mcap`` in the order played, plus ``rig.yaml``. The dataset is written as a
    whole (a temporary folder renamed at the end); an existing ``output`` is refused unless
    ``overwrite``. ``progress(i, n, scenario name)`` is called before each scenario.
    """
    root = Path(output)
    channels = measured_channels()
    m = truth.measurement
    rng = np.random.default_rng(truth.seed)
    chain_rng = np.random.default_rng([truth.seed, _CHAIN_STREAM])
    offsets = {name: rng.uniform(-1.0, 1.0) * sensor(unit, m)[1] for name, unit in channels.items()
               if name not in INPUT_CHANNELS}
    vehicle = truth.vehicle
    rig = rig_description(m, chain=bool(truth.chain), mechanics=not truth.rig.ideal)
    with atomic_directory(root, overwrite=overwrite) as tmp:
        files = []
        for i, scenario in enumerate(truth.scenarios):
            if progress is not None:
                progress(i, len(truth.scenarios), scenario.name)
            played = servoed(scenario, truth.chain)   # the command the servoed inputs' transducers read
            on = played.rig if truth.rig.ideal else truth.rig
            run = simulate(replace(played, bushing_model=None, rig=on), vehicle,
                           duration_scale=truth.duration_scale)
            signals = {}
            for name, unit in channels.items():
                if name not in run.signals:
                    continue
                x = run.signals[name]
                if name in truth.chain:
                    chain = truth.chain[name]
                    x = chain.apply(run.t_s, x, chain_rng, seen(chain, name, run.signals))
                if name not in INPUT_CHANNELS:
                    noise, _, resolution = sensor(unit, m)
                    x = quantise(x + offsets[name] + rng.normal(0.0, noise, x.shape), resolution)
                signals[name] = x
            file = f"{i + 1:02d}_{scenario.name}.mcap"
            # The scenario file as seen from the dataset, so that a reader finds it wherever both are moved to.
            where = Path(os.path.relpath(scenario.path.resolve(), root.resolve()))
            write_rig_recording(tmp / file, replace(scenario, path=where), run.t_s, signals,
                                {name: channels[name] for name in signals}, rig=rig,
                                duration_scale=truth.duration_scale, source=f"{scenario.path} on the virtual rig")
            files.append(file)
        write_kc_rig_yaml(tmp, _vehicle_text(truth.baseline), rig, files)
    return root


def _vehicle_text(baseline: VehicleDefinition) -> str:
    return f"{baseline.name}: {baseline.description}" if baseline.description else baseline.name
