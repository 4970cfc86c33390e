"""A student's session in a real browser: JupyterLab in headless Chromium, driven by Playwright.

For every notebook: open it, Run All, wait for the kernel to go idle, then check
that no cell failed, the browser logged no error, nothing was requested from
outside localhost, every slider rendered as a widget, and that moving one
slider with the keyboard changes its readout and redraws the plot. The time
from the key press to the new image is printed per notebook.

Run alone: ``.venv/bin/python -m pytest tests/browser -s``.
"""
import json
import os
import shutil
import socket
import statistics
import subprocess
import sys
import time
import urllib.request
from pathlib import Path
from urllib.parse import urlparse

import pytest

LATENCIES = {}  # notebook name -> median ms, printed by tests/conftest.py's terminal summary
ROOT = Path(__file__).resolve().parents[2]
CHROMIUM = Path("/usr/bin/chromium")
SCREENSHOTS = ROOT / "build" / "screenshots"
NOTEBOOKS = sorted((ROOT / "notebooks").glob("*.ipynb"))
TOKEN = "labkit-browser-test"
CHROMIUM_FLAGS = [
    "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
    "--disable-background-networking", "--disable-component-update", "--disable-sync",
]
LAB_SETTINGS = {
    "@jupyterlab/apputils-extension/notification.jupyterlab-settings": {"fetchNews": "false", "checkForUpdates": False},
    "@jupyterlab/docmanager-extension/plugin.jupyterlab-settings": {"autosave": False},
    # render every cell, so widgets far down the notebook exist and are visible to the test
    "@jupyterlab/notebook-extension/tracker.jupyterlab-settings": {"windowingMode": "none"},
}

playwright_api = pytest.importorskip("playwright.sync_api", reason="playwright is not installed (test extras)")
if not CHROMIUM.exists():
    pytest.skip(
        "!! BROWSER TEST SKIPPED: /usr/bin/chromium is missing (install Debian's chromium package; "
        "`make test` does this when run as root)", allow_module_level=True)


def _free_port():
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


def _api(base, path):
    request = urllib.request.Request(f"{base}{path}", headers={"Authorization": f"token {TOKEN}"})
    with urllib.request.urlopen(request, timeout=5) as response:
        return json.loads(response.read())


@pytest.fixture(scope="module")
def lab(tmp_path_factory):
    """A JupyterLab server on 127.0.0.1 serving a temporary copy of notebooks/."""
    home = tmp_path_factory.mktemp("lab")
    served = home / "notebooks"
    shutil.copytree(ROOT / "notebooks", served, ignore=shutil.ignore_patterns("*.vtu", ".ipynb_checkpoints"))
    settings = home / "settings"
    for name, values in LAB_SETTINGS.items():
        (settings / name).parent.mkdir(parents=True, exist_ok=True)
        (settings / name).write_text(json.dumps(values))
    env = dict(os.environ)
    for var in ("JUPYTER_RUNTIME_DIR", "JUPYTER_DATA_DIR", "JUPYTER_CONFIG_DIR", "IPYTHONDIR", "MPLCONFIGDIR"):
        env[var] = str(home / var.lower())
    env["JUPYTERLAB_SETTINGS_DIR"] = str(settings)
    env["JUPYTERLAB_WORKSPACES_DIR"] = str(home / "workspaces")
    port = _free_port()
    command = [
        sys.executable, "-m", "jupyterlab", "--no-browser", "--ip=127.0.0.1", f"--port={port}",
        "--ServerApp.port_retries=0", f"--IdentityProvider.token={TOKEN}", f"--ServerApp.root_dir={served}",
        "--LabApp.check_for_updates_class=jupyterlab.NeverCheckForUpdate", "--LabApp.extension_manager=readonly",
        "--LabApp.expose_app_in_browser=True", "--allow-root",
    ]
    log = open(home / "server.log", "w")
    server = subprocess.Popen(command, env=env, stdout=log, stderr=subprocess.STDOUT)
    base = f"http://127.0.0.1:{port}"
    try:
        deadline = time.monotonic() + 60
        while True:
            try:
                _api(base, "/api/status")
                break
            except OSError:
                if server.poll() is not None or time.monotonic() > deadline:
                    raise RuntimeError(f"JupyterLab did not start: {(home / 'server.log').read_text()[-2000:]}")
                time.sleep(0.3)
        yield base
    finally:
        server.terminate()
        try:
            server.wait(timeout=20)
        except subprocess.TimeoutExpired:
            server.kill()
            server.wait()
        log.close()


@pytest.fixture(scope="module")
def browser():
    with playwright_api.sync_playwright() as p:
        chromium = p.chromium.launch(executable_path=str(CHROMIUM), headless=True, args=CHROMIUM_FLAGS)
        yield chromium
        chromium.close()


def _wait_for_idle_kernel(base, timeout=60):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        kernels = _api(base, "/api/kernels")
        if kernels and all(k["execution_state"] == "idle" and k["connections"] > 0 for k in kernels):
            return
        time.sleep(0.25)
    raise AssertionError(f"kernel not connected and idle after {timeout} s: {kernels}")


CELL_SUMMARY = """() => {
  const panel = window.jupyterapp.shell.currentWidget;
  const cells = panel.content.model.sharedModel.cells;
  return cells.filter(c => c.cell_type === 'code').map(c => ({
    source: c.source, count: c.execution_count,
    errors: c.outputs.filter(o => o.output_type === 'error').map(o => o.ename + ': ' + o.evalue)}));
}"""


def _run_all(page, base, expected_cells):
    page.wait_for_function("() => window.jupyterapp && window.jupyterapp.shell.currentWidget"
                           " && window.jupyterapp.shell.currentWidget.sessionContext"
                           " && window.jupyterapp.shell.currentWidget.sessionContext.session")
    _wait_for_idle_kernel(base)
    page.evaluate("() => window.jupyterapp.commands.execute('notebook:run-all-cells')")
    page.wait_for_function(
        f"() => {{ const cells = ({CELL_SUMMARY})(); return cells.length === {expected_cells}"
        " && cells.every(c => c.count !== null && c.count > 0); }", timeout=120_000)
    _wait_for_idle_kernel(base)


def _slider_count(path):
    source = "".join(c["source"] if isinstance(c["source"], str) else "".join(c["source"])
                     for c in json.loads(path.read_text())["cells"] if c["cell_type"] == "code")
    return source.count("IntSlider(") + source.count("FloatSlider(")


@pytest.mark.parametrize("notebook", NOTEBOOKS, ids=lambda p: p.name)
def test_student_runs_the_notebook_and_moves_a_slider(lab, browser, notebook):
    context = browser.new_context(viewport={"width": 1400, "height": 1000})
    outside, console_errors = [], []

    def guard(route):
        host = urlparse(route.request.url).hostname
        if host in ("127.0.0.1", "localhost") or route.request.url.startswith("data:"):
            route.continue_()
        else:
            outside.append(route.request.url)
            route.abort()

    context.route("**/*", guard)
    page = context.new_page()
    page.on("console", lambda msg: msg.type == "error" and console_errors.append(msg.text))
    page.on("pageerror", lambda exc: console_errors.append(str(exc)))
    # a workspace of its own, reset: only this notebook is open
    page.goto(f"{lab}/lab/workspaces/{notebook.stem}/tree/{notebook.name}?reset&token={TOKEN}")
    code_cells = sum(c["cell_type"] == "code" for c in json.loads(notebook.read_text())["cells"])
    _run_all(page, lab, code_cells)

    cells = page.evaluate(CELL_SUMMARY)
    failures = [c["errors"] for c in cells if c["errors"]]
    assert not failures, failures

    panel = page.locator("#" + page.evaluate("() => window.jupyterapp.shell.currentWidget.id"))
    sliders = panel.locator(".widget-slider")
    sliders.first.wait_for(state="attached", timeout=30_000)
    page.evaluate("""() => { const panel = window.jupyterapp.shell.currentWidget;
        const last = panel.content.widgets.length - 1;
        panel.content.activeCellIndex = last; return panel.content.scrollToItem(last, 'start'); }""")
    sliders.last.wait_for(state="visible", timeout=30_000)
    assert sliders.count() == _slider_count(notebook)
    assert panel.locator(".jp-OutputArea-output:has-text('interactive(children')").count() == 0

    output = panel.locator(".widget-output img").last
    output.wait_for(timeout=30_000)
    SCREENSHOTS.mkdir(parents=True, exist_ok=True)
    stem = notebook.stem
    page.screenshot(path=str(SCREENSHOTS / f"{stem}-before.png"))

    readout = panel.locator(".widget-slider .widget-readout").first
    handle = panel.locator(".widget-slider .noUi-handle").first
    latencies = []
    for _ in range(4):
        old_readout, old_image = readout.inner_text(), output.get_attribute("src")
        handle.focus()
        start = time.perf_counter()
        page.keyboard.press("ArrowRight")
        page.wait_for_function(
            "old => { const panel = window.jupyterapp.shell.currentWidget.node;"
            " const imgs = panel.querySelectorAll('.widget-output img');"
            " return imgs.length && imgs[imgs.length - 1].src !== old; }", arg=old_image, timeout=10_000)
        latencies.append(time.perf_counter() - start)
        assert readout.inner_text() != old_readout
    page.screenshot(path=str(SCREENSHOTS / f"{stem}-after.png"))
    median_ms = 1000 * statistics.median(latencies)
    LATENCIES[notebook.name] = median_ms
    print(f"\n{notebook.name}: slider move -> new plot, median of {len(latencies)}: {median_ms:.0f} ms")

    context.close()
    for session in _api(lab, "/api/sessions"):
        request = urllib.request.Request(f"{lab}/api/sessions/{session['id']}", method="DELETE",
                                         headers={"Authorization": f"token {TOKEN}"})
        urllib.request.urlopen(request, timeout=10).close()
    assert not outside, f"requests left localhost: {outside}"
    assert not console_errors, console_errors
