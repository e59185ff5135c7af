"""The .tir reader (issue 26, step 1): the TNO / Adams format read into numbers, texts and tables with
their lines; every malformed file refused naming the file, line, section and key."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from elastokin.core.errors import InputError
from elastokin.tyres.tir_file import read_tir

SAMPLE = """[MDI_HEADER]
FILE_TYPE                ='tir'
FILE_VERSION             = 3.0
! : COMMENT :      a test file, not a tyre
$---------------------------------------------------------------units
[UNITS]
LENGTH                   = 'meter'
FORCE                    = 'newton'
ANGLE                    = 'radians'
MASS                     = 'kg'
TIME                     = 'second'
[MODEL]
FITTYP                   = 61                  $Magic Formula 6.1
TYRESIDE                 = 'LEFT'              $ a '$' in a comment
VXLOW                    = 1
[dimension]
unloaded_radius          = 0.3135
WIDTH                    = 0.205
[VERTICAL]
FNOMIN                   = 4.0D+03
VERTICAL_STIFFNESS       = 2.1e5
[SHAPE]
{radial width}
 1.0    0.0
 1.0    0.4
 0.95   0.9
[LATERAL_COEFFICIENTS]
PCY1                     = +1.3
PEY1                     = -.8
"""


def write(tmp_path: Path, text: str | bytes) -> Path:
    path = tmp_path / "t.tir"
    path.write_bytes(text if isinstance(text, bytes) else text.encode())
    return path


def test_sections_numbers_texts_tables_and_lines_are_read(tmp_path: Path) -> None:
    tir = read_tir(write(tmp_path, SAMPLE))
    assert tir.fittyp == 61 and tir.text("MODEL", "TYRESIDE") == "LEFT"
    assert tir.number("DIMENSION", "UNLOADED_RADIUS") == 0.3135          # case-insensitive keys and sections
    assert tir.number("VERTICAL", "FNOMIN") == 4000.0                     # Fortran's D exponent
    assert tir.number("LATERAL_COEFFICIENTS", "PCY1") == 1.3 and tir.number("LATERAL_COEFFICIENTS", "PEY1") == -0.8
    assert tir.columns["SHAPE"] == ("radial", "width")
    np.testing.assert_array_equal(tir.tables["SHAPE"], [[1.0, 0.0], [1.0, 0.4], [0.95, 0.9]])
    assert tir.lines[("VERTICAL", "VERTICAL_STIFFNESS")] == SAMPLE.splitlines().index("VERTICAL_STIFFNESS       = 2.1e5") + 1
    assert tir.number("LATERAL_COEFFICIENTS", "PKY1", default=-15.0) == -15.0   # absent, with a default


@pytest.mark.parametrize("edit, expected", [
    (("FITTYP                   = 61", "FITTYP = 5"), r"t\.tir:13: \[MODEL\] FITTYP: unknown Magic Formula 5\.0; expected one "
                                                      r"of 6 \(MF 5\.2\), 21 \(MF 5\.2\), 52 \(MF 5\.2\), 61 \(MF 6\.1\), 62"),
    (("FITTYP                   = 61", "FITTYP = 61.5"), r"\[MODEL\] FITTYP: unknown Magic Formula 61\.5"),
    (("LENGTH                   = 'meter'", "LENGTH = 'mm'"), r"t\.tir:7: \[UNITS\] LENGTH: 'mm' is not SI; expected 'meter'"),
    (("ANGLE                    = 'radians'", ""), r"t\.tir: \[UNITS\] ANGLE: missing; expected a quoted text"),
    (("WIDTH                    = 0.205", "WIDTH = 0.205\nWIDTH = 0.21"), r"t\.tir:19: \[DIMENSION\] WIDTH: given twice \(first at line 18\)"),
    (("PCY1                     = +1.3", "PCY1 = 1e400"), r"t\.tir:\d+: \[LATERAL_COEFFICIENTS\] PCY1: expected a finite number or a quoted text, got '1e400'"),
    (("PCY1                     = +1.3", "PCY1 = abc"), r"\[LATERAL_COEFFICIENTS\] PCY1: expected a finite number or a quoted text"),
    (("PCY1                     = +1.3", "PCY1 1.3"), r"\[LATERAL_COEFFICIENTS\]: expected KEY = value"),
    ((" 0.95   0.9", " 0.95"), r"\[SHAPE\]: expected a row of 2 numbers, got '0.95'"),
    (("[UNITS]", "[VERTICAL]"), r"section \[VERTICAL\] appears twice"),
    (("[MDI_HEADER]", ""), r"t\.tir:2: .FILE_TYPE  .* before any \[SECTION\]"),
])
def test_malformed_files_are_refused_naming_line_section_and_key(tmp_path: Path, edit: tuple[str, str],
                                                                   expected: str) -> None:
    old, new = edit
    assert old in SAMPLE
    with pytest.raises(InputError, match=expected):
        read_tir(write(tmp_path, SAMPLE.replace(old, new, 1)))


def test_a_missing_or_textual_coefficient_names_section_and_key(tmp_path: Path) -> None:
    tir = read_tir(write(tmp_path, SAMPLE))
    with pytest.raises(InputError, match=r"t\.tir: \[LATERAL_COEFFICIENTS\] PKY1: missing; expected a number"):
        tir.number("LATERAL_COEFFICIENTS", "PKY1")
    with pytest.raises(InputError, match=r"\[SCALING_COEFFICIENTS\] LFZO: missing.*has no \[SCALING_COEFFICIENTS\] section"):
        tir.number("SCALING_COEFFICIENTS", "LFZO")
    with pytest.raises(InputError, match=r"t\.tir:14: \[MODEL\] TYRESIDE: expected a number, got 'LEFT'"):
        tir.number("MODEL", "TYRESIDE")


def test_unreadable_files_are_refused(tmp_path: Path) -> None:
    with pytest.raises(InputError, match=r"nope\.tir: no such tyre property file"):
        read_tir(tmp_path / "nope.tir")
    with pytest.raises(InputError, match=r"t\.tir: .*UTF-8"):
        read_tir(write(tmp_path, SAMPLE.encode() + b"\xff\xfe"))
