"""The graded exercises: what the student defines, which checks run, points, refused references.

A new exercise's check goes in the topic module it belongs to (``hermite``,
``patches``, ``splines``, ``bilinear``, or a new one), and gets one entry in
:data:`EXERCISES` here. The same entry serves a student's notebook and
``labkit grade``: :func:`grade` only reads names from a mapping, which is the
notebook's own variables in the notebook and a proxy into the sandboxed
notebook in the grader (:mod:`labkit.grading.remote`).
"""
from dataclasses import dataclass

from . import bilinear, hermite, patches, splines
from .result import CheckResult

# scipy's interpolants that would answer a 1-D interpolation exercise outright
_SCIPY_1D = ("scipy.interpolate.CubicHermiteSpline", "scipy.interpolate.PchipInterpolator",
             "scipy.interpolate.CubicSpline", "scipy.interpolate.Akima1DInterpolator",
             "scipy.interpolate.BPoly", "scipy.interpolate.PPoly", "scipy.interpolate.KroghInterpolator",
             "scipy.interpolate.make_interp_spline", "scipy.interpolate.interp1d",
             "scipy.interpolate.splrep", "scipy.interpolate.InterpolatedUnivariateSpline")
_LABKIT_SPLINES = ("labkit.ccspline", "labkit.ncspline", "labkit.nakspline", "labkit.spline",
                   "labkit.pchip", "labkit.pchip_slopes", "labkit.convergence_table")


@dataclass(frozen=True)
class Exercise:
    """One graded exercise.

    ``names`` are what the student's notebook defines (any of them present
    means the notebook is the exercise's own). ``run(ns, seed)`` returns the
    check results. ``refused`` are reference implementations switched off
    while the grader calls this exercise's functions (the lab asks students
    to write them); anything not listed, such as ``labkit.bracket``, stays
    available.
    """

    number: int
    names: tuple
    run: object
    points: int = 10
    refused: tuple = ()


EXERCISES = {e.number: e for e in (
    Exercise(2, ("eval_pherm",), lambda ns, seed: [hermite.eval_pherm(ns["eval_pherm"], seed=seed)],
             refused=("labkit.eval_pherm", "labkit.hermite_basis") + _SCIPY_1D),
    Exercise(3, ("runge", "test_pherm_interpolate"),
             lambda ns, seed: [hermite.runge(ns["runge"], seed=seed),
                               hermite.test_pherm_interpolate(ns["test_pherm_interpolate"], seed=seed)],
             refused=("labkit.runge", "labkit.convergence_table", "labkit.ConvergenceTable")),
    Exercise(5, ("coons",), lambda ns, seed: [patches.coons(ns["coons"], seed=seed)],
             refused=("labkit.patch",)),
    Exercise(6, ("graded",), lambda ns, seed: [patches.graded_corners(ns["graded"])]),
    Exercise(7, ("straight",), lambda ns, seed: [patches.straight_corners(ns["straight"])]),
    Exercise(8, ("circle_sides",), lambda ns, seed: [patches.circle_corners(ns["circle_sides"])]),
    Exercise(9, ("two_patches", "mirror"),
             lambda ns, seed: [patches.two_patches(ns["two_patches"], [ns["A9"], ns["B9"], ns["C9"], ns["D9"]])]),
    Exercise(10, ("ccspline", "complete_system"),
             lambda ns, seed: [splines.ccspline(ns["ccspline"], ns.get("complete_system"), seed=seed)],
             refused=_LABKIT_SPLINES + _SCIPY_1D),
    Exercise(12, ("ncspline",), lambda ns, seed: [splines.ncspline(ns["ncspline"], seed=seed)],
             refused=_LABKIT_SPLINES + _SCIPY_1D),
    Exercise(16, ("runge2d", "eval_pbilin"),
             lambda ns, seed: [bilinear.runge2d(ns["runge2d"], seed=seed), bilinear.eval_pbilin(ns["eval_pbilin"], seed=seed)],
             refused=("labkit.eval_pbilin", "labkit.runge2d", "labkit.bilinear_convergence",
                      "scipy.interpolate.RegularGridInterpolator", "scipy.interpolate.interpn",
                      "scipy.interpolate.RectBivariateSpline", "scipy.interpolate.LinearNDInterpolator",
                      "scipy.interpolate.griddata")),
)}
POINTS = {number: exercise.points for number, exercise in EXERCISES.items()}
NAMES = {number: list(exercise.names) for number, exercise in EXERCISES.items()}


def grade(number, namespace, seed=None):
    """Run the checks of exercise `number` on a notebook's variables; a dict for the grader.

    `namespace` is any mapping of names to the student's functions and data.
    ``defined`` says whether the notebook defines any of the exercise's names,
    so the grader can tell the exercise's own notebook from one that only
    mentions it. `seed` draws the random test data afresh (see
    :func:`labkit.checks.result.case_rng`).
    """
    exercise = EXERCISES[number]
    defined = any(name in namespace for name in exercise.names)
    try:
        results = exercise.run(namespace, seed)
    except KeyError as exc:
        name = str(exc).strip("'\"")
        missing = CheckResult(name)
        missing.fail(f"{name} is defined", "not defined when the notebook finished",
                     f"run the cell that defines {name} (and keep its name); a cell that raised stops it.")
        results = [missing]
    passed = all(r.passed for r in results)
    return {"exercise": number, "passed": passed, "points": exercise.points if passed else 0,
            "defined": defined, "checks": [r.as_dict() for r in results]}
