"""Time limits are exceptions of their own types, raised where they are detected and told apart by type.

The real workers here run with the none backend (no sandbox needed); the
end-to-end messages a student sees are tested in test_grading.py and
test_hostile.py ("the submission's time limit of N s").
"""

import time

import nbformat
import pytest

from labkit.grading.options import GradeOptions
from labkit.grading.sandbox import remote
from labkit.grading.submission import scoring

pytestmark = pytest.mark.slow  # waits for time limits

UNCONFINED = GradeOptions(backend="none", cell_timeout=2)


def test_the_timeouts_are_grading_errors_of_their_own_types():
    assert issubclass(remote.NotebookTimeout, remote.WorkerTimeout)
    assert issubclass(remote.CellTimeout, remote.WorkerTimeout)
    assert issubclass(remote.WorkerTimeout, remote.WorkerError)
    assert not issubclass(remote.CellTimeout, remote.NotebookTimeout)
    assert remote.NotebookTimeout("x").total and not remote.CellTimeout("x").total
    assert remote.CellTimeout("x").kind == "Timeout"  # what the checks' feedback shows it as


@pytest.fixture
def worker():
    notebooks = []

    def start(deadline=None):
        notebook = remote.NotebookHandle(UNCONFINED, deadline)
        notebooks.append(notebook)
        return notebook

    yield start
    for notebook in notebooks:
        notebook.close()


def test_a_request_past_its_own_limit_is_a_cell_timeout(worker):
    notebook = worker()
    with pytest.raises(remote.CellTimeout, match="stopped after the time limit: the notebook did not answer"):
        notebook.request({"op": "run", "cells": ["import time\ntime.sleep(60)"], "cell_timeout": 60}, 2)
    assert notebook.stopped


def test_a_request_past_the_submissions_deadline_is_a_notebook_timeout(worker):
    notebook = worker(deadline=time.monotonic() + 15)  # the worker starts well within it
    with pytest.raises(remote.NotebookTimeout, match="stopped after the total time limit"):
        notebook.request({"op": "run", "cells": ["import time\ntime.sleep(120)"], "cell_timeout": 300}, 300)


def test_a_call_past_its_limit_is_a_cell_timeout_and_a_students_own_timeout_is_not(worker):
    notebook = worker()
    cells = [
        "import time\ndef slow():\n    time.sleep(60)\n",
        "class Timeout(Exception):\n    pass\ndef mine():\n    raise Timeout('my own')\n",
    ]
    ran = notebook.request({"op": "run", "cells": cells, "cell_timeout": 30}, 60)
    assert ran["errors"] == []
    with pytest.raises(remote.CellTimeout) as stopped:
        remote.Function(notebook, "slow", None, 1)()
    assert str(stopped.value) == "interrupted: it ran longer than the time limit"  # the words are unchanged
    with pytest.raises(remote.StudentError) as own:
        remote.Function(notebook, "mine", None, 10)()
    assert own.value.kind == "Timeout" and str(own.value) == "my own"
    assert not isinstance(own.value, remote.WorkerTimeout)


class _Stub:
    """Stands for remote.NotebookHandle: its run request raises what the test gives."""

    error = None

    def __init__(self, options, deadline, profiles, passables=()):
        self.tampered, self.stopped = None, None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        pass

    def request(self, message, timeout):
        raise self.error


@pytest.fixture
def stubbed(tmp_path, monkeypatch):
    nb = nbformat.v4.new_notebook()
    nb.cells = [nbformat.v4.new_markdown_cell("## Exercise 16"), nbformat.v4.new_code_cell("x = 1")]
    path = tmp_path / "work.ipynb"
    nbformat.write(nb, path)
    monkeypatch.setattr(remote, "NotebookHandle", _Stub)

    def problems(error):
        _Stub.error = error
        results, found = scoring.grade_notebook(path, GradeOptions(total_timeout=321))
        assert results == {}
        return found

    return problems


def test_scoring_tells_timeouts_apart_by_type_not_by_their_words(stubbed):
    # the student sees the same sentences as before, whatever words the exception carries
    assert stubbed(remote.NotebookTimeout("anything")) == [
        "work.ipynb: stopped after the submission's time limit of 321 s."
    ]
    assert stubbed(remote.CellTimeout("stopped after the time limit: the notebook did not answer in time")) == [
        "work.ipynb: stopped after the time limit: the notebook did not answer in time."
    ]
    # a grading error whose words merely read like a timeout is not one
    words = "stopped after the total time limit: the notebook did not answer in time"
    assert stubbed(remote.WorkerError(words)) == [f"work.ipynb: {words} while running its cells."]
