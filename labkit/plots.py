"""Figures of the lab, shared by the notebooks and tested in tests/test_plots.py.

Every function draws into the axes it is given (or a new figure's), labels
its axes, sets a title and returns the axes, so a notebook cell (or a
slider callback) is one call.
"""
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.collections import PolyCollection

from .bilinear import eval_pbilin
from .convergence import METHOD_TITLES, _interpolate
from .functions import limacon, runge, runge2d
from .mesh import quad_mesh
from .monotone import pchip
from .patches import patch
from .piecewise import eval_pherm, eval_plin
from .splines import spline


def _axes(ax, size=(5, 5)):
    if ax is None:
        _, ax = plt.subplots(figsize=size)
    return ax


def _label(ax, xlabel, ylabel, title):
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    return ax


def draw_mesh(mesh, ax=None, color_by_quality=False, title=None, **line_kw):
    """Draw a QuadMesh's element edges (x-y plane); fill by quality if asked."""
    ax = _axes(ax)
    polygons = mesh.points[mesh.quads][..., :2]
    style = {"edgecolor": "tab:blue", "linewidth": 0.8, **line_kw}
    if color_by_quality:
        cells = PolyCollection(polygons, array=mesh.quality(), cmap="RdYlGn", clim=(-1, 1), **style)
        ax.add_collection(cells)
        ax.figure.colorbar(cells, ax=ax, label="quality (min scaled Jacobian)", shrink=0.8)
    else:
        ax.add_collection(PolyCollection(polygons, facecolor="none", **style))
    ax.autoscale_view()
    ax.set_aspect("equal")
    return _label(ax, "x", "y", title or f"{len(mesh.quads)} quadrilaterals")


def plot_patch(corners, ns=11, nt=11, ax=None, color_by_quality=False, title=None, s=None, t=None):
    """Mesh a Coons patch on an ns x nt grid (or given s, t) and draw it; return the axes."""
    s = np.linspace(0, 1, ns) if s is None else s
    t = np.linspace(0, 1, nt) if t is None else t
    mesh = quad_mesh(*patch(*corners, s, t))
    title = title or f"{len(s) - 1} x {len(t) - 1} elements, worst quality {mesh.quality().min():.2f}"
    return draw_mesh(mesh, ax=ax, color_by_quality=color_by_quality, title=title)


def plot_limacon(nintervals=20, r0=1.15, method="pherm", ax=None):
    """Interpolate the limaçon from nintervals+1 points with 'plin' or 'pherm' and draw it."""
    if method not in ("plin", "pherm"):
        raise ValueError("method must be 'plin' (piecewise linear) or 'pherm' (Hermite).")
    ax = _axes(ax)
    tdata = np.linspace(0, 2 * np.pi, nintervals + 1)
    xdata, ydata, xpdata, ypdata = limacon(tdata, r0)
    tval = np.linspace(0, 2 * np.pi, 10 * (nintervals + 1))
    if method == "plin":
        xval, yval = eval_plin(tdata, xdata, tval), eval_plin(tdata, ydata, tval)
    else:
        xval, yval = eval_pherm(tdata, xdata, xpdata, tval), eval_pherm(tdata, ydata, ypdata, tval)
    exact = limacon(np.linspace(0, 2 * np.pi, 2001), r0)
    ax.plot(exact[0], exact[1], color="0.75", lw=3, label="exact")
    ax.plot(xval, yval, color="tab:blue", label=METHOD_TITLES[method].lower())
    ax.plot(xdata, ydata, "o", color="tab:red", ms=4, label="data")
    ax.set_aspect("equal")
    ax.legend(loc="upper right", fontsize="small")
    return _label(ax, "x", "y", f"limaçon r = {r0:g} + cos t, {nintervals} intervals")


def plot_convergence(tables, ax=None):
    """Log-log plot of error against number of data for ConvergenceTables, with slopes -2 and -4."""
    ax = _axes(ax, size=(6, 4.5))
    for table in tables:
        ax.loglog(table.ndata, table.errors, "o-", ms=4, label=f"{table.title.split(', ')[-1]} (order {table.order})")
    n = np.array([tables[0].ndata[2], tables[0].ndata[-1]], dtype=float)
    for order, style in ((2, "k--"), (4, "k:")):
        anchor = min(t.errors[2] for t in tables)
        ax.loglog(n, anchor * (n / n[0]) ** -order, style, lw=1, label=f"slope -{order}")
    ax.legend(fontsize="small")
    return _label(ax, "number of data points", "relative max error", "Convergence on the Runge function")


def plot_interpolation_error(methods, ndata, ax=None, f=runge, interval=(0.0, 5.0)):
    """Pointwise error p - f of each method with ndata equally spaced points."""
    ax = _axes(ax, size=(6, 4))
    a, b = interval
    x = np.linspace(a, b, 1001)
    exact = f(x)[0]
    for method in methods:
        ax.plot(x, _interpolate(method, f, a, b, ndata, x) - exact, label=METHOD_TITLES[method])
    ax.plot(np.linspace(a, b, ndata), np.zeros(ndata), "k.", ms=4, label="data points")
    ax.ticklabel_format(axis="y", style="sci", scilimits=(-2, 2))
    ax.legend(fontsize="small")
    return _label(ax, "x", "p(x) - f(x)", f"Interpolation error, {ndata} equally spaced points")


def plot_spline_vs_pchip(xdata, ydata, ax=None):
    """Data as circles, the not-a-knot spline and pchip on at least 200 points."""
    ax = _axes(ax, size=(6, 4))
    xv = np.linspace(xdata[0], xdata[-1], 201)
    ax.plot(xv, spline(xdata, ydata, xv), label="not-a-knot spline")
    ax.plot(xv, pchip(xdata, ydata, xv), label="pchip")
    ax.plot(xdata, ydata, "o", mfc="none", color="k", label="data")
    ax.legend(fontsize="small")
    return _label(ax, "time", "temperature", "Spline overshoots, pchip keeps the data's shape")


def plot_bilinear_error(ndata, ax=None, f=runge2d, square=(0.0, 5.0), ntest=201):
    """Colour map of I - f for bilinear interpolation from an ndata x ndata grid."""
    ax = _axes(ax, size=(5.5, 4.5))
    a, b = square
    grid, test = np.linspace(a, b, ndata), np.linspace(a, b, ntest)
    X, Y = np.meshgrid(test, test, indexing="ij")
    error = eval_pbilin(f, grid, grid, test, test) - f(X, Y)
    image = ax.pcolormesh(test, test, error.T, cmap="coolwarm", shading="auto")
    ax.figure.colorbar(image, ax=ax, label="I(x, y) - f(x, y)")
    ax.set_aspect("equal")
    return _label(ax, "x", "y", f"Bilinear error, {ndata} x {ndata} data, max {np.abs(error).max():.1e}")
