"""Graph and neighbour kernels in plain numpy: connected components, close point pairs, paths.

They replace scipy's ``csgraph`` and ``cKDTree`` on the read path, so reading a file does not
import scipy (about half a second in a fresh process). Each is vectorised: a number of
whole-array passes that grows with the logarithm of the input, never a Python loop per node.

* :func:`component_roots`: connected components by hooking and pointer jumping, each node
  labelled by the lowest node of its component.
* :func:`close_pairs` / :func:`nearest_within`: point pairs within a distance, found in a hashed
  grid of cubes as wide as the distance (the 27 cubes around a point hold every point that
  close to it); hash collisions only add candidates, which the exact distance test drops.
* :func:`path_order`: the nodes of paths (each node linked to at most two others) in order
  from a given end, by list ranking.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from geobrep.errors import TopologyError
from geobrep.geometry.arrays import FloatArray, IntArray

__all__ = [
    "cell_hash",
    "close_pairs",
    "component_roots",
    "equal_rows",
    "hashed_order",
    "nearest_within",
    "path_order",
]

_HASH = (
    np.uint64(0x9E3779B97F4A7C15),
    np.uint64(0xC2B2AE3D27D4EB4F),
    np.uint64(0x165667B19E3779F9),
)
_MIX = (np.uint64(0xBF58476D1CE4E5B9), np.uint64(0x94D049BB133111EB))
#: Above this many candidate pairs per point (and a floor), a crowd of points closer than the
#: distance makes the grid search quadratic: callers are told (None) and use another way.
_PAIRS_PER_POINT = 64
_PAIRS_FLOOR = 1_000_000


def component_roots(n: int, a: ArrayLike, b: ArrayLike) -> IntArray:
    """The lowest node of the component of each of the nodes ``0 … n-1`` joined by the edges
    ``(a[i], b[i])``.

    Every round hooks each root onto the lowest root it has an edge to and then jumps every
    pointer to its root; a component that has an edge to another merges in every round, so
    the rounds are logarithmic in the component sizes.

    >>> component_roots(5, [3, 1], [4, 3]).tolist()
    [0, 1, 2, 1, 1]
    """
    parent = np.arange(n, dtype=np.int64)
    lo = np.asarray(a, dtype=np.int64).reshape(-1)
    hi = np.asarray(b, dtype=np.int64).reshape(-1)
    while lo.size:
        pa, pb = parent[lo], parent[hi]
        differ = pa != pb
        if not differ.all():
            lo, hi, pa, pb = lo[differ], hi[differ], pa[differ], pb[differ]
            if not lo.size:
                break
        # roots: hook the higher root under the lowest root it meets (no cycles: parents
        # only decrease), then point every node at its root
        np.minimum.at(parent, np.maximum(pa, pb), np.minimum(pa, pb))
        while True:
            grand = parent[parent]
            if np.array_equal(grand, parent):
                break
            parent = grand
    return parent


def cell_hash(cubes: IntArray) -> IntArray:
    """A 64-bit hash of integer cell coordinates (N, 3), as int64 for sorting: equal cells,
    equal hashes (unequal cells share one rarely, which callers must tolerate).

    The coordinates are combined linearly with three odd 64-bit constants (two cells collide
    only when their difference is a multiple of 2^64 along that combination, never for nearby
    cells of a lattice) and the sum is mixed by splitmix64's finaliser, a bijection that
    spreads every input bit over the high bits :func:`hashed_order` keeps."""
    with np.errstate(over="ignore"):
        u = cubes.astype(np.uint64)
        key = u[:, 0] * _HASH[0]
        key += u[:, 1] * _HASH[1]
        key += u[:, 2] * _HASH[2]
        key ^= key >> np.uint64(30)
        key *= _MIX[0]
        key ^= key >> np.uint64(27)
        key *= _MIX[1]
        key ^= key >> np.uint64(31)
    hashed: IntArray = key.view(np.int64)
    return hashed


def hashed_order(keys: IntArray) -> tuple[IntArray, IntArray]:
    """``(order, sorted_keys)``: the positions of the hash ``keys`` sorted by their high bits,
    equal keys in index order, by one plain ``np.sort`` (several times faster than a stable
    ``argsort``): each key's low ``bits`` (enough to number the keys) are replaced by its index.
    ``sorted_keys`` are the high bits, ascending (``keys >> bits`` sorted): callers compare
    and search them, never the full keys, so two keys differing only in their low bits count
    as equal — one more rare collision for callers that tolerate them.

    >>> order, high = hashed_order(np.array([5 << 40, 3 << 40, 5 << 40]))
    >>> order.tolist(), (high >> 38).tolist()
    ([1, 0, 2], [3, 5, 5])
    """
    n = keys.shape[0]
    bits = max((n - 1).bit_length(), 1)
    mask = (1 << bits) - 1
    packed = np.sort((keys & ~mask) | np.arange(n, dtype=np.int64))
    return packed & mask, packed >> bits


def _ranges(sorted_keys: IntArray, wanted: IntArray) -> tuple[IntArray, IntArray]:
    """Where each wanted key's run starts and ends in ``sorted_keys``: the needles are sorted
    first, which makes the binary searches walk the keys in order (several times faster than
    random needles on large arrays)."""
    order = np.argsort(wanted)
    needles = wanted[order]
    lo, hi = np.empty_like(order), np.empty_like(order)
    lo[order] = np.searchsorted(sorted_keys, needles, side="left")
    hi[order] = np.searchsorted(sorted_keys, needles, side="right")
    return lo, hi


def _offsets(half: bool) -> IntArray:
    """The 27 cube offsets around a cube, or the 14 that see every pair once (itself first)."""
    grid = np.stack(np.meshgrid(*[np.arange(-1, 2)] * 3, indexing="ij"), axis=-1).reshape(-1, 3)
    if not half:
        return grid.astype(np.int64)
    code = grid[:, 0] * 9 + grid[:, 1] * 3 + grid[:, 2]
    return grid[code >= 0][np.argsort(code[code >= 0])].astype(np.int64)


def _grid_candidates(
    points: FloatArray, queries: FloatArray | None, distance: float
) -> tuple[IntArray, IntArray] | None:
    """Candidate pairs ``(query, point)`` sharing or touching a cube of side ``distance``
    (``queries`` None: pairs of ``points`` with the first index lower); None when there are
    too many or the cubes cannot be numbered."""
    n = points.shape[0]
    same = queries is None
    q = points if queries is None else queries
    scale = 1.0 / distance
    cubes_p = np.floor(points * scale)
    cubes_q = cubes_p if same else np.floor(q * scale)
    if not (np.isfinite(cubes_p).all() and np.isfinite(cubes_q).all()):
        return None
    if max(np.abs(cubes_p).max(initial=0.0), np.abs(cubes_q).max(initial=0.0)) > 2.0**62:
        return None
    cp, cq = cubes_p.astype(np.int64), cubes_q.astype(np.int64)
    order, sorted_keys = hashed_order(cell_hash(cp))
    bits = max((n - 1).bit_length(), 1)
    limit = max(_PAIRS_FLOOR, _PAIRS_PER_POINT * (n + q.shape[0]))
    left: list[IntArray] = []
    right: list[IntArray] = []
    total = 0
    for offset in _offsets(same):  # with ``same``, the cube itself first
        wanted = cell_hash(cq + offset) >> bits  # the high bits, as hashed_order keeps them
        lo, hi = _ranges(sorted_keys, wanted)
        counts = hi - lo
        total += int(counts.sum())
        if total > limit:
            return None
        rows = np.flatnonzero(counts)
        c = counts[rows]
        owner = np.repeat(rows, c)
        within = np.arange(owner.shape[0], dtype=np.int64) - np.repeat(np.cumsum(c) - c, c)
        left.append(owner)
        right.append(order[np.repeat(lo[rows], c) + within])
    if not same:
        return np.concatenate(left), np.concatenate(right)
    # a pair in one cube comes both ways; across cubes once, either way round
    i, j = np.concatenate(left[1:]), np.concatenate(right[1:])
    i, j = np.minimum(i, j), np.maximum(i, j)
    i0, j0 = left[0], right[0]
    keep = i0 < j0
    i, j = np.concatenate([i0[keep], i]), np.concatenate([j0[keep], j])
    distinct = i != j
    return i[distinct], j[distinct]


def _within(
    points: FloatArray, queries: FloatArray, i: IntArray, j: IntArray, distance: float
) -> tuple[IntArray, IntArray, FloatArray]:
    d = queries[i] - points[j]
    squared = np.einsum("ij,ij->i", d, d)
    keep = squared <= distance * distance
    return i[keep], j[keep], squared[keep]


def _exact_pairs(points: FloatArray) -> IntArray:
    """Pairs ``(i, j)``, ``i < j``, of equal points (each later copy with the first)."""
    _, first, inverse = np.unique(
        points + 0.0, axis=0, return_index=True, return_inverse=True
    )  # + 0.0 folds -0.0 onto 0.0
    inverse = inverse.reshape(-1)
    lowest = first[inverse]
    later = np.flatnonzero(lowest != np.arange(points.shape[0]))
    return np.stack([lowest[later], later], axis=1).astype(np.int64)


def equal_rows(points: FloatArray) -> IntArray:
    """For each point (N, 3), the lowest index of a point with the same coordinates (``-0.0``
    equal to ``0.0``) found by one sort of a hash of the coordinates: two equal points get the
    same index, except in the rare case where an unequal point's hash equals theirs and sorts
    between them (a caller that searches close pairs afterwards still joins them).

    >>> equal_rows(np.array([[0.0, 0, 0], [1, 0, 0], [-0.0, 0, 0]])).tolist()
    [0, 1, 0]
    """
    n = points.shape[0]
    if n == 0:
        return np.zeros(0, dtype=np.int64)
    bits = np.ascontiguousarray(points + 0.0).view(np.int64)
    order, high = hashed_order(cell_hash(bits))  # equal points in index order
    same = np.zeros(n, dtype=np.bool_)
    same[1:] = high[1:] == high[:-1]
    # Equal hashes are rare but for equal points: compare the coordinates of those only.
    later = np.flatnonzero(same)
    one, other = np.take(order, later), np.take(order, later - 1)
    same[later] = (bits[one] == bits[other]).all(axis=1)
    run_start = np.maximum.accumulate(np.where(same, 0, np.arange(n, dtype=np.int64)))
    first = np.empty(n, dtype=np.int64)
    first[order] = order[run_start]
    return first


def close_pairs(points: ArrayLike, distance: float) -> IntArray | None:
    """Pairs ``(i, j)``, ``i < j``, of the points (N, 3) at most ``distance`` apart (M, 2);
    ``distance=0`` pairs equal points with their first copy only.

    None when a crowd of points closer than ``distance`` would make more than about 64
    candidate pairs per point: the caller then uses a search that bounds its work otherwise.

    >>> close_pairs([[0, 0, 0], [5, 0, 0], [0, 0, 1e-9]], 1e-6).tolist()
    [[0, 2]]
    """
    p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    if distance == 0.0 or p.shape[0] < 2:
        return _exact_pairs(p) if p.shape[0] else np.zeros((0, 2), dtype=np.int64)
    found = _grid_candidates(p, None, distance)
    if found is None:
        return None
    i, j, _ = _within(p, p, *found, distance)
    return np.stack([i, j], axis=1).astype(np.int64)


def nearest_within(points: ArrayLike, queries: ArrayLike, distance: float) -> IntArray | None:
    """For each query point (K, 3): the index of the nearest of ``points`` (N, 3) at most
    ``distance`` away (the lowest index among equally near), or -1. None as for
    :func:`close_pairs`.

    >>> nearest_within([[0, 0, 0], [1, 0, 0]], [[0.9, 0, 0], [5, 5, 5]], 0.5).tolist()
    [1, -1]
    """
    p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    q = np.asarray(queries, dtype=np.float64).reshape(-1, 3)
    nearest = np.full(q.shape[0], -1, dtype=np.int64)
    if not p.shape[0] or not q.shape[0]:
        return nearest
    if distance == 0.0:
        both = np.concatenate([p, q])
        pairs = _exact_pairs(both)
        hit = (pairs[:, 0] < p.shape[0]) & (pairs[:, 1] >= p.shape[0])
        nearest[pairs[hit, 1] - p.shape[0]] = pairs[hit, 0]
        return nearest
    found = _grid_candidates(p, q, distance)
    if found is None:
        return None
    i, j, squared = _within(p, q, *found, distance)
    order = np.lexsort((j, squared, i))
    first = np.ones(order.shape[0], dtype=np.bool_)
    first[1:] = i[order][1:] != i[order][:-1]
    nearest[i[order][first]] = j[order][first]
    return nearest


def path_order(n: int, a: ArrayLike, b: ArrayLike, heads: ArrayLike) -> IntArray:
    """The nodes of the paths through ``heads``, path after path (in the order of ``heads``),
    each from its head.

    Nodes ``0 … n-1`` are joined by the links ``(a[i], b[i])``; every node has at most two
    links and every head, an end of its path, at most one. A node on no head's path is left
    out. :class:`~geobrep.errors.TopologyError` when the links do not form such paths.

    List ranking: each link taken both ways is a step, whose successor is the step out of its
    target that does not come back; pointer jumping gives every step its distance to the end
    of its path and that end, in a logarithmic number of rounds.

    >>> path_order(5, [0, 1, 3], [1, 2, 4], [2, 4]).tolist()
    [2, 1, 0, 4, 3]
    """
    src0 = np.asarray(a, dtype=np.int64).reshape(-1)
    dst0 = np.asarray(b, dtype=np.int64).reshape(-1)
    head = np.asarray(heads, dtype=np.int64).reshape(-1)
    src, dst = np.concatenate([src0, dst0]), np.concatenate([dst0, src0])
    n_steps = src.shape[0]
    degree = np.bincount(src, minlength=n)
    if n_steps and int(degree.max()) > 2:
        raise TopologyError("path order: a node has more than two links")
    if head.size and int(degree[head].max(initial=0)) > 1:
        raise TopologyError("path order: a head is not the end of its path")
    # the steps out of each node (two columns, -1 when absent)
    order = np.argsort(src, kind="stable")
    out = np.full((n, 2), -1, dtype=np.int64)
    starts = np.cumsum(degree) - degree
    slot = np.arange(n_steps, dtype=np.int64) - starts[src[order]]
    out[src[order], slot] = order
    # successor of step s (x -> y): the step out of y that does not go back to x
    candidates = out[dst]  # (S, 2)
    forward = (candidates >= 0) & (dst[np.maximum(candidates, 0)] != src[:, None])
    succ = np.where(forward[:, 0], candidates[:, 0], np.where(forward[:, 1], candidates[:, 1], -1))
    distance = (succ >= 0).astype(np.int64)
    last = np.where(succ >= 0, succ, np.arange(n_steps, dtype=np.int64))
    jump = succ.copy()
    for _ in range(2 + max(n_steps, 1).bit_length()):
        active = np.flatnonzero(jump >= 0)
        if not active.size:
            break
        target = jump[active]
        distance[active] += distance[target]
        last[active] = last[target]
        jump[active] = jump[target]
    if (jump >= 0).any():
        raise TopologyError("path order: the links close a loop")
    first_step = out[head, 0]  # -1: a path of one node
    path_of_end = np.full(n_steps, -1, dtype=np.int64)
    with_steps = np.flatnonzero(first_step >= 0)
    path_of_end[last[first_step[with_steps]]] = with_steps
    lengths = np.ones(head.shape[0], dtype=np.int64)
    lengths[with_steps] += distance[first_step[with_steps]] + 1
    begin = np.cumsum(lengths) - lengths
    result = np.full(int(lengths.sum()), -1, dtype=np.int64)
    result[begin] = head
    steps = np.flatnonzero(path_of_end[last] >= 0) if n_steps else np.zeros(0, np.int64)
    path = path_of_end[last[steps]]
    position = begin[path] + 1 + distance[first_step[path]] - distance[steps]
    result[position] = dst[steps]
    if (result < 0).any():  # pragma: no cover - every position of a path is filled
        raise TopologyError("path order: the links do not form paths")
    return result
