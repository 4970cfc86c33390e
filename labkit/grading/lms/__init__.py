"""The LMSs a class comes from and goes back to: one module per LMS, whose ``LMS`` is an :class:`Lms`.

:func:`systems` finds them all, so adding an LMS is adding its module. It all runs in the instructor's process.
"""

from __future__ import annotations

import functools
import importlib
import pkgutil

from ...errors import InputError
from ..store.report import one_line


class Lms:
    """One LMS: its download recognised and read, its grade export, its feedback zip, its roster keys.

    ``name`` is its layout, ``aliases`` others it hands feedback back for. ``rank`` orders recognition (a name
    several claim is the lowest rank's); a ``sole`` LMS takes the class when it claims any entry at its top, a
    ``rest`` one what no other claims. ``depth`` is the levels of a class zip's path that name its student;
    ``download`` and ``counted`` name it in messages; ``keys`` are its roster keys, the default first.
    """

    name = ""
    aliases: tuple[str, ...] = ()
    rank = 50
    sole = rest = assignments = False
    depth = 1
    download = counted = steps = ""
    keys: tuple[str, ...] = ()

    def claims(self, name, kind):
        """Whether an entry at the top of a download (`kind` "dir", "file" or "link") is named as it names one."""
        return False

    def whole(self, root):
        """Whether the folder `root` is its download by its own name, whatever its entries are named."""
        return False

    def described(self, tops):
        """The entries `tops` ([(name, kind)]) it claims, counted for a message on mixed layouts."""
        return f"{len(tops)} {self.counted}"

    def owners(self, tops, builder):
        """{name at the top of a class zip: its student's key, or None when it is no one's (the notes say why)}."""
        return {}

    def owner(self, parts, owners):
        """The key of the student whose member of a class zip has the path `parts`, or None."""
        return owners.get(parts[0])

    def shown(self, key):
        """A student's key as the instructor knows the student."""
        return one_line("_".join(key[1:]), 64)

    def students(self, root, builder, assignment):
        """The students of the download in the folder `root`, read with an :class:`~.intake.Builder`."""
        raise NotImplementedError

    def remember(self, student):
        """What the run's record keeps of a student to name their feedback afterwards."""
        return {"lms id": student.lms_id, "file": student.lms_file}

    def feedback_names(self, name, entry):
        """The feedback zip's members for `name`'s page (`entry`: :meth:`remember`'s); ValueError if it lacks some."""
        raise NotImplementedError

    def feedback(self, name, entry, page):
        """{member of the feedback zip: its text} for the student `name`, whose page is `page`."""
        return dict.fromkeys(self.feedback_names(name, entry), page)

    def export(self, grades, roster, out, **options):
        """Write `grades` for its grade import (an :class:`~.exports.Export`), matched through `roster`."""
        raise InputError(f"{self.name} has no grade import; labkit export writes Canvas's and Moodle's.")


def systems() -> list[Lms]:
    """Every LMS of this package, in the order of recognition.

    >>> [lms.name for lms in systems()]
    ['nbgrader', 'moodle', 'canvas', 'folders']
    """
    return list(_discover(tuple(__path__)))


@functools.lru_cache(maxsize=8)
def _discover(path):
    found = [getattr(importlib.import_module(f"{__name__}.{m.name}"), "LMS", None) for m in pkgutil.iter_modules(path)]
    return tuple(sorted((lms for lms in found if isinstance(lms, Lms)), key=lambda lms: (lms.rank, lms.name)))


def named(layout: str) -> Lms:
    """The LMS whose layout is `layout`; ValueError naming the layouts when none is."""
    for lms in systems():
        if layout in (lms.name, *lms.aliases):
            return lms
    names = [name for lms in systems() for name in (lms.name, *lms.aliases)]
    raise InputError(f"the layout is one of {', '.join(names)}, not {layout!r}.")
