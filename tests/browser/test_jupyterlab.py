"""A student's session in a real browser: JupyterLab in headless Chromium, driven by Playwright.

For every notebook: open it, Run All, wait for the kernel to go idle, then check
that no cell failed, the browser logged no error, nothing was requested from
outside localhost, every slider rendered as a widget, and that moving every
slider with the keyboard changes its readout, its picture's alt text and redraws the
plot; in 03_meshes, drag a corner of the patch editor with the mouse. The page is a
HiDPI one (deviceScaleFactor 2): each explorer's background picture and canvas must
have two device pixels per CSS pixel, and the live picture the browser draws (the
background with the scene over it) must be the static picture of the same state,
within the differences of two rasterizers. The times from key press (or drag step)
to the new picture shown are printed per slider, never asserted: the limits are
`make bench`'s (benchmarks/bench_browser_latency.py).

Run alone: ``.venv/bin/python -m pytest tests/browser -s``.
"""

from pathlib import Path
from urllib.parse import urlparse

import pytest
from jupyterlab_session import (  # the lab and browser fixtures are in tests/conftest.py
    COUNT_IMAGE_FRAMES,
    DRAWN_AHEAD,
    MOVES,
    NOTEBOOKS,
    close_sessions,
    drag_a_corner,
    frames,
    latencies,
    move_every_slider,
    open_and_run,
    show_explorers,
    skip_without_chromium,
)

LATENCIES = {}  # slider -> (median ms, 90th percentile ms, moves), printed by tests/conftest.py's summary
ROOT = Path(__file__).resolve().parents[2]
SCREENSHOTS = ROOT / "build" / "screenshots"
playwright_api = pytest.importorskip("playwright.sync_api", reason="playwright is not installed (test extras)")
skip_without_chromium()


# sliders each notebook's Explore section shows (labkit.plots.explorers; 03 adds the patch editor's two)
SLIDERS = {"01_limacon": 2, "02_convergence": 1, "03_meshes": 6, "04_splines": 1, "05_monotone": 2, "06_bilinear": 1}


def _nudge_with_keys(page, panel, after_drag):
    """Check the keyboard fallback after a drag: the dragged handle stays selected, n moves on, arrows nudge."""
    readout = panel.locator(".labkit-patch-editor").first.locator(".labkit-editor-readout")
    changed = "([node, old]) => node.innerText !== old"
    page.wait_for_function(
        "() => document.activeElement && document.activeElement.classList.contains('labkit-editor')", timeout=5_000
    )
    page.keyboard.press("ArrowUp")
    page.wait_for_function(changed, arg=[readout.element_handle(), after_drag], timeout=10_000)
    nudged = readout.inner_text()
    for _ in range(4):  # handles: corners A-D (0-3), then the d/ds tips (4-7), then the d/dt tips
        page.keyboard.press("n")
    page.keyboard.press("ArrowRight")  # now B's d/ds tip: B's ds changes, its point does not
    page.wait_for_function(changed, arg=[readout.element_handle(), nudged], timeout=10_000)
    keyed = readout.inner_text()
    assert keyed.splitlines()[2].split(", ds=")[0] == nudged.splitlines()[2].split(", ds=")[0]
    assert keyed.splitlines()[2] != nudged.splitlines()[2]


def _held_key_ends_on_the_latest_value(page, panel, presses=12):
    """A held key (presses as fast as the browser takes them, no waiting for pictures): the moves that pile up are
    merged on their way to the kernel, and the picture left on the page is the one of the slider's last value."""
    slider = panel.locator(".labkit-explorer .widget-slider").first  # y at t=1
    readout, handle = slider.locator(".widget-readout"), slider.locator(".noUi-handle")
    before, start = frames(page), float(readout.inner_text())
    handle.focus()
    for _ in range(presses):
        page.keyboard.press("ArrowLeft")
    value = float(readout.inner_text())
    assert value < start, f"the held key did not move the slider ({start} -> {value})"
    page.wait_for_function(
        "([box, text]) => box.querySelector('img').alt.includes(text)",
        arg=[panel.locator(".labkit-explorer .labkit-explorer-picture").first.element_handle(), f"(1, {value:g})"],
        timeout=10_000,
    )
    print(f"\nheld key: {presses} presses, {frames(page) - before} pictures arrived, the last of y = {value:g}")


def _a_key_press_is_drawn_ahead(page, box, slider):
    """Once the kernel has answered a slider's move (and sent the pictures of its next moves), the next key press
    is drawn from those at once: the drawn-ahead count goes up with the picture, and the kernel's own scene of
    that move, when it comes, is not drawn again (nor its alt text changed)."""
    box, slider = box.first, slider.first
    readout, handle = slider.locator(".widget-readout"), slider.locator(".noUi-handle")
    state = "b => [Number(b.dataset.labkitShown), Number(b.dataset.labkitDrawnAhead || 0), b.querySelector('img').alt]"
    idle = "() => window.jupyterapp.shell.currentWidget.sessionContext.session.kernel.status === 'idle'"
    handle.focus()
    moved = "([n, old]) => n.innerText !== old"
    for key, back in (("ArrowLeft", "ArrowRight"), ("ArrowRight", "ArrowLeft")):  # it may stand at an end
        old = readout.inner_text()
        page.keyboard.press(key)
        try:
            page.wait_for_function(moved, arg=[readout.element_handle(), old], timeout=2_000)
        except playwright_api.TimeoutError:
            continue
        page.wait_for_function("b => Number(b.dataset.labkitKept || 0) > 0", arg=box.element_handle(), timeout=10_000)
        page.wait_for_function(idle, timeout=10_000)  # both batches of pictures ahead came before the kernel's idle
        shown, ahead, alt = box.evaluate(state)
        page.keyboard.press(back)  # back to where it stood: the picture one step back was sent ahead
        page.wait_for_function(f"b => Number(b.dataset.labkitShown) > {shown}", arg=box.element_handle())
        after = box.evaluate(state)
        assert after[1] == ahead + 1, (key, shown, ahead, alt, after)
        page.wait_for_timeout(300)
        page.wait_for_function(idle, timeout=10_000)
        assert box.evaluate(state) == after  # the kernel's scene of the same move was not drawn over it
        return
    raise AssertionError("the slider did not move")


def _explorer_pictures(page, panel):
    """Each explorer picture's background (natural width, device pixels), canvas (backing width, device pixels),
    displayed CSS width, alt text and the page's devicePixelRatio, once loaded and painted."""
    boxes = panel.locator(".labkit-explorer .labkit-explorer-picture")
    for k in range(boxes.count()):
        boxes.nth(k).scroll_into_view_if_needed()
        page.wait_for_function(
            "box => { const img = box.querySelector('img'); return img.complete && img.naturalWidth > 0"
            " && Number(box.dataset.labkitShown) > 0; }",
            arg=boxes.nth(k).element_handle(),
        )
    return boxes.evaluate_all(
        """boxes => boxes.map(box => { const img = box.querySelector('img'), canvas = box.querySelector('canvas');
        return {natural: img.naturalWidth, shown: img.getBoundingClientRect().width, alt: img.alt,
                canvas: canvas.width, canvasHeight: canvas.height, canvasShown: canvas.getBoundingClientRect().width,
                canvasShownHeight: canvas.getBoundingClientRect().height, ratio: window.devicePixelRatio}; })"""
    )


LIVE_PICTURES = """() => [...window.jupyterapp.shell.currentWidget.node.querySelectorAll('.labkit-explorer-picture')]
  .map(box => { // what the page shows of each explorer: its background with its canvas over it, as a PNG
    const img = box.querySelector('img'), canvas = box.querySelector('canvas');
    const both = document.createElement('canvas');
    both.width = canvas.width; both.height = canvas.height;
    const ctx = both.getContext('2d');
    ctx.drawImage(img, 0, 0, canvas.width, canvas.height);
    const background = both.toDataURL('image/png');
    ctx.drawImage(canvas, 0, 0);
    return {background, live: both.toDataURL('image/png')};
  })"""

STATIC_PICTURES = """() => window.jupyterapp.shell.currentWidget.content.model.sharedModel.cells
  .filter(c => c.cell_type === 'code').flatMap(c => c.outputs)
  .filter(o => o.data && o.data['image/png'] && String(o.data['text/plain']).startsWith('<Explorer:'))
  .map(o => o.data['image/png'])"""


def _pixels(data_url_or_base64, mode="RGB"):
    import base64
    import io

    import numpy as np
    from PIL import Image

    data = data_url_or_base64.split(",", 1)[-1]
    return np.asarray(Image.open(io.BytesIO(base64.b64decode(data))).convert(mode)).astype(float)


def _unmatched(drawn, expected, reach=2, tolerance=96):
    """The fraction of `expected`'s pixels that no pixel of `drawn` within `reach` pixels matches (every channel
    within `tolerance`): two rasterizers' anti-aliasing and a text a pixel wider match, a missing curve does not."""
    import numpy as np

    best = np.full(expected.shape[:2], np.inf)
    for dy in range(-reach, reach + 1):
        for dx in range(-reach, reach + 1):
            shifted = np.roll(drawn, (dy, dx), axis=(0, 1))
            best = np.minimum(best, np.abs(shifted - expected).max(axis=2))
    return float(np.mean(best > tolerance))


def _live_is_static(page):
    """The live picture of every explorer (before any move) is its static picture: every pixel of the static one
    is drawn, give or take two pixels, where the background alone misses the changing artists."""
    live, static = page.evaluate(LIVE_PICTURES), page.evaluate(STATIC_PICTURES)
    assert len(live) == len(static) > 0, (len(live), len(static))
    for k, (shown, picture) in enumerate(zip(live, static)):
        expected = _pixels(picture)
        drawn, background = _pixels(shown["live"]), _pixels(shown["background"])
        assert drawn.shape == expected.shape, (k, drawn.shape, expected.shape)
        missed, without_scene = _unmatched(drawn, expected), _unmatched(background, expected)
        assert without_scene > 0.002 and missed < 0.1 * without_scene and missed < 0.002, (k, missed, without_scene)


@pytest.mark.parametrize("notebook", NOTEBOOKS, ids=lambda p: p.name)
def test_student_runs_the_notebook_and_moves_a_slider(lab, browser, notebook):
    context = browser.new_context(viewport={"width": 1400, "height": 1000}, device_scale_factor=2)
    outside, console_errors = [], []

    def guard(route):
        host = urlparse(route.request.url).hostname
        if host in ("127.0.0.1", "localhost") or route.request.url.startswith("data:"):
            route.continue_()
        else:
            outside.append(route.request.url)
            route.abort()

    context.route("**/*", guard)
    context.add_init_script(f"({COUNT_IMAGE_FRAMES})()")
    page = context.new_page()
    page.on("console", lambda msg: msg.type == "error" and console_errors.append(msg.text))
    page.on("pageerror", lambda exc: console_errors.append(str(exc)))
    cells = open_and_run(page, lab, notebook)
    failures = [c["errors"] for c in cells if c["errors"]]
    assert not failures, failures

    panel = show_explorers(page)
    assert panel.locator(".widget-slider").count() == SLIDERS[notebook.stem]
    assert panel.locator(".jp-OutputArea-output:has-text('interactive(children')").count() == 0

    output = panel.locator(".labkit-explorer img, .labkit-patch-editor img").last
    output.wait_for(timeout=30_000)
    pictures = _explorer_pictures(page, panel)
    assert pictures, "no explorer picture"
    for picture in pictures:  # crisp on this HiDPI page: the page's device pixels, and described
        assert picture["ratio"] == 2 and picture["natural"] >= 2 * picture["shown"] > 0, picture
        assert picture["canvas"] == round(picture["canvasShown"] * picture["ratio"]) > 0, picture
        assert picture["canvasHeight"] == round(picture["canvasShownHeight"] * picture["ratio"]) > 0, picture
        assert picture["alt"] and any(ch.isdigit() for ch in picture["alt"]), picture
    _live_is_static(page)
    SCREENSHOTS.mkdir(parents=True, exist_ok=True)
    stem = notebook.stem
    page.screenshot(path=str(SCREENSHOTS / f"{stem}-before.png"))

    alts = [picture["alt"] for picture in pictures]
    timings = move_every_slider(page, panel, stem)
    moved = [picture["alt"] for picture in _explorer_pictures(page, panel)]
    assert all(after != before for before, after in zip(alts, moved)), (alts, moved)  # the alt text follows
    if stem == "03_meshes":
        drag = drag_a_corner(page, panel)
        before, after = drag["before"], drag["after"]
        assert drag["steps"], "the mesh picture did not change while the corner was being dragged"
        assert after != before and after.splitlines()[2] != before.splitlines()[2], "corner B's readout did not change"
        # every step drawn in the page at once, and what it drew is the kernel's picture of the same corners
        assert drag["sketched"] == len(drag["steps"]) == MOVES, drag["sketched"]
        sketch, kernel = _pixels(drag["last_step"], "RGBA"), _pixels(drag["settled"], "RGBA")  # the canvas alone
        assert sketch.shape == kernel.shape and (abs(sketch - kernel).max(axis=2) > 8).sum() <= 10
        _nudge_with_keys(page, panel, after)
        timings[f"{stem} editor drag step"] = drag["steps"]
        DRAWN_AHEAD[f"{stem} editor drag step"] = drag["sketched"]
    if stem == "05_monotone":
        _held_key_ends_on_the_latest_value(page, panel)
    explorer = panel.locator(".labkit-explorer").first
    _a_key_press_is_drawn_ahead(page, explorer.locator(".labkit-explorer-picture"), explorer.locator(".widget-slider"))
    editor = panel.locator(".labkit-patch-editor")
    if editor.count():  # its mesh size, drawn ahead with its readout
        _a_key_press_is_drawn_ahead(page, editor.locator(".labkit-editor"), editor.locator(".widget-slider"))
    page.screenshot(path=str(SCREENSHOTS / f"{stem}-after.png"))
    measured = latencies(timings)
    LATENCIES.update(measured)
    for label, (median_ms, p90_ms, moves) in measured.items():
        print(f"\n{label}: median {median_ms:.0f} ms, 90th percentile {p90_ms:.0f} ms over {moves} moves")

    context.close()
    close_sessions(lab)
    assert not outside, f"requests left localhost: {outside}"
    assert not console_errors, console_errors
