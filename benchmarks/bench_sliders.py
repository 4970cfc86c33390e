"""In-process time of one slider move, before and after the explorers (one run, same machine).

Run: ``.venv/bin/python benchmarks/bench_sliders.py``. "Before" is what a slider
did until now: build a new figure with the ``plot_*`` function and render it to
PNG at 100 dpi, as the inline backend does. "After" is what an explorer of
:mod:`labkit.plots.explorers` does: change a control, update the same artists,
render one PNG. The browser adds the trip to the page: see
``benchmarks/bench_browser_latency.py``.
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


def main():
    print(f"{'slider':<30}{'before':>10}{'after':>10}")
    for name, (draw, factory, control, values) in SLIDERS.items():
        explorer = factory()
        after = _median_ms(lambda v, e=explorer, c=control: setattr(e.controls[c], "value", v), values)
        print(f"{name:<30}{_median_ms(_old(draw), values):8.0f} ms{after:7.0f} ms")
    editor = plots.patch_editor()
    step = _median_ms(lambda v: setattr(editor.widget_, "drag", {"index": 1, "x": 1 + v, "y": 0.0}), (0.0, 0.05))
    print(f"{'03 patch editor drag step':<30}{'-':>10}{step:7.0f} ms")


if __name__ == "__main__":
    main()
