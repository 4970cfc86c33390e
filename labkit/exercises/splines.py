"""Checks for exercises 10 and 12: the complete and the natural cubic spline.

The maths is derived in ``notebooks/04_splines.ipynb``. References are
labkit's splines (:func:`labkit.ccspline`, :func:`labkit.ncspline`), the
lab's equations (11)-(12) for the matrix, and cubics the complete spline
must reproduce exactly.
"""

import numpy as np

from .. import piecewise, splines
from .experiments import RUNGE_A, Experiment
from .model import INTERPOLANTS, Exercise, Optional, Part
from .result import CheckResult, call, case_rng, close, floats, judged_by_the_lab, shown, worst

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


def _part(AD, index):
    """AD[index], or None if the student's value has no such part."""
    try:
        return AD[index]
    except (TypeError, IndexError, KeyError):
        return None


def _matrix(AD):
    """The float matrix A of a student's (A, D), or None if it is not one."""
    try:
        A = floats(_part(AD, 0))
    except (TypeError, ValueError):
        return None
    return A if A.ndim == 2 and np.all(np.isfinite(A)) else None


def check_ccspline(fn, system=None, seed=None):
    """Check ``ccspline(xdata, ydata, y1p, ynp)``; with ``system(xdata, ydata, y1p, ynp) -> (A, D)``
    also the matrix (symmetric, diagonally dominant, equal to equations 11-12)."""
    result = CheckResult("ccspline")
    name, x, y, y1p, ynp = SPLINE_CASES[0]
    ok, sprime = call(result, name, fn, np.array(x), np.array(y), y1p, ynp)
    if not ok:
        return result
    expected = 3 * np.array(x) ** 2
    if result.step(
        f"{name}: slopes [0 3 12 48]",
        close(sprime, expected),
        "" if close(sprime, expected) else f"got {shown(sprime)}",
    ):
        return _ccspline_random(result, fn, seed)
    if system is not None and not _complete_matrix_sound(result, system):
        return result
    name2, x2, y2, a2, b2 = SPLINE_CASES[1]
    ok, sprime2 = call(result, name2, fn, np.array(x2), np.array(y2), a2, b2)
    if not ok:
        return result
    if result.step(name2, close(sprime2, 3 * np.array(x2) ** 2), f"got {shown(sprime2)}"):
        result.hint = (
            "equal intervals work and unequal ones do not: a subscript of h is off "
            "(h(k) = x(k+1) - x(k); row k uses h(k-1) and h(k))."
        )
        return result
    if system is not None:
        return _complete_system_slip(result, system, _slopes_slip(sprime, expected, y1p, ynp))
    result.hint = (
        "the slopes are wrong for equal intervals too: check A and D against equations (11) and (12) "
        "(define complete_system so the grader can check them too), then the slopes against (8)."
    )
    return result


def _ccspline_random(result, fn, seed):
    """After the lab's case: random unequal data, against labkit's ccspline."""
    rng = case_rng(seed, "splines.ccspline")
    xr = np.cumsum(rng.uniform(0.2, 1.5, 9))
    yr = rng.normal(size=9)
    ok, got = call(result, "random data", fn, xr, yr, 0.3, -0.7)
    if ok:
        want = splines.ccspline(xr, yr, 0.3, -0.7)
        if not result.step("random unequal data agree with labkit.ccspline", close(got, want), worst(got, want)):
            result.hint = "check the loop bounds: every interior row k uses h(k-1) and h(k)."
    return result


def _complete_matrix_sound(result, system):
    """Whether the student's A for the lab's case is a symmetric, diagonally dominant matrix other than the
    natural spline's; when it is not, `result` says why."""
    name, x, y, y1p, ynp = SPLINE_CASES[0]
    ok, AD = call(result, "the matrix A", system, np.array(x), np.array(y), y1p, ynp)
    if not ok:
        return False
    A = _matrix(AD)
    if A is None:
        result.fail(
            "the matrix A",
            "complete_system must return (A, D) with A a matrix of numbers",
            "end the function with `return A, D`.",
        )
        return False
    natural_rows = A.shape == (4, 4) and np.allclose(A[0], [1, 0, 0, 0]) and np.allclose(A[-1], [0, 0, 0, 1])
    if natural_rows:
        result.fail(
            "the first and last rows of A",
            "they say M1 = 0 and Mn = 0",
            "the first and last rows of A are the natural spline's (M1 = 0, Mn = 0); the complete "
            "spline's first row is h1/3, h1/6 and its last h(n-1)/6, h(n-1)/3 (equation 11), with "
            "y1p and ynp in D.",
        )
        return False
    if not result.step("A is symmetric", A.shape == (4, 4) and np.allclose(A, A.T)):
        result.hint = _matrix_slip(A, _reference_complete_system(np.array(x), np.array(y), y1p, ynp)[0])
        return False
    off = np.abs(A).sum(axis=1) - np.abs(np.diag(A))
    if not result.step("each diagonal entry exceeds the rest of its row (Gershgorin)", np.all(np.diag(A) > off)):
        result.hint = "the diagonal is (h(k-1) + h(k))/3 inside and h/3 in the first and last rows."
        return False
    return True


def _complete_system_slip(result, system, slopes_slip):
    """Where ccspline goes wrong when both interval cases fail: the student's A and D for [0 1 3] against equations
    (11) and (12), or, when they are right, the solve (`slopes_slip` says how the slopes are wrong)."""
    name3, x3, y3, a3, b3 = SPLINE_CASES[2]
    ok, AD = call(result, "A and D for [0 1 3]", system, np.array(x3), np.array(y3), a3, b3)
    if not ok:
        return result
    A_ref, D_ref = _reference_complete_system(np.array(x3), np.array(y3), a3, b3)
    if _matrix(AD) is None:
        return result.fail(
            "A and D for [0 1 3]",
            "complete_system must return (A, D) with A a matrix of numbers",
            "end the function with `return A, D`.",
        )
    if not result.step("A for xdata = [0 1 3] matches equation (11)", close(AD[0], A_ref), worst(AD[0], A_ref)):
        result.hint = "compute the 3 x 3 matrix by hand from (11) and compare entry by entry."
        return result
    D = _part(AD, 1)
    if not result.step("D for xdata = [0 1 3] matches equation (12)", close(D, D_ref), worst(D, D_ref)):
        result.hint = _d_slip(D, D_ref)
        return result
    result.hint = (
        "your complete_system's A and D are right, so what ccspline does with them is wrong"
        + slopes_slip
        + ": it must solve A M = D with complete_system's A and D, then s'(x_k) = -M_k h_k/3 - M_{k+1} h_k/6 + "
        "(y_{k+1} - y_k)/h_k (equation 8), with s'(x_1) = y1p and s'(x_n) = ynp."
    )
    return result


def _d_slip(D, D_ref):
    """The hint for a student's D that differs from equation (12)."""
    flipped = _flipped_ends(D, D_ref)
    if flipped:
        which = flipped[0]
        formula = "(y2 - y1)/h1 - y1p" if which == "first" else "ynp - (yn - y(n-1))/h(n-1)"
        return f"D's {which} entry has the wrong sign: it is {formula} (equation 12)."
    if _flipped_inside(D, D_ref):
        return (
            "D's inside entries have the wrong sign (its first and last are right): each is the difference "
            "of two neighbouring secants, taken in the order equation (12) takes them."
        )
    return "compute D by hand from (12): first and last entries use y1p and ynp."


def _matrix_slip(A, reference):
    """Where a student's matrix A differs from equation (11) (the lab's case it was built for), in the
    student's words, 1-based as the lab counts: the first or last row, or the inside rows' off-diagonals."""
    with np.errstate(all="ignore"):  # a student's entries may be huge: no RuntimeWarning for them
        rows, cols = np.nonzero(~np.isclose(A, reference))
    named = [f"A({i + 1}, {j + 1})" for i, j in zip(rows, cols)]
    entries = ", ".join(named[:-1]) + (" and " if len(named) > 1 else "") + (named[-1] if named else "")
    ends = {0, len(A) - 1}
    if rows.size and set(rows) <= ends:
        which = " and ".join(name for row, name in ((0, "first"), (len(A) - 1, "last")) if row in set(rows))
        return (
            f"A's {which} row{'s are' if ' and ' in which else ' is'} not equation (11)'s: {entries} "
            f"{'differs' if rows.size == 1 else 'differ'} from it. The inside rows are right; compare the end "
            "rows entry by entry with (11)."
        )
    where = f"{entries} {'differs' if rows.size == 1 else 'differ'} from equation (11): " if rows.size else ""
    return f"{where}A(k, k-1) and A(k-1, k) must both be h(k-1)/6."


def _flipped_inside(D, D_ref):
    """True if D's inside entries are the reference's with the sign turned, and its ends are the reference's."""
    try:
        values = floats(D)
    except (TypeError, ValueError):
        return False
    inside = slice(1, -1)
    with np.errstate(all="ignore"):
        return bool(
            values.shape == D_ref.shape
            and np.any(np.abs(D_ref[inside]) > 1e-12)
            and np.allclose(values[inside], -D_ref[inside])
            and np.allclose(values[[0, -1]], D_ref[[0, -1]])
        )


def _slopes_slip(sprime, expected, y1p, ynp):
    """Which of ccspline's slopes are wrong when its A and D are right, as a clause (', ...'), or ''."""
    try:
        got = floats(sprime)
    except (TypeError, ValueError):
        return ""
    if got.shape != expected.shape:
        return ""
    with np.errstate(all="ignore"):
        inside = np.allclose(got[1:-1], expected[1:-1])
        ends_swapped = np.allclose(got[[0, -1]], [ynp, y1p])
        ends = np.allclose(got[[0, -1]], expected[[0, -1]])
    if inside and ends_swapped:
        return ", as the first and the last slope are swapped (the first is y1p, the last ynp)"
    if inside:
        return ", as its inside slopes are right and an end slope is not"
    if ends:
        return ", as the end slopes are right and the inside slopes s'(x_2), ..., s'(x_{n-1}) are not"
    return ""


def check_ncspline(fn, seed=None, system=None):
    """Check ``ncspline(xdata, ydata)``: the lab's linear case, zero end curvature, labkit's reference.

    `system` is the student's ``complete_system``, which the lab's ncspline
    builds on: when it is wrong (Exercise 10 marks that) but still a spline
    system (:func:`spline_system`) and ncspline gives exactly the natural
    spline of it, ncspline is right. A system that is no spline system is no
    reference: ncspline is judged against the lab's, and the feedback says why.
    """
    result = CheckResult("ncspline")
    own = _own_natural(fn, system, seed)
    if isinstance(own, str):  # ncspline follows a complete_system that is no spline system: not forgiven
        judged_by_the_lab(result, own, "the lab's natural spline")
        own = None
    if own is not None:
        result.step(
            "slopes are the natural spline of your own complete_system (its mistake is marked in "
            "Exercise 10, not again here)",
            True,
        )
        return result
    ok, sprime = call(
        result, "linear data [0 2 4 6]", fn, np.array([0.0, 1.0, 2.0, 3.0]), np.array([0.0, 2.0, 4.0, 6.0])
    )
    if not ok:
        return result
    linear_ok = result.step(
        "linear data y = 2x give slopes 2",
        close(sprime, [2.0] * 4),
        "" if close(sprime, [2.0] * 4) else f"got {shown(sprime)}",
    )
    x, y = _ncspline_data(seed)
    ok, slopes = call(result, "a nonlinear function", fn, x, y)
    if not ok:
        return result
    try:
        # s'' at the two ends of the piecewise cubic with these knot slopes
        ends = piecewise.eval_pherm(x, y, slopes, x[[0, -1]], der=2)
    except (ValueError, IndexError, TypeError):
        return result.fail("slopes for six knots", f"got {slopes!r}", "return one slope per knot.")
    want = splines.ncspline(x, y)
    try:
        got = floats(slopes)
    except (TypeError, ValueError):
        return result.fail("slopes for six knots", f"got {shown(slopes)}", "return one slope per knot.")
    if got.shape == want.shape and np.allclose(got[:-1], want[:-1]) and not np.allclose(got[-1], want[-1]):
        return result.fail(
            "every slope from the system",
            "all but the last agree with labkit.ncspline",
            "every slope but the last is right: equation (8) gives the slope at the left end of a "
            "piece, and the last knot is a right end, which needs (9).",
        )
    if not result.step(
        "second derivative zero at both ends (M1 = Mn = 0)", close(ends, [0.0, 0.0]), f"s'' = {np.round(ends, 6)}"
    ):
        result.hint = _natural_ends_slip(x, y, slopes, got, want)
        return result
    if not result.step("slopes agree with labkit.ncspline", close(slopes, want), worst(slopes, want)) or not linear_ok:
        result.hint = _natural_rows_slip(x, y, got) or (
            "the ends are right, so check the interior rows and the slopes from (8) and, at the last knot, (9)."
        )
    return result


def _natural_ends_slip(x, y, slopes, got, want):
    """The hint for natural spline slopes whose ends have a second derivative other than 0."""
    if close(slopes, _natural_slopes(x, y, rows_in_d=False)):
        return (
            "A's first and last rows say M1 = 0 and Mn = 0, but D's first and last entries are still "
            "the complete spline's: set them to 0 too."
        )
    if close(slopes, _natural_slopes(x, y, rows_in_a=False, rows_in_d=False)):
        return (
            "the first and last rows of A, and the first and last entries of D, are still the complete "
            "spline's rows: change them so that those two equations say M1 = 0 and Mn = 0."
        )
    if got.shape == want.shape and np.allclose(got[[0, -1]], 0.0) and not np.allclose(want[[0, -1]], 0.0):
        return (
            "your end slopes are 0: the natural spline's ends have zero second derivative (M1 = Mn = 0), "
            "not zero slope; its end slopes come from the solved M by (8) and (9), as the others do."
        )
    return _natural_rows_slip(x, y, got) or (
        "the second derivative is not 0 at the ends: the first and last equations of the system "
        "must say M1 = 0 and Mn = 0."
    )


def _curvatures(x, y, slopes, first_left=True):
    """The M (second derivatives at the knots) a student's slopes were computed from, read back through the
    lab's slope equations: (8) at every knot but the last and (9) there (`first_left`), or (8) at the first
    and (9) at every other; None where they give none."""
    n, h = len(x), np.diff(x)
    secant = np.diff(y) / h
    B, c = np.zeros((n, n)), np.zeros(n)
    for k in range(n):
        if k == 0 or (first_left and k < n - 1):  # (8): s'(x_k) = -M_k h_k/3 - M_{k+1} h_k/6 + secant_k
            B[k, k], B[k, k + 1], c[k] = -h[k] / 3, -h[k] / 6, secant[k]
        else:  # (9): s'(x_k) = M_k h_{k-1}/3 + M_{k-1} h_{k-1}/6 + secant_{k-1}
            B[k, k], B[k, k - 1], c[k] = h[k - 1] / 3, h[k - 1] / 6, secant[k - 1]
    try:
        with np.errstate(all="ignore"):
            M = np.linalg.solve(B, slopes - c)
    except np.linalg.LinAlgError:
        return None
    return M if np.all(np.isfinite(M)) else None


def _natural_rows_slip(x, y, slopes):
    """What the system a student's natural-spline slopes come from gets wrong, in the student's words ('' when
    nothing can be named): its M read back through the slope equations (:func:`_curvatures`), then the lab's
    end equations M1 = Mn = 0 and the inside rows of equations (11)-(12) checked on it."""
    A, D = _reference_complete_system(x, y, 0.0, 0.0)
    for first_left in (True, False):
        M = _curvatures(x, y, slopes, first_left)
        if M is None or np.max(np.abs(M)) > 1e100:  # no spline's second derivatives
            continue
        if not np.allclose(M[[0, -1]], 0.0, atol=1e-9 * max(1.0, np.max(np.abs(M)))):
            continue
        inside = A[1:-1] @ M
        if np.allclose(inside, D[1:-1]):
            return ""
        if np.allclose(inside, -D[1:-1]):
            return (
                "your first and last rows are right (M1 = Mn = 0 in what your slopes come from), but D's inside "
                "entries have the wrong sign: each is the difference of two neighbouring secants, taken in the "
                "order equation (12) takes them."
            )
        rows = [str(k + 2) for k in np.flatnonzero(~np.isclose(inside, D[1:-1]))]
        return (
            f"your first and last rows are right (M1 = Mn = 0 in what your slopes come from), but row"
            f"{'s' if len(rows) > 1 else ''} {', '.join(rows)} of your system {'are' if len(rows) > 1 else 'is'} "
            "not equations (11)-(12): compare them entry by entry, in A and in D."
        )
    return ""


def _ncspline_data(seed):
    x = (
        np.array([0.0, 0.7, 1.5, 2.0, 3.2, 4.0])
        if seed is None
        else np.cumsum(case_rng(seed, "splines.ncspline").uniform(0.2, 1.5, 6))
    )
    return x, np.exp(x / 2)


def spline_system(given, xdata, ydata):
    """Why `given`, a student's ``complete_system(xdata, ydata, ...)``, is no spline system ('' when it is one).

    A spline system is an n x n tridiagonal matrix A and n entries D, whose inside rows are equations
    (11)-(12): (h(k-1) + h(k))/3 on the diagonal, D(k) = the difference of the two secants, and h/6 beside the
    diagonal, where the h of either neighbouring interval counts (the subscript slip Exercise 10 names). The
    first and last rows are free: the natural spline replaces them, and Exercise 10 judges them.
    """
    n, h = len(xdata), np.diff(xdata)
    try:
        A, D = floats(_part(given, 0)), floats(_part(given, 1))
    except (TypeError, ValueError):
        return "your complete_system does not return a matrix A and a right side D of numbers"
    if A.shape != (n, n) or D.shape != (n,) or not (np.all(np.isfinite(A)) and np.all(np.isfinite(D))):
        return f"your complete_system does not return an {n} x {n} matrix A and {n} entries D for {n} knots"
    rows, cols = np.indices(A.shape)
    if not np.allclose(A[np.abs(rows - cols) > 1], 0.0):
        return "your complete_system's A is not tridiagonal"
    secant = np.diff(ydata) / h
    beside = lambda got, k: np.isclose(got, h[k - 1] / 6) or np.isclose(got, h[k] / 6)
    for k in range(1, n - 1):
        if not (
            np.isclose(A[k, k], (h[k - 1] + h[k]) / 3)
            and beside(A[k, k - 1], k)
            and beside(A[k, k + 1], k)
            and np.isclose(D[k], secant[k] - secant[k - 1])
        ):
            return f"row {k + 1} of your complete_system's A and D is not the spline's equation at an inside knot"
    return ""


def _own_natural(fn, system, seed):
    """True when the student's complete_system is wrong and `fn` gives exactly the natural spline of it
    (the lab's cases: linear data and a nonlinear function); None otherwise (the usual check decides).

    A system that is no spline system (:func:`spline_system`) is no reference: when `fn` follows it, the
    reason (in the student's words), so the usual check decides and the feedback says why."""
    if system is None:
        return None
    scratch, differs, why = CheckResult("ncspline"), False, ""
    sides = [True, False]  # the slopes from (8) at every knot but the last, or from (9) at every knot but the first
    for x, y in ((np.array([0.0, 1.0, 2.0, 3.0]), np.array([0.0, 2.0, 4.0, 6.0])), _ncspline_data(seed)):
        ok, given = call(scratch, "complete_system", system, x, y, 0.0, 0.0)
        if not ok:
            return None
        why = why or spline_system(given, x, y)
        ok, slopes = call(scratch, "ncspline", fn, x, y)
        if not ok:
            return None
        followed = []
        for first_left in sides:
            try:
                with np.errstate(all="ignore"):
                    own = _natural_slopes(x, y, system=given, first_left=first_left)
            except (TypeError, ValueError, IndexError, np.linalg.LinAlgError):
                return None
            if not np.all(np.isfinite(own)):
                return None  # the student's system gives no spline: the usual check decides
            if close(slopes, own):
                followed.append(first_left)
                differs = differs or not close(own, splines.ncspline(x, y))
        sides = followed  # the same side in every case
        if not sides:
            return None
    if why and differs:
        return why
    return True if differs else None  # with a right system, the usual check decides


def _flipped_ends(D, D_ref):
    """Which end entries of D ('first', 'last') are the reference's with the sign turned."""
    try:
        values = floats(D)
    except (TypeError, ValueError):
        return []
    if values.shape != D_ref.shape:
        return []
    return [
        which
        for i, which in ((0, "first"), (-1, "last"))
        if abs(D_ref[i]) > 1e-12 and np.isclose(values[i], -D_ref[i]) and np.allclose(values[1:-1], D_ref[1:-1])
    ]


def _natural_slopes(x, y, rows_in_a=True, rows_in_d=True, system=None, first_left=True):
    """The slopes a natural spline comes out with when its end rows are set in A and/or in D (the usual slips),
    from the complete spline's system: labkit's, or `system` (A, D) as the student's complete_system gave it.

    The slopes are read from the second derivatives M by equation (8) at every knot but the last and (9) there
    (`first_left`), or by (8) at the first knot and (9) at every other: the lab allows both, and they agree
    only when M is a spline's."""
    A, D = _reference_complete_system(x, y, 0.0, 0.0) if system is None else (floats(a).copy() for a in system)
    if rows_in_a:
        A[0, :], A[-1, :] = 0.0, 0.0
        A[0, 0], A[-1, -1] = 1.0, 1.0
    if rows_in_d:
        D[0], D[-1] = 0.0, 0.0
    M = np.linalg.solve(A, D)
    h, secant = np.diff(x), np.diff(y) / np.diff(x)
    slopes = np.empty_like(x)
    if first_left:
        slopes[:-1] = -M[:-1] * h / 3 - M[1:] * h / 6 + secant
        slopes[-1] = M[-1] * h[-1] / 3 + M[-2] * h[-1] / 6 + secant[-1]
    else:
        slopes[1:] = M[1:] * h / 3 + M[:-1] * h / 6 + secant
        slopes[0] = -M[0] * h[0] / 3 - M[1] * h[0] / 6 + secant[0]
    return slopes


COMPLETE = Experiment(
    "complete",
    4,
    "test_ccspline_interpolate",
    "errors_complete",
    "rate_complete",
    weights=(5, 2, 2),
    pieces=(splines.ccspline,),
    uses=("ccspline", "complete_system"),
)
NATURAL = Experiment(
    "natural",
    2,
    "test_ncspline_interpolate",
    "errors_natural",
    "rate_natural",
    weights=(2, 2, 2),
    pieces=(splines.ncspline,),
    uses=("ncspline", "complete_system"),
)
# Exercise 12(b): the natural spline's end rows of A and D, as a text or code would write them
NATURAL_ROWS = (
    "1 on the diagonal, 0 elsewhere",
    "A[0, 0] = 1",
    "A[0] = [1, 0",
    "A[-1, -1] = 1",
    "D[0] = 0",
    "D[-1] = 0",
    "rows 1, 0, ..., 0",
    "[1, 0, 0, 0]",
    "[0, 0, 0, 1]",
)
# the remark after Exercise 12: why the natural spline converges more slowly
NATURAL_WHY = (
    "f''(0) = -2",
    "f''(0) is not 0",
    "f''(0) is not zero",
    "f'' is not zero at",
    "where the Runge function itself bends",
    "errs at the left end",
    "s'' = 0 at both ends, but",
    "order lower",
    "lower order",
    "order is lower",
)
NOTAKNOT = Experiment("notaknot", 4, "test_spline_interpolate", "errors_notaknot", "rate_notaknot", weights=(3, 2, 2))

EXERCISES = (
    Exercise(
        10,
        ("ccspline", "complete_system"),
        (
            Part(
                "ccspline",
                15,
                check_ccspline,
                ("ccspline", Optional("complete_system")),
                seeded=True,
                refused=INTERPOLANTS,
                functions=("ccspline", "complete_system"),
            ),
        ),
        notebook="04_splines.ipynb",
    ),
    Exercise(
        11,
        COMPLETE.names(),
        COMPLETE.parts(),
        notebook="04_splines.ipynb",
        answers=("the order, with f' used only at the ends",),
        withheld=COMPLETE.withheld,
        params=(RUNGE_A,),  # the scale of the Runge function, drawn with Exercise 3
        sound=COMPLETE.sound,
    ),
    Exercise(
        12,
        ("ncspline",) + NATURAL.names(),
        (
            Part(
                "ncspline",
                9,
                check_ncspline,
                ("ncspline",),
                keywords=(("system", Optional("complete_system")),),
                seeded=True,
                refused=INTERPOLANTS,
                uses=("complete_system",),
            ),
        )
        + NATURAL.parts(),
        notebook="04_splines.ipynb",
        answers=("why the natural spline's order is lower",),
        withheld=NATURAL_ROWS + NATURAL_WHY + NATURAL.withheld,
        params=(RUNGE_A,),  # the scale of the Runge function, drawn with Exercise 3
        sound=NATURAL.sound,
    ),
    Exercise(
        13,
        NOTAKNOT.names(),
        NOTAKNOT.parts(),
        notebook="04_splines.ipynb",
        answers=("the three splines compared",),
        withheld=NOTAKNOT.withheld,
        params=(RUNGE_A,),  # the scale of the Runge function, drawn with Exercise 3
        sound=NOTAKNOT.sound,
    ),
)
