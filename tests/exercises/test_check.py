"""labkit.check: passes the reference implementations, and narrows real mistakes down."""

import numpy as np
import pytest

import labkit
from labkit import check


def test_reference_implementations_pass_every_check():
    assert check.eval_pherm(labkit.eval_pherm).passed
    assert check.runge(labkit.runge).passed
    assert check.ccspline(labkit.ccspline, labkit.exercises.splines._reference_complete_system).passed
    assert check.ncspline(labkit.ncspline).passed
    assert check.runge2d(labkit.runge2d).passed
    assert check.eval_pbilin(labkit.eval_pbilin).passed
    assert check.coons(lambda *args: tuple(labkit.patch(*args))).passed


def _hermite(combine):
    def eval_pherm(xdata, ydata, ypdata, xval):
        xdata, ydata, ypdata, xval = map(np.asarray, (xdata, ydata, ypdata, xval))
        k = labkit.bracket(xdata, xval)
        h = labkit.hermite_basis(xdata[k], xdata[k + 1], xval)
        return combine(ydata, ypdata, k, h)

    return eval_pherm


def test_swapped_basis_functions_are_named():
    swapped = _hermite(lambda y, yp, k, h: y[k] * h[0] + yp[k] * h[3] + y[k + 1] * h[2] + yp[k + 1] * h[1])
    result = check.eval_pherm(swapped)
    assert "h2" in result.hint and "swapped" in result.hint  # the lab's step iv: reproduce each h_k with eval_pherm


def test_wrong_combination_is_found_after_the_basis_checks_pass():
    # squares the values: right for the 0/1 data of the basis checks, wrong for monomials
    squared = _hermite(lambda y, yp, k, h: y[k] ** 2 * h[0] + yp[k] * h[1] + y[k + 1] ** 2 * h[2] + yp[k + 1] * h[3])
    result = check.eval_pherm(squared)
    assert not result.passed
    assert "each basis function is right, so the combination is wrong" in result.hint


def test_single_interval_code_fails_on_several_intervals():
    first_interval_only = _hermite(lambda y, yp, k, h: y[0] * h[0] + yp[0] * h[1] + y[1] * h[2] + yp[1] * h[3])
    result = check.eval_pherm(first_interval_only)
    assert "use bracket" in result.hint


def test_exceptions_and_wrong_shapes_are_reported_not_raised():
    assert "raised ZeroDivisionError" in repr(check.runge(lambda x: 1 / 0))
    assert not check.eval_pherm(lambda *a: None).passed
    assert "return both values" in check.runge(lambda x: 1 / (1 + x**2)).hint


def test_runge_with_a_wrong_derivative():
    result = check.runge(lambda x: (1 / (1 + x**2), -2 * x / (1 + x**2)))
    assert [ok for _, ok, _ in result.steps] == [True, False] and "chain rule" in result.hint


def test_ccspline_subscript_mistake_is_located_by_the_equal_interval_case():
    def shifted_h(xdata, ydata, y1p, ynp):
        xdata = np.asarray(xdata, float)
        h = np.diff(xdata)[::-1]  # wrong interval lengths, right when they are all equal
        return labkit.ccspline(np.concatenate(([xdata[0]], xdata[0] + np.cumsum(h))), ydata, y1p, ynp)

    result = check.ccspline(shifted_h)
    assert not result.passed and "a subscript of h is off" in result.hint


def test_ccspline_asymmetric_matrix_is_reported():
    def system(xdata, ydata, y1p, ynp):
        A, D = labkit.exercises.splines._reference_complete_system(
            np.asarray(xdata, float), np.asarray(ydata, float), y1p, ynp
        )
        A[1, 0] *= 2
        return A, D

    result = check.ccspline(lambda *a: labkit.ccspline(*a) * 1.1, system)
    assert "A is symmetric" in repr(result) and "h(k-1)/6" in result.hint


def test_eval_pbilin_transposed_output_fails_at_the_single_cell():
    result = check.eval_pbilin(lambda f, xd, yd, xv, yv: labkit.eval_pbilin(f, xd, yd, xv, yv).T + 0 * xv[0])
    assert not result.passed


@pytest.mark.parametrize(
    "corners, passed",
    [
        (
            [
                labkit.Corner([0, 0], [3, 0], [0, 1]),
                labkit.Corner([1, 0], [0.1, 0], [0, 1]),
                labkit.Corner([1, 1], [0.1, 0], [0, 1]),
                labkit.Corner([0, 1], [3, 0], [0, 1]),
            ],
            True,
        ),
        (
            [
                labkit.Corner([0, 0], [0.1, 0], [0, 1]),
                labkit.Corner([1, 0], [3, 0], [0, 1]),
                labkit.Corner([1, 1], [3, 0], [0, 1]),
                labkit.Corner([0, 1], [0.1, 0], [0, 1]),
            ],
            False,
        ),
        ("not corners", False),
    ],
)
def test_graded_corner_data(corners, passed):
    assert check.graded_corners(corners).passed is passed


def test_grade_reports_missing_names_with_a_hint():
    verdict = check.exercise(16, {"runge2d": labkit.runge2d})
    assert verdict["defined"] and not verdict["passed"]
    passed = [c["name"] for c in verdict["checks"] if c["passed"]]
    assert passed == ["runge2d"] and verdict["points"] == 1 and verdict["fraction"] == 1 / 8
    missing = next(c for c in verdict["checks"] if c["name"] == "eval_pbilin")
    assert "run the cell that defines eval_pbilin" in missing["hint"]


def _recording(calls):
    def eval_pherm(xdata, ydata, ypdata, xval):
        calls.append(np.asarray(xdata, float).copy())
        return labkit.eval_pherm(xdata, ydata, ypdata, xval)

    return eval_pherm


def test_seeded_random_cases_are_fresh_per_seed_and_repeatable():
    runs = {}
    for label, seed in (("a", None), ("b", None), ("c", 1), ("d", 1), ("e", 2)):
        calls = []
        assert check.eval_pherm(_recording(calls), seed=seed).passed
        runs[label] = calls[-1]  # the random unequal intervals
    assert np.array_equal(runs["a"], runs["b"]) and np.array_equal(runs["c"], runs["d"])
    assert not np.array_equal(runs["a"], runs["c"]) and not np.array_equal(runs["c"], runs["e"])


@pytest.mark.parametrize("seed", [None, 7, 2**62])
def test_reference_implementations_pass_with_any_seed(seed):
    assert check.runge(labkit.runge, seed=seed).passed
    assert check.driver("pherm", _table_error, seed=seed).passed
    assert check.ccspline(labkit.ccspline, labkit.exercises.splines._reference_complete_system, seed=seed).passed
    assert check.ncspline(labkit.ncspline, seed=seed).passed
    assert check.runge2d(labkit.runge2d, seed=seed).passed
    assert check.eval_pbilin(labkit.eval_pbilin, seed=seed).passed
    assert check.coons(lambda *args: tuple(labkit.patch(*args)), seed=seed).passed


def _table_error(ndata, f=labkit.runge, interpolate=labkit.eval_pherm):
    x, xtest = np.linspace(0, 5, ndata), np.linspace(0, 5, 4001)
    y, yp = f(x)
    exact = f(xtest)[0]
    return np.max(np.abs(interpolate(x, y, yp, xtest) - exact)) / np.max(np.abs(exact))


def test_a_zero_function_gets_no_denominator_hint():
    result = check.eval_pherm(lambda xd, yd, yp, xv: 0.0 * np.asarray(xv))
    assert not result.passed and "times 0" not in result.hint and "wrong" in result.hint


def test_natural_spline_check_reads_the_end_curvature_from_the_derivative():
    result = check.ncspline(lambda x, y: labkit.ccspline(x, y, 0.0, 0.0))  # the complete spline's ends
    assert not result.passed and "M1 = 0 and Mn = 0" in result.hint
    assert "s'' = [" in repr(result)


def _system_with_h_subscript_slip(xdata, ydata, y1p, ynp):
    """complete_system with A(k, k-1) = h(k)/6 (the right one is h(k-1)/6), written here from equation (11)."""
    x, y = np.asarray(xdata, dtype=float), np.asarray(ydata, dtype=float)
    n, h = len(x), np.diff(x)
    secant = np.diff(y) / h
    A, D = np.zeros((n, n)), np.zeros(n)
    A[0, :2], D[0] = [h[0] / 3, h[0] / 6], secant[0] - y1p
    for k in range(1, n - 1):
        A[k, k - 1 : k + 2], D[k] = [h[k] / 6, (h[k - 1] + h[k]) / 3, h[k] / 6], secant[k] - secant[k - 1]
    A[-1, -2:], D[-1] = [h[-1] / 6, h[-1] / 3], ynp - secant[-1]
    return A, D


def _natural_from(system):
    def ncspline(x, y):
        x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
        A, D = system(x, y, 0.0, 0.0)
        A[[0, -1], :], D[[0, -1]] = 0.0, 0.0
        A[0, 0] = A[-1, -1] = 1.0
        M = np.linalg.solve(A, D)
        h, secant = np.diff(x), np.diff(y) / np.diff(x)
        slopes = np.append(-M[:-1] * h / 3 - M[1:] * h / 6 + secant, M[-1] * h[-1] / 3 + M[-2] * h[-1] / 6 + secant[-1])
        return slopes

    return ncspline


@pytest.mark.parametrize("seed", [None, 3])
def test_ncspline_built_on_a_wrong_complete_system_is_not_charged_twice(seed):
    from labkit.exercises import splines as spline_checks

    ncspline = _natural_from(_system_with_h_subscript_slip)
    A, _ = _system_with_h_subscript_slip([0.0, 0.7, 1.5, 2.0], [1.0, 2.0, 0.0, 1.0], 0.0, 0.0)
    assert not np.allclose(A, A.T)  # the slip is real on unequal spacing (Exercise 10 marks it)
    assert not spline_checks.check_ncspline(ncspline, seed=seed).passed  # on its own, not the natural spline
    ours = spline_checks.check_ncspline(ncspline, seed=seed, system=_system_with_h_subscript_slip)
    assert ours.passed and "your own complete_system" in repr(ours)
    # ... but a slip of its own next to the wrong system still costs ncspline
    slipped = spline_checks.check_ncspline(
        lambda x, y: ncspline(x, y) * 1.01, seed=seed, system=_system_with_h_subscript_slip
    )
    assert not slipped.passed
    # and the right natural spline next to the wrong system passes the usual way
    assert spline_checks.check_ncspline(labkit.ncspline, seed=seed, system=_system_with_h_subscript_slip).passed


# -- issue 30: a hint for every slip (the catalog plants most of them; these are the ones it does not) ----------


def test_an_index_one_past_the_end_and_a_caret_for_a_power_are_named_where_they_raise():
    from labkit.exercises.result import CheckResult, call

    past, caret = CheckResult("f"), CheckResult("f")
    call(past, "runs", lambda n: np.linspace(0, 5, n)[n], 7)
    call(caret, "runs", lambda x: 1 / (1 + x ^ 2), np.linspace(0, 1, 3))
    assert "index 7 is one past the last entry of an array of 7 entries" in past.hint
    assert "its last index is 6, or -1" in past.hint and "look at that line" not in past.hint
    assert "`^` is bitwise xor in Python, not a power" in caret.hint
    other = CheckResult("f")
    call(other, "runs", lambda: np.zeros(3)[5])
    assert "index 5 is outside an array of 3 entries" in other.hint


def _pherm_with(search=labkit.bracket, h3=None):
    def eval_pherm(xdata, ydata, ypdata, xval):
        xdata, ydata, ypdata, xval = (np.asarray(a, dtype=float) for a in (xdata, ydata, ypdata, xval))
        k = search(xdata, xval)
        h = list(labkit.hermite_basis(xdata[k], xdata[k + 1], xval))
        if h3 is not None:
            h[2] = h3(xval, xdata[k], xdata[k + 1])
        return ydata[k] * h[0] + ypdata[k] * h[1] + ydata[k + 1] * h[2] + ypdata[k + 1] * h[3]

    return eval_pherm


@pytest.mark.parametrize(
    "search, said",
    [
        (lambda x, v: np.clip(np.searchsorted(x, v), 0, len(x) - 2), "the interval to its right"),
        (lambda x, v: np.clip(np.searchsorted(x, v) - 2, 0, len(x) - 2), "the interval to its left"),
        (lambda x, v: np.searchsorted(x, v, side="right") - 1, "points at or past the last knot raise an error"),
        (lambda x, v: np.maximum(np.searchsorted(x, v) - 1, 0), "points past the last knot raise an error"),
        (lambda x, v: np.minimum(np.searchsorted(x, v) - 1, len(x) - 2), "points before the first knot get the wrong"),
    ],
)
def test_the_interval_search_is_named_on_either_side_and_at_either_end(search, said):
    result = check.eval_pherm(_pherm_with(search))
    assert not result.passed and said in result.hint and "look at that line" not in result.hint
    assert check.eval_pherm(_pherm_with(lambda x, v: labkit.bracket(x, v))).passed


def test_a_basis_function_is_named_by_the_entries_of_table_3_it_misses():
    # h3 with h1's last factor: 3 x_k - x_{k+1} - 2x instead of 3 x_{k+1} - x_k - 2x
    result = check.eval_pherm(_pherm_with(h3=lambda x, a, b: (x - a) ** 2 * (3 * a - b - 2 * x) / (b - a) ** 3))
    assert "h3 is wrong: its value at x_{k+1} and its slope at x_{k+1} are not what the lab's table (3)" in result.hint


def test_a_basis_function_written_as_another_is_not_blamed_on_the_combination():
    result = check.eval_pherm(_pherm_with(h3=lambda x, a, b: labkit.hermite_basis(a, b, x)[0]))  # h3 is h1
    assert "your h3 is h1's formula" in result.hint and "combination" not in result.hint


def _natural_with(change_d):
    def ncspline(x, y):
        x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
        A, D = labkit.exercises.splines._reference_complete_system(x, y, 0.0, 0.0)
        change_d(D)
        A[[0, -1], :], D[[0, -1]] = 0.0, 0.0
        A[0, 0] = A[-1, -1] = 1.0
        M = np.linalg.solve(A, D)
        h, secant = np.diff(x), np.diff(y) / np.diff(x)
        return np.append(-M[:-1] * h / 3 - M[1:] * h / 6 + secant, M[-1] * h[-1] / 3 + M[-2] * h[-1] / 6 + secant[-1])

    return ncspline


def test_a_natural_spline_with_a_wrong_inside_row_is_told_which_row_not_its_end_rows():
    def third_row(D):
        D[2] += 0.5

    result = check.ncspline(_natural_with(third_row))
    assert (
        "row 3 of your system is not equations (11)-(12)" in result.hint
        and "first and last rows are right" in result.hint
    )

    def negated(D):
        D[1:-1] *= -1

    assert "D's inside entries have the wrong sign" in check.ncspline(_natural_with(negated), seed=4).hint


def test_a_complete_system_with_its_last_row_swapped_is_told_so():
    def system(xdata, ydata, y1p, ynp):
        A, D = labkit.exercises.splines._reference_complete_system(
            np.asarray(xdata, float), np.asarray(ydata, float), y1p, ynp
        )
        A[-1, -2], A[-1, -1] = A[-1, -1], A[-1, -2]
        return A, D

    def ccspline(x, y, y1p, ynp):
        A, D = system(x, y, y1p, ynp)
        M, h = np.linalg.solve(A, D), np.diff(np.asarray(x, float))
        return np.append(-M[:-1] * h / 3 - M[1:] * h / 6 + np.diff(np.asarray(y, float)) / h, ynp)

    result = check.ccspline(ccspline, system)
    assert "A's last row is not equation (11)'s: A(4, 3) and A(4, 4) differ from it" in result.hint


def _pherm_driver(measure):
    def test_pherm_interpolate(ndata, f=labkit.runge, interpolate=labkit.eval_pherm):
        xdata, xtest = np.linspace(0, 5, ndata), np.linspace(0, 5, 4001)
        return measure(f, xdata, xtest, interpolate)

    return test_pherm_interpolate


@pytest.mark.parametrize(
    "measure, said",
    [
        (
            lambda f, x, t, p: np.max(f(t)[0] - p(x, *f(x), t)) / np.max(np.abs(f(t)[0])),
            "The error takes no absolute value",
        ),
        (
            lambda f, x, t, p: np.max(np.abs(f(t)[0] - p(x, *f(x)[::-1], t))) / np.max(np.abs(f(t)[0])),
            "The values and the slopes of the data look swapped",
        ),
        (
            lambda f, x, t, p: np.mean(np.abs(f(t)[0] - p(x, *f(x), t))) / np.max(np.abs(f(t)[0])),
            "the mean of |f - p|",
        ),
    ],
)
def test_a_driver_that_measures_another_way_is_told_how(measure, said):
    result = check.driver("pherm", _pherm_driver(measure), seed=2)
    assert not result.passed and said in result.hint


def test_a_complete_driver_with_the_next_to_last_end_slope_is_told_so():
    def test_ccspline_interpolate(ndata, f=labkit.runge, slopes=labkit.ccspline):
        xdata, xtest = np.linspace(0, 5, ndata), np.linspace(0, 5, 4001)
        ydata, ypdata = f(xdata)
        values = labkit.eval_pherm(xdata, ydata, slopes(xdata, ydata, ypdata[0], ypdata[-2]), xtest)
        return np.max(np.abs(f(xtest)[0] - values)) / np.max(np.abs(f(xtest)[0]))

    result = check.driver("complete", test_ccspline_interpolate)
    assert "The last end slope looks like f' at the next-to-last data point" in result.hint


def test_a_quarter_circle_side_is_told_which_derivative_points_off_the_circle():
    q = np.pi / 4
    corners = [
        labkit.Corner([0, 0], [q, -q], [q, q]),
        labkit.Corner([1, 0], [q, q], [-q, q]),
        labkit.Corner([1, 1], [q, -q], [q, q]),
        labkit.Corner([0, 1], [q, q], [-q, q]),
    ]
    assert check.circle_corners(corners).passed
    corners[1] = labkit.Corner([1, 0], [q, 0.5 * q], [-q, q])  # B's ds turned off the tangent
    result = check.circle_corners(corners)
    assert "at B, the derivative along AB (ds) does not point along the circle" in result.hint
    assert "both its direction and its length matter" in result.hint


def test_in_the_graders_sandbox_a_self_check_calls_nothing_of_the_students(monkeypatch):
    """The grader runs every check itself, from outside: in its sandbox (LABKIT_HEADLESS=1) a self-check in the
    notebook's cells calls none of the student's functions, so they are not computed twice."""
    calls = []

    def eval_pherm(*args):
        calls.append(args)
        return labkit.eval_pherm(*args)

    def driver(ndata, f=labkit.runge, interpolate=labkit.eval_pherm):
        calls.append(ndata)
        return 0.1

    monkeypatch.setenv("LABKIT_HEADLESS", "1")
    results = [
        check.eval_pherm(eval_pherm),
        check.driver("pherm", driver),
        check.table("pherm", [0.1] * 8, driver),
        check.rate("pherm", 4, [0.1] * 8, driver),
    ]
    # (a hidden test's assert on it holds: the grader's own check, run from outside, is what counts)
    assert calls == [] and all(r.passed and "grader runs this check itself" in r.steps[0][0] for r in results)
    monkeypatch.delenv("LABKIT_HEADLESS")
    assert check.eval_pherm(eval_pherm).passed and calls  # in a student's notebook it runs as ever
