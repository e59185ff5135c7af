"""The slow suites' success rates reach the run's summary, also when pytest-xdist runs the tests
(which swallows what they print)."""

from __future__ import annotations

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
