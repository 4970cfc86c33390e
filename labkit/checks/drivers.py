"""Checks for the convergence experiments: the drivers, their tables and the rate answers.

Exercises 3, 11, 12(g-i), 13, 15 and 16(e-g) each ask for the same three
things, so one check of each kind serves every method:

* :func:`driver` - the student's ``test_..._interpolate(ndata, f, ...)``
  returns the relative maximum error of one row of the table. It is compared
  with labkit's experiment (:func:`labkit.convergence_table`,
  :func:`labkit.bilinear_convergence`) and, when it disagrees, with the
  usual slips (another interval, other test points, an absolute error) so
  the hint can name the slip;
* :func:`table` - the error list for the lab's sizes is what the student's
  driver returns for them (to the four significant digits that
  :func:`labkit.ratio_table` prints, so a table typed in from the printout
  counts), and it shows an experiment: its errors shrink as ``ndata`` grows,
  with an observed order of at least :data:`MIN_ORDER` across the table;
* :func:`rate` - the rate answer is the order the student's own table
  supports, stated as the exponent ``p`` of the nearest power of two
  ``2**p`` to the ratios; a table that shows no experiment supports none.

The pieces a driver builds on (the Runge function, the interpolant or the
spline's slopes) are handed to it by the check, from labkit, so a mistake in
an earlier exercise is not counted again here. The functions handed over are
module-level functions, so ``labkit grade`` can name them to the sandboxed
notebook (:data:`labkit.grading.protocol.PASSABLE`).
"""
import functools
from dataclasses import dataclass

import numpy as np

from .. import bilinear, convergence, functions, piecewise, splines
from .result import CheckResult, call, case_rng, shown

DRIVER_TOLERANCE = 1e-6  # relative: the driver's error against the reference error
PRINTED = 6e-4  # relative: a table copied from ratio_table's four significant digits (half a unit is 5e-4)
MIN_ORDER = 0.5  # observed order across the table below which it shows no experiment


def scaled_runge(x):
    """3 / (1 + (x-1)^2) with its derivative: the Runge function moved right by 1 and scaled by 3.

    Its maximum on [0, 5] is 3, so an absolute error is three times the
    relative one, and a driver that ignores its `f` gives the Runge
    function's error instead. Written out rather than calling
    :func:`labkit.runge`, which is switched off while Exercise 3 is graded.
    """
    u = np.asarray(x, dtype=float) - 1.0
    return 3.0 / (1.0 + u * u), -6.0 * u / (1.0 + u * u) ** 2


def scaled_runge2d(x, y):
    """3 / (1 + (x+y-1)^2): the two-dimensional Runge function moved and scaled (see :func:`scaled_runge`)."""
    s = np.asarray(x, dtype=float) + np.asarray(y, dtype=float) - 1.0
    return 3.0 / (1.0 + s * s)


@dataclass(frozen=True)
class Method:
    """One convergence experiment of the lab."""

    key: str  # labkit.convergence_table's method, or "bilinear"
    driver: str  # the student's function
    table: str  # the student's error list
    rate: str  # the student's rate answer
    title: str
    ndata: tuple
    pieces: tuple = ()  # what the check hands the driver after ndata and f
    ntest: int = 4001

    def f(self, scaled=False):
        if self.key == "bilinear":
            return scaled_runge2d if scaled else functions.runge2d
        return scaled_runge if scaled else functions.runge

    def reference(self, ndata, scaled=False, interval=(0.0, 5.0), ntest=None):
        """The relative errors labkit's experiment gives for `ndata` (a sequence of sizes)."""
        ntest = ntest or self.ntest
        sizes = list(ndata) * 2 if len(ndata) == 1 else list(ndata)  # the tables want two sizes
        if self.key == "bilinear":
            found = convergence.bilinear_convergence(sizes, self.f(scaled), interval, ntest)
        else:
            found = convergence.convergence_table(self.key, sizes, self.f(scaled), interval, ntest)
        return found.errors[: len(ndata)]

    @property
    def order(self):
        """The order the reference table shows (the lab's answer)."""
        return _reference_order(self)


@functools.lru_cache(maxsize=None)
def _reference_order(method):
    """Computed once per experiment: a grading run asks for it once per submission."""
    return convergence.ConvergenceTable(method.title, np.array(method.ndata), method.reference(method.ndata)).order


LAB_NDATA = convergence.DEFAULT_NDATA
METHODS = {m.key: m for m in (
    Method("pherm", "test_pherm_interpolate", "errors_pherm", "rate_pherm", "Piecewise Hermite Cubic", LAB_NDATA,
           (piecewise.eval_pherm,)),
    Method("complete", "test_ccspline_interpolate", "errors_complete", "rate_complete", "Complete Cubic Spline",
           LAB_NDATA, (splines.ccspline,)),
    Method("natural", "test_ncspline_interpolate", "errors_natural", "rate_natural", "Natural Cubic Spline",
           LAB_NDATA, (splines.ncspline,)),
    Method("notaknot", "test_spline_interpolate", "errors_notaknot", "rate_notaknot", "Not-A-Knot Cubic Spline",
           LAB_NDATA),
    Method("pchip", "test_pchip_interpolate", "errors_pchip", "rate_pchip", "Monotone Cubic Interpolation",
           LAB_NDATA),
    Method("bilinear", "test_pbilin_interpolate", "errors_bilinear", "rate_bilinear", "Piecewise Bilinear",
           (11, 21, 41, 81, 161), (bilinear.eval_pbilin,), ntest=401),
)}


def _method(key):
    if key not in METHODS:
        raise ValueError(f"unknown experiment {key!r}; choose one of {', '.join(map(repr, METHODS))}.")
    return METHODS[key]


def _number(value):
    """A float from a student's value, or None if it is not one finite number."""
    if getattr(value, "not_numbers", False) or isinstance(value, (str, bytes)):
        return None
    try:
        number = float(np.asarray(value, dtype=float).reshape(()))
    except (TypeError, ValueError):
        return None
    return number if np.isfinite(number) else None


def _agrees(value, expected, tol=DRIVER_TOLERANCE):
    number = _number(value)
    return number is not None and abs(number - expected) <= tol * abs(expected) + 1e-300


def _diagnosis(method, got, ndata):
    """The usual slip that explains an error value, or None."""
    number = _number(got)
    if number is None:
        return None
    if abs(number) < 1e-14:
        return ("The error is 0: it looks measured only at the data points, where every interpolant is exact; "
                f"use {method.ntest} equally spaced test points.")
    other_points = (4000, 401, 1001, 1000, 201, 101, 100, 40001) if method.ntest == 4001 else (400, 4001, 101, 100, 201)
    slips = [(f"The error looks measured on [{a:g}, {b:g}] instead of [0, 5].", {"interval": (a, b)})
             for a, b in ((-5.0, 5.0), (0.0, 1.0), (-1.0, 1.0), (0.0, 10.0), (1.0, 5.0))]
    slips += [(f"The error looks measured at {n} test points instead of {method.ntest}.", {"ntest": n})
              for n in other_points]
    for description, options in slips:
        try:
            expected = method.reference([ndata], **options)[0]
        except ValueError:
            continue
        if _agrees(got, expected):
            return description
    return None


def driver(key, fn, seed=None):
    """Check the driver of experiment `key`: ``fn(ndata, f, *pieces)`` is the relative max error.

    The driver gets labkit's Runge function as `f` (and labkit's interpolant
    or spline slopes where it takes them), then :func:`scaled_runge`, whose
    maximum is 3: an absolute error comes out three times too large, and a
    driver that ignores `f` gives the Runge function's error.
    """
    method = _method(key)
    result = CheckResult(method.driver)
    sizes = method.ndata[:3]
    if seed is not None:  # the grader's fresh size: never one of the sizes checked anyway
        fresh = [n for n in range(6, 60) if n not in method.ndata]
        sizes += (int(case_rng(seed, f"drivers.driver.{key}").choice(fresh)),)
    where = (f"[0, 5]^2 with {method.ntest} x {method.ntest} test points" if key == "bilinear"
             else f"[0, 5] with {method.ntest} test points")
    for ndata in sizes:
        ok, err = call(result, f"ndata = {ndata}", fn, ndata, method.f(), *method.pieces)
        if not ok:
            return result
        expected = method.reference([ndata])[0]
        if not result.step(f"Err({ndata}) = max|f - p| / max|f| on {where}",
                           _agrees(err, expected), f"got {shown(err)}, expected {expected:.6e}"):
            slip = _diagnosis(method, err, ndata)
            result.hint = (slip if slip else
                           f"use ndata equally spaced data points on [0, 5] from f, {method.ntest} equally spaced "
                           "test points on [0, 5], and divide the largest error by max|f| there.")
            return result
    ndata = sizes[1]
    other = "3 / (1 + (x + y - 1)^2)" if key == "bilinear" else "3 / (1 + (x - 1)^2)"
    ok, err = call(result, f"f = {other}", fn, ndata, method.f(scaled=True), *method.pieces)
    if not ok:
        return result
    expected = method.reference([ndata], scaled=True)[0]
    if not result.step(f"the error is relative to max|f|, for f = {other} too",
                       _agrees(err, expected), f"got {shown(err)}, expected {expected:.6e}"):
        number = _number(err)
        tripled = number is not None and abs(number - 3 * expected) <= DRIVER_TOLERANCE * 3 * expected
        result.hint = ("the error is absolute, not relative to max|f|: divide the largest error by max|f| over "
                       "the test points (for the Runge function on [0, 5] that is 1, which hides the slip)."
                       if tripled else "compute f from the function passed in as `f`, not from runge itself.")
    return result


def observed_order(key, errors):
    """The order across a whole table: log(Err(first)/Err(last)) / log(h(first)/h(last)); None if not a table."""
    method = _method(key)
    values = _numbers(errors)
    if values is None or values.shape != (len(method.ndata),):
        return None
    return float(np.log(values[0] / values[-1]) / np.log((method.ndata[-1] - 1) / (method.ndata[0] - 1)))


def _no_experiment(method, values):
    return (f"the errors do not shrink as ndata grows (Err({method.ndata[0]}) = {values[0]:.3e}, "
            f"Err({method.ndata[-1]}) = {values[-1]:.3e}): this table shows no experiment")


def table(key, errors, fn):
    """Check the error list of experiment `key`: what the student's driver `fn` returns for the lab's
    sizes, and an experiment that converges.

    The driver is called as the student would, ``fn(ndata)`` with its own
    defaults, so the table follows the student's own functions: a mistake
    in them is marked where they are checked, not again here. A table that
    does not shrink (a driver returning a constant, say) earns nothing.
    """
    method = _method(key)
    result = CheckResult(method.table)
    sizes = ", ".join(map(str, method.ndata))
    description = f"one error per ndata = {sizes}"
    values = _numbers(errors)
    if values is None or values.shape != (len(method.ndata),):
        return result.fail(description, f"got {shown(errors)}",
                           f"make {method.table} a list of {len(method.ndata)} positive errors: "
                           f"[{method.driver}(n) for n in {list(method.ndata)}].")
    result.step(description, True)
    own = []
    for ndata in method.ndata:
        ok, err = call(result, f"{method.driver}({ndata}) runs", fn, ndata)
        if not ok:
            result.hint = f"{method.table} is checked against what {method.driver} returns, so the driver must run."
            return result
        own.append(_number(err))
    agree = None not in own and bool(np.allclose(values, own, rtol=PRINTED, atol=0))
    if not result.step(f"the errors are what {method.driver} returns for each ndata (to 4 significant digits)",
                       agree, f"got {np.array2string(values, precision=3)}"):
        result.hint = f"fill the table by running your driver: [{method.driver}(n) for n in {list(method.ndata)}]."
        return result
    order = observed_order(key, values)
    if not result.step(f"the errors shrink as ndata grows (an observed order of at least {MIN_ORDER} across "
                       "the table)", order >= MIN_ORDER, _no_experiment(method, values)):
        result.hint = (f"{method.driver} must interpolate f from ndata points and measure the error at the test "
                       "points; with more points the error gets smaller.")
    return result


def _numbers(value):
    if getattr(value, "not_numbers", False):
        return None
    try:
        values = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        return None
    return values if values.ndim == 1 and np.all(np.isfinite(values)) and np.all(values > 0) else None


def supported_order(key, errors):
    """The order a table of errors supports, as labkit estimates it; None if it is not a table that
    shows an experiment (errors that shrink with an observed order of at least MIN_ORDER)."""
    method = _method(key)
    values = _numbers(errors)
    if values is None or values.shape != (len(method.ndata),):
        return None
    if observed_order(key, values) < MIN_ORDER:
        return None
    return convergence.ConvergenceTable(method.title, np.array(method.ndata), values).order


def rate(key, answer, errors=None):
    """Check the rate answer of experiment `key`: the exponent p with Err(n)/Err(2n-1) close to 2**p,
    read from the student's own table `errors`.

    The answer must be the order that table supports: a student whose
    table is off but who reads it correctly is not marked down twice, and a
    rate with no table that shows an experiment earns nothing.
    """
    method = _method(key)
    result = CheckResult(method.rate)
    description = "the rate is the exponent p of the nearest power of two 2**p to your table's ratios"
    values = _numbers(errors)
    if values is None or values.shape != (len(method.ndata),):
        return result.fail(description, f"{method.table} is not a table of {len(method.ndata)} positive errors "
                                        "yet, so there is nothing to read the rate from",
                           f"fill {method.table} first, then read the rate off its ratios.")
    own = supported_order(key, values)
    if own is None:
        return result.fail(description, _no_experiment(method, values) + ", so it supports no rate",
                           f"fix {method.driver} so that its errors shrink, refill {method.table}, then read the "
                           "rate off the ratios.")
    number = _number(answer)
    if number is None or number != round(number):
        return result.fail(description, f"got {shown(answer)}",
                           f"set {method.rate} to a whole number p: the ratios Err(41)/Err(81), ... are close to 2**p.")
    p = int(round(number))
    if p == own:
        result.step(description, True)
        return result
    exponent = p.bit_length() - 1 if p > 1 else None
    if exponent is not None and p == 2 ** exponent and exponent == own:
        hint = f"{p} is the ratio itself, 2**{exponent}; the rate is its exponent {exponent}."
    else:
        hint = ("take the ratios Err(41)/Err(81), Err(81)/Err(161), ... of your table; they settle near a power "
                "of two 2**p, and p is the rate.")
    result.fail(description, f"got {p}; your table's ratios support {own}", hint)
    return result
