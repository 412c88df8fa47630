"""Grouped-row helpers shared by the stages (rows delimited by offsets, or labelled by group)."""

from __future__ import annotations

import numpy as np

from geobrep.geometry.arrays import FloatArray, IntArray
from geobrep.geometry.graph import component_roots
from geobrep.geometry.mesh import compact_indices

__all__ = ["components", "concatenated_ranges", "group_sums"]


def concatenated_ranges(starts: IntArray, counts: IntArray) -> IntArray:
    """``range(start, start + count)`` for every pair, concatenated, without a Python loop.

    >>> import numpy as np
    >>> concatenated_ranges(np.array([5, 0]), np.array([2, 3])).tolist()
    [5, 6, 0, 1, 2]
    """
    total = int(counts.sum())
    shift = (starts - (np.cumsum(counts) - counts)).astype(np.int64, copy=False)
    ranges: IntArray = np.arange(total, dtype=np.int64)
    ranges += np.repeat(shift, counts)  # in place: no third array as long as the ranges
    return ranges


def group_sums(labels: IntArray, weights: FloatArray, n_groups: int) -> FloatArray:
    """Sum of ``weights`` per label (float64, ``n_groups`` long); 2-D weights sum per column.

    >>> import numpy as np
    >>> group_sums(np.array([1, 0, 1]), np.array([2.0, 3.0, 4.0]), 3).tolist()
    [3.0, 6.0, 0.0]
    """
    if weights.ndim == 2:
        return np.stack(
            [group_sums(labels, weights[:, k], n_groups) for k in range(weights.shape[1])], axis=1
        )
    return np.asarray(np.bincount(labels, weights=weights, minlength=n_groups), dtype=np.float64)


def components(n: int, a: IntArray, b: IntArray) -> tuple[int, IntArray]:
    """Connected components of nodes ``0 … n-1`` joined by the edges ``(a[i], b[i])``: their
    number and the label of every node, components numbered by their lowest node — the
    labels of scipy's ``connected_components`` (undirected), without building a sparse matrix
    (for the small graphs of patch sides and patches, that is most of the cost).

    >>> import numpy as np
    >>> count, labels = components(5, np.array([3, 4]), np.array([1, 3]))
    >>> count, labels.tolist()
    (3, [0, 1, 2, 1, 1])
    """
    used, labels = compact_indices(component_roots(n, a, b), n)
    return int(used.shape[0]), labels
