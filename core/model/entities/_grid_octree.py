"""Linear octrees as regular grids (one cell per finest octree cell) and back.

A :class:`LinearOctree` becomes the axis-aligned :class:`RegularGrid` of its ``2**depth`` finest
cells per axis, with an int64 cell property: the leaf's label (1 for an unlabelled leaf) where a
leaf is, ``-1`` (the no-data value) elsewhere. The way back takes a labelled axis-aligned grid
of cubic cells, makes each labelled cell a finest leaf and merges every full set of eight
siblings with one label into their parent, level by level (all vectorised on Morton codes).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from geobrep.errors import EntityValidationError
from geobrep.geometry.morton import morton_encode
from geobrep.model.properties import Property

if TYPE_CHECKING:
    from geobrep.model.entities.grid import RegularGrid
    from geobrep.model.entities.octree import LinearOctree

__all__ = ["MAX_GRID_CELLS", "grid_from_octree", "octree_from_grid"]

#: The most finest cells an octree may expand into (int64 labels: 2 GiB).
MAX_GRID_CELLS = 1 << 28
NO_LABEL = -1


def grid_from_octree(octree: LinearOctree, name: str = "label") -> RegularGrid:
    """The finest-level grid of ``octree`` with its labels as the cell property ``name``."""
    from geobrep.model.entities.grid import RegularGrid

    n = 1 << octree.depth
    if n**3 > MAX_GRID_CELLS:
        raise octree.fail("depth", f"{n}³ finest cells are more than a grid of {MAX_GRID_CELLS}")
    labels = np.full(n**3, NO_LABEL, dtype=np.int64)
    cells, edge = octree.leaf_cells()
    values = np.ones(octree.n_leaves, dtype=np.int64) if octree.labels is None else octree.labels
    for size in np.unique(edge):
        chosen = edge == size
        offsets = np.stack(np.meshgrid(*(np.arange(size),) * 3, indexing="ij"), axis=-1).reshape(
            -1, 3
        )
        ijk = (cells[chosen][:, None, :] + offsets[None, :, :]).reshape(-1, 3)
        flat = ijk[:, 0] + n * (ijk[:, 1] + n * ijk[:, 2])
        labels[flat] = np.repeat(values[chosen], offsets.shape[0])
    step = octree.size / n
    return RegularGrid(
        name=octree.name,
        origin=octree.origin,
        u=[step, 0, 0],
        v=[0, step, 0],
        w=[0, 0, step],
        counts=(n, n, n),
        cell_data={name: Property(values=labels, no_data_value=NO_LABEL)},
    )


def _voxels(
    grid: RegularGrid, name: str
) -> tuple[NDArray[np.float64], tuple[int, int, int], NDArray[Any]]:
    """The voxel lattice's origin and counts and its labels: cell data as they are, point data
    (a Voxet's nodes) as voxels centred on the nodes."""
    if name in grid.cell_data:
        return grid.origin, grid.counts, np.asarray(grid.cell_data[name].values)
    if name in grid.point_data:
        origin = grid.origin - 0.5 * (grid.u + grid.v + grid.w)
        return origin, grid.point_counts, np.asarray(grid.point_data[name].values)
    raise grid.fail("cell_data", f"no property {name!r} to make octree leaves of")


def octree_from_grid(grid: RegularGrid, name: str = "label") -> LinearOctree:
    """The octree of the labelled cells of an axis-aligned grid of cubic cells."""
    from geobrep.model.entities.octree import MAX_OCTREE_DEPTH, LinearOctree

    step = float(grid.u[0])
    if not np.array_equal(grid.axes, np.diag([step] * 3)) or step <= 0:
        raise grid.fail("u", "an octree needs axis-aligned cubic cells (u, v, w = s·x, s·y, s·z)")
    origin, counts, raw = _voxels(grid, name)
    prop = grid.cell_data.get(name) or grid.point_data[name]
    if raw.dtype.kind not in "iub" and not np.all(np.isnan(raw) | (raw == np.round(raw))):
        raise grid.fail(name, "octree labels must be integers")
    values = np.nan_to_num(raw.astype(np.float64), nan=NO_LABEL).astype(np.int64)
    empty = values == NO_LABEL
    if prop.no_data_value is not None:
        empty |= np.asarray(raw == prop.no_data_value, dtype=bool)
    depth = int(np.ceil(np.log2(max(counts)))) if max(counts) > 1 else 0
    if depth > MAX_OCTREE_DEPTH:
        raise EntityValidationError(grid.label, "counts", f"{counts} needs octree depth {depth}")
    flat = np.flatnonzero(~empty)
    ni, nj, _ = counts
    i, j, k = flat % ni, (flat // ni) % nj, flat // (ni * nj)
    codes = morton_encode(i, j, k)
    order = np.argsort(codes)
    codes, labels = codes[order], values[flat][order]
    levels = np.full(codes.shape[0], depth, dtype=np.uint8)
    codes, levels, labels = _merge(codes, levels, labels, depth)
    return LinearOctree(
        name=grid.name,
        codes=codes,
        levels=levels,
        depth=depth,
        origin=origin,
        size=step * (1 << depth),
        labels=labels,
    )


def _merge(
    codes: NDArray[np.uint64], levels: NDArray[np.uint8], labels: NDArray[np.int64], depth: int
) -> tuple[NDArray[np.uint64], NDArray[np.uint8], NDArray[np.int64]]:
    """Merge each full set of eight same-label sibling leaves into its parent, bottom up."""
    for level in range(depth, 0, -1):
        span = np.uint64(8 ** (depth - level + 1))
        at = np.flatnonzero(levels == level)
        if at.size < 8:
            continue
        parent = codes[at] // span
        # a full family is 8 consecutive leaves of this level with one parent and one label
        start = at[:-7]
        full = (parent[:-7] == parent[7:]) & (at[7:] - at[:-7] == 7) & (codes[start] % span == 0)
        same = np.ones(start.shape[0], dtype=bool)
        for m in range(1, 8):
            same &= labels[at[m : m + start.shape[0]]] == labels[start]
        heads = start[full & same]
        if heads.size == 0:
            continue
        drop = np.zeros(codes.shape[0], dtype=bool)
        drop[(heads[:, None] + np.arange(1, 8)).ravel()] = True
        levels = levels.copy()
        levels[heads] = level - 1
        keep = ~drop
        codes, levels, labels = codes[keep], levels[keep], labels[keep]
    return codes, levels, labels
