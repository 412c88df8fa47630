"""Closed loops from directed edges: successor choice at pinch points and cycle ordering.

The cut of a closed surface leaves boundary edges on the plane that form closed loops. Each edge's
successor is the edge leaving its end vertex; where several leave one vertex (loops touching at a
point) the successor is the one turning most to the left, so touching loops come out as separate
simple loops. Cycles are then ordered with pointer jumping (log₂ of the longest loop passes), not
one Python step per edge.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from geobrep.errors import DegenerateGeometryError
from geobrep.geometry.arrays import FloatArray, IntArray

__all__ = ["edge_successors", "order_cycles", "order_paths"]


def edge_successors(edges: IntArray, uv: FloatArray, what: str) -> IntArray:
    """For directed ``edges`` (E, 2) over 2D points ``uv``: the index of each edge's successor.

    Raises:
        DegenerateGeometryError: a vertex has more edges arriving than leaving (the edges do not
            form closed loops), naming ``what``.
    """
    count = edges.shape[0]
    if count == 0:
        return np.zeros(0, dtype=np.int64)
    starts, ends = edges[:, 0], edges[:, 1]
    order = np.argsort(starts, kind="stable").astype(np.int64)
    sorted_starts = starts[order]
    first = np.searchsorted(sorted_starts, ends, side="left")
    last = np.searchsorted(sorted_starts, ends, side="right")
    leaving = last - first
    if (leaving == 0).any() or not np.array_equal(
        np.bincount(starts, minlength=int(edges.max()) + 1),
        np.bincount(ends, minlength=int(edges.max()) + 1),
    ):
        bad = int(np.argmax(leaving == 0)) if (leaving == 0).any() else 0
        raise DegenerateGeometryError(
            f"{what}: the cut does not form closed loops (edge {edges[bad].tolist()} has no "
            "successor): is the surface closed?"
        )
    successor: IntArray = order[np.minimum(first, count - 1)]
    for edge in np.flatnonzero(leaving > 1).tolist():
        candidates = order[first[edge] : last[edge]]
        incoming = uv[ends[edge]] - uv[starts[edge]]
        outgoing = uv[ends[candidates]] - uv[starts[candidates]]
        turn = np.arctan2(
            incoming[0] * outgoing[:, 1] - incoming[1] * outgoing[:, 0],
            incoming @ outgoing.T,
        )
        successor[edge] = candidates[int(np.argmax(turn))]
    if np.bincount(successor, minlength=count).max() > 1:
        _pair_pinches(edges, uv, successor, leaving > 1)
    return successor


def _pair_pinches(
    edges: IntArray, uv: FloatArray, successor: IntArray, pinched: NDArray[np.bool_]
) -> None:
    """Make ``successor`` a permutation at pinch vertices: leftmost turns, each edge used once."""
    for vertex in np.unique(edges[pinched, 1]).tolist():
        arriving = np.flatnonzero(edges[:, 1] == vertex)
        leaving = np.flatnonzero(edges[:, 0] == vertex)
        free = set(leaving.tolist())
        # Pair each arriving edge with the leftmost free leaving edge, sharpest turns first.
        choices = []
        for edge in arriving.tolist():
            incoming = uv[vertex] - uv[edges[edge, 0]]
            for candidate in leaving.tolist():
                outgoing = uv[edges[candidate, 1]] - uv[vertex]
                turn = float(
                    np.arctan2(
                        incoming[0] * outgoing[1] - incoming[1] * outgoing[0],
                        incoming @ outgoing,
                    )
                )
                choices.append((-turn, edge, candidate))
        choices.sort()
        paired: set[int] = set()
        for _, edge, candidate in choices:
            if edge in paired or candidate not in free:
                continue
            successor[edge] = candidate
            paired.add(edge)
            free.discard(candidate)


def order_cycles(successor: IntArray, keys: IntArray) -> tuple[IntArray, IntArray]:
    """The cycles of the permutation ``successor``: ``(order, offsets)``.

    Cycle ``c`` is ``order[offsets[c]:offsets[c + 1]]``; each cycle starts at its element with the
    smallest ``keys`` value and cycles come in increasing order of that value, so the result does
    not depend on how the edges were numbered.

    >>> order, offsets = order_cycles(np.array([1, 2, 0, 4, 3]), np.array([5, 3, 4, 1, 2]))
    >>> order.tolist(), offsets.tolist()
    ([3, 4, 1, 2, 0], [0, 2, 5])
    """
    count = successor.shape[0]
    if count == 0:
        return np.zeros(0, dtype=np.int64), np.zeros(1, dtype=np.int64)
    rank_key = np.empty(count, dtype=np.int64)
    rank_key[np.argsort(keys, kind="stable")] = np.arange(count, dtype=np.int64)
    label = rank_key.copy()
    jump = successor.copy()
    steps = max(1, int(np.ceil(np.log2(count))) + 1)
    for _ in range(steps):
        label = np.minimum(label, label[jump])
        jump = jump[jump]
    # Distance of every element from its cycle's first element (list ranking, Wyllie).
    is_root = label == rank_key
    distance = np.where(is_root, 0, 1).astype(np.int64)
    ahead = np.where(is_root, np.arange(count), _predecessors(successor))
    for _ in range(steps):
        distance = distance + np.where(ahead != np.arange(count), distance[ahead], 0)
        ahead = ahead[ahead]
    sort_key = label * count + distance
    order = np.argsort(sort_key, kind="stable").astype(np.int64)
    cycle_label = label[order]
    starts = np.flatnonzero(np.concatenate([[True], cycle_label[1:] != cycle_label[:-1]]))
    offsets = np.append(starts, count).astype(np.int64)
    return order, offsets


def _predecessors(successor: IntArray) -> IntArray:
    previous = np.empty_like(successor)
    previous[successor] = np.arange(successor.shape[0], dtype=np.int64)
    return previous


def order_paths(edges: IntArray) -> tuple[IntArray, IntArray, NDArray[np.bool_]]:
    """Directed edges (E, 2) joined head to tail into open chains and closed loops.

    Returns ``(order, offsets, closed)``: path ``p`` is ``edges[order[offsets[p]:offsets[p+1]]]``
    and ``closed[p]`` tells whether it returns to its start. A vertex where paths meet or branch
    ends them. Chains come first, each from its first edge.

    >>> order, offsets, closed = order_paths(np.array([[2, 3], [0, 1], [1, 2], [5, 6], [6, 5]]))
    >>> order.tolist(), offsets.tolist(), closed.tolist()
    ([1, 2, 0, 3, 4], [0, 3, 5], [False, True])
    """
    count = edges.shape[0]
    if count == 0:
        return np.zeros(0, dtype=np.int64), np.zeros(1, dtype=np.int64), np.zeros(0, np.bool_)
    starts, ends = edges[:, 0], edges[:, 1]
    size = int(edges.max()) + 1
    out_count = np.bincount(starts, minlength=size)
    in_count = np.bincount(ends, minlength=size)
    leaving = np.full(size, -1, dtype=np.int64)
    leaving[starts] = np.arange(count, dtype=np.int64)
    through = (out_count[ends] == 1) & (in_count[ends] == 1)
    successor = np.where(through, leaving[ends], -1)
    has_predecessor = np.zeros(count, dtype=np.bool_)
    has_predecessor[successor[successor >= 0]] = True
    heads = np.flatnonzero(~has_predecessor)
    jump = np.where(successor >= 0, successor, np.arange(count, dtype=np.int64))
    for _ in range(int(np.ceil(np.log2(count))) + 1):
        jump = jump[jump]
    linked = successor.copy()
    linked[jump[heads]] = heads
    keys = np.where(has_predecessor, count, 0) + np.arange(count, dtype=np.int64)
    order, offsets = order_cycles(linked, keys)
    closed = has_predecessor[order[offsets[:-1]]]
    return order, offsets, closed
