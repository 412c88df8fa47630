"""Rectilinear block grids (OMF volumes, geoh5 block models): cell sizes along each axis.

A grid whose cells along each axis have one size is a :class:`~geobrep.model.entities.RegularGrid`;
one with varying sizes, which RegularGrid cannot hold, reads as a
:class:`~geobrep.model.entities.PointSet` whose points are the cell centres, with the cell values
as point properties and the grid itself (origin, axes, cell sizes along each axis) in
``metadata["grid"]``. Cells are ordered u fastest, then v, then w. Writers take either and
write the grid back.

>>> import numpy as np
>>> grid = Grid(origin=(0.0, 0.0, 0.0), sizes=(np.ones(2), np.ones(1), np.full(1, 2.0)))
>>> grid.centres().tolist()
[[0.5, 0.5, 1.0], [1.5, 0.5, 1.0]]
>>> Grid.of(grid.point_set("g")) == grid
True
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from geobrep.model.entities import Entity, PointSet, RegularGrid
from geobrep.model.properties import PropertyMap

__all__ = ["GRID_KEY", "Grid", "as_grid", "cell_values", "grid_entity", "triple"]

GRID_KEY = "grid"
"""The metadata key of a point set that stands for a grid."""

_AXES = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))


def triple(values: Any) -> tuple[float, float, float]:
    """Three floats from a sequence of three numbers (ValueError otherwise)."""
    x, y, z = (float(v) for v in values)
    return (x, y, z)


@dataclass(frozen=True, eq=False)
class Grid:
    """A rectilinear grid: an origin (the corner of cell 0), three axes and cell sizes."""

    origin: tuple[float, float, float]
    sizes: tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]
    axes: tuple[tuple[float, float, float], ...] = field(default=_AXES)

    @property
    def shape(self) -> tuple[int, int, int]:
        """Cells along u, v and w."""
        return (len(self.sizes[0]), len(self.sizes[1]), len(self.sizes[2]))

    @property
    def n_cells(self) -> int:
        return int(np.prod(self.shape))

    def __eq__(self, other: object) -> bool:
        return (
            isinstance(other, Grid)
            and self.origin == other.origin
            and self.axes == other.axes
            and all(np.array_equal(a, b) for a, b in zip(self.sizes, other.sizes, strict=True))
        )

    def centres(self) -> NDArray[np.float64]:
        """Cell centres, u fastest."""
        mids = [np.cumsum(s) - s / 2 for s in self.sizes]
        w, v, u = np.meshgrid(mids[2], mids[1], mids[0], indexing="ij")
        local = np.stack([u.ravel(), v.ravel(), w.ravel()], axis=1)
        return np.asarray(self.origin) + local @ np.asarray(self.axes, dtype=np.float64)

    def record(self) -> dict[str, Any]:
        return {
            "origin": list(self.origin),
            "axes": [list(a) for a in self.axes],
            "sizes": [s.tolist() for s in self.sizes],
        }

    def point_set(self, name: str, **fields: Any) -> PointSet:
        """The point set of the cell centres standing for this grid."""
        metadata = {**fields.pop("metadata", {}), GRID_KEY: self.record()}
        return PointSet(vertices=self.centres(), name=name, metadata=metadata, **fields)

    @classmethod
    def of(cls, entity: Any) -> Grid | None:
        """The grid a point set stands for (None: an ordinary point set)."""
        record = getattr(entity, "metadata", {}).get(GRID_KEY)
        if not isinstance(record, dict):
            return None
        try:
            u, v, w = (np.asarray(s, dtype=np.float64) for s in record["sizes"])
            grid = cls(
                origin=triple(record["origin"]),
                sizes=(u, v, w),
                axes=tuple(triple(a) for a in record["axes"]),
            )
        except (KeyError, TypeError, ValueError):
            return None
        return grid if grid.n_cells == entity.n_points and len(grid.axes) == 3 else None


def as_grid(entity: Any) -> Grid | None:
    """The grid of a :class:`~geobrep.model.entities.RegularGrid` (axes as unit vectors, exact
    for axis-aligned grids) or of a point set standing for one; None for anything else."""
    if entity.type == "RegularGrid":
        axes = np.asarray(entity.axes, dtype=np.float64)
        steps = np.sqrt((axes * axes).sum(axis=1))  # sqrt(x * x) == |x|: exact when aligned
        u, v, w = (np.full(n, s) for n, s in zip(entity.counts, steps, strict=True))
        unit = tuple(triple(a / s) for a, s in zip(axes, steps, strict=True))
        return Grid(origin=triple(entity.origin), sizes=(u, v, w), axes=unit)
    return Grid.of(entity)


def cell_values(entity: Any) -> PropertyMap:
    """The cell properties of a grid entity (a stand-in point set holds them per point)."""
    found: PropertyMap = entity.cell_data if entity.type == "RegularGrid" else entity.point_data
    return found


def grid_entity(
    grid: Grid, name: str, cells: PropertyMap, metadata: dict[str, Any], **fields: Any
) -> Entity:
    """A :class:`RegularGrid` when the cells along each axis have one size, else the point
    set of the cell centres standing for ``grid``; ``fields`` are more entity fields (id)."""
    if all(len(s) and bool(np.all(s == s[0])) for s in grid.sizes):
        u, v, w = (np.asarray(a) * s[0] for a, s in zip(grid.axes, grid.sizes, strict=True))
        return RegularGrid(
            origin=grid.origin,
            u=u,
            v=v,
            w=w,
            counts=grid.shape,
            cell_data=cells,
            name=name,
            metadata=metadata,
            **fields,
        )
    return grid.point_set(name, point_data=cells, metadata=metadata, **fields)
