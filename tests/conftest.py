import sys
from pathlib import Path

import numpy as np
import pytest


@pytest.fixture
def rng():
    return np.random.default_rng(20261122)


def sandbox_or_skip():
    """Skip a test that needs bubblewrap where there is none, but fail in CI, which must have it."""
    import os

    from labkit.grading.sandbox.backends import get_backend
    from labkit.grading.sandbox.backends.base import SandboxUnavailable

    try:
        get_backend("bwrap").available()
    except SandboxUnavailable as exc:
        if os.environ.get("CI"):
            raise
        pytest.skip(f"no sandbox here: {exc}")


# The fast tier (`make test-fast`, `pytest -m "not slow"`) leaves out what starts sandboxes, browsers, servers or
# whole notebooks: the browser tests, these modules, and every test whose code or fixtures call sandbox_or_skip().
SLOW_MODULES = {
    "test_catalog",  # the catalog class, graded in one sandboxed run
    "test_hostile",  # the hostile class
    "test_make_lab",  # make lab in a fresh folder
    "test_packaging",  # builds the package
    "test_wheel",  # builds and installs a wheel
    "test_dask",  # a Dask cluster
    "test_nbgrader",  # nbgrader's own commands
    "test_notebooks_clean",  # executes notebooks
    "test_cell_numbers",  # executes a notebook
    "test_student_work",  # executes notebooks
    "test_timeouts",  # waits for time limits
    "test_grading",  # grades the instructor notebooks and small classes
    "test_refusals",  # a worker process per case
    "test_handin",  # executes notebooks
}
SLOW_CALLS = ("sandbox_or_skip(", "grading.grade(")  # a test or fixture calling one of these is slow


def _calls_the_sandbox(item):
    import inspect

    functions = [getattr(item, "function", None)]
    info = getattr(item, "_fixtureinfo", None)
    for definitions in info.name2fixturedefs.values() if info else ():
        functions += [definition.func for definition in definitions]
    for function in functions:
        try:
            if function is not None and any(call in inspect.getsource(function) for call in SLOW_CALLS):
                return True
        except (OSError, TypeError):
            continue
    return False


def pytest_configure(config):
    config.addinivalue_line("markers", "slow: left out of the fast tier (make test-fast); see tests/conftest.py")


def pytest_collection_modifyitems(config, items):
    for item in items:
        module = item.nodeid.split("::")[0]
        name = Path(module).stem
        if module.startswith("tests/browser/") or name in SLOW_MODULES or _calls_the_sandbox(item):
            item.add_marker(pytest.mark.slow)


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
    shares = getattr(sys.modules.get("test_known"), "SHARES", {})
    if shares:
        from labkit.grading.submission.known import MIN_SHARED, THRESHOLD

        terminalreporter.section(
            f"known code: a part is held from a share of {THRESHOLD} with {MIN_SHARED} fingerprints shared"
        )
        for what, value in sorted(shares.items()):
            terminalreporter.write_line(f"{what:<72} {value:g}")
    module = sys.modules.get("test_jupyterlab")
    latencies = getattr(module, "LATENCIES", {})
    if latencies:
        terminalreporter.section("JupyterLab: key press or drag step -> new picture shown")
        ahead = getattr(sys.modules.get("jupyterlab_session"), "DRAWN_AHEAD", {})
        for name, (median, p90, moves) in latencies.items():
            terminalreporter.write_line(
                f"{name:<40} median {median:4.0f} ms   90th percentile {p90:4.0f} ms   ({moves} moves, "
                f"{ahead.get(name, 0)} without a round trip: drawn ahead or in the page)"
            )
    # the axe-core check's findings per notebook: what is in the notebooks' outputs (asserted to be nothing
    # serious) and what JupyterLab itself causes (named only)
    found = getattr(sys.modules.get("test_accessibility"), "AXE", {})
    if found:
        terminalreporter.section("axe-core in JupyterLab: serious and critical violations")
        for notebook, result in found.items():
            nodes = ", ".join(f"{impact} {n}" for impact, n in result["all"].items() if n) or "none"
            terminalreporter.write_line(f"{notebook}: nodes by impact: {nodes}")
            for where in ("outputs", "jupyterlab"):
                rules = sorted({f"{rule} ({impact})" for rule, impact, *_ in result[where]})
                label = "in labkit's outputs" if where == "outputs" else "JupyterLab's own"
                terminalreporter.write_line(f"    {label:<20} {', '.join(rules) or 'none'}")


# the browser tests' (tests/browser/): one JupyterLab server and one headless Chromium per test module. Kept
# here, as a second conftest.py there would be a second module named conftest (tests import this one's helpers)


@pytest.fixture(scope="module")
def lab(tmp_path_factory):
    """A JupyterLab server on 127.0.0.1 serving a temporary copy of notebooks/."""
    from jupyterlab_session import course_lab

    with course_lab(tmp_path_factory.mktemp("lab")) as base:
        yield base


@pytest.fixture(scope="module")
def browser():
    """Headless Chromium (/usr/bin/chromium, never a Playwright download)."""
    from jupyterlab_session import CHROMIUM, CHROMIUM_FLAGS
    from playwright import sync_api

    with sync_api.sync_playwright() as p:
        chromium = p.chromium.launch(executable_path=str(CHROMIUM), headless=True, args=CHROMIUM_FLAGS)
        yield chromium
        chromium.close()


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


# the notebooks under tests/data are fixtures (students' submissions, graded by the tests), not notebooks of the
# kit for nbval to run
collect_ignore_glob = ["data/*"]
