"""A submission's name is its key: kept whole wherever it is looked up (grades.csv, the results, ``labkit
merge``, the report, the LMS export, ``marks.csv``), shortened only where a person reads it (:func:`shown_name`).
"""

from __future__ import annotations

import hashlib

from .report import name_cell, one_line

__all__ = ["name_cell", "name_from_cell", "shown_name"]


def shown_name(name: str, limit: int = 80) -> str:
    """`name` to show: one printable line of at most `limit` characters, a shortened one ending with a hash of
    the whole name, so that two names sharing a beginning never look the same.

    >>> shown_name("ada")
    'ada'
    >>> a, b = shown_name("x" * 230 + "a", 40), shown_name("x" * 230 + "b", 40)
    >>> len(a) == len(b) == 40 and a != b
    True
    """
    line = one_line(name, len(str(name)) + 1)
    if len(line) <= limit:
        return line
    digest = hashlib.sha256(str(name).encode("utf-8", "surrogatepass")).hexdigest()[:8]
    return line[: max(limit - 10, 1)] + "\u2026" + f"#{digest}"


def name_from_cell(cell: str, names) -> str | None:
    """The name among `names` that a cell of a CSV labkit wrote (or a person retyped) stands for, or None.

    >>> name_from_cell("'=1+1 eve", ["=1+1 eve", "ada"]), name_from_cell(" ada ", ["ada"]), name_from_cell("x", [])
    ('=1+1 eve', 'ada', None)
    """
    names = list(names)
    if cell in names:
        return cell
    cells = {name_cell(name): name for name in names}
    stripped = cell.strip()
    for candidate in (cell, stripped):
        if candidate in cells:
            return cells[candidate]
    return stripped if stripped in names else None
