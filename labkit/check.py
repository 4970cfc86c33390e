"""Self-checks for the functions students write, with the lab's debugging steps.

Each check takes the student's function (or data), runs the lab's own
verification and, when something is wrong, narrows it down the way the lab's
debugging hints do, then says which step failed and what to look at. The
reference is always labkit's own implementation or the mathematics (a
polynomial the method must reproduce), never a stored output.

In a notebook, put ``labkit.check.eval_pherm(eval_pherm)`` right after the
function: the result prints as a short report. ``labkit grade`` runs the
same checks from outside the notebook's process, calling the student's
functions through a proxy into a sandbox. The checks live in
:mod:`labkit.checks`, one module per topic; this module gathers the names
the notebooks use.
"""
from .checks.bilinear import eval_pbilin, phi_table, runge2d
from .checks.drivers import driver, rate, table
from .checks.exercises import EXERCISES, NAMES, POINTS, Exercise, grade
from .checks.hermite import eval_pherm, limacon_derivatives, runge
from .checks.patches import circle_corners, combined_mesh, coons, graded_corners, straight_corners, two_patches
from .checks.plotted import boiling_plot, limacon_plot
from .checks.result import TOLERANCE, CheckResult
from .checks.splines import ccspline, ncspline

__all__ = ["CheckResult", "EXERCISES", "Exercise", "NAMES", "POINTS", "TOLERANCE", "boiling_plot", "ccspline",
           "circle_corners", "combined_mesh", "coons", "driver", "eval_pbilin", "eval_pherm", "grade",
           "graded_corners", "limacon_derivatives", "limacon_plot", "ncspline", "phi_table", "rate", "runge",
           "runge2d", "straight_corners", "table", "two_patches"]
