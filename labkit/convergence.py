"""The lab's convergence experiments: error tables and observed orders.

``convergence_table`` interpolates a function from equally spaced data of
growing size and reports the relative maximum error, the ratios between
successive errors and the order they imply. The tables the lab asks for are
printed in ``notebooks/02_convergence.ipynb``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ._validate import as_float_array, as_scalar
from .bilinear import eval_pbilin
from .errors import InputError
from .functions import runge, runge2d
from .monotone import pchip_slopes
from .piecewise import _hermite_eval, eval_plin
from .splines import ccspline, nakspline, ncspline

METHOD_TITLES = {
    "plin": "Piecewise Linear",
    "pherm": "Piecewise Hermite Cubic",
    "complete": "Complete Cubic Spline",
    "natural": "Natural Cubic Spline",
    "notaknot": "Not-A-Knot Cubic Spline",
    "pchip": "Monotone Cubic Interpolation",
}
NEEDS_DERIVATIVE = {"pherm", "complete"}
DEFAULT_NDATA = (5, 11, 21, 41, 81, 161, 321, 641)


@dataclass(frozen=True)
class ConvergenceTable:
    """Errors of one interpolation method for growing data sizes.

    Attributes
    ----------
    title : str
        First line of the printed table, e.g. ``"Runge function, Natural Cubic Spline"``.
    ndata : ndarray of int
        Number of data points of each row.
    errors : ndarray
        ``max|f - p| / max|f|`` over the test points, one per row.
    ratios : ndarray
        ``errors[i] / errors[i+1]`` (one fewer than rows).
    rates : ndarray
        Observed order of each ratio: ``log(ratio) / log(h_i / h_{i+1})``.
    order : int
        The estimated order: the nearest integer to the mean of the
        observed rates of the three finest ratios.
    """

    title: str
    ndata: NDArray[np.int_]
    errors: NDArray[np.float64]

    @property
    def ratios(self) -> NDArray[np.float64]:
        return self.errors[:-1] / self.errors[1:]

    @property
    def rates(self) -> NDArray[np.float64]:
        spacing_ratio = (self.ndata[1:] - 1) / (self.ndata[:-1] - 1)
        return np.log(self.ratios) / np.log(spacing_ratio)

    @property
    def order(self) -> int:
        return int(np.rint(np.mean(self.rates[-3:])))

    def __str__(self) -> str:
        return _rows(self.title, self.ndata, self.errors) + f"\nEstimated order of convergence: {self.order}"


def _rows(title, ndata, errors):
    lines = [title]
    for i, (n, err) in enumerate(zip(ndata, errors)):
        row = f"ndata ={n:3d}  Err({n:3d}) = {err:10.3e}"
        if i:
            row += f"  Err({ndata[i - 1]:3d})/Err({n:3d}) = {errors[i - 1] / err:8.3f}"
        lines.append(row)
    return "\n".join(lines)


def ratio_table(title: str, ndata: ArrayLike, errors: ArrayLike) -> str:
    """The lab's table layout for your own errors: each row's error and its ratio to the row above.

    Unlike ``str(convergence_table(...))`` it does not state an order: reading
    the order off the ratios is the exercise.

    Parameters
    ----------
    title : str
        First line, e.g. ``"Runge function, Piecewise Hermite Cubic"``.
    ndata : sequence of int
        Number of data points of each row.
    errors : sequence of float
        The error of each row, as your driver returns them.

    Returns
    -------
    str

    Examples
    --------
    >>> from labkit import ratio_table
    >>> print(ratio_table("halving", [3, 5, 9], [0.4, 0.1, 0.025]))
    halving
    ndata =  3  Err(  3) =  4.000e-01
    ndata =  5  Err(  5) =  1.000e-01  Err(  3)/Err(  5) =    4.000
    ndata =  9  Err(  9) =  2.500e-02  Err(  5)/Err(  9) =    4.000
    """
    sizes = _sizes(ndata)
    values = as_float_array(errors, "errors")
    if values.shape != sizes.shape:
        raise InputError(
            f"errors has {values.size} entries but ndata has {sizes.size}; give one error per row "
            "(e.g. [test_pherm_interpolate(n) for n in ndata])."
        )
    if not np.all(np.isfinite(values)) or np.any(values <= 0):
        raise InputError(
            "every error must be a positive finite number; a zero or NaN error means the driver "
            "measured at the wrong points or failed."
        )
    return _rows(str(title), sizes, values)


def convergence_table(
    method: Literal["plin", "pherm", "complete", "natural", "notaknot", "pchip"],
    ndata: ArrayLike = DEFAULT_NDATA,
    f: Callable[[NDArray[np.float64]], ArrayLike | tuple[ArrayLike, ArrayLike]] = runge,
    interval: tuple[float, float] = (0.0, 5.0),
    ntest: int = 4001,
) -> ConvergenceTable:
    """Interpolation errors of `method` on equally spaced data, as in the lab.

    Parameters
    ----------
    method : {'plin', 'pherm', 'complete', 'natural', 'notaknot', 'pchip'}
        Piecewise linear, piecewise Hermite, and the complete, natural and
        not-a-knot cubic splines, or monotone cubic (pchip) interpolation.
    ndata : sequence of int
        Data sizes, each at least 2 (4 for 'notaknot' to be a true spline).
    f : callable
        ``f(x)`` returning values, or ``(values, derivatives)`` as
        :func:`labkit.runge` does; 'pherm' and 'complete' need derivatives
        ('complete' uses them at the two ends only).
    interval : (float, float)
        Where the data and test points lie.
    ntest : int
        Number of equally spaced test points.

    Returns
    -------
    ConvergenceTable
        ``str()`` of it is the table in the lab's layout.

    Examples
    --------
    >>> from labkit import convergence_table
    >>> table = convergence_table("pherm")
    >>> table.order
    4
    >>> print(str(table).splitlines()[2])
    ndata = 11  Err( 11) =  1.252e-03  Err(  5)/Err( 11) =   28.446
    """
    if not isinstance(method, str) or method not in METHOD_TITLES:
        raise InputError(f"unknown method {method!r}; choose one of {', '.join(map(repr, METHOD_TITLES))}.")
    sizes = _sizes(ndata)
    a, b = _check_interval(interval)
    xtest = np.linspace(a, b, _count(ntest, "ntest"))
    exact, _ = _values_and_slopes(f, xtest, method)
    scale = np.max(np.abs(exact))
    errors = np.array([np.max(np.abs(exact - _interpolate(method, f, a, b, n, xtest))) / scale for n in sizes])
    name = "Runge function" if f is runge else getattr(f, "__name__", "f")
    return ConvergenceTable(f"{name}, {METHOD_TITLES[method]}", sizes, errors)


def _sizes(ndata):
    """ndata: at least two whole numbers, each at least 2."""
    sizes = as_float_array(ndata, "ndata")
    if sizes.ndim != 1 or sizes.size < 2 or not np.all(np.isfinite(sizes)) or np.any(sizes != np.round(sizes)):
        raise InputError("ndata must be a sequence of at least two whole numbers of points.")
    if np.any(sizes < 2):
        raise InputError("every entry of ndata must be at least 2 (one interval).")
    return sizes.astype(int)


def _count(value, name):
    """A whole number of test points, at least 2."""
    number = as_scalar(value, name)
    if number != round(number) or number < 2:
        raise InputError(f"{name} must be a whole number of test points, at least 2; got {value!r}.")
    return int(number)


def _check_interval(interval, name="interval"):
    ends = as_float_array(interval, name)
    if ends.shape != (2,):
        raise InputError(f"{name} must be a pair (a, b) of numbers.")
    a, b = float(ends[0]), float(ends[1])
    if not (np.isfinite(a) and np.isfinite(b) and a < b):
        raise InputError(f"interval must satisfy a < b with finite ends; got ({a}, {b}).")
    return a, b


def _values_and_slopes(f, x, method):
    out = f(x)
    if isinstance(out, tuple):
        return np.asarray(out[0], dtype=float), np.asarray(out[1], dtype=float)
    if method in NEEDS_DERIVATIVE:
        raise InputError(
            f"method {method!r} needs derivatives: f must return (values, derivatives) as labkit.runge does."
        )
    return np.asarray(out, dtype=float), None


def _interpolate(method, f, a, b, n, xtest):
    """Build the interpolant of f from n equally spaced points; evaluate it."""
    x = np.linspace(a, b, n)
    y, yp = _values_and_slopes(f, x, method)
    if method == "plin":
        return eval_plin(x, y, xtest)
    slopes = {
        "pherm": lambda: yp,
        "complete": lambda: ccspline(x, y, yp[0], yp[-1]),
        "natural": lambda: ncspline(x, y),
        "notaknot": lambda: nakspline(x, y),
        "pchip": lambda: pchip_slopes(x, y),
    }[method]()
    return _hermite_eval(x, y, slopes, xtest)


def bilinear_convergence(
    ndata: ArrayLike = (11, 21, 41, 81, 161),
    f: Callable[[NDArray[np.float64], NDArray[np.float64]], ArrayLike] = runge2d,
    square: tuple[float, float] = (0.0, 5.0),
    ntest: int = 401,
) -> ConvergenceTable:
    """Errors of piecewise bilinear interpolation on a square, as in exercise 16.

    Data on an ``n x n`` equally spaced grid of `square` squared; the error
    is ``max|f - I| / max|f|`` on an ``ntest x ntest`` grid of test points.

    Returns
    -------
    ConvergenceTable

    Examples
    --------
    >>> from labkit import bilinear_convergence
    >>> bilinear_convergence().order
    2
    """
    sizes = _sizes(ndata)
    a, b = _check_interval(square, "square")
    test = np.linspace(a, b, _count(ntest, "ntest"))
    X, Y = np.meshgrid(test, test, indexing="ij")
    exact = np.asarray(f(X, Y), dtype=float)
    scale = np.max(np.abs(exact))
    errors = []
    for n in sizes:
        grid = np.linspace(a, b, n)
        errors.append(np.max(np.abs(exact - eval_pbilin(f, grid, grid, test, test))) / scale)
    name = "Runge2d function" if f is runge2d else getattr(f, "__name__", "f")
    return ConvergenceTable(f"{name}, Piecewise Bilinear", sizes, np.array(errors))
