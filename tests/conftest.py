import sys

import numpy as np
import pytest


@pytest.fixture
def rng():
    return np.random.default_rng(20261122)


def pytest_terminal_summary(terminalreporter):
    """Show the browser test's slider latencies in every run's summary, not only with -s."""
    module = sys.modules.get("test_jupyterlab")
    latencies = getattr(module, "LATENCIES", {})
    if latencies:
        terminalreporter.section("slider move -> new plot in JupyterLab (median of 4 moves)")
        for name, ms in latencies.items():
            terminalreporter.write_line(f"{name:<24}{ms:6.0f} ms")
