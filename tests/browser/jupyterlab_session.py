"""A JupyterLab server and what a test does with it in the browser: shared by the browser test,
benchmarks/bench_backends.py and benchmarks/bench_browser_latency.py.

The server runs on 127.0.0.1 with a token, with every Jupyter/IPython/matplotlib folder in a
temporary directory, news, update checks and autosave off.
"""

import contextlib
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

ROOT = Path(__file__).resolve().parents[2]
CHROMIUM = Path("/usr/bin/chromium")  # Debian's: Playwright never downloads a browser of its own


def skip_without_chromium():
    """Skip the calling test module, saying so loudly, when /usr/bin/chromium is missing."""
    if not CHROMIUM.exists():
        import pytest

        pytest.skip(
            "!! BROWSER TEST SKIPPED: /usr/bin/chromium is missing (install Debian's chromium package; "
            "`make test` does this when run as root)",
            allow_module_level=True,
        )


NOTEBOOKS = sorted((ROOT / "notebooks").glob("*.ipynb"))
MOVES = 8  # key presses per slider, mouse steps per drag
TOKEN = "labkit-browser-test"
CHROMIUM_FLAGS = [
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
]
LAB_SETTINGS = {
    "@jupyterlab/apputils-extension/notification.jupyterlab-settings": {"fetchNews": "false", "checkForUpdates": False},
    "@jupyterlab/docmanager-extension/plugin.jupyterlab-settings": {"autosave": False},
    # render every cell, so widgets far down the notebook exist and are visible to the test
    "@jupyterlab/notebook-extension/tracker.jupyterlab-settings": {"windowingMode": "none"},
}


def _free_port():
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


def api(base, path):
    request = urllib.request.Request(f"{base}{path}", headers={"Authorization": f"token {TOKEN}"})
    with urllib.request.urlopen(request, timeout=5) as response:
        return json.loads(response.read())


def kernel_channels(base):
    """Start a python3 kernel through the server at `base`'s REST API; the URL of its channels websocket."""
    request = urllib.request.Request(
        f"{base}/api/kernels",
        data=b'{"name": "python3"}',
        method="POST",
        headers={"Authorization": f"token {TOKEN}", "Content-Type": "application/json"},
    )
    with urllib.request.urlopen(request, timeout=30) as response:
        kernel = json.loads(response.read())
    return f"{base.replace('http', 'ws')}/api/kernels/{kernel['id']}/channels?token={TOKEN}"


@contextlib.contextmanager
def jupyterlab(home, served, *options):
    """A JupyterLab server on 127.0.0.1 serving the folder `served` (more command-line `options` after the
    harness's own); yields its base URL. Its log is `home`/server.log."""
    home = Path(home)
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
        sys.executable,
        "-m",
        "jupyterlab",
        "--no-browser",
        "--ip=127.0.0.1",
        f"--port={port}",
        "--ServerApp.port_retries=0",
        f"--IdentityProvider.token={TOKEN}",
        f"--ServerApp.root_dir={served}",
        "--LabApp.check_for_updates_class=jupyterlab.NeverCheckForUpdate",
        "--LabApp.extension_manager=readonly",
        "--LabApp.expose_app_in_browser=True",
        "--allow-root",
        *options,
    ]
    log = open(home / "server.log", "w")
    server = subprocess.Popen(command, env=env, stdout=log, stderr=subprocess.STDOUT)
    base = f"http://127.0.0.1:{port}"
    try:
        deadline = time.monotonic() + 60
        while True:
            try:
                api(base, "/api/status")
                break
            except OSError:
                if server.poll() is not None or time.monotonic() > deadline:
                    raise RuntimeError(
                        f"JupyterLab did not start: {(home / 'server.log').read_text()[-2000:]}"
                    ) from None
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


@contextlib.contextmanager
def course_lab(home):
    """A JupyterLab server serving a copy of the course's notebooks/ made in `home`; yields its base URL."""
    served = Path(home) / "notebooks"
    shutil.copytree(ROOT / "notebooks", served, ignore=shutil.ignore_patterns("*.vtu", ".ipynb_checkpoints"))
    with jupyterlab(home, served) as base:
        yield base


@contextlib.contextmanager
def release_lab(home):
    """A JupyterLab server serving a copy of the packaged student release (labkit/student_notebooks/), as a
    student gets it: nothing run, nothing written; yields its base URL."""
    served = Path(home) / "release"
    shutil.copytree(ROOT / "labkit" / "student_notebooks", served, ignore=shutil.ignore_patterns("*.py", "__pycache__"))
    with jupyterlab(home, served) as base:
        yield base


def close_sessions(base):
    """Shut down every notebook's kernel, so the next notebook runs alone."""
    for session in api(base, "/api/sessions"):
        request = urllib.request.Request(
            f"{base}/api/sessions/{session['id']}", method="DELETE", headers={"Authorization": f"token {TOKEN}"}
        )
        urllib.request.urlopen(request, timeout=10).close()


def wait_for_idle_kernel(base, timeout=60):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        kernels = api(base, "/api/kernels")
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


def run_all(page, base, expected_cells):
    page.wait_for_function(
        "() => window.jupyterapp && window.jupyterapp.shell.currentWidget"
        " && window.jupyterapp.shell.currentWidget.sessionContext"
        " && window.jupyterapp.shell.currentWidget.sessionContext.session"
    )
    wait_for_idle_kernel(base)
    page.evaluate("() => window.jupyterapp.commands.execute('notebook:run-all-cells')")
    page.wait_for_function(
        f"() => {{ const cells = ({CELL_SUMMARY})(); return cells.length === {expected_cells}"
        " && cells.every(c => c.count !== null && c.count > 0); }",
        timeout=120_000,
    )
    wait_for_idle_kernel(base)


COUNT_IMAGE_FRAMES = """() => {
  if (window.__labkitCounting) return;
  window.__labkitCounting = true;
  window.__labkitImageFrames = 0;
  const Original = window.WebSocket;
  window.WebSocket = function (...args) {
    const socket = new Original(...args);
    socket.addEventListener('message', (event) => {
      const data = event.data;
      const size = data.byteLength !== undefined ? data.byteLength : (data.size !== undefined ? data.size : 0);
      if (size > 2000 || (typeof data === 'string' && data.includes('image/png'))) window.__labkitImageFrames += 1;
    });
    return socket;
  };
  window.WebSocket.prototype = Original.prototype;
  Object.assign(window.WebSocket, Original);
}"""


def frames(page):
    return page.evaluate("() => window.__labkitImageFrames || 0")


def open_and_run(page, base, notebook):
    """Open `notebook` alone in a fresh workspace and Run All; the code cells' summary (CELL_SUMMARY)."""
    page.goto(f"{base}/lab/workspaces/{notebook.stem}/tree/{notebook.name}?reset&token={TOKEN}")
    code_cells = sum(c["cell_type"] == "code" for c in json.loads(notebook.read_text())["cells"])
    run_all(page, base, code_cells)
    return page.evaluate(CELL_SUMMARY)


def show_explorers(page):
    """Scroll to the notebook's last cell and wait until its last slider is visible; the notebook's panel."""
    panel = page.locator("#" + page.evaluate("() => window.jupyterapp.shell.currentWidget.id"))
    sliders = panel.locator(".widget-slider")
    sliders.first.wait_for(state="attached", timeout=30_000)
    page.evaluate("""() => { const panel = window.jupyterapp.shell.currentWidget;
        const last = panel.content.widgets.length - 1;
        panel.content.activeCellIndex = last; return panel.content.scrollToItem(last, 'start'); }""")
    sliders.last.wait_for(state="visible", timeout=30_000)
    return panel


EXPLORERS = "window.jupyterapp.shell.currentWidget.node.querySelectorAll('.labkit-explorer, .labkit-patch-editor')"

PICTURE_STATE_NTH = f"""e => {{
  // what explorer e shows now: the count of pictures its widget has shown (data-labkit-shown, raised by
  // image.js and editor.js once the frame that drew the new picture is rendered) and when (data-labkit-shown-at),
  // or, for a widget that keeps no count, its <img>'s src
  const node = {EXPLORERS}[e];
  if (!node) return {{shown: null, at: null, src: null}};
  const counter = node.querySelector('[data-labkit-shown]');
  const img = node.querySelector('img');
  return {{shown: counter ? Number(counter.dataset.labkitShown) : null,
           at: counter && counter.dataset.labkitShownAt ? Number(counter.dataset.labkitShownAt) : null,
           ahead: counter ? Number(counter.dataset.labkitDrawnAhead || 0) : 0,
           sketched: counter ? Number(counter.dataset.labkitSketched || 0) : 0,
           src: img ? img.src : null}};
}}"""

# the page notes when its last key press or mouse move happened (the event's timeStamp, on the clock of
# data-labkit-shown-at), so a move's time is measured inside the browser: no round trip of Playwright's in it
NOTE_INPUT = """() => {
  if (window.__labkitNotingInput) return;
  window.__labkitNotingInput = true;
  for (const type of ['keydown', 'pointermove'])
    document.addEventListener(type, (event) => { window.__labkitInputAt = event.timeStamp; }, true);
}"""

NEW_PICTURE_SHOWN_NTH = f"""([e, old, framesBefore]) => {{
  // a new picture SHOWN in explorer e: its shown count went up; or an <img> whose src changed and is
  // decoded (complete: the next frame paints it); or (a canvas backend such as ipympl) image data arrived
  const now = ({PICTURE_STATE_NTH})(e);
  if (now.shown !== null && old.shown !== null) return now.shown > old.shown;
  const img = {EXPLORERS}[e] && {EXPLORERS}[e].querySelector('img');
  if (img) return img.src !== old.src && img.complete && img.naturalWidth > 0;
  return window.__labkitImageFrames > framesBefore;
}}"""


def _picture_state_nth(page, e):
    return page.evaluate(PICTURE_STATE_NTH, e)


def _wait_until_shown(page, e, old, frames_before, start):
    """Wait until explorer e shows a picture newer than `old` (polled at every animation frame); the seconds from
    the last key press or mouse move to that picture shown, measured in the page when the widget notes when it
    showed it (else from `start`, a time.perf_counter(), to now)."""
    page.wait_for_function(NEW_PICTURE_SHOWN_NTH, arg=[e, old, frames_before], timeout=10_000, polling="raf")
    now = time.perf_counter()
    shown, pressed = page.evaluate(f"e => [({PICTURE_STATE_NTH})(e).at, window.__labkitInputAt ?? null]", e)
    if shown is not None and pressed is not None and shown >= pressed:
        return (shown - pressed) / 1000
    return now - start


DRAWN_AHEAD: dict = {}  # slider -> how many of its moves move_every_slider saw drawn ahead (no round trip)


def move_every_slider(page, panel, name):
    """Press the arrow keys on each explorer slider; {slider: [seconds from key press to new picture shown]}.
    How many of each slider's moves were drawn ahead goes into DRAWN_AHEAD."""
    from playwright.sync_api import TimeoutError as PlaywrightTimeout

    page.evaluate(NOTE_INPUT)
    timings = {}
    explorers = panel.locator(".labkit-explorer, .labkit-patch-editor")
    for e in range(explorers.count()):
        explorer = explorers.nth(e)
        kind = "editor " if "labkit-patch-editor" in (explorer.get_attribute("class") or "") else ""
        sliders = explorer.locator(".widget-slider")
        for k in range(sliders.count()):
            slider = sliders.nth(k)
            label = f"{name} {kind}{slider.locator('.widget-label').inner_text() or k}"
            readout, handle = slider.locator(".widget-readout"), slider.locator(".noUi-handle")
            times, ahead = [], 0
            key = "ArrowRight"
            for _ in range(MOVES):
                old_readout = readout.inner_text()
                old, frames_before = _picture_state_nth(page, e), frames(page)
                handle.focus()
                start = time.perf_counter()
                page.keyboard.press(key)
                try:
                    page.wait_for_function(
                        "([node, old]) => node.innerText !== old",
                        arg=[readout.element_handle(), old_readout],
                        timeout=2_000,
                    )
                except PlaywrightTimeout:  # at the end of its range: go back
                    key = "ArrowLeft" if key == "ArrowRight" else "ArrowRight"
                    continue
                times.append(_wait_until_shown(page, e, old, frames_before, start))
                ahead += _picture_state_nth(page, e)["ahead"] > old["ahead"]
            assert len(times) >= MOVES - 1, f"{label}: the slider did not move"
            timings[label] = times
            DRAWN_AHEAD[label] = ahead
    return timings


KEEP_SHOWN = """c => { window.__labkitShownPixels = null; new MutationObserver(() => {
  window.__labkitShownPixels = c.toDataURL(); }).observe(c.parentElement, {attributeFilter: ["data-labkit-shown"]}); }"""
KERNEL_IDLE = "() => window.jupyterapp.shell.currentWidget.sessionContext.session.kernel.status === 'idle'"


def drag_a_corner(page, panel):
    """Drag corner B of the patch editor in steps and let go. A dict: "steps" (seconds from each step to its
    picture shown), "sketched" (how many steps the page drew itself, editor.js's sketch), the readout "before"
    and "after", and the editor's canvas (a PNG data URL) as the page drew the last step ("last_step") and once
    the kernel has answered every move ("settled")."""
    editor = panel.locator(".labkit-patch-editor").first
    e = page.evaluate(
        "() => [...window.jupyterapp.shell.currentWidget.node"
        ".querySelectorAll('.labkit-explorer, .labkit-patch-editor')]"
        ".findIndex(n => n.classList.contains('labkit-patch-editor'))"
    )
    corner = editor.locator("circle[data-handle='1']")
    corner.scroll_into_view_if_needed()
    readout, canvas = editor.locator(".labkit-editor-readout"), editor.locator("canvas")
    before_readout = readout.inner_text()
    box = corner.bounding_box()
    x, y = box["x"] + box["width"] / 2, box["y"] + box["height"] / 2
    page.evaluate(NOTE_INPUT)
    page.mouse.move(x, y)
    page.mouse.down()
    steps, sketched = [], 0
    for k in range(1, MOVES + 1):
        if k == MOVES and canvas.count():  # the canvas as the last step's picture is shown (not a picture not new)
            canvas.evaluate(KEEP_SHOWN)
        old, frames_before = _picture_state_nth(page, e), frames(page)
        start = time.perf_counter()
        page.mouse.move(x + 6 * k, y + 3 * k)
        steps.append(_wait_until_shown(page, e, old, frames_before, start))
        sketched += _picture_state_nth(page, e)["sketched"] > old["sketched"]
    last_step = page.evaluate("() => window.__labkitShownPixels")
    page.mouse.up()
    page.wait_for_function(
        "([node, old]) => node.innerText !== old", arg=[readout.element_handle(), before_readout], timeout=10_000
    )
    page.wait_for_function(KERNEL_IDLE, timeout=10_000)
    page.wait_for_timeout(200)  # the kernel's last picture painted
    return {
        "steps": steps,
        "sketched": sketched,
        "before": before_readout,
        "after": readout.inner_text(),
        "last_step": last_step,
        "settled": canvas.evaluate("c => c.toDataURL()") if canvas.count() else None,
    }


def percentile(values, fraction):
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, int(round(fraction * (len(ordered) - 1))))]


def latencies(timings):
    """{slider: (median ms, 90th percentile ms, moves)} from move_every_slider's {slider: [seconds]}."""
    return {
        label: (1000 * statistics.median(times), 1000 * percentile(times, 0.9), len(times))
        for label, times in timings.items()
    }


# values with bytes (a widget's buffers) for a page of the tests' own: page_json(value) there, then
# revive(text) in the page (after REVIVE is added) gives them back with Uint8Arrays, as the widget models hold them
REVIVE = """window.revive = (text) => JSON.parse(text, (key, value) =>
  value && typeof value === "object" && typeof value.b64 === "string"
    ? Uint8Array.from(atob(value.b64), (c) => c.charCodeAt(0)) : value);"""


def page_json(value):
    import base64

    def plain(v):
        if isinstance(v, bytes):
            return {"b64": base64.b64encode(v).decode()}
        if isinstance(v, dict):
            return {k: plain(x) for k, x in v.items()}
        if isinstance(v, (list, tuple)):
            return [plain(x) for x in v]
        return v

    return json.dumps(plain(value))
