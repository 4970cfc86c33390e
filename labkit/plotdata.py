"""A plot read as plain data: each line's points, marker and whether a line joins them.

Used by the plot checks in a notebook (:mod:`labkit.checks.plotted`) and by
the sandboxed notebook when it sends a plot to the grader
(:mod:`labkit.grading.protocol`), so a plot is judged from its data, never
from pixels. It holds no reference of the lab's: the grader's watch never
refuses it.
"""
from dataclasses import dataclass

import numpy as np

NO_LINE = ("None", "none", "", " ")


@dataclass(frozen=True)
class Line:
    """One plotted line as plain data."""

    x: np.ndarray
    y: np.ndarray
    marker: str  # matplotlib's marker code: "o" for circles, "None" for none
    linestyle: str  # "-", "--", ... or "None"

    @property
    def joined(self):
        """Whether a line is drawn between the points."""
        return self.linestyle not in NO_LINE


def line_of(line):
    """A matplotlib Line2D as a :class:`Line`."""
    x = np.asarray(line.get_xdata(orig=False), dtype=float).ravel()
    y = np.asarray(line.get_ydata(orig=False), dtype=float).ravel()
    marker = line.get_marker()
    style = line.get_linestyle() if line.get_linewidth() > 0 else "None"
    return Line(x, y, str(marker) if isinstance(marker, str) else "custom", str(style))


def lines_of(plot):
    """The lines of an Axes, of every Axes of a Figure, or a list of lines already read; else None."""
    if isinstance(plot, (list, tuple)) and all(isinstance(line, Line) for line in plot):
        return list(plot)
    axes = getattr(plot, "axes", None)
    if hasattr(plot, "get_lines"):
        return [line_of(line) for line in plot.get_lines()]
    if isinstance(axes, list):  # a Figure
        return [line_of(line) for ax in axes for line in ax.get_lines()]
    return None
