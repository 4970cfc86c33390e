"""What only a person can mark, read into a run: ``labkit mark OUT --import marks.csv``.

A mark is one row of ``marks.csv``, ``submission,item,points,comment``; its item is an
:class:`~labkit.grading.store.model.ItemKey`:

* ``exercise12-answer-1`` (an answer's nbgrader grade id, as in grades.csv's "to read" columns) with
  points between 0 and what the rubric's ``[answers]`` table gives it;
* ``exercise2/eval_pherm`` (a part held for a person, :mod:`labkit.grading.submission.known`) with ``release``
  (its points are paid) or ``keep`` (they are not);
* ``exercise12`` with ``excused`` (out of the student's total and full credit) or ``counted`` (back in).

:func:`import_marks` checks every row against the run before it changes anything, and importing twice is
importing once.
"""

from __future__ import annotations

import csv
import io
from datetime import UTC, datetime
from pathlib import Path

from ...errors import InputError
from . import record as records
from .feedback import blank
from .grade import SubmissionGrade
from .model import ItemKey, Mark
from .names import name_cell, name_from_cell
from .report import csv_cell, csv_text, enter, read_results, write_csv
from .rubric import Rubric
from .text import one_line, points_text, printable

HEADER = ["submission", "item", "points", "comment"]
MAX_MARKS_BYTES = 16 * 1024 * 1024  # a marks.csv larger than this is not read
MAX_COMMENT = 2000  # characters of a comment kept
WORDS = {"held": ("release", "keep"), "exercise": ("excused", "counted")}  # the points of an item not paid in points


def items(grade: SubmissionGrade) -> dict[ItemKey, float | None]:
    """What can be marked for `grade`: each item, with the points an answer in words is worth (None for a
    held part or an exercise)."""
    rubric = grade.rubric
    found: dict[ItemKey, float | None] = {
        ItemKey.of_answer(grade_id): rubric.answers.get(grade_id, 0.0)
        for grade_id, (number, _) in rubric.registry.answers.items()
        if number in rubric.points
    }
    found.update({ItemKey.held(number, part): None for number, part, _, _ in grade.held()})
    found.update({ItemKey.exercise(number): None for number in rubric.graded})
    return found


def read_marks(text: str, grades: list[SubmissionGrade]) -> list[tuple[str, ItemKey, Mark]]:
    """The rows of marks.csv `text` as (submission, item, its mark with no time yet), each checked against
    `grades` (by name); ValueError listing every bad row (line number and why) when any is bad."""
    by_name = {grade.name: grade for grade in grades}
    reader = csv.reader(io.StringIO(text))
    header = next(reader, None)
    if header is None or [cell.strip().lower() for cell in header] != HEADER:
        shown = "nothing" if header is None else one_line(",".join(header), 120)
        raise InputError(f"marks.csv must start with the header {','.join(HEADER)}; it starts with {shown}.")
    rows, problems = [], []
    for line, row in enumerate(reader, start=2):
        if any(cell.strip() for cell in row):
            found = _row(row, by_name)
            if isinstance(found, str):
                problems.append(f"line {line}: {found}")
            else:
                rows.append(found)
    if problems:
        shown = problems[:20] + ([f"... and {len(problems) - 20} more"] if len(problems) > 20 else [])
        raise InputError("marks.csv was not imported, nothing changed:\n  " + "\n  ".join(shown))
    return rows


def _row(row: list[str], by_name: dict[str, SubmissionGrade]) -> tuple[str, ItemKey, Mark] | str:
    """One row of marks.csv as a mark, or why it is refused."""
    if len(row) not in (3, 4):
        return f"{len(row)} cells, not 4 ({','.join(HEADER)})"
    cell, item, points, comment = [*row, ""][:4]
    item, points = item.strip(), points.strip()
    name = name_from_cell(cell, by_name) or cell.strip()  # the whole name, as the page wrote it
    grade = by_name.get(name)
    if grade is None:
        return f"no submission {one_line(name, 80)!r} in this run"
    if not grade.graded:
        return f"{one_line(name, 80)} could not be graded, so it cannot be marked"
    known = {str(key): (key, worth) for key, worth in items(grade).items()}
    if item not in known:
        return (
            f"{one_line(item, 80)!r} is nothing to mark for {one_line(name, 80)} (an answer's "
            "grade id such as exercise12-answer-1, exerciseN/part of a held part, or exerciseN to excuse)"
        )
    key, worth = known[item]
    value, why = _points(key.kind, worth or 0.0, points)
    if not why and key.kind == "answer" and value and blank(grade.answers.get(item)):
        why = "the student wrote no answer (blank, or YOUR ANSWER HERE): it is marked 0, no answer"
    if why or value is None:
        return f"{item} of {one_line(name, 80)}: {why}"
    return name, key, Mark(value, printable(comment).strip()[:MAX_COMMENT])


def _points(kind: str, worth: float, text: str) -> tuple[float | str | None, str]:
    """(the points of a row, why they are refused or "")."""
    if kind in WORDS:
        word, words = text.lower(), WORDS[kind]
        return (word, "") if word in words else (None, f"points are {' or '.join(words)}, not {one_line(text, 20)!r}")
    try:
        value = float(text.replace(",", "."))
    except ValueError:
        return None, f"points {one_line(text, 20)!r} are not a number"
    if not 0.0 <= value <= worth:  # NaN fails this too
        if not worth:
            return None, "the rubric gives this answer no points: add it to the rubric's [answers] table"
        return None, f"points {one_line(text, 20)} are outside 0 to {points_text(worth)}"
    return round(value, 2), ""


def import_marks(out, path, rubric: Rubric | None = None, now: datetime | None = None) -> int:
    """Put the marks of marks.csv `path` into the run in folder `out`; the number of marks that changed.

    Every row is checked first: an unknown submission or item, points outside the item's range or a `rubric`
    other than the run's (in what it grades) is an InputError, and nothing is written. Then each marked
    submission's result (its marks, each with the time it was first imported) and feedback, the record and
    grades.csv are written again. A row equal to the mark held changes nothing; a later row replaces an earlier."""
    out, path = Path(out), Path(path)
    try:
        if path.stat().st_size > MAX_MARKS_BYTES:
            raise InputError(f"{path} is larger than {MAX_MARKS_BYTES} bytes; it is not read.")
        text = path.read_text(encoding="utf-8-sig")
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"cannot read the marks {path}: {exc}") from None
    record = records.read(out)
    recorded = record.rubric_object(out)
    if rubric is not None and recorded.digest != rubric.digest:
        raise InputError(
            f"{out} was graded under the rubric {recorded.title!r} ({recorded.digest}), not {rubric.title!r} "
            f"({rubric.digest}): marks are imported under the run's own rubric; leave out --rubric."
        )
    grades = read_results([out], recorded)
    if grades.refused:
        raise InputError(
            f"{out} has result files its record does not vouch for ({one_line(grades.refused[0][0], 200)}); "
            "grade the class again before marking."
        )
    when = (now or datetime.now(UTC)).isoformat(timespec="seconds")
    by_name = {grade.name: grade for grade in grades}
    changed = set()
    for name, item, mark in read_marks(text, grades):  # a later row replaces an earlier one
        held = by_name[name].marks.get(item)
        if held is None or (held.points, held.comment) != (mark.points, mark.comment):
            by_name[name].marks[item] = Mark(mark.points, mark.comment, when)
            changed.add((name, item))
    for name in sorted({name for name, _ in changed}):
        enter(out, record, by_name[name], record.submissions.get(name, {}).get("content"), save=False)
    if changed:
        records.write(out, record)
        write_csv(out / "grades.csv", list(grades))
    return len(changed)


def marks_csv(grades: list[SubmissionGrade]) -> str:
    """marks.csv of every mark `grades` hold (the file :func:`import_marks` reads)."""
    rows = [HEADER]
    for grade in grades:
        for item, mark in sorted(grade.marks.items(), key=lambda pair: str(pair[0])):
            points = mark.points if isinstance(mark.points, str) else points_text(mark.points)
            rows.append([name_cell(grade.name), str(item), points, csv_cell(mark.comment)])
    return csv_text(rows)
