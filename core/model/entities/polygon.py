"""Filled 3D polygons with holes: section fills, map outlines, the papers' "filled polygons"."""

from __future__ import annotations

from collections.abc import Sequence
from functools import cached_property
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray
from pydantic import model_validator

from geobrep.model.arrays import IndexArray, Points
from geobrep.model.entities.base import VertexEntity

__all__ = ["Polygon"]


def _ring_array(ring: ArrayLike) -> NDArray[np.float64]:
    points = np.asarray(ring, dtype=np.float64).reshape(-1, 3)
    if len(points) > 1 and np.array_equal(points[0], points[-1]):
        points = points[:-1]  # a closing repeat of the first vertex is implied, not stored
    return points


class Polygon(VertexEntity):
    """One or more polygons, each an outer ring followed by its holes.

    Ring ``r`` is ``vertices[ring_offsets[r]:ring_offsets[r+1]]`` (closed implicitly: the first
    vertex is not repeated). Polygon ``p`` owns rings ``polygon_offsets[p]:polygon_offsets[p+1]``,
    the first being its outer ring. Cells are polygons: ``cell_data`` has one value per polygon.

    >>> square = [[0, 0, 0], [2, 0, 0], [2, 2, 0], [0, 2, 0]]
    >>> hole = [[0.5, 0.5, 0], [0.5, 1.5, 0], [1.5, 1.5, 0], [1.5, 0.5, 0]]
    >>> Polygon.from_rings(square, holes=[hole]).area
    3.0
    """

    type: Literal["Polygon"] = "Polygon"
    cell_noun = "polygons"
    vertices: Points
    ring_offsets: IndexArray
    polygon_offsets: IndexArray

    @model_validator(mode="before")
    @classmethod
    def _default_single_ring(cls, data: Any) -> Any:
        if isinstance(data, dict) and "vertices" in data:
            if "ring_offsets" not in data:
                count = len(np.asarray(data["vertices"]))
                data = {**data, "ring_offsets": np.array([0, count], dtype=np.int64)}
            if "polygon_offsets" not in data:
                rings = len(np.asarray(data["ring_offsets"])) - 1
                data = {**data, "polygon_offsets": np.array([0, rings], dtype=np.int64)}
        return data

    @classmethod
    def from_rings(
        cls, outer: ArrayLike, holes: Sequence[ArrayLike] = (), **fields: Any
    ) -> Polygon:
        """One polygon from its outer ring and holes (each ``(k, 3)``)."""
        return cls.from_polygons([(outer, holes)], **fields)

    @classmethod
    def from_polygons(
        cls, polygons: Sequence[tuple[ArrayLike, Sequence[ArrayLike]]], **fields: Any
    ) -> Polygon:
        """Several polygons, each given as ``(outer, holes)``."""
        rings: list[NDArray[np.float64]] = []
        polygon_offsets = [0]
        for outer, holes in polygons:
            rings.append(_ring_array(outer))
            rings.extend(_ring_array(h) for h in holes)
            polygon_offsets.append(len(rings))
        ring_offsets = np.concatenate([[0], np.cumsum([len(r) for r in rings])]).astype(np.int64)
        vertices = np.concatenate(rings) if rings else np.zeros((0, 3))
        return cls(
            vertices=vertices,
            ring_offsets=ring_offsets,
            polygon_offsets=np.asarray(polygon_offsets, dtype=np.int64),
            **fields,
        )

    @property
    def n_rings(self) -> int:
        return int(self.ring_offsets.shape[0] - 1)

    @property
    def n_polygons(self) -> int:
        return int(self.polygon_offsets.shape[0] - 1)

    @property
    def n_cells(self) -> int:
        return self.n_polygons

    def ring(self, index: int) -> NDArray[np.float64]:
        """Coordinates ``(k, 3)`` of ring ``index``."""
        return np.asarray(self.vertices[self.ring_offsets[index] : self.ring_offsets[index + 1]])

    @cached_property
    def ring_vector_areas(self) -> NDArray[np.float64]:
        """``(R, 3)`` vector area of each ring (Newell): its norm is the ring's area."""
        v = self.vertices - (self.vertices.mean(axis=0) if len(self.vertices) else 0.0)
        nxt = np.arange(len(v)) + 1
        ends = self.ring_offsets[1:]
        starts = self.ring_offsets[:-1]
        ring_of = np.repeat(np.arange(self.n_rings), np.diff(self.ring_offsets))
        last = nxt == ends[ring_of]
        nxt[last] = starts[ring_of[last]]
        cross = np.cross(v, v[nxt]) * 0.5
        sums = np.zeros((self.n_rings, 3))
        np.add.at(sums, ring_of, cross)
        return sums

    @cached_property
    def polygon_areas(self) -> NDArray[np.float64]:
        """Area of each polygon: outer ring minus holes."""
        ring_areas = np.linalg.norm(self.ring_vector_areas, axis=1)
        first = self.polygon_offsets[:-1]
        totals = np.add.reduceat(ring_areas, first) if ring_areas.size else np.zeros(0)
        return np.asarray(2 * ring_areas[first] - totals if totals.size else totals)

    @property
    def area(self) -> float:
        """Total filled area."""
        return float(self.polygon_areas.sum())

    def _check(self) -> None:
        rings, polys = self.ring_offsets, self.polygon_offsets
        n = self.vertices.shape[0]
        if rings.shape[0] < 1 or rings[0] != 0 or rings[-1] != n:
            raise self.fail("ring_offsets", f"must start at 0 and end at len(vertices) = {n}")
        sizes = np.diff(rings)
        if sizes.size and sizes.min() < 3:
            bad = int(np.argmax(sizes < 3))
            raise self.fail("ring_offsets", f"ring {bad} has {int(sizes[bad])} vertices; need ≥ 3")
        if polys.shape[0] < 1 or polys[0] != 0 or polys[-1] != self.n_rings:
            raise self.fail(
                "polygon_offsets", f"must start at 0 and end at the ring count {self.n_rings}"
            )
        if np.any(np.diff(polys) < 1):
            raise self.fail("polygon_offsets", "every polygon needs an outer ring")
