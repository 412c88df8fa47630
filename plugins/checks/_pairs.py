"""Candidate pairs of triangles of one surface whose boxes overlap (the self-intersection
broad phase).

The block builder's grid broad phase pairs triangles of *different* groups; within one surface
every triangle is its own group and that grid degrades. Here triangles are binned into levels
by their radius ``R`` (the largest distance from the centroid to a corner, grown by the margin),
levels √2 apart from 1.1 × the median radius: two triangles that meet have centroids within
``R_i + R_j``, so a k-d tree of each level's centroids answers ``query_pairs`` (one level) and
``sparse_distance_matrix`` (two levels) with the levels' largest radii, in C. The pairs left are
those whose boxes, grown by the margin, overlap on all three axes (tested axis by axis on
contiguous columns).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

__all__ = ["boxes_overlap", "centre_pairs", "near_pairs"]

IntArray = NDArray[np.int64]
FloatArray = NDArray[np.float64]

_STEP = np.sqrt(2.0)
_FIRST = 1.1


def _level_pairs(
    centres: FloatArray, radius: FloatArray, members: list[IntArray]
) -> tuple[IntArray, IntArray]:
    from scipy.spatial import cKDTree

    trees = [cKDTree(centres[rows]) for rows in members]
    reach = [float(radius[rows].max()) for rows in members]
    firsts: list[IntArray] = []
    seconds: list[IntArray] = []
    for a, rows_a in enumerate(members):
        pairs = trees[a].query_pairs(2.0 * reach[a], output_type="ndarray")
        firsts.append(rows_a[pairs[:, 0]])
        seconds.append(rows_a[pairs[:, 1]])
        for b in range(a + 1, len(members)):
            found = trees[a].sparse_distance_matrix(
                trees[b], reach[a] + reach[b], output_type="ndarray"
            )
            firsts.append(rows_a[found["i"]])
            seconds.append(members[b][found["j"]])
    first, second = np.concatenate(firsts), np.concatenate(seconds)
    return first.astype(np.int64, copy=False), second.astype(np.int64, copy=False)


def near_pairs(corners: FloatArray, margin: float = 0.0) -> tuple[IntArray, IntArray]:
    """Pairs ``(i, j)``, ``i != j``, each once, of triangles ``corners`` (K, 3, 3) whose boxes
    grown by ``margin`` overlap: every pair of triangles within ``margin`` of each other.

    >>> import numpy as np
    >>> flat = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], dtype=float)
    >>> i, j = near_pairs(np.stack([flat, flat + [0.5, 0.5, 0], flat + 3.0]))
    >>> sorted(zip(i.tolist(), j.tolist()))
    [(0, 1)]
    """
    i, j = centre_pairs(corners, margin)
    return boxes_overlap(corners, i, j, margin)


def centre_pairs(corners: FloatArray, margin: float = 0.0) -> tuple[IntArray, IntArray]:
    """The k-d tree stage of :func:`near_pairs`: pairs whose centroids lie within the sum of
    their levels' radii (grown by ``margin``), a superset of the pairs whose boxes overlap."""
    n = corners.shape[0]
    if n < 2:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    centres = corners.mean(axis=1)
    radius = np.sqrt(((corners - centres[:, None, :]) ** 2).sum(axis=2)).max(axis=1) + margin
    unit = _FIRST * max(float(np.median(radius)), 1e-300)
    level = np.ceil(np.log(np.maximum(radius, unit) / unit) / np.log(_STEP)).astype(np.int64)
    order = np.argsort(level, kind="stable")
    cuts = np.flatnonzero(np.diff(level[order])) + 1
    members = [rows.astype(np.int64, copy=False) for rows in np.split(order, cuts)]
    return _level_pairs(centres, radius, members)


def boxes_overlap(
    corners: FloatArray, i: IntArray, j: IntArray, margin: float = 0.0
) -> tuple[IntArray, IntArray]:
    """The pairs ``(i, j)`` whose boxes, grown by ``margin``, overlap on all three axes."""
    low = np.ascontiguousarray((corners.min(axis=1) - margin).T)
    high = np.ascontiguousarray((corners.max(axis=1) + margin).T)
    for axis in range(3):
        keep = (low[axis][i] <= high[axis][j]) & (low[axis][j] <= high[axis][i])
        i, j = i[keep], j[keep]
    return i, j
