"""The patch editor of exercises 5 to 9: shape a Coons patch by dragging its corners and derivatives.

:func:`patch_editor` shows a patch's mesh, filled by element quality on a
colour-safe map (folded elements hatched and outlined), with twelve handles drawn over it in the browser: the four
corners, and the tips of each corner's d/ds and d/dt arrows. Dragging a
handle moves it at once in the browser and sends its position to the kernel,
which rebuilds the mesh and sends it as a scene (:mod:`labkit.plots.scene`: the
mesh's polygons and colours, drawn on a canvas over a background picture, both
at the page's devicePixelRatio), the worst quality and the corner data as
``Corner(...)`` lines to copy into an exercise cell. Sliders set the mesh size
and the twist. Moves that pile up while a picture is on its way are coalesced:
``editor.js`` keeps one dragged position on its way until the kernel acknowledges
it (``ack``) and sends only the newest after, and the sliders' messages are
merged as the explorers' are (see :mod:`labkit.plots.explorers`). After a move of
either slider the kernel also sends its next moves' pictures, readouts and
statuses, drawn ahead as the explorers' are; they are keyed by the last drag drawn
(``ack``) as well, so a picture drawn before a drag is never shown after it.
A handle's move does not wait for the kernel at all: ``mesh.js`` draws its mesh
in the page from the editor's ``sketch`` (:meth:`Editor._sketch`), item for item
the scene the kernel sends for it, which is then drawn over it.

Without a mouse (:data:`KEYS`): Tab reaches the editor and leaves it as it
leaves any control; ``n`` and ``p`` select the next and the previous handle,
the arrow keys move the selected handle (with Shift five times further). The
editor is an ARIA ``application`` named by :data:`LABEL`, and a polite live
region announces :func:`status_text`, the selected handle and the worst
quality, after every change.

The handles' logic is plain Python, tested without a browser
(``tests/plots/test_plots.py``, ``tests/plots/test_editor_access.py``):
:func:`handle_positions`, :func:`nearest_handle`, :func:`move_handle`,
:func:`corner_code`, :func:`handle_name`, :func:`status_text`. The browser
side is ``editor.js`` beside this file, an anywidget module.
"""

import functools

import numpy as np

from ..errors import InputError
from ..patches import Corner
from .explorers import (
    DPI,
    Painter,
    ahead_entry,
    esm,
    freeze_layout,
    headless,
    live_ratio,
    new_figure,
    next_moves,
    shown_only,
    static_png,
    widget_with_picture,
)
from .figures import PatchView
from .labels import label_sliders
from .scene import Scene

NAMES = "ABCD"
ARROW = 0.25  # an arrow is this fraction of its derivative, so the handles stay near the patch
KEYS = "n or p: next or previous handle. Arrow keys: move it, with Shift 5 times further. Tab: leave the editor."
LABEL = "Patch editor, 12 handles: the corners A to D and the tips of their d/ds and d/dt arrows. " + KEYS


def handle_positions(corners, scale=ARROW):
    """The twelve handles, shape (12, 2): corners A-D, then the d/ds tips, then the d/dt tips."""
    points = np.array([c.point[:2] for c in corners], dtype=float)
    ds = np.array([c.ds[:2] for c in corners], dtype=float)
    dt = np.array([c.dt[:2] for c in corners], dtype=float)
    return np.concatenate((points, points + scale * ds, points + scale * dt))


def nearest_handle(positions, point, radius):
    """Index of the handle nearest to `point`, or None if none lies within `radius`."""
    distance = np.hypot(*(np.asarray(positions, float) - np.asarray(point, float)).T)
    index = int(np.argmin(distance))
    return index if distance[index] <= radius else None


def move_handle(corners, index, point, scale=ARROW):
    """The corners after handle `index` is dropped at `point` (a corner carries its arrows along)."""
    corners = list(corners)
    point = np.asarray(point, dtype=float)
    which, kind = index % 4, index // 4
    c = corners[which]
    if kind == 0:
        corners[which] = Corner(point, c.ds, c.dt, c.dsdt)
    elif kind == 1:
        corners[which] = Corner(c.point, (point - c.point) / scale, c.dt, c.dsdt)
    elif kind == 2:
        corners[which] = Corner(c.point, c.ds, (point - c.point) / scale, c.dsdt)
    else:
        raise InputError(f"handle index must be 0 to 11; got {index}.")
    return corners


def handle_name(index):
    """What handle `index` is, as the editor announces it: "corner B", "B's d/ds arrow tip", ...

    Examples
    --------
    >>> handle_name(1), handle_name(4), handle_name(11)
    ('corner B', "A's d/ds arrow tip", "D's d/dt arrow tip")
    """
    if not isinstance(index, (int, np.integer)) or not 0 <= index < 12:
        raise InputError(f"handle index must be 0 to 11; got {index!r}.")
    which, kind = NAMES[index % 4], index // 4
    return f"corner {which}" if kind == 0 else f"{which}'s {('d/ds', 'd/dt')[kind - 1]} arrow tip"


def status_text(corners, index, quality):
    """The editor's live-region sentence: the selected handle, where it is, the worst quality and the folds.

    `quality` holds the mesh's element qualities (``Mesh.quality()``); the
    worst is their minimum, as in the readout.

    Examples
    --------
    >>> from labkit import Corner
    >>> square = [Corner(p, [1, 0], [0, 1]) for p in ([0, 0], [1, 0], [1, 1], [0, 1])]
    >>> status_text(square, 5, [1.0, 0.5, -0.25])
    "B's d/ds arrow tip at (1.25, 0). Worst quality -0.25, 1 folded."
    """
    x, y = handle_positions(corners)[index]
    quality = np.asarray(quality, dtype=float)
    folded = int(np.sum(quality <= 0))
    return (
        f"{handle_name(index)} at ({_number(x)}, {_number(y)}). Worst quality {quality.min():.2f}"
        + (f", {folded} folded" if folded else "")
        + "."
    )


def with_twist(corners, twist):
    """The same corners with the twist d2/dsdt = (twist, twist) at all four."""
    return [Corner(c.point, c.ds, c.dt, [twist, twist]) for c in corners]


def _number(value):
    text = f"{value:.3f}".rstrip("0").rstrip(".")
    return "0" if text in ("", "-0") else text


def _numbers(vector):
    return "[" + ", ".join(_number(v) for v in vector) + "]"


def corner_code(corners):
    """The corner data as the Corner(...) lines an exercise cell uses, rounded to 3 decimals."""
    return "\n".join(
        f"{name} = Corner({_numbers(c.point)}, ds={_numbers(c.ds)}, dt={_numbers(c.dt)}, dsdt={_numbers(c.dsdt)})"
        for name, c in zip(NAMES, corners)
    )


def _editor_class():
    import anywidget
    import traitlets

    class PatchEditor(anywidget.AnyWidget):
        """The editor's widget: picture, handles and readout synced with editor.js."""

        _esm = esm("mesh.js", "editor.js")
        background = traitlets.Bytes(b"").tag(sync=True)  # PNG of what does not change with a move
        scene = traitlets.Dict({}).tag(sync=True)  # the mesh and title, drawn over it (scene.py)
        overlays = traitlets.Dict({}).tag(sync=True)  # the pixels the scene's overlay items name (sent on change)
        pixel_ratio = traitlets.Float(0.0).tag(sync=True)  # the page's devicePixelRatio, from the browser
        handles = traitlets.List([]).tag(sync=True)  # [[x, y], ...] in data coordinates
        frame = traitlets.Dict({}).tag(sync=True)  # where the axes lie in the picture, for mouse -> data
        drag = traitlets.Dict({}).tag(sync=True)  # {"index", "x", "y", "seq"} from the browser
        readout = traitlets.Unicode("").tag(sync=True)
        worst = traitlets.Float(1.0).tag(sync=True)
        ack = traitlets.Int(0).tag(sync=True)  # the seq of the last drag drawn
        selected = traitlets.Int(0).tag(sync=True)  # the handle the keys move, chosen in the browser
        status = traitlets.Unicode("").tag(sync=True)  # the live region's sentence (status_text)
        label = traitlets.Unicode(LABEL).tag(sync=True)  # the editor's aria-label, naming the keys
        key_help = traitlets.Unicode(KEYS).tag(sync=True)  # the keys, shown under the readout
        alt = traitlets.Unicode("").tag(sync=True)  # the picture's alt text
        # pictures of the sliders' next moves, drawn ahead (see labkit.plots.explorers.AHEAD), and where the
        # browser reads the sliders' values that key them: {name: [model id, "value"]}
        ahead = traitlets.List([]).tag(sync=True)
        controls = traitlets.Dict({}).tag(sync=True)
        # what the page needs to draw a dragged handle's mesh itself (mesh.js), changed with the mesh size,
        # the twist or the background only: see Editor._sketch
        sketch = traitlets.Dict({}).tag(sync=True)

    return PatchEditor


class Editor:
    """A patch editor: the widget, the corners it holds, and the sliders for mesh size and twist."""

    def __init__(self, corners, elements=10, limits=None):
        import ipywidgets as widgets

        self.corners = list(corners)
        self.figure, self.ax = new_figure((5, 5))
        self.view = PatchView(self.ax, colorbar=False)
        self.elements = _size_slider(elements)
        self.twist = widgets.FloatSlider(
            value=float(np.mean([c.dsdt[0] for c in self.corners])),
            min=-3.0,
            max=3.0,
            step=0.1,
            description="twist",
            continuous_update=True,
        )
        self.widget_ = _editor_class()()
        self.widget_.controls = {
            "elements": [self.elements.model_id, "value"],
            "twist": [self.twist.model_id, "value"],
        }
        self.limits = limits or self._fit_limits()
        self.redraws = 0
        self.ratio = 1.0  # the static picture's and, until the page says otherwise, the live one's
        self._draw_mesh()
        freeze_layout(self.figure)
        self.painter = Painter(self.figure, self.view)
        self.scene = Scene(self.figure, self.view)
        self.seq = 0  # the number of the last scene sent
        self.widget_.observe(self._new_ratio, names="pixel_ratio")
        self.widget_.observe(self._dragged, names="drag")
        self.widget_.observe(self._selected, names="selected")
        self.elements.observe(self._sized, names="value")
        self.twist.observe(self._twisted, names="value")
        self.refresh()
        self.widget = label_sliders(widgets.VBox([self.widget_, widgets.HBox([self.elements, self.twist])]))
        self.widget.add_class("labkit-patch-editor")

    def _fit_limits(self):
        points = np.concatenate((handle_positions(self.corners), [c.point[:2] for c in self.corners]))
        low, high = points.min(axis=0), points.max(axis=0)
        centre, half = (low + high) / 2, max(high - low) * 0.8 + 0.2
        return (centre[0] - half, centre[0] + half, centre[1] - half, centre[1] + half)

    def _dragged(self, change):
        drag = change["new"]
        try:
            index, point = int(drag["index"]), (float(drag["x"]), float(drag["y"]))
        except (KeyError, TypeError, ValueError):
            return
        with self.widget_.hold_sync():  # the picture and the acknowledgement in one message
            if isinstance(drag.get("seq"), int):
                self.widget_.ack = drag["seq"]  # first: the picture's key names the drag it shows
            if 0 <= index < 12 and all(np.isfinite(point)):
                self.corners = move_handle(self.corners, index, point)
                self.widget_.selected = index  # the browser selects a handle before it drags it: usually no change
                self.refresh()

    def _selected(self, change):
        if 0 <= change["new"] < 12:
            self.widget_.status = status_text(self.corners, change["new"], self.quality)

    def _sized(self, change):
        self.refresh()
        self._send_ahead(change)

    def _twisted(self, change):
        self.corners = with_twist(self.corners, change["new"])
        self.refresh()
        self._send_ahead(change)

    def _draw_mesh(self, corners=None, elements=None):
        n = (self.elements.value if elements is None else elements) + 1
        self.view.update(self.corners if corners is None else corners, n, n)
        self.ax.set_xlim(*self.limits[:2])
        self.ax.set_ylim(*self.limits[2:])
        self.ax.set_aspect("equal")

    def _new_ratio(self, change):
        ratio = live_ratio(change["new"])
        if ratio != self.ratio:
            self.ratio = ratio
            self.refresh()

    def refresh(self):
        """Rebuild the mesh from the corners and send it."""
        if headless():  # nothing will show the picture, its readout or its handles
            self._draw_mesh()
            self.quality = self.view.mesh.quality()
            return
        self.seq += 1
        self._send(self.seq)

    def _values(self, elements=None, twist=None):
        """The sliders' values as the browser holds them, and the last drag drawn (``ack``): what keys a picture
        drawn ahead (a drag changes the corners, so a picture drawn before it is not one to show after)."""
        return {
            "elements": self.elements.value if elements is None else elements,
            "twist": self.twist.value if twist is None else twist,
            "shape": self.widget_.ack,
        }

    def _fields(self, corners, quality, elements=None):
        """The readout, worst quality, alt text and status of the mesh of `corners` with `quality`, `elements`
        (default: the slider's) by as many elements."""
        worst = float(quality.min())
        folded = int(np.sum(quality <= 0))
        n = self.elements.value if elements is None else elements
        return {
            "readout": f"worst quality {worst:.2f}"
            + (f", {folded} folded" if folded else "")
            + "\n"
            + corner_code(corners),
            "worst": worst,
            "alt": (
                f"Mesh of the patch, {n} by {n} elements coloured by quality, with its 12 handles; worst "
                f"quality {worst:.2f}" + (f", {folded} folded" if folded else "") + "."
            ),
            "status": status_text(corners, self.widget_.selected, quality),
        }

    def _scene(self, seq, items, values, corners=None):
        width, height = self.figure.canvas.get_width_height()
        scene = {
            "seq": seq,
            "size": [width, height],
            "ratio": self.ratio,
            "items": items,
            "values": values,
            "background": self.scene.backgrounds,
        }
        if corners is not None:  # the corner data it shows, at full precision: where the page's sketch starts
            scene["corners"] = [[float(v) for v in (*c.point[:2], *c.ds[:2], *c.dt[:2], *c.dsdt[:2])] for c in corners]
        return scene

    def _sketch(self, items):
        """What ``mesh.js`` needs to draw the mesh of a drag not yet answered, as this kernel would draw it:
        the Hermite basis at the mesh's parameter values, the axes' transform to the picture's device pixels,
        the colour map as bytes, and the scene items of the mesh, the title and the folded elements without
        their data (:meth:`labkit.plots.figures.PatchView.dynamic`'s order). Empty (no sketch: every drag
        waits for the kernel) when the scene is not of that shape."""
        from ..piecewise import hermite_basis
        from .figures import TITLE

        view = self.view
        kinds = [item["kind"] for item in items]
        if kinds != ["polygons", "text", "polygons"] or view.s is None or not view.color_by_quality:
            return {}
        # the items without what the page computes: the elements' vertices and colours, the title's text, the
        # folded elements' vertices (their faces are none whatever they are)
        cells, title, folded = (
            {k: v for k, v in item.items() if k not in data}
            for item, data in zip(items, (("xy", "counts", "faces", "face_count"), ("text",), ("xy", "counts")))
        )
        cmap, norm = view.cells.get_cmap(), view.cells.norm
        colors = np.vstack((cmap(np.arange(cmap.N)), cmap.get_under(), cmap.get_over()))
        matrix = self.ax.transData.get_affine().get_matrix()
        return {
            "background": self.scene.backgrounds,
            "values": {"elements": self.elements.value, "twist": self.twist.value},
            "size": list(self.figure.canvas.get_width_height()),
            "in_s": np.asarray(hermite_basis(0.0, 1.0, view.s), dtype="<f8").tobytes(),
            "in_t": np.asarray(hermite_basis(0.0, 1.0, view.t), dtype="<f8").tobytes(),
            "arrow": ARROW,
            "matrix": [float(v) for v in matrix[:2].ravel()],  # display = [[a, c, e], [b, d, f]] @ [x, y, 1]
            "height": float(self.figure.bbox.height),
            "colors": np.round(255 * colors).astype(np.uint8).tobytes(),  # N colours, then under and over
            "n_colors": int(cmap.N),
            "vmin": float(norm.vmin),
            "vmax": float(norm.vmax),
            # the title with its worst quality left for the page to write (with two decimals, as Python does)
            "title": {
                **title,
                "text": TITLE.replace("{worst:.2f}", "{worst}").format(
                    ns=len(view.s) - 1, nt=len(view.t) - 1, worst="{worst}"
                ),
            },
            "cells": cells,
            "folded": folded,
        }

    def _send(self, seq):
        """Rebuild the mesh; send its scene, handles, readout, worst quality, alt and status."""
        self._draw_mesh()
        self.quality = self.view.mesh.quality()
        background, items = self.scene.frame(self.ratio, DPI * self.ratio)
        fields = self._fields(self.corners, self.quality)
        with self.widget_.hold_sync():  # one message a move: each message costs the browser a round of work
            self.widget_.frame = self._frame()
            self.widget_.handles = handle_positions(self.corners).round(6).tolist()
            for name, value in fields.items():
                setattr(self.widget_, name, value)
            if background is not None:
                self.widget_.background = background
            self.widget_.overlays = self.scene.overlays
            self.widget_.sketch = self._sketch(items)
            self.widget_.scene = self._scene(seq, items, self._values(), self.corners)
        self.redraws += 1

    def _send_ahead(self, change):
        """Send the pictures of the moved slider's next moves (``AHEAD``), with their readouts."""
        if headless():
            return
        name = "elements" if change.get("owner") is self.elements else "twist"
        for batch in next_moves(change):
            entries = []
            for value in batch:
                corners = with_twist(self.corners, value) if name == "twist" else self.corners
                elements = value if name == "elements" else None
                entry = ahead_entry(
                    self.scene,
                    functools.partial(self._draw_mesh, corners, elements),
                    self._values(**{name: value}),
                    DPI * self.ratio,
                    lambda corners=corners, n=elements: self._fields(corners, self.view.mesh.quality(), n),
                )
                if entry is not None:
                    entry["scene"] = self._scene(self.seq, entry.pop("items"), entry["values"], corners)
                    entries.append(entry)
            if entries:
                self.widget_.ahead = entries
        self._draw_mesh()  # the figure shows the editor's mesh again

    def _frame(self):
        """The axes' data limits and box in the last picture (CSS pixels), so the browser can map the mouse."""
        width, height = self.figure.canvas.get_width_height()
        box = self.ax.get_window_extent()  # device pixels, as drawn (after the equal aspect was applied)
        r = self.figure.dpi / DPI  # device pixels per CSS pixel
        (x0, x1), (y0, y1) = self.ax.get_xlim(), self.ax.get_ylim()
        return {
            "width": round(width / r),
            "height": round(height / r),
            "left": float(box.x0 / r),
            "right": float(box.x1 / r),
            "top": float((height - box.y1) / r),
            "bottom": float((height - box.y0) / r),
            "x0": float(x0),
            "x1": float(x1),
            "y0": float(y0),
            "y1": float(y1),
        }

    def png(self):
        """The mesh now as the static picture: a PNG at DPI (one device pixel per CSS pixel)."""
        return static_png(self.figure, self.painter, DPI)

    def _repr_mimebundle_(self, **kwargs):
        return widget_with_picture(self.widget, self.png(), self.widget_.readout, alt=self.widget_.alt, **kwargs)


def _size_slider(elements):
    import ipywidgets as widgets

    return widgets.IntSlider(value=elements, min=2, max=40, description="elements", continuous_update=True)


# What the editor opens on: a gently curved patch near the unit square, none of whose data is an answer the lab
# asks for (Exercise 5's identity data, a straight side's derivatives): the student shapes it from there.
FIRST_PATCH = (
    Corner([0.0, 0.0], [1.2, -0.3], [0.2, 1.0]),
    Corner([1.2, 0.1], [1.0, 0.4], [-0.2, 1.1]),
    Corner([1.1, 1.2], [0.9, -0.2], [-0.1, 0.9]),
    Corner([-0.1, 1.0], [1.1, 0.3], [0.1, 0.8]),
)


@shown_only
def patch_editor(corners=None, elements=10):
    """An editor for a Coons patch; `corners` default to :data:`FIRST_PATCH`.

    Examples
    --------
    >>> from labkit import Corner
    >>> from labkit.plots import patch_editor
    >>> editor = patch_editor([Corner(p, [2.0, 0.0], [0.0, 1.0]) for p in ([0, 0], [2, 0], [2, 1], [0, 1])])
    >>> print(editor.widget_.readout.splitlines()[1])
    A = Corner([0, 0], ds=[2, 0], dt=[0, 1], dsdt=[0, 0])
    """
    if corners is None:
        corners = list(FIRST_PATCH)
    if len(corners) != 4 or not all(isinstance(c, Corner) for c in corners):
        raise InputError("patch_editor needs a list of four labkit.Corner objects A, B, C, D.")
    if any(c.point.size != 2 for c in corners):
        raise InputError("patch_editor edits plane patches: give corners with 2 coordinates.")
    return Editor(corners, elements)
