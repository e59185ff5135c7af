"""Virtual bushing bench: a bench YAML file (model, parameters, time step, programme) → a table.

The file is in the thesis's units (N, mm, s); it is validated and converted to SI once, by
:func:`load_bench`. Time-series programmes give the columns ``t_s, e_mm, F_N``; a sweep gives
``amplitude_mm, frequency_hz, k_dyn_n_per_mm, tan_delta`` (first harmonic of the stabilised last
cycle, :func:`bushings.frequency.first_harmonic`).
"""

from __future__ import annotations

import contextlib
import math
import os
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Iterator, Mapping

import numpy as np

from bushings.effects import NO_EFFECTS, Effects, ExtendedBank
from vsim_core.errors import InputError, read_yaml
from bushings.frequency import first_harmonic
from bushings.parameters import MODELS, ChannelParams, load_parameter_set, to_si
from bushings.bench.programmes import MM, Sweep, TimeSeries, parse_programme

_BENCH_KEYS = ("model", "params", "dt_s", "programme")


@dataclass(frozen=True)
class Bench:
    """A validated bench: one bushing channel (SI) under one programme."""

    source: str                     #: the bench file
    channel: ChannelParams
    dt_s: float                     #: time step [s] (for a sweep: the largest allowed real step)
    programme: TimeSeries | Sweep
    effects: Effects = NO_EFFECTS   #: the parameter set's law extensions (time-series programmes)


def parse_bench(data: Any, source: str, base_dir: Path | None = None) -> Bench:
    """Validate a bench mapping; errors name ``source`` and the key.

    ``params`` is the name (or path) of a parameter set, read as ``model`` if given, or an inline
    mapping in N, mm, s (``model`` then required).
    """
    if not isinstance(data, Mapping):
        raise InputError(f"expected a mapping with keys {', '.join(_BENCH_KEYS)}", source=source)
    unknown = sorted(set(data) - set(_BENCH_KEYS))
    if unknown:
        raise InputError(f"unknown key {unknown[0]!r}; expected {', '.join(_BENCH_KEYS)}",
                         source=source, key=unknown[0])
    for key in ("params", "dt_s", "programme"):
        if key not in data:
            raise InputError("missing key", source=source, key=key)
    model = data.get("model")
    if model is not None and model not in MODELS:
        raise InputError(f"unknown model {model!r}; expected one of {', '.join(MODELS)}", source=source, key="model")
    params = data["params"]
    effects = NO_EFFECTS
    if isinstance(params, Mapping):
        if model is None:
            raise InputError("missing key (needed with inline params)", source=source, key="model")
        channel = to_si(model, params, source=source)
    elif isinstance(params, str):
        channel, effects = _named_set(params, model, source, base_dir)
    else:
        raise InputError(f"expected a parameter-set name or a mapping, got {params!r}", source=source, key="params")
    if channel.quantity != "translation":
        raise InputError(f"the bench works in mm; set {params!r} is a {channel.quantity}", source=source, key="params")
    dt = data["dt_s"]
    if isinstance(dt, bool) or not isinstance(dt, (int, float)) or not 0.0 < dt < math.inf:
        raise InputError(f"expected a positive time step in s, got {dt!r}", source=source, key="dt_s")
    programme = parse_programme(data["programme"], float(dt), source, base_dir)
    if effects.active and isinstance(programme, Sweep):
        raise InputError(f"set {params!r} has effects (state extensions), which a sweep's per-point restarts "
                         f"would misrepresent; play its sines as time-series programmes", source=source, key="params")
    return Bench(source, channel, float(dt), programme, effects)


def _named_set(name: str, model: str | None, source: str, base_dir: Path | None) -> tuple[ChannelParams, Effects]:
    """A parameter set (SI law and effects) by name, or by path relative to the bench file; errors
    name both files."""
    path = Path(name)
    if path.suffix in (".yaml", ".yml") and not path.is_absolute() and base_dir is not None:
        name = str(base_dir / path)
    try:
        pset = load_parameter_set(name)
        return pset.channel(model), pset.effects_si()
    except InputError as exc:
        raise InputError(str(exc), source=source, key="params") from exc


def load_bench(path: Path) -> Bench:
    """Read and validate a bench YAML file."""
    return parse_bench(read_yaml(path, "no such bench file"), str(path), path.parent)


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


@contextlib.contextmanager
def atomic_output(path: Path) -> Iterator[Path]:
    """Yield a temporary path beside ``path``; rename it to ``path`` only if the block succeeds,
    so that a reader never sees a half-written file."""
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=path.suffix, dir=path.parent)
    os.close(fd)
    umask = os.umask(0)  # mkstemp creates 0600; give the file the usual permissions
    os.umask(umask)
    os.chmod(tmp, 0o666 & ~umask)
    try:
        yield Path(tmp)
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


def write_table(path: Path, columns: Mapping[str, np.ndarray]) -> None:
    """Write the columns as CSV with a header line, atomically."""
    with atomic_output(path) as tmp:
        np.savetxt(tmp, np.column_stack(list(columns.values())), delimiter=",", fmt="%.10g",
                   header=",".join(columns), comments="")
