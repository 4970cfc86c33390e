"""Quadrilateral meshes from patch grids: connectivity, quality, merging, files, drawing.

``quad_mesh(x, y)`` turns the coordinate arrays of :func:`labkit.patch` into
nodes and counter-clockwise quadrilaterals; ``m1 + m2`` joins meshes that
share an edge into one conforming mesh (exercise 9 of the lab). See
``notebooks/03_meshes.ipynb``.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ._alt import describe, num
from ._validate import as_float_array, require_finite
from .errors import InputError

if TYPE_CHECKING:  # matplotlib is imported only when a mesh is drawn
    from matplotlib.axes import Axes

WRITERS = {".vtu": ("vtu", {}), ".vtk": ("vtk", {}), ".msh": ("gmsh22", {"binary": True})}
MERGE_TOLERANCE = 1e-6  # relative to the shortest edge of the meshes being joined
# the quality map reads for colour-blind readers too (cividis: dark blue to yellow, lightness rising
# throughout); folded elements are hatched and outlined as well, so no reading rests on colour alone
QUALITY_CMAP = "cividis"
FOLDED_STYLE = {"facecolor": "none", "edgecolor": "white", "hatch": "////", "linewidth": 1.5}
FOLDED_LABEL = "folded or inverted (quality ≤ 0): hatched, outlined"


class QuadMesh:
    """Nodes and quadrilateral elements of a mesh.

    Attributes
    ----------
    points : ndarray, shape (N, dim)
        Node coordinates, ``dim`` 2 or 3.
    quads : ndarray of int, shape (M, 4)
        Node indices of each element, counter-clockwise for a positively
        oriented patch.
    """

    points: NDArray[np.float64]
    quads: NDArray[np.intp]

    def __init__(self, points: ArrayLike, quads: ArrayLike) -> None:
        self.points = as_float_array(points, "points")
        numbers = as_float_array(quads, "quads")
        if not np.all(np.isfinite(numbers)) or np.any(numbers != np.round(numbers)):
            raise InputError("quads must hold whole node numbers (0, 1, 2, ...).")
        self.quads = numbers.astype(np.intp)
        if self.points.ndim != 2 or self.points.shape[1] not in (2, 3):
            raise InputError(f"points must have shape (N, 2) or (N, 3); got {self.points.shape}.")
        if self.quads.ndim != 2 or self.quads.shape[1] != 4:
            raise InputError(f"quads must have shape (M, 4); got {self.quads.shape}.")
        if self.quads.size and (self.quads.min() < 0 or self.quads.max() >= len(self.points)):
            raise InputError("quads refer to nodes that do not exist in points.")

    def __repr__(self) -> str:
        return f"QuadMesh({len(self.points)} nodes, {len(self.quads)} quads, {self.dim}-D)"

    @property
    def dim(self) -> int:
        """Number of coordinates of the nodes, 2 or 3."""
        return self.points.shape[1]

    def edge_lengths(self) -> NDArray[np.float64]:
        """Length of the four edges of every element, shape (M, 4)."""
        corners = self.points[self.quads]
        return np.linalg.norm(np.roll(corners, -1, axis=1) - corners, axis=2)

    def quality(self) -> NDArray[np.float64]:
        """Minimum scaled Jacobian of each element, in [-1, 1].

        At every corner the two edges leaving it, scaled to unit length,
        span a signed area: 1 for a right angle, sin(angle) in general,
        <= 0 where the element is degenerate, folded or inverted. The
        element's quality is the smallest of its four. For a surface in
        space the sign is taken against the element's normal (the cross
        product of its diagonals).

        Examples
        --------
        >>> from labkit import quad_mesh
        >>> import numpy as np
        >>> x, y = np.meshgrid([0.0, 1.0], [0.0, 1.0], indexing="ij")
        >>> quad_mesh(x, y).quality().tolist()
        [1.0]
        """
        corners = self.points[self.quads]
        forward = np.roll(corners, -1, axis=1) - corners
        backward = np.roll(corners, 1, axis=1) - corners
        if self.dim == 2:
            signed = forward[..., 0] * backward[..., 1] - forward[..., 1] * backward[..., 0]
        else:
            normal = np.cross(corners[:, 2] - corners[:, 0], corners[:, 3] - corners[:, 1])
            unit = normal / np.maximum(np.linalg.norm(normal, axis=1, keepdims=True), np.finfo(float).tiny)
            signed = np.einsum("mkd,md->mk", np.cross(forward, backward), unit)
        lengths = np.linalg.norm(forward, axis=2) * np.linalg.norm(backward, axis=2)
        with np.errstate(divide="ignore", invalid="ignore"):
            scaled = np.where(lengths > 0, signed / lengths, 0.0)
        return np.clip(scaled.min(axis=1), -1.0, 1.0)

    def folded(self) -> NDArray[np.bool_]:
        """Boolean mask of elements that are degenerate, folded or inverted (quality <= 0)."""
        return self.quality() <= 0.0

    def __add__(self, other: QuadMesh) -> QuadMesh:
        """Join two meshes, merging nodes that coincide into one conforming mesh."""
        if not isinstance(other, QuadMesh):
            return NotImplemented
        if other.dim != self.dim:
            raise InputError(f"cannot join a {self.dim}-D mesh and a {other.dim}-D mesh.")
        points = np.vstack((self.points, other.points))
        quads = np.vstack((self.quads, other.quads + len(self.points)))
        shortest = min(_shortest_edge(self), _shortest_edge(other))
        return _merge_coincident(points, quads, MERGE_TOLERANCE * shortest)

    def write(self, path: str | os.PathLike[str]) -> Path:
        """Write the mesh with meshio; the format follows the suffix (.vtu, .vtk, .msh).

        Node coordinates are written with three columns (z = 0 for a plane
        mesh) and the element quality is attached as cell data ``quality``.
        ``.msh`` is written as binary gmsh 2.2.
        """
        import meshio

        path = Path(path)
        if path.suffix.lower() not in WRITERS:
            raise InputError(f"cannot tell the mesh format from {path.name!r}; use one of " + ", ".join(WRITERS) + ".")
        file_format, options = WRITERS[path.suffix.lower()]
        points = self.points if self.dim == 3 else np.column_stack((self.points, np.zeros(len(self.points))))
        cell_data: dict[str, list[NDArray[Any]]] = {"quality": [self.quality()]}
        if file_format == "gmsh22":
            ones = np.ones(len(self.quads), dtype=np.int32)
            cell_data.update({"gmsh:physical": [ones], "gmsh:geometrical": [ones]})
        mesh = meshio.Mesh(points, [("quad", self.quads)], cell_data=cell_data)
        meshio.write(path, mesh, file_format=file_format, **options)
        return path

    def plot(
        self,
        ax: Axes | None = None,
        color_by_quality: bool = False,
        title: str | None = None,
        colorbar: bool = True,
        **line_kw: Any,
    ) -> Axes:
        """Draw the element edges (x and y) with matplotlib; return the axes.

        With ``color_by_quality`` the elements are filled by their quality
        on the cividis map (dark blue: folded or inverted, yellow: square),
        with a colour bar unless ``colorbar=False``; folded or inverted
        elements (quality <= 0) are also hatched and outlined in white, and a
        legend below the axes says so. ``labkit.plots`` builds its mesh
        figures on this. The axes' alternative text (the ``alt`` of the
        picture in a notebook) gives the mesh's size, extent and quality.
        """
        import matplotlib.pyplot as plt
        from matplotlib.collections import PolyCollection
        from matplotlib.patches import Patch

        if ax is None:
            _, ax = plt.subplots(figsize=(5, 5))
        # shape (M, 4, 2): PolyCollection takes an array, though matplotlib's stubs type it as a Sequence
        polygons = self.points[self.quads][..., :2]
        style = {"edgecolor": "tab:blue", "linewidth": 0.8, **line_kw}
        quality = self.quality()
        if color_by_quality:
            cells = PolyCollection(
                polygons,  # type: ignore[arg-type]
                array=quality,
                cmap=QUALITY_CMAP,
                clim=(-1, 1),
                gid="quality",
                **style,
            )
            ax.add_collection(cells)
            folded = PolyCollection(polygons[quality <= 0], gid="folded", **FOLDED_STYLE)  # type: ignore[arg-type]
            ax.add_collection(folded)
            sample = Patch(label=FOLDED_LABEL, **{**FOLDED_STYLE, "facecolor": cells.cmap(0.25)})  # type: ignore[arg-type]
            ax.legend(
                handles=[sample],
                loc="upper center",
                bbox_to_anchor=(0.5, -0.13),
                fontsize="small",
                frameon=False,
                handleheight=1.5,
            )
            if colorbar:
                ax.figure.colorbar(cells, ax=ax, label="quality (min scaled Jacobian)", shrink=0.8)
        else:
            ax.add_collection(PolyCollection(polygons, facecolor="none", **style))  # type: ignore[arg-type]
        ax.autoscale_view()
        ax.set_aspect("equal")
        ax.set_xlabel("x")
        ax.set_ylabel("y")
        ax.set_title(title or f"{len(self.quads)} quadrilaterals")
        describe(ax, self.describe())
        return ax

    def describe(self) -> str:
        """What a drawing of the mesh shows, in numbers: its size, extent and quality (the picture's alt text).

        Examples
        --------
        >>> from labkit import quad_mesh
        >>> import numpy as np
        >>> x, y = np.meshgrid([0.0, 1.0, 2.0], [0.0, 1.0], indexing="ij")
        >>> quad_mesh(x, y).describe()
        'mesh of 2 quadrilaterals, 6 nodes, x from 0 to 2, y from 0 to 1: worst quality 1.00, none folded'
        """
        quality = self.quality()
        count = len(self.quads)
        text = f"mesh of {count} quadrilateral{'s' * (count != 1)}, {len(self.points)} nodes"
        if len(self.quads) == 0:
            return text
        used = self.points[np.unique(self.quads)]
        low, high = used.min(axis=0), used.max(axis=0)
        folded = int(np.sum(quality <= 0))
        return (
            f"{text}, x from {num(low[0])} to {num(high[0])}, y from {num(low[1])} to {num(high[1])}: "
            f"worst quality {quality.min():.2f}, " + (f"{folded} folded" if folded else "none folded")
        )


def quad_mesh(x: ArrayLike, y: ArrayLike, z: ArrayLike | None = None) -> QuadMesh:
    """Build a :class:`QuadMesh` from coordinate arrays of shape (ns, nt).

    Node ``i * nt + j`` is ``(x[i, j], y[i, j])``; the element between
    parameter lines i, i+1 and j, j+1 lists its nodes in the order
    (i, j), (i+1, j), (i+1, j+1), (i, j+1): counter-clockwise when the
    patch is positively oriented.

    Parameters
    ----------
    x, y : array_like, shape (ns, nt)
        Coordinates, e.g. ``x, y = patch(A, B, C, D, s, t)``; ``ns, nt >= 2``.
    z : array_like, shape (ns, nt), optional
        Third coordinate for a surface mesh.

    Returns
    -------
    QuadMesh

    Examples
    --------
    >>> import numpy as np
    >>> from labkit import quad_mesh
    >>> x, y = np.meshgrid(np.linspace(0, 1, 4), np.linspace(0, 1, 5), indexing="ij")
    >>> mesh = quad_mesh(x, y)
    >>> mesh.points.shape, mesh.quads.shape
    ((20, 2), (12, 4))
    """
    coords = [_grid(c, name) for c, name in ((x, "x"), (y, "y"), (z, "z")) if c is not None or name != "z"]
    shapes = {c.shape for c in coords}
    if len(shapes) != 1:
        raise InputError(
            "coordinate arrays of different shapes: "
            + ", ".join(f"{n} {c.shape}" for n, c in zip("xyz", coords))
            + ". Pass the arrays of one patch evaluation."
        )
    ns, nt = coords[0].shape
    if ns < 2 or nt < 2:
        raise InputError(f"a mesh needs at least 2 x 2 nodes; got {ns} x {nt}.")
    index = np.arange(ns * nt).reshape(ns, nt)
    quads = np.stack((index[:-1, :-1], index[1:, :-1], index[1:, 1:], index[:-1, 1:]), axis=-1).reshape(-1, 4)
    return QuadMesh(np.stack([c.ravel() for c in coords], axis=1), quads)


def _grid(values, name):
    arr = as_float_array(values, name)
    if arr.ndim != 2:
        raise InputError(f"{name} must be a 2-D array of shape (ns, nt); got shape {arr.shape}.")
    require_finite(arr, name)
    return arr


def _shortest_edge(mesh):
    lengths = mesh.edge_lengths()
    positive = lengths[lengths > 0]
    return positive.min() if positive.size else 1.0


def _merge_coincident(points, quads, tolerance):
    """Renumber nodes so that points closer than `tolerance` become one node.

    The pairs are counted before they are listed: meshes meet along edges,
    so a join has about as many coinciding pairs as shared nodes, and one
    with far more (thousands of nodes piled on one spot) is refused instead
    of listing billions of pairs. The count is of the pairs in one cell of
    a grid whose cells' diagonal is `tolerance` (each such pair coincides,
    and a pile of nodes fills some cell), so it costs a sort."""
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        cells = np.floor(points / (tolerance / np.sqrt(points.shape[1]))) if tolerance > 0 else points
    if not np.all(np.isfinite(cells)):
        cells = points  # a tolerance too small for a grid: count exact duplicates
    _, counts = np.unique(cells, axis=0, return_counts=True)
    count = int(np.sum(counts.astype(np.int64) * (counts - 1) // 2))
    limit = max(10_000, 10 * len(points))
    if count > limit:
        raise InputError(
            f"{count:,} pairs of nodes coincide; meshes should meet only along their shared edges. "
            "Check that each mesh's nodes are distinct (no points piled on one spot)."
        )
    from scipy.spatial import cKDTree  # loaded when meshes are joined: `import labkit` stays light

    pairs = cKDTree(points).query_pairs(tolerance, output_type="ndarray")
    target = np.arange(len(points))
    if len(pairs):
        # every node points at the smallest index of its cluster
        pairs = np.sort(pairs, axis=1)
        np.minimum.at(target, pairs[:, 1], pairs[:, 0])
        while True:
            settled = target[target]
            if np.array_equal(settled, target):
                break
            target = settled
    keep, new_index = np.unique(target, return_inverse=True)
    return QuadMesh(points[keep], new_index[quads])
