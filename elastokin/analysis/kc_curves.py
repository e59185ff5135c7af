"""The curves behind `vsim kc`'s metrics as a K&C rig delivers them: one CSV per test (``bump.csv``,
``roll.csv``, ``lateral.csv``, ``longitudinal.csv``, ``drive.csv``, ``aligning.csv``, ``steering.csv``), a row per
sample of its unloading then loading leg, a column per quantity and wheel with its unit in its
name (``time_s``, ``rack_mm``, ``toe_fl_deg``, ``pad_fz_rr_n`` …; ISO 8855 signs as in
:data:`elastokin.analysis.kc_metrics.METRICS`). Read back, or read from a rig, each file's legs are
split at the extremes of its test's input, and its metrics are those `vsim kc` computes."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from elastokin.analysis.kc_metrics import Leg
from elastokin.analysis.kc_test import SEQUENCE, Legs, Samples, metrics_of_legs, rig_leg
from elastokin.vehicle.model.definition import VehicleDefinition
from elastokin.vehicle.model.geometry import contact_point
from elastokin.core.errors import InputError
from elastokin.core.tables import read_csv_columns, write_csv_columns
from elastokin.vehicle.scenarios.channels import AXLES, CORNER_TAGS

#: Each per-wheel quantity's unit in its column name and the factor from SI to it.
UNITS = {"pad_height": ("mm", 1e3), "wheel_travel": ("mm", 1e3), "toe": ("deg", math.degrees(1.0)),
         "camber": ("deg", math.degrees(1.0)), "steer": ("deg", math.degrees(1.0)), "half_track": ("mm", 1e3),
         "wheel_centre_x": ("mm", 1e3), "wheel_centre_y": ("mm", 1e3), "pad_fx": ("n", 1.0), "pad_fy": ("n", 1.0),
         "pad_fz": ("n", 1.0), "pad_mz": ("nm", 1.0), "centre_fx": ("n", 1.0)}
#: The quantity only a test at the wheel centres needs (its input, 0 in the others' files).
CENTRE_INPUT = "centre_fx"
#: The column of each test's input (a wheel whose input rises with the test's, or the rack) and its
#: factor from the test's input in SI (the braking force: −Fx).
INPUT_COLUMNS = {"bump": ("pad_height_fl_mm", 1e3), "roll": ("pad_height_fr_mm", 1e3), "lateral": ("pad_fy_fl_n", 1.0),
                 "longitudinal": ("pad_fx_fl_n", -1.0), "drive": ("centre_fx_fl_n", 1.0), "aligning": ("pad_mz_fl_nm", 1.0),
                 "steering": ("rack_mm", 1e3)}
_MIN_ROWS = 8   #: a leg needs a few samples on each side of design


def column(quantity: str, corner: str) -> str:
    """The CSV column of ``quantity`` (a key of :data:`UNITS`) at ``corner``."""
    return f"{quantity}_{CORNER_TAGS[corner]}_{UNITS[quantity][0]}"


def write_curves(folder: Path, samples: Samples) -> list[Path]:
    """Write each test's samples (:func:`elastokin.analysis.kc_test.rig_samples`) as ``folder/<test>.csv``; the paths."""
    folder.mkdir(parents=True, exist_ok=True)
    test = {t.name: t for t in SEQUENCE}
    written = []
    for name, (down, up) in samples.items():
        rows = down + up
        leg = rig_leg(rows, test[name])
        columns = {"time_s": np.array([o.time for o in rows])}
        if name == "steering":
            columns["rack_mm"] = 1e3 * leg("rack", "front_left")
        for corner in CORNER_TAGS:
            for quantity, (_, factor) in UNITS.items():
                columns[column(quantity, corner)] = factor * leg(quantity, corner)
        path = folder / f"{name}.csv"
        write_csv_columns(path, columns)
        written.append(path)
    return written


def read_curves(folder: Path) -> tuple[Legs, dict[str, float]]:
    """Every test's (down, up) legs from ``folder/<test>.csv`` (the layout of :func:`write_curves`;
    other columns ignored), and its amplitude (the input's largest magnitude) [m, N or N·m].
    InputError naming the file for a missing file or column, a non-number or a leg with too few samples."""
    legs, amplitude = {}, {}
    for t in SEQUENCE:
        path = folder / f"{t.name}.csv"
        if not path.is_file():
            raise InputError(f"no {t.name} curves; expected {path.name} ({', '.join(s.name + '.csv' for s in SEQUENCE)}, "
                             f"as vsim kc --curves writes them)", source=str(folder))
        needed = ["time_s"] + [INPUT_COLUMNS[t.name][0]] * (t.name == "steering") + [
            column(q, c) for c in CORNER_TAGS for q in UNITS if q != CENTRE_INPUT or t.at == "centre"]
        data = read_csv_columns(path, needed, 4 * _MIN_ROWS)
        name, factor = INPUT_COLUMNS[t.name]
        drive = data[name] / factor
        # unloading from the largest value before the smallest, loading from there to the largest after it
        bottom = int(np.argmin(drive))
        top, end = int(np.argmax(drive[:bottom + 1])), bottom + int(np.argmax(drive[bottom:])) + 1
        if bottom - top < _MIN_ROWS or end - bottom < _MIN_ROWS:
            raise InputError(f"column {name}: expected an unloading leg from its largest value to its smallest, then a "
                             f"loading leg, each of at least {_MIN_ROWS} samples; got the smallest at line {bottom + 2}, "
                             f"the largest values before and after it at lines {top + 2} and {end + 1}", source=str(path))
        legs[t.name] = tuple(_leg(data, slice(a, b), drive) for a, b in ((top, bottom + 1), (bottom, end)))
        amplitude[t.name] = float(np.max(np.abs(drive)))
    return legs, amplitude


def _leg(data: dict[str, np.ndarray], rows: slice, drive: np.ndarray) -> Leg:
    def leg(quantity: str, corner: str) -> np.ndarray:
        if quantity == "rack":
            return drive[rows]
        return data[column(quantity, corner)][rows] / UNITS[quantity][1]
    return leg


def curves_metrics(folder: Path, vehicle: VehicleDefinition) -> dict[str, dict[str, float]]:
    """The metrics `vsim kc` gives (per axle, :data:`elastokin.analysis.kc_metrics.METRICS`) of the
    curves in ``folder`` (:func:`read_curves`), measured on ``vehicle`` (its tyre radius, contact
    bases at design, car figures and steering axis)."""
    legs, amplitude = read_curves(folder)
    return metrics_of_legs(legs, amplitude, vehicle, design_base(vehicle))


def design_base(vehicle: VehicleDefinition) -> dict[str, float]:
    """Each axle's lateral distance between its left and right contact points at design [m]."""
    out = {}
    for axle in AXLES:
        a = getattr(vehicle, axle)
        out[axle] = 2.0 * float(contact_point(a.hardpoints["wheel_centre"], a.static_toe, a.static_camber, 1.0,
                                              vehicle.tyre.radius)[1])
    return out
