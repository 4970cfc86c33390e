"""The patch editor for keyboard and screen-reader users, without a browser: what the live region says,
that its numbers are the mesh's, the keys it names, and the sliders' accessible names.

The browser side (Tab leaves the editor, n / p and the arrows, the live region, axe-core) is
tests/browser/test_accessibility.py.
"""

import re

import matplotlib

matplotlib.use("Agg")
import numpy as np
import pytest

import labkit
from labkit import plots
from labkit.plots import editor as editor_module

ROOT = __import__("pathlib").Path(__file__).resolve().parents[2]
SQUARE = [labkit.Corner(p, [1.0, 0.0], [0.0, 1.0]) for p in ([0, 0], [1, 0], [1, 1], [0, 1])]
STATUS = re.compile(
    r"^(?P<name>.+) at \((?P<x>[-\d.]+), (?P<y>[-\d.]+)\)\. Worst quality (?P<worst>[-\d.]+)(, (?P<folded>\d+) folded)?\.$"
)


def _worst_and_folded(corners, n):
    """The smallest sine of a corner angle over all elements, and how many elements have one <= 0, from the
    patch's points alone (the mathematics of the scaled Jacobian, not labkit's Mesh.quality)."""
    s = np.linspace(0, 1, n)
    x, y = labkit.patch(*corners, s, s)[:2]
    p = np.stack([x, y], axis=-1)
    quads = np.stack([p[:-1, :-1], p[1:, :-1], p[1:, 1:], p[:-1, 1:]], axis=2)  # counter-clockwise in (s, t)
    sines = []
    for k in range(4):
        a, b = quads[:, :, (k + 1) % 4] - quads[:, :, k], quads[:, :, k - 1] - quads[:, :, k]
        a = a / np.linalg.norm(a, axis=-1, keepdims=True)
        b = b / np.linalg.norm(b, axis=-1, keepdims=True)
        sines.append(a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0])
    quality = np.min(sines, axis=0)
    return quality.min(), int(np.sum(quality <= 0))


def _parse(status):
    match = STATUS.match(status)
    assert match, f"the live region's sentence has an unexpected form: {status!r}"
    return match


@pytest.mark.parametrize("index", range(12))
def test_each_handle_is_named_after_what_dragging_it_changes(index):
    name = plots.handle_name(index)
    moved = plots.move_handle(SQUARE, index, plots.handle_positions(SQUARE)[index] + [0.1, 0.2])
    changed = [
        (letter, field)
        for letter, before, after in zip("ABCD", SQUARE, moved)
        for field in ("point", "ds", "dt")
        if not np.allclose(getattr(before, field), getattr(after, field))
    ]
    assert len(changed) == 1
    letter, field = changed[0]
    assert (
        name
        == {"point": f"corner {letter}", "ds": f"{letter}'s d/ds arrow tip", "dt": f"{letter}'s d/dt arrow tip"}[field]
    )
    assert len({plots.handle_name(i) for i in range(12)}) == 12


@pytest.mark.parametrize("index", [-1, 12, 1.0, "1", None])
def test_a_handle_outside_the_twelve_is_refused(index):
    with pytest.raises(ValueError, match="0 to 11"):
        plots.handle_name(index)


def test_the_status_names_the_handle_its_place_and_the_worst_quality():
    quality = np.array([0.9, 0.31, -0.5, 0.0])
    match = _parse(plots.status_text(SQUARE, 6, quality))  # C's d/ds tip: C + ds / 4
    assert match["name"] == "C's d/ds arrow tip"
    assert (float(match["x"]), float(match["y"])) == (1.25, 1.0)
    assert float(match["worst"]) == -0.5 and match["folded"] == "2"  # a zero quality is degenerate: folded
    assert _parse(plots.status_text(SQUARE, 0, [1.0]))["folded"] is None


def test_the_live_region_follows_the_selection_and_every_change_with_the_mesh_numbers():
    editor = plots.patch_editor(SQUARE, elements=6)
    widget = editor.widget_
    match = _parse(widget.status)
    assert match["name"] == "corner A" and float(match["worst"]) == pytest.approx(1.0)

    widget.selected = 9  # the browser's n key, pressed nine times
    match = _parse(widget.status)
    assert match["name"] == "B's d/dt arrow tip"
    assert [float(match["x"]), float(match["y"])] == pytest.approx(plots.handle_positions(editor.corners)[9])
    assert editor.redraws == 1  # selecting redraws nothing

    widget.drag = {"index": 5, "x": 0.6, "y": 0.0, "seq": 1}  # B's d/ds tip dragged back past A: folds
    worst, folded = _worst_and_folded(editor.corners, 7)
    match = _parse(widget.status)
    assert match["name"] == "B's d/ds arrow tip" and widget.selected == 5
    assert (float(match["x"]), float(match["y"])) == (0.6, 0.0)
    assert folded > 0 and int(match["folded"]) == folded
    assert float(match["worst"]) == pytest.approx(worst, abs=0.005)
    assert f"worst quality {match['worst']}, {folded} folded" in widget.readout  # the readout says the same
    assert match["worst"] in widget.alt and f"{folded} folded" in widget.alt

    editor.elements.value = 12  # a slider: the same handle, the new mesh's numbers
    worst, folded = _worst_and_folded(editor.corners, 13)
    match = _parse(widget.status)
    assert match["name"] == "B's d/ds arrow tip" and int(match["folded"]) == folded
    assert float(match["worst"]) == pytest.approx(worst, abs=0.005)


def test_the_label_and_the_docs_name_the_keys_and_tab_is_not_the_editors():
    widget = plots.patch_editor().widget_
    assert widget.label == editor_module.LABEL and widget.key_help == editor_module.KEYS
    assert widget.label.startswith("Patch editor") and widget.key_help in widget.label
    source = (ROOT / "labkit" / "plots" / "editor.js").read_text()
    cycle = re.search(r"const CYCLE = \{ n: 1, p: 11 \}", source)
    assert cycle, "editor.js's cycle keys are not n (next) and p (previous)"
    assert '"Tab"' not in source, "editor.js handles Tab: a keyboard trap (WCAG 2.1.2)"
    for key in ("n or p", "Arrow keys", "Shift", "Tab: leave"):
        assert key in editor_module.KEYS
    docs = (ROOT / "docs" / "students.md").read_text()
    for key in ("`n`", "`p`", "arrow keys", "Shift", "Tab"):
        assert key in docs.split("## Explore sections")[1]


@pytest.mark.parametrize("make", [plots.patch_editor, plots.mesh_explorer, plots.limacon_explorer])
def test_every_box_with_sliders_carries_the_hidden_widget_that_names_them(make):
    box = make().widget
    labellers = [w for w in box.children if type(w).__name__ == "SliderLabels"]
    assert len(labellers) == 1 and labellers[0].layout.display == "none"
    assert (ROOT / "labkit" / "plots" / "labels.js").read_text().count('setAttribute("aria-label"') == 1
