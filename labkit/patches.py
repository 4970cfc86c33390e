"""Bicubic Hermite (Coons) patches: the unit square mapped onto a curved quadrilateral.

A patch is fixed by 16 data per coordinate at its corners A (s=0, t=0),
B (1, 0), C (1, 1) and D (0, 1): the point, the derivatives along s and t,
and the cross derivative (twist). ``notebooks/03_meshes.ipynb`` builds the
patch step by step and uses it to generate the lab's meshes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ._validate import as_float_array, require_finite
from .errors import InputError
from .piecewise import hermite_basis


@dataclass(frozen=True, init=False)
class Corner:
    """The data of a patch at one corner.

    Parameters
    ----------
    point : array_like, shape (dim,)
        Where the corner is, ``dim`` 2 (a plane patch) or 3 (a surface in space).
    ds, dt : array_like, shape (dim,)
        Derivatives of the map with respect to s and to t at the corner.
    dsdt : array_like, shape (dim,), optional
        The twist, the cross derivative d2/dsdt; zeros if omitted.

    Examples
    --------
    >>> from labkit import Corner
    >>> Corner([0, 0], ds=[1, 0], dt=[0, 1]).dsdt.tolist()
    [0.0, 0.0]
    """

    point: NDArray[np.float64]
    ds: NDArray[np.float64]
    dt: NDArray[np.float64]
    dsdt: NDArray[np.float64]

    # Written out (not generated from the fields) because it takes any array_like
    # while the fields hold the validated float vectors.
    def __init__(self, point: ArrayLike, ds: ArrayLike, dt: ArrayLike, dsdt: ArrayLike | None = None) -> None:
        where = _vector(point, "point")
        if where.size not in (2, 3):
            raise InputError(f"Corner point must have 2 (plane) or 3 (space) coordinates; got {where.size}.")
        twist = np.zeros(where.size) if dsdt is None else dsdt
        object.__setattr__(self, "point", where)
        for name, value in (("ds", ds), ("dt", dt), ("dsdt", twist)):
            vec = _vector(value, name)
            if vec.size != where.size:
                raise InputError(
                    f"Corner {name} has {vec.size} components but point has {where.size}; "
                    "give every field of a corner the same dimension."
                )
            object.__setattr__(self, name, vec)

    @property
    def dim(self) -> int:
        """Number of coordinates, 2 or 3."""
        return self.point.size


def _vector(value, name):
    vec = as_float_array(value, f"Corner {name}")
    if vec.ndim != 1:
        raise InputError(f"Corner {name} must be a vector; got shape {vec.shape}.")
    require_finite(vec, f"Corner {name}")
    return vec.copy()


def _parameter(values, name):
    u = as_float_array(values, name)
    if u.ndim != 1 or u.size == 0:
        raise InputError(f"{name} must be a non-empty 1-D array of parameter values in [0, 1]; got shape {u.shape}.")
    require_finite(u, name)
    if u.min() < 0.0 or u.max() > 1.0:
        raise InputError(
            f"{name} must lie in [0, 1] (the unit square is the patch's parameter domain); "
            f"got values from {u.min():g} to {u.max():g}."
        )
    return u


def patch(A: Corner, B: Corner, C: Corner, D: Corner, s: ArrayLike, t: ArrayLike) -> NDArray[np.float64]:
    """Evaluate the bicubic Hermite patch with corners A, B, C, D on the grid s x t.

    The lab's construction: Hermite cubics in s give the bottom edge AB and
    the top edge DC, and the t-derivative along them (from the corner
    t-derivatives and twists); a Hermite cubic in t then joins bottom and
    top for every s at once.

    Parameters
    ----------
    A, B, C, D : Corner
        Data at (s, t) = (0, 0), (1, 0), (1, 1), (0, 1), all of one dimension.
    s, t : array_like, 1-D
        Parameter values in [0, 1]; they need not be equally spaced.

    Returns
    -------
    ndarray, shape (dim, len(s), len(t))
        ``x, y = patch(...)`` (or ``x, y, z``) gives coordinate arrays with
        ``x[i, j] = x(s[i], t[j])``.

    Examples
    --------
    The identity map of the unit square (exercise 5):

    >>> import numpy as np
    >>> from labkit import Corner, patch
    >>> e1, e2, zero = [1, 0], [0, 1], [0, 0]
    >>> A, B = Corner(zero, e1, e2), Corner(e1, e1, e2)
    >>> C, D = Corner([1, 1], e1, e2), Corner(e2, e1, e2)
    >>> x, y = patch(A, B, C, D, np.linspace(0, 1, 3), np.linspace(0, 1, 2))
    >>> x.tolist(), y.tolist()
    ([[0.0, 0.0], [0.5, 0.5], [1.0, 1.0]], [[0.0, 1.0], [0.0, 1.0], [0.0, 1.0]])
    """
    corners = (A, B, C, D)
    for label, corner in zip("ABCD", corners):
        if not isinstance(corner, Corner):
            raise InputError(f"{label} must be a labkit.Corner; got {type(corner).__name__}.")
    dims = {c.dim for c in corners}
    if len(dims) != 1:
        raise InputError(
            "corners of mixed dimension: "
            + ", ".join(f"{lab} is {c.dim}-D" for lab, c in zip("ABCD", corners))
            + ". Give all four corners 2 or all four 3 coordinates."
        )
    in_s = np.array(hermite_basis(0.0, 1.0, _parameter(s, "s")))  # (4, ns)
    in_t = np.array(hermite_basis(0.0, 1.0, _parameter(t, "t")))  # (4, nt)
    bottom = _hermite_in_s(in_s, A.point, A.ds, B.point, B.ds)
    bottom_dt = _hermite_in_s(in_s, A.dt, A.dsdt, B.dt, B.dsdt)
    top = _hermite_in_s(in_s, D.point, D.ds, C.point, C.ds)
    top_dt = _hermite_in_s(in_s, D.dt, D.dsdt, C.dt, C.dsdt)
    # Hermite in t between the two edges: values bottom/top, slopes bottom_dt/top_dt.
    return np.stack((bottom, bottom_dt, top, top_dt), axis=-1) @ in_t


def _hermite_in_s(basis, left_value, left_slope, right_value, right_slope):
    """Hermite cubic in s for every coordinate at once: shape (dim, ns)."""
    return np.stack((left_value, left_slope, right_value, right_slope), axis=1) @ basis
