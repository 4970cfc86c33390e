"""nbgrader's cell metadata for the instructor notebooks (cell metadata schema version 3).

A course that runs nbgrader takes ``notebooks/`` as its ``source/<assignment>/``
folder. nbgrader reads what each cell is from ``cell.metadata["nbgrader"]``:

* a code cell with a ``### BEGIN SOLUTION`` region is a *solution* cell
  (``solution: true``): nbgrader replaces the region by its stub, as
  ``labkit release`` does;
* a markdown cell with a ``### BEGIN SOLUTION`` region is a *manually graded
  answer* (``solution: true``, ``grade: true``, 0 points: the lab's rubric
  has no points for words, the instructor reads them), with the grade id
  ``exerciseN-answer-K`` of the exercise whose section it is in;
* a cell with ``### BEGIN HIDDEN TESTS`` is an *autograded test* cell
  (``grade: true``, ``locked: true``) worth the points of the parts its
  asserts check: their weights (:mod:`labkit.exercises`), scaled to the
  points of the rubric in force, so nbgrader's points per exercise are labkit's;
* every other cell is *locked*: students cannot edit it (they can add cells).

:func:`mark` computes this from the cells' markers, so it never drifts from the
notebooks; ``labkit execute`` applies it before saving. The keys and their
meaning follow nbgrader's ``nbgrader/nbgraderformat/v3.json``.
"""

import re

from ...errors import InputError
from ...exercises.model import sections
from ..store import rubric as rubrics
from .release import BEGIN_HIDDEN, BEGIN_SOLUTION, END_HIDDEN

SCHEMA_VERSION = 3
EXERCISE_OF_TESTS = re.compile(r"^# tests for exercise (\d+)\s*$", re.MULTILINE)


def _hidden_region(source):
    return source.split(BEGIN_HIDDEN, 1)[1].split(END_HIDDEN, 1)[0]


# a self-check call: labkit.check.<name>(...) in the lab, or a course's own check_<name>(...); the first
# argument, when quoted, is an experiment's key
CHECK_CALL = re.compile(r"(?:\blabkit\.check\.|\bcheck_)(\w+)\(\s*(?:\"(\w+)\")?")


def test_points(source, where="a test cell", rubric=None):
    """(exercise, points) of a hidden-test cell: the points of the parts its asserts check.

    Each ``labkit.check.f(...)`` (or ``check_f(...)``) call checks the parts whose declared check is
    ``check_f`` (for ``driver``, ``table`` and ``rate``, of the experiment named by
    the first argument). The parts' weights are scaled to the exercise's
    points under `rubric` (the lab's when None)."""
    rubric = rubric or rubrics.default()
    registry = rubric.registry
    found = EXERCISE_OF_TESTS.search(source)
    if not found or int(found.group(1)) not in registry.exercises:
        raise InputError(f"{where} has hidden tests but no '# tests for exercise N' line naming a graded exercise.")
    number = int(found.group(1))
    exercise = registry.exercises[number]
    checked = {
        part.name
        for function, key in CHECK_CALL.findall(_hidden_region(source))
        for part in registry.parts_checked(number, function, key or None)
    }
    weights = sum(part.weight for part in exercise.parts if part.name in checked)
    if not weights:
        raise InputError(
            f"{where} tests exercise {number} but checks none of its parts "
            f"({', '.join(p.name for p in exercise.parts)})."
        )
    scale = rubric.points.get(number, exercise.points) / exercise.points if exercise.points else 0
    points = weights * scale
    return number, int(points) if points == int(points) else round(points, 2)


def answer_ids(nb):
    """The grade ids of a notebook's answers in words, in order: ``exerciseN-answer-K``."""
    ids, exercise, counters = [], None, {}
    for cell in nb.cells:
        if cell.cell_type != "markdown":
            continue
        found = sections(cell.source)
        if found:
            exercise = found[-1]
        if BEGIN_SOLUTION in cell.source:
            counters[exercise] = counters.get(exercise, 0) + 1
            ids.append(f"exercise{exercise}-answer-{counters[exercise]}")
    return ids


def mark(nb, name="notebook", rubric=None):
    """Give every cell of an instructor notebook nbgrader's metadata (in place); returns `nb`."""
    counters = {}
    answers = iter(answer_ids(nb))

    def grade_id(kind):
        counters[kind] = counters.get(kind, 0) + 1
        return f"{kind}-{counters[kind]}"

    for index, cell in enumerate(nb.cells):
        meta = {"schema_version": SCHEMA_VERSION, "grade": False, "solution": False, "locked": True}
        if cell.cell_type == "markdown" and BEGIN_SOLUTION in cell.source:
            meta.update(solution=True, grade=True, locked=False, points=0, grade_id=next(answers))
        elif cell.cell_type == "code" and BEGIN_SOLUTION in cell.source:
            meta.update(solution=True, locked=False, grade_id=grade_id(f"{_stem(name)}-solution"))
        elif cell.cell_type == "code" and BEGIN_HIDDEN in cell.source:
            number, points = test_points(cell.source, f"{name}, cell {index}", rubric)
            meta.update(grade=True, points=points, grade_id=grade_id(f"exercise{number}-tests"))
        else:
            meta["grade_id"] = grade_id(f"{_stem(name)}-locked")
        cell.metadata["nbgrader"] = meta
    return nb


def _stem(name):
    return re.sub(r"[^a-zA-Z0-9_-]+", "-", name.rsplit(".", 1)[0])
