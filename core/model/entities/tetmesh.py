"""Tetrahedral meshes: GOCAD TSolids, volume meshes of blocks."""

from __future__ import annotations

from functools import cached_property
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray
from pydantic import Field

from geobrep.model.arrays import IndexArray, Points, TetArray
from geobrep.model.entities.base import VertexEntity

__all__ = ["TetMesh"]


class TetMesh(VertexEntity):
    """Tetrahedra ``cells (K, 4)`` over ``vertices (N, 3)``, grouped into named regions.

    ``region_labels[k]`` is the region of cell ``k`` and ``region_names[label]`` its name (GOCAD
    TVOLUME parts, model regions); without labels the mesh is one region. ``cell_data`` holds one
    value per tetrahedron.

    >>> tet = TetMesh(vertices=[[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], cells=[[0, 1, 2, 3]])
    >>> round(tet.volume, 12)
    0.166666666667
    """

    type: Literal["TetMesh"] = "TetMesh"
    cell_noun = "tetrahedra"
    vertices: Points
    cells: TetArray
    region_labels: IndexArray | None = None
    region_names: tuple[str, ...] = Field(default=())

    @property
    def n_cells(self) -> int:
        return int(self.cells.shape[0])

    @property
    def n_regions(self) -> int:
        if self.region_names:
            return len(self.region_names)
        if self.region_labels is None or self.region_labels.size == 0:
            return 1
        return int(self.region_labels.max()) + 1

    def region_cells(self, label: int) -> NDArray[np.int64]:
        """Indices of the tetrahedra of region ``label``."""
        if not 0 <= label < self.n_regions:
            raise self.fail("region_labels", f"no region {label} (mesh has {self.n_regions})")
        if self.region_labels is None:
            return np.arange(self.n_cells, dtype=np.int64)
        return np.flatnonzero(self.region_labels == label).astype(np.int64)

    @cached_property
    def cell_volumes(self) -> NDArray[np.float64]:
        """Signed volume of each tetrahedron (positive when ``(b-a)·((c-a)×(d-a)) > 0``)."""
        v = self.vertices
        if self.n_cells == 0:
            return np.zeros(0)
        a = v[self.cells[:, 0]]
        ab, ac, ad = (v[self.cells[:, k]] - a for k in (1, 2, 3))
        return np.asarray(np.einsum("ij,ij->i", ab, np.cross(ac, ad)) / 6.0, dtype=np.float64)

    @property
    def volume(self) -> float:
        """Total volume (absolute values of the cell volumes: orientation-independent)."""
        return float(np.abs(self.cell_volumes).sum())

    def _check(self) -> None:
        n = self.vertices.shape[0]
        cells = self.cells
        if cells.size:
            lo, hi = int(cells.min()), int(cells.max())
            if lo < 0 or hi >= n:
                bad = lo if lo < 0 else hi
                row = int(np.argmax(((cells < 0) | (cells >= n)).any(axis=1)))
                raise self.fail(
                    "cells", f"tetrahedron {row} refers to vertex {bad} (there are {n} vertices)"
                )
        labels: Any = self.region_labels
        if labels is not None:
            if labels.shape[0] != cells.shape[0]:
                raise self.fail(
                    "region_labels", f"has {labels.shape[0]} labels for {cells.shape[0]} cells"
                )
            if labels.size and labels.min() < 0:
                raise self.fail("region_labels", "labels must be ≥ 0")
            if self.region_names and labels.size and labels.max() >= len(self.region_names):
                raise self.fail(
                    "region_labels",
                    f"label {int(labels.max())} has no name ({len(self.region_names)} names)",
                )
        elif len(self.region_names) > 1:
            raise self.fail("region_names", "several region names need region_labels")
