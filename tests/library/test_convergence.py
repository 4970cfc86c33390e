import numpy as np
import pytest

from labkit import convergence_table, runge

EXPECTED_ORDER = {"plin": 2, "pherm": 4, "complete": 4, "natural": 2, "notaknot": 4, "pchip": 2}


@pytest.fixture(scope="module")
def tables():
    return {method: convergence_table(method) for method in EXPECTED_ORDER}


@pytest.mark.parametrize("method, order", EXPECTED_ORDER.items())
def test_runge_orders_of_convergence(tables, method, order):
    table = tables[method]
    assert table.order == order
    # the finest ratios sit near 2**order (equal spacing halves h each row)
    np.testing.assert_allclose(table.ratios[-2:], 2.0**order, rtol=0.05)


def test_errors_are_the_relative_max_norm():
    table = convergence_table("plin", ndata=(3, 5), ntest=5)
    x = np.linspace(0, 5, 5)
    y = runge(x)[0]
    # 3 points: 0, 2.5, 5; test points 1.25 and 3.75 are the midpoints
    mid = 0.5 * (runge(np.array([0.0, 2.5]))[0].sum()), 0.5 * (runge(np.array([2.5, 5.0]))[0].sum())
    expected = max(abs(y[1] - mid[0]), abs(y[3] - mid[1])) / y.max()
    assert table.errors[0] == pytest.approx(expected, rel=1e-12)


def test_table_prints_in_the_lab_layout(tables):
    text = str(tables["pherm"])
    lines = text.splitlines()
    assert lines[0] == "Runge function, Piecewise Hermite Cubic"
    assert lines[1].startswith("ndata =  5  Err(  5) = ")
    assert "Err(  5)/Err( 11) = " in lines[2]
    assert lines[8].startswith("ndata =641  Err(641) = ")
    assert lines[-1] == "Estimated order of convergence: 4"


def test_other_functions_and_intervals():
    table = convergence_table("natural", ndata=(11, 21, 41, 81), f=np.sin, interval=(0, np.pi))
    assert table.title == "sin, Natural Cubic Spline"
    assert table.order == 4  # sin'' vanishes at 0 and pi: the natural end condition is exact


def test_bad_arguments_are_explained():
    with pytest.raises(ValueError, match="unknown method 'cubic'"):
        convergence_table("cubic")
    with pytest.raises(ValueError, match="needs derivatives"):
        convergence_table("pherm", f=np.sin)
    with pytest.raises(ValueError, match="at least 2"):
        convergence_table("plin", ndata=(1, 5))
    with pytest.raises(ValueError, match="a < b"):
        convergence_table("plin", interval=(5, 0))
