"""Report tests: the screenshots the browser tests take are listed at the end of the run."""

from __future__ import annotations

import pytest

_SCREENSHOTS: list[str] = []


@pytest.fixture
def screenshot_log():
    """Append a screenshot's path to have it printed in the test summary."""
    return _SCREENSHOTS


def pytest_terminal_summary(terminalreporter):
    if _SCREENSHOTS:
        terminalreporter.section("report screenshots")
        for path in _SCREENSHOTS:
            terminalreporter.write_line(path)
