"""A fresh student copy in JupyterLab: Run All goes past every stub to the explorers, which render.

Each notebook of the packaged release (labkit/student_notebooks/, nothing written in it) is opened in
JupyterLab in headless Chromium and run with Run All. Every code cell must run (an error in a cell that
is not tagged ``raises-exception`` would stop the rest); the errors shown are those of the tagged cells
(the stubs and what uses their names); the last explorer's picture loads; and axe-core finds no
``image-alt`` violation in the outputs: labkit's static figures come as an ``<img>`` with its alt text.

Run alone: ``.venv/bin/python -m pytest tests/browser/test_explore_first_browser.py -s``.
"""

import json
from pathlib import Path

import pytest
from jupyterlab_session import (  # the browser fixture is in tests/conftest.py
    close_sessions,
    open_and_run,
    release_lab,
    show_explorers,
    skip_without_chromium,
)

playwright_api = pytest.importorskip("playwright.sync_api", reason="playwright is not installed (test extras)")
axe_playwright = pytest.importorskip("axe_playwright_python.sync_playwright", reason="axe-playwright-python is missing")
skip_without_chromium()

RAISES = "raises-exception"
WHERE = """(target) => {
  const node = document.querySelector(target[0]);
  const panel = window.jupyterapp.shell.currentWidget;
  const index = panel.content.widgets.findIndex(w => node && w.node.contains(node));
  const cell = index < 0 ? null : panel.content.model.sharedModel.cells[index];
  return {renderedImage: !!(node && node.closest('.jp-RenderedImage')), tags: cell ? (cell.metadata.tags || []) : [],
          source: cell ? cell.source : ''};
}"""
RELEASE = sorted((Path(__file__).resolve().parents[2] / "labkit" / "student_notebooks").glob("*.ipynb"))


@pytest.fixture(scope="module")
def fresh_lab(tmp_path_factory):
    with release_lab(tmp_path_factory.mktemp("release-lab")) as base:
        yield base


def _tagged(notebook):
    cells = [c for c in json.loads(notebook.read_text())["cells"] if c["cell_type"] == "code"]
    return [RAISES in c["metadata"].get("tags", []) for c in cells]


@pytest.mark.parametrize("notebook", RELEASE, ids=lambda p: p.stem)
def test_run_all_on_a_fresh_copy_reaches_the_last_explorer(fresh_lab, browser, notebook):
    context = browser.new_context(viewport={"width": 1400, "height": 1000})
    page = context.new_page()
    try:
        cells = open_and_run(page, fresh_lab, notebook)  # waits until every code cell has run
        assert all(c["count"] for c in cells)
        failed = [bool(c["errors"]) for c in cells]
        assert failed == _tagged(notebook), [c["source"][:60] for c, f in zip(cells, failed) if f]
        assert any("NotImplementedError" in e for c in cells for e in c["errors"])  # shown, not hidden

        panel = show_explorers(page)
        last = panel.locator(".labkit-explorer img, .labkit-patch-editor img").last
        last.scroll_into_view_if_needed()
        page.wait_for_function("img => img.complete && img.naturalWidth > 0", arg=last.element_handle(), timeout=30_000)
        assert (last.get_attribute("alt") or "").strip()
        page.wait_for_function(
            "() => [...window.jupyterapp.shell.currentWidget.node.querySelectorAll('.jp-OutputArea-output img')]"
            ".every(i => i.complete && i.naturalWidth > 0)",
            timeout=30_000,
        )
        static = page.evaluate(
            "() => [...window.jupyterapp.shell.currentWidget.node.querySelectorAll("
            "'.jp-OutputArea-output img')].filter(i => !i.closest('.labkit-explorer, .labkit-patch-editor'))"
            ".map(i => i.alt)"
        )
        results = axe_playwright.Axe().run(page, options={"runOnly": {"type": "rule", "values": ["image-alt"]}})
        missing = [page.evaluate(WHERE, n["target"]) for v in results.response["violations"] for n in v["nodes"]]
        print(
            f"\n{notebook.stem}: {sum(failed)} cells raised and were passed; {len(static)} static figures, alt: "
            f"{[a[:40] for a in static]}; image-alt violations: {missing}"
        )
        # the only pictures without alt: a student's own empty figure (plt.subplots before the stub), which
        # labkit leaves as it is and JupyterLab's image renderer shows without one
        for where in missing:
            assert where["renderedImage"] and RAISES in where["tags"] and "plt.subplots(" in where["source"], where
        assert sum(not alt.strip() for alt in static) == len(missing), static  # every other picture has its alt
    finally:
        context.close()
        close_sessions(fresh_lab)
