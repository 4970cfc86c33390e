"""Keyboard, screen readers and axe-core in JupyterLab: headless Chromium (Debian's, never a downloaded one)
driven by Playwright, one JupyterLab server for the whole file.

- The patch editor (03_meshes): Tab and Shift+Tab leave it like any control (no keyboard trap, WCAG 2.1.2);
  n / p select a handle and the arrow keys move it, which changes the kernel's corner data; the polite live
  region then names the handle and the worst quality; the editor has a role and a label naming the keys.
- Every notebook, run with its explorers drawn: axe-core (bundled with axe-playwright-python, injected into
  the page, no network) finds no serious or critical violation in the notebook's outputs (labkit's widgets
  and figures). What it finds in JupyterLab itself is printed (``-s``, and the run's summary) and listed in
  docs/students.md, never asserted. Static pictures without alt count as JupyterLab's: its image renderer
  never sets one, not even from the output's `alt` metadata; labkit's own figures are an HTML <img> with
  their alt (not JupyterLab's image renderer), so one of them without alt counts as labkit's. A violation listed in PENDING (a known one of
  labkit's, waiting for its fix; none today) makes the test xfail instead of fail.

One page serves the whole file: 03_meshes first (the editor, then its axe check), then each other notebook
in turn, the one before closed and its kernel shut down.

Run alone: ``.venv/bin/python -m pytest tests/browser/test_accessibility.py -q -s``.
"""

import json
import re
import urllib.request

import pytest
from jupyterlab_session import (  # the lab and browser fixtures are in tests/conftest.py
    CELL_SUMMARY,
    NOTEBOOKS,
    TOKEN,
    api,
    open_and_run,
    run_all,
    show_explorers,
    skip_without_chromium,
)

playwright_api = pytest.importorskip("playwright.sync_api", reason="playwright is not installed (test extras)")
axe_playwright = pytest.importorskip("axe_playwright_python.sync_playwright", reason="axe-playwright-python is missing")
skip_without_chromium()

SERIOUS = ("serious", "critical")
IMPACTS = ("critical", "serious", "moderate", "minor")
AXE = {}  # notebook -> {"outputs": [...], "jupyterlab": [...]}, printed by tests/conftest.py's summary
# Violations in the outputs that another part of issue 23 removes (the explorers' pictures get alt text with
# item 2): they make the test xfail, not pass; remove an entry once nothing matches it any more.
PENDING = {}  # (rule, marker in the node) -> why: a known violation of labkit's own, waiting for its fix
# 03_meshes first: it stays open from the editor's test to its axe check
MESHES = next(p for p in NOTEBOOKS if p.stem == "03_meshes")
ORDERED = sorted(NOTEBOOKS, key=lambda p: p != MESHES)
CORNER = re.compile(r"^(?P<name>[ABCD]) = Corner\(\[(?P<x>[-\d.]+), (?P<y>[-\d.]+)\], ds=(?P<ds>\[[^\]]*\]), dt=")


def _shut_down(base, notebook):
    """Shut down the kernel of `notebook` only (another notebook's page may still be in use)."""
    for session in api(base, "/api/sessions"):
        if session["path"].endswith(notebook.name):
            request = urllib.request.Request(
                f"{base}/api/sessions/{session['id']}", method="DELETE", headers={"Authorization": f"token {TOKEN}"}
            )
            urllib.request.urlopen(request, timeout=10).close()


class OnePage:
    """One JupyterLab page for the whole file (JupyterLab's scripts load once): `show` a notebook, run, with
    every output drawn; the notebook shown before is closed and its kernel shut down."""

    def __init__(self, browser, base):
        self.base, self.current, self.panel = base, None, None
        self.context = browser.new_context(viewport={"width": 1400, "height": 1000})
        self.page = self.context.new_page()

    def show(self, notebook):
        if notebook == self.current:
            return self.page, self.panel
        if self.current is None:
            cells = open_and_run(self.page, self.base, notebook)
        else:
            self.page.evaluate(
                "() => { const w = window.jupyterapp.shell.currentWidget; w.context.model.dirty = false; w.dispose(); }"
            )
            _shut_down(self.base, self.current)
            self.page.evaluate(
                "path => window.jupyterapp.commands.execute('docmanager:open', {path}).then(() => true)", notebook.name
            )
            self.page.wait_for_function(
                "name => { const w = window.jupyterapp.shell.currentWidget;"
                " return !!(w && w.context && w.context.path.endsWith(name)); }",
                arg=notebook.name,
                timeout=60_000,
            )
            run_all(
                self.page, self.base, sum(c["cell_type"] == "code" for c in json.loads(notebook.read_text())["cells"])
            )
            cells = self.page.evaluate(CELL_SUMMARY)
        self.current = notebook
        assert not [c["errors"] for c in cells if c["errors"]]
        self.panel = _draw_outputs(self.page)
        return self.page, self.panel

    def close(self):
        self.context.close()
        if self.current is not None:
            _shut_down(self.base, self.current)


def _draw_outputs(page):
    """Wait until the current notebook's explorers, editor and pictures are drawn; its panel."""
    panel = show_explorers(page)
    panel.locator(".labkit-explorer img, .labkit-patch-editor img").last.wait_for(timeout=30_000)
    page.wait_for_function(
        "() => [...window.jupyterapp.shell.currentWidget.node.querySelectorAll('.jp-OutputArea-output img')]"
        ".every(i => i.complete && i.naturalWidth > 0)",
        timeout=30_000,
    )
    try:  # labels.js names the sliders once they are in the page; if it does not, axe says so below
        page.wait_for_function(
            "() => [...window.jupyterapp.shell.currentWidget.node.querySelectorAll('.widget-slider .noUi-handle')]"
            ".every(h => h.hasAttribute('aria-label'))",
            timeout=10_000,
        )
    except playwright_api.TimeoutError:
        pass
    return panel


@pytest.fixture(scope="module")
def one_page(lab, browser):
    shown = OnePage(browser, lab)
    yield shown
    shown.close()


def _corner(readout, name):
    line = next(line for line in readout.splitlines() if line.startswith(f"{name} = Corner("))
    match = CORNER.match(line)
    return float(match["x"]), float(match["y"]), match["ds"]


def _focus_in_editor(page):
    return page.evaluate(
        "() => { const a = document.activeElement;"
        " return [!!(a && a.closest('.labkit-editor')), a ? a.className || a.tagName : null]; }"
    )


def test_the_patch_editor_lets_tab_leave_and_moves_handles_with_keys_it_announces(one_page):
    page, panel = one_page.show(MESHES)
    editor = panel.locator(".labkit-patch-editor").first
    stage, live = editor.locator(".labkit-editor"), editor.locator(".labkit-editor-status")
    readout = editor.locator(".labkit-editor-readout")
    changed = "([node, old]) => node.innerText !== old"

    assert stage.get_attribute("role") == "application"
    label = stage.get_attribute("aria-label") or ""
    assert label.startswith("Patch editor") and "n or p" in label and "Arrow keys" in label and "Tab" in label
    assert live.get_attribute("aria-live") == "polite" and live.get_attribute("role") == "status"
    assert "Tab: leave" in editor.locator(".labkit-editor-keys").inner_text()  # the keys, shown as well
    assert (editor.locator(".labkit-editor-image").get_attribute("alt") or "").startswith("Mesh of the patch")
    first, shown = live.inner_text(), readout.inner_text()  # the editor opens on plots.editor.FIRST_PATCH
    worst = re.search(r"^worst quality (-?[\d.]+)", shown)[1]
    assert first.startswith(f"corner A at (0, 0). Worst quality {worst}"), (first, shown)

    stage.scroll_into_view_if_needed()
    stage.focus()
    assert _focus_in_editor(page)[0]

    # n selects corner B; the kernel answers with the sentence the live region speaks
    page.keyboard.press("n")
    page.wait_for_function(changed, arg=[live.element_handle(), first], timeout=10_000)
    selected = live.inner_text()
    at_b = shown.splitlines()[2][len("B = Corner([") :].split("]")[0]
    assert selected.startswith(f"corner B at ({at_b}). Worst quality "), (selected, shown)
    assert _focus_in_editor(page)[0], "n took the focus out of the editor"

    # an arrow moves B in the kernel's corner data (the readout is the model's), the live region follows
    before = readout.inner_text()
    x0, y0, ds0 = _corner(before, "B")
    page.keyboard.press("ArrowRight")
    page.wait_for_function(changed, arg=[readout.element_handle(), before], timeout=10_000)
    page.wait_for_function(changed, arg=[live.element_handle(), selected], timeout=10_000)
    after = readout.inner_text()
    x1, y1, ds1 = _corner(after, "B")
    assert x1 > x0 and y1 == y0 and ds1 == ds0  # the corner moved right, carrying its arrows
    assert _corner(after, "A") == _corner(before, "A")
    step = x1 - x0
    moved = live.inner_text()
    worst = re.search(r"^worst quality (-?[\d.]+)", after)[1]
    assert moved.startswith(f"corner B at ({after.splitlines()[2][len('B = Corner([') :].split(']')[0]}).")
    assert f"Worst quality {worst}" in moved, (moved, after)

    # Shift+arrow: five times further
    page.keyboard.press("Shift+ArrowUp")
    page.wait_for_function(changed, arg=[readout.element_handle(), after], timeout=10_000)
    x2, y2, _ = _corner(readout.inner_text(), "B")
    assert x2 == x1 and y2 - y1 == pytest.approx(5 * step, abs=0.002)

    # p goes back to corner A
    now = live.inner_text()
    page.keyboard.press("p")
    page.wait_for_function(changed, arg=[live.element_handle(), now], timeout=10_000)
    assert live.inner_text().startswith("corner A at (0, 0). Worst quality ")

    # Tab leaves the editor for the next control (its elements slider); Shift+Tab comes back and leaves again
    page.keyboard.press("Tab")
    inside, where = _focus_in_editor(page)
    assert not inside, f"Tab stayed in the editor (focus on {where}): a keyboard trap"
    assert page.evaluate("() => !!document.activeElement.closest('.labkit-patch-editor .widget-slider')"), where
    page.keyboard.press("Shift+Tab")
    assert _focus_in_editor(page)[0], "Shift+Tab from the next control did not come back to the editor"
    page.keyboard.press("Shift+Tab")
    assert not _focus_in_editor(page)[0], "Shift+Tab stayed in the editor: a keyboard trap"


RESOLVE = """(target) => {
  // axe's target: a selector, or a chain of them through shadow roots and frames
  let node = document.querySelector(target[0]);
  for (const selector of target.slice(1)) node = node && (node.shadowRoot || node).querySelector(selector);
  if (!node) return null;
  return {
    output: !!node.closest('.jp-OutputArea-output'),
    widget: !!node.closest('.jupyter-widgets, .widget-box, .labkit-explorer, .labkit-patch-editor'),
    staticImage: node.matches('.jp-RenderedImage > img'),
  };
}"""


def _classify(page, violations):
    """Split axe's serious and critical nodes: in the notebook's outputs (labkit's), or JupyterLab's own.

    JupyterLab's own: nodes outside the outputs, and static pictures without alt: JupyterLab's image renderer
    never sets an alt, not even from the output's `alt` metadata (jupyter/enhancement-proposals#120).
    """
    outputs, jupyterlab = [], []
    for violation in violations:
        for node in violation["nodes"]:
            where = page.evaluate(RESOLVE, node["target"]) or {"output": False, "widget": False, "staticImage": False}
            item = (violation["id"], violation["impact"], node["target"][-1], node["html"][:160])
            if violation["id"] == "image-alt" and where["staticImage"]:
                jupyterlab.append(("image-alt on static pictures", *item[1:]))
            elif where["output"]:
                outputs.append(item)
            else:
                jupyterlab.append(item)
    return outputs, jupyterlab


def _summary(items):
    counts = {}
    for rule, impact, *_ in items:
        counts.setdefault(f"{rule} ({impact})", 0)
        counts[f"{rule} ({impact})"] += 1
    return ", ".join(f"{key} x{n}" for key, n in sorted(counts.items())) or "none"


def _pending(item):
    rule, _, target, html = item
    return any(rule == r and marker in target + html for r, marker in PENDING)


@pytest.mark.parametrize("notebook", ORDERED, ids=lambda p: p.name)
def test_axe_finds_nothing_serious_in_the_notebooks_outputs(one_page, notebook):
    page, panel = one_page.show(notebook)
    results = axe_playwright.Axe().run(page)
    violations = results.response["violations"]
    outputs, jupyterlab = _classify(page, [v for v in violations if v["impact"] in SERIOUS])
    AXE[notebook.stem] = {
        "all": {impact: sum(len(v["nodes"]) for v in violations if v["impact"] == impact) for impact in IMPACTS},
        "rules": sorted({f"{v['id']} ({v['impact']})" for v in violations}),
        "outputs": outputs,
        "jupyterlab": jupyterlab,
        "widgets": panel.locator(".labkit-explorer, .labkit-patch-editor").count(),
    }
    print(f"\n{notebook.name}: axe-core {results.response.get('testEngine', {}).get('version', '?')}")
    print(f"  all impacts (nodes): {AXE[notebook.stem]['all']}; rules: {', '.join(AXE[notebook.stem]['rules'])}")
    print(f"  serious/critical in the outputs: {_summary(outputs)}")
    print(f"  serious/critical from JupyterLab itself: {_summary(jupyterlab)}")
    for rule in sorted({item[0] for item in jupyterlab}):
        print(f"    e.g. {rule}: {next(item[3] for item in jupyterlab if item[0] == rule)[:110]}")
    assert AXE[notebook.stem]["widgets"] >= 1, "no explorer was drawn"
    unexpected = [item for item in outputs if not _pending(item)]
    assert not unexpected, "\n".join(map(str, unexpected))
    if outputs:
        pytest.xfail(f"pending elsewhere in issue 23: {PENDING}; found {_summary(outputs)}")
