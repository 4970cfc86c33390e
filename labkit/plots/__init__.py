"""Figures of the lab, shared by the notebooks and tested in tests/plots/test_plots.py.

* :mod:`~labkit.plots.figures` - each figure as a view built once and updated in place,
  and the one-call ``plot_*`` functions;
* :mod:`~labkit.plots.explorers` - the Explore sections' sliders (one function per notebook);
* :mod:`~labkit.plots.editor` - the patch editor of exercises 5 to 9 (drag corners and derivatives);
* :mod:`~labkit.plots.labels` - accessible names for the widgets' sliders.
"""

from .editor import corner_code, handle_name, handle_positions, move_handle, nearest_handle, patch_editor, status_text
from .explorers import (
    Explorer,
    bilinear_explorer,
    convergence_explorer,
    limacon_explorer,
    mesh_explorer,
    pchip_explorer,
    spline_explorer,
)
from .figures import (
    BilinearErrorView,
    ErrorCurvesView,
    LimaconView,
    PatchView,
    SplinePchipView,
    draw_mesh,
    plot_bilinear_error,
    plot_convergence,
    plot_interpolation_error,
    plot_limacon,
    plot_patch,
    plot_second_derivatives,
    plot_spline_vs_pchip,
)

__all__ = [
    "BilinearErrorView",
    "ErrorCurvesView",
    "Explorer",
    "LimaconView",
    "PatchView",
    "SplinePchipView",
    "bilinear_explorer",
    "convergence_explorer",
    "corner_code",
    "draw_mesh",
    "handle_name",
    "handle_positions",
    "limacon_explorer",
    "mesh_explorer",
    "move_handle",
    "nearest_handle",
    "patch_editor",
    "pchip_explorer",
    "plot_bilinear_error",
    "plot_convergence",
    "plot_interpolation_error",
    "plot_limacon",
    "plot_patch",
    "plot_second_derivatives",
    "plot_spline_vs_pchip",
    "spline_explorer",
    "status_text",
]
