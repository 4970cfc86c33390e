import numpy as np
import pytest
from helpers import unequal_knots
from scipy.interpolate import CubicHermiteSpline

from labkit import bracket, eval_pherm, eval_plin, hermite_basis


def test_bracket_finds_the_interval_and_clips_to_the_ends():
    x = np.array([0.0, 1.0, 2.0, 4.0])
    xv = np.array([-5.0, 0.0, 0.999, 1.0, 3.9, 4.0, 7.0])
    k = bracket(x, xv)
    assert k.tolist() == [0, 0, 0, 1, 2, 2, 2]
    inside = (xv >= x[0]) & (xv < x[-1])
    assert np.all((x[k[inside]] <= xv[inside]) & (xv[inside] < x[k[inside] + 1]))


def test_bracket_keeps_the_shape_and_gives_scalars_for_scalars():
    x = np.linspace(0, 1, 5)
    assert bracket(x, np.full((2, 3), 0.3)).shape == (2, 3)
    assert isinstance(bracket(x, 0.3), (int, np.integer))
    assert bracket(x, 0.3) == 1


def test_plin_matches_numpy_inside_and_extrapolates_linearly(rng):
    x = unequal_knots(rng, 30)
    y = rng.normal(size=30)
    xv = rng.uniform(x[0], x[-1], 1000)
    np.testing.assert_allclose(eval_plin(x, y, xv), np.interp(xv, x, y), rtol=1e-12, atol=1e-14)
    left, right = x[0] - 0.7, x[-1] + 1.3
    slope0 = (y[1] - y[0]) / (x[1] - x[0])
    slope1 = (y[-1] - y[-2]) / (x[-1] - x[-2])
    assert eval_plin(x, y, left) == pytest.approx(y[0] - 0.7 * slope0, rel=1e-12)
    assert eval_plin(x, y, right) == pytest.approx(y[-1] + 1.3 * slope1, rel=1e-12)


def test_pherm_matches_scipy_including_extrapolation(rng):
    x = unequal_knots(rng, 40)
    y, yp = rng.normal(size=40), rng.normal(size=40)
    xv = np.concatenate((rng.uniform(x[0] - 1, x[-1] + 1, 2000), x))
    expected = CubicHermiteSpline(x, y, yp)(xv)
    np.testing.assert_allclose(eval_pherm(x, y, yp, xv), expected, rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("power", [0, 1, 2, 3])
def test_pherm_reproduces_the_monomials_on_0_2(power):
    # The lab's check (exercise 2e): four points decide a cubic, two outside [0, 2].
    x = np.array([0.0, 2.0])
    y, yp = x**power, power * x ** max(power - 1, 0)
    xv = np.array([-1.0, 0.5, 1.0, 3.0])
    np.testing.assert_allclose(eval_pherm(x, y, yp, xv), xv**power, rtol=1e-14, atol=1e-14)


def test_hermite_basis_matches_the_table_of_values_and_slopes():
    xk, xk1, eps = 0.5, 2.0, 1e-6
    values = np.array(hermite_basis(xk, xk1, np.array([xk, xk1])))
    slopes = (
        np.array(hermite_basis(xk, xk1, np.array([xk, xk1]) + eps))
        - np.array(hermite_basis(xk, xk1, np.array([xk, xk1]) - eps))
    ) / (2 * eps)
    np.testing.assert_allclose(values, [[1, 0], [0, 0], [0, 1], [0, 0]], atol=1e-15)
    np.testing.assert_allclose(slopes, [[0, 0], [1, 0], [0, 0], [0, 1]], atol=1e-8)


def test_hermite_basis_equals_the_lab_formulas_written_out(rng):
    xk, xk1 = 0.3, 1.9
    x = rng.uniform(-1, 3, 50)
    lab = [
        (x - xk1) ** 2 * (3 * xk - xk1 - 2 * x) / (xk - xk1) ** 3,
        (x - xk) * (x - xk1) ** 2 / (xk - xk1) ** 2,
        (x - xk) ** 2 * (3 * xk1 - xk - 2 * x) / (xk1 - xk) ** 3,
        (x - xk1) * (x - xk) ** 2 / (xk1 - xk) ** 2,
    ]
    np.testing.assert_allclose(hermite_basis(xk, xk1, x), lab, rtol=1e-12, atol=1e-13)


def test_scalars_lists_and_nan():
    assert isinstance(eval_pherm([0, 1], [0, 1], [1, 1], 0.5), float)
    assert eval_plin([0, 1], [0, 2], 0.25) == pytest.approx(0.5)
    out = eval_pherm([0, 1, 2], [0, 1, 0], [0, 0, 0], [np.nan, 1.0])
    assert np.isnan(out[0]) and out[1] == 1.0
    assert np.isnan(eval_plin([0, 1], [0, 1], np.nan))


def test_inputs_are_not_modified(rng):
    x = unequal_knots(rng, 10)
    y, yp, xv = rng.normal(size=10), rng.normal(size=10), rng.uniform(-3, 8, 20)
    copies = [a.copy() for a in (x, y, yp, xv)]
    eval_pherm(x, y, yp, xv)
    eval_plin(x, y, xv)
    bracket(x, xv)
    for before, after in zip(copies, (x, y, yp, xv)):
        np.testing.assert_array_equal(before, after)
