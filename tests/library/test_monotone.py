import numpy as np
import pytest
from helpers import unequal_knots
from scipy.interpolate import PchipInterpolator

from labkit import pchip, pchip_slopes


@pytest.mark.parametrize("n", [2, 3, 4, 60])
def test_pchip_matches_scipy_with_extrapolation(rng, n):
    x = unequal_knots(rng, n)
    y = rng.normal(size=n)
    xv = rng.uniform(x[0] - 1, x[-1] + 1, 2000)
    reference = PchipInterpolator(x, y)
    np.testing.assert_allclose(pchip_slopes(x, y), reference(x, 1), rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(pchip(x, y, xv), reference(xv), rtol=1e-12, atol=1e-12)


def test_pchip_matches_scipy_on_data_with_flats_and_sign_changes():
    x = np.array([0.0, 1.0, 2.0, 3.0, 4.0, 5.5, 6.0, 8.0])
    y = np.array([0.0, 1.0, 2.0, 2.0, 2.0, -1.0, 3.0, 3.0])
    xv = np.linspace(-1, 9, 1001)
    np.testing.assert_allclose(pchip(x, y, xv), PchipInterpolator(x, y)(xv), rtol=1e-12, atol=1e-13)


def test_boiling_water_data_stay_flat_where_the_data_are_flat():
    # Exercise 14: after boiling starts the temperature must not move.
    x, y = [0, 1, 2, 3, 4], [0, 1, 2, 2, 2]
    xv = np.linspace(2, 4, 101)
    np.testing.assert_allclose(pchip(x, y, xv), 2.0, rtol=0, atol=1e-15)
    rising = pchip(x, y, np.linspace(0, 2, 101))
    assert np.all(np.diff(rising) >= 0) and rising.max() <= 2.0


def test_end_slope_is_clamped_to_three_secants():
    # End formula gives 3.5 * delta0 > 3 delta0 with the next secant of opposite sign.
    x, y = [0.0, 1.0, 2.0], [0.0, 1.0, 0.0]
    np.testing.assert_allclose(pchip_slopes(x, y)[0], PchipInterpolator(x, y)(0.0, 1))
    # h0 = 1, h1 = 0.1, secants 1 and -10: the formula gives 11, clamped to 3.
    x, y = [0.0, 1.0, 1.1], [0.0, 1.0, 0.0]
    assert pchip_slopes(x, y)[0] == pytest.approx(3.0)
    assert PchipInterpolator(x, y)(0.0, 1) == pytest.approx(3.0)
