"""Candidate pairs of triangles from different groups, by hashing into a uniform grid.

Each triangle's bounding box is entered in every grid cell it overlaps; rows are sorted by
(cell, group), so the partners of a row are the rows of its cell that belong to later groups —
pairs inside one group (triangles of one surface) are never generated. The cell size follows the
triangles' median extent. A triangle larger than a cell (a coarse boundary surface, a long fan
triangle) is first bisected along its longest edge until every piece fits in a cell: the pieces'
boxes hug the triangle, where its own box would cover — and pair it with — every small triangle
around it. Each pair of pieces is reported from one cell only (the one holding the lower corner
of their boxes' overlap), and pairs of pieces are mapped back to their triangles.

A coarse grid (cells three times larger, at most 192 per axis) first marks the cells that boxes
of two or more groups reach: triangles — and pieces of bisected ones — that reach none of them
cannot meet another group and are dropped early. Most of a surface lies far from the others, so
only the neighbourhood of contacts goes through the fine grid.
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

#: Grid cell size, in median triangle extents.
_CELL_FACTOR = 2.0
#: Coarse cell size, in fine cells, and the most coarse cells along an axis.
_COARSE_FACTOR = 3.0
_COARSE_CELLS = 192


def _boxes(corners: FloatArray, margin: float) -> tuple[FloatArray, FloatArray]:
    a, b, c = corners[:, 0], corners[:, 1], corners[:, 2]
    return np.minimum(np.minimum(a, b), c) - margin, np.maximum(np.maximum(a, b), c) + margin


class _Crowding:
    """Coarse cells reached by the boxes of two or more groups (a dense boolean grid)."""

    def __init__(
        self, mins: FloatArray, maxs: FloatArray, groups: IntArray, origin: FloatArray, size: float
    ) -> None:
        self.origin, self.size = origin, size
        top = np.floor((maxs.max(axis=0) - origin) / size).astype(np.int64)
        self.dims = top + 1
        self.strides = np.array([self.dims[1] * self.dims[2], self.dims[2], 1], dtype=np.int64)
        box, key = self._cells(mins, maxs)
        n_groups = int(groups.max()) + 1
        present = np.unique(key * n_groups + groups[box]) // n_groups  # (cell, group) once
        shared = present[1:][present[1:] == present[:-1]]
        self.crowded = np.zeros(int(np.prod(self.dims)), dtype=np.bool_)
        self.crowded[shared] = True

    def _cells(self, mins: FloatArray, maxs: FloatArray) -> tuple[IntArray, IntArray]:
        """Rows (box, coarse cell key) of every coarse cell each box reaches."""
        lo = np.floor((mins - self.origin) / self.size).astype(np.int64)
        hi = np.minimum(np.floor((maxs - self.origin) / self.size).astype(np.int64), self.dims - 1)
        lo = np.maximum(lo, 0)
        sizes = hi - lo + 1
        counts = sizes[:, 0] * sizes[:, 1] * sizes[:, 2]
        box = np.repeat(np.arange(mins.shape[0], dtype=np.int64), counts)
        k = concatenated_ranges(np.zeros(mins.shape[0], np.int64), counts)
        sx, sy = (sizes[:, 1] * sizes[:, 2])[box], sizes[box, 2]
        key = (
            (lo[box] @ self.strides)
            + (k // sx) * self.strides[0]
            + ((k % sx) // sy) * (self.strides[1])
            + k % sy
        )
        return box, key

    def near(self, mins: FloatArray, maxs: FloatArray) -> BoolArray:
        """Which boxes reach a crowded cell."""
        box, key = self._cells(mins, maxs)
        hits = np.bincount(box[self.crowded[key]], minlength=mins.shape[0])
        return np.asarray(hits > 0)


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
    cover it exactly, except those ``keep(pieces, parents)`` rejects along the way.

    >>> import numpy as np
    >>> pieces, parent = bisect_to_size(np.array([[[0, 0, 0], [4, 0, 0], [0, 1, 0]]], float), 1.0)
    >>> bool(np.all(parent == 0)), bool(np.all(np.ptp(pieces, axis=1) <= 1.0)), len(pieces) > 4
    (True, True, True)
    """
    parent = np.arange(corners.shape[0], dtype=np.int64)
    done_pieces, done_parents = [corners[:0]], [parent[:0]]
    pieces = corners
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
        if keep is not None:
            wanted = keep(pieces, parent)
            pieces, parent = pieces[wanted], parent[wanted]
    return np.concatenate(done_pieces), np.concatenate(done_parents)


def overlapping_pairs(
    corners: FloatArray, groups: IntArray, margin: float = 0.0, cell: float | None = None
) -> tuple[IntArray, IntArray]:
    """Pairs ``(i, j)``, ``groups[i] < groups[j]``, of triangles ``corners`` (K, 3, 3) that may
    lie within ``margin`` of each other (their pieces' boxes, grown by ``margin``, overlap).

    A point is a triangle with three equal corners.

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
    if cell is None:
        cell = _CELL_FACTOR * float(np.median(_extent(corners)))
    mins, maxs = _boxes(corners, margin)
    origin = mins.min(axis=0)
    span = float((maxs.max(axis=0) - origin).max())
    cell = max(cell, 4.0 * margin, span / 2.0**20, np.finfo(np.float64).tiny)
    crowding = _Crowding(
        mins, maxs, groups, origin, max(_COARSE_FACTOR * cell, span / _COARSE_CELLS)
    )
    candidates = np.flatnonzero(crowding.near(mins, maxs))

    def near(pieces: FloatArray, parent: IntArray) -> BoolArray:
        return crowding.near(*_boxes(pieces, margin))

    pieces, parent = bisect_to_size(corners[candidates], cell - 2.0 * margin, near)
    parent = candidates[parent]
    if parent.size == 0:
        return empty, empty
    piece_groups = groups[parent]
    if np.any(piece_groups[1:] < piece_groups[:-1]):
        order = np.argsort(piece_groups, kind="stable")
        pieces, parent = pieces[order], parent[order]
    m = pieces.shape[0]
    mins, maxs = _boxes(pieces, margin)
    lo = np.floor((mins - origin) / cell).astype(np.int64)
    hi = np.floor((maxs - origin) / cell).astype(np.int64)
    dims = hi.max(axis=0) + 1
    strides = np.array([dims[1] * dims[2], dims[2], 1], dtype=np.int64)
    base = lo @ strides
    reach = hi - lo  # 0 or 1 per axis: pieces fit in a cell
    piece_parts, key_parts, code_parts = [], [], []
    everything = np.arange(m, dtype=np.int64)
    for step in range(8):
        dx, dy, dz = step >> 2, (step >> 1) & 1, step & 1
        inside = (reach[:, 0] >= dx) & (reach[:, 1] >= dy) & (reach[:, 2] >= dz)
        piece_parts.append(everything[inside])
        key_parts.append(base[inside] + (dx * strides[0] + dy * strides[1] + dz))
        code_parts.append(np.full(int(inside.sum()), step, dtype=np.int64))
    piece = np.concatenate(piece_parts)
    key = np.concatenate(key_parts)
    code = np.concatenate(code_parts)
    # Pieces are in group order: sorting by (cell, piece) keeps each cell's rows by group.
    if int(key.max()) < (2**62) // (8 * m):
        packed = np.sort((key * m + piece) * 8 + code)
        code, packed = packed % 8, packed // 8
        key, piece = packed // m, packed % m
    else:
        order = np.lexsort((piece, key))
        key, piece, code = key[order], piece[order], code[order]
    group = groups[parent[piece]]
    rows = key.shape[0]
    new_cell = np.ones(rows, dtype=np.bool_)
    new_cell[1:] = key[1:] != key[:-1]
    new_block = new_cell.copy()
    new_block[1:] |= group[1:] != group[:-1]
    cell_end = np.append(np.flatnonzero(new_cell)[1:], rows)[np.cumsum(new_cell) - 1]
    block_end = np.append(np.flatnonzero(new_block)[1:], rows)[np.cumsum(new_block) - 1]
    partners = cell_end - block_end
    first_row = np.repeat(np.arange(rows, dtype=np.int64), partners)
    second_row = concatenated_ranges(block_end, partners)
    # Both pieces hold this cell; it is the lower corner of their boxes' overlap unless both
    # reached it by stepping up along some axis (their offset codes share a bit).
    canonical = (code[first_row] & code[second_row]) == 0
    first, second = piece[first_row[canonical]], piece[second_row[canonical]]
    keep = np.ones(first.shape[0], dtype=np.bool_)
    for k in range(3):
        low, high = mins[:, k], maxs[:, k]
        keep &= (low[first] <= high[second]) & (low[second] <= high[first])
    first, second = parent[first[keep]], parent[second[keep]]
    unique = np.unique(first * n + second)
    return (unique // n).astype(np.int64), (unique % n).astype(np.int64)
