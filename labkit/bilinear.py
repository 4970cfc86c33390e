"""Piecewise bilinear interpolation on a rectangular grid (the lab's extra credit).

On each grid cell the interpolant is the unique function a + bx + cy + dxy
that matches the four corner values; the derivation with the four cell
basis functions is in ``notebooks/06_bilinear.ipynb``.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ._locate import locate
from ._validate import as_float_array, as_knots, require_finite
from .errors import InputError


def eval_pbilin(
    f: Callable[[NDArray[np.float64], NDArray[np.float64]], ArrayLike] | ArrayLike,
    xdata: ArrayLike,
    ydata: ArrayLike,
    xval: ArrayLike,
    yval: ArrayLike,
) -> float | NDArray[np.float64]:
    """Piecewise bilinear interpolant of `f` on the grid ``xdata x ydata``.

    Parameters
    ----------
    f : callable or array_like
        ``f(X, Y)`` evaluated on the grid (it must accept arrays, as
        :func:`labkit.runge2d` does), or the table of values itself with
        shape ``(len(xdata), len(ydata))``.
    xdata, ydata : array_like, 1-D
        Strictly increasing grid lines, at least 2 each.
    xval, yval : array_like, 1-D (or scalars)
        Where to evaluate; points outside the grid extend the edge cells.

    Returns
    -------
    zval : ndarray, shape (len(xval), len(yval))
        ``zval[k, l] = I(xval[k], yval[l])``; a float if both are scalars.

    Examples
    --------
    Bilinear functions are reproduced exactly:

    >>> from labkit import eval_pbilin
    >>> z = eval_pbilin(lambda x, y: x * y, [0, 1, 3], [0, 2], [0.5, 2.0], [1.0])
    >>> z.tolist()
    [[0.5], [2.0]]
    """
    x = as_knots(xdata, "xdata")
    y = as_knots(ydata, "ydata")
    values = _grid_values(f, x, y)
    xv = np.atleast_1d(as_float_array(xval, "xval"))
    yv = np.atleast_1d(as_float_array(yval, "yval"))
    for arr, name in ((xv, "xval"), (yv, "yval")):
        if arr.ndim != 1:
            raise InputError(f"{name} must be 1-D (the grid is xval x yval); got shape {arr.shape}.")
    # Separable: linear in x along every grid line y = ydata[j], then linear in y.
    kx, wx = _cell_and_weight(x, xv)
    along_x = values[kx] * (1.0 - wx)[:, None] + values[kx + 1] * wx[:, None]
    ky, wy = _cell_and_weight(y, yv)
    zval = along_x[:, ky] * (1.0 - wy) + along_x[:, ky + 1] * wy
    return zval[0, 0] if np.ndim(xval) == 0 and np.ndim(yval) == 0 else zval


def _cell_and_weight(knots, points):
    k = locate(knots, points)
    return k, (points - knots[k]) / (knots[k + 1] - knots[k])


def _grid_values(f, x, y):
    if callable(f):
        X, Y = np.meshgrid(x, y, indexing="ij")
        values = as_float_array(f(X, Y), "f(X, Y)")
        name = "f(X, Y)"
    else:
        values = as_float_array(f, "f")
        name = "f"
    if values.shape != (x.size, y.size):
        raise InputError(
            f"{name} has shape {values.shape} but the grid is {x.size} x {y.size}; "
            "f must give one value per (xdata[i], ydata[j])."
        )
    require_finite(values, name)
    return values
