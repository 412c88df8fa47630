"""Regular grids: GOCAD Voxets, rasters as volumes, block models on a rotated lattice.

A regular grid is the lattice ``origin + i·u + j·v + k·w`` for ``0 ≤ i ≤ ni``, ``0 ≤ j ≤ nj``,
``0 ≤ k ≤ nk``: ``u``, ``v`` and ``w`` are the edge vectors of one cell (rotated and
non-orthogonal axes are allowed, they only need to span 3D), ``counts = (ni, nj, nk)`` the number
of cells along each axis. Cell ``(i, j, k)`` is element ``i + ni·(j + nj·k)`` of ``cell_data``
(i fastest, as GOCAD and Eclipse order them); point ``(i, j, k)`` is element
``i + (ni+1)·(j + (nj+1)·k)`` of ``point_data``.
"""

from __future__ import annotations

from functools import cached_property
from typing import TYPE_CHECKING, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray
from pydantic import Field

from geobrep.geometry.bbox import BoundingBox
from geobrep.model.arrays import Vector3
from geobrep.model.entities.base import Entity

if TYPE_CHECKING:
    from geobrep.model.entities.octree import LinearOctree

__all__ = ["RegularGrid", "lattice"]


def lattice(
    origin: NDArray[np.float64], axes: NDArray[np.float64], shape: tuple[int, int, int]
) -> NDArray[np.float64]:
    """The points ``origin + i·axes[0] + j·axes[1] + k·axes[2]`` of a lattice of ``shape``
    points, ``(n, 3)`` with i fastest."""
    i, j, k = (np.arange(n, dtype=np.float64) for n in shape)
    kk, jj, ii = np.meshgrid(k, j, i, indexing="ij")
    steps = np.stack([ii.ravel(), jj.ravel(), kk.ravel()], axis=1)
    return np.asarray(origin + steps @ axes, dtype=np.float64)


class RegularGrid(Entity):
    """A lattice of parallelepiped cells ``origin + i·u + j·v + k·w`` with cell or point data.

    >>> grid = RegularGrid(origin=[0, 0, 0], u=[2, 0, 0], v=[0, 1, 0], w=[0, 0, 0.5],
    ...                    counts=(3, 2, 4))
    >>> grid.n_cells, grid.n_points, grid.cell_volume, grid.volume
    (24, 60, 1.0, 24.0)
    """

    type: Literal["RegularGrid"] = "RegularGrid"
    cell_noun = "cells"
    origin: Vector3
    u: Vector3
    v: Vector3
    w: Vector3
    counts: tuple[int, int, int] = Field(description="cells along u, v and w (each ≥ 1)")

    @property
    def axes(self) -> NDArray[np.float64]:
        """``(3, 3)``: the rows are ``u``, ``v`` and ``w``."""
        return np.stack([self.u, self.v, self.w])

    @property
    def point_counts(self) -> tuple[int, int, int]:
        """Points along each axis: ``counts + 1``."""
        ni, nj, nk = self.counts
        return ni + 1, nj + 1, nk + 1

    @property
    def n_cells(self) -> int:
        ni, nj, nk = self.counts
        return ni * nj * nk

    @property
    def n_points(self) -> int:
        pi, pj, pk = self.point_counts
        return pi * pj * pk

    @property
    def cell_volume(self) -> float:
        """Volume of one cell: ``|det(u, v, w)|``."""
        return float(abs(np.linalg.det(self.axes)))

    @property
    def volume(self) -> float:
        return self.cell_volume * self.n_cells

    def points(self) -> NDArray[np.float64]:
        """Every lattice point ``(n_points, 3)``, i fastest."""
        return lattice(self.origin, self.axes, self.point_counts)

    def cell_centers(self) -> NDArray[np.float64]:
        """The centre of every cell ``(n_cells, 3)``, i fastest."""
        centre = self.origin + 0.5 * (self.u + self.v + self.w)
        return lattice(centre, self.axes, self.counts)

    def cell_index(self, ijk: ArrayLike) -> NDArray[np.int64]:
        """The flat index of cells ``(n, 3)`` of ``(i, j, k)`` (no bounds check)."""
        cells = np.asarray(ijk, dtype=np.int64).reshape(-1, 3)
        ni, nj, _ = self.counts
        return np.asarray(cells[:, 0] + ni * (cells[:, 1] + nj * cells[:, 2]), dtype=np.int64)

    def locate(self, points: ArrayLike) -> NDArray[np.int64]:
        """The flat index of the cell holding each point ``(n, 3)``, -1 outside the grid."""
        xyz = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        local = np.linalg.solve(self.axes.T, (xyz - self.origin).T).T
        cells = np.floor(local).astype(np.int64)
        counts = np.array(self.counts, dtype=np.int64)
        # a point on the far face belongs to the last cell
        cells = np.where((local == counts) & (counts > 0), counts - 1, cells)
        inside = ((cells >= 0) & (cells < counts)).all(axis=1)
        return np.where(inside, self.cell_index(np.clip(cells, 0, counts - 1)), -1)

    @classmethod
    def from_octree(cls, octree: LinearOctree, name: str = "label") -> RegularGrid:
        """The grid of ``octree``'s finest cells, its leaf labels (1 without labels) as the
        int64 cell property ``name``, -1 (no-data) outside the leaves.

        >>> from geobrep import LinearOctree
        >>> tree = LinearOctree(codes=[0], levels=[1], depth=1, origin=[0, 0, 0], size=2.0)
        >>> RegularGrid.from_octree(tree).cell_data["label"].values.tolist()
        [1, -1, -1, -1, -1, -1, -1, -1]
        """
        from geobrep.model.entities._grid_octree import grid_from_octree

        return grid_from_octree(octree, name)

    def to_octree(self, name: str = "label") -> LinearOctree:
        """The linear octree of the cells whose property ``name`` is set (not -1 or no-data),
        eight same-label siblings merged into their parent. Cell data are the cells; point data
        (a Voxet's nodes) are voxels centred on the points. The grid must be axis-aligned with
        cubic cells."""
        from geobrep.model.entities._grid_octree import octree_from_grid

        return octree_from_grid(self, name)

    @cached_property
    def bounds(self) -> BoundingBox | None:
        ni, nj, nk = self.counts
        corners = lattice(self.origin, self.axes * np.array([[ni], [nj], [nk]]), (2, 2, 2))
        return BoundingBox.from_points(corners)

    def _check(self) -> None:
        if min(self.counts) < 1:
            raise self.fail("counts", f"every axis needs at least one cell, got {self.counts}")
        axes = self.axes
        scale = float(np.prod(np.linalg.norm(axes, axis=1)))
        if scale == 0.0 or abs(np.linalg.det(axes)) <= 1e-12 * scale:
            raise self.fail("u", "the axis vectors u, v and w must span 3D (they are flat)")
