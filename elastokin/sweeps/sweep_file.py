"""Reading a sweep file (format: scenarios/sweeps/README.md): the base vehicle, the scenarios, the
parameters varied by their place in the vehicle file, the design and the metrics collected.

Everything a sweep could trip on later is checked here, before any run: each parameter's place
holds a number of the vehicle file (bushing parameters through their sets), its bounds are in
order, the vehicle builds with every parameter at each bound, the design gives at least one run,
and each metric is given by at least one of the scenarios. Errors name the sweep file, line, key
and value.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

from elastokin.bushings.parameter_sets import load_parameter_set
from elastokin.vehicle.model.definition import VehicleDefinition
from elastokin.vehicle.model.file_overrides import PlaceError, file_value, vehicle_with
from elastokin.vehicle.model.vehicle_file import parse_vehicle
from elastokin.vehicle.scenarios.road_scenario import RoadScenario
from elastokin.vehicle.scenarios.scenario import NAME_PATTERN, Scenario
from elastokin.vehicle.scenarios.scenario_file import parse_scenario
from elastokin.analysis.kc_metrics import TEST_METRICS
from elastokin.analysis.road_metrics import TYPE_METRICS
from elastokin.analysis.run_metrics import KC_TESTS
from elastokin.core.documents import Document, Fields
from elastokin.core.errors import InputError
from elastokin.core.files import read_text
from elastokin.core.shipped import DEFAULT_VEHICLE, SCENARIO_DIR, SWEEP_DIR, VEHICLE_DIR, resolve
from elastokin.sweeps.designs import Design, run_count

_TOP = ("name", "description", "vehicle", "scenarios", "duration_scale", "parameters", "design", "metrics", "record")
#: Shortest and longest duration scale of a sweep's runs.
DURATION_SCALE_RANGE = (0.01, 10.0)


@dataclass(frozen=True)
class Parameter:
    """A number of the vehicle file that the sweep varies, between two bounds in the file's units."""

    place: str           #: dotted place in the vehicle file (:mod:`elastokin.vehicle.model.file_overrides`)
    low: float
    high: float


@dataclass(frozen=True)
class SourceFile:
    """A file a run reads, by its absolute path, with its text."""

    path: str
    text: str


@dataclass(frozen=True)
class MetricColumn:
    """One column of the sweep's table: a metric of one case of one scenario."""

    name: str            #: ``<scenario>.c<case>.<metric>``
    scenario: int        #: index in :attr:`Sweep.scenarios`
    case: int            #: 1-based
    axle: str | None     #: K&C metrics: the axle; road metrics: None
    metric: str


@dataclass(frozen=True)
class Sweep:
    """A validated sweep file."""

    name: str
    description: str
    path: Path
    vehicle: SourceFile                              #: the base vehicle file (absolute path) and its text
    scenarios: tuple[Scenario | RoadScenario, ...]   #: parsed here: a worker resolves none of their paths
    inputs: tuple[SourceFile, ...]                   #: every file the runs read (sweep, vehicle, scenarios, sets, tyre)
    duration_scale: float
    parameters: tuple[Parameter, ...]
    design: Design
    columns: tuple[MetricColumn, ...]
    record: bool

    @property
    def runs(self) -> int:
        """How many runs the design makes."""
        return run_count(self.design, len(self.parameters))


def _parameters(top: Fields, vehicle: SourceFile) -> tuple[Parameter, ...]:
    raw = top.raw("parameters")
    if not isinstance(raw, dict) or not raw:
        raise top.fail("parameters", f"expected a mapping of vehicle-file places to bounds "
                                     f"({{front.spring.rate: {{min: 25000, max: 31000}}}}), got {raw!r:.80}")
    data = Document(vehicle.text, vehicle.path).data
    p = top.fields("parameters", tuple(raw))
    out = []
    for place in raw:
        if not isinstance(place, str):
            raise p.fail(place, f"expected a dotted place in the vehicle file (front.spring.rate), got {place!r}")
        b = p.fields(place, ("min", "max", "min_factor", "max_factor"))
        try:
            base = file_value(data, place)
        except PlaceError as exc:
            raise p.fail(place, f"not a number of the vehicle file {vehicle.path}: {exc}") from None
        relative = b.has("min_factor") or b.has("max_factor")
        if relative and (b.has("min") or b.has("max")):
            raise p.fail(place, "give min and max (the file's units) or min_factor and max_factor, not both")
        if relative:
            if base is None:
                raise p.fail(place, f"the vehicle file {vehicle.path} has no value there to scale (a key left to "
                                    f"its default, or a typo): give min and max, which are checked against the "
                                    f"format")
            low, high = (b.number(k, positive=True) * base for k in ("min_factor", "max_factor"))
            if base < 0:
                low, high = high, low
        else:
            low, high = b.number("min"), b.number("max")
        if not low < high:
            raise p.fail(place, f"expected min < max, got {low!r} and {high!r}")
        for value in (low, high):
            try:
                vehicle_with(vehicle.text, Path(vehicle.path), {place: value}, p.doc.where(p.path(place)))
            except InputError as exc:
                raise p.fail(place, f"the vehicle does not build with {value!r} there: "
                                    f"{exc.key + ': ' if exc.key else ''}{exc.bare}") from None
        out.append(Parameter(place, low, high))
    return tuple(out)


def metrics_given(scenario: Scenario | RoadScenario) -> list[tuple[str | None, str]]:
    """(axle or None, metric) of every metric the scenario's cases can give."""
    if isinstance(scenario, RoadScenario):
        return [(None, m) for m in TYPE_METRICS[scenario.manoeuvre]]
    test = KC_TESTS.get(scenario.type)
    return [(axle, m) for axle in scenario.axles for m in TEST_METRICS.get(test, ())]


def _columns(top: Fields, scenarios: list[Scenario | RoadScenario]) -> tuple[MetricColumn, ...]:
    raw = top.raw("metrics")
    if not isinstance(raw, list) or not raw or not all(isinstance(m, str) for m in raw):
        raise top.fail("metrics", f"expected a list of metric names, got {raw!r:.80}")
    columns = []
    for i, name in enumerate(raw):
        axle, _, metric = name.rpartition(".")
        found = [MetricColumn(f"{s.name}.c{c}.{name}", k, c, axle or None, metric)
                 for k, s in enumerate(scenarios) if (axle or None, metric) in metrics_given(s)
                 for c in range(1, len(s.cases) + 1)]
        if name in raw[:i]:
            raise top.doc.error(top.path("metrics") + (i,), f"{name!r} is asked for twice")
        if not found:
            given = sorted({f"{a}.{m}" if a else m for s in scenarios for a, m in metrics_given(s)})
            raise top.doc.error(top.path("metrics") + (i,),
                                f"no scenario of the sweep gives {name!r}; they give {', '.join(given) or 'none'}")
        columns += found
    return tuple(columns)


def _duration_scale(top: Fields) -> float:
    scale = top.number("duration_scale", 1.0, positive=True, at_most=DURATION_SCALE_RANGE[1])
    if scale < DURATION_SCALE_RANGE[0]:
        raise top.fail("duration_scale", f"expected at least {DURATION_SCALE_RANGE[0]:g}, got {scale!r}")
    return scale


def load_sweep(path: str | Path) -> Sweep:
    """Load and validate a sweep file (module docstring); InputError naming file:line, key and value."""
    path = resolve(path, SWEEP_DIR, "sweep").resolve()
    doc = Document(read_text(path), str(path))
    top = doc.top(_TOP)
    name = top.text("name", path.stem)
    if not NAME_PATTERN.fullmatch(name):
        raise top.fail("name", f"expected a plain name (letters, digits, '_', '.', '-'; the output folder is "
                               f"out/sweep_<name>), got {name!r}")
    try:
        vehicle_path = resolve(top.text("vehicle", str(DEFAULT_VEHICLE)), VEHICLE_DIR, "vehicle",
                               base=path.parent).resolve()
    except InputError as exc:
        raise top.fail("vehicle", f"{exc.source}: {exc.bare}") from None
    vehicle = SourceFile(str(vehicle_path), read_text(vehicle_path))
    base = parse_vehicle(vehicle.text, vehicle_path)   # the base vehicle's own errors name its file
    raw = top.raw("scenarios")
    if not isinstance(raw, list) or not raw or not all(isinstance(s, str) for s in raw):
        raise top.fail("scenarios", f"expected a list of scenario files or built-in names, got {raw!r:.80}")
    files, scenarios = [], []
    for i, entry in enumerate(raw):
        try:
            p = resolve(entry, SCENARIO_DIR, "scenario", base=path.parent).resolve()
        except InputError as exc:
            raise doc.error(top.path("scenarios") + (i,), exc.bare) from None
        files.append(SourceFile(str(p), read_text(p)))
        scenarios.append(replace(parse_scenario(files[-1].text, p), vehicle=vehicle_path))
    names = [s.name for s in scenarios]
    if len(set(names)) != len(names):
        raise top.fail("scenarios", f"two scenarios have the same name in {names}: their columns would clash")
    parameters = _parameters(top, vehicle)
    design = Design.of(top.fields("design", ("type", "levels", "runs", "base_runs", "seed")), len(parameters))
    columns = _columns(top, scenarios)
    inputs = (SourceFile(str(path), doc.text), vehicle, *files, *_read_by(base))
    return Sweep(name, top.text("description", ""), path, vehicle, tuple(scenarios), inputs,
                 _duration_scale(top), parameters, design, columns,
                 bool(top.choice("record", (True, False), False)))


def _read_by(vehicle: VehicleDefinition) -> list[SourceFile]:
    """The files a run of ``vehicle`` reads besides its own: its bushing parameter sets and its tyre."""
    names = {d.set_name for b in vehicle.bushings for d in b.directions.values() if d.set_name}
    names |= {n for b in vehicle.bushings for d in b.directions.values() for n in d.families.sets.values()}
    paths = sorted({load_parameter_set(n).path for n in names} - {None})
    if vehicle.tyre.property_file is not None:
        paths.append(vehicle.tyre.property_file)
    return [SourceFile(str(p), read_text(p)) for p in paths]

