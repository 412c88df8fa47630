"""The patent's depth buffers: nearest and farthest hit per pixel along each axis, and min/max
pyramids of them that classify whole octants at once.

A voxel centre ``c`` is inside when, on all three axes, ``near ≤ c < far`` for the ray through
it (the half-open interval puts a centre lying exactly on a face shared by two blocks in exactly
one of them). An octant at level ``l`` (edge ``s`` voxels) is

* black when, on every axis, the *largest* near depth over its footprint is ≤ its lowest voxel
  centre and the *smallest* far depth is > its highest centre — exactly "all its voxels black";
* white when, on some axis, the *smallest* near depth is above its highest centre or the
  *largest* far depth is ≤ its lowest centre;
* grey otherwise (its children decide).

The pyramids are built by 2 × 2 min/max sampling of the full-resolution buffers, level by level.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from geobrep.plugins.voxelize._classify import BLACK, GREY, WHITE
from geobrep.plugins.voxelize._rasterize import RayCrossings

__all__ = ["AxisDepthBuffers", "DepthBufferClassifier", "depth_buffers"]


def _pool(image: NDArray[np.float64], reduce: str) -> NDArray[np.float64]:
    h = image.shape[0] // 2
    blocks = image.reshape(h, 2, h, 2)
    if reduce == "min":
        return np.minimum(
            np.minimum(blocks[:, 0, :, 0], blocks[:, 0, :, 1]),
            np.minimum(blocks[:, 1, :, 0], blocks[:, 1, :, 1]),
        )
    return np.maximum(
        np.maximum(blocks[:, 0, :, 0], blocks[:, 0, :, 1]),
        np.maximum(blocks[:, 1, :, 0], blocks[:, 1, :, 1]),
    )


@dataclass(frozen=True)
class AxisDepthBuffers:
    """Near/far depth buffers of one axis and their min/max pyramids (index = level)."""

    axis: int
    near: NDArray[np.float64]
    far: NDArray[np.float64]
    near_min: list[NDArray[np.float64]]
    near_max: list[NDArray[np.float64]]
    far_min: list[NDArray[np.float64]]
    far_max: list[NDArray[np.float64]]


def depth_buffers(crossings: RayCrossings) -> AxisDepthBuffers:
    """The pair of depth buffers of one axis (``+inf``/``-inf`` where a ray misses) and pyramids.

    >>> import numpy as np
    >>> from geobrep.plugins.voxelize._rasterize import RayCrossings
    >>> hits = RayCrossings(2, 2, np.array([0, 0]), np.array([0.4, 1.6]), np.array([True, False]))
    >>> buffers = depth_buffers(hits)
    >>> buffers.near.tolist(), buffers.far_max[0].tolist()
    ([[0.4, inf], [inf, inf]], [[1.6]])
    """
    n = crossings.resolution
    near_flat = np.full(n * n, np.inf)
    far_flat = np.full(n * n, -np.inf)
    np.minimum.at(near_flat, crossings.pixels, crossings.depths)
    np.maximum.at(far_flat, crossings.pixels, crossings.depths)
    near, far = near_flat.reshape(n, n), far_flat.reshape(n, n)
    near_min, near_max, far_min, far_max = [near], [near], [far], [far]
    while near_min[-1].shape[0] > 1:
        near_min.append(_pool(near_min[-1], "min"))
        near_max.append(_pool(near_max[-1], "max"))
        far_min.append(_pool(far_min[-1], "min"))
        far_max.append(_pool(far_max[-1], "max"))
    return AxisDepthBuffers(
        crossings.axis,
        near,
        far,
        near_min[::-1],
        near_max[::-1],
        far_min[::-1],
        far_max[::-1],
    )


class DepthBufferClassifier:
    """Classifies octants from three axes' depth-buffer pyramids (the patent's method)."""

    def __init__(self, buffers: list[AxisDepthBuffers], depth: int) -> None:
        self.buffers = buffers
        self.depth = depth

    def classify(
        self, level: int, i: NDArray[np.int64], j: NDArray[np.int64], k: NDArray[np.int64]
    ) -> NDArray[np.uint8]:
        cells = (i, j, k)
        side = 1 << level
        if level == self.depth:  # voxels: black or white, one near and one far per axis
            inside = np.ones(i.shape[0], dtype=np.bool_)
            for buffers in self.buffers:
                a = buffers.axis
                pixel = cells[(a + 1) % 3] * side + cells[(a + 2) % 3]
                centre = cells[a] + 0.5
                inside &= np.take(buffers.near, pixel) <= centre
                inside &= np.take(buffers.far, pixel) > centre
            return inside.view(np.uint8)
        edge = float(1 << (self.depth - level))
        black = np.ones(i.shape[0], dtype=np.bool_)
        white = np.zeros(i.shape[0], dtype=np.bool_)
        for buffers in self.buffers:
            a = buffers.axis
            pixel = cells[(a + 1) % 3] * side + cells[(a + 2) % 3]
            lowest = cells[a] * edge + 0.5
            highest = lowest + (edge - 1.0)
            black &= np.take(buffers.near_max[level], pixel) <= lowest
            black &= np.take(buffers.far_min[level], pixel) > highest
            white |= np.take(buffers.near_min[level], pixel) > highest
            white |= np.take(buffers.far_max[level], pixel) <= lowest
        return np.where(white, WHITE, np.where(black, BLACK, GREY)).astype(np.uint8)
