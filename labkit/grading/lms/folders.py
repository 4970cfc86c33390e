"""A folder per student: ``CLASS/<student>/…/*.ipynb`` (a zip in it unpacked), or a notebook ``CLASS/alice.ipynb``
for the student ``alice``. Feedback: ``{submission}/feedback.html``, a zip that unpacks over the class folder."""

from __future__ import annotations

import re
from pathlib import Path

from ..store.report import file_stem, one_line
from . import Lms
from .intake import Student, entries

PAGE = "feedback.html"


class Folders(Lms):
    name = "folders"
    aliases = ("listed",)  # submissions listed one by one are folders too
    rank = 90
    rest = True
    download = "a folder per student"
    steps = "unzip it over the class folder: each student's folder gets its feedback.html"

    def claims(self, name, kind):
        return kind == "dir" or (kind == "file" and name.endswith(".ipynb"))

    def described(self, tops):
        folders = sum(kind == "dir" for _, kind in tops)
        return f"{folders} other folder(s) and {len(tops) - folders} other notebook(s)"

    def owners(self, tops, builder):
        return {name: ("folders", name) for name, kind in tops if self.claims(name, kind)}

    def students(self, root, builder, assignment):
        students = []
        for entry in entries(root):
            name = builder.name(entry)
            if entry.is_symlink():  # a student all the same, with nothing labkit will read: never a silent gap
                students.append(Student(name, None, "is a link, and links are never followed", "folders"))
            elif entry.is_dir(follow_symlinks=False):
                students.append(builder.from_folder(name, Path(entry.path), "folders"))
            elif entry.is_file(follow_symlinks=False) and name.endswith(".ipynb"):
                student = Student(name[: -len(".ipynb")], Path(entry.path), None, "folders")
                students.append(builder.refusal(student, ("folders", name)) or student)
            else:
                builder.notes.append(f"ignored {one_line(name)}: not a student's folder or notebook")
        return students

    def feedback_names(self, name, entry):
        """``{submission}/feedback.html`` (a name that is no plain folder name, hashed)."""
        plain = not re.search(r"[/\\\x00]", name) and not name.startswith(".")
        return [f"{name if plain else file_stem(name)}/{PAGE}"]


LMS = Folders()
