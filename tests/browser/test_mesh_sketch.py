"""mesh.js in Chromium: the patch editor's page draws a moved handle's mesh itself (the editor's `sketch`); its
scene items must be the kernel's own for that move, vertex, colour and title, at every mesh size, pixel ratio and
twist, for corner and arrow-tip moves, folded meshes and drags of several steps that the kernel gets as one."""

from pathlib import Path

import numpy as np
import pytest
from jupyterlab_session import REVIVE, page_json, skip_without_chromium

pytest.importorskip("playwright.sync_api", reason="playwright is not installed (test extras)")
pytest.importorskip("anywidget", reason="anywidget is not installed")
skip_without_chromium()

from labkit.plots.editor import FIRST_PATCH, Editor, handle_positions, with_twist

PLOTS = Path(__file__).resolve().parents[2] / "labkit" / "plots"
SKETCHED = """window.sketched = (text) => {
  const {sketch, corners, moves} = revive(text);
  let now = corners;
  for (const [index, x, y] of moves) now = meshMove(now, index, [x, y], sketch.arrow);
  const {items, worst} = meshItems(sketch, now);
  return {worst, items: items.map((item) => Object.fromEntries(Object.entries(item).map(([k, v]) =>
    [k, ArrayBuffer.isView(v) ? Array.from(v) : v])))};
};"""


@pytest.fixture(scope="module")
def page(browser):
    page = browser.new_page()
    page.set_content("<html><body></body></html>")
    page.add_script_tag(content=(PLOTS / "scene.js").read_text() + (PLOTS / "mesh.js").read_text() + REVIVE + SKETCHED)
    yield page
    page.close()


def _editor(elements, twist, ratio):
    editor = Editor(with_twist(list(FIRST_PATCH), twist), elements)
    editor.twist.value = twist
    editor.widget_.pixel_ratio = ratio
    return editor


def _drag(editor, moves):
    """The kernel's scene after a drag whose steps are `moves` [(handle, x, y)]: it gets the last one only."""
    index, x, y = moves[-1]
    editor.widget_.drag = {"index": index, "x": x, "y": y, "seq": editor.widget_.ack + 1}
    return editor.widget_.scene["items"]


def _compare(page, editor, moves):
    sketch, corners = editor.widget_.sketch, editor.widget_.scene["corners"]
    assert sketch, "the editor sent no sketch"
    mine = page.evaluate("text => sketched(text)", page_json({"sketch": sketch, "corners": corners, "moves": moves}))
    theirs = _drag(editor, moves)
    assert editor.widget_.sketch == sketch  # a drag leaves the sketch as it was: it is not sent again
    assert [i["kind"] for i in mine["items"]] == [i["kind"] for i in theirs]
    for drawn, kernel in zip(mine["items"], theirs):
        assert set(drawn) == set(kernel)
        for key, value in kernel.items():
            if key == "xy":
                np.testing.assert_allclose(np.asarray(drawn[key], float), np.frombuffer(value, "<f4"), atol=1e-3)
            elif isinstance(value, bytes):
                assert bytes(drawn[key]) == value, key
            else:
                assert drawn[key] == value, key
    assert mine["worst"] == pytest.approx(editor.view.mesh.quality().min(), abs=1e-12)
    return editor.view.mesh.quality()


@pytest.mark.parametrize("elements, twist, ratio", [(10, 0.0, 1.0), (2, 0.7, 2.0), (23, -1.3, 1.5), (40, 0.2, 2.0)])
def test_the_page_draws_a_handle_move_as_the_kernel_does(page, elements, twist, ratio):
    editor = _editor(elements, twist, ratio)
    rng = np.random.default_rng(elements)
    folded = 0
    for step in range(12):
        handles = handle_positions(editor.corners)
        index = int(rng.integers(12))
        x, y = handles[index] + rng.normal(scale=0.25 if step % 3 else 0.8, size=2)  # every third a big move
        quality = _compare(page, editor, [(index, float(x), float(y))])
        folded += int(np.any(quality <= 0))
    assert folded, "no move folded the mesh: the hatched elements were not compared"


def test_a_drag_of_several_steps_ends_where_the_kernel_does(page):
    editor = _editor(10, 0.0, 2.0)
    for index in (1, 6, 11):  # a corner (carrying its arrows), a d/ds tip, a d/dt tip
        x, y = handle_positions(editor.corners)[index]
        _compare(page, editor, [(index, x + 0.05 * k, y - 0.03 * k) for k in range(1, 6)])


def test_python_ties_and_signed_zero_in_the_title(page):
    written = page.evaluate("() => [0.125, -0.125, 0.375, 0.625, -0.875, 0.955, -0.001, -0, 1, 0.5].map(meshFixed2)")
    assert written == [f"{v:.2f}" for v in (0.125, -0.125, 0.375, 0.625, -0.875, 0.955, -0.001, -0.0, 1.0, 0.5)]


def test_a_square_mesh_takes_the_colour_maps_top_end(page):
    from labkit import Corner

    square = [Corner(p, [1.0, 0.0], [0.0, 1.0]) for p in ([0, 0], [1, 0], [1, 1], [0, 1])]
    editor = Editor(square, 6)
    x, y = handle_positions(editor.corners)[1]
    quality = _compare(page, editor, [(1, float(x), float(y))])  # a drag that leaves corner B where it is
    assert np.all(quality == 1.0)  # every element exactly square: the colour of quality 1 is the last one
