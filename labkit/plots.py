"""Figures of the lab, shared by the notebooks and tested in tests/test_plots.py.

Every function draws into the axes it is given (or a new figure's), labels
the axes, sets a title and returns the axes.
"""
import matplotlib.pyplot as plt
import numpy as np
from matplotlib.collections import PolyCollection


def _axes(ax):
    if ax is None:
        _, ax = plt.subplots(figsize=(5, 5))
    return ax


def draw_mesh(mesh, ax=None, color_by_quality=False, title=None, **line_kw):
    """Draw a QuadMesh's element edges (x-y plane); fill by quality if asked."""
    ax = _axes(ax)
    polygons = mesh.points[mesh.quads][..., :2]
    style = {"edgecolor": "tab:blue", "linewidth": 0.8, **line_kw}
    if color_by_quality:
        cells = PolyCollection(polygons, array=mesh.quality(), cmap="RdYlGn", clim=(-1, 1), **style)
        ax.add_collection(cells)
        ax.figure.colorbar(cells, ax=ax, label="element quality (min scaled Jacobian)", shrink=0.8)
    else:
        ax.add_collection(PolyCollection(polygons, facecolor="none", **style))
    ax.autoscale_view()
    ax.set_aspect("equal")
    ax.set_xlabel("x")
    ax.set_ylabel("y")
    ax.set_title(title or f"{len(mesh.quads)} quadrilaterals")
    return ax
