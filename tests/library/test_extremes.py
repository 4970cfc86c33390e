"""No silent wrong answers at the extremes, and no silent casts of what is not real numbers.

The interpolants are covariant under x -> b x, y -> c y, so labkit works in a
frame scaled by powers of two: knots and values from 1e-300 to 1e308 give
the answer scipy gives (or, where scipy overflows, the answer of the same
problem scaled to ordinary numbers, scaled back). Where the answer itself is
beyond the float range, a ValueError says so. No RuntimeWarning escapes.
"""

import warnings

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from scipy.interpolate import CubicSpline, PchipInterpolator

import labkit

pytestmark = pytest.mark.filterwarnings("error")  # a RuntimeWarning (or ComplexWarning) fails the test

SLOPES = {
    "ccspline": lambda x, y: labkit.ccspline(x, y, 0.0, 0.0),
    "ncspline": labkit.ncspline,
    "nakspline": labkit.nakspline,
    "pchip_slopes": labkit.pchip_slopes,
}


def _scipy(name, x, y):
    """scipy's knot slopes; NaN where scipy has no finite answer (it overflows, or says so)."""
    with warnings.catch_warnings(), np.errstate(all="ignore"):
        warnings.simplefilter("ignore")
        try:
            if name == "pchip_slopes":
                return PchipInterpolator(x, y)(x, 1)
            bc = {"ccspline": ((1, 0.0), (1, 0.0)), "ncspline": "natural", "nakspline": "not-a-knot"}[name]
            return CubicSpline(x, y, bc_type=bc)(x, 1)
        except ValueError:
            return np.full(x.size, np.nan)


def test_knots_near_the_top_of_the_float_range():
    x = np.array([1e300, 3e305, 1e306, 4e307, 1e308])
    y = np.array([0.0, 1.0, -1.0, 2.0, 0.5])
    base_x = np.ldexp(x, -1000)  # the same knots scaled by a power of two: ordinary numbers
    for name, slopes in SLOPES.items():
        got = slopes(x, y)
        assert np.all(np.isfinite(got)), name
        np.testing.assert_array_equal(got, np.ldexp(slopes(base_x, y), -1000))  # exact covariance
    values = labkit.spline(x, y, [2e307, 9e307])
    np.testing.assert_array_equal(values, labkit.spline(base_x, y, np.ldexp([2e307, 9e307], -1000)))


def test_knots_spanning_both_signs_of_huge_numbers():
    x = np.array([-1e308, -1e307, 0.0, 1e307, 1e308])
    y = np.array([1.0, 0.0, 2.0, 0.0, 1.0])
    for der in range(4):
        got = labkit.spline(x, y, np.array([-5e307, 5e307]), der=der)
        assert np.all(np.isfinite(got)) or der > 1  # high derivatives of a curve this wide underflow to 0
        assert not np.any(np.isnan(got))
    np.testing.assert_allclose(labkit.pchip(x, y, x), y)


@pytest.mark.parametrize("name", sorted(SLOPES))
def test_subnormal_spacing_raises_instead_of_overflowing(name):
    x = np.array([0.0, 5e-324, 1e-323, 1.0])
    with pytest.raises(
        ValueError, match="slopes are beyond the float range.*smallest interval is xdata\\[1\\] - xdata\\[0\\]"
    ):
        SLOPES[name](x, np.array([0.0, 1.0, 2.0, 3.0]))


def test_tiny_data_on_subnormal_spacing_are_fine():
    x = np.array([0.0, 5e-324, 1e-323, 1.5e-323])
    y = np.ldexp(np.array([0.0, 1.0, 4.0, 9.0]), -1074)  # values as tiny as the spacing: slopes of order 1
    assert np.all(np.isfinite(labkit.pchip_slopes(x, y)))


def test_a_cubic_evaluated_beyond_the_float_range_raises():
    with pytest.raises(ValueError, match="value at xval = 1e\\+200 is beyond the float range"):
        labkit.eval_pherm([0.0, 1.0], [0.0, 1.0], [0.0, 3.0], [0.5, 1e200])
    assert np.isnan(labkit.eval_pherm([0.0, 1.0], [0.0, 1.0], [0.0, 3.0], [np.nan]))[0]


@st.composite
def extreme_data(draw):
    """Knots at magnitude 10**kx, values at 10**ky; gaps from a few ulps of the knots up to their size.

    Within one draw the gaps differ by at most 10**4: the splines' conditioning grows with that
    ratio (for not-a-knot about as its square), and beyond it neither scipy nor labkit is accurate.
    """
    kx, ky = draw(st.integers(-300, 300)), draw(st.integers(-300, 300))
    n = draw(st.integers(4, 9))
    smallest = draw(st.floats(-15.0, -4.0))
    exponents = [smallest + e for e in draw(st.lists(st.floats(0.0, 4.0), min_size=n - 1, max_size=n - 1))]
    start = draw(st.floats(-10.0, 10.0))
    gaps = 10.0 ** np.array(exponents)
    x = 10.0**kx * (start + np.concatenate(([0.0], np.cumsum(gaps))))
    x = np.unique(x)
    y = 10.0**ky * np.array(draw(st.lists(st.floats(-1.0, 1.0), min_size=x.size, max_size=x.size)))
    return x, y


def _reference(name, x, y):
    """scipy's knot slopes, computed on the data scaled by powers of two to ordinary numbers and
    scaled back (exact, as the methods are covariant), so that scipy's own intermediate overflow
    (seen: pchip's weighted harmonic mean silently giving 0 for knots near 1e61) does not count."""
    ex, ey = np.frexp(np.max(np.abs(x)))[1], np.frexp(np.max(np.abs(y)) or 1.0)[1]
    xs, ys = np.ldexp(x, -ex), np.ldexp(y, -ey)
    slopes = _scipy(name, xs, ys).copy()
    # scipy's slope at a knot that starts an interval is a stored coefficient, but at the last knot
    # it is the last cubic's derivative at its right end, which cancels (5e-6 relative error seen):
    # take that one from the mirrored problem, where it starts the first interval
    slopes[-1] = -_scipy(name, -xs[::-1], ys[::-1])[0]
    with np.errstate(all="ignore"):
        return np.ldexp(slopes, ey - ex)


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.filter_too_much])
@given(extreme_data(), st.sampled_from(sorted(SLOPES)))
def test_fuzz_extremes_against_scipy_or_a_clear_error(data, name):
    x, y = data
    if x.size < 4:
        return
    reference = _reference(name, x, y)
    try:
        got = SLOPES[name](x, y)
    except ValueError as exc:
        assert "beyond the float range" in str(exc)
        assert not np.all(np.isfinite(reference)), f"the slopes exist: {reference}"
        return
    assert np.all(np.isfinite(reference)), f"labkit gave {got} where the slopes overflow"
    spread = np.max(np.diff(x)) / np.min(np.diff(x))
    with np.errstate(all="ignore"):
        secants = np.abs(np.diff(y) / np.diff(x))
    scale = max(np.max(np.abs(reference)), np.max(secants[np.isfinite(secants)], initial=0.0))
    # accuracy of both: a few ulps of the slope scale, times the conditioning (for not-a-knot about
    # the square of the intervals' spread); below ~1e-300 (subnormal) nothing is relative
    np.testing.assert_allclose(got, reference, rtol=1e-6, atol=max(1e-12 * spread**2 * scale, 1e-300))


# -- what is not real numbers ------------------------------------------------------------------

X3, Y3 = [0.0, 1.0, 2.0], [0.0, 1.0, 0.0]
SQUARE = [labkit.Corner(p, [1.0, 0.0], [0.0, 1.0]) for p in ([0, 0], [1, 0], [1, 1], [0, 1])]
BAD = {
    "complex": lambda good: np.asarray(good, dtype=float) + 1j,
    "None": lambda good: None,
    "object": lambda good: np.array([object()] * np.size(good), dtype=object).reshape(np.shape(good)),
    "bool": lambda good: np.asarray(good, dtype=float) > 0.5,
    "str": lambda good: np.asarray(good, dtype=float).astype(str),
}
MESSAGE = {
    "complex": "complex numbers",
    "None": "None",
    "object": "object where a number should be",
    "bool": "booleans",
    "str": "text, not numbers",
}
# every public function of the library and the arguments that take numbers, with good values
CALLS = {
    "bracket": (labkit.bracket, {"xdata": X3, "xval": 0.5}),
    "eval_plin": (labkit.eval_plin, {"xdata": X3, "ydata": Y3, "xval": 0.5}),
    "eval_pherm": (labkit.eval_pherm, {"xdata": X3, "ydata": Y3, "ypdata": Y3, "xval": 0.5}),
    "hermite_basis": (labkit.hermite_basis, {"xk": 0.0, "xk1": 1.0, "x": 0.5}),
    "ccspline": (labkit.ccspline, {"xdata": X3, "ydata": Y3, "y1p": 0.0, "ynp": 0.0}),
    "ncspline": (labkit.ncspline, {"xdata": X3, "ydata": Y3}),
    "nakspline": (labkit.nakspline, {"xdata": X3, "ydata": Y3}),
    "spline": (labkit.spline, {"xdata": X3, "ydata": Y3, "xval": 0.5}),
    "pchip": (labkit.pchip, {"xdata": X3, "ydata": Y3, "xval": 0.5}),
    "pchip_slopes": (labkit.pchip_slopes, {"xdata": X3, "ydata": Y3}),
    "eval_pbilin": (labkit.eval_pbilin, {"f": np.ones((3, 3)), "xdata": X3, "ydata": X3, "xval": 0.5, "yval": 0.5}),
    "runge": (labkit.runge, {"x": 0.5}),
    "runge2d": (labkit.runge2d, {"x": 0.5, "y": 0.5}),
    "limacon": (labkit.limacon, {"t": 0.5, "r0": 1.15}),
    "Corner": (labkit.Corner, {"point": [0.0, 0.0], "ds": [1.0, 0.0], "dt": [0.0, 1.0], "dsdt": [0.0, 0.0]}),
    "quad_mesh": (labkit.quad_mesh, {"x": np.zeros((2, 2)) + [[0, 0], [1, 1]], "y": np.zeros((2, 2)) + [0, 1]}),
    "QuadMesh": (labkit.QuadMesh, {"points": [[0, 0], [1, 0], [1, 1], [0, 1]], "quads": [[0, 1, 2, 3]]}),
    "patch": (lambda s, t: labkit.patch(*SQUARE, s, t), {"s": [0.0, 0.5, 1.0], "t": [0.0, 1.0]}),
    "convergence_table": (
        lambda **kw: labkit.convergence_table("plin", **kw),
        {"ndata": [5, 11], "interval": [0.0, 5.0], "ntest": 101},
    ),
    "ratio_table": (
        lambda ndata, errors: labkit.ratio_table("t", ndata, errors),
        {"ndata": [5, 11], "errors": [0.1, 0.01]},
    ),
    "bilinear_convergence": (labkit.bilinear_convergence, {"ndata": [5, 9], "square": [0.0, 5.0], "ntest": 11}),
}
# public names that take no numbers from a user, and why: everything else in labkit.__all__ must be in CALLS
NO_NUMBERS = {
    "ConvergenceTable": "a record built by convergence_table and bilinear_convergence, which are in CALLS",
    "ready": "takes a version text; tested in labkit/notebook.py's doctest",
    "ready_to_hand_in": "takes a notebook's name and its variables; bad ones are tested in tests/library/test_handin.py",
}


def test_every_public_function_has_its_bad_input_cases():
    """A new public function fails here until it is in CALLS (or in NO_NUMBERS, with a reason)."""
    assert set(CALLS) | set(NO_NUMBERS) == set(labkit.__all__), set(labkit.__all__) ^ (set(CALLS) | set(NO_NUMBERS))
    assert not set(CALLS) & set(NO_NUMBERS)


CASES = [
    (name, arg, bad)
    for name, (_, kwargs) in CALLS.items()
    for arg in kwargs
    for bad in BAD
    if not (arg == "dsdt" and bad == "None")
]  # a Corner without a twist is allowed: dsdt=None means 0


@pytest.mark.parametrize("name, arg, bad", CASES, ids=[f"{n}-{a}-{b}" for n, a, b in CASES])
def test_every_argument_refuses_what_is_not_real_numbers(name, arg, bad):
    function, kwargs = CALLS[name]
    function(**kwargs)  # the good call works
    kwargs = {**kwargs, arg: BAD[bad](kwargs[arg])}
    with pytest.raises(ValueError, match=MESSAGE[bad] if arg != "quads" else "quads"):
        function(**kwargs)


@pytest.mark.parametrize(
    "call, message",
    [
        (lambda: labkit.convergence_table(np.array(["plin"], dtype=object)), "unknown method"),
        (lambda: labkit.convergence_table("plin", ndata=[5, 10.5]), "whole numbers"),
        (lambda: labkit.convergence_table("plin", ntest=2.5), "whole number of test points"),
        (lambda: labkit.bilinear_convergence(ntest=True), "booleans"),
    ],
)
def test_tables_refuse_what_is_not_a_count(call, message):
    with pytest.raises(ValueError, match=message):
        call()
