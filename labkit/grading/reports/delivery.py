"""Feedback back to the students through the LMS, with no server: ``labkit feedback OUT`` writes
``OUT/feedback-upload.zip``, each student's ``feedback.html`` named as the LMS the class came from names it.

The run's record knows the layout the class came in, and what names each student's files there
(:func:`remember`, called by ``labkit grade``). One naming function per layout:

``canvas``
    Canvas's "Re-upload submissions" (the assignment's page in SpeedGrader's menu) attaches each file of the
    zip to a student's submission as a comment. Canvas reads a file's name as its download named it
    (``lib/content_zipper.rb``: ``{sortable name}[_LATE]_{user id}_{file id}_{display name}``): it splits the
    name at ``_`` and takes the first two all-digit pieces as the user id and the id of a file of that
    user's submission (``Assignment#infer_comment_context_from_filename`` in instructure/canvas-lms); a name
    whose ids are not of that submission is ignored. So each file is ``{the download's prefix}_feedback.html``,
    the prefix of one of the student's own files in the download the class was graded from.
``moodle``
    Moodle's "Upload multiple feedback files in a zip" (``mod/assign/feedback/file/importziplib.php``)
    splits each folder or file name of the zip at ``_`` and needs ``{full name}_{participant id}_{plugin type}_
    {plugin name}``: the participant id a number, the plugin ``assignfeedback_file``. So each file is
    ``{full name}_{participant id}_assignfeedback_file_/feedback.html`` (the full name without ``_``, as
    Moodle writes it). The Moodle grade CSV of ``labkit export --moodle --feedback`` carries the text too.
``folders``, ``listed``
    ``{submission}/feedback.html``: the zip unpacks over the class folder, one page in each student's folder.
``nbgrader``
    ``{student}/feedback.html``, and nbgrader's own feedback folder, ``feedback/{student}/{assignment}/
    {notebook}.html`` with the ``timestamp.txt`` and ``submission_secret.txt`` of the submission, which
    ``nbgrader release_feedback`` hands to the student's ``nbgrader fetch_feedback``.
"""

from __future__ import annotations

import re
import zipfile
from pathlib import Path

from ...errors import InputError
from ..store import feedback as feedbacks
from ..store import record as records
from ..store.report import file_stem, one_line, read_results

UPLOAD = "feedback-upload.zip"
PAGE = "feedback.html"
NBGRADER_FILES = ("timestamp.txt", "submission_secret.txt")  # copied into nbgrader's feedback folder
MAX_SMALL = 200  # characters kept of one of those files
LAYOUTS = ("canvas", "moodle", "folders", "nbgrader", "listed")


def remember(out, intake) -> None:
    """Enter in `out`'s run record the layout the class came in and each student's names in the LMS
    (`intake`, a :class:`labkit.grading.run.intake.Intake`); a resumed run's earlier students are kept."""
    record = records.read(out)
    earlier = record.delivery.get("students", {}) if record.delivery.get("layout") == intake.layout else {}
    students = {**earlier, **{s.name: _entry(s) for s in intake.students}}
    record.delivery = {"layout": intake.layout, "students": students}
    records.write(out, record)


def _entry(student) -> dict:
    entry: dict = {"lms id": student.lms_id, "file": student.lms_file}
    if student.layout == "nbgrader" and student.path is not None:
        entry["assignment"] = student.path.name
        entry["notebooks"] = sorted(p.stem for p in Path(student.path).glob("*.ipynb"))
        for name in NBGRADER_FILES:
            entry[name] = _small(Path(student.path) / name)
    return entry


def _small(path):
    """The first characters of a small text file of the submission, or None (it is only copied back)."""
    try:
        with open(path, encoding="utf-8", errors="replace") as handle:
            return handle.read(MAX_SMALL)
    except OSError:
        return None


def canvas_names(name, entry):
    """Canvas: the download's prefix of one of the student's files, then ``_feedback.html``."""
    prefix = str(entry.get("file") or "")
    if not re.fullmatch(r"[^/\\\x00]+_\d+_\d+|anon\w*_[A-Za-z0-9]+_\d+", prefix):
        raise InputError(f"no Canvas file of {one_line(name, 80)} is recorded")
    return [f"{prefix}_{PAGE}"]


def moodle_names(name, entry):
    """Moodle: ``{full name}_{participant id}_assignfeedback_file_/feedback.html``."""
    pid = str(entry.get("lms id") or "")
    if not pid.isdigit():
        raise InputError(f"no Moodle participant id of {one_line(name, 80)} is recorded")
    full = name[: -len(pid) - 1] if name.endswith(f"_{pid}") else name
    full = re.sub(r"[_/\\\x00]+", " ", full).strip() or "Participant"
    return [f"{full}_{pid}_assignfeedback_file_/{PAGE}"]


def folder_names(name, entry):
    """A folder per student: ``{submission}/feedback.html`` (a name that is no plain folder name, hashed)."""
    plain = name not in (".", "..") and not re.search(r"[/\\\x00]", name) and not name.startswith(".")
    return [f"{name if plain else file_stem(name)}/{PAGE}"]


def nbgrader_names(name, entry):
    """nbgrader: ``{student}/feedback.html`` and ``feedback/{student}/{assignment}/{notebook}.html``."""
    names = folder_names(name, entry)
    assignment = str(entry.get("assignment") or "")
    if name == Path(name).name and assignment == Path(assignment).name and not name.startswith("."):
        folder = f"feedback/{name}/{assignment}"
        names += [f"{folder}/{notebook}.html" for notebook in entry.get("notebooks", []) if "/" not in notebook]
    return names


NAMING = {
    "canvas": canvas_names,
    "moodle": moodle_names,
    "folders": folder_names,
    "listed": folder_names,
    "nbgrader": nbgrader_names,
}


def write_upload(out, layout=None) -> tuple[Path, list[str], list[str]]:
    """``OUT/feedback-upload.zip`` of a run: (its path, the members written, notes on students left out).

    `layout` overrides the recorded one (``folders`` for a run that recorded none)."""
    out = Path(out)
    delivery = records.read(out).delivery or {}
    layout = layout_of(out, layout)
    if layout not in NAMING:
        raise InputError(f"the layout is one of {', '.join(LAYOUTS)}, not {layout!r}.")
    students = delivery.get("students", {})
    grades = read_results([out])
    members, notes = [], [f"not read: {one_line(p, 200)}: {one_line(w, 300)}" for p, w in grades.refused]
    path = out / UPLOAD
    partial = path.with_name(f".{path.name}.partial")
    with zipfile.ZipFile(partial, "w", zipfile.ZIP_DEFLATED) as archive:
        for grade in grades:
            try:
                names = NAMING[layout](grade.name, students.get(grade.name, {}))
            except ValueError as exc:
                notes.append(f"{one_line(grade.name, 80)} left out: {exc} (was the class graded as {layout}?)")
                continue
            page = feedbacks.html(feedbacks.build(grade))
            for member in names:
                archive.writestr(member, page)
            members += names
            members += _nbgrader_extras(archive, layout, grade.name, students.get(grade.name, {}))
    partial.replace(path)
    return path, members, notes


def _nbgrader_extras(archive, layout, name, entry):
    """nbgrader's feedback folder also needs the submission's timestamp and secret, as nbgrader wrote them."""
    if layout != "nbgrader" or len(nbgrader_names(name, entry)) < 2:
        return []
    folder = f"feedback/{name}/{entry.get('assignment')}"
    written = []
    for file_name in NBGRADER_FILES:
        if entry.get(file_name) is not None:
            archive.writestr(f"{folder}/{file_name}", entry[file_name])
            written.append(f"{folder}/{file_name}")
    return written


STEPS = {
    "canvas": "upload it in Canvas: the assignment's SpeedGrader or Submissions page, 'Re-upload submissions'",
    "moodle": "upload it in Moodle: the assignment's 'View all submissions', 'Upload multiple feedback files "
    "in a zip' (with the 'Feedback files' feedback type on)",
    "folders": "unzip it over the class folder: each student's folder gets its feedback.html",
    "listed": "unzip it over the class folder: each student's folder gets its feedback.html",
    "nbgrader": "unzip it in the course folder, then `nbgrader release_feedback ASSIGNMENT`",
}


def layout_of(out, layout=None):
    """The layout `labkit feedback` names the files for: `layout`, else the run's recorded one, else folders."""
    return layout or records.read(out).delivery.get("layout") or "folders"
