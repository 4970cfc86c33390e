"""Every picture labkit puts in a notebook says in numbers what it shows: its output's ``alt``.

A notebook is executed in a real kernel with the inline backend (as a student's
is), and each image output's ``metadata["image/png"]["alt"]`` is read and its
numbers compared with what scipy computes from the same data; the explorers'
image widget carries the same text as its ``description`` and follows the
sliders. nbconvert's classic HTML template turns it into ``<img alt=...>``.
"""

import re

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import pytest
from scipy.interpolate import CubicSpline, PchipInterpolator, RegularGridInterpolator

import labkit
from labkit import plots

nbformat = pytest.importorskip("nbformat")
nbclient = pytest.importorskip("nbclient")

NUMBER = r"(-?\d+(?:\.\d+)?(?:e[+-]?\d+)?)"


@pytest.fixture(autouse=True)
def close_figures():
    yield
    plt.close("all")


def runge(x):
    return 1 / (1 + np.asarray(x) ** 2)


def natural_spline_error(ndata):
    """Largest |p - f| of scipy's natural spline of the Runge function on [0, 5] (1001 points), and where."""
    x = np.linspace(0, 5, 1001)
    xdata = np.linspace(0, 5, ndata)
    error = np.abs(CubicSpline(xdata, runge(xdata), bc_type="natural")(x) - runge(x))
    return error.max(), x[np.argmax(error)]


def _largest_at(text, method):
    match = re.search(rf"{method} with (\d+) points: largest {NUMBER} at x = {NUMBER}", text)
    assert match, text
    return int(match[1]), float(match[2]), float(match[3])


CELLS = [
    "%matplotlib inline\nimport numpy as np\nimport matplotlib.pyplot as plt\nimport labkit\nfrom labkit import plots",
    'ax = plots.plot_interpolation_error(["natural"], 19)',
    "ax = plots.plot_bilinear_error(9, ntest=81)",
    "x, y = np.meshgrid(np.linspace(0, 2, 4), np.linspace(-1, 1, 5), indexing='ij')\n"
    "ax = labkit.quad_mesh(x, y).plot(color_by_quality=True)",
    "fig, (left, right) = plt.subplots(1, 2)\n"
    'plots.plot_limacon(8, method="plin", ax=left)\nplots.plot_limacon(8, method="pherm", ax=right);',
    "fig, ax = plt.subplots()\nax.plot([0, 1], [1, 0]);  # a student's own figure: left as it was",
    "%config InlineBackend.figure_formats = ['retina']\nax = plots.plot_interpolation_error(['natural'], 19)",
    "plots.spline_explorer()",
]


@pytest.fixture(scope="module")
def executed(tmp_path_factory):
    nb = nbformat.v4.new_notebook()
    nb.cells = [nbformat.v4.new_code_cell(source) for source in CELLS]
    folder = tmp_path_factory.mktemp("alt")
    nbclient.NotebookClient(
        nb, timeout=120, kernel_name="python3", resources={"metadata": {"path": str(folder)}}
    ).execute()
    return nb


def _pictures(cell):
    return [o for o in cell.outputs if "image/png" in o.get("data", {})]


def _alt(cell):
    (picture,) = _pictures(cell)
    return picture.get("metadata", {}).get("image/png", {}).get("alt")


def test_the_error_plot_says_how_large_the_error_is_and_where(executed):
    ndata, largest, at = _largest_at(_alt(executed.cells[1]), "natural cubic spline")
    expected, where = natural_spline_error(19)
    assert ndata == 19 and largest == pytest.approx(expected, rel=0.06) and at == pytest.approx(where, abs=0.01)


def test_the_bilinear_map_says_its_largest_error_and_where(executed):
    text = _alt(executed.cells[2])
    match = re.search(rf"from 9 x 9 data: largest \|I - f\| {NUMBER} at \(x, y\) = \({NUMBER}, {NUMBER}\)", text)
    assert match, text
    grid = np.linspace(0, 5, 9)
    X, Y = np.meshgrid(grid, grid, indexing="ij")
    interpolant = RegularGridInterpolator((grid, grid), 1 / (1 + (X + Y) ** 2))
    test = np.linspace(0, 5, 81)
    T, S = np.meshgrid(test, test, indexing="ij")
    error = np.abs(interpolant(np.stack((T, S), axis=-1)) - 1 / (1 + (T + S) ** 2))
    i, j = np.unravel_index(np.argmax(error), error.shape)
    assert float(match[1]) == pytest.approx(error.max(), rel=0.06)
    # the Runge function is symmetric in x and y: the largest error may sit at either of two mirror points
    assert sorted((float(match[2]), float(match[3]))) == pytest.approx(sorted((test[i], test[j])), abs=0.01)


def test_a_mesh_says_its_size_and_extent(executed):
    text = _alt(executed.cells[3])
    assert text.startswith("mesh of 12 quadrilaterals, 20 nodes, x from 0 to 2, y from -1 to 1"), text
    assert "worst quality 1.00, none folded" in text  # rectangles: every corner a right angle


def test_a_figure_of_two_labkit_plots_describes_both(executed):
    texts = _alt(executed.cells[4]).split("; ")
    assert len(texts) == 2 and "piecewise linear" in texts[0] and "hermite" in texts[1]
    tdata = np.linspace(0, 2 * np.pi, 9)
    tval = np.linspace(0, 2 * np.pi, 90)

    def curve(t):
        r = 1.15 + np.cos(t)
        return r * np.cos(t), r * np.sin(t)

    x, y = curve(tdata)
    error = np.hypot(np.interp(tval, tdata, x) - curve(tval)[0], np.interp(tval, tdata, y) - curve(tval)[1])
    match = re.search(rf"from 9 points \(8 intervals\): largest error {NUMBER} at t = {NUMBER}", texts[0])
    assert match and float(match[1]) == pytest.approx(error.max(), rel=0.06), texts[0]
    assert float(match[2]) == pytest.approx(tval[np.argmax(error)], abs=0.01)


def test_a_students_own_figure_is_left_alone(executed):
    (picture,) = _pictures(executed.cells[5])
    assert "alt" not in picture.get("metadata", {}).get("image/png", {})


def test_a_retina_figure_keeps_its_size_and_gains_the_alt(executed):
    (picture,) = _pictures(executed.cells[6])
    metadata = picture["metadata"]["image/png"]
    assert metadata["width"] > 0 and metadata["height"] > 0  # the retina printer's own metadata, kept
    assert _largest_at(metadata["alt"], "natural cubic spline")[0] == 19


def test_an_explorers_static_picture_carries_its_description(executed):
    text = _alt(executed.cells[7])
    assert text.count("largest") == 3
    ndata, largest, at = _largest_at(text, "natural cubic spline")
    expected, where = natural_spline_error(ndata)
    assert largest == pytest.approx(expected, rel=0.06) and at == pytest.approx(where, abs=0.01)


def test_nbconvert_writes_the_alt_into_the_page(executed):
    from nbconvert import HTMLExporter

    html, _ = HTMLExporter(template_name="classic").from_notebook_node(executed)
    assert 'alt="error of the natural cubic spline with 19 points: largest' in html


def _img(output):
    """The one <img> of an output's text/html, as its attributes (html.parser decodes the escapes)."""
    from html.parser import HTMLParser

    found = []

    class Images(HTMLParser):
        def handle_starttag(self, tag, attrs):
            if tag == "img":
                found.append(dict(attrs))

    Images().feed(output["data"]["text/html"])
    (img,) = found
    return img


@pytest.mark.parametrize("index", [1, 2, 3, 4, 6, 7])
def test_jupyterlab_gets_the_alt_text_in_an_img_of_the_same_picture(executed, index):
    """JupyterLab ignores metadata's alt: the text/html output (what it shows) is an <img> with that alt."""
    import base64

    (picture,) = _pictures(executed.cells[index])
    img = _img(picture)
    metadata = picture["metadata"]["image/png"]
    assert img["alt"] == metadata["alt"] and any(ch.isdigit() for ch in img["alt"])
    assert img["src"] == "data:image/png;base64," + picture["data"]["image/png"].replace("\n", "")
    assert base64.b64decode(img["src"].split(",", 1)[1])[:8] == b"\x89PNG\r\n\x1a\n"
    if "width" in metadata:  # a 2x picture shows at its CSS size in the <img> too
        assert (int(img["width"]), int(img["height"])) == (metadata["width"], metadata["height"])


def test_a_students_own_figure_gets_no_img_either(executed):
    (picture,) = _pictures(executed.cells[5])
    assert "text/html" not in picture["data"]


def test_the_img_escapes_what_could_end_the_attribute():
    from labkit._alt import img_tag

    tag = img_tag(b"\x89PNG", 'error of "x" < 1 & more')
    assert 'alt="error of &quot;x&quot; &lt; 1 &amp; more"' in tag and tag.count('"') == 4


# -- the explorers: the image widget's description follows the sliders ---------------------------


def test_the_explorer_description_follows_the_slider():
    explorer = plots.convergence_explorer()
    explorer.controls["method"].value = "natural"
    explorer.controls["ndata"].value = 19
    first = explorer.image.description
    ndata, largest, at = _largest_at(first, "natural cubic spline")
    expected, where = natural_spline_error(19)
    assert ndata == 19 and largest == pytest.approx(expected, rel=0.06) and at == pytest.approx(where, abs=0.01)
    explorer.controls["ndata"].value = 41
    ndata, largest, _ = _largest_at(explorer.image.description, "natural cubic spline")
    assert ndata == 41 and largest == pytest.approx(natural_spline_error(41)[0], rel=0.06)
    assert explorer.image.description == explorer.description != first


def test_the_pchip_explorer_says_where_each_curve_goes():
    explorer = plots.pchip_explorer()
    explorer.controls["y1"].value = 2.5
    text = explorer.image.description
    x, y = np.arange(5.0), np.array([0.0, 2.5, 2.0, explorer.controls["y3"].value, 2.0])
    xv = np.linspace(0, 4, 201)
    spline, monotone = CubicSpline(x, y)(xv), PchipInterpolator(x, y)(xv)  # scipy's default: not-a-knot
    match = re.search(rf"spline goes from {NUMBER} to {NUMBER}, pchip from {NUMBER} to {NUMBER}", text)
    assert match, text
    found = [float(v) for v in match.groups()]
    assert found == pytest.approx([spline.min(), spline.max(), monotone.min(), monotone.max()], abs=5e-3)
    assert "(1, 2.5)" in text


def test_the_mesh_explorer_counts_the_folds():
    explorer = plots.mesh_explorer()
    assert "none folded" in explorer.image.description
    explorer.controls["dxds_BC"].value = -1.5
    mesh = explorer.painter.view.mesh
    corners = mesh.points[mesh.quads]
    x, y = corners[..., 0], corners[..., 1]
    # shoelace: the signed area of each element at each corner; a folded element has a corner turning the wrong way
    turns = (np.roll(x, -1, 1) - x) * (np.roll(y, 1, 1) - y) - (np.roll(y, -1, 1) - y) * (np.roll(x, 1, 1) - x)
    folded = int(np.sum(turns.min(axis=1) <= 0))
    assert folded > 0 and f"{folded} folded (hatched)" in explorer.image.description


def test_alt_numbers_are_short():
    from labkit._alt import num, sci

    assert [sci(8.4e-3), sci(-12.0), sci(0.0), num(0.15), num(-0.0), num(1234.5)] == [
        "8.4e-3",
        "-1.2e1",
        "0",
        "0.15",
        "0",
        "1.23e+03",
    ]
    assert labkit.quad_mesh(np.zeros((2, 2)), np.eye(2)).describe().startswith("mesh of 1 quadrilateral, 4 nodes")
