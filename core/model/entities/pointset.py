"""Scattered points: survey points, well markers, VSet vertices."""

from __future__ import annotations

from typing import Literal

from geobrep.model.arrays import Points
from geobrep.model.entities.base import VertexEntity

__all__ = ["PointSet"]


class PointSet(VertexEntity):
    """Points ``vertices (N, 3)`` with per-point properties; it has no cells.

    >>> import numpy as np
    >>> PointSet(vertices=np.array([[450000.0, 6700000.0, -12.5]]), name="markers").n_points
    1
    """

    type: Literal["PointSet"] = "PointSet"
    vertices: Points

    def _check(self) -> None:
        if self.cell_data:
            raise self.fail("cell_data", "a PointSet has no cells; use point_data")
