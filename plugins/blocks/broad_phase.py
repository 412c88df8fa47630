"""Candidate pairs of triangles from different groups, by hashing into a uniform grid.

Each triangle's bounding box is entered in every grid cell it overlaps; rows are sorted by
(cell, group), so the partners of a row are the rows of its cell that belong to later groups —
pairs inside one group (triangles of one surface) are never generated. Triangles larger than
three median extents (a coarse boundary surface, a long fan triangle) are first bisected along
their longest edge until every piece is that small: the pieces' boxes hug the triangle, where its
own box would cover — and pair it with — every small triangle around it. Grid cells are half
that size, so a piece reaches at most three cells per axis. Each pair of pieces is reported from
one cell only (the one holding the lower corner of their boxes' overlap), pairs of pieces are
mapped back to their triangles, and only pairs involving bisected triangles need deduplicating.

A coarse grid (cells two thirds of the piece size, at most 192 per axis) first marks the cells
that boxes of two or more groups reach (the lowest and the highest group reaching a cell differ):
triangles — and pieces of bisected ones — that reach none of them cannot meet another group and
are dropped early. Most of a large surface lies far from the others, so only the neighbourhood of
contacts goes through the fine grid.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from geobrep.plugins.blocks.csr import concatenated_ranges

__all__ = ["bisect_to_size", "overlapping_pairs"]

IntArray = NDArray[np.int64]
FloatArray = NDArray[np.float64]

BoolArray = NDArray[np.bool_]

#: Largest piece (bisection limit), in median triangle extents, and grid cells per piece size.
_CELL_FACTOR = 3.0
_SPLIT = 2
#: Bisection rounds between two calls of the ``keep`` filter (pieces grow up to 2**k times).
_KEEP_EVERY = 3
#: Coarse cell size, in piece sizes, and the most coarse cells along an axis.
_COARSE_FACTOR = 2.0 / 3.0
_COARSE_CELLS = 192


def _boxes(corners: FloatArray, margin: float) -> tuple[FloatArray, FloatArray]:
    a, b, c = corners[:, 0], corners[:, 1], corners[:, 2]
    return np.minimum(np.minimum(a, b), c) - margin, np.maximum(np.maximum(a, b), c) + margin


class _Crowding:
    """Coarse cells reached by the boxes of two or more groups (a dense grid)."""

    def __init__(self, origin: FloatArray, size: float, top: FloatArray) -> None:
        self.origin, self.size = origin, size
        self.dims = np.floor((top - origin) / size).astype(np.int64) + 1
        self.strides = np.array([self.dims[1] * self.dims[2], self.dims[2], 1], dtype=np.int64)
        self.crowded = np.zeros(int(np.prod(self.dims)), dtype=np.bool_)

    def _cells(self, mins: FloatArray, maxs: FloatArray) -> tuple[IntArray, IntArray]:
        """Rows (box, coarse cell key) of every coarse cell each box reaches."""
        lo = np.maximum(np.floor((mins - self.origin) / self.size).astype(np.int64), 0)
        hi = np.minimum(np.floor((maxs - self.origin) / self.size).astype(np.int64), self.dims - 1)
        base = lo @ self.strides
        sizes = hi - lo + 1
        counts = sizes[:, 0] * sizes[:, 1] * sizes[:, 2]
        single = counts == 1  # most boxes lie in one coarse cell
        spread = np.flatnonzero(~single)
        if spread.size == 0:
            return np.arange(mins.shape[0], dtype=np.int64), base
        sizes, counts = sizes[spread], counts[spread]
        box = np.repeat(spread, counts)
        k = concatenated_ranges(np.zeros(spread.shape[0], np.int64), counts)
        sx, sy = np.repeat(sizes[:, 1] * sizes[:, 2], counts), np.repeat(sizes[:, 2], counts)
        key = base[box] + (k // sx) * self.strides[0] + ((k % sx) // sy) * self.strides[1] + k % sy
        alone = np.flatnonzero(single)
        return np.concatenate([alone, box]), np.concatenate([base[alone], key])

    def mark(self, mins: FloatArray, maxs: FloatArray, groups: IntArray) -> BoolArray:
        """Mark the cells two or more groups reach; return which boxes reach one of them."""
        box, key = self._cells(mins, maxs)
        group = groups[box]
        n_cells = self.crowded.shape[0]
        lowest = np.full(n_cells, np.iinfo(np.int64).max, dtype=np.int64)
        highest = np.full(n_cells, -1, dtype=np.int64)
        np.minimum.at(lowest, key, group)
        np.maximum.at(highest, key, group)
        self.crowded = lowest < highest
        return self._reached(box, key, mins.shape[0])

    def _reached(self, box: IntArray, key: IntArray, n: int) -> BoolArray:
        hits = np.zeros(n, dtype=np.bool_)
        hits[box[self.crowded[key]]] = True
        return hits

    def near(self, mins: FloatArray, maxs: FloatArray) -> BoolArray:
        """Which boxes reach a crowded cell."""
        box, key = self._cells(mins, maxs)
        return self._reached(box, key, mins.shape[0])


def _extent(corners: FloatArray) -> FloatArray:
    """Largest side of each triangle's bounding box."""
    a, b, c = corners[:, 0], corners[:, 1], corners[:, 2]
    size = np.maximum(np.maximum(a, b), c) - np.minimum(np.minimum(a, b), c)
    return np.asarray(np.maximum(np.maximum(size[:, 0], size[:, 1]), size[:, 2]))


def bisect_to_size(
    corners: FloatArray,
    limit: float,
    keep: Callable[[FloatArray, IntArray], BoolArray] | None = None,
) -> tuple[FloatArray, IntArray]:
    """Split triangles along their longest edge until every piece's box is at most ``limit``.

    Returns the pieces (M, 3, 3) and the triangle each comes from; the pieces of a triangle
    cover it exactly, except those ``keep(pieces, parents)`` rejects along the way (asked every
    few rounds, when the pieces have multiplied).

    >>> import numpy as np
    >>> pieces, parent = bisect_to_size(np.array([[[0, 0, 0], [4, 0, 0], [0, 1, 0]]], float), 1.0)
    >>> bool(np.all(parent == 0)), bool(np.all(np.ptp(pieces, axis=1) <= 1.0)), len(pieces) > 4
    (True, True, True)
    """
    parent = np.arange(corners.shape[0], dtype=np.int64)
    done_pieces, done_parents = [corners[:0]], [parent[:0]]
    pieces = corners
    rounds = 0
    while pieces.shape[0]:
        large = _extent(pieces) > limit
        done_pieces.append(pieces[~large])
        done_parents.append(parent[~large])
        pieces, parent = pieces[large], parent[large]
        if not pieces.shape[0]:
            break
        lengths = np.stack(
            [
                np.einsum("ij,ij->i", d, d)
                for d in (pieces[:, (k + 1) % 3] - pieces[:, k] for k in range(3))
            ],
            axis=1,
        )
        k = np.argmax(lengths, axis=1)
        rows = np.arange(pieces.shape[0])
        a, b, c = pieces[rows, k], pieces[rows, (k + 1) % 3], pieces[rows, (k + 2) % 3]
        middle = 0.5 * (a + b)
        pieces = np.concatenate(
            [np.stack([a, middle, c], axis=1), np.stack([middle, b, c], axis=1)]
        )
        parent = np.concatenate([parent, parent])
        rounds += 1
        if keep is not None and rounds % _KEEP_EVERY == 0:
            wanted = keep(pieces, parent)
            pieces, parent = pieces[wanted], parent[wanted]
    return np.concatenate(done_pieces), np.concatenate(done_parents)


def overlapping_pairs(
    corners: FloatArray, groups: IntArray, margin: float = 0.0, cell: float | None = None
) -> tuple[IntArray, IntArray]:
    """Pairs ``(i, j)``, ``groups[i] < groups[j]``, of triangles ``corners`` (K, 3, 3) that may
    lie within ``margin`` of each other (their pieces' boxes, grown by ``margin``, overlap).

    A point is a triangle with three equal corners. Each pair is listed once, in no set order.

    >>> import numpy as np
    >>> flat = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]
    >>> corners = np.array([flat, np.add(flat, [0.5, 0.5, 0]), np.add(flat, 3.0)], dtype=float)
    >>> i, j = overlapping_pairs(corners, np.array([0, 1, 1]))
    >>> i.tolist(), j.tolist()
    ([0], [1])
    """
    n = corners.shape[0]
    empty = np.zeros(0, dtype=np.int64)
    if n == 0:
        return empty, empty
    mins, maxs = _boxes(corners, margin)
    size = maxs - mins
    extent = np.maximum(np.maximum(size[:, 0], size[:, 1]), size[:, 2]) - 2.0 * margin
    if cell is None:
        cell = _CELL_FACTOR * float(np.median(extent))
    origin = mins.min(axis=0)
    top = maxs.max(axis=0)
    span = float((top - origin).max())
    cell = max(cell, 4.0 * margin, span / 2.0**20, np.finfo(np.float64).tiny)
    crowding = _Crowding(origin, max(_COARSE_FACTOR * cell, span / _COARSE_CELLS), top)
    candidates = np.flatnonzero(crowding.mark(mins, maxs, groups))
    limit = cell - 2.0 * margin
    large = extent[candidates] > limit
    small, big = candidates[~large], candidates[large]

    def near(pieces: FloatArray, parent: IntArray) -> BoolArray:
        return crowding.near(*_boxes(pieces, margin))

    pieces, big_parent = bisect_to_size(corners[big], limit, near)
    piece_mins, piece_maxs = _boxes(pieces, margin)
    parent = np.concatenate([small, big[big_parent]])
    if parent.size == 0:
        return empty, empty
    mins = np.concatenate([mins[small], piece_mins])
    maxs = np.concatenate([maxs[small], piece_maxs])
    n_whole = small.shape[0]  # pieces from n_whole on come from bisected triangles
    piece_groups = groups[parent]
    if np.any(piece_groups[1:] < piece_groups[:-1]):
        order = np.argsort(piece_groups, kind="stable")
        mins, maxs, parent = mins[order], maxs[order], parent[order]
        piece_groups = piece_groups[order]
        whole = order < n_whole
    else:
        whole = np.arange(parent.shape[0]) < n_whole
    m = parent.shape[0]
    # Grid cells a _SPLIT-th of a piece's largest size: a piece reaches at most _SPLIT + 1 cells
    # per axis; a cell's offset code has bit 4 set when it lies past the piece's first cell
    # along x, 2 along y, 1 along z.
    grid = cell / _SPLIT
    lo = np.floor((mins - origin) / grid).astype(np.int64)
    hi = np.floor((maxs - origin) / grid).astype(np.int64)
    dims = hi.max(axis=0) + 1
    strides = np.array([dims[1] * dims[2], dims[2], 1], dtype=np.int64)
    width = _SPLIT + 1
    offsets = np.arange(width**3, dtype=np.int64)
    dx, dy, dz = offsets // (width * width), (offsets // width) % width, offsets % width
    span = hi - lo
    reached = (dx <= span[:, 0:1]) & (dy <= span[:, 1:2]) & (dz <= span[:, 2:3])
    rows = np.flatnonzero(reached.reshape(-1))
    piece, offset = rows // width**3, rows % width**3
    key = (lo @ strides)[piece] + (dx * strides[0] + dy * strides[1] + dz)[offset]
    code = (4 * (dx > 0) + 2 * (dy > 0) + (dz > 0)).astype(np.int64)[offset]
    # Pieces are in group order: sorting by (cell, piece) keeps each cell's rows by group.
    if int(key.max()) < (2**62) // (8 * m):
        packed = np.sort((key * m + piece) * 8 + code)
        code, packed = packed % 8, packed // 8
        key, piece = packed // m, packed % m
    else:
        order = np.lexsort((piece, key))
        key, piece, code = key[order], piece[order], code[order]
    group = piece_groups[piece]
    n_rows = key.shape[0]
    new_cell = np.ones(n_rows, dtype=np.bool_)
    new_cell[1:] = key[1:] != key[:-1]
    new_block = new_cell.copy()
    new_block[1:] |= group[1:] != group[:-1]
    cell_end = np.append(np.flatnonzero(new_cell)[1:], n_rows)[np.cumsum(new_cell) - 1]
    block_end = np.append(np.flatnonzero(new_block)[1:], n_rows)[np.cumsum(new_block) - 1]
    partners = cell_end - block_end
    first_row = np.repeat(np.arange(n_rows, dtype=np.int64), partners)
    second_row = concatenated_ranges(block_end, partners)
    # Both pieces hold this cell; it is the lower corner of their boxes' overlap unless both
    # reached it by stepping up along some axis (their offset codes share a bit).
    canonical = np.flatnonzero((code[first_row] & code[second_row]) == 0)
    first, second = piece[first_row[canonical]], piece[second_row[canonical]]
    keep = np.ones(first.shape[0], dtype=np.bool_)
    for k in range(3):
        low, high = mins[:, k], maxs[:, k]
        keep &= (low[first] <= high[second]) & (low[second] <= high[first])
    first, second = first[keep], second[keep]
    # Pairs of whole triangles come once; pieces of bisected ones may repeat a pair.
    once = whole[first] & whole[second]
    i, j = parent[first[once]], parent[second[once]]
    again = ~once
    if again.any():
        unique = np.unique(parent[first[again]] * n + parent[second[again]])
        i = np.concatenate([i, unique // n])
        j = np.concatenate([j, unique % n])
    return i.astype(np.int64), j.astype(np.int64)
