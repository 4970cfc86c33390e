"""A folder per student: ``CLASS/<student>/…/*.ipynb``, the notebooks at any depth (within
:data:`~.intake.MAX_DEPTH`); a zip in a student's folder is unpacked. A notebook at the top of ``CLASS`` is a
student of its own, named after the file (``alice.ipynb`` is ``alice``), as ``labkit grade`` names it.

Feedback: ``{submission}/feedback.html`` in the zip, which unpacks over the class folder.
"""

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
                students.append(builder.from_folder(name, Path(entry.path), "folders", key=("folders", name)))
            elif entry.is_file(follow_symlinks=False) and name.endswith(".ipynb"):
                student = name[: -len(".ipynb")]
                refused = builder.refusal(student, "folders", ("folders", name))
                students.append(refused or Student(student, Path(entry.path), None, "folders"))
            else:
                builder.notes.append(f"ignored {one_line(name)}: not a student's folder or notebook")
        return students

    def feedback_names(self, name, entry):
        """``{submission}/feedback.html`` (a name that is no plain folder name, hashed)."""
        plain = name not in (".", "..") and not re.search(r"[/\\\x00]", name) and not name.startswith(".")
        return [f"{name if plain else file_stem(name)}/{PAGE}"]


LMS = Folders()
