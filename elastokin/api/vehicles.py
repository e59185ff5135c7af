"""A vehicle as the API hands it out: a validated vehicle file whose numbers can be set by their place."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

from elastokin.core.errors import InputError
from elastokin.core.files import atomic_output
from elastokin.core.shipped import DEFAULT_VEHICLE
from elastokin.analysis.kc_curves import curves_metrics, write_curves
from elastokin.analysis.kc_test import vehicle_kc
from elastokin.vehicle.model.definition import BUSHING_MODELS, VehicleDefinition
from elastokin.vehicle.model.elements import BuildOptions
from elastokin.vehicle.model.file_overrides import PlaceError, file_value, vehicle_with
from elastokin.vehicle.model import vehicle_file
from elastokin.core.documents import Document

#: What the errors of :meth:`Vehicle.with_values` name as their source.
VALUES_SOURCE = "with_values"


def check_bushing_model(bushings: str | None) -> None:
    """InputError unless ``bushings`` is a bushing model to put on every direction, or None."""
    if bushings is not None and bushings not in BUSHING_MODELS:
        raise InputError(f"expected one of {', '.join(BUSHING_MODELS)} or None, got {bushings!r}", key="bushings")


@dataclass(frozen=True)
class Vehicle:
    """A vehicle: a validated vehicle file (format: ``models/vehicles/README.md``), SI and ISO 8855.

    Made by :func:`load_vehicle`; :meth:`with_values` gives a changed copy. ``definition`` is the
    validated model the simulation builds (hardpoints [m], rates [N/m], bushing laws).
    """

    definition: VehicleDefinition

    def __repr__(self) -> str:
        changed = "" if vehicle_file.as_filed(self.definition) else ", changed in code"
        return f"<Vehicle {self.name!r} from {self.path}{changed}>"

    @property
    def name(self) -> str:
        """The vehicle file's ``name``."""
        return self.definition.name

    @property
    def path(self) -> Path:
        """The file the vehicle was read from (for a changed copy: the file it was changed from)."""
        return self.definition.path

    @property
    def text(self) -> str:
        """The vehicle file's text (of a changed copy: the changed file), as recordings carry it."""
        return self.definition.text

    def value(self, place: str) -> float | None:
        """The number at a dotted ``place`` of the vehicle file, in the file's units.

        Args:
            place: e.g. ``"front.spring.rate"`` [N/m], ``"front.hardpoints.tie_rod_inner.z"`` [m],
                ``"bushings.e2_front.y.Kr"`` (a parameter of the direction's law, in the parameter
                set's units: N/mm, N, mm, s).

        Returns:
            The number, or None where the file leaves the key to its default.

        Raises:
            InputError: ``place`` is not a number of the file (the message says why).

        >>> import elastokin
        >>> elastokin.load_vehicle("c_segment").value("bushings.e2_front.y.Kr")
        2935.0
        """
        try:
            return file_value(Document(self.text, str(self.path)).data, place)
        except PlaceError as exc:
            raise InputError(str(exc), source=str(self.path), key=place) from None

    def with_values(self, values: Mapping[str, float]) -> Vehicle:
        """A copy with each dotted place of ``values`` set to its number (units as :meth:`value`).

        A bushing direction that names a parameter set gets the set's parameters written inline,
        with the one changed.

        Args:
            values: ``{place: number}``, e.g. ``{"bushings.e2_front.y.Kr": 3000.0, "front.spring.rate": 26e3}``.

        Returns:
            The changed vehicle, validated as a file is.

        Raises:
            InputError: a place that is not a number of the file, a value that is not a finite
                number, or one the file refuses (named by its place; source ``with_values``).

        >>> import elastokin
        >>> car = elastokin.load_vehicle("c_segment")
        >>> car.with_values({"bushings.e2_front.y.Kr": 3000.0}).value("bushings.e2_front.y.Kr")
        3000.0
        >>> car.value("bushings.e2_front.y.Kr")       # the original is unchanged
        2935.0
        """
        data = Document(self.text, str(self.path)).data
        for place, number in values.items():
            try:
                file_value(data, place)
            except PlaceError as exc:
                raise InputError(str(exc), source=VALUES_SOURCE, key=place) from None
            if isinstance(number, bool) or not isinstance(number, (int, float)) or not math.isfinite(number):
                raise InputError(f"expected a finite number, got {number!r}", source=VALUES_SOURCE, key=place)
        try:
            changed = vehicle_with(self.text, self.path, dict(values), VALUES_SOURCE)
        except PlaceError as exc:
            raise InputError(str(exc), source=VALUES_SOURCE) from None
        return Vehicle(changed)

    def kc_metrics(self, bushings: str | None = None, curves: str | Path | None = None) -> dict[str, dict[str, float]]:
        """The standard K&C metrics of the car on the virtual rig (``vsim kc``): bump, roll,
        lateral-force, longitudinal-force and aligning-torque triangles on both axles, a rack
        sweep, and the steering axis at design.

        Args:
            bushings: one bushing model on every direction (``linear``, ``sts``, ``rt``, ``stvs``);
                None: as the vehicle file says.
            curves: a folder to write the curves behind the metrics in, one CSV per test as a K&C
                rig delivers them (:mod:`elastokin.analysis.kc_curves`); None: not written.

        Returns:
            ``{"front": {metric: value}, "rear": {...}}``, the unit in each metric's name
            (``bump_camber_deg_per_m``; ISO 8855 signs: toe-in and camber top-out positive;
            definitions in :data:`elastokin.analysis.kc_metrics.METRICS`; the steering's on the
            front only).

        Raises:
            InputError: an unknown bushing model.
        """
        check_bushing_model(bushings)
        options = BuildOptions(bushing_model=bushings)
        if curves is None:
            return vehicle_kc(self.definition, options)
        return vehicle_kc(self.definition, options, lambda samples: write_curves(Path(curves), samples))

    def compare_kc(self, curves: str | Path, bushings: str | None = None) -> dict[str, dict[str, dict[str, float]]]:
        """The K&C metrics of curves measured on this car by a rig, beside the simulated car's.

        Args:
            curves: a folder of one CSV per test in the layout of ``vsim kc --curves``
                (:mod:`elastokin.analysis.kc_curves`).
            bushings: as for :meth:`kc_metrics`, for the simulated car.

        Returns:
            ``{axle: {metric: {"sim": value, "rig": value, "difference": rig − sim}}}`` for every
            metric both give (units in the names, :data:`elastokin.analysis.kc_metrics.METRICS`).

        Raises:
            InputError: a missing curve file or column, a non-number, a test without both legs,
                an unknown bushing model.
        """
        rig = curves_metrics(Path(curves), self.definition)
        sim = self.kc_metrics(bushings)
        return {axle: {key: {"sim": sim[axle][key], "rig": value, "difference": value - sim[axle][key]}
                       for key, value in rig[axle].items() if key in sim[axle]} for axle in sim}

    def save(self, path: str | Path, *, overwrite: bool = False) -> Path:
        """Write the vehicle file (as changed) to ``path``; its relative references (the tyre's
        ``property_file``) are then taken from ``path``'s folder.

        Raises:
            InputError: ``path`` exists and not ``overwrite``, or cannot be written.
        """
        path = Path(path)
        if path.exists() and not overwrite:
            raise InputError("the output exists; pass overwrite=True to replace it", source=str(path))
        with atomic_output(path) as partial:
            partial.write_text(self.text)
        return path


def load_vehicle(name_or_path: str | Path = DEFAULT_VEHICLE) -> Vehicle:
    """Load and validate a vehicle file, or a built-in vehicle by name.

    Args:
        name_or_path: a vehicle file, or a built-in name (``c_segment``, the default car;
            :func:`elastokin.built_ins` lists them).

    Returns:
        The :class:`Vehicle`.

    Raises:
        InputError: no such file or built-in (the built-in names listed), or a bad value, named by
            file:line, key and value.

    >>> import elastokin
    >>> elastokin.load_vehicle().name
    'c_segment'
    """
    return Vehicle(vehicle_file.load_vehicle(name_or_path))
