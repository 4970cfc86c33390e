"""Derivatives of every interpolant: against scipy's, and against the mathematics of each method."""

import numpy as np
import pytest
from helpers import unequal_knots
from scipy.interpolate import CubicHermiteSpline, CubicSpline, PchipInterpolator

import labkit


def _close(got, want, rtol=1e-10):
    scale = np.max(np.abs(want))
    np.testing.assert_allclose(got, want, rtol=rtol, atol=rtol * scale)


@pytest.fixture
def data(rng):
    x = unequal_knots(rng, 12)
    inside = rng.uniform(x[0], x[-1], 300)
    outside = np.concatenate((rng.uniform(x[0] - 2, x[0], 20), rng.uniform(x[-1], x[-1] + 2, 20)))
    return x, rng.normal(size=12), rng.normal(size=12), np.concatenate((inside, outside))


@pytest.mark.parametrize("der", [0, 1, 2, 3])
def test_hermite_derivatives_match_scipy(data, der):
    x, y, yp, xv = data
    _close(labkit.eval_pherm(x, y, yp, xv, der=der), CubicHermiteSpline(x, y, yp)(xv, der))


@pytest.mark.parametrize("der", [0, 1, 2, 3])
@pytest.mark.parametrize("kind", ["notaknot", "complete"])
def test_spline_derivatives_match_scipy(data, der, kind):
    x, y, _, xv = data
    if kind == "notaknot":
        ours, theirs = labkit.spline(x, y, xv, der=der), CubicSpline(x, y)(xv, der)
    else:
        ours = labkit.spline(x, np.concatenate(([0.5], y, [-1.5])), xv, der=der)
        theirs = CubicSpline(x, y, bc_type=((1, 0.5), (1, -1.5)))(xv, der)
    _close(ours, theirs)


@pytest.mark.parametrize("der", [0, 1, 2, 3])
def test_pchip_derivatives_match_scipy(data, der):
    x, y, _, xv = data
    _close(labkit.pchip(x, y, xv, der=der), PchipInterpolator(x, y)(xv, der))


def test_piecewise_linear_slope_is_the_secant_of_each_piece(data):
    x, y, _, xv = data
    k = np.clip(np.searchsorted(x, xv, "right") - 1, 0, x.size - 2)
    np.testing.assert_allclose(labkit.eval_plin(x, y, xv, der=1), (np.diff(y) / np.diff(x))[k], rtol=1e-13)


def test_cubics_have_exact_derivatives_everywhere():
    x = np.array([-1.0, 0.3, 0.7, 2.0, 3.5])
    xv = np.linspace(-3, 5, 41)
    p = np.poly1d([0.5, -1.0, 2.0, 0.25])
    for der in range(4):
        want = p.deriv(der)(xv) if der else p(xv)
        _close(labkit.eval_pherm(x, p(x), p.deriv()(x), xv, der=der), want, 1e-12)
        _close(labkit.spline(x, p(x), xv, der=der), want, 1e-12)  # not-a-knot reproduces cubics


def test_natural_spline_second_derivative_vanishes_at_the_ends(data):
    x, y, _, _ = data
    ends = labkit.eval_pherm(x, y, labkit.ncspline(x, y), x[[0, -1]], der=2)
    assert np.max(np.abs(ends)) < 1e-10 * np.max(np.abs(y)) / np.min(np.diff(x)) ** 2


def _jumps(x, y, slopes, der):
    """The jump of the der-th derivative at each interior knot (right piece minus left piece)."""
    h = np.diff(x)
    right = labkit.eval_pherm(x, y, slopes, x[1:-1], der=der)  # at a knot: the piece to its right
    # the left piece's value at its right end, from its own cubic evaluated on one interval
    left = np.array(
        [labkit.eval_pherm(x[k : k + 2], y[k : k + 2], slopes[k : k + 2], x[k + 1], der=der) for k in range(len(h) - 1)]
    )
    return right - left


def test_splines_are_c2_and_hermite_and_pchip_are_not(data):
    x, y, yp, _ = data
    scale = np.max(np.abs(y)) / np.min(np.diff(x)) ** 2
    for slopes in (labkit.ccspline(x, y, 0.2, -0.3), labkit.ncspline(x, y), labkit.nakspline(x, y)):
        assert np.max(np.abs(_jumps(x, y, slopes, 1))) < 1e-10 * scale
        assert np.max(np.abs(_jumps(x, y, slopes, 2))) < 1e-9 * scale
        assert np.max(np.abs(_jumps(x, y, slopes, 3))) > 1e-3  # a cubic spline's third derivative jumps
    for slopes in (yp, labkit.pchip_slopes(x, y)):
        assert np.max(np.abs(_jumps(x, y, slopes, 1))) < 1e-10 * scale  # C1 ...
        assert np.max(np.abs(_jumps(x, y, slopes, 2))) > 1e-3  # ... but not C2


def test_hermite_basis_derivatives_are_the_derivatives_of_the_basis():
    xk, xk1, x = 0.5, 2.0, np.linspace(-1, 3, 9)
    step = 1e-6
    for der in range(1, 4):
        up, down = labkit.hermite_basis(xk, xk1, x + step, der - 1), labkit.hermite_basis(xk, xk1, x - step, der - 1)
        for got, a, b in zip(labkit.hermite_basis(xk, xk1, x, der), up, down):
            np.testing.assert_allclose(got, (a - b) / (2 * step), rtol=1e-6, atol=1e-6)


@pytest.mark.parametrize(
    "call, highest",
    [
        (lambda der: labkit.eval_plin([0, 1], [0, 1], 0.5, der=der), 1),
        (lambda der: labkit.eval_pherm([0, 1], [0, 1], [0, 0], 0.5, der=der), 3),
        (lambda der: labkit.spline([0, 1, 2], [0, 1, 0], 0.5, der=der), 3),
        (lambda der: labkit.pchip([0, 1, 2], [0, 1, 0], 0.5, der=der), 3),
        (lambda der: labkit.hermite_basis(0.0, 1.0, 0.5, der=der), 3),
    ],
)
@pytest.mark.parametrize("offset", [1, 2])
def test_derivative_order_out_of_range_is_refused(call, highest, offset):
    with pytest.raises(ValueError, match=f"der must be a whole number from 0 .* to {highest}"):
        call(highest + offset)
    for bad in (-1, 1.0, True, "1", None):
        with pytest.raises(ValueError, match="der must be a whole number"):
            call(bad)


@pytest.mark.parametrize("a", [0.5, 1.0, 1.837, 4.0])
def test_runge_scale_is_the_function_and_its_derivative(a):
    """runge(x, a) is 1/(1 + a x^2): its value at x = 1/sqrt(a) is 1/2 whatever a is, and its derivative is
    the central difference of its values (the derivative's exactness, not labkit against itself)."""
    y, _ = labkit.runge(1.0 / np.sqrt(a), a=a)
    assert y == pytest.approx(0.5, rel=1e-15)
    x = np.linspace(-3.0, 3.0, 61)
    h = 1e-5
    central = (labkit.runge(x + h, a=a)[0] - labkit.runge(x - h, a=a)[0]) / (2 * h)
    np.testing.assert_allclose(labkit.runge(x, a=a)[1], central, rtol=1e-8, atol=1e-10)
    # scaling x by sqrt(a) turns it into the lab's function: runge(x, a) = runge(sqrt(a) x)
    np.testing.assert_allclose(labkit.runge(x, a=a)[0], labkit.runge(np.sqrt(a) * x)[0], rtol=1e-14)


def test_runge_lab_scale_keeps_its_bits():
    """a = 1 gives exactly the lab's 1/(1+x^2) and -2x/(1+x^2)^2 (the committed outputs depend on it)."""
    x = np.linspace(-5.0, 5.0, 1001)
    y, yp = labkit.runge(x, a=1.0)
    assert np.array_equal(y, 1.0 / (1.0 + x * x))
    assert np.array_equal(yp, -2.0 * x * y * y)
    assert np.array_equal(labkit.runge(x)[1], yp)


@pytest.mark.parametrize("a", [0.0, -1.0, np.nan, np.inf, [1.0, 2.0], "two"])
def test_runge_scale_refuses_what_is_no_scale(a):
    with pytest.raises(ValueError, match="a"):
        labkit.runge(0.5, a=a)


@pytest.mark.parametrize("a", [0.5, 1.0, 1.6543])
def test_runge2d_scale_is_the_function_of_the_sum(a):
    """runge2d(x, y, a) = 1/(1 + a (x+y)^2): 1/2 where x + y = 1/sqrt(a), and runge2d(sqrt(a) x, sqrt(a) y)."""
    half = 0.5 / np.sqrt(a)
    assert labkit.runge2d(half, half, a=a) == pytest.approx(0.5, rel=1e-15)
    x, y = np.meshgrid(np.linspace(-2, 2, 9), np.linspace(0, 3, 7), indexing="ij")
    np.testing.assert_allclose(labkit.runge2d(x, y, a=a), labkit.runge2d(np.sqrt(a) * x, np.sqrt(a) * y), rtol=1e-14)
    with pytest.raises(ValueError, match=r"a is the Runge function's scale, 1/\(1 \+ a \(x\+y\)\^2\); got -.*above 0"):
        labkit.runge2d(x, y, a=-a)
