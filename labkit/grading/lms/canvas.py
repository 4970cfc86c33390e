"""Canvas: its "Download Submissions", its gradebook export filled in, its "Re-upload submissions".

The download names each file ``{name}[_LATE]_{user id}_{file id}_{display name}`` (canvas-lms's
``lib/content_zipper.rb``): ``{name}`` is the sortable name lower-cased, word characters only (``lovelaceada``),
or ``anon_{id}``. Both ends are the student's choice, so a name can read several ways (:func:`resolve_canvas`).
The gradebook (``lib/gradebook_importer.rb``): student columns closed by ``Section``, an assignment per column
``Title (number)``, read-only totals, maybe ``Muted`` and ``Points Possible`` rows; Canvas makes a **new
assignment** of a header it does not know, so :func:`to_canvas` fills an existing column unless ``--new-column``.
"""

from __future__ import annotations

import functools
import os
import re
from contextlib import suppress
from dataclasses import dataclass, replace
from pathlib import Path

from ...errors import InputError
from ..store.report import SubmissionGrade, one_line
from ..store.text import points_text
from . import Lms
from .exports import DEFAULT_COLUMN, Export, check_outputs, match, start, write, write_summary
from .intake import entries, safe_part
from .roster import csv_rows, first_row, read_roster, read_text

KEYS = ("ID", "SIS User ID", "SIS Login ID")
STUDENT_COLUMNS = ("Student", "ID", "SIS User ID", "SIS Login ID", "Integration ID", "Root Account", "Section")
# headers the Canvas importer takes for totals, and ignores
TOTALS = re.compile("(Current|Final) (Score|Points|Grade)|Override (Score|Grade|Status)")
TEST_STUDENT = "Student, Test"  # the row of the test student Canvas adds to every course ("Test Student")
MAX_LISTED = 20  # assignment columns named in a message
FIX = "give Canvas's Grades > Export > Export Entire Gradebook file as it is (or saved as 'CSV UTF-8')."
REUPLOAD = re.compile(r"^(?P<stem>.+)-(?P<number>[1-9][0-9]?)(?P<ext>\.[^.]+)?$", re.DOTALL)
_FIXED = re.compile(r"(?=(_LATE)?_(0|[1-9][0-9]*)_(0|[1-9][0-9]*)_(.))", re.DOTALL)  # ids have no leading 0
_ANON = re.compile(r"^(LATE_)?(anon(?:ymous)?)(_LATE)?_([A-Za-z0-9]+)_([0-9]+)_(.+)$", re.DOTALL)
_NOT_WORD = re.compile(r"\W")


@dataclass(frozen=True)
class Reading:
    """One reading of a Canvas file name: the name part, late or not, the user id, the file id, the display name."""

    login: str
    late: bool
    uid: str
    fid: str
    file: str

    @property
    def prefix(self):  # what every file of this user starts with
        return (self.login, self.late, self.uid)


@functools.lru_cache(maxsize=1 << 14)
def canvas_readings(name: str) -> tuple[Reading, ...]:
    """Every reading of `name` as Canvas names a submission's file, shortest name part first.

    >>> [(r.login, r.uid, r.file) for r in canvas_readings("ada_1001_9_lab.ipynb")]
    [('ada', '1001', 'lab.ipynb')]
    >>> [(r.login, r.uid) for r in canvas_readings("ada_1001_9_00_2002_77_x.ipynb")]
    [('ada', '1001'), ('ada_1001_9_00', '2002')]
    >>> [(r.login, r.uid, r.file) for r in canvas_readings("ada_LATE_1001_98765_02_convergence.ipynb")]
    [('ada', '1001', '02_convergence.ipynb')]
    >>> canvas_readings("Ada Lovelace.ipynb")
    ()
    """
    if anon := _ANON.match(name):
        return (Reading(f"{anon[2]}_{anon[4]}", bool(anon[1] or anon[3]), anon[4], anon[5], anon[6]),)
    stop = _NOT_WORD.search(name)
    end = len(name) if stop is None else stop.start()  # the name part holds word characters only
    found = []
    for match_ in _FIXED.finditer(name):
        login = name[: match_.start()]
        if match_.start() > end:
            break
        if login == login.lower():  # Canvas lower-cases the name
            found.append(Reading(login, bool(match_[1]), match_[2], match_[3], name[match_.end(3) + 1 :]))
    return tuple(found)


def resolve_canvas(names, roster_ids=()) -> tuple[dict, list[str]]:
    """{file name: the Reading its user's other files confirm, else the one whose user is among `roster_ids`,
    else None} and notes.

    >>> names = ["ada_1001_5_a.ipynb", "ada_1001_7_hw_1_2_c.ipynb"]
    >>> resolve_canvas(names)[0]["ada_1001_7_hw_1_2_c.ipynb"] is None  # user 1001, or user 1 named ada_1001_7_hw?
    True
    >>> chosen, notes = resolve_canvas(names, roster_ids=["1001"])
    >>> chosen["ada_1001_7_hw_1_2_c.ipynb"].uid, len(notes)
    ('1001', 1)
    """
    readings = {name: canvas_readings(name) for name in names}
    settled: dict = {}  # user id -> the prefixes files without a second reading show it with
    for found in readings.values():
        if len(found) == 1:
            settled.setdefault(found[0].uid, set()).add(found[0].prefix)
    notes: list[str] = []
    chosen = {name: _choose(name, found, settled, set(roster_ids), notes) for name, found in readings.items()}
    return chosen, notes


def _choose(name, found, settled, roster, notes):
    if len(found) < 2:
        return found[0] if found else None
    shown = one_line(name, 120)
    left = [r for r in found if r.uid not in settled or r.prefix in settled[r.uid]]
    if len(left) > 1 and roster:
        left = [r for r in left if r.uid in roster] or left
    if len(left) == 1:
        others = ", ".join(f"user {one_line(r.uid, 20)} ({one_line(r.login, 60)})" for r in found if r != left[0])
        notes.append(f"file {shown}: filed under user {one_line(left[0].uid, 20)} by its id; it could also be {others}")
        return left[0]
    readings = ", ".join(f"user {one_line(r.uid, 20)} ({one_line(r.login, 60)})" for r in left or found)
    notes.append(
        f"file {shown}: filed to no one: its name reads as {readings} (a --roster with one of them settles it); "
        "ask the student to rename the file, and grade it alone"
    )
    return None


class Canvas(Lms):
    name = "canvas"
    rank = 20
    download = "Canvas's download"
    counted = "file(s) named as Canvas names them"
    keys = KEYS
    steps = "upload it in Canvas: the assignment's SpeedGrader or Submissions page, 'Re-upload submissions'"

    def claims(self, name, kind):
        return kind == "file" and bool(canvas_readings(name))

    def owners(self, tops, builder):
        chosen, said = resolve_canvas([name for name, kind in tops if kind == "file"], builder.roster_ids)
        builder.notes += said  # the files filed to no one are never unpacked: their notes are said here
        owners = {name: None for name, _ in tops if canvas_readings(name)}
        return owners | {name: ("canvas", r.uid) for name, r in chosen.items() if r is not None}

    def shown(self, key):
        return f"Canvas user {one_line(key[1], 40)}"

    def students(self, root, builder, assignment):
        groups: dict = {}  # user id -> {"logins", "late", "files": {original: [(number, path, given, fid)]}, "prefix"}
        for name, (reading, path) in _files(root, builder).items():
            group = groups.setdefault(reading.uid, {"logins": set(), "late": False, "files": {}})
            group["logins"].add(reading.login)
            group["late"] |= reading.late
            original, number = reading.file, 0
            if again := REUPLOAD.match(original):
                original, number = again["stem"] + (again["ext"] or ""), int(again["number"])
            group["files"].setdefault(original, []).append((number, path, reading.file, reading.fid))
            group["prefix"] = name[: len(name) - len(reading.file) - 1]  # "{login}[_LATE]_{uid}_{fid}"
        logins = [min(group["logins"]) for group in groups.values()]
        students = []
        for (uid, group), login in zip(groups.items(), logins):
            if logins.count(login) > 1 or len(group["logins"]) > 1:  # namesakes: the user id parts them
                said = f"{one_line(login, 80)} names several Canvas students: each is named {one_line(login, 60)}_ID"
                builder.notes += [] if said in builder.notes else [said]
                login = f"{login}_{uid}"
            pieces = _pieces(login, group["files"], builder.notes)
            student = builder.from_files(login, pieces, "canvas", uid, group["late"], key=("canvas", uid))
            students.append(replace(student, lms_file=group["prefix"]))
        return students

    def feedback_names(self, name, entry):
        """The download's prefix of one of the student's files, then ``_feedback.html``."""
        prefix = str(entry.get("file") or "")
        if not re.fullmatch(r"[^/\\\x00]+_\d+_\d+|anon\w*_[A-Za-z0-9]+_\d+", prefix):
            raise InputError(f"no Canvas file of {one_line(name, 80)} is recorded")
        return [f"{prefix}_feedback.html"]

    def export(self, grades, roster, out, **options):
        """:func:`to_canvas`, the gradebook given as ``gradebook=``; refused without one."""
        if "gradebook" not in options:
            raise InputError(
                "a Canvas export fills in the course's gradebook: give it with `labkit export OUT --canvas "
                "GRADEBOOK.csv` (Canvas: Grades > Export) instead of --lms canvas."
            )
        return to_canvas(grades, options.pop("gradebook"), roster, out, **options)


def _files(root, builder):
    """{file name as Canvas gave it: (its Reading, path)} of the download's files whose owner is settled."""
    files = {}
    for entry in entries(root):
        name = builder.name(entry)
        if entry.is_file(follow_symlinks=False) and canvas_readings(name):
            files[name] = Path(entry.path)
        else:
            builder.notes.append(f"ignored {one_line(name)}: not named as Canvas names a submission's file")
    chosen, said = resolve_canvas(files, builder.roster_ids)
    builder.notes += [] if builder.zip_depth else said  # a class zip's owners() said them already
    return {name: (reading, files[name]) for name, reading in chosen.items() if reading is not None}


def _pieces(login, files, notes):
    """[(name to give, path)] of one student's files: of a file uploaded again, the newest only."""
    pieces = []
    for original, versions in sorted(files.items()):
        if not any(number == 0 for number, *_ in versions):
            # no file of that very name: `part-1` and `part-2` may be two notebooks, not two uploads of one
            pieces += [(Path(safe_part(given)), path) for _, path, given, _ in versions]
            continue
        versions.sort(key=lambda v: (int(v[3]), v[0]))  # file ids grow with each upload: the last is newest
        number, path, given, _ = versions[-1]
        if len(versions) > 1:
            dropped = ", ".join(one_line(v[2], 80) for v in versions[:-1])
            kept = f"kept {one_line(given, 80)} (the newest upload) as {one_line(original, 80)}"
            notes.append(f"{one_line(login, 80)}: {kept}; older: {dropped}")
        pieces.append((Path(safe_part(original)), path))
    return pieces


@dataclass
class CanvasGradebook:
    """A Canvas gradebook export as read: its header, its rows padded to it, its CSV dialect, where ``Section`` is."""

    header: list
    rows: list
    delimiter: str
    newline: str
    bom: bool
    section: int

    def kind(self, row: list) -> str:
        """``"points"``, ``"muted"`` (a row marking hidden grades, or an empty one) or ``"student"``."""
        if row and "Points Possible" in row[0]:
            return "points"
        if all(re.fullmatch(r"\s*(Muted|Manual Posting.*)?\s*", cell, re.IGNORECASE) for cell in row):
            return "muted"
        return "student"

    def points_row(self):
        """The Points Possible row, or None."""
        return next((row for row in self.rows if row and self.kind(row) == "points"), None)

    def number(self, value):
        """Points as Canvas writes them: a decimal comma where the cells are separated by semicolons."""
        text = points_text(value)
        return text.replace(".", ",") if self.delimiter == ";" else text


def read_canvas(path: str | os.PathLike) -> CanvasGradebook:
    """A Canvas gradebook export (UTF-8 CSV, comma or semicolon separated); ValueError when it is not one."""
    text, bom, newline = read_text(path, "the Canvas gradebook", FIX)
    for delimiter in (",", ";"):
        if [cell.strip() for cell in first_row(text, delimiter)][:2] == ["Student", "ID"]:
            break
    else:
        found = ", ".join(repr(one_line(c, 40)) for c in first_row(text, ",")[:6]) or "nothing"
        raise InputError(
            f"{path} is not a Canvas gradebook export: its header begins with {found}, not 'Student' and 'ID'; {FIX}"
        )
    rows = csv_rows(text, path, delimiter, FIX)
    header = rows[0]
    section = next((i for i, cell in enumerate(header) if cell.strip() == "Section"), None)
    if section is None or any(cell.strip() not in STUDENT_COLUMNS for cell in header[:section]):
        raise InputError(f"{path} has no 'Section' column after the student columns, which Canvas needs; {FIX}")
    width, body = len(header), []
    for number, row in enumerate(rows[1:], start=2):
        if row and len(row) > width and any(cell.strip() for cell in row[width:]):
            raise InputError(f"{path}, row {number} has {len(row)} cells but the header only {width}; {FIX}")
        body.append(row[:width] + [""] * (width - len(row)) if row else row)
    return CanvasGradebook(header, body, delimiter, newline, bom, section)


def _assignments_text(book):
    """The gradebook's assignment columns (after ``Section``, neither a total nor read-only) in words."""
    points_row = book.points_row()
    names = [
        cell.strip()
        for i, cell in enumerate(book.header)
        if i > book.section
        and cell.strip()
        and TOTALS.search(cell) is None
        and not (points_row and "read only" in points_row[i].lower())
    ]
    if not names:
        return "it has no assignment column yet"
    shown = ", ".join(repr(one_line(name, 80)) for name in names[:MAX_LISTED])
    more = f", and {len(names) - MAX_LISTED} more" if len(names) > MAX_LISTED else ""
    return f"its assignment columns are {shown}{more}"


def _assignment_column(book, column, path):
    """The index of the assignment column named `column` (with or without its Canvas number), or None."""
    pattern = re.compile(re.escape(column.strip()) + r"(\s*\(\d+\))?")
    found = [i for i, cell in enumerate(book.header) if i > book.section and pattern.fullmatch(cell.strip())]
    if len(found) > 1:
        names = ", ".join(repr(book.header[i]) for i in found)
        example = repr(book.header[found[0]].strip())
        raise InputError(
            f"{path} has {len(found)} assignment columns named {column!r} ({names}); e.g. --column {example}."
        )
    return found[0] if found else None


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
    """Fill the assignment `column` of the Canvas `gradebook` with the grades' totals into `out` (and its summary),
    matching students through `roster` on the `key` column; ValueError, and nothing written, for bad input."""
    if key not in KEYS:
        raise InputError(f"--key for Canvas is one of {', '.join(KEYS)} (a gradebook column); got {key!r}.")
    by_name, export = start(grades, out, "Canvas", column)
    entries_ = read_roster(roster)
    book = read_canvas(gradebook)
    check_outputs(export, [gradebook, roster], force)
    at_key = _key_column(book, key, gradebook)
    full_credit = next(iter(by_name.values())).rubric.full_credit
    target = _target(book, export, gradebook, full_credit, new_column)
    students = _students_by_key(book, at_key, key, gradebook, entries_, export)
    matched = match(export, by_name, entries_, students)
    if not matched:
        raise InputError(
            f"no submission of the results matched a row of {gradebook} through the roster {roster}: give the "
            f"gradebook's {key!r} values (--key) as the roster's ids, and grades.csv's names as its submissions."
        )
    roster_ids = set(entries_.values())
    for value, row in students.items():
        name = matched.get(value)
        if name is None:
            if value not in roster_ids:  # a roster entry without a submission is listed as such
                export.lms_only.append((row[0].strip(), value))
        elif by_name[name].graded:
            row[target] = book.number(by_name[name].total)
            export.exported[name] = (value, by_name[name].total)
    if any(total > full_credit for _, total in export.exported.values()):
        full = points_text(full_credit)
        export.notes.append(f"note: some totals are above full credit ({full}) with extra credit; Canvas takes them.")
    write([book.header, *book.rows], out, delimiter=book.delimiter, newline=book.newline, bom=book.bom)
    write_summary(export, entries_, by_name)
    return export


def _key_column(book, key, path):
    """The index of the `key` column among the gradebook's student columns."""
    header = [cell.strip() for cell in book.header]
    if key not in header[: book.section]:
        columns = ", ".join(header[: book.section + 1])
        raise InputError(f"{path} has no {key!r} column (it has {columns}); export it with one, or give another --key.")
    return header.index(key)


def _target(book, export, path, full_credit, new_column):
    """The index of the assignment column to fill: the export's column, or a new one at the end."""
    column = export.column
    if TOTALS.search(column) or column.strip() in STUDENT_COLUMNS:
        raise InputError(f"Canvas reads {column!r} as a student column or a total: give another --column.")
    target = _assignment_column(book, column, path)
    if target is None and not new_column:
        raise InputError(
            f"{path} has no assignment column named {column!r}; {_assignments_text(book)}. Give one of them with "
            "--column, or --new-column to add one on purpose (Canvas then creates a new assignment)."
        )
    if target is not None and new_column:
        raise InputError(
            f"{path} already has the assignment column {one_line(book.header[target], 80)!r} that --column "
            f"{column!r} names: leave out --new-column to fill it, or give the new assignment another --column."
        )
    if target is None:
        book.header.append(column)
        for row in book.rows:
            if row:
                row.append(book.number(full_credit) if book.kind(row) == "points" else "")
        return len(book.header) - 1
    export.column = book.header[target]
    points_row = book.points_row()
    possible = points_row[target].strip() if points_row else ""
    if "read only" in possible.lower():
        raise InputError(f"the column {book.header[target]!r} of {path} is read-only in Canvas: give another --column.")
    with suppress(ValueError):  # points Canvas does not write as a number are not compared
        if possible and float(possible.replace(",", ".")) != full_credit:
            worth = f"is worth {possible} points in Canvas, {points_text(full_credit)} in the rubric"
            export.notes.append(f"note: {book.header[target]!r} {worth}: the totals are written as they are.")
    return target


def _students_by_key(book, at_key, key, path, roster, export):
    """{the key's value: its row} of the gradebook's students; the test student and rows without it in `export`."""
    students: dict = {}
    rows_of: dict = {}
    for number, row in enumerate(book.rows, start=2):
        if not row or book.kind(row) != "student":
            continue
        value = row[at_key].strip()
        if value in students:
            lines = f"rows {rows_of[value]} and {number}"
            raise InputError(f"{path} has two rows with {key} {one_line(value, 60)!r} ({lines}); give another --key.")
        if row[0].strip() == TEST_STUDENT and value not in set(roster.values()):
            export.notes.append(f"note: Canvas's test student ({TEST_STUDENT!r}) is in the gradebook; left as it is.")
        elif not value:  # a student without this id: no roster entry can name it
            export.lms_only.append((row[0].strip(), ""))
        else:
            students[value], rows_of[value] = row, number
    return students


LMS = Canvas()
