"""Conversions of a :class:`~geobrep.LinearOctree` to VTK (pyvista) and open3d objects.

pyvista (extra ``viz``) and open3d (extra ``open3d``) are imported here, on first use only.
Coordinates stay float64: VTK points and open3d voxel origins are double precision.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Literal, cast

import numpy as np
from numpy.typing import NDArray

from geobrep.errors import MissingDependencyError, OptionsError

if TYPE_CHECKING:
    import open3d
    import pyvista

    from geobrep.model.entities.octree import LinearOctree

__all__ = ["octree_to_open3d", "octree_to_open3d_octree", "octree_to_pyvista"]

#: Largest image-data grid built by ``to_pyvista("image")`` (cells).
MAX_IMAGE_CELLS = 1 << 27

# VTK hexahedron corner order, as (x, y, z) offsets of the unit cube.
_HEX_CORNERS = np.array(
    [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]],
    dtype=np.float64,
)


def _pyvista() -> Any:
    try:
        import pyvista
    except ImportError as exc:
        raise MissingDependencyError("pyvista", "viz", "Converting an octree to VTK") from exc
    return pyvista


def _open3d() -> Any:
    try:
        import open3d
    except ImportError as exc:  # also OSError-like failures surface as ImportError (libusb)
        raise MissingDependencyError("open3d", "open3d", "Converting an octree to open3d") from exc
    return open3d


def octree_to_pyvista(
    tree: LinearOctree, kind: Literal["hexahedra", "image"] = "hexahedra"
) -> pyvista.UnstructuredGrid | pyvista.ImageData:
    """See :meth:`LinearOctree.to_pyvista`."""
    pv = _pyvista()
    if kind == "hexahedra":
        mins, maxs = tree.leaf_bounds()
        extent = maxs - mins
        points = (mins[:, None, :] + _HEX_CORNERS[None, :, :] * extent[:, None, :]).reshape(-1, 3)
        n = tree.n_leaves
        connectivity = np.hstack(
            [np.full((n, 1), 8, dtype=np.int64), np.arange(8 * n, dtype=np.int64).reshape(n, 8)]
        ).ravel()
        cell_types = np.full(n, pv.CellType.HEXAHEDRON, dtype=np.uint8)
        grid = pv.UnstructuredGrid(connectivity, cell_types, points)
        grid.cell_data["level"] = tree.levels
        if tree.labels is not None:
            grid.cell_data["label"] = tree.labels
        for name, prop in tree.cell_data.items():
            grid.cell_data[name] = np.asarray(prop.values)
        return cast("pyvista.UnstructuredGrid", grid)
    if kind == "image":
        resolution = 1 << tree.depth
        if resolution**3 > MAX_IMAGE_CELLS:
            raise OptionsError(
                f"{tree.label}: image data of depth {tree.depth} would hold {resolution**3:,} "
                f"cells (limit {MAX_IMAGE_CELLS:,}); use kind='hexahedra'"
            )
        dense = dense_labels(tree)
        image = pv.ImageData(
            dimensions=(resolution + 1,) * 3,
            spacing=(tree.size / resolution,) * 3,
            origin=tuple(float(v) for v in tree.origin),
        )
        image.cell_data["label"] = dense.ravel(order="F")  # VTK: x varies fastest
        return cast("pyvista.ImageData", image)
    raise OptionsError(f"kind must be 'hexahedra' or 'image', got {kind!r}")


def dense_labels(tree: LinearOctree, level: int | None = None) -> NDArray[np.int64]:
    """The octree as a dense ``(r, r, r)`` array indexed ``[i, j, k]`` at ``level``.

    Cells hold the leaf's label (``1`` without labels), ``-1`` where there is no leaf. A leaf
    finer than ``level`` marks its whole cell.
    """
    level = tree.depth if level is None else level
    resolution = 1 << level
    dense = np.full((resolution,) * 3, -1, dtype=np.int64)
    cells, edges = tree.leaf_cells()
    shift = tree.depth - level
    values = (
        np.ones(tree.n_leaves, dtype=np.int64)
        if tree.labels is None
        else tree.labels.astype(np.int64)
    )
    # Leaves at or finer than `level` are one cell each; coarser leaves are blocks of cells,
    # written through a view that splits each axis into (block, cell in block): no index arrays.
    coarse_edge = np.maximum(edges >> shift, 1)
    start = cells >> shift
    for size in np.unique(coarse_edge):
        e = int(size)
        chosen = np.flatnonzero(coarse_edge == size)
        blocks = start[chosen] // e
        view = dense.reshape(resolution // e, e, resolution // e, e, resolution // e, e)
        view[blocks[:, 0], :, blocks[:, 1], :, blocks[:, 2], :] = values[chosen, None, None, None]
    return dense


def octree_to_open3d(tree: LinearOctree, level: int | None = None) -> open3d.geometry.VoxelGrid:
    """See :meth:`LinearOctree.to_open3d`."""
    o3d = _open3d()
    level = tree.depth if level is None else int(level)
    if not 0 <= level <= tree.depth:
        raise OptionsError(f"level must be between 0 and the depth {tree.depth}, got {level}")
    if 8**level > MAX_IMAGE_CELLS:
        raise OptionsError(f"{tree.label}: level {level} is too fine for a voxel grid")
    dense = dense_labels(tree, level)
    occupied = np.argwhere(dense >= 0)
    voxel = tree.size / (1 << level)
    centres = tree.origin + (occupied + 0.5) * voxel
    cloud = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(centres))
    labels = dense[occupied[:, 0], occupied[:, 1], occupied[:, 2]]
    if labels.size:
        span = max(int(labels.max() - labels.min()), 1)
        shade = (labels - labels.min()) / span
        cloud.colors = o3d.utility.Vector3dVector(np.stack([shade, 1 - shade, 0.5 + 0 * shade], 1))
    grid = o3d.geometry.VoxelGrid.create_from_point_cloud_within_bounds(
        cloud, voxel, tree.origin, tree.origin + tree.size
    )
    return cast("open3d.geometry.VoxelGrid", grid)


def octree_to_open3d_octree(tree: LinearOctree, level: int | None = None) -> open3d.geometry.Octree:
    """See :meth:`LinearOctree.to_open3d_octree`."""
    o3d = _open3d()
    grid = octree_to_open3d(tree, level)
    octree = o3d.geometry.Octree(max_depth=tree.depth if level is None else int(level))
    octree.create_from_voxel_grid(grid)
    return cast("open3d.geometry.Octree", octree)
