"""Each figure of the notebooks: labelled, titled, and drawing the right data."""
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

import labkit  # noqa: E402
from labkit import plots  # noqa: E402


@pytest.fixture(autouse=True)
def close_figures():
    yield
    plt.close("all")


def _labelled(ax):
    assert ax.get_title() and ax.get_xlabel() and ax.get_ylabel()


@pytest.mark.parametrize("method", ["plin", "pherm"])
def test_limacon_draws_the_interpolant_of_the_sampled_curve(method):
    ax = plots.plot_limacon(nintervals=8, r0=1.3, method=method)
    _labelled(ax)
    assert ax.get_aspect() == 1.0
    exact, curve, data = ax.get_lines()
    tdata = np.linspace(0, 2 * np.pi, 9)
    x, y, xp, yp = labkit.limacon(tdata, 1.3)
    np.testing.assert_allclose(data.get_xydata(), np.column_stack((x, y)))
    tval = np.linspace(0, 2 * np.pi, 90)
    expected_x = labkit.eval_plin(tdata, x, tval) if method == "plin" else labkit.eval_pherm(tdata, x, xp, tval)
    np.testing.assert_allclose(curve.get_xdata(), expected_x)
    # the exact curve closes on itself
    np.testing.assert_allclose(exact.get_xydata()[0], exact.get_xydata()[-1], atol=1e-12)


def test_limacon_rejects_other_methods():
    with pytest.raises(ValueError, match="'plin'.*'pherm'"):
        plots.plot_limacon(method="spline")


def test_convergence_plot_has_a_line_per_table_and_reference_slopes():
    tables = [labkit.convergence_table(m, ndata=(5, 11, 21, 41)) for m in ("plin", "pherm")]
    ax = plots.plot_convergence(tables)
    _labelled(ax)
    lines = ax.get_lines()
    assert len(lines) == 4 and ax.get_xscale() == "log" and ax.get_yscale() == "log"
    np.testing.assert_allclose(lines[1].get_ydata(), tables[1].errors)
    for line, order in zip(lines[2:], (2, 4)):
        x, y = line.get_xdata(), line.get_ydata()
        assert np.log(y[1] / y[0]) / np.log(x[1] / x[0]) == pytest.approx(-order)


def test_interpolation_error_curve_is_p_minus_f():
    ax = plots.plot_interpolation_error(["natural", "notaknot"], 9)
    _labelled(ax)
    natural = ax.get_lines()[0]
    x = natural.get_xdata()
    xdata = np.linspace(0, 5, 9)
    ydata = labkit.runge(xdata)[0]
    expected = labkit.eval_pherm(xdata, ydata, labkit.ncspline(xdata, ydata), x) - labkit.runge(x)[0]
    np.testing.assert_allclose(natural.get_ydata(), expected, atol=1e-15)


def test_spline_vs_pchip_shows_both_interpolants_and_the_data():
    x, y = np.arange(5.0), np.array([0, 1, 2, 2, 2.0])
    ax = plots.plot_spline_vs_pchip(x, y)
    _labelled(ax)
    spline_line, pchip_line, data = ax.get_lines()
    assert len(spline_line.get_xdata()) >= 100
    np.testing.assert_allclose(pchip_line.get_ydata(), labkit.pchip(x, y, pchip_line.get_xdata()))
    np.testing.assert_allclose(spline_line.get_ydata(), labkit.spline(x, y, spline_line.get_xdata()))
    assert data.get_linestyle() == "None"


def test_bilinear_error_map_is_interpolant_minus_function():
    ax = plots.plot_bilinear_error(5, ntest=21)
    _labelled(ax)
    test = np.linspace(0, 5, 21)
    X, Y = np.meshgrid(test, test, indexing="ij")
    expected = labkit.eval_pbilin(labkit.runge2d, np.linspace(0, 5, 5), np.linspace(0, 5, 5), test, test) - labkit.runge2d(X, Y)
    np.testing.assert_allclose(ax.collections[0].get_array().reshape(21, 21), expected.T)


def test_plot_patch_titles_with_the_worst_quality_and_colours_folds():
    e1, e2 = [1, 0], [0, 1]
    corners = [labkit.Corner([0, 0], e1, e2), labkit.Corner([1, 0], [-1.5, 0], e2),
               labkit.Corner([1, 1], [-1.5, 0], e2), labkit.Corner([0, 1], e1, e2)]
    ax = plots.plot_patch(corners, ns=11, nt=3, color_by_quality=True)
    _labelled(ax)
    assert "worst quality -" in ax.get_title()
    assert ax.collections[0].get_array().min() < 0
