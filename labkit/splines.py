"""Cubic splines: complete, natural and not-a-knot.

Every spline here is computed the way the lab derives it: solve the
tridiagonal system ``A M = D`` for the second derivatives ``M_k`` at the
knots, turn them into knot slopes with the lab's equations (8) and (9), and
evaluate with the piecewise Hermite cubic. The derivation, and why the
matrix is nonsingular, is in ``notebooks/04_splines.ipynb``.

The systems are solved in O(n) with LAPACK's tridiagonal solver; no dense
matrix is ever formed.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ._frame import Frame
from ._validate import as_data, as_knots, as_order, as_points, as_scalar, scalar_or_array
from .errors import InputError
from .piecewise import _hermite_eval


def _solve_tridiagonal(sub, diag, sup, rhs):
    """Solve a tridiagonal system in O(n) (sub/sup diagonals of length n-1)."""
    if diag.size == 1:
        return rhs / diag
    from scipy.linalg import lapack  # loaded at the first solve: `import labkit` stays light

    *_, solution, info = lapack.dgtsv(sub, diag, sup, rhs, 1, 1, 1, 1)
    if info != 0:  # cannot happen for the diagonally dominant systems built here
        raise InputError(f"the spline system is singular (LAPACK info={info}).")
    return solution


def _slopes_from_curvatures(h, secants, M):
    """Knot slopes s'(x_k) from second derivatives: lab equations (8) and (9)."""
    slopes = np.empty(M.size)
    slopes[:-1] = secants - h * (2.0 * M[:-1] + M[1:]) / 6.0
    slopes[-1] = secants[-1] + h[-1] * (2.0 * M[-1] + M[-2]) / 6.0
    return slopes


def _interior_system(h, secants):
    """Rows k = 1..n-2 of A M = D: continuity of s' at the interior knots.

    Row k reads h_{k-1}/6 M_{k-1} + (h_{k-1}+h_k)/3 M_k + h_k/6 M_{k+1}
    = secant_k - secant_{k-1}.
    """
    return h[:-1] / 6.0, (h[:-1] + h[1:]) / 3.0, h[1:] / 6.0, np.diff(secants)


def _prepare(xdata, ydata, name):
    """Validated knots and values in a frame of ordinary magnitude, their intervals and secants."""
    x = as_knots(xdata)
    y = as_data(ydata, x.size, "ydata")
    frame = Frame(x, y)
    x, y = frame.knots, frame.values
    with np.errstate(all="ignore"):
        h = np.diff(x)
        secants = np.diff(y) / h
    if not np.all(np.isfinite(secants)):
        frame.knot_slopes(secants, name)  # raises: the data rise too steeply for the float range
    return frame, h, secants


def ccspline(
    xdata: ArrayLike, ydata: ArrayLike, y1p: float | None = None, ynp: float | None = None
) -> NDArray[np.float64]:
    """Knot slopes of the complete cubic spline (end slopes given).

    Parameters
    ----------
    xdata : array_like, shape (n,)
        Strictly increasing knots, ``n >= 2``.
    ydata : array_like, shape (n,)
        Values at the knots.
    y1p, ynp : float
        The spline's derivative at ``xdata[0]`` and ``xdata[-1]``; required.

    Returns
    -------
    sprime : ndarray, shape (n,)
        The spline's derivative at every knot; evaluate the spline with
        ``eval_pherm(xdata, ydata, sprime, xval)``.

    Examples
    --------
    The lab's check: a cubic is reproduced, so the slopes of x**3 come back.

    >>> from labkit import ccspline
    >>> ccspline([0, 1, 2, 4], [0, 1, 8, 64], 0, 48).round(12).tolist()
    [0.0, 3.0, 12.0, 48.0]
    """
    first = as_scalar(y1p, "y1p (the slope at xdata[0])")
    last = as_scalar(ynp, "ynp (the slope at xdata[-1])")
    frame, h, secants = _prepare(xdata, ydata, "complete spline's")
    first, last = frame.slopes(first), frame.slopes(last)
    with np.errstate(all="ignore"):
        sub_i, diag_i, sup_i, rhs_i = _interior_system(h, secants)
        # First and last rows (lab eq. 10): the given end slopes close the system.
        diag = np.concatenate(([h[0] / 3.0], diag_i, [h[-1] / 3.0]))
        rhs = np.concatenate(([secants[0] - first], rhs_i, [last - secants[-1]]))
        M = _solve_tridiagonal(h / 6.0, diag, h / 6.0, rhs)
        slopes = _slopes_from_curvatures(h, secants, M)
    slopes[0], slopes[-1] = first, last
    return frame.knot_slopes(slopes, "complete spline's")


def ncspline(xdata: ArrayLike, ydata: ArrayLike) -> NDArray[np.float64]:
    """Knot slopes of the natural cubic spline (zero second derivative at the ends).

    Parameters
    ----------
    xdata : array_like, shape (n,)
        Strictly increasing knots, ``n >= 2``.
    ydata : array_like, shape (n,)
        Values at the knots.

    Returns
    -------
    sprime : ndarray, shape (n,)
        The spline's derivative at every knot.

    Examples
    --------
    Data on a line give the line's slope everywhere:

    >>> from labkit import ncspline
    >>> ncspline([0, 1, 2, 3], [0, 2, 4, 6]).tolist()
    [2.0, 2.0, 2.0, 2.0]
    """
    frame, h, secants = _prepare(xdata, ydata, "natural spline's")
    with np.errstate(all="ignore"):
        slopes = _slopes_from_curvatures(h, secants, natural_curvatures(h, secants))
    return frame.knot_slopes(slopes, "natural spline's")


def natural_curvatures(h, secants):
    """Second derivatives M of the natural spline: M_0 = M_{n-1} = 0."""
    M = np.zeros(h.size + 1)
    if h.size > 1:
        sub, diag, sup, rhs = _interior_system(h, secants)
        M[1:-1] = _solve_tridiagonal(sub[1:], diag, sup[:-1], rhs)
    return M


def nakspline(xdata: ArrayLike, ydata: ArrayLike) -> NDArray[np.float64]:
    """Knot slopes of the not-a-knot cubic spline.

    The third derivative is continuous at the second and the second-to-last
    knots, so the first two and the last two pieces are single cubics. With
    three points this is the parabola through them, with two the line.

    Parameters
    ----------
    xdata : array_like, shape (n,)
        Strictly increasing knots, ``n >= 2``.
    ydata : array_like, shape (n,)
        Values at the knots.

    Returns
    -------
    sprime : ndarray, shape (n,)
        The spline's derivative at every knot.

    Examples
    --------
    >>> from labkit import nakspline
    >>> nakspline([0, 1, 3], [0, 1, 9]).round(12).tolist()
    [0.0, 2.0, 6.0]
    """
    frame, h, secants = _prepare(xdata, ydata, "not-a-knot spline's")
    with np.errstate(all="ignore"):
        if h.size == 1:
            slopes = np.full(2, secants[0])
        elif h.size == 2:
            slopes = _parabola_slopes(h, secants)
        else:
            slopes = _slopes_from_curvatures(h, secants, _notaknot_curvatures(h, secants))
    return frame.knot_slopes(slopes, "not-a-knot spline's")


def _parabola_slopes(h, secants):
    """Slopes at the three knots of the parabola through three points."""
    curvature = 2.0 * (secants[1] - secants[0]) / (h[0] + h[1])  # = p''
    middle = secants[0] + curvature * h[0] / 2.0
    return np.array([middle - curvature * h[0], middle, middle + curvature * h[1]])


def _notaknot_curvatures(h, secants):
    """Second derivatives of the not-a-knot spline (n >= 4).

    s''' continuous at x_1 means (M_1 - M_0)/h_0 = (M_2 - M_1)/h_1, i.e.
    M_0 = ((h_0 + h_1) M_1 - h_0 M_2) / h_1, and likewise at x_{n-2}.
    Substituting those into the first and last interior rows leaves a
    strictly diagonally dominant tridiagonal system for M_1 .. M_{n-2}.
    """
    sub, diag, sup, rhs = _interior_system(h, secants)
    sub, diag, sup = sub[1:].copy(), diag.copy(), sup[:-1].copy()
    h0, h1 = h[0], h[1]
    diag[0] = (h0 + h1) * (h0 + 2.0 * h1) / (6.0 * h1)
    sup[0] = (h1 - h0) * (h1 + h0) / (6.0 * h1)
    ha, hb = h[-2], h[-1]
    diag[-1] = (ha + hb) * (2.0 * ha + hb) / (6.0 * ha)
    sub[-1] = (ha - hb) * (ha + hb) / (6.0 * ha)
    M = np.empty(h.size + 1)
    M[1:-1] = _solve_tridiagonal(sub, diag, sup, rhs)
    M[0] = ((h0 + h1) * M[1] - h0 * M[2]) / h1
    M[-1] = ((ha + hb) * M[-2] - hb * M[-3]) / ha
    return M


def spline(xdata: ArrayLike, ydata: ArrayLike, xval: ArrayLike, der: int = 0) -> float | NDArray[np.float64]:
    """Cubic spline interpolation with MATLAB's ``spline`` conventions.

    Parameters
    ----------
    xdata : array_like, shape (n,)
        Strictly increasing knots, ``n >= 2``.
    ydata : array_like, shape (n,) or (n + 2,)
        Values at the knots: the not-a-knot spline. With ``n + 2`` entries,
        the first and the last are the end slopes and the rest the values:
        the complete spline.
    xval : array_like
        Evaluation points, any shape; outside the knots the end cubics are
        extended.
    der : {0, 1, 2, 3}
        0 for the values, else that derivative (at a knot, of the piece to
        its right). The spline's first and second derivatives are continuous;
        its third jumps at the knots (``notebooks/04_splines.ipynb``).

    Returns
    -------
    yval : float or ndarray, same shape as `xval`

    Examples
    --------
    >>> from labkit import spline
    >>> x = [0, 1, 2, 4]
    >>> float(spline(x, [0, 1, 8, 64], 3.0))
    27.0
    >>> float(spline(x, [0, 0, 1, 8, 64, 48], 3.0))   # slopes 0 and 48 at the ends
    27.0
    >>> float(spline(x, [0, 1, 8, 64], 3.0, der=2))   # (x**3)'' = 6 x
    18.0
    """
    x = as_knots(xdata)
    y = as_points(ydata, "ydata")
    if y.ndim == 1 and y.size == x.size + 2:
        values = y[1:-1]
        slopes = ccspline(x, values, y[0], y[-1])
    else:
        values = as_data(y, x.size, "ydata (n values, or n + 2 with end slopes)")
        slopes = nakspline(x, values)
    xv = as_points(xval)
    return scalar_or_array(_hermite_eval(x, values, slopes, xv, as_order(der, 3)), xval)
