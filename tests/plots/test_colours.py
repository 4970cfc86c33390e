"""No labkit figure tells its series (or the ends of a colour map) apart by red versus green alone.

Every figure labkit draws is built here with the Agg backend; what a reader
with a colour-vision deficiency sees is simulated with the matrices of Machado,
Oliveira & Fernandes (2009, "A physiologically-based model for simulation of
color vision deficiency", severity 1.0) applied in linear RGB, and compared in
CIELAB (ΔE*ab, 1976). Two series of one axes must differ in line style or
marker, or stay at least ``MIN_DELTA_E`` apart under protanopia and
deuteranopia (red-green blindness, about 1 in 12 men); two values of a colour
map at least half its range apart likewise.
"""

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import pytest
from matplotlib import colors

import labkit
from labkit import plots

MACHADO = {
    "protan": np.array(
        [[0.152286, 1.052583, -0.204868], [0.114503, 0.786281, 0.099216], [-0.003882, -0.048116, 1.051998]]
    ),
    "deutan": np.array(
        [[0.367322, 0.860646, -0.227968], [0.280085, 0.672501, 0.047413], [-0.011820, 0.042940, 0.968881]]
    ),
    "tritan": np.array(
        [[1.255528, -0.076749, -0.178779], [-0.078411, 0.930809, 0.147602], [0.004733, 0.691367, 0.303900]]
    ),
}
RED_GREEN = ("protan", "deutan")
MIN_DELTA_E = 20.0  # CIELAB distance: tab:orange and tab:green are 4.6 apart for a protanope, 101 for others
SRGB_TO_XYZ = np.array([[0.4124, 0.3576, 0.1805], [0.2126, 0.7152, 0.0722], [0.0193, 0.1192, 0.9505]])
WHITE = np.array([0.95047, 1.0, 1.08883])  # D65


def _linear(rgb):
    rgb = np.asarray(rgb, dtype=float)
    return np.where(rgb <= 0.04045, rgb / 12.92, ((rgb + 0.055) / 1.055) ** 2.4)


def _lab(linear_rgb):
    xyz = linear_rgb @ SRGB_TO_XYZ.T / WHITE
    delta = 6 / 29
    f = np.where(xyz > delta**3, np.cbrt(np.maximum(xyz, 0)), xyz / (3 * delta**2) + 4 / 29)
    return np.stack((116 * f[..., 1] - 16, 500 * (f[..., 0] - f[..., 1]), 200 * (f[..., 1] - f[..., 2])), axis=-1)


def seen(colours, deficiency=None):
    """CIELAB of `colours` (anything matplotlib reads) as seen with `deficiency` (None: normal vision)."""
    rgb = _linear(colors.to_rgba_array(colours)[:, :3])
    if deficiency is not None:
        rgb = np.clip(rgb @ MACHADO[deficiency].T, 0.0, 1.0)
    return _lab(rgb)


def delta_e(first, second, deficiency=None):
    return float(np.linalg.norm(seen(first, deficiency) - seen(second, deficiency), axis=-1).max())


def test_the_simulation_confuses_red_and_green_but_keeps_grey_and_blue_yellow():
    assert delta_e("tab:red", "tab:green") > 100
    assert delta_e("tab:red", "tab:green", "deutan") < 10
    assert delta_e("tab:orange", "tab:green", "protan") < 10
    for deficiency in MACHADO:
        np.testing.assert_allclose(seen("0.5", deficiency), seen("0.5"), atol=0.5)  # a grey stays that grey
        np.testing.assert_allclose(MACHADO[deficiency].sum(axis=1), 1.0, atol=1e-3)
    assert min(delta_e("#0072B2", "#E69F00", d) for d in MACHADO) > 60  # Okabe–Ito's blue and orange


# -- every figure labkit draws ------------------------------------------------------------------

SQUARE = [labkit.Corner(p, [1.0, 0.0], [0.0, 1.0]) for p in ([0, 0], [1, 0], [1, 1], [0, 1])]
FOLDED = [
    SQUARE[0],
    labkit.Corner([1, 0], [-1.5, 0], [0, 1]),
    labkit.Corner([1, 1], [-1.5, 0], [0, 1]),
    SQUARE[3],
]
METHODS = ["plin", "pherm", "complete", "natural", "notaknot", "pchip"]


def _mesh():
    return labkit.quad_mesh(*labkit.patch(*FOLDED, np.linspace(0, 1, 11), np.linspace(0, 1, 4)))


FIGURES = {
    "plot_limacon": lambda: plots.plot_limacon(8).figure,
    "plot_convergence": lambda: (
        plots.plot_convergence([labkit.convergence_table(m, ndata=(5, 11, 21, 41)) for m in METHODS]).figure
    ),
    "plot_interpolation_error": lambda: plots.plot_interpolation_error(METHODS, 11).figure,
    "plot_spline_vs_pchip": lambda: plots.plot_spline_vs_pchip(np.arange(5.0), [0, 1, 2, 2.5, 2]).figure,
    "plot_bilinear_error": lambda: plots.plot_bilinear_error(5, ntest=41).figure,
    "plot_patch": lambda: plots.plot_patch(FOLDED, 11, 4, color_by_quality=True).figure,
    "plot_second_derivatives": lambda: plots.plot_second_derivatives(7).figure,
    "draw_mesh": lambda: plots.draw_mesh(_mesh(), color_by_quality=True).figure,
    "QuadMesh.plot": lambda: _mesh().plot(color_by_quality=True).figure,
    "limacon_explorer": lambda: plots.limacon_explorer().figure,
    "convergence_explorer": lambda: plots.convergence_explorer().figure,
    "mesh_explorer": lambda: plots.mesh_explorer().figure,
    "spline_explorer": lambda: plots.spline_explorer().figure,
    "pchip_explorer": lambda: plots.pchip_explorer().figure,
    "bilinear_explorer": lambda: plots.bilinear_explorer().figure,
    "patch_editor": lambda: plots.patch_editor(FOLDED).figure,
}


@pytest.fixture(autouse=True)
def close_figures():
    yield
    plt.close("all")


def test_every_figure_function_of_labkit_plots_is_checked():
    drawing = {name for name in plots.__all__ if name.startswith(("plot_", "draw_")) or name.endswith("_explorer")}
    drawing.add("patch_editor")
    assert drawing <= set(FIGURES), drawing - set(FIGURES)


def _series(ax):
    """The visible lines of `ax` that a reader tells apart: (label, colours, line style, marker)."""
    series = []
    for line in ax.get_lines():
        if not line.get_visible() or len(line.get_xdata()) == 0:
            continue
        marker = line.get_marker() if line.get_marker() not in ("None", "", " ", None) else None
        style = line.get_linestyle() if line.get_linestyle() not in ("None", "", " ") else None
        painted = [c for c in (line.get_color(), line.get_markerfacecolor() if marker else None) if c is not None]
        painted = [c for c in painted if colors.to_rgba(c)[3] > 0]
        series.append((line.get_label(), painted, style, marker))
    return series


def _same_but_colour(first, second):
    return first[2] == second[2] and first[3] == second[3]


def _told_apart(first, second, deficiency):
    return all(delta_e(a, b, deficiency) >= MIN_DELTA_E for a in first[1] for b in second[1])


def _confused_series(figure):
    confused = []
    for ax in figure.axes:
        series = _series(ax)
        for k, first in enumerate(series):
            for second in series[k + 1 :]:
                for deficiency in RED_GREEN:
                    if _same_but_colour(first, second) and not _told_apart(first, second, deficiency):
                        confused.append((first[0], second[0], deficiency))
    return confused


def _colour_maps(figure):
    """The colour maps of the figure's mapped artists (filled meshes, images), with their ranges."""
    for ax in figure.axes:
        for artist in [*ax.collections, *ax.images]:
            if artist.get_array() is not None and artist.get_cmap() is not None:
                yield artist.get_cmap(), artist.norm


def _confused_map_values(cmap, deficiency):
    values = np.linspace(0.0, 1.0, 11)
    lab = seen(cmap(values), deficiency)
    return [
        (round(values[i], 1), round(values[j], 1))
        for i in range(len(values))
        for j in range(i + 1, len(values))
        if values[j] - values[i] >= 0.5 - 1e-9 and np.linalg.norm(lab[i] - lab[j]) < MIN_DELTA_E
    ]


@pytest.mark.parametrize("name", FIGURES)
def test_no_two_series_differ_by_red_versus_green_alone(name):
    figure = FIGURES[name]()
    assert not _confused_series(figure), _confused_series(figure)


@pytest.mark.parametrize("name", FIGURES)
def test_colour_maps_read_in_red_green_colour_blindness(name):
    figure = FIGURES[name]()
    for cmap, _ in _colour_maps(figure):
        for deficiency in RED_GREEN:
            assert not _confused_map_values(cmap, deficiency), (cmap.name, deficiency)


def test_the_checks_catch_red_versus_green():
    figure, ax = plt.subplots()
    ax.plot([0, 1], [0, 1], color="tab:orange", label="one")
    ax.plot([0, 1], [1, 0], color="tab:green", label="two")
    assert _confused_series(figure) == [("one", "two", "protan")]  # 4.6 apart for a protanope, 32 for a deuteranope
    ax.get_lines()[1].set_linestyle("--")  # a second cue: fine
    assert not _confused_series(figure)
    assert _confused_map_values(matplotlib.colormaps["RdYlGn"], "protan")
    assert not _confused_map_values(matplotlib.colormaps["cividis"], "protan")


def test_folded_elements_are_marked_by_more_than_colour():
    from matplotlib.collections import PolyCollection

    mesh = _mesh()
    ax = mesh.plot(color_by_quality=True)
    hatched = [c for c in ax.collections if isinstance(c, PolyCollection) and c.get_hatch()]
    assert len(hatched) == 1 and len(hatched[0].get_paths()) == int(np.sum(mesh.quality() <= 0)) > 0
    for path, quad in zip(hatched[0].get_paths(), mesh.points[mesh.quads][mesh.quality() <= 0]):
        np.testing.assert_allclose(path.vertices[:4], quad[:, :2])
    legend = ax.get_legend()
    assert legend is not None and "folded" in legend.get_texts()[0].get_text()
    assert "hatched" in legend.get_texts()[0].get_text() and legend.legend_handles[0].get_hatch()


def test_folds_follow_the_explorer_and_a_blit_draws_the_hatching():
    explorer = plots.mesh_explorer()
    view_hatch = [c for c in explorer.figure.axes[0].collections if c.get_hatch()]
    assert len(view_hatch) == 1 and len(view_hatch[0].get_paths()) == 0  # nothing folded at first
    explorer.controls["dxds_BC"].value = -1.5
    assert len(view_hatch[0].get_paths()) > 0
    assert view_hatch[0] in explorer.painter.view.dynamic()
