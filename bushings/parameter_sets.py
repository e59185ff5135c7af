"""Named parameter sets: one bushing direction's law as written in a YAML file of ``models/bushings/``
(or anywhere), with its provenance and law extensions; loading, validating and saving them."""

from __future__ import annotations

import copy
import functools
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Mapping


from elastokin.bushings.effects import Effects, effects_to_si
from elastokin.bushings.parameters import MODELS, ChannelParams, check_one_elastic_law, model_keys, to_si
from elastokin.core.documents import Document, dump_yaml
from elastokin.core.errors import InputError
from elastokin.core.files import atomic_output, is_file, read_text
from elastokin.core.shipped import PARAMETER_SET_DIR


@dataclass(frozen=True)
class ParameterSet:
    """A named, cited parameter set for one bushing direction, as written in its YAML file."""

    name: str
    model: str
    quantity: str
    values: Mapping[str, Any]  #: user-facing values in the thesis's units
    source: str                #: provenance (publication, figure, measurement, assumption)
    path: Path | None = None
    effects: Mapping[str, Any] = field(default_factory=dict)  #: law extensions, see :mod:`elastokin.bushings.effects`

    def effects_si(self) -> Effects:
        """The set's state extensions (preload, asymmetry, Mullins, self-heating, backlash) in SI."""
        return effects_to_si(self.effects, self.quantity, str(self.path or self.name))

    def channel(self, model: str | None = None) -> ChannelParams:
        """SI parameters of this set, optionally read as another model.

        Reading as another model keeps the parameters that model uses (e.g. an STVS set read as
        ``sts`` drops Co and pw; read as ``sts_continuous`` it takes Ct = 2·Ff·Kr, Coveney's
        limit of the discrete ladder); a parameter the other model needs and the set lacks is an
        error naming this set.
        """
        target = model or self.model
        values = dict(self.values)
        check_one_elastic_law(self.model, values, str(self.path or self.name))   # before another model drops one
        if target != self.model:
            if target in ("sts_continuous", "stsn") and "Ct" not in values and {"Ff", "Kr"} <= set(values):
                values["Ct"] = 2.0 * values["Ff"] * values["Kr"]
            if not isinstance(target, str) or target not in MODELS:
                raise InputError(f"unknown model {target!r}; expected one of {', '.join(MODELS)}",
                                 source=str(self.path or self.name), key="model")
            required, optional = model_keys(target, values)
            values = {k: v for k, v in values.items() if k in required + optional}
        return to_si(target, values, self.quantity, str(self.path or self.name))


def parse_parameter_set(data: Any, source: str, name: str | None = None) -> ParameterSet:
    """Validate the mapping of a parameter-set file (keys: model, quantity, source, params)."""
    if not isinstance(data, Mapping):
        raise InputError("expected a mapping with keys model, params, source", source=source)
    allowed = {"name", "model", "quantity", "source", "description", "params", "effects"}
    unknown = sorted(set(data) - allowed)
    if unknown:
        raise InputError(f"unknown key {unknown[0]!r}; expected {', '.join(sorted(allowed))}",
                         source=source, key=unknown[0])
    for key in ("model", "params"):
        if key not in data:
            raise InputError("missing key", source=source, key=key)
    for key in ("params", "effects"):
        if not isinstance(data.get(key, {}), Mapping):
            raise InputError(f"expected a mapping, got {data[key]!r}", source=source, key=key)
    for key in ("name", "source", "description"):
        if not isinstance(data.get(key, ""), str):
            raise InputError(f"expected text, got {str(data[key])[:80]!r}", source=source, key=key)
    pset = ParameterSet(name=str(data.get("name", name or source)), model=str(data["model"]),
                        quantity=str(data.get("quantity", "translation")), values=dict(data["params"]),
                        source=str(data.get("source", "unspecified")),
                        path=Path(source) if source.endswith((".yaml", ".yml")) else None,
                        effects=dict(data.get("effects") or {}))
    pset.channel()  # validate now, so errors name this file
    pset.effects_si()
    return pset


def load_parameter_set(name_or_path: str | Path) -> ParameterSet:
    """Load a parameter set by name (a file in ``models/bushings/``) or by path."""
    path = Path(name_or_path)
    if path.suffix not in (".yaml", ".yml"):
        path = PARAMETER_SET_DIR / f"{name_or_path}.yaml"
    if not is_file(path):
        known = ", ".join(sorted(p.stem for p in PARAMETER_SET_DIR.glob("*.yaml")))
        raise InputError(f"no parameter set {str(name_or_path)!r}; known sets: {known}", source=str(path))
    # a vehicle build reads the same few files once per bushing direction: parsed once per content;
    # a copy keeps the cached set intact
    return copy.deepcopy(_parsed(str(path), read_text(path)))


@functools.lru_cache(maxsize=128)
def _parsed(path: str, text: str) -> ParameterSet:
    return parse_parameter_set(Document(text, path).data, path, name=Path(path).stem)


def save_parameter_set(pset: ParameterSet, path: str | Path) -> Path:
    """Write a parameter set in the format of ``models/bushings/*.yaml`` (read back by
    :func:`load_parameter_set`), atomically."""
    data: dict[str, Any] = {"model": pset.model, "quantity": pset.quantity, "source": pset.source,
                            "params": {k: _plain(v) for k, v in pset.values.items()}}
    if pset.effects:
        data["effects"] = {k: float(v) for k, v in pset.effects.items()}
    with atomic_output(Path(path)) as tmp:
        tmp.write_text(dump_yaml(data, sort_keys=False, default_flow_style=None, width=10_000,
                                      allow_unicode=True))
    return Path(path)


def _plain(v: Any) -> Any:
    """A parameter value as a YAML scalar (int or float), or a list of them (a curve: of pairs)."""
    if isinstance(v, (list, tuple)):
        return [_plain(x) if isinstance(x, (list, tuple)) else float(x) for x in v]
    return int(v) if isinstance(v, int) else float(v)


def available_parameter_sets() -> list[str]:
    """Names of the parameter sets shipped in ``models/bushings/``."""
    return sorted(p.stem for p in PARAMETER_SET_DIR.glob("*.yaml"))
