"""Checks a TSurf read warns about (its triangles are kept as read): duplicated and zero-area
triangles, and BORDER lines that do not run along a border edge of their TFACEs.

Both look at every triangle once, with whole-array passes: the common file, which has no
defect, costs one sort of one key per triangle (duplicates), a cross product per triangle (zero
area) and a look at the triangle edges whose two vertices are on some BORDER line.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

__all__ = ["BadTriangles", "bad_triangles", "borders_on_patch_borders"]


class BadTriangles(NamedTuple):
    """How many triangles of a TSurf repeat an earlier one or have no area, and the first."""

    duplicated: int
    flat: int
    first: int  # index of the first duplicated or flat triangle


def _triangle_keys(faces: NDArray[np.int64], n: int) -> NDArray[np.int64] | None:
    """One int64 per triangle, equal for the same three vertices in any order (None when
    ``n**3`` does not fit an int64)."""
    if n > 2_000_000:
        return None
    a, b, c = faces[:, 0], faces[:, 1], faces[:, 2]
    low = np.minimum(np.minimum(a, b), c)
    high = np.maximum(np.maximum(a, b), c)
    middle = a + b + c - low - high
    keys: NDArray[np.int64] = (low * n + middle) * n + high
    return keys


def _repeated(faces: NDArray[np.int64], n: int) -> NDArray[np.bool_]:
    """True for each triangle with the three vertices of an earlier one (in any order)."""
    repeated = np.ones(faces.shape[0], dtype=bool)
    keys = _triangle_keys(faces, n)
    if keys is None:
        first = np.unique(np.sort(faces, axis=1), axis=0, return_index=True)[1]
    else:
        first = np.unique(keys, return_index=True)[1]
    repeated[first] = False
    return repeated


def _flat(xyz: NDArray[np.float64], faces: NDArray[np.int64]) -> NDArray[np.bool_]:
    """True for each triangle whose edge cross product is exactly zero (a repeated vertex, or
    three collinear points); NaN from an overflow is not zero area."""
    columns = np.ascontiguousarray(xyz.T)
    # np.take gathers columns several times faster than fancy indexing ``columns[:, ids]``
    p0 = np.take(columns, faces[:, 0], axis=1)
    u = np.take(columns, faces[:, 1], axis=1) - p0
    v = np.take(columns, faces[:, 2], axis=1) - p0
    with np.errstate(over="ignore", invalid="ignore"):
        zero: NDArray[np.bool_] = (u[1] * v[2] - u[2] * v[1]) == 0
        zero &= (u[2] * v[0] - u[0] * v[2]) == 0
        zero &= (u[0] * v[1] - u[1] * v[0]) == 0
    return zero


def bad_triangles(xyz: NDArray[np.float64], faces: NDArray[np.int64]) -> BadTriangles | None:
    """Duplicated triangles (the three vertices of an earlier one, in any order) and zero-area
    ones of a TSurf, or None when it has neither.

    >>> xyz = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [2, 0, 0]])
    >>> bad_triangles(xyz, np.array([[0, 1, 2], [2, 0, 1], [0, 1, 3]]))
    BadTriangles(duplicated=1, flat=1, first=1)
    """
    if faces.shape[0] == 0:
        return None
    faces = np.asarray(faces, dtype=np.int64)  # the keys need 64 bits
    n = xyz.shape[0]
    flat = _flat(xyz, faces)
    keys = _triangle_keys(faces, n)
    if keys is not None and not flat.any():
        ordered = np.sort(keys)
        if not (ordered[1:] == ordered[:-1]).any():
            return None  # the usual file: nothing to find the first of
    duplicated = _repeated(faces, n)
    bad = duplicated | flat
    if not bad.any():
        return None
    return BadTriangles(int(duplicated.sum()), int(flat.sum()), int(np.argmax(bad)))


def borders_on_patch_borders(
    faces: NDArray[np.int64], parts: NDArray[np.int64], pairs: NDArray[np.int64]
) -> NDArray[np.bool_]:
    """For each BORDER vertex pair (B, 2), whether it is a border edge of some TFACE: an edge
    that exactly one triangle of that patch (``parts``: the patch of each triangle) uses.

    Only the triangle edges whose two vertices both lie on BORDER lines are counted: every
    edge with a BORDER's two vertices is among them.

    >>> faces = np.array([[0, 1, 2], [0, 2, 3]])
    >>> borders_on_patch_borders(faces, np.array([0, 0]), np.array([[1, 0], [0, 2]])).tolist()
    [True, False]
    """
    faces = np.asarray(faces, dtype=np.int64)  # the keys need 64 bits
    pairs = np.asarray(pairs, dtype=np.int64)
    n = int(max(faces.max(initial=0), pairs.max(initial=0))) + 1
    on_line = np.zeros(n, dtype=bool)
    on_line[pairs.reshape(-1)] = True
    marked = on_line[faces]
    near = marked & marked[:, [1, 2, 0]]  # edge k runs from corner k to corner k + 1
    triangle, corner = np.nonzero(near)
    a, b = faces[triangle, corner], faces[triangle, (corner + 1) % 3]
    keys = np.minimum(a, b) * n + np.maximum(a, b)
    patch = np.asarray(parts, dtype=np.int64)[triangle]
    low = int(patch.min(initial=0))
    span = int(patch.max(initial=0)) - low + 1
    if float(span) * n * n < 2.0**62:  # (patch, edge) as one int64 key
        combined, counts = np.unique((patch - low) * (n * n) + keys, return_counts=True)
        border_keys = np.sort(combined[counts == 1] % (n * n))
    else:
        rows, counts = np.unique(np.column_stack([patch, keys]), axis=0, return_counts=True)
        border_keys = np.sort(rows[counts == 1, 1])
    pair_keys = pairs.min(axis=1) * n + pairs.max(axis=1)
    # membership by a search of the sorted keys (np.isin and a plain np.unique import
    # numpy.ma, which nothing else of a read needs)
    if not border_keys.size:
        return np.zeros(pair_keys.shape[0], dtype=np.bool_)
    at = np.minimum(np.searchsorted(border_keys, pair_keys), border_keys.shape[0] - 1)
    on_border: NDArray[np.bool_] = border_keys[at] == pair_keys
    return on_border
