"""A K&C rig's own mechanics as a file writes them (a rig scenario's ``rig`` mapping, a virtual
rig's truth's): the keys in the units chassis engineers quote them in, converted to SI once, here.

::

    rig:
      pad_friction_n: 12                  # each floating pad's bearing friction, x and y [N]
      pad_compliance_mm_per_kn: 3.0       # each pad's compliance in x and y, in series [mm/kN]
      clamp_lateral_mm_per_kn: 0.01       # the body clamp's compliance in y [mm/kN]
      clamp_vertical_mm_per_kn: 0.01      # in z [mm/kN]
      clamp_roll_deg_per_knm: 0.003       # about x [deg/(kN·m)]
      clamp_pitch_deg_per_knm: 0.003      # about y [deg/(kN·m)]

Every key is optional, 0 (the ideal rig's) when absent (:class:`elastokin.vehicle.model.elements.RigMechanics`).
"""

from __future__ import annotations

import math
from typing import Any

from elastokin.core.documents import Document, Fields, KeyPath
from elastokin.vehicle.model.elements import RigMechanics

#: file key -> (RigMechanics field, SI per file unit, the largest value accepted [file unit], unit):
#: the bounds far beyond a rig (a pad that slips at 1 kN is no floating pad, a clamp yielding 1 mm/kN
#: no clamp), well within what MuJoCo resolves.
KEYS = {
    "pad_friction_n": ("pad_friction_n", 1.0, 1000.0, "N"),
    "pad_compliance_mm_per_kn": ("pad_compliance_m_per_n", 1e-6, 100.0, "mm/kN"),
    "clamp_lateral_mm_per_kn": ("clamp_lateral_m_per_n", 1e-6, 1.0, "mm/kN"),
    "clamp_vertical_mm_per_kn": ("clamp_vertical_m_per_n", 1e-6, 1.0, "mm/kN"),
    "clamp_roll_deg_per_knm": ("clamp_roll_rad_per_nm", math.radians(1.0) * 1e-3, 1.0, "deg/(kN·m)"),
    "clamp_pitch_deg_per_knm": ("clamp_pitch_rad_per_nm", math.radians(1.0) * 1e-3, 1.0, "deg/(kN·m)"),
}


def parse_rig(doc: Document, path: KeyPath, data: Any) -> RigMechanics:
    """The rig mechanics of the ``rig`` mapping ``data`` (:data:`KEYS`, file units) found at ``path``
    of ``doc``; InputError there for a key not known, a value negative, non-finite or beyond its
    bound, or the pads' compliance without their friction."""
    fields = Fields.of(doc, path, data, tuple(KEYS))
    rig = RigMechanics(**{name: si * fields.number(key, 0.0, nonneg=True, at_most=bound, unit=unit)
                          for key, (name, si, bound, unit) in KEYS.items() if fields.has(key)})
    if rig.pad_compliance_m_per_n and not rig.pad_friction_n:
        raise fields.fail("pad_compliance_mm_per_kn", "acts only in series with the pads' friction: expected "
                          "pad_friction_n beside it (a frictionless pad floats whatever its compliance)")
    return rig


def rig_values(rig: RigMechanics) -> dict[str, float]:
    """The file's mapping of ``rig`` (file units), the ideal rig's zeros left out."""
    return {key: getattr(rig, name) / si for key, (name, si, _, _) in KEYS.items() if getattr(rig, name)}
