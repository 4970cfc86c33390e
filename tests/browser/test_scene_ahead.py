"""scene.js's sceneAhead in Chromium, on a page of its own with stand-ins for the widget models: which picture is
shown when pictures drawn ahead, the controls and the kernel's scenes arrive in every order. The real widgets, in
JupyterLab, are tests/browser/test_jupyterlab.py's."""

import json
from pathlib import Path

import pytest
from jupyterlab_session import skip_without_chromium

pytest.importorskip("playwright.sync_api", reason="playwright is not installed (test extras)")
skip_without_chromium()

SCENE_JS_PATH = Path(__file__).resolve().parents[2] / "labkit" / "plots" / "scene.js"
SCENE_JS = SCENE_JS_PATH.read_text()

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
  const picture = (name, values, background, base = background) =>
    ({ name, values, background, base, scene: { values, background } });
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


# a 1 x 1 PNG, as a new background drawn ahead carries its own
PNG = "iVBORw0KGgoAAAANSUhEUgAAAAEAAAABCAIAAACQd1PeAAAADElEQVR4nGP4z8AAAAMBAQDJ/pLvAAAAAElFTkSuQmCC"
ON_ITS_OWN = f"""const png = Uint8Array.from(atob("{PNG}"), (c) => c.charCodeAt(0));
const own = (name, values, background, base) => ({{ ...t.picture(name, values, background, base), picture: png }});
const decoded = async () => {{ // until every picture sent ahead is decoded (a busy machine takes its time)
  for (let k = 0; k < 500 && !(t.model.get("ahead") || []).every((e) => !e.picture || e.bitmap); k++)
    await new Promise((r) => setTimeout(r, 10));
}};"""


def test_a_picture_on_a_background_of_its_own_is_shown_once_decoded_and_only_from_its_base(page):
    shown = run(
        page,
        ON_ITS_OWN
        + """t.kernel("k1", {n: 1}, 0);
        t.model.set("ahead", [own("a2", {n: 2}, 5, 0)]);  // the axes fit again at n = 2: background 5, sent with it
        await decoded();
        t.n.set("value", 2);
        t.kernel("k2", {n: 2}, 5);  // the kernel's own, on that background: on the page already
        t.model.set("ahead", [t.picture("a3", {n: 3}, 5)]);  // drawn from background 5
        t.n.set("value", 3)""",
    )
    assert shown == ["k1", "a2", "a3"]
    shown = run(
        page,
        ON_ITS_OWN
        + """t.kernel("k1", {n: 1}, 0);
        t.model.set("ahead", [own("a2", {n: 2}, 5, 0)]);
        t.n.set("value", 2);  // not decoded yet: nothing shown at once ...
        t.kernel("k2", {n: 2}, 5);  // ... and the kernel's picture, come first, is shown
        await decoded()""",
    )
    assert shown == ["k1", "k2"]
    shown = run(
        page,
        ON_ITS_OWN
        + """t.kernel("k1", {n: 1}, 0);
        t.model.set("ahead", [own("a2", {n: 2}, 5, 0)]);
        t.n.set("value", 2);
        await decoded();  // decoded before the kernel answers: shown then
        t.kernel("k2", {n: 2}, 5)""",
    )
    assert shown == ["k1", "a2"]
    shown = run(
        page,
        ON_ITS_OWN
        + """t.kernel("k1", {n: 1}, 0);
        t.model.set("ahead", [own("a3", {n: 3}, 5, 0)]);  // drawn from background 0 ...
        await decoded();
        t.kernel("k2", {n: 2}, 4);  // ... but the page shows background 4 now: its limits may be others
        t.n.set("value", 3);
        t.kernel("k3", {n: 3}, 4)""",
    )
    assert shown == ["k1", "k2", "k3"]


def _png(rgb):
    import base64

    import numpy as np

    from labkit.plots.scene import encode_png

    return base64.b64encode(encode_png(np.full((4, 4, 3), rgb, dtype=np.uint8))).decode()


def test_image_js_paints_a_picture_on_a_background_of_its_own_over_that_background(browser):
    """image.js itself: the picture of a move whose axes fit again is drawn ahead over the new background it came
    with (the canvas covers the old one until the <img> has the new one)."""
    image_js = SCENE_JS + "\n" + (SCENE_JS_PATH.parent / "image.js").read_text().replace("export default", "//")
    page = browser.new_page()
    try:
        page.set_content("<html><body><div id='out'></div></body></html>")
        page.add_script_tag(content=image_js + STAND_INS + "window.renderImage = render;")
        red, blue, green = _png([255, 0, 0]), _png([0, 0, 255]), _png([0, 255, 0])
        result = page.evaluate(
            f"""async () => {{
            const bytes = (b64) => Uint8Array.from(atob(b64), (c) => c.charCodeAt(0));
            const frames = async (k) => {{ for (let i = 0; i < k; i++) await new Promise((r) => requestAnimationFrame(r)); }};
            setUp({{}});
            const model = t.model;
            model.save_changes = () => {{}};
            Object.assign(model.state, {{ background: bytes("{red}"), css_size: [4, 4], description: "red", overlays: {{}},
              scene: {{ size: [4, 4], items: [], values: {{ n: 1 }}, background: 1 }} }});
            const el = document.getElementById("out");
            renderImage({{ model, el }});
            const canvas = el.querySelector("canvas"), img = el.querySelector("img");
            const pixel = () => Array.from(canvas.getContext("2d").getImageData(1, 1, 1, 1).data);
            for (let k = 0; k < 300 && pixel()[3] === 0; k++) await frames(1);  // the first picture painted
            const before = [pixel(), img.src];
            model.set("ahead", [{{ values: {{ n: 2 }}, base: 1, background: 2, picture: bytes("{blue}"), overlays: {{}},
              description: "blue", scene: {{ size: [4, 4], items: [], values: {{ n: 2 }}, background: 2 }} }}]);
            for (let k = 0; k < 500 && !model.get("ahead")[0].bitmap; k++) await new Promise((r) => setTimeout(r, 10));
            t.n.set("value", 2);
            await frames(3);
            const after = pixel(), changed = img.src !== before[1];
            // back before the kernel made that move: its next scene lies on the first background, which the
            // canvas paints under it, whatever the <img> holds (the one sent ahead, here)
            t.n.set("value", 1);
            model.set("scene", {{ size: [4, 4], items: [], values: {{ n: 1 }}, background: 1 }});
            await frames(3);
            const back = pixel();
            // a new background whose scene's change event comes first (one message's events come in any order):
            // the paint waits for the background set after it
            const decode = window.createImageBitmap;  // a decode slower than a frame, as a big picture's is
            window.createImageBitmap = (blob) => new Promise((r) => setTimeout(r, 100)).then(() => decode(blob));
            model.set("scene", {{ size: [4, 4], items: [], values: {{ n: 1 }}, background: 3 }});
            model.set("background", bytes("{green}"));
            await new Promise((r) => setTimeout(r, 250));
            await frames(2);
            window.createImageBitmap = decode;
            return {{ before, after, changed, back, green: pixel(), alt: img.alt,
                      ahead: el.querySelector("[data-labkit-drawn-ahead]")?.dataset.labkitDrawnAhead }};
        }}"""
        )
    finally:
        page.close()
    assert result["before"][0] == [255, 0, 0, 255]  # the canvas holds the whole picture: its background first
    assert result["after"] == [0, 0, 255, 255]  # the new background, on the canvas, under the picture's items
    assert result["changed"] and result["ahead"] == "1"
    assert result["back"] == [255, 0, 0, 255]  # the kernel's scene on its own background, not the one sent ahead
    assert result["green"] == [0, 255, 0, 255]
