"""A thread-safe, picklable 3D R-tree over axis-aligned boxes with int64 ids (rtree bulk load)."""

from __future__ import annotations

import ctypes
import threading
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from geobrep.errors import EntityValidationError
from geobrep.geometry.arrays import FloatArray, IntArray
from geobrep.geometry.bbox import BoundingBox, boxes_plane_side, column_extremes
from geobrep.geometry.plane import Plane

__all__ = ["SpatialIndex"]


def _boxes(
    mins: ArrayLike, maxs: ArrayLike, entity: str, count: int | None = None
) -> tuple[FloatArray, FloatArray]:
    """Validate (K, 3) ``mins`` and ``maxs``: finite, same shape, mins ≤ maxs."""
    arrays: list[FloatArray] = []
    for field, values in (("mins", mins), ("maxs", maxs)):
        try:
            arr = np.asarray(values, dtype=np.float64)
        except (TypeError, ValueError) as exc:
            raise EntityValidationError(entity, field, f"not a numeric array: {exc}") from exc
        if arr.ndim != 2 or arr.shape[1] != 3:
            raise EntityValidationError(entity, field, f"expected shape (K, 3), got {arr.shape}")
        if count is not None and arr.shape[0] != count:
            raise EntityValidationError(
                entity, field, f"expected {count} rows (one per id), got {arr.shape[0]}"
            )
        if not np.isfinite(arr).all():
            raise EntityValidationError(entity, field, "contains NaN or infinite values")
        arrays.append(arr)
    lo, hi = arrays
    if lo.shape != hi.shape:
        raise EntityValidationError(
            entity, "maxs", f"shape {hi.shape} differs from mins {lo.shape}"
        )
    inverted = np.flatnonzero((lo > hi).any(axis=1))
    if inverted.size:
        raise EntityValidationError(
            entity, "maxs", f"maxs < mins for rows {inverted[:10].tolist()}"
        )
    return lo, hi


def _frozen(arr: NDArray[Any]) -> NDArray[Any]:
    out = np.array(arr, copy=True)
    out.flags.writeable = False
    return out


class SpatialIndex:
    """R-tree over K boxes ``[mins[i], maxs[i]]`` identified by unique int64 ``ids``.

    Queries treat boxes as closed (touching counts). All rtree calls hold one lock, so one
    index can be shared between threads; pickling rebuilds the tree from the stored arrays.

    >>> idx = SpatialIndex([10, 20], [[0, 0, 0], [5, 5, 5]], [[1, 1, 1], [6, 6, 6]])
    >>> idx.intersection([0.5, 0.5, 0.5], [5, 5, 5]).tolist()
    [10, 20]
    """

    __slots__ = ("_ids", "_index", "_lock", "_maxs", "_mins", "_row_of_sorted", "_sorted_ids")

    def __init__(self, ids: ArrayLike, mins: ArrayLike, maxs: ArrayLike) -> None:
        entity = "SpatialIndex"
        id_arr = np.asarray(ids)
        if id_arr.ndim != 1:
            raise EntityValidationError(entity, "ids", f"expected shape (K,), got {id_arr.shape}")
        if id_arr.size and not np.issubdtype(id_arr.dtype, np.integer):
            raise EntityValidationError(entity, "ids", f"expected integers, got {id_arr.dtype}")
        if id_arr.dtype == np.uint64 and id_arr.size and int(id_arr.max()) > 2**63 - 1:
            raise EntityValidationError(entity, "ids", "values do not fit in int64")
        id64 = id_arr.astype(np.int64)
        lo, hi = _boxes(mins, maxs, entity, count=id64.shape[0])
        order = np.argsort(id64, kind="stable")
        sorted_ids = id64[order]
        duplicated = sorted_ids[1:][sorted_ids[1:] == sorted_ids[:-1]]
        if duplicated.size:
            raise EntityValidationError(
                entity, "ids", f"must be unique; repeated: {np.unique(duplicated)[:10].tolist()}"
            )
        self._ids: IntArray = _frozen(id64)
        self._mins: FloatArray = _frozen(lo)
        self._maxs: FloatArray = _frozen(hi)
        self._sorted_ids: IntArray = _frozen(sorted_ids)
        self._row_of_sorted: IntArray = _frozen(order.astype(np.int64))
        self._lock = threading.Lock()
        from rtree import index as rtree_index  # imported on first use: keeps imports fast

        properties = rtree_index.Property(dimension=3)
        # rtree's numpy methods are unannotated: hold the index as Any.
        self._index: Any
        if id64.shape[0]:
            self._index = rtree_index.Index(
                (self._ids, self._mins, self._maxs), properties=properties
            )
        else:  # libspatialindex refuses to bulk-load an empty stream
            self._index = rtree_index.Index(properties=properties)

    # ----------------------------------------------------------------- data
    @property
    def ids(self) -> IntArray:
        """Box ids (K,), read-only, in construction order."""
        return self._ids

    @property
    def mins(self) -> FloatArray:
        """Box minima (K, 3), read-only."""
        return self._mins

    @property
    def maxs(self) -> FloatArray:
        """Box maxima (K, 3), read-only."""
        return self._maxs

    @property
    def bounds(self) -> BoundingBox | None:
        """Box holding every stored box, or None when the index is empty.

        >>> SpatialIndex([1], [[0, 0, 0]], [[1, 2, 3]]).bounds
        BoundingBox(mins=[0.0, 0.0, 0.0], maxs=[1.0, 2.0, 3.0])
        """
        if len(self) == 0:
            return None
        return BoundingBox(column_extremes(self._mins)[0], column_extremes(self._maxs)[1])

    def __len__(self) -> int:
        return int(self._ids.shape[0])

    def __repr__(self) -> str:
        bounds = self.bounds
        where = "empty" if bounds is None else f"bounds={bounds.as_tuple()}"
        return f"SpatialIndex({len(self)} boxes, {where})"

    def __reduce__(self) -> tuple[type[SpatialIndex], tuple[IntArray, FloatArray, FloatArray]]:
        return (SpatialIndex, (self._ids, self._mins, self._maxs))

    def _rows(self, ids: IntArray) -> IntArray:
        """Rows (in ``ids`` order) of the given stored ids."""
        return self._row_of_sorted[np.searchsorted(self._sorted_ids, ids)]

    # ----------------------------------------------------------------- queries
    def intersection(self, mins: ArrayLike, maxs: ArrayLike) -> IntArray:
        """Sorted ids of the boxes meeting the closed query box [mins, maxs] ((3,) each).

        >>> SpatialIndex([3, 1], [[0, 0, 0], [2, 0, 0]], [[1, 1, 1], [3, 1, 1]]).intersection(
        ...     [1, 0, 0], [2, 1, 1]).tolist()
        [1, 3]
        """
        entity = "SpatialIndex.intersection"
        lo, hi = _boxes(
            np.reshape(_vector(mins, entity, "mins"), (1, 3)),
            np.reshape(_vector(maxs, entity, "maxs"), (1, 3)),
            entity,
        )
        if len(self) == 0:
            return np.zeros(0, dtype=np.int64)
        with self._lock:
            hits, _ = _bulk_query(self._index, "intersects", lo, hi)
        return np.sort(hits)

    def intersection_batch(self, mins: ArrayLike, maxs: ArrayLike) -> tuple[IntArray, IntArray]:
        """All (query, id) hits of Q query boxes: ``(query_index (H,), ids (H,))``, sorted.

        >>> idx = SpatialIndex([7, 8], [[0, 0, 0], [2, 2, 2]], [[1, 1, 1], [3, 3, 3]])
        >>> q, i = idx.intersection_batch([[0, 0, 0], [5, 5, 5], [1, 1, 1]],
        ...                               [[3, 3, 3], [6, 6, 6], [2, 2, 2]])
        >>> q.tolist(), i.tolist()
        ([0, 0, 2, 2], [7, 8, 7, 8])
        """
        lo, hi = _boxes(mins, maxs, "SpatialIndex.intersection_batch")
        if len(self) == 0 or lo.shape[0] == 0:
            return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)
        with self._lock:
            hit_ids, counts = _bulk_query(self._index, "intersects", lo, hi)
        query = np.repeat(np.arange(lo.shape[0], dtype=np.int64), counts)
        order = np.lexsort((hit_ids, query))
        return query[order], hit_ids[order]

    def plane_side(self, plane: Plane, tolerance: float = 0.0) -> NDArray[np.int8]:
        """Side of each stored box (in ``ids`` order): −1, +1, or 0 if it straddles/touches.

        >>> SpatialIndex([1, 2], [[0, 0, 0], [2, 0, 0]], [[1, 1, 1], [3, 1, 1]]).plane_side(
        ...     Plane.x(1.5)).tolist()
        [-1, 1]
        """
        return boxes_plane_side(self._mins, self._maxs, plane, tolerance)

    def straddling(self, plane: Plane, tolerance: float = 0.0) -> IntArray:
        """Sorted ids of the boxes crossing or touching ``plane`` (within ``tolerance``).

        >>> SpatialIndex([1, 2], [[0, 0, 0], [2, 0, 0]], [[1, 1, 1], [3, 1, 1]]).straddling(
        ...     Plane.x(1)).tolist()
        [1]
        """
        return np.sort(self._ids[self.plane_side(plane, tolerance) == 0])

    def nearest(self, points: ArrayLike, k: int = 1) -> IntArray:
        """Ids (Q, k) of the k boxes nearest each point, nearest first (ties: smaller id first).

        A point inside a box is at distance 0 from it.

        >>> idx = SpatialIndex([1, 2, 3], [[0, 0, 0], [5, 0, 0], [9, 0, 0]],
        ...                    [[1, 1, 1], [6, 1, 1], [10, 1, 1]])
        >>> idx.nearest([[6, 0, 0], [-1, 0, 0]], k=2).tolist()
        [[2, 3], [1, 2]]
        """
        entity = "SpatialIndex.nearest"
        try:
            pts = np.asarray(points, dtype=np.float64)
        except (TypeError, ValueError) as exc:
            raise EntityValidationError(entity, "points", f"not a numeric array: {exc}") from exc
        if pts.ndim != 2 or pts.shape[1] != 3:
            raise EntityValidationError(entity, "points", f"expected shape (Q, 3), got {pts.shape}")
        if not np.isfinite(pts).all():
            raise EntityValidationError(entity, "points", "contains NaN or infinite values")
        if isinstance(k, bool) or not isinstance(k, int | np.integer):
            raise EntityValidationError(entity, "k", f"expected an int, got {k!r}")
        if not 1 <= k <= len(self):
            raise EntityValidationError(
                entity, "k", f"must be between 1 and the number of boxes ({len(self)}), got {k}"
            )
        k = int(k)
        if pts.shape[0] == 0:
            return np.zeros((0, k), dtype=np.int64)
        with self._lock:
            # Non-strict: every box tied with the k-th nearest comes back, so the choice
            # among ties is made below, deterministically, not by the tree traversal.
            hit_ids, counts64 = _bulk_query(self._index, "nearest", pts, pts, k)
        if (counts64 < k).any():
            raise RuntimeError(f"rtree returned fewer than k={k} neighbours for some points")
        query = np.repeat(np.arange(pts.shape[0], dtype=np.int64), counts64)
        rows = self._rows(hit_ids)
        p = pts[query]
        gap = np.maximum(np.maximum(self._mins[rows] - p, p - self._maxs[rows]), 0.0)
        dist2 = np.einsum("ij,ij->i", gap, gap)
        order = np.lexsort((hit_ids, dist2, query))
        starts = np.concatenate(([0], np.cumsum(counts64)[:-1]))
        rank = np.arange(order.shape[0], dtype=np.int64) - np.repeat(starts, counts64)
        return np.asarray(hit_ids[order][rank < k].reshape(pts.shape[0], k), dtype=np.int64)


def _bulk_query(
    index: Any, kind: str, lo: FloatArray, hi: FloatArray, k: int = 0
) -> tuple[IntArray, IntArray]:
    """Hit ids (H,) and hits per query (Q,) of Q boxes: libspatialindex's batch call, in full.

    ``kind`` is ``"intersects"`` or ``"nearest"`` (``k`` neighbours, ties kept). This is what
    rtree's ``Index.intersection_v`` / ``nearest_v`` do, except for the growth of the id buffer:
    rtree 1.4.1 computes the new size as ``2 * len(ids) + counts[i]``, a float under numpy < 2
    (Python int + uint64), which ``ndarray.resize`` rejects as soon as the hits outgrow the first
    buffer (``TypeError: expected a sequence of integers ... got '812.0'``). Sizes here are ints.
    The C function fills whole queries in order while they fit and reports how many it finished
    (``done``) and the hit count of the first one that did not fit, so each retry resumes there.
    """
    from rtree import core  # imported on first use, like rtree.index

    mins = np.ascontiguousarray(lo, dtype=np.float64)
    maxs = np.ascontiguousarray(hi, dtype=np.float64)
    n, d = mins.shape
    if kind == "intersects":
        call = core.rt.Index_Intersects_id_v
        head: tuple[int, ...] = ()
        tail: tuple[None, ...] = ()
    elif kind == "nearest":
        call = core.rt.Index_NearestNeighbors_id_v
        head, tail = (k,), (None,)  # non-strict k (every tie comes back), no distance output
    else:
        raise ValueError(f"unknown bulk query kind {kind!r}")
    ids = np.empty(max(2 * n, n * k, 64), dtype=np.int64)
    counts = np.zeros(n, dtype=np.uint64)
    done = ctypes.c_int64(0)
    first, filled = 0, 0  # first unfinished query, ids written so far
    while True:
        call(
            index.handle,
            *head,
            n - first,
            d,
            ids.shape[0] - filled,
            d,  # row stride, in doubles (C-contiguous (n, d))
            1,  # column stride
            mins[first:].ctypes.data,
            maxs[first:].ctypes.data,
            ids[filled:].ctypes.data,
            counts[first:].ctypes.data,
            *tail,
            ctypes.byref(done),
        )
        finished = int(done.value)
        filled += int(counts[first : first + finished].sum())
        first += finished
        if first == n:
            return ids[:filled], counts.astype(np.int64)
        needed = filled + int(counts[first])  # the query that did not fit, at least
        grown = np.empty(max(2 * ids.shape[0], needed), dtype=np.int64)
        grown[:filled] = ids[:filled]
        ids = grown


def _vector(values: ArrayLike, entity: str, field: str) -> FloatArray:
    try:
        arr = np.asarray(values, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise EntityValidationError(entity, field, f"not a numeric array: {exc}") from exc
    if arr.shape != (3,):
        raise EntityValidationError(entity, field, f"expected shape (3,), got {arr.shape}")
    return arr
