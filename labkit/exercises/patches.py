"""Checks for exercises 5 to 9: the Coons patch and the corner data of the meshes.

The maths is derived in ``notebooks/03_meshes.ipynb``. References are
:func:`labkit.patch` and the geometry each exercise asks for (the bilinear
map of a straight quadrilateral, quarter circles, a conforming join).
"""

import numpy as np

from .. import patches
from ..mesh import QuadMesh, quad_mesh
from .model import OWN_PATCH, Exercise, Optional, Part, Together
from .result import CheckResult, call, case_rng, close, floats, judged_by_the_lab, worst
from .variants import Param

# the grader's work on a student's meshes is bounded by the lab's sizes (600 and 1170 nodes): far larger is refused
MAX_NODES = 20_000
SIZES9 = (20, 30)  # each patch of Exercise 9 is meshed with 20 x 30 points
ON_CORNER = 1e-6  # a mesh node this close to a corner point is on it


def _identity_corners():
    e1, e2 = [1.0, 0.0], [0.0, 1.0]
    return [patches.Corner(p, e1, e2) for p in ([0, 0], [1, 0], [1, 1], [0, 1])]


def check_coons(fn, seed=None):
    """Check a student's ``coons(A, B, C, D, s, t) -> (x, y)`` (the script of exercise 5)."""
    result = CheckResult("coons")
    s, t = np.linspace(0, 1, 4), np.linspace(0, 1, 5)
    ok, out = call(result, "identity patch", fn, *_identity_corners(), s, t)
    if not ok:
        return result
    S, T = np.meshgrid(s, t, indexing="ij")
    if not result.step(
        "the unit square with the identity data gives the 4 x 5 grid",
        close(out, [S, T]),
        "" if close(out, [S, T]) else worst(out, [S, T]),
    ):
        if close(out, [S.T, T.T]):
            result.hint = (
                "x and y are transposed: x[i, j] belongs to s[i] and t[j], so they have one row per "
                "value of s (shape (len(s), len(t)))."
            )
        elif _coons_slip(out, _identity_corners(), s, t):
            result.hint = _coons_slip(out, _identity_corners(), s, t)
        else:
            result.hint = (
                "start with the outline: x along AB is eval_pherm([0, 1], [xA, xB], [dxdsA, dxdsB], s); "
                "DC uses D and C; then join them in t for every s."
            )
        return result
    rng = case_rng(seed, "patches.coons")
    corners = [patches.Corner(*rng.normal(size=(4, 2))) for _ in range(4)]
    expected = patches.patch(*corners, s, t)
    ok, out = call(result, "random corner data with twists", fn, *corners, s, t)
    if not ok or result.step(
        "random corner data with twists agree with labkit.patch",
        close(out, expected),
        "" if close(out, expected) else worst(out, expected),
    ):
        return result
    for edge, untwist in (("AB and DC", "ABCD"), ("AB", "AB"), ("DC", "DC")):
        candidate = [
            patches.Corner(c.point, c.ds, c.dt) if label in untwist else c for label, c in zip("ABCD", corners)
        ]
        if close(out, patches.patch(*candidate, s, t)):
            result.hint = (
                f"your patch ignores the twists along {edge}: the t-derivative along an edge "
                "(dxdtAB, dxdtDC) is a Hermite cubic in s with values dx/dt and slopes d2x/dsdt "
                "at its corners (likewise for y)."
            )
            break
    else:
        result.hint = _coons_slip(out, corners, s, t) or (
            "compare the four edge curves one at a time with labkit.patch: values along AB and DC, "
            "then the t-derivatives along them, then the join in t."
        )
    return result


COONS_SLIPS = {
    "dc_reversed": "your top edge DC runs from C to D: along DC, s = 0 is at D and s = 1 at C, as along AB s = 0 "
    "is at A, so D's data come first when you interpolate along DC.",
    "no_join_slopes": "your patch ignores the t-derivatives along AB and DC when it joins them: each line of "
    "constant s is a Hermite cubic in t whose values are xAB(k), xDC(k) and whose slopes are dxdtAB(k), dxdtDC(k) "
    "(likewise for y).",
}


def _coons_with(corners, s, t, dc_reversed=False, no_join_slopes=False):
    """The lab's Coons patch with one of the slips of :data:`COONS_SLIPS`: x and y as one (2, len(s), len(t))."""
    from ..piecewise import eval_pherm

    A, B, C, D = corners
    first, last = (C, D) if dc_reversed else (D, C)
    out = np.empty((2, len(s), len(t)))
    for c in range(2):
        along_ab = eval_pherm([0, 1], [A.point[c], B.point[c]], [A.ds[c], B.ds[c]], s)
        dt_ab = eval_pherm([0, 1], [A.dt[c], B.dt[c]], [A.dsdt[c], B.dsdt[c]], s)
        along_dc = eval_pherm([0, 1], [first.point[c], last.point[c]], [first.ds[c], last.ds[c]], s)
        dt_dc = eval_pherm([0, 1], [D.dt[c], C.dt[c]], [D.dsdt[c], C.dsdt[c]], s)
        for k in range(len(s)):
            slopes = [0.0, 0.0] if no_join_slopes else [dt_ab[k], dt_dc[k]]
            out[c, k] = eval_pherm([0, 1], [along_ab[k], along_dc[k]], slopes, t)
    return out


def _coons_slip(out, corners, s, t):
    """The hint of the slip of :data:`COONS_SLIPS` that gives the student's patch `out`, or ''."""
    for slip, hint in COONS_SLIPS.items():
        if close(out, _coons_with(corners, s, t, **{slip: True})):
            return hint
    return ""


def _corner_list(corners, result, label):
    if not (
        isinstance(corners, (list, tuple)) and len(corners) == 4 and all(isinstance(c, patches.Corner) for c in corners)
    ):
        result.fail(
            label,
            "expected a list of four labkit.Corner objects A, B, C, D",
            "build them with Corner(point, ds, dt, dsdt).",
        )
        return False
    return True


def check_graded_corners(corners):
    """Exercise 6: the unit square with dx/ds 3 at A, D and 0.1 at B, C."""
    result = CheckResult("exercise 6 corners")
    if not _corner_list(corners, result, "four corners"):
        return result
    x, y = patches.patch(*corners, np.linspace(0, 1, 11), np.linspace(0, 1, 16))
    outline = close([x[0], x[-1]], [np.zeros(16), np.ones(16)]) and close(
        [y[:, 0], y[:, -1]], [np.zeros(11), np.ones(11)]
    )
    if not result.step("outline is still the unit square", outline):
        moved_dt = [label for label, c in zip("ABCD", corners) if not close(c.dt, [0.0, 1.0])]
        moved_dyds = [label for label, c in zip("ABCD", corners) if not close(c.ds[1], 0.0)]
        result.hint = (
            f"you changed dt at {_and(moved_dt)}: the exercise changes dx/ds, the first entry of ds, and every "
            "other value stays as in exercise 5."
            if moved_dt
            else f"you changed dy/ds (the second entry of ds) at {_and(moved_dyds)}: only dx/ds, the first, "
            "changes; every other value stays as in exercise 5."
            if moved_dyds
            else "only dx/ds changes; every other value stays as in exercise 5."
        )
        return result
    dxds = [c.ds[0] for c in corners]
    if not result.step("dx/ds is 3 at A and D and 0.1 at B and C", close(dxds, [3.0, 0.1, 0.1, 3.0]), f"got {dxds}"):
        result.hint = "A and D are on the left (s = 0), B and C on the right (s = 1)."
        return result
    widths = np.diff(x, axis=0)
    result.step("elements get thinner towards the right", np.all(np.diff(widths, axis=0) < 0))
    return result


LAB_QUAD = {"xC": 1.0, "yC": 0.5, "xD": 0.0, "yD": 1.0}  # Exercise 7's C = (1, 0.5) and D = (0, 1)
QUAD_A, QUAD_B = (-1.0, 0.0), (1.0, 0.0)  # A and B, the same in every variant


def quad_twist(values):
    """Exercise 7's twist d2/dsdt at every corner, A - B + C - D, for C = (xC, yC) and D = (xD, yD)."""
    return (
        QUAD_A[0] - QUAD_B[0] + values["xC"] - values["xD"],
        QUAD_A[1] - QUAD_B[1] + values["yC"] - values["yD"],
    )


def quad_shown(values):
    """What Exercise 7's data cell shows besides C and D: the twist the lab gives, as numbers."""
    tx, ty = quad_twist(values)
    return {"twist7": f"({tx:.2f}, {ty:.2f})"}


def quad_sound(values):
    """Why a draw of Exercise 7's corners would not do ('' when it does): ABCD must be a convex quadrilateral,
    counter-clockwise, whose bilinear map folds nowhere (its Jacobian well away from zero)."""
    P = np.array([QUAD_A, QUAD_B, (values["xC"], values["yC"]), (values["xD"], values["yD"])])
    edges = np.roll(P, -1, axis=0) - P
    turns = edges[:, 0] * np.roll(edges, -1, axis=0)[:, 1] - edges[:, 1] * np.roll(edges, -1, axis=0)[:, 0]
    if turns.min() <= 0.05:
        return "ABCD is not a convex quadrilateral, counter-clockwise, with no corner nearly straight"
    return ""


def _point(P):
    return f"({P[0]:g}, {P[1]:g})"


def check_straight_corners(corners, xC=1.0, yC=0.5, xD=0.0, yD=1.0):
    """Exercise 7: A(-1,0), B(1,0), C(xC,yC), D(xD,yD) (the lab's C(1,0.5), D(0,1)); the patch must be the
    bilinear map."""
    result = CheckResult("exercise 7 corners")
    if not _corner_list(corners, result, "four corners"):
        return result
    A, B, C, D = (np.array(p, dtype=float) for p in (QUAD_A, QUAD_B, (xC, yC), (xD, yD)))
    where = f"A = {_point(A)}, B = {_point(B)}, C = {_point(C)}, D = {_point(D)}."
    if not result.step("corner points A, B, C, D", close([c.point for c in corners], [A, B, C, D])):
        swapped = [label for label, c, P in zip("ABCD", corners, (A, B, C, D)) if close(c.point, P[::-1])]
        result.hint = (
            f"{_and(swapped)} {'has its' if len(swapped) == 1 else 'have their'} x and y swapped: a point is "
            f"(x, y). {where}"
            if swapped
            else where
        )
        return result
    tx, ty = A - B + C - D
    if not result.step(
        f"twists d2x/dsdt = {tx:g}, d2y/dsdt = {ty:g}", close([c.dsdt for c in corners], [A - B + C - D] * 4)
    ):
        turned = close([c.dsdt for c in corners], [-(A - B + C - D)] * 4)
        result.hint = (
            f"the twists have the wrong sign: set d2xdsdt = {tx:g} and d2ydsdt = {ty:g} at all four corners."
            if turned
            else f"set d2xdsdt = {tx:g} and d2ydsdt = {ty:g} at all four corners."
        )
        return result
    s, t = np.linspace(0, 1, 20), np.linspace(0, 1, 15)
    S, T = np.meshgrid(s, t, indexing="ij")
    bilinear_map = [(1 - S) * (1 - T) * A[i] + S * (1 - T) * B[i] + S * T * C[i] + (1 - S) * T * D[i] for i in (0, 1)]
    got = patches.patch(*corners, s, t)
    if not result.step("mesh lines straight and evenly spaced", close(got, bilinear_map), worst(got, bilinear_map)):
        sides = {"ds": ("AB", "AB", "DC", "DC"), "dt": ("AD", "BC", "BC", "AD")}
        along = {"AB": B - A, "DC": C - D, "AD": D - A, "BC": C - B}
        off = [
            f"{label}'s {d} (along {side})"
            for d in ("ds", "dt")
            for label, corner, side in zip("ABCD", corners, sides[d])
            if not close(getattr(corner, d), along[side])
        ]
        result.hint = (
            f"{_and(off)} {'bends its side or spaces' if len(off) == 1 else 'bend their sides or space'} the mesh "
            "points unevenly: each side is a Hermite cubic between its two corners, so ask which end derivatives "
            "make that cubic a straight line traced at an even pace."
            if off
            else "each side is a Hermite cubic between its two corners: ask which end derivatives make it a straight "
            "line traced at an even pace."
        )
    return result


def _and(labels):
    """'A', 'A and D', 'A, B and D'."""
    labels = list(labels)
    return ", ".join(labels[:-1]) + (" and " if len(labels) > 1 else "") + (labels[-1] if labels else "")


def check_circle_corners(corners):
    """Exercise 8: quarter-circle sides through the unit square's corners, two-fold symmetric."""
    result = CheckResult("exercise 8 corners")
    if not _corner_list(corners, result, "four corners"):
        return result
    u = np.linspace(0, 1, 25)
    x, y = patches.patch(*corners, u, u)
    if not result.step(
        "corners at the unit square's corners", close([c.point for c in corners], [[0, 0], [1, 0], [1, 1], [0, 1]])
    ):
        result.hint = "A = (0, 0), B = (1, 0), C = (1, 1), D = (0, 1) as in exercise 5."
        return result
    radius = np.sqrt(2) / 2
    bound = np.sqrt(2) * radius * (np.pi / 2) ** 4 / 384
    sides = {
        "AB": (x[:, 0], y[:, 0], [(0.5, 0.5), (0.5, -0.5)]),
        "DC": (x[:, -1], y[:, -1], [(0.5, 0.5), (0.5, 1.5)]),
        "AD": (x[0], y[0], [(0.5, 0.5), (-0.5, 0.5)]),
        "BC": (x[-1], y[-1], [(0.5, 0.5), (1.5, 0.5)]),
    }
    for name, (xs, ys, centres) in sides.items():
        near = min(np.max(np.abs(np.hypot(xs - cx, ys - cy) - radius)) for cx, cy in centres)
        if not result.step(
            f"side {name} close to a quarter circle of radius sqrt(2)/2", near < bound, f"off by {near:.3f}"
        ):
            found = _arc_slips(name, corners, centres, radius)
            advice = (
                "write the side as an arc with its angle growing by pi/2 as s goes from 0 to 1, "
                "differentiate it, and give each corner that derivative at s = 0 or s = 1: both its "
                "direction and its length matter."
            )
            result.hint = f"{found}. {advice[:1].upper()}{advice[1:]}" if found else advice
            return result
    symmetric = close(x + x[::-1], np.ones_like(x)) and close(y + y[:, ::-1], np.ones_like(y))
    if not result.step("left-right and top-bottom symmetric", symmetric):
        result.hint = "mirror the bottom side's data to get the top, and the left side's to get the right."
    return result


ARC_ENDS = {"AB": ("A", "B", "ds"), "DC": ("D", "C", "ds"), "AD": ("A", "D", "dt"), "BC": ("B", "C", "dt")}


def _arc_slips(side, corners, centres, radius):
    """What is wrong with the derivatives at the two ends of a side of Exercise 8 that is no quarter circle,
    in the student's words ('at A and B, the derivative along AB points along the chord AB, not along the
    circle'); '' if its end derivatives are those of a quarter circle through them (the slip is elsewhere).

    The arc's derivative at an end is tangent to the circle (perpendicular to the radius there, heading round
    the arc) and as long as the arc's speed, radius * pi/2; of the two circles the check allows (the side
    bowing either way), the one whose tangents are nearer the student's counts.
    """
    first, last, which = ARC_ENDS[side]
    by_label = dict(zip("ABCD", corners))
    P, Q = (np.asarray(by_label[label].point, dtype=float)[:2] for label in (first, last))
    chord = Q - P
    found = {}
    best = None
    for centre in centres:
        problems = {}
        score = 0.0
        for label, point in ((first, P), (last, Q)):
            v = np.asarray(getattr(by_label[label], which), dtype=float)[:2]
            radial = point - np.asarray(centre, dtype=float)
            tangent = np.array([-radial[1], radial[0]])
            tangent *= np.sign(tangent @ chord) * radius * np.pi / 2 / np.hypot(*tangent)
            size = np.hypot(*v)
            cosine = (v @ tangent) / (size * np.hypot(*tangent)) if size > 0 else -1.0
            score += cosine
            if (
                size > 0
                and abs(v @ np.array([-chord[1], chord[0]])) <= 1e-9 * size * np.hypot(*chord)
                and v @ chord > 0
            ):
                problems[label] = f"points along the chord {side}, not along the circle"
            elif cosine < 1 - 1e-9:
                problems[label] = "does not point along the circle"
            elif not np.isclose(size, np.hypot(*tangent), rtol=1e-6):
                problems[label] = (
                    f"points along the circle but is too {'long' if size > np.hypot(*tangent) else 'short'}"
                )
        if best is None or score > best:
            best, found = score, problems
    if not found:
        return ""
    said = {}
    for label, problem in found.items():
        said.setdefault(problem, []).append(label)
    return "; ".join(
        f"at {_and(labels)}, the derivative along {side} ({which}) {problem}" for problem, labels in said.items()
    )


def check_two_patches(fn, corners, coons=None):
    """Exercise 9: ``two_patches(A, B, C, D) -> (mesh1, mesh2)`` joins along BC / dc.

    `coons` is the student's own (Exercise 5), which the student's two_patches
    may mesh its patches with: when the meshes are exactly what that coons
    gives for ABCD and for the lab's mirror image abcd (:func:`_own_coons_meshes`),
    two_patches is right, and a slip in coons is marked in Exercise 5 only.
    """
    result = CheckResult("exercise 9 patches")
    if not _corner_list(corners, result, "corners of ABCD"):
        return result
    for label, ABCD in (
        ("sharp corner", corners),
        ("rounded corner", [*corners[:2], patches.Corner([1.8, 1.8], [0.5, -0.5], corners[2].dt), corners[3]]),
    ):
        trial = _two_patches_once(CheckResult(result.name), label, fn, ABCD)
        if not trial.passed:
            if _own_coons_meshes(fn, coons, ABCD):
                result.step(
                    f"{label}: the meshes are your coons's patches of ABCD and of its mirror image abcd (your "
                    "coons is checked in Exercise 5, and its mistake is marked there, not again here)",
                    True,
                )
                continue
            result.add_steps(trial)
            result.hint = trial.hint
            return result
        result.add_steps(trial)
    return result


def _own_coons_meshes(two_patches, coons, ABCD):
    """True when the student's `two_patches` meshes ABCD and its mirror image abcd (the lab's mirror rule) with
    the student's own `coons`, 20 x 30 and 30 x 20 points, and both meshes pass through their patch's corner
    points: a wrong coons changes the inside and the edges of a patch, not where its corners are."""
    if coons is None or not callable(coons):
        return False
    scratch = CheckResult("exercise 9 patches")
    ok, out = call(scratch, "two_patches", two_patches, *ABCD)
    own = _own_meshes(lambda *corners: out, ABCD) if ok else None
    if own is None or _corners_missed(own, ABCD):
        return False
    A, B, C, D = ABCD
    mirrored = [patches.Corner(c.point[::-1], c.dt[::-1], c.ds[::-1], c.dsdt[::-1]) for c in (A, D, C, B)]
    for mesh, data, (m, n) in zip(own, ((A, B, C, D), mirrored), (SIZES9, SIZES9[::-1])):
        ok, xy = call(scratch, "coons", coons, *data, np.linspace(0, 1, m), np.linspace(0, 1, n))
        try:
            x, y = (floats(v) for v in xy) if ok else (None, None)
            nodes = floats(mesh.points)[:, :2]
        except (TypeError, ValueError, IndexError):
            return False
        if x is None or x.size != m * n or y.size != m * n or nodes.shape != (m * n, 2):
            return False
        theirs = np.stack((x.ravel(), y.ravel()), axis=1)
        if not np.all(np.isfinite(theirs)) or not close(
            nodes[np.lexsort(np.round(nodes, 9).T[::-1])], theirs[np.lexsort(np.round(theirs, 9).T[::-1])], 1e-7
        ):
            return False
    return True


def _two_patches_once(result, label, fn, ABCD):
    """The steps of :func:`check_two_patches` for one set of corners, recorded in `result` (its hint set when one
    fails)."""
    ok, out = call(result, label, fn, *ABCD)
    if not ok:
        return result
    try:
        first, second = out
        sizes = [len(first.points), len(second.points), len(first.quads), len(second.quads)]
    except Exception:  # noqa: BLE001
        return result.fail(
            label,
            f"got {getattr(out, 'description', type(out).__name__)}",
            "return the two QuadMesh objects: `return first, second`.",
        )
    if max(sizes) > MAX_NODES:
        return result.fail(
            label,
            f"meshes of {sizes[0]:,} and {sizes[1]:,} nodes",
            "each patch is meshed with 20 x 30 points (600 nodes); keep to the lab's sizes.",
        )
    missed = _corners_missed((first, second), ABCD)
    if not result.step(
        f"{label}: the meshes pass through the corners two_patches is given",
        not missed,
        f"no node at {', '.join(missed)}",
    ):
        result.hint = (
            "mesh the patches of the corners two_patches is given: the first mesh has A, B, C, D at its "
            "corners, the second a, b, c, d at theirs."
        )
        return result
    try:
        merged = first + second
    except Exception as exc:  # noqa: BLE001
        return result.fail(
            label,
            f"could not join the two meshes ({exc})",
            "return the two QuadMesh objects: `return first, second`.",
        )
    expected_nodes = len(first.points) + len(second.points) - 30
    if not result.step(
        f"{label}: the 30 nodes of the shared edge merge",
        len(merged.points) == expected_nodes,
        f"{len(first.points)} + {len(second.points)} nodes gave {len(merged.points)}",
    ):
        result.hint = _mirror_slip(second, ABCD) or (
            "the two meshes do not share the 30 nodes of the edge BC (dc): compare the second patch's corners "
            "(points and derivatives) one at a time with the patch abcd the lab describes, and use 30 points "
            "along dc."
        )
        return result
    if not result.step(f"{label}: every element positively oriented", merged.quality().min() > 0):
        result.hint = (
            _mirror_slip(second, ABCD) or "a folded element means a corner derivative of abcd points the wrong way."
        )
        return result
    return result


MIRROR_SLIPS = (
    (
        "the second patch's corners are not in the order a, b, c, d: a is A's mirror image, and b, c, d follow "
        "round the patch abcd as the lab's table of its points lists them.",
        lambda c: patches.Corner(c.point[::-1], c.dt[::-1], c.ds[::-1], c.dsdt[::-1]),
        "ABCD",
        (SIZES9[1], SIZES9[0]),
    ),
    (
        "in your second patch each corner's ds is the mirror image of ABCD's ds (and dt of dt), so its mesh lines "
        "do not meet the first patch's along dc: in the mirror image, which way does s run, and which way t?",
        lambda c: patches.Corner(c.point[::-1], c.ds[::-1], c.dt[::-1], c.dsdt[::-1]),
        "ADCB",
        (SIZES9[1], SIZES9[0]),
    ),
    (
        "the second patch's derivatives are not mirrored: its corner points are the mirror images of ABCD's, but "
        "their derivative vectors are ABCD's own; reflecting in y = x changes a vector as it changes a point.",
        lambda c: patches.Corner(c.point[::-1], c.dt, c.ds, c.dsdt),
        "ADCB",
        (SIZES9[1], SIZES9[0]),
    ),
    (
        "the mirror reflects the derivative vectors but not the points: your second patch's corners are ABCD's own "
        "points; reflecting in y = x swaps a point's x and y as it swaps a vector's.",
        lambda c: patches.Corner(c.point, c.dt[::-1], c.ds[::-1], c.dsdt[::-1]),
        "ADCB",
        (SIZES9[1], SIZES9[0]),
    ),
)
COUNTS_SWAPPED = (  # the right mirror, meshed with the first patch's counts: s and t swapped
    "the second patch's point counts in s and t are swapped: its edge dc runs in s and lies on the first "
    "patch's edge BC, which runs in t with 30 points, so abcd needs 30 points in s and 20 in t.",
    lambda c: patches.Corner(c.point[::-1], c.dt[::-1], c.ds[::-1], c.dsdt[::-1]),
    "ADCB",
    (SIZES9[0], SIZES9[1]),
)


def _mirror_slip(second, corners):
    """The hint of the slip of :data:`MIRROR_SLIPS` whose patch gives the student's second mesh (the same nodes,
    in any order), or ''."""
    try:
        nodes = floats(getattr(second, "points", ()))
    except (TypeError, ValueError):
        return ""
    if nodes.ndim != 2 or nodes.shape[1] < 2 or len(nodes) != SIZES9[0] * SIZES9[1] or not np.all(np.isfinite(nodes)):
        return ""
    by_label = dict(zip("ABCD", corners))
    mine = nodes[np.lexsort(np.round(nodes[:, :2], 9).T[::-1])][:, :2]
    for hint, mirrored, order, counts in MIRROR_SLIPS + (COUNTS_SWAPPED,):
        x, y = patches.patch(
            *(mirrored(by_label[label]) for label in order), np.linspace(0, 1, counts[0]), np.linspace(0, 1, counts[1])
        )
        theirs = np.stack((x.ravel(), y.ravel()), axis=1)
        if close(mine, theirs[np.lexsort(np.round(theirs, 9).T[::-1])], 1e-7):
            return hint
    return ""


def _boundary_edges(mesh):
    """How many element edges belong to one element only (a crack between patches adds to them)."""
    quads = np.asarray(mesh.quads)
    edges = np.sort(np.stack((quads, np.roll(quads, -1, axis=1)), axis=-1).reshape(-1, 2), axis=1)
    _, counts = np.unique(edges, axis=0, return_counts=True)
    return int(np.sum(counts == 1))


def _own_meshes(two_patches, corners):
    """The student's own two meshes of the lab's corners (two_patches called quietly), or None."""
    if two_patches is None or not callable(two_patches):
        return None
    try:
        first, second = two_patches(*corners)
    except Exception:  # noqa: BLE001 - a failing two_patches is marked in its own part
        return None
    if not (isinstance(first, QuadMesh) and isinstance(second, QuadMesh)):
        return None
    if max(len(first.points), len(second.points), len(first.quads), len(second.quads)) > MAX_NODES:
        return None
    return first, second


def _corner_points(corners):
    """{label: point} of the corners of patch ABCD and of its mirror image abcd in y = x (a = A mirrored,
    b = D, c = C, d = B: the points only, which the mirror rule for the derivatives does not change)."""
    A, B, C, D = (np.asarray(c.point, dtype=float)[:2] for c in corners)
    first = {"A": A, "B": B, "C": C, "D": D}
    second = {"a": A[::-1], "b": D[::-1], "c": C[::-1], "d": B[::-1]}
    return first, second


def _missed(mesh, points):
    nodes = np.asarray(mesh.points, dtype=float)[:, :2]
    return [
        f"{label} = ({point[0]:.3g}, {point[1]:.3g})"
        for label, point in points.items()
        if not nodes.size or np.min(np.hypot(*(nodes - point).T)) > ON_CORNER
    ]


def _corners_missed(meshes, corners):
    """The corner points (as 'B = (0.707, 0.707)') that no node of their mesh is on: ABCD's for the first
    mesh, abcd's for the second. A second mesh on ABCD's own points is a mirror that left the points where
    they were: a slip of the mirror rule, charged in two_patches, so nothing is missed."""
    first, second = _corner_points(corners)
    missed = _missed(meshes[0], first)
    if _missed(meshes[1], second) and _missed(meshes[1], first):
        missed += _missed(meshes[1], second)
    return missed


def attempted_meshes(own, corners):
    """Why the student's own two meshes are no attempt at the lab's two patches ('' when they are one).

    They are one when each has the lab's size (20 x 30 points) and passes through its patch's corners (ABCD's
    for the first mesh, the mirror image's for the second): a slip in ``coons`` or in the mirror rule changes
    the inside and the edges of a patch, not its corner points, and is charged in its own part; two unit
    squares, or meshes of other corners, are not the lab's region.
    """
    nodes, elements = SIZES9[0] * SIZES9[1], (SIZES9[0] - 1) * (SIZES9[1] - 1)
    if any(len(mesh.points) != nodes or len(mesh.quads) != elements for mesh in own):
        return (
            f"your two_patches meshes have {len(own[0].points)} and {len(own[1].points)} nodes, not the lab's "
            f"{SIZES9[0]} x {SIZES9[1]} points each"
        )
    missed = _corners_missed(own, corners)
    if missed:
        return f"your two_patches meshes do not pass through the lab's corners (no node at {', '.join(missed[:3])})"
    return ""


def _folded(mesh):
    return int(np.sum(mesh.quality() <= 0))


def check_combined_mesh(region, corners, two_patches=None):
    """Exercise 9(c): ``region`` is one conforming mesh of the two patches, judged from its data.

    The reference is the student's own two meshes (``two_patches`` called with
    the lab's corners), joined: the same nodes (in any order), the same
    number of elements, no crack along the shared edge (no more boundary
    edges than the join) and no element folded that is not folded in the
    student's own meshes already. So a mistake in ``coons`` or the mirror is
    marked there, once. When ``two_patches`` gives no meshes, or meshes that
    are no attempt at the lab's two patches (:func:`attempted_meshes`: not the
    lab's size, or not through the lab's corners), the reference is labkit's
    patch of the lab's corners, and the feedback says why.
    """
    result = CheckResult("region")
    if not isinstance(region, QuadMesh):
        return result.fail(
            "region is a QuadMesh",
            f"got {getattr(region, 'description', type(region).__name__)}",
            "make region one QuadMesh of the two meshes two_patches returns.",
        )
    if max(len(region.points), len(region.quads)) > MAX_NODES:
        return result.fail(
            "region has the lab's size",
            f"{len(region.points):,} nodes and {len(region.quads):,} elements",
            "mesh the two patches with 20 x 30 points each and make region of those two meshes.",
        )
    own = _own_meshes(two_patches, corners)
    why = attempted_meshes(own, corners) if own is not None else ""
    if why:  # trivial meshes (two unit squares, other corners) are no reference: the lab's patches are
        judged_by_the_lab(result, why, "the lab's two patches")
        own = None
    if own is not None:
        whose = "your two_patches meshes"
        try:
            reference = own[0] + own[1]
        except ValueError:
            own = None
    if own is None:
        whose = "the lab's two patches"
        A, B, C, D = corners
        first = quad_mesh(*patches.patch(A, B, C, D, np.linspace(0, 1, 20), np.linspace(0, 1, 30)))
        mirrored = [patches.Corner(c.point[::-1], c.dt[::-1], c.ds[::-1], c.dsdt[::-1]) for c in (A, D, C, B)]
        second = quad_mesh(*patches.patch(*mirrored, np.linspace(0, 1, 30), np.linspace(0, 1, 20)))
        reference = first + second
    if not result.step(
        f"{len(reference.points)} nodes and {len(reference.quads)} elements, as {whose} joined",
        len(region.points) == len(reference.points) and len(region.quads) == len(reference.quads),
        f"got {len(region.points)} nodes and {len(region.quads)} elements",
    ):
        result.hint = (
            f"a conforming mesh holds each node of the shared edge once, so region has {len(reference.points)} "
            f"nodes where yours has {len(region.points)}: the edge's nodes are there "
            f"{'twice' if len(region.points) > len(reference.points) else 'too few times'}."
        )
        return result
    order = np.lexsort(np.round(region.points, 9).T[::-1])
    expected = np.lexsort(np.round(reference.points, 9).T[::-1])
    if not result.step(
        f"the nodes are those of {whose}",
        close(region.points[order], reference.points[expected], 1e-7),
        worst(region.points[order], reference.points[expected]),
    ):
        result.hint = "make region from the two meshes two_patches returns, both whole."
        return result
    if not result.step(
        "conforming: no crack along the shared edge",
        _boundary_edges(region) == _boundary_edges(reference),
        f"{_boundary_edges(region)} boundary edges, {_boundary_edges(reference)} expected",
    ):
        result.hint = "elements on both sides of the shared edge must use the same nodes, not two copies of them."
        return result
    if not result.step(
        "no element folded by the join",
        _folded(region) <= _folded(reference),
        f"{_folded(region)} folded elements, {_folded(reference)} in the two meshes joined",
    ):
        result.hint = "the join turned elements over: keep each mesh's node order when you join them."
    return result


CORNERS9 = Together(("A9", "B9", "C9", "D9"))

# what Exercises 5, 7, 8 and 9 ask the student to find, in the words and code a text would use
IDENTITY_DATA = (  # 5: the identity map's corner derivatives
    "dx/ds = 1, dy/ds = 0",
    "\u2202x/\u2202s = 1, \u2202y/\u2202s = 0",
    "dx/dt = 0, dy/dt = 1",
    "\u2202x/\u2202t = 0, \u2202y/\u2202t = 1",
    "[1, 0], [0, 1], [0, 0])",
    "(1, 0), (0, 1), (0, 0)",
    "ds=[1, 0], dt=[0, 1]",  # as labkit.Corner writes itself (the patch editor's readout)
)
STRAIGHT_RULE = (  # 7: the derivatives of a straight, evenly divided side
    "the derivative is the vector along that side",
    "the vector along the side",
    "the vector from the corner where the side starts",
    "ds = B - A",
    "dt = D - A",
    "ds = C - D",
    "dt = C - B",
    "B - A, D - A",
)
ARC_ANSWERS = (  # 8: AB's parametrisation about G and its derivatives at A and B
    "5 * np.pi / 4 + np.pi / 2 *",
    "5pi/4 + pi/2",
    "5\\pi/4 + \\pi s/2",
    "(1 + s) * np.pi / 2 + np.pi / 4",
    "0.5 + radius * np.cos(5 * np.pi / 4",
    "dxds = [0.785",
    "0.785398",
    "0.7854",
    "pi/4, -pi/4",
    "pi / 4, pi / 4",
)
MIRROR_RULE = (  # 9: the mirror rule for abcd's corners
    "d is B",
    "b is D",
    "d = B",
    "b = D",
    "a = A mirrored",
    "swap ds and dt",
    "ds and dt swap",
    "ds and dt are swapped",
    "ds is the mirror image of ABCD's dt",
    "its ds is ABCD's dt",
    "dt[::-1], c.ds[::-1]",
    "dt[::-1], corner.ds[::-1]",
    "point[::-1], dt[::-1], ds[::-1]",
)

JOIN_RULE = (  # 9(c): how two meshes become one conforming mesh
    "+ merges",
    "with +, which merges",
    "merges nodes that coincide",
    "merges coinciding nodes",
    "merges the nodes that coincide",
    "coinciding nodes are merged",
)

EXERCISES = (
    Exercise(
        5,
        ("coons",),
        (Part("coons", 12, check_coons, ("coons",), seeded=True, refused=OWN_PATCH),),
        notebook="03_meshes.ipynb",
        withheld=IDENTITY_DATA,
    ),
    Exercise(6, ("graded",), (Part("graded", 10, check_graded_corners, ("graded",)),), notebook="03_meshes.ipynb"),
    Exercise(
        7,
        ("straight",),
        (Part("straight", 10, check_straight_corners, ("straight",), varied=tuple(LAB_QUAD)),),
        notebook="03_meshes.ipynb",
        answers=("why these corner data give straight, evenly divided sides",),
        withheld=STRAIGHT_RULE,
        # C and D of the quadrilateral ABCD (A and B stay): kept convex, so its mesh never folds
        params=(
            Param("xC", 0.8, 1.3, 2, lab=LAB_QUAD["xC"]),
            Param("yC", 0.3, 0.8, 2, lab=LAB_QUAD["yC"]),
            Param("xD", -0.3, 0.3, 2, lab=LAB_QUAD["xD"]),
            Param("yD", 0.8, 1.3, 2, lab=LAB_QUAD["yD"]),
        ),
        sound=quad_sound,
        derived=quad_shown,
    ),
    Exercise(
        8,
        ("circle_sides",),
        (Part("circle_sides", 12, check_circle_corners, ("circle_sides",)),),
        notebook="03_meshes.ipynb",
        answers=("AB as parametric equations, and dx/ds, dy/ds at A and B",),
        withheld=ARC_ANSWERS,
    ),
    Exercise(
        9,
        ("two_patches", "mirror", "region"),
        (
            Part(
                "two_patches",
                10,
                check_two_patches,
                ("two_patches", CORNERS9),
                keywords=(("coons", Optional("coons")),),
                uses=("coons",),
            ),
            Part(
                "region",
                6,
                check_combined_mesh,
                ("region", CORNERS9, Optional("two_patches")),
                uses=("two_patches", "coons"),
            ),
        ),
        notebook="03_meshes.ipynb",
        answers=("why the mirror image's corner data make the two patches match",),
        withheld=MIRROR_RULE + JOIN_RULE,
    ),
)
