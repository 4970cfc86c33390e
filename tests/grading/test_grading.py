"""Student release and grading: instructor = full marks and all extra credit, release = zero,
the lab's branch rubric, planted mistakes lose exactly their part with the matching hint,
broken submissions never stop the run."""

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
from labkit.check import EXERCISES
from labkit.exercises.registry import LAB
from labkit.grading.store.report import file_stem

pytestmark = pytest.mark.slow  # grades the instructor notebooks and small classes

ANSWERS = LAB.answers
from labkit.grading.store.rubric import default

ROOT = Path(__file__).resolve().parents[2]
NOTEBOOKS = ROOT / "notebooks"
RUBRIC = default()
FULL = RUBRIC.full_credit
EVERYTHING = RUBRIC.maximum


def test_strip_solutions_keeps_signature_indentation_and_drops_hidden_tests():
    source = (
        "def f(x):\n    '''doc'''\n    ### BEGIN SOLUTION\n    return x\n    ### END SOLUTION\n"
        "### BEGIN HIDDEN TESTS\nassert f(1) == 1\n### END HIDDEN TESTS\nprint('kept')"
    )
    assert grading.strip_solutions(source) == (
        "def f(x):\n    '''doc'''\n    # YOUR CODE HERE\n    raise NotImplementedError()\nprint('kept')"
    )


@pytest.mark.parametrize(
    "source, message",
    [
        ("### BEGIN SOLUTION\nx = 1", "never closed"),
        ("x = 1\n### END SOLUTION", "without a matching"),
        ("### BEGIN SOLUTION\n### BEGIN HIDDEN TESTS", "inside an open"),
    ],
)
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
            assert s_cell.cell_type == t_cell.cell_type
            # a hidden test's cell is the grader's: the student's copy locks it (read-only, not deletable)
            locked = {"editable": False, "deletable": False} if "### BEGIN HIDDEN TESTS" in t_cell.source else {}
            assert s_cell.metadata == {**t_cell.metadata, **locked}
            if t_cell.cell_type == "markdown":
                # an answer in words is the instructor's; the student gets an empty answer cell
                expected = "YOUR ANSWER HERE" if "### BEGIN SOLUTION" in t_cell.source else t_cell.source
                assert s_cell.source == expected
                continue
            assert s_cell.outputs == [] and s_cell.execution_count is None
            assert "BEGIN SOLUTION" not in s_cell.source and "HIDDEN TESTS" not in s_cell.source
            if "### BEGIN SOLUTION" in t_cell.source:
                assert "raise NotImplementedError()" in s_cell.source
            elif "### BEGIN HIDDEN TESTS" not in t_cell.source:
                assert s_cell.source == t_cell.source


def test_required_student_code_sits_in_solution_regions_with_signatures_outside():
    sources = [
        c.source
        for p in sorted(NOTEBOOKS.glob("*.ipynb"))
        for c in nbformat.read(p, as_version=4).cells
        if c.cell_type == "code"
    ]
    stripped = "\n".join(grading.strip_solutions(source) for source in sources)
    for name in (
        "eval_pherm",
        "runge",
        "test_pherm_interpolate",
        "limacon_derivatives",
        "coons",
        "mirror",
        "two_patches",
        "complete_system",
        "ccspline",
        "ncspline",
        "test_ccspline_interpolate",
        "test_ncspline_interpolate",
        "test_spline_interpolate",
        "test_pchip_interpolate",
        "eval_pbilin",
        "runge2d",
        "test_pbilin_interpolate",
    ):
        body = stripped.split(f"def {name}(", 1)[1].split("\ndef ", 1)[0]
        assert '"""' in body.split("# YOUR CODE HERE")[0], f"{name} keeps its docstring"
        assert "raise NotImplementedError()" in body and "\n    return" not in body, name
    data = [
        "graded =",
        "straight =",
        "circle_sides =",
        "A = Corner(",
        "region =",
        "phi_table =",
        "xdata = r * np.cos(tdata)",
        "ax14.plot(",
        "ax4.plot(",
    ]
    for key in ("pherm", "complete", "natural", "notaknot", "pchip", "bilinear"):
        data += [f"errors_{key} =", f"rate_{key} ="]
    for line in data:
        assert line in "\n".join(sources) and line not in stripped, line
    # every graded name has a hidden test that asserts its check
    hidden = "\n".join(s.split("### BEGIN HIDDEN TESTS")[1] for s in sources if "### BEGIN HIDDEN TESTS" in s)
    for exercise in EXERCISES.values():
        for part in exercise.parts:
            name = part.name.split(":")[0]
            assert name in hidden, f"exercise {exercise.number}: no hidden test mentions {name}"


def _partly_done(tmp_path, name, released, untouched):
    """A submission folder: the instructor notebooks, but those in `untouched` as released (not done)."""
    folder = tmp_path / name
    folder.mkdir()
    for path in NOTEBOOKS.glob("*.ipynb"):
        shutil.copy((released if path.name in untouched else NOTEBOOKS) / path.name, folder / path.name)
    return folder


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


# planted mistakes of the lab's student work: (name, notebook, old text, new text, exercise, part, hint)
PLANTED = [
    (
        "wrong_sign_dydt",
        "01_limacon.ipynb",
        "dydt = -np.sin(t) ** 2 + r * np.cos(t)",
        "dydt = np.sin(t) ** 2 - r * np.cos(t)",
        4,
        "limacon_derivatives",
        "dy/dt has the wrong sign",
    ),
    (
        "absolute_error",
        "04_splines.ipynb",
        "labkit.eval_pherm(xdata, ydata, sprime, xtest))) / np.max(np.abs(exact))",
        "labkit.eval_pherm(xdata, ydata, sprime, xtest)))",
        11,
        "test_ccspline_interpolate",
        "the error is absolute, not relative to max|f|",
    ),
    (
        "rate_eight",
        "04_splines.ipynb",
        "rate_complete = 4",
        "rate_complete = 8",
        11,
        "rate_complete",
        "the exponent p of the power of two",
    ),
    (
        "data_joined",
        "05_monotone.ipynb",
        'ax14.plot(xdata, ydata, "o", color="k"',
        'ax14.plot(xdata, ydata, "o-", color="k"',
        14,
        "ax14: the data",
        "no line may join the data points",
    ),
    (
        "spline_20_points",
        "05_monotone.ipynb",
        "ax14.plot(xval, labkit.spline(xdata, ydata, xval)",
        "ax14.plot(xval[::10], labkit.spline(xdata, ydata, xval[::10])",
        14,
        "ax14: the not-a-knot spline",
        "at least 100 points",
    ),
]


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
        "wrong_denominator": _plant(
            tmp, "wrong_denominator", "02_convergence.ipynb", "/ (xk - xk1) ** 3", "/ (xk - xk1) ** 2"
        ),
        "natural_rows": _plant(
            tmp,
            "natural_rows",
            "04_splines.ipynb",
            "    A[0, :], A[-1, :] = 0.0, 0.0\n    A[0, 0], A[-1, -1] = 1.0, 1.0\n    D[0], D[-1] = 0.0, 0.0\n",
            "",
        ),
        "missing_twist": _plant(tmp, "missing_twist", "03_meshes.ipynb", "[A.dsdt[c], B.dsdt[c]]", "[0.0, 0.0]"),
        "raises": _broken(tmp, "raises", "raise RuntimeError('student bug')"),
        "loops_forever": _broken(tmp, "loops_forever", "while True:\n    pass"),
        "syntax_error": _broken(tmp, "syntax_error", "def broken(:\n    pass"),
        "prints_megabytes": _broken(tmp, "prints_megabytes", "for _ in range(50):\n    print('x' * 1_000_000)"),
        "deletes_files": _broken(tmp, "deletes_files", "import os\nfor f in os.listdir('.'):\n    os.remove(f)"),
        # the lab's rubric: exercises 1-4 and one branch is full credit, the other branch extra
        "spline_branch_only": _partly_done(
            tmp, "spline_branch_only", released, ("03_meshes.ipynb", "06_bilinear.ipynb")
        ),
        "both_branches": _partly_done(tmp, "both_branches", released, ("06_bilinear.ipynb",)),
    }
    for name, notebook, old, new, *_ in PLANTED:
        subs[name] = _plant(tmp, name, notebook, old, new)
    not_json = tmp / "not_json.ipynb"
    not_json.write_text("{ this is not json")
    subs["not_json"] = not_json
    out = tmp / "grades"
    results = grading.grade(
        list(subs.values()), out, grading.GradeOptions(cell_timeout=10, total_timeout=120, jobs=2), progress=False
    )
    return {name: r for name, r in zip(subs, results)}, out, sentinel, subs


def test_instructor_notebooks_score_full_marks_and_all_extra_credit(graded):
    results, *_ = graded
    grade = results["instructor"]
    assert EVERYTHING == FULL + RUBRIC.branch_extra + sum(RUBRIC.points[n] for n in RUBRIC.extra_credit)
    assert grade.total == EVERYTHING, grade.feedback()
    assert all(verdict.passed for verdict in grade.results.values()) and set(grade.results) == set(EXERCISES)


def test_spline_branch_alone_is_full_credit_without_extra(graded):
    results, *_ = graded
    score = results["spline_branch_only"].score
    assert score.total == FULL and score.branch == "splines" and score.extra_total == 0, results[
        "spline_branch_only"
    ].feedback()
    assert "Branch that counts: splines, 60 / 60" in results["spline_branch_only"].feedback()


def test_the_second_branch_is_ten_points_of_extra_credit(graded):
    results, *_ = graded
    score = results["both_branches"].score
    assert score.total == FULL + 10 and score.extra == {"exercise 16": 0, "branch splines": 10.0}, results[
        "both_branches"
    ].feedback()
    assert "Extra credit, branch splines: 10" in results["both_branches"].feedback()


@pytest.mark.parametrize("name, exercise, part, hint", [(p[0], p[4], p[5], p[6]) for p in PLANTED])
def test_planted_mistake_loses_exactly_its_part_with_the_matching_hint(graded, name, exercise, part, hint):
    results, *_ = graded
    grade, instructor = results[name], results["instructor"]
    failed = [(n, c.name) for n, v in grade.results.items() for c in v.parts if not c.passed]
    assert failed == [(exercise, part)], grade.feedback()
    lost = (
        RUBRIC.points[exercise]
        * next(p.weight for p in EXERCISES[exercise].parts if p.name == part)
        / EXERCISES[exercise].points
    )
    assert grade.points[exercise] == pytest.approx(RUBRIC.points[exercise] - lost, abs=0.01), grade.feedback()
    assert grade.total < EVERYTHING
    assert {n: p for n, p in grade.points.items() if n != exercise} == {
        n: p for n, p in instructor.points.items() if n != exercise
    }
    section = grade.feedback().split(f"Exercise {exercise}:")[1].split("\nExercise ")[0]
    assert hint in section, section


def test_student_release_scores_zero_without_crashing(graded):
    results, *_ = graded
    assert results["student_release"].total == 0
    feedback = results["student_release"].feedback()
    assert "not done" in feedback and "Traceback" not in feedback and "not implemented yet" not in feedback


@pytest.mark.parametrize(
    "name, exercise, part, hint",
    [
        ("wrong_denominator", 2, "eval_pherm", "denominators"),
        ("natural_rows", 12, "ncspline", "M1 = 0 and Mn = 0"),
        ("missing_twist", 5, "coons", "ignores the twists"),
    ],
)
def test_planted_bug_loses_exactly_its_function_with_the_matching_hint(graded, name, exercise, part, hint):
    results, *_ = graded
    grade = results[name]
    # a wrong function does not cost the drivers, tables and rates built on it: the driver's check
    # hands in labkit's function, the table follows the student's own driver, the rate their table. A
    # table whose errors do not shrink keeps its points too when the driver is real (a wrong Hermite
    # denominator makes the student's own driver's errors stall at 1): it is what the driver measured. But a
    # rate is read from the student's own table, so the planted copy's unchanged answer no longer fits it
    also = {"natural_rows": [(12, "rate_natural")]}.get(name, [])
    failed = [(n, c.name) for n, v in grade.results.items() for c in v.parts if not c.passed]
    assert failed == [(exercise, part)] + also, grade.feedback()
    changed = {exercise} | {n for n, _ in also}
    assert {n: p for n, p in grade.points.items() if n not in changed} == {
        n: p for n, p in results["instructor"].points.items() if n not in changed
    }, grade.feedback()
    if name == "wrong_denominator":
        assert "shows no experiment" not in grade.feedback()
    feedback = grade.feedback()
    section = feedback.split(f"Exercise {exercise}:")[1].split("\nExercise ")[0]
    assert hint in section


@pytest.mark.parametrize(
    "name, problem",
    [
        ("raises", "raised RuntimeError: student bug"),
        ("loops_forever", "ran past its time limit"),
        ("syntax_error", "raised SyntaxError"),
        ("prints_megabytes", None),
        ("deletes_files", None),
    ],
)
def test_broken_submissions_are_graded_as_far_as_they_get(graded, name, problem):
    results, *_ = graded
    grade = results[name]
    assert grade.points[16] == RUBRIC.points[16], grade.feedback()  # the rest of the notebook still ran
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
    nb.cells += [nbformat.v4.new_code_cell("import time\ntime.sleep(1)") for _ in range(150)]
    path = tmp_path / "slow.ipynb"
    nbformat.write(nb, path)
    start = time.perf_counter()
    results, problems = grading.grade_notebook(path, grading.GradeOptions(cell_timeout=60, total_timeout=3))
    # unstopped, the cells take 150 s; the limit is 3 s, and the rest is slack for a busy machine
    assert time.perf_counter() - start < 90
    assert results == {} and "the submission's time limit of 3 s" in problems[0]


def test_grades_csv_and_feedback_files(graded):
    results, out, _, subs = graded
    with open(out / "grades.csv", newline="") as handle:
        rows = list(csv.reader(handle))
    assert rows[0][: len(EXERCISES) + 8] == ["submission"] + [f"exercise {n}" for n in sorted(EXERCISES)] + [
        "required",
        "branch",
        "branch points",
        "extra credit",
        "total",
        "full credit",
        "status",
    ]
    # then one empty column per answer in words, for the instructor to fill in after reading it
    assert rows[0][len(EXERCISES) + 8 :] == [f"to read: exercise {n}, {what}" for n, what in ANSWERS.values()]
    assert all(row[len(EXERCISES) + 8 :] == [""] * len(ANSWERS) for row in rows[1:])
    assert [row[0] for row in rows[1:]] == [results[name].name for name in subs]
    column = {name: i for i, name in enumerate(rows[0])}
    for row in rows[1:]:
        value = {name: row[i] for name, i in column.items()}
        assert float(value["required"]) == sum(float(value[f"exercise {n}"]) for n in (2, 3, 4))
        assert float(value["total"]) == pytest.approx(
            float(value["required"]) + float(value["branch points"]) + float(value["extra credit"])
        )
        assert value["full credit"] == "100"
    row = next(r for r in rows if r[0] == "spline_branch_only")
    assert row[column["branch"]] == "splines" and row[column["total"]] == "100"
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
    for grade in results.values():
        data = json.loads((out / "results" / f"{grading.store.report.safe_name(grade.name)}.json").read_text())
        assert data["total"] == grade.total and data["seed"] == seed
        assert {int(n): v for n, v in data["points"].items()} == grade.points


@pytest.fixture(scope="module")
def two_runs(tmp_path_factory, released):
    """The class split over two 'batch jobs' with one seed, as on a cluster, and merged."""
    tmp = tmp_path_factory.mktemp("split")
    solved, bare = tmp / "alice.ipynb", tmp / "bob.ipynb"
    shutil.copy(NOTEBOOKS / "06_bilinear.ipynb", solved)
    shutil.copy(released / "06_bilinear.ipynb", bare)
    first = grading.grade([solved], tmp / "job1", grading.GradeOptions(seed=4242, jobs=1), progress=False)
    second = grading.grade([bare], tmp / "job2", grading.GradeOptions(seed=4242, jobs=1), progress=False)
    again = grading.grade([solved], tmp / "job3", grading.GradeOptions(seed=4242, jobs=1), progress=False)
    return tmp, first + second, again


def test_merge_combines_batch_jobs_into_one_grades_csv(two_runs):
    tmp, graded_apart, _ = two_runs
    run = _cli("merge", str(tmp / "job1"), str(tmp / "job2"), "--out", str(tmp / "merged"))
    assert run.returncode == 0, run.stderr
    with open(tmp / "merged" / "grades.csv", newline="") as handle:
        rows = {row[0]: row for row in csv.reader(handle)}
    assert sorted(rows) == ["alice", "bob", "submission"]
    total = rows["submission"].index("total")
    assert rows["alice"][total] == "8" and rows["bob"][total] == "0"
    for grade in graded_apart:
        assert float(rows[grade.name][total]) == grade.total
        assert (tmp / "merged" / "feedback" / f"{file_stem(grade.name)}.txt").read_text() == grade.feedback()
    assert (tmp / "merged" / "seed.txt").read_text() == "4242\n"


def test_merge_keeps_a_later_folders_result_and_refuses_folders_without_results(two_runs, tmp_path):
    tmp, *_ = two_runs
    merged = grading.merge([tmp / "job1", tmp / "job3"], tmp_path / "m0")
    result = f"{grading.store.report.safe_name('alice')}.json"
    assert [g.name for g in merged] == ["alice"]
    assert [(r.name, r.earlier, r.later) for r in merged.replaced] == [
        ("alice", tmp / "job1" / "results" / result, tmp / "job3" / "results" / result)
    ]
    with pytest.raises(ValueError, match="has no run record"):
        grading.merge([tmp_path], tmp_path / "m")
    (tmp_path / "results").mkdir()
    (tmp_path / "results" / "x.json").write_text('{"format": "something else"}')
    with pytest.raises(ValueError, match="has no run record"):  # results no run vouches for are never read
        grading.merge([tmp_path], tmp_path / "m")


def test_merge_scores_with_the_runs_rubric_and_refuses_one_with_other_points(tmp_path, released):
    solved, bare = tmp_path / "alice.ipynb", tmp_path / "bob.ipynb"
    shutil.copy(NOTEBOOKS / "06_bilinear.ipynb", solved)
    shutil.copy(released / "06_bilinear.ipynb", bare)
    rubric = tmp_path / "rubric.toml"
    rubric.write_text('title = "bilinear only"\nrequired = [16]\n[points]\n16 = 20\n')
    for path, job in ((solved, "job1"), (bare, "job2")):
        grading.grade([path], tmp_path / job, grading.GradeOptions(seed=4242, rubric=rubric, jobs=1), progress=False)
    tmp = tmp_path
    other = tmp_path / "other.toml"
    other.write_text('title = "bilinear only"\nrequired = [16]\n[points]\n16 = 10\n')
    refused = _cli("merge", str(tmp / "job1"), str(tmp / "job2"), "--out", str(tmp_path / "m"), "--rubric", str(other))
    assert refused.returncode == 2 and "results of different rubrics" in refused.stderr
    assert not (tmp_path / "m").exists()
    run = _cli("merge", str(tmp / "job1"), str(tmp / "job2"), "--out", str(tmp_path / "m"))
    assert run.returncode == 0, run.stderr
    with open(tmp_path / "m" / "grades.csv", newline="") as handle:
        rows = {row[0]: row for row in csv.reader(handle)}
    assert rows["submission"][1:9] == [
        "exercise 16",
        "required",
        "branch",
        "branch points",
        "extra credit",
        "total",
        "full credit",
        "status",
    ]
    assert [c.split(",")[0] for c in rows["submission"][9:]] == ["to read: exercise 16"] * 2
    assert rows["alice"][1:9] == ["20", "20", "", "0", "0", "20", "20", "graded"] and rows["bob"][6] == "0"
    feedback = tmp_path / "m" / "feedback" / f"{file_stem('alice')}.txt"
    assert "Rubric: bilinear only" in feedback.read_text()
    bad = tmp_path / "bad.toml"
    bad.write_text("[points]\n17 = 5\n")
    run = _cli("merge", str(tmp / "job1"), "--out", str(tmp_path / "m2"), "--rubric", str(bad))
    assert run.returncode == 2 and "exercise '17', which labkit does not grade" in run.stderr


def test_the_same_seed_gives_the_same_feedback(two_runs):
    tmp, *_ = two_runs
    name = f"{file_stem('alice')}.txt"
    assert (tmp / "job1" / "feedback" / name).read_text() == (tmp / "job3" / "feedback" / name).read_text()


def test_grading_without_bwrap_stops_and_says_how_to_install_it(tmp_path, monkeypatch):
    monkeypatch.setenv("PATH", str(tmp_path))  # no bwrap on this PATH
    with pytest.raises(ValueError, match="install bubblewrap"):
        grading.grade([NOTEBOOKS / "06_bilinear.ipynb"], tmp_path / "out", progress=False)
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("switch", [["--no-sandbox"], ["--sandbox", "none"]])
def test_no_sandbox_warns_loudly_and_still_grades(tmp_path, switch):
    run = _cli(
        "grade", str(NOTEBOOKS / "06_bilinear.ipynb"), "--out", str(tmp_path / "g"), *switch, "--quiet", "--seed", "5"
    )
    assert run.returncode == 0, run.stderr
    assert "student code runs UNCONFINED" in run.stderr and "random test data from seed 5" in run.stdout
    assert f"06_bilinear{' ' * 20}" in run.stdout and run.stdout.split("06_bilinear")[1].split()[0] == "8"


def test_cli_grade_needs_submissions_and_points_the_old_merge_to_its_command(tmp_path):
    run = _cli("grade", "--out", str(tmp_path))
    assert run.returncode == 2 and "give the submissions" in run.stderr and "labkit merge DIR" in run.stderr
    run = _cli("grade", str(NOTEBOOKS), "--merge", str(tmp_path), "--out", str(tmp_path))
    assert run.returncode == 2 and "is now a command of its own: labkit merge DIR... --out DIR" in run.stderr
    assert not (tmp_path / "grades.csv").exists()
    run = _cli("grade", str(NOTEBOOKS), "--jobs", "0", "--out", str(tmp_path))
    assert run.returncode == 2 and "--jobs must be at least 1" in run.stderr
