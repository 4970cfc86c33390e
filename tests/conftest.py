import sys

import numpy as np
import pytest


@pytest.fixture
def rng():
    return np.random.default_rng(20261122)


def sandbox_or_skip():
    """Skip a test that needs bubblewrap where there is none, but fail in CI, which must have it."""
    import os

    from labkit.grading.backends import get_backend
    from labkit.grading.backends.base import SandboxUnavailable

    try:
        get_backend("bwrap").available()
    except SandboxUnavailable as exc:
        if os.environ.get("CI"):
            raise
        pytest.skip(f"no sandbox here: {exc}")


def pytest_terminal_summary(terminalreporter):
    """Show the browser test's slider latencies, and the hostile class's grading figures, in every run's
    summary, not only with -s (they are printed, never asserted: see benchmarks/)."""
    run = getattr(sys.modules.get("test_hostile"), "RUN", {})
    if run:
        terminalreporter.section("labkit grade: the hostile class (attackers with honest classmates)")
        peak = run.get("grader peak bytes")
        terminalreporter.write_line(
            f"{run.get('submissions')} submissions in {run.get('seconds')} s with --jobs {run.get('jobs')}; "
            f"{run.get('not graded')} not graded; grader peak "
            + (f"{peak / 1024**2:.0f} MiB" if peak else "not measured (no memory cgroup)")
        )
    module = sys.modules.get("test_jupyterlab")
    latencies = getattr(module, "LATENCIES", {})
    if latencies:
        terminalreporter.section("JupyterLab: key press or drag step -> new picture")
        for name, (median, p90, moves) in latencies.items():
            terminalreporter.write_line(
                f"{name:<40} median {median:4.0f} ms   90th percentile {p90:4.0f} ms   ({moves} moves)"
            )


@pytest.fixture(scope="session")
def small_class(tmp_path_factory):
    """The small class of tests/small_class.py, graded once with ``--jobs 2`` and its seed: (its submissions in
    name order, the output folder), the reference the other ways of grading it are compared with."""
    from small_class import SEED, cli, plant_small_class

    sandbox_or_skip()
    tmp = tmp_path_factory.mktemp("small-class")
    submissions = plant_small_class(tmp / "submissions")
    run = cli("grade", *submissions, "--out", tmp / "reference", "--seed", SEED, "--jobs", "2", "--quiet")
    assert run.returncode == 0, run.stderr
    return submissions, tmp / "reference"
