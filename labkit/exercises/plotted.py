"""Checks for plots, judged from the data drawn, never from pixels.

A plot is read as its lines: for every ``Line2D`` of an Axes (or of every
Axes of a Figure), its x and y data, its marker and whether a line is drawn
between the points (:func:`lines_of`). In a notebook that is the real
Axes; in ``labkit grade`` the sandboxed notebook sends the same lines as
plain numbers (:mod:`labkit.grading.sandbox.protocol`) and the decisions are made
here, on the grader's side.

* Exercise 4 (:func:`limacon_plot`): a curve of at least 100 points that
  is the Hermite interpolant (of the notebook's own slopes, or the lab's),
  not the exact limaçon, and goes all the way round;
* Exercise 14 (:func:`boiling_plot`): the data as circles with no lines, and
  the not-a-knot spline and pchip each as a curve of at least 100 points
  over the whole data range.
"""

import numpy as np

from .. import functions, monotone, piecewise, splines
from ..plotdata import NO_LINE, Line, line_of, lines_of  # noqa: F401 - Line and line_of for the checks' users
from .result import NOT_DONE, CheckResult, Results, call, close, floats, judged_by_the_lab, several

MIN_POINTS = 100
# bounds on the grader's work for one plot, whatever the notebook drew: the long lines examined,
# and the points of each (evenly strided; an interpolant's error is no isolated point)
MAX_CURVES = 10
SAMPLE = 20_000
HERMITE_LIMACON = 2e-3  # near the curve: Hermite with 20 intervals is 2.3e-4 from the limaçon, linear 3.8e-2
ON_CURVE = 1e-5  # on the Hermite interpolant itself (the polyline standing for it is within 1e-7)
CIRCLE = "o"


def _nothing_drawn(result, name):
    """An Axes with no line at all: the plot is not done yet (its cell still raises, or draws nothing)."""
    return result.fail(
        f"something is drawn on {name}",
        "nothing is drawn on it yet",
        f"draw the plot on `{name}`: replace the `raise NotImplementedError()` of its cell with your code.",
        NOT_DONE,
    )


def _no_plot(result, name, plot):
    what = getattr(plot, "description", None) or type(plot).__name__
    return result.fail(
        f"{name} is a plot",
        f"got {what}",
        f"draw on the Axes `{name}` the cell gives you (e.g. `{name}.plot(x, y)`), and keep the name.",
    )


# -- Exercise 4 ---------------------------------------------------------------


def _distances(points, curve, bound, neighbours=8):
    """For each of `points` (2, n) its distance to the polyline `curve` (2, m), or inf beyond `bound`.

    The nearest `neighbours` vertices come from a k-d tree; the distance is
    then taken to the two segments at each of them, so a dense polyline
    stands for the curve to within its chord error (about 1e-7 here), also
    where the curve crosses itself (a vertex of the other branch may be the
    nearest one)."""
    from scipy.spatial import cKDTree

    near, index = cKDTree(curve.T).query(points.T, k=neighbours, distance_upper_bound=bound)
    best = near.min(axis=1)
    last = curve.shape[1] - 1
    found = np.isfinite(near)  # (n, k): the neighbours within the bound
    rows, columns = np.nonzero(found)
    vertex = index[rows, columns]
    p = points[:, rows]
    for step in (-1, 1):
        a, b = curve[:, vertex], curve[:, np.clip(vertex + step, 0, last)]
        ab = b - a
        length2 = np.maximum(np.sum(ab * ab, axis=0), 1e-300)
        u = np.clip(np.sum((p - a) * ab, axis=0) / length2, 0.0, 1.0)
        np.minimum.at(best, rows, np.hypot(*(a + u * ab - p)))
    return best


def _nearest(points, cloud, bound):
    """For each of `points` (2, n) the distance to the nearest point of `cloud` (2, m), or inf beyond `bound`."""
    from scipy.spatial import cKDTree

    return cKDTree(cloud.T).query(points.T, distance_upper_bound=bound)[0]


def _hermite_curve(tdata, xdata, ydata, xpdata, ypdata, count=20001):
    t = np.linspace(tdata[0], tdata[-1], count)
    return np.stack((piecewise.eval_pherm(tdata, xdata, xpdata, t), piecewise.eval_pherm(tdata, ydata, ypdata, t)))


NINTERVALS = 20  # the lab's: 21 points of the limaçon
LAB_R0 = 1.15  # the lab's limaçon, r = 1.15 + cos t (a student's own with variants: labkit.exercises.variants)


def _lab_hermite(r0=LAB_R0, nintervals=NINTERVALS):
    """The lab's Hermite limaçon: 21 points of the curve with its exact derivatives."""
    tdata = np.linspace(0, 2 * np.pi, nintervals + 1)
    x, y, dx, dy = functions.limacon(tdata, r0=r0)
    return _hermite_curve(tdata, x, y, dx, dy)


def derivative_slips(t, r0=LAB_R0):
    """dx/dt and dy/dt of the limaçon at `t`, each with the slips Exercise 4's derivative check names:
    ``{"dx/dt": ((slip, values), ...), "dy/dt": ...}``, the right values first (slip ``""``)."""
    t = np.asarray(t, dtype=float)
    r = r0 + np.cos(t)
    _, _, dxdt, dydt = functions.limacon(t, r0=r0)
    sin, cos = np.sin(t), np.cos(t)
    return {
        "dx/dt": (
            ("", dxdt),
            ("has the wrong sign", -dxdt),
            ("leaves out the product rule", -r * sin),
            ("is dy/dt: the two are swapped", dydt),
            ("has dr/dt with the wrong sign", sin * cos - r * sin),
        ),
        "dy/dt": (
            ("", dydt),
            ("has the wrong sign", -dydt),
            ("leaves out the product rule", r * cos),
            ("is dx/dt: the two are swapped", dxdt),
            ("has dr/dt with the wrong sign", sin * sin + r * cos),
        ),
    }


def _own_slopes(derivatives, tdata, r0):
    """The student's own ``limacon_derivatives(tdata, r0)`` (dx/dt, dy/dt) as floats, or None."""
    if derivatives is None or not callable(derivatives):
        return None
    ok, got = call(CheckResult("limacon_derivatives"), "limacon_derivatives", derivatives, tdata, r0)
    out = several(got, 2) if ok else None
    try:
        return None if out is None else [floats(v) for v in out]
    except (TypeError, ValueError):
        return None


def attempted_data(own, r0=LAB_R0, derivatives=None):
    """Is the notebook's ``(tdata, xdata, ydata, xpdata, ypdata)`` an attempt at the lab's data?

    ``(data as floats, "")`` when it is: ``tdata``, ``xdata``, ``ydata`` are the lab's 21 points of the
    limaçon, and ``xpdata``, ``ypdata`` its derivatives there, each right or wrong by a slip the derivative
    check names, or what the student's own `derivatives` (``limacon_derivatives``) give there, whatever its
    slip (so a wrong derivative is charged there, once). ``(None, why)`` when it is not, `why` in the
    student's words; ``(None, "")`` when the notebook lacks them.
    """
    if own is None:
        return None, ""
    try:
        data = [floats(v) for v in own]
    except (TypeError, ValueError):
        return None, "your tdata, xdata, ydata, xpdata, ypdata are not arrays of numbers"
    if len(data) != 5:
        return None, "your tdata, xdata, ydata, xpdata, ypdata are not five arrays"
    tdata = np.linspace(0, 2 * np.pi, NINTERVALS + 1)
    x, y, _, _ = functions.limacon(tdata, r0=r0)
    if not (close(data[0], tdata) and close(data[1], x) and close(data[2], y)):
        whose = "the lab's" if r0 == LAB_R0 else "your variant's"
        given = "" if r0 == LAB_R0 else ", the r0 your notebook was given"
        return None, (
            f"your tdata, xdata, ydata are not {whose} {NINTERVALS + 1} points of the limaçon "
            f"(t from 0 to 2*pi, r0 = {r0:g}{given})"
        )
    slips = derivative_slips(tdata, r0)
    if r0 != LAB_R0:  # a function that ignores its r0 for the lab's (the derivative check names it)
        slips = {name: (*found, ("", derivative_slips(tdata)[name][0][1])) for name, found in slips.items()}
    mine = _own_slopes(derivatives, tdata, r0)
    if mine is not None:  # the student's own derivatives, whatever their slip: charged in their own part
        slips = {name: (*found, ("", values)) for (name, found), values in zip(slips.items(), mine)}
    for name, got in (("dx/dt", data[3]), ("dy/dt", data[4])):
        if not any(close(got, values) for _, values in slips[name]):
            return None, (
                f"your {'xpdata' if name == 'dx/dt' else 'ypdata'} are not {name} at tdata, not even with one "
                "of the slips the derivative check names"
            )
    return data, ""


def check_limacon_plot(plot, own=None, r0=LAB_R0, derivatives=None):
    """Check Exercise 4's plot: the Hermite interpolant of the limaçon, drawn all the way round.

    The curve must be the piecewise cubic Hermite interpolant itself (to
    1e-5), not the exact limaçon (which differs from it by up to 2.3e-4) and
    not straight segments: the interpolant of the notebook's own data `own`
    (``tdata, xdata, ydata, xpdata, ypdata``) when they are an attempt at the
    lab's (:func:`attempted_data`: the lab's 21 points, slopes right or wrong by
    a named slip, or what the student's own `derivatives` give there), so a
    wrong slope is marked where the slopes are checked and not again here;
    otherwise the lab's (21 points, exact derivatives), and the feedback says why.
    """
    result = CheckResult("ax4")
    lines = lines_of(plot)
    if lines is None:
        return _no_plot(result, "ax4", plot)
    if not lines:
        return _nothing_drawn(result, "ax4")
    long = [line for line in lines if line.x.size >= MIN_POINTS and line.x.size == line.y.size]
    if not result.step(
        f"a curve of at least {MIN_POINTS} points",
        bool(long),
        f"the longest line has {max((line.x.size for line in lines), default=0)} points",
    ):
        result.hint = "plot the Hermite interpolant at the 10*(nintervals+1) values of tval, not only the data points."
        return result
    long = long[:MAX_CURVES]
    curves = [("the Hermite interpolant of the lab's data", _lab_hermite(r0))]
    data, why = attempted_data(own, r0, derivatives)
    if why:
        whose = "the lab's" if r0 == LAB_R0 else f"your variant's (r0 = {r0:g})"
        judged_by_the_lab(result, why, f"{whose} Hermite limaçon (its 21 points with the exact slopes)")
    own_curve = _own_hermite(data)
    if own_curve is not None:
        curves.insert(0, ("the Hermite interpolant of your tdata, xdata, ydata, xpdata, ypdata", own_curve))
    best = _closest_curve(long, curves)
    if best is None:
        return result.fail(
            "the curve is the Hermite interpolant",
            "every long line has NaN or infinite points",
            "plot xherm, yherm from eval_pherm.",
        )
    far, cover, name = best
    on_exact = _all_on(long, _limacon_curve(r0))
    ok = result.step(
        f"the curve is {name} (within {ON_CURVE:g})",
        far <= ON_CURVE,
        f"a point is {far:.2e} away from it"
        if np.isfinite(far)
        else f"points are more than {10 * HERMITE_LIMACON:g} away from it",
    )
    if not ok:
        result.hint = _plot_slip(long, data, r0) or _limacon_miss(on_exact, far <= HERMITE_LIMACON, bool(why))
        return result
    if not result.step(
        "the curve goes all the way round",
        cover <= 0.1,
        f"part of the curve is {min(cover, 1.0):.2f} or more away from every plotted point",
    ):
        result.hint = "interpolate over the whole turn: tval from 0 to 2*pi."
    return result


def _closest_curve(long, curves):
    """(how far, how much of it is left undrawn, its name) of the named curve that the finite lines of `long`
    follow most closely, or None when no line is finite."""
    best = None
    for line in long:
        points = np.stack((line.x, line.y))[:, :: -(-line.x.size // SAMPLE)]
        if not np.all(np.isfinite(points)):
            continue
        for name, curve in curves:
            far = float(_distances(points, curve, 10 * HERMITE_LIMACON).max())
            # every part of the curve is drawn (repeated points are dropped: they would unbalance the tree)
            cover = float(_nearest(curve[:, ::50], np.unique(points, axis=1), 1.0).max())
            if best is None or (far, cover) < best[:2]:
                best = (far, cover, name)
    return best


def _all_on(long, curve):
    """Whether every finite line of `long` lies on `curve` (within :data:`ON_CURVE`)."""
    return all(
        float(_distances(np.stack((ln.x, ln.y))[:, :: -(-ln.x.size // SAMPLE)], curve, 10 * HERMITE_LIMACON).max())
        <= ON_CURVE
        for ln in long
        if np.all(np.isfinite(ln.x)) and np.all(np.isfinite(ln.y))
    )


def _limacon_miss(on_exact, near, labs):
    """The hint for a curve that is not the Hermite interpolant and shows no named slip: the exact limaçon,
    `near` the interpolant (of the lab's data when `labs`), or corners and wiggles."""
    if on_exact:
        return (
            "that is the exact limaçon, not its Hermite interpolant: evaluate eval_pherm with tdata, "
            "xdata, xpdata (and ydata, ypdata) at tval and plot xherm, yherm."
        )
    if near:
        return (
            f"close to the curve but not the interpolant of {'the lab' if labs else 'your'} data: plot "
            "eval_pherm of tdata, xdata, xpdata and of tdata, ydata, ypdata at tval."
        )
    return (
        "corners or wiggles: straight segments (eval_plin) are about 4e-2 off, and a wrong slope "
        "bends the curve away; use eval_pherm with the derivatives of Exercise 4."
    )


def _plot_slip(long, data, r0=LAB_R0):
    """The slip that explains Exercise 4's curve, in the student's words ('' for none): x and y swapped, y
    drawn against t, the slopes of x and y swapped, or straight segments; of the notebook's own data when they
    are an attempt at the lab's (`data`), else of the lab's."""
    if data is None:
        tdata = np.linspace(0, 2 * np.pi, NINTERVALS + 1)
        data = (tdata, *functions.limacon(tdata, r0=r0))
    tdata, xdata, ydata, xpdata, ypdata = data
    t = np.linspace(tdata[0], tdata[-1], 20001)
    candidates = (
        (
            "x and y are swapped: the curve is drawn with y across and x up. The first argument of ax4.plot is "
            "the horizontal coordinate: plot xherm, then yherm.",
            _hermite_curve(tdata, ydata, xdata, ypdata, xpdata),
        ),
        (
            "xpdata and ypdata are swapped in the eval_pherm calls: x is interpolated with the slopes of y and y "
            "with those of x. Each coordinate takes its own derivative.",
            _hermite_curve(tdata, xdata, ydata, ypdata, xpdata),
        ),
        (
            "straight segments: that is eval_plin's curve (Exercise 1's), with corners at the data points, not "
            "the Hermite interpolant; use eval_pherm with the derivatives of Exercise 4.",
            np.stack((piecewise.eval_plin(tdata, xdata, t), piecewise.eval_plin(tdata, ydata, t))),
        ),
    )
    for line in long:
        points = np.stack((line.x, line.y))[:, :: -(-line.x.size // SAMPLE)]
        if not np.all(np.isfinite(points)):
            continue
        for hint, curve in candidates:
            if float(_distances(points, curve, 10 * HERMITE_LIMACON).max()) <= ON_CURVE:
                return hint
        inside = (points[0] >= tdata[0] - 1e-9) & (points[0] <= tdata[-1] + 1e-9)
        if inside.all():
            for name, values, slopes in (("x", xdata, xpdata), ("y", ydata, ypdata)):
                if close(points[1], piecewise.eval_pherm(tdata, values, slopes, points[0]), 1e-6):
                    return (
                        f"the curve is {name} against t: the plot's horizontal axis is t. The limaçon is the "
                        "curve of the points (x, y): plot xherm, then yherm, both from eval_pherm at tval."
                    )
    return ""


def _limacon_curve(r0=LAB_R0, count=20001):
    x, y, _, _ = functions.limacon(np.linspace(0, 2 * np.pi, count), r0=r0)
    return np.stack((x, y))


def _own_hermite(own):
    """The Hermite curve of the notebook's own data (densely), or None."""
    if own is None:
        return None
    try:
        tdata, xdata, ydata, xpdata, ypdata = (floats(v) for v in own)
        curve = _hermite_curve(tdata, xdata, ydata, xpdata, ypdata)
    except (TypeError, ValueError, IndexError):
        return None
    return curve if np.all(np.isfinite(curve)) else None


# -- Exercise 14 ----------------------------------------------------------------

LAB_RISE, LAB_BOIL = 1.0, 2.0  # the lab's temperatures at times 1 and 2 (boiling from time 2 on)


def boiling_data(rise=LAB_RISE, boil=LAB_BOIL):
    """Exercise 14's data: times 0 to 4, the temperature 0 at time 0, `rise` at 1, and `boil` from 2 on."""
    return np.array([0.0, 1.0, 2.0, 3.0, 4.0]), np.array([0.0, rise, boil, boil, boil], dtype=float)


BOILING = boiling_data()


def boiling_sound(values):
    """Why a draw of Exercise 14's data would not teach its lesson ('' when it does): the spline must overshoot
    the boiling point and dip below it, pchip must stay monotone and flat, and the two must differ visibly."""
    xdata, ydata = boiling_data(values["rise"], values["boil"])
    x = np.linspace(0, 4, 401)
    spline, pchip = splines.spline(xdata, ydata, x), monotone.pchip(xdata, ydata, x)
    boil = values["boil"]
    if not (spline.max() > boil + 0.02 and spline[x >= 2].min() < boil - 0.02):
        return "the spline neither overshoots the boiling point nor dips below it visibly"
    if np.any(np.diff(pchip) < -1e-12) or np.abs(pchip[x >= 2] - boil).max() > 1e-12:
        return "pchip is not monotone and flat after boiling starts"
    return ""


def _matches(line, values):
    return bool(np.allclose(line.y, values, rtol=0, atol=1e-6))


def check_boiling_plot(plot, rise=LAB_RISE, boil=LAB_BOIL):
    """Check Exercise 14's plot: data circles without lines, then the spline and pchip curves, of the data
    with the temperature `rise` at time 1 and `boil` from time 2 on (the lab's, or a student's variant)."""
    xdata, ydata = boiling_data(rise, boil)
    results = Results()
    lines = lines_of(plot)
    if lines is None:
        failed = _no_plot(CheckResult("ax14"), "ax14", plot)
        return Results([failed, failed, failed])
    if not lines:
        names = ("ax14: the data", "ax14: the not-a-knot spline", "ax14: pchip")
        return Results(_nothing_drawn(CheckResult(name), "ax14") for name in names)
    lines = [
        ln
        for ln in lines
        if ln.x.size == ln.y.size and ln.x.size and np.all(np.isfinite(ln.x)) and np.all(np.isfinite(ln.y))
    ]

    data, at_data = _boiling_data_check(lines, xdata, ydata)
    results.append(data)
    curves = [ln for ln in lines if all(ln is not d for d in at_data)]
    for name, interpolant in (("the not-a-knot spline", splines.spline), ("pchip", monotone.pchip)):
        results.append(_boiling_curve_check(curves, name, interpolant, xdata, ydata))
    return results


def _boiling_data_check(lines, xdata, ydata):
    """Exercise 14's data drawn as circles without lines: (the check, the lines at the data points)."""
    data = CheckResult("ax14: the data")
    at_data = [
        ln
        for ln in lines
        if ln.x.size == xdata.size and np.allclose(np.sort(ln.x), xdata) and _matches(ln, np.interp(ln.x, xdata, ydata))
    ]
    if not data.step("a line at the five data points", bool(at_data), "no line has exactly the data's points"):
        swapped = any(
            ln.y.size == xdata.size
            and np.allclose(np.sort(ln.y), xdata)
            and np.allclose(ln.x, np.interp(ln.y, xdata, ydata))
            for ln in lines
        )
        data.hint = (
            "x and y are swapped: the data are drawn with the temperatures across and the times up. The first "
            "argument of ax14.plot is the horizontal coordinate: xdata, then ydata."
            if swapped
            else "draw the data points themselves: the times across, the temperatures up."
        )
    elif data.step(
        "drawn as circles",
        any(ln.marker == CIRCLE for ln in at_data),
        f"markers {sorted({ln.marker for ln in at_data})}",
    ):
        if not data.step(
            "with no lines between them",
            any(ln.marker == CIRCLE and not ln.joined for ln in at_data),
            "the circles are joined by lines",
        ):
            data.hint = "circles only: no line may join the data points."
    else:
        data.hint = "draw each data point as a circle."
    return data, at_data


def _boiling_curve_check(curves, name, interpolant, xdata, ydata):
    """One of Exercise 14's curves (`interpolant` of the data, called `name`) among the lines `curves`."""
    check = CheckResult(f"ax14: {name}")
    matching = [
        ln
        for ln in curves
        if _matches(ln, interpolant(xdata, ydata, ln.x)) and not _matches(ln, _other(interpolant)(xdata, ydata, ln.x))
    ]
    if not check.step(f"a curve that is {name}", bool(matching), f"none of the {len(curves)} other line(s) follows it"):
        swapped = any(  # a line whose x are the interpolant's values at its y
            np.allclose(ln.x, interpolant(xdata, ydata, ln.y), rtol=0, atol=1e-6)
            and not np.allclose(ln.x, _other(interpolant)(xdata, ydata, ln.y), rtol=0, atol=1e-6)
            for ln in curves
        )
        check.hint = (
            f"x and y are swapped: {name} is drawn with its values across and xval up. The first argument "
            "of ax14.plot is the horizontal coordinate: xval, then the values."
            if swapped
            else f"evaluate {name} of the data at many times from the first data point to the last, and draw "
            "its values against those times."
        )
        return check
    most = max(matching, key=lambda ln: ln.x.size)
    if not check.step(f"at least {MIN_POINTS} points", most.x.size >= MIN_POINTS, f"only {most.x.size} points"):
        check.hint = f"evaluate it at {MIN_POINTS} points or more, so that the curve looks smooth."
    elif not check.step(
        "over the whole data range [0, 4]",
        most.x.min() <= 1e-9 and most.x.max() >= 4 - 1e-9,
        f"from {most.x.min():.3g} to {most.x.max():.3g}",
    ):
        check.hint = "let its times run from the first data point to the last."
    elif not check.step("drawn as a line", most.joined, "drawn as separate markers"):
        check.hint = "draw the curve as a line, not as separate markers."
    return check


def _other(interpolant):
    """The other of the two interpolants: a curve that is both (where they agree) identifies neither."""
    return monotone.pchip if interpolant is splines.spline else splines.spline
