"""Grades into the LMS: the course's Canvas gradebook filled in, or a file for Moodle's grade import.

``labkit export OUT`` reads a grading run's results (``OUT/results/*.json``,
:func:`labkit.grading.store.report.read_results`) and writes, for each student it
can match, the **total under the rubric** (required exercises, the branch that
counted and the extra credit: the ``total`` column of ``grades.csv``). A
submission that could not be graded gets no number, never a zero.

The roster
----------
Submissions are named after their folders or notebooks; the LMS knows
students by its own identifiers. The instructor's roster joins the two: a
CSV file (UTF-8, a byte-order mark allowed, separated by commas, semicolons
or tabs) whose header row has the columns ``submission`` (the name in
``grades.csv``) and ``id`` (the student's identifier in the LMS); other
columns, a name for instance, are ignored. What ``id`` holds is said by
``--key``: for Canvas the gradebook column it is compared with (``ID``,
Canvas's own user number, by default; or ``SIS User ID`` or ``SIS Login
ID``), for Moodle the user field (``idnumber`` by default, or ``email``).
A submission and an identifier may each appear once.

For Moodle the ids are checked against the key, because Moodle matches them
only against the field it is told and a wrong field stops the whole import:
with ``--key email`` every id must look like an email address (something,
``@``, a domain with a dot); with ``--key idnumber`` none may. A roster of
email addresses under the default ``idnumber`` is refused with the advice to
give ``--key email``; a roster that mixes email addresses with other ids is
refused under either key (under ``idnumber`` the email rows would match no
student, under ``email`` the others), naming a few rows of each kind to
correct. (A site whose ID numbers are the users' email addresses exports
with ``--key email``.)

Canvas's gradebook CSV, as this module relies on it
---------------------------------------------------
Sources: Instructure's Canvas Instructor Guide, "How do I import grades in the
Gradebook?" (community.canvaslms.com, Instructor-Guide, ta-p/807), as cited
and tried in PrairieLearn's issue 4547 and Materia's issue 1071 (which list
the columns an import needs); university help pages that summarise the
export and import (VCU's "Gradebook Action Menu": totals are read-only and
ignored on import; Ohio State's "Import a CSV file into Carmen grades": the
student, SIS Login ID, Section and assignment columns); and Canvas's own
exporter and importer (``lib/gradebook_exporter.rb`` and
``lib/gradebook_importer.rb`` in Instructure's canvas-lms repository), read
for the exact strings and rules. In my words:

* The first row names the columns. It begins with the student columns:
  ``Student`` (the name) and ``ID`` (Canvas's user number), then, when the
  export includes them, ``SIS User ID``, ``SIS Login ID`` (and possibly
  ``Integration ID`` or ``Root Account``), and ``Section``, which closes
  them. The importer refuses a header whose first two cells are not
  ``Student`` and ``ID`` or in which ``Section`` does not close the student
  columns.
* Then one column per assignment, headed ``Title (number)``, the number
  being Canvas's assignment id; then read-only totals (``Current Score``,
  ``Final Points``, ``Unposted Final Score``, a group's ``... Current
  Score``, ``Current Grade`` and so on), which the importer ignores.
* Before the students come at most two rows that are not students: a row
  whose cells are empty or ``Muted`` (``Manual Posting`` on newer Canvas)
  under assignments whose grades are hidden, and the row whose first cell
  reads ``Points Possible`` (padded with spaces), which gives each
  assignment's points and says ``(read only)`` under the totals.
* Each further row is a student. On import Canvas finds the student by
  ``ID``, else by ``SIS User ID`` or ``SIS Login ID``, else by name; it finds
  an assignment by the number in its header, else by its title, and makes a
  **new assignment** for a header it does not know, worth the points of the
  ``Points Possible`` row. It compares each cell with the grade it holds,
  so a cell left as exported changes nothing.
* The file is UTF-8, often with a byte-order mark; where decimals are
  written with a comma, the cells are separated by semicolons (the importer
  recognises both and reads ``7,5`` as 7.5).

So the file written here is the export itself, every row and column as it
was, with one assignment column filled in: the column named ``--column``
(its title with or without the ``(number)``). Because Canvas makes a new
assignment of any header it does not know, a ``--column`` that matches no
assignment column is refused, and the message lists the gradebook's
assignment columns (at most :data:`MAX_LISTED`, each shown on one printable
line): a typo never creates an assignment. A new column is added only on
purpose, with ``--new-column`` (``new_column=True``): at the end, its
``Points Possible`` cell the rubric's full credit. ``--new-column`` with the
title of a column the gradebook already has is refused too, rather than
filling that column: Canvas would match the title to the existing
assignment, so the file would not do what was asked; leave out
``--new-column`` to fill it. The separator, byte-order mark and line endings
are the export's.

Moodle's grade import, as this module relies on it
--------------------------------------------------
Sources: MoodleDocs, "Grade import" (docs.moodle.org, the pages of Moodle
2.x to 4.x), and Moodle's importer (``grade/import/csv/classes/load_data.php``
in Moodle's repository). In my words: a CSV file with a header row; on
import the instructor picks the column that identifies users ("Map from")
and the user field it holds ("Map to": ID number or email address; older
pages warn that emails are compared case-sensitively), then maps
every other column to an existing grade item, a new grade item, the feedback
of an item, or nothing. A row whose user Moodle cannot find stops the whole
import; an empty cell or ``-`` means "no grade" and would erase a grade
entered by hand; grades above 100 need the site settings ``unlimitedgrades``
and ``gradepointmax``; importing an item's feedback replaces its grades too,
so feedback always comes with the grade.

The file written here has the columns ``ID number`` (or ``Email address``),
the grade item named ``--column``, and with ``--feedback`` a ``Feedback``
column (the points in words). The feedback begins with the grade written
beside it, so that the two never disagree: with a rubric's ``[late]`` table
that is the total after the late penalty, followed by the points before it
and the penalty (points, started days or hours, percent), e.g. ``94.4
points: 118 (100 of 100 for full credit, and 18 of extra credit) less 23.6
for late work (2 started days, 20% off) (labkit grade)``. Only students with a grade are in it: the
others keep what Moodle has.

What is listed
--------------
Nothing is dropped silently: a submission that could not be graded, a
submission with no roster entry, a roster entry with no submission, and for
Canvas a roster entry whose identifier no row of the gradebook has and a
gradebook row with no roster entry are all listed (:meth:`Export.problems`)
and written to a summary CSV next to the output, one row per submission,
roster entry and unmatched gradebook row, with the total of every graded
submission, so that a grade can be entered by hand. Their cells are left as
the LMS has them. Names from submissions reach the summary through
:func:`~labkit.grading.store.report.csv_cell` and a terminal through
:func:`~labkit.grading.store.report.one_line`.

Bad input (a roster without its columns or with a name or identifier twice,
a gradebook that is not Canvas's CSV or not UTF-8, an assignment column that
is read-only, ambiguous, missing without ``--new-column`` or present with it)
raises a ``ValueError`` that says what to fix, and
then nothing is written. The output never replaces an input file, nor an
existing file unless ``force`` is given; it is written to a temporary file
and renamed into place.
"""

from __future__ import annotations

import csv
import io
import os
import re
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

from ...errors import InputError
from ..store.report import FORMULA_START, SubmissionGrade, csv_cell, one_line
from ..store.text import points_text

DEFAULT_COLUMN = "labkit"
CANVAS_KEYS = ("ID", "SIS User ID", "SIS Login ID")
MOODLE_KEYS = {"idnumber": "ID number", "email": "Email address"}
# the columns Canvas puts before the assignments, Section last
CANVAS_STUDENT_COLUMNS = ("Student", "ID", "SIS User ID", "SIS Login ID", "Integration ID", "Root Account", "Section")
# headers the Canvas importer takes for totals, and ignores (a group's, and the "Unposted" ones, contain these)
CANVAS_TOTALS = re.compile(
    "Current Score|Current Points|Current Grade|Final Score|Final Points|Final Grade|"
    "Override Score|Override Grade|Override Status"
)
SUMMARY_HEADER = ["submission", "id", "points", "status"]
EMAIL = re.compile(r"[^@\s]+@[^@\s]+\.[^@\s]+")  # what looks like an email address, for --key
XLSX_MAGIC = b"PK\x03\x04"
MAX_LISTED = 20  # assignment columns named in a message


@dataclass
class Export:
    """What an export wrote, and what it could not match.

    Attributes
    ----------
    path, summary_path : Path
        The file for the LMS, and the summary CSV beside it.
    lms : str
        ``"Canvas"`` or ``"Moodle"``.
    column : str
        The header of the column that holds the points.
    exported : dict
        Submission name -> (identifier, points written).
    not_graded : dict
        Submission name -> why it could not be graded (it got no number).
    not_in_roster : list
        Submissions with no roster entry.
    no_submission : list
        (submission, identifier) of roster entries with no result.
    not_in_lms : list
        (submission, identifier) of roster entries whose identifier no gradebook row has (Canvas).
    lms_only : list
        (name, identifier) of gradebook rows with no roster entry (Canvas).
    notes : list
        Remarks that need no action (points possible that differ from full credit, totals above it).
    """

    path: Path
    summary_path: Path
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
    def listed(self) -> int:
        """How many students need the instructor's attention (each is in :meth:`problems`)."""
        names = set(self.not_graded) | set(self.not_in_roster)
        names |= {name for name, _ in self.no_submission + self.not_in_lms}
        return len(names) + len(self.lms_only)

    def problems(self) -> list[str]:
        """One printable line per student who got no points from this export, and why.

        Returns
        -------
        list of str
            Lines for a terminal: names pass through :func:`~labkit.grading.store.report.one_line`.

        Examples
        --------
        >>> e = Export(Path("g.csv"), Path("g-summary.csv"), "Moodle", "labkit", not_in_roster=["ada\\x1b[2J"])
        >>> e.problems()
        ['no roster entry, nothing exported: ada\\ufffd[2J']
        """
        lines = [
            f"not graded, no points exported: {one_line(name, 80)} ({one_line(reason, 200)})"
            for name, reason in self.not_graded.items()
        ]
        lines += [f"no roster entry, nothing exported: {one_line(name, 80)}" for name in self.not_in_roster]
        lines += [
            f"in the roster, no submission: {one_line(name, 80)} (id {one_line(key, 60)})"
            for name, key in self.no_submission
        ]
        lines += [
            f"in the roster, not in the {self.lms} gradebook: {one_line(name, 80)} (id {one_line(key, 60)})"
            for name, key in self.not_in_lms
        ]
        lines += [
            f"in the {self.lms} gradebook, not in the roster: {one_line(name, 80)} (id {one_line(key, 60) or 'none'})"
            for name, key in self.lms_only
        ]
        return lines

    def summary(self) -> str:
        """What was written, in a few lines for a terminal."""
        lines = [
            f"wrote {self.path}: the totals of {len(self.exported)} student(s) in the column "
            f"{one_line(self.column, 80)!r}, for {self.lms}'s grade import",
        ]
        if self.listed:
            lines.append(
                f"{self.listed} student(s) got nothing from this file (listed above, and in {self.summary_path}): "
                "enter their grades by hand or fix the roster and export again"
            )
        else:
            lines.append(f"every submission and roster entry matched; the summary is in {self.summary_path}")
        return "\n".join(lines + self.notes)


@dataclass
class CanvasGradebook:
    """A Canvas gradebook export, as read: its rows and how it was written.

    Attributes
    ----------
    header : list of str
        The first row.
    rows : list of list of str
        Every further row, each as long as the header (empty lines stay empty).
    delimiter, newline : str
        The export's separator and line ending.
    bom : bool
        Whether the file started with a UTF-8 byte-order mark.
    section : int
        The index of the ``Section`` column, the last student column.
    """

    header: list
    rows: list
    delimiter: str
    newline: str
    bom: bool
    section: int

    def kind(self, row: list) -> str:
        """``"points"`` for the Points Possible row, ``"muted"`` for a row that only marks hidden grades
        (or an empty line), else ``"student"``."""
        if row and "Points Possible" in row[0]:
            return "points"
        if all(re.fullmatch(r"\s*(Muted|Manual Posting.*)?\s*", cell, re.IGNORECASE) for cell in row):
            return "muted"
        return "student"


def default_file(results_dir: str | os.PathLike, lms: str) -> Path:
    """Where ``labkit export`` writes when not told: next to the results folder, named after it.

    Parameters
    ----------
    results_dir : path
        The grading run's ``--out`` folder.
    lms : str
        ``"canvas"`` or ``"moodle"``.

    Returns
    -------
    Path
        ``<folder>-<lms>.csv`` in the folder's parent.

    Examples
    --------
    >>> default_file("/course/grades", "canvas").as_posix()
    '/course/grades-canvas.csv'
    """
    folder = Path(results_dir).resolve()
    return folder.with_name(f"{folder.name}-{lms}.csv")


def summary_file(path: str | os.PathLike) -> Path:
    """The summary CSV that goes with an export file.

    Examples
    --------
    >>> summary_file("/course/grades-canvas.csv").as_posix()
    '/course/grades-canvas-summary.csv'
    """
    path = Path(path)
    return path.with_name(f"{path.stem}-summary.csv")


def _text(path, what, fix):
    """The UTF-8 text of `path` (a byte-order mark removed), whether it had one, and its line ending."""
    path = Path(path)
    try:
        data = path.read_bytes()
    except OSError as exc:
        raise InputError(f"cannot read {what} {path}: {exc.strerror or exc}.") from None
    if data.startswith(XLSX_MAGIC):
        raise InputError(f"{path} is an Excel workbook, not CSV: {fix}")
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise InputError(
            f"{path} is not UTF-8 text (byte {exc.start} is {data[exc.start : exc.start + 1]!r}): {fix}"
        ) from None
    if "\x00" in text:
        raise InputError(f"{path} is not a CSV text file (it holds NUL bytes): {fix}")
    return text, data.startswith(b"\xef\xbb\xbf"), "\r\n" if "\r\n" in text else "\n"


def _rows(text, path, delimiter, fix):
    try:
        return list(csv.reader(io.StringIO(text, newline=""), delimiter=delimiter, strict=True))
    except csv.Error as exc:
        raise InputError(f"{path} is not valid CSV ({exc}): {fix}") from None


def _first_row(text, delimiter):
    try:
        return next(csv.reader(io.StringIO(text, newline=""), delimiter=delimiter), [])
    except csv.Error:
        return []


ROSTER_FIX = "save the roster as CSV (UTF-8) with a header row 'submission,id' and one student per line."


def read_roster(path: str | os.PathLike) -> dict[str, str]:
    """The roster: submission name -> the student's identifier in the LMS, in the file's order.

    Parameters
    ----------
    path : path
        A CSV file whose header has the columns ``submission`` and ``id`` (any case, any order, other
        columns ignored); comma, semicolon or tab separated; UTF-8, with or without a byte-order mark.

    Returns
    -------
    dict
        Submission name -> identifier, both without surrounding spaces.

    Raises
    ------
    ValueError
        The file cannot be read, is not UTF-8 CSV, lacks a column, has a row with an empty
        submission or id, names a submission or an id twice, or has no student.

    Examples
    --------
    >>> import pathlib, tempfile
    >>> roster = pathlib.Path(tempfile.mkdtemp()) / "roster.csv"
    >>> _ = roster.write_text("name,submission,id\\nAda Lovelace,ada,1815\\n", encoding="utf-8")
    >>> read_roster(roster)
    {'ada': '1815'}
    """
    text, _, _ = _text(path, "the roster", ROSTER_FIX)
    for delimiter in (",", ";", "\t"):
        header = [cell.strip().lower() for cell in _first_row(text, delimiter)]
        if {"submission", "id"} <= set(header):
            break
    else:
        found = ", ".join(repr(one_line(c, 40)) for c in _first_row(text, ",")[:8]) or "nothing"
        raise InputError(
            f"the roster {path} needs a header row with the columns 'submission' (the names in grades.csv) "
            f"and 'id' (the students' identifiers in the LMS); its first row has {found}. For example:\n"
            "    submission,id\n    ada_lovelace,1815"
        )
    for name in ("submission", "id"):
        if header.count(name) > 1:
            raise InputError(f"the roster {path} has two '{name}' columns; keep one.")
    rows = _rows(text, path, delimiter, ROSTER_FIX)
    at_name, at_id = header.index("submission"), header.index("id")
    roster: dict = {}
    lines_of: dict = {}
    names_of: dict = {}
    for number, row in enumerate(rows[1:], start=2):
        if not any(cell.strip() for cell in row):
            continue
        name = row[at_name].strip() if at_name < len(row) else ""
        key = row[at_id].strip() if at_id < len(row) else ""
        if not name or not key:
            missing = "submission" if not name else "id"
            raise InputError(
                f"the roster {path}, row {number}: the {missing} is empty; give every student both, or delete the row."
            )
        if name in roster:
            raise InputError(
                f"the roster {path} names the submission {one_line(name, 80)!r} twice (rows {lines_of[name]} and "
                f"{number}); keep one row per submission."
            )
        if key in names_of:
            raise InputError(
                f"the roster {path} gives the id {one_line(key, 60)!r} to two submissions "
                f"({one_line(names_of[key], 60)!r} and {one_line(name, 60)!r}, rows {lines_of[names_of[key]]} and "
                f"{number}); each student has one id: correct one of the rows."
            )
        roster[name], lines_of[name], names_of[key] = key, number, name
    if not roster:
        raise InputError(f"the roster {path} has a header but no student: add one row per submission.")
    return roster


CANVAS_FIX = (
    "give the file that Canvas's Grades > Export > Export Entire Gradebook downloads, as it is "
    "(or saved from a spreadsheet as 'CSV UTF-8')."
)


def read_canvas(path: str | os.PathLike) -> CanvasGradebook:
    """A Canvas gradebook export, checked to be one.

    Parameters
    ----------
    path : path
        The CSV that Canvas's gradebook export downloads (comma or semicolon separated, UTF-8, with or
        without a byte-order mark).

    Returns
    -------
    CanvasGradebook

    Raises
    ------
    ValueError
        The file is not UTF-8 CSV, or its header does not begin with ``Student``, ``ID`` and has no
        ``Section`` closing the student columns, or a row has more cells than the header.
    """
    text, bom, newline = _text(path, "the Canvas gradebook", CANVAS_FIX)
    for delimiter in (",", ";"):
        first = [cell.strip() for cell in _first_row(text, delimiter)]
        if first[:2] == ["Student", "ID"]:
            break
    else:
        found = ", ".join(repr(one_line(c, 40)) for c in _first_row(text, ",")[:6]) or "nothing"
        raise InputError(
            f"{path} is not a Canvas gradebook export: its header must begin with the columns 'Student' and "
            f"'ID' (it begins with {found}); {CANVAS_FIX}"
        )
    rows = _rows(text, path, delimiter, CANVAS_FIX)
    header = rows[0]
    section = next((i for i, cell in enumerate(header) if cell.strip() == "Section"), None)
    if section is None or any(cell.strip() not in CANVAS_STUDENT_COLUMNS for cell in header[:section]):
        raise InputError(
            f"{path} has no 'Section' column after the student columns (Student, ID, SIS User ID, SIS Login ID), "
            f"which Canvas needs to import it; {CANVAS_FIX}"
        )
    width, body = len(header), []
    for number, row in enumerate(rows[1:], start=2):
        if not row:
            body.append(row)
            continue
        if len(row) > width and any(cell.strip() for cell in row[width:]):
            raise InputError(
                f"{path}, row {number} has {len(row)} cells but the header only {width}: a cell with an unquoted "
                f"separator? {CANVAS_FIX}"
            )
        body.append(row[:width] + [""] * (width - len(row)))
    return CanvasGradebook(header, body, delimiter, newline, bom, section)


def _check_column(column):
    if not isinstance(column, str) or not column.strip() or column != one_line(column, 200):
        raise InputError(
            f"the column name {one_line(column, 80)!r} must be one line of text, at most 200 characters; "
            "give the assignment's name with --column."
        )
    if column.startswith(FORMULA_START):
        raise InputError(
            f"the column name {column!r} starts like a spreadsheet formula ({column[0]!r}); give the assignment "
            "another name with --column."
        )


def _assignment_column(book, column, path):
    """The index of the assignment column named `column` (with or without its Canvas number), or None."""
    pattern = re.compile(re.escape(column.strip()) + r"(\s*\(\d+\))?")
    found = [
        i for i, cell in enumerate(book.header) if i > book.section and pattern.fullmatch(cell.strip()) is not None
    ]
    if len(found) > 1:
        names = ", ".join(repr(book.header[i]) for i in found)
        raise InputError(
            f"{path} has {len(found)} assignment columns named {column!r} ({names}); give the one to fill with its "
            "number, e.g. --column " + repr(book.header[found[0]].strip()) + "."
        )
    return found[0] if found else None


def assignment_columns(book: CanvasGradebook) -> list[str]:
    """The headers of a gradebook's assignment columns: after ``Section``, neither a total nor read-only.

    Examples
    --------
    >>> book = CanvasGradebook(
    ...     ["Student", "ID", "Section", "Quiz 1 (501)", "Current Score"],
    ...     [["    Points Possible", "", "", "10", "(read only)"]], ",", "\\n", False, 2)
    >>> assignment_columns(book)
    ['Quiz 1 (501)']
    """
    points_row = next((row for row in book.rows if row and book.kind(row) == "points"), None)
    return [
        cell.strip()
        for i, cell in enumerate(book.header)
        if i > book.section
        and cell.strip()
        and CANVAS_TOTALS.search(cell) is None
        and not (points_row and "read only" in points_row[i].lower())
    ]


def _assignments_text(book):
    """The gradebook's assignment columns in words, for a message: bounded, each name on one printable line."""
    names = assignment_columns(book)
    if not names:
        return "it has no assignment column yet"
    shown = ", ".join(repr(one_line(name, 80)) for name in names[:MAX_LISTED])
    more = f", and {len(names) - MAX_LISTED} more" if len(names) > MAX_LISTED else ""
    return f"its assignment columns are {shown}{more}"


def _write(rows, path, *, delimiter=",", newline="\r\n", bom=False):
    """Write `rows` as CSV: to a temporary file beside `path`, renamed into place when complete (checked by
    :func:`_check_outputs` first)."""
    path = Path(path)
    handle = tempfile.NamedTemporaryFile(  # noqa: SIM115 - closed below, then renamed into place
        "w", encoding="utf-8", newline="", dir=path.parent, prefix=f".{path.name}.", suffix=".tmp", delete=False
    )
    try:
        with handle:
            if bom:
                handle.write("\ufeff")
            csv.writer(handle, delimiter=delimiter, lineterminator=newline).writerows(rows)
        os.replace(handle.name, path)
    except BaseException:
        Path(handle.name).unlink(missing_ok=True)
        raise


def _check_outputs(paths, inputs, force):
    for path in paths:
        path = Path(path)
        for source in inputs:
            if path.resolve() == Path(source).resolve():
                raise InputError(
                    f"{path} is an input of this export; it is never overwritten: give --out another file name."
                )
        if not path.parent.is_dir():
            raise InputError(f"the folder {path.parent} does not exist: create it, or give --out another path.")
        if path.exists() and not force:
            raise InputError(
                f"{path} already exists (an earlier export?); give --out another file name, or --force to replace it."
            )


def _by_name(grades):
    by_name = {}
    for grade in grades:
        if not isinstance(grade, SubmissionGrade):
            raise InputError(f"expected the grades of a grading run (read_results), got {type(grade).__name__}.")
        by_name[grade.name] = grade
    if not by_name:
        raise InputError("there are no grades to export: give the --out folder of a `labkit grade` run.")
    return by_name


def _summary_rows(export, roster, by_name):
    """The summary: a row per submission, per roster entry without a submission, per unmatched LMS row."""
    rows = [SUMMARY_HEADER]
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
    for name, key in export.no_submission:
        rows.append([csv_cell(name), csv_cell(key), "", "no submission (in the roster)"])
    for name, key in export.lms_only:
        status = f"in the {export.lms} gradebook ({one_line(name, 80)}), not in the roster"
        rows.append(["", csv_cell(key), "", csv_cell(status)])
    return rows


def _number(value, delimiter):
    """Points as Canvas writes them: a decimal comma where the cells are separated by semicolons."""
    text = points_text(value)
    return text.replace(".", ",") if delimiter == ";" else text


def to_canvas(
    grades: list[SubmissionGrade],
    gradebook: str | os.PathLike,
    roster: str | os.PathLike,
    out: str | os.PathLike,
    *,
    column: str = DEFAULT_COLUMN,
    key: str = "ID",
    new_column: bool = False,
    force: bool = False,
) -> Export:
    """Fill one assignment column of a Canvas gradebook export with the grades' totals.

    Parameters
    ----------
    grades : list of SubmissionGrade
        The results of a grading run (:func:`~labkit.grading.store.report.read_results`), scored by their rubric.
    gradebook : path
        The course's gradebook as Canvas exports it (see the module's description of the layout).
    roster : path
        The roster (:func:`read_roster`): submission name -> the student's value in the `key` column.
    out : path
        The file to write, for Canvas's Grades > Import; the summary CSV goes beside it (:func:`summary_file`).
    column : str
        The assignment: the existing column of that title (with or without Canvas's ``(number)``) is
        filled. When the gradebook has none, the export is refused (a mistyped name would otherwise
        become a new assignment in Canvas), unless `new_column` is given.
    key : {"ID", "SIS User ID", "SIS Login ID"}
        The gradebook column whose values the roster's ids are.
    new_column : bool
        Add `column` as a new column at the end, worth the rubric's full credit, which Canvas makes a new
        assignment on import. Refused when the gradebook already has a column of that title: Canvas would
        match the title to that assignment anyway, so leave out `new_column` to fill it.
    force : bool
        Replace `out` and its summary if they exist (an input file is never replaced).

    Returns
    -------
    Export
        What was written, and every student who got nothing from it.

    Raises
    ------
    ValueError
        Bad input (see :func:`read_roster` and :func:`read_canvas`), a `key` the export lacks, two gradebook
        rows with one id, an ambiguous or read-only assignment column, a `column` the gradebook lacks
        without `new_column` (the message lists its assignment columns) or has with it, no student matched
        at all, or an output that exists or is an input. Nothing is written then.
    """
    if key not in CANVAS_KEYS:
        raise InputError(f"--key for Canvas is one of {', '.join(CANVAS_KEYS)} (a gradebook column); got {key!r}.")
    _check_column(column)
    by_name = _by_name(grades)
    entries = read_roster(roster)
    book = read_canvas(gradebook)
    out = Path(out)
    export = Export(out, summary_file(out), "Canvas", column)
    _check_outputs([out, export.summary_path], [gradebook, roster], force)

    header = [cell.strip() for cell in book.header]
    if key not in header[: book.section]:
        raise InputError(
            f"{gradebook} has no {key!r} column (its student columns are {', '.join(header[: book.section + 1])}); "
            "export the gradebook with that column, or match the roster on another with --key."
        )
    at_key = header.index(key)
    if CANVAS_TOTALS.search(column) or column.strip() in CANVAS_STUDENT_COLUMNS:
        raise InputError(
            f"Canvas reads a column named {column!r} as a student column or a total, never as an assignment; "
            "give the assignment another name with --column."
        )
    target = _assignment_column(book, column, gradebook)
    points_row = next((row for row in book.rows if row and book.kind(row) == "points"), None)
    full_credit = by_name[next(iter(by_name))].rubric.full_credit
    if target is None and not new_column:
        raise InputError(
            f"{gradebook} has no assignment column named {column!r}; "
            f"{_assignments_text(book)}. Give one of them with --column (its title, with or "
            "without the number), or pass --new-column to add a column of that name on purpose (Canvas then "
            "creates a new assignment when the file is imported)."
        )
    if target is not None and new_column:
        raise InputError(
            f"{gradebook} already has the assignment column {one_line(book.header[target], 80)!r}, which "
            f"--column {column!r} names (Canvas would fill that assignment, not make a new one): leave out "
            "--new-column to fill it, or give the new assignment another name with --column."
        )
    if target is None:
        book.header.append(column)
        for row in book.rows:
            if row:
                row.append(_number(full_credit, book.delimiter) if book.kind(row) == "points" else "")
        target = len(book.header) - 1
    else:
        export.column = book.header[target]
        possible = points_row[target].strip() if points_row else ""
        if "read only" in possible.lower():
            raise InputError(
                f"the column {book.header[target]!r} of {gradebook} is read-only in Canvas (a total); "
                "give an assignment's column with --column."
            )
        try:
            differs = possible and float(possible.replace(",", ".")) != full_credit
        except ValueError:
            differs = False
        if differs:
            export.notes.append(
                f"note: {book.header[target]!r} is worth {possible} points in Canvas, the rubric's full credit is "
                f"{points_text(full_credit)}: the totals are written as they are."
            )

    students: dict = {}  # the key's value -> its row
    rows_of: dict = {}  # and its row number
    for number, row in enumerate(book.rows, start=2):
        if not row or book.kind(row) != "student":
            continue
        value = row[at_key].strip()
        if value in students:
            raise InputError(
                f"{gradebook} has two rows with {key} {one_line(value, 60)!r} (rows {rows_of[value]} and "
                f"{number}); export the gradebook again, or match on another column with --key."
            )
        if _test_student(row, value, entries, export):
            continue
        if not value:  # a student without this id: no roster entry can name it
            export.lms_only.append((row[0].strip(), ""))
            continue
        students[value], rows_of[value] = row, number

    matched, roster_ids = {}, set(entries.values())
    for name, grade in by_name.items():
        if name not in entries:
            export.not_in_roster.append(name)
        if not grade.graded:
            export.not_graded[name] = grade.failure
    for name, value in entries.items():
        if name not in by_name:
            export.no_submission.append((name, value))
        elif value not in students:
            export.not_in_lms.append((name, value))
        else:
            matched[value] = name
    if not matched:
        raise InputError(
            f"no submission of the results matched a row of {gradebook} through the roster {roster}: are the "
            f"roster's ids the gradebook's {key!r} values (--key), and its submissions the names in grades.csv?"
        )
    for value, row in students.items():
        name = matched.get(value)
        if name is None:
            if value not in roster_ids:  # a roster entry without a submission is listed as such
                export.lms_only.append((row[0].strip(), value))
            continue
        grade = by_name[name]
        if grade.graded:
            row[target] = _number(grade.total, book.delimiter)
            export.exported[name] = (value, grade.total)
    if any(total > full_credit for _, total in export.exported.values()):
        export.notes.append(
            f"note: some totals are above full credit ({points_text(full_credit)}) with extra credit; "
            "Canvas takes them as they are."
        )

    _write([book.header, *book.rows], out, delimiter=book.delimiter, newline=book.newline, bom=book.bom)
    _write(_summary_rows(export, entries, by_name), export.summary_path)
    return export


CANVAS_TEST_STUDENT = "Student, Test"  # the row of the test student Canvas adds to every course ("Test Student")


def _test_student(row, value, entries, export):
    """Whether a gradebook row is Canvas's test student, which no roster holds: left alone, with a note."""
    if row[0].strip() != CANVAS_TEST_STUDENT or value in set(entries.values()):
        return False
    export.notes.append(f"note: Canvas's test student ({CANVAS_TEST_STUDENT!r}) is in the gradebook; left as it is.")
    return True


def _feedback(grade):
    """The points in words, first the grade written beside them (after any late penalty), then how it was made.

    Examples
    --------
    >>> from labkit.grading.store.report import SubmissionGrade
    >>> _feedback(SubmissionGrade("ada", {2: {"fraction": 1.0, "passed": True, "checks": []}}))
    '10 points: 10 of 100 for full credit (labkit grade)'
    """
    score = grade.score
    extra = f", and {points_text(score.extra_total)} of extra credit" if score.extra_total else ""
    earned = f"{points_text(score.required + score.counted)} of {points_text(score.full_credit)} for full credit{extra}"
    lateness = grade.lateness
    if lateness is None or not lateness.penalty:
        return f"{points_text(grade.total)} points: {earned} (labkit grade)"
    rule = grade.rubric.late
    units = f"{lateness.units} started {rule.per}{'' if lateness.units == 1 else 's'}"
    capped = ", the cap" if lateness.units * rule.percent > rule.cap else ""
    return (
        f"{points_text(grade.total)} points: {points_text(lateness.raw_total)} ({earned}) less "
        f"{points_text(lateness.penalty)} for late work ({units}, {points_text(lateness.percent)}% off{capped}) "
        "(labkit grade)"
    )


MAX_FEEDBACK = 30_000  # characters of a Moodle feedback cell (the student's feedback text, bounded)


def _feedback_cell(grade):
    """Moodle's feedback cell: the points in words on the first line, then the student's whole feedback text
    (labkit.grading.store.feedback), printable, bounded, and never read as a formula."""
    from ..store.feedback import build, text

    whole = f"{_feedback(grade)}\n\n{text(build(grade))}"
    whole = whole if len(whole) <= MAX_FEEDBACK else whole[: MAX_FEEDBACK - 1] + "\u2026"
    return csv_cell(_feedback(grade)) if not grade.graded else _formula_safe(whole)


def _formula_safe(text):
    """A multi-line cell that a spreadsheet shows as text (as :func:`csv_cell`, keeping its lines)."""
    return csv_cell(text[:1]) + text[1:] if text else text


def _is_email(value):
    """Whether an identifier looks like an email address (something, an @, a domain with a dot)."""
    return EMAIL.fullmatch(value) is not None


def _examples(entries, names):
    """A few roster entries, for a message: each name and id on one printable line."""
    shown = ", ".join(f"{one_line(name, 40)!r} ({one_line(entries[name], 60)!r})" for name in names[:3])
    return shown + (f" and {len(names) - 3} more" if len(names) > 3 else "")


def _check_id_numbers(entries, roster):
    """Refuse a roster for ``--key idnumber`` that holds email addresses: all of them, or some among ID numbers."""
    emails = [name for name, value in entries.items() if _is_email(value)]
    if not emails:
        return
    if len(emails) == len(entries):
        raise InputError(
            f"the roster {roster} holds email addresses (e.g. {_examples(entries, emails)}), not ID numbers, and "
            "--key idnumber (the default) would write them into Moodle's ID number column: give --key email, "
            "or give the students' ID numbers in the roster."
        )
    others = [name for name in entries if name not in emails]
    raise InputError(
        f"the roster {roster} mixes email addresses ({len(emails)} of {len(entries)}: {_examples(entries, emails)}) "
        f"with other ids (e.g. {_examples(entries, others)}); with --key idnumber (the default) every id is an ID "
        "number: correct those rows, or give every student's email address with --key email."
    )


def to_moodle(
    grades: list[SubmissionGrade],
    roster: str | os.PathLike,
    out: str | os.PathLike,
    *,
    key: str = "idnumber",
    column: str = DEFAULT_COLUMN,
    feedback: bool = False,
    force: bool = False,
) -> Export:
    """Write a CSV for Moodle's "Import grades from CSV": one row per graded student on the roster.

    Parameters
    ----------
    grades : list of SubmissionGrade
        The results of a grading run (:func:`~labkit.grading.store.report.read_results`), scored by their rubric.
    roster : path
        The roster (:func:`read_roster`): submission name -> the student's ID number or email address.
    out : path
        The file to write; the summary CSV goes beside it (:func:`summary_file`).
    key : {"idnumber", "email"}
        The Moodle user field the roster's ids are: the first column is headed ``ID number`` or
        ``Email address``, to map on import to "ID number" or "Email address".
    column : str
        The header of the points column, to map on import to a grade item (or a new one).
    feedback : bool
        Add a ``Feedback`` column: the points in words (the grade first, then how it was made, a late
        penalty included), to map to the item's feedback.
    force : bool
        Replace `out` and its summary if they exist (the roster is never replaced).

    Returns
    -------
    Export
        What was written, and every student who got nothing from it.

    Raises
    ------
    ValueError
        Bad input (see :func:`read_roster`), an id that is not an email address with ``key="email"``, a roster
        with any email address with ``key="idnumber"`` (see the module's description of the roster), an id
        that starts like a formula, no student to write, or an output that exists or is an input.
    """
    if key not in MOODLE_KEYS:
        raise InputError(f"--key for Moodle is idnumber or email (the user field of the roster's ids); got {key!r}.")
    _check_column(column)
    by_name = _by_name(grades)
    entries = read_roster(roster)
    for name, value in entries.items():
        if key == "email" and not _is_email(value):
            raise InputError(
                f"the roster {roster} gives {one_line(name, 60)!r} the id {one_line(value, 60)!r}, which is not an "
                "email address: with --key email every id is one (or use --key idnumber)."
            )
        if value.startswith(FORMULA_START):
            raise InputError(
                f"the roster {roster} gives {one_line(name, 60)!r} the id {one_line(value, 60)!r}, which starts like "
                "a spreadsheet formula; correct the roster."
            )
    if key == "idnumber":
        _check_id_numbers(entries, roster)
    out = Path(out)
    export = Export(out, summary_file(out), "Moodle", column)
    _check_outputs([out, export.summary_path], [roster], force)
    header = [MOODLE_KEYS[key], column] + (["Feedback"] if feedback else [])
    rows = [header]
    for name, grade in by_name.items():
        if name not in entries:
            export.not_in_roster.append(name)
        if not grade.graded:
            export.not_graded[name] = grade.failure
    for name, value in entries.items():
        grade = by_name.get(name)
        if grade is None:
            export.no_submission.append((name, value))
        elif grade.graded:
            rows.append([value, points_text(grade.total)] + ([_feedback_cell(grade)] if feedback else []))
            export.exported[name] = (value, grade.total)
    if not export.exported:
        raise InputError(
            f"no graded submission of the results is on the roster {roster}: are its submissions the names in "
            "grades.csv?"
        )
    full_credit = by_name[next(iter(by_name))].rubric.full_credit
    top = max(total for _, total in export.exported.values())
    if top > full_credit:
        export.notes.append(
            f"note: totals reach {points_text(top)}, above full credit ({points_text(full_credit)}), with extra "
            f"credit: give the Moodle grade item a maximum of at least {points_text(top)} (above 100, Moodle needs "
            "the site settings 'unlimitedgrades' and 'gradepointmax')."
        )
    _write(rows, out)
    _write(_summary_rows(export, entries, by_name), export.summary_path)
    return export
