"""Figures of the lab: each a *view* built once and updated in place, and a one-call plot function.

A view draws its artists (lines, a mesh collection, a colour map) into an axes
when it is made, and ``update(...)`` puts new data into those same artists:
``set_data``, ``set_verts``, ``set_array`` and the title, never a new figure.
The sliders of :mod:`labkit.plots.explorers` call ``update`` on every move;
the ``plot_*`` functions are a view updated once, for a static figure.
Every function labels its axes, sets a title and returns the axes, and describes
what it drew in numbers (the picture's alternative text, see ``labkit/_alt.py``).

Colours are safe for colour-blind readers: lines take the Okabe–Ito palette
(``PALETTE``) and each method keeps its own colour, line style and marker
(``METHOD_STYLES``) in every figure, so no two curves differ by colour alone;
colour maps are cividis (mesh quality) and coolwarm (signed errors).
"""

import numpy as np

from .._alt import describe, num, sci
from ..bilinear import eval_pbilin
from ..convergence import METHOD_TITLES, _interpolate
from ..errors import InputError
from ..functions import limacon, runge, runge2d
from ..mesh import quad_mesh
from ..monotone import pchip
from ..patches import patch
from ..piecewise import eval_pherm, eval_plin
from ..splines import ccspline, nakspline, ncspline, spline

# Okabe & Ito's palette (Color Universal Design, 2008): told apart with every common colour-vision deficiency
PALETTE = {
    "blue": "#0072B2",
    "vermillion": "#D55E00",
    "green": "#009E73",
    "orange": "#E69F00",
    "purple": "#CC79A7",
    "sky": "#56B4E9",
    "black": "#000000",
}
# one look per method in every figure: colour, line style and marker differ together
METHOD_STYLES = {
    "plin": {"color": PALETTE["blue"], "linestyle": "-", "marker": "o"},
    "pherm": {"color": PALETTE["vermillion"], "linestyle": "--", "marker": "s"},
    "complete": {"color": PALETTE["green"], "linestyle": "-.", "marker": "^"},
    "natural": {"color": PALETTE["orange"], "linestyle": "-", "marker": "D"},
    "notaknot": {"color": PALETTE["purple"], "linestyle": ":", "marker": "v"},
    "pchip": {"color": PALETTE["sky"], "linestyle": (0, (5, 1, 1, 1, 1, 1)), "marker": "P"},
}


def method_style(method, markers=False):
    """Colour and line style of `method` (and its marker if `markers`), as keyword arguments of ``plot``."""
    style = dict(METHOD_STYLES[method])
    if not markers:
        style.pop("marker")
    return style


def new_axes(ax=None, size=(5, 5)):
    """`ax`, or the axes of a new pyplot figure of this size."""
    if ax is None:
        import matplotlib.pyplot as plt

        _, ax = plt.subplots(figsize=size)
    return ax


def _label(ax, xlabel, ylabel, title):
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    return ax


def _fit(ax, x, y, margin=0.05):
    """Axis limits around the points (x, y), with a margin; for artists relim() does not see."""
    x, y = np.asarray(x)[np.isfinite(x)], np.asarray(y)[np.isfinite(y)]
    if x.size == 0 or y.size == 0:
        return
    for setter, values in ((ax.set_xlim, x), (ax.set_ylim, y)):
        low, high = values.min(), values.max()
        pad = margin * (high - low) or 0.5
        setter(low - pad, high + pad)


def _fills(ax, x, y, share=0.75, inset=0.03):
    """Whether the points (x, y) lie inside the axes' limits, at least `inset` of each span from its edges (a
    marker on a data point stays clear of the frame), and span at least `share` of each: the limits may then
    stay as they are (a small move of a slider leaves the axes still, and only the curves are redrawn)."""
    for (low, high), values in ((ax.get_xlim(), np.asarray(x)), (ax.get_ylim(), np.asarray(y))):
        values = values[np.isfinite(values)]
        room = inset * (high - low)
        if values.size == 0 or values.min() < low + room or values.max() > high - room:
            return False
        if values.max() - values.min() < share * (high - low):
            return False
    return True


class View:
    """What every view of the lab's figures is, and what the explorers rely on.

    A view is made once with an axes (or makes its own) and draws its artists
    there. ``update(...)`` puts new data into those same artists; its
    keyword arguments are what an explorer's controls are named. For quicker
    redraws while a slider moves, a view may name the artists that change
    (``dynamic``) and a key of everything else (``static_key``): while the key
    stays the same, :class:`labkit.plots.explorers.Painter` redraws only the
    dynamic artists over a saved copy of the rest. The defaults (nothing
    dynamic) make every picture a full draw.
    """

    ax = None

    def update(self, **values):
        raise NotImplementedError(f"{type(self).__name__} must define update(...), which changes its artists in place")

    def dynamic(self):
        """The artists that change on every update (none: every picture is drawn in full)."""
        return ()

    def static_key(self):
        """A value that changes exactly when something outside :meth:`dynamic` changes."""
        return None


class LimaconView(View):
    """The limaçon r = r0 + cos t: exact curve, its interpolant from the sampled points, the data."""

    def __init__(self, ax=None):
        self.ax = new_axes(ax)
        (self.exact,) = self.ax.plot([], [], color="0.75", lw=3, label="exact")
        (self.curve,) = self.ax.plot([], [], color=PALETTE["blue"], label="interpolant")
        (self.data,) = self.ax.plot([], [], "o", color=PALETTE["vermillion"], ms=4, label="data")
        self._r0 = None
        self.ax.set_aspect("equal")
        _label(self.ax, "x", "y", "")

    def update(self, nintervals=20, r0=1.15, method="pherm"):
        if method not in ("plin", "pherm"):
            raise InputError("method must be 'plin' (piecewise linear) or 'pherm' (Hermite).")
        tdata = np.linspace(0, 2 * np.pi, nintervals + 1)
        xdata, ydata, xpdata, ypdata = limacon(tdata, r0)
        tval = np.linspace(0, 2 * np.pi, 10 * (nintervals + 1))
        if method == "plin":
            xval, yval = eval_plin(tdata, xdata, tval), eval_plin(tdata, ydata, tval)
        else:
            xval, yval = eval_pherm(tdata, xdata, xpdata, tval), eval_pherm(tdata, ydata, ypdata, tval)
        if self._r0 != r0:  # the exact curve depends on r0 only
            exact = limacon(np.linspace(0, 2 * np.pi, 2001), r0)
            self.exact.set_data(exact[0], exact[1])
            if self._r0 is None or not _fills(self.ax, exact[0], exact[1]):
                _fit(self.ax, exact[0], exact[1], margin=0.05 if self._r0 is None else 0.12)
            self._r0 = r0
        self.curve.set_data(xval, yval)
        label = METHOD_TITLES[method].lower()
        if label != self.curve.get_label() or self.ax.get_legend() is None:
            self.curve.set_label(label)
            self.ax.legend(loc="upper right", fontsize="small")
        self.data.set_data(xdata, ydata)
        self.ax.set_title(f"limaçon r = {r0:g} + cos t, {nintervals} intervals")
        xexact, yexact = limacon(tval, r0)[:2]
        distance = np.hypot(xval - xexact, yval - yexact)
        worst = int(np.argmax(distance))
        describe(
            self.ax,
            f"limaçon r = {r0:g} + cos t and its {label} interpolant from {nintervals + 1} points "
            f"({nintervals} intervals): largest error {sci(distance[worst])} at t = {num(tval[worst])}",
        )
        return self.ax

    def dynamic(self):
        """The artists a move of the interval count or of r0 changes (see PatchView.dynamic), in the order they
        are drawn: the exact curve under the legend, the interpolant and the data over it, as ever."""
        legend = self.ax.get_legend()
        return [self.exact, *([legend] if legend is not None else []), self.curve, self.data, self.ax.title]

    def static_key(self):
        return self.ax.get_xlim(), self.ax.get_ylim(), self.curve.get_label()


class ErrorCurvesView(View):
    """Pointwise error p - f of several interpolation methods from ndata equally spaced points."""

    def __init__(self, methods, ax=None, f=runge, interval=(0.0, 5.0)):
        self.ax = new_axes(ax, size=(6, 4))
        self.f, (self.a, self.b) = f, interval
        self.x = np.linspace(self.a, self.b, 1001)
        self.exact = f(self.x)[0]
        self._errors, self._shown = {}, None
        self.lines = {
            m: self.ax.plot(self.x, 0 * self.x, label=METHOD_TITLES[m], **method_style(m))[0] for m in methods
        }
        (self.points,) = self.ax.plot([], [], "k.", ms=4, label="data points")
        self.ax.ticklabel_format(axis="y", style="sci", scilimits=(-2, 2))
        _label(self.ax, "x", "p(x) - f(x)", "")

    def _error(self, method, ndata):
        """p - f, computed once per method and ndata (a checkbox shows a curve again without recomputing it)."""
        if (method, ndata) not in self._errors:
            if len(self._errors) > 64:
                self._errors.clear()
            self._errors[method, ndata] = _interpolate(method, self.f, self.a, self.b, ndata, self.x) - self.exact
        return self._errors[method, ndata]

    def update(self, methods, ndata):
        low, high = 0.0, 0.0
        for method, line in self.lines.items():
            line.set_visible(method in methods)
            if method in methods:
                error = self._error(method, ndata)
                line.set_ydata(error)
                low, high = min(low, error.min()), max(high, error.max())
        self.points.set_data(np.linspace(self.a, self.b, ndata), np.zeros(ndata))
        self.ax.set_xlim(self.a - 0.02 * (self.b - self.a), self.b + 0.02 * (self.b - self.a))
        # the y-axis keeps its limits while the curves fit and fill a quarter of them: a small move
        # of a slider then leaves the axis still (and only the curves are redrawn)
        bottom, top = self.ax.get_ylim()
        span = high - low
        if low < bottom or high > top or top - bottom > 4 * span or self._shown is None:
            pad = 0.05 * span or 1e-16
            self.ax.set_ylim(low - pad, high + pad)
        shown = [line for method, line in self.lines.items() if method in methods] + [self.points]
        if shown != self._shown:  # a new legend only when the set of curves changes
            self.ax.legend(handles=shown, fontsize="small")
            self._shown = shown
        self.ax.set_title(f"Interpolation error, {ndata} equally spaced points")
        describe(self.ax, "; ".join(self._describe(method, ndata) for method in self.lines if method in methods))
        return self.ax

    def _describe(self, method, ndata):
        error = np.abs(self._error(method, ndata))
        worst = int(np.argmax(error))
        return (
            f"error of the {METHOD_TITLES[method].lower()} with {ndata} points: "
            f"largest {sci(error[worst])} at x = {num(self.x[worst])}"
        )

    def dynamic(self):
        """The curves, the data points and the title: see PatchView.dynamic."""
        return [*self.lines.values(), self.points, self.ax.title]

    def static_key(self):
        return self.ax.get_xlim(), self.ax.get_ylim(), tuple(self._shown or ())


class SplinePchipView(View):
    """Data as circles, the not-a-knot spline and pchip through them, on 201 points."""

    def __init__(self, xdata, ax=None):
        self.ax = new_axes(ax, size=(6, 4))
        self.xdata = np.asarray(xdata, dtype=float)
        self.xv = np.linspace(self.xdata[0], self.xdata[-1], 201)
        (self.spline,) = self.ax.plot(self.xv, 0 * self.xv, label="not-a-knot spline", **method_style("notaknot"))
        (self.pchip,) = self.ax.plot(self.xv, 0 * self.xv, label="pchip", **method_style("pchip"))
        (self.data,) = self.ax.plot(self.xdata, 0 * self.xdata, "o", mfc="none", color="k", label="data")
        self._fitted = False
        self.ax.legend(fontsize="small")
        _label(self.ax, "time", "temperature", "Spline overshoots, pchip keeps the data's shape")

    def update(self, ydata):
        ydata = np.asarray(ydata, dtype=float)
        curve = spline(self.xdata, ydata, self.xv)
        monotone = pchip(self.xdata, ydata, self.xv)
        self.spline.set_ydata(curve)
        self.pchip.set_ydata(monotone)
        self.data.set_ydata(ydata)
        values = np.concatenate((curve, ydata))
        low, high = values.min(), values.max()
        bottom, top = self.ax.get_ylim()
        if not self._fitted or low < bottom or high > top or top - bottom > 4 * (high - low):
            _fit(self.ax, self.xv, values)  # otherwise the axes stay still while the curves fit
            self._fitted = True
        points = ", ".join(f"({num(x)}, {num(y)})" for x, y in zip(self.xdata, ydata))
        describe(
            self.ax,
            f"data {points}: the not-a-knot spline goes from {num(curve.min())} to {num(curve.max())}, "
            f"pchip from {num(monotone.min())} to {num(monotone.max())} (the data from {num(ydata.min())} "
            f"to {num(ydata.max())})",
        )
        return self.ax

    def dynamic(self):
        """The two curves and the data: see PatchView.dynamic."""
        return [self.spline, self.pchip, self.data]

    def static_key(self):
        return self.ax.get_xlim(), self.ax.get_ylim()


class BilinearErrorView(View):
    """Colour map of I - f for bilinear interpolation from an ndata x ndata grid."""

    def __init__(self, ax=None, f=runge2d, square=(0.0, 5.0), ntest=201):
        self.ax = new_axes(ax, size=(5.5, 4.5))
        self.f, (self.a, self.b) = f, square
        self.test = np.linspace(self.a, self.b, ntest)
        X, Y = np.meshgrid(self.test, self.test, indexing="ij")
        self.exact = f(X, Y)
        step = (self.b - self.a) / (ntest - 1)  # one pixel per test point, centred on it
        extent = (self.a - step / 2, self.b + step / 2, self.a - step / 2, self.b + step / 2)
        self.image = self.ax.imshow(
            0 * self.exact.T, origin="lower", extent=extent, cmap="coolwarm", interpolation="nearest"
        )
        self.colorbar = self.ax.figure.colorbar(self.image, ax=self.ax, label="I(x, y) - f(x, y)")
        self.ax.set_aspect("equal")
        _label(self.ax, "x", "y", "")

    def update(self, ndata):
        grid = np.linspace(self.a, self.b, ndata)
        error = eval_pbilin(self.f, grid, grid, self.test, self.test) - self.exact
        i, j = np.unravel_index(np.argmax(np.abs(error)), error.shape)
        largest = np.abs(error[i, j])
        self.image.set_array(error.T)
        self.image.set_clim(-largest or -1e-16, largest or 1e-16)
        self.ax.set_title(f"Bilinear error, {ndata} x {ndata} data, max {largest:.1e}")
        describe(
            self.ax,
            f"error I - f of bilinear interpolation from {ndata} x {ndata} data: largest |I - f| {sci(largest)} "
            f"at (x, y) = ({num(self.test[i])}, {num(self.test[j])}), from {sci(error.min())} to {sci(error.max())}",
        )
        return self.ax

    def dynamic(self):
        """The map, the title and the colour bar (its scale follows the error): see PatchView.dynamic."""
        return [self.image, self.ax.title, self.colorbar.ax]

    def live_dynamic(self):
        """What a live picture draws at each move (labkit.plots.scene): the colour bar's axis only, since
        its colours are the same at every symmetric scale."""
        return [self.image, self.ax.title, self.colorbar.ax.yaxis]

    def static_key(self):
        return self.ax.get_xlim(), self.ax.get_ylim()


TITLE = "{ns} x {nt} elements, worst quality {worst:.2f}"  # a patch view's title (the editor's page writes it too)


class PatchView(View):
    """A Coons patch's mesh, filled by element quality (folded elements hatched), with the worst in the title."""

    def __init__(self, ax=None, color_by_quality=True, colorbar=True):
        self.ax = new_axes(ax)
        self.color_by_quality, self.colorbar = color_by_quality, colorbar
        self.cells = None
        self.folded = None  # the hatched outlines of the folded elements, when coloured by quality
        self.mesh = None
        self.s = self.t = None  # the parameter values of the mesh's lines
        self._fitted = False  # have the axes been fitted to a mesh yet?

    def update(self, corners, ns=11, nt=11, s=None, t=None, title=None):
        s = np.linspace(0, 1, ns) if s is None else s
        t = np.linspace(0, 1, nt) if t is None else t
        self.mesh = quad_mesh(*patch(*corners, s, t))
        quality = self.mesh.quality()
        worst = quality.min()
        self.s, self.t = s, t
        title = title or TITLE.format(ns=len(s) - 1, nt=len(t) - 1, worst=worst)
        if self.cells is None:
            self.mesh.plot(ax=self.ax, color_by_quality=self.color_by_quality, title=title, colorbar=self.colorbar)
            drawn = {c.get_gid(): c for c in self.ax.collections}
            self.cells = drawn.get("quality", self.ax.collections[-1])
            self.folded = drawn.get("folded")
        else:
            polygons = self.mesh.points[self.mesh.quads][..., :2]
            self.cells.set_verts(polygons)
            if self.color_by_quality:
                self.cells.set_array(quality)
                self.folded.set_verts(polygons[quality <= 0])
            self.ax.set_title(title)
        x, y = self.mesh.points[:, 0], self.mesh.points[:, 1]
        if not self._fitted or not _fills(self.ax, x, y):  # a move that keeps the mesh inside keeps the axes
            _fit(self.ax, x, y, margin=0.12 if self._fitted else 0.05)
            self._fitted = True
        folded = int(np.sum(quality <= 0))
        describe(
            self.ax,
            f"mesh of a Coons patch, {len(s) - 1} x {len(t) - 1} elements: worst quality {worst:.2f}, "
            + (f"{folded} folded" + (" (hatched)" if self.color_by_quality else "") if folded else "none folded"),
        )
        return self.ax

    def dynamic(self):
        """The artists a move changes (the rest is drawn once and copied: see Explorer)."""
        return [self.cells, self.ax.title] + ([self.folded] if self.folded is not None else [])

    def static_key(self):
        """What the copied background depends on: a new key means a full redraw."""
        return self.ax.get_xlim(), self.ax.get_ylim()


def draw_mesh(mesh, ax=None, color_by_quality=False, title=None, **line_kw):
    """Draw a QuadMesh's element edges (x-y plane); fill by quality if asked (see QuadMesh.plot)."""
    return mesh.plot(ax=ax, color_by_quality=color_by_quality, title=title, **line_kw)


def plot_patch(corners, ns=11, nt=11, ax=None, color_by_quality=False, title=None, s=None, t=None):
    """Mesh a Coons patch on an ns x nt grid (or given s, t) and draw it; return the axes."""
    return PatchView(ax, color_by_quality).update(corners, ns, nt, s, t, title)


def plot_limacon(nintervals=20, r0=1.15, method="pherm", ax=None):
    """Interpolate the limaçon from nintervals+1 points with 'plin' or 'pherm' and draw it."""
    if method not in ("plin", "pherm"):
        raise InputError("method must be 'plin' (piecewise linear) or 'pherm' (Hermite).")
    return LimaconView(ax).update(nintervals, r0, method)


def plot_convergence(tables, ax=None, slopes=()):
    """Log-log plot of error against number of data for ConvergenceTables; with `slopes` (orders, e.g. (2, 4)),
    a guide line of slope -p for each. The student release draws none: lines of the lab's orders beside the
    tables would answer the question the tables ask."""
    ax = new_axes(ax, size=(6, 4.5))
    titles = {title.lower(): method for method, title in METHOD_TITLES.items()}
    looks = list(METHOD_STYLES.values())
    for k, table in enumerate(tables):
        name = table.title.split(", ")[-1]
        look = METHOD_STYLES.get(titles.get(name.lower()), looks[k % len(looks)])
        ax.loglog(table.ndata, table.errors, ms=4, label=name, **look)  # the name only: the order is the lab's question
    n = np.array([tables[0].ndata[2], tables[0].ndata[-1]], dtype=float)
    for order, style in zip(slopes, ("k--", "k:", "k-.")):
        anchor = min(t.errors[2] for t in tables)
        ax.loglog(n, anchor * (n / n[0]) ** -order, style, lw=1, label=f"slope -{order}")
    ax.legend(fontsize="small")
    describe(
        ax,
        "convergence on the Runge function, relative max error against the number of data points: "
        + "; ".join(
            f"{t.title.split(', ')[-1].lower()} from {sci(t.errors[0])} at {t.ndata[0]} points "
            f"to {sci(t.errors[-1])} at {t.ndata[-1]}"
            for t in tables
        ),
    )
    return _label(ax, "number of data points", "relative max error", "Convergence on the Runge function")


def plot_interpolation_error(methods, ndata, ax=None, f=runge, interval=(0.0, 5.0)):
    """Pointwise error p - f of each method with ndata equally spaced points."""
    return ErrorCurvesView(methods, ax, f, interval).update(methods, ndata)


def plot_second_derivatives(ndata=7, ax=None, f=runge, interval=(0.0, 5.0)):
    """s'' of the Hermite interpolant and of the three cubic splines of f from ndata equally spaced points.

    The Hermite cubics (values and true slopes of f) only match first derivatives at the data
    points, so their s'' jumps there; a spline's s'' is continuous, and the natural spline's is
    0 at both ends. See ``notebooks/04_splines.ipynb``.
    """
    ax = new_axes(ax, size=(6, 4))
    a, b = interval
    xdata = np.linspace(a, b, ndata)
    y, yp = f(xdata)
    # each piece is evaluated on its own interval (its own cubic up to both ends), with a NaN between
    # pieces, so that a jump of s'' at a data point shows as a jump
    pieces = [np.linspace(xdata[k], xdata[k + 1], 40) for k in range(ndata - 1)]
    x = np.concatenate([np.append(piece, np.nan) for piece in pieces])

    def curve(slopes):
        return np.concatenate(
            [
                np.append(eval_pherm(xdata[k : k + 2], y[k : k + 2], slopes[k : k + 2], piece, der=2), np.nan)
                for k, piece in enumerate(pieces)
            ]
        )

    hermite = curve(yp)
    ax.plot(x, hermite, color="0.5", lw=2.5, label="Hermite (true slopes): s'' jumps")
    ax.plot(x, curve(ccspline(xdata, y, yp[0], yp[-1])), label="complete spline", **method_style("complete"))
    ax.plot(x, curve(ncspline(xdata, y)), label="natural spline (s'' = 0 at the ends)", **method_style("natural"))
    ax.plot(x, curve(nakspline(xdata, y)), lw=2, label="not-a-knot spline", **method_style("notaknot"))
    ax.plot(xdata, np.zeros(ndata), "k|", ms=12, label="data points")
    ax.legend(fontsize="small")
    pieces = hermite.reshape(ndata - 1, -1)  # each piece's 40 values and its NaN
    jumps = np.abs(pieces[1:, 0] - pieces[:-1, -2])  # s'' just right and just left of each inner data point
    jump = (
        f"the Hermite cubics' s'' jumps by up to {num(jumps.max())} (at x = {num(xdata[1 + np.argmax(jumps)])})"
        if jumps.size
        else "one Hermite cubic"
    )
    describe(
        ax,
        f"second derivatives s'' from {ndata} equally spaced points: {jump}; the complete, natural and "
        f"not-a-knot splines' s'' are continuous, the natural spline's 0 at x = {num(a)} and x = {num(b)}",
    )
    return _label(ax, "x", "s''(x)", f"Second derivatives, {ndata} equally spaced points")


def plot_spline_vs_pchip(xdata, ydata, ax=None):
    """Data as circles, the not-a-knot spline and pchip on 201 points."""
    return SplinePchipView(xdata, ax).update(ydata)


def plot_bilinear_error(ndata, ax=None, f=runge2d, square=(0.0, 5.0), ntest=201):
    """Colour map of I - f for bilinear interpolation from an ndata x ndata grid."""
    return BilinearErrorView(ax, f, square, ntest).update(ndata)
