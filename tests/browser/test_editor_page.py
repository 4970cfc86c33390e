"""editor.js on a page of its own, with a stand-in for its widget model: what it sends the kernel when handles move
faster than the kernel answers. Every moved handle's newest place must reach the kernel, one message at a time."""

import json
from pathlib import Path

import pytest
from jupyterlab_session import REVIVE, page_json, skip_without_chromium

pytest.importorskip("playwright.sync_api", reason="playwright is not installed (test extras)")
skip_without_chromium()

PLOTS = Path(__file__).resolve().parents[2] / "labkit" / "plots"
MODULE = "\n".join((PLOTS / name).read_text() for name in ("scene.js", "mesh.js", "editor.js")).replace(
    "export default", "//"
)
HANDLES = (
    [[0, 0], [1, 0], [1, 1], [0, 1]]
    + [[0.25, 0], [1.25, 0], [1.25, 1], [0.25, 1]]
    + [[0, 0.25], [1, 0.25], [1, 1.25], [0, 1.25]]
)
STAND_IN = f"""
window.setUp = (extra) => {{
  const handlers = {{}}, state = {{
    handles: {json.dumps(HANDLES)}, selected: 0, label: "editor", key_help: "keys", status: "", readout: "",
    worst: 1, alt: "", ack: 0, drag: {{}}, scene: {{}}, sketch: {{}}, overlays: {{}}, controls: {{}}, ahead: [],
    background: new Uint8Array(0), pixel_ratio: 1,
    frame: {{ width: 200, height: 200, left: 0, right: 200, top: 0, bottom: 200, x0: -1, x1: 3, y0: -1, y1: 3 }},
    ...(extra ? revive(extra) : {{}}),
  }};
  const controls = {{}};
  for (const name of Object.keys(state.controls)) controls[name] = stand(state.values[name]);
  const sent = [];
  const model = {{
    get: (name) => state[name],
    set(name, value) {{
      state[name] = value;
      if (name === "drag") sent.push(value);
      (handlers["change:" + name] || []).forEach((f) => f());
    }},
    on(event, f) {{ (handlers[event] = handlers[event] || []).push(f); }},
    off() {{}},
    save_changes() {{}},
    widget_manager: {{ get_model: async (id) => controls[id] }},
  }};
  const el = document.createElement("div");
  document.body.appendChild(el);
  render({{ model, el }});
  const stage = el.querySelector(".labkit-editor");
  const key = (k) => stage.dispatchEvent(new KeyboardEvent("keydown", {{ key: k, bubbles: true }}));
  window.t = {{ model, sent, key, controls, stage }};
}};
function stand(value) {{ // a slider's model
  const handlers = [];
  return {{ get: () => value, set(v) {{ value = v; handlers.forEach((f) => f()); }}, on: (e, f) => handlers.push(f),
           off() {{}} }};
}}
"""


@pytest.fixture(scope="module")
def page(browser):
    page = browser.new_page()
    page.set_content("<html><body></body></html>")
    page.add_script_tag(content=MODULE + REVIVE + STAND_IN)
    yield page
    page.close()


def test_every_moved_handle_reaches_the_kernel_at_its_newest_place(page):
    sent = page.evaluate(
        """() => { setUp();
        t.key("ArrowRight");  // corner A: sent at once
        t.key("ArrowRight");  // A again while the kernel draws: waits
        t.key("n");           // corner B selected
        t.key("ArrowUp");     // B moved: waits too, behind A
        t.model.set("ack", 1);  // the kernel drew the first: A's newest place goes
        t.model.set("ack", 2);  // then B's
        t.model.set("ack", 3);
        return t.sent; }"""
    )
    step = 0.01 * 4  # an arrow key moves a handle 1 % of the x span (4 here)
    assert [(d["index"], d["seq"]) for d in sent] == [(0, 1), (0, 2), (1, 3)]
    assert sent[0]["x"] == pytest.approx(step) and sent[1]["x"] == pytest.approx(2 * step)
    assert (sent[2]["x"], sent[2]["y"]) == pytest.approx((1, step))


def test_a_drag_is_not_drawn_here_from_corners_of_another_twist(page):
    """The twist slider moved, a handle dragged before the kernel's answer to it came: the page's corner data has
    the old twist, so no move is drawn here until an answer shows every move made; then moves are drawn here."""
    from labkit.plots.editor import FIRST_PATCH, Editor

    editor = Editor(list(FIRST_PATCH), 4)
    widget = editor.widget_
    before = {"scene": widget.scene, "sketch": widget.sketch, "handles": widget.handles}
    editor.twist.value = 0.5
    twisted = {"scene": widget.scene, "sketch": widget.sketch}
    widget.drag = {"index": 0, "x": 0.04, "y": 0.0, "seq": 1}
    answer = dict(widget.scene)
    state = {**before, "controls": {"elements": ["elements", "value"], "twist": ["twist", "value"]}}
    state["values"] = {"elements": 4, "twist": 0.0}
    sketched = page.evaluate(
        """async ([extra, twisted, answer]) => { setUp(extra); await new Promise((r) => setTimeout(r, 0));
        const count = () => Number(t.stage.dataset.labkitSketched || 0);
        const counts = [];
        t.controls.twist.set(0.5);  // the twist slider moved; its answer is on its way
        t.key("ArrowRight");        // corner A: sent; not drawn here (the sketch is of twist 0)
        counts.push(count());
        const later = revive(twisted);
        t.model.set("sketch", later.sketch);  // the twist's answer comes while A's move is on its way
        t.model.set("scene", later.scene);
        t.key("ArrowRight");        // A again: the sketch is of twist 0.5, the page's corners still of 0
        await new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r)));
        counts.push(count());
        const first = revive(answer);  // the answer to the first move, which shows not every move made
        t.model.set("ack", 1);       // (A's newest place goes)
        t.model.set("scene", first);
        const last = {...first, values: {...first.values, shape: 2}};
        t.model.set("ack", 2);
        t.model.set("scene", last);   // the answer to every move made: its corners are taken
        t.key("ArrowRight");
        await new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r)));
        counts.push(count());
        return counts; }""",
        [page_json(state), page_json(twisted), page_json(answer)],
    )
    assert sketched == [0, 0, 1]


def test_a_late_answer_to_a_drag_given_up_on_does_not_free_the_next(page):
    """No answer for 2 s: the page sends again. The late answer to the old drag, when it comes, is not the answer
    to the new one: the page still sends one drag at a time."""
    counts = page.evaluate(
        """async () => { setUp();
        t.key("ArrowRight");                                // drag 1: its answer is late
        await new Promise((r) => setTimeout(r, 2200));      // given up on
        t.key("ArrowRight");                                // drag 2: sent
        t.model.set("ack", 1);                              // the late answer to drag 1
        t.key("ArrowRight");                                // waits for drag 2's answer
        const before = t.sent.length;
        t.model.set("ack", 2);                              // drag 2's: the waiting move goes
        return [before, t.sent.length]; }"""
    )
    assert counts == [2, 3]


def test_a_narrow_readout_wraps_a_corner_line_between_its_items_never_inside_a_list(page):
    text = (
        "Corner data:\n"
        "A = Corner([0, 0], ds=[1.2, -0.3], dt=[0.2, 1], dsdt=[0, 0])\n"
        "B = Corner([1.2, 0.1], ds=[1, 0.4], dt=[-0.2, 1.1], dsdt=[0, 0])\n"
        "worst quality 0.42"
    )
    seen = page.evaluate(
        """(text) => { setUp(JSON.stringify({readout: text}));
        const box = [...document.querySelectorAll('.labkit-editor-readout')].pop();  // this set-up's editor
        box.style.width = '30ch';  // narrower than a Corner line
        const rows = [...box.children];
        const spans = [...box.querySelectorAll('span')];
        const line = parseFloat(getComputedStyle(box).lineHeight) || 16;
        return {text: box.innerText, rows: rows.length,
                broken: spans.filter(s => s.getClientRects().length !== 1).map(s => s.textContent),
                items: spans.map(s => s.textContent),
                wrapped: rows.filter(r => r.getBoundingClientRect().height > 1.5 * line).length}; }""",
        text,
    )
    assert seen["text"].splitlines() == text.splitlines() and seen["rows"] == 4
    assert not seen["broken"], seen["broken"]  # every item on one visual line
    assert "ds=[1.2, -0.3]," in seen["items"] and "dsdt=[0, 0])" in seen["items"]
    assert seen["wrapped"] == 2  # the two Corner lines wrapped, between items
