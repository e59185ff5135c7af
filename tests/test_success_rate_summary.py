"""The slow suites' success rates reach the run's summary, also when pytest-xdist runs the tests
(which swallows what they print)."""

from __future__ import annotations

import os
from pathlib import Path

pytest_plugins = ["pytester"]

ROOT = Path(__file__).resolve().parents[1]


def test_tallies_are_summed_up_per_file_under_xdist(pytester, monkeypatch):
    monkeypatch.setenv("PYTHONPATH", str(ROOT))
    pytester.makeconftest("from tests.conftest import pytest_terminal_summary  # noqa: F401\n")
    pytester.makepyfile(test_rates="""
        import pytest
        from tests.diagnosis_helpers import assert_success_rate

        @pytest.mark.parametrize("cause, wrong", [("mullins", ()), ("asymmetry", (103,)), ("none", (101, 100))])
        def test_rate(tmp_path, record_property, cause, wrong):
            def attempt(case, seed):
                assert seed not in wrong, "named another cause"
            assert_success_rate(cause, range(100, 110), tmp_path, attempt, record_property)
    """)
    result = pytester.runpytest_subprocess("-n", "2", "-p", "no:cacheprovider")
    result.assert_outcomes(passed=2, failed=1)  # 8 of 10 is below 90 %; 9 of 10 is not
    result.stdout.re_match_lines([r".*diagnosis success rates.*",
                                  r"test_rates.py  asymmetry +9/10 +wrong: seeds 103$",
                                  r"test_rates.py  mullins +10/10$",
                                  r"test_rates.py  none +8/10 +wrong: seeds 100, 101$",
                                  r"test_rates.py  all single draws +27/30 +\(90%; required at least 90%\)$"])


def test_draws_spread_on_a_cluster_give_the_tally_of_draws_in_turn(tmp_path):
    """VSIM_SLOW_SCHEDULER: the draws as tasks of a local Dask cluster, each in a folder of its own
    with its diagnosis kept in its worker's process, tally as the draws made one after the other."""
    from tests.diagnosis_helpers import assert_success_rate
    from elastokin.cluster.executor import LOCAL, SCHEDULER_ENV, SERIAL

    here = os.getpid()

    def attempt(case: Path, seed: int) -> None:
        assert case.is_dir() and not any(case.iterdir())
        assert os.getpid() == here or os.environ[SCHEDULER_ENV] == SERIAL, "a nested cluster"
        assert seed % 3, "named another cause"

    tallies = {}
    for scheduler in (SERIAL, LOCAL):
        (tmp_path / scheduler).mkdir()
        assert_success_rate("mullins", range(100, 109), tmp_path / scheduler, attempt,
                            lambda name, tally: tallies.setdefault(scheduler, tally), 0.5, scheduler)
    assert tallies[LOCAL] == tallies[SERIAL] == {"cause": "mullins", "right": 6, "draws": 9, "wrong": [102, 105, 108]}
