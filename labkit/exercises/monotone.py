"""Exercises 14 and 15: pchip against the not-a-knot spline on the boiling-water data, and pchip's order.

The plot is checked in :mod:`~labkit.exercises.plotted` and the experiment in
:mod:`~labkit.exercises.experiments`; this module declares the exercises.
"""

from .experiments import RUNGE_A, Experiment
from .model import Exercise, Part
from .plotted import LAB_BOIL, LAB_RISE, boiling_sound, check_boiling_plot
from .variants import Param

# what Exercise 14's plot shows, and the calls that draw it: the exercise is to draw it and look
BOILING_VIEW = (
    "the spline overshoots",
    "overshoots above the boiling point",
    "dips below it",
    "pchip never leaves",
    "plot(xdata, ydata, 'o')",
    "the format string 'o'",
)
PCHIP = Experiment("pchip", 2, "test_pchip_interpolate", "errors_pchip", "rate_pchip", weights=(4, 2, 2))

EXERCISES = (
    Exercise(
        14,
        ("ax14",),
        tuple(
            Part(name, 2, check_boiling_plot, ("ax14",), index=i, varied=("rise", "boil"))
            for i, name in enumerate(("ax14: the data", "ax14: the not-a-knot spline", "ax14: pchip"))
        ),
        notebook="05_monotone.ipynb",
        withheld=BOILING_VIEW,
        # the temperature at time 1 and the boiling point: rising, then flat, so the spline overshoots
        params=(Param("rise", 0.6, 1.4, 2, lab=LAB_RISE), Param("boil", 1.8, 2.6, 2, lab=LAB_BOIL)),
        sound=boiling_sound,
    ),
    Exercise(
        15,
        PCHIP.names(),
        PCHIP.parts(),
        notebook="05_monotone.ipynb",
        answers=("pchip's order against the spline's, and when to choose pchip",),
        withheld=PCHIP.withheld,
        params=(RUNGE_A,),  # the scale of the Runge function, drawn with Exercise 3
        sound=PCHIP.sound,
    ),
)
