"""Small geometries whose answers are known by hand, and independent geometric checks.

Shared by the test modules (``from shapes import ...``) and by ``conftest.py``'s fixtures.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from geobrep import Surface

#: A UTM-scale origin (EPSG:32631 metres) used to check that large coordinates keep precision.
UTM_ORIGIN = (450_000.0, 6_700_000.0, 0.0)

CUBE_VERTICES = np.array(
    [
        [0, 0, 0],
        [1, 0, 0],
        [1, 1, 0],
        [0, 1, 0],
        [0, 0, 1],
        [1, 0, 1],
        [1, 1, 1],
        [0, 1, 1],
    ],
    dtype=np.float64,
)
# Two triangles per side, wound counter-clockwise seen from outside.
CUBE_FACES = np.array(
    [
        [0, 2, 1],
        [0, 3, 2],  # z = 0, normal -z
        [4, 5, 6],
        [4, 6, 7],  # z = 1, normal +z
        [0, 1, 5],
        [0, 5, 4],  # y = 0, normal -y
        [3, 7, 6],
        [3, 6, 2],  # y = 1, normal +y
        [0, 4, 7],
        [0, 7, 3],  # x = 0, normal -x
        [1, 2, 6],
        [1, 6, 5],  # x = 1, normal +x
    ],
    dtype=np.int64,
)
#: Outward normal of each cube face, in CUBE_FACES order.
CUBE_NORMALS = np.repeat(
    np.array([[0, 0, -1], [0, 0, 1], [0, -1, 0], [0, 1, 0], [-1, 0, 0], [1, 0, 0]], float),
    2,
    axis=0,
)

TETRA_VERTICES = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=np.float64)
TETRA_FACES = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]], dtype=np.int64)


def make_cube(origin: Sequence[float] = (0.0, 0.0, 0.0), name: str = "cube") -> Surface:
    """The unit cube with its minimum corner at ``origin`` (12 outward triangles)."""
    return Surface(
        vertices=CUBE_VERTICES + np.asarray(origin, dtype=np.float64),
        faces=CUBE_FACES,
        name=name,
    )


def winding_numbers(
    points: ArrayLike, vertices: ArrayLike, faces: ArrayLike
) -> NDArray[np.float64]:
    """Generalised winding number of each point w.r.t. a triangle mesh (van Oosterom–Strackee).

    1 inside an outward-oriented closed mesh, 0 outside, -1 inside an inward-oriented one.
    Independent of geobrep's kernels; centre coordinates first for UTM-scale meshes.
    """
    p = np.asarray(points, dtype=np.float64)[:, None, :]
    v = np.asarray(vertices, dtype=np.float64)
    f = np.asarray(faces)
    a, b, c = (v[f[:, k]][None, :, :] - p for k in range(3))
    la, lb, lc = (np.linalg.norm(x, axis=2) for x in (a, b, c))

    def dot(x: NDArray[np.float64], y: NDArray[np.float64]) -> NDArray[np.float64]:
        return np.einsum("pfi,pfi->pf", x, y)

    numerator = dot(a, np.cross(b, c))
    denominator = la * lb * lc + dot(a, b) * lc + dot(b, c) * la + dot(c, a) * lb
    return np.asarray(2.0 * np.arctan2(numerator, denominator).sum(axis=1) / (4.0 * np.pi))
