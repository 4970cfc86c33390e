import numpy as np
import pytest

from labkit import Corner, patch, quad_mesh

R2 = np.sqrt(2) / 2
E1, E2, ZERO = [1.0, 0.0], [0.0, 1.0], [0.0, 0.0]


def unit_square(**changes):
    """Exercise 5's corners (the identity map), with some fields replaced."""
    data = {
        "A": dict(point=ZERO, ds=E1, dt=E2),
        "B": dict(point=E1, ds=E1, dt=E2),
        "C": dict(point=[1.0, 1.0], ds=E1, dt=E2),
        "D": dict(point=E2, ds=E1, dt=E2),
    }
    for key, value in changes.items():
        corner, field = key.split("_")
        data[corner][field] = value
    return [Corner(**data[c]) for c in "ABCD"]


def test_identity_patch_reproduces_the_grid_exactly():
    s, t = np.linspace(0, 1, 4), np.linspace(0, 1, 5)
    x, y = patch(*unit_square(), s, t)
    X, Y = np.meshgrid(s, t, indexing="ij")
    np.testing.assert_allclose(x, X, atol=1e-15)
    np.testing.assert_allclose(y, Y, atol=1e-15)


def test_non_uniform_parameters_grade_the_mesh_without_moving_the_outline():
    s = np.linspace(0, 1, 9) ** 2
    x, y = patch(*unit_square(), s, np.linspace(0, 1, 3))
    np.testing.assert_allclose(x[:, 0], s, atol=1e-15)


def test_exercise7_straight_quadrilateral_is_the_bilinear_map():
    A, B, C, D = map(np.array, ([-1.0, 0.0], [1.0, 0.0], [1.0, 0.5], [0.0, 1.0]))
    twist = A - B + C - D
    assert twist.tolist() == [-1.0, -0.5]  # the lab's d2x/dsdt and d2y/dsdt
    corners = [
        Corner(A, B - A, D - A, twist),
        Corner(B, B - A, C - B, twist),
        Corner(C, C - D, C - B, twist),
        Corner(D, C - D, D - A, twist),
    ]
    s, t = np.linspace(0, 1, 20), np.linspace(0, 1, 15)
    S, T = np.meshgrid(s, t, indexing="ij")
    bilinear = (
        np.multiply.outer(A, (1 - S) * (1 - T))
        + np.multiply.outer(B, S * (1 - T))
        + np.multiply.outer(C, S * T)
        + np.multiply.outer(D, (1 - S) * T)
    )
    xy = patch(*corners, s, t)
    np.testing.assert_allclose(xy, bilinear, atol=1e-14)
    # mesh lines straight and uniformly divided: second differences vanish
    np.testing.assert_allclose(np.diff(xy, 2, axis=1), 0, atol=1e-14)
    np.testing.assert_allclose(np.diff(xy, 2, axis=2), 0, atol=1e-14)


def test_exercise6_graded_mesh_shrinks_towards_the_right():
    x, y = patch(
        *unit_square(A_ds=[3.0, 0.0], D_ds=[3.0, 0.0], B_ds=[0.1, 0.0], C_ds=[0.1, 0.0]),
        np.linspace(0, 1, 11),
        np.linspace(0, 1, 16),
    )
    widths = np.diff(x, axis=0)
    assert np.all(widths > 0)
    assert np.all(np.diff(widths, axis=0) < 0)
    np.testing.assert_allclose(x[[0, -1]], [np.zeros(16), np.ones(16)], atol=1e-15)
    assert widths[0, 0] / widths[-1, 0] > 10


def _hermite_monomial_matrix():
    # rows: coefficients of 1, u, u^2, u^3 for h00, h10, h01, h11 (value/slope at 0, at 1)
    return np.array([[1, 0, -3, 2], [0, 1, -2, 1], [0, 0, 3, -2], [0, 0, -1, 1]], dtype=float)


def test_patch_equals_the_tensor_form_on_random_data(rng):
    corners = [Corner(*rng.normal(size=(4, 3))) for _ in range(4)]
    A, B, C, D = corners
    s, t = rng.uniform(0, 1, 7), rng.uniform(0, 1, 5)
    P = _hermite_monomial_matrix()
    Hs = P @ np.vander(s, 4, increasing=True).T  # (4, ns)
    Ht = P @ np.vander(t, 4, increasing=True).T
    # geometry matrix: rows (A-side value, A-side s-slope, B-side value, B-side s-slope)
    # of the t-data (bottom value, bottom t-slope, top value, top t-slope)
    G = np.array(
        [
            [A.point, A.dt, D.point, D.dt],
            [A.ds, A.dsdt, D.ds, D.dsdt],
            [B.point, B.dt, C.point, C.dt],
            [B.ds, B.dsdt, C.ds, C.dsdt],
        ]
    )  # (4, 4, dim)
    expected = np.einsum("is,ijd,jt->dst", Hs, G, Ht)
    np.testing.assert_allclose(patch(A, B, C, D, s, t), expected, atol=1e-12)


def test_patch_matches_corner_points_slopes_and_twists(rng):
    corners = [Corner(*rng.normal(size=(4, 2))) for _ in range(4)]
    A = corners[0]
    eps = 1e-6
    xy = patch(*corners, [0.0, eps, 1.0], [0.0, eps, 1.0])
    for (i, j), corner in zip([(0, 0), (2, 0), (2, 2), (0, 2)], corners):
        np.testing.assert_allclose(xy[:, i, j], corner.point, atol=1e-14)
    np.testing.assert_allclose((xy[:, 1, 0] - xy[:, 0, 0]) / eps, A.ds, atol=1e-4)
    np.testing.assert_allclose((xy[:, 0, 1] - xy[:, 0, 0]) / eps, A.dt, atol=1e-4)
    twist = (xy[:, 1, 1] - xy[:, 1, 0] - xy[:, 0, 1] + xy[:, 0, 0]) / eps**2
    np.testing.assert_allclose(twist, A.dsdt, atol=1e-3)


def test_three_dimensional_patch_gives_three_coordinate_arrays(rng):
    corners = [Corner(*rng.normal(size=(4, 3))) for _ in range(4)]
    x, y, z = patch(*corners, np.linspace(0, 1, 6), np.linspace(0, 1, 4))
    assert x.shape == y.shape == z.shape == (6, 4)
    np.testing.assert_allclose([x[0, 0], y[0, 0], z[0, 0]], corners[0].point)


def test_backward_corner_derivative_folds_elements():
    corners = unit_square(B_ds=[-1.5, 0.0], C_ds=[-1.5, 0.0])
    mesh = quad_mesh(*patch(*corners, np.linspace(0, 1, 21), np.linspace(0, 1, 5)))
    quality = mesh.quality()
    assert quality.min() < 0
    folded = mesh.folded()
    np.testing.assert_array_equal(folded, quality <= 0)
    # the folds sit next to B and C, the right-hand edge (s near 1)
    s_index = np.repeat(np.arange(20), 4)
    assert folded.any() and s_index[folded].min() >= 10


def test_corner_and_patch_reject_bad_input():
    with pytest.raises(ValueError, match="2 .plane. or 3 .space. coordinates"):
        Corner([0, 0, 0, 0], [1, 0, 0, 0], [0, 1, 0, 0])
    with pytest.raises(ValueError, match="ds has 3 components but point has 2"):
        Corner([0, 0], [1, 0, 0], [0, 1])
    with pytest.raises(ValueError, match="dsdt contains a non-finite"):
        Corner([0, 0], [1, 0], [0, 1], [np.nan, 0])
    A, B, C, D = unit_square()
    with pytest.raises(ValueError, match="mixed dimension.*C is 3-D"):
        patch(A, B, Corner([1, 1, 0], [1, 0, 0], [0, 1, 0]), D, [0, 1], [0, 1])
    with pytest.raises(ValueError, match=r"s must lie in \[0, 1\].*1.5"):
        patch(A, B, C, D, [0, 1.5], [0, 1])
    with pytest.raises(ValueError, match="t must be a non-empty 1-D array"):
        patch(A, B, C, D, [0, 1], [[0, 1]])
    with pytest.raises(ValueError, match="D must be a labkit.Corner"):
        patch(A, B, C, (0, 1), [0, 1], [0, 1])


def test_corner_data_is_copied_not_shared():
    point = np.array([0.0, 0.0])
    corner = Corner(point, [1, 0], [0, 1])
    point[0] = 5.0
    assert corner.point[0] == 0.0
