"""The Explore sections' sliders: a figure built once that follows the controls while they move.

An :class:`Explorer` holds ipywidgets controls and a view of
:mod:`labkit.plots.figures`. Every change of a control (while it is being
dragged, not only when it is let go) updates the view's artists in place
and sends one PNG into an ``ipywidgets.Image``: no new figure, no output area
cleared and redrawn. Shown in a notebook it is the widget; where widgets
cannot run (nbval, ``jupyter nbconvert --execute``, GitHub's or nbviewer's
static view, ``labkit grade``) the same output carries a PNG of the first
picture, so a static copy of the notebook still shows the figure.

One function per notebook builds its explorer, so a notebook's Explore cell
is one line, e.g. ``plots.limacon_explorer()``.

The pictures are rendered at ``PIXEL_RATIO`` (2) device pixels per CSS pixel
and shown at their CSS size (``DPI`` CSS pixels per inch of figure), so their
text stays sharp on HiDPI screens and at the width JupyterLab gives them. The
picture's alternative text (and the image widget's ``description``) says what
the figure shows, in numbers, and follows the controls.
"""

import base64
import functools
import pathlib
import struct
import zlib

import numpy as np

from .._alt import figure_alt, img_tag
from ..notebook import HEADLESS, headless
from ..patches import Corner
from .figures import BilinearErrorView, ErrorCurvesView, LimaconView, PatchView, SplinePchipView


class NotShown:
    """What an explorer is where no picture is ever shown (:func:`headless`): nothing built, nothing drawn."""

    redraws = 0

    def __init__(self, name):
        self.name = name

    def __repr__(self):
        return f"<{self.name}: not built here, where nothing is shown ({HEADLESS}=1)>"


def shown_only(factory):
    """Make an explorer's function return a :class:`NotShown` where nothing is shown (the grader's sandbox,
    which never grades an explorer and has only its time to lose on one)."""

    @functools.wraps(factory)
    def build(*args, **kwargs):
        if headless():
            return NotShown(factory.__name__)
        return factory(*args, **kwargs)

    return build


DPI = 80  # CSS pixels per inch of the slider pictures (what they measure on the page)
PIXEL_RATIO = 2  # device pixels rendered per CSS pixel: crisp on HiDPI screens and when zoomed


def new_figure(size, dpi=DPI):
    """A matplotlib Figure outside pyplot (never shown twice, never kept alive by pyplot) and its axes."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    figure = Figure(figsize=size, dpi=dpi, layout="constrained")
    FigureCanvasAgg(figure)
    return figure, figure.add_subplot()


class Painter:
    """Draws a figure for a new picture: in full, or, for a view that names its changing artists,
    only those over a copy of the rest (blitting) while the rest has not changed."""

    def __init__(self, figure, view=None):
        self.figure, self.view = figure, view
        self.key, self.background = None, None
        self.blitted = 0

    def draw(self):
        canvas = self.figure.canvas
        dynamic = tuple(self.view.dynamic()) if self.view is not None else ()
        if not dynamic:  # a view that names no changing artists is drawn in full
            canvas.draw()
            return
        key = self.view.static_key()
        if key != self.key or self.background is None:
            for artist in dynamic:
                artist.set_animated(True)
            canvas.draw()  # everything but the changing artists
            self.background, self.key = canvas.copy_from_bbox(self.figure.bbox), key
        else:
            canvas.restore_region(self.background)
            self.blitted += 1
        for artist in dynamic:
            self.figure.draw_artist(artist)


def png(figure, painter=None):
    """The figure as PNG bytes (RGB): one Agg draw (or a blit), then :func:`encode_png`."""
    canvas = figure.canvas
    (painter or Painter(figure)).draw()
    width, height = canvas.get_width_height()
    return encode_png(np.asarray(canvas.buffer_rgba()).reshape(height, width, 4))


def _chunk(kind, data):
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))


def encode_png(pixels):
    """A lossless PNG of an (height, width, 3 or 4) uint8 array, its colours as RGB (alpha dropped).

    Written here rather than with Pillow, whose choice of a filter for each row took half of a 2x
    picture's time: every row is stored unfiltered and the whole compressed at zlib's fastest level,
    which suits a plot's flat colours (about the size Pillow writes, in half the time).

    >>> picture = encode_png(np.zeros((2, 3, 4), dtype=np.uint8))
    >>> picture[:8] == b"\\x89PNG\\r\\n\\x1a\\n", int.from_bytes(picture[16:20], "big")
    (True, 3)
    """
    pixels = np.asarray(pixels)
    if pixels.dtype != np.uint8 or pixels.ndim != 3 or pixels.shape[2] not in (3, 4) or 0 in pixels.shape[:2]:
        raise ValueError(
            f"encode_png takes a non-empty (height, width, 3 or 4) array of uint8; got {pixels.dtype} of shape "
            f"{pixels.shape}: pass a figure canvas's buffer_rgba() reshaped to (height, width, 4)."
        )
    height, width = pixels.shape[:2]
    rows = np.zeros((height, 1 + 3 * width), dtype=np.uint8)  # each row: filter 0 (none), then its RGB bytes
    rows[:, 1:] = pixels[:, :, :3].reshape(height, 3 * width)
    header = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)  # 8 bits per channel, RGB
    return (
        b"\x89PNG\r\n\x1a\n"
        + _chunk(b"IHDR", header)
        + _chunk(b"IDAT", zlib.compress(rows.tobytes(), 1))
        + _chunk(b"IEND", b"")
    )


def freeze_layout(figure):
    """Lay the figure out once (constrained layout) and keep those positions: later draws skip the solver."""
    figure.canvas.draw()
    figure.set_layout_engine("none")


@functools.cache
def _image_class():
    import anywidget
    import traitlets

    class ExplorerImage(anywidget.AnyWidget):
        """The explorer's picture (``image.js``): a PNG shown at its CSS size, with its description as alt text."""

        _esm = pathlib.Path(__file__).with_name("image.js")
        value = traitlets.Bytes(b"").tag(sync=True)
        css_size = traitlets.List([0, 0]).tag(sync=True)  # [width, height] in CSS pixels
        description = traitlets.Unicode("").tag(sync=True)

    return ExplorerImage


def explorer_image():
    """A new image widget of the explorers: ``value`` (PNG bytes), ``css_size`` and ``description``."""
    return _image_class()()


class Explorer:
    """Controls and a figure that follows them.

    Parameters
    ----------
    figure : matplotlib.figure.Figure
        Drawn into by `update`; rendered to PNG after every change, and
        shown at ``DPI`` CSS pixels per inch: a figure of ``DPI * PIXEL_RATIO``
        dots per inch (:func:`new_figure`'s ``ratio``) is sharp on HiDPI screens.
    update : callable
        ``update(**values)`` with the controls' current values by name; it
        changes the figure's artists in place.
    controls : dict of str to ipywidgets widget
        Each control's ``value`` is passed to `update` under its name.
    """

    def __init__(self, figure, update, controls, view=None):
        import ipywidgets as widgets

        self.figure, self._update, self.controls = figure, update, dict(controls)
        self.painter = Painter(figure, view)
        self.image = explorer_image()
        self.redraws = 0
        for control in self.controls.values():
            control.observe(self.refresh, names="value")
        self._update(**self.values())
        freeze_layout(figure)
        self.image.css_size = list(self.css_size())
        self.refresh()
        self.widget = widgets.VBox([*self.controls.values(), self.image])
        self.widget.add_class("labkit-explorer")
        from .labels import label_sliders  # the sliders' handles get their descriptions as names (axe-core)

        label_sliders(self.widget)

    def values(self):
        return {name: control.value for name, control in self.controls.items()}

    def refresh(self, change=None):
        """Update the figure from the controls and send its new picture and description (one message)."""
        self._update(**self.values())
        if headless():
            return
        picture = self.png()
        with self.image.hold_sync():
            self.image.description = self.description
            self.image.value = picture
        self.redraws += 1

    @property
    def description(self):
        """What the figure shows now, in numbers (the picture's alt text)."""
        return figure_alt(self.figure)

    def css_size(self):
        """(width, height) of the picture on the page, in CSS pixels."""
        width, height = self.figure.canvas.get_width_height()
        ratio = self.figure.dpi / DPI
        return round(width / ratio), round(height / ratio)

    def png(self):
        return png(self.figure, self.painter)

    def _repr_mimebundle_(self, **kwargs):
        return widget_with_picture(
            self.widget,
            self.png(),
            f"<{type(self).__name__}: {', '.join(self.controls)}>",
            alt=self.description,
            size=self.css_size(),
            **kwargs,
        )


def widget_with_picture(widget, picture, text, alt=None, size=None, **kwargs):
    """A widget's output bundle that also carries a PNG: front ends with widgets show the widget,
    static views (nbconvert, GitHub, nbviewer, nbval's saved outputs) the picture.

    The picture's metadata carries `alt` (default: `text`) as its alternative text and, given `size`
    (CSS pixels), its width and height, so a 2x picture shows at its CSS size there too. The same picture
    is also an HTML ``<img>`` with that alt (``text/html``: what JupyterLab shows of a static copy, since
    its image renderer ignores the metadata). Returns ``(data, metadata)``.
    """
    bundle = widget._repr_mimebundle_(**kwargs)
    data, metadata = bundle if isinstance(bundle, tuple) else (bundle, {})
    data["image/png"] = base64.b64encode(picture).decode("ascii")
    data["text/plain"] = text
    picture_metadata = {"alt": text if alt is None else alt}
    if size is not None:
        picture_metadata.update(width=int(size[0]), height=int(size[1]))
    data["text/html"] = img_tag(
        data["image/png"], picture_metadata["alt"], picture_metadata.get("width"), picture_metadata.get("height")
    )
    return data, {**(metadata or {}), "image/png": picture_metadata}


def _slider(kind, value, low, high, step=None, description=""):
    import ipywidgets as widgets

    options = {"value": value, "min": low, "max": high, "description": description, "continuous_update": True}
    if step is not None:
        options["step"] = step
    return (widgets.IntSlider if kind is int else widgets.FloatSlider)(**options)


@shown_only
def limacon_explorer():
    """01: the limaçon interpolated from n points, linear or Hermite, for a radius r0."""
    import ipywidgets as widgets

    figure, ax = new_figure((5, 5), dpi=DPI * PIXEL_RATIO)
    view = LimaconView(ax)
    return Explorer(
        figure,
        lambda intervals, r0, method: view.update(intervals, r0, method),
        view=view,
        controls={
            "intervals": _slider(int, 20, 3, 60, description="intervals"),
            "r0": _slider(float, 1.15, 0.5, 2.0, 0.05, "r0"),
            "method": widgets.Dropdown(
                options=[("Hermite", "pherm"), ("linear", "plin")], value="pherm", description="method"
            ),
        },
    )


@shown_only
def convergence_explorer(methods=("plin", "pherm", "complete", "natural", "notaknot", "pchip")):
    """02: the error curve p - f of one method for ndata points."""
    import ipywidgets as widgets

    from ..convergence import METHOD_TITLES

    figure, ax = new_figure((6, 4), dpi=DPI * PIXEL_RATIO)
    view = ErrorCurvesView(methods, ax)
    return Explorer(
        figure,
        lambda method, ndata: view.update([method], ndata),
        view=view,
        controls={
            "method": widgets.Dropdown(
                options=[(METHOD_TITLES[m], m) for m in methods],
                value="pherm" if "pherm" in methods else methods[0],  # the method 02 teaches
                description="method",
            ),
            "ndata": _slider(int, 11, 3, 81, description="ndata"),
        },
    )


@shown_only
def mesh_explorer():
    """03: the graded unit-square patch: dx/ds at A, D and at B, C, the twist and the mesh size."""
    figure, ax = new_figure((5.5, 5), dpi=DPI * PIXEL_RATIO)
    view = PatchView(ax)

    def update(dxds_AD, dxds_BC, twist, elements):
        corners = [
            Corner([0, 0], [dxds_AD, 0], [0, 1], [twist, 0]),
            Corner([1, 0], [dxds_BC, 0], [0, 1], [twist, 0]),
            Corner([1, 1], [dxds_BC, 0], [0, 1], [twist, 0]),
            Corner([0, 1], [dxds_AD, 0], [0, 1], [twist, 0]),
        ]
        view.update(corners, elements + 1, elements + 1)

    return Explorer(
        figure,
        update,
        view=view,
        controls={
            "dxds_AD": _slider(float, 3.0, -2.0, 5.0, 0.1, "dx/ds A,D"),
            "dxds_BC": _slider(float, 0.1, -2.0, 5.0, 0.1, "dx/ds B,C"),
            "twist": _slider(float, 0.0, -3.0, 3.0, 0.1, "twist"),
            "elements": _slider(int, 10, 2, 40, description="elements"),
        },
    )


@shown_only
def spline_explorer():
    """04: the error curves of the complete, natural and not-a-knot splines for ndata points."""
    import ipywidgets as widgets

    figure, ax = new_figure((6, 4), dpi=DPI * PIXEL_RATIO)
    methods = ("complete", "natural", "notaknot")
    view = ErrorCurvesView(methods, ax)

    def update(ndata, **shown):
        view.update([m for m in methods if shown[m]] or ["notaknot"], ndata)

    controls = {"ndata": _slider(int, 11, 4, 41, description="ndata")}
    for method, label in zip(methods, ("complete", "natural", "not-a-knot")):
        controls[method] = widgets.Checkbox(value=True, description=label)
    return Explorer(figure, update, controls, view=view)


@shown_only
def pchip_explorer(xdata=(0.0, 1.0, 2.0, 3.0, 4.0)):
    """05: move two data values and watch the spline overshoot while pchip keeps the shape."""
    figure, ax = new_figure((6, 4), dpi=DPI * PIXEL_RATIO)
    view = SplinePchipView(np.asarray(xdata, dtype=float), ax)
    return Explorer(
        figure,
        lambda y1, y3: view.update([0.0, y1, 2.0, y3, 2.0]),
        view=view,
        controls={
            "y1": _slider(float, 1.0, 0.0, 2.5, 0.05, "y at t=1"),
            "y3": _slider(float, 2.0, 0.5, 3.0, 0.05, "y at t=3"),
        },
    )


@shown_only
def bilinear_explorer():
    """06: the bilinear interpolation error over the square for an ndata x ndata grid."""
    figure, ax = new_figure((5.5, 4.5), dpi=DPI * PIXEL_RATIO)
    view = BilinearErrorView(ax, ntest=161)
    return Explorer(figure, view.update, {"ndata": _slider(int, 11, 2, 41, description="ndata")}, view=view)
