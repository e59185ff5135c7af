"""The foundation (elastokin.core): the one YAML reader's errors, the one units table, atomic folders."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from elastokin.core import units
from elastokin.core.documents import Document, Fields, check_number
from elastokin.core.errors import InputError
from elastokin.core.files import atomic_directory

TEXT = """\
name: car
body:
  mass: 1200
  cg: [0.1, 0, 0.5]
body:
  mass: 5
"""


def test_a_repeated_key_is_refused_at_its_line():
    """YAML lets the last of two equal keys win silently (a 5 kg body): the reader refuses it."""
    with pytest.raises(InputError) as err:
        Document(TEXT, "car.yaml")
    assert str(err.value) == "car.yaml:5: body: duplicate key 'body'"


def test_errors_name_file_line_key_and_value():
    doc = Document(TEXT.split("body:\n  mass: 5")[0], "car.yaml")
    body = doc.top(("name", "body")).fields("body", ("mass", "cg"))
    with pytest.raises(InputError, match=r"^car\.yaml:3: body\.mass: expected a non-zero number, got 0$"):
        check_number(doc, body.path("mass"), 0, nonzero=True)
    with pytest.raises(InputError, match=r"^car\.yaml:4: body\.cg: expected a list of 2 numbers, got \[0\.1, 0, 0\.5\]$"):
        body.vector("cg", 2)
    with pytest.raises(InputError, match=r"^car\.yaml:3: body\.inertia: missing key$"):
        body.raw("inertia")
    assert body.vector("cg") == (0.1, 0.0, 0.5) and body.number("mass", positive=True) == 1200.0


def test_values_built_in_code_are_checked_alike_without_a_line():
    doc = Document.of_data({"spring": {"rate": -3}}, "with_extensions")
    with pytest.raises(InputError, match=r"^with_extensions: spring\.rate: expected a positive number, got -3$"):
        Fields.of(doc, ("spring",), doc.data["spring"], ("rate",)).number("rate", positive=True)


def test_a_file_that_is_not_utf8_is_named(tmp_path: Path):
    path = tmp_path / "car.yaml"
    path.write_bytes(b"name: \xff\xfe\n")
    with pytest.raises(InputError, match="car.yaml: not UTF-8 text"):
        Document.read(path)


def test_the_units_table_gives_the_exact_factors_of_the_boundary():
    assert units.MM == 1e-3 and units.DEG == math.pi / 180.0 == math.radians(1.0)
    assert units.factor("m", "mm") == 1000.0 and units.factor("rad", "deg") == math.degrees(1.0)
    assert units.per_si("deg") == math.degrees(1.0) and units.si("daN") == 10.0 and units.si("kN·m") == 1e3
    assert units.factor("arcmin", "deg") == 1.0 / 60.0 and units.factor("ms", "s") == 1e-3
    assert units.si("deg/s") == math.pi / 180.0 and units.factor("g", "m/s²") == 9.80665 == units.si("g")
    for unit in units.UNITS:   # every unit goes to SI and back
        assert units.si(unit) * units.per_si(unit) == pytest.approx(1.0, rel=1e-15)
    with pytest.raises(ValueError, match="does not convert"):
        units.factor("mm", "deg")


def test_an_atomic_folder_appears_whole_or_not_at_all(tmp_path: Path):
    root = tmp_path / "dataset"
    with atomic_directory(root) as tmp:
        (tmp / "a.csv").write_text("1")
    assert [p.name for p in root.iterdir()] == ["a.csv"]
    with pytest.raises(RuntimeError):
        with atomic_directory(root, overwrite=True) as tmp:
            (tmp / "b.csv").write_text("2")
            raise RuntimeError("interrupted")
    assert [p.name for p in root.iterdir()] == ["a.csv"] and sorted(p.name for p in tmp_path.iterdir()) == ["dataset"]
    with pytest.raises(InputError, match="exists; pass --overwrite"):
        with atomic_directory(root):
            pass
