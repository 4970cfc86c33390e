"""Pictures drawn ahead (labkit.plots.explorers.AHEAD): after a slider's move the kernel sends the pictures of its
next moves, which image.js shows at a key press without a round trip. Each must be the very picture the kernel
draws when the move is made, lie on the background already sent, and leave nothing of the explorer changed."""

import io

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import pytest
from PIL import Image

from labkit import plots
from labkit.plots import explorers

SLIDERS = [
    (plots.limacon_explorer, "intervals"),
    (plots.limacon_explorer, "r0"),
    (plots.convergence_explorer, "ndata"),
    (plots.mesh_explorer, "dxds_AD"),
    (plots.mesh_explorer, "twist"),
    (plots.mesh_explorer, "elements"),
    (plots.spline_explorer, "ndata"),
    (plots.pchip_explorer, "y1"),
    (plots.pchip_explorer, "y3"),
    (plots.bilinear_explorer, "ndata"),
]


@pytest.fixture(autouse=True)
def close_figures():
    yield
    plt.close("all")


class Sent:
    """Every value the explorer's image widget sends to the browser for `names`, in order."""

    def __init__(self, image, names=("ahead",)):
        self.values = []
        image.observe(lambda change: self.values.append(change["new"]), names=list(names))

    def entries(self):
        return [entry for batch in self.values for entry in batch]


def _scene_without_seq(scene):
    return {key: value for key, value in scene.items() if key != "seq"}


def _comparable(scene):
    """A scene of one explorer comparable with another's: an overlay is named by its artist's id(), so by its
    place here; a background by its pixels (its number counts the backgrounds rendered, ahead of moves too)."""
    items = [{**item, "id": k} if item["kind"] == "overlay" else item for k, item in enumerate(scene["items"])]
    return {**_scene_without_seq(scene), "items": items, "background": None}


def _pixels(png):
    return np.asarray(Image.open(io.BytesIO(png)))


@pytest.mark.parametrize("factory, name", SLIDERS, ids=lambda v: getattr(v, "__name__", v))
def test_a_picture_drawn_ahead_is_the_picture_the_kernel_draws_for_that_move(factory, name):
    explorer = factory()
    slider = explorer.controls[name]
    sent = Sent(explorer.image)
    start = slider.value
    slider.value = start + slider.step if start + slider.step <= slider.max else start - slider.step
    entries = sent.entries()
    assert entries, f"{name}: nothing drawn ahead"
    direction = np.sign(slider.value - start)
    # the next move first, alone; then the one after and the one back
    assert len(sent.values[0]) == 1 and sent.values[0][0]["values"][name] == pytest.approx(
        slider.value + direction * slider.step
    )
    moved = slider.value
    for entry in entries:
        assert set(entry["values"]) == set(explorer.controls)
        others = {k: v for k, v in explorer.browser_values(explorer.values()).items() if k != name}
        assert {k: v for k, v in entry["values"].items() if k != name} == others
        assert entry["base"] == explorer.scene.backgrounds  # drawn from the background on the page
        slider.value = entry["values"][name]  # the move made: the kernel draws it
        assert explorer.scene.backgrounds == entry["background"]  # on the background sent, or sent with it
        if "picture" in entry:
            assert explorer.image.background == entry["picture"]
            assert explorer.image.overlays == entry["overlays"]
        assert _scene_without_seq(explorer.image.scene) == _scene_without_seq(entry["scene"])
        assert explorer.image.description == entry["description"]
        slider.value = moved


@pytest.mark.parametrize("factory, name", SLIDERS, ids=lambda v: getattr(v, "__name__", v))
def test_drawing_ahead_changes_nothing_the_explorer_draws(factory, name, monkeypatch):
    """The same moves, with and without pictures drawn ahead: the same scenes, backgrounds, static picture and
    description at every step (the views keep their axes by history, so an ahead that moved them would show)."""

    def run(ahead):
        monkeypatch.setattr(explorers, "AHEAD", ahead)
        explorer = factory()
        slider = explorer.controls[name]
        span = slider.max - slider.min
        moves = [slider.min + f * span for f in (0.5, 0.55, 0.95, 1.0, 0.0)]
        moves = [type(slider.value)(round(v / slider.step) * slider.step) for v in moves]
        seen = []
        for value in moves:
            slider.value = value
            seen.append(
                (
                    _comparable(explorer.image.scene),
                    explorer.image.background,  # its pixels (PNG), sent again only when they change
                    list(explorer.image.overlays.values()),  # named by id() too
                    explorer.image.description,
                    explorer.description,
                )
            )
        seen.append(_pixels(explorer.png()))
        return seen

    with_ahead, without = run(explorers.AHEAD), run(())
    assert without[:-1] == with_ahead[:-1]
    assert np.array_equal(with_ahead[-1], without[-1])


def test_the_next_move_that_needs_a_new_background_is_drawn_ahead_with_it(monkeypatch):
    """The limaçon's axes fit again once a growing r0 leaves them. The move that does so is drawn ahead, when it is
    the next one, on a new background sent with it (PNG and legend pixels), which the kernel then sends as its own
    when the move is made, without rendering it again; the move after it (two steps on) is not drawn ahead."""
    ahead = explorers.AHEAD
    monkeypatch.setattr(explorers, "AHEAD", ())
    probe = plots.limacon_explorer()
    slider, moves = probe.controls["r0"], []
    while slider.value + slider.step <= slider.max:
        before = probe.scene.backgrounds
        slider.value = round(slider.value + slider.step, 12)
        moves.append((slider.value, probe.scene.backgrounds > before, probe.image.background, probe.image.scene))
    # the first refit after a move that kept the axes (1.15 up to 2.0 grows the curve past its axes)
    refit, _, picture, scene = next(m for m, last in zip(moves[1:], moves) if m[1] and not last[1])

    monkeypatch.setattr(explorers, "AHEAD", ahead)
    explorer = plots.limacon_explorer()
    slider = explorer.controls["r0"]
    sent = Sent(explorer.image)
    while round(slider.value + 2 * slider.step, 12) < refit:  # up to two steps before it: the refit is two on
        slider.value = round(slider.value + slider.step, 12)
    assert refit not in [pytest.approx(e["values"]["r0"]) for e in sent.entries()]  # not from two steps before
    sent.values.clear()
    slider.value = round(slider.value + slider.step, 12)  # the refit is the next move now
    first = sent.values[0][0]
    assert first["values"]["r0"] == pytest.approx(refit)
    assert first["base"] == explorer.scene.backgrounds != first["background"]  # drawn from the page's, on its own
    assert first["picture"] == picture  # the background the kernel renders for that move, pixel for pixel
    assert all("picture" not in e and e["base"] == e["background"] for batch in sent.values[1:] for e in batch)

    rendered = explorer.scene.rendered
    slider.value = refit
    assert explorer.scene.rendered == rendered  # not rendered again: the one drawn ahead is sent
    assert explorer.scene.backgrounds == first["background"] and explorer.image.background == picture
    assert _comparable(explorer.image.scene) == _comparable(scene) == _comparable(first["scene"])
    assert list(explorer.image.overlays.values()) == list(first["overlays"].values())
    assert explorer.image.description == first["description"]


def test_a_checkbox_or_a_dropdown_draws_nothing_ahead():
    explorer = plots.spline_explorer()
    sent = Sent(explorer.image)
    explorer.controls["natural"].value = False
    assert sent.values == []
    explorer = plots.convergence_explorer()
    sent = Sent(explorer.image)
    explorer.controls["method"].value = "plin"
    assert sent.values == []


def test_the_image_names_its_controls_and_where_the_browser_holds_their_values():
    explorer = plots.limacon_explorer()
    controls = explorer.controls
    assert explorer.image.controls == {
        "intervals": [controls["intervals"].model_id, "value"],
        "r0": [controls["r0"].model_id, "value"],
        "method": [controls["method"].model_id, "index"],  # a dropdown's value stays in the kernel
    }
    controls["method"].value = "plin"
    assert explorer.image.scene["values"] == {"intervals": 20, "r0": 1.15, "method": 1}


EDITOR_FIELDS = ("readout", "worst", "alt", "status")


@pytest.mark.parametrize("name", ["elements", "twist"])
def test_the_editors_sliders_draw_ahead_the_mesh_and_readout_the_kernel_sends(name):
    editor = plots.patch_editor(elements=6)
    slider = getattr(editor, name)
    sent = Sent(editor.widget_)
    slider.value = slider.value + slider.step
    entries = sent.entries()
    assert [entry["values"][name] for entry in entries] == pytest.approx(
        [slider.value + slider.step, slider.value + 2 * slider.step, slider.value - slider.step]
    )
    moved = slider.value
    for entry in entries:
        slider.value = entry["values"][name]
        widget = editor.widget_
        assert _scene_without_seq(widget.scene) == _scene_without_seq(entry["scene"])
        assert {field: getattr(widget, field) for field in EDITOR_FIELDS} == {f: entry[f] for f in EDITOR_FIELDS}
        assert (
            widget.scene["values"]
            == entry["values"]
            == {"elements": editor.elements.value, "twist": editor.twist.value, "shape": widget.ack}
        )
        slider.value = moved


def test_a_drag_keys_the_editors_pictures_anew():
    """A picture drawn before a drag shows the corners before it: its key (the last drag drawn) is another."""
    editor = plots.patch_editor(elements=6)
    sent = Sent(editor.widget_)
    editor.elements.value = 7
    before = sent.entries()[0]["values"]
    editor.widget_.drag = {"index": 1, "x": 1.6, "y": 0.2, "seq": 1}
    assert editor.widget_.ack == 1 and editor.widget_.scene["values"] == {**before, "elements": 7, "shape": 1}
    assert before["shape"] == 0


def test_drawing_ahead_changes_nothing_the_editor_draws(monkeypatch):
    def run(ahead):
        monkeypatch.setattr(explorers, "AHEAD", ahead)
        editor = plots.patch_editor(elements=6)
        seen = []
        for name, value in (("elements", 7), ("twist", 0.5), ("elements", 12), ("twist", -1.0), ("elements", 4)):
            getattr(editor, name).value = value
            widget = editor.widget_
            seen.append((_comparable(widget.scene), [getattr(widget, f) for f in EDITOR_FIELDS], widget.handles))
        seen.append(_pixels(editor.png()))
        return seen

    with_ahead, without = run(explorers.AHEAD), run(())
    assert without[:-1] == with_ahead[:-1]
    assert np.array_equal(with_ahead[-1], without[-1])


@pytest.mark.parametrize("factory, name", SLIDERS, ids=lambda v: getattr(v, "__name__", v))
def test_drawing_ahead_changes_nothing_step_by_step(factory, name, monkeypatch):
    """One step at a time, as a student's key presses go, across the axes' refits and back now and then: the same scenes,
    backgrounds and descriptions with and without pictures drawn ahead (a background rendered ahead must leave
    the axes' box where the figure's own limits put it: an equal-aspect box follows its limits)."""

    def run(ahead):
        monkeypatch.setattr(explorers, "AHEAD", ahead)
        explorer = factory()
        slider = explorer.controls[name]
        steps = [1, 1, -1] * 12 + [1] * 12  # forward, with a step back now and then
        seen = []
        for step in steps:
            value = round(slider.value + step * slider.step, 12)
            if not slider.min <= value <= slider.max:
                continue
            slider.value = value
            seen.append(
                (
                    _comparable(explorer.image.scene),
                    explorer.image.background,
                    list(explorer.image.overlays.values()),
                    explorer.image.description,
                )
            )
        seen.append(_pixels(explorer.png()))
        return seen

    with_ahead, without = run(explorers.AHEAD), run(())
    assert len(without) > 10
    for k, (a, b) in enumerate(zip(with_ahead[:-1], without[:-1])):
        assert a == b, f"step {k} differs"
    assert np.array_equal(with_ahead[-1], without[-1])
