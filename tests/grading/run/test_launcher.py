"""The warm launcher makes, before its first fork, what every submission's grading process reads alike."""

import json
import os
import re
from pathlib import Path

import nbformat
import pytest

from labkit.grading.options import GradeOptions
from labkit.grading.run.launcher import Launcher
from labkit.grading.submission import known, scoring

NOTEBOOKS = Path(__file__).resolve().parents[3] / "notebooks"


def _fingerprinted(cache):
    """The names of the functions that have fingerprints in the known-code cache folder `cache`."""
    units = [json.loads(p.read_text(encoding="utf-8"))["units"] for p in (cache / "known").glob("*.json")]
    return {unit[0] for each in units for unit in each}


@pytest.mark.slow
@pytest.mark.parametrize("solutions", [None, str(NOTEBOOKS)])
def test_the_launcher_fingerprints_the_known_code_before_it_is_ready(tmp_path, monkeypatch, solutions):
    monkeypatch.setenv("LABKIT_CACHE", str(tmp_path))
    launcher = Launcher(GradeOptions(solutions=solutions), None)
    try:
        launcher.wait_ready()
        names = _fingerprinted(tmp_path)
    finally:
        launcher.stop()
    assert "labkit.piecewise.eval_pherm" in names and any(name.startswith("scipy.interpolate.") for name in names)
    notebooks = {name.split(": ")[0] for name in names if ".ipynb: " in name}
    expected = {p.name for p in NOTEBOOKS.glob("*.ipynb") if _defines_functions(p)} if solutions else set()
    assert notebooks == expected and (not solutions or expected)


def _defines_functions(path):
    code = "\n".join(c.source for c in nbformat.read(path, as_version=4).cells if c.cell_type == "code")
    return re.search(r"^def ", code, re.MULTILINE) is not None


def test_a_process_forked_after_warm_finds_the_known_code_made():
    """What the launcher's children rely on: warm() fills the very caches a grading process then looks in (the
    test above shows the launcher calls it)."""
    registry = scoring.load_registry(None)
    scoring.warm(registry, str(NOTEBOOKS))
    reader, misses = scoring._own_reader(), known.corpus.cache_info().misses
    pid = os.fork()
    if pid == 0:  # the child: a grading process forked by the launcher; it never returns into pytest
        code = 1
        try:
            made = scoring.known_sources(registry, str(NOTEBOOKS))
            fresh = known.corpus.cache_info().misses != misses or scoring._own_reader() is not reader
            code = 1 if fresh or not made.units else 0
        finally:
            os._exit(code)
    _, status = os.waitpid(pid, 0)
    assert os.waitstatus_to_exitcode(status) == 0
