"""A student's graded work made by hand (no sandbox): exercise 2 done, exercise 3 with a slip and parts not
done, exercise 4 with an error and a plot that is off, a cell of theirs that raised, two stubs left. Its
name and texts hold markup, which the feedback page must show as text. Used by the feedback page's browser
test and by the picture in docs/instructors.md (tests/browser/feedback_picture.py)."""

from labkit.exercises.result import NOT_DONE, RAISED
from labkit.grading.store.report import ProblemText, SubmissionGrade
from labkit.grading.store.rubric import default

HOSTILE = "<script>alert(1)</script>"


def _check(name, weight, failed=(), hint="", figure=None):
    steps = [{"step": step, "passed": False, "detail": detail, **({"kind": kind} if kind else {})}
             for step, detail, kind in failed]  # fmt: skip
    return {"name": name, "weight": weight, "passed": not failed, "hint": hint,
            "steps": steps or [{"step": "the values at 41 points", "passed": True, "detail": ""}],
            **({"figure": figure} if figure else {})}  # fmt: skip


def _limacon(points=211):
    """The exact limaçon r = 1.15 + cos t, as a student plotting it instead of its interpolant draws it, with
    the 21 data points as markers."""
    import math

    t = [2 * math.pi * k / (points - 1) for k in range(points)]
    curve = {"x": [(1.15 + math.cos(a)) * math.cos(a) for a in t], "y": [(1.15 + math.cos(a)) * math.sin(a) for a in t],
             "joined": True}  # fmt: skip
    data = {"x": curve["x"][::10], "y": curve["y"][::10], "joined": False}
    return [curve, data]


def _verdict(checks):
    total = sum(c["weight"] for c in checks)
    fraction = sum(c["weight"] for c in checks if c["passed"]) / total
    return {"fraction": fraction, "passed": fraction == 1.0, "checks": checks}


def sample_grade(name="ada"):
    """The graded work of `name`, under the lab's rubric."""
    results = {
        2: _verdict([_check("eval_pherm", 10)]),
        3: _verdict([
            _check("runge", 3, [("the derivative at 21 points", "largest difference 4.00e+00", None)],
                   "yprime has the wrong sign: the Runge function falls for positive x, so its derivative must "
                   "be negative there; check the sign the chain rule gives for the derivative of 1/u."),
            _check("test_pherm_interpolate", 6),
            _check("errors_pherm", 3, [("errors_pherm is defined", "not defined when the notebook finished",
                                        NOT_DONE)], "run the cell that defines errors_pherm."),
            _check("rate_pherm", 3, [("rate_pherm is defined", "not defined when the notebook finished",
                                      NOT_DONE)], "run the cell that defines rate_pherm."),
        ]),
        4: _verdict([
            _check("limacon_derivatives", 8, [("dx/dt at 21 points", "raised ZeroDivisionError: division by zero "
                                               f"(in limacon_derivatives, line 3: `d = 1 / {HOSTILE}`)", RAISED)],
                   "the error happened in limacon_derivatives, line 3: look at that line."),
            _check("ax4", 7, [("the curve is the Hermite interpolant of your data (within 1e-05)",
                               "a point is 2.31e-04 away from it", None)],
                   "that is the exact limaçon, not its Hermite interpolant: evaluate eval_pherm with tdata, "
                   "xdata, xpdata (and ydata, ypdata) at tval and plot xherm, yherm.", _limacon()),
        ]),
    }  # fmt: skip
    problems = [
        ProblemText(
            "02_convergence.ipynb: 2 cell(s) raised an error",
            [
                (RAISED, f"02_convergence.ipynb: cell 13 raised NameError: name 'n_data' is not defined {HOSTILE}"),
                (NOT_DONE, "02_convergence.ipynb: cell 14 raised NotImplementedError"),
            ],
        ),  # fmt: skip
        ProblemText("05_monotone.ipynb: 1 cell(s) raised", [(NOT_DONE, "05_monotone.ipynb: cell 9 raised NameError")]),
        ProblemText(
            "01_limacon.ipynb: 1 cell(s) raised", [(NOT_DONE, "01_limacon.ipynb: cell 6 raised NotImplementedError")]
        ),
    ]
    return SubmissionGrade(name, results, problems, seed=20261205, rubric=default())
