import warnings

import matplotlib
import meshio
import numpy as np
import pytest

import labkit
from labkit import Corner, QuadMesh, patch, quad_mesh

matplotlib.use("Agg")
R2 = np.sqrt(2) / 2


def mirror(corner):
    """Corner data of the mirror image in y = x with the roles of s and t swapped."""
    flip = lambda v: v[::-1]
    return Corner(flip(corner.point), flip(corner.dt), flip(corner.ds), flip(corner.dsdt))


def exercise9(C_point=(2.0, 2.0), C_ds=(2.0, 0.0)):
    """Patch ABCD of exercise 9 and its mirror abcd (a, b, c, d = A', D', C', B')."""
    q = R2 * np.pi / 4
    A = Corner([0, 1], [np.pi / 4, 0], [0, 1])
    B = Corner([R2, R2], [q, -q], [2 - R2, 2 - R2])
    C = Corner(C_point, C_ds, [2 - R2, 2 - R2])
    D = Corner([0, 2], [2, 0], [0, 1])
    a, b, c, d = mirror(A), mirror(D), mirror(C), mirror(B)
    return (A, B, C, D), (a, b, c, d)


@pytest.mark.parametrize(
    "variant", [{}, {"C_point": (1.8, 1.8), "C_ds": (0.5, -0.5)}], ids=["sharp corner", "rounded corner"]
)
def test_exercise9_two_patches_join_into_one_conforming_mesh(variant):
    first, second = exercise9(**variant)
    x1, y1 = patch(*first, np.linspace(0, 1, 20), np.linspace(0, 1, 30))
    x2, y2 = patch(*second, np.linspace(0, 1, 30), np.linspace(0, 1, 20))
    # shared edge: BC (s = 1 of ABCD) is dc (t = 1 of abcd), node for node
    np.testing.assert_array_equal(np.stack((x1[-1], y1[-1])), np.stack((x2[:, -1], y2[:, -1])))
    # the second patch is the mirror image of the first in y = x
    np.testing.assert_allclose(x2, y1.T, atol=1e-14)
    np.testing.assert_allclose(y2, x1.T, atol=1e-14)
    merged = quad_mesh(x1, y1) + quad_mesh(x2, y2)
    assert len(merged.points) == 2 * 20 * 30 - 30
    assert len(merged.quads) == 2 * 19 * 29
    assert merged.quality().min() > 0
    # conforming: every interior edge is shared by exactly two elements
    edges = np.sort(np.stack((merged.quads, np.roll(merged.quads, -1, axis=1)), axis=-1).reshape(-1, 2), axis=1)
    _, counts = np.unique(edges, axis=0, return_counts=True)
    boundary_edges = 2 * (19 + 29) + 2 * (19 + 29) - 2 * 29
    assert np.sum(counts == 1) == boundary_edges and counts.max() == 2


def exercise8_corners():
    """Quarter circles of radius sqrt(2)/2: AB and DC bow outwards, AD and BC inwards.

    (ERRATA: the sketch is lost. With every side bowing outwards the four arcs
    form one circle and the corners flatten to 180 degrees; this choice keeps
    90 degree corners and the two mirror symmetries.)
    """
    q = np.pi / 4
    return [
        Corner([0, 0], [q, -q], [q, q]),
        Corner([1, 0], [q, q], [-q, q]),
        Corner([1, 1], [q, -q], [q, q]),
        Corner([0, 1], [q, q], [-q, q]),
    ]


def test_exercise8_boundary_is_close_to_the_quarter_circles_and_symmetric():
    u = np.linspace(0, 1, 25)
    x, y = patch(*exercise8_corners(), u, u)
    radius = R2
    # Hermite error bound per coordinate: max|f''''| / 384 with f = G + R (cos, sin)(theta),
    # theta' = pi/2 on [0, 1]; for the point: sqrt(2) times that.
    bound = np.sqrt(2) * radius * (np.pi / 2) ** 4 / 384
    sides = {
        "AB": (x[:, 0], y[:, 0], (0.5, 0.5)),
        "DC": (x[:, -1], y[:, -1], (0.5, 0.5)),
        "AD": (x[0], y[0], (-0.5, 0.5)),
        "BC": (x[-1], y[-1], (1.5, 0.5)),
    }
    for name, (xs, ys, centre) in sides.items():
        deviation = np.abs(np.hypot(xs - centre[0], ys - centre[1]) - radius)
        assert deviation.max() < bound, name
    assert y[:, 0].min() < -0.15 and y[:, -1].max() > 1.15  # bottom and top bow outwards
    assert x[0].max() > 0.15 and x[-1].min() < 0.85  # left and right bow inwards
    # two-fold symmetry: left-right and top-bottom
    np.testing.assert_allclose(x + x[::-1], 1.0, atol=1e-14)
    np.testing.assert_allclose(y, y[::-1], atol=1e-14)
    np.testing.assert_allclose(y + y[:, ::-1], 1.0, atol=1e-14)
    np.testing.assert_allclose(x, x[:, ::-1], atol=1e-14)
    assert quad_mesh(x, y).quality().min() > 0.5


def test_quads_are_counter_clockwise_and_quality_of_known_shapes():
    x, y = np.meshgrid([0.0, 2.0], [0.0, 1.0], indexing="ij")
    mesh = quad_mesh(x, y)
    corners = mesh.points[mesh.quads[0]]
    area = 0.5 * np.sum(corners[:, 0] * np.roll(corners[:, 1], -1) - np.roll(corners[:, 0], -1) * corners[:, 1])
    assert area == pytest.approx(2.0)  # positive: counter-clockwise
    assert mesh.quality()[0] == pytest.approx(1.0)
    # a parallelogram with a 60 degree angle: sin(60)
    skew = QuadMesh([[0, 0], [1, 0], [1.5, np.sqrt(3) / 2], [0.5, np.sqrt(3) / 2]], [[0, 1, 2, 3]])
    assert skew.quality()[0] == pytest.approx(np.sqrt(3) / 2)
    # the same element listed clockwise is inverted
    assert QuadMesh(skew.points, [[0, 3, 2, 1]]).quality()[0] == pytest.approx(-np.sqrt(3) / 2)
    # a bow-tie (crossed) element is folded
    assert QuadMesh([[0, 0], [1, 0], [0, 1], [1, 1]], [[0, 1, 2, 3]]).folded()[0]


def test_quality_of_a_surface_mesh_ignores_the_embedding(rng):
    rotation, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    x, y = np.meshgrid(np.linspace(0, 1, 4), np.linspace(0, 2, 5), indexing="ij")
    flat = np.stack((x, y, np.zeros_like(x)), axis=-1) @ rotation.T
    mesh = quad_mesh(flat[..., 0], flat[..., 1], flat[..., 2])
    np.testing.assert_allclose(mesh.quality(), 1.0)


def test_merge_tolerance_follows_the_mesh_size():
    small = 1e-9
    x, y = np.meshgrid([0.0, small], [0.0, small], indexing="ij")
    left = quad_mesh(x, y)
    right = quad_mesh(x + small, y)
    assert len((left + right).points) == 6  # tiny elements still join, nothing collapses
    apart = quad_mesh(x + 2 * small, y)
    assert len((left + apart).points) == 8


@pytest.mark.parametrize("suffix", [".vtu", ".msh", ".vtk"])
def test_written_files_read_back_with_the_same_points_and_quads(tmp_path, suffix):
    first, second = exercise9()
    mesh = quad_mesh(*patch(*first, np.linspace(0, 1, 5), np.linspace(0, 1, 4)))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        path = mesh.write(tmp_path / f"mesh{suffix}")
    back = meshio.read(path)
    np.testing.assert_allclose(back.points[:, :2], mesh.points)
    np.testing.assert_array_equal(back.points[:, 2], 0.0)
    np.testing.assert_array_equal(back.cells_dict["quad"], mesh.quads)
    np.testing.assert_allclose(back.cell_data_dict["quality"]["quad"], mesh.quality())


def test_mesh_rejects_bad_input(tmp_path):
    with pytest.raises(ValueError, match=r"different shapes: x \(3, 4\), y \(4, 3\)"):
        quad_mesh(np.zeros((3, 4)), np.zeros((4, 3)))
    with pytest.raises(ValueError, match="at least 2 x 2 nodes"):
        quad_mesh(np.zeros((1, 4)), np.zeros((1, 4)))
    with pytest.raises(ValueError, match="2-D array of shape"):
        quad_mesh(np.zeros(4), np.zeros(4))
    x, y = np.meshgrid([0.0, 1.0], [0.0, 1.0], indexing="ij")
    with pytest.raises(ValueError, match="cannot tell the mesh format.*\\.vtu"):
        quad_mesh(x, y).write(tmp_path / "mesh.stl")


def test_plot_draws_every_element_with_labels():
    import matplotlib.pyplot as plt

    x, y = patch(*exercise8_corners(), np.linspace(0, 1, 6), np.linspace(0, 1, 5))
    mesh = quad_mesh(x, y)
    ax = mesh.plot(color_by_quality=True, title="exercise 8")
    cells = ax.collections[0]
    assert len(cells.get_paths()) == 20
    np.testing.assert_allclose(cells.get_array(), mesh.quality())
    assert ax.get_title() == "exercise 8" and ax.get_xlabel() == "x" and ax.get_aspect() == 1.0
    plt.close(ax.figure)


def test_joining_meshes_with_nodes_piled_on_one_spot_is_refused_not_enumerated():
    # 60,000 nodes each at the origin: listing the coinciding pairs would take some 115 GB
    quads = np.array([[0, 1, 2, 3]])
    heap = labkit.QuadMesh(np.zeros((60_000, 2)), quads)
    unit = labkit.QuadMesh(np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]] * 15_000), quads)
    with pytest.raises(ValueError, match="pairs of nodes coincide"):
        heap + unit
    # an honest join along a shared edge merges its nodes as before
    x, y = np.meshgrid(np.linspace(0, 1, 4), np.linspace(0, 1, 3), indexing="ij")
    left, right = labkit.quad_mesh(x, y), labkit.quad_mesh(x + 1, y)
    assert len((left + right).points) == 12 + 12 - 3
