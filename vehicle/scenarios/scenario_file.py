"""Reading a scenario file (format: scenarios/README.md) into a :class:`Scenario`, from a path or from
text (a scenario stored in a recording, or written inline in another file).

Values in the file carry their unit in the key name (``amplitude_mm``, ``amplitude_daN``,
``speed_mm_s``) and are converted to SI once, here. Validation errors are :class:`InputError` naming
``file:line``, the dotted key, the value and what was expected; unknown keys are errors.
"""

from __future__ import annotations

from pathlib import Path
from typing import Mapping

import numpy as np

from elastokin.vehicle.model.definition import BUSHING_MODELS
from elastokin.vehicle.scenarios.channels import (AXLES, CORNER_TAGS, FILE_UNITS, INPUT_CHANNELS, csv_columns, file_si,
                                        channel_quantity)
from elastokin.vehicle.scenarios.rig_file import parse_rig
from elastokin.vehicle.scenarios.road_scenario import ROAD_TOP_KEYS, ROAD_TYPES, RoadScenario, parse_road_scenario
from elastokin.vehicle.scenarios.scenario import (BISINE_INPUTS, MAX_FREQUENCY_HZ, MAX_INPUT_S, MAX_SETTLE_S, SHAPES,
                                        SIGNAL_TYPES, TYPES, Case, InputTable, Limits, Scenario, Settle, Waveform)
from elastokin.vehicle.scenarios.scenario_fields import LIMIT_KEYS, case_fields, limit_values, output_rate, scenario_name, vehicle_file
from elastokin.core import units
from elastokin.core.documents import Document, Fields, dump_yaml
from elastokin.core.errors import InputError
from elastokin.core.files import is_file, read_text
from elastokin.core.shipped import SCENARIO_DIR, resolve
from elastokin.core.tables import read_csv_columns, read_csv_header
from elastokin.core.units import MM

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


def _case_keys(kind: str) -> tuple[str, ...]:
    if kind in SIGNAL_TYPES:
        unit = FILE_UNITS[SIGNAL_TYPES[kind]]
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


def _frequency(f: Fields) -> float:
    """The ``frequency_hz`` of ``f`` [Hz], positive and at most MAX_FREQUENCY_HZ."""
    frequency = f.number("frequency_hz", positive=True)
    if frequency > MAX_FREQUENCY_HZ:
        raise f.fail("frequency_hz", f"expected at most {MAX_FREQUENCY_HZ:g} Hz (a K&C rig input), "
                                     f"got {frequency}")
    return frequency


def _periodic(f: Fields, kind: str) -> tuple[Waveform, int]:
    """Triangle 0 → +A → −A → 0 or sine A·sin(2πft), ``cycles`` times, SI."""
    quantity = SIGNAL_TYPES[kind]
    unit, si = FILE_UNITS[quantity], file_si(quantity)
    amplitude = f.number(f"amplitude_{unit}", positive=True, at_most=units.plausible(unit), unit=unit) * si
    shape = f.choice("shape", SHAPES, "triangle")
    cycles = int(f.number("cycles", 1, positive=True, integer=True))
    speed_key = f"speed_{unit}_s"
    if f.has("frequency_hz") == f.has(speed_key):
        raise f.doc.error(f.where, f"give exactly one of frequency_hz or {speed_key}")
    if f.has(speed_key):
        if shape != "triangle":
            raise f.fail(speed_key, f"a speed defines a triangle only; give frequency_hz for a {shape}")
        period = 4.0 * amplitude / (f.number(speed_key, positive=True) * si)
        if period * MAX_FREQUENCY_HZ < 1.0:
            raise f.fail(speed_key, f"a triangle of period {period:.3g} s (4 × amplitude / speed); expected at "
                                    f"most {MAX_FREQUENCY_HZ:g} Hz (a K&C rig input)")
    else:
        period = 1.0 / _frequency(f)
    if cycles * period > MAX_INPUT_S:   # checked before a triangle lists its corners
        raise f.fail("cycles", f"{cycles:.6g} cycles of {period:.6g} s last {cycles * period:.6g} s; expected at most "
                               f"{MAX_INPUT_S:g} s of simulated time per case")
    if shape == "sine":
        return Waveform((0.0, cycles * period), (0.0, 0.0), ((amplitude, 1.0 / period),)), cycles
    times = [0.0] + [period * (c + q) for c in range(cycles) for q in (0.25, 0.75, 1.0)]
    return Waveform(tuple(times), (0.0,) + (amplitude, -amplitude, 0.0) * cycles), cycles


def _ramps(f: Fields, levels: list[tuple[float, float]]) -> Waveform:
    """From rest, ramp to each (level [m], hold [s]) in turn over ``rise_time_s``."""
    rise = f.number("rise_time_s", DEFAULT_RISE_TIME_S, positive=True)
    times, values, t = [0.0], [0.0], 0.0
    for level, hold in levels:
        t += rise
        times += [t, t + hold]
        values += [level, level]
        t += hold
    return Waveform(tuple(times), tuple(values))


def _bisine(f: Fields, axles: tuple[str, ...]) -> tuple[Waveform, tuple[float, ...]]:
    kind = f.choice("input", BISINE_INPUTS)
    quantity = SIGNAL_TYPES.get(kind, "rack")
    unit, si = FILE_UNITS[quantity], file_si(quantity)
    raw = f.raw("components")
    if not isinstance(raw, list) or not raw:
        raise f.fail("components", f"expected a list of {{amplitude_{unit}, frequency_hz}} mappings, got {raw!r}")
    sines = []
    for i, item in enumerate(raw):
        c = Fields.of(f.doc, f.path("components") + (i,), item, (f"amplitude_{unit}", "frequency_hz"))
        sines.append((c.number(f"amplitude_{unit}", nonzero=True, at_most=units.plausible(unit), unit=unit) * si,
                      _frequency(c)))
    if f.has("duration_s") and f.has("cycles"):
        raise f.fail("duration_s", "give either cycles (of the slowest component) or duration_s, not both")
    duration = (f.number("duration_s", positive=True) if f.has("duration_s")
                else f.number("cycles", 2, positive=True, integer=True) / min(fr for _, fr in sines))
    return Waveform((0.0, duration), (0.0, 0.0), tuple(sines)), _pattern(kind, axles)


def _rack(f: Fields, key: str) -> float:
    """A rack displacement written in mm, in m."""
    return f.number(key, nonzero=True, at_most=units.plausible("mm"), unit="mm") * MM


def _case(f: Fields, kind: str, axles: tuple[str, ...], base_dir: Path) -> Case:
    params = {k: v for k, (v, _) in f.values.items() if k != "label"}
    label = f.text("label", ", ".join(f"{k}={v}" for k, (v, p) in f.values.items() if p[0] == "cases") or "case")
    if kind in SIGNAL_TYPES:
        waveform, cycles = _periodic(f, kind)
        return Case(label, params, cycles, waveform, _pattern(kind, axles))
    if kind == "rack_step":
        levels = [(_rack(f, "rack_mm"), f.number("hold_s", positive=True))]
        return Case(label, params, 1, _ramps(f, levels), _pattern("rack", axles))
    if kind == "double_rack_step":
        first = _rack(f, "first_mm")
        second = first + _rack(f, "second_mm")
        levels = [(first, f.number("rest_s", positive=True)), (second, f.number("hold_s", positive=True))]
        return Case(label, params, 1, _ramps(f, levels), _pattern("rack", axles))
    if kind == "bisine":
        waveform, pattern = _bisine(f, axles)
        return Case(label, params, 1, waveform, pattern)
    name = f.text("path")
    csv_path = Path(name) if Path(name).is_absolute() else base_dir / name
    if not is_file(csv_path):
        raise f.fail("path", f"no such CSV file {str(csv_path)!r}")
    return Case(label, params, 1, table=read_input_csv(csv_path))


def read_input_csv(path: Path) -> InputTable:
    """Read a scenario time series: a header ``t_s`` plus any of :func:`csv_columns` (absent
    channels stay at 0), then one line per time, from 0. Raises InputError naming the file, the
    line and the column for an unknown or missing column, a non-number, or a time that does not
    start at 0 or does not increase (the numbers are read by :func:`elastokin.core.tables.read_csv_columns`)."""
    columns = csv_columns()
    header = read_csv_header(path)
    unknown = [c for c in header if c != "t_s" and c not in columns]
    if unknown:
        raise InputError(f"unknown column {unknown[0]!r}; expected t_s and any of {', '.join(columns)}",
                         source=str(path), key="line 1")
    present = [c for c in columns if c in header]
    if not present:
        raise InputError(f"expected t_s and at least one input column, got {','.join(header) or 'an empty file'}",
                         source=str(path), key="line 1")
    unit_of = {c: FILE_UNITS[channel_quantity(ch)] for c, ch in zip(columns, INPUT_CHANNELS)}
    limits = {"t_s": units.plausible("s")} | {c: units.plausible(unit_of[c]) for c in present}
    data = read_csv_columns(path, ("t_s", *present), min_rows=2, limits=limits)
    if data["t_s"][0] != 0.0:
        raise InputError(f"expected the inputs to start at t_s = 0, got {data['t_s'][0]}", source=str(path),
                         key="first data line, column t_s")
    values = np.zeros((len(data["t_s"]), len(INPUT_CHANNELS)))
    for name in present:
        k = columns.index(name)
        values[:, k] = data[name] * file_si(channel_quantity(INPUT_CHANNELS[k]))
    return InputTable(data["t_s"], values)


# -- the file ---------------------------------------------------------------------------------------
_TOP_KEYS = ("name", "description", "type", "vehicle", "bushings", "axles", "output_rate_hz", "settle",
             "limits", "rig", "defaults", "cases")
_RACK_TYPES = ("rack_step", "double_rack_step", "csv")


def _axles(top: Fields, kind: str) -> tuple[str, ...]:
    if kind in _RACK_TYPES:
        if top.has("axles"):
            raise top.fail("axles", f"a {kind} scenario has no axle selection (the rack steers the front axle; "
                                    f"a CSV names its channels)")
        return AXLES if kind == "csv" else ("front",)
    raw = top.raw("axles", list(AXLES))
    if not isinstance(raw, list) or not raw or any(a not in AXLES for a in raw) or len(set(raw)) != len(raw):
        raise top.fail("axles", f"expected a list of distinct axles from {', '.join(AXLES)}, got {raw!r}")
    return tuple(a for a in AXLES if a in raw)


def load_scenario(path: str | Path) -> Scenario | RoadScenario:
    """Load and validate a scenario file (of the rig or the road), or a built-in scenario by name
    (``pumping``, ``kc/roll``, ``road/step_steer``); raises :class:`InputError` naming file:line,
    key and value."""
    path = resolve(path, SCENARIO_DIR, "scenario")
    return parse_scenario(read_text(path), path)


def with_case_values(scenario: Scenario, values: Mapping[str, float], source: str) -> Scenario:
    """``scenario`` with ``values`` set in every case (``{"rise_time_s": 0.5}``: each step ramped in
    0.5 s), read again from its changed text, which its recordings then carry; errors (a key its
    cases do not take, a value out of range) name ``source``."""
    data = Document(scenario.text, str(scenario.path)).data
    for case in data["cases"]:
        case.update({key: float(value) for key, value in values.items()})
    return parse_scenario(dump_yaml(data, sort_keys=False), scenario.path, source)


def parse_scenario(text: str, path: Path, source: str | None = None) -> Scenario | RoadScenario:
    """The scenario written in ``text``, as if read from the file ``path``: relative paths in it are
    taken from ``path``'s folder, its name defaults to ``path``'s stem. Errors name ``source``
    (default: ``path``), the line, the key and the value."""
    path = Path(path)
    doc = Document(text, source or str(path))
    top = doc.top(tuple(dict.fromkeys(_TOP_KEYS + ROAD_TOP_KEYS)))
    kind = top.choice("type", TYPES + ROAD_TYPES)
    if kind in ROAD_TYPES:
        return parse_road_scenario(top, kind, path, text)
    top.check_keys(_TOP_KEYS, " in a rig scenario")
    vehicle = vehicle_file(top, path)
    axles = _axles(top, kind)

    s = Fields.of(doc, ("settle",), top.raw("settle", {}), ("before_bushings_s", "before_input_s"))
    settle = Settle(s.number("before_bushings_s", Settle.before_bushings_s, nonneg=True, at_most=MAX_SETTLE_S, unit="s"),
                    s.number("before_input_s", Settle.before_input_s, nonneg=True, at_most=MAX_SETTLE_S, unit="s"))
    limits = Limits(**limit_values(Fields.of(doc, ("limits",), top.raw("limits", {}), LIMIT_KEYS)))

    allowed = _case_keys(kind)
    cases = []
    for i, fields in case_fields(top, allowed):
        case = _case(fields, kind, axles, path.parent)
        if not case.duration_s <= MAX_INPUT_S:
            raise doc.error(("cases", i), f"its input lasts {case.duration_s:.6g} s; expected at most {MAX_INPUT_S:g} s "
                                          f"of simulated time per case")
        cases.append(case)
    if kind == "bisine" and len({c.parameters["input"] for c in cases}) > 1:
        raise top.fail("cases", "expected every bi-sine case to drive the same input (put `input` in defaults)")
    return Scenario(
        name=scenario_name(top, path), description=top.text("description", ""), path=path, text=text, type=kind,
        vehicle=vehicle, bushing_model=top.choice("bushings", BUSHING_MODELS, None), axles=axles,
        output_rate_hz=output_rate(top), settle=settle, limits=limits, cases=tuple(cases),
        rig=parse_rig(doc, top.path("rig"), top.raw("rig", {})))
