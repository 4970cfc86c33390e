"""Whose file is it: the LMS's own ids in a download's file names, read where a student's name could mislead.

Canvas names each file of an assignment's "Download Submissions" as
``{name}[_LATE]_{user id}_{file id}_{display name}`` (``add_upload_submission``
and ``get_filename`` in canvas-lms's ``lib/content_zipper.rb``): ``{name}`` is
the student's sortable name lower-cased with every character that is not a
letter, digit or ``_`` dropped; ``{display name}`` is the file's name as
uploaded, with only ``/ \\ : * ? " < > |`` and NUL made ``_``. Anonymous
grading writes ``anon_{anonymous id}`` for name and user id (``LATE_`` before
it when late). Both ends are the student's choice: Canvas removes ``_123_``
from a name, but not ``_ 123 _``, whose spaces it drops afterwards; and a
display name may hold ``_1001_9_`` too. So a file name can have several
readings, one per place where ``_{digits}_{digits}_`` can end the name, less
those Canvas cannot write: a name part with capitals (Canvas lower-cases it),
an id with a leading zero (``02_convergence.ipynb`` after the file id is a
display name, never a user id and a file id).

:func:`resolve_canvas` takes the reading its user's other files confirm: a
user's files all start with the same ``{name}[_LATE]_{user id}_``, so a
reading whose user id some file shows unambiguously under another name is
ruled out. When more than one reading is left, the roster's ids (``--roster``)
pick the one whose user is on it; when that does not settle it, the file is
filed to no one, and the notes say so. A display name never decides, and every
file whose reading depended on one is named in the notes.
"""

from __future__ import annotations

import functools
import re
from dataclasses import dataclass

from ..store.report import one_line

_FIXED = re.compile(r"(?=(_LATE)?_([0-9]+)_([0-9]+)_(.))", re.DOTALL)
_ANON = re.compile(r"^(LATE_)?(anon(?:ymous)?)(_LATE)?_([A-Za-z0-9]+)_([0-9]+)_(.+)$", re.DOTALL)
_NOT_WORD = re.compile(r"\W")


@dataclass(frozen=True)
class Reading:
    """One way to read a Canvas file name: the name part, late or not, the user id, the file id, the display name."""

    login: str
    late: bool
    uid: str
    fid: str
    file: str

    @property
    def prefix(self):
        """What every file of this user starts with."""
        return (self.login, self.late, self.uid)


def canvas_readings(name: str) -> list[Reading]:
    """Every reading of `name` as Canvas names a submission's file, shortest name part first.

    >>> [(r.login, r.uid, r.file) for r in canvas_readings("ada_1001_9_lab.ipynb")]
    [('ada', '1001', 'lab.ipynb')]
    >>> [(r.login, r.uid) for r in canvas_readings("ada_1001_9_00_2002_77_x.ipynb")]
    [('ada', '1001'), ('ada_1001_9_00', '2002')]
    >>> [(r.login, r.uid, r.file) for r in canvas_readings("ada_LATE_1001_98765_02_convergence.ipynb")]
    [('ada', '1001', '02_convergence.ipynb')]
    >>> canvas_readings("Ada Lovelace.ipynb")
    []
    """
    return list(_readings(name))


@functools.lru_cache(maxsize=1 << 14)
def _readings(name):
    """The readings of canvas_readings, kept for the next look at the same name."""
    anon = _ANON.match(name)
    if anon:
        late = bool(anon[1] or anon[3])
        return (Reading(f"{anon[2]}_{anon[4]}", late, anon[4], anon[5], anon[6]),)
    stop = _NOT_WORD.search(name)
    end = len(name) if stop is None else stop.start()  # the name part holds word characters only
    found = []
    for match in _FIXED.finditer(name):
        at = match.start()
        if at > end:
            break
        login = name[:at]
        if login != login.lower() or _padded(match[2]) or _padded(match[3]):
            continue  # Canvas lower-cases the name, and writes its ids without leading zeros
        file = name[match.end(3) + 1 :]
        found.append(Reading(login, bool(match[1]), match[2], match[3], file))
    return tuple(found)


def _padded(number):
    return len(number) > 1 and number.startswith("0")


def resolve_canvas(names, roster_ids=()) -> tuple[dict, list[str]]:
    """{file name: its Reading, or None when it is no one's} and notes for the instructor.

    `names` are a download's file names; `roster_ids` the roster's ids (Canvas user ids), if any.

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
    chosen: dict = {}
    notes: list[str] = []
    roster = set(roster_ids)
    for name, found in readings.items():
        chosen[name] = found[0] if len(found) == 1 else _choose(name, found, settled, roster, notes)
    return chosen, notes


def _choose(name, found, settled, roster, notes):
    if not found:
        return None
    shown = one_line(name, 120)
    left = [r for r in found if r.uid not in settled or r.prefix in settled[r.uid]]
    if len(left) > 1 and roster:
        on_roster = [r for r in left if r.uid in roster]
        left = on_roster or left
    if len(left) == 1:
        others = ", ".join(f"user {one_line(r.uid, 20)} ({one_line(r.login, 60)})" for r in found if r != left[0])
        notes.append(
            f"file {shown}: filed under user {one_line(left[0].uid, 20)} by its id; its name, which a student "
            f"chooses, could also be read as {others}"
        )
        return left[0]
    readings = ", ".join(f"user {one_line(r.uid, 20)} ({one_line(r.login, 60)})" for r in left or found)
    notes.append(
        f"file {shown}: filed to no one: its name, which a student chooses, reads as {readings}, and nothing "
        "tells which (a --roster settles it when only one of those users is on it); ask the student to rename the "
        "file, and grade it alone"
    )
    return None
