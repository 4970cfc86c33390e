"""The instructor notebooks are an nbgrader source folder: the real nbgrader releases and grades them.

A temporary course folder gets ``source/lab8/`` = ``notebooks/``; nbgrader's own
``generate_assignment`` must release all six notebooks with no solution and no
hidden test, stripping exactly what ``labkit release`` strips; ``autograde``
must give a submission made from the instructor notebooks full marks in
nbgrader's own gradebook, and the untouched release zero: nbgrader's, and labkit's
packaged one, whose ``raises-exception`` tags (Run All goes on past the stubs) keep
no point a stub's error loses.
"""

import os
import shutil
import subprocess
import sys
from pathlib import Path

import nbformat
import pytest

from labkit.check import EXERCISES
from labkit.grading import release_notebook

pytestmark = pytest.mark.slow  # nbgrader's own commands

nbgrader_api = pytest.importorskip("nbgrader.api")

ROOT = Path(__file__).resolve().parents[3]
NOTEBOOKS = sorted((ROOT / "notebooks").glob("*.ipynb"))
PACKAGED = ROOT / "labkit" / "student_notebooks"
STUDENTS = ("instructor", "untouched", "untouched-labkit")


def _nbgrader(course, *args):
    env = {**os.environ, "PATH": f"{Path(sys.executable).parent}{os.pathsep}{os.environ['PATH']}"}  # alembic
    run = subprocess.run(
        [sys.executable, "-m", "nbgrader", *args], cwd=course, env=env, capture_output=True, text=True, timeout=600
    )
    assert run.returncode == 0, run.stdout[-3000:] + run.stderr[-3000:]
    return run


@pytest.fixture(scope="module")
def course(tmp_path_factory):
    root = tmp_path_factory.mktemp("course")
    (root / "nbgrader_config.py").write_text(
        "c = get_config()\n"
        f"c.CourseDirectory.root = {str(root)!r}\n"
        "c.CourseDirectory.course_id = 'labkit'\n"
        "c.ExecutePreprocessor.timeout = 300\n"
    )
    source = root / "source" / "lab8"
    source.mkdir(parents=True)
    for path in NOTEBOOKS:
        shutil.copy(path, source / path.name)
    _nbgrader(root, "generate_assignment", "lab8", "--create")
    released = root / "release" / "lab8"
    for student, folder in zip(STUDENTS, (source, released, PACKAGED)):
        submitted = root / "submitted" / student / "lab8"
        submitted.mkdir(parents=True)
        for path in NOTEBOOKS:
            shutil.copy(folder / path.name, submitted / path.name)
        _nbgrader(root, "db", "student", "add", student)
    _nbgrader(root, "autograde", "lab8")
    return root


def test_nbgrader_version_is_recorded():
    import nbgrader

    print(f"nbgrader {nbgrader.__version__}")
    assert tuple(int(p) for p in nbgrader.__version__.split(".")[:2]) >= (0, 9)


def test_generate_assignment_releases_every_notebook_without_solutions_or_hidden_tests(course):
    released = course / "release" / "lab8"
    assert sorted(p.name for p in released.glob("*.ipynb")) == [p.name for p in NOTEBOOKS]
    for path in NOTEBOOKS:
        text = (released / path.name).read_text()
        for marker in ("### BEGIN SOLUTION", "### END SOLUTION", "### BEGIN HIDDEN TESTS", "assert labkit.check"):
            assert marker not in text, (path.name, marker)
        assert "raise NotImplementedError()" in text


def test_nbgrader_and_labkit_release_strip_the_same_things(course):
    for path in NOTEBOOKS:
        theirs = nbformat.read(course / "release" / "lab8" / path.name, as_version=4)
        ours = release_notebook(nbformat.read(path, as_version=4), path.name)
        assert [c.cell_type for c in theirs.cells] == [c.cell_type for c in ours.cells]
        for a, b in zip(theirs.cells, ours.cells):
            assert a.source == b.source, (path.name, a.source[:80], b.source[:80])
            assert a.get("outputs", []) == b.get("outputs", []) == []


def test_nbgraders_release_keeps_the_tags_that_let_run_all_go_on(course):
    for path in NOTEBOOKS:
        theirs = nbformat.read(course / "release" / "lab8" / path.name, as_version=4)
        ours = nbformat.read(PACKAGED / path.name, as_version=4)
        tagged = [
            [c.source for c in nb.cells if "raises-exception" in c.metadata.get("tags", [])] for nb in (theirs, ours)
        ]
        assert tagged[0] == tagged[1] and tagged[0], path.name


def test_every_graded_cell_of_the_untouched_releases_scores_zero(course):
    with nbgrader_api.Gradebook(f"sqlite:///{course / 'gradebook.db'}") as gradebook:
        for student in STUDENTS[1:]:
            for notebook in gradebook.find_submission("lab8", student).notebooks:
                for grade in notebook.grades:
                    if grade.max_score:
                        assert grade.auto_score == 0, (student, notebook.name, grade.name)


def _scores(course):
    with nbgrader_api.Gradebook(f"sqlite:///{course / 'gradebook.db'}") as gradebook:
        scores = {}
        for student in STUDENTS:
            submission = gradebook.find_submission("lab8", student)
            scores[student] = (submission.score, submission.max_score)
        cells = {
            (notebook.name, cell.name): cell.max_score
            for notebook in gradebook.find_assignment("lab8").notebooks
            for cell in notebook.grade_cells
        }
    return scores, cells


def test_autograde_gives_the_instructor_notebooks_full_marks_and_the_release_zero(course):
    scores, cells = _scores(course)
    total = sum(e.points for e in EXERCISES.values())
    assert scores["instructor"] == (total, total)
    assert scores["untouched"] == (0, total)
    assert scores["untouched-labkit"] == (0, total)  # its raises-exception tags cost no test cell its points
    # nbgrader's points per exercise are labkit's
    per_exercise = {}
    for (_, name), points in cells.items():
        number = int(name.split("-")[0].removeprefix("exercise"))
        per_exercise[number] = per_exercise.get(number, 0) + points
    assert per_exercise == {n: e.points for n, e in EXERCISES.items()}
