"""Checks for exercises 10 and 12: the complete and the natural cubic spline.

The maths is derived in ``notebooks/04_splines.ipynb``. References are
labkit's splines (:func:`labkit.ccspline`, :func:`labkit.ncspline`), the
lab's equations (11)-(12) for the matrix, and cubics the complete spline
must reproduce exactly.
"""
import numpy as np

from .. import piecewise, splines
from .result import CheckResult, call, case_rng, close, shown, worst

SPLINE_CASES = [
    ("x^3 on [0 1 2 4] (exercise 10g)", [0.0, 1.0, 2.0, 4.0], [0.0, 1.0, 8.0, 64.0], 0.0, 48.0),
    ("x^3 on [0 1 2] (equal intervals)", [0.0, 1.0, 2.0], [0.0, 1.0, 8.0], 0.0, 12.0),
    ("x^3 on [0 1 3]", [0.0, 1.0, 3.0], [0.0, 1.0, 27.0], 0.0, 27.0),
]


def _reference_complete_system(xdata, ydata, y1p, ynp):
    h = np.diff(xdata)
    secants = np.diff(ydata) / h
    diagonal = np.concatenate(([h[0] / 3], (h[:-1] + h[1:]) / 3, [h[-1] / 3]))
    A = np.diag(diagonal) + np.diag(h / 6, 1) + np.diag(h / 6, -1)
    D = np.concatenate(([secants[0] - y1p], np.diff(secants), [ynp - secants[-1]]))
    return A, D


def _part(AD, index):
    """AD[index], or None if the student's value has no such part."""
    try:
        return AD[index]
    except (TypeError, IndexError, KeyError):
        return None


def _matrix(AD):
    """The float matrix A of a student's (A, D), or None if it is not one."""
    try:
        A = np.asarray(_part(AD, 0), dtype=float)
    except (TypeError, ValueError):
        return None
    return A if A.ndim == 2 and np.all(np.isfinite(A)) else None


def ccspline(fn, system=None, seed=None):
    """Check ``ccspline(xdata, ydata, y1p, ynp)``; with ``system(xdata, ydata, y1p, ynp) -> (A, D)``
    also the matrix (symmetric, diagonally dominant, equal to equations 11-12)."""
    result = CheckResult("ccspline")
    name, x, y, y1p, ynp = SPLINE_CASES[0]
    ok, sprime = call(result, name, fn, np.array(x), np.array(y), y1p, ynp)
    if not ok:
        return result
    expected = 3 * np.array(x) ** 2
    if result.step(f"{name}: slopes [0 3 12 48]", close(sprime, expected),
                   "" if close(sprime, expected) else f"got {shown(sprime)}"):
        rng = case_rng(seed, "splines.ccspline")
        xr = np.cumsum(rng.uniform(0.2, 1.5, 9))
        yr = rng.normal(size=9)
        ok, got = call(result, "random data", fn, xr, yr, 0.3, -0.7)
        if ok:
            want = splines.ccspline(xr, yr, 0.3, -0.7)
            if not result.step("random unequal data agree with labkit.ccspline", close(got, want), worst(got, want)):
                result.hint = "check the loop bounds: every interior row k uses h(k-1) and h(k)."
        return result
    if system is not None:
        ok, AD = call(result, "the matrix A", system, np.array(x), np.array(y), y1p, ynp)
        if not ok:
            return result
        A = _matrix(AD)
        if A is None:
            return result.fail("the matrix A", "complete_system must return (A, D) with A a matrix of numbers",
                               "end the function with `return A, D`.")
        if not result.step("A is symmetric", A.shape == (4, 4) and np.allclose(A, A.T)):
            result.hint = "A(k, k-1) and A(k-1, k) must both be h(k-1)/6."
            return result
        off = np.abs(A).sum(axis=1) - np.abs(np.diag(A))
        if not result.step("each diagonal entry exceeds the rest of its row (Gershgorin)", np.all(np.diag(A) > off)):
            result.hint = "the diagonal is (h(k-1) + h(k))/3 inside and h/3 in the first and last rows."
            return result
    name2, x2, y2, a2, b2 = SPLINE_CASES[1]
    ok, sprime2 = call(result, name2, fn, np.array(x2), np.array(y2), a2, b2)
    if not ok:
        return result
    if result.step(name2, close(sprime2, 3 * np.array(x2) ** 2), f"got {shown(sprime2)}"):
        result.hint = ("equal intervals work and unequal ones do not: a subscript of h is off "
                       "(h(k) = x(k+1) - x(k); row k uses h(k-1) and h(k)).")
        return result
    name3, x3, y3, a3, b3 = SPLINE_CASES[2]
    if system is not None:
        ok, AD = call(result, "A and D for [0 1 3]", system, np.array(x3), np.array(y3), a3, b3)
        if not ok:
            return result
        A_ref, D_ref = _reference_complete_system(np.array(x3), np.array(y3), a3, b3)
        if _matrix(AD) is None:
            return result.fail("A and D for [0 1 3]", "complete_system must return (A, D) with A a matrix of numbers",
                               "end the function with `return A, D`.")
        if not result.step("A for xdata = [0 1 3] matches equation (11)", close(AD[0], A_ref), worst(AD[0], A_ref)):
            result.hint = "compute the 3 x 3 matrix by hand from (11) and compare entry by entry."
            return result
        if not result.step("D for xdata = [0 1 3] matches equation (12)", close(_part(AD, 1), D_ref), worst(_part(AD, 1), D_ref)):
            result.hint = "compute D by hand from (12): first and last entries use y1p and ynp."
            return result
    result.hint = ("A and D are right, so the slopes are wrong: s'(x_k) = -M_k h_k/3 - M_{k+1} h_k/6 + "
                   "(y_{k+1} - y_k)/h_k (equation 8), with s'(x_1) = y1p and s'(x_n) = ynp.")
    return result


def ncspline(fn, seed=None):
    """Check ``ncspline(xdata, ydata)``: the lab's linear case, zero end curvature, labkit's reference."""
    result = CheckResult("ncspline")
    ok, sprime = call(result, "linear data [0 2 4 6]", fn, np.array([0.0, 1.0, 2.0, 3.0]), np.array([0.0, 2.0, 4.0, 6.0]))
    if not ok:
        return result
    linear_ok = result.step("linear data y = 2x give slopes 2", close(sprime, [2.0] * 4),
                            "" if close(sprime, [2.0] * 4) else f"got {shown(sprime)}")
    x = np.array([0.0, 0.7, 1.5, 2.0, 3.2, 4.0]) if seed is None else np.cumsum(case_rng(seed, "splines.ncspline").uniform(0.2, 1.5, 6))
    y = np.exp(x / 2)
    ok, slopes = call(result, "a nonlinear function", fn, x, y)
    if not ok:
        return result
    try:
        # s'' at the two ends of the piecewise cubic with these knot slopes
        ends = piecewise.eval_pherm(x, y, slopes, x[[0, -1]], der=2)
    except (ValueError, IndexError, TypeError):
        return result.fail("slopes for six knots", f"got {slopes!r}", "return one slope per knot.")
    if not result.step("second derivative zero at both ends (M1 = Mn = 0)", close(ends, [0.0, 0.0]), f"s'' = {np.round(ends, 6)}"):
        result.hint = ("the first and last rows of A must say M1 = 0 and Mn = 0 (1 on the diagonal, 0 elsewhere, "
                       "0 in D): they are still the complete spline's rows.")
        return result
    want = splines.ncspline(x, y)
    if not result.step("slopes agree with labkit.ncspline", close(slopes, want), worst(slopes, want)) or not linear_ok:
        result.hint = "the ends are right, so check the interior rows and the slopes from (8) and, at the last knot, (9)."
    return result
