"""Which side of a plane points lie on, and where edges cross it: the kernels every clipper uses.

A point is *on* the plane when its distance is at most the tolerance; it is then neither kept
nor dropped by itself, and no edge is cut at it. An edge is cut only when its ends lie strictly on
opposite sides. The crossing point of an edge is computed from its endpoints taken in
lexicographic order of their coordinates, so the same geometric edge gives the same point, bit for
bit, in every entity that holds it (neighbouring surfaces, block boundaries, caps).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from geobrep import Property
from geobrep.geometry.arrays import FloatArray, IntArray
from geobrep.plugins import PropertyMap

__all__ = [
    "NEGATIVE_BIT",
    "POSITIVE_BIT",
    "canonical_edges",
    "crossing_points",
    "interpolate_properties",
    "side_bits",
    "vertex_sides",
]


#: Bit set in :func:`side_bits` for a point strictly on the negative side.
NEGATIVE_BIT = 1
#: Bit set in :func:`side_bits` for a point strictly on the positive side.
POSITIVE_BIT = 2


def vertex_sides(distances: FloatArray, tolerance: float) -> NDArray[np.int8]:
    """−1, 0 (within ``tolerance`` of the plane) or +1 for each distance.

    >>> vertex_sides(np.array([-1.0, 1e-12, 2.0]), 1e-9).tolist()
    [-1, 0, 1]
    """
    sides = (distances > tolerance).view(np.int8) - (distances < -tolerance).view(np.int8)
    return np.asarray(sides, dtype=np.int8)


def side_bits(sides: NDArray[np.int8]) -> NDArray[np.uint8]:
    """:data:`NEGATIVE_BIT` / :data:`POSITIVE_BIT` / 0 per point; OR them over a cell's corners.

    >>> side_bits(np.array([-1, 0, 1], dtype=np.int8)).tolist()
    [1, 0, 2]
    """
    return np.asarray((sides < 0).view(np.uint8) | ((sides > 0).view(np.uint8) << 1), np.uint8)


def canonical_edges(vertices: FloatArray, a: IntArray, b: IntArray) -> tuple[IntArray, IntArray]:
    """The endpoints of each edge ordered so that ``vertices[a]`` is lexicographically smaller."""
    if a.shape[0] == 0:
        return a, b
    diff = vertices[b] - vertices[a]
    nonzero = diff != 0
    first = np.argmax(nonzero, axis=1)
    swap = diff[np.arange(diff.shape[0]), first] < 0
    return np.where(swap, b, a), np.where(swap, a, b)


def crossing_points(
    vertices: FloatArray, distances: FloatArray, a: IntArray, b: IntArray
) -> tuple[FloatArray, IntArray, IntArray, FloatArray]:
    """Where edges ``(a, b)`` (ends strictly on opposite sides) cross the plane.

    Returns ``(points (K, 3), a, b, t)`` with the endpoints in canonical order and
    ``points = vertices[a] + t · (vertices[b] − vertices[a])``.
    """
    a, b = canonical_edges(vertices, a, b)
    da, db = distances[a], distances[b]
    t = da / (da - db)
    start = vertices[a]
    points = start + t[:, None] * (vertices[b] - start)
    return points, a, b, t


def interpolate_properties(
    props: PropertyMap, keep: IntArray, a: IntArray, b: IntArray, t: FloatArray
) -> PropertyMap:
    """Point data of ``keep`` (original points) followed by points interpolated on edges ``(a, b)``.

    Floating-point values are interpolated linearly (no-data or NaN at either end gives no-data);
    integer and boolean values take the value of the nearer end.
    """
    if not props:
        return PropertyMap()
    result: dict[str, Property] = {}
    for name, prop in props.items():
        result[name] = prop.model_copy(
            update={"values": _readonly(_interpolated(prop, keep, a, b, t))}
        )
    return PropertyMap(result)


def _interpolated(
    prop: Property, keep: IntArray, a: IntArray, b: IntArray, t: FloatArray
) -> NDArray[Any]:
    values = prop.values
    kept = values[keep]
    if a.shape[0] == 0:
        return np.asarray(kept)
    if values.dtype.kind in "fc":
        weight = t if values.ndim == 1 else t[:, None]
        va, vb = values[a], values[b]
        new = va + weight * (vb - va)
        if prop.no_data_value is not None:
            missing = (va == prop.no_data_value) | (vb == prop.no_data_value)
            new = np.where(missing, prop.no_data_value, new)
        new = new.astype(values.dtype, copy=False)
    else:
        nearer = np.where(t <= 0.5, a, b)
        new = values[nearer]
    return np.concatenate([kept, new])


def _readonly(array: NDArray[Any]) -> NDArray[Any]:
    array.flags.writeable = False
    return array
