"""Self-checks for the functions students write, with the lab's debugging steps.

Each check takes the student's function (or data), runs the lab's own
verification and, when something is wrong, narrows it down the way the lab's
debugging hints do, then says which step failed and what to look at. The
reference is always labkit's own implementation or the mathematics (a
polynomial the method must reproduce), never a stored output.

In a notebook, put ``labkit.check.eval_pherm(eval_pherm)`` right after the
function: the result prints as a short report. The grader
(``labkit grade``) calls :func:`grade` with the notebook's variables.
"""
from dataclasses import dataclass, field

import numpy as np

from . import bilinear, functions, patches, piecewise, splines
from .mesh import quad_mesh

TOLERANCE = 1e-9


@dataclass
class CheckResult:
    """Outcome of one check: the steps run, whether all passed, and a hint if not."""

    name: str
    steps: list = field(default_factory=list)  # (description, passed, detail)
    hint: str = ""

    @property
    def passed(self):
        return bool(self.steps) and all(ok for _, ok, _ in self.steps)

    def step(self, description, ok, detail=""):
        """Record a step; the detail explains a failure, so a passed step drops it."""
        self.steps.append((description, bool(ok), "" if ok else detail))
        return bool(ok)

    def fail(self, description, detail, hint):
        self.step(description, False, detail)
        self.hint = hint
        return self

    def __repr__(self):
        verdict = "all checks passed" if self.passed else "FAILED"
        lines = [f"{self.name}: {verdict}"]
        for description, ok, detail in self.steps:
            lines.append(f"  [{'ok' if ok else 'FAIL'}] {description}" + (f": {detail}" if detail else ""))
        if self.hint:
            lines.append(f"  hint: {self.hint}")
        return "\n".join(lines)

    def as_dict(self):
        return {"name": self.name, "passed": self.passed, "hint": self.hint,
                "steps": [{"step": d, "passed": ok, "detail": det} for d, ok, det in self.steps]}


def _call(result, description, fn, *args):
    """Run student code; an exception becomes a failed step (never escapes)."""
    try:
        return True, fn(*args)
    except NotImplementedError:
        result.fail(description, "not implemented yet", "replace the `raise NotImplementedError()` with your code.")
    except Exception as exc:  # noqa: BLE001 - any student error is reported, not raised
        result.fail(description, f"raised {type(exc).__name__}: {exc}", "read the error above; run the cell on its own to see the traceback.")
    return False, None


def _close(actual, expected, tol=TOLERANCE):
    try:
        actual = np.asarray(actual, dtype=float)
    except (TypeError, ValueError):
        return False
    expected = np.asarray(expected, dtype=float)
    return actual.shape == expected.shape and np.allclose(actual, expected, rtol=tol, atol=tol)


def _worst(actual, expected):
    try:
        diff = np.abs(np.asarray(actual, dtype=float) - np.asarray(expected, dtype=float))
        return f"largest difference {np.max(diff):.2e}"
    except (TypeError, ValueError):
        return f"expected shape {np.shape(expected)}, got {np.shape(actual)}"


# -- Exercise 2 ---------------------------------------------------------------

MONOMIAL_POINTS = np.array([-1.0, 0.5, 1.5, 3.0])


def _monomials(fn, interval, result, label):
    """Interpolate 1, x, x^2, x^3 on one interval; return the failing powers."""
    xdata = np.array(interval, dtype=float)
    wrong = []
    for power in range(4):
        ydata, ypdata = xdata**power, power * xdata ** max(power - 1, 0)
        ok, yval = _call(result, f"y = x^{power} on {label}", fn, xdata, ydata, ypdata, MONOMIAL_POINTS)
        if not ok:
            return None
        if not _close(yval, MONOMIAL_POINTS**power):
            wrong.append(power)
    return wrong


def eval_pherm(fn):
    """Check a student's ``eval_pherm(xdata, ydata, ypdata, xval)`` (exercise 2).

    Steps: the four monomials on [0, 2] at x = -1, 0.5, 1.5, 3; if that fails,
    the monomials on [0, 1] (interval length 1 hides wrong denominators),
    then each Hermite basis function alone on [0, 1] and on [0, 2]. Last,
    several unequal intervals against labkit's reference.
    """
    result = CheckResult("eval_pherm")
    wrong = _monomials(fn, [0.0, 2.0], result, "[0, 2]")
    if wrong is None:
        return result
    if not result.step("reproduces 1, x, x^2, x^3 on [0, 2] at x = -1, 0.5, 1.5, 3", not wrong,
                       f"wrong for x^{wrong}" if wrong else ""):
        return _narrow_pherm(fn, result)
    rng = np.random.default_rng(2)
    xdata = np.cumsum(rng.uniform(0.2, 1.5, 8))
    ydata, ypdata = rng.normal(size=8), rng.normal(size=8)
    xval = np.linspace(xdata[0] - 0.5, xdata[-1] + 0.5, 57)
    ok, yval = _call(result, "several unequal intervals", fn, xdata, ydata, ypdata, xval)
    if ok and not result.step("several unequal intervals agree with labkit.eval_pherm",
                              _close(yval, piecewise.eval_pherm(xdata, ydata, ypdata, xval)),
                              _worst(yval, piecewise.eval_pherm(xdata, ydata, ypdata, xval))):
        result.hint = ("one interval works but several do not: use bracket(xdata, xval) to pick the "
                       "interval k of each point, and x_k, x_{k+1} of that interval in h1..h4.")
    return result


def _narrow_pherm(fn, result):
    """The lab's debugging steps iii to v for eval_pherm."""
    wrong_unit = _monomials(fn, [0.0, 1.0], result, "[0, 1]")
    if wrong_unit is None:
        return result
    unit_ok = result.step("monomials on [0, 1] (interval length 1)", not wrong_unit,
                          f"wrong for x^{wrong_unit}" if wrong_unit else "")
    # on [0, 1] every denominator is 1; on [0, 2] they are not
    interval = [0.0, 1.0] if not unit_ok else [0.0, 2.0]
    bad = _basis_failures(fn, interval, result)
    if bad is None:
        return result
    label = f"each Hermite basis function alone on [{interval[0]:g}, {interval[1]:g}]"
    if not bad:
        result.step(label, True)
        result.hint = ("each basis function is right, so the combination is wrong: "
                       "p = y_k h1 + y'_k h2 + y_{k+1} h3 + y'_{k+1} h4 (equation 4).")
        return result
    name, factor = bad[0]
    if factor is not None or unit_ok:
        times = f" times {factor:g}" if factor is not None else ""
        hint = (f"{name} is the right polynomial{times} on [{interval[0]:g}, {interval[1]:g}]: its denominator is wrong "
                "(the denominators are (x_k - x_{k+1})^3 for h1, (x_k - x_{k+1})^2 for h2, "
                "(x_{k+1} - x_k)^3 for h3 and (x_{k+1} - x_k)^2 for h4).")
        if factor is None:
            hint = hint.replace(" is the right polynomial on", " is right on [0, 1] but not on")
    else:
        hint = (f"{name} is wrong: compare your formula with the lab's definition of the four Hermite "
                "polynomials, factor by factor.")
    result.fail(label, f"wrong: {', '.join(n for n, _ in bad)}", hint)
    return result


def _basis_failures(fn, interval, result):
    xdata = np.array(interval, dtype=float)
    xcheck = np.array([xdata[0], xdata[1], xdata[0] + 0.25 * (xdata[1] - xdata[0]), xdata.mean()])
    expected = piecewise.hermite_basis(xdata[0], xdata[1], xcheck)
    data = [([1, 0], [0, 0]), ([0, 0], [1, 0]), ([0, 1], [0, 0]), ([0, 0], [0, 1])]
    bad = []
    for m, ((y, yp), want) in enumerate(zip(data, expected), start=1):
        ok, got = _call(result, f"h{m} on {interval}", fn, xdata, np.array(y, float), np.array(yp, float), xcheck)
        if not ok:
            return None
        if not _close(got, want):
            bad.append((f"h{m}", _constant_factor(got, want)))
    return bad


def _constant_factor(got, want):
    """c if got == c * want at every point (a wrong constant such as a denominator), else None."""
    try:
        got = np.asarray(got, dtype=float)
    except (TypeError, ValueError):
        return None
    nonzero = np.abs(want) > 1e-12
    if got.shape != want.shape or not nonzero.any() or not np.allclose(got[~nonzero], 0, atol=1e-12):
        return None
    ratios = got[nonzero] / want[nonzero]
    return float(ratios[0]) if np.allclose(ratios, ratios[0], rtol=1e-9) else None


# -- Exercise 3 ---------------------------------------------------------------

def runge(fn):
    """Check ``runge(x) -> (y, yprime)`` against 1/(1+x^2) and its derivative."""
    result = CheckResult("runge")
    x = np.linspace(-3.0, 3.0, 13)
    ok, out = _call(result, "runge(x) returns (y, yprime)", fn, x)
    if not ok:
        return result
    if not (isinstance(out, tuple) and len(out) == 2):
        return result.fail("runge(x) returns (y, yprime)", f"got {type(out).__name__}",
                           "return both values: `return y, yprime`.")
    y, yprime = functions.runge(x)
    if not result.step("y = 1/(1+x^2)", _close(out[0], y), "" if _close(out[0], y) else _worst(out[0], y)):
        result.hint = "use componentwise operations: 1 / (1 + x**2)."
        return result
    if not result.step("yprime = -2x/(1+x^2)^2", _close(out[1], yprime),
                       "" if _close(out[1], yprime) else _worst(out[1], yprime)):
        result.hint = "differentiate 1/(1+x^2) with the chain rule: -2x/(1+x^2)^2."
    return result


def test_pherm_interpolate(fn):
    """Check the driver ``test_pherm_interpolate(ndata, interpolate) -> relative max error``.

    The driver is run with labkit's ``eval_pherm`` as `interpolate`, so a
    mistake in the student's interpolant does not count against the driver.
    """
    result = CheckResult("test_pherm_interpolate")
    for ndata in (5, 11, 21):
        ok, err = _call(result, f"ndata = {ndata}", fn, ndata, piecewise.eval_pherm)
        if not ok:
            return result
        x = np.linspace(0.0, 5.0, ndata)
        xtest = np.linspace(0.0, 5.0, 4001)
        y, yp = functions.runge(x)
        exact = functions.runge(xtest)[0]
        expected = np.max(np.abs(piecewise.eval_pherm(x, y, yp, xtest) - exact)) / np.max(np.abs(exact))
        if not result.step(f"Err({ndata}) on [0, 5] with 4001 test points", _close(err, expected, 1e-6),
                           "" if _close(err, expected, 1e-6) else f"got {err}, expected {expected:.6e}"):
            result.hint = ("the error is max|f - p| / max|f| over 4001 equally spaced points of [0, 5], "
                           "with ndata equally spaced data points from runge (values and derivatives).")
            return result
    return result


# -- Exercises 5 to 9 ---------------------------------------------------------

def _identity_corners():
    e1, e2 = [1.0, 0.0], [0.0, 1.0]
    return [patches.Corner(p, e1, e2) for p in ([0, 0], [1, 0], [1, 1], [0, 1])]


def coons(fn):
    """Check a student's ``coons(A, B, C, D, s, t) -> (x, y)`` (the script of exercise 5)."""
    result = CheckResult("coons")
    s, t = np.linspace(0, 1, 4), np.linspace(0, 1, 5)
    ok, out = _call(result, "identity patch", fn, *_identity_corners(), s, t)
    if not ok:
        return result
    S, T = np.meshgrid(s, t, indexing="ij")
    if not result.step("the unit square with the identity data gives the 4 x 5 grid", _close(out, [S, T]),
                       "" if _close(out, [S, T]) else _worst(out, [S, T])):
        result.hint = ("start with the outline: x along AB is eval_pherm([0, 1], [xA, xB], [dxdsA, dxdsB], s); "
                       "DC uses D and C; then join them in t for every s.")
        return result
    rng = np.random.default_rng(5)
    corners = [patches.Corner(*rng.normal(size=(4, 2))) for _ in range(4)]
    expected = patches.patch(*corners, s, t)
    ok, out = _call(result, "random corner data with twists", fn, *corners, s, t)
    if not ok or result.step("random corner data with twists agree with labkit.patch", _close(out, expected),
                             "" if _close(out, expected) else _worst(out, expected)):
        return result
    for edge, untwist in (("AB and DC", "ABCD"), ("AB", "AB"), ("DC", "DC")):
        candidate = [patches.Corner(c.point, c.ds, c.dt) if label in untwist else c
                     for label, c in zip("ABCD", corners)]
        if _close(out, patches.patch(*candidate, s, t)):
            result.hint = (f"your patch ignores the twists along {edge}: the t-derivative along an edge "
                           "(dxdtAB, dxdtDC) is a Hermite cubic in s with values dx/dt and slopes d2x/dsdt "
                           "at its corners (likewise for y).")
            break
    else:
        result.hint = ("compare the four edge curves one at a time with labkit.patch: values along AB and DC, "
                       "then the t-derivatives along them, then the join in t.")
    return result


def _corner_list(corners, result, label):
    if not (isinstance(corners, (list, tuple)) and len(corners) == 4
            and all(isinstance(c, patches.Corner) for c in corners)):
        result.fail(label, "expected a list of four labkit.Corner objects A, B, C, D",
                    "build them with Corner(point, ds, dt, dsdt).")
        return False
    return True


def graded_corners(corners):
    """Exercise 6: the unit square with dx/ds 3 at A, D and 0.1 at B, C."""
    result = CheckResult("exercise 6 corners")
    if not _corner_list(corners, result, "four corners"):
        return result
    x, y = patches.patch(*corners, np.linspace(0, 1, 11), np.linspace(0, 1, 16))
    outline = _close([x[0], x[-1]], [np.zeros(16), np.ones(16)]) and _close([y[:, 0], y[:, -1]], [np.zeros(11), np.ones(11)])
    if not result.step("outline is still the unit square", outline):
        result.hint = "only dx/ds changes; every other value stays as in exercise 5."
        return result
    dxds = [c.ds[0] for c in corners]
    if not result.step("dx/ds is 3 at A and D and 0.1 at B and C", _close(dxds, [3.0, 0.1, 0.1, 3.0]),
                       f"got {dxds}"):
        result.hint = "A and D are on the left (s = 0), B and C on the right (s = 1)."
        return result
    widths = np.diff(x, axis=0)
    result.step("elements get thinner towards the right", np.all(np.diff(widths, axis=0) < 0))
    return result


def straight_corners(corners):
    """Exercise 7: A(-1,0), B(1,0), C(1,0.5), D(0,1); the patch must be the bilinear map."""
    result = CheckResult("exercise 7 corners")
    if not _corner_list(corners, result, "four corners"):
        return result
    A, B, C, D = (np.array(p) for p in ([-1.0, 0.0], [1.0, 0.0], [1.0, 0.5], [0.0, 1.0]))
    if not result.step("corner points A, B, C, D", _close([c.point for c in corners], [A, B, C, D])):
        result.hint = "A = (-1, 0), B = (1, 0), C = (1, 0.5), D = (0, 1)."
        return result
    if not result.step("twists d2x/dsdt = -1, d2y/dsdt = -0.5", _close([c.dsdt for c in corners], [A - B + C - D] * 4)):
        result.hint = "set d2xdsdt = -1 and d2ydsdt = -0.5 at all four corners."
        return result
    s, t = np.linspace(0, 1, 20), np.linspace(0, 1, 15)
    S, T = np.meshgrid(s, t, indexing="ij")
    bilinear_map = [(1 - S) * (1 - T) * A[i] + S * (1 - T) * B[i] + S * T * C[i] + (1 - S) * T * D[i] for i in (0, 1)]
    got = patches.patch(*corners, s, t)
    if not result.step("mesh lines straight and evenly spaced", _close(got, bilinear_map), _worst(got, bilinear_map)):
        result.hint = ("along a straight side with even spacing the derivative is the vector along that side: "
                       "d/ds = B - A on AB and C - D on DC, d/dt = D - A on AD and C - B on BC.")
    return result


def circle_corners(corners):
    """Exercise 8: quarter-circle sides through the unit square's corners, two-fold symmetric."""
    result = CheckResult("exercise 8 corners")
    if not _corner_list(corners, result, "four corners"):
        return result
    u = np.linspace(0, 1, 25)
    x, y = patches.patch(*corners, u, u)
    if not result.step("corners at the unit square's corners",
                       _close([c.point for c in corners], [[0, 0], [1, 0], [1, 1], [0, 1]])):
        result.hint = "A = (0, 0), B = (1, 0), C = (1, 1), D = (0, 1) as in exercise 5."
        return result
    radius = np.sqrt(2) / 2
    bound = np.sqrt(2) * radius * (np.pi / 2) ** 4 / 384
    sides = {"AB": (x[:, 0], y[:, 0], [(0.5, 0.5), (0.5, -0.5)]), "DC": (x[:, -1], y[:, -1], [(0.5, 0.5), (0.5, 1.5)]),
             "AD": (x[0], y[0], [(0.5, 0.5), (-0.5, 0.5)]), "BC": (x[-1], y[-1], [(0.5, 0.5), (1.5, 0.5)])}
    for name, (xs, ys, centres) in sides.items():
        near = min(np.max(np.abs(np.hypot(xs - cx, ys - cy) - radius)) for cx, cy in centres)
        if not result.step(f"side {name} close to a quarter circle of radius sqrt(2)/2", near < bound,
                           f"off by {near:.3f}"):
            result.hint = ("parametrise the arc (centre, radius sqrt(2)/2, angle growing by pi/2 over s in [0, 1]) "
                           "and differentiate: the derivative's length is (sqrt(2)/2)(pi/2) = pi/(2 sqrt 2).")
            return result
    symmetric = _close(x + x[::-1], np.ones_like(x)) and _close(y + y[:, ::-1], np.ones_like(y))
    if not result.step("left-right and top-bottom symmetric", symmetric):
        result.hint = "mirror the bottom side's data to get the top, and the left side's to get the right."
    return result


def two_patches(fn, corners):
    """Exercise 9: ``two_patches(A, B, C, D) -> (mesh1, mesh2)`` joins along BC / dc."""
    result = CheckResult("exercise 9 patches")
    if not _corner_list(corners, result, "corners of ABCD"):
        return result
    for label, ABCD in (("sharp corner", corners),
                        ("rounded corner", [*corners[:2], patches.Corner([1.8, 1.8], [0.5, -0.5], corners[2].dt), corners[3]])):
        ok, out = _call(result, label, fn, *ABCD)
        if not ok:
            return result
        try:
            first, second = out
            merged = first + second
        except Exception as exc:  # noqa: BLE001
            return result.fail(label, f"could not join the two meshes ({exc})",
                               "return the two QuadMesh objects: `return first, second`.")
        expected_nodes = len(first.points) + len(second.points) - 30
        if not result.step(f"{label}: the 30 nodes of the shared edge merge", len(merged.points) == expected_nodes,
                           f"{len(first.points)} + {len(second.points)} nodes gave {len(merged.points)}"):
            result.hint = ("abcd is ABCD mirrored in y = x with s and t swapped: give each corner the mirrored "
                           "dt as ds and the mirrored ds as dt, and use 30 points along dc.")
            return result
        if not result.step(f"{label}: every element positively oriented", merged.quality().min() > 0):
            result.hint = "a folded element means a corner derivative of abcd points the wrong way."
            return result
    return result


# -- Exercises 10 and 12 ------------------------------------------------------

SPLINE_CASES = [
    ("x^3 on [0 1 2 4] (exercise 10g)", [0.0, 1.0, 2.0, 4.0], [0.0, 1.0, 8.0, 64.0], 0.0, 48.0),
    ("x^3 on [0 1 2] (equal intervals)", [0.0, 1.0, 2.0], [0.0, 1.0, 8.0], 0.0, 12.0),
    ("x^3 on [0 1 3]", [0.0, 1.0, 3.0], [0.0, 1.0, 27.0], 0.0, 27.0),
]


def _reference_complete_system(xdata, ydata, y1p, ynp):
    h = np.diff(xdata)
    secants = np.diff(ydata) / h
    diagonal = np.concatenate(([h[0] / 3], (h[:-1] + h[1:]) / 3, [h[-1] / 3]))
    A = np.diag(diagonal) + np.diag(h / 6, 1) + np.diag(h / 6, -1)
    D = np.concatenate(([secants[0] - y1p], np.diff(secants), [ynp - secants[-1]]))
    return A, D


def ccspline(fn, system=None):
    """Check ``ccspline(xdata, ydata, y1p, ynp)``; with ``system(xdata, ydata, y1p, ynp) -> (A, D)``
    also the matrix (symmetric, diagonally dominant, equal to equations 11-12)."""
    result = CheckResult("ccspline")
    name, x, y, y1p, ynp = SPLINE_CASES[0]
    ok, sprime = _call(result, name, fn, np.array(x), np.array(y), y1p, ynp)
    if not ok:
        return result
    expected = 3 * np.array(x) ** 2
    if result.step(f"{name}: slopes [0 3 12 48]", _close(sprime, expected),
                   "" if _close(sprime, expected) else f"got {np.round(np.asarray(sprime, float), 6)}"):
        rng = np.random.default_rng(10)
        xr = np.cumsum(rng.uniform(0.2, 1.5, 9))
        yr = rng.normal(size=9)
        ok, got = _call(result, "random data", fn, xr, yr, 0.3, -0.7)
        if ok:
            want = splines.ccspline(xr, yr, 0.3, -0.7)
            if not result.step("random unequal data agree with labkit.ccspline", _close(got, want), _worst(got, want)):
                result.hint = "check the loop bounds: every interior row k uses h(k-1) and h(k)."
        return result
    if system is not None:
        ok, AD = _call(result, "the matrix A", system, np.array(x), np.array(y), y1p, ynp)
        if not ok:
            return result
        A = np.asarray(AD[0], dtype=float)
        if not result.step("A is symmetric", A.shape == (4, 4) and np.allclose(A, A.T)):
            result.hint = "A(k, k-1) and A(k-1, k) must both be h(k-1)/6."
            return result
        off = np.abs(A).sum(axis=1) - np.abs(np.diag(A))
        if not result.step("each diagonal entry exceeds the rest of its row (Gershgorin)", np.all(np.diag(A) > off)):
            result.hint = "the diagonal is (h(k-1) + h(k))/3 inside and h/3 in the first and last rows."
            return result
    name2, x2, y2, a2, b2 = SPLINE_CASES[1]
    ok, sprime2 = _call(result, name2, fn, np.array(x2), np.array(y2), a2, b2)
    if not ok:
        return result
    if result.step(name2, _close(sprime2, 3 * np.array(x2) ** 2), f"got {np.round(np.asarray(sprime2, float), 6)}"):
        result.hint = ("equal intervals work and unequal ones do not: a subscript of h is off "
                       "(h(k) = x(k+1) - x(k); row k uses h(k-1) and h(k)).")
        return result
    name3, x3, y3, a3, b3 = SPLINE_CASES[2]
    if system is not None:
        ok, AD = _call(result, "A and D for [0 1 3]", system, np.array(x3), np.array(y3), a3, b3)
        if not ok:
            return result
        A_ref, D_ref = _reference_complete_system(np.array(x3), np.array(y3), a3, b3)
        if not result.step("A for xdata = [0 1 3] matches equation (11)", _close(AD[0], A_ref), _worst(AD[0], A_ref)):
            result.hint = "compute the 3 x 3 matrix by hand from (11) and compare entry by entry."
            return result
        if not result.step("D for xdata = [0 1 3] matches equation (12)", _close(AD[1], D_ref), _worst(AD[1], D_ref)):
            result.hint = "compute D by hand from (12): first and last entries use y1p and ynp."
            return result
    result.hint = ("A and D are right, so the slopes are wrong: s'(x_k) = -M_k h_k/3 - M_{k+1} h_k/6 + "
                   "(y_{k+1} - y_k)/h_k (equation 8), with s'(x_1) = y1p and s'(x_n) = ynp.")
    return result


def _end_curvatures(x, y, slopes):
    """s'' at the two ends of the Hermite cubic with these knot slopes."""
    h = np.diff(x)
    d = np.diff(y) / h
    first = (6 * d[0] - 4 * slopes[0] - 2 * slopes[1]) / h[0]
    last = (-6 * d[-1] + 2 * slopes[-2] + 4 * slopes[-1]) / h[-1]
    return first, last


def ncspline(fn):
    """Check ``ncspline(xdata, ydata)``: the lab's linear case, zero end curvature, labkit's reference."""
    result = CheckResult("ncspline")
    ok, sprime = _call(result, "linear data [0 2 4 6]", fn, np.array([0.0, 1.0, 2.0, 3.0]), np.array([0.0, 2.0, 4.0, 6.0]))
    if not ok:
        return result
    linear_ok = result.step("linear data y = 2x give slopes 2", _close(sprime, [2.0] * 4),
                            "" if _close(sprime, [2.0] * 4) else f"got {np.round(np.asarray(sprime, float), 6)}")
    x = np.array([0.0, 0.7, 1.5, 2.0, 3.2, 4.0])
    y = np.exp(x / 2)
    ok, slopes = _call(result, "a nonlinear function", fn, x, y)
    if not ok:
        return result
    try:
        ends = _end_curvatures(x, y, np.asarray(slopes, dtype=float))
    except (ValueError, IndexError, TypeError):
        return result.fail("slopes for six knots", f"got {slopes!r}", "return one slope per knot.")
    if not result.step("second derivative zero at both ends (M1 = Mn = 0)", _close(ends, [0.0, 0.0]), f"s'' = {np.round(ends, 6)}"):
        result.hint = ("the first and last rows of A must say M1 = 0 and Mn = 0 (1 on the diagonal, 0 elsewhere, "
                       "0 in D): they are still the complete spline's rows.")
        return result
    want = splines.ncspline(x, y)
    if not result.step("slopes agree with labkit.ncspline", _close(slopes, want), _worst(slopes, want)) or not linear_ok:
        result.hint = "the ends are right, so check the interior rows and the slopes from (8) and, at the last knot, (9)."
    return result


# -- Exercise 16 --------------------------------------------------------------

def runge2d(fn):
    """Check ``runge2d(x, y)`` = 1/(1+(x+y)^2), on arrays."""
    result = CheckResult("runge2d")
    X, Y = np.meshgrid(np.linspace(-2, 2, 5), np.linspace(0, 3, 4), indexing="ij")
    ok, out = _call(result, "runge2d on a grid", fn, X, Y)
    if ok and not result.step("1/(1+(x+y)^2) on arrays", _close(out, functions.runge2d(X, Y)), _worst(out, functions.runge2d(X, Y))):
        result.hint = "use componentwise operations: 1 / (1 + (x + y)**2)."
    return result


def eval_pbilin(fn):
    """Check ``eval_pbilin(f, xdata, ydata, xval, yval)``: one cell, then 1, x, y, xy on a grid."""
    result = CheckResult("eval_pbilin")
    unit = np.array([0.0, 1.0])
    ok, z = _call(result, "corners of [0, 1]^2", fn, functions.runge2d, unit, unit, unit, unit)
    if not ok:
        return result
    X, Y = np.meshgrid(unit, unit, indexing="ij")
    if not result.step("returns runge2d at the four corners of [0, 1]^2", _close(z, functions.runge2d(X, Y)),
                       _worst(z, functions.runge2d(X, Y))):
        result.hint = "zval(k, l) is I(xval(k), yval(l)): check the order of the indices and the four basis functions."
        return result
    xdata, ydata = np.array([0.0, 0.5, 2.0, 3.0]), np.array([-1.0, 0.0, 2.5])
    xval, yval = np.linspace(0, 3, 7), np.linspace(-1, 2.5, 6)
    XV, YV = np.meshgrid(xval, yval, indexing="ij")
    for name, f in (("1", lambda x, y: np.ones_like(x * y)), ("x", lambda x, y: x + 0 * y),
                    ("y", lambda x, y: y + 0 * x), ("xy", lambda x, y: x * y)):
        ok, z = _call(result, f"f = {name}", fn, f, xdata, ydata, xval, yval)
        if not ok:
            return result
        if not result.step(f"reproduces f = {name} on an unequal grid", _close(z, f(XV, YV)), _worst(z, f(XV, YV))):
            result.hint = ("one cell works but a grid does not: use bracket on xval and on yval to find the cell "
                           "and that cell's corners in the basis functions.")
            return result
    return result


# -- grading -------------------------------------------------------------------

# exercise -> (names the student's notebook defines, checks to run on them)
EXERCISES = {
    2: lambda ns: [eval_pherm(ns["eval_pherm"])],
    3: lambda ns: [runge(ns["runge"]), test_pherm_interpolate(ns["test_pherm_interpolate"])],
    5: lambda ns: [coons(ns["coons"])],
    6: lambda ns: [graded_corners(ns["graded"])],
    7: lambda ns: [straight_corners(ns["straight"])],
    8: lambda ns: [circle_corners(ns["circle_sides"])],
    9: lambda ns: [two_patches(ns["two_patches"], [ns["A9"], ns["B9"], ns["C9"], ns["D9"]])],
    10: lambda ns: [ccspline(ns["ccspline"], ns.get("complete_system"))],
    12: lambda ns: [ncspline(ns["ncspline"])],
    16: lambda ns: [runge2d(ns["runge2d"]), eval_pbilin(ns["eval_pbilin"])],
}
POINTS = {number: 10 for number in EXERCISES}
NAMES = {2: ["eval_pherm"], 3: ["runge", "test_pherm_interpolate"], 5: ["coons"], 6: ["graded"],
         7: ["straight"], 8: ["circle_sides"], 9: ["two_patches", "mirror"], 10: ["ccspline", "complete_system"],
         12: ["ncspline"], 16: ["runge2d", "eval_pbilin"]}


def grade(number, namespace):
    """Run the checks of exercise `number` on a notebook's variables; a dict for the grader.

    ``defined`` says whether the notebook defines any of the exercise's names,
    so the grader can tell the exercise's own notebook from one that only
    mentions it.
    """
    defined = any(name in namespace for name in NAMES[number])
    try:
        results = EXERCISES[number](namespace)
    except KeyError as exc:
        name = str(exc).strip("'")
        missing = CheckResult(name)
        missing.fail(f"{name} is defined", "not defined when the notebook finished",
                     f"run the cell that defines {name} (and keep its name); a cell that raised stops it.")
        results = [missing]
    passed = all(r.passed for r in results)
    return {"exercise": number, "passed": passed, "points": POINTS[number] if passed else 0,
            "defined": defined, "checks": [r.as_dict() for r in results]}
