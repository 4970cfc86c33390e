"""The explorers' live picture as a scene: a background picture and the changing artists as data.

An explorer's figure has artists that change with every move of a control (the view's
``dynamic()``: curves, points, the mesh, the colour map, the title) and everything else (axes,
ticks, labels, the legend), which changes only when the view's ``static_key()`` does. A
:class:`Scene` renders "everything else" once into a background PNG at the page's own
``devicePixelRatio``, and turns each changing artist into a small item the browser draws on a
``<canvas>`` (``scene.js``) in the figure's device pixels (origin top left):

* a line (``Line2D``): its vertices (float32), colour, width, dashes and markers;
* polygons (a ``PolyCollection``: the mesh): vertices, a colour per polygon, edge and hatch;
* an image (``AxesImage``: the colour map): its RGBA pixels (uint8, colour-mapped here) and the box it fills;
* a text (a title, tick labels) of one line, level or turned a quarter: the string, its font and where
  matplotlib's layout puts its baseline, drawn with the browser's DejaVu Sans (matplotlib's font) or the
  nearest sans-serif;
* an axis (a colour bar's, whose scale follows the data): its tick marks as lines, its labels as texts;
* a legend as an *overlay*: its own pixels with their transparency (RGBA, rendered here by Agg on a clear
  picture), drawn in its place among the items, so what lies under it shows through its frame as it does
  in matplotlib's drawing. The item names the overlay; its pixels are in :attr:`Scene.overlays`, which the
  widgets sync as a trait of their own, so they cross to the browser only when they change;
* anything else (mathematics in a text, say) as a *patch*: the pixels of its box, rendered here by Agg over
  the background, sent raw (RGBA) so the browser draws them without decoding anything.

A move then sends a few kilobytes instead of a picture, and the browser draws at its own pixel
ratio. The static picture of the notebook (the mimebundle's PNG) is not made here: it stays
:func:`labkit.plots.explorers.png`'s.
"""

import contextlib
import struct
import zlib

import numpy as np

from ..errors import InputError

CAPS = {"butt": "butt", "round": "round", "projecting": "square"}
AHEAD_KEPT = 2  # backgrounds rendered ahead of a move and kept for it (each a few MB of Agg pixels)


def _rgba(color, alpha=None):
    from matplotlib.colors import to_rgba

    if color is None or (isinstance(color, str) and color.lower() == "none"):
        return None
    r, g, b, a = to_rgba(color, alpha)
    return [round(255 * r), round(255 * g), round(255 * b), round(a, 4)]


def _float32(points):
    return np.ascontiguousarray(points, dtype="<f4").tobytes()


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
        raise InputError(
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


@contextlib.contextmanager
def animated(artists):
    """The artists marked animated (left out of a full draw) while the block runs, as they were after."""
    before = [artist.get_animated() for artist in artists]
    for artist in artists:
        artist.set_animated(True)
    try:
        yield
    finally:
        for artist, was in zip(artists, before):
            artist.set_animated(was)


def fit_boxes(figure, renderer=None):
    """Put every axes' box where a draw of the figure would, for its limits now (Axes.draw's first step): an
    equal-aspect box follows its limits, so one drawn for other limits (a move drawn ahead) is put back."""
    renderer = renderer or figure.canvas.get_renderer()
    for ax in figure.axes:
        locator = ax.get_axes_locator()
        ax.apply_aspect(locator(ax, renderer) if locator else None)


class Scene:
    """A figure's live picture for one view: :meth:`frame` gives the background (when it changed) and the items."""

    def __init__(self, figure, view):
        self.figure, self.view = figure, view
        self.key = None
        self.background = None  # Agg's saved copy of the background, for the patches
        self.backgrounds = 0  # the number of the background the scene lies on (a new one when the static part changed)
        self.rendered = 0  # how many backgrounds were rendered, for the figure or ahead of a move
        self.overlays: dict = {}  # an overlay's id -> {"rgba", "box"}: the pixels its scene items name
        self._made: dict = {}  # an overlay's id -> the background's key it was rendered under
        self._ahead: dict = {}  # key -> a background rendered ahead of a move (:meth:`ahead`), newest last

    def _device(self, xy):
        """Display coordinates (origin bottom left) -> the picture's device pixels (origin top left)."""
        xy = np.asarray(xy, dtype=float).reshape(-1, 2).copy()
        xy[:, 1] = self.figure.bbox.height - xy[:, 1]
        return xy

    def _clip(self, artist):
        box = artist.get_clip_box() if artist.get_clip_on() else None
        if box is None:
            return None
        height = self.figure.bbox.height
        return [float(box.x0), float(height - box.y1), float(box.width), float(box.height)]

    def frame(self, ratio, dpi):
        """(background PNG or None if unchanged, items) of the figure drawn at `dpi` (`ratio` device px per CSS px)."""
        figure = self.figure
        if figure.dpi != dpi:
            figure.set_dpi(dpi)
        dynamic = list(getattr(self.view, "live_dynamic", self.view.dynamic)())
        key = (self.view.static_key(), figure.dpi)
        background = None
        if not dynamic or key != self.key or self.background is None:  # nothing named: everything is new
            kept = self._ahead.pop(key, None) if dynamic else None
            if kept is not None:  # rendered ahead of this move, and sent with its picture: the same pixels
                background = kept["png"]
                self.background, self.key, self.backgrounds = kept["region"], key, kept["number"]
                self.overlays, self._made = kept["overlays"], kept["made"]
            else:
                background = self._render(dynamic)
                self.key, self.backgrounds = key, self.rendered
        items = self._all_items(dynamic)
        named = {item["id"] for item in items if item["kind"] == "overlay"}
        if set(self.overlays) - named:  # an overlay no item names any more (a legend replaced): gone
            self.overlays = {name: pixels for name, pixels in self.overlays.items() if name in named}
            self._made = {name: key for name, key in self._made.items() if name in named}
        return background, items

    def _render(self, dynamic):
        """Draw everything but the `dynamic` artists, keep Agg's copy of it, and return it as a PNG."""
        figure, canvas = self.figure, self.figure.canvas
        with animated(dynamic):
            canvas.draw()  # everything but the changing artists
        self.background = canvas.copy_from_bbox(figure.bbox)
        self.rendered += 1
        width, height = canvas.get_width_height()
        return encode_png(np.asarray(canvas.buffer_rgba()).reshape(height, width, 4))

    def ahead(self, dpi, render=False):
        """A picture the browser can show at once for a move not made yet: the items of the figure as it is now,
        to draw over the background last sent; or, where the static part changed and `render` is true, over a
        new background rendered now, with the overlays its items name. ``{"items", "background"}`` (the number
        of the background they lie on) and, for a new one, ``"picture"`` (its PNG) and ``"overlays"``. None
        where the static part changed and `render` is false, where an overlay would be new on the background
        sent (pixels the browser has not got), or where the dpi is another.

        A background rendered here is kept: when the move is made, :meth:`frame` sends that one (the same pixels)
        rather than draw it again. Nothing else :meth:`frame` keeps is changed."""
        dynamic = list(getattr(self.view, "live_dynamic", self.view.dynamic)())
        if not dynamic or self.background is None or self.figure.dpi != dpi:
            return None
        kept = (self.background, self.key, self.backgrounds, self.overlays, self._made)
        key = (self.view.static_key(), dpi)
        if key == self.key:
            self._made = dict(self._made)
            items = self._all_items(dynamic)
            new_overlays = self.overlays is not kept[3]
            self.background, self.key, self.backgrounds, self.overlays, self._made = kept
            return None if new_overlays else {"items": items, "background": self.backgrounds}
        if not render:
            return None
        try:
            picture = self._render(dynamic)
            self.key, self.backgrounds, self._made = key, self.rendered, dict(self._made)
            items = self._all_items(dynamic)
            self._ahead.pop(key, None)
            self._ahead[key] = {
                "region": self.background,
                "png": picture,
                "number": self.backgrounds,
                "overlays": self.overlays,
                "made": self._made,
            }
            while len(self._ahead) > AHEAD_KEPT:
                self._ahead.pop(next(iter(self._ahead)))
            return {"items": items, "background": self.backgrounds, "picture": picture, "overlays": self.overlays}
        finally:
            self.background, self.key, self.backgrounds, self.overlays, self._made = kept

    def _all_items(self, dynamic):
        renderer = self.figure.canvas.get_renderer()
        fit_boxes(self.figure, renderer)  # where the axes lie for their limits now, as a draw would put them
        items = []
        for artist in dynamic:
            if artist.get_visible():
                items.extend(self._items(artist, renderer))
        return items

    def _items(self, artist, renderer):
        from matplotlib.axis import Axis
        from matplotlib.collections import PolyCollection
        from matplotlib.image import AxesImage
        from matplotlib.legend import Legend
        from matplotlib.lines import Line2D
        from matplotlib.text import Text

        if isinstance(artist, Legend):
            return [self._overlay(artist, renderer)]
        if isinstance(artist, Line2D):
            return [self._line(artist, renderer)]
        if isinstance(artist, Axis):
            return self._axis(artist, renderer)
        if isinstance(artist, Text):
            return self._text(artist, renderer)
        if isinstance(artist, PolyCollection):
            return [self._polygons(artist, renderer)]
        if isinstance(artist, AxesImage):
            return [self._image(artist)]
        return [self._patch(artist, renderer)]

    def _line(self, line, renderer):
        scale = renderer.points_to_pixels(1.0)
        if line._invalidx or line._invalidy or line._path is None:  # as Line2D.draw does
            line.recache()
        path = line._get_transformed_path().get_fully_transformed_path()
        xy = self._device(path.vertices)
        item = {"kind": "line", "xy": _float32(xy), "clip": self._clip(line)}
        style = line.get_linestyle()
        if style not in ("None", " ", "", "none") and line.get_linewidth() > 0:
            offset, dashes = line._dash_pattern
            item["stroke"] = _rgba(line.get_color(), line.get_alpha())
            item["width"] = float(line.get_linewidth() * scale)
            item["dashes"] = [float(d * scale) for d in dashes] if dashes else []
            item["offset"] = float(offset * scale) if dashes else 0.0
            capstyle = line.get_dash_capstyle() if dashes else line.get_solid_capstyle()
            joinstyle = line.get_dash_joinstyle() if dashes else line.get_solid_joinstyle()
            item["cap"], item["join"] = CAPS.get(capstyle, "butt"), str(joinstyle)
        marker = line._marker
        if marker.get_marker() not in ("None", None, "", " ", "none"):
            from matplotlib.transforms import Affine2D

            size = renderer.points_to_pixels(line.get_markersize())
            shape = marker.get_path().transformed(marker.get_transform() + Affine2D().scale(size, -size))
            outline = [p for p in shape.to_polygons(closed_only=False) if len(p)]
            fill = marker.is_filled() and marker.get_fillstyle() != "none"
            item["marker"] = {
                "outline": _float32(np.concatenate(outline)) if outline else b"",
                "counts": [len(p) for p in outline],
                "closed": bool(marker.is_filled()),
                "fill": _rgba(line.get_markerfacecolor(), line.get_alpha()) if fill else None,
                "stroke": _rgba(line.get_markeredgecolor(), line.get_alpha()),
                "width": float(line.get_markeredgewidth() * scale),
            }
        return item

    def _text(self, text, renderer):
        """A text item, or a patch of its pixels where the browser could not lay it out as matplotlib does."""
        string = text.get_text()
        if not string or not text.get_visible():
            return []
        if "\n" in string or "$" in string or text.get_usetex():
            return [self._patch(text, renderer)]
        # matplotlib's layout: the line's baseline starts at `start` (display coordinates) and runs at `angle`
        _, ((_, (width, _, _), offset),), _ = text._get_layout(renderer)
        anchor = text.get_transform().transform(text.get_unitless_position())
        angle = np.deg2rad(text.get_rotation())
        align = {"left": "left", "center": "center", "right": "right"}[text.get_horizontalalignment()]
        along = {"left": 0.0, "center": 0.5, "right": 1.0}[align] * width  # the aligned point, kept in place
        x = anchor[0] + offset[0] + along * np.cos(angle)
        y = self.figure.bbox.height - (anchor[1] + offset[1] + along * np.sin(angle))
        rotation = float(text.get_rotation())
        props = text.get_fontproperties()
        family = list(props.get_family())
        if family and family[0] in ("sans-serif", "sans"):
            from matplotlib import rcParams

            family = list(rcParams["font.sans-serif"][:2]) + ["sans-serif"]
        weight = props.get_weight()
        return [
            {
                "kind": "text",
                "text": string,
                "x": float(x),
                "y": float(y),
                "angle": float(rotation),
                "align": align,
                "font": f"{props.get_style()} {weight} {renderer.points_to_pixels(props.get_size_in_points()):.2f}px "
                + ", ".join(f'"{name}"' if name not in ("sans-serif", "serif") else name for name in family),
                "fill": _rgba(text.get_color(), text.get_alpha()),
                "clip": self._clip(text),
            }
        ]

    def _axis(self, axis, renderer):
        """An axis as matplotlib's Axis.draw lays it out: its ticks' lines and labels, its label, its offset."""
        ticks = axis._update_ticks()
        above, below = axis._get_ticklabel_bboxes(ticks, renderer)
        items = []
        for tick in ticks:
            for line in (tick.gridline, tick.tick1line, tick.tick2line):
                if line.get_visible():
                    items.append(self._line(line, renderer))
            for label in (tick.label1, tick.label2):
                if label.get_visible():
                    items += self._text(label, renderer)
        axis._update_label_position(renderer)
        items += self._text(axis.label, renderer)
        axis._update_offset_text_position(above, below)
        axis.offsetText.set_text(axis.major.formatter.get_offset())
        items += self._text(axis.offsetText, renderer)
        return items

    def _polygons(self, collection, renderer):
        collection.update_scalarmappable()  # the colours of its values (set_array) through its colour map
        transform = collection.get_transform()
        paths = collection.get_paths()
        outlines = [self._device(transform.transform(p.vertices)) for p in paths]
        counts = [len(p) for p in outlines]
        faces = np.asarray(collection.get_facecolor(), dtype=float).reshape(-1, 4)
        edges = np.asarray(collection.get_edgecolor(), dtype=float).reshape(-1, 4)
        widths = np.asarray(collection.get_linewidth(), dtype=float).reshape(-1)
        scale = renderer.points_to_pixels(1.0)
        item = {
            "kind": "polygons",
            "xy": _float32(np.concatenate(outlines)) if outlines else b"",
            "counts": counts,
            "faces": np.ascontiguousarray(np.round(255 * faces), dtype=np.uint8).tobytes() if len(faces) else b"",
            "face_count": len(faces),
            "edge": _rgba(tuple(edges[0])) if len(edges) and edges[0][3] > 0 else None,
            "width": float(widths[0] * scale) if len(widths) else 0.0,
            "clip": self._clip(collection),
        }
        hatch = collection.get_hatch()
        if hatch:
            slashes = sum(hatch.count(c) for c in "/xX")
            item["hatch"] = {
                "spacing": float(self.figure.dpi / max(1, 6 * slashes)),  # matplotlib's: 6 lines an inch per "/"
                "stroke": _rgba(collection.get_hatchcolor()[0] if len(collection.get_hatchcolor()) else "black"),
                "width": float(collection.get_hatch_linewidth() * scale),
            }
        return item

    def _image(self, image):
        rgba = image.to_rgba(image.get_array(), bytes=True)
        x0, x1, y0, y1 = image.get_extent()
        corners = self._device(image.get_transform().transform([[x0, y0], [x1, y1]]))
        if image.origin != "lower":  # pixel row 0 is the top row of the picture either way
            pass
        else:
            rgba = rgba[::-1]
        (left, top), (right, bottom) = corners.min(axis=0), corners.max(axis=0)
        return {
            "kind": "image",
            "rgba": np.ascontiguousarray(rgba, dtype=np.uint8).tobytes(),
            "size": [int(rgba.shape[1]), int(rgba.shape[0])],
            "box": [float(left), float(top), float(right - left), float(bottom - top)],
            "smooth": image.get_interpolation() not in ("nearest", "none"),
            "clip": self._clip(image),
        }

    def _overlay(self, artist, renderer):
        """The pixels of `artist` alone, with their transparency (Agg's RGBA is not premultiplied, as the browser's
        ImageData), cut to its box; kept while the background's key stays (a legend changes with the axes)."""
        from matplotlib.backends.backend_agg import RendererAgg

        name = f"{type(artist).__name__.lower()}-{id(artist)}"
        item = {"kind": "overlay", "id": name}
        if self._made.get(name) == self.key:
            return item
        width, height = self.figure.canvas.get_width_height()
        clear = RendererAgg(width, height, self.figure.dpi)
        artist.draw(clear)
        box = artist.get_window_extent(renderer)
        left, right = max(0, int(np.floor(box.x0)) - 2), min(width, int(np.ceil(box.x1)) + 2)
        top, bottom = max(0, int(np.floor(height - box.y1)) - 2), min(height, int(np.ceil(height - box.y0)) + 2)
        overlay = {"rgba": b"", "box": [0, 0, 0, 0]}
        if right > left and bottom > top:
            pixels = np.asarray(clear.buffer_rgba())[top:bottom, left:right]
            overlay = {"rgba": np.ascontiguousarray(pixels).tobytes(), "box": [left, top, right - left, bottom - top]}
        self.overlays = {**self.overlays, name: overlay}  # a new dict: the widget's trait sees the change
        self._made[name] = self.key
        return item

    def _patch(self, artist, renderer):
        """The pixels of `artist`'s box, drawn by Agg over the background (a title, a colour bar)."""
        canvas = self.figure.canvas
        canvas.restore_region(self.background)
        self.figure.draw_artist(artist)
        box = artist.get_window_extent(renderer)
        if hasattr(artist, "get_tightbbox"):
            tight = artist.get_tightbbox(renderer)
            if tight is not None:
                box = tight
        width, height = canvas.get_width_height()
        left, right = max(0, int(np.floor(box.x0)) - 2), min(width, int(np.ceil(box.x1)) + 2)
        top, bottom = max(0, int(np.floor(height - box.y1)) - 2), min(height, int(np.ceil(height - box.y0)) + 2)
        if right <= left or bottom <= top:
            return {"kind": "patch", "rgba": b"", "box": [0, 0, 0, 0]}
        pixels = np.asarray(canvas.buffer_rgba()).reshape(height, width, 4)[top:bottom, left:right]
        return {
            "kind": "patch",
            "rgba": np.ascontiguousarray(pixels).tobytes(),
            "box": [left, top, right - left, bottom - top],
        }
