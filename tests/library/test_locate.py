"""The bucket locator behind bracket and every evaluation, against a binary search.

The reference is ``np.searchsorted``: the index k with x[k] <= p < x[k+1],
clipped to [0, n-2]. The bucket path has several regimes (one step, several
steps, crowded buckets finished by binary search, buckets straddling two
blocks of knots, too few points to be worth buckets); each is forced here.
"""

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from labkit import _locate
from labkit._locate import Locator, blockwise, locate


def reference(x, p):
    return np.clip(np.searchsorted(x, p, side="right") - 1, 0, x.size - 2)


def probe_points(x, rng, m=2000):
    """Random points inside and outside the data, plus every knot exactly."""
    span = x[-1] - x[0]
    inside = rng.uniform(x[0], x[-1], m)
    outside = np.array([x[0] - span, x[0] - 1e-300, x[-1], x[-1] + span, -np.inf, np.inf])
    return np.concatenate([inside, x, np.nextafter(x, -np.inf), outside])


SPACINGS = {
    "equal": lambda rng, n: np.linspace(-1.0, 1.0, n),
    "unequal": lambda rng, n: np.cumsum(rng.uniform(0.5, 1.5, n)),
    "random": lambda rng, n: np.sort(rng.uniform(0.0, 1.0, n)),
    # Knots bunched geometrically at 0: thousands share the first bucket.
    "clustered": lambda rng, n: np.concatenate([[0.0], np.geomspace(1e-12, 1.0, n - 1)]),
    "huge offset": lambda rng, n: 1e12 + np.cumsum(rng.uniform(0.5, 1.5, n)),
}


@pytest.mark.parametrize("spacing", SPACINGS)
def test_agrees_with_binary_search(spacing, rng):
    x = SPACINGS[spacing](rng, 3000)
    p = probe_points(x, rng)
    np.testing.assert_array_equal(locate(x, p), reference(x, p))


@pytest.mark.parametrize("spacing", ["random", "clustered"])
def test_small_blocks_split_crowded_buckets_between_blocks(spacing, rng, monkeypatch):
    # With blocks of 8 knots a crowded bucket is counted in several blocks,
    # and MAX_STEPS = 1 sends every point of it to the binary-search finish.
    monkeypatch.setattr(_locate, "BLOCK", 8)
    monkeypatch.setattr(_locate, "MAX_STEPS", 1)
    x = SPACINGS[spacing](rng, 500)
    locator = Locator(x, 10_000)
    assert locator.use_buckets and locator.crowded
    p = probe_points(x, rng)
    np.testing.assert_array_equal(locate(x, p), reference(x, p))


def test_bucket_table_counts_every_interior_knot_once(rng, monkeypatch):
    # Blocks of 16 knots, so buckets straddle blocks and are counted twice over.
    monkeypatch.setattr(_locate, "BLOCK", 16)
    x = SPACINGS["random"](rng, 1000)
    locator = Locator(x, x.size)
    per_bucket = np.diff(locator.left)
    bucket = np.floor((x[1:-1] - x[0]) * locator.scale).astype(int)
    np.testing.assert_array_equal(per_bucket, np.bincount(bucket, minlength=x.size + 1))
    assert locator.steps == min(per_bucket.max(), _locate.MAX_STEPS)


def test_few_points_use_plain_binary_search(rng):
    x = SPACINGS["unequal"](rng, 4000)
    assert not Locator(x, 10).use_buckets
    assert Locator(x, 1000).use_buckets
    p = rng.uniform(x[0], x[-1], 10)
    np.testing.assert_array_equal(locate(x, p), reference(x, p))


@pytest.mark.parametrize(
    "x", [np.array([-1e308, 1e308]), np.array([-1e308, 0.0, 1e308]), np.array([0.0, 5e-324, 1e-323])]
)
def test_extreme_ranges_fall_back_to_binary_search(x):
    # The bucket scale n / (x[-1] - x[0]) overflows or vanishes here.
    p = np.array([-np.inf, -1e308, 0.0, 5e-324, 1e-320, 1e308, np.inf])
    with np.errstate(all="raise"):
        np.testing.assert_array_equal(locate(x, p), reference(x, p))


def test_nan_points_get_a_valid_index_without_warnings(rng):
    x = SPACINGS["unequal"](rng, 100)
    p = np.where(rng.random(400) < 0.5, np.nan, rng.uniform(x[0], x[-1], 400))
    with np.errstate(all="raise"):
        k = locate(x, p)
    assert k.min() >= 0 and k.max() <= x.size - 2
    finite = ~np.isnan(p)
    np.testing.assert_array_equal(k[finite], reference(x, p[finite]))


def test_blocks_cover_every_point_of_any_shape(rng, monkeypatch):
    monkeypatch.setattr(_locate, "BLOCK", 7)
    x = SPACINGS["unequal"](rng, 50)
    p = rng.uniform(x[0] - 5, x[-1] + 5, (9, 13))

    def record(k, block, out):
        out[...] = block + 1000 * k

    np.testing.assert_array_equal(blockwise(x, p, record), p + 1000 * reference(x, p))


@settings(max_examples=200, deadline=None)
@given(
    gaps=st.lists(st.floats(1e-9, 1e3, allow_nan=False, allow_infinity=False), min_size=1, max_size=60),
    start=st.floats(-1e6, 1e6),
    points=st.lists(st.floats(-1e7, 1e7), min_size=1, max_size=80),
)
def test_property_agrees_with_binary_search(gaps, start, points):
    x = start + np.concatenate(([0.0], np.cumsum(gaps)))
    assume(np.all(np.diff(x) > 0))  # tiny gaps can vanish against a big start
    p = np.concatenate([np.array(points), x])
    np.testing.assert_array_equal(locate(x, p), reference(x, p))
