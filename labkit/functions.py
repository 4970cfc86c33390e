"""Test functions of the lab: the Runge function in one and two variables."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ._validate import as_float_array, as_positive_scalar, as_scalar, scalar_or_array


def runge(x: ArrayLike, a: float = 1.0) -> tuple[float | NDArray[np.float64], float | NDArray[np.float64]]:
    """The Runge function ``1 / (1 + a x**2)`` and its derivative.

    Parameters
    ----------
    x : array_like
        Points, any shape.
    a : float, optional
        The positive scale of ``x**2``; the lab's function has ``a = 1``, and a
        student's own variant of the lab may have another
        (:mod:`labkit.exercises.variants`).

    Returns
    -------
    y, yprime : float or ndarray, same shape as `x`
        ``y = 1/(1+a x^2)`` and ``y' = -2ax/(1+a x^2)^2``.

    Raises
    ------
    ValueError
        If `a` is not one positive finite number.

    Examples
    --------
    >>> from labkit import runge
    >>> [float(v) for v in runge(1.0)]
    [0.5, -0.5]
    >>> [float(v) for v in runge(1.0, a=3.0)]
    [0.25, -0.375]
    """
    xa = as_float_array(x, "x")
    scale = as_positive_scalar(a, "a", "the Runge function's scale, 1/(1 + a x^2)")
    # the lab's a = 1 multiplies exactly, so its values are the same bits as 1/(1+x^2)
    y = 1.0 / (1.0 + scale * (xa * xa))
    yprime = -2.0 * xa * (scale * y) * y  # finite for any finite scale
    return scalar_or_array(y, x), scalar_or_array(yprime, x)


def runge2d(x: ArrayLike, y: ArrayLike, a: float = 1.0) -> float | NDArray[np.float64]:
    """The two-dimensional Runge function ``1 / (1 + a (x + y)**2)``.

    `x` and `y` broadcast against each other, so ``runge2d(X, Y)`` on
    ``np.meshgrid(..., indexing='ij')`` grids gives a table of values. `a` is
    the positive scale (the lab's function has ``a = 1``; a student's own
    variant of the lab may have another).

    Examples
    --------
    >>> from labkit import runge2d
    >>> float(runge2d(0.5, 0.5))
    0.5
    >>> float(runge2d(0.5, 0.5, a=3.0))
    0.25
    """
    s = as_float_array(x, "x") + as_float_array(y, "y")
    scale = as_positive_scalar(a, "a", "the Runge function's scale, 1/(1 + a (x+y)^2)")
    return scalar_or_array(1.0 / (1.0 + scale * (s * s)), s)


def limacon(
    t: ArrayLike, r0: float = 1.15
) -> tuple[
    float | NDArray[np.float64], float | NDArray[np.float64], float | NDArray[np.float64], float | NDArray[np.float64]
]:
    """The limaçon r = r0 + cos t as a parametric curve, with its t-derivatives.

    Parameters
    ----------
    t : array_like
        Parameter values (a full turn is 0 .. 2 pi).
    r0 : float
        Offset of the radius; r0 = 1 is the cardioid.

    Returns
    -------
    x, y, dxdt, dydt : float or ndarray, same shape as `t`
        ``x = r cos t``, ``y = r sin t`` and their derivatives.

    Examples
    --------
    >>> from labkit import limacon
    >>> [round(float(v), 12) + 0.0 for v in limacon(0.0, r0=1.0)]
    [2.0, 0.0, 0.0, 2.0]
    """
    ta = as_float_array(t, "t")
    r = as_scalar(r0, "r0") + np.cos(ta)
    drdt = -np.sin(ta)
    x, y = r * np.cos(ta), r * np.sin(ta)
    return x, y, drdt * np.cos(ta) - y, drdt * np.sin(ta) + x
