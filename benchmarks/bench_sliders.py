"""In-process time of one slider move: a new figure, the 2x PNG of a figure updated in place, and the scene.

Run: ``.venv/bin/python benchmarks/bench_sliders.py``. Three ways to answer a move, timed on the
same machine in one run:

* "new figure": build a new figure with the ``plot_*`` function and render it to PNG at 100 dpi, as
  the inline backend does (what the sliders did before the explorers);
* "2x PNG": update the explorer's artists in place and render its 2x PNG by blitting (what every move
  sent until the scenes; still how the static picture is made, :meth:`Explorer.png`);
* "scene": what a move does now: update the artists, and turn the changing ones into the
  :class:`labkit.plots.scene.Scene` the browser draws (at the page's pixel ratio, 2 here), whose
  size is the last column.

The browser adds the trip to the page: see ``benchmarks/bench_browser_latency.py``.
"""

import io
import time

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

import labkit
from labkit import plots


def _graded(elements, dxds_bc):
    e2 = [0, 1]
    return [
        labkit.Corner([0, 0], [3, 0], e2),
        labkit.Corner([1, 0], [dxds_bc, 0], e2),
        labkit.Corner([1, 1], [dxds_bc, 0], e2),
        labkit.Corner([0, 1], [3, 0], e2),
    ]


# name -> (the old redraw for a value, explorer factory, control, two values to alternate)
SLIDERS = {
    "01 limacon intervals": (
        lambda v: plots.plot_limacon(v, 1.15, "pherm"),
        plots.limacon_explorer,
        "intervals",
        (40, 41),
    ),
    "02 convergence ndata": (
        lambda v: plots.plot_interpolation_error(["natural"], v),
        plots.convergence_explorer,
        "ndata",
        (40, 41),
    ),
    "03 mesh dx/ds B,C (11 x 11)": (
        lambda v: plots.plot_patch(_graded(10, v), 11, 11, color_by_quality=True),
        plots.mesh_explorer,
        "dxds_BC",
        (0.1, 0.2),
    ),
    "03 mesh elements (40 x 40)": (
        lambda v: plots.plot_patch(_graded(v, 0.1), v + 1, v + 1, color_by_quality=True),
        plots.mesh_explorer,
        "elements",
        (39, 40),
    ),
    "04 three spline errors": (
        lambda v: plots.plot_interpolation_error(["complete", "natural", "notaknot"], v),
        plots.spline_explorer,
        "ndata",
        (20, 21),
    ),
    "05 spline vs pchip": (
        lambda v: plots.plot_spline_vs_pchip(np.arange(5.0), np.array([0, v, 2, 2.4, 2])),
        plots.pchip_explorer,
        "y1",
        (1.0, 1.05),
    ),
    "06 bilinear ndata": (lambda v: plots.plot_bilinear_error(v), plots.bilinear_explorer, "ndata", (20, 21)),
}


def _median_ms(action, values, repeats=9):
    times = []
    for k in range(repeats):
        start = time.perf_counter()
        action(values[k % 2])
        times.append(time.perf_counter() - start)
    return 1000 * float(np.median(times))


def _old(draw):
    def redraw(value):
        ax = draw(value)
        ax.figure.savefig(io.BytesIO(), format="png", dpi=100)
        plt.close(ax.figure)

    return redraw


def _sent_kb(scene):
    """Kilobytes of a scene's binary buffers (its JSON adds little)."""

    def size(value):
        if isinstance(value, bytes):
            return len(value)
        if isinstance(value, dict):
            return sum(size(v) for v in value.values())
        if isinstance(value, list):
            return sum(size(v) for v in value)
        return 0

    return size(scene) / 1024


def main():
    print(f"{'slider':<30}{'new figure':>12}{'2x PNG':>10}{'scene':>10}{'sent':>10}")
    for name, (draw, factory, control, values) in SLIDERS.items():
        explorer = factory()

        def png_move(v, e=explorer, c=control):
            e._update(**{**e.values(), c: v})
            e.png()

        picture = _median_ms(png_move, values)
        after = _median_ms(lambda v, e=explorer, c=control: setattr(e.controls[c], "value", v), values)
        print(
            f"{name:<30}{_median_ms(_old(draw), values):10.0f} ms{picture:7.0f} ms{after:7.0f} ms"
            f"{_sent_kb(explorer.image.scene):7.0f} KB"
        )
    editor = plots.patch_editor()
    step = _median_ms(lambda v: setattr(editor.widget_, "drag", {"index": 1, "x": 1 + v, "y": 0.0}), (0.0, 0.05))
    print(f"{'03 patch editor drag step':<30}{'-':>12}{'-':>10}{step:7.0f} ms{_sent_kb(editor.widget_.scene):7.0f} KB")


if __name__ == "__main__":
    main()
