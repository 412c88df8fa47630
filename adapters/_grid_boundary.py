"""The outer boundary of a grid as a triangle surface, for viewers that draw surfaces only.

A grid is shown as the faces of its active cells that no active neighbour covers (the hull of
the cell grid). Cells are active unless ``actnum`` is False (a StructuredGrid) or the cell
property ``active`` is 0 (a clipped RegularGrid), as :func:`active_cells` says. In a corner-point
grid, a face whose neighbour's matching face has other corners (a fault's throw) is shown too:
the fault walls are part of the boundary. A RegularGrid with every cell active and no property
asked for is its parallelepiped: six faces, twelve triangles. Each quadrilateral face becomes two
triangles, counter-clockwise seen from outside (the boundary encloses a positive volume, also for
left-handed grids, whose depth axis points down).

With ``property``, the surface carries the grid's property of that name: a cell property as
``cell_data`` (each triangle its cell's value), a point property (a Voxet's nodes) as
``point_data`` (each vertex its lattice point's value).

>>> from geobrep import RegularGrid
>>> box = RegularGrid(origin=[0, 0, 0], u=[1, 0, 0], v=[0, 1, 0], w=[0, 0, 1], counts=(4, 3, 2))
>>> grid_boundary(box).n_faces, grid_boundary(box, "k").n_faces  # "k": no such property
(12, 104)
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from geobrep.model.entities import RegularGrid, StructuredGrid, Surface
from geobrep.model.entities.grid import lattice
from geobrep.model.entities.structured import HEX_FACES
from geobrep.model.properties import PropertyMap

__all__ = ["ACTIVE", "active_cells", "grid_boundary"]

#: The cell property of a RegularGrid marking its active cells (0: left out), as a clip sets it.
ACTIVE = "active"
# corner number x + 2y + 4z -> its lattice offset (x, y, z)
_OFFSETS = np.array([[c & 1, (c >> 1) & 1, (c >> 2) & 1] for c in range(8)], dtype=np.int64)
# the faces i-, i+, j-, j+, k-, k+ (rows of HEX_FACES): their axis and side
_FACE_AXIS = (0, 0, 1, 1, 2, 2)
_FACE_SIDE = (-1, 1, -1, 1, -1, 1)


def active_cells(grid: RegularGrid | StructuredGrid) -> NDArray[np.bool_] | None:
    """The active cells ``(n_cells,)`` (None: every cell is)."""
    if isinstance(grid, StructuredGrid) and grid.actnum is not None:
        return np.asarray(grid.actnum, dtype=bool)
    if ACTIVE in grid.cell_data and grid.cell_data[ACTIVE].values.ndim == 1:
        return np.asarray(np.asarray(grid.cell_data[ACTIVE].values) != 0, dtype=bool)
    return None


def _neighbour_active(cube: NDArray[np.bool_], axis: int, side: int) -> NDArray[np.bool_]:
    """Whether the neighbour of each cell across its face on ``side`` of grid ``axis`` is active
    (False beyond the grid); ``cube`` is ``(nk, nj, ni)``."""
    along = 2 - axis
    out = np.zeros_like(cube)
    source: list[slice] = [slice(None)] * 3
    target: list[slice] = [slice(None)] * 3
    source[along], target[along] = (slice(1, None), slice(0, -1))[::side]
    out[tuple(target)] = cube[tuple(source)]
    return out


def _exposed_faces(
    grid: RegularGrid | StructuredGrid, corners: NDArray[np.float64] | None
) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
    """The cell ``(m,)`` and face number ``(m,)`` (row of HEX_FACES) of every boundary face;
    ``corners`` ``(n, 8, 3)`` (corner-point grids) also exposes faces whose neighbour's face
    differs."""
    ni, nj, nk = grid.counts
    active = active_cells(grid)
    cube = (np.ones(grid.n_cells, bool) if active is None else active).reshape(nk, nj, ni)
    strides = (1, ni, ni * nj)
    cells: list[NDArray[np.int64]] = []
    faces: list[NDArray[np.int64]] = []
    for face, (axis, side) in enumerate(zip(_FACE_AXIS, _FACE_SIDE, strict=True)):
        beside = _neighbour_active(cube, axis, side)
        exposed = (cube & ~beside).reshape(-1)
        if corners is not None:
            shared = np.flatnonzero((cube & beside).reshape(-1))
            mine = HEX_FACES[face]
            theirs = mine - side * (1 << axis)
            other = shared + side * strides[axis]
            differ = np.any(corners[shared][:, mine] != corners[other][:, theirs], axis=(1, 2))
            exposed[shared[differ]] = True
        found = np.flatnonzero(exposed)
        cells.append(found)
        faces.append(np.full(found.shape[0], face, dtype=np.int64))
    return np.concatenate(cells), np.concatenate(faces)


def _triangles(quads: NDArray[np.int64]) -> NDArray[np.int64]:
    """Two triangles per quadrilateral ``(m, 4)``: ``(a, b, c)`` and ``(a, c, d)``, in turn."""
    return np.stack([quads[:, [0, 1, 2]], quads[:, [0, 2, 3]]], axis=1).reshape(-1, 3)


def _outward(vertices: NDArray[np.float64], triangles: NDArray[np.int64]) -> NDArray[np.int64]:
    """``triangles`` turned so that they enclose a positive volume (divergence theorem)."""
    xyz = vertices - vertices.mean(axis=0)
    a, b, c = (xyz[triangles[:, m]] for m in range(3))
    volume = float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum())
    return triangles if volume >= 0 else np.ascontiguousarray(triangles[:, ::-1])


def _parallelepiped(grid: RegularGrid) -> Surface:
    ni, nj, nk = grid.counts
    corners = lattice(grid.origin, grid.axes * np.array([[ni], [nj], [nk]]), (2, 2, 2))
    faces = _outward(corners, _triangles(HEX_FACES))
    return Surface(vertices=corners, faces=faces, name=grid.name, kind=grid.kind)


def grid_boundary(grid: RegularGrid | StructuredGrid, property: str | None = None) -> Surface:
    """The boundary faces of the active cells of ``grid`` as a Surface (see the module)."""
    if isinstance(grid, RegularGrid) and property is None and active_cells(grid) is None:
        return _parallelepiped(grid)
    corner_point = isinstance(grid, StructuredGrid) and grid.is_corner_point
    corners = grid.cell_corners() if corner_point else None  # type: ignore[union-attr]
    cells, faces = _exposed_faces(grid, corners)
    point_data: dict[str, Any] = {}
    if corners is not None:
        xyz = corners[cells[:, None], HEX_FACES[faces]].reshape(-1, 3)
        vertices, inverse = np.unique(xyz, axis=0, return_inverse=True)
        quads = inverse.reshape(-1, 4).astype(np.int64)
    else:
        ni, nj, _ = grid.counts
        ijk = np.stack([cells % ni, (cells // ni) % nj, cells // (ni * nj)], axis=1)
        at = ijk[:, None, :] + _OFFSETS[HEX_FACES[faces]]  # (m, 4, 3) lattice points
        ids = at[..., 0] + (ni + 1) * (at[..., 1] + (nj + 1) * at[..., 2])
        used, inverse = np.unique(ids, return_inverse=True)
        quads = inverse.reshape(-1, 4).astype(np.int64)
        if isinstance(grid, RegularGrid):
            steps = np.stack([used % (ni + 1), (used // (ni + 1)) % (nj + 1)], axis=1)
            steps = np.column_stack([steps, used // ((ni + 1) * (nj + 1))])
            vertices = grid.origin + steps.astype(np.float64) @ grid.axes
        else:
            assert grid.points is not None
            vertices = np.asarray(grid.points[used], dtype=np.float64)
        if property is not None and property in grid.point_data:
            point_data[property] = grid.point_data[property].take(used)
    cell_data: dict[str, Any] = {}
    if property is not None and property in grid.cell_data:
        cell_data[property] = grid.cell_data[property].take(np.repeat(cells, 2))
    return Surface(
        vertices=vertices,
        faces=_outward(vertices, _triangles(quads)),
        cell_data=PropertyMap(cell_data),
        point_data=PropertyMap(point_data),
        name=grid.name,
        kind=grid.kind,
    )
