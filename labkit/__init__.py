"""labkit: the interpolation lab's methods, meshes and figures in Python.

Everything a notebook needs is importable from here, e.g.
``from labkit import eval_pherm, ccspline, convergence_table``.
"""
from .convergence import ConvergenceTable, convergence_table
from .functions import runge, runge2d
from .monotone import pchip, pchip_slopes
from .piecewise import bracket, eval_pherm, eval_plin, hermite_basis
from .splines import ccspline, nakspline, ncspline, spline

__all__ = [
    "ConvergenceTable",
    "bracket",
    "ccspline",
    "convergence_table",
    "eval_pherm",
    "eval_plin",
    "hermite_basis",
    "nakspline",
    "ncspline",
    "pchip",
    "pchip_slopes",
    "runge",
    "runge2d",
    "spline",
]
