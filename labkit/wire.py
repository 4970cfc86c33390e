"""The library's own types that may cross the grader's wire, as a table: one row per type.

The sandbox's protocol (:mod:`labkit.grading.sandbox.protocol`) sends plain numbers only. A course type
(a :class:`labkit.Corner`, a :class:`labkit.QuadMesh`) crosses as its tag and its fields, each a float array,
and the grader rebuilds it from those checked arrays with the row's ``rebuild``, which never runs code of the
type that the watch may refuse while a student's function runs. A new answer type is one row here; the
sandbox is not edited.
"""

from dataclasses import dataclass
from importlib import import_module

import numpy as np

from .errors import InputError


@dataclass(frozen=True)
class WireType:
    """One course type on the wire: its tag, where its class lives, its fields in order, and how the grader
    builds it from the fields (float arrays, already checked to be arrays); ``rebuild`` raises ValueError
    with the reason when the fields cannot be one."""

    tag: str
    where: str  # "module:Class"
    fields: tuple
    rebuild: object

    def kind(self):
        module, _, name = self.where.partition(":")
        return getattr(import_module(module), name)


def _corner(point, ds, dt, dsdt):
    from .patches import Corner

    fields = [np.ravel(f) for f in (point, ds, dt, dsdt)]
    if fields[0].size not in (2, 3) or any(f.size != fields[0].size for f in fields):
        raise InputError("an invalid Corner (its fields must be vectors of 2 or 3 numbers, all the same size)")
    if not all(np.all(np.isfinite(f)) for f in fields):
        raise InputError("an invalid Corner (NaN or infinite numbers)")
    corner = object.__new__(Corner)
    for name, value in zip(("point", "ds", "dt", "dsdt"), fields):
        object.__setattr__(corner, name, value.copy())
    return corner


def _mesh(points, quads):
    from .mesh import QuadMesh

    if not np.array_equal(quads, np.round(quads)):
        raise InputError("a QuadMesh whose quads are not node numbers")
    try:
        return QuadMesh(points, quads.astype(np.intp))
    except (ValueError, TypeError) as exc:
        raise InputError(f"an invalid QuadMesh ({exc})") from None


TYPES = (
    WireType("corner", "labkit.patches:Corner", ("point", "ds", "dt", "dsdt"), _corner),
    WireType("mesh", "labkit.mesh:QuadMesh", ("points", "quads"), _mesh),
)
BY_TAG = {row.tag: row for row in TYPES}
