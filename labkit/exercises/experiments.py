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

The table and the rate are checked together (:func:`experiment`), against
one run of the student's driver: neither earns a point without a driver that
runs and whose errors shrink, so a table typed in from elsewhere, and a rate
read off it, earn nothing. The one exception is a real driver (given labkit's
pieces, it measures the experiment: :func:`honest_driver`) whose errors stand
still with the student's own pieces: its table is what it honestly measured.

The pieces a driver builds on (the Runge function, the interpolant or the
spline's slopes) are handed to it by the check, from labkit, so a mistake in
an earlier exercise is not counted again here. The functions handed over are
module-level functions, so ``labkit grade`` can name them to the sandboxed
notebook: the declaration lists them (:attr:`Experiment.passes`).

With variants (:mod:`labkit.exercises.variants`) every table on the Runge
function is on the student's own scale of it, :data:`RUNGE_A`: the table and
the rate are judged against the driver run on ``labkit.runge`` with that scale
bound (a partial with one float keyword, which crosses into the sandbox by
name too), while the driver itself is checked on labkit's functions as always.
"""

import functools
from dataclasses import dataclass

import numpy as np

from .. import bilinear, convergence, functions, piecewise, splines
from . import answer_key
from .model import EXPERIMENTS, Part
from .result import NOT_DONE, CheckResult, call, case_rng, floats, judged_by_the_lab, shown
from .variants import Param

DRIVER_TOLERANCE = 1e-6  # relative: the driver's error against the reference error
PRINTED = 6e-4  # relative: a table copied from ratio_table's four significant digits (half a unit is 5e-4)
MIN_ORDER = 0.5  # observed order across the table below which it shows no experiment
# the size at which a driver is called with the shifted, scaled Runge function: its spacing 5/8 does not
# divide the shift of 1, so the shifted function's relative error is not the Runge function's (at 11 or 21
# points the shift is a whole number of intervals and the two errors coincide)
SHIFTED_PROBE = 9
# the scale a of the Runge function 1/(1 + a x^2) a student's tables measure: one datum for every experiment on
# it, drawn with Exercise 3 (where the student writes runge). Over [0.5, 2] every table shows the lab's orders
# (tests/exercises/test_variants.py), and 4 decimals give 15001 values: a class of 100 has a tie about one time
# in four, which release and `labkit variants --check` name for a redraw
RUNGE_A = Param("runge_a", 0.5, 2.0, 4, lab=1.0, drawn_with=3)
# the scale a of the two-dimensional Runge function 1/(1 + a (x+y)^2) of Exercise 16, which the student writes and
# the bilinear table measures: over [0.5, 2] the table shows order 2
RUNGE2D_A = Param("runge2d_a", 0.5, 2.0, 4, lab=1.0)


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


def runge_sign_slip(x, a=1.0):
    """The Runge function 1/(1 + a x^2) with the sign slip in its derivative (+2ax/(1+ax^2)^2), as Exercise 3's
    check names it: what a driver's own `f` may be and still count as an attempt at the experiment. Written
    out (see :func:`scaled_runge`)."""
    x = np.asarray(x, dtype=float)
    return 1.0 / (1.0 + a * x * x), 2.0 * a * x / (1.0 + a * x * x) ** 2


def runge_unsquared(x, a=1.0):
    """The Runge function with -2ax/(1+ax^2) as its derivative: the chain-rule slip Exercise 3's check names."""
    x = np.asarray(x, dtype=float)
    return 1.0 / (1.0 + a * x * x), -2.0 * a * x / (1.0 + a * x * x)


def runge_inner_a_left_out(x, a=1.0):
    """The Runge function 1/(1 + a x^2) with -2x/(1+ax^2)^2 as its derivative: the chain rule's inner factor a
    left out, the slip Exercise 3's check names when a student has their own scale."""
    x = np.asarray(x, dtype=float)
    return 1.0 / (1.0 + a * x * x), -2.0 * x / (1.0 + a * x * x) ** 2


# every Runge function with a slip a driver's own f may be (at the student's scale, or ignoring it): the checks
# hand them to the driver, so they are declared to cross into the sandbox (Part.passes)
RUNGE_SLIPS = (runge_sign_slip, runge_unsquared, runge_inner_a_left_out)


def _at(function, a):
    """`function` of the Runge function's scale at `a`: itself at the lab's scale, else bound to `a` (a partial of a
    module-level function with one float keyword crosses into the sandbox by name)."""
    return function if a is None or a == RUNGE_A.lab else functools.partial(function, a=float(a))


def runge2d_product(x, y, a=1.0):
    """1 / (1 + a (x y)^2): the slip in ``runge2d`` the catalog of typical mistakes plants (a product for the sum)."""
    p = np.asarray(x, dtype=float) * np.asarray(y, dtype=float)
    return 1.0 / (1.0 + a * p * p)


@dataclass(frozen=True)
class Experiment:
    """One convergence experiment of the lab, as its exercise declares it.

    ``key`` is the method (:func:`labkit.convergence_table`'s, or
    ``"bilinear"``), whose title the library keeps; ``order`` is the order the
    lab expects the table to show (tests check that labkit's own table shows
    it). ``driver``, ``table`` and ``rate`` are the student's names, and
    ``weights`` their parts' weights. ``pieces`` are what the check hands the
    driver after ``ndata`` and ``f``. ``uses`` are the student's earlier
    functions the driver calls by default (its ``f`` and pieces, and what
    they call): every part of the experiment relies on them
    (:attr:`labkit.exercises.model.Part.uses`).
    """

    key: str
    order: int
    driver: str
    table: str
    rate: str
    weights: tuple = (1, 1, 1)
    pieces: tuple = ()
    ndata: tuple = convergence.DEFAULT_NDATA
    ntest: int = 4001
    uses: tuple = ()

    @property
    def title(self):
        if self.key == "bilinear":
            return "Piecewise Bilinear"
        return convergence.METHOD_TITLES[self.key]

    @property
    def scale(self):
        """The student's datum the table and the rate are checked against: the test function's scale."""
        return RUNGE2D_A if self.key == "bilinear" else RUNGE_A

    @property
    def varied(self):
        return (self.scale.name,)

    def f(self, scaled=False, a=None):
        """The test function: the lab's (the Runge function with scale `a`, the lab's when None), or the moved,
        scaled one the driver check tells a relative error by."""
        if self.key == "bilinear":
            return scaled_runge2d if scaled else _at(functions.runge2d, a)
        return scaled_runge if scaled else _at(functions.runge, a)

    def formula(self, a):
        """The student's test function in words, with their scale."""
        if self.key == "bilinear":
            return f"1/(1 + runge2d_a (x+y)^2) with your runge2d_a = {self.scale.shown(a)}"
        return f"1/(1 + runge_a x^2) with your runge_a = {self.scale.shown(a)}"

    @property
    def passes(self):
        """Every function the checks hand the driver: the pieces and both test functions."""
        return tuple(self.pieces) + (self.f(), self.f(scaled=True))

    def f_slips(self, a=None, own_data=True):
        """The test function (with scale `a`) with each slip its own check names: a driver's own `f` may be one
        of them. With a student's own scale, a driver whose default `f` is the student's own function
        (runge in Exercise 3, runge2d in 16) and a notebook holding the student's own scale (`own_data`), the
        lab's function, with or without those slips, is one too: a function that ignores the scale is marked in
        its own part. A notebook holding another scale (a copy, or the lab's release) is not the student's
        experiment, nor is a notebook on the lab's function where the notebook gives it (exercises 11 to 15)."""
        lab_slips = (runge2d_product,) if self.key == "bilinear" else (runge_sign_slip, runge_unsquared)
        if self.f(a=a) is self.f():
            return lab_slips
        slips = tuple(_at(slip, a) for slip in ((runge2d_product,) if self.key == "bilinear" else RUNGE_SLIPS))
        own = "runge2d" if self.key == "bilinear" else "runge"
        return slips + ((self.f(),) + lab_slips if own in self.uses and own_data else ())

    @property
    def slip_functions(self):
        """Every function :meth:`f_slips` may hand a driver, whatever the student's scale."""
        return (runge2d_product, functions.runge2d) if self.key == "bilinear" else RUNGE_SLIPS + (functions.runge,)

    def reference(self, ndata, scaled=False, interval=(0.0, 5.0), ntest=None, a=None):
        """The relative errors labkit's experiment gives for `ndata` (a sequence of sizes), on the Runge function
        with scale `a` (the lab's when None)."""
        # computed once per process: the driver's check and the table's ask for the same ones, and a driver's
        # slips are looked for at each size (a bilinear one at 4001 x 4001 test points takes seconds)
        a = None if a is None or float(a) == self.scale.lab else float(a)
        return _reference(self, tuple(int(n) for n in ndata), scaled, tuple(interval), ntest or self.ntest, a).copy()

    def sound(self, values):
        """Why the Runge function's scale in `values` would not teach this experiment's lesson ('' when it does):
        its table must show the lab's order."""
        a = values.get(self.scale.name)
        shown = convergence.ConvergenceTable(self.title, np.array(self.ndata), self.reference(self.ndata, a=a)).order
        if shown != self.order:
            return (
                f"with {self.scale.name} = {a} the {self.title.lower()}'s table shows order {shown}, not the lab's "
                f"{self.order}"
            )
        return ""

    @property
    def observed_order(self):
        """The order labkit's own table shows (the declared ``order`` must be it)."""
        return _reference_order(self)

    @property
    def withheld(self):
        """What the experiment asks the student to find, for the exercise's ``withheld``: the order (as a text
        would state it, and as the rate answer) and labkit's table (as it prints), computed when asked for."""
        return answer_key.orders(self.order, self.rate) + (answer_key.values(lambda: self.reference(self.ndata)),)

    def parts(self):
        """The experiment's three parts: the driver, the table and the rate answer.

        The table and the rate share one run of the student's driver at the
        lab's sizes (:func:`check_experiment`): both are read from what the
        driver returns, so neither is earned by numbers typed in from elsewhere.
        """
        driver, table, rate = self.weights
        both = (self.table, self.rate, self.driver)
        return (
            ExperimentPart(
                self.driver,
                driver,
                check_driver,
                reads=(self.driver,),
                seeded=True,
                refused=EXPERIMENTS,
                passes=self.passes,
                uses=self.uses,
                experiment=self,
            ),
            ExperimentPart(
                self.table,
                table,
                check_experiment,
                reads=both,
                index=0,
                refused=EXPERIMENTS,
                passes=self.passes + self.slip_functions,
                functions=(self.table, self.driver),
                uses=self.uses,
                varied=self.varied,
                experiment=self,
            ),
            ExperimentPart(
                self.rate,
                rate,
                check_experiment,
                reads=both,
                index=1,
                refused=EXPERIMENTS,
                passes=self.passes + self.slip_functions,
                functions=(self.rate, self.driver),
                uses=self.uses,
                varied=self.varied,
                experiment=self,
            ),
        )

    def names(self):
        return (self.driver, self.table, self.rate)


@dataclass(frozen=True)
class ExperimentPart(Part):
    """A part of a convergence experiment: its check takes the experiment first, and reads what is missing as
    :data:`MISSING` (the table and the rate say which name is missing)."""

    experiment: Experiment | None = None

    @property
    def self_check(self):
        return {check_driver: "driver", check_experiment: ("table" if self.index == 0 else "rate")}[self.check]

    def run(self, namespace, seed=None, variant=None):
        values = [
            namespace[name] if name in namespace or self.check is check_driver else MISSING for name in self.reads
        ]
        if self.check is check_driver:
            return check_driver(self.experiment, *values, seed=seed)
        name = self.experiment.scale.name
        a = (variant or {}).get(name) if name in self.varied else None
        held = _number(namespace[name]) if a is not None and name in namespace else None
        own_data = held is None or self.experiment.scale.holds(held, a)  # the data cell shows the student's scale
        return check_experiment(self.experiment, *values, scale=a, own_data=own_data)


@functools.lru_cache(maxsize=1024)  # a grading run asks for each student's scale where a table is judged by it
def _reference(method, ndata, scaled, interval, ntest, a=None):
    """:meth:`Experiment.reference`, computed."""
    sizes = list(ndata) * 2 if len(ndata) == 1 else list(ndata)  # the tables want two sizes
    if method.key == "bilinear":
        found = convergence.bilinear_convergence(sizes, method.f(scaled, a), interval, ntest)
    else:
        found = convergence.convergence_table(method.key, sizes, method.f(scaled, a), interval, ntest)
    return found.errors[: len(ndata)]


@functools.cache
def _reference_order(method):
    """Computed once per experiment: a grading run asks for it once per submission."""
    return convergence.ConvergenceTable(method.title, np.array(method.ndata), method.reference(method.ndata)).order


def _reference_error(key, ndata):
    """labkit's relative error of method `key` on the Runge function at `ndata` points (a slip's signature)."""
    return convergence.convergence_table(key, [ndata] * 2, functions.runge).errors[0]


def _number(value):
    """A float from a student's value, or None if it is not one finite number."""
    if getattr(value, "not_numbers", False) or isinstance(value, (str, bytes)):
        return None
    try:
        number = float(floats(value).reshape(()))
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
        return (
            "The error is 0: it looks measured only at the data points, where every interpolant is exact; "
            f"use {method.ntest} equally spaced test points."
        )
    other_points = (4000, 401, 1001, 1000, 201, 101, 100, 40001) if method.ntest == 4001 else (400, 4001, 101, 100, 201)
    slips = [
        (f"The error looks measured on [{a:g}, {b:g}] instead of [0, 5].", {"interval": (a, b)})
        for a, b in ((-5.0, 5.0), (0.0, 1.0), (-1.0, 1.0), (0.0, 10.0), (1.0, 5.0))
    ]
    slips += [
        (f"The error looks measured at {n} test points instead of {method.ntest}.", {"ntest": n}) for n in other_points
    ]
    for description, options in slips:
        try:
            expected = method.reference([ndata], **options)[0]
        except ValueError:
            continue
        if _agrees(got, expected):
            return description
    for description, expected in _other_methods(method, ndata):
        if _agrees(got, expected):
            return description
    for description, error in _measurement_slips(method, ndata):
        try:
            with np.errstate(all="ignore"):
                expected = error()
        except (ValueError, np.linalg.LinAlgError):  # too few points for the method
            continue
        if _agrees(got, expected):
            return description
    return None


@functools.lru_cache(maxsize=16)
def _measured(method, ndata, data="values", against=0):
    """The exact values at the test points and the error f - p of a driver of `method` at `ndata`, with the
    interpolant built from the Runge function's `data` ("values": as f returns them, "swapped": values and
    derivatives swapped, "derivatives": the derivatives as values) and compared with row `against` of what f
    returns (0 the values, 1 the derivatives). Kept for the next slip: a driver's slips share them."""
    if method.key == "bilinear":
        grid, test = np.linspace(0.0, 5.0, ndata), np.linspace(0.0, 5.0, method.ntest)
        exact = functions.runge2d(*np.meshgrid(test, test, indexing="ij"))
        return exact, exact - bilinear.eval_pbilin(functions.runge2d, grid, grid, test, test)
    rows = {"values": lambda y, yp: (y, yp), "swapped": lambda y, yp: (yp, y), "derivatives": lambda y, yp: (yp, yp)}
    xtest = np.linspace(0.0, 5.0, method.ntest)
    exact = functions.runge(xtest)[against]
    f = lambda x: rows[data](*functions.runge(x))
    return exact, exact - convergence._interpolate(method.key, f, 0.0, 5.0, ndata, xtest)


def _slip_error(method, ndata, norm="max", **how):
    """The error a driver of `method` returns at `ndata` when it measures as :func:`_measured` says, in the
    `norm`: "max" (the lab's), "2", "mean", or "signed+" / "signed-" (the largest of f - p or p - f, with its
    sign)."""
    exact, error = _measured(method, ndata, **how)
    scale = np.max(np.abs(exact))
    return float(
        {
            "max": lambda: np.max(np.abs(error)) / scale,
            "2": lambda: np.linalg.norm(error) / np.linalg.norm(exact),
            "mean": lambda: np.mean(np.abs(error)) / scale,
            "signed+": lambda: np.max(error) / scale,
            "signed-": lambda: np.max(-error) / scale,
        }[norm]()
    )


def _cut_error(method, ndata, cut):
    """The relative max error of a driver whose test points are the lab's with `cut` taken (one end left out)."""
    exact, error = _measured(method, ndata)
    return float(np.max(np.abs(error[cut])) / np.max(np.abs(exact[cut])))


def _scaled_at_the_data(method, ndata, expected):
    """The error a driver gives on the moved, scaled f when it divides by max|f| at the data points instead of
    over the test points (`expected` is the lab's relative error there)."""
    f = method.f(scaled=True)
    data, test = np.linspace(0.0, 5.0, ndata), np.linspace(0.0, 5.0, method.ntest)
    if method.key == "bilinear":
        at = lambda x: np.asarray(f(*np.meshgrid(x, x, indexing="ij")), dtype=float)
    else:
        at = lambda x: np.asarray(f(x)[0], dtype=float)
    return expected * np.max(np.abs(at(test))) / np.max(np.abs(at(data)))


SCALED_AT_THE_DATA = (
    "the error is divided by max|f| at the data points, not over the test points: the largest |f| can fall "
    "between data points (for the Runge function on [0, 5] it is at a data point, which hides the slip)."
)


MEASURED = "the lab's error is the largest |f - p| over the test points (the infinity norm), relative to max|f|"


def _measurement_slips(method, ndata):
    """(hint, a function giving the error) of the usual slips in how a driver measures, besides the interval
    and the test points: the number of data points, the norm of the error, the row of what f returns, an end
    slope's index. The errors are computed as they are asked for."""
    found = [
        (
            f"The data look like ndata {'+' if n > ndata else '-'} 1 data points ({n} for ndata = {ndata}): "
            "the driver interpolates f from ndata equally spaced points on [0, 5].",
            lambda n=n: _slip_error(method, n),
        )
        for n in (ndata + 1, ndata - 1)
        if n >= (4 if method.key == "notaknot" else 2)
    ]
    found += [
        (
            "The error looks like the square root of the sum of squares of f - p (a 2-norm), not the largest "
            f"difference: {MEASURED}.",
            lambda: _slip_error(method, ndata, "2"),
        ),
        (
            f"The error looks like the mean of |f - p| over the test points, not its largest value: {MEASURED}.",
            lambda: _slip_error(method, ndata, "mean"),
        ),
    ]
    found += [
        (
            "The error takes no absolute value: it is the largest difference with its sign, not the largest "
            f"|f - p|; {MEASURED}.",
            lambda norm=norm: _slip_error(method, ndata, norm),
        )
        for norm in ("signed+", "signed-")
    ]
    if method.key != "bilinear":
        found += [
            (
                f"The error leaves out the {end} test point (x = {where}): the lab's {method.ntest} test points run "
                "from 0 to 5, both ends included.",
                lambda cut=cut: _cut_error(method, ndata, cut),
            )
            for end, where, cut in (("first", 0, slice(1, None)), ("last", 5, slice(None, -1)))
        ]
        found.append(
            (
                "The error looks measured against f's derivatives, the second of the two things f returns, "
                "instead of its values (the first).",
                lambda: _slip_error(method, ndata, against=1),
            )
        )
        if method.key == "pherm":
            found.append(
                (
                    "The values and the slopes of the data look swapped: f returns the values first, then the "
                    "derivatives.",
                    lambda: _slip_error(method, ndata, data="swapped"),
                )
            )
        elif method.key != "complete":
            found.append(
                (
                    "The data look like f's derivatives, the second of the two things f returns, instead of its "
                    "values (the first): interpolate the values.",
                    lambda: _slip_error(method, ndata, data="derivatives"),
                )
            )
    if method.key == "complete":
        found += [
            (
                f"The {which} end slope looks like f' at the {where}: Python counts from 0, so the first data "
                "point is index 0 and the last is index -1 (or ndata - 1).",
                lambda ends=ends: _complete_error(ndata, ends),
            )
            for which, where, ends in (
                ("first", "second data point (index 1), not the first", lambda yp: (yp[1], yp[-1])),
                ("last", "next-to-last data point, not the last", lambda yp: (yp[0], yp[-2])),
            )
        ]
    return found


OTHER_METHOD_HINTS = {
    ("notaknot", "complete"): "spline(xdata, ydata, xval) with ydata alone gives the not-a-knot spline; with the "
    "end slopes added to ydata it gives the complete one",
    ("natural", "complete"): "use the slopes function passed in (your ncspline), not ccspline",
    ("complete", "natural"): "use the slopes function passed in (your ccspline) with the end slopes f'(0), f'(5)",
    ("pchip", "notaknot"): "use pchip, not spline",
    ("notaknot", "pchip"): "use spline, not pchip",
}


def _other_methods(method, ndata):
    """(hint, error) of what a driver gives when it builds another interpolant than its own."""
    if method.key == "bilinear":
        return []
    found = []
    for other in ("pherm", "complete", "natural", "notaknot", "pchip"):
        if other == method.key:
            continue
        advice = OTHER_METHOD_HINTS.get((method.key, other), f"build the {method.title.lower()} itself")
        found.append(
            (
                f"That is the {convergence.METHOD_TITLES[other].lower()}'s error, not the {method.title.lower()}'s: "
                f"{advice}.",
                _reference_error(other, ndata),
            )
        )
    if method.key == "complete":
        found += [
            (
                f"The end slopes look like {wrong}: the complete spline takes the derivatives f returns at "
                "the first and the last data point, in that order.",
                _complete_error(ndata, ends),
            )
            for wrong, ends in (
                ("0 and 0", lambda yp: (0.0, 0.0)),
                ("the last and the first (swapped)", lambda yp: (yp[-1], yp[0])),
            )
        ]
    if method.key == "pchip":
        found.append(
            (
                "The slopes look like arithmetic means of neighbouring secants: pchip takes their harmonic "
                "mean (and 0 where the data turn), which keeps the interpolant monotone.",
                _arithmetic_mean_error(ndata),
            )
        )
    return found


def _hermite_error(ndata, slopes, ntest=4001):
    """The relative max error on [0, 5] of the Hermite interpolant of the Runge function with knot slopes
    ``slopes(x, y, yp)``: what a driver gives when it builds its slopes another way (the usual slips)."""
    x = np.linspace(0.0, 5.0, ndata)
    y, yp = functions.runge(x)
    xtest = np.linspace(0.0, 5.0, ntest)
    exact = functions.runge(xtest)[0]
    return float(np.max(np.abs(exact - piecewise.eval_pherm(x, y, slopes(x, y, yp), xtest))) / np.max(np.abs(exact)))


def _complete_error(ndata, ends):
    """The complete spline with end slopes ``ends(f'(xdata))`` (a slip in passing them)."""
    return _hermite_error(ndata, lambda x, y, yp: splines.ccspline(x, y, *ends(yp)))


def _arithmetic_mean_error(ndata):
    """Arithmetic means of the neighbouring secants as slopes (a pchip slip)."""

    def slopes(x, y, yp):
        secants = np.diff(y) / np.diff(x)
        return np.concatenate(([secants[0]], (secants[:-1] + secants[1:]) / 2, [secants[-1]]))

    return _hermite_error(ndata, slopes)


def check_driver(method, fn, seed=None):
    """Check the driver of an :class:`Experiment`: ``fn(ndata, f, *pieces)`` is the relative max error.

    The driver gets labkit's Runge function as `f` (and labkit's interpolant
    or spline slopes where it takes them), then :func:`scaled_runge`, whose
    maximum is 3: an absolute error comes out three times too large, and a
    driver that ignores `f` gives the Runge function's error.
    """
    result = CheckResult(method.driver)
    sizes = method.ndata[:3]
    if seed is not None:  # the grader's fresh size: never one of the sizes checked anyway
        fresh = [n for n in range(6, 60) if n not in method.ndata]
        sizes += (int(case_rng(seed, f"drivers.driver.{method.key}").choice(fresh)),)
    where = (
        f"[0, 5]^2 with {method.ntest} x {method.ntest} test points"
        if method.key == "bilinear"
        else f"[0, 5] with {method.ntest} test points"
    )
    for ndata in sizes:
        ok, err = call(result, f"ndata = {ndata}", fn, ndata, method.f(), *method.pieces)
        if not ok:
            return result
        expected = method.reference([ndata])[0]
        if not result.step(
            f"Err({ndata}) = max|f - p| / max|f| on {where}",
            _agrees(err, expected),
            f"got {shown(err)}, {_how_far(err, expected)}",
        ):
            slip = _diagnosis(method, err, ndata) or _ignores_f(method, fn, ndata, err)
            result.hint = (
                slip
                if slip
                else f"use ndata equally spaced data points on [0, 5] from f, {method.ntest} equally spaced "
                "test points on [0, 5], and divide the largest error by max|f| there."
            )
            return result
    ndata = SHIFTED_PROBE
    other = "3 / (1 + (x + y - 1)^2)" if method.key == "bilinear" else "3 / (1 + (x - 1)^2)"
    ok, err = call(result, f"f = {other}", fn, ndata, method.f(scaled=True), *method.pieces)
    if not ok:
        return result
    expected = method.reference([ndata], scaled=True)[0]
    if not result.step(
        f"the error is relative to max|f|, for f = {other} too",
        _agrees(err, expected),
        f"got {shown(err)}, {_how_far(err, expected)}",
    ):
        number = _number(err)
        tripled = number is not None and abs(number - 3 * expected) <= DRIVER_TOLERANCE * 3 * expected
        result.hint = (
            "the error is absolute, not relative to max|f|: divide the largest error by max|f| over "
            "the test points (for the Runge function on [0, 5] that is 1, which hides the slip)."
            if tripled
            else SCALED_AT_THE_DATA
            if _agrees(err, _scaled_at_the_data(method, ndata, expected))
            else IGNORES_F
        )
    return result


IGNORES_F = "compute f from the function passed in as `f`, not from runge itself."


def _ignores_f(method, fn, ndata, err):
    """The hint for a driver that gives the same error whatever `f` it is passed (it computes its own), or None.
    With the lab's data its own Runge function is labkit's, so only the moved, scaled one shows it; with a
    student's own scale the lab's f already does. At a size where the two functions' errors coincide (the
    shift a whole number of intervals) nothing can be told."""
    if _agrees(method.reference([ndata])[0], method.reference([ndata], scaled=True)[0]):
        return None
    ok, moved = call(CheckResult(method.driver), "the driver with another f", fn, ndata, method.f(scaled=True),
                     *method.pieces)  # fmt: skip
    return IGNORES_F if ok and _same(err, moved) else None


def _how_far(err, expected):
    """How a driver's error misses the lab's, without saying the lab's (which is a row of the student's table)."""
    number = _number(err)
    if number is None or not np.isfinite(number) or expected <= 0:
        return "which is not a relative error of the lab's experiment"
    if number <= 0:
        return "but an error of an interpolant that does not reproduce f exactly is positive"
    return f"{'larger' if number > expected else 'smaller'} than the lab's experiment gives at this size"


def table_order(method, errors):
    """The order across a whole table: log(Err(first)/Err(last)) / log(h(first)/h(last)); None if not a table."""
    values = _numbers(errors)
    if values is None or values.shape != (len(method.ndata),):
        return None
    return float(np.log(values[0] / values[-1]) / np.log((method.ndata[-1] - 1) / (method.ndata[0] - 1)))


def check_table(method, errors, fn, scale=None):
    """Check the error list of an experiment against what the student's driver `fn` returns
    (the notebook's self-check; see :func:`experiment`); `scale` is the notebook's scale of its test function."""
    return check_experiment(method, errors, MISSING, fn, scale)[0]


def check_rate(method, answer, errors, fn, scale=None):
    """Check the rate answer of an experiment: the exponent p with Err(n)/Err(2n-1) close to 2**p, read
    from the table `errors` of the student's driver `fn` (the notebook's self-check; see :func:`experiment`);
    `scale` is the notebook's scale of its test function."""
    return check_experiment(method, errors, answer, fn, scale)[1]


def _no_experiment(method, values, whose="the", verdict="this table shows no experiment"):
    return (
        f"{whose} errors do not shrink as ndata grows (Err({method.ndata[0]}) = {values[0]:.3e}, "
        f"Err({method.ndata[-1]}) = {values[-1]:.3e}): {verdict}"
    )


def _own_errors(method, fn, result):
    """What the student's driver returns for each of the lab's sizes, called as the student would
    (``fn(ndata)``, its own defaults); None, with a failed step in `result`, if it does not run."""
    if fn is None or fn is MISSING:
        result.fail(
            f"{method.driver} is defined",
            "not defined when the notebook finished",
            f"this part is read from what {method.driver} returns: define it first.",
            NOT_DONE,
        )
        return None
    own = []
    for ndata in method.ndata:
        ok, err = call(result, f"{method.driver}({ndata}) runs", fn, ndata)
        if not ok:
            result.hint = f"this part is checked against what {method.driver} returns, so the driver must run."
            return None
        own.append(_number(err))
    if None in own or _numbers(own) is None:
        result.fail(
            f"{method.driver} returns one positive error per ndata",
            f"got {_shown_errors([np.nan if v is None else v for v in own])}",
            f"make {method.driver}(ndata) return the relative max error as one positive number.",
        )
        return None
    return np.array(own)


MISSING = type("Missing", (), {"__repr__": lambda self: "not defined"})()  # a name the notebook does not define
LAB_EXPERIMENT = "the lab's experiment (labkit's table of it)"


def _same(value, other):
    number = _number(other)
    return number is not None and _agrees(value, number)


def _measures(method, fn, scratch):
    """Whether the driver `fn` measures an experiment, right or not: given labkit's pieces, its errors at the
    lab's first three sizes are positive and shrink, and the moved, scaled test function changes them (a
    driver that ignores what it is given, or returns errors made up, does neither)."""
    values = []
    for ndata in method.ndata[:3]:
        ok, err = call(scratch, "the driver with the lab's f", fn, ndata, method.f(), *method.pieces)
        number = _number(err) if ok else None
        if number is None or not np.isfinite(number) or number <= 0:
            return False
        values.append(number)
    if not all(later < earlier for earlier, later in zip(values, values[1:])):
        return False
    ok, plain = call(scratch, "the driver with the lab's f", fn, SHIFTED_PROBE, method.f(), *method.pieces)
    ok_other, moved = call(scratch, "the driver with another f", fn, SHIFTED_PROBE, method.f(True), *method.pieces)
    first, second = _number(plain) if ok else None, _number(moved) if ok_other else None
    return first is not None and second is not None and not _agrees(first, second)


def attempted_driver(method, fn, own, a=None, own_data=True):
    """Why the student's driver `fn` is no attempt at the lab's experiment ('' when it is one).

    `own` is what it returned, with its own defaults, for the lab's sizes. It is an attempt when, given
    labkit's test function and pieces as the driver check gives them, its first two errors are labkit's or
    those of a slip the driver check names (another interval, other test points, another method, ...) or,
    for a slip no check names, it still measures an experiment (:func:`_measures`), and
    when the `f` it uses by default is the test function or one with a slip its own check names (the
    derivative's sign, a missing square; a product in ``runge2d``): so a driver, or a Runge function,
    that measures something else is no reference for the table and the rate read from it. `a` is the
    student's scale of the Runge function (the lab's when None): the test function the default `f` must be;
    `own_data` whether the notebook shows that scale (see :meth:`Experiment.f_slips`).
    """
    scratch = CheckResult(method.driver)
    for index, ndata in enumerate(method.ndata[:2]):
        ok, err = call(scratch, "the driver with the lab's f", fn, ndata, method.f(), *method.pieces)
        if not ok:  # a driver that takes no f or pieces: its own run is all there is to judge
            err = own[index]
        if not (_agrees(err, method.reference([ndata])[0]) or _diagnosis(method, err, ndata)):
            if _measures(method, fn, scratch):  # a slip no check names, in a driver that does measure
                break
            return (
                f"what your {method.driver} returns for ndata = {ndata} is neither the lab's experiment "
                "nor the lab's experiment with one of the usual slips"
            )
    ndata = method.ndata[1]
    ok, given = call(scratch, "the driver with the lab's f", fn, ndata, method.f(a=a))
    if not ok or _same(own[1], given):
        return ""
    for slip in method.f_slips(a, own_data):
        ok, given = call(scratch, "the driver with a slip in f", fn, ndata, slip)
        if ok and _same(own[1], given):
            return ""
    name = "runge2d" if method.key == "bilinear" else "Runge"
    yours = f" {method.formula(a)}" if method.f(a=a) is not method.f() else ""
    return (
        f"the f your {method.driver} uses when it is given none is not the {name} function{yours}, not even with "
        "one of the slips its own check names"
    )


def check_experiment(method, errors, answer, fn, scale=None, own_data=True):
    """Check the table and the rate answer of an experiment against one run of the student's driver
    `fn` at the lab's sizes: ``[table result, rate result]``.

    The driver is called as the student would, ``fn(ndata)`` with its own
    defaults, so both parts follow the student's own functions: a mistake in
    them is marked where they are checked, not again here. The table must be
    what the driver returns (to the four digits ``ratio_table`` prints) and
    shrink; the rate must be the order the driver's errors support. Neither
    earns anything without a driver that runs: a table typed in from
    elsewhere, or a rate read off it, is not the student's experiment.

    A table that does not shrink earns nothing only when the driver itself is
    not real: when, given labkit's test function and pieces, it measures no
    experiment either (:func:`honest_driver`). When it does, the table is what
    the driver honestly measured with the student's own pieces, whose mistake
    is marked in their own part: the table keeps its points, and the rate is
    right when it is the order read off that table's ratios (as the lab reads
    them) or the order the lab's experiment shows.

    `scale` is the student's own scale of the test function (a variant,
    :mod:`labkit.exercises.variants`; the lab's when None): the driver's
    default `f` must be that function, and the lab's experiment is on it.
    `own_data` is False when the notebook shows another scale than the
    student's: then a function on the lab's scale is no slip of the student's.
    """
    table_result, rate_result = CheckResult(method.table), CheckResult(method.rate)
    own = _own_errors(method, fn, table_result)
    lab, honest = None, False
    if own is None:
        rate_result.add_steps(table_result)
        rate_result.hint = table_result.hint
    else:
        why = attempted_driver(method, fn, own, scale, own_data)
        if why:  # the driver measures something else: the lab's experiment is the reference
            lab = method.reference(method.ndata, a=scale)
            for result in (table_result, rate_result):
                judged_by_the_lab(result, why, LAB_EXPERIMENT)
        else:
            honest = honest_driver(method, fn, own)
    return [
        _table(method, errors, own, table_result, lab, honest),
        _rate(method, answer, errors, own, rate_result, lab, honest),
    ]


def honest_driver(method, fn, own):
    """True when the student's driver `fn` is real but its own run `own` (with its own defaults) shows no
    experiment: given labkit's test function and pieces it measures one (:func:`_measures`), so what makes its
    errors stand still is in the student's functions it uses by default, which are checked in their own parts."""
    if supported_order(method, own) is not None or not method.pieces:
        return False
    return _measures(method, fn, CheckResult(method.driver))


HONEST = (
    "your errors do not shrink, but your driver, given labkit's {pieces}, measures the experiment: the table is "
    "what it honestly measured with your own functions, whose mistake is marked where they are checked"
)


def _printed(values, reference):
    """True if `values` are `reference` to the four significant digits ratio_table prints."""
    return bool(np.allclose(values, reference, rtol=PRINTED, atol=0))


def _table(method, errors, own, result, lab=None, honest=False):
    if own is None:
        return result
    sizes = ", ".join(map(str, method.ndata))
    description = f"one error per ndata = {sizes}"
    if errors is MISSING:
        return result.fail(
            f"{method.table} is defined",
            "not defined when the notebook finished",
            f"run the cell that fills {method.table} (and keep its name).",
            NOT_DONE,
        )
    values = _numbers(errors)
    if values is None or values.shape != (len(method.ndata),):
        count = (
            f"your table has {values.size} errors for the {len(method.ndata)} sizes in ndata: "
            if (values is not None and values.ndim == 1)
            else ""
        )
        return result.fail(
            description,
            f"got {_shown_errors(errors)}",
            f"{count}make {method.table} a list of {len(method.ndata)} positive errors: "
            f"[{method.driver}(n) for n in {list(method.ndata)}].",
        )
    result.step(description, True)
    agree = _printed(values, own)
    if not result.step(
        f"the errors are what {method.driver} returns for each ndata (to 4 significant digits)",
        agree,
        f"got {np.array2string(values, precision=3)}",
    ):
        wrong = [
            n
            for n, mine, theirs in zip(method.ndata, values, own)
            if not np.isclose(mine, theirs, rtol=PRINTED, atol=0)
        ]
        rows = ", ".join(f"Err({n})" for n in wrong[:3]) + (" and more" if len(wrong) > 3 else "")
        result.hint = (
            f"{rows} in your table {'is' if len(wrong) == 1 else 'are'} not what {method.driver} returns: "
            f"fill the table by running your driver, [{method.driver}(n) for n in {list(method.ndata)}]."
        )
        return result
    order = table_order(method, values)
    if honest and order < MIN_ORDER:
        result.step(HONEST.format(pieces=_pieces(method)), True)
        return result
    if not result.step(
        f"the errors shrink as ndata grows (an observed order of at least {MIN_ORDER} across the table)",
        order >= MIN_ORDER,
        _no_experiment(method, values),
    ):
        result.hint = (
            f"{method.driver} must interpolate f from ndata points and measure the error at the test "
            "points; with more points the error gets smaller."
        )
        return result
    if lab is not None and not result.step(
        "the errors are those of the lab's experiment (to 4 significant digits)",
        _printed(values, lab),
        "they are not",
    ):
        result.hint = (
            f"make {method.driver} measure the lab's experiment (f from ndata equally spaced points on [0, 5], the "
            "error at the test points relative to max|f|), then refill the table."
        )
    return result


SANE = (1e-150, 1e150)  # a relative error outside this range is no measurement (and its ratios would overflow)


def _numbers(value):
    """A 1-d float array of positive errors within :data:`SANE`, or None.

    A table of one-element arrays (a driver that returns ``np.max(..., keepdims=True)``,
    which the driver check accepts as one number) counts as its numbers.
    """
    if value is MISSING or getattr(value, "not_numbers", False) or isinstance(value, (str, bytes)):
        return None
    try:
        values = floats(value)
    except (TypeError, ValueError):
        return None
    if values.ndim > 1 and values.size == values.shape[0]:
        values = values.reshape(-1)
    if values.ndim != 1 or not np.all(np.isfinite(values)):
        return None
    return values if np.all(values > SANE[0]) and np.all(values < SANE[1]) else None


def _shown_errors(value):
    """A student's table for a failure message: its numbers to four digits, or what it is instead."""
    try:
        values = floats(value).reshape(-1)
    except (TypeError, ValueError):
        return shown(value)
    if values.size > 20:
        return f"{values.size} numbers"
    return "[" + ", ".join(f"{v:.3e}" for v in values) + "]"


def supported_order(method, errors):
    """The order a table of errors supports, as labkit estimates it; None if it is not a table that
    shows an experiment (errors that shrink with an observed order of at least MIN_ORDER)."""
    values = _numbers(errors)
    if values is None or values.shape != (len(method.ndata),):
        return None
    if table_order(method, values) < MIN_ORDER:
        return None
    return convergence.ConvergenceTable(method.title, np.array(method.ndata), values).order


def _pieces(method):
    """The functions a driver is given from labkit when it is checked, in words ('runge and eval_pherm')."""
    return " and ".join(function.__name__ for function in (method.f(), *method.pieces))


def _read_off(method, values):
    """The order a table's ratios settle near, read as the lab reads them, shrinking or not."""
    return convergence.ConvergenceTable(method.title, np.array(method.ndata), values).order


def _rate(method, answer, errors, own, result, lab=None, honest=False):
    """The rate answer: the exponent p with Err(n)/Err(2n-1) close to 2**p, read from the student's table.

    The table must be read from an experiment: the driver ran (`own` is what it
    returned) and its errors shrink. Then the answer must be the order the
    student's own table supports, so a student whose table is off but who reads
    it correctly is not marked down twice.
    """
    if own is None:
        return result
    description = "the rate is the exponent p of the power of two 2**p that your table's ratios settle near"
    if supported_order(method, own) is None and not honest:
        return result.fail(
            description,
            _no_experiment(method, own, f"{method.driver}'s", "they show no experiment, so there is no rate to read"),
            f"fix {method.driver} so that its errors shrink, refill {method.table}, then read the rate off the ratios.",
        )
    if answer is MISSING:
        return result.fail(
            f"{method.rate} is defined",
            "not defined when the notebook finished",
            f"run the cell that sets {method.rate} (and keep its name).",
            NOT_DONE,
        )
    values = _numbers(errors)
    if values is None or values.shape != (len(method.ndata),):
        return result.fail(
            description,
            f"{method.table} is not a table of {len(method.ndata)} positive errors, "
            "so there is nothing to read the rate from",
            f"fill {method.table} from your driver first, then read the rate off its ratios.",
        )
    if lab is not None and not _printed(values, lab):
        return result.fail(
            description,
            f"{method.table} is not the lab's experiment, so there is no rate of it to read",
            f"make {method.driver} measure the lab's experiment, refill {method.table}, then read the rate "
            "off the ratios.",
        )
    supported = supported_order(method, values)
    readings = {supported}
    if supported is None and honest and _printed(values, own):  # the honest table: read off it, or the lab's
        supported = _read_off(method, values)
        readings = {supported, method.observed_order}
    if supported is None:
        return result.fail(
            description,
            _no_experiment(method, values, "your table's", "this table shows no experiment, so it supports no rate"),
            f"fill {method.table} by running {method.driver}, then read the rate off the ratios.",
        )
    number = _number(answer)
    if number is None or number != round(number):
        return result.fail(
            description,
            f"got {shown(answer)}",
            f"set {method.rate} to a whole number p: the ratios Err(41)/Err(81), ... are close to 2**p.",
        )
    p = int(round(number))
    if p in readings:
        result.step(description, True)
        return result
    exponent = p.bit_length() - 1 if p > 1 else None
    if exponent is not None and p == 2**exponent and p > 2:  # any power of two: saying which would tell the rate
        return result.fail(
            description,
            f"got {p}, a power of two: if you copied a ratio Err(n)/Err(2n-1), that is 2**p itself",
            "the rate is not a ratio of your table but the exponent p of the power of two 2**p the ratios settle near.",
        )
    return result.fail(
        description,
        f"got {p}, which is not the exponent of the power of two your table's ratios settle near",
        "your rate does not fit your own table: take its ratios Err(41)/Err(81), Err(81)/Err(161), ...; they "
        "settle near a power of two 2**p, and p is the rate.",
    )
