"""The explorers' live pictures (labkit/plots/scene.py): what the browser is sent to draw, at which pixel
ratio, and that every move is drawn at once. Where the browser draws it is tests/browser/test_jupyterlab.py's
(the drawn picture against the static one)."""

import io

import matplotlib

matplotlib.use("Agg")

import numpy as np
import pytest
from PIL import Image

import labkit
from labkit import plots
from labkit.plots.explorers import live_ratio


def _floats(data):
    return np.frombuffer(data, dtype="<f4").reshape(-1, 2)


def _png_pixels(data):
    return np.asarray(Image.open(io.BytesIO(data)).convert("RGB"))


def test_a_curve_is_sent_where_the_axes_put_its_data():
    """The pixels of a curve are the axes' box and limits applied to its data, computed here by hand."""
    explorer = plots.convergence_explorer()
    explorer.controls["ndata"].value = 15
    ax = explorer.figure.axes[0]
    line = explorer.figure.axes[0].get_lines()[[m for m in ("plin", "pherm")].index("pherm")]  # the visible one
    line = next(line for line in ax.get_lines()[:-1] if line.get_visible())
    item = next(i for i in explorer.image.scene["items"] if i["kind"] == "line" and "stroke" in i)
    xy = _floats(item["xy"])
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    box = ax.get_window_extent()
    height = explorer.figure.bbox.height
    x, y = line.get_xdata(), line.get_ydata()
    # the error of Hermite interpolation of Runge's function, from scipy, is the curve the kernel drew
    from scipy.interpolate import CubicHermiteSpline

    xdata = np.linspace(0, 5, 15)
    f, fp = labkit.runge(xdata)
    np.testing.assert_allclose(y, CubicHermiteSpline(xdata, f, fp)(x) - labkit.runge(x)[0], atol=1e-12)
    np.testing.assert_allclose(xy[:, 0], box.x0 + (x - x0) / (x1 - x0) * box.width, atol=1e-3)
    np.testing.assert_allclose(xy[:, 1], height - (box.y0 + (y - y0) / (y1 - y0) * box.height), atol=1e-3)
    assert item["width"] == pytest.approx(line.get_linewidth() * explorer.figure.dpi / 72)
    assert item["stroke"][:3] == [0xD5, 0x5E, 0x00] and item["dashes"]  # Hermite: vermillion, dashed


def test_the_title_is_sent_as_text_where_matplotlib_draws_it():
    explorer = plots.limacon_explorer()
    explorer.controls["intervals"].value = 9
    title = explorer.figure.axes[0].title
    item = next(i for i in explorer.image.scene["items"] if i["kind"] == "text")
    assert item["text"] == title.get_text() == "limaçon r = 1.15 + cos t, 9 intervals"
    renderer = explorer.figure.canvas.get_renderer()
    box = title.get_window_extent(renderer)
    height = explorer.figure.bbox.height
    assert item["align"] == "center" and item["x"] == pytest.approx((box.x0 + box.x1) / 2, abs=1)
    assert height - box.y1 < item["y"] < height - box.y0  # the baseline lies inside the text's box
    assert f"{12 * explorer.figure.dpi / 72:.2f}px" in item["font"] and "DejaVu Sans" in item["font"]


def test_the_background_leaves_out_what_the_scene_draws():
    """The background is the static picture without the changing artists: the same pixels where none is."""
    explorer = plots.pchip_explorer()
    background, static = _png_pixels(explorer.image.background), _png_pixels(explorer.png())
    assert background.shape == static.shape
    differ = np.any(background != static, axis=2)
    assert 0.001 < differ.mean() < 0.2  # the curves and the data only
    ax = explorer.figure.axes[0]
    box = ax.get_window_extent()
    rows, cols = np.nonzero(differ)
    height = explorer.figure.bbox.height
    assert box.x0 - 8 <= cols.min() and cols.max() <= box.x1 + 8  # inside the axes (markers spill a little)
    assert height - box.y1 - 8 <= rows.min() and rows.max() <= height - box.y0 + 8


def test_the_colour_map_is_sent_as_its_colours_and_the_colour_bar_as_its_axis():
    explorer = plots.bilinear_explorer()
    explorer.controls["ndata"].value = 5
    view = explorer.scene.view
    items = explorer.image.scene["items"]
    image = next(i for i in items if i["kind"] == "image")
    width, height = image["size"]
    rgba = np.frombuffer(image["rgba"], dtype=np.uint8).reshape(height, width, 4)
    error = view.image.get_array()  # (y, x): row 0 at the bottom (origin="lower")
    expected = (matplotlib.colormaps["coolwarm"](view.image.norm(error), bytes=True))[::-1]
    assert np.array_equal(rgba, expected) and (width, height) == (161, 161)
    labels = [i["text"] for i in items if i["kind"] == "text"]
    low, high = view.image.get_clim()
    axis = view.colorbar.ax.yaxis
    ticks = {t.get_text() for t, at in zip(axis.get_ticklabels(), axis.get_ticklocs()) if low <= at <= high}
    assert len(ticks) >= 3 and ticks <= set(labels) and "I(x, y) - f(x, y)" in labels


@pytest.mark.parametrize("ratio", [1, 1.5, 3])
def test_the_live_picture_follows_the_pages_pixel_ratio_and_the_static_one_stays_2x(ratio):
    explorer = plots.spline_explorer()
    css = explorer.css_size()
    static = explorer.png()
    explorer.image.pixel_ratio = ratio  # what image.js reports
    scene = explorer.image.scene
    assert (
        tuple(scene["size"])
        == (round(css[0] * ratio), round(css[1] * ratio))
        == _png_pixels(explorer.image.background).shape[1::-1]
    )
    assert explorer.css_size() == css and scene["ratio"] == ratio
    line = next(i for i in scene["items"] if i["kind"] == "line" and "stroke" in i)
    assert line["width"] == pytest.approx(1.5 * 80 * ratio / 72)  # 1.5 points at 80 CSS px an inch
    assert explorer.png() == static  # the static picture is the 2x one whatever the page
    editor = plots.patch_editor()
    editor.widget_.pixel_ratio = ratio
    assert tuple(editor.widget_.scene["size"]) == (round(400 * ratio), round(400 * ratio))
    assert editor.widget_.frame["width"] == 400  # the handles are placed in CSS pixels


def test_a_pixel_ratio_is_taken_between_1_and_4_in_quarters():
    assert [live_ratio(v) for v in (2, 1, 0.5, 1.1, 1.25, 2.6, 10)] == [2, 1, 1, 1.25, 1.25, 2.75, 4]
    assert [live_ratio(v) for v in (None, "big", float("nan"), -1, 0)] == [2.0] * 5


def test_every_move_the_kernel_gets_is_drawn_at_once_with_its_values_and_nothing_waits_for_the_browser():
    explorer = plots.pchip_explorer()
    slider = explorer.controls["y1"]
    sent = []
    explorer.image.observe(lambda change: sent.append(change["new"]["seq"]), names="scene")
    for value in (1.1, 1.2, 1.3):  # no browser has said anything: each move is drawn and sent at once
        slider.value = value
        data = explorer.figure.axes[0].get_lines()[2]
        assert data.get_ydata()[1] == value and f"(1, {value:g})" in explorer.image.description
    assert sent == [2, 3, 4] and explorer.redraws == 4
    # the picture's widget has no trait the browser would have to send back for the next move to be drawn
    synced = explorer.image.keys
    assert "shown" not in synced and set(synced) >= {"background", "scene", "pixel_ratio", "description"}


def test_the_limacons_legend_is_an_overlay_between_the_exact_curve_and_the_interpolant():
    """The exact curve changes with r0, so it is drawn live; the legend, which lay over it in the background,
    comes as an overlay with its transparency, drawn after it and before the interpolant and the data (the
    order of the static picture)."""
    explorer = plots.limacon_explorer()
    sent = []
    explorer.image.observe(lambda change: sent.append(change["new"]), names="overlays")
    explorer.controls["r0"].value = 1.2
    items = explorer.image.scene["items"]
    kinds = [item["kind"] for item in items]
    overlay = items[kinds.index("overlay")]
    strokes = [item for item in items if item["kind"] == "line"]
    assert kinds.index("overlay") == 1 and kinds[0] == "line" and kinds[2:4] == ["line", "line"]
    assert strokes[0]["width"] > strokes[1]["width"]  # the exact curve (3 pt) first, then the interpolant
    overlay = explorer.image.overlays[overlay["id"]]  # its pixels travel in a trait of their own
    w, h = overlay["box"][2:]
    rgba = np.frombuffer(overlay["rgba"], dtype=np.uint8).reshape(h, w, 4)
    legend = explorer.figure.axes[0].get_legend().get_window_extent()
    assert abs(overlay["box"][0] - legend.x0) <= 3 and abs(w - legend.width) <= 6  # its box, 2 px round it
    alphas = set(np.unique(rgba[..., 3]))
    assert 0 in alphas and 255 in alphas and any(0 < a < 255 for a in alphas)  # clear around, the frame see-through
    # the legend's pixels crossed once; moves that keep the axes send only the overlay's name
    count = len(sent)
    for intervals in (12, 14, 16):
        explorer.controls["intervals"].value = intervals
    assert len(sent) == count and "overlay" in [item["kind"] for item in explorer.image.scene["items"]]
    explorer.controls["method"].value = "plin"  # a new legend: new pixels, and the old ones dropped
    assert len(sent) == count + 1 and len(explorer.image.overlays) == 1
