"""Time each notebook slider's redraw (build the figure and render it to PNG, as inline does).

Run: ``.venv/bin/python benchmarks/bench_sliders.py``. The goal is well under 200 ms each.
"""
import io
import time

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import labkit  # noqa: E402
from labkit import plots  # noqa: E402

E2 = [0, 1]
GRADED = [labkit.Corner([0, 0], [3, 0], E2), labkit.Corner([1, 0], [-0.5, 0], E2),
          labkit.Corner([1, 1], [-0.5, 0], E2), labkit.Corner([0, 1], [3, 0], E2)]
REDRAWS = {
    "01 limacon (60 intervals, Hermite)": lambda: plots.plot_limacon(60, 1.15, "pherm"),
    "02 convergence error curve (81 points)": lambda: plots.plot_interpolation_error(["pchip"], 81),
    "03 mesh coloured by quality (40 x 40)": lambda: plots.plot_patch(GRADED, 41, 41, color_by_quality=True),
    "04 three spline error curves": lambda: plots.plot_interpolation_error(["complete", "natural", "notaknot"], 41),
    "05 spline vs pchip": lambda: plots.plot_spline_vs_pchip(np.arange(5.0), np.array([0, 1, 2, 2.4, 2])),
    "06 bilinear error map (41 x 41)": lambda: plots.plot_bilinear_error(41),
}


def redraw_time(draw, repeats=5):
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        ax = draw()
        ax.figure.savefig(io.BytesIO(), format="png")
        plt.close(ax.figure)
        times.append(time.perf_counter() - start)
    return np.median(times)


if __name__ == "__main__":
    for name, draw in REDRAWS.items():
        print(f"{name:<42}{1000 * redraw_time(draw):7.0f} ms")
