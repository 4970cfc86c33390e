import numpy as np
import pytest
from helpers import unequal_knots
from scipy.interpolate import RegularGridInterpolator

from labkit import bilinear_convergence, eval_pbilin, runge2d


@pytest.mark.parametrize(
    "f",
    [lambda x, y: np.ones_like(x), lambda x, y: x, lambda x, y: y, lambda x, y: x * y],
    ids=["1", "x", "y", "xy"],
)
def test_bilinear_functions_are_reproduced(rng, f):
    xdata, ydata = unequal_knots(rng, 9), unequal_knots(rng, 7, start=1.0)
    xval = rng.uniform(xdata[0] - 1, xdata[-1] + 1, 40)
    yval = rng.uniform(ydata[0] - 1, ydata[-1] + 1, 30)
    X, Y = np.meshgrid(xval, yval, indexing="ij")
    np.testing.assert_allclose(eval_pbilin(f, xdata, ydata, xval, yval), f(X, Y), atol=1e-12)


def test_matches_scipy_regular_grid_interpolator_on_runge2d(rng):
    xdata, ydata = unequal_knots(rng, 15, start=0.0), unequal_knots(rng, 12, start=0.0)
    xval = rng.uniform(xdata[0], xdata[-1], 50)
    yval = rng.uniform(ydata[0], ydata[-1], 60)
    X, Y = np.meshgrid(xdata, ydata, indexing="ij")
    reference = RegularGridInterpolator((xdata, ydata), runge2d(X, Y))
    XV, YV = np.meshgrid(xval, yval, indexing="ij")
    expected = reference(np.stack((XV, YV), axis=-1))
    np.testing.assert_allclose(eval_pbilin(runge2d, xdata, ydata, xval, yval), expected, rtol=1e-13)


def test_a_table_of_values_works_like_the_function_and_corners_are_exact():
    xdata = ydata = np.array([0.0, 1.0])
    z = eval_pbilin(runge2d, xdata, ydata, xdata, ydata)
    X, Y = np.meshgrid(xdata, ydata, indexing="ij")
    np.testing.assert_array_equal(z, runge2d(X, Y))  # exercise 16(d)
    table = runge2d(X, Y)
    assert eval_pbilin(table, xdata, ydata, 0.5, 0.5) == pytest.approx(table.mean())


def test_convergence_order_is_two():
    table = bilinear_convergence()
    assert table.order == 2
    assert table.title == "Runge2d function, Piecewise Bilinear"
    np.testing.assert_allclose(table.ratios[-1], 4.0, rtol=0.05)


def test_bad_grids_are_explained():
    with pytest.raises(ValueError, match="ydata must be strictly increasing"):
        eval_pbilin(runge2d, [0, 1, 2], [0, 2, 1], [0.5], [0.5])
    with pytest.raises(ValueError, match=r"f has shape \(2, 2\) but the grid is 3 x 2"):
        eval_pbilin(np.zeros((2, 2)), [0, 1, 2], [0, 1], [0.5], [0.5])
    with pytest.raises(ValueError, match="xval must be 1-D"):
        eval_pbilin(runge2d, [0, 1], [0, 1], [[0.5]], [0.5])
    with pytest.raises(ValueError, match=r"f\(X, Y\) contains a non-finite"), np.errstate(all="ignore"):
        eval_pbilin(lambda x, y: x / y, [0, 1], [0, 1], [0.5], [0.5])


def test_inputs_are_not_modified():
    table = np.arange(6.0).reshape(3, 2)
    xdata, ydata, xval = np.array([0.0, 1.0, 2.0]), np.array([0.0, 1.0]), np.array([0.5, 1.5])
    copies = [a.copy() for a in (table, xdata, ydata, xval)]
    eval_pbilin(table, xdata, ydata, xval, xval)
    for before, after in zip(copies, (table, xdata, ydata, xval)):
        np.testing.assert_array_equal(before, after)
