"""The student release gives no answer away: no stated order, no worked derivation, no remark to copy.

Whatever the lab asks a student to find or explain stays in the instructor notebooks, inside
solution regions: code the student writes, and answers in words (markdown solution cells, which
the release turns into ``YOUR ANSWER HERE`` and nbgrader's metadata marks for manual grading).
"""

import re
from pathlib import Path

import nbformat
import pytest

from labkit.check import EXERCISES
from labkit.exercises.registry import LAB

ANSWERS = LAB.answers
from labkit.grading.authoring.release import BEGIN_SOLUTION, END_SOLUTION, answer_ids, mark, strip_solutions

ROOT = Path(__file__).resolve().parents[3]
NOTEBOOKS = sorted((ROOT / "notebooks").glob("*.ipynb"))
STUDENT = ROOT / "labkit" / "student_notebooks"

STATED_ORDER = re.compile(
    r"\b(first|second|third|fourth|fifth|[1-5](st|nd|rd|th))[- ]order\b"
    r"|\border\s+(of\s+(convergence\s+)?)?(is\s+)?\d|Estimated order|\.order\b"
    r"|\brate_\w+\s*=\s*\d|\bfourfold\b|\bsixteenfold\b",
    re.IGNORECASE,
)


def _student(path):
    return nbformat.read(STUDENT / path.name, as_version=4)


def _solution_lines(source):
    lines, inside = [], False
    for line in source.split("\n"):
        if line.strip() == BEGIN_SOLUTION:
            inside = True
        elif line.strip() == END_SOLUTION:
            inside = False
        elif inside:
            lines.append(line.strip())
    return lines


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.stem)
def test_the_release_states_no_order_and_no_rate(path):
    for index, cell in enumerate(_student(path).cells):
        found = STATED_ORDER.search(cell.source)
        assert found is None, f"{path.name}, cell {index}: {found.group(0)!r} in\n{cell.source}"


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.stem)
def test_no_worked_answer_is_left_in_the_release(path):
    teacher = nbformat.read(path, as_version=4)
    given = {
        line.strip() for cell in teacher.cells for line in strip_solutions(cell.source).split("\n")
    }  # what the student is meant to see
    student_text = "\n".join(cell.source for cell in _student(path).cells)
    for cell in teacher.cells:
        for line in _solution_lines(cell.source):
            if len(line) >= 25 and line not in given:
                assert line not in student_text, f"{path.name}: a solution line is in the release: {line!r}"


def test_the_worked_answers_the_review_found_are_gone():
    text = {path.stem: "\n".join(c.source for c in _student(path).cells) for path in NOTEBOOKS}
    meshes = text["03_meshes"]
    assert "B - A$ on AB" not in meshes and "(\\pi/4, -\\pi/4)" not in meshes  # Exercise 7's rule, 8(b)'s values
    assert "t$-derivative as" not in meshes and "with s and t swapped" not in meshes  # Exercise 9's mirror rule
    assert "[0.5, -0.5]" not in meshes  # 9(d)'s corner data
    assert "natural_curvatures" not in text["04_splines"]  # 12(e) prints the student's own M
    assert "rows of the identity" not in text["04_splines"]  # 12(b)'s answer
    assert "The table is the identity" not in text["06_bilinear"]  # 16(a)'s explanation
    assert "`nintervals`" in text["01_limacon"].split("## Exercise 4")[0]  # Exercise 1 names what it defines


def test_every_answer_in_words_is_a_stub_marked_for_manual_grading_and_listed_in_the_registry():
    found = []
    for path in NOTEBOOKS:
        teacher = mark(nbformat.read(path, as_version=4), path.name)
        student = _student(path)
        ids = answer_ids(teacher)
        found += ids
        answers = [
            (t, s)
            for t, s in zip(teacher.cells, student.cells)
            if t.cell_type == "markdown" and BEGIN_SOLUTION in t.source
        ]
        assert len(answers) == len(ids)
        for (t, s), grade_id in zip(answers, ids):
            assert s.source == "YOUR ANSWER HERE"
            meta = t.metadata["nbgrader"]
            assert meta["grade_id"] == grade_id and meta["solution"] and meta["grade"] and meta["points"] == 0
            assert not meta["locked"]
    # the registry declares each answer with its exercise, in the notebooks' order
    assert found == list(ANSWERS)
    for grade_id, (number, what) in ANSWERS.items():
        assert grade_id.startswith(f"exercise{number}-answer-") and what in EXERCISES[number].answers


def test_a_release_per_student_refuses_two_folders_one_file_system_could_not_tell_apart(tmp_path):
    from labkit.exercises import variants
    from labkit.grading.authoring.release import folder_name, release

    found = variants.write(tmp_path / "v.toml", bytes(range(32)), {})
    notebooks = Path(__file__).resolve().parents[3] / "notebooks"
    with pytest.raises(ValueError, match="share a release folder"):
        release(notebooks, tmp_path / "out", {"Ada": "1", "ada": "2"}, found)
    with pytest.raises(ValueError, match="both --roster and --variants"):
        release(notebooks, tmp_path / "out", {"ada": "1"}, None)
    assert folder_name("ada_lovelace-2") == "ada_lovelace-2"
    for odd in ("../x", ".hidden", "a/b", "x" * 61, "Jane Doe", "ü"):  # never a path, nor hidden
        name = folder_name(odd)
        assert re.fullmatch(r"[A-Za-z0-9_-][A-Za-z0-9._-]*", name) and name != odd


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.name)
def test_the_hidden_test_placeholders_are_read_only_and_say_they_are_the_graders(path):
    """A student finds each hidden-test cell locked (read-only, not deletable, as nbgrader's release leaves it)
    and saying it is the grader's; every other cell stays as editable as it was."""
    from labkit.grading.authoring.release import release_notebook

    teacher = nbformat.read(path, as_version=4)
    student = release_notebook(teacher, path.name)
    hidden = ["### BEGIN HIDDEN TESTS" in c.source for c in teacher.cells]
    assert any(hidden)
    for was_hidden, cell in zip(hidden, student.cells):
        locked = cell.metadata.get("editable") is False and cell.metadata.get("deletable") is False
        assert locked == was_hidden, cell.source
        if was_hidden:
            assert "grader" in cell.source and "nothing to write" in cell.source.lower(), cell.source
    assert [c.source for c in student.cells] == [c.source for c in _student(path).cells]  # the packaged copy too
