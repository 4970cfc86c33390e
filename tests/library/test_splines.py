import numpy as np
import pytest
from helpers import unequal_knots
from scipy.interpolate import CubicSpline

from labkit import ccspline, eval_pherm, nakspline, ncspline, spline
from labkit.splines import natural_curvatures


@pytest.fixture
def data(rng):
    x = unequal_knots(rng, 50)
    return x, np.sin(x) + rng.normal(scale=0.3, size=x.size), rng.uniform(x[0] - 1, x[-1] + 1, 3000)


def _close(actual, expected):
    np.testing.assert_allclose(actual, expected, rtol=1e-11, atol=1e-11 * np.max(np.abs(expected)))


def test_complete_matches_scipy_clamped(data):
    x, y, xv = data
    a, b = 0.7, -1.3
    reference = CubicSpline(x, y, bc_type=((1, a), (1, b)))
    slopes = ccspline(x, y, a, b)
    _close(slopes, reference(x, 1))
    _close(eval_pherm(x, y, slopes, xv), reference(xv))
    _close(spline(x, np.concatenate(([a], y, [b])), xv), reference(xv))


def test_natural_matches_scipy(data):
    x, y, xv = data
    reference = CubicSpline(x, y, bc_type="natural")
    slopes = ncspline(x, y)
    _close(slopes, reference(x, 1))
    _close(eval_pherm(x, y, slopes, xv), reference(xv))


@pytest.mark.parametrize("n", [2, 3, 4, 5, 50])
def test_notaknot_matches_scipy(rng, n):
    x = unequal_knots(rng, n)
    y = rng.normal(size=n)
    xv = rng.uniform(x[0] - 1, x[-1] + 1, 500)
    reference = CubicSpline(x, y, bc_type="not-a-knot")
    _close(nakspline(x, y), reference(x, 1))
    _close(spline(x, y, xv), reference(xv))


def test_lab_check_complete_spline_of_x_cubed():
    # Exercise 10(g), data from ERRATA.md: x^3 on [0, 4] with unequal intervals.
    np.testing.assert_allclose(ccspline([0, 1, 2, 4], [0, 1, 8, 64], 0, 48), [0, 3, 12, 48], atol=1e-12)


@pytest.mark.parametrize(
    "x, y, y1p, ynp",
    [([0, 1, 2], [0, 1, 8], 0, 12), ([0, 1, 3], [0, 1, 27], 0, 27)],
)
def test_lab_debugging_cases_reproduce_the_cubic(x, y, y1p, ynp):
    np.testing.assert_allclose(ccspline(x, y, y1p, ynp), 3 * np.asarray(x, float) ** 2, atol=1e-12)


def test_lab_check_natural_spline_of_a_line():
    np.testing.assert_allclose(ncspline([0, 1, 2, 3], [0, 2, 4, 6]), 2.0, rtol=1e-14)


def test_natural_and_complete_agree_given_the_natural_end_slopes():
    x, y = [0.0, 1.0, 2.0], [0.0, -3.0, -16.0]
    natural = ncspline(x, y)
    np.testing.assert_allclose(ccspline(x, y, natural[0], natural[-1]), natural, rtol=1e-13)


def _second_derivative_jumps(x, y, slopes):
    """s'' from the left and the right of every interior knot, from the Hermite form."""
    h = np.diff(x)
    d = np.diff(y) / h
    left_end = (6 * d - 4 * slopes[:-1] - 2 * slopes[1:]) / h  # s'' at x_k on [x_k, x_k+1]
    right_end = (-6 * d + 2 * slopes[:-1] + 4 * slopes[1:]) / h  # s'' at x_k+1 on [x_k, x_k+1]
    return right_end[:-1], left_end[1:], left_end[0], right_end[-1]


@pytest.mark.parametrize("method", ["complete", "natural", "notaknot"])
def test_splines_are_twice_continuously_differentiable(rng, method):
    x = unequal_knots(rng, 30)
    y = np.cos(x) + rng.normal(scale=0.1, size=x.size)
    slopes = {
        "complete": lambda: ccspline(x, y, 1.0, -2.0),
        "natural": lambda: ncspline(x, y),
        "notaknot": lambda: nakspline(x, y),
    }[method]()
    from_left, from_right, first, last = _second_derivative_jumps(x, y, slopes)
    scale = np.max(np.abs(from_left))
    np.testing.assert_allclose(from_left, from_right, atol=1e-10 * scale)
    if method == "natural":
        assert abs(first) < 1e-10 * scale and abs(last) < 1e-10 * scale


def test_natural_curvatures_vanish_at_the_ends(rng):
    x = unequal_knots(rng, 12)
    M = natural_curvatures(np.diff(x), np.diff(np.exp(x)) / np.diff(x))
    assert M[0] == 0.0 and M[-1] == 0.0 and np.all(M[1:-1] > 0)  # exp is convex


def test_notaknot_third_derivative_is_continuous_at_second_and_penultimate_knot(rng):
    x = unequal_knots(rng, 9)
    y = rng.normal(size=9)
    xv = np.linspace(x[0], x[2], 7)
    # the first two pieces are one cubic: a cubic through 4 of its points predicts the rest
    coeffs = np.polyfit(xv[:4], spline(x, y, xv[:4]), 3)
    np.testing.assert_allclose(np.polyval(coeffs, xv), spline(x, y, xv), atol=1e-9)


def test_spline_three_points_is_the_parabola():
    x, y = [0.0, 1.0, 3.0], [1.0, 2.0, 10.0]
    parabola = np.polyfit(x, y, 2)
    xv = np.linspace(-1, 4, 11)
    np.testing.assert_allclose(spline(x, y, xv), np.polyval(parabola, xv), atol=1e-12)


def test_inputs_are_not_modified(rng):
    x = unequal_knots(rng, 8)
    y = rng.normal(size=8)
    ext = np.concatenate(([1.0], y, [2.0]))
    copies = [a.copy() for a in (x, y, ext)]
    ccspline(x, y, 1.0, 2.0), ncspline(x, y), nakspline(x, y), spline(x, ext, x), spline(x, y, x)
    for before, after in zip(copies, (x, y, ext)):
        np.testing.assert_array_equal(before, after)
