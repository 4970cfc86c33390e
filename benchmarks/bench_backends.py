"""Which way of redrawing a slider's figure is quickest in JupyterLab? One run, same machine, same figure.

Three ways, each a 6 x 4 in figure at 80 dpi with one 1001-point line, updated with
``set_ydata`` (the figure is reused, never rebuilt):

* ``image``: the figure drawn with Agg and its PNG put into an ``ipywidgets.Image`` (what
  ``labkit.plots.explorers`` does);
* ``output``: the same PNG shown with ``display`` in an ``ipywidgets.Output`` after
  ``clear_output(wait=True)`` (the inline-PNG way, with a reused figure);
* ``ipympl``: ``%matplotlib widget`` and ``fig.canvas.draw_idle()`` (only if ipympl is
  installed; it is not a labkit dependency: ``.venv/bin/pip install ipympl`` first).

Run: ``.venv/bin/python benchmarks/bench_backends.py``. It starts JupyterLab and headless
Chromium like the browser test (``tests/browser/jupyterlab_session.py``), presses the right-arrow
key on each slider 12 times and prints the median and 90th percentile from key press to the new
picture: an ``<img>`` whose ``src`` changed, or for ipympl's canvas, image data arriving on the
kernel's websocket.
"""

import importlib.util
import statistics
import sys
import tempfile
import time
from pathlib import Path

import nbformat

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "browser"))
from jupyterlab_session import CHROMIUM_FLAGS, COUNT_IMAGE_FRAMES, TOKEN, frames, jupyterlab, run_all

SETUP = """import io
import ipywidgets as widgets
import numpy as np
from IPython.display import Image, display
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

x = np.linspace(0, 1, 1001)


def agg_figure():
    figure = Figure(figsize=(6, 4), dpi=80)
    FigureCanvasAgg(figure)
    line, = figure.add_subplot().plot(x, np.sin(x))
    return figure, line


def png(figure):
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png")
    return buffer.getvalue()
"""
WAYS = {
    "image": """figure_i, line_i = agg_figure()
picture = widgets.Image(value=png(figure_i))
slider_i = widgets.IntSlider(1, 1, 60, description="image")
def redraw_i(change):
    line_i.set_ydata(np.sin(change["new"] * x))
    picture.value = png(figure_i)
slider_i.observe(redraw_i, "value")
box = widgets.VBox([slider_i, picture]); box.add_class("bench-image"); box""",
    "output": """figure_o, line_o = agg_figure()
out = widgets.Output()
with out:
    display(Image(png(figure_o)))
slider_o = widgets.IntSlider(1, 1, 60, description="output")
def redraw_o(change):
    line_o.set_ydata(np.sin(change["new"] * x))
    with out:
        out.clear_output(wait=True)
        display(Image(png(figure_o)))
slider_o.observe(redraw_o, "value")
box = widgets.VBox([slider_o, out]); box.add_class("bench-output"); box""",
    "ipympl": """%matplotlib widget
import matplotlib.pyplot as plt
plt.ioff()
figure_m, axes_m = plt.subplots(figsize=(6, 4), dpi=80)
line_m, = axes_m.plot(x, np.sin(x))
slider_m = widgets.IntSlider(1, 1, 60, description="ipympl")
def redraw_m(change):
    line_m.set_ydata(np.sin(change["new"] * x))
    figure_m.canvas.draw_idle()
slider_m.observe(redraw_m, "value")
box = widgets.VBox([slider_m, figure_m.canvas]); box.add_class("bench-ipympl"); box""",
}
NEW_PICTURE = """([scope, old, before]) => {
  const node = document.querySelector(scope);
  const img = node && node.querySelector('img');
  if (img) return img.src !== old;
  return window.__labkitImageFrames > before;
}"""


def main():
    from playwright.sync_api import sync_playwright

    ways = {k: v for k, v in WAYS.items() if k != "ipympl" or importlib.util.find_spec("ipympl")}
    if "ipympl" not in ways:
        print("ipympl is not installed: measuring image and output only (pip install ipympl to add it)")
    nb = nbformat.v4.new_notebook()
    nb.metadata["kernelspec"] = {"name": "python3", "display_name": "Python 3 (ipykernel)", "language": "python"}
    nb.cells = [nbformat.v4.new_code_cell(SETUP)] + [nbformat.v4.new_code_cell(source) for source in ways.values()]
    with tempfile.TemporaryDirectory() as home:
        served = Path(home) / "served"
        served.mkdir()
        nbformat.write(nb, served / "backends.ipynb")
        with jupyterlab(home, served) as base, sync_playwright() as p:
            browser = p.chromium.launch(executable_path="/usr/bin/chromium", headless=True, args=CHROMIUM_FLAGS)
            context = browser.new_context(viewport={"width": 1400, "height": 2400})
            context.add_init_script(f"({COUNT_IMAGE_FRAMES})()")
            page = context.new_page()
            page.goto(f"{base}/lab/workspaces/bench/tree/backends.ipynb?reset&token={TOKEN}")
            run_all(page, base, len(nb.cells))
            for way in ways:
                scope = f".bench-{way}"
                page.locator(f"{scope} .noUi-handle").wait_for(timeout=30_000)
                times = []
                for _ in range(12):
                    old = page.evaluate(
                        "s => { const i = document.querySelector(s + ' img'); return i ? i.src : null; }", scope
                    )
                    before = frames(page)
                    page.locator(f"{scope} .noUi-handle").focus()
                    start = time.perf_counter()
                    page.keyboard.press("ArrowRight")
                    page.wait_for_function(NEW_PICTURE, arg=[scope, old, before], timeout=10_000)
                    times.append(1000 * (time.perf_counter() - start))
                    time.sleep(0.1)  # let a late second frame pass before the next press
                ordered = sorted(times)
                print(
                    f"{way:<8} median {statistics.median(times):4.0f} ms, "
                    f"90th percentile {ordered[int(0.9 * (len(ordered) - 1))]:4.0f} ms over {len(times)} key presses"
                )
            browser.close()


if __name__ == "__main__":
    main()
