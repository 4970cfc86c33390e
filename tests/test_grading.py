"""Student release and grading: instructor = full marks, release = zero, planted bugs lose
exactly their exercise with the matching hint, broken submissions never stop the run."""
import csv
import json
import shutil
import subprocess
import sys
import time
from pathlib import Path

import nbformat
import pytest

from labkit import grading
from labkit.check import EXERCISES, POINTS

ROOT = Path(__file__).resolve().parents[1]
NOTEBOOKS = ROOT / "notebooks"
FULL = sum(POINTS.values())


def test_strip_solutions_keeps_signature_indentation_and_drops_hidden_tests():
    source = "def f(x):\n    '''doc'''\n    ### BEGIN SOLUTION\n    return x\n    ### END SOLUTION\n" \
             "### BEGIN HIDDEN TESTS\nassert f(1) == 1\n### END HIDDEN TESTS\nprint('kept')"
    assert grading.strip_solutions(source) == (
        "def f(x):\n    '''doc'''\n    # YOUR CODE HERE\n    raise NotImplementedError()\nprint('kept')")


@pytest.mark.parametrize("source, message", [
    ("### BEGIN SOLUTION\nx = 1", "never closed"),
    ("x = 1\n### END SOLUTION", "without a matching"),
    ("### BEGIN SOLUTION\n### BEGIN HIDDEN TESTS", "inside an open"),
])
def test_unbalanced_markers_are_reported_with_their_place(source, message):
    with pytest.raises(ValueError, match=message):
        grading.strip_solutions(source, "nb.ipynb, cell 3")


@pytest.fixture(scope="module")
def released(tmp_path_factory):
    out = tmp_path_factory.mktemp("release")
    grading.release(NOTEBOOKS, out)
    return out


def test_release_is_deterministic_and_keeps_everything_but_solutions(released, tmp_path):
    again = tmp_path / "again"
    grading.release(NOTEBOOKS, again)
    for path in sorted(NOTEBOOKS.glob("*.ipynb")):
        student_bytes = (released / path.name).read_bytes()
        assert student_bytes == (again / path.name).read_bytes()
        teacher = nbformat.read(path, as_version=4)
        student = nbformat.reads(student_bytes.decode(), as_version=4)
        assert len(student.cells) == len(teacher.cells)
        for t_cell, s_cell in zip(teacher.cells, student.cells):
            assert s_cell.cell_type == t_cell.cell_type and s_cell.metadata == t_cell.metadata
            if t_cell.cell_type == "markdown":
                assert s_cell.source == t_cell.source
                continue
            assert s_cell.outputs == [] and s_cell.execution_count is None
            assert "BEGIN SOLUTION" not in s_cell.source and "HIDDEN TESTS" not in s_cell.source
            if "### BEGIN SOLUTION" in t_cell.source:
                assert "raise NotImplementedError()" in s_cell.source
            elif "### BEGIN HIDDEN TESTS" not in t_cell.source:
                assert s_cell.source == t_cell.source


def test_required_student_code_sits_in_solution_regions_with_signatures_outside():
    sources = [c.source for p in sorted(NOTEBOOKS.glob("*.ipynb"))
               for c in nbformat.read(p, as_version=4).cells if c.cell_type == "code"]
    stripped = "\n".join(grading.strip_solutions(source) for source in sources)
    for name in ("eval_pherm", "runge", "test_pherm_interpolate", "coons", "mirror", "two_patches",
                 "complete_system", "ccspline", "ncspline", "eval_pbilin", "runge2d"):
        body = stripped.split(f"def {name}(", 1)[1].split("\ndef ", 1)[0]
        assert '"""' in body.split("# YOUR CODE HERE")[0], f"{name} keeps its docstring"
        assert "raise NotImplementedError()" in body and "return" not in body, name
    for data in ("graded =", "straight =", "circle_sides =", "A = Corner("):
        assert data in "\n".join(sources) and data not in stripped


def _plant(tmp_path, name, notebook, old, new):
    """A submission folder: the instructor notebooks with one solution line changed."""
    folder = tmp_path / name
    folder.mkdir()
    for path in NOTEBOOKS.glob("*.ipynb"):
        nb = nbformat.read(path, as_version=4)
        if path.name == notebook:
            hits = [c for c in nb.cells if old in c.source]
            assert len(hits) == 1, f"planted text not found once in {notebook}"
            hits[0].source = hits[0].source.replace(old, new)
        nbformat.write(nb, folder / path.name)
    return folder


def _broken(tmp_path, name, first_cell_source):
    """06_bilinear.ipynb with an extra first code cell (student code gone wrong)."""
    nb = nbformat.read(NOTEBOOKS / "06_bilinear.ipynb", as_version=4)
    nb.cells.insert(1, nbformat.v4.new_code_cell(first_cell_source))
    path = tmp_path / f"{name}.ipynb"
    nbformat.write(nb, path)
    return path


@pytest.fixture(scope="module")
def graded(tmp_path_factory, released):
    tmp = tmp_path_factory.mktemp("submissions")
    sentinel = tmp / "outside.txt"
    sentinel.write_text("must survive")
    subs = {
        "instructor": NOTEBOOKS,
        "student_release": released,
        "wrong_denominator": _plant(tmp, "wrong_denominator", "02_convergence.ipynb",
                                    "/ (xk - xk1) ** 3", "/ (xk - xk1) ** 2"),
        "natural_rows": _plant(tmp, "natural_rows", "04_splines.ipynb",
                               "    A[0, :], A[-1, :] = 0.0, 0.0\n    A[0, 0], A[-1, -1] = 1.0, 1.0\n    D[0], D[-1] = 0.0, 0.0\n", ""),
        "missing_twist": _plant(tmp, "missing_twist", "03_meshes.ipynb",
                                "[A.dsdt[c], B.dsdt[c]]", "[0.0, 0.0]"),
        "raises": _broken(tmp, "raises", "raise RuntimeError('student bug')"),
        "loops_forever": _broken(tmp, "loops_forever", "while True:\n    pass"),
        "syntax_error": _broken(tmp, "syntax_error", "def broken(:\n    pass"),
        "prints_megabytes": _broken(tmp, "prints_megabytes", "for _ in range(50):\n    print('x' * 1_000_000)"),
        "deletes_files": _broken(tmp, "deletes_files", "import os\nfor f in os.listdir('.'):\n    os.remove(f)"),
    }
    not_json = tmp / "not_json.ipynb"
    not_json.write_text("{ this is not json")
    subs["not_json"] = not_json
    out = tmp / "grades"
    results = grading.grade(list(subs.values()), out, jobs=2, cell_timeout=10, total_timeout=120, progress=False)
    return {name: r for name, r in zip(subs, results)}, out, sentinel, subs


def test_instructor_notebooks_score_full_marks(graded):
    results, *_ = graded
    assert results["instructor"].total == FULL, results["instructor"].feedback()


def test_student_release_scores_zero_without_crashing(graded):
    results, *_ = graded
    assert results["student_release"].total == 0
    assert "not implemented yet" in results["student_release"].feedback()


@pytest.mark.parametrize("name, exercise, hint", [
    ("wrong_denominator", 2, "denominators"),
    ("natural_rows", 12, "M1 = 0 and Mn = 0"),
    ("missing_twist", 5, "ignores the twists"),
])
def test_planted_bug_loses_exactly_its_exercise_with_the_matching_hint(graded, name, exercise, hint):
    results, *_ = graded
    grade = results[name]
    assert grade.points[exercise] == 0
    assert grade.total == FULL - POINTS[exercise], grade.feedback()
    feedback = grade.feedback()
    section = feedback.split(f"Exercise {exercise}:")[1].split("\nExercise ")[0]
    assert hint in section


@pytest.mark.parametrize("name, problem", [
    ("raises", "raised an error"),
    ("loops_forever", "raised an error"),
    ("syntax_error", "raised an error"),
    ("prints_megabytes", None),
    ("deletes_files", None),
])
def test_broken_submissions_are_graded_as_far_as_they_get(graded, name, problem):
    results, *_ = graded
    grade = results[name]
    assert grade.points[16] == POINTS[16], grade.feedback()  # the rest of the notebook still ran
    if problem:
        assert problem in grade.feedback()


def test_invalid_notebook_is_recorded_not_fatal(graded):
    results, *_ = graded
    assert results["not_json"].total == 0
    assert "is not a valid notebook" in results["not_json"].feedback()


def test_nothing_outside_the_temporary_folders_is_touched(graded):
    _, _, sentinel, subs = graded
    assert sentinel.read_text() == "must survive"
    assert subs["deletes_files"].exists()


def test_total_time_limit_stops_a_slow_notebook(tmp_path):
    nb = nbformat.v4.new_notebook()
    nb.cells = [nbformat.v4.new_markdown_cell("## Exercise 16")]
    nb.cells += [nbformat.v4.new_code_cell("import time\ntime.sleep(1)") for _ in range(10)]
    path = tmp_path / "slow.ipynb"
    nbformat.write(nb, path)
    start = time.perf_counter()
    results, problems = grading.grade_notebook(path, cell_timeout=60, total_timeout=3)
    assert time.perf_counter() - start < 8
    assert results == {} and "total time limit of 3 s" in problems[0]


def test_grades_csv_and_feedback_files(graded):
    results, out, _, subs = graded
    with open(out / "grades.csv", newline="") as handle:
        rows = list(csv.reader(handle))
    assert rows[0] == ["submission"] + [f"exercise {n}" for n in sorted(EXERCISES)] + ["total"]
    assert [row[0] for row in rows[1:]] == [results[name].name for name in subs]
    for row in rows[1:]:
        assert sum(int(v) for v in row[1:-1]) == int(row[-1])
    assert len(list((out / "feedback").glob("*.txt"))) == len(subs)


def _cli(*args):
    return subprocess.run([sys.executable, "-m", "labkit.cli", *args], capture_output=True, text=True, timeout=120)


@pytest.mark.parametrize("command", ["execute", "release", "grade"])
def test_cli_help(command):
    run = _cli(command, "--help")
    assert run.returncode == 0 and "usage: labkit " + command in run.stdout


def test_cli_rejects_bad_paths_and_non_notebooks(tmp_path):
    run = _cli("grade", str(tmp_path / "missing.ipynb"), "--out", str(tmp_path / "g"))
    assert run.returncode != 0 and "does not exist" in run.stderr
    text = tmp_path / "essay.txt"
    text.write_text("hello")
    run = _cli("grade", str(text), "--out", str(tmp_path / "g"))
    assert run.returncode != 0 and "is not a notebook" in run.stderr
    run = _cli("release", str(tmp_path), "--out", str(tmp_path / "r"))
    assert run.returncode != 0 and "no notebooks" in run.stderr


def test_every_submission_gets_a_result_file_and_the_seed_is_saved(graded):
    results, out, _, subs = graded
    seed = int((out / "seed.txt").read_text())
    for name, grade in results.items():
        data = json.loads((out / "results" / f"{grading.report.safe_name(grade.name)}.json").read_text())
        assert data["total"] == grade.total and data["seed"] == seed
        assert {int(n): v for n, v in data["points"].items()} == grade.points


@pytest.fixture(scope="module")
def two_runs(tmp_path_factory, released):
    """The class split over two 'batch jobs' with one seed, as on a cluster, and merged."""
    tmp = tmp_path_factory.mktemp("split")
    solved, bare = tmp / "alice.ipynb", tmp / "bob.ipynb"
    shutil.copy(NOTEBOOKS / "06_bilinear.ipynb", solved)
    shutil.copy(released / "06_bilinear.ipynb", bare)
    first = grading.grade([solved], tmp / "job1", jobs=1, seed=4242, progress=False)
    second = grading.grade([bare], tmp / "job2", jobs=1, seed=4242, progress=False)
    again = grading.grade([solved], tmp / "job3", jobs=1, seed=4242, progress=False)
    return tmp, first + second, again


def test_merge_combines_batch_jobs_into_one_grades_csv(two_runs):
    tmp, graded_apart, _ = two_runs
    run = _cli("grade", "--merge", str(tmp / "job1"), str(tmp / "job2"), "--out", str(tmp / "merged"))
    assert run.returncode == 0, run.stderr
    with open(tmp / "merged" / "grades.csv", newline="") as handle:
        rows = {row[0]: row for row in csv.reader(handle)}
    assert sorted(rows) == ["alice", "bob", "submission"]
    assert rows["alice"][-1] == str(POINTS[16]) and rows["bob"][-1] == "0"
    for grade in graded_apart:
        assert int(rows[grade.name][-1]) == grade.total
        assert (tmp / "merged" / "feedback" / f"{grade.name}.txt").read_text() == grade.feedback()
    assert (tmp / "merged" / "seed.txt").read_text() == "4242\n"


def test_merge_refuses_a_submission_graded_twice_and_folders_without_results(two_runs, tmp_path):
    tmp, *_ = two_runs
    with pytest.raises(ValueError, match="graded twice"):
        grading.merge([tmp / "job1", tmp / "job3"], tmp_path / "m")
    with pytest.raises(ValueError, match="holds no results"):
        grading.merge([tmp_path], tmp_path / "m")
    (tmp_path / "results").mkdir()
    (tmp_path / "results" / "x.json").write_text('{"format": "something else"}')
    with pytest.raises(ValueError, match="is not a labkit grade result"):
        grading.merge([tmp_path], tmp_path / "m")


def test_the_same_seed_gives_the_same_feedback(two_runs):
    tmp, *_ = two_runs
    assert (tmp / "job1" / "feedback" / "alice.txt").read_text() == (tmp / "job3" / "feedback" / "alice.txt").read_text()


def test_grading_without_bwrap_stops_and_says_how_to_install_it(tmp_path, monkeypatch):
    monkeypatch.setenv("PATH", str(tmp_path))  # no bwrap on this PATH
    with pytest.raises(ValueError, match="install bubblewrap"):
        grading.grade([NOTEBOOKS / "06_bilinear.ipynb"], tmp_path / "out", progress=False)
    assert not (tmp_path / "out").exists()


def test_no_sandbox_warns_loudly_and_still_grades(tmp_path):
    run = _cli("grade", str(NOTEBOOKS / "06_bilinear.ipynb"), "--out", str(tmp_path / "g"), "--no-sandbox",
               "--quiet", "--seed", "5")
    assert run.returncode == 0, run.stderr
    assert "UNCONFINED" in run.stderr and "random test data from seed 5" in run.stdout
    assert f"06_bilinear{' ' * 20}" in run.stdout and run.stdout.split("06_bilinear")[1].split()[0] == str(POINTS[16])


def test_cli_grade_needs_submissions_or_merge(tmp_path):
    run = _cli("grade", "--out", str(tmp_path))
    assert run.returncode == 2 and "give the submissions" in run.stderr
    run = _cli("grade", str(NOTEBOOKS), "--merge", str(tmp_path), "--out", str(tmp_path))
    assert run.returncode == 2 and "not submissions" in run.stderr
    run = _cli("grade", str(NOTEBOOKS), "--jobs", "0", "--out", str(tmp_path))
    assert run.returncode == 2 and "--jobs must be at least 1" in run.stderr
