"""The RegularGrid and StructuredGrid clippers: cells are kept whole, and a section is a surface.

A grid cell is never cut: a clipped grid is made of whole cells of the input, so its cell
properties, active flags and ``(i, j, k)`` structure stay exact. Which cells a side keeps is the
option ``cells``: ``"centre"`` (the default) keeps a cell whose centre (the mean of its eight
corners) is on the kept side, a centre on the plane (within the tolerance) counting as positive, so
``keep="both"`` partitions the cells; ``"inside"`` keeps only cells with no corner beyond the plane
(the kept cells lie within the half-space); ``"touching"`` keeps every cell with a corner strictly
on the kept side (the kept cells cover the half-space's part of the grid). Inactive cells of a
StructuredGrid are never kept.

The result is the smallest sub-grid (index box) holding the kept cells. When the plane is oblique
to the grid, that box also holds cells of the other side: a StructuredGrid marks them inactive in
``actnum``; a RegularGrid, which has no active flags, gets the ``uint8`` cell property ``active``
(1 kept, 0 not; an existing ``active`` property is combined with it). Cell and point data follow
the cells and points of the box.

The section of a grid is a triangulated :class:`~geobrep.Surface` on the plane: each cell the
plane crosses is split into the six tetrahedra of its 0-7 diagonal (the decomposition its volume
is computed with), whose plane sections are one or two triangles; crossing points on an edge
shared by neighbouring cells are one vertex. Each triangle carries the properties of its cell as
cell data, with the flat index of the cell as the int64 cell property ``grid_cell``; point data
is interpolated along the edges. Triangles face the plane's normal.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from geobrep import Property, RegularGrid, StructuredGrid, Surface
from geobrep.geometry import Plane
from geobrep.geometry.arrays import BoolArray, FloatArray, IntArray
from geobrep.plugins import ClipContext, Keep, PropertyMap, halves, pack_halves
from geobrep.plugins.clip._sides import interpolate_properties
from geobrep.plugins.clip.options import GridClipOptions, tolerance_of

__all__ = [
    "ACTIVE",
    "GRID_CELL",
    "clip_regular_grid",
    "clip_structured_grid",
    "section_cells",
    "section_regular_grid",
    "section_structured_grid",
]

#: The cell property marking the kept cells of a clipped RegularGrid's box.
ACTIVE = "active"
#: The cell property of a grid section giving each triangle's cell (flat index).
GRID_CELL = "grid_cell"

# The six tetrahedra of a hexahedron through its 0-7 diagonal (corner numbers x + 2y + 4z).
_HEX_TETS = np.array(
    [[0, 1, 3, 7], [0, 3, 2, 7], [0, 2, 6, 7], [0, 6, 4, 7], [0, 4, 5, 7], [0, 5, 1, 7]],
    dtype=np.int64,
)
_CORNERS = np.array([[x, y, z] for z in (0, 1) for y in (0, 1) for x in (0, 1)], dtype=np.int64)


# ------------------------------------------------------------------------------- which cells
@dataclass(frozen=True)
class _CellSides:
    """Signed distance of each cell's centre and the range of its corners' distances."""

    centre: FloatArray
    low: FloatArray
    high: FloatArray

    def kept(self, side: int, rule: str, tolerance: float) -> BoolArray:
        if rule == "centre":
            on_negative = self.centre < -tolerance
            return np.asarray(on_negative if side < 0 else ~on_negative)
        if rule == "inside":
            return np.asarray(self.high <= tolerance if side < 0 else self.low >= -tolerance)
        return np.asarray(self.low < -tolerance if side < 0 else self.high > tolerance)


def _regular_sides(grid: RegularGrid, plane: Plane) -> _CellSides:
    """Cell distances of a lattice from its affine form: no corner array is built."""
    normal = plane.normal
    steps = grid.axes @ normal  # distance gained per cell along u, v, w
    ni, nj, nk = grid.counts
    base = float(plane.signed_distance(grid.origin.reshape(1, 3))[0])
    along = [
        (np.arange(n, dtype=np.float64) + 0.5) * s for n, s in zip((ni, nj, nk), steps, strict=True)
    ]
    centre = base + along[2][:, None, None] + along[1][None, :, None] + along[0][None, None, :]
    centre = centre.reshape(-1)
    half = 0.5 * float(np.abs(steps).sum())
    return _CellSides(centre, centre - half, centre + half)


def _corner_sides(corner_distances: FloatArray) -> _CellSides:
    return _CellSides(
        corner_distances.mean(axis=1), corner_distances.min(axis=1), corner_distances.max(axis=1)
    )


def _box(kept: BoolArray, counts: tuple[int, int, int]) -> tuple[slice, slice, slice] | None:
    """The index box ``(k, j, i)`` slices of the kept cells, None if none."""
    ni, nj, nk = counts
    cube = kept.reshape(nk, nj, ni)
    ranges = []
    for axes in ((1, 2), (0, 2), (0, 1)):
        hit = np.flatnonzero(cube.any(axis=axes))
        if hit.shape[0] == 0:
            return None
        ranges.append(slice(int(hit[0]), int(hit[-1]) + 1))
    return ranges[0], ranges[1], ranges[2]


def _box_indices(box: tuple[slice, slice, slice], shape: tuple[int, int, int]) -> IntArray:
    """Flat indices (i fastest) of the elements of ``box`` in a ``(nk, nj, ni)`` array."""
    flat = np.arange(shape[0] * shape[1] * shape[2], dtype=np.int64).reshape(shape)
    return np.asarray(flat[box].reshape(-1), dtype=np.int64)


def _point_box(box: tuple[slice, slice, slice]) -> tuple[slice, slice, slice]:
    return tuple(slice(s.start, s.stop + 1) for s in box)  # type: ignore[return-value]


def _box_counts(box: tuple[slice, slice, slice]) -> tuple[int, int, int]:
    k, j, i = (s.stop - s.start for s in box)
    return i, j, k


# ------------------------------------------------------------------------------- RegularGrid
def clip_regular_grid(
    grid: RegularGrid, plane: Plane, keep: Keep, options: GridClipOptions, context: ClipContext
) -> Any:
    """Clipper of :class:`RegularGrid` entities (see the module docstring)."""
    sides = _regular_sides(grid, plane)
    tolerance = tolerance_of(options, context)
    parts: dict[int, RegularGrid | None] = {}
    for side in halves(keep):
        parts[side] = _regular_part(grid, sides.kept(side, options.cells, tolerance))
    return pack_halves(keep, parts)


def _regular_part(grid: RegularGrid, kept: BoolArray) -> RegularGrid | None:
    if kept.all():
        return grid
    box = _box(kept, grid.counts)
    if box is None:
        return None
    ni, nj, nk = grid.counts
    cells = _box_indices(box, (nk, nj, ni))
    pi, pj, pk = grid.point_counts
    points = _box_indices(_point_box(box), (pk, pj, pi))
    cell_data = dict(grid.cell_data.take(cells))
    inside = kept[cells]
    if not inside.all():
        active = inside.astype(np.uint8)
        if ACTIVE in cell_data:
            active &= (np.asarray(cell_data[ACTIVE].values) != 0).astype(np.uint8)
        cell_data[ACTIVE] = Property(values=active, description="1: a cell the clip kept")
    k, j, i = (s.start for s in box)
    origin = grid.origin + i * grid.u + j * grid.v + k * grid.w
    return grid.replace(
        origin=origin,
        counts=_box_counts(box),
        cell_data=PropertyMap(cell_data),
        point_data=grid.point_data.take(points),
    )


def section_regular_grid(
    grid: RegularGrid, plane: Plane, options: GridClipOptions, context: ClipContext
) -> Surface | None:
    """The section of a RegularGrid: triangles on the plane carrying the cell data."""
    tolerance = tolerance_of(options, context)
    sides = _regular_sides(grid, plane)
    crossed = np.flatnonzero((sides.low <= tolerance) & (sides.high >= -tolerance))
    ni, nj, _ = grid.counts
    i = crossed % ni
    j = (crossed // ni) % nj
    k = crossed // (ni * nj)
    cell_ijk = np.stack([i, j, k], axis=1)
    corner_ijk = cell_ijk[:, None, :] + _CORNERS[None]  # (m, 8, 3)
    pi, pj, _ = grid.point_counts
    ids = corner_ijk[..., 0] + pi * (corner_ijk[..., 1] + pj * corner_ijk[..., 2])
    xyz = grid.origin + corner_ijk.astype(np.float64) @ grid.axes
    return _section_surface(grid, plane, crossed, ids, xyz, tolerance)


# ------------------------------------------------------------------------------- StructuredGrid
def _structured_corners(grid: StructuredGrid) -> tuple[FloatArray, IntArray]:
    """Each cell's corners ``(n, 8, 3)`` and corner ids ``(n, 8)`` shared between cells."""
    xyz = grid.cell_corners()
    if grid.points is not None:
        ni, nj, _ = grid.counts
        i = np.arange(grid.n_cells, dtype=np.int64) % ni
        j = (np.arange(grid.n_cells, dtype=np.int64) // ni) % nj
        k = np.arange(grid.n_cells, dtype=np.int64) // (ni * nj)
        ijk = np.stack([i, j, k], axis=1)[:, None, :] + _CORNERS[None]
        ids = ijk[..., 0] + (ni + 1) * (ijk[..., 1] + (nj + 1) * ijk[..., 2])
        return xyz, np.asarray(ids, dtype=np.int64)
    _, inverse = np.unique(xyz.reshape(-1, 3), axis=0, return_inverse=True)
    return xyz, np.asarray(inverse.reshape(-1, 8), dtype=np.int64)


def _active(grid: StructuredGrid) -> BoolArray:
    if grid.actnum is None:
        return np.ones(grid.n_cells, dtype=bool)
    return np.asarray(grid.actnum, dtype=bool)


def clip_structured_grid(
    grid: StructuredGrid, plane: Plane, keep: Keep, options: GridClipOptions, context: ClipContext
) -> Any:
    """Clipper of :class:`StructuredGrid` entities (see the module docstring)."""
    corners = grid.cell_corners()
    distances = plane.signed_distance(corners.reshape(-1, 3)).reshape(-1, 8)
    sides = _corner_sides(distances)
    tolerance = tolerance_of(options, context)
    active = _active(grid)
    parts: dict[int, StructuredGrid | None] = {}
    for side in halves(keep):
        parts[side] = _structured_part(grid, sides.kept(side, options.cells, tolerance) & active)
    return pack_halves(keep, parts)


def _structured_part(grid: StructuredGrid, kept: BoolArray) -> StructuredGrid | None:
    active = _active(grid)
    if np.array_equal(kept, active):
        return grid
    box = _box(kept, grid.counts)
    if box is None:
        return None
    ni, nj, nk = grid.counts
    cells = _box_indices(box, (nk, nj, ni))
    inside = kept[cells]
    update: dict[str, Any] = {
        "counts": _box_counts(box),
        "cell_data": grid.cell_data.take(cells),
        "actnum": None if inside.all() else inside,
    }
    k, j, i = box
    if grid.points is not None:
        points = _box_indices(_point_box(box), (nk + 1, nj + 1, ni + 1))
        update["points"] = grid.points[points]
        update["point_data"] = grid.point_data.take(points)
    else:
        assert grid.coord is not None
        assert grid.zcorn is not None
        pillars = grid.coord.reshape(nj + 1, ni + 1, 6)[_point_box(box)[1:]]
        update["coord"] = pillars.reshape(-1, 6)
        zcorn = grid.zcorn.reshape(nk, 2, nj, 2, ni, 2)[k, :, j, :, i, :]
        update["zcorn"] = np.ascontiguousarray(zcorn).reshape(-1)
    return grid.replace(**update)


def section_structured_grid(
    grid: StructuredGrid, plane: Plane, options: GridClipOptions, context: ClipContext
) -> Surface | None:
    """The section of a StructuredGrid's active cells: triangles carrying the cell data."""
    tolerance = tolerance_of(options, context)
    xyz, ids = _structured_corners(grid)
    distances = plane.signed_distance(xyz.reshape(-1, 3)).reshape(-1, 8)
    sides = _corner_sides(distances)
    crossed = np.flatnonzero((sides.low <= tolerance) & (sides.high >= -tolerance) & _active(grid))
    return _section_surface(grid, plane, crossed, ids[crossed], xyz[crossed], tolerance)


# ------------------------------------------------------------------------------- sections
def _section_surface(
    grid: RegularGrid | StructuredGrid,
    plane: Plane,
    cells: IntArray,
    ids: IntArray,
    xyz: FloatArray,
    tolerance: float,
) -> Surface | None:
    vertices, faces, face_cell, lo, hi, t = section_cells(plane, cells, ids, xyz, tolerance)
    if faces.shape[0] == 0:
        return None
    cell_data = dict(grid.cell_data.take(face_cell))
    cell_data[GRID_CELL] = Property(values=face_cell, description="the grid cell cut")
    point_data = interpolate_properties(grid.point_data, np.zeros(0, np.int64), lo, hi, t)
    return Surface(
        vertices=vertices,
        faces=faces,
        cell_data=PropertyMap(cell_data),
        point_data=point_data,
        name=grid.name,
        kind=grid.kind,
        metadata={**grid.metadata, "grid": grid.id},
    )


def section_cells(
    plane: Plane, cells: IntArray, ids: IntArray, xyz: FloatArray, tolerance: float
) -> tuple[FloatArray, IntArray, IntArray, IntArray, IntArray, FloatArray]:
    """Triangles where ``plane`` cuts hexahedra (each as six tetrahedra).

    ``cells`` ``(m,)`` names the hexahedra, ``ids`` ``(m, 8)`` their corners' shared ids and
    ``xyz`` ``(m, 8, 3)`` the corners (numbered ``x + 2y + 4z``). Returns the vertices, the
    triangles (facing the plane's normal), each triangle's cell, and each vertex's corner ids
    ``lo``, ``hi`` and parameter ``t`` (vertex = ``lo + t (hi − lo)``; ``lo == hi`` for a corner
    on the plane).
    """
    tet_ids = ids[:, _HEX_TETS].reshape(-1, 4)
    tet_xyz = xyz[:, _HEX_TETS].reshape(-1, 4, 3)
    tet_cell = np.repeat(cells, _HEX_TETS.shape[0])
    distances = plane.signed_distance(tet_xyz.reshape(-1, 3)).reshape(-1, 4)
    distances = np.where(np.abs(distances) <= tolerance, 0.0, distances)
    positive = distances >= 0
    count = positive.sum(axis=1)
    triangles: list[IntArray] = []  # (t, 3, 2): the (negative, positive) corner of each vertex
    owners: list[IntArray] = []
    for n_positive in (1, 2, 3):
        chosen = np.flatnonzero(count == n_positive)
        if chosen.shape[0] == 0:
            continue
        order = np.argsort(positive[chosen], axis=1, kind="stable")  # negatives first
        neg, pos = order[:, : 4 - n_positive], order[:, 4 - n_positive :]
        if n_positive == 1:
            edges = [np.stack([neg[:, m], pos[:, 0]], axis=1) for m in range(3)]
            tris = [np.stack(edges, axis=1)]
        elif n_positive == 3:
            edges = [np.stack([neg[:, 0], pos[:, m]], axis=1) for m in range(3)]
            tris = [np.stack(edges, axis=1)]
        else:
            quad = [(0, 0), (0, 1), (1, 1), (1, 0)]
            edges = [np.stack([neg[:, a], pos[:, b]], axis=1) for a, b in quad]
            tris = [np.stack(edges[:3], axis=1), np.stack([edges[0], edges[2], edges[3]], axis=1)]
        for tri in tris:
            triangles.append(tri + 4 * chosen[:, None, None])
            owners.append(chosen)
    if not triangles:
        empty = np.zeros(0, np.int64)
        return np.zeros((0, 3)), np.zeros((0, 3), np.int64), empty, empty, empty, np.zeros(0)
    corners = np.concatenate(triangles).reshape(-1, 2)  # flat (tet, corner) numbers
    tet_of_face = np.concatenate(owners)
    return _weld(corners, tet_ids.reshape(-1), tet_xyz.reshape(-1, 3), distances.reshape(-1),
                 tet_cell[tet_of_face], plane)  # fmt: skip


def _weld(
    corners: IntArray,
    corner_ids: IntArray,
    corner_xyz: FloatArray,
    corner_d: FloatArray,
    face_cell: IntArray,
    plane: Plane,
) -> tuple[FloatArray, IntArray, IntArray, IntArray, IntArray, FloatArray]:
    """One vertex per crossed edge (or corner on the plane); degenerate triangles dropped."""
    a, b = corners[:, 0], corners[:, 1]
    on_plane = corner_d[b] == 0.0
    ida, idb = corner_ids[a], corner_ids[b]
    lo = np.where(on_plane, idb, np.minimum(ida, idb))
    hi = np.where(on_plane, idb, np.maximum(ida, idb))
    keys = np.stack([lo, hi], axis=1)
    unique, first, inverse = np.unique(keys, axis=0, return_index=True, return_inverse=True)
    # compute each vertex from its edge taken low id first: the same edge, the same point
    fa, fb = a[first], b[first]
    swap = corner_ids[fa] > corner_ids[fb]
    start, end = np.where(swap, fb, fa), np.where(swap, fa, fb)
    d0, d1 = corner_d[start], corner_d[end]
    flat = unique[:, 0] == unique[:, 1]
    t = np.where(flat, 0.0, d0 / np.where(flat, 1.0, d0 - d1))
    t = np.where(flat & (corner_ids[start] != unique[:, 0]), 1.0, t)
    vertices = corner_xyz[start] + t[:, None] * (corner_xyz[end] - corner_xyz[start])
    faces = inverse.reshape(-1, 3).astype(np.int64)
    good = (
        (faces[:, 0] != faces[:, 1]) & (faces[:, 1] != faces[:, 2]) & (faces[:, 0] != faces[:, 2])
    )
    normals = np.cross(
        vertices[faces[:, 1]] - vertices[faces[:, 0]], vertices[faces[:, 2]] - vertices[faces[:, 0]]
    )
    facing = normals @ plane.normal
    good &= facing != 0.0
    faces = np.where((facing < 0)[:, None], faces[:, ::-1], faces)[good]
    face_cell = face_cell[good]
    used, remap = np.unique(faces, return_inverse=True)
    return (
        vertices[used],
        remap.reshape(-1, 3).astype(np.int64),
        np.asarray(face_cell, dtype=np.int64),
        np.asarray(unique[used, 0], dtype=np.int64),
        np.asarray(unique[used, 1], dtype=np.int64),
        np.asarray(t[used], dtype=np.float64),
    )
