"""A K&C rig's own mechanics, nuisances the diagnosis fits beside the causes (issue 53 items 2, 3).
Written from what a rig is known to do, apart from the virtual rig's truth (which also has the clamp's
damping, and each pad's own compliance where this module assumes a typical pad's):

- the pads float in x and y so that the tyres do not scrub, but their bearings keep some Coulomb
  friction: the contact patches' sideways and fore-aft travel in pumping, roll and steering meets
  it, and a commanded lateral force reaches the car less it. It opens loops in half-track, camber,
  toe and the pads' vertical forces that read as a bushing's hysteresis or the struts' friction;
- the body's clamps yield: the body moves with the loads the pads put through the car (sideways and
  in roll under lateral force, in heave and pitch under vertical loads), while the rig measures the
  wheels against its bedplate. It reads as a softer axle or bushing.

Each is a column: the compared rows' derivative with respect to its value (the file unit of
:mod:`elastokin.vehicle.scenarios.rig_file`), from a baseline run of every test on a rig with it at
:attr:`Element.nominal` over the scenario's own rig (first order). The pads' friction is run with a
typical pad's compliance in series (:attr:`Element.beside`) where the scenario states none: a real
pad's friction acts through it, and the rigidly stuck pad of a bare Coulomb column misreads the
small contact-patch travels of a steering step. A Coulomb friction's effect is not proportional to
it, and it changes what a car cause that sticks and slips too (the struts' friction) does: when the
data show the pads' friction (:func:`not_proportional`), the diagnosis runs again on a rig with it
(:func:`on_rig`), each column then the change from it. The columns are projected out of
every residual with the transducers' (:class:`elastokin.diagnosis.kc_scorer.Scorer`), each held
between no effect and :attr:`Element.bound`, and what the data tell of each is reported.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from elastokin.diagnosis.kc_layout import Job, Layout
from elastokin.vehicle.model.elements import RigMechanics
from elastokin.vehicle.scenarios.rig_file import KEYS

RIG = "rig"


@dataclass(frozen=True)
class Element:
    """One element of the rig's mechanics the diagnosis fits."""

    key: str          #: its rig file key (:data:`elastokin.vehicle.scenarios.rig_file.KEYS`)
    label: str        #: for people
    unit: str         #: of the key's values
    nominal: float    #: the value its column's run adds to the scenario's rig [unit]
    bound: float      #: the largest value fitted [unit]: a rig's, generously
    floor: float      #: a value worth a word beyond this [unit] (and 3 standard uncertainties)
    beside: tuple[tuple[str, float], ...] = ()  #: (rig file key, value) its column's run sets where the rig has neither
    proportional: bool = True   #: whether its effect is, to first order, proportional to its value


#: The elements fitted, at nominal values of a typical rig's, each held below 2.5 times the most a
#: typical rig shows (:data:`elastokin.diagnosis.rig_chain.GRADES`: what a larger one would take is
#: left to the car's causes, as a transducer's calibration is held).
ELEMENTS = (
    Element("pad_friction_n", "the pads' friction", "N", 10.0, 50.0, 1.0,
            beside=(("pad_compliance_mm_per_kn", 3.5),), proportional=False),
    Element("clamp_lateral_mm_per_kn", "the body clamp's lateral compliance", "mm/kN", 0.01, 0.05, 0.001),
    Element("clamp_vertical_mm_per_kn", "the body clamp's vertical compliance", "mm/kN", 0.01, 0.05, 0.001),
    Element("clamp_roll_deg_per_knm", "the body clamp's roll compliance", "deg/(kN·m)", 0.003, 0.0125, 0.0003),
    Element("clamp_pitch_deg_per_knm", "the body clamp's pitch compliance", "deg/(kN·m)", 0.003, 0.0125, 0.0003),
)
BY_KEY = {e.key: e for e in ELEMENTS}


def with_element(rig: RigMechanics, element: Element, value: float) -> RigMechanics:
    """``rig`` with ``value`` [the element's unit] added to the element, and what it acts beside
    (:attr:`Element.beside`) set where ``rig`` has neither (a rig stating the element keeps its own)."""
    name, si, _, _ = KEYS[element.key]
    beside = {KEYS[key][0]: v * KEYS[key][1] for key, v in element.beside
              if not getattr(rig, name) and not getattr(rig, KEYS[key][0])}
    return replace(rig, **{name: getattr(rig, name) + value * si}, **beside)


def element_jobs(layout: Layout, element: Element) -> list[Job]:
    """The baseline runs of every test on its scenario's rig with ``element`` moved by its nominal value."""
    return [t.job for t in on_rig(layout, {element.key: element.nominal}).tests]


def element_column(rows: np.ndarray, baseline: np.ndarray, element: Element) -> np.ndarray:
    """(N, C) the rows' derivative with respect to ``element``'s value, from its runs' rows and the
    baseline's."""
    return (rows - baseline) / element.nominal


def not_proportional(shown: dict[str, float]) -> dict[str, float]:
    """Of the elements' values [their units] the data show (``shown``), those whose effect is not
    proportional to them: the rig to run on again."""
    return {key: value for key, value in shown.items() if not BY_KEY[key].proportional}


def on_rig(layout: Layout, values: dict[str, float]) -> Layout:
    """``layout`` with every test run on its scenario's rig with each element's value [its unit] of
    ``values`` added (:func:`with_element`)."""
    def moved(rig: RigMechanics) -> RigMechanics:
        for key, value in values.items():
            rig = with_element(rig, BY_KEY[key], value)
        return rig
    return replace(layout, tests=[replace(t, job=replace(t.job, scenario=replace(t.job.scenario,
                                                                                 rig=moved(t.job.scenario.rig))))
                                  for t in layout.tests])
