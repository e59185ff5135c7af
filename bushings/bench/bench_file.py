"""A bench file (one bushing law, a time step, a programme) and its run on the virtual bench → a table.

The file is in the thesis's units (N, mm, s); it is validated and converted to SI once, by
:func:`load_bench`. Time-series programmes give the columns ``t_s, e_mm, F_N``; a sweep gives
``amplitude_mm, frequency_hz, k_dyn_n_per_mm, tan_delta`` (first harmonic of the stabilised last
cycle, :func:`elastokin.bushings.frequency.first_harmonic`).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any, Mapping

import numpy as np

from elastokin.bushings.adams_bus import read_bus
from elastokin.bushings.bench.programmes import Sweep, TimeSeries, read_programme
from elastokin.bushings.effects import NO_EFFECTS, Effects
from elastokin.bushings.extended_bank import ExtendedBank
from elastokin.bushings.frequency import first_harmonic
from elastokin.bushings.parameter_sets import load_parameter_set
from elastokin.bushings.parameters import MODELS, ChannelParams, to_si
from elastokin.core.documents import Document, Fields
from elastokin.core.errors import InputError
from elastokin.core.shipped import BENCH_DIR, resolve
from elastokin.core.units import MM

#: Longest bench time step accepted [s]: the bench samples rubber that relaxes in tenths of a second.
MAX_DT_S = 1.0
_BENCH_KEYS = ("model", "params", "direction", "dt_s", "programme")


@dataclass(frozen=True)
class Bench:
    """A validated bench: one bushing channel (SI) under one programme."""

    source: str                     #: the bench file
    channel: ChannelParams
    dt_s: float                     #: time step [s] (for a sweep: the largest allowed real step)
    programme: TimeSeries | Sweep
    effects: Effects = NO_EFFECTS   #: the parameter set's law extensions (time-series programmes)


def parse_bench(data: Any, source: str, base_dir: Path | None = None) -> Bench:
    """Validate a bench mapping built in code (:func:`read_bench`); errors name ``source`` and the key."""
    return read_bench(Document.of_data(data, source), base_dir)


def read_bench(doc: Document, base_dir: Path | None = None) -> Bench:
    """Validate a bench document; errors name its file:line and the key.

    ``params`` is the name (or path) of a parameter set, read as ``model`` if given, an Adams bushing
    property file (``.bus``, its ``direction``'s curve and damping: x, y or z, default x), or an
    inline mapping in N, mm, s (``model`` then required).
    """
    f = doc.top(_BENCH_KEYS)
    for key in ("params", "dt_s", "programme"):
        f.raw(key)
    model = f.raw("model", None)
    if model is not None and (not isinstance(model, str) or model not in MODELS):
        raise f.fail("model", f"unknown model {model!r}; expected one of {', '.join(MODELS)}")
    params = f.raw("params")
    if f.has("direction") and not (isinstance(params, str) and Path(params).suffix.lower() == ".bus"):
        raise f.fail("direction", "a direction is read from an Adams property file (params: F.bus) only")
    effects = NO_EFFECTS
    if isinstance(params, Mapping):
        if model is None:
            raise f.fail("model", "missing key (needed with inline params)")
        channel = to_si(model, params, source=doc.where(f.path("params")))
    elif isinstance(params, str):
        channel, effects = _named_set(params, model, f, base_dir)
    else:
        raise f.fail("params", f"expected a parameter-set name or a mapping, got {params!r}")

    if channel.quantity != "translation":
        raise f.fail("params", f"the bench works in mm; set {params!r} is a {channel.quantity}")
    dt = f.raw("dt_s")
    if isinstance(dt, bool) or not isinstance(dt, (int, float)) or not 0.0 < dt <= MAX_DT_S:
        raise f.fail("dt_s", f"expected a positive time step of at most {MAX_DT_S:g} s, got {dt!r}")
    programme = read_programme(doc, f.path("programme"), float(dt), base_dir)
    if effects.active and isinstance(programme, Sweep):
        raise f.fail("params", f"set {params!r} has effects (state extensions), which a sweep's per-point restarts "
                               f"would misrepresent; play its sines as time-series programmes")
    return Bench(doc.source, channel, float(dt), programme, effects)


def _named_set(name: str, model: str | None, f: Fields, base_dir: Path | None) -> tuple[ChannelParams, Effects]:
    """A parameter set (SI law and effects) by name, or by path relative to the bench file; errors
    name both files."""
    path = Path(name)
    if path.suffix.lower() in (".yaml", ".yml", ".bus") and not path.is_absolute() and base_dir is not None:
        name = str(base_dir / path)
    direction = f.raw("direction", "x")
    if direction not in ("x", "y", "z"):
        raise f.fail("direction", f"expected x, y or z (the bench works in mm), got {direction!r}")
    try:
        pset = read_bus(name).parameter_set(direction) if path.suffix.lower() == ".bus" else load_parameter_set(name)
        return pset.channel(model), pset.effects_si()
    except InputError as exc:
        raise f.fail("params", str(exc)) from exc


def load_bench(path: str | Path) -> Bench:
    """Read and validate a bench YAML file, or a built-in bench programme by name (``bisine``)."""
    path = resolve(path, BENCH_DIR, "bench")
    return read_bench(Document.read(path, "no such bench file"), path.parent)


def run_bench(bench: Bench) -> dict[str, np.ndarray]:
    """Run the bench; returns the output columns in order (names carry the units)."""
    prog = bench.programme
    if isinstance(prog, Sweep):
        amplitude, frequency = (g.ravel() for g in np.meshgrid(prog.amplitudes_m, prog.frequencies_hz, indexing="ij"))
        result = first_harmonic(bench.channel, amplitude, frequency, cycles=prog.cycles,
                                points_per_cycle=prog.points_per_cycle, max_dt_s=bench.dt_s)
        return {"amplitude_mm": amplitude / MM, "frequency_hz": frequency,
                "k_dyn_n_per_mm": result.k_dyn_n_per_m * MM, "tan_delta": result.tan_delta}
    force = ExtendedBank([bench.channel], [bench.effects]).run(prog.e_m, bench.dt_s)[:, 0]
    return {"t_s": prog.t_s, "e_mm": prog.e_m / MM, "F_N": force}
