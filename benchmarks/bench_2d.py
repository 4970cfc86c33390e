"""Time the 2-D tools: patch and quality of a 1000 x 1000 mesh, eval_pbilin vs scipy.

Run: ``.venv/bin/python benchmarks/bench_2d.py``.
"""

import time

import numpy as np
from scipy.interpolate import RegularGridInterpolator

import labkit


def best_time(fn, repeats=3):
    best = np.inf
    for _ in range(repeats):
        start = time.perf_counter()
        result = fn()
        best = min(best, time.perf_counter() - start)
    return best, result


def main():
    q = np.pi / 4
    corners = [
        labkit.Corner([0, 0], [q, -q], [q, q]),
        labkit.Corner([1, 0], [q, q], [-q, q]),
        labkit.Corner([1, 1], [q, -q], [q, q]),
        labkit.Corner([0, 1], [q, q], [-q, q]),
    ]
    u = np.linspace(0, 1, 1000)
    t_patch, (x, y) = best_time(lambda: labkit.patch(*corners, u, u))
    mesh = labkit.quad_mesh(x, y)
    t_quality, _ = best_time(mesh.quality)
    print(f"patch 1000 x 1000 nodes:        {t_patch:.3f} s")
    print(f"quality of {len(mesh.quads):,} quads:   {t_quality:.3f} s")

    data = np.linspace(0, 5, 161)
    test = np.linspace(0, 5, 2001)

    def ours():
        return labkit.eval_pbilin(labkit.runge2d, data, data, test, test)

    def scipy_rgi():
        X, Y = np.meshgrid(data, data, indexing="ij")
        interp = RegularGridInterpolator((data, data), labkit.runge2d(X, Y))
        TX, TY = np.meshgrid(test, test, indexing="ij")
        return interp(np.stack((TX, TY), axis=-1))

    t_ours, z_ours = best_time(ours)
    t_scipy, z_scipy = best_time(scipy_rgi)
    print(
        f"eval_pbilin 161^2 data on 2001^2: {t_ours:.3f} s, "
        f"RegularGridInterpolator {t_scipy:.3f} s, ratio {t_ours / t_scipy:.3f}"
        f" (max difference {np.max(np.abs(z_ours - z_scipy)):.1e})"
    )


if __name__ == "__main__":
    main()
