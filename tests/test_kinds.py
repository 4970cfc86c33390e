"""Problems and outcomes are data: each failed step and each problem of a submission carries a kind code set
where it is made (labkit.exercises.result.KINDS), and what reads them reads the codes, never the words.

A student's exception is an error raised whatever its class is named or its message says: only labkit's own
exceptions (labkit.grading.remote's, each with its ``grader_kind``) and the worker's own marks stand for a time
limit, a crash or tampering. The real workers here run with the none backend (no sandbox needed).
"""

import json

import nbformat
import pytest

from labkit.exercises import result as results
from labkit.exercises.result import ABOUT_THE_NOTEBOOK, KINDS, CheckResult, call
from labkit.grading import class_report, remote, scoring
from labkit.grading.options import GradeOptions
from labkit.grading.report import FORMAT, ProblemText, SubmissionGrade

UNCONFINED = GradeOptions(backend="none", cell_timeout=2)


def _called(exception):
    def student(*args):
        raise exception

    result = CheckResult("eval_pherm")
    call(result, "eval_pherm(...) runs", student)
    return result


def test_the_vocabulary_is_defined_once_and_the_report_uses_the_same_codes():
    assert KINDS == ("not done", "raised", "refused", "timeout", "crash", "tampered", "other")
    for name in ("PASSED", "SLIP", "NOT_DONE", "RAISED", "REFUSED", "TIMEOUT", "CRASH", "TAMPERED", "OTHER"):
        assert getattr(class_report, name) is getattr(results, name)
    assert set(class_report.KINDS) == set(KINDS) - {"not done"} | {"not graded"}
    with pytest.raises(ValueError, match="kind is one of 'not done', 'raised'"):
        CheckResult("x").fail("s", "d", "h", kind="time limit")
    with pytest.raises(ValueError, match="kind is one of"):
        ProblemText("a.ipynb: x", [("killed", "x")])


def test_a_step_records_its_kind_beside_the_steps_which_stay_triples():
    result = CheckResult("eval_pherm")
    result.step("runs", True, kind="raised")  # a passed step has no kind
    result.fail("the values", "off by 0.3", "divide by h")  # a slip has none
    result.fail("eval_pherm(...) runs", "raised KeyError: 1", "look at that line.", "raised")
    assert all(len(step) == 3 for step in result.steps)
    assert [step.get("kind") for step in result.as_dict()["steps"]] == [None, None, "raised"]


@pytest.mark.parametrize(
    "exception",
    [
        ValueError("it ran past the time limit"),
        ValueError("the notebook's process was killed by SIGKILL"),
        RuntimeError("stopped answering; none of its answers count"),
        remote.StudentError("Timeout", "interrupted: it ran longer than the time limit"),
        remote.StudentError("Tampered", "the notebook used threads"),
        remote.StudentError("WorkerError", "the notebook's process stopped answering"),
    ],
    ids=str,
)
def test_a_students_exception_is_an_error_raised_whatever_its_name_or_words(exception):
    result = _called(exception)
    assert [step["kind"] for step in result.as_dict()["steps"]] == ["raised"]
    assert result.hint != ABOUT_THE_NOTEBOOK  # no "see what the feedback says about the notebook"
    assert class_report.check_outcome(result.as_dict()) == "raised"


def test_a_students_own_class_named_timeout_is_an_error_raised():
    class Timeout(Exception):
        kind = "Timeout"
        grader_kind = "timeout"  # not one of labkit's own classes, so not trusted

    result = _called(Timeout("interrupted: it ran longer than the time limit"))
    assert result.as_dict()["steps"][0]["kind"] == "raised"
    assert result.as_dict()["steps"][0]["detail"].startswith("raised Timeout: interrupted")


@pytest.mark.parametrize(
    "exception, kind",
    [
        (remote.CellTimeout("interrupted: it ran longer than the time limit"), "timeout"),
        (remote.NotebookTimeout("stopped after the total time limit"), "timeout"),
        (remote.WorkerError("the notebook's process exited with status 3"), "crash"),
        (remote.Tampered("Tampered", "the notebook used threads"), "tampered"),
        (remote.CallEnded("WorkerError", "the notebook's process exited with status 7"), "crash"),
        (NotImplementedError(), "not done"),
    ],
    ids=lambda v: v if isinstance(v, str) else type(v).__name__,
)
def test_labkits_own_errors_give_their_kinds(exception, kind):
    result = _called(exception)
    assert result.as_dict()["steps"][0]["kind"] == kind
    assert class_report.check_outcome(result.as_dict()) == kind


@pytest.fixture
def notebook():
    started = remote.Notebook(UNCONFINED, None)
    yield started
    started.close()


def test_through_the_worker_a_students_timeout_is_raised_and_the_workers_own_is_a_time_limit(notebook):
    cells = [
        "import time\ndef slow():\n    time.sleep(60)\n",
        "class Timeout(Exception):\n    pass\ndef mine():\n    raise Timeout('interrupted: it ran longer than the time limit')\n",
        "class Tampered(Exception):\n    pass\ndef forged():\n    raise Tampered('none of its answers count')\n",
        "class WorkerError(Exception):\n    pass\ndef crashed():\n    raise WorkerError('killed by SIGKILL')\n",
    ]
    assert notebook.request({"op": "run", "cells": cells, "cell_timeout": 30}, 60)["errors"] == []
    kinds = {}
    for name in ("mine", "forged", "crashed", "slow"):
        result = CheckResult(name)
        call(result, f"{name}() runs", remote.Function(notebook, name, None, 1))
        kinds[name] = result.as_dict()["steps"][0]["kind"]
    assert kinds == {"mine": "raised", "forged": "raised", "crashed": "raised", "slow": "timeout"}
    assert notebook.tampered is None  # a student's exception named Tampered voids nothing


def test_through_the_worker_a_cell_stopped_at_its_limit_is_a_time_limit_and_a_cell_raising_timeout_is_not(notebook):
    cells = [
        "class Timeout(Exception):\n    pass\nraise Timeout('interrupted: it ran longer than the time limit')\n",
        "while True:\n    pass\n",
    ]
    ran = notebook.request({"op": "run", "cells": cells, "cell_timeout": 1}, 60)
    [problem] = scoring._run_problems("a.ipynb", ran)
    assert [kind for kind, _ in class_report.problem_kinds(problem)] == ["raised", "timeout"]
    # the student reads the same words for both cells as before
    assert "cell 1 raised Timeout: interrupted: it ran longer than the time limit" in problem
    assert "cell 2 raised Timeout: interrupted: it ran longer than the time limit" in problem


class _Stub:
    """Stands for remote.Notebook: its run request raises what the test gives."""

    error = None

    def __init__(self, options, deadline, profiles, passables=()):
        self.tampered, self.stopped = None, None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        pass

    def request(self, message, timeout):
        raise self.error


@pytest.mark.parametrize(
    "error, kind",
    [
        (remote.NotebookTimeout("anything"), "timeout"),
        (remote.CellTimeout("stopped after the time limit: the notebook did not answer in time"), "timeout"),
        (remote.WorkerError("stopped after the total time limit: the notebook did not answer in time"), "crash"),
        (remote.WorkerError("the notebook's process exited with status 3 (os._exit or a crash)"), "crash"),
    ],
    ids=lambda v: v if isinstance(v, str) else type(v).__name__,
)
def test_a_notebooks_problems_carry_the_kind_set_where_they_are_made(error, kind, tmp_path, monkeypatch):
    nb = nbformat.v4.new_notebook()
    nb.cells = [nbformat.v4.new_markdown_cell("## Exercise 16"), nbformat.v4.new_code_cell("x = 1")]
    nbformat.write(nb, tmp_path / "work.ipynb")
    monkeypatch.setattr(remote, "Notebook", _Stub)
    _Stub.error = error
    _, [problem] = scoring.grade_notebook(tmp_path / "work.ipynb", GradeOptions(total_timeout=321))
    assert problem.kinds == ((kind, str(problem)),)


def test_a_results_problems_keep_their_kinds_through_its_file_and_old_formats_are_refused():
    [cells] = scoring._run_problems(
        "a.ipynb",
        {
            "errors": [
                {
                    "cell": 2,
                    "kind": "Timeout",
                    "message": "interrupted: it ran longer than the time limit",
                    "timeout": True,
                },
                {"cell": 4, "kind": "Timeout", "message": "interrupted: it ran longer than the time limit"},
            ]
        },
    )
    grade = SubmissionGrade("ada", {}, [cells, ProblemText.one("b.ipynb: it stopped.", "crash")], 1)
    data = json.loads(json.dumps(grade.as_dict()))
    assert data["format"] == FORMAT == "labkit-grade/3"
    assert data["problems"] == [str(cells), "b.ipynb: it stopped."]
    back = SubmissionGrade.from_dict(data, "ada.json")
    assert back.problems == grade.problems
    assert [p.kinds for p in back.problems] == [
        (
            ("timeout", "a.ipynb: cell 3 ran past its time limit"),
            ("raised", "a.ipynb: cell 5 raised Timeout: interrupted: it ran longer than the time limit"),
        ),
        (("crash", "b.ipynb: it stopped."),),
    ]
    with pytest.raises(ValueError, match="ada.json is not a labkit grade result .format is 'labkit-grade/2'"):
        SubmissionGrade.from_dict({**data, "format": "labkit-grade/2"}, "ada.json")
    for bad in ([[]], [[["crash"]], [["crash", "y"]]], [[["killed", "x"]], [["crash", "y"]]]):
        with pytest.raises(ValueError, match="ada.json is not a labkit grade result"):
            SubmissionGrade.from_dict({**data, "problem_kinds": bad}, "ada.json")


def test_a_stubbed_driver_leaves_its_table_and_rate_not_done_not_slipped():
    # the rate's check takes the table's failed steps: their kinds come along
    from labkit.exercises.registry import LAB

    def stub(*args):
        raise NotImplementedError()

    exercise = LAB.exercises[3]
    namespace = {**dict.fromkeys(exercise.names, stub), "errors_pherm": [1.0] * 5, "rate_pherm": 4.0}
    checks = LAB.check(3, namespace)["checks"]
    assert {check["name"]: class_report.check_outcome(check) for check in checks} == dict.fromkeys(
        exercise.names, "not done"
    )
