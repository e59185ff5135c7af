"""The virtual rig (spec measured-data §1): a truth model = a baseline + effects from the catalogue
(or outside it) + measurement imperfections, played through the standard campaign and written in
exactly the format of real rig data, with no trace of the truth. This module holds the bench level;
the K&C level is :mod:`elastokin.diagnosis.virtual_kc_rig`, and :mod:`elastokin.diagnosis.truths` reads either.

TRUTH.yaml (bench level)::

    level: bench
    baseline: fig5_9_progressive      # parameter set, by name or path relative to this file
    part: "E1 front bushing, radial x"
    effects:                          # catalogue causes with their parameters (parameter-set units),
      - {cause: mullins, mullins: 0.15}   # or `backlash` (outside the catalogue: a dead band, mm),
                                          # or another form of a catalogued effect (truth_forms.FORMS)
    measurement: {force_noise_n: 1.0, displacement_noise_mm: 0.0005, force_offset_n: 2.0,
                  displacement_offset_mm: 0.002, force_resolution_n: 0.05, displacement_resolution_mm: 0.0001}
    seed: 0
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Mapping

import numpy as np

from elastokin.bushings.bench.campaign import CAMPAIGN, BenchTest
from elastokin.bushings.bench.records import BenchRecord
from elastokin.bushings.extended_bank import ExtendedBank
from elastokin.bushings.parameter_sets import ParameterSet, load_parameter_set
from elastokin.core.errors import InputError
from elastokin.diagnosis.catalogue import CAUSES, Parameter
from elastokin.diagnosis.truth_forms import FORMS
from elastokin.diagnosis.measurement import parse_measurement, quantise, required, truth_values
from elastokin.recordings.bench_dataset import BenchTestRecord, write_bench_dataset
from elastokin.core.units import MM, MM_PER_M

#: Effects the virtual rig can hide that the diagnosis's catalogue does not hold (to test that an
#: unexplained mismatch is reported as such).
OUTSIDE: dict[str, Parameter] = {
    "backlash": Parameter("backlash", "mm", (0.0, 1.0), (0.02, 0.06),
                          description="half-width of a dead band in series with the part (a worn ball joint)"),
}

#: Measurement imperfections: key -> default (a realistic servo-hydraulic bushing bench).
MEASUREMENT_DEFAULTS = {
    "force_noise_n": 1.0,                 # load-cell noise, standard deviation [N]
    "displacement_noise_mm": 0.0005,      # displacement-sensor noise, standard deviation [mm]
    "force_offset_n": 2.0,                # load-cell zero error, drawn in ±this [N]
    "displacement_offset_mm": 0.002,      # displacement zero error, drawn in ±this [mm]
    "force_resolution_n": 0.05,           # quantisation step [N]
    "displacement_resolution_mm": 0.0001,  # quantisation step [mm]
}
#: Truth simulation steps per rig sample (the rig samples a continuous process).
OVERSAMPLING = 4
_KEYS = {"level", "baseline", "part", "effects", "measurement", "seed"}


@dataclass(frozen=True)
class Truth:
    """A validated truth file."""

    source: str
    baseline: ParameterSet
    effects: list[tuple[str, dict[str, float]]]
    measurement: dict[str, float]
    seed: int
    part: str = "bushing under test"

    @property
    def model(self) -> ParameterSet:
        """The truth: the baseline with its effects switched on."""
        return truth_model(self.baseline, self.effects)


def truth_model(baseline: ParameterSet, effects: list[tuple[str, dict[str, float]]]) -> ParameterSet:
    """The baseline set with every listed effect switched on (catalogue causes, then outside ones);
    other forms (:data:`~elastokin.diagnosis.truth_forms.FORMS`) act on its measured force instead."""
    model = baseline
    for cause, values in effects:
        if cause in FORMS:
            continue
        if cause in CAUSES:
            model = CAUSES[cause].apply(model, values)
        else:
            model = ParameterSet(model.name, model.model, model.quantity, model.values, model.source,
                                 effects={**model.effects, cause: values[cause]})
    return model


def parse_truth(data: Any, source: str, base_dir: Path | None = None) -> Truth:
    """Validate a truth mapping; errors name the file and key."""
    if not isinstance(data, Mapping):
        raise InputError("expected a mapping", source=source)
    unknown = sorted(set(data) - _KEYS)
    if unknown:
        raise InputError(f"unknown key {unknown[0]!r}; expected {', '.join(sorted(_KEYS))}", source=source, key=unknown[0])
    level = data.get("level")
    if level != "bench":
        hint = ("a K&C truth is read by elastokin.diagnosis.virtual_kc_rig.parse_kc_truth (load_truth reads either)"
                if level == "kc" else "expected level: bench or level: kc")
        raise InputError(f"level {level!r}: this parser reads bench truths (level: bench); {hint}", source=source,
                         key="level")
    if not isinstance(data.get("baseline"), str):
        raise InputError(f"expected a parameter-set name or path, got {data.get('baseline')!r}", source=source,
                         key="baseline")
    name = data["baseline"]
    if name.endswith((".yaml", ".yml")) and base_dir is not None and not Path(name).is_absolute():
        name = str(base_dir / name)
    try:
        baseline = load_parameter_set(name)
    except InputError as exc:
        raise InputError(str(exc), source=source, key="baseline") from exc
    effects = []
    raw = data.get("effects") or []
    if not isinstance(raw, list):
        raise InputError(f"expected a list of {{cause: ID, ...parameters}}, got {raw!r}", source=source, key="effects")
    for i, entry in enumerate(raw):
        key = f"effects[{i}]"
        cause = entry.get("cause") if isinstance(entry, Mapping) else None
        if cause not in CAUSES and cause not in OUTSIDE and cause not in FORMS:
            raise InputError(f"unknown cause {cause!r}; expected one of {', '.join([*CAUSES, *OUTSIDE, *FORMS])}",
                             source=source, key=f"{key}.cause")
        params = [OUTSIDE[cause]] if cause in OUTSIDE else list((FORMS.get(cause) or CAUSES[cause]).parameters)
        names = {p.name for p in params}
        extra = sorted(set(entry) - names - {"cause"})
        missing = sorted(set(required(params)) - set(entry))
        if extra or missing:
            raise InputError(f"{'unknown' if extra else 'missing'} parameter {(extra or missing)[0]!r} for {cause}; "
                             f"expected {', '.join(sorted(names))}", source=source, key=f"{key}.{(extra or missing)[0]}")
        values = truth_values(entry, params, source, key)
        if cause in CAUSES and not CAUSES[cause].applies(baseline):
            raise InputError(f"{cause} does not apply to baseline {baseline.name} ({baseline.model})", source=source,
                             key=f"{key}.cause")
        effects.append((cause, values))
    measurement = parse_measurement(data.get("measurement"), MEASUREMENT_DEFAULTS, source)
    seed = data.get("seed", 0)
    if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
        raise InputError(f"expected a whole number >= 0, got {seed!r}", source=source, key="seed")
    truth = Truth(source, baseline, effects, measurement, seed, str(data.get("part", "bushing under test")))
    truth.model.channel()  # validate the combination now, naming this file
    return truth


def measure_bench(truth: Truth, output: Path, *, overwrite: bool = False, tests: tuple[BenchTest, ...] = CAMPAIGN,
                  progress: Callable[[int, int, str], None] | None = None) -> Path:
    """Play the campaign on the truth part and write the measured dataset to ``output``.

    The truth is simulated with :data:`OVERSAMPLING` steps per rig sample; the rig then samples it,
    adds its zero errors and noise and quantises. Nothing of the truth is written.
    """
    rng = np.random.default_rng(truth.seed)
    m = truth.measurement
    force_offset = rng.uniform(-1.0, 1.0) * m["force_offset_n"]
    e_offset_mm = rng.uniform(-1.0, 1.0) * m["displacement_offset_mm"]
    model = truth.model
    channel = model.channel()
    bank = ExtendedBank([channel], [model.effects_si()])
    forms = [(FORMS[cause], values, {}) for cause, values in truth.effects if cause in FORMS]
    records = []
    for i, test in enumerate(tests):
        if progress is not None:
            progress(i, len(tests), test.name)
        rest_before(bank, test.rest_before_s)
        t_fine, e_fine = test.signal(test.dt_s / OVERSAMPLING)
        force = bank.run(e_fine, test.dt_s / OVERSAMPLING)[:, 0]
        for form, values, state in forms:
            force = form.change(e_fine, force, channel.K0, values, state, test.dt_s / OVERSAMPLING,
                                test.rest_before_s)
        t, e, F = t_fine[::OVERSAMPLING], e_fine[::OVERSAMPLING], force[::OVERSAMPLING]
        e_mm = quantise(e * MM_PER_M + e_offset_mm + rng.normal(0.0, m["displacement_noise_mm"], len(e)),
                         m["displacement_resolution_mm"])
        F_n = quantise(F + force_offset + rng.normal(0.0, m["force_noise_n"], len(F)), m["force_resolution_n"])
        records.append(BenchTestRecord(test.name, test.programme, test.rest_before_s,
                                       BenchRecord(test.name, t, e_mm * MM, F_n)))
    rig = {"name": "virtual bench", "sample_steps_s": sorted({t.dt_s for t in tests})}
    return write_bench_dataset(output, truth.part, records, rig, overwrite=overwrite)


def rest_before(bank: ExtendedBank, rest_s: float, step_s: float = 0.05) -> None:
    """Hold every channel of ``bank`` at zero deflection for ``rest_s`` seconds."""
    n = math.ceil(rest_s / step_s - 1e-9)
    if n > 0:
        bank.run(np.zeros(n), rest_s / n)
