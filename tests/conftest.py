import sys

import numpy as np
import pytest


@pytest.fixture
def rng():
    return np.random.default_rng(20261122)


def sandbox_or_skip():
    """Skip a test that needs bubblewrap where there is none, but fail in CI, which must have it."""
    import os

    from labkit.grading import sandbox

    try:
        sandbox.available()
    except sandbox.SandboxUnavailable as exc:
        if os.environ.get("CI"):
            raise
        pytest.skip(f"no sandbox here: {exc}")


def pytest_terminal_summary(terminalreporter):
    """Show the browser test's slider latencies in every run's summary, not only with -s."""
    module = sys.modules.get("test_jupyterlab")
    latencies = getattr(module, "LATENCIES", {})
    if latencies:
        terminalreporter.section("JupyterLab: key press or drag step -> new picture")
        for name, (median, p90, moves) in latencies.items():
            terminalreporter.write_line(f"{name:<40} median {median:4.0f} ms   90th percentile {p90:4.0f} ms   ({moves} moves)")
