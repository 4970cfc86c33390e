"""Piecewise linear and piecewise cubic Hermite interpolation.

The maths (the four Hermite basis cubics and why their combination is C1) is
derived in ``notebooks/02_convergence.ipynb``; the parametric use of both
interpolants is in ``notebooks/01_limacon.ipynb``.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ._frame import Frame
from ._locate import blockwise, locate
from ._validate import as_data, as_float_array, as_knots, as_order, as_points, scalar_or_array


def bracket(xdata: ArrayLike, xval: ArrayLike) -> np.intp | NDArray[np.intp]:
    """Index of the data interval that holds each evaluation point.

    Parameters
    ----------
    xdata : array_like, shape (n,)
        Strictly increasing data points, ``n >= 2``.
    xval : array_like
        Points to locate; any shape.

    Returns
    -------
    k : int or ndarray of int, same shape as `xval`
        ``xdata[k] <= xval < xdata[k+1]``, clipped to ``[0, n-2]`` so that
        points left of the data use the first interval and points at or
        right of ``xdata[-1]`` use the last one. A NaN point gets some valid
        index (every interpolant gives NaN there).

    Examples
    --------
    >>> from labkit import bracket
    >>> bracket([0.0, 1.0, 2.0, 4.0], [-1.0, 0.0, 1.5, 4.0, 9.0]).tolist()
    [0, 0, 1, 2, 2]
    """
    x = as_knots(xdata)
    xv = as_points(xval)
    return scalar_or_array(locate(x, xv), xval)


def eval_plin(xdata: ArrayLike, ydata: ArrayLike, xval: ArrayLike, der: int = 0) -> float | NDArray[np.float64]:
    """Piecewise linear interpolant of ``(xdata, ydata)`` evaluated at `xval`.

    Parameters
    ----------
    xdata : array_like, shape (n,)
        Strictly increasing data points, ``n >= 2``.
    ydata : array_like, shape (n,)
        Data values.
    xval : array_like
        Evaluation points, any shape. Points outside the data are
        extrapolated linearly from the end pieces; NaN gives NaN.
    der : {0, 1}
        0 for the values, 1 for the slope of the piece that holds each point
        (at a data point, the piece to its right; outside, the end pieces).

    Returns
    -------
    yval : float or ndarray, same shape as `xval`

    Examples
    --------
    >>> from labkit import eval_plin
    >>> eval_plin([0, 1, 3], [0, 2, 3], [0.5, 2.0, 4.0]).tolist()
    [1.0, 2.5, 3.5]
    >>> eval_plin([0, 1, 3], [0, 2, 3], [0.5, 2.0, 4.0], der=1).tolist()
    [2.0, 0.5, 0.5]
    """
    x = as_knots(xdata)
    y = as_data(ydata, x.size, "ydata")
    xv = as_points(xval)
    der = as_order(der, 1)
    frame = Frame(x, y)
    x, y, xv = frame.knots, frame.values, frame.points(xv)
    with np.errstate(all="ignore"):
        slope = np.diff(y)
        slope /= np.diff(x)

    def line(k, p, out):
        if der:
            out[...] = np.take(slope, k)
            return
        np.subtract(p, np.take(x, k), out=out)
        out *= np.take(slope, k)
        out += np.take(y, k)

    return scalar_or_array(frame.result(blockwise(x, xv, line), der, xv), xval)


def hermite_basis(
    xk: ArrayLike, xk1: ArrayLike, x: ArrayLike, der: int = 0
) -> tuple[
    float | NDArray[np.float64], float | NDArray[np.float64], float | NDArray[np.float64], float | NDArray[np.float64]
]:
    """The four cubic Hermite basis polynomials on the interval ``[xk, xk1]``, or their derivatives.

    ``h1`` and ``h3`` carry the values at the left and right ends, ``h2`` and
    ``h4`` the derivatives: ``h1(xk) = 1``, ``h2'(xk) = 1``, ``h3(xk1) = 1``,
    ``h4'(xk1) = 1`` and every other value and slope at the two ends is 0.

    Parameters
    ----------
    xk, xk1 : float or ndarray
        Left and right ends of the interval (broadcast against `x`).
    x : float or ndarray
        Evaluation points.
    der : {0, 1, 2, 3}
        Which derivative of the four polynomials (0: the polynomials).

    Returns
    -------
    h1, h2, h3, h4 : float or ndarray
        Of the broadcast shape of `xk`, `xk1` and `x`; floats if all three
        are scalars.

    Examples
    --------
    >>> from labkit import hermite_basis
    >>> [float(h) for h in hermite_basis(0.0, 2.0, 1.0)]
    [0.5, 0.25, 0.5, -0.25]
    >>> [float(h) for h in hermite_basis(0.0, 2.0, 1.0, der=1)]   # h1' = -h3' = -3/(2h) in the middle
    [-0.75, -0.25, 0.75, -0.25]
    """
    der = as_order(der, 3)
    xk = as_float_array(xk, "xk")
    h = as_float_array(xk1, "xk1") - xk
    # t is the position inside the interval scaled to [0, 1]; in that variable
    # the lab's formulas become polynomials with the length h factored out,
    # and each derivative in x is a derivative in t divided by h.
    t = (as_float_array(x, "x") - xk) / h
    s = 1.0 - t
    if der == 0:
        return s * s * (1.0 + 2.0 * t), h * t * s * s, t * t * (3.0 - 2.0 * t), -h * t * t * s
    if der == 1:
        h1 = 6.0 * t * (t - 1.0) / h
        return h1, s * (1.0 - 3.0 * t), -h1, t * (3.0 * t - 2.0)
    if der == 2:
        h1 = (12.0 * t - 6.0) / (h * h)
        return h1, (6.0 * t - 4.0) / h, -h1, (6.0 * t - 2.0) / h
    ones = np.ones_like(t)
    return 12.0 / h**3 * ones, 6.0 / (h * h) * ones, -12.0 / h**3 * ones, 6.0 / (h * h) * ones


def eval_pherm(
    xdata: ArrayLike, ydata: ArrayLike, ypdata: ArrayLike, xval: ArrayLike, der: int = 0
) -> float | NDArray[np.float64]:
    """Piecewise cubic Hermite interpolant from values and slopes, or its derivatives.

    On each interval ``[x_k, x_{k+1}]`` the interpolant is
    ``y_k h1 + y'_k h2 + y_{k+1} h3 + y'_{k+1} h4`` with the basis of
    :func:`hermite_basis`, so it matches values and first derivatives at
    every data point and is continuously differentiable (its second
    derivative jumps at the data points: see ``notebooks/04_splines.ipynb``).

    Parameters
    ----------
    xdata : array_like, shape (n,)
        Strictly increasing data points, ``n >= 2``.
    ydata, ypdata : array_like, shape (n,)
        Values and derivatives at `xdata`.
    xval : array_like
        Evaluation points, any shape. Points outside the data use the cubic
        of the nearest end interval; NaN gives NaN.
    der : {0, 1, 2, 3}
        0 for the values, else that derivative (at a data point, of the piece
        to its right).

    Returns
    -------
    yval : float or ndarray, same shape as `xval`

    Raises
    ------
    ValueError
        If the input is not real numbers, or a value is beyond the float
        range (a point far outside the data, or slopes too steep).

    Examples
    --------
    Cubics are reproduced exactly, inside and outside the data, and so are
    their derivatives:

    >>> from labkit import eval_pherm
    >>> x = [0.0, 2.0]
    >>> eval_pherm(x, [0.0, 8.0], [0.0, 12.0], [-1.0, 1.0, 3.0]).tolist()
    [-1.0, 1.0, 27.0]
    >>> eval_pherm(x, [0.0, 8.0], [0.0, 12.0], [-1.0, 1.0, 3.0], der=2).tolist()
    [-6.0, 6.0, 18.0]
    """
    x = as_knots(xdata)
    y = as_data(ydata, x.size, "ydata")
    yp = as_data(ypdata, x.size, "ypdata")
    xv = as_points(xval)
    return scalar_or_array(_hermite_eval(x, y, yp, xv, as_order(der, 3)), xval)


def _power_form(x, y, yp, der):
    """Each interval's cubic (or its `der`-th derivative) in powers of ``x - x_k``, highest power first.

    Offsets from the left knot keep a straight line's higher coefficients at zero, so far outside
    closely spaced data the cubic does not cancel large terms (as the basis form would).
    """
    h = np.diff(x)
    delta = np.diff(y) / h
    c2 = (3 * delta - 2 * yp[:-1] - yp[1:]) / h
    c3 = (yp[:-1] + yp[1:] - 2 * delta) / h**2
    powers = [c3, c2, yp[:-1], y[:-1]]
    for _ in range(der):
        powers = [c * (len(powers) - 1 - i) for i, c in enumerate(powers[:-1])]
    return powers


def _hermite_eval(x, y, yp, xv, der=0):
    """Evaluate validated Hermite data (or a derivative); shared by the splines and pchip.

    Very large or very small numbers are handled in a frame scaled by powers
    of two (:class:`labkit._frame.Frame`), so the cubic never overflows on the
    way to a representable answer.
    """
    frame = Frame(x, y)
    x, y, yp, xv = frame.knots, frame.values, frame.slopes(yp), frame.points(xv)
    with np.errstate(all="ignore"):
        coefficients = _power_form(x, y, yp, der)

    def cubic(k, p, out):
        d = p - np.take(x, k)
        np.take(coefficients[0], k, out=out)
        for c in coefficients[1:]:
            out *= d
            out += np.take(c, k)

    with np.errstate(all="ignore"):
        values = blockwise(x, xv, cubic)
    return frame.result(values, der, xv)
