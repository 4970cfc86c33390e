"""Monotone piecewise cubic interpolation (MATLAB's ``pchip``).

Fritsch and Carlson showed which knot slopes keep a piecewise cubic Hermite
interpolant monotone on every interval where the data are; the choice below
(a weighted harmonic mean of the neighbouring secants, zero at a local
extremum, a clamped three-point formula at the ends) is the one MATLAB and
scipy use. See ``notebooks/05_monotone.ipynb``.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ._frame import Frame
from ._validate import as_data, as_knots, as_order, as_points, scalar_or_array
from .piecewise import _hermite_eval


def pchip_slopes(xdata: ArrayLike, ydata: ArrayLike) -> NDArray[np.float64]:
    """Knot slopes of the shape-preserving piecewise cubic interpolant.

    Parameters
    ----------
    xdata : array_like, shape (n,)
        Strictly increasing knots, ``n >= 2``.
    ydata : array_like, shape (n,)
        Values at the knots.

    Returns
    -------
    slopes : ndarray, shape (n,)

    Examples
    --------
    Flat data next to rising data get a zero slope where the rise stops:

    >>> from labkit import pchip_slopes
    >>> pchip_slopes([0, 1, 2, 3, 4], [0, 1, 2, 2, 2]).tolist()
    [1.0, 1.0, 0.0, 0.0, 0.0]
    """
    x = as_knots(xdata)
    y = as_data(ydata, x.size, "ydata")
    frame = Frame(x, y)
    with np.errstate(all="ignore"):
        h = np.diff(frame.knots)
        delta = np.diff(frame.values) / h
        if not np.all(np.isfinite(delta)):
            frame.knot_slopes(delta, "pchip")  # raises: the data rise too steeply for the float range
        if x.size == 2:
            return frame.knot_slopes(np.full(2, delta[0]), "pchip")
        slopes = np.empty(x.size)
        slopes[1:-1] = _interior_slopes(h, delta)
        slopes[0] = _end_slope(h[0], h[1], delta[0], delta[1])
        slopes[-1] = _end_slope(h[-1], h[-2], delta[-1], delta[-2])
    return frame.knot_slopes(slopes, "pchip")


def _interior_slopes(h, delta):
    """Weighted harmonic mean of neighbouring secants; 0 at a sign change."""
    left, right = delta[:-1], delta[1:]
    w1 = 2.0 * h[1:] + h[:-1]
    w2 = h[1:] + 2.0 * h[:-1]
    same_sign = np.sign(left) * np.sign(right) > 0  # a product of tiny secants could underflow to 0
    with np.errstate(all="ignore"):
        mean = (w1 + w2) / (w1 / left + w2 / right)
    return np.where(same_sign, mean, 0.0)


def _end_slope(h_end, h_next, delta_end, delta_next):
    """One-sided three-point slope, clamped so the end piece stays monotone."""
    slope = ((2.0 * h_end + h_next) * delta_end - h_end * delta_next) / (h_end + h_next)
    if np.sign(slope) != np.sign(delta_end):
        return 0.0
    if np.sign(delta_end) != np.sign(delta_next) and abs(slope) > abs(3.0 * delta_end):
        return 3.0 * delta_end
    return slope


def pchip(xdata: ArrayLike, ydata: ArrayLike, xval: ArrayLike, der: int = 0) -> float | NDArray[np.float64]:
    """Evaluate the shape-preserving piecewise cubic interpolant.

    Parameters
    ----------
    xdata : array_like, shape (n,)
        Strictly increasing knots, ``n >= 2``.
    ydata : array_like, shape (n,)
        Values at the knots.
    xval : array_like
        Evaluation points, any shape; outside the knots the end cubics are
        extended.
    der : {0, 1, 2, 3}
        0 for the values, else that derivative (at a knot, of the piece to
        its right). pchip is only C1: its second derivative jumps at the knots.

    Returns
    -------
    yval : float or ndarray, same shape as `xval`

    Examples
    --------
    >>> from labkit import pchip
    >>> pchip([0, 1, 2, 3, 4], [0, 1, 2, 2, 2], [2.5, 3.5]).tolist()
    [2.0, 2.0]
    >>> pchip([0, 1, 2, 3, 4], [0, 1, 2, 2, 2], [0.5, 2.5], der=1).tolist()
    [1.0, 0.0]
    """
    x = as_knots(xdata)
    y = as_data(ydata, x.size, "ydata")
    xv = as_points(xval)
    return scalar_or_array(_hermite_eval(x, y, pchip_slopes(x, y), xv, as_order(der, 3)), xval)
