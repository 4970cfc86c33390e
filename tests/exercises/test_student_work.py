"""The checks of the lab's student work beyond functions: drivers, tables, rate answers, plots,
the φ table, the limaçon's derivatives and the combined mesh of Exercise 9.

References are labkit's experiments (which test_convergence.py compares with scipy) and the
mathematics; every mistake below is one a student makes, and each must fail its own check with
its own hint while the right answer passes.
"""

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import pytest

import labkit
from labkit import check
from labkit.exercises import experiments, plotted
from labkit.exercises.registry import LAB
from labkit.grading.sandbox import protocol

pytestmark = pytest.mark.slow  # executes notebooks

# -- drivers ---------------------------------------------------------------------


def _driver_1d(method, interval=(0.0, 5.0), ntest=4001, relative=True):
    """A student's driver for `method`, written independently of labkit's experiment."""

    def driver(ndata, f=labkit.runge, piece=None):
        x = np.linspace(*interval, ndata)
        xtest = np.linspace(*interval, ntest)
        y, yp = f(x)
        exact = f(xtest)[0]
        if method == "pherm":
            value = (piece or labkit.eval_pherm)(x, y, yp, xtest)
        elif method == "complete":
            value = labkit.eval_pherm(x, y, (piece or labkit.ccspline)(x, y, yp[0], yp[-1]), xtest)
        elif method == "natural":
            value = labkit.eval_pherm(x, y, (piece or labkit.ncspline)(x, y), xtest)
        elif method == "notaknot":
            value = labkit.spline(x, y, xtest)
        else:
            value = labkit.pchip(x, y, xtest)
        error = np.max(np.abs(exact - value))
        return error / np.max(np.abs(exact)) if relative else error

    return driver


def _driver_2d(ndata, f=labkit.runge2d, interpolate=labkit.eval_pbilin):
    grid, test = np.linspace(0, 5, ndata), np.linspace(0, 5, 401)
    X, Y = np.meshgrid(test, test, indexing="ij")
    exact = f(X, Y)
    return np.max(np.abs(interpolate(f, grid, grid, test, test) - exact)) / np.max(np.abs(exact))


ONE_D = ["pherm", "complete", "natural", "notaknot", "pchip"]


@pytest.mark.parametrize("method", ONE_D)
@pytest.mark.parametrize("seed", [None, 11])
def test_a_correct_driver_passes(method, seed):
    assert check.driver(method, _driver_1d(method), seed=seed).passed


def test_a_correct_bilinear_driver_passes():
    assert check.driver("bilinear", _driver_2d, seed=3).passed


def test_the_reference_matches_scipy():
    # the drivers are judged against labkit's experiment; here it is against scipy's interpolants
    from scipy.interpolate import CubicHermiteSpline, CubicSpline, PchipInterpolator

    x, xtest = np.linspace(0, 5, 21), np.linspace(0, 5, 4001)
    y, yp = labkit.runge(x)
    exact = labkit.runge(xtest)[0]
    for key, interpolant in (
        ("pherm", CubicHermiteSpline(x, y, yp)),
        ("complete", CubicSpline(x, y, bc_type=((1, yp[0]), (1, yp[-1])))),
        ("natural", CubicSpline(x, y, bc_type="natural")),
        ("notaknot", CubicSpline(x, y)),
        ("pchip", PchipInterpolator(x, y)),
    ):
        expected = np.max(np.abs(interpolant(xtest) - exact)) / np.max(np.abs(exact))
        assert LAB.experiment(key).reference([21])[0] == pytest.approx(expected, rel=1e-9), key


@pytest.mark.parametrize("method", ONE_D)
def test_an_absolute_error_is_named_although_runge_hides_it(method):
    # max|runge| on [0, 5] is 1, so only the scaled function shows the slip
    result = check.driver(method, _driver_1d(method, relative=False))
    assert not result.passed
    assert [s[1] for s in result.steps[:3]] == [True, True, True]
    assert "the error is absolute, not relative to max|f|" in result.hint


@pytest.mark.parametrize(
    "slip, kwargs, hint",
    [
        ("interval", {"interval": (-5.0, 5.0)}, "measured on [-5, 5] instead of [0, 5]"),
        ("test points", {"ntest": 401}, "measured at 401 test points instead of 4001"),
        ("data points", {"ntest": 5}, "measured only at the data points"),
        ("something else", {"interval": (0.0, 3.0)}, None),
    ],
)
def test_the_usual_slips_are_told_apart(slip, kwargs, hint):
    result = check.driver("complete", _driver_1d("complete", **kwargs))
    assert not result.passed
    if hint:
        assert hint in result.hint
    else:
        assert "max|f|" in result.hint


def test_a_driver_measured_only_at_the_data_points_is_told_so():
    def at_data(ndata, f=labkit.runge, slopes=labkit.ccspline):
        x = np.linspace(0, 5, ndata)
        y, yp = f(x)
        return np.max(np.abs(labkit.eval_pherm(x, y, slopes(x, y, yp[0], yp[-1]), x) - y)) / np.max(np.abs(y))

    assert "measured only at the data points" in check.driver("complete", at_data).hint


def test_a_driver_that_ignores_f_is_caught():
    def ignores_f(ndata, f=labkit.runge, slopes=labkit.ccspline):
        return _driver_1d("complete")(ndata)

    result = check.driver("complete", ignores_f)
    assert not result.passed and "compute f from the function passed in" in result.hint


def test_unknown_experiment_is_a_clear_value_error():
    with pytest.raises(ValueError, match="unknown experiment 'cubic'; choose one of"):
        check.driver("cubic", _driver_2d)


# -- tables ---------------------------------------------------------------------------


def test_a_table_is_what_the_students_own_driver_gives():
    driver = _driver_1d("natural")
    assert check.table("natural", [driver(n) for n in labkit.convergence.DEFAULT_NDATA], driver).passed
    # consistent with a wrong driver: the driver check marks the driver, the table is not marked twice
    wrong = _driver_1d("natural", ntest=401)
    assert check.table("natural", [wrong(n) for n in labkit.convergence.DEFAULT_NDATA], wrong).passed
    # the reference table copied next to a wrong driver is not the student's table
    reference = labkit.convergence_table("natural").errors
    result = check.table("natural", reference, wrong)
    assert not result.passed and "fill the table by running your driver" in result.hint


@pytest.mark.parametrize(
    "errors, detail",
    [
        ([0.1, 0.01], "got"),
        ("eight numbers", "got"),
        ([1.0] * 7 + [np.nan], "got"),
        (None, "got"),
    ],
)
def test_a_table_that_is_not_eight_errors_says_what_to_give(errors, detail):
    result = check.table("pherm", errors, _driver_1d("pherm"))
    assert not result.passed and "make errors_pherm a list of 8 positive errors" in result.hint


# -- rate answers ---------------------------------------------------------------------


def _returning(errors, ndata=labkit.convergence.DEFAULT_NDATA):
    """A driver that returns the given errors for the lab's sizes (as a fabricated one would)."""
    return lambda n, *rest: float(errors[list(ndata).index(n)])


def _table_of(driver, key):
    return [driver(n) for n in LAB.experiment(key).ndata]


@pytest.mark.parametrize(
    "method, order", [("pherm", 4), ("complete", 4), ("natural", 2), ("notaknot", 4), ("pchip", 2), ("bilinear", 2)]
)
def test_the_true_order_is_right_and_its_ratio_or_a_neighbour_is_not(method, order):
    assert LAB.experiment(method).order == order  # what the exercise declares ...
    assert LAB.experiment(method).observed_order == order  # ... is what labkit's own table shows
    driver = _driver_2d if method == "bilinear" else _driver_1d(method)
    table = _table_of(driver, method)
    assert check.rate(method, order, table, driver).passed
    assert check.rate(method, float(order), tuple(table), driver).passed
    ratio = check.rate(method, 2**order, table, driver)
    assert not ratio.passed and "if you copied a ratio Err(n)/Err(2n-1)" in repr(ratio)
    # the same words for any power of two, so the hint does not tell which ratio is the table's
    other = check.rate(method, 2 ** (order + 1), table, driver)
    assert not other.passed and other.hint == ratio.hint
    assert not check.rate(method, order + 1, table, driver).passed
    # without a driver, or without a table, there is nothing to read the rate from, even for the right answer
    bare = check.rate(method, order, table, None)
    assert not bare.passed and "define it first" in bare.hint
    empty = check.rate(method, order, None, driver)
    assert not empty.passed and "nothing to read the rate from" in repr(empty)


def test_eight_for_the_complete_spline_fails_with_the_ratios_hint_and_never_names_the_rate():
    driver = _driver_1d("complete")
    result = check.rate("complete", 8, _table_of(driver, "complete"), driver)
    assert not result.passed and "the exponent p of the power of two" in result.hint
    assert "4" not in repr(result).replace("Err(41)", "")  # the self-check never gives the answer away


def test_the_rate_is_read_from_the_students_own_table():
    # a table whose errors fall like h^3 supports 3
    ndata = np.array(labkit.convergence.DEFAULT_NDATA)
    assert experiments.supported_order(LAB.experiment("complete"), 1.0 / (ndata - 1.0) ** 3) == 3
    # a right driver whose own slopes (its default, the student's ccspline) are the natural spline's: the driver
    # check gives it labkit's ccspline and it passes, Exercise 10 marks the slopes, and its table supports 2: the
    # answer 2 is right, the true 4 is not
    natural_slopes = lambda x, y, y1p, ynp: labkit.ncspline(x, y)
    driver = lambda n, f=labkit.runge, slopes=natural_slopes: _driver_1d("complete")(n, f, slopes)
    assert check.driver("complete", driver).passed
    errors = _table_of(driver, "complete")
    assert experiments.supported_order(LAB.experiment("complete"), errors) == 2
    assert check.rate("complete", 2, errors, driver).passed
    three = check.rate("complete", 3, errors, driver)
    assert not three.passed and "not the exponent" in repr(three)
    assert not check.rate("complete", 4, errors, driver).passed
    # a table with one row mistyped, read correctly, keeps the rate (the table alone loses its part)
    honest = _driver_1d("complete")
    mistyped = _table_of(honest, "complete")
    mistyped[-1] *= 20  # the last ratio is now about 0.8
    own = experiments.supported_order(LAB.experiment("complete"), mistyped)
    table, rate = experiments.check_experiment(LAB.experiment("complete"), mistyped, own, honest)
    assert not table.passed and rate.passed and own != 4


def test_a_table_and_rate_typed_in_without_a_driver_that_runs_earn_nothing():
    # the second red team's fabricated table: it shrinks, and the rate read off it is right for it
    errors = list(1.0 / (np.array(labkit.convergence.DEFAULT_NDATA) - 1.0) ** 4)
    table, rate = experiments.check_experiment(LAB.experiment("pherm"), errors, 4, None)
    assert not table.passed and not rate.passed
    broken = lambda n, *rest: 1 / 0  # a driver that does not run
    table, rate = experiments.check_experiment(LAB.experiment("pherm"), errors, 4, broken)
    assert not table.passed and not rate.passed and "must run" in rate.hint
    # ... nor next to a driver whose own errors do not shrink
    table, rate = experiments.check_experiment(LAB.experiment("pherm"), errors, 4, lambda n, *rest: 0.5)
    assert not table.passed and not rate.passed and "no rate to read" in repr(rate)


@pytest.mark.parametrize("errors", [[1.0] * 8, list(np.linspace(0.1, 0.2, 8)), [1e-3] * 7 + [0.9e-3]])
def test_a_table_that_shows_no_experiment_earns_nothing_and_supports_no_rate(errors):
    constant = _returning(errors)
    table = check.table("pherm", errors, constant)
    assert not table.passed and "shows no experiment" in repr(table)
    for answer in (0, 1, 4):
        rate = check.rate("pherm", answer, errors, constant)
        assert not rate.passed and "no rate" in repr(rate)
    # next to an honest driver, the degenerate table itself is named
    honest = check.rate("pherm", 4, errors, _driver_1d("pherm"))
    assert not honest.passed and "your table's errors do not shrink" in repr(honest)


def test_a_table_copied_from_the_printout_counts():
    driver = _driver_1d("pherm")
    exact = [driver(n) for n in labkit.convergence.DEFAULT_NDATA]
    copied = [float(f"{e:.3e}") for e in exact]  # what ratio_table prints
    assert check.table("pherm", copied, driver).passed
    assert not check.table("pherm", [e * 1.002 for e in exact], driver).passed
    # a table that is a tuple or an array counts the same
    assert check.table("pherm", tuple(copied), driver).passed and check.table("pherm", np.array(copied), driver).passed


@pytest.mark.parametrize("answer", ["4", None, 3.5, [4, 4], np.nan])
def test_a_rate_that_is_not_a_whole_number_says_so(answer):
    driver = _driver_1d("pherm")
    result = check.rate("pherm", answer, _table_of(driver, "pherm"), driver)
    assert not result.passed and "whole number" in result.hint


# -- Exercise 4: derivatives and plot ------------------------------------------------


def _derivatives(sign_y=1.0):
    def limacon_derivatives(t, r0=1.15):
        t = np.asarray(t, dtype=float)
        r = r0 + np.cos(t)
        return -np.sin(t) * np.cos(t) - r * np.sin(t), sign_y * (-(np.sin(t) ** 2) + r * np.cos(t))

    return limacon_derivatives


def test_limacon_derivatives_match_centred_differences_and_a_sign_slip_is_named():
    assert check.limacon_derivatives(_derivatives(), seed=5).passed
    # the check's reference against a centred difference of the curve itself
    t, h = np.linspace(0, 2 * np.pi, 13), 1e-6
    x = lambda t: (1.15 + np.cos(t)) * np.cos(t)
    np.testing.assert_allclose(labkit.limacon(t)[2], (x(t + h) - x(t - h)) / (2 * h), atol=1e-8)
    wrong = check.limacon_derivatives(_derivatives(-1.0))
    assert not wrong.passed and "dy/dt has the wrong sign" in wrong.hint
    assert not check.limacon_derivatives(lambda t, r0: (np.zeros_like(t), np.zeros_like(t))).passed


def _limacon_axes(method="pherm", sign_y=1.0, nval=210, turn=2 * np.pi):
    t = np.linspace(0, 2 * np.pi, 21)
    x, y, xp, _ = labkit.limacon(t)
    yp = _derivatives(sign_y)(t)[1]
    tval = np.linspace(0, turn, nval)
    if method == "pherm":
        xv, yv = labkit.eval_pherm(t, x, xp, tval), labkit.eval_pherm(t, y, yp, tval)
    else:
        xv, yv = labkit.eval_plin(t, x, tval), labkit.eval_plin(t, y, tval)
    fig, ax = plt.subplots()
    ax.plot(xv, yv)
    plt.close(fig)
    return ax, (t, x, y, xp, yp)


def test_the_hermite_limacon_plot_passes_and_the_polygon_and_the_exact_curve_do_not():
    ax, own = _limacon_axes()
    assert check.limacon_plot(ax, own).passed and check.limacon_plot(ax, None).passed
    polygon, own = _limacon_axes("plin")
    result = check.limacon_plot(polygon, own)
    assert not result.passed and "straight segments: that is eval_plin's curve" in result.hint
    # the exact limaçon, drawn with no interpolation at all, is not the exercise's plot
    fig, exact = plt.subplots()
    x, y, _, _ = labkit.limacon(np.linspace(0, 2 * np.pi, 210))
    exact.plot(x, y)
    plt.close(fig)
    result = check.limacon_plot(exact, own)
    assert not result.passed and "exact limaçon, not its Hermite interpolant" in result.hint


def test_a_plot_that_follows_the_students_wrong_slopes_is_not_marked_twice():
    ax, own = _limacon_axes(sign_y=-1.0)
    assert not check.limacon_plot(ax, None).passed  # against the true curve alone it is off
    assert check.limacon_plot(ax, own).passed  # but it is the Hermite curve of the student's own data


@pytest.mark.parametrize("kwargs, hint", [({"nval": 21}, "10*(nintervals+1)"), ({"turn": np.pi}, "whole turn")])
def test_a_limacon_plot_with_too_few_points_or_half_a_turn_fails(kwargs, hint):
    ax, own = _limacon_axes(**kwargs)
    result = check.limacon_plot(ax, own)
    assert not result.passed and hint in result.hint


def test_something_that_is_not_a_plot_is_told_to_draw_on_the_axes():
    result = check.limacon_plot(np.zeros(3))
    assert not result.passed and "draw on the Axes `ax4`" in result.hint


# -- Exercise 14: the boiling-water plot ---------------------------------------------


def _boiling(data="o", spline_points=201, pchip_points=201, spline_style="-"):
    xdata, ydata = plotted.BOILING
    fig, ax = plt.subplots()
    ax.plot(xdata, ydata, data)
    xs, xp = np.linspace(0, 4, spline_points), np.linspace(0, 4, pchip_points)
    ax.plot(xs, labkit.spline(xdata, ydata, xs), spline_style)
    ax.plot(xp, labkit.pchip(xdata, ydata, xp))
    plt.close(fig)
    return ax


def test_the_boiling_plot_passes_when_right():
    results = check.boiling_plot(_boiling())
    assert results.passed and len(results) == 3
    # and the spline and pchip really differ there (else a curve could not be told apart)
    x = np.linspace(0, 4, 201)
    assert np.max(np.abs(labkit.spline(*plotted.BOILING, x) - labkit.pchip(*plotted.BOILING, x))) > 0.05


@pytest.mark.parametrize(
    "kwargs, failing, hint",
    [
        ({"data": "o-"}, 0, "no line may join the data points"),
        ({"data": "s"}, 0, "as a circle"),
        ({"spline_points": 20}, 1, "100 points or more"),
        ({"pchip_points": 5}, 2, "evaluate pchip of the data at many times"),
        ({"spline_style": "."}, 1, "as a line"),
    ],
)
def test_each_plot_mistake_fails_only_its_part(kwargs, failing, hint):
    results = check.boiling_plot(_boiling(**kwargs))
    assert [r.passed for r in results] == [i != failing for i in range(3)]
    assert hint in results[failing].hint


def test_the_spline_is_not_taken_for_pchip():
    xdata, ydata = plotted.BOILING
    fig, ax = plt.subplots()
    ax.plot(xdata, ydata, "o")
    x = np.linspace(0, 4, 201)
    ax.plot(x, labkit.spline(xdata, ydata, x))
    ax.plot(x, labkit.spline(xdata, ydata, x))
    plt.close(fig)
    assert [r.passed for r in check.boiling_plot(ax)] == [True, True, False]


def test_plots_cross_to_the_grader_as_their_lines():
    ax = _boiling()
    message = protocol.loads(protocol.dumps({"value": protocol.encode(ax)}))
    lines = protocol.decode(message["value"])
    assert [line.marker for line in lines] == ["o", "None", "None"]
    assert [line.joined for line in lines] == [False, True, True]
    assert [r.passed for r in check.boiling_plot(lines)] == [True, True, True]
    assert check.boiling_plot(protocol.decode(protocol.encode(ax.figure))).passed
    with pytest.raises(protocol.ProtocolError):
        protocol.decode(["lines", [["a", "b", "o", "-"]]])


# -- Exercise 16(a) and Exercise 9(c) ---------------------------------------------------


def test_the_phi_table_is_checked_against_the_definition():
    assert check.phi_table(np.eye(4)).passed
    assert check.phi_table([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]).passed
    shifted = np.roll(np.eye(4), 1, axis=1)  # the corners numbered from another one
    result = check.phi_table(shifted)
    assert not result.passed and "numbered in another order" in result.hint
    averaged = check.phi_table(np.full((4, 4), 0.25))
    assert not averaged.passed and "put the corner's x and y into every factor" in averaged.hint
    assert not check.phi_table(np.eye(3)).passed


def _corners9():
    r2 = np.sqrt(2) / 2
    return [
        labkit.Corner([0, 1], [np.pi / 4, 0], [0, 1]),
        labkit.Corner([r2, r2], [r2 * np.pi / 4, -r2 * np.pi / 4], [2 - r2, 2 - r2]),
        labkit.Corner([2, 2], [2, 0], [2 - r2, 2 - r2]),
        labkit.Corner([0, 2], [2, 0], [0, 1]),
    ]


def _patch_meshes(corners, mirror_ds_dt=True):
    A, B, C, D = corners
    first = labkit.quad_mesh(*labkit.patch(A, B, C, D, np.linspace(0, 1, 20), np.linspace(0, 1, 30)))
    swap = (
        (lambda c: labkit.Corner(c.point[::-1], c.dt[::-1], c.ds[::-1], c.dsdt[::-1]))
        if mirror_ds_dt
        else (lambda c: labkit.Corner(c.point[::-1], c.ds[::-1], c.dt[::-1], c.dsdt[::-1]))
    )
    second = labkit.quad_mesh(
        *labkit.patch(swap(A), swap(D), swap(C), swap(B), np.linspace(0, 1, 30), np.linspace(0, 1, 20))
    )
    return first, second


def test_the_combined_mesh_is_judged_from_its_data():
    corners = _corners9()
    first, second = _patch_meshes(corners)
    region = first + second
    assert check.combined_mesh(region, corners).passed
    # the shared edge: 20 x 30 + 30 x 20 nodes less the 30 it has
    assert len(region.points) == 1170
    # two meshes side by side without merging: a crack along the shared edge
    cracked = labkit.QuadMesh(
        np.vstack((first.points, second.points)), np.vstack((first.quads, second.quads + len(first.points)))
    )
    result = check.combined_mesh(cracked, corners)
    assert not result.passed and "the shared edge once" in result.hint and "twice" in result.hint
    assert not check.combined_mesh(first, corners).passed
    assert "one QuadMesh of the two meshes" in check.combined_mesh(protocol.NotNumbers("a list"), corners).hint


def test_a_shuffled_but_equal_mesh_passes_and_the_protocol_carries_it():
    corners = _corners9()
    region = sum(_patch_meshes(corners)[1:], _patch_meshes(corners)[0])
    order = np.random.default_rng(0).permutation(len(region.points))
    inverse = np.argsort(order)
    shuffled = labkit.QuadMesh(region.points[order], inverse[region.quads])
    assert check.combined_mesh(shuffled, corners).passed
    assert check.combined_mesh(protocol.decode(protocol.encode(shuffled)), corners).passed


def test_very_long_lines_are_judged_on_a_sample_with_the_same_verdict():
    # the grader bounds its work on a plot (plotted.SAMPLE points per line, plotted.MAX_CURVES lines)
    t = np.linspace(0, 2 * np.pi, 3 * plotted.SAMPLE + 7)
    data = np.linspace(0, 2 * np.pi, 21)
    xd, yd, xp, yp = labkit.limacon(data)
    x, y = labkit.eval_pherm(data, xd, xp, t), labkit.eval_pherm(data, yd, yp, t)
    on_curve = plotted.Line(x, y, "None", "-")
    assert check.limacon_plot([on_curve]).passed
    off = plotted.Line(x + np.where(np.arange(t.size) % 2 == 0, 0.05, 0.0), y, "None", "-")
    result = check.limacon_plot([off])
    assert not result.passed and "more than 0.02 away" in repr(result)
    nowhere = plotted.Line(np.zeros(t.size), np.zeros(t.size), "None", "-")
    assert not check.limacon_plot([nowhere] * (plotted.MAX_CURVES + 5)).passed
