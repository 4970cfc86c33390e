"""Grades into the LMS: what every LMS's export shares (each LMS module writes its own file).

An export writes the **total under the rubric** of each student the roster matches; an ungraded submission gets
no number, never a zero, and every student who got nothing is listed. Bad input writes nothing, and the output
never replaces an input, nor an existing file unless ``force``.
"""

from __future__ import annotations

import csv
import io
import os
from dataclasses import dataclass, field
from pathlib import Path

from ...errors import InputError
from ..store.record import replace_text
from ..store.report import FORMULA_START, SubmissionGrade, csv_cell, one_line
from ..store.text import points_text

DEFAULT_COLUMN = "labkit"


@dataclass
class Export:
    """What an export wrote (`exported` {submission: (id, points)}) and what it could not match: `not_graded`
    {submission: why}, `not_in_roster` [submission], `no_submission` and `not_in_lms` (roster entries without a
    result, or a gradebook row) [(submission, id)], `lms_only` (gradebook rows with no roster entry) [(name, id)]."""

    path: Path
    lms: str
    column: str
    exported: dict = field(default_factory=dict)
    not_graded: dict = field(default_factory=dict)
    not_in_roster: list = field(default_factory=list)
    no_submission: list = field(default_factory=list)
    not_in_lms: list = field(default_factory=list)
    lms_only: list = field(default_factory=list)
    notes: list = field(default_factory=list)

    @property
    def summary_path(self) -> Path:
        """The summary CSV beside the export file: ``grades-canvas.csv``'s is ``grades-canvas-summary.csv``."""
        return self.path.with_name(f"{self.path.stem}-summary.csv")

    @property
    def listed(self) -> int:
        """How many students need the instructor's attention (each is in :meth:`problems`)."""
        names = set(self.not_graded) | set(self.not_in_roster)
        names |= {name for name, _ in self.no_submission + self.not_in_lms}
        return len(names) + len(self.lms_only)

    def problems(self) -> list[str]:
        """One printable line per student who got no points from this export, and why."""
        gradebook = f"the {self.lms} gradebook"
        lines = [
            f"not graded, no points exported: {one_line(name, 80)} ({one_line(reason, 200)})"
            for name, reason in self.not_graded.items()
        ]
        lines += [f"no roster entry, nothing exported: {one_line(name, 80)}" for name in self.not_in_roster]
        for what, pairs in (("no submission", self.no_submission), (f"not in {gradebook}", self.not_in_lms)):
            lines += [f"in the roster, {what}: {one_line(n, 80)} (id {one_line(k, 60)})" for n, k in pairs]
        lines += [
            f"in {gradebook}, not in the roster: {one_line(name, 80)} (id {one_line(key, 60) or 'none'})"
            for name, key in self.lms_only
        ]
        return lines

    def summary(self) -> str:
        """What was written, in a few lines for a terminal."""
        column, where = one_line(self.column, 80), self.summary_path
        wrote = f"wrote {self.path}: the totals of {len(self.exported)} student(s) in the column {column!r}, for "
        lines = [f"{wrote}{self.lms}'s grade import"]
        if self.listed:
            nothing = f"{self.listed} student(s) got nothing from this file (listed above, and in {where})"
            lines.append(f"{nothing}: enter their grades by hand or fix the roster and export again")
        else:
            lines.append(f"every submission and roster entry matched; the summary is in {where}")
        return "\n".join(lines + self.notes)


def default_file(results_dir: str | os.PathLike, lms: str) -> Path:
    """Where ``labkit export`` writes when not told: ``<folder>-<lms>.csv`` beside the run's ``--out`` folder."""
    folder = Path(results_dir).resolve()
    return folder.with_name(f"{folder.name}-{lms}.csv")


def start(grades, out, lms, column):
    """({submission: grade}, the Export to fill) once `column` and `grades` are checked."""
    if not isinstance(column, str) or not column.strip() or column != one_line(column, 200):
        raise InputError(
            f"the column name {one_line(column, 80)!r} must be one line of 200 characters at most: fix --column."
        )
    if column.startswith(FORMULA_START):
        raise InputError(f"the column name {column!r} starts like a spreadsheet formula: give another --column.")
    by_name = {}
    for grade in grades:
        if not isinstance(grade, SubmissionGrade):
            raise InputError(f"expected the grades of a grading run (read_results), got {type(grade).__name__}.")
        by_name[grade.name] = grade
    if not by_name:
        raise InputError("there are no grades to export: give the --out folder of a `labkit grade` run.")
    return by_name, Export(Path(out), lms, column)


def check_outputs(export, inputs, force):
    """ValueError when the export's files would replace an input, or an existing file without `force`."""
    for path in (export.path, export.summary_path):
        if any(path.resolve() == Path(source).resolve() for source in inputs):
            raise InputError(f"{path} is an input of this export; it is never overwritten: give another --out.")
        if not path.parent.is_dir():
            raise InputError(f"the folder {path.parent} does not exist: create it, or give --out another path.")
        if path.exists() and not force:
            raise InputError(
                f"{path} already exists (an earlier export?); give another --out, or --force to replace it."
            )


def match(export, by_name, roster, rows=None):
    """{id: submission} of the roster entries with a submission (and a row of `rows`, if given); others in `export`."""
    for name, grade in by_name.items():
        if name not in roster:
            export.not_in_roster.append(name)
        if not grade.graded:
            export.not_graded[name] = grade.failure
    matched = {}
    for name, value in roster.items():
        if name not in by_name:
            export.no_submission.append((name, value))
        elif rows is not None and value not in rows:
            export.not_in_lms.append((name, value))
        else:
            matched[value] = name
    return matched


def write(rows, path, *, delimiter=",", newline="\r\n", bom=False):
    """Write `rows` as CSV into `path`, replaced whole; only its owner may read it (it holds ids and grades)."""
    buffer = io.StringIO()
    csv.writer(buffer, delimiter=delimiter, lineterminator=newline).writerows(rows)
    replace_text(Path(path), ("\ufeff" if bom else "") + buffer.getvalue(), 0o600)


def write_summary(export, roster, by_name):
    """The summary beside the export: a row per submission, roster entry without one, and unmatched gradebook row."""
    rows = [["submission", "id", "points", "status"]]
    missing_in_lms = {name for name, _ in export.not_in_lms}
    for name, grade in by_name.items():
        status = []
        if not grade.graded:
            status.append(f"not graded: {grade.failure}")
        if name not in roster:
            status.append("no roster entry")
        elif name in missing_in_lms:
            status.append(f"not in the {export.lms} gradebook")
        points = points_text(grade.total) if grade.graded else ""
        rows.append([csv_cell(name), csv_cell(roster.get(name, "")), points, csv_cell("; ".join(status) or "exported")])
    rows += [[csv_cell(name), csv_cell(key), "", "no submission (in the roster)"] for name, key in export.no_submission]
    for name, key in export.lms_only:
        status = f"in the {export.lms} gradebook ({one_line(name, 80)}), not in the roster"
        rows.append(["", csv_cell(key), "", csv_cell(status)])
    write(rows, export.summary_path)
