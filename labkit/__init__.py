"""labkit: the interpolation lab's methods, meshes and figures in Python.

Everything a notebook needs is importable from here, e.g.
``from labkit import eval_pherm, ccspline, convergence_table``.

``import labkit`` loads the interpolation library only. The students'
self-checks (:mod:`labkit.check`) and the figures (:mod:`labkit.plots`)
load when first used, as ``labkit.check`` and ``labkit.plots``; so does
``labkit.ready_to_hand_in`` (:mod:`labkit.handin`), every notebook's last cell.
"""

import importlib

from .bilinear import eval_pbilin
from .convergence import ConvergenceTable, bilinear_convergence, convergence_table, ratio_table
from .functions import limacon, runge, runge2d
from .mesh import QuadMesh, quad_mesh
from .monotone import pchip, pchip_slopes
from .notebook import ready
from .patches import Corner, patch
from .piecewise import bracket, eval_pherm, eval_plin, hermite_basis
from .splines import ccspline, nakspline, ncspline, spline

__all__ = [
    "ConvergenceTable",
    "Corner",
    "QuadMesh",
    "bilinear_convergence",
    "eval_pbilin",
    "patch",
    "quad_mesh",
    "bracket",
    "ccspline",
    "convergence_table",
    "eval_pherm",
    "eval_plin",
    "hermite_basis",
    "limacon",
    "nakspline",
    "ncspline",
    "pchip",
    "pchip_slopes",
    "ratio_table",
    "ready",
    "ready_to_hand_in",
    "runge",
    "runge2d",
    "spline",
]

_LAZY = ("check", "plots", "exercises", "grading", "handin")


def __getattr__(name):
    if name in _LAZY:
        return importlib.import_module(f".{name}", __name__)
    if name == "ready_to_hand_in":  # the notebooks' last cell: loads the self-checks, so only when called
        return importlib.import_module(".handin", __name__).ready_to_hand_in
    raise AttributeError(f"module 'labkit' has no attribute {name!r}")


def __dir__():
    return sorted(list(globals()) + list(_LAZY) + ["ready_to_hand_in"])
