"""The industry's tyre property file (``.tir``, the TNO / Adams format): a TeimOrbit file
(:mod:`elastokin.core.teim_orbit`) whose units and Magic Formula are checked.

A table section (``[SHAPE]``, ``[DEFLECTION_LOAD_CURVE]``, ...) holds a ``{column names}`` line and
rows of numbers. Only SI files are read: ``[UNITS]`` must say meter, newton, radian, kg and second
(a file in other units is refused rather than converted key by key), and ``[MODEL] FITTYP`` must
name a Magic Formula this software evaluates (:data:`FITTYPS`).
"""

from __future__ import annotations

from pathlib import Path

from elastokin.core.teim_orbit import TeimOrbitFile, read_teim_orbit

#: FITTYP values read, with the Magic Formula version each names: MF 5.2 files say 6 (MF-Tyre 5.2,
#: Adams' PAC2002), 21 (MF-Tyre) or 52 (files written by hand), as MFeval reads them; MF-Tyre 5.0
#: and 5.1 files (FITTYP 5) differ in equations not checked here and stay refused.
FITTYPS = {6: "MF 5.2", 21: "MF 5.2", 52: "MF 5.2", 61: "MF 6.1", 62: "MF 6.2"}
#: [UNITS] keys and the SI names accepted for each (lower case).
SI_UNITS = {"LENGTH": ("meter", "metre", "m"), "FORCE": ("newton", "n"), "ANGLE": ("radian", "radians", "rad"),
            "MASS": ("kg", "kilogram"), "TIME": ("second", "sec", "s")}


class TirFile(TeimOrbitFile):
    """A read ``.tir`` file (see :class:`elastokin.core.teim_orbit.TeimOrbitFile`)."""

    @property
    def fittyp(self) -> int:
        """``[MODEL] FITTYP``: which Magic Formula the coefficients fit."""
        return int(self.number("MODEL", "FITTYP"))


def read_tir(path: str | Path) -> TirFile:
    """Read and check the ``.tir`` file ``path``: InputError naming the file, line, section and key
    for a line that is neither a section, an entry, a comment nor a table row, a key given twice,
    a value that is neither a finite number nor a quoted text, units other than SI, or a FITTYP
    other than :data:`FITTYPS`."""
    tir = read_teim_orbit(path, "tyre property file", kind=TirFile)
    _check_units(tir)
    if tir.number("MODEL", "FITTYP") not in FITTYPS:
        raise tir.error("MODEL", "FITTYP", f"unknown Magic Formula {tir.values['MODEL']['FITTYP']!r}; expected one of "
                                           f"{', '.join(f'{k} ({v})' for k, v in FITTYPS.items())}")
    return tir


def _check_units(tir: TirFile) -> None:
    for key, accepted in SI_UNITS.items():
        unit = tir.text("UNITS", key).lower()
        if unit not in accepted:
            raise tir.error("UNITS", key, f"'{unit}' is not SI; expected '{accepted[0]}' (files in other units are "
                                          f"not converted: convert its dimensional keys first)")
