"""scene.js's sceneAhead in Chromium, on a page of its own with stand-ins for the widget models: which picture is
shown when pictures drawn ahead, the controls and the kernel's scenes arrive in every order. The real widgets, in
JupyterLab, are tests/browser/test_jupyterlab.py's."""

import json
from pathlib import Path

import pytest
from jupyterlab_session import skip_without_chromium

pytest.importorskip("playwright.sync_api", reason="playwright is not installed (test extras)")
skip_without_chromium()

SCENE_JS = (Path(__file__).resolve().parents[2] / "labkit" / "plots" / "scene.js").read_text()

# a model as anywidget hands it over (get, set, on, off, widget_manager.get_model), and one control model
STAND_INS = """
function standIn(state) {
  const handlers = {};
  return {
    state,
    get: (name) => state[name],
    set(name, value) { state[name] = value; (handlers["change:" + name] || []).forEach((f) => f()); },
    on(event, f) { (handlers[event] = handlers[event] || []).push(f); },
    off(event, f) { handlers[event] = (handlers[event] || []).filter((g) => g !== f); },
  };
}
window.setUp = (extra) => {
  const n = standIn({ value: 1 });
  const model = standIn({ controls: { n: ["id-n", "value"] }, ahead: [], scene: {} });
  model.widget_manager = { get_model: async (id) => (id === "id-n" ? n : undefined) };
  const shown = [];
  const node = document.createElement("div");
  let settled = true;
  const ahead = sceneAhead(model, node, (picture) => shown.push(picture.name), () => (settled ? extra : null));
  const kernel = (name, values, background) => {
    const scene = { values, background, name };
    model.set("scene", scene);
    ahead.fromKernel({ scene, values, background, name });
  };
  const picture = (name, values, background) => ({ name, values, background, scene: { values, background } });
  window.t = { n, model, shown, node, ahead, kernel, picture, settle: (s) => { settled = s; } };
};
"""


@pytest.fixture(scope="module")
def page(browser):
    page = browser.new_page()
    page.set_content("<html><body></body></html>")
    page.add_script_tag(content=SCENE_JS + STAND_INS)
    yield page
    page.close()


def run(page, steps, extra=None):
    """Set up anew, run `steps` (JavaScript using t), and return the names of the pictures shown, in order."""
    page.evaluate(f"() => setUp({json.dumps(extra or {})})")
    page.evaluate("async () => { await new Promise((r) => setTimeout(r, 0)); }")  # the control's model arrives
    return page.evaluate(f"async () => {{\n{steps}\nreturn t.shown;\n}}")


def test_a_picture_drawn_ahead_is_shown_when_the_control_reaches_its_values(page):
    shown = run(
        page,
        """t.kernel("k1", {n: 1}, 0);
        t.model.set("ahead", [t.picture("a2", {n: 2}, 0), t.picture("a3", {n: 3}, 0)]);
        t.n.set("value", 2);
        t.kernel("k2", {n: 2}, 0);  // the kernel's own scene of that move: on the page already""",
    )
    assert shown == ["k1", "a2"]


def test_numbers_match_to_rounding_and_every_control_must_match(page):
    shown = run(
        page,
        """t.kernel("k1", {n: 1}, 0);
        t.model.set("ahead", [t.picture("a2", {n: 1.2000000000000002}, 0)]);
        t.n.set("value", 1.2)""",
    )
    assert shown == ["k1", "a2"]
    shown = run(
        page,
        """t.kernel("k1", {n: 1, shape: 4}, 0);
        t.model.set("ahead", [t.picture("a2", {n: 2, shape: 3}, 0)]);  // drawn before the last drag
        t.n.set("value", 2)""",
        extra={"shape": 4},
    )
    assert shown == ["k1"]


def test_a_scene_older_than_the_page_is_not_shown_and_the_newest_is(page):
    shown = run(
        page,
        """t.kernel("k1", {n: 1}, 0);
        t.model.set("ahead", [t.picture("a2", {n: 2}, 0), t.picture("a3", {n: 3}, 0)]);
        t.n.set("value", 2);
        t.n.set("value", 3);
        t.kernel("k2", {n: 2}, 0);  // older than the page, which shows n = 3
        t.n.set("value", 4);        // nothing kept for 4: the page waits for the kernel
        t.kernel("k3", {n: 3}, 0);  // the page's own, drawn ahead
        t.kernel("k4", {n: 4}, 0)""",
    )
    assert shown == ["k1", "a2", "a3", "k4"]


def test_a_new_background_comes_from_the_kernel_and_old_pictures_ahead_do_not_lie_on_it(page):
    shown = run(
        page,
        """t.kernel("k1", {n: 1}, 0);
        t.model.set("ahead", [t.picture("a2", {n: 2}, 0), t.picture("a1", {n: 1}, 0)]);
        t.n.set("value", 2);
        t.kernel("k2", {n: 2}, 1);  // the same values on a new background (the axes fitted again): shown
        t.n.set("value", 1);        // kept for n = 1, but on the old background: not shown
        t.kernel("k1b", {n: 1}, 1)""",
    )
    assert shown == ["k1", "a2", "k2", "k1b"]


def test_nothing_is_drawn_ahead_while_the_values_are_in_flux(page):
    shown = run(
        page,
        """t.kernel("k1", {n: 1}, 0);
        t.settle(false);  // a drag on its way
        t.model.set("ahead", [t.picture("a2", {n: 2}, 0)]);
        t.n.set("value", 2);
        t.kernel("k2", {n: 2}, 0)""",
    )
    assert shown == ["k1", "k2"]


def test_the_newest_pictures_are_kept_and_counted(page):
    kept = page.evaluate(
        """async () => { setUp({}); await new Promise((r) => setTimeout(r, 0));
        const counts = [];
        t.model.set("ahead", [t.picture("a", {n: 2}, 0)]);
        t.model.set("ahead", [t.picture("again", {n: 2}, 0)]);  // the same values: replaced, not added
        counts.push(Number(t.node.dataset.labkitKept));
        for (let k = 0; k < 20; k++) t.model.set("ahead", [t.picture("a" + k, {n: 100 + k}, 0)]);
        counts.push(Number(t.node.dataset.labkitKept));
        t.n.set("value", 2);  // the oldest were let go
        return [counts, t.shown]; }"""
    )
    assert kept == [[1, 12], []]


def test_after_dispose_the_controls_are_not_watched(page):
    shown = run(
        page,
        """t.kernel("k1", {n: 1}, 0);
        t.model.set("ahead", [t.picture("a2", {n: 2}, 0)]);
        t.ahead.dispose();
        t.n.set("value", 2)""",
    )
    assert shown == ["k1"]
