"""What the browser tests share: a JupyterLab server and headless Chromium, one of each per test module."""

import sys

import pytest
from jupyterlab_session import CHROMIUM, CHROMIUM_FLAGS, course_lab


def pytest_terminal_summary(terminalreporter):
    """Show the axe-core check's findings per notebook in every run's summary, not only with -s: what is in
    the notebooks' outputs (asserted to be nothing serious) and what JupyterLab itself causes (named only)."""
    found = getattr(sys.modules.get("test_accessibility"), "AXE", {})
    if not found:
        return
    terminalreporter.section("axe-core in JupyterLab: serious and critical violations")
    for notebook, result in found.items():
        nodes = ", ".join(f"{impact} {n}" for impact, n in result["all"].items() if n) or "none"
        terminalreporter.write_line(f"{notebook}: nodes by impact: {nodes}")
        for where in ("outputs", "jupyterlab"):
            rules = sorted({f"{rule} ({impact})" for rule, impact, *_ in result[where]})
            label = "in labkit's outputs" if where == "outputs" else "JupyterLab's own"
            terminalreporter.write_line(f"    {label:<20} {', '.join(rules) or 'none'}")


@pytest.fixture(scope="module")
def lab(tmp_path_factory):
    """A JupyterLab server on 127.0.0.1 serving a temporary copy of notebooks/ (a browser test's fixture)."""
    with course_lab(tmp_path_factory.mktemp("lab")) as base:
        yield base


@pytest.fixture(scope="module")
def browser():
    """Headless Chromium (/usr/bin/chromium, never a Playwright download), for one test module."""
    from playwright import sync_api

    with sync_api.sync_playwright() as p:
        chromium = p.chromium.launch(executable_path=str(CHROMIUM), headless=True, args=CHROMIUM_FLAGS)
        yield chromium
        chromium.close()
