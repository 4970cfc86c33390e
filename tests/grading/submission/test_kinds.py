"""Problems and outcomes are data: each failed step and each problem of a submission carries a kind code set
where it is made (labkit.exercises.result.KINDS), and what reads them reads the codes, never the words.

A student's exception is an error raised whatever its class is named or its message says: only labkit's own
exceptions (labkit.grading.sandbox.remote's, each with its ``grader_kind``) and the worker's own marks stand for a time
limit, a crash or tampering. The real workers here run with the none backend (no sandbox needed).
"""

import json
import shutil

import nbformat
import pytest
from catalog import Planted, plant
from conftest import sandbox_or_skip
from small_class import cli, rows

from labkit.cli import main
from labkit.exercises import result as results
from labkit.exercises.registry import LAB
from labkit.exercises.result import ABOUT_THE_NOTEBOOK, KINDS, CheckResult, call
from labkit.grading.options import GradeOptions
from labkit.grading.reports import class_report
from labkit.grading.sandbox import remote
from labkit.grading.store.report import FORMAT, ProblemText, SubmissionGrade, merge
from labkit.grading.submission import scoring

UNCONFINED = GradeOptions(backend="none", cell_timeout=2)


def _called(exception):
    def student(*args):
        raise exception

    result = CheckResult("eval_pherm")
    call(result, "eval_pherm(...) runs", student)
    return result


def test_the_vocabulary_is_defined_once_and_the_report_uses_the_same_codes():
    assert KINDS == ("not done", "raised", "refused", "timeout", "crash", "tampered", "other", "another variant")
    names = ("PASSED", "SLIP", "NOT_DONE", "RAISED", "REFUSED", "TIMEOUT", "CRASH", "TAMPERED", "OTHER", "VARIANT")
    for name in names:
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
    started = remote.NotebookHandle(UNCONFINED, None)
    yield started
    started.close()


@pytest.mark.slow  # starts a worker process
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


@pytest.mark.slow  # starts a worker process
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
    monkeypatch.setattr(remote, "NotebookHandle", _Stub)
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
    for old in ("labkit-grade/2", "labkit-grade/1"):
        with pytest.raises(ValueError, match=f"ada.json is in the results format {old}, .* Grade those submissions"):
            SubmissionGrade.from_dict({**data, "format": old}, "ada.json")
    for bad in ([[]], [[["crash"]], [["crash", "y"]]], [[["killed", "x"]], [["crash", "y"]]]):
        with pytest.raises(ValueError, match="ada.json is not a labkit grade result"):
            SubmissionGrade.from_dict({**data, "problem_kinds": bad}, "ada.json")


def test_the_report_on_a_folder_of_the_old_format_says_to_grade_again(tmp_path, capsys):
    import hashlib

    from labkit.grading.store.report import write_report

    write_report(tmp_path, [SubmissionGrade("ada", {}, [ProblemText.one("a.ipynb: it stopped.", "crash")], 1)])
    [path] = (tmp_path / "results").iterdir()
    text = path.read_text().replace(f'"format": "{FORMAT}"', '"format": "labkit-grade/2"')
    path.write_text(text)
    record = json.loads((tmp_path / "record.json").read_text())  # vouching for the old file, as its run would
    record["submissions"]["ada"]["sha256"] = hashlib.sha256(text.encode()).hexdigest()
    (tmp_path / "record.json").write_text(json.dumps(record))
    assert main(["report", str(tmp_path), "--quiet"]) == 2
    said = capsys.readouterr().err
    assert "in the results format labkit-grade/2" in said and "Grade those submissions again" in said, said
    assert not (tmp_path / "report.html").exists()


def test_a_stubbed_driver_leaves_its_table_and_rate_not_done_not_slipped():
    # the rate's check takes the table's failed steps: their kinds come along
    def stub(*args):
        raise NotImplementedError()

    exercise = LAB.exercises[3]
    namespace = {**dict.fromkeys(exercise.names, stub), "errors_pherm": [1.0] * 5, "rate_pherm": 4.0}
    checks = LAB.check(3, namespace)["checks"]
    assert {check["name"]: class_report.check_outcome(check) for check in checks} == dict.fromkeys(
        exercise.names, "not done"
    )


# ---------------------------------------------------------------- a class graded in the sandbox, end to end

HOSTILE_CLASSES = (
    "class Timeout(Exception):\n    pass\n"
    "class Tampered(Exception):\n    pass\n"
    "class WorkerError(Exception):\n    pass\n"
    "def runge2d(x, y):\n    raise Timeout('interrupted: it ran longer than the time limit')\n"
    "def eval_pbilin(f, xdata, ydata, xval, yval):\n"
    '    raise Tampered("the grader\'s watch reported tampering; none of its answers count")\n'
    "def test_pbilin_interpolate(ndata, f=None, interpolate=None):\n"
    '    raise WorkerError("the notebook\'s process was killed by SIGKILL (a resource limit, or os.kill)")\n'
)
# every phrase the report once matched, in the student's own messages
HOSTILE_WORDS = (
    "def runge2d(x, y):\n    raise ValueError('stopped after the time limit: it ran past the time limit')\n"
    "def eval_pbilin(f, xdata, ydata, xval, yval):\n"
    "    raise RuntimeError(\"the notebook's process was killed by SIGKILL; exited with status 9; stopped answering;"
    ' ran out of memory; answered out of protocol; larger than the protocol allows; crashed")\n'
    "def test_pbilin_interpolate(ndata, f=None, interpolate=None):\n"
    "    raise ValueError('called numpy.interp, which is switched off while this exercise is graded; not implemented"
    " yet; not defined when the notebook finished; the check failed inside labkit; none of its answers count')\n"
)
# a real time limit and a real end of the process, for contrast
ENDS = (
    "import os\n"
    "def runge2d(x, y):\n    while True:\n        pass\n"
    "def eval_pbilin(f, xdata, ydata, xval, yval):\n    os._exit(3)\n"
)
FUNCTIONS = ("runge2d", "eval_pbilin", "test_pbilin_interpolate")


def _planted(folder, *cells):
    """Exercise 16 as the instructor solved it, with `cells` appended (they run after the solution's). The number
    the report gives each appended cell: its place among the notebook's code cells, counted from 1."""
    path = plant(Planted("as handed out", "06_bilinear.ipynb", ()), folder)
    nb = nbformat.read(path, as_version=4)
    before = sum(cell.cell_type == "code" for cell in nb.cells)
    nb.cells += [nbformat.v4.new_code_cell(cell) for cell in cells]
    nbformat.write(nb, path)
    return [before + 1 + index for index in range(len(cells))]


@pytest.fixture(scope="module")
def graded_class(tmp_path_factory):
    """A class of four graded in one sandboxed run: an honest student, one whose graded functions raise
    exceptions of classes named Timeout, Tampered and WorkerError (and whose cells raise two of them), one whose
    exceptions' messages hold every phrase the report once matched, and one whose functions really run past the
    time limit and end their process. Its output folder."""
    sandbox_or_skip()
    root = tmp_path_factory.mktemp("kinds")
    submissions = root / "submissions"
    _planted(submissions / "honest")
    numbers = _planted(
        submissions / "named",
        HOSTILE_CLASSES,
        "raise Tampered('none of its answers count')",
        "raise Timeout('interrupted: it ran longer than the time limit')",
    )
    _planted(submissions / "worded", HOSTILE_WORDS, "raise ValueError('ran out of memory; time limit; killed by')")
    _planted(submissions / "ends", ENDS)
    out = root / "out"
    run = cli("grade", submissions, "--out", out, "--seed", "20261203", "--cell-timeout", "3", "--quiet")
    assert run.returncode == 0, run.stderr
    return submissions, out, numbers


def _outcomes(grade, number=16):
    return {check.name: class_report.check_outcome(check.as_dict()) for check in grade.results[number].parts}


def _kinds_by_student(summary):
    return {(kind, p.student) for kind, rows in summary.problems.items() for p in rows}


@pytest.mark.slow  # starts a sandbox
def test_in_a_sandboxed_class_a_students_own_timeout_tampered_and_workererror_are_errors_raised(graded_class):
    _, out, (_, tampered, timeout) = graded_class
    grades = {grade.name: grade for grade in class_report.read(out)}
    named = grades["named"]
    assert {name: _outcomes(named)[name] for name in FUNCTIONS} == dict.fromkeys(FUNCTIONS, "raised")
    assert _outcomes(named)["phi_table"] == "passed"  # nothing voided: the answers that are right count
    feedback = out / "feedback" / next(p.name for p in (out / "feedback").iterdir() if "named" in p.name)
    text = feedback.read_text()
    assert "see what the feedback says about the notebook above" not in text  # no notebook-timeout hint
    assert "raised Timeout: interrupted: it ran longer than the time limit (in runge2d" in text
    assert "the error happened in eval_pbilin" in text and "the error happened in test_pbilin_interpolate" in text
    summary = class_report.summarise(grades.values())
    assert {kind for kind, student in _kinds_by_student(summary) if student == "named"} == {"raised"}
    # its two raising cells are errors raised, each named, not a time limit and not a voided notebook
    [cells] = [p for p in summary.problems["raised"] if p.student == "named"]
    assert any(f"cell {timeout} raised Timeout" in line for line in cells.texts), cells.texts
    assert any(f"cell {tampered} raised Tampered" in line for line in cells.texts), cells.texts


@pytest.mark.slow  # starts a sandbox
def test_in_a_sandboxed_class_the_old_phrases_in_a_students_messages_are_errors_raised(graded_class):
    _, out, _ = graded_class
    grades = {grade.name: grade for grade in class_report.read(out)}
    assert {name: _outcomes(grades["worded"])[name] for name in FUNCTIONS} == dict.fromkeys(FUNCTIONS, "raised")
    summary = class_report.summarise(grades.values())
    assert {kind for kind, student in _kinds_by_student(summary) if student == "worded"} == {"raised"}


@pytest.mark.slow  # starts a sandbox
def test_in_a_sandboxed_class_a_real_time_limit_and_a_real_end_of_the_process_keep_their_kinds(graded_class):
    _, out, _ = graded_class
    grades = {grade.name: grade for grade in class_report.read(out)}
    outcomes = _outcomes(grades["ends"])
    assert (outcomes["runge2d"], outcomes["eval_pbilin"]) == ("timeout", "crash")
    assert outcomes["phi_table"] == "passed"  # the call that ended the process cost only itself


@pytest.mark.slow  # starts a sandbox
def test_the_honest_classmate_gets_full_marks(graded_class):
    _, out, _ = graded_class
    [honest] = [grade for grade in class_report.read(out) if grade.name == "honest"]
    assert set(_outcomes(honest).values()) == {"passed"} and honest.problems == []
    assert honest.points[16] == LAB.exercises[16].points == 8
    assert rows(out)["honest"]["exercise 16"] == "8" and rows(out)["honest"]["status"] == "graded"


@pytest.mark.slow  # starts a sandbox
def test_the_report_reads_the_same_kinds_from_a_resumed_run_and_a_merge(graded_class, tmp_path):
    submissions, out, _ = graded_class
    first = class_report.summarise(class_report.read(out))
    resumed = tmp_path / "resumed"
    shutil.copytree(out, resumed)
    run = cli("grade", submissions, "--out", resumed, "--cell-timeout", "3")
    assert run.returncode == 0 and "4 submission(s) were graded there already and kept, 0 graded now" in run.stdout, (
        run.stdout + run.stderr
    )
    merge([resumed], tmp_path / "merged")
    for folder in (resumed, tmp_path / "merged"):
        assert main(["report", str(folder), "--quiet"]) == 0
        again = class_report.summarise(class_report.read(folder))
        assert again.problems == first.problems and again.parts == first.parts
        html = (folder / "report.html").read_text()
        assert "Errors raised" in html and "Answers voided" not in html


@pytest.mark.slow  # starts a sandbox
def test_rewording_every_message_changes_nothing_the_report_says(graded_class):
    """The grader's words may change: scrambled, every failed step's detail and every problem's text, the
    report's outcomes and problem kinds are the same."""
    _, out, _ = graded_class
    grades = class_report.read(out)

    def scrambled(text):
        return str(text)[::-1].swapcase()

    reworded = []
    for grade in grades:
        data = json.loads(json.dumps(grade.as_dict()))
        for verdict in data["results"].values():
            for check in verdict["checks"]:
                for step in check["steps"]:
                    step["detail"] = scrambled(step["detail"])
                    step["step"] = scrambled(step["step"])
        copy = SubmissionGrade.from_dict(data, grade.name, grade.rubric)
        copy.problems = [ProblemText(scrambled(p), [(k, scrambled(d)) for k, d in p.kinds]) for p in copy.problems]
        reworded.append(copy)
    before, after = class_report.summarise(grades), class_report.summarise(reworded)
    assert [(g.name, _outcomes(g)) for g in grades] == [(g.name, _outcomes(g)) for g in reworded]
    assert _kinds_by_student(before) == _kinds_by_student(after)
    assert {kind for kind, _ in _kinds_by_student(before)} >= {"raised", "timeout", "crash"}
    assert [(r.passed, r.slipped, r.problem, r.not_done) for r in before.parts] == [
        (r.passed, r.slipped, r.problem, r.not_done) for r in after.parts
    ]


def test_exercises_in_takes_a_notebook_or_its_markdown_and_counts_only_markdown_headings():
    import nbformat

    from labkit.grading.submission.scoring import exercises_in

    nb = nbformat.v4.new_notebook(
        cells=[
            nbformat.v4.new_markdown_cell("## Exercise 3\nA heading the grader counts."),
            nbformat.v4.new_code_cell("## Exercise 5\n# a comment, not a section"),
            nbformat.v4.new_markdown_cell("## Exercise 99\nno such exercise in the lab"),
        ]
    )
    assert exercises_in(nb) == [3]
    assert exercises_in([cell.source for cell in nb.cells if cell.cell_type == "markdown"]) == [3]
