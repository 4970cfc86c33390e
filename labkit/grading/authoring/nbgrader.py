"""nbgrader's cell metadata (schema version 3, ``nbgrader/nbgraderformat/v3.json``) for the instructor notebooks.

:func:`mark` derives it from the cells' markers (``labkit execute`` applies it): a code cell with a solution region
is a *solution* cell; a markdown one a *manually graded answer* worth 0 points (the instructor reads it), grade id
``exerciseN-answer-K``; a hidden-test cell an *autograded test* worth the weights of the parts its asserts check,
scaled to the rubric's points; every other cell is *locked*.
"""

import re

from ...errors import InputError
from ...exercises.model import sections
from ..store import rubric as rubrics
from .release import BEGIN_HIDDEN, BEGIN_SOLUTION, END_HIDDEN

SCHEMA_VERSION = 3
EXERCISE_OF_TESTS = re.compile(r"^# tests for exercise (\d+)\s*$", re.MULTILINE)

# a self-check call, labkit.check.<name>(...) or a course's check_<name>(...); a quoted first argument is an experiment
CHECK_CALL = re.compile(r"(?:\blabkit\.check\.|\bcheck_)(\w+)\(\s*(?:\"(\w+)\")?")


def test_points(source, where="a test cell", rubric=None):
    """(exercise, points) of a hidden-test cell: the weights of the parts its ``labkit.check.f(...)`` (or
    ``check_f(...)``) calls check (of the experiment the first argument names), scaled to `rubric`'s points."""
    rubric = rubric or rubrics.default()
    registry, found = rubric.registry, EXERCISE_OF_TESTS.search(source)
    if not found or int(found.group(1)) not in registry.exercises:
        raise InputError(f"{where} has hidden tests but no '# tests for exercise N' line naming a graded exercise.")
    number = int(found.group(1))
    exercise = registry.exercises[number]
    checked = {
        part.name
        for function, key in CHECK_CALL.findall(source.split(BEGIN_HIDDEN, 1)[1].split(END_HIDDEN, 1)[0])
        for part in registry.parts_checked(number, function, key or None)
    }
    weights = sum(part.weight for part in exercise.parts if part.name in checked)
    if not weights:
        parts = ", ".join(p.name for p in exercise.parts)
        raise InputError(f"{where} tests exercise {number} but checks none of its parts ({parts}).")
    points = weights * (rubric.points.get(number, exercise.points) / exercise.points if exercise.points else 0)
    return number, int(points) if points == int(points) else round(points, 2)


def answer_ids(nb):
    """The grade ids of a notebook's answers in words, in order: ``exerciseN-answer-K``."""
    ids, exercise, counters = [], None, {}
    for cell in (cell for cell in nb.cells if cell.cell_type == "markdown"):
        found = sections(cell.source)
        if found:
            exercise = found[-1]
        if BEGIN_SOLUTION in cell.source:
            counters[exercise] = counters.get(exercise, 0) + 1
            ids.append(f"exercise{exercise}-answer-{counters[exercise]}")
    return ids


def mark(nb, name="notebook", rubric=None):
    """Give every cell of an instructor notebook nbgrader's metadata (in place); returns `nb`."""
    counters, answers = {}, iter(answer_ids(nb))
    stem = re.sub(r"[^a-zA-Z0-9_-]+", "-", name.rsplit(".", 1)[0])

    def grade_id(kind):
        counters[kind] = counters.get(kind, 0) + 1
        return f"{kind}-{counters[kind]}"

    for index, cell in enumerate(nb.cells):
        meta = {"schema_version": SCHEMA_VERSION, "grade": False, "solution": False, "locked": True}
        if cell.cell_type == "markdown" and BEGIN_SOLUTION in cell.source:
            meta.update(solution=True, grade=True, locked=False, points=0, grade_id=next(answers))
        elif cell.cell_type == "code" and BEGIN_SOLUTION in cell.source:
            meta.update(solution=True, locked=False, grade_id=grade_id(f"{stem}-solution"))
        elif cell.cell_type == "code" and BEGIN_HIDDEN in cell.source:
            number, points = test_points(cell.source, f"{name}, cell {index}", rubric)
            meta.update(grade=True, points=points, grade_id=grade_id(f"exercise{number}-tests"))
        else:
            meta["grade_id"] = grade_id(f"{stem}-locked")
        cell.metadata["nbgrader"] = meta
    return nb
