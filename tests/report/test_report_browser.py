"""The report in a real browser (Debian's Chromium, headless, through chromedriver): it loads with
no console message, every figure and table is drawn and not empty, nothing is requested but the
file itself, it prints on A4 pages with a page per section, and a screenshot is taken.

Skipped with the reason when chromium, chromedriver or selenium is missing (CI installs them:
``.ci/run``).
"""

from __future__ import annotations

import base64
import re
import shutil
from pathlib import Path

import pytest

import impstab

from _report_helpers import GRID_STUDY, copy_example, run_study_file

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
CHROMEDRIVER = shutil.which("chromedriver")
selenium = pytest.importorskip("selenium", reason="selenium is not installed (pip install 'impstab[test]')")
pytestmark = pytest.mark.skipif(not (CHROMIUM and CHROMEDRIVER),
                                reason="Chromium and chromedriver are needed (Debian: apt-get install chromium "
                                       "chromium-driver)")

_FLAGS = ("--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
          "--disable-background-networking", "--disable-component-update", "--disable-sync",
          "--disable-dev-shm-usage", "--hide-scrollbars")


class _Screenshots:
    """A plugin that lists the screenshots taken at the end of the test run."""

    def __init__(self) -> None:
        self.paths: list[str] = []

    def pytest_terminal_summary(self, terminalreporter):
        if self.paths:
            terminalreporter.section("report screenshots")
            for path in self.paths:
                terminalreporter.write_line(path)


@pytest.fixture(scope="module")
def screenshot_log(request):
    """Append a screenshot's path to have it printed in the test summary."""
    plugin = _Screenshots()
    request.config.pluginmanager.register(plugin, "impstab-report-screenshots")
    return plugin.paths


@pytest.fixture(scope="module")
def browser(tmp_path_factory):
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    opts = webdriver.ChromeOptions()
    opts.binary_location = CHROMIUM
    for flag in _FLAGS:
        opts.add_argument(flag)
    opts.add_argument(f"--user-data-dir={tmp_path_factory.mktemp('chromium-profile')}")
    opts.add_argument("--window-size=1280,1000")
    opts.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    driver = webdriver.Chrome(service=Service(CHROMEDRIVER), options=opts)
    driver.set_page_load_timeout(120)
    yield driver
    driver.quit()


@pytest.fixture(scope="module")
def pages(tmp_path_factory):
    """A model report (every section) and a study report, as files."""
    folder = tmp_path_factory.mktemp("pages")
    model = copy_example(folder, "imp_isolation.toml")
    model_page = folder / "model-report.html"
    model_rep = impstab.report(model, model_page)
    study = folder / "study"
    run_study_file(study, GRID_STUDY.format(name="grid"))
    study_page = folder / "study-report.html"
    study_rep = impstab.report(study / "study.zarr", study_page)
    return {"model": (model_rep, model_page), "study": (study_rep, study_page)}


def _load(driver, page: Path) -> str:
    url = page.resolve().as_uri()
    driver.get_log("browser")           # drop what an earlier page left
    driver.get(url)
    assert driver.execute_script("return document.readyState") == "complete"
    return url


def _check_page(driver, rep, page: Path):
    url = _load(driver, page)
    # no console message at all (errors, CSP violations, warnings)
    assert driver.get_log("browser") == []
    # nothing fetched but the file itself
    resources = driver.execute_script("return performance.getEntriesByType('resource').map(e => e.name)")
    assert resources == []
    nav = driver.execute_script("return performance.getEntriesByType('navigation').map(e => e.name)")
    assert nav == [url]
    # every figure drawn with a size, with lines and text; every table with rows of cells
    figures = driver.execute_script("""
        return Array.from(document.querySelectorAll('svg.figure')).map(s => {
            const r = s.getBoundingClientRect(), b = s.getBBox();
            return [r.width, r.height, b.width, b.height, s.querySelectorAll('path').length,
                    s.querySelectorAll('text').length, s.closest('section').dataset.section];
        });""")
    assert len(figures) == rep.figures
    for w, h, bw, bh, paths, texts, where in figures:
        assert w > 300 and h > 150 and bw > 0 and bh > 0 and paths > 20 and texts > 5, where
        assert w <= 1024, f"{where}: a figure wider than the page column"
    tables = driver.execute_script("""
        return Array.from(document.querySelectorAll('table.impstab')).map(t => [
            t.querySelectorAll('tbody tr').length, t.querySelectorAll('tbody td').length,
            t.getBoundingClientRect().width, t.closest('section').dataset.section]);""")
    assert len(tables) == rep.tables
    for rows, cells, width, where in tables:
        assert rows >= 1 and cells >= 2 and width > 0, where
    # nothing wider than the page: no horizontal scrolling
    assert driver.execute_script("return document.documentElement.scrollWidth <= window.innerWidth")
    sections = driver.execute_script(
        "return Array.from(document.querySelectorAll('section')).map(s => [s.dataset.section, s.dataset.status])")
    assert sections == [[s.name, s.status] for s in rep.sections]


def _screenshot(driver, path: Path) -> Path:
    height = driver.execute_script("return document.documentElement.scrollHeight")
    driver.set_window_size(1280, min(int(height) + 40, 16000))
    driver.save_screenshot(str(path))
    driver.set_window_size(1280, 1000)
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and path.stat().st_size > 50_000
    return path


def test_model_report_in_chromium(browser, pages, tmp_path, screenshot_log, record_property):
    rep, page = pages["model"]
    _check_page(browser, rep, page)
    shot = _screenshot(browser, tmp_path / "model-report.png")
    screenshot_log.append(str(shot))
    record_property("screenshot", str(shot))
    print(f"screenshot: {shot}")


def test_study_report_in_chromium(browser, pages, tmp_path, screenshot_log, record_property):
    rep, page = pages["study"]
    _check_page(browser, rep, page)
    shot = _screenshot(browser, tmp_path / "study-report.png")
    screenshot_log.append(str(shot))
    record_property("screenshot", str(shot))


def test_report_prints_on_a4_with_a_page_per_section(browser, pages, tmp_path):
    from selenium.webdriver.common.print_page_options import PrintOptions

    rep, page = pages["model"]
    _load(browser, page)
    opts = PrintOptions()
    opts.page_width, opts.page_height = 21.0, 29.7                 # cm
    pdf = base64.b64decode(browser.print_page(opts))
    assert pdf[:5] == b"%PDF-"
    (tmp_path / "model-report.pdf").write_bytes(pdf)
    pages_printed = len(re.findall(rb"/Type\s*/Page[^s]", pdf))
    assert pages_printed >= len(rep.sections) + 1                  # the contents, then one or more per section
    assert browser.get_log("browser") == []
    # printed, a figure fits the A4 column and a table of numbers keeps its numbers whole
    browser.execute_cdp_cmd("Emulation.setEmulatedMedia", {"media": "print"})
    try:
        widths = browser.execute_script(
            "return Array.from(document.querySelectorAll('svg.figure')).map(s => s.getBoundingClientRect().width)")
        body = browser.execute_script("return document.body.getBoundingClientRect().width")
        assert widths and max(widths) <= body + 0.5
    finally:
        browser.execute_cdp_cmd("Emulation.setEmulatedMedia", {"media": ""})
