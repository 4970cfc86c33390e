"""One mistake, one part, only for an attempt (issue 29): a part judged against the student's own earlier work
follows it only when that work is an attempt at the same task, the lab's or within a slip the checks name.

Trivial earlier work (data reduced to a dot, two unit squares for the two patches, an identity matrix for the
spline system, a driver that returns made-up numbers, a Runge function that is another function) is no
reference: the part is judged against labkit's reference, earns nothing, and its feedback says why in the
student's words. The named slips next to it still cost only their own part.
"""

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import pytest
from test_check import _natural_from, _system_with_h_subscript_slip
from test_student_work import _corners9, _driver_1d, _driver_2d, _patch_meshes

import labkit
from labkit import check
from labkit.exercises import experiments, splines
from labkit.exercises.registry import LAB

NOT_AN_ATTEMPT = "that is not an attempt at the lab's task, so this part was judged against"


def _said(result, lab):
    """The feedback (as the grader shows it) says the part was judged against `lab`, and why."""
    hint = result.as_dict()["hint"]
    return NOT_AN_ATTEMPT in hint and f"judged against {lab}" in hint and "instead of your own earlier work" in hint


# -- Exercise 4: the plot against the student's data --------------------------------------------------------


def _axes(x, y):
    fig, ax = plt.subplots()
    ax.plot(x, y)
    plt.close(fig)
    return ax


T = np.linspace(0, 2 * np.pi, 21)
TVAL = np.linspace(0, 2 * np.pi, 210)


def _hermite_axes(t, x, y, xp, yp):
    return _axes(labkit.eval_pherm(t, x, xp, TVAL), labkit.eval_pherm(t, y, yp, TVAL))


def test_a_limacon_plot_of_data_reduced_to_a_dot_earns_nothing_and_says_why():
    zeros = np.zeros(21)
    dot = _axes(np.zeros(210), np.zeros(210))  # the Hermite interpolant of the dot, exactly
    result = check.limacon_plot(dot, (T, zeros, zeros, zeros, zeros))
    assert not result.passed
    assert "the Hermite interpolant of the lab's data" in result.steps[1][0]
    assert _said(result, "the lab's Hermite limaçon") and "not the lab's 21 points of the limaçon" in repr(result)
    # the same with a single point for all the data
    single = check.limacon_plot(dot, ([0.0, 1.0], [0.0, 0.0], [0.0, 0.0], [0.0, 0.0], [0.0, 0.0]))
    assert not single.passed and _said(single, "the lab's Hermite limaçon")
    # a right plot next to trivial data still passes: it is the lab's
    x, y, xp, yp = labkit.limacon(T)
    right = check.limacon_plot(_hermite_axes(T, x, y, xp, yp), (T, zeros, zeros, zeros, zeros))
    assert right.passed and NOT_AN_ATTEMPT not in repr(right)


@pytest.mark.parametrize(
    "slip",
    ["dy/dt has the wrong sign", "dx/dt has the wrong sign", "dx/dt without the product rule", "dy/dt without it"],
)
def test_a_plot_that_follows_a_named_slip_in_the_slopes_still_costs_only_the_slopes(slip):
    x, y, xp, yp = labkit.limacon(T)
    r = 1.15 + np.cos(T)
    xp, yp = {
        "dy/dt has the wrong sign": (xp, -yp),
        "dx/dt has the wrong sign": (-xp, yp),
        "dx/dt without the product rule": (-r * np.sin(T), yp),
        "dy/dt without it": (xp, r * np.cos(T)),
    }[slip]
    ax = _hermite_axes(T, x, y, xp, yp)
    assert not check.limacon_plot(ax, None).passed  # against the lab's curve it is off ...
    assert check.limacon_plot(ax, (T, x, y, xp, yp)).passed  # ... but it follows the student's own slip


def test_slopes_or_points_that_are_no_slip_are_no_reference():
    x, y, xp, yp = labkit.limacon(T)
    halved = check.limacon_plot(_hermite_axes(T, x, y, xp / 2, yp), (T, x, y, xp / 2, yp))
    assert not halved.passed and "Your xpdata are not dx/dt at tdata" in repr(halved)
    t11 = np.linspace(0, 2 * np.pi, 11)  # other points than the lab's 21
    x11, y11, xp11, yp11 = labkit.limacon(t11)
    other = check.limacon_plot(_hermite_axes(t11, x11, y11, xp11, yp11), (t11, x11, y11, xp11, yp11))
    assert not other.passed and _said(other, "the lab's Hermite limaçon")


# -- Exercise 9: region against the student's meshes, and two_patches itself --------------------------------


def _unit_squares(A, B, C, D):
    """Two unit squares side by side, of the lab's sizes, sharing 30 nodes, whatever the corners."""
    S, T2 = np.meshgrid(np.linspace(0, 1, 20), np.linspace(0, 1, 30), indexing="ij")
    first = labkit.quad_mesh(S, T2)
    S, T2 = np.meshgrid(np.linspace(0, 1, 30), np.linspace(0, 1, 20), indexing="ij")
    second = labkit.quad_mesh(1 + T2, 1 - S)
    return first, second


def test_two_unit_squares_earn_nothing_for_two_patches_nor_region():
    corners = _corners9()
    first, second = _unit_squares(*corners)
    region = first + second
    assert len(region.points) == 1170 and region.quality().min() > 0  # they join like the lab's patches would
    patches = check.two_patches(_unit_squares, corners)
    assert not patches.passed and "pass through the corners two_patches is given" in repr(patches)
    result = check.combined_mesh(region, corners, _unit_squares)
    assert not result.passed and _said(result, "the lab's two patches")
    assert "do not pass through the lab's corners" in repr(result)


def test_meshes_of_another_size_are_no_reference():
    corners = _corners9()

    def coarse(A, B, C, D):
        first = labkit.quad_mesh(*labkit.patch(A, B, C, D, np.linspace(0, 1, 5), np.linspace(0, 1, 30)))
        a, b, c, d = (labkit.Corner(k.point[::-1], k.dt[::-1], k.ds[::-1], k.dsdt[::-1]) for k in (A, D, C, B))
        return first, labkit.quad_mesh(*labkit.patch(a, b, c, d, np.linspace(0, 1, 30), np.linspace(0, 1, 5)))

    result = check.combined_mesh(sum(coarse(*corners)[1:], coarse(*corners)[0]), corners, coarse)
    assert not result.passed and _said(result, "the lab's two patches") and "not the lab's 20 x 30" in repr(result)


def test_region_built_on_a_slip_in_the_mirror_rule_still_costs_only_two_patches():
    corners = _corners9()

    def slipped(A, B, C, D):
        return _patch_meshes([A, B, C, D], mirror_ds_dt=False)

    patches = check.two_patches(slipped, corners)
    assert not patches.passed and "ds is the mirror image of ABCD's ds" in patches.hint
    first, second = slipped(*corners)
    assert check.combined_mesh(first + second, corners, slipped).passed
    # and the right meshes with the right region
    right = lambda *c: _patch_meshes(list(c))
    assert check.two_patches(right, corners).passed
    assert check.combined_mesh(sum(right(*corners)[1:], right(*corners)[0]), corners, right).passed


# -- Exercise 12: ncspline against the student's complete_system --------------------------------------------


def _identity_system(xdata, ydata, y1p, ynp):
    return np.eye(len(xdata)), np.zeros(len(xdata))


def _no_interior_equations(xdata, ydata, y1p, ynp):
    """Tridiagonal and of the right size, but the inside rows are not the spline's equations."""
    n = len(xdata)
    return np.eye(n) * 2 + np.eye(n, k=1) + np.eye(n, k=-1), np.ones(n)


@pytest.mark.parametrize("system", [_identity_system, _no_interior_equations], ids=["identity", "not the equations"])
@pytest.mark.parametrize("seed", [None, 3])
def test_ncspline_following_a_system_that_is_no_spline_system_earns_nothing(system, seed):
    result = splines.check_ncspline(_natural_from(system), seed=seed, system=system)
    assert not result.passed and _said(result, "the lab's natural spline")
    assert "your own complete_system" not in repr(result)
    # the right ncspline next to it passes, with nothing to say
    right = splines.check_ncspline(labkit.ncspline, seed=seed, system=system)
    assert right.passed and NOT_AN_ATTEMPT not in repr(right)


def test_the_spline_system_test_knows_the_named_slips_and_the_equations():
    x, y = np.array([0.0, 0.7, 1.5, 2.0, 3.2]), np.exp(np.array([0.0, 0.7, 1.5, 2.0, 3.2]))
    assert splines.spline_system(splines._reference_complete_system(x, y, 0.5, 1.0), x, y) == ""
    assert splines.spline_system(_system_with_h_subscript_slip(x, y, 0.0, 0.0), x, y) == ""  # Exercise 10's slip
    A, D = splines._reference_complete_system(x, y, 0.0, 0.0)
    A[[0, -1]], D[[0, -1]] = 0.0, 0.0  # the end rows are free: the natural spline replaces them
    assert splines.spline_system((A, D), x, y) == ""
    assert "not tridiagonal" in splines.spline_system((A + 0.01, D), x, y)
    assert "row 3" in splines.spline_system((A, D + np.eye(5)[2]), x, y)
    assert "5 x 5" in splines.spline_system((A[:4, :4], D[:4]), x, y)
    assert "of numbers" in splines.spline_system("A, D", x, y)


def test_ncspline_on_the_h_subscript_slip_is_still_charged_only_in_exercise_10():
    ncspline = _natural_from(_system_with_h_subscript_slip)
    result = splines.check_ncspline(ncspline, seed=3, system=_system_with_h_subscript_slip)
    assert result.passed and "your own complete_system" in repr(result)


# -- tables and rates against the student's driver, and the f the driver evaluates ------------------------


def _table(key, driver):
    return [driver(n) for n in LAB.experiment(key).ndata]


def _graded(key, driver, rate=None):
    method = LAB.experiment(key)
    table = _table(key, driver)
    if rate is None:
        rate = experiments.supported_order(method, table)
    return experiments.check_experiment(method, table, rate, driver)


ALL = ["pherm", "complete", "natural", "notaknot", "pchip", "bilinear"]


@pytest.mark.parametrize("key", ALL)
def test_a_driver_that_returns_made_up_errors_earns_nothing_for_its_table_and_rate(key):
    order = LAB.experiment(key).order

    def made_up(ndata, *rest):
        return 1.0 / (ndata - 1.0) ** order  # shrinks at the lab's order, measures nothing

    table, rate = _graded(key, made_up, rate=order)
    assert not table.passed and not rate.passed
    assert _said(table, "the lab's experiment") and _said(rate, "the lab's experiment")
    assert "neither the lab's experiment nor the lab's experiment with one of the usual slips" in repr(table)
    # the lab's table copied next to it is still not what the driver returns
    copied = LAB.experiment(key).reference(LAB.experiment(key).ndata)
    table, _ = experiments.check_experiment(LAB.experiment(key), copied, order, made_up)
    assert not table.passed and "not what" in table.hint


def _sine(x):
    return np.sin(x) + 2.0, np.cos(x)


@pytest.mark.parametrize("key", ["pherm", "complete", "natural", "notaknot", "pchip"])
def test_a_driver_whose_own_f_is_not_the_runge_function_earns_nothing_for_its_table(key):
    def driver(ndata, f=_sine, piece=None):
        return _driver_1d(key)(ndata, f, piece)

    table, rate = _graded(key, driver)
    assert not table.passed and not rate.passed
    assert _said(table, "the lab's experiment") and "is not the Runge function" in repr(table)


def test_a_bilinear_driver_whose_own_f_is_not_runge2d_earns_nothing_for_its_table():
    def driver(ndata, f=lambda x, y: np.sin(x + y) + 2.0, interpolate=labkit.eval_pbilin):
        return _driver_2d(ndata, f, interpolate)

    table, rate = _graded("bilinear", driver)
    assert not table.passed and not rate.passed and "is not the runge2d function" in repr(table)


def _runge_sign(x):
    y, yp = labkit.runge(x)
    return y, -yp


def _runge_unsquared(x):
    x = np.asarray(x, dtype=float)
    return 1 / (1 + x**2), -2 * x / (1 + x**2)


@pytest.mark.parametrize("f", [_runge_sign, _runge_unsquared], ids=["yprime's sign", "a missing square"])
@pytest.mark.parametrize("key", ["pherm", "complete"])
def test_a_driver_whose_own_runge_has_a_named_slip_keeps_its_table_and_rate(key, f):
    assert not check.runge(f).passed  # Exercise 3 charges the slip
    table, rate = _graded(key, lambda ndata, g=f, piece=None: _driver_1d(key)(ndata, g, piece))
    assert table.passed and rate.passed, (table, rate)


def test_a_bilinear_driver_on_runge2d_with_a_product_keeps_its_table_and_rate():
    def product(x, y):
        return 1 / (1 + (np.asarray(x) * np.asarray(y)) ** 2)

    assert not check.runge2d(product).passed
    table, rate = _graded("bilinear", lambda n, f=product, i=labkit.eval_pbilin: _driver_2d(n, f, i))
    assert table.passed and rate.passed


@pytest.mark.parametrize(
    "key, kwargs",
    [
        ("pherm", {"interval": (-5.0, 5.0)}),
        ("pherm", {"ntest": 401}),
        ("complete", {"relative": False}),
        ("natural", {"ntest": 1001}),
        ("pchip", {"interval": (0.0, 1.0)}),
    ],
)
def test_a_table_that_follows_a_named_slip_in_the_driver_still_costs_only_the_driver(key, kwargs):
    driver = _driver_1d(key, **kwargs)
    if kwargs != {"relative": False}:
        assert not check.driver(key, driver).passed
    table, rate = _graded(key, driver)
    assert table.passed and rate.passed, (table, rate)


@pytest.mark.parametrize(
    "key, kwargs",
    [("pherm", {"interval": (0.0, 3.0)}), ("natural", {"ntest": 333}), ("pchip", {"interval": (-1.0, 4.0)})],
)
def test_a_slip_no_check_names_in_a_real_driver_still_costs_only_the_driver(key, kwargs):
    """A driver that measures an experiment, with a slip the catalog does not know: charged once, where it is."""
    driver = _driver_1d(key, **kwargs)
    assert not check.driver(key, driver).passed
    table, rate = _graded(key, driver)
    assert table.passed and rate.passed and not table.note, (table, rate)


@pytest.mark.parametrize("key", ALL)
def test_correct_work_says_nothing_of_the_lab_reference(key):
    driver = _driver_2d if key == "bilinear" else _driver_1d(key)
    table, rate = _graded(key, driver)
    assert table.passed and rate.passed and not table.note and not rate.note
