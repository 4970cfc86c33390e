"""Checks for exercises 2 to 4: the piecewise cubic Hermite interpolant, runge, the limaçon's slopes.

Exercise 3's driver, table and rate are checked in :mod:`labkit.exercises.experiments`; the
exercises are declared at the end of this module.

The maths is derived in ``notebooks/02_convergence.ipynb``. References are
labkit's :func:`labkit.eval_pherm` and :func:`labkit.hermite_basis`, and the
polynomials a cubic Hermite interpolant must reproduce exactly.
"""

import numpy as np

from .. import functions, piecewise
from .experiments import RUNGE_A, Experiment
from .model import INTERPOLANTS, OWN_FUNCTIONS, Exercise, Optional, Part, Together
from .plotted import LAB_R0, check_limacon_plot, derivative_slips
from .result import CheckResult, call, case_rng, close, floats, gave_up, several, shown, worst
from .variants import Param

MONOMIAL_POINTS = np.array([-1.0, 0.5, 1.5, 3.0])


def _monomials(fn, interval, result, label):
    """Interpolate 1, x, x^2, x^3 on one interval; return the failing powers."""
    xdata = np.array(interval, dtype=float)
    wrong = []
    for power in range(4):
        ydata, ypdata = xdata**power, power * xdata ** max(power - 1, 0)
        ok, yval = call(result, f"y = x^{power} on {label}", fn, xdata, ydata, ypdata, MONOMIAL_POINTS)
        if not ok:
            return None
        if not close(yval, MONOMIAL_POINTS**power):
            wrong.append(power)
    return wrong


def check_eval_pherm(fn, seed=None):
    """Check a student's ``eval_pherm(xdata, ydata, ypdata, xval)`` (exercise 2).

    Steps: the four monomials on [0, 2] at x = -1, 0.5, 1.5, 3; if that fails,
    the monomials on [0, 1] (interval length 1 hides wrong denominators),
    then each Hermite basis function alone on [0, 1] and on [0, 2]. Last,
    several unequal intervals against labkit's reference. When a call raises,
    or several intervals disagree, the interval search is probed point by
    point (:func:`_search_slip`), so the hint can say which points it misses.
    """
    result = CheckResult("eval_pherm")
    wrong = _monomials(fn, [0.0, 2.0], result, "[0, 2]")
    if wrong is None:
        if not gave_up(result):
            result.hint = _search_slip(fn) or result.hint  # x = 3 is past the last knot
        return result
    if not result.step(
        "reproduces 1, x, x^2, x^3 on [0, 2] at x = -1, 0.5, 1.5, 3", not wrong, f"wrong for x^{wrong}" if wrong else ""
    ):
        return _narrow_pherm(fn, result)
    rng = case_rng(seed, "hermite.eval_pherm")
    xdata = np.cumsum(rng.uniform(0.2, 1.5, 8))
    ydata, ypdata = rng.normal(size=8), rng.normal(size=8)
    xval = np.linspace(xdata[0] - 0.5, xdata[-1] + 0.5, 57)
    ok, yval = call(result, "several unequal intervals", fn, xdata, ydata, ypdata, xval)
    if ok and not result.step(
        "several unequal intervals agree with labkit.eval_pherm",
        close(yval, piecewise.eval_pherm(xdata, ydata, ypdata, xval)),
        worst(yval, piecewise.eval_pherm(xdata, ydata, ypdata, xval)),
    ):
        result.hint = _search_slip(fn) or (
            "one interval works but several do not: use bracket(xdata, xval) to pick the "
            "interval k of each point, and x_k, x_{k+1} of that interval in h1..h4."
        )
    return result


# knots, values and slopes of the interval search's probe: unequal intervals, no two pieces alike
SEARCH_DATA = (
    np.array([0.0, 1.0, 2.5, 3.0, 4.5]),
    np.array([0.3, -1.2, 0.8, 2.0, -0.5]),
    np.array([1.0, 0.4, -2.0, 0.7, 1.5]),
)


def _piece(xdata, ydata, ypdata, k, x):
    """The cubic of interval k (0-based) at the points x, or None if there is no interval k."""
    if not 0 <= k < len(xdata) - 1:
        return None
    h = piecewise.hermite_basis(xdata[k], xdata[k + 1], x)
    return ydata[k] * h[0] + ypdata[k] * h[1] + ydata[k + 1] * h[2] + ypdata[k + 1] * h[3]


def _search_slip(fn):
    """What the interval search of a student's ``eval_pherm`` gets wrong, in the student's words ('' when
    nothing, or when the interval search is not what is wrong).

    Each probe point is evaluated alone, on several unequal intervals: points between two knots, at an
    inside knot, at the first and the last knot, before the first and past the last. A point between two
    knots that gets the cubic of the neighbouring interval is an index one off; a point at or past an end
    that raises or gets another cubic has no interval of its own there.
    """
    xdata, ydata, ypdata = SEARCH_DATA
    groups = {
        "between": (xdata[:-1] + xdata[1:]) / 2,
        "at an inside knot": xdata[1:-1],
        "at the first knot": xdata[:1],
        "before the first knot": xdata[:1] - 0.7,
        "at the last knot": xdata[-1:],
        "past the last knot": xdata[-1:] + 0.7,
    }
    scratch = CheckResult("eval_pherm")
    found = {}
    for group, points in groups.items():
        outcomes = []
        for x in points:
            ok, got = call(scratch, "one point", fn, xdata, ydata, ypdata, np.array([x]))
            k = int(piecewise.bracket(xdata, x))
            if not ok and gave_up(scratch):
                return ""
            if not ok:
                outcomes.append("raises")
            elif close(got, _piece(xdata, ydata, ypdata, k, np.array([x]))):
                outcomes.append("right")
            else:
                neighbours = {
                    side: _piece(xdata, ydata, ypdata, k + step, np.array([x]))
                    for side, step in (("its right", 1), ("its left", -1))
                }
                outcomes.append(next((side for side, value in neighbours.items() if close(got, value)), "wrong"))
        found[group] = outcomes
    between = set(found["between"])
    for side in ("its right", "its left"):
        if side in between and between <= {side, "right", "raises"}:
            return (
                f"each point between two knots is evaluated with the cubic of the interval to {side}: the "
                "interval k of x is the one with x_k <= x < x_{k+1}, which labkit.bracket(xdata, xval) gives "
                "(counting from 0, as Python does)"
            )
    if between != {"right"}:
        return ""
    hints = []
    for at, beyond, interval in (
        ("at the last knot", "past the last knot", "the last interval"),
        ("at the first knot", "before the first knot", "the first interval"),
    ):
        failed = [where for where in (at, beyond) if found[where] != ["right"]]
        if not failed:
            continue
        raised = any(found[where] == ["raises"] for where in failed)
        where = f"at or {beyond}" if len(failed) == 2 else failed[0]
        hints.append(
            f"points {where} {'raise an error' if raised else 'get the wrong value'}: there is no interval "
            f"{beyond}, so they belong to {interval}, as labkit.bracket gives them"
        )
    if found["at an inside knot"] != ["right"] * len(groups["at an inside knot"]):
        hints.append(
            "points exactly at an inside knot get the wrong value: such a point belongs to the interval it starts"
        )
    return "; ".join(hints)


def _narrow_pherm(fn, result):
    """The lab's debugging steps iii to v for eval_pherm."""
    wrong_unit = _monomials(fn, [0.0, 1.0], result, "[0, 1]")
    if wrong_unit is None:
        return result
    unit_ok = result.step(
        "monomials on [0, 1] (interval length 1)", not wrong_unit, f"wrong for x^{wrong_unit}" if wrong_unit else ""
    )
    # on [0, 1] every denominator is 1; on [0, 2] they are not
    interval = [0.0, 1.0] if not unit_ok else [0.0, 2.0]
    bad = _basis_failures(fn, interval, result)
    if bad is None:
        return result
    label = f"each Hermite basis function alone on [{interval[0]:g}, {interval[1]:g}]"
    if not bad:
        result.step(label, True)
        result.hint = _search_slip(fn) or (  # the basis is checked inside [x_k, x_{k+1}], the monomials outside too
            "each basis function is right, so the combination is wrong: "
            "p = y_k h1 + y'_k h2 + y_{k+1} h3 + y'_{k+1} h4 (equation 4)."
        )
        return result
    name, factor, other = bad[0]
    mixed = _combination_slip(fn, interval) if all(o is None for _, _, o in bad) else ""
    if mixed:
        result.fail(label, f"wrong: {', '.join(n for n, _, _ in bad)}", mixed)
        return result
    if factor == -1 and not unit_ok:
        # -1 on [0, 1] is a sign slip, or a power of (x_k - x_{k+1}) = -1 too many or too few: [0, 2] tells
        wider = _basis_failures(fn, [0.0, 2.0], result)
        if wider is None:
            return result
        factor2 = next((f for n, f, _ in wider if n == name), None)
        if factor2 is not None and not np.isclose(factor2, -1.0):
            factor, interval, unit_ok = factor2, [0.0, 2.0], True
            label = "each Hermite basis function alone on [0, 2]"
    if other is not None:
        hint = _swapped_basis_hint(name, other, {n for n, _, _ in bad})
    else:
        hint = _basis_formula_hint(fn, name, factor, interval, unit_ok)
    result.fail(label, f"wrong: {', '.join(n for n, _, _ in bad)}", hint)
    return result


def _swapped_basis_hint(name, other, wrong):
    """The hint when the data of basis function `name` alone give `other` (`wrong`: every basis function found
    wrong)."""
    if other not in wrong:
        return (
            f"with only the data of {name} set, your interpolant gives {other}, and {other}'s own data give "
            f"{other}: your {name} is {other}'s formula. Compare {name} with the lab's definition, factor by "
            "factor (which of x_k, x_{k+1} each factor has)."
        )
    if {name, other} in ({"h1", "h2"}, {"h3", "h4"}):
        return (
            f"with only the data of {name} set, your interpolant gives {other}: the values and the slopes are "
            "swapped in the combination. The value y_k goes with h1 and the slope y'_k with h2 "
            "(y_{k+1} with h3, y'_{k+1} with h4), equation (4)."
        )
    if {name, other} in ({"h1", "h3"}, {"h2", "h4"}):
        return (
            f"with only the data of {name} set, your interpolant gives {other}: the two ends of the interval "
            "are swapped in the combination. The data at x_k (y_k, y'_k) go with h1 and h2, the data at "
            "x_{k+1} with h3 and h4, equation (4)."
        )
    return (
        f"with only the data of {name} set, your interpolant gives {other}: the combination pairs the data "
        "with the wrong basis functions. p = y_k h1 + y'_k h2 + y_{k+1} h3 + y'_{k+1} h4 (equation 4)."
    )


def _basis_formula_hint(fn, name, factor, interval, unit_ok):
    """The hint for a basis function `name` whose own formula is wrong: its sign, its denominator (off by
    `factor` on `interval`), or a value or slope of the lab's table (3)."""
    if factor == -1:
        return (
            f"{name} has the wrong sign: compare its factors with the lab's definition, a minus sign at a time "
            "(x - x_{k+1} and x_k - x_{k+1} are not the same)."
        )
    if factor is not None or unit_ok:
        times = f" times {factor:g}" if factor is not None else ""
        hint = (
            f"{name} is the right polynomial{times} on [{interval[0]:g}, {interval[1]:g}]: its denominator is wrong "
            "(the denominators are (x_k - x_{k+1})^3 for h1, (x_k - x_{k+1})^2 for h2, "
            "(x_{k+1} - x_k)^3 for h3 and (x_{k+1} - x_k)^2 for h4)."
        )
        if factor is None:
            hint = hint.replace(" is the right polynomial on", " is right on [0, 1] but not on")
        return hint
    off = _table3_slips(fn, name)
    return (
        f"{name} is wrong: {off} {'is' if ' and ' not in off else 'are'} not what the lab's table (3) says. "
        "Compare your formula with the lab's definition of the four Hermite polynomials, factor by factor."
        if off
        else f"{name} is wrong: compare your formula with the lab's definition of the four Hermite "
        "polynomials, factor by factor."
    )


TABLE3 = {  # the lab's table (3): each basis function's value and slope at x_k and x_{k+1}
    "h1": (1.0, 0.0, 0.0, 0.0),
    "h2": (0.0, 1.0, 0.0, 0.0),
    "h3": (0.0, 0.0, 1.0, 0.0),
    "h4": (0.0, 0.0, 0.0, 1.0),
}


def _table3_slips(fn, name, eps=1e-5):
    """Which entries of the lab's table (3) the student's basis function `name` misses on [0, 1] ('its value
    at x_k and its slope at x_{k+1}'), '' for none; its slopes are centred differences of the interpolant."""
    data = {"h1": ([1, 0], [0, 0]), "h2": ([0, 0], [1, 0]), "h3": ([0, 1], [0, 0]), "h4": ([0, 0], [0, 1])}[name]
    points = np.array([0.0, -eps, eps, 1.0, 1.0 - eps, 1.0 + eps])
    ok, got = call(
        CheckResult("eval_pherm"), f"{name} near the ends", fn, np.array([0.0, 1.0]), *map(np.array, data), points
    )
    try:
        values = floats(got) if ok else None
    except (TypeError, ValueError):
        values = None
    if values is None or values.shape != points.shape or not np.all(np.isfinite(values)):
        return ""
    found = (values[0], (values[2] - values[1]) / (2 * eps), values[3], (values[5] - values[4]) / (2 * eps))
    what = ("its value at x_k", "its slope at x_k", "its value at x_{k+1}", "its slope at x_{k+1}")
    off = [w for w, got_, want in zip(what, found, TABLE3[name]) if abs(got_ - want) > 1e-4]
    return ", ".join(off[:-1]) + (" and " if len(off) > 1 else "") + off[-1] if off else ""


DATA_NAMES = ("y_k", "y'_k", "y_{k+1}", "y'_{k+1}")


def _combination_slip(fn, interval):
    """The combination's slip in the student's words when each basis function is right but multiplied by other
    data than equation (4) says (``y'_k * h4``), '' otherwise: each datum alone set, the interpolant is read as a
    sum of the four basis functions, and every sum must be of whole basis functions."""
    xdata = np.array(interval, dtype=float)
    points = xdata[0] + (xdata[1] - xdata[0]) * np.linspace(0.05, 0.95, 9)
    basis = np.asarray(piecewise.hermite_basis(xdata[0], xdata[1], points))  # (4, points)
    rows = []
    for m in range(4):
        y, yp = np.zeros(2), np.zeros(2)
        (y if m % 2 == 0 else yp)[m // 2] = 1.0
        ok, got = call(CheckResult("eval_pherm"), "one datum", fn, xdata, y, yp, points)
        try:
            rows.append(floats(got) if ok else None)
        except (TypeError, ValueError):
            return ""
    if any(r is None or r.shape != points.shape for r in rows):
        return ""
    weights = np.linalg.lstsq(basis.T, np.stack(rows).T, rcond=None)[0].T  # weights[m, n]: datum m times h_n
    whole = np.rint(weights)
    if not close(weights, whole, 1e-6) or np.array_equal(whole, np.eye(4)) or not set(whole.ravel()) <= {0.0, 1.0}:
        return ""
    wrong = [n for n in range(4) if not np.array_equal(whole[:, n], np.eye(4)[:, n])]
    said = []
    for n in wrong:
        used = [DATA_NAMES[m] for m in range(4) if whole[m, n]]
        said.append(f"h{n + 1} is multiplied by {' + '.join(used) or 'nothing'} where equation (4) has {DATA_NAMES[n]}")
    return (
        "each basis function is right, but the combination multiplies them by the wrong data: "
        + "; ".join(said)
        + ". p = y_k h1 + y'_k h2 + y_{k+1} h3 + y'_{k+1} h4."
    )


def _basis_failures(fn, interval, result):
    xdata = np.array(interval, dtype=float)
    xcheck = np.array([xdata[0], xdata[1], xdata[0] + 0.25 * (xdata[1] - xdata[0]), xdata.mean()])
    expected = piecewise.hermite_basis(xdata[0], xdata[1], xcheck)
    data = [([1, 0], [0, 0]), ([0, 0], [1, 0]), ([0, 1], [0, 0]), ([0, 0], [0, 1])]
    bad = []
    for m, ((y, yp), want) in enumerate(zip(data, expected), start=1):
        ok, got = call(result, f"h{m} on {interval}", fn, xdata, np.array(y, float), np.array(yp, float), xcheck)
        if not ok:
            return None
        if not close(got, want):
            other = next((f"h{n}" for n, basis in enumerate(expected, start=1) if n != m and close(got, basis)), None)
            bad.append((f"h{m}", _constant_factor(got, want), other))
    return bad


def _constant_factor(got, want):
    """c if got == c * want at every point (a wrong constant such as a denominator), else None."""
    try:
        got = floats(got)
    except (TypeError, ValueError):
        return None
    nonzero = np.abs(want) > 1e-12
    if got.shape != want.shape or not nonzero.any() or not np.allclose(got[~nonzero], 0, atol=1e-12):
        return None
    ratios = got[nonzero] / want[nonzero]
    if abs(ratios[0]) < 1e-12 or not np.allclose(ratios, ratios[0], rtol=1e-9):
        return None  # zero everywhere is no denominator mistake
    return float(ratios[0])


# -- Exercise 3 ---------------------------------------------------------------


def check_runge(fn, seed=None, runge_a=RUNGE_A.lab):
    """Check ``runge(x) -> (y, yprime)`` against 1/(1 + a x^2) and its derivative, a = `runge_a` (the
    notebook's data cell; the lab's function has a = 1)."""
    result = CheckResult("runge")
    x = np.linspace(-3.0, 3.0, 13)
    if seed is not None:  # the grader's fresh points besides the fixed ones
        x = np.concatenate((x, case_rng(seed, "hermite.runge").uniform(-5.0, 5.0, 8)))
    ok, got = call(result, "runge(x) returns (y, yprime)", fn, x)
    if not ok:
        return result
    out = several(got, 2)
    if out is None:
        return result.fail(
            "runge(x) returns (y, yprime)", f"got {shown(got)}", "return both values: `return y, yprime`."
        )
    lab = runge_a == RUNGE_A.lab
    formula = "1/(1+x^2)" if lab else f"1/(1 + runge_a x^2), runge_a = {RUNGE_A.shown(runge_a)}"
    y, yprime = functions.runge(x, a=runge_a)
    if not result.step(f"y = {formula}", close(out[0], y), "" if close(out[0], y) else worst(out[0], y)):
        result.hint = (
            "your runge leaves out runge_a: the function is 1 / (1 + runge_a * x**2), with runge_a from the "
            "notebook's data cell."
            if not lab and close(out[0], functions.runge(x)[0])
            else f"use componentwise operations: 1 / (1 + {'' if lab else 'runge_a * '}x**2)."
        )
        return result
    if _sign_slip(out[1], yprime):
        return result.fail(
            f"yprime is the derivative of {formula}",
            "yprime has the wrong sign",
            "yprime has the wrong sign: the Runge function falls for positive x, so its derivative must be negative "
            "there; check the sign the chain rule gives for the derivative of 1/u.",
        )
    if not result.step(
        f"yprime is the derivative of {formula}",
        close(out[1], yprime),
        "" if close(out[1], yprime) else worst(out[1], yprime),
    ):
        unsquared = close(out[1], yprime * (1 + runge_a * x**2))  # the chain rule's square left out
        inner = not lab and close(out[1], yprime / runge_a)  # the chain rule's inner factor runge_a left out
        square = "1 + x**2" if lab else "1 + runge_a * x**2"
        result.hint = (
            "yprime's denominator lacks a square: the chain rule, applied to 1/u with u = "
            f"{square}, puts u squared in the denominator."
            if unsquared
            else "yprime lacks the factor runge_a: the chain rule multiplies by the derivative of u = 1 + runge_a "
            "* x**2, which has runge_a in it."
            if inner
            else f"differentiate {formula.split(',')[0]} with the chain rule, then compare yprime with a centred "
            "difference of y."
        )
    return result


# -- Exercise 4 ---------------------------------------------------------------


def _sign_slip(got, want):
    """'has the wrong sign' if got == -want (and want is not zero), else ''."""
    try:
        got = floats(got)
    except (TypeError, ValueError):
        return ""
    if got.shape == want.shape and np.any(np.abs(want) > 1e-6) and np.allclose(got, -want, atol=1e-9):
        return "has the wrong sign"
    return ""


def _term_slip(name, got, t, r0):
    """Which of the product rule's two terms of `name` (dx/dt or dy/dt) is wrong, when the other is right and the
    wrong one is a plain mix-up of sine and cosine or of a sign, in the student's words; '' otherwise."""
    try:
        got = floats(got)
    except (TypeError, ValueError):
        return ""
    sin, cos, r = np.sin(t), np.cos(t), r0 + np.cos(t)
    trig = cos if name == "dx/dt" else sin  # x = r cos t, y = r sin t
    first, second = -sin * trig, r * (-sin if name == "dx/dt" else cos)  # dr/dt * trig, r * d(trig)/dt
    if got.shape != t.shape:
        return ""
    wrong_second = [k * r * w for k in (1, -1) for w in (sin, cos)]
    wrong_first = [k * sin * w for k in (1, -1) for w in (sin, cos)] + [
        k * cos * w for k in (1, -1) for w in (sin, cos)
    ]
    which = "cos t" if name == "dx/dt" else "sin t"
    if any(close(got - first, w) for w in wrong_second):
        return f"the second term of your {name}, r times the derivative of {which}, is not that derivative: check it."
    if any(close(got - second, w) for w in wrong_first):
        return (
            f"the first term of your {name}, dr/dt times {which}, is wrong: check dr/dt and the factor it multiplies."
        )
    return ""


def check_limacon_derivatives(fn, seed=None):
    """Check ``limacon_derivatives(t, r0) -> (dxdt, dydt)`` of x = r cos t, y = r sin t, r = r0 + cos t."""
    result = CheckResult("limacon_derivatives")
    cases = [(np.linspace(0, 2 * np.pi, 21), LAB_R0)]
    rng = case_rng(seed, "hermite.limacon_derivatives")
    cases.append((rng.uniform(-7.0, 7.0, 15), float(rng.uniform(0.3, 2.0)) if seed is not None else 0.5))
    for t, r0 in cases:
        label = f"{t.size} values of t, r0 = {r0:g}"
        ok, got = call(result, label, fn, t, r0)
        if not ok:
            return result
        out = several(got, 2)
        if out is None:
            return result.fail(label, f"got {shown(got)}", "return both derivatives: `return dxdt, dydt`.")
        slips = derivative_slips(t, r0)  # the right values and the slips named here (the plot's check forgives them)
        for name, got, formula in (
            ("dx/dt", out[0], "the derivative of x = r cos t"),
            ("dy/dt", out[1], "the derivative of y = r sin t"),
        ):
            want, no_product_rule = dict(slips[name])[""], dict(slips[name])["leaves out the product rule"]
            if not result.step(f"{label}: {name} = {formula}", close(got, want), worst(got, want)):
                if close(got, no_product_rule):
                    result.hint = (
                        f"{name} leaves out the product rule: r = r0 + cos t depends on t too, so it "
                        "has a second term, with dr/dt in it."
                    )
                    return result
                other = dict(slips[name])[f"is {'dy/dt' if name == 'dx/dt' else 'dx/dt'}: the two are swapped"]
                if close(got, other):
                    result.hint = (
                        f"your {name} is {'dy/dt' if name == 'dx/dt' else 'dx/dt'}: the two are swapped. Return "
                        "them in the order the function promises, dxdt first, then dydt."
                    )
                    return result
                if close(got, dict(slips[name])["has dr/dt with the wrong sign"]):
                    result.hint = (
                        f"{name} has the product rule, but in it dr/dt has the wrong sign: r = r0 + cos t, so "
                        "dr/dt is the derivative of cos t."
                    )
                    return result
                if r0 != LAB_R0 and close(got, derivative_slips(t)[name][0][1]):
                    result.hint = (
                        f"{name} is right for r0 = 1.15 but not for r0 = {r0:g}: use the r0 it is given "
                        "(r = r0 + cos t), not 1.15."
                    )
                    return result
                slip = _sign_slip(got, want)
                result.hint = (
                    f"{name} {slip}: differentiate with the product rule, and check the sign of each term."
                    if slip
                    else _term_slip(name, got, t, r0)
                    or f"differentiate {'x = r cos t' if name == 'dx/dt' else 'y = r sin t'} "
                    "with the product rule (r = r0 + cos t depends on t too); compare with a centred difference."
                )
                return result
    return result


# what Exercises 3(a) and 4(b) ask the student to derive, in the spellings a text or code would use
RUNGE_DERIVATIVE = (
    "-2x/(1+x^2)^2",
    "-2*x/(1 + x**2)**2",
    "-2x(1+x^2)^-2",
    "-2x*(1+x^2)**(-2)",
    "-\\frac{2x}{(1+x^2)^2}",
    "-2x/(x^2+1)^2",
    "2x/(1+x^2)^2",  # the sign alone would still give the rest away
    # with the student's own scale a of 1/(1 + a x^2), as the notebook names it and as a text would write it
    "-2*runge_a*x/(1 + runge_a*x**2)**2",
    "2*runge_a*x/(1 + runge_a*x**2)**2",
    "-2ax/(1+ax^2)^2",
    "-2*a*x/(1 + a*x**2)**2",
)
LIMACON_DERIVATIVES = (
    "-sin t cos t - r sin t",
    "-r sin t - sin t cos t",
    "-np.sin(t) * np.cos(t) - r * np.sin(t)",
    "-sin t (r + cos t)",
    "-sin t (r0 + 2 cos t)",
    "-(r0 + 2 cos t) sin t",
    "-sin 2t / 2 - r0 sin t",
    "-sin^2 t + r cos t",
    "r cos t - sin^2 t",
    "-np.sin(t)**2 + r * np.cos(t)",
    "cos 2t + r0 cos t",
    "r0 cos t + cos 2t",
    "cos^2 t - sin^2 t + r0 cos t",
    "dr/dt = -sin t",
    "r' = -sin t",
)

PHERM = Experiment(
    "pherm",
    4,
    "test_pherm_interpolate",
    "errors_pherm",
    "rate_pherm",
    weights=(6, 3, 3),
    pieces=(piecewise.eval_pherm,),
    uses=("eval_pherm", "runge"),
)

EXERCISES = (
    Exercise(
        2,
        ("eval_pherm",),
        (Part("eval_pherm", 10, check_eval_pherm, ("eval_pherm",), seeded=True, refused=INTERPOLANTS),),
        notebook="02_convergence.ipynb",
    ),
    Exercise(
        3,
        ("runge",) + PHERM.names(),
        (Part("runge", 3, check_runge, ("runge",), seeded=True, refused=OWN_FUNCTIONS, varied=(RUNGE_A.name,)),)
        + PHERM.parts(),
        notebook="02_convergence.ipynb",
        answers=("the order the table shows, against piecewise linear",),
        withheld=RUNGE_DERIVATIVE + PHERM.withheld,
        # the Runge function's scale: every convergence table measures the student's own function
        params=(RUNGE_A,),
        sound=PHERM.sound,
    ),
    Exercise(
        4,
        ("limacon_derivatives", "ax4"),
        (
            Part(
                "limacon_derivatives",
                8,
                check_limacon_derivatives,
                ("limacon_derivatives",),
                seeded=True,
                refused=OWN_FUNCTIONS,
            ),
            Part(
                "ax4",
                7,
                check_limacon_plot,
                ("ax4", Together(("tdata", "xdata", "ydata", "xpdata", "ypdata"), required=False)),
                keywords=(("derivatives", Optional("limacon_derivatives")),),
                uses=("limacon_derivatives",),
                varied=("r0",),
            ),
        ),
        notebook="01_limacon.ipynb",
        withheld=LIMACON_DERIVATIVES,
        # the limaçon's offset: near 1 the curve nears the cardioid's cusp, and well above 1.3 its dimple flattens
        params=(Param("r0", 1.05, 1.3, 4, lab=LAB_R0),),
    ),
)
