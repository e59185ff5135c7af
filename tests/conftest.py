"""Suite-wide hooks: the slow suites' diagnosis tallies, added up in the run's summary.

The success-rate tests record their tallies as a user property rather than only printing them:
``pytest -n`` swallows what tests print, but a report's properties reach the summary either way.
"""

from __future__ import annotations

from collections import defaultdict

import pytest


def pytest_terminal_summary(terminalreporter: pytest.TerminalReporter) -> None:
    """A "diagnosis success rates" section: per test file (the level), one line per cause
    (right/draws and the wrong seeds) and the rate over all its single-cause draws against the required
    one (pairs have their own required rate)."""
    reports = [r for key in ("passed", "failed") for r in terminalreporter.stats.get(key, [])
               if r.when == "call" and r.user_properties]
    if not reports:
        return
    from tests.diagnosis_helpers import MIN_SUCCESS_RATE, PAIR, TALLY  # only now: it imports the vehicle

    by_file: dict[str, list[dict]] = defaultdict(list)
    for report in sorted(reports, key=lambda r: r.nodeid):
        for name, value in report.user_properties:
            if name == TALLY:
                by_file[report.location[0]].append(value)
    if not by_file:
        return
    terminalreporter.section("diagnosis success rates")
    for path, tallies in by_file.items():
        for t in tallies:
            wrong = f"  wrong: seeds {', '.join(map(str, t['wrong']))}" if t["wrong"] else ""
            terminalreporter.write_line(f"{path}  {t['cause']:<24} {t['right']:>3}/{t['draws']}{wrong}")
        singles = [t for t in tallies if t["cause"] != PAIR]   # pairs have their own rate, on their line
        if singles:
            right, draws = sum(t["right"] for t in singles), sum(t["draws"] for t in singles)
            terminalreporter.write_line(f"{path}  {'all single draws':<24} {right:>3}/{draws} ({right / draws:.0%}; "
                                        f"required at least {MIN_SUCCESS_RATE:.0%})")
