"""A plot read as plain data: each line's points, marker and whether a line joins them.

Every artist that puts marks at points counts: a ``Line2D`` (``plot``, and
the lines ``errorbar`` and ``stem`` draw) and a ``PathCollection``
(``scatter``), whose marker is recognised from its shape.

Used by the plot checks in a notebook (:mod:`labkit.exercises.plotted`) and by
the sandboxed notebook when it sends a plot to the grader
(:mod:`labkit.grading.sandbox.protocol`), so a plot is judged from its data, never
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


MARKERS = ("o", "s", "^", "v", "<", ">", "D", "d", "p", "h", "*", "+", "x", ".")


def _marker_shapes():
    from matplotlib.markers import MarkerStyle

    shapes = {}
    for code in MARKERS:
        style = MarkerStyle(code)
        shapes[code] = style.get_path().transformed(style.get_transform()).vertices
    return shapes


def scatter_of(collection):
    """A scatter plot's PathCollection as a :class:`Line` of unjoined marks (its marker from its shape)."""
    offsets = np.asarray(collection.get_offsets(), dtype=float).reshape(-1, 2)
    marker = "custom"
    paths = collection.get_paths()
    if len(paths) == 1:
        vertices = paths[0].vertices
        for code, shape in _marker_shapes().items():
            if shape.shape == vertices.shape and np.allclose(shape, vertices, atol=1e-6):
                marker = code
                break
    return Line(offsets[:, 0], offsets[:, 1], marker, "None")


def _marks(ax):
    from matplotlib.collections import PathCollection

    lines = [line_of(line) for line in ax.get_lines()]
    lines += [scatter_of(c) for c in ax.collections if type(c) is PathCollection and len(c.get_offsets())]
    return lines


def lines_of(plot):
    """The marks of an Axes, of every Axes of a Figure, or a list of lines already read; else None."""
    if isinstance(plot, (list, tuple)) and all(isinstance(line, Line) for line in plot):
        return list(plot)
    axes = getattr(plot, "axes", None)
    if hasattr(plot, "get_lines"):
        return _marks(plot)
    if isinstance(axes, list):  # a Figure
        return [line for ax in axes for line in _marks(ax)]
    return None


def figure_data(lines, max_lines=8, max_points=300):
    """A plot's lines as small plain data for a student's feedback page: at most `max_lines` lines of at most
    `max_points` finite points each (every k-th point kept), numbers to 6 significant digits.

    >>> line = Line(np.linspace(0.0, 1.0, 1001), np.linspace(0.0, 2.0, 1001), "None", "-")
    >>> shown = figure_data([line])
    >>> len(shown[0]["x"]) <= 300, shown[0]["x"][0], shown[0]["y"][-1], shown[0]["joined"]
    (True, 0.0, 2.0, True)
    """
    shown = []
    for line in list(lines)[:max_lines]:
        x, y = np.ravel(line.x).astype(float), np.ravel(line.y).astype(float)
        size = min(x.size, y.size)
        keep = np.isfinite(x[:size]) & np.isfinite(y[:size])
        x, y = x[:size][keep], y[:size][keep]
        if x.size == 0:
            continue
        step = -(-x.size // max_points)
        index = np.unique(np.append(np.arange(0, x.size, step), x.size - 1))
        rounded = [[float(f"{v:.6g}") for v in values[index]] for values in (x, y)]
        shown.append({"x": rounded[0], "y": rounded[1], "joined": line.joined})
    return shown
