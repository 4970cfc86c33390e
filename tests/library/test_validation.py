"""Bad input gets a ValueError that says what is wrong, never a wrong answer."""

import numpy as np
import pytest

from labkit import bracket, ccspline, eval_pherm, eval_plin, nakspline, ncspline, pchip, pchip_slopes, spline

X, Y = [0.0, 1.0, 2.0, 3.0], [0.0, 1.0, 0.0, 1.0]

ONE_D = {
    "bracket": lambda x, y: bracket(x, 0.5),
    "eval_plin": lambda x, y: eval_plin(x, y, 0.5),
    "eval_pherm": lambda x, y: eval_pherm(x, y, y, 0.5),
    "ccspline": lambda x, y: ccspline(x, y, 0.0, 0.0),
    "ncspline": ncspline,
    "nakspline": nakspline,
    "spline": lambda x, y: spline(x, y, 0.5),
    "pchip": lambda x, y: pchip(x, y, 0.5),
    "pchip_slopes": pchip_slopes,
}


@pytest.fixture(params=ONE_D.values(), ids=ONE_D.keys())
def call(request):
    return request.param


def test_two_dimensional_xdata(call):
    with pytest.raises(ValueError, match=r"xdata must be a 1-D array.*shape \(2, 2\)"):
        call(np.reshape(X, (2, 2)), Y)


def test_too_few_points(call):
    with pytest.raises(ValueError, match="at least 2 points"):
        call([1.0], [1.0])


def test_repeated_or_decreasing_xdata(call):
    with pytest.raises(ValueError, match=r"strictly increasing.*xdata\[1\] = 1 and xdata\[2\] = 1"):
        call([0.0, 1.0, 1.0, 3.0], Y)
    with pytest.raises(ValueError, match="strictly increasing.*Sort the data"):
        call([3.0, 2.0, 1.0, 0.0], Y)


def test_nan_or_inf_in_xdata(call):
    with pytest.raises(ValueError, match="xdata contains a non-finite value"):
        call([0.0, np.nan, 2.0, 3.0], Y)
    with pytest.raises(ValueError, match="xdata contains a non-finite value"):
        call([0.0, 1.0, 2.0, np.inf], Y)


def test_length_mismatch():
    for bad in (
        lambda: eval_plin(X, Y[:3], 0.5),
        lambda: eval_pherm(X, Y, Y[:3], 0.5),
        lambda: ncspline(X, Y + [2.0]),
        lambda: pchip(X, Y[:2], 0.5),
        lambda: spline(X, Y + [1.0], 0.5),
    ):
        with pytest.raises(ValueError, match=r"has \d entries but xdata has 4"):
            bad()


def test_nan_in_values_and_derivatives():
    with pytest.raises(ValueError, match="ydata contains a non-finite value"):
        ncspline(X, [0.0, np.nan, 1.0, 2.0])
    with pytest.raises(ValueError, match="ypdata contains a non-finite value"):
        eval_pherm(X, Y, [0.0, 0.0, np.inf, 0.0], 0.5)
    with pytest.raises(ValueError, match="y1p.*non-finite"):
        ccspline(X, Y, np.nan, 0.0)


def test_complete_spline_needs_both_end_slopes():
    with pytest.raises(ValueError, match="y1p .* is required"):
        ccspline(X, Y)
    with pytest.raises(ValueError, match="ynp .* is required"):
        ccspline(X, Y, 0.0)
    with pytest.raises(ValueError, match="single number"):
        ccspline(X, Y, [0.0, 1.0], 0.0)


def test_non_numeric_input():
    with pytest.raises(ValueError, match="xdata holds text, not numbers"):
        eval_plin(["a", "b"], [1, 2], 0.5)


def test_nan_in_xval_gives_nan_not_an_error():
    for f in (lambda v: spline(X, Y, v), lambda v: pchip(X, Y, v), lambda v: eval_plin(X, Y, v)):
        out = f([np.nan, 0.5])
        assert np.isnan(out[0]) and np.isfinite(out[1])
