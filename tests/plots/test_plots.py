"""Each figure of the notebooks: labelled, titled, and drawing the right data."""

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import pytest

import labkit
from labkit import plots
from labkit.plots.explorers import NotShown

ROOT = __import__("pathlib").Path(__file__).resolve().parents[2]


@pytest.fixture(autouse=True)
def close_figures():
    yield
    plt.close("all")


def _labelled(ax):
    assert ax.get_title() and ax.get_xlabel() and ax.get_ylabel()


@pytest.mark.parametrize("method", ["plin", "pherm"])
def test_limacon_draws_the_interpolant_of_the_sampled_curve(method):
    ax = plots.plot_limacon(nintervals=8, r0=1.3, method=method)
    _labelled(ax)
    assert ax.get_aspect() == 1.0
    exact, curve, data = ax.get_lines()
    tdata = np.linspace(0, 2 * np.pi, 9)
    x, y, xp, yp = labkit.limacon(tdata, 1.3)
    np.testing.assert_allclose(data.get_xydata(), np.column_stack((x, y)))
    tval = np.linspace(0, 2 * np.pi, 90)
    expected_x = labkit.eval_plin(tdata, x, tval) if method == "plin" else labkit.eval_pherm(tdata, x, xp, tval)
    np.testing.assert_allclose(curve.get_xdata(), expected_x)
    # the exact curve closes on itself
    np.testing.assert_allclose(exact.get_xydata()[0], exact.get_xydata()[-1], atol=1e-12)


def test_limacon_rejects_other_methods():
    with pytest.raises(ValueError, match="'plin'.*'pherm'"):
        plots.plot_limacon(method="spline")


def test_convergence_plot_has_a_line_per_table_and_reference_slopes():
    tables = [labkit.convergence_table(m, ndata=(5, 11, 21, 41)) for m in ("plin", "pherm")]
    assert len(plots.plot_convergence(tables).get_lines()) == 2  # no guide lines unless asked for (issue 47)
    ax = plots.plot_convergence(tables, slopes=(2, 4))
    _labelled(ax)
    lines = ax.get_lines()
    assert len(lines) == 4 and ax.get_xscale() == "log" and ax.get_yscale() == "log"
    np.testing.assert_allclose(lines[1].get_ydata(), tables[1].errors)
    for line, order in zip(lines[2:], (2, 4)):
        x, y = line.get_xdata(), line.get_ydata()
        assert np.log(y[1] / y[0]) / np.log(x[1] / x[0]) == pytest.approx(-order)


def test_interpolation_error_curve_is_p_minus_f():
    ax = plots.plot_interpolation_error(["natural", "notaknot"], 9)
    _labelled(ax)
    natural = ax.get_lines()[0]
    x = natural.get_xdata()
    xdata = np.linspace(0, 5, 9)
    ydata = labkit.runge(xdata)[0]
    expected = labkit.eval_pherm(xdata, ydata, labkit.ncspline(xdata, ydata), x) - labkit.runge(x)[0]
    np.testing.assert_allclose(natural.get_ydata(), expected, atol=1e-15)


def test_spline_vs_pchip_shows_both_interpolants_and_the_data():
    x, y = np.arange(5.0), np.array([0, 1, 2, 2, 2.0])
    ax = plots.plot_spline_vs_pchip(x, y)
    _labelled(ax)
    spline_line, pchip_line, data = ax.get_lines()
    assert len(spline_line.get_xdata()) >= 100
    np.testing.assert_allclose(pchip_line.get_ydata(), labkit.pchip(x, y, pchip_line.get_xdata()))
    np.testing.assert_allclose(spline_line.get_ydata(), labkit.spline(x, y, spline_line.get_xdata()))
    assert data.get_linestyle() == "None"


def test_bilinear_error_map_is_interpolant_minus_function():
    ax = plots.plot_bilinear_error(5, ntest=21)
    _labelled(ax)
    test = np.linspace(0, 5, 21)
    X, Y = np.meshgrid(test, test, indexing="ij")
    expected = labkit.eval_pbilin(
        labkit.runge2d, np.linspace(0, 5, 5), np.linspace(0, 5, 5), test, test
    ) - labkit.runge2d(X, Y)
    image = ax.images[0]
    np.testing.assert_allclose(image.get_array(), expected.T)  # row j is y = test[j], from the bottom
    assert image.origin == "lower" and image.get_extent()[0] < 0 < 5 < image.get_extent()[1]


def test_plot_patch_titles_with_the_worst_quality_and_colours_folds():
    e1, e2 = [1, 0], [0, 1]
    corners = [
        labkit.Corner([0, 0], e1, e2),
        labkit.Corner([1, 0], [-1.5, 0], e2),
        labkit.Corner([1, 1], [-1.5, 0], e2),
        labkit.Corner([0, 1], e1, e2),
    ]
    ax = plots.plot_patch(corners, ns=11, nt=3, color_by_quality=True)
    _labelled(ax)
    assert "worst quality -" in ax.get_title()
    assert ax.collections[0].get_array().min() < 0


# -- views updated in place, explorers, the patch editor -----------------------------------------


def test_a_view_updates_its_own_artists_instead_of_drawing_new_ones():
    view = plots.LimaconView()
    view.update(8, 1.3, "pherm")
    lines = view.ax.get_lines()
    view.update(20, 0.8, "plin")
    assert view.ax.get_lines() == lines and len(lines) == 3
    tdata = np.linspace(0, 2 * np.pi, 21)
    x, y, _, _ = labkit.limacon(tdata, 0.8)
    np.testing.assert_allclose(view.data.get_xydata(), np.column_stack((x, y)))
    assert "0.8" in view.ax.get_title() and "20 intervals" in view.ax.get_title()
    # the limits hold the smaller curve, and it fills three quarters of them or more
    for (low, high), values in zip((view.ax.get_xlim(), view.ax.get_ylim()), view.exact.get_data()):
        assert low <= values.min() and values.max() <= high
        assert values.max() - values.min() >= 0.75 * (high - low)


def test_moves_of_r0_keep_the_limaçon_axes_mostly_and_the_curve_always_clear_of_the_frame():
    view = plots.LimaconView()
    view.update(20, 1.15, "pherm")
    keys = [view.static_key()]
    for r0 in np.arange(1.2, 1.56, 0.05):  # the explorer's slider, eight steps up
        view.update(20, round(float(r0), 2), "pherm")
        keys.append(view.static_key())
        x, y = view.exact.get_data()
        np.testing.assert_allclose(x, labkit.limacon(np.linspace(0, 2 * np.pi, 2001), round(float(r0), 2))[0])
        for (low, high), values in zip((view.ax.get_xlim(), view.ax.get_ylim()), (x, y)):
            room = 0.03 * (high - low)
            assert low + room <= values.min() and values.max() <= high - room  # the data's markers clear the frame
    changes = sum(a != b for a, b in zip(keys, keys[1:]))
    assert 1 <= changes <= 2  # the axes grew with the curve, with room to spare: not at every step
    view.update(20, 2.0, "pherm")  # far beyond: new limits around it
    assert view.ax.get_xlim()[1] >= 3.0


def test_error_curves_view_hides_unselected_methods_and_rescales():
    view = plots.ErrorCurvesView(["complete", "natural"])
    view.update(["natural"], 9)
    assert not view.lines["complete"].get_visible() and view.lines["natural"].get_visible()
    low, high = view.ax.get_ylim()
    error = view.lines["natural"].get_ydata()
    assert low <= error.min() and error.max() <= high and high - low < 2 * np.ptp(error)
    view.update(["natural"], 10)  # a small change keeps the axis still, the curve still inside
    assert view.ax.get_ylim() == (low, high)
    error = view.lines["natural"].get_ydata()
    assert low <= error.min() and error.max() <= high
    view.update(["natural"], 41)  # a curve four times smaller: the axis follows it
    error = view.lines["natural"].get_ydata()
    low, high = view.ax.get_ylim()
    assert high - low < 2 * np.ptp(error)


def test_patch_view_moves_the_same_collection_and_recolours_folds():
    e1, e2 = [1, 0], [0, 1]
    square = [labkit.Corner(p, e1, e2) for p in ([0, 0], [1, 0], [1, 1], [0, 1])]
    view = plots.PatchView()
    view.update(square, 5, 5)
    cells = view.ax.collections[0]
    folded = [square[0], labkit.Corner([1, 0], [-1.5, 0], e2), labkit.Corner([1, 1], [-1.5, 0], e2), square[3]]
    view.update(folded, 11, 3)
    assert view.ax.collections[0] is cells and len(cells.get_paths()) == 10 * 2
    np.testing.assert_allclose(cells.get_array(), view.mesh.quality())
    assert cells.get_array().min() < 0 and "worst quality -" in view.ax.get_title()


def _png_size(data):
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    return int.from_bytes(data[16:20], "big"), int.from_bytes(data[20:24], "big")


@pytest.mark.parametrize(
    "factory, control, value",
    [
        (plots.limacon_explorer, "intervals", 7),
        (plots.convergence_explorer, "ndata", 21),
        (plots.mesh_explorer, "dxds_BC", -1.0),
        (plots.spline_explorer, "natural", False),
        (plots.pchip_explorer, "y3", 2.5),
        (plots.bilinear_explorer, "ndata", 5),
    ],
)
def test_every_explorer_redraws_while_dragged_and_sends_a_new_picture(factory, control, value):
    explorer = factory()
    sliders = [c for c in explorer.controls.values() if hasattr(c, "continuous_update")]
    assert sliders and all(c.continuous_update for c in sliders)
    before, redraws = explorer.image.scene, explorer.redraws
    explorer.controls[control].value = value
    scene = explorer.image.scene
    assert explorer.redraws == redraws + 1 and scene["seq"] == before["seq"] + 1 and scene["items"] != before["items"]
    size = tuple(int(v) for v in explorer.figure.canvas.get_width_height())
    assert tuple(scene["size"]) == size == _png_size(explorer.image.background)  # drawn over it, pixel for pixel
    bundle, metadata = explorer._repr_mimebundle_()
    assert "application/vnd.jupyter.widget-view+json" in bundle and "interactive" not in bundle["text/plain"]
    width, height = _png_size(__import__("base64").b64decode(bundle["image/png"]))
    # the static copy is the 2x picture, shown at its CSS size, with the figure's description as alt text
    assert (metadata["image/png"]["width"], metadata["image/png"]["height"]) == (width // 2, height // 2)
    assert width // 2 > 100 and metadata["image/png"]["alt"] == explorer.image.description != ""


def test_the_explorer_figure_shows_what_the_controls_say():
    explorer = plots.pchip_explorer()
    explorer.controls["y3"].value = 2.5
    x = np.arange(5.0)
    y = np.array([0.0, explorer.controls["y1"].value, 2.0, 2.5, 2.0])
    spline_line, pchip_line, data = explorer.figure.axes[0].get_lines()
    np.testing.assert_allclose(data.get_ydata(), y)
    np.testing.assert_allclose(pchip_line.get_ydata(), labkit.pchip(x, y, pchip_line.get_xdata()))


def test_no_slider_of_the_kit_waits_for_release():
    sources = [p.read_text() for p in (ROOT / "labkit" / "plots").glob("*.py")]
    sources += [p.read_text() for p in (ROOT / "notebooks").glob("*.ipynb")]
    assert not any("continuous_update=False" in s for s in sources)


def test_mesh_does_not_import_plots():
    import ast

    tree = ast.parse((ROOT / "labkit" / "mesh.py").read_text())
    imported = {node.module for node in ast.walk(tree) if isinstance(node, ast.ImportFrom)}
    imported |= {a.name for node in ast.walk(tree) if isinstance(node, ast.Import) for a in node.names}
    assert not any(name and "plots" in name for name in imported)


SQUARE = [labkit.Corner(p, [1.0, 0.0], [0.0, 1.0]) for p in ([0, 0], [1, 0], [1, 1], [0, 1])]


def test_handles_are_the_corners_and_the_arrow_tips():
    positions = plots.handle_positions(SQUARE, scale=0.5)
    np.testing.assert_allclose(positions[:4], [[0, 0], [1, 0], [1, 1], [0, 1]])
    np.testing.assert_allclose(positions[4:8], positions[:4] + [0.5, 0])
    np.testing.assert_allclose(positions[8:], positions[:4] + [0, 0.5])


def test_the_nearest_handle_within_reach_is_picked():
    positions = plots.handle_positions(SQUARE, scale=0.25)
    assert plots.nearest_handle(positions, [1.02, 0.01], 0.05) == 1
    assert plots.nearest_handle(positions, [1.24, 0.0], 0.05) == 5  # B's d/ds tip
    assert plots.nearest_handle(positions, [0.5, 0.5], 0.05) is None


def test_dragging_a_corner_carries_its_arrows_and_a_tip_sets_its_derivative():
    moved = plots.move_handle(SQUARE, 1, [1.5, -0.5], scale=0.25)
    assert moved[1].point.tolist() == [1.5, -0.5] and moved[1].ds.tolist() == [1.0, 0.0]
    assert moved[0] is SQUARE[0]
    tip = plots.move_handle(SQUARE, 9, [1.0, 0.5], scale=0.25)  # B's d/dt tip
    assert tip[1].dt.tolist() == [0.0, 2.0] and tip[1].point.tolist() == [1.0, 0.0]
    with pytest.raises(ValueError, match="0 to 11"):
        plots.move_handle(SQUARE, 12, [0, 0])


def test_the_readout_is_code_that_rebuilds_the_corners():
    corners = [labkit.Corner([0.1234, -2], [np.pi, 0], [0, 1e-5], [0.5, -0.25])] + SQUARE[1:]
    namespace = {"Corner": labkit.Corner}
    exec(plots.corner_code(corners), namespace)
    for name, corner in zip("ABCD", corners):
        for field in ("point", "ds", "dt", "dsdt"):
            np.testing.assert_allclose(getattr(namespace[name], field), getattr(corner, field), atol=5e-4)
    assert "-0," not in plots.corner_code(corners) and "Corner([0.123, -2], ds=[3.142, 0]" in plots.corner_code(corners)


def test_the_editor_follows_a_drag_and_reports_folds():
    editor = plots.patch_editor(SQUARE, elements=6)
    widget, picture = editor.widget_, editor.widget_.scene
    assert widget.worst == pytest.approx(1.0) and len(widget.handles) == 12
    widget.drag = {"index": 5, "x": 0.6, "y": 0.0, "seq": 1}  # B's d/ds tip dragged back past A
    assert widget.ack == 1  # the browser sends its next position once this one is drawn
    assert editor.corners[1].ds[0] < 0 and widget.worst <= 0 and "folded" in widget.readout
    assert widget.scene["items"] != picture["items"] and widget.scene["seq"] == picture["seq"] + 1
    frame = widget.frame
    assert frame["left"] < frame["right"] <= frame["width"] and frame["x0"] < 0 < 1 < frame["x1"]
    widget.drag = {"index": "nonsense"}
    assert editor.redraws == 2
    editor.twist.value = 0.7
    assert all(c.dsdt.tolist() == [0.7, 0.7] for c in editor.corners)
    assert "dsdt=[0.7, 0.7]" in widget.readout


def test_the_editor_refuses_what_it_cannot_edit():
    with pytest.raises(ValueError, match="four labkit.Corner"):
        plots.patch_editor(SQUARE[:3])
    with pytest.raises(ValueError, match="plane patches"):
        plots.patch_editor([labkit.Corner([0, 0, 0], [1, 0, 0], [0, 1, 0])] * 4)


@pytest.mark.parametrize(
    "factory, control, value",
    [
        (plots.mesh_explorer, "dxds_BC", 0.6),
        (plots.mesh_explorer, "twist", 1.2),
        (plots.limacon_explorer, "intervals", 9),
        (plots.bilinear_explorer, "ndata", 5),
        (plots.spline_explorer, "ndata", 12),
        (plots.convergence_explorer, "ndata", 12),
        (plots.pchip_explorer, "y1", 1.05),
    ],
)
def test_a_blitted_picture_is_the_full_drawing_pixel_for_pixel(factory, control, value):
    import io

    from PIL import Image

    explorer = factory()
    explorer.png()  # the static picture of the first state: drawn in full
    explorer.controls[control].value = value
    blitted = np.asarray(Image.open(io.BytesIO(explorer.png())))
    assert explorer.painter.blitted == 1  # only the changing artists were drawn
    explorer.painter.key = None  # force a full drawing of the same state
    full = np.asarray(Image.open(io.BytesIO(explorer.png())))
    assert np.array_equal(blitted, full)


def test_a_change_of_limits_draws_everything_again():
    explorer = plots.limacon_explorer()
    backgrounds = explorer.scene.backgrounds
    explorer.controls["intervals"].value = 30  # the same limits: the background stays
    assert explorer.scene.backgrounds == backgrounds
    explorer.controls["r0"].value = 1.9  # a bigger curve: new limits, new ticks, a new background
    assert explorer.scene.backgrounds == backgrounds + 1
    x0, x1 = explorer.figure.axes[0].get_xlim()
    assert x1 > 2.8


def test_second_derivative_plot_shows_hermite_jumps_and_c2_splines():
    ax = plots.plot_second_derivatives(7)
    _labelled(ax)
    hermite, complete, natural, notaknot, _ = ax.get_lines()

    def jumps(line):
        pieces = np.split(line.get_ydata(), np.flatnonzero(np.isnan(line.get_ydata())))
        pieces = [p[~np.isnan(p)] for p in pieces if np.any(~np.isnan(p))]
        return np.array([left[-1] - right[0] for left, right in zip(pieces, pieces[1:])])

    assert np.max(np.abs(jumps(hermite))) > 0.05
    for line in (complete, natural, notaknot):
        assert np.max(np.abs(jumps(line))) < 1e-9
    s2 = natural.get_ydata()[~np.isnan(natural.get_ydata())]
    assert abs(s2[0]) < 1e-12 and abs(s2[-1]) < 1e-12
    x = np.linspace(0, 5, 7)
    y, _ = labkit.runge(x)
    np.testing.assert_allclose(
        notaknot.get_ydata()[:40], labkit.spline(x, y, np.linspace(x[0], x[1], 40), der=2), rtol=1e-12, atol=1e-12
    )


def test_every_view_follows_the_written_view_interface_and_a_new_one_needs_only_update():
    import inspect

    import ipywidgets as widgets

    from labkit.plots import explorers, figures

    views = [
        cls
        for _, cls in inspect.getmembers(figures, inspect.isclass)
        if issubclass(cls, figures.View) and cls is not figures.View
    ]
    assert len(views) >= 5
    for cls in views:
        assert cls.update is not figures.View.update, cls  # each view changes its own artists

    class Sine(figures.View):  # a newcomer's view: update only, no blitting
        def __init__(self, ax):
            self.ax = ax
            (self.line,) = ax.plot([], [])
            ax.set_xlim(0, 1)
            ax.set_ylim(-1, 1)

        def update(self, k=1):
            x = np.linspace(0, 1, 50)
            self.line.set_data(x, np.sin(k * x))

    figure, ax = explorers.new_figure((3, 2))
    view = Sine(ax)
    explorer = explorers.Explorer(figure, view.update, {"k": widgets.IntSlider(1, 1, 5)}, view)
    explorer.controls["k"].value = 3
    assert explorer.redraws == 2 and explorer.scene.backgrounds == 2  # nothing dynamic: a new background each move
    assert np.allclose(view.line.get_ydata(), np.sin(3 * np.linspace(0, 1, 50)))
    with pytest.raises(NotImplementedError, match="must define update"):
        figures.View().update(k=1)


@pytest.mark.parametrize(
    "factory",
    [
        plots.limacon_explorer,
        plots.convergence_explorer,
        plots.mesh_explorer,
        plots.spline_explorer,
        plots.pchip_explorer,
        plots.bilinear_explorer,
        lambda: plots.patch_editor(SQUARE, elements=6),
    ],
)
def test_where_nothing_is_shown_an_explorer_draws_no_picture(monkeypatch, factory):
    """The grader's sandbox sets LABKIT_HEADLESS=1: an explorer's call runs (the student's code runs as
    written) but builds and renders nothing; elsewhere it renders at once."""
    monkeypatch.setenv("LABKIT_HEADLESS", "1")
    quiet = factory()
    assert quiet.redraws == 0 and isinstance(quiet, NotShown) and "not built here" in repr(quiet)
    monkeypatch.delenv("LABKIT_HEADLESS")
    shown = factory()
    picture = shown.widget_.background if hasattr(shown, "widget_") else shown.image.background
    assert shown.redraws == 1 and picture[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize("channels", [3, 4])
def test_the_explorers_png_decodes_to_the_very_pixels(channels):
    from io import BytesIO

    from PIL import Image

    from labkit.plots.explorers import encode_png

    pixels = np.random.default_rng(channels).integers(0, 256, size=(37, 53, channels), dtype=np.uint8)
    decoded = Image.open(BytesIO(encode_png(pixels)))
    assert decoded.mode == "RGB" and decoded.size == (53, 37)
    np.testing.assert_array_equal(np.asarray(decoded), pixels[:, :, :3])
    for bad in (pixels.astype(float), pixels[:, :, 0], np.zeros((0, 4, 3), dtype=np.uint8)):
        with pytest.raises(ValueError, match="uint8"):
            encode_png(bad)
