"""nbgrader: ``COURSE/submitted/<student>/<assignment>/*.ipynb``; the path is the assignment's folder, so
``timestamp.txt`` stays where :mod:`~labkit.grading.store.late` looks. Feedback: ``{student}/feedback.html`` and
``feedback/{student}/{assignment}/{notebook}.html`` with the submission's timestamp and secret, for ``nbgrader
release_feedback``."""

from __future__ import annotations

import os
from pathlib import Path

from ...errors import InputError
from ..store.report import one_line
from . import Lms
from .folders import LMS as FOLDERS
from .intake import entries
from .unzip import as_text

FILES = ("timestamp.txt", "submission_secret.txt")  # copied into nbgrader's feedback folder
MAX_SMALL = 200  # characters kept of one of those files


class Nbgrader(Lms):
    name = "nbgrader"
    rank = 0
    sole = True
    depth = 3
    assignments = True
    download = "nbgrader's submitted/"
    steps = "unzip it in the course folder, then `nbgrader release_feedback ASSIGNMENT`"

    def claims(self, name, kind):
        return name == "submitted" and kind == "dir"

    def whole(self, root):
        found = entries(root)
        return (
            os.path.basename(os.path.normpath(root)) == "submitted"
            and all(e.is_dir(follow_symlinks=False) for e in found)
            and any(any(i.is_dir(follow_symlinks=False) for i in entries(e.path)) for e in found)
        )

    def owner(self, parts, owners):
        return ("nbgrader", parts[1]) if parts[0] == "submitted" and len(parts) > 1 else None

    def students(self, root, builder, assignment):
        submitted = root if root.name == "submitted" and not (root / "submitted").is_dir() else root / "submitted"
        found = _assignments(submitted, builder.notes)
        assignment = _chosen(submitted, found, assignment)
        students, missing = [], []
        for name, per in found.items():
            if assignment in per:
                students.append(builder.from_folder(name, per[assignment], "nbgrader", keep=FILES[:1]))
            else:
                missing.append(name)
        if missing:
            shown = ", ".join(one_line(m, 64) for m in sorted(missing)[:10]) + (" …" if len(missing) > 10 else "")
            builder.notes.append(
                f"{len(missing)} student(s) in submitted/ without {one_line(assignment, 60)!r}: {shown}"
            )
        return students

    def remember(self, student):
        entry = super().remember(student)
        if student.path is not None:
            entry["assignment"] = student.path.name
            entry["notebooks"] = sorted(p.stem for p in student.path.glob("*.ipynb"))
            entry |= {name: _small(student.path / name) for name in FILES}
        return entry

    def feedback_names(self, name, entry):
        names = FOLDERS.feedback_names(name, entry)
        assignment = str(entry.get("assignment") or "")
        if name == Path(name).name and assignment == Path(assignment).name and not name.startswith("."):
            folder = f"feedback/{name}/{assignment}"
            names += [f"{folder}/{notebook}.html" for notebook in entry.get("notebooks", []) if "/" not in notebook]
        return names

    def feedback(self, name, entry, page):
        members = super().feedback(name, entry, page)
        if len(members) > 1:  # nbgrader's feedback folder also needs the submission's timestamp and secret
            folder = f"feedback/{name}/{entry.get('assignment')}"
            members |= {f"{folder}/{file}": entry[file] for file in FILES if entry.get(file) is not None}
        return members


def _assignments(submitted, notes):
    """{student: {assignment: folder}} of nbgrader's ``submitted/``."""
    found: dict = {}
    for entry in entries(submitted):
        name = as_text(entry.name)
        if not entry.is_dir(follow_symlinks=False):  # a link is no folder here
            notes.append(f"ignored {one_line(name)} in submitted/: not a student's folder")
            continue
        found[name] = {}
        for inner in entries(entry.path):
            if inner.is_dir(follow_symlinks=False):
                found[name][as_text(inner.name)] = Path(inner.path)
            else:
                notes.append(f"ignored {one_line(name)}/{one_line(as_text(inner.name))}: not an assignment's folder")
    return found


def _chosen(submitted, found, assignment):
    """The assignment to grade: `assignment`, or the only one there is; ValueError when it cannot be told."""
    assignments = sorted({a for per in found.values() for a in per})
    where = as_text(str(submitted))
    if not assignments:
        raise InputError(f"{where} holds no assignment folders: nbgrader's is submitted/<student>/<assignment>/.")
    if assignment is None and len(assignments) > 1:
        shown = ", ".join(one_line(n, 64) for n in assignments)
        raise InputError(f"{where} holds several assignments ({shown}); pass --assignment NAME to grade one.")
    if assignment is not None and assignment not in assignments:
        there = ", ".join(one_line(a, 60) for a in assignments)
        raise InputError(f"no student of {where} submitted {one_line(assignment, 60)!r}; the assignments are {there}.")
    return assignment if assignment is not None else assignments[0]


def _small(path):
    """The first characters of a small text file of the submission, or None (it is only copied back)."""
    try:
        with open(path, encoding="utf-8", errors="replace") as handle:
            return handle.read(MAX_SMALL)
    except OSError:
        return None


LMS = Nbgrader()
