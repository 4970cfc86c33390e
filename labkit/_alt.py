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

Nothing here imports matplotlib or IPython unless they are loaded already, so
``import labkit`` stays light.
"""

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
    try:
        printer = formatter.lookup_by_type(Figure)
    except KeyError:
        return
    if getattr(printer, "labkit_alt", False):
        return
    formatter.for_type(Figure, _with_alt(printer))


def _with_alt(printer):
    def print_with_alt(figure):
        output = printer(figure)
        alt = figure_alt(figure)
        if output is None or not alt:
            return output
        data, metadata = output if isinstance(output, tuple) else (output, {})
        return data, {**(metadata or {}), "alt": alt}

    print_with_alt.labkit_alt = True
    print_with_alt.wrapped = printer
    return print_with_alt
