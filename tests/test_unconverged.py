"""Bushing steps whose implicit solve stops at its iteration cap: counted and measured by the
kernel, tallied per direction with the samples of the worst, kept in the recording's status
record, said in a warning and in the run's summary (issue 50, item 5)."""

from __future__ import annotations

import functools
import warnings

import numpy as np
import pytest

import elastokin
from elastokin.bushings.bank import DEFAULT_TOLERANCE, BushingBank
from elastokin.bushings.extended_bank import ExtendedBank
from elastokin.bushings.parameter_sets import load_parameter_set
from elastokin.vehicle.simulation import coupling
from elastokin.vehicle.simulation.unconverged import UnconvergedBushingSteps, UnconvergedSteps, UnconvergedTally

#: A tolerance no solve meets: every step of a slipping ladder reaches the iteration cap.
UNREACHABLE = 1e-300
#: The two channels' tolerances in the tally's tests [m or rad].
TOLERANCES = np.full(2, 1e-8)


def _sine(set_name: str, tolerance: float) -> tuple[BushingBank, np.ndarray]:
    """fig5_9 (a 4-cell STVS ladder) over two 2 Hz cycles of ±1 mm, and ±0.5 mm in a second channel."""
    channel = load_parameter_set(set_name).channel()
    bank = BushingBank([channel, channel], tolerance=tolerance)
    e = 1e-3 * np.sin(2.0 * np.pi * 2.0 * np.arange(1, 1001) * 1e-3)
    forces, _ = bank.run(np.column_stack([e, 0.5 * e]), 1e-3)
    return bank, forces


def test_the_kernel_counts_the_steps_at_its_cap_and_their_residual() -> None:
    converged, f_default = _sine("fig5_9", DEFAULT_TOLERANCE)
    assert converged.failed_steps.tolist() == [0, 0] and converged.worst_residual.tolist() == [0.0, 0.0]
    capped, f_capped = _sine("fig5_9", UNREACHABLE)
    channel = capped.channels[0]
    # every step in which some slider slips fails (the sliders slip most of each cycle)
    assert (capped.failed_steps > 500).all() and (capped.failed_steps <= 1000).all()
    # what is left is round-off: nodes placed to far below the default tolerance...
    assert (capped.worst_residual > 0.0).all() and (capped.worst_residual < 1e-3 * DEFAULT_TOLERANCE).all()
    # ...and the forces agree with the default solve to the force its tolerance stands for
    assert np.abs(f_capped - f_default).max() <= 4 * DEFAULT_TOLERANCE * (channel.Kpa + 2 * channel.Kr)


def test_the_tally_keeps_the_block_of_the_worst_and_a_nan() -> None:
    tally, seen = UnconvergedTally(), np.zeros(2, dtype=np.int64)
    names, units = ["b.x", "b.rz"], ["m", "rad"]
    tally.add(names, units, np.array([3, 0]), seen, np.array([2e-7, 0.0]), TOLERANCES, 1, 0.0, 1.0)
    tally.add(names, units, np.array([5, 1]), seen, np.array([2e-7, 4e-6]), TOLERANCES, 1, 1.0, 2.0)   # x not worse
    tally.add(names, units, np.array([6, 1]), seen, np.array([9e-7, 4e-6]), TOLERANCES, 1, 2.0, 3.0)   # x worse
    x, rz = tally.steps()
    assert (x.steps, x.worst_residual, x.from_s, x.to_s) == (6, 9e-7, 2.0, 3.0)
    assert (rz.steps, rz.unit, rz.from_s) == (1, "rad", 1.0)
    assert seen.tolist() == [6, 1]
    # a fresh bank (the next case) counts from 0 again, its worst from 0: a smaller one keeps the old window
    seen[:] = 0
    tally.add(names, units, np.array([2, 0]), seen, np.array([1e-7, 0.0]), TOLERANCES, 2, 10.0, 11.0)
    tally.add(names, units, np.array([3, 0]), seen, np.array([np.nan, 0.0]), TOLERANCES, 2, 11.0, 12.0)
    tally.add(names, units, np.array([4, 0]), seen, np.array([np.nan, 0.0]), TOLERANCES, 2, 12.0, 13.0)
    x = tally.steps()[0]
    assert x.steps == 10 and np.isnan(x.worst_residual) and (x.case, x.from_s) == (2, 11.0)
    assert UnconvergedSteps.from_record(x.to_record()).to_record() == x.to_record()
    assert x.describe().startswith("b.x: 10 steps, worst residual nan mm (tolerance 1e-05 mm) in t = 11.000–12.000 s")
    assert "0.000229 deg" in rz.describe()   # 4e-6 rad


QUICK = {"name": "quick_pumping", "type": "pumping", "vehicle": "c_segment", "output_rate_hz": 50,
         "settle": {"before_bushings_s": 0.3, "before_input_s": 0.3},
         "cases": [{"amplitude_mm": 20, "frequency_hz": 2, "cycles": 1}]}


def test_a_run_says_where_its_bushing_solve_did_not_converge(tmp_path, monkeypatch) -> None:
    scenario = elastokin.scenario_from(QUICK)
    with warnings.catch_warnings():
        warnings.simplefilter("error", UnconvergedBushingSteps)
        assert elastokin.Simulation(None, scenario).run().unconverged == ()   # the shipped car's laws converge
    monkeypatch.setattr(coupling, "ExtendedBank", functools.partial(ExtendedBank, tolerance=UNREACHABLE))
    with pytest.warns(UnconvergedBushingSteps, match=r"rig\.mcap: \d+ bushing steps in \d+ direction\(s\) did not "
                                                     r"converge .*: \w+\.r?[xyz]: \d+ steps, worst residual"):
        run = elastokin.Simulation(None, scenario).run(output=tmp_path / "rig.mcap")
    found = run.unconverged
    case = run.cases[0]
    steps_on = round((case["end_s"] - case["bushings_on_s"]) / run.metadata["timestep_s"])
    assert found and all(0 < s.steps <= steps_on for s in found)
    assert all(s.tolerance == UNREACHABLE and 0.0 < s.worst_residual < 1e-3 * DEFAULT_TOLERANCE for s in found)
    # the worst came while the laws were on, in one block of samples
    assert all(case["bushings_on_s"] - 1e-9 <= s.from_s < s.to_s <= case["end_s"] + 1e-9 for s in found)
    assert {s.unit for s in found} <= {"m", "rad"}
    # kept by the recording, the same after a reading and a saving
    assert elastokin.load_run(tmp_path / "rig.mcap").unconverged == found
    assert run.save(tmp_path / "again.mcap").read_bytes() == (tmp_path / "rig.mcap").read_bytes()
    lines = run.summary().splitlines()
    start = lines.index(next(line for line in lines if line.startswith("WARNING: ")))
    assert lines[start + 1:start + 1 + len(found)] == [f"  {s.describe()}" for s in
                                                       sorted(found, key=lambda s: -s.worst_residual)]


def test_vsim_run_warns_in_one_line_and_summarises(tmp_path, monkeypatch, capsys) -> None:
    from elastokin.cli.main import main
    from elastokin.core.documents import dump_yaml

    monkeypatch.setattr(coupling, "ExtendedBank", functools.partial(ExtendedBank, tolerance=UNREACHABLE))
    (tmp_path / "quick.yaml").write_text(dump_yaml(QUICK, sort_keys=False))
    assert main(["run", str(tmp_path / "quick.yaml"), "-o", str(tmp_path / "quick.mcap")]) == 0
    out, err = capsys.readouterr()
    warned = [line for line in err.splitlines() if line.startswith("vsim: warning: ")]
    assert len(warned) == 1 and "quick.mcap: " in warned[0] and "did not converge" in warned[0]
    assert "WARNING: " in out and "did not converge" in out
