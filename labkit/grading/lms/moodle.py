"""Moodle: its "Download all submissions", a file for its "Import grades from CSV", its feedback files zip.

The download (``mod/assign``'s ``download_submissions``) names a folder ``{Full Name}_{id}_assignsubmission_
{plugin}_`` per plugin, or files ``…_assignsubmission_{plugin}_{file}`` (``_`` in the name made a space, the id
the participant id); the student ``{Full Name}_{id}`` keeps namesakes apart. The grade import
(``grade/import/csv/classes/load_data.php``) stops at a user it cannot find, and an empty cell would erase a
grade, so ids must fit ``--key`` and only graded students are written.
"""

from __future__ import annotations

import os
import re
from pathlib import Path

from ...errors import InputError
from ..store.feedback import build, text
from ..store.report import FORMULA_START, SubmissionGrade, csv_cell, one_line
from ..store.text import points_text
from . import Lms
from .exports import DEFAULT_COLUMN, Export, check_outputs, match, start, write, write_summary
from .intake import entries, safe_part, walk
from .roster import read_roster

KEYS = {"idnumber": "ID number", "email": "Email address"}
EMAIL = re.compile(r"[^@\s]+@[^@\s]+\.[^@\s]+")  # what looks like an email address, for --key
MAX_FEEDBACK = 30_000  # characters of a feedback cell (the student's feedback text, bounded)
# a folder per plugin (``file`` empty), or a file
NAME = re.compile(r"^(?P<name>[^_]+)_(?P<pid>[0-9]+)_assignsubmission_(?P<plugin>[a-z0-9]+)_(?P<file>.*)$", re.DOTALL)


class Moodle(Lms):
    name = "moodle"
    rank = 10
    download = "Moodle's download"
    counted = "named as Moodle names submissions"
    keys = tuple(KEYS)
    steps = "upload it in Moodle: the assignment's 'View all submissions', 'Upload multiple feedback files in a zip'"

    def claims(self, name, kind):
        return _match(name, kind) is not None

    def owners(self, tops, builder):
        found = {name: _match(name, kind) for name, kind in tops}
        return {name: ("moodle", got["name"], got["pid"]) for name, got in found.items() if got}

    def students(self, root, builder, assignment):
        folders, loose = {}, {}  # (name, pid) -> [folders] / [(original, path)]
        for entry in entries(root):
            name = builder.name(entry)
            if entry.is_symlink():
                builder.notes.append(f"ignored {one_line(name)}: a link (links are never followed)")
            elif entry.is_dir(follow_symlinks=False) and (found := _match(name, "dir")):
                folders.setdefault((found["name"], found["pid"]), []).append(Path(entry.path))
            elif entry.is_file(follow_symlinks=False) and (found := _match(name, "file")):
                loose.setdefault((found["name"], found["pid"]), []).append((found["file"], Path(entry.path)))
            else:
                builder.notes.append(f"ignored {one_line(name)}: not named as Moodle names a submission")
        return [_student(key, folders, loose, builder) for key in sorted(set(folders) | set(loose))]

    def feedback_names(self, name, entry):
        """``{full name}_{participant id}_assignfeedback_file_/feedback.html``."""
        pid = str(entry.get("lms id") or "")
        if not pid.isdigit():
            raise InputError(f"no Moodle participant id of {one_line(name, 80)} is recorded")
        full = name[: -len(pid) - 1] if name.endswith(f"_{pid}") else name
        full = re.sub(r"[_/\\\x00]+", " ", full).strip() or "Participant"
        return [f"{full}_{pid}_assignfeedback_file_/feedback.html"]

    def export(self, grades, roster, out, **options):
        return to_moodle(grades, roster, out, **options)


def _match(name, kind):
    found = NAME.match(name)
    return found if found and kind == ("file" if found["file"] else "dir") else None


def _student(key, folders, loose, builder):
    name = f"{key[0]}_{key[1]}"
    if key in folders and key not in loose and len(folders[key]) == 1:
        return builder.from_folder(name, folders[key][0], "moodle", key[1], key=("moodle", *key))
    pieces = [(Path(safe_part(original)), path) for original, path in loose.get(key, [])]
    for folder in folders.get(key, []):
        try:
            files = walk(folder, builder.notes)
        except ValueError as exc:
            builder.notes.append(one_line(exc, 300))
            files = []
        pieces += [(f.relative_to(folder), f) for f in files]
    return builder.from_files(name, pieces, "moodle", key[1], key=("moodle", *key))


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
    """Write `out` for Moodle's "Import grades from CSV" (and its summary): a row per graded student on `roster`,
    whose ids are the user field `key`, the totals in `column`, with `feedback` a ``Feedback`` column. `force`
    replaces an existing `out`. ValueError, and nothing written, for bad input."""
    if key not in KEYS:
        raise InputError(f"--key for Moodle is idnumber or email (the user field of the roster's ids); got {key!r}.")
    by_name, export = start(grades, out, "Moodle", column)
    entries_ = read_roster(roster)
    _check_ids(entries_, roster, key)
    check_outputs(export, [roster], force)
    rows = [[KEYS[key], column] + (["Feedback"] if feedback else [])]
    for value, name in match(export, by_name, entries_).items():
        grade = by_name[name]
        if grade.graded:
            rows.append([value, points_text(grade.total)] + ([_feedback_cell(grade)] if feedback else []))
            export.exported[name] = (value, grade.total)
    if not export.exported:
        raise InputError(f"no graded submission of the results is on the roster {roster}: give grades.csv's names.")
    full_credit = next(iter(by_name.values())).rubric.full_credit
    highest = max(total for _, total in export.exported.values())
    if highest > full_credit:
        top = points_text(highest)
        export.notes.append(
            f"note: totals reach {top}, above full credit ({points_text(full_credit)}), with extra credit: give the "
            f"Moodle grade item a maximum of at least {top} (above 100, with 'unlimitedgrades' and 'gradepointmax')."
        )
    write(rows, out)
    write_summary(export, entries_, by_name)
    return export


def _check_ids(entries_, roster, key):
    """Refuse ids Moodle would not find under `key`, and ids that start like a formula."""
    for name, value in entries_.items():
        gives = f"the roster {roster} gives {one_line(name, 60)!r} the id {one_line(value, 60)!r}"
        if key == "email" and not EMAIL.fullmatch(value):
            raise InputError(f"{gives}, which is not an email address: give one, or --key idnumber.")
        if value.startswith(FORMULA_START):
            raise InputError(f"{gives}, which starts like a spreadsheet formula; correct the roster.")
    emails = [name for name, value in entries_.items() if EMAIL.fullmatch(value)]
    if key != "idnumber" or not emails:
        return
    if len(emails) == len(entries_):
        raise InputError(
            f"the roster {roster} holds email addresses (e.g. {_examples(entries_, emails)}), not ID numbers for "
            "Moodle's ID number column (--key idnumber): give --key email, or the students' ID numbers."
        )
    others = [name for name in entries_ if name not in emails]
    raise InputError(
        f"the roster {roster} mixes email addresses ({len(emails)} of {len(entries_)}: {_examples(entries_, emails)}) "
        f"with other ids (e.g. {_examples(entries_, others)}) under --key idnumber: correct those rows, or give "
        "every email address with --key email."
    )


def _examples(entries_, names):
    """A few roster entries, for a message: each name and id on one printable line."""
    shown = ", ".join(f"{one_line(name, 40)!r} ({one_line(entries_[name], 60)!r})" for name in names[:3])
    return shown + (f" and {len(names) - 3} more" if len(names) > 3 else "")


def points_in_words(grade):
    """The points in words: the grade (after any late penalty), then how it was made.

    >>> from labkit.grading.store.report import SubmissionGrade
    >>> points_in_words(SubmissionGrade("ada", {2: {"fraction": 1.0, "passed": True, "checks": []}}))
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


def _feedback_cell(grade):
    """The points in words, then the graded student's feedback text, bounded and never read as a formula."""
    whole = f"{points_in_words(grade)}\n\n{text(build(grade))}"
    whole = whole if len(whole) <= MAX_FEEDBACK else whole[: MAX_FEEDBACK - 1] + "\u2026"
    return csv_cell(whole[:1]) + whole[1:]


LMS = Moodle()
