"""Checks for exercise 16: runge2d and the piecewise bilinear interpolant.

The maths is derived in ``notebooks/06_bilinear.ipynb``. References are
:func:`labkit.runge2d` and the functions 1, x, y and xy, which a bilinear
interpolant reproduces exactly on any grid.

The functions handed to the student's ``eval_pbilin`` are module-level
functions (not lambdas), so that ``labkit grade`` can name them to the
sandboxed notebook: the declaration lists them (``passes``).
"""

import numpy as np

from .. import bilinear, functions
from .experiments import Experiment
from .model import INTERPOLANTS, OWN_FUNCTIONS, Exercise, Part
from .result import CheckResult, call, case_rng, close, floats, worst


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


def check_runge2d(fn, seed=None):
    """Check ``runge2d(x, y)`` = 1/(1+(x+y)^2), on arrays."""
    result = CheckResult("runge2d")
    X, Y = np.meshgrid(np.linspace(-2, 2, 5), np.linspace(0, 3, 4), indexing="ij")
    if seed is not None:
        X, Y = case_rng(seed, "bilinear.runge2d").uniform(-3, 3, (2, 5, 4))
    ok, out = call(result, "runge2d on a grid", fn, X, Y)
    if ok and not result.step(
        "1/(1+(x+y)^2) on arrays", close(out, functions.runge2d(X, Y)), worst(out, functions.runge2d(X, Y))
    ):
        result.hint = "use componentwise operations: 1 / (1 + (x + y)**2)."
    return result


def check_eval_pbilin(fn, seed=None):
    """Check ``eval_pbilin(f, xdata, ydata, xval, yval)``: one cell, then 1, x, y, xy on a grid."""
    result = CheckResult("eval_pbilin")
    unit = np.array([0.0, 1.0])
    ok, z = call(result, "corners of [0, 1]^2", fn, functions.runge2d, unit, unit, unit, unit)
    if not ok:
        return result
    X, Y = np.meshgrid(unit, unit, indexing="ij")
    if not result.step(
        "returns runge2d at the four corners of [0, 1]^2",
        close(z, functions.runge2d(X, Y)),
        worst(z, functions.runge2d(X, Y)),
    ):
        result.hint = "zval(k, l) is I(xval(k), yval(l)): check the order of the indices and the four basis functions."
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
            return result
        if not result.step(f"reproduces f = {name} on an unequal grid", close(z, f(XV, YV)), worst(z, f(XV, YV))):
            if close(z, f(XV, YV).T):
                result.hint = (
                    "zval is transposed: zval[k, l] is I(xval[k], yval[l]), one row per value of xval "
                    f"(shape ({len(xval)}, {len(yval)}))."
                )
            else:
                result.hint = (
                    "one cell works but a grid does not: use bracket on xval and on yval to find the cell "
                    "and that cell's corners in the basis functions."
                )
            return result
    return result


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
                "evaluate each phi_m at each corner P_n from its formula: a factor such as (x1 - x) is 0 "
                "on the side x = x1, so each phi_m vanishes at three corners."
            )
    return result


BILINEAR = Experiment(
    "bilinear",
    2,
    "test_pbilin_interpolate",
    "errors_bilinear",
    "rate_bilinear",
    pieces=(bilinear.eval_pbilin,),
    ndata=(11, 21, 41, 81, 161),
    ntest=401,
)

EXERCISES = (
    Exercise(
        16,
        ("phi_table", "runge2d", "eval_pbilin") + BILINEAR.names(),
        (
            Part("phi_table", 1, check_phi_table, ("phi_table",)),
            Part("runge2d", 1, check_runge2d, ("runge2d",), seeded=True, refused=OWN_FUNCTIONS),
            Part(
                "eval_pbilin",
                3,
                check_eval_pbilin,
                ("eval_pbilin",),
                seeded=True,
                refused=INTERPOLANTS,
                passes=(functions.runge2d,) + tuple(function for _, function in BILINEAR_FUNCTIONS),
            ),
        )
        + BILINEAR.parts(),
        notebook="06_bilinear.ipynb",
        answers=(
            "16(a): why the phi table makes I the bilinear interpolant",
            "the order, against piecewise linear in one dimension",
        ),
    ),
)
