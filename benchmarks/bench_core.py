"""Time labkit's 1-D interpolants against scipy in one run; print labkit/scipy.

Run: ``.venv/bin/python benchmarks/bench_core.py [--n 1000000]``.
Each entry is the best of a few repeats, so a busy moment on the machine
does not decide a ratio.
"""

import argparse
import time

import numpy as np
from scipy.interpolate import CubicHermiteSpline, CubicSpline, PchipInterpolator

import labkit


def best_time(fn, repeats):
    best = np.inf
    for _ in range(repeats):
        start = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - start)
    return best


def cases(n, rng):
    x = np.cumsum(rng.uniform(0.5, 1.5, n))
    y = np.sin(x / 50.0) + 0.01 * rng.normal(size=n)
    yp = np.cos(x / 50.0) / 50.0
    xv = np.sort(rng.uniform(x[0], x[-1], n))
    shuffled = rng.permutation(xv)
    return [
        ("nakspline build", lambda: labkit.nakspline(x, y), lambda: CubicSpline(x, y)),
        (
            "ccspline build",
            lambda: labkit.ccspline(x, y, 0.0, 1.0),
            lambda: CubicSpline(x, y, bc_type=((1, 0.0), (1, 1.0))),
        ),
        ("ncspline build", lambda: labkit.ncspline(x, y), lambda: CubicSpline(x, y, bc_type="natural")),
        ("pchip build+eval", lambda: labkit.pchip(x, y, xv), lambda: PchipInterpolator(x, y)(xv)),
        ("eval_pherm", lambda: labkit.eval_pherm(x, y, yp, xv), lambda: CubicHermiteSpline(x, y, yp)(xv)),
        ("eval_plin vs np.interp", lambda: labkit.eval_plin(x, y, xv), lambda: np.interp(xv, x, y)),
        (
            "eval_pherm, shuffled",
            lambda: labkit.eval_pherm(x, y, yp, shuffled),
            lambda: CubicHermiteSpline(x, y, yp)(shuffled),
        ),
        ("eval_plin, shuffled", lambda: labkit.eval_plin(x, y, shuffled), lambda: np.interp(shuffled, x, y)),
    ]


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=1_000_000, help="knots and evaluation points")
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args(argv)
    rng = np.random.default_rng(0)
    print(
        f"{args.n:,} unequally spaced knots, {args.n:,} evaluation points (sorted unless "
        f"shuffled), best of {args.repeats}"
    )
    print(f"{'task':<24}{'labkit s':>10}{'scipy s':>10}{'ratio':>8}")
    for name, ours, theirs in cases(args.n, rng):
        t_ours, t_theirs = best_time(ours, args.repeats), best_time(theirs, args.repeats)
        print(f"{name:<24}{t_ours:>10.4f}{t_theirs:>10.4f}{t_ours / t_theirs:>8.2f}")


if __name__ == "__main__":
    main()
