"""Alternative text for the pictures labkit draws: what each figure shows, in numbers.

A labkit figure function describes its axes with :func:`describe` (for example
"error of the natural spline with 19 points: largest 8.4e-3 at x = 0.15").
When the figure is shown in a notebook, IPython's PNG formatter for matplotlib
figures (the inline backend's) returns the picture together with the metadata
``{"alt": ...}``, which IPython files under the output's ``metadata["image/png"]``:
the key ``IPython.display.Image(alt=...)`` uses, and the one nbconvert's HTML
templates read for the ``<img alt="...">`` of the exported page. A figure with
several described axes joins their texts; a figure labkit did not describe
keeps the inline backend's output unchanged.

JupyterLab's image renderer ignores that metadata, so a described figure also gets
a ``text/html`` output, :func:`img_tag`: the same PNG as an ``<img>`` with the text
as its ``alt``. JupyterLab, nbconvert, GitHub and nbviewer show the richer ``text/html``;
the ``image/png`` stays for the rest (and for the tests that read its metadata).

Nothing here imports matplotlib or IPython unless they are loaded already, so
``import labkit`` stays light.
"""

import base64
import html
import sys

ATTRIBUTE = "_labkit_alt"


def describe(ax, text):
    """Give the axes `ax` the alternative text `text`; return `ax`.

    In an IPython session, make sure the figure's PNG output carries it.
    """
    setattr(ax, ATTRIBUTE, str(text))
    install()
    return ax


def figure_alt(figure):
    """The alternative text of a matplotlib figure: its described axes' texts, joined; "" if none."""
    texts = [getattr(ax, ATTRIBUTE, "") for ax in getattr(figure, "axes", ())]
    return "; ".join(text for text in texts if text)


def sci(value):
    """A number in the short scientific notation of the alt texts: 8.4e-3, -1.2e+1, 0."""
    value = float(value)
    if value == 0 or value != value or value in (float("inf"), float("-inf")):
        return f"{value:g}"
    mantissa, exponent = f"{value:.1e}".split("e")
    return f"{mantissa}e{int(exponent)}"


def num(value):
    """A number with three significant digits: 0.15, 2.5, 1.2e+03."""
    text = f"{float(value):.3g}"
    return "0" if text == "-0" else text


def install():
    """Wrap the current IPython shell's PNG printer for matplotlib figures (once) so that it adds the alt text.

    Called on every :func:`describe`, so a printer that ``%matplotlib inline`` (or
    ``set_matplotlib_formats``) registers afresh is wrapped again. Outside IPython, or
    before a figure printer exists, nothing happens.
    """
    if "IPython" not in sys.modules or "matplotlib.figure" not in sys.modules:
        return
    shell = sys.modules["IPython"].get_ipython()
    if shell is None or not hasattr(shell, "display_formatter"):
        return
    from matplotlib.figure import Figure

    formatter = shell.display_formatter.formatters["image/png"]
    html_formatter = shell.display_formatter.formatters["text/html"]
    try:
        printer = formatter.lookup_by_type(Figure)
    except KeyError:  # no PNG of figures (SVG chosen, say): no <img> of one either
        html_formatter.pop(Figure, None)
        return
    if not getattr(printer, "labkit_alt", False):
        printer = _with_alt(printer)
        formatter.for_type(Figure, printer)
    try:
        current = html_formatter.lookup_by_type(Figure)
    except KeyError:
        current = None
    if getattr(current, "png_printer", None) is not printer:
        html_formatter.for_type(Figure, _html_printer(printer))


def img_tag(picture, alt, width=None, height=None):
    """An HTML ``<img>`` of a PNG (bytes, or their base64 text) with `alt` as its alternative text, escaped.

    >>> img_tag(b"PNG", 'a "quoted" <b>', width=10)
    '<img src="data:image/png;base64,UE5H" alt="a &quot;quoted&quot; &lt;b&gt;" width="10">'
    """
    if isinstance(picture, bytes):
        picture = base64.b64encode(picture).decode("ascii")
    size = "".join(f' {name}="{int(value)}"' for name, value in (("width", width), ("height", height)) if value)
    return f'<img src="data:image/png;base64,{picture}" alt="{html.escape(str(alt), quote=True)}"{size}>'


def _html_printer(png_printer):
    """The ``text/html`` printer of figures: the PNG printer's picture in an ``<img>`` with the alt text.

    IPython asks for ``text/html`` before ``image/png``: the picture drawn here is kept on the figure for
    the PNG printer (:func:`_with_alt`), so a figure is drawn once for both."""

    def print_html(figure):
        if not figure_alt(figure):
            return None
        output = png_printer(figure)
        if output is None:
            return None
        setattr(figure, _DRAWN, output)
        data, metadata = output if isinstance(output, tuple) else (output, {})
        metadata = metadata or {}
        return img_tag(data, metadata["alt"], metadata.get("width"), metadata.get("height"))

    print_html.png_printer = png_printer
    return print_html


_DRAWN = "_labkit_drawn_png"


def _with_alt(printer):
    def print_with_alt(figure):
        drawn = figure.__dict__.pop(_DRAWN, None)  # what the text/html printer drew a moment ago
        if drawn is not None:
            return drawn
        output = printer(figure)
        alt = figure_alt(figure)
        if output is None or not alt:
            return output
        data, metadata = output if isinstance(output, tuple) else (output, {})
        return data, {**(metadata or {}), "alt": alt}

    print_with_alt.labkit_alt = True
    print_with_alt.wrapped = printer
    return print_with_alt
