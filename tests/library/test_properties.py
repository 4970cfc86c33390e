"""Property tests: reproduction of polynomials and shape preservation."""

import numpy as np
from helpers import knots
from hypothesis import example, given, settings
from hypothesis import strategies as st

from labkit import ccspline, eval_pherm, eval_plin, nakspline, ncspline, pchip, spline

coefficient = st.floats(-5.0, 5.0)
settings.register_profile("labkit", max_examples=60, deadline=None)
settings.load_profile("labkit")


def _points(x):
    span = x[-1] - x[0]
    return np.linspace(x[0] - 0.3 * span, x[-1] + 0.3 * span, 37)


def _close(actual, expected):
    scale = max(1.0, np.max(np.abs(expected)))
    np.testing.assert_allclose(actual, expected, rtol=0, atol=1e-8 * scale)


@given(knots(min_size=2), st.tuples(coefficient, coefficient, coefficient, coefficient))
def test_cubic_is_reproduced_by_hermite_complete_and_notaknot(x, c):
    # shift so the cubic is centred on the data: keeps the values well scaled
    centre = x.mean()
    p = np.polynomial.Polynomial(c, domain=[centre - 1, centre + 1], window=[-1, 1])
    y, dp = p(x), p.deriv()
    xv = _points(x)
    _close(eval_pherm(x, y, dp(x), xv), p(xv))
    _close(eval_pherm(x, y, ccspline(x, y, dp(x[0]), dp(x[-1])), xv), p(xv))
    if x.size >= 4:
        _close(spline(x, y, xv), p(xv))


# Closely spaced end knots, evaluated far outside: a Hermite basis in (x - x_k) / h cancels terms of size
# ((x - x_k) / h)^3 there and missed the line by 2e-7, where scipy's power form misses by 1e-13.
CLOSE_END_KNOTS = np.array(
    [
        0.0,
        1.0,
        4.95065826,
        8.59594371,
        9.59593371,
        11.40297388,
        12.70805107,
        14.02733514,
        18.03588028,
        19.92650528,
        23.96424009,
        28.13703432,
        28.39703432,
        31.39703432,
        34.08504308,
        38.80379308,
        43.55379308,
        44.46860776,
        48.71860776,
        48.76860776,
    ]
)


@given(knots(min_size=2), coefficient, coefficient)
@example(CLOSE_END_KNOTS, 0.0, 1.0)
def test_lines_are_reproduced_by_every_method(x, a, b):
    y = a + b * (x - x.mean())
    xv = _points(x)
    line = a + b * (xv - x.mean())
    _close(eval_plin(x, y, xv), line)
    _close(eval_pherm(x, y, np.full(x.size, b), xv), line)
    for slopes in (ncspline(x, y), nakspline(x, y), ccspline(x, y, b, b)):
        _close(eval_pherm(x, y, slopes, xv), line)
    _close(spline(x, y, xv), line)
    _close(pchip(x, y, xv), line)


@given(knots(min_size=2), st.lists(st.floats(0.0, 10.0), min_size=25, max_size=25))
def test_pchip_is_monotone_on_monotone_data(x, steps):
    y = np.cumsum(steps[: x.size])
    xv = np.linspace(x[0], x[-1], 400)
    assert np.all(np.diff(pchip(x, y, xv)) >= -1e-12 * max(1.0, y[-1]))
    assert np.all(np.diff(pchip(x, -y, xv)) <= 1e-12 * max(1.0, y[-1]))


@given(knots(min_size=2), st.lists(st.floats(-10.0, 10.0), min_size=25, max_size=25))
def test_pchip_stays_within_the_data_range_of_each_interval(x, values):
    y = np.asarray(values[: x.size])
    t = np.linspace(0, 1, 21)
    xv = (x[:-1, None] + t * np.diff(x)[:, None]).ravel()
    p = pchip(x, y, xv).reshape(-1, t.size)
    low = np.minimum(y[:-1], y[1:])[:, None]
    high = np.maximum(y[:-1], y[1:])[:, None]
    tol = 1e-12 * max(1.0, np.max(np.abs(y)))
    assert np.all(p >= low - tol) and np.all(p <= high + tol)
