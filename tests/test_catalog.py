"""Grades are right in both directions: every correct variation earns full marks, every typical slip costs
exactly its part and is named (the catalogs are in tests/catalog.py), all graded in one sandboxed run."""

import os
from pathlib import Path

import pytest
from catalog import CORRECT, MISTAKES, plant_class
from conftest import sandbox_or_skip

from labkit import grading
from labkit.check import EXERCISES
from labkit.grading.rubric import default

pytestmark = pytest.mark.skipif(os.name != "posix", reason="the sandbox is Linux's")
RUBRIC = default()
SEED = 20261201
# grades.csv of this very class and seed, graded before the exercises were declared once (issue 20): the
# refactoring changed where things are declared, not one grade
BEFORE = Path(__file__).with_name("data") / "catalog_grades_seed20261201.csv"
RUN = {}


@pytest.fixture(scope="module")
def graded(tmp_path_factory):
    sandbox_or_skip()
    tmp = tmp_path_factory.mktemp("catalog")
    folders = plant_class(tmp)
    results = grading.grade(list(folders.values()), tmp / "out", jobs=2, progress=False, seed=SEED)
    RUN["out"] = tmp / "out"
    return dict(zip(folders, results))


def _failed(grade):
    return {(n, c["name"]) for n, verdict in grade.results.items() for c in verdict["checks"] if not c["passed"]}


def _section(grade, number):
    return grade.feedback().split(f"Exercise {number}:")[1].split("\nExercise ")[0]


def test_the_catalogs_are_big_enough_and_cover_every_graded_exercise():
    assert len(MISTAKES) >= 30 and len(CORRECT) >= 10
    assert {entry.exercise for entry in MISTAKES} == set(EXERCISES)


@pytest.mark.parametrize("entry", CORRECT, ids=lambda e: e.name)
def test_every_correct_variation_earns_full_marks(graded, entry):
    grade = graded[entry.name]
    for number in entry.full:
        assert grade.points[number] == RUBRIC.points[number], grade.feedback()


def test_a_complete_matlab_style_solution_earns_everything(graded):
    grade = graded["matlab_style"]
    assert grade.total == RUBRIC.maximum, grade.feedback()


@pytest.mark.parametrize("entry", MISTAKES, ids=lambda e: e.name)
def test_every_slip_costs_exactly_its_part_and_is_named(graded, entry):
    grade = graded[entry.name]
    expected = {(entry.exercise, entry.part)} | set(entry.also)
    assert _failed(grade) == expected, grade.feedback()
    section = _section(grade, entry.exercise)
    assert entry.hint in section, section
    # only those parts' points are lost: every other exercise of the notebook is complete
    for number in grade.results:
        if number not in {n for n, _ in expected}:
            assert grade.points[number] == RUBRIC.points[number], grade.feedback()


def test_the_same_seed_gives_the_same_grades_csv_as_before_the_exercises_were_declared_once(graded):
    assert (RUN["out"] / "seed.txt").read_text().strip() == str(SEED)
    assert (RUN["out"] / "grades.csv").read_text(encoding="utf-8") == BEFORE.read_text(encoding="utf-8")
