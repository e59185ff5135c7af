"""The K&C test of a vehicle (`vsim kc`): the standard triangles played on a fresh rig, their samples
turned into the legs the metric definitions read."""

from __future__ import annotations

import dataclasses
from typing import Callable, Mapping

import numpy as np

from elastokin.vehicle.model.definition import CORNERS, VehicleDefinition
from elastokin.vehicle.model.elements import BuildOptions
from elastokin.vehicle.model.statics import cg_height
from elastokin.vehicle.scenarios.channels import AXLES
from elastokin.vehicle.model.steering_axis import steering_axis
from elastokin.vehicle.scenarios.kc_tests import STEERING, TESTS, Triangle, triangle_input
from elastokin.vehicle.simulation.kc_triangles import design_contact_base, run_triangle
from elastokin.vehicle.simulation.outputs import RigOutputs, WheelOutputs
from elastokin.vehicle.simulation.rig import KCRig
from elastokin.analysis.kc_metrics import (CarFigures, Leg, bump_loop_widths, car_metrics, fit_window, steering_metrics,
                                          triangle_metrics)
from elastokin.tyres.magic_formula import coefficients
from elastokin.tyres.tir_file import read_tir
from elastokin.analysis.loops import Branches

#: Per-wheel quantities the metric definitions read, from one rig sample's wheel (SI).
WHEEL_QUANTITIES: dict[str, Callable[[WheelOutputs], float]] = {
    "pad_height": lambda w: w.pad_height, "toe": lambda w: w.toe, "camber": lambda w: w.camber,
    "steer": lambda w: w.steer, "wheel_travel": lambda w: w.travel, "half_track": lambda w: w.half_track,
    "wheel_centre_x": lambda w: w.wheel_centre[0], "wheel_centre_y": lambda w: w.wheel_centre[1],
    "pad_fx": lambda w: w.pad_force[0], "pad_fy": lambda w: w.pad_force[1], "pad_fz": lambda w: w.pad_force[2],
    "pad_mz": lambda w: w.pad_torque,
}


def rig_leg(samples: list[RigOutputs], test: Triangle | None = None) -> Leg:
    """The :data:`Leg` of samples measured on the rig; with the ``test`` that made them, its input
    at the samples' times as quantity ``rack`` (the rack displacement [m]) and ``centre_fx`` (the
    force Fx at each wheel centre [N]: a test at the centres' input, else 0)."""
    def leg(quantity: str, corner: str) -> np.ndarray:
        if quantity in ("rack", "centre_fx") and test is not None:
            scale = 1.0 if quantity == "rack" else (test.at == "centre") * test.pattern[CORNERS.index(corner)]
            return scale * np.array([triangle_input(test, o.time) for o in samples])
        return np.array([WHEEL_QUANTITIES[quantity](o.wheels[corner]) for o in samples])
    return leg


def branches(down: list[RigOutputs], up: list[RigOutputs], x, y) -> Branches:
    """Branches of ``y(sample)`` against ``x(sample)`` from the samples of :func:`run_triangle`."""
    return Branches(np.array([x(o) for o in down]), np.array([y(o) for o in down]),
                    np.array([x(o) for o in up]), np.array([y(o) for o in up]))


#: Each test's (down, up) legs, by test name (:data:`TESTS` and :data:`STEERING`).
Legs = Mapping[str, tuple[Leg, Leg]]
#: Each test's (down, up) rig samples, by test name.
Samples = dict[str, tuple[list[RigOutputs], list[RigOutputs]]]
SEQUENCE = (*TESTS, STEERING)   #: the tests of `vsim kc`, in their order


def rig_samples(rig: KCRig) -> Samples:
    """Run the K&C sequence (:data:`SEQUENCE`) on ``rig``, each test from design with virgin bushings."""
    out = {t.name: run_triangle(rig, t) for t in SEQUENCE}
    rig.reset()
    return out


def legs_of(samples: Samples) -> dict[str, tuple[Leg, Leg]]:
    """The :data:`Legs` of rig samples."""
    test = {t.name: t for t in SEQUENCE}
    return {name: (rig_leg(down, test[name]), rig_leg(up, test[name])) for name, (down, up) in samples.items()}


def metrics_of_legs(legs: Legs, amplitude: Mapping[str, float], vehicle: VehicleDefinition,
                    base: Mapping[str, float]) -> dict[str, dict[str, float]]:
    """The metrics per axle (keys of :data:`elastokin.analysis.kc_metrics.METRICS`) of every test's
    legs, fitted over ±80 % of its ``amplitude`` [m, N, N·m], for ``vehicle`` (tyre radius, car
    figures, steering axis) with contact bases ``base`` [m]."""
    radius, out = vehicle.tyre.radius, {}
    for axle in AXLES:
        m = {}
        for t in TESTS:
            m |= triangle_metrics(t.name, axle, *legs[t.name], fit_window(t.name, amplitude[t.name], base[axle]),
                                  base[axle], radius)
        out[axle] = m | bump_loop_widths(axle, *legs["bump"], fit_window("bump", amplitude["bump"], base[axle]))
    car = car_figures(vehicle)
    window = fit_window(STEERING.name, amplitude[STEERING.name], base["front"])
    out["front"] |= (steering_metrics(*legs[STEERING.name], window, base["front"], car)
                     | dataclasses.asdict(steering_axis(vehicle)))
    return car_metrics(out, car)


def kc_metrics(rig: KCRig, keep: Callable[[Samples], object] | None = None) -> dict[str, dict[str, float]]:
    """Run the K&C sequence (:data:`SEQUENCE`) on ``rig``; metrics per axle (keys of
    :data:`elastokin.analysis.kc_metrics.METRICS`). ``keep`` is given the tests' samples (to write the curves)."""
    samples = rig_samples(rig)
    if keep is not None:
        keep(samples)
    return metrics_of_legs(legs_of(samples), {t.name: t.amplitude for t in SEQUENCE}, rig.vehicle,
                           design_contact_base(rig))


def car_figures(vehicle: VehicleDefinition) -> CarFigures:
    """The wheelbase, centre-of-mass height and tyre vertical stiffness (at its nominal load, from
    the tyre's .tir when the vehicle names one) of ``vehicle``."""
    tyre = vehicle.tyre.property_file
    return CarFigures(vehicle.front.hardpoints["wheel_centre"][0] - vehicle.rear.hardpoints["wheel_centre"][0],
                      cg_height(vehicle),
                      None if tyre is None else float(coefficients(read_tir(tyre))["VERTICAL_STIFFNESS"]),
                      vehicle.front.rack_travel_per_rev)


def vehicle_kc(vehicle: VehicleDefinition, options: BuildOptions = BuildOptions(),
               keep: Callable[[Samples], object] | None = None) -> dict[str, dict[str, float]]:
    """K&C metrics of ``vehicle`` built with ``options`` (on a fresh rig); ``keep`` as for :func:`kc_metrics`."""
    return kc_metrics(KCRig(vehicle, options), keep)
