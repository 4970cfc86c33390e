"""Piecewise linear and piecewise cubic Hermite interpolation.

The maths (the four Hermite basis cubics and why their combination is C1) is
derived in ``notebooks/02_convergence.ipynb``; the parametric use of both
interpolants is in ``notebooks/01_limacon.ipynb``.
"""
import numpy as np

from ._locate import blockwise, locate
from ._validate import as_data, as_knots, as_points, scalar_or_array


def bracket(xdata, xval):
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


def eval_plin(xdata, ydata, xval):
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

    Returns
    -------
    yval : float or ndarray, same shape as `xval`

    Examples
    --------
    >>> from labkit import eval_plin
    >>> eval_plin([0, 1, 3], [0, 2, 3], [0.5, 2.0, 4.0]).tolist()
    [1.0, 2.5, 3.5]
    """
    x = as_knots(xdata)
    y = as_data(ydata, x.size, "ydata")
    xv = as_points(xval)
    slope = np.diff(y)
    slope /= np.diff(x)

    def line(k, p, out):
        np.subtract(p, np.take(x, k), out=out)
        out *= np.take(slope, k)
        out += np.take(y, k)

    return scalar_or_array(blockwise(x, xv, line), xval)


def hermite_basis(xk, xk1, x):
    """The four cubic Hermite basis polynomials on the interval ``[xk, xk1]``.

    ``h1`` and ``h3`` carry the values at the left and right ends, ``h2`` and
    ``h4`` the derivatives: ``h1(xk) = 1``, ``h2'(xk) = 1``, ``h3(xk1) = 1``,
    ``h4'(xk1) = 1`` and every other value and slope at the two ends is 0.

    Parameters
    ----------
    xk, xk1 : float or ndarray
        Left and right ends of the interval (broadcast against `x`).
    x : float or ndarray
        Evaluation points.

    Returns
    -------
    h1, h2, h3, h4 : ndarray

    Examples
    --------
    >>> from labkit import hermite_basis
    >>> [float(h) for h in hermite_basis(0.0, 2.0, 1.0)]
    [0.5, 0.25, 0.5, -0.25]
    """
    h = np.asarray(xk1, dtype=float) - xk
    # t is the position inside the interval scaled to [0, 1]; in that variable
    # the lab's formulas become polynomials with the length h factored out.
    t = (np.asarray(x, dtype=float) - xk) / h
    s = 1.0 - t
    h1 = s * s * (1.0 + 2.0 * t)
    h2 = h * t * s * s
    h3 = t * t * (3.0 - 2.0 * t)
    h4 = -h * t * t * s
    return h1, h2, h3, h4


def eval_pherm(xdata, ydata, ypdata, xval):
    """Piecewise cubic Hermite interpolant from values and slopes.

    On each interval ``[x_k, x_{k+1}]`` the interpolant is
    ``y_k h1 + y'_k h2 + y_{k+1} h3 + y'_{k+1} h4`` with the basis of
    :func:`hermite_basis`, so it matches values and first derivatives at
    every data point and is continuously differentiable.

    Parameters
    ----------
    xdata : array_like, shape (n,)
        Strictly increasing data points, ``n >= 2``.
    ydata, ypdata : array_like, shape (n,)
        Values and derivatives at `xdata`.
    xval : array_like
        Evaluation points, any shape. Points outside the data use the cubic
        of the nearest end interval; NaN gives NaN.

    Returns
    -------
    yval : float or ndarray, same shape as `xval`

    Examples
    --------
    Cubics are reproduced exactly, inside and outside the data:

    >>> from labkit import eval_pherm
    >>> x = [0.0, 2.0]
    >>> eval_pherm(x, [0.0, 8.0], [0.0, 12.0], [-1.0, 1.0, 3.0]).tolist()
    [-1.0, 1.0, 27.0]
    """
    x = as_knots(xdata)
    y = as_data(ydata, x.size, "ydata")
    yp = as_data(ypdata, x.size, "ypdata")
    xv = as_points(xval)
    return scalar_or_array(_hermite_eval(x, y, yp, xv), xval)


def _hermite_eval(x, y, yp, xv):
    """Evaluate validated Hermite data; shared by the splines and pchip."""

    def cubic(k, p, out):
        right = k + 1
        h1, h2, h3, h4 = hermite_basis(np.take(x, k), np.take(x, right), p)
        np.multiply(h1, np.take(y, k), out=out)
        h2 *= np.take(yp, k)
        h3 *= np.take(y, right)
        h4 *= np.take(yp, right)
        out += h2
        out += h3
        out += h4

    return blockwise(x, xv, cubic)
