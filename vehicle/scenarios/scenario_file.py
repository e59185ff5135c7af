"""Rig scenarios: load and validate a scenario YAML file (format: scenarios/README.md).

A scenario is one kind of K&C rig test (pumping, roll, a force or torque at the wheel bases, rack
steps, a bi-sine or a CSV time series) run for a list of cases. Values in the file carry their unit
in the key name (``amplitude_mm``, ``amplitude_daN``, ``speed_mm_s``) and are converted to SI once,
here: every :class:`Case` returns its rig inputs in m, N, N·m. Validation errors are
:class:`InputError` naming ``file:line``, the dotted key, the value and what was expected; unknown
keys are errors.
"""

from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Mapping

import numpy as np
import yaml

from vsim_core.errors import InputError
from bushings.bench.records import read_csv_columns
from vehicle.model.builder import CORNERS, BuildOptions
from vehicle.model.definition import DEFAULT_VEHICLE
from vsim_cli.model import BUSHING_MODELS

#: Corner names of the rig (order of ``vehicle.model.builder.CORNERS``) and their short tags (fl, fr, rl, rr).
CORNER_TAGS = {corner: "".join(word[0] for word in corner.split("_")) for corner in CORNERS}
AXLES = ("front", "rear")

#: Rig input channels, in the order of :meth:`Case.inputs` columns: pad vertical displacement
#: (bump positive) [m], longitudinal and lateral pad force [N], aligning torque [N·m] per corner,
#: then the rack displacement (+y, to the left) [m].
INPUT_QUANTITIES = ("pad_z", "pad_fx", "pad_fy", "pad_mz")
INPUT_CHANNELS = tuple(f"{q}_{tag}" for q in INPUT_QUANTITIES for tag in CORNER_TAGS.values()) + ("rack",)

#: File unit of each input quantity: (key suffix, SI per file unit).
FILE_UNITS = {"pad_z": ("mm", 1e-3), "pad_fx": ("daN", 10.0), "pad_fy": ("daN", 10.0),
              "pad_mz": ("Nm", 1.0), "rack": ("mm", 1e-3)}

#: Scenario types driving one input quantity with a triangle or a sine, and that quantity.
SIGNAL_TYPES = {"pumping": "pad_z", "roll": "pad_z", "lateral_force": "pad_fy",
                "longitudinal_force": "pad_fx", "aligning_torque": "pad_mz"}
#: What a bi-sine may drive: a signal type's pattern, or the rack.
BISINE_INPUTS = (*SIGNAL_TYPES, "rack")
TYPES = (*SIGNAL_TYPES, "rack_step", "double_rack_step", "bisine", "csv")
SHAPES = ("triangle", "sine")

#: The rig's time step [s]; output rates must divide 1/step.
RIG_TIMESTEP_S = BuildOptions().timestep
#: Largest sine frequency accepted [Hz]: 20 rig steps per period.
MAX_FREQUENCY_HZ = 1.0 / (20 * RIG_TIMESTEP_S)


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
        return self.times_s[-1]

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

    @property
    def x_quantity(self) -> str | None:
        """Per-corner signal that wheel outputs are plotted against (wheel travel, pad force or
        torque), or None for time-only scenarios (rack steps, CSV)."""
        kind = self.cases[0].parameters.get("input", self.type) if self.type == "bisine" else self.type
        driven = SIGNAL_TYPES.get(kind)
        return None if driven is None else ("wheel_travel" if driven == "pad_z" else driven)


# -- reading the document with line numbers ---------------------------------------------------------
#: Where a value sits in the document: mapping keys and list indices from the top.
KeyPath = tuple[Any, ...]


def dotted(path: KeyPath) -> str:
    """``("cases", 2, "amplitude_mm")`` → ``"cases[2].amplitude_mm"``."""
    out = ""
    for part in path:
        out += f"[{part}]" if isinstance(part, int) else (f".{part}" if out else str(part))
    return out


class _Document:
    """A YAML document as plain data plus the line of every key path (from the composed nodes)."""

    def __init__(self, text: str, source: str):
        self.source = source
        loader = yaml.SafeLoader(text)
        try:
            node = loader.get_single_node()
            self.data = loader.construct_document(node) if node is not None else None
        except yaml.YAMLError as exc:
            raise InputError(f"not valid YAML: {exc}", source=source) from exc
        finally:
            loader.dispose()
        self.lines: dict[KeyPath, int] = {}
        if node is not None:
            self._index(node, ())

    def _index(self, node: yaml.Node, path: KeyPath) -> None:
        self.lines[path] = node.start_mark.line + 1
        if isinstance(node, yaml.MappingNode):
            seen = set()
            for key, value in node.value:
                if key.value in seen:
                    raise InputError(f"duplicate key {key.value!r}", source=f"{self.source}:{key.start_mark.line + 1}",
                                     key=dotted(path + (key.value,)))
                seen.add(key.value)
                self._index(value, path + (key.value,))
        elif isinstance(node, yaml.SequenceNode):
            for i, item in enumerate(node.value):
                self._index(item, path + (i,))

    def error(self, path: KeyPath, message: str) -> InputError:
        """An InputError at ``path`` (or its closest enclosing node that has a line)."""
        where = path
        while where not in self.lines and where:
            where = where[:-1]
        line = self.lines.get(where)
        return InputError(message, source=f"{self.source}:{line}" if line else self.source, key=dotted(path) or None)


class _Fields:
    """Typed access to a mapping of the document; each value remembers where it was written."""

    def __init__(self, doc: _Document, values: Mapping[str, tuple[Any, KeyPath]], where: KeyPath):
        self.doc, self.values, self.where = doc, values, where

    @classmethod
    def of(cls, doc: _Document, path: KeyPath, data: Any, allowed: tuple[str, ...]) -> "_Fields":
        """The mapping ``data`` at ``path``, checked against the ``allowed`` keys."""
        if not isinstance(data, Mapping):
            raise doc.error(path, f"expected a mapping, got {data!r}")
        fields = cls(doc, {k: (v, path + (k,)) for k, v in data.items()}, path)
        fields.check_keys(allowed)
        return fields

    def check_keys(self, allowed: tuple[str, ...], context: str = "") -> None:
        for key, (_, path) in self.values.items():
            if key not in allowed:
                raise self.doc.error(path, f"unknown key {key!r}{context}; expected one of {', '.join(allowed)}")

    def has(self, key: str) -> bool:
        return key in self.values

    def path(self, key: str) -> KeyPath:
        return self.values[key][1] if key in self.values else self.where + (key,)

    def raw(self, key: str, default: Any = ...) -> Any:
        if key not in self.values:
            if default is ...:
                raise self.doc.error(self.where + (key,), "missing key")
            return default
        return self.values[key][0]

    def fail(self, key: str, message: str) -> InputError:
        return self.doc.error(self.path(key), message)

    def number(self, key: str, default: Any = ..., *, positive: bool = False, nonneg: bool = False,
               nonzero: bool = False, integer: bool = False) -> float:
        value = self.raw(key, default)
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            raise self.fail(key, f"expected a finite number, got {value!r}")
        if integer and value != int(value):
            raise self.fail(key, f"expected a whole number, got {value!r}")
        for bad, what in ((positive and value <= 0, "positive"), (nonneg and value < 0, "non-negative"),
                          (nonzero and value == 0, "non-zero")):
            if bad:
                raise self.fail(key, f"expected a {what} number, got {value!r}")
        return float(value)

    def choice(self, key: str, options: tuple[str, ...], default: Any = ...) -> Any:
        value = self.raw(key, default)
        if value not in options and not (value is None and default is None):
            raise self.fail(key, f"expected one of {', '.join(options)}, got {value!r}")
        return value

    def text(self, key: str, default: Any = ...) -> str:
        value = self.raw(key, default)
        if not isinstance(value, str):
            raise self.fail(key, f"expected a string, got {value!r}")
        return value


# -- cases ------------------------------------------------------------------------------------------
#: Keys a case (merged over ``defaults``) may have, per type; ``label`` is always allowed.
_SIGNAL_KEYS = ("shape", "amplitude", "frequency_hz", "speed", "cycles")
_CASE_KEYS = {
    "rack_step": ("rack_mm", "rise_time_s", "hold_s"),
    "double_rack_step": ("first_mm", "rest_s", "second_mm", "hold_s", "rise_time_s"),
    "bisine": ("input", "components", "duration_s", "cycles"),
    "csv": ("path",),
}
DEFAULT_RISE_TIME_S = 0.05   #: rack step ramp when a file does not say [s]


def _unit(quantity: str) -> str:
    return FILE_UNITS[quantity][0]


def _case_keys(kind: str) -> tuple[str, ...]:
    if kind in SIGNAL_TYPES:
        unit = _unit(SIGNAL_TYPES[kind])
        keys = tuple(f"{k}_{unit}" if k == "amplitude" else f"{k}_{unit}_s" if k == "speed" else k
                     for k in _SIGNAL_KEYS)
    else:
        keys = _CASE_KEYS[kind]
    return (*keys, "label")


def _pattern(kind: str, axles: tuple[str, ...]) -> tuple[float, ...]:
    """Gain of a scalar input on every channel: the driven quantity at the selected axles' corners
    (roll: the right side in opposite phase), or the rack."""
    gains = dict.fromkeys(INPUT_CHANNELS, 0.0)
    if kind == "rack":
        gains["rack"] = 1.0
    else:
        for corner, tag in CORNER_TAGS.items():
            if corner.split("_")[0] in axles:
                gains[f"{SIGNAL_TYPES[kind]}_{tag}"] = -1.0 if kind == "roll" and corner.endswith("right") else 1.0
    return tuple(gains.values())


def _frequency(f: _Fields) -> float:
    """The ``frequency_hz`` of ``f`` [Hz], positive and at most MAX_FREQUENCY_HZ."""
    frequency = f.number("frequency_hz", positive=True)
    if frequency > MAX_FREQUENCY_HZ:
        raise f.fail("frequency_hz", f"expected at most {MAX_FREQUENCY_HZ} Hz (20 rig steps per period), "
                                     f"got {frequency}")
    return frequency


def _periodic(f: _Fields, kind: str) -> tuple[Waveform, int]:
    """Triangle 0 → +A → −A → 0 or sine A·sin(2πft), ``cycles`` times, SI."""
    quantity = SIGNAL_TYPES[kind]
    unit, si = FILE_UNITS[quantity]
    amplitude = f.number(f"amplitude_{unit}", positive=True) * si
    shape = f.choice("shape", SHAPES, "triangle")
    cycles = int(f.number("cycles", 1, positive=True, integer=True))
    speed_key = f"speed_{unit}_s"
    if f.has("frequency_hz") == f.has(speed_key):
        raise f.doc.error(f.where, f"give exactly one of frequency_hz or {speed_key}")
    if f.has(speed_key):
        if shape != "triangle":
            raise f.fail(speed_key, f"a speed defines a triangle only; give frequency_hz for a {shape}")
        period = 4.0 * amplitude / (f.number(speed_key, positive=True) * si)
    else:
        period = 1.0 / _frequency(f)
    if shape == "sine":
        return Waveform((0.0, cycles * period), (0.0, 0.0), ((amplitude, 1.0 / period),)), cycles
    times = [0.0] + [period * (c + q) for c in range(cycles) for q in (0.25, 0.75, 1.0)]
    return Waveform(tuple(times), (0.0,) + (amplitude, -amplitude, 0.0) * cycles), cycles


def _ramps(f: _Fields, levels: list[tuple[float, float]]) -> Waveform:
    """From rest, ramp to each (level [m], hold [s]) in turn over ``rise_time_s``."""
    rise = f.number("rise_time_s", DEFAULT_RISE_TIME_S, positive=True)
    times, values, t = [0.0], [0.0], 0.0
    for level, hold in levels:
        t += rise
        times += [t, t + hold]
        values += [level, level]
        t += hold
    return Waveform(tuple(times), tuple(values))


def _bisine(f: _Fields, axles: tuple[str, ...]) -> tuple[Waveform, tuple[float, ...]]:
    kind = f.choice("input", BISINE_INPUTS)
    unit, si = FILE_UNITS[SIGNAL_TYPES.get(kind, "rack")]
    raw = f.raw("components")
    if not isinstance(raw, list) or not raw:
        raise f.fail("components", f"expected a list of {{amplitude_{unit}, frequency_hz}} mappings, got {raw!r}")
    sines = []
    for i, item in enumerate(raw):
        c = _Fields.of(f.doc, f.path("components") + (i,), item, (f"amplitude_{unit}", "frequency_hz"))
        sines.append((c.number(f"amplitude_{unit}", nonzero=True) * si, _frequency(c)))
    if f.has("duration_s") and f.has("cycles"):
        raise f.fail("duration_s", "give either cycles (of the slowest component) or duration_s, not both")
    duration = (f.number("duration_s", positive=True) if f.has("duration_s")
                else f.number("cycles", 2, positive=True, integer=True) / min(fr for _, fr in sines))
    return Waveform((0.0, duration), (0.0, 0.0), tuple(sines)), _pattern(kind, axles)


def _case(f: _Fields, kind: str, axles: tuple[str, ...], base_dir: Path) -> Case:
    params = {k: v for k, (v, _) in f.values.items() if k != "label"}
    label = f.text("label", ", ".join(f"{k}={v}" for k, (v, p) in f.values.items() if p[0] == "cases") or "case")
    if kind in SIGNAL_TYPES:
        waveform, cycles = _periodic(f, kind)
        return Case(label, params, cycles, waveform, _pattern(kind, axles))
    if kind == "rack_step":
        levels = [(f.number("rack_mm", nonzero=True) * 1e-3, f.number("hold_s", positive=True))]
        return Case(label, params, 1, _ramps(f, levels), _pattern("rack", axles))
    if kind == "double_rack_step":
        first = f.number("first_mm", nonzero=True) * 1e-3
        second = first + f.number("second_mm", nonzero=True) * 1e-3
        levels = [(first, f.number("rest_s", positive=True)), (second, f.number("hold_s", positive=True))]
        return Case(label, params, 1, _ramps(f, levels), _pattern("rack", axles))
    if kind == "bisine":
        waveform, pattern = _bisine(f, axles)
        return Case(label, params, 1, waveform, pattern)
    name = f.text("path")
    csv_path = Path(name) if Path(name).is_absolute() else base_dir / name
    if not csv_path.is_file():
        raise f.fail("path", f"no such CSV file {str(csv_path)!r}")
    return Case(label, params, 1, table=read_input_csv(csv_path))


def input_quantity(channel: str) -> str:
    """The quantity of an input channel: ``pad_z_fl`` → ``pad_z``; ``rack`` → ``rack``."""
    return channel if channel == "rack" else channel.rsplit("_", 1)[0]


def csv_columns() -> tuple[str, ...]:
    """Input columns a scenario CSV may have besides ``t_s``: channel name and file unit."""
    return tuple(f"{ch}_{_unit(input_quantity(ch))}" for ch in INPUT_CHANNELS)


def read_input_csv(path: Path) -> InputTable:
    """Read a scenario time series: a header ``t_s`` plus any of :func:`csv_columns` (absent
    channels stay at 0), then one line per time, from 0. Raises InputError naming the file, the
    line and the column for an unknown or missing column, a non-number, or a time that does not
    start at 0 or does not increase (the numbers are read by :func:`bushings.bench.records.read_csv_columns`)."""
    columns = csv_columns()
    with path.open(newline="") as handle:
        header = [c.strip() for c in next(csv.reader(handle), [])]
    unknown = [c for c in header if c != "t_s" and c not in columns]
    if unknown:
        raise InputError(f"unknown column {unknown[0]!r}; expected t_s and any of {', '.join(columns)}",
                         source=str(path), key="line 1")
    present = [c for c in columns if c in header]
    if not present:
        raise InputError(f"expected t_s and at least one input column, got {','.join(header) or 'an empty file'}",
                         source=str(path), key="line 1")
    data = read_csv_columns(path, ("t_s", *present), min_rows=2)
    if data["t_s"][0] != 0.0:
        raise InputError(f"expected the inputs to start at t_s = 0, got {data['t_s'][0]}", source=str(path),
                         key="first data line, column t_s")
    values = np.zeros((len(data["t_s"]), len(INPUT_CHANNELS)))
    for name in present:
        k = columns.index(name)
        values[:, k] = data[name] * FILE_UNITS[input_quantity(INPUT_CHANNELS[k])][1]
    return InputTable(data["t_s"], values)


# -- the file ---------------------------------------------------------------------------------------
_TOP_KEYS = ("name", "description", "type", "vehicle", "bushings", "axles", "output_rate_hz", "settle",
             "limits", "defaults", "cases")
_RACK_TYPES = ("rack_step", "double_rack_step", "csv")


def _axles(top: _Fields, kind: str) -> tuple[str, ...]:
    if kind in _RACK_TYPES:
        if top.has("axles"):
            raise top.fail("axles", f"a {kind} scenario has no axle selection (the rack steers the front axle; "
                                    f"a CSV names its channels)")
        return AXLES if kind == "csv" else ("front",)
    raw = top.raw("axles", list(AXLES))
    if not isinstance(raw, list) or not raw or any(a not in AXLES for a in raw) or len(set(raw)) != len(raw):
        raise top.fail("axles", f"expected a list of distinct axles from {', '.join(AXLES)}, got {raw!r}")
    return tuple(a for a in AXLES if a in raw)


def _output_rate(top: _Fields) -> float:
    rate = top.number("output_rate_hz", 100.0, positive=True)
    every = 1.0 / (rate * RIG_TIMESTEP_S)
    if abs(every - round(every)) > 1e-9:
        raise top.fail("output_rate_hz", f"expected a whole divisor of {1 / RIG_TIMESTEP_S:g} Hz (the rig's "
                                         f"{RIG_TIMESTEP_S * 1e3:g} ms step), got {rate}")
    return rate


def load_scenario(path: str | Path) -> Scenario:
    """Load and validate a scenario file; raises :class:`InputError` naming file:line, key and value."""
    path = Path(path)
    source = str(path)
    if not path.is_file():
        raise InputError("no such scenario file", source=source)
    text = path.read_text()
    doc = _Document(text, source)
    top = _Fields.of(doc, (), doc.data, _TOP_KEYS)
    kind = top.choice("type", TYPES)
    vehicle = Path(top.text("vehicle", str(DEFAULT_VEHICLE)))
    vehicle = vehicle if vehicle.is_absolute() else path.parent / vehicle
    if not vehicle.is_file():
        raise top.fail("vehicle", f"no such vehicle file {str(vehicle)!r}")
    axles = _axles(top, kind)

    s = _Fields.of(doc, ("settle",), top.raw("settle", {}), ("before_bushings_s", "before_input_s"))
    settle = Settle(s.number("before_bushings_s", Settle.before_bushings_s, nonneg=True),
                    s.number("before_input_s", Settle.before_input_s, nonneg=True))
    lim = _Fields.of(doc, ("limits",), top.raw("limits", {}), ("translation_mm", "rotation_deg", "closure_error_mm"))
    limits = Limits(lim.number("translation_mm", Limits.translation_m * 1e3, positive=True) * 1e-3,
                    math.radians(lim.number("rotation_deg", math.degrees(Limits.rotation_rad), positive=True)),
                    lim.number("closure_error_mm", Limits.closure_error_m * 1e3, positive=True) * 1e-3)

    allowed = _case_keys(kind)
    defaults = _Fields.of(doc, ("defaults",), top.raw("defaults", {}), allowed)
    raw_cases = top.raw("cases")
    if not isinstance(raw_cases, list) or not raw_cases:
        raise top.fail("cases", f"expected a non-empty list of cases, got {raw_cases!r}")
    cases = []
    for i, item in enumerate(raw_cases):
        own = _Fields.of(doc, ("cases", i), item, allowed)
        merged = _Fields(doc, {**defaults.values, **own.values}, ("cases", i))
        cases.append(_case(merged, kind, axles, path.parent))
    if kind == "bisine" and len({c.parameters["input"] for c in cases}) > 1:
        raise top.fail("cases", "expected every bi-sine case to drive the same input (put `input` in defaults)")
    return Scenario(
        name=top.text("name", path.stem), description=top.text("description", ""), path=path, text=text, type=kind,
        vehicle=vehicle, bushing_model=top.choice("bushings", BUSHING_MODELS, None), axles=axles,
        output_rate_hz=_output_rate(top), settle=settle, limits=limits, cases=tuple(cases))
