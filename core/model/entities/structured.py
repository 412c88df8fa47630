"""Structured grids: GOCAD SGrids (curvilinear points) and Eclipse corner-point grids.

A structured grid has ``counts = (ni, nj, nk)`` hexahedral cells, ordered i fastest. Its geometry
is given one of two ways:

* ``points`` ``((ni+1)(nj+1)(nk+1), 3)``: the shared corners of a curvilinear grid, i fastest
  (a GOCAD SGrid); ``point_data`` has one value per point;
* ``coord`` ``((ni+1)(nj+1), 6)`` and ``zcorn`` ``(8·ni·nj·nk,)``: the pillars (top and bottom
  points ``x1 y1 z1 x2 y2 z2``) and each cell's own eight corner depths along them, in Eclipse
  order (k, then top/bottom, then j, then near/far, then i, then left/right): a corner-point
  grid, whose neighbouring cells need not share corners (fault throws); it has no point data.

``actnum`` marks the active cells (all are active without it).
"""

from __future__ import annotations

from functools import cached_property
from typing import TYPE_CHECKING, Literal, TypeAlias

import numpy as np
from numpy.typing import NDArray
from pydantic import Field

from geobrep.geometry.bbox import BoundingBox
from geobrep.model.arrays import BoolArray, FloatArray, Points, array_field
from geobrep.model.entities.base import Entity

__all__ = ["HEX_FACES", "StructuredGrid"]

if TYPE_CHECKING:
    Pillars: TypeAlias = NDArray[np.float64]
else:
    Pillars = array_field("float64", (None, 6), finite=True)

#: The six quadrilateral faces of a cell, as corner numbers ``x + 2y + 4z`` (i-, i+, j-, j+,
#: k-, k+), each listed counter-clockwise seen from outside when ``u × v · w > 0``.
HEX_FACES = np.array(
    [[0, 4, 6, 2], [1, 3, 7, 5], [0, 1, 5, 4], [2, 6, 7, 3], [0, 2, 3, 1], [4, 5, 7, 6]],
    dtype=np.int64,
)

# Tetrahedra covering a hexahedron (corner numbers x + 2y + 4z), for volumes.
_HEX_TETS = np.array(
    [[0, 1, 3, 7], [0, 3, 2, 7], [0, 2, 6, 7], [0, 6, 4, 7], [0, 4, 5, 7], [0, 5, 1, 7]],
    dtype=np.int64,
)


class StructuredGrid(Entity):
    """Hexahedral cells ``(ni, nj, nk)``: curvilinear ``points`` or pillars ``coord`` + ``zcorn``.

    >>> import numpy as np
    >>> coord = [[x, y, 0, x, y, 10] for y in (0, 1) for x in (0, 1)]
    >>> grid = StructuredGrid(counts=(1, 1, 1), coord=coord, zcorn=[0] * 4 + [2] * 4)
    >>> grid.n_cells, round(grid.volume, 12)
    (1, 2.0)
    """

    type: Literal["StructuredGrid"] = "StructuredGrid"
    cell_noun = "cells"
    counts: tuple[int, int, int] = Field(description="cells along i, j and k (each ≥ 1)")
    points: Points | None = None
    coord: Pillars | None = None
    zcorn: FloatArray | None = None
    actnum: BoolArray | None = None

    @property
    def is_corner_point(self) -> bool:
        """True when the geometry is pillars + ZCORN."""
        return self.coord is not None

    @property
    def n_cells(self) -> int:
        ni, nj, nk = self.counts
        return ni * nj * nk

    @property
    def n_points(self) -> int:
        return 0 if self.points is None else int(self.points.shape[0])

    @property
    def n_active(self) -> int:
        return self.n_cells if self.actnum is None else int(self.actnum.sum())

    def cell_corners(self) -> NDArray[np.float64]:
        """The eight corners of every cell ``(n_cells, 8, 3)``, corner ``x + 2y + 4z``."""
        ni, nj, nk = self.counts
        if self.points is not None:
            grid = self.points.reshape(nk + 1, nj + 1, ni + 1, 3)
            parts = [
                grid[z : z + nk, y : y + nj, x : x + ni]
                for z in (0, 1)
                for y in (0, 1)
                for x in (0, 1)
            ]
            return np.stack(parts, axis=3).reshape(-1, 8, 3)
        assert self.coord is not None
        assert self.zcorn is not None
        z = self.zcorn.reshape(nk, 2, nj, 2, ni, 2).transpose(0, 2, 4, 1, 3, 5)
        z = z.reshape(nk, nj, ni, 8)
        pillars = self.coord.reshape(nj + 1, ni + 1, 6)
        corner_pillars = np.stack(
            [pillars[y : y + nj, x : x + ni] for b in (0, 1) for y in (0, 1) for x in (0, 1)],
            axis=2,
        )  # (nj, ni, 8, 6)
        top, bottom = corner_pillars[..., :3], corner_pillars[..., 3:]
        dz = bottom[..., 2] - top[..., 2]
        safe = np.where(dz == 0.0, 1.0, dz)
        t = np.where(dz == 0.0, 0.0, (z - top[..., 2]) / safe)  # (nk, nj, ni, 8)
        xy = top[..., :2] + t[..., None] * (bottom[..., :2] - top[..., :2])
        return np.concatenate([xy, z[..., None]], axis=-1).reshape(-1, 8, 3)

    def corner_points(self) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
        """Distinct corners ``(m, 3)`` and each cell's eight corner indices ``(n_cells, 8)``.

        Corners with the same coordinates are one point, so a faulted grid has more corners
        than ``(ni+1)(nj+1)(nk+1)``: those split by the fault's throw.
        """
        corners = self.cell_corners().reshape(-1, 3)
        unique, inverse = np.unique(corners, axis=0, return_inverse=True)
        return unique, inverse.reshape(-1, 8).astype(np.int64)

    @cached_property
    def cell_volumes(self) -> NDArray[np.float64]:
        """The volume of each cell (six tetrahedra through the 0-7 diagonal; exact for
        parallelepipeds and planar-faced cells)."""
        corners = self.cell_corners()
        a, b, c, d = (corners[:, _HEX_TETS[:, m]] for m in range(4))
        det = np.einsum("ntj,ntj->nt", b - a, np.cross(c - a, d - a))
        return np.asarray(np.abs(det.sum(axis=1)) / 6.0, dtype=np.float64)

    @property
    def volume(self) -> float:
        """The total volume of the active cells."""
        volumes = self.cell_volumes
        return float(volumes.sum() if self.actnum is None else volumes[self.actnum].sum())

    @cached_property
    def bounds(self) -> BoundingBox | None:
        if self.points is not None:
            return BoundingBox.from_points(self.points)
        return BoundingBox.from_points(self.cell_corners().reshape(-1, 3))

    def _check(self) -> None:
        if min(self.counts) < 1:
            raise self.fail("counts", f"every axis needs at least one cell, got {self.counts}")
        ni, nj, nk = self.counts
        if (self.points is None) == (self.coord is None):
            raise self.fail("points", "give either points or coord + zcorn")
        if self.points is not None:
            want = (ni + 1) * (nj + 1) * (nk + 1)
            if self.points.shape[0] != want or self.zcorn is not None:
                raise self.fail(
                    "points", f"has {self.points.shape[0]} points, counts {self.counts} need {want}"
                )
        else:
            self._check_corner_point(ni, nj, nk)
        if self.actnum is not None and self.actnum.shape[0] != self.n_cells:
            raise self.fail("actnum", f"has {self.actnum.shape[0]} flags for {self.n_cells} cells")

    def _check_corner_point(self, ni: int, nj: int, nk: int) -> None:
        assert self.coord is not None
        if self.coord.shape[0] != (ni + 1) * (nj + 1):
            raise self.fail(
                "coord",
                f"has {self.coord.shape[0]} pillars, counts {self.counts} need "
                f"{(ni + 1) * (nj + 1)}",
            )
        if self.zcorn is None or self.zcorn.shape[0] != 8 * ni * nj * nk:
            got = "none" if self.zcorn is None else str(self.zcorn.shape[0])
            raise self.fail("zcorn", f"has {got} depths, counts need {8 * ni * nj * nk}")
        if self.point_data:
            raise self.fail("point_data", "a corner-point grid has no shared points")
