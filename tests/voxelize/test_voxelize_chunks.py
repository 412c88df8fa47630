"""The rasteriser prepares triangles a chunk at a time (issue 17, memory): the crossings are the
same, in the same order, whatever the chunk size."""

from __future__ import annotations

import numpy as np
import pytest

from geobrep.plugins.voxelize import _rasterize
from geobrep.plugins.voxelize._rasterize import ray_crossings


def _sphere(n: int) -> tuple[np.ndarray, np.ndarray]:
    theta = np.linspace(0.0, np.pi, n + 1)[1:-1]
    phi = np.linspace(0.0, 2.0 * np.pi, n, endpoint=False)
    t, p = np.meshgrid(theta, phi, indexing="ij")
    ring = np.column_stack([(np.sin(t) * np.cos(p)).ravel(), (np.sin(t) * np.sin(p)).ravel(),
                            np.cos(t).ravel()])  # fmt: skip
    vertices = np.vstack([ring, [[0.0, 0.0, 1.0], [0.0, 0.0, -1.0]]])
    rows, cols = n - 1, n
    r, c = np.meshgrid(np.arange(rows - 1), np.arange(cols), indexing="ij")
    a, b = (r * cols + c).ravel(), (r * cols + (c + 1) % cols).ravel()
    faces = [np.stack([a, a + cols, b], axis=1), np.stack([b, a + cols, b + cols], axis=1)]
    top, bottom = np.arange(cols), (rows - 1) * cols + np.arange(cols)
    faces.append(np.stack([np.full(cols, len(ring)), top, np.roll(top, -1)], axis=1))
    faces.append(np.stack([np.full(cols, len(ring) + 1), np.roll(bottom, -1), bottom], axis=1))
    return vertices, np.concatenate(faces)


@pytest.mark.parametrize("chunk", [1, 7, 500])
@pytest.mark.parametrize("axis", [0, 1, 2])
def test_chunked_crossings_are_the_whole_pass(
    chunk: int, axis: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    vertices, faces = _sphere(40)
    resolution = 64
    grid = (vertices + 1.0) * (0.49 * resolution) + 0.3  # inside the grid, off the pixel centres
    whole = ray_crossings(grid, faces, axis, resolution)  # one chunk: all 3,120 triangles
    monkeypatch.setattr(_rasterize, "TRIANGLE_CHUNK", chunk)
    parts = ray_crossings(grid, faces, axis, resolution)
    assert whole.size > 0
    assert np.array_equal(parts.pixels, whole.pixels)
    assert np.array_equal(parts.depths, whole.depths)
    assert np.array_equal(parts.entering, whole.entering)
    assert (whole.counts() % 2 == 0).all()  # a closed surface: every ray crosses it evenly
