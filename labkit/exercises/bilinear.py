"""Checks for exercise 16: runge2d and the piecewise bilinear interpolant.

The maths is derived in ``notebooks/06_bilinear.ipynb``. References are
:func:`labkit.runge2d` and the functions 1, x, y and xy, which a bilinear
interpolant reproduces exactly on any grid.

The functions handed to the student's ``eval_pbilin`` are module-level
functions (not lambdas), so that ``labkit grade`` can name them to the
sandboxed notebook: the declaration lists them (``passes``).
"""

import numpy as np

from .. import bilinear, functions, piecewise
from .experiments import RUNGE2D_A, Experiment
from .model import INTERPOLANTS, OWN_FUNCTIONS, Exercise, Part
from .result import CheckResult, call, case_rng, close, floats, gave_up, worst


def one(x, y):
    """f(x, y) = 1 on arrays x, y of one shape."""
    return np.ones_like(np.asarray(x, dtype=float) * np.asarray(y, dtype=float))


def x_only(x, y):
    """f(x, y) = x."""
    return np.asarray(x, dtype=float) + 0 * np.asarray(y, dtype=float)


def y_only(x, y):
    """f(x, y) = y."""
    return np.asarray(y, dtype=float) + 0 * np.asarray(x, dtype=float)


def product(x, y):
    """f(x, y) = x y."""
    return np.asarray(x, dtype=float) * np.asarray(y, dtype=float)


BILINEAR_FUNCTIONS = (("1", one), ("x", x_only), ("y", y_only), ("xy", product))


def corner_1(x, y):
    """phi_1 of the unit square: 1 at P_1 = (0, 0), 0 at the other corners."""
    return (1 - np.asarray(x, dtype=float)) * (1 - np.asarray(y, dtype=float))


def corner_2(x, y):
    """phi_2 of the unit square: 1 at P_2 = (1, 0)."""
    return np.asarray(x, dtype=float) * (1 - np.asarray(y, dtype=float))


def corner_3(x, y):
    """phi_3 of the unit square: 1 at P_3 = (1, 1)."""
    return np.asarray(x, dtype=float) * np.asarray(y, dtype=float)


def corner_4(x, y):
    """phi_4 of the unit square: 1 at P_4 = (0, 1)."""
    return (1 - np.asarray(x, dtype=float)) * np.asarray(y, dtype=float)


CORNERS = (corner_1, corner_2, corner_3, corner_4)  # f(P_n) = 1 at one corner: which phi_m it is multiplied by


def check_runge2d(fn, seed=None, runge2d_a=RUNGE2D_A.lab):
    """Check ``runge2d(x, y)`` = 1/(1 + a (x+y)^2), a = `runge2d_a` (the notebook's data cell; the lab's function
    has a = 1), on arrays."""
    result = CheckResult("runge2d")
    X, Y = np.meshgrid(np.linspace(-2, 2, 5), np.linspace(0, 3, 4), indexing="ij")
    if seed is not None:
        X, Y = case_rng(seed, "bilinear.runge2d").uniform(-3, 3, (2, 5, 4))
    ok, out = call(result, "runge2d on a grid", fn, X, Y)
    lab = runge2d_a == RUNGE2D_A.lab
    want = functions.runge2d(X, Y, a=runge2d_a)
    formula = "1/(1+(x+y)^2)" if lab else f"1/(1 + runge2d_a (x+y)^2), runge2d_a = {RUNGE2D_A.shown(runge2d_a)}"
    yours = "" if lab else ", with your runge2d_a: 1 / (1 + runge2d_a * (x + y)**2)"
    if ok and not result.step(f"{formula} on arrays", close(out, want), worst(out, want)):
        result.hint = (
            "your runge2d squares the product x*y, not the sum x + y: the lab's function is 1 / (1 + (x + y)**2)"
            f"{yours}."
            if close(out, 1 / (1 + runge2d_a * (X * Y) ** 2))
            else "your runge2d leaves out runge2d_a: the function is 1 / (1 + runge2d_a * (x + y)**2), with "
            "runge2d_a from the notebook's data cell."
            if not lab and close(out, functions.runge2d(X, Y))
            else f"compare it with the lab's function, 1 / (1 + (x + y)**2){yours}, written with componentwise "
            "operations."
        )
    return result


def check_eval_pbilin(fn, seed=None):
    """Check ``eval_pbilin(f, xdata, ydata, xval, yval)``: one cell, then 1, x, y, xy on a grid."""
    result = CheckResult("eval_pbilin")
    unit = np.array([0.0, 1.0])
    ok, z = call(result, "corners of [0, 1]^2", fn, functions.runge2d, unit, unit, unit, unit)
    if not ok:
        if not gave_up(result):
            result.hint = _pbilin_search_slip(fn) or result.hint
        return result
    X, Y = np.meshgrid(unit, unit, indexing="ij")
    if not result.step(
        "returns runge2d at the four corners of [0, 1]^2",
        close(z, functions.runge2d(X, Y)),
        worst(z, functions.runge2d(X, Y)),
    ):
        result.hint = _pbilin_corner_slip(fn) or (
            "zval(k, l) is I(xval(k), yval(l)): check the order of the indices and the four basis functions."
        )
        return result
    xdata, ydata = np.array([0.0, 0.5, 2.0, 3.0]), np.array([-1.0, 0.0, 2.5])
    if seed is not None:
        rng = case_rng(seed, "bilinear.eval_pbilin")
        xdata, ydata = (np.cumsum(rng.uniform(0.2, 1.5, n)) - 1.0 for n in (5, 4))
    xval, yval = np.linspace(xdata[0], xdata[-1], 7), np.linspace(ydata[0], ydata[-1], 6)
    XV, YV = np.meshgrid(xval, yval, indexing="ij")
    for name, f in BILINEAR_FUNCTIONS:
        ok, z = call(result, f"f = {name}", fn, f, xdata, ydata, xval, yval)
        if not ok:
            if not gave_up(result):
                result.hint = _pbilin_search_slip(fn) or result.hint
            return result
        if not result.step(f"reproduces f = {name} on an unequal grid", close(z, f(XV, YV)), worst(z, f(XV, YV))):
            if close(z, f(XV, YV).T):
                result.hint = (
                    "zval is transposed: zval[k, l] is I(xval[k], yval[l]), one row per value of xval "
                    f"(shape ({len(xval)}, {len(yval)}))."
                )
            else:
                result.hint = (
                    _pbilin_corner_slip(fn)
                    or _pbilin_search_slip(fn)
                    or (
                        "one cell works but a grid does not: use bracket on xval and on yval to find the cell "
                        "and that cell's corners in the basis functions."
                    )
                )
            return result
    return _several_cells(fn, result, xdata, ydata, xval, yval)


def curved(x, y):
    """A function that is not bilinear: each cell's interpolant of it is its own."""
    return np.asarray(x, dtype=float) ** 2 + np.asarray(x, dtype=float) * np.asarray(y, dtype=float) ** 2


def _several_cells(fn, result, xdata, ydata, xval, yval):
    """The last step: a function that is not bilinear at points spread over every cell, against labkit's
    interpolant (1, x, y and xy come out right from any one cell, extrapolated)."""
    want = bilinear.eval_pbilin(curved, xdata, ydata, xval, yval)
    ok, z = call(result, "f = x^2 + x y^2", fn, curved, xdata, ydata, xval, yval)
    if not ok or result.step("each point in its own cell: f = x^2 + x y^2 on the grid", close(z, want), worst(z, want)):
        return result
    i, j = piecewise.bracket(xdata, xval[:1]), piecewise.bracket(ydata, yval[:1])
    one = _one_cell(xdata, ydata, xval, yval, int(i[0]), int(j[0]))
    result.hint = (
        "every point is interpolated in the same cell (the first point's): each xval[k], yval[l] has its own "
        "cell, which bracket(xdata, xval) and bracket(ydata, yval) give, one index per point."
        if close(z, one)
        else "1, x, y and xy come out right but a curved f does not: each point must use the four corners of its "
        "own cell, found with bracket on xval and on yval."
    )
    return result


def _one_cell(xdata, ydata, xval, yval, i, j):
    """The bilinear interpolant of :func:`curved` on cell (i, j), extended to every point."""
    x0, x1, y0, y1 = xdata[i], xdata[i + 1], ydata[j], ydata[j + 1]
    X, Y = np.meshgrid(xval, yval, indexing="ij")
    f = curved
    area = (x1 - x0) * (y1 - y0)
    return (
        f(x0, y0) * (x1 - X) * (y1 - Y)
        + f(x1, y0) * (X - x0) * (y1 - Y)
        + f(x1, y1) * (X - x0) * (Y - y0)
        + f(x0, y1) * (x1 - X) * (Y - y0)
    ) / area


def _pbilin_corner_slip(fn):
    """Which corner values a student's ``eval_pbilin`` pairs with another corner's basis function, in the
    student's words ('' for none): on the unit square, f = phi_n (1 at P_n, 0 at the others) must come out
    as phi_n itself."""
    unit, points = np.array([0.0, 1.0]), np.array([0.0, 0.3, 0.8, 1.0])
    X, Y = np.meshgrid(points, points, indexing="ij")
    scratch, pairs = CheckResult("eval_pbilin"), []
    for n, corner in enumerate(CORNERS, start=1):
        ok, z = call(scratch, f"f = phi_{n}", fn, corner, unit, unit, points, points)
        if not ok:
            return ""
        if not close(z, corner(X, Y)):
            m = next((m for m, other in enumerate(CORNERS, start=1) if close(z, other(X, Y))), None)
            if m is None:
                return ""
            pairs.append(f"f(P_{n}) goes with phi_{m}")
    if not pairs:
        return ""
    return (
        f"in your sum, {' and '.join(pairs)}: each corner's value f(P_n) goes with its own basis function phi_n, "
        "I = f(P_1) phi_1 + f(P_2) phi_2 + f(P_3) phi_3 + f(P_4) phi_4 (equation 13)."
    )


def _pbilin_search_slip(fn):
    """Where the cell search of a student's ``eval_pbilin`` fails, in the student's words ('' when it does
    not): points inside the grid work, points at or past its last knot raise an error or come out wrong."""
    xdata, ydata = np.array([0.0, 1.0, 2.5]), np.array([0.0, 1.5, 2.0])
    scratch, inside = CheckResult("eval_pbilin"), (np.array([0.4, 1.7]), np.array([0.6, 1.8]))
    ok, z = call(scratch, "inside the grid", fn, product, xdata, ydata, *inside)
    if not ok or not close(z, np.outer(*inside)):
        return ""
    failed = []
    for where, (xval, yval) in {
        "at the last knot": (np.array([0.4, 2.5]), np.array([0.6, 2.0])),
        "past the last knot": (np.array([0.4, 3.0]), np.array([0.6, 2.4])),
    }.items():
        ok, z = call(scratch, where, fn, product, xdata, ydata, xval, yval)
        if not ok and gave_up(scratch):
            return ""
        if not ok or not close(z, np.outer(xval, yval)):
            failed.append((where, ok))
    if not failed:
        return ""
    where = "at or past the last knot" if len(failed) == 2 else failed[0][0]
    what = "get the wrong value" if all(ok for _, ok in failed) else "raise an error"
    return (
        f"points {where} of xdata or ydata {what}: "
        "there is no cell beyond the last knot, so they belong to the last cell, as labkit.bracket gives it "
        "(use bracket twice, once for xval and once for yval)."
    )


def check_phi_table(table):
    """Exercise 16(a): the table of phi_m(P_n), rows P_1..P_4 and columns phi_1..phi_4.

    The reference is the definition: each phi_m evaluated at each corner of a
    rectangle (any rectangle gives the same table).
    """
    result = CheckResult("phi_table")
    x0, x1, y0, y1 = 1.0, 3.0, -1.0, 0.5
    area = (x1 - x0) * (y1 - y0)
    P = np.array([(x0, y0), (x1, y0), (x1, y1), (x0, y1)])
    x, y = P[:, 0], P[:, 1]
    expected = (
        np.stack(((x1 - x) * (y1 - y), (x - x0) * (y1 - y), (x - x0) * (y - y0), (x1 - x) * (y - y0)), axis=1) / area
    )  # expected[n, m] = phi_m(P_n)
    if not result.step("a 4 x 4 table of phi_m(P_n)", close(table, expected), worst(table, expected)):
        try:
            values = floats(table)
            permutation = (
                values.shape == (4, 4)
                and np.allclose(np.sort(values, axis=1), [[0, 0, 0, 1]] * 4)
                and np.allclose(values.sum(axis=0), 1)
            )
        except (TypeError, ValueError):
            permutation = False
        if permutation:
            result.hint = (
                "your corners are numbered in another order: P_1 = (x0, y0), P_2 = (x1, y0), "
                "P_3 = (x1, y1), P_4 = (x0, y1), counter-clockwise; row n is P_n, column m is phi_m."
            )
        else:
            result.hint = (
                "evaluate each phi_m at each corner P_n from its formula, one entry at a time: put the "
                "corner's x and y into every factor, such as (x1 - x)."
            )
    return result


# Exercise 16(a): what the table of phi_m(P_n) shows, in the words an explanation would use
PHI_RULE = (
    "identity matrix",
    "np.eye(4)",
    "kronecker",
    "delta_mn",
    "delta_{mn}",
    "vanishes at three corners",
    "vanishes at the other three",
    "1 at its own corner",
    "1 if m = n",
    "1 when m = n",
)

BILINEAR = Experiment(
    "bilinear",
    2,
    "test_pbilin_interpolate",
    "errors_bilinear",
    "rate_bilinear",
    pieces=(bilinear.eval_pbilin,),
    uses=("eval_pbilin", "runge2d"),
    ndata=(11, 21, 41, 81, 161),
    ntest=401,
)

EXERCISES = (
    Exercise(
        16,
        ("phi_table", "runge2d", "eval_pbilin") + BILINEAR.names(),
        (
            Part("phi_table", 1, check_phi_table, ("phi_table",)),
            Part(
                "runge2d", 1, check_runge2d, ("runge2d",), seeded=True, refused=OWN_FUNCTIONS, varied=(RUNGE2D_A.name,)
            ),
            Part(
                "eval_pbilin",
                3,
                check_eval_pbilin,
                ("eval_pbilin",),
                seeded=True,
                refused=INTERPOLANTS,
                passes=(functions.runge2d, curved) + tuple(function for _, function in BILINEAR_FUNCTIONS) + CORNERS,
            ),
        )
        + BILINEAR.parts(),
        notebook="06_bilinear.ipynb",
        answers=(
            "16(a): why the phi table makes I the bilinear interpolant",
            "the order, against piecewise linear in one dimension",
        ),
        withheld=PHI_RULE + BILINEAR.withheld,
        # the two-dimensional Runge function's scale: the student's runge2d and the bilinear table use it
        params=(RUNGE2D_A,),
        sound=BILINEAR.sound,
    ),
)
