"""The PointSet clipper: points on the kept side stay, with their data; points on the plane
(within the tolerance) belong to both sides."""

from __future__ import annotations

from typing import Any

import numpy as np

from geobrep import PointSet
from geobrep.geometry import Plane
from geobrep.plugins import ClipContext, Keep, halves, pack_halves
from geobrep.plugins.clip._sides import vertex_sides
from geobrep.plugins.clip.options import ClipOptions, tolerance_of

__all__ = ["clip_pointset", "section_pointset"]


def clip_pointset(
    points: PointSet, plane: Plane, keep: Keep, options: ClipOptions, context: ClipContext
) -> Any:
    """Clipper of :class:`PointSet` entities."""
    sides = vertex_sides(plane.signed_distance(points.vertices), tolerance_of(options, context))
    parts: dict[int, PointSet | None] = {}
    for side in halves(keep):
        chosen = np.flatnonzero(sides != -side)
        if chosen.shape[0] == points.n_points:
            parts[side] = points
        elif chosen.shape[0] == 0:
            parts[side] = None
        else:
            parts[side] = points.replace(
                vertices=points.vertices[chosen], point_data=points.point_data.take(chosen)
            )
    return pack_halves(keep, parts)


def section_pointset(
    points: PointSet, plane: Plane, options: ClipOptions, context: ClipContext
) -> PointSet | None:
    """The points lying on the plane (within the tolerance)."""
    sides = vertex_sides(plane.signed_distance(points.vertices), tolerance_of(options, context))
    chosen = np.flatnonzero(sides == 0)
    if chosen.shape[0] == 0:
        return None
    return points.replace(
        id=None, vertices=points.vertices[chosen], point_data=points.point_data.take(chosen)
    )
