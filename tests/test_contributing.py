"""CONTRIBUTING.md's walkthrough, run as written: a toy exercise declared in a registry of its own, its
notebook marked for nbgrader with the rubric's points, released, and a right and a wrong answer graded."""

import csv
import os
import re
import subprocess
import sys
from pathlib import Path

import nbformat
import pytest
from conftest import sandbox_or_skip

ROOT = Path(__file__).resolve().parents[1]
BLOCK = re.compile(r"^```(\w*)\n(.*?)^```", re.MULTILINE | re.DOTALL)


def _walkthrough():
    """{file name: text} and the notebook's cells, from CONTRIBUTING.md's tagged code blocks."""
    files, cells = {}, []
    for _, body in BLOCK.findall((ROOT / "CONTRIBUTING.md").read_text(encoding="utf-8")):
        first, _, rest = body.partition("\n")
        if first.startswith("# file: "):
            files[first[len("# file: ") :].strip()] = rest
        elif first.strip() == "# cell: code":
            cells.append(nbformat.v4.new_code_cell(rest.rstrip("\n")))
        elif first.strip() == "<!-- cell: markdown -->":
            cells.append(nbformat.v4.new_markdown_cell(rest.strip("\n")))
    return files, cells


@pytest.fixture(scope="module")
def course(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("toy_course")
    files, cells = _walkthrough()
    assert set(files) == {"toy_lab.py", "toy.toml"} and len(cells) == 4
    for name, text in files.items():
        (tmp / name).write_text(text, encoding="utf-8")
    (tmp / "notebooks").mkdir()
    nb = nbformat.v4.new_notebook(cells=cells)
    nbformat.write(nb, tmp / "notebooks" / "07_secants.ipynb")
    old = os.environ.get("PYTHONPATH")
    os.environ["PYTHONPATH"] = str(tmp) + (os.pathsep + old if old else "")
    sys.path.insert(0, str(tmp))
    yield tmp
    sys.path.remove(str(tmp))
    sys.modules.pop("toy_lab", None)
    if old is None:
        os.environ.pop("PYTHONPATH")
    else:
        os.environ["PYTHONPATH"] = old


def _labkit(*args, cwd):
    return subprocess.run(
        [sys.executable, "-m", "labkit.cli", *map(str, args)], cwd=cwd, capture_output=True, text=True, timeout=600
    )


def test_the_toy_exercise_is_declared_once_and_everything_follows(course):
    import toy_lab

    from labkit.grading.authoring.release import mark
    from labkit.grading.store import rubric as rubrics

    registry = toy_lab.REGISTRY
    assert registry.points[17] == 5 and registry.exercises[17].notebook == "07_secants.ipynb"
    assert registry.self_checks["secants"] is toy_lab.check_secants
    rubric = rubrics.load(course / "toy.toml")
    assert rubric.registry is registry and rubric.points == {17: 5.0} and rubric.full_credit == 5
    # nbgrader's points are the rubric's in force: the declared weight, or the rubric's own
    nb = nbformat.read(course / "notebooks" / "07_secants.ipynb", as_version=4)
    tests = [
        c
        for c in mark(nb, "07_secants.ipynb", rubric).cells
        if c.metadata["nbgrader"]["grade"] and c.cell_type == "code"
    ]
    assert [c.metadata["nbgrader"]["points"] for c in tests] == [5]
    doubled = (course / "toy.toml").read_text() + "\n[points]\n17 = 10\n"
    (course / "doubled.toml").write_text(doubled)
    marked = mark(nb, "07_secants.ipynb", rubrics.load(course / "doubled.toml"))
    assert [
        c.metadata["nbgrader"]["points"]
        for c in marked.cells
        if c.metadata["nbgrader"]["grade"] and c.cell_type == "code"
    ] == [10]
    # a right and a wrong answer, checked in this process as a student's self-check would
    assert toy_lab.check_secants(lambda x, y: (y[1:] - y[:-1]) / (x[1:] - x[:-1])).passed
    slip = toy_lab.check_secants(lambda x, y: y[1:] - y[:-1])
    assert not slip.passed and "divide each difference" in slip.hint


@pytest.mark.slow  # starts a sandbox
def test_the_toy_exercise_is_executed_released_and_graded_right_and_wrong(course):
    sandbox_or_skip()
    ran = _labkit("execute", "notebooks", "--rubric", "toy.toml", cwd=course)
    assert ran.returncode == 0, ran.stderr
    instructor = nbformat.read(course / "notebooks" / "07_secants.ipynb", as_version=4)
    assert "all checks passed" in str(instructor.cells[2].outputs)
    released = _labkit("release", "notebooks", "--out", "release", cwd=course)
    assert released.returncode == 0, released.stderr
    student = (course / "release" / "07_secants.ipynb").read_text()
    assert "raise NotImplementedError()" in student and "np.diff(ydata) / np.diff(xdata)" not in student
    assert "HIDDEN TESTS" not in student and "seed=1" not in student
    submissions = course / "submissions"
    for name, text in (("right", None), ("wrong", "np.diff(ydata)")):
        folder = submissions / name
        folder.mkdir(parents=True)
        source = (course / "notebooks" / "07_secants.ipynb").read_text()
        if text is not None:
            source = source.replace("np.diff(ydata) / np.diff(xdata)", text)
        (folder / "07_secants.ipynb").write_text(source)
    (submissions / "bare").mkdir()
    (submissions / "bare" / "07_secants.ipynb").write_text(student)
    graded = _labkit(
        "grade",
        "--rubric",
        "toy.toml",
        "--seed",
        "5",
        "--quiet",
        "--out",
        "graded",
        *(submissions / n for n in ("right", "wrong", "bare")),
        cwd=course,
    )
    assert graded.returncode == 0, graded.stderr
    with open(course / "graded" / "grades.csv", newline="") as handle:
        rows = {row["submission"]: row for row in csv.DictReader(handle)}
    assert {name: rows[name]["exercise 17"] for name in rows} == {"right": "5", "wrong": "0", "bare": "0"}
    assert rows["right"]["total"] == "5"
    wrong = (course / "graded" / "feedback").glob("wrong*.txt")
    assert "divide each difference of ydata" in next(wrong).read_text()
    # the course module is there in the sandbox too: the right answer's self-check cells ran without an error
    right = next((course / "graded" / "feedback").glob("right*.txt")).read_text()
    assert "raised" not in right and "toy_lab" not in right and re.search(r"\n\s+17\s+5 / 5  done\n", right), right
