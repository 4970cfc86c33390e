"""A saved notebook reopens clean, as a student finds it in JupyterLab in headless Chromium: Run All, save,
close, reopen. The explorers' outputs hold a widget view (the live explorer) beside their picture; JupyterLab
saves the view but not the widget's state, so without labkit's pre-save hook (labkit/server_extension.py)
the reopened notebook would show "Error displaying widget: model not found" in every explorer's place.

Run alone: ``.venv/bin/python -m pytest tests/browser/test_reopen_saved.py -s``.
"""

import json
import urllib.request

import pytest
from jupyterlab_session import (
    NOTEBOOKS,
    TOKEN,
    close_sessions,
    open_and_run,
    show_explorers,
    skip_without_chromium,
)

pytest.importorskip("playwright.sync_api", reason="playwright is not installed (test extras)")
skip_without_chromium()

VIEW = "application/vnd.jupyter.widget-view+json"
EXPLORER_CELLS = """() => {
  // each explorer's cell (plots.*_explorer(...), plots.patch_editor(...)): its output's mime types as the open
  // notebook holds them, the pictures it shows (decoded <img>s) and its text
  const panel = window.jupyterapp.shell.currentWidget;
  return panel.content.widgets
    .filter(c => c.model.type === 'code' && /plots\\.\\w*(explorer|editor)\\(/.test(c.model.sharedModel.source))
    .map(c => {
      const area = c.node.querySelector('.jp-OutputArea');
      const imgs = area ? [...area.querySelectorAll('img')] : [];
      const outputs = c.model.sharedModel.outputs || [];
      return {mimes: outputs.flatMap(o => Object.keys(o.data || {})),
              pictures: imgs.filter(i => i.complete && i.naturalWidth > 0).length,
              text: area ? area.innerText : ''};
    });
}"""
OPENED = """() => { const w = window.jupyterapp && window.jupyterapp.shell.currentWidget;
  return w && w.context && w.context.isReady && w.content.widgets.length > 0; }"""


def _saved(base, name):
    request = urllib.request.Request(
        f"{base}/api/contents/{name}?content=1", headers={"Authorization": f"token {TOKEN}"}
    )
    with urllib.request.urlopen(request, timeout=30) as response:
        return json.loads(response.read())["content"]


@pytest.mark.parametrize("notebook", NOTEBOOKS, ids=lambda p: p.name)
def test_a_saved_notebook_reopens_with_a_picture_in_every_explorer(lab, browser, notebook):
    page = browser.new_page(viewport={"width": 1400, "height": 1000})
    cells = open_and_run(page, lab, notebook)
    assert not [c["errors"] for c in cells if c["errors"]]
    show_explorers(page)
    live = page.evaluate(EXPLORER_CELLS)
    assert live and all(VIEW in cell["mimes"] for cell in live), live  # live explorers, before saving
    page.evaluate("() => window.jupyterapp.commands.execute('docmanager:save')")
    saved = [c for c in _saved(lab, notebook.name)["cells"] if c["cell_type"] == "code"]
    views = [o for c in saved for o in c.get("outputs", []) if VIEW in o.get("data", {})]
    pictures = [o for c in saved for o in c.get("outputs", []) if "image/png" in o.get("data", {})]
    assert not views and len(pictures) >= len(live), (len(views), len(pictures))

    page.evaluate("() => window.jupyterapp.commands.execute('application:close-all')")
    close_sessions(lab)
    page.goto(f"{lab}/lab/workspaces/{notebook.stem}-reopened/tree/{notebook.name}?reset&token={TOKEN}")
    page.wait_for_function(OPENED, timeout=60_000)
    page.wait_for_function(f"() => ({EXPLORER_CELLS})().every(c => c.pictures > 0)", timeout=60_000)
    reopened = page.evaluate(EXPLORER_CELLS)
    assert len(reopened) == len(live) and all(cell["pictures"] >= 1 for cell in reopened), reopened
    text = page.evaluate("() => window.jupyterapp.shell.currentWidget.node.innerText")
    assert "Error displaying widget" not in text and "model not found" not in text
    # the reopened notebook's kernel, up before it is shut down with the page
    page.evaluate("() => window.jupyterapp.shell.currentWidget.sessionContext.ready")
    close_sessions(lab)
    page.close()
