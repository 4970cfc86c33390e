"""The LMSs a class comes from and goes back to: one module per LMS, behind the interface :class:`Lms`.

Run in the instructor's process: ``labkit grade`` reads the class as its LMS hands it over (:mod:`.intake`, with the
safe unzip :mod:`.unzip`), ``labkit export`` writes the grades for the LMS (:mod:`.exports`), ``labkit feedback``
the feedback zip (:mod:`.delivery`), ``labkit release`` and ``labkit variants`` read the roster (:mod:`.roster`).

An LMS is a module of this package that exposes ``LMS``, an instance of a subclass of :class:`Lms`: a folder per
student (:mod:`.folders`), nbgrader (:mod:`.nbgrader`), Canvas (:mod:`.canvas`), Moodle (:mod:`.moodle`).
:func:`systems` finds them all, so adding an LMS is adding its module.
"""

from __future__ import annotations

import importlib
import pkgutil

from ...errors import InputError
from ..store.report import one_line


class Lms:
    """One LMS: its download recognised and read, its grade export, its feedback zip, its roster keys.

    Attributes
    ----------
    name : str
        The layout's name (``Student.layout``, the run's record, ``labkit feedback --layout``).
    aliases : tuple of str
        Other layouts it hands feedback back for (``listed`` submissions are folders).
    rank : int
        The order of recognition: a name that several LMSs claim is the lowest rank's.
    sole : bool
        An entry it claims at the top makes the class its, whatever else is there (nbgrader's ``submitted``).
    rest : bool
        It claims only what no other LMS claims (a folder per student).
    depth : int
        The levels of a path in a class zip that name its student (kept for a student refused).
    assignments : bool
        Its downloads hold several assignments (``--assignment`` picks one).
    download : str
        Its download in words, for a message.
    counted : str
        What the entries it claims are, after their number, for a message.
    keys : tuple of str
        The roster keys its grade import takes (what the roster's ``id`` is), the default first.
    steps : str
        How the instructor hands ``feedback-upload.zip`` to the LMS.
    """

    name = ""
    aliases: tuple[str, ...] = ()
    rank = 50
    sole = False
    rest = False
    depth = 1
    assignments = False
    download = ""
    counted = ""
    keys: tuple[str, ...] = ()
    steps = ""

    def claims(self, name, kind):
        """Whether an entry at the top of a download, of `kind` ``"dir"``, ``"file"`` or ``"link"``, is named as
        this LMS names a student's."""
        return False

    def whole(self, root):
        """Whether the folder `root` is this LMS's download by its own name, whatever its entries are named."""
        return False

    def described(self, tops):
        """The entries `tops` ([(name, kind)]) it claims, counted for a message on mixed layouts."""
        return f"{len(tops)} {self.counted}"

    def owners(self, tops, builder):
        """{name at the top of a class zip: the key of its student, or None when it is no one's (the notes say
        why)}; `tops` are [(name, kind)], `builder` an :class:`~.intake.Builder`."""
        return {}

    def owner(self, parts, owners):
        """The key of the student whose member of a class zip has the path `parts`, or None."""
        return owners.get(parts[0])

    def shown(self, key):
        """A student's key as the instructor knows the student, for a message."""
        return one_line("_".join(key[1:]), 64)

    def students(self, root, builder, assignment):
        """The students (:class:`~.intake.Student`) of the download in the folder `root`, read with `builder`."""
        raise NotImplementedError

    def remember(self, student):
        """What the run's record keeps of a :class:`~.intake.Student` to name their feedback afterwards."""
        return {"lms id": student.lms_id, "file": student.lms_file}

    def feedback_names(self, name, entry):
        """The members of the feedback zip that hold the page of the student `name` (`entry`: :meth:`remember`'s);
        ValueError when the entry lacks what the LMS needs."""
        raise NotImplementedError

    def feedback(self, name, entry, page):
        """{member of the feedback zip: its text} for the student `name`, whose page is `page`."""
        return dict.fromkeys(self.feedback_names(name, entry), page)

    def export(self, grades, roster, out, **options):
        """Write `grades` for the LMS's grade import (an :class:`~.exports.Export`); `roster` is a roster file."""
        raise InputError(f"{self.name} has no grade import; labkit export writes Canvas's and Moodle's.")


def systems() -> list[Lms]:
    """Every LMS of this package (each module's ``LMS``), in the order of recognition: by rank, then name.

    >>> [lms.name for lms in systems()]
    ['nbgrader', 'moodle', 'canvas', 'folders']
    """
    found = []
    for module in pkgutil.iter_modules(__path__):
        lms = getattr(importlib.import_module(f"{__name__}.{module.name}"), "LMS", None)
        if isinstance(lms, Lms):
            found.append(lms)
    return sorted(found, key=lambda lms: (lms.rank, lms.name))


def named(layout: str) -> Lms:
    """The LMS whose layout is `layout`; ValueError naming the layouts when none is."""
    found = systems()
    for lms in found:
        if layout == lms.name or layout in lms.aliases:
            return lms
    names = [name for lms in found for name in (lms.name, *lms.aliases)]
    raise InputError(f"the layout is one of {', '.join(names)}, not {layout!r}.")
