"""The Explore sections' sliders: a figure built once that follows the controls while they move.

An :class:`Explorer` holds ipywidgets controls and a view of
:mod:`labkit.plots.figures`. Every change of a control (while it is being
dragged, not only when it is let go) updates the view's artists in place and
sends them to the browser as a :class:`~labkit.plots.scene.Scene`: the parts
of the figure that stay (axes, ticks, labels, legend) as a background picture,
rendered again only when they change, and the changing artists (curves,
points, mesh, colour map; a title or colour bar as the pixels of its box) as
a few kilobytes of data that ``image.js`` draws on a ``<canvas>`` over the
background. Both are at the page's own ``devicePixelRatio`` (the browser
reports it in ``pixel_ratio``), so text and lines are sharp on every screen.
No new figure, no output area cleared and redrawn.

Moves that pile up while a picture is on its way are coalesced without a
message of labkit's own: a widget in the browser keeps one message on its way
to the kernel at a time and merges the changes made meanwhile into the next
(ipywidgets' ``WidgetModel.sync``), so a held key or a fast drag sends its
latest value once the kernel has answered the last, and the kernel draws every
request it gets at once. The browser paints at most once an animation frame,
the newest scene. (A report from the browser of each picture shown, which the
kernel waited for, cost a second round trip per move: ``docs/performance.md``.)

A key press needs no round trip at all when its picture was drawn ahead: after
a slider's move the kernel also sends the pictures of that slider's next moves
(``AHEAD``: the next step on first, alone, then the one after and the one
back), each keyed by the controls' values it shows and the background it lies
on. ``image.js`` keeps them and shows one in the next frame when the controls
reach its values; the kernel's own scene of that move, when it comes, is not
drawn again. The next move's picture may lie on a new background (the axes fit
again): that background is rendered then and sent with it, and sent again as
the kernel's own when the move is made (:meth:`Scene.ahead`). Drawing ahead
changes nothing the explorer draws afterwards (the axes are put back, the
figure updated to the controls again).

Where widgets cannot run (nbval, ``jupyter nbconvert --execute``, GitHub's or
nbviewer's static view, ``labkit grade``) the same output carries a PNG of the
first picture (:meth:`Explorer.png`, rendered at ``PIXEL_RATIO`` (2) device
pixels per CSS pixel and shown at its CSS size), so a static copy of the
notebook still shows the figure. The picture's alternative text (and the
widget's ``description``) says what the figure shows, in numbers, and follows
the controls.

One function per notebook builds its explorer, so a notebook's Explore cell
is one line, e.g. ``plots.limacon_explorer()``.
"""

import base64
import functools
import pathlib

import numpy as np

from .._alt import figure_alt, img_tag
from ..notebook import HEADLESS, headless
from ..patches import Corner
from .figures import BilinearErrorView, ErrorCurvesView, LimaconView, PatchView, SplinePchipView
from .scene import Scene, animated, encode_png, fit_boxes


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
PIXEL_RATIO = 2  # device pixels per CSS pixel of the static picture (and of the live one until the page says)
MAX_PIXEL_RATIO = 4  # a page's devicePixelRatio is taken between 1 and this


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
        key = (self.view.static_key(), self.figure.dpi)
        if key != self.key or self.background is None:
            with animated(dynamic):
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


def freeze_layout(figure):
    """Lay the figure out once (constrained layout) and keep those positions: later draws skip the solver."""
    figure.canvas.draw()
    figure.set_layout_engine("none")


def live_ratio(value):
    """A page's reported devicePixelRatio as the ratio the live picture is drawn at: between 1 and
    MAX_PIXEL_RATIO, in quarters (a zoom of 110 % draws at 1.25), PIXEL_RATIO if it is no number."""
    try:
        ratio = float(value)
    except (TypeError, ValueError):
        return float(PIXEL_RATIO)
    if not np.isfinite(ratio) or ratio <= 0:
        return float(PIXEL_RATIO)
    return float(min(MAX_PIXEL_RATIO, max(1.0, np.ceil(4 * ratio - 1e-9) / 4)))


def esm(*names):
    """The anywidget module of the files `names` (the last is the module: image.js, editor.js; before it, what
    it uses besides scene.js) with scene.js, which draws the scenes, first."""
    folder = pathlib.Path(__file__).parent
    return "\n".join((folder / name).read_text() for name in ("scene.js", *names))


@functools.cache
def _image_class():
    import anywidget
    import traitlets

    class ExplorerImage(anywidget.AnyWidget):
        """The explorer's picture (``image.js``): the background PNG with the scene drawn over it, shown at
        its CSS size, with its description as alt text."""

        _esm = esm("image.js")
        background = traitlets.Bytes(b"").tag(sync=True)  # PNG of what does not change with a move
        scene = traitlets.Dict({}).tag(sync=True)  # {"seq", "size" (device px), "items"}: see scene.py
        overlays = traitlets.Dict({}).tag(sync=True)  # the pixels the scene's overlay items name (sent on change)
        css_size = traitlets.List([0, 0]).tag(sync=True)  # [width, height] in CSS pixels
        description = traitlets.Unicode("").tag(sync=True)
        pixel_ratio = traitlets.Float(0.0).tag(sync=True)  # the page's devicePixelRatio, from the browser
        # pictures drawn ahead: [{"values", "background", "scene", "description"}], for moves not made yet
        ahead = traitlets.List([]).tag(sync=True)
        # {name: [model id, attribute]}: where the browser reads the controls' values that key those pictures
        controls = traitlets.Dict({}).tag(sync=True)

    return ExplorerImage


def explorer_image():
    """A new image widget of the explorers: ``background``, ``scene``, ``css_size``, ``description``,
    ``pixel_ratio``, ``ahead`` and ``controls``."""
    return _image_class()()


AHEAD = ((1,), (2, -1))  # after a slider's move, the pictures drawn ahead, in its steps along its last move: the
# next first, sent alone, then the one after and the one back; each is drawn over the background already sent, but
# the next one's may be a new background (the axes fit again), rendered then and sent with it


def _browser_attribute(control):
    """Where the browser's model of `control` holds its value: a dropdown's is its ``index`` (its value
    stays in the kernel), any other control's its ``value``."""
    import ipywidgets as widgets

    return "index" if isinstance(control, widgets.widget_selection._Selection) else "value"


def _slider_step(control):
    """The step of an ipywidgets IntSlider or FloatSlider (a slider moves by it at a key press), else None."""
    import ipywidgets as widgets

    if isinstance(control, (widgets.IntSlider, widgets.FloatSlider)) and control.step:
        return control.step
    return None


def next_moves(change):
    """The values of a slider's next moves after `change` (a traitlets change of its ``value``), in the batches
    of ``AHEAD``: within its range, one step apart; nothing for another control or no move."""
    control = change.get("owner")
    step = _slider_step(control)
    if step is None or change.get("new") == change.get("old"):
        return []
    direction = 1 if change["new"] > change["old"] else -1
    batches = []
    for steps in AHEAD:
        values = [control.value + direction * k * step for k in steps]
        values = [round(v, 12) if isinstance(v, float) else v for v in values]
        batches.append([v for v in values if control.min <= v <= control.max])
    return batches


def ahead_entry(scene, draw, values, dpi, fields, render=False):
    """A picture drawn ahead: the `scene`'s items once `draw()` has updated the figure to a move not made yet,
    keyed by the controls' `values` there (as the browser holds them) and by the background it was drawn from
    (``base``: the one the page must show for it to be that move's picture), with the widget's other `fields`
    (a callable). It lies on the background sent (``background`` is ``base``) or, where that does not fit and
    `render` is true, on a new one sent with it (``picture``, ``overlays``: :meth:`Scene.ahead`); else None.
    The figure's axes are then put back as they were before `draw`, so its next update decides its limits as
    it would have."""
    limits = [(ax, ax.get_xlim(), ax.get_ylim()) for ax in scene.figure.axes]
    base = scene.backgrounds
    try:
        draw()
        picture = scene.ahead(dpi, render)
        return None if picture is None else {"values": values, "base": base, **picture, **fields()}
    finally:
        for ax, xlim, ylim in limits:
            ax.set_xlim(xlim)
            ax.set_ylim(ylim)
        fit_boxes(scene.figure)  # a background drawn ahead laid the boxes out for its limits


class Explorer:
    """Controls and a figure that follows them.

    Parameters
    ----------
    figure : matplotlib.figure.Figure
        Drawn into by `update`, shown at ``DPI`` CSS pixels per inch: live as a
        :class:`~labkit.plots.scene.Scene` at the page's pixel ratio, and as a PNG
        at ``PIXEL_RATIO`` for the static copy (:meth:`png`).
    update : callable
        ``update(**values)`` with the controls' current values by name; it
        changes the figure's artists in place.
    controls : dict of str to ipywidgets widget
        Each control's ``value`` is passed to `update` under its name.
    view : labkit.plots.figures.View, optional
        Names the artists that change (``dynamic``) and a key of the rest
        (``static_key``); without one, every move sends a whole new background.
    """

    def __init__(self, figure, update, controls, view=None):
        import ipywidgets as widgets

        self.figure, self._update, self.controls = figure, update, dict(controls)
        self.painter = Painter(figure, view)
        self.scene = Scene(figure, view if view is not None else _NothingDynamic())
        self.image = explorer_image()
        self.redraws = 0
        self.ratio = float(PIXEL_RATIO)
        self.seq = 0  # the number of the last scene sent
        for control in self.controls.values():
            control.observe(self.refresh, names="value")
        self._draw(self.values())
        freeze_layout(figure)
        self.image.css_size = list(self.css_size())
        self.image.observe(self._new_ratio, names="pixel_ratio")
        self.image.controls = {name: [c.model_id, _browser_attribute(c)] for name, c in self.controls.items()}
        self.refresh()
        self.widget = widgets.VBox([*self.controls.values(), self.image])
        self.widget.add_class("labkit-explorer")
        from .labels import label_sliders  # the sliders' handles get their descriptions as names (axe-core)

        label_sliders(self.widget)

    def values(self):
        return {name: control.value for name, control in self.controls.items()}

    def browser_values(self, values):
        """`values` (the controls' by name) as the browser's models hold them (:func:`_browser_attribute`)."""
        return {
            name: self.controls[name].index if _browser_attribute(self.controls[name]) == "index" else v
            for name, v in values.items()
        }

    def _draw(self, values):
        self._update(**values)

    def refresh(self, change=None):
        """Bring the figure and its picture up to the controls; after a slider's move, send the pictures of
        its next moves too (``AHEAD``), which the browser shows at a key press without asking the kernel."""
        if headless():
            self._draw(self.values())
            return
        self.seq += 1
        self._send(self.seq)
        if change is not None:
            self._send_ahead(change)

    def _scene(self, seq, items, values, background=None):
        width, height = self.figure.canvas.get_width_height()
        return {
            "seq": seq,
            "size": [width, height],
            "ratio": self.ratio,
            "items": items,
            # the controls' values it shows, as the browser holds them: the browser tells it from one drawn ahead
            "values": self.browser_values(values),
            "background": self.scene.backgrounds if background is None else background,  # which it lies on
        }

    def _send(self, seq):
        """Update the figure from the controls and send its scene and description (one message)."""
        values = self.values()
        self._draw(values)
        background, items = self.scene.frame(self.ratio, DPI * self.ratio)
        with self.image.hold_sync():
            self.image.description = self.description
            if background is not None:
                self.image.background = background
            self.image.overlays = self.scene.overlays
            self.image.scene = self._scene(seq, items, values)
        self.redraws += 1

    def _send_ahead(self, change):
        """Send the pictures of the moved slider's next moves (``AHEAD``) that lie on the background sent."""
        name = next((name for name, c in self.controls.items() if c is change.get("owner")), None)
        values, batches = self.values(), next_moves(change) if name is not None else []
        for first, batch in zip((True, False, False), batches):
            entries = []
            for value in batch:
                moved = {**values, name: value}
                entry = ahead_entry(
                    self.scene,
                    functools.partial(self._draw, moved),
                    self.browser_values(moved),
                    DPI * self.ratio,
                    lambda: {"description": figure_alt(self.figure)},
                    render=first,  # the next move only: it may bring a new background, rendered now
                )
                if entry is not None:
                    entry["scene"] = self._scene(self.seq, entry.pop("items"), moved, entry["background"])
                    entries.append(entry)
            if entries:
                self.image.ahead = entries
        if batches:
            self._draw(values)  # the figure shows the controls again (it is the notebook's to read or save)

    def _new_ratio(self, change):
        ratio = live_ratio(change["new"])
        if ratio != self.ratio:
            self.ratio = ratio
            self.refresh()

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
        """The figure now as the static picture: a PNG at PIXEL_RATIO (whatever the live picture's ratio)."""
        return static_png(self.figure, self.painter, DPI * PIXEL_RATIO)

    def _repr_mimebundle_(self, **kwargs):
        picture = self.png()
        return widget_with_picture(
            self.widget,
            picture,
            f"<{type(self).__name__}: {', '.join(self.controls)}>",
            alt=self.description,
            size=self.css_size(),
            **kwargs,
        )


class _NothingDynamic:
    """The view of an explorer made without one: nothing is drawn in the browser, the background is all."""

    def dynamic(self):
        return ()

    def static_key(self):
        return object()  # never equal: a new background on every move


def static_png(figure, painter, dpi):
    """The figure as a PNG at `dpi` (the static picture's), its live dpi put back after."""
    live = figure.dpi
    if live != dpi:
        figure.set_dpi(dpi)
    try:
        return png(figure, painter)
    finally:
        if figure.dpi != live:
            figure.set_dpi(live)


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
