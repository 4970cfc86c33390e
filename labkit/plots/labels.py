"""Accessible names for the sliders of labkit's widgets.

ipywidgets draws a slider's handle (the element with ``role="slider"`` that
takes the keyboard) without an accessible name: the description is a
separate ``<label>`` not tied to it, so a screen reader announces only
"slider" and axe-core reports ``aria-input-field-name``.
:func:`label_sliders` puts a small invisible anywidget (``labels.js`` beside
this file) into a box; in the browser it names every slider handle in that
box after the slider's description.
"""

import functools
import pathlib


@functools.cache
def _labeller_class():
    import anywidget

    class SliderLabels(anywidget.AnyWidget):
        """Draws nothing; names the slider handles of the box it is in (labels.js)."""

        _esm = pathlib.Path(__file__).with_name("labels.js")

    return SliderLabels


def label_sliders(box):
    """Add to the ipywidgets `box` the invisible widget that names its sliders' handles; return `box`.

    Examples
    --------
    >>> import ipywidgets as widgets
    >>> box = label_sliders(widgets.VBox([widgets.IntSlider(description="ndata")]))
    >>> type(box.children[-1]).__name__, box.children[-1].layout.display
    ('SliderLabels', 'none')
    """
    import ipywidgets as widgets

    labeller = _labeller_class()(layout=widgets.Layout(display="none"))
    box.children = (*box.children, labeller)
    return box
