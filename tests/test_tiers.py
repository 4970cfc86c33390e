"""The fast tier's guard (tests/conftest.py): a test not marked slow that starts a sandbox fails at once."""

import subprocess
import sys

import pytest
from conftest import _starts_the_grader


def test_the_commands_that_start_the_grader_are_told_from_others():
    assert _starts_the_grader(["/usr/bin/bwrap", "--ro-bind", "/", "/"])
    assert _starts_the_grader([sys.executable, "-m", "labkit.grading.submission.scoring", "spec.json"])
    assert _starts_the_grader([sys.executable, "-m", "labkit.grading.run.launcher", ""])
    assert not _starts_the_grader([sys.executable, "-c", "print(1)"])
    assert not _starts_the_grader(["git", "status", "--short"])
    assert not _starts_the_grader("bwrapper --version")
    assert not _starts_the_grader([sys.executable, "-m", "labkit.cli", "grade", "x.ipynb", "--sandbox", "bwrap"])


def test_a_fast_test_that_starts_a_grading_process_fails_before_it_starts():
    with pytest.raises(pytest.fail.Exception, match="not marked slow"):
        subprocess.Popen([sys.executable, "-m", "labkit.grading.run.launcher", ""])


def test_a_fast_test_may_start_other_processes():
    assert subprocess.run([sys.executable, "-c", "print(6 * 7)"], capture_output=True, text=True).stdout == "42\n"


@pytest.mark.slow
def test_a_slow_test_is_not_guarded():
    assert subprocess.Popen is not None and subprocess.Popen.__name__ == "Popen"
