"""Feedback back through the LMS: ``OUT/feedback-upload.zip``, each student's page named as the class's LMS names
it (:meth:`~labkit.grading.lms.Lms.feedback`), from what the run's record kept (:func:`remember`)."""

from __future__ import annotations

import zipfile
from pathlib import Path

from ..store import feedback as feedbacks
from ..store import record as records
from ..store.report import one_line, read_results
from . import named

UPLOAD = "feedback-upload.zip"


def remember(out, intake) -> None:
    """Record in `out` the layout of `intake` and each student's names in the LMS; a resumed run's are kept."""
    record = records.read(out)
    earlier = record.delivery.get("students", {}) if record.delivery.get("layout") == intake.layout else {}
    lms = named(intake.layout)
    students = {**earlier, **{s.name: lms.remember(s) for s in intake.students}}
    record.delivery = {"layout": intake.layout, "students": students}
    records.write(out, record)


def write_upload(out, layout=None) -> tuple[Path, list[str], list[str]]:
    """Write ``OUT/feedback-upload.zip`` for `layout` (or the recorded one): (its path, members, notes)."""
    out = Path(out)
    layout = layout_of(out, layout)
    lms = named(layout)
    students = records.read(out).delivery.get("students", {})
    grades = read_results([out])
    members, notes = [], [f"not read: {one_line(p, 200)}: {one_line(w, 300)}" for p, w in grades.refused]
    path = out / UPLOAD
    partial = path.with_name(f".{path.name}.partial")
    with zipfile.ZipFile(partial, "w", zipfile.ZIP_DEFLATED) as archive:
        for grade in grades:
            try:
                files = lms.feedback(grade.name, students.get(grade.name, {}), feedbacks.html(feedbacks.build(grade)))
            except ValueError as exc:
                notes.append(f"{one_line(grade.name, 80)} left out: {exc} (was the class graded as {layout}?)")
                continue
            for member, text in files.items():
                archive.writestr(member, text)
            members += files
    partial.replace(path)
    return path, members, notes


def layout_of(out, layout=None):
    """The layout `labkit feedback` names the files for: `layout`, else the run's recorded one, else folders."""
    return layout or records.read(out).delivery.get("layout") or "folders"
