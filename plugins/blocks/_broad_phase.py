"""Candidate pairs of triangles from different groups, by hashing into a uniform grid.

Cells are one and a half median triangle extents wide. Each triangle's box (grown by the
margin) is first entered in one cell only, the one holding its lower corner — or, when it
spans more than two cells along an axis, in every cell it reaches. The lowest and the highest
group entered in each cell, spread over its 3 x 3 x 3 neighbourhood, tell which boxes may meet
a box of another group: most of a large surface lies far from the others and goes no further.

The boxes left are entered in every cell they reach, and only cells that two groups reach are
kept. A triangle larger than two median extents (a coarse boundary surface, a long fan
triangle) has a box that covers — and would pair it with — every small triangle around it, so
it is kept only in the cells it really comes near (no separating axis between the triangle and
the cell grown by the margin). Rows are sorted by (cell, group); the partners of a row are the
rows of its cell that belong to later groups, so pairs inside one group (triangles of one
surface) are never generated. A pair of boxes is reported from one cell only, the one holding
the lower corner of their overlap; only pairs involving a large triangle need deduplicating.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import NDArray

from geobrep.geometry.arrays import BoolArray, FloatArray, IntArray
from geobrep.plugins.blocks._csr import concatenated_ranges

__all__ = ["component_major", "overlapping_pairs", "stored_pairs"]


#: Triangles larger than this many median extents are kept only in the cells they come near.
_LARGE_FACTOR = 2.0
#: Grid cell size, in median extents, and the most cells along an axis.
_CELL_FACTOR = 1.5
_MAX_CELLS = 192
#: A large triangle's cells are listed only in the blocks of this many cells per axis that
#: another group comes near.
_COARSE = 4
#: Spread boxes reaching more cells than this many per box go through the blocks.
_BLOCKS_OVER = 2
#: Boxes converted to cells at a time.
_SLICE = 32_768
#: Cell offsets (x, y, z) of the eight cells a box reaching two cells per axis may reach; code c
#: has bit 4 set when the cell lies past the box's first cell along x, 2 along y, 1 along z.
_OFFSETS = np.array([[(c >> 2) & 1, (c >> 1) & 1, c & 1] for c in range(8)], dtype=np.int64).T


def _boxes(corners: FloatArray, margin: float) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Boxes of triangles stored component-major, (corner, xyz, K): mins and maxs (xyz, K), and
    each box's largest side (K), margins included.

    In slices whose temporaries stay in cache (the same operations as on whole rows)."""
    n = corners.shape[2]
    low, high = np.empty((3, n)), np.empty((3, n))
    extent = np.empty(n)
    a, b, c = corners[0], corners[1], corners[2]
    for start in range(0, n, _SLICE):
        rows = slice(start, start + _SLICE)
        part_low, part_high = low[:, rows], high[:, rows]
        np.minimum(a[:, rows], b[:, rows], out=part_low)
        np.maximum(a[:, rows], b[:, rows], out=part_high)
        np.minimum(part_low, c[:, rows], out=part_low)
        np.maximum(part_high, c[:, rows], out=part_high)
        if margin:
            part_low -= margin
            part_high += margin
        size = part_high - part_low
        part = extent[rows]
        np.maximum(size[0], size[1], out=part)
        np.maximum(part, size[2], out=part)
    return low, high, extent


def _dilated(values: NDArray[Any], op: Callable[..., object]) -> NDArray[Any]:
    """``op`` (``np.minimum`` or ``np.maximum``) over the 3 x 3 x 3 cells around each cell.

    One axis at a time, in the array's own memory order (slices along the axis, no transposed
    copies): ``op`` of each pair of neighbours, then of each pair of those pairs."""
    out = np.array(values, order="C")
    for axis in range(3):
        if out.shape[axis] < 2:
            continue
        if axis == 2:
            # The last axis over the flattened cells (one long pass instead of a short one per
            # row of cells): pairs and pairs of pairs that reach across the end of a row are
            # wrong only at the ends of the rows, which take their one pair instead.
            n, flat = out.shape[2], out.reshape(-1)
            pairs = np.empty(flat.shape[0] - 1, dtype=out.dtype)
            op(flat[:-1], flat[1:], out=pairs)  # cells k and k + 1
            op(pairs[:-1], pairs[1:], out=flat[1:-1])
            rows = flat.reshape(-1, n)
            rows[:, 0] = pairs[0::n]
            rows[:, n - 1] = pairs[n - 2 :: n]
            continue

        def part(start: int | None, stop: int | None, axis: int = axis) -> tuple[slice, ...]:
            return tuple(slice(start, stop) if k == axis else slice(None) for k in range(3))

        pairs = np.empty_like(out[part(1, None)])
        op(out[part(None, -1)], out[part(1, None)], out=pairs)  # cells k and k + 1
        out[part(None, 1)] = pairs[part(None, 1)]
        out[part(-1, None)] = pairs[part(-1, None)]
        op(pairs[part(None, -1)], pairs[part(1, None)], out=out[part(1, -1)])
    return out


class _Grid:
    """A dense uniform grid of cubic cells over the boxes (``origin`` is a column)."""

    def __init__(self, origin: FloatArray, size: float, top: FloatArray) -> None:
        self.origin, self.size = origin[:, None], size
        self.dims = np.floor((top - origin) / size).astype(np.int64) + 1
        self.strides = np.array([self.dims[1] * self.dims[2], self.dims[2], 1], dtype=np.int64)
        self.n_cells = int(np.prod(self.dims))

    def coarser(self, factor: int) -> _Grid:
        """The grid of ``factor``³ blocks of these cells (cell ``i`` lies in block ``i // factor``
        along each axis), over the same origin."""
        grid = object.__new__(_Grid)
        grid.origin, grid.size = self.origin, self.size * factor
        grid.dims = (self.dims - 1) // factor + 1
        grid.strides = np.array([grid.dims[1] * grid.dims[2], grid.dims[2], 1], dtype=np.int64)
        grid.n_cells = int(np.prod(grid.dims))
        return grid

    def keys(self, index: IntArray) -> IntArray:
        """Cell keys of cell indices (xyz, R) (``strides @ index``: numpy's integer matrix
        product is several times slower than these elementwise passes)."""
        key = index[0] * self.strides[0]
        key += index[1] * self.strides[1]
        key += index[2]
        return np.asarray(key)

    def index(self, key: IntArray) -> IntArray:
        """Cell indices (xyz, R) of cell keys."""
        return np.stack(
            [key // self.strides[0], (key // self.strides[1]) % self.dims[1], key % self.dims[2]]
        )

    def cells_of(self, bounds: FloatArray) -> IntArray:
        """The cell (xyz, K) holding each point ``bounds`` (xyz, K) of the boxes the grid was
        made over."""
        # Offsets from the origin are not negative for those boxes (the origin is their least
        # corner, and x - y >= 0 exactly when x >= y), so a truncating cast floors them;
        # x · (1 / size) is monotone in x like x / size, so boxes that overlap still share a
        # cell (and the cell geometry of :meth:`touches` allows for the rounding).
        # In slices whose temporaries stay in cache, cast straight into the result.
        scale, top = 1.0 / self.size, self.dims[:, None] - 1
        n = bounds.shape[1]
        cells = np.empty((3, n), dtype=np.int64)
        for start in range(0, n, _SLICE):
            rows = slice(start, start + _SLICE)
            offset = bounds[:, rows] - self.origin
            offset *= scale
            part = cells[:, rows]
            np.copyto(part, offset, casting="unsafe")  # truncation, as astype
            np.minimum(part, top, out=part)
        return cells

    def cells(self, first: IntArray, past: IntArray) -> tuple[IntArray, IntArray, IntArray]:
        """Rows (box, cell key, offset code) of every cell of each box's range."""
        sizes = past + 1
        box = np.arange(sizes.shape[1], dtype=np.int64)
        key = self.keys(first)
        code = np.zeros(box.shape[0], dtype=np.int64)
        # One axis at a time (x, then y, then z: rows by box, then dx, dy, dz): each row is
        # repeated as many times as the box spans cells along the axis, without divisions.
        for axis, bit in ((0, 4), (1, 2), (2, 1)):
            count = np.take(sizes[axis], box)
            if int(count.max(initial=1)) == 1:
                continue
            step = concatenated_ranges(np.zeros(count.shape[0], np.int64), count)
            box, key, code = np.repeat(box, count), np.repeat(key, count), np.repeat(code, count)
            key += step * self.strides[axis]
            code |= (step > 0) * bit
        return box, key, code

    def touches(self, corners: FloatArray, key: IntArray, margin: float) -> BoolArray:
        """Whether each triangle (component-major, (corner, xyz, R)) comes within ``margin`` of
        cell ``key``: no separating axis between it and the cell grown by ``margin`` among the
        triangle's normal and its edges crossed with x, y and z (the cell's own axes separate
        nothing: the triangle's box reaches the cell)."""
        index = self.index(key)
        half = 0.5 * self.size
        p = corners - (index * self.size + (self.origin + half))  # corners about the centre
        radius = (half + margin) * (1.0 + 1e-9)
        edge = p[[1, 2, 0]] - p  # edge k runs from corner k to k + 1
        normal = np.stack(
            [
                edge[0, 1] * edge[1, 2] - edge[0, 2] * edge[1, 1],
                edge[0, 2] * edge[1, 0] - edge[0, 0] * edge[1, 2],
                edge[0, 0] * edge[1, 1] - edge[0, 1] * edge[1, 0],
            ]
        )
        near = np.abs((normal * p[0]).sum(axis=0)) <= radius * np.abs(normal).sum(axis=0)
        for u in range(3):  # the axis edge x e_u has components e_w along v and -e_v along w
            v, w = (u + 1) % 3, (u + 2) % 3
            for k in range(3):
                ev, ew = edge[k, v], edge[k, w]
                # Corners k and k + 1 project alike; corner k + 2 is the other end.
                one = p[k, v] * ew - p[k, w] * ev
                other = p[(k + 2) % 3, v] * ew - p[(k + 2) % 3, w] * ev
                reach = radius * (np.abs(ev) + np.abs(ew))
                near &= (np.minimum(one, other) <= reach) & (np.maximum(one, other) >= -reach)
        return np.asarray(near)


def _block_extremes(values: NDArray[Any], factor: int, lowest: bool) -> NDArray[Any]:
    """Least (``lowest``) or greatest value of each block of ``factor`` ³ cells of a dense
    (X, Y, Z) grid, flattened in block order."""
    op = np.minimum if lowest else np.maximum
    for axis in range(3):  # strided slices: elementwise passes, no reduction over short axes
        moved = np.moveaxis(values, axis, 0)
        out = moved[::factor].copy()
        for k in range(1, factor):
            part = moved[k::factor]
            op(out[: part.shape[0]], part, out=out[: part.shape[0]])
        values = np.moveaxis(out, 0, axis)
    return np.ascontiguousarray(values).reshape(-1)


def _groups_differ(n_cells: int, key: IntArray, group: NDArray[np.integer]) -> BoolArray:
    """Whether rows of another group than each row's share its cell ``key`` (of ``n_cells``)."""
    low = np.full(n_cells, np.iinfo(group.dtype).max, dtype=group.dtype)
    high = np.zeros(n_cells, dtype=group.dtype)
    np.minimum.at(low, key, group)
    np.maximum.at(high, key, group)
    return np.asarray(low[key] < high[key])


def _spread_rows(
    grid: _Grid,
    boxes: tuple[IntArray, IntArray, IntArray],
    around: tuple[NDArray[Any], NDArray[Any]],
    large: BoolArray,
    stored: FloatArray,
    groups: NDArray[np.integer],
    margin: float,
) -> tuple[IntArray, IntArray, IntArray]:
    """Rows (box, cell key, offset code) of the spread boxes ``boxes`` = (indices, first
    cells, cells past them). ``around`` is the least and greatest group whose boxes have
    their first cell in the 3 x 3 x 3 cells around each cell (dense grids). A large triangle
    has rows only in the blocks of :data:`_COARSE` ³ cells it comes near where another group
    is around (or has a spread box reaching the block), or where a large triangle of another
    group comes near too.

    A large triangle spans many cells, most of them far from any other surface: the blocks
    tell where its cells can matter before they are listed. A cell matters to it only where
    a box of another group has its first cell around or reaches it (they may pair or make each
    other near) or where a large triangle of another group comes near it too.
    Offset codes of large triangles are 0 (their pairs are deduplicated instead)."""
    spread, first, past = boxes
    big = large[spread]
    small, small_first, small_past = spread[~big], first[:, ~big], past[:, ~big]
    wide = spread[big]
    if wide.size == 0:
        box, key, code = grid.cells(small_first, small_past)
        return small[box], key, code
    coarse = grid.coarser(_COARSE)
    shift = _COARSE.bit_length() - 1
    low = first[:, big] >> shift
    c_box, c_key, _ = coarse.cells(low, ((first[:, big] + past[:, big]) >> shift) - low)
    c_box = wide[c_box]
    group = groups[c_box]
    lowest = _block_extremes(around[0], _COARSE, lowest=True)
    highest = _block_extremes(around[1], _COARSE, lowest=False)
    wanted = (lowest[c_key] < group) | (highest[c_key] > group)
    kept = np.arange(small.shape[0])
    if small.size:
        # The other spread boxes enter every cell they reach, which may lie two cells past
        # their first (beyond ``around``): the blocks of those cells, by group. The blocks of
        # a box's cells are the blocks of its range of blocks, listed as such (a few rows per
        # box, not one per cell, and no cell indices divided out of the keys).
        b_low = small_first >> shift
        b_row, block, _ = coarse.cells(b_low, ((small_first + small_past) >> shift) - b_low)
        b_group = groups[small[b_row]]
        spread_low = np.full(coarse.n_cells, np.iinfo(groups.dtype).max, dtype=groups.dtype)
        spread_high = np.zeros(coarse.n_cells, dtype=groups.dtype)
        np.minimum.at(spread_low, block, b_group)
        np.maximum.at(spread_high, block, b_group)
        wanted |= (spread_low[c_key] < group) | (spread_high[c_key] > group)
        kept = _not_alone(
            coarse,
            (np.minimum(lowest, spread_low), np.maximum(highest, spread_high)),
            (c_key, group),
            (b_row, block, b_group),
            small.shape[0],
        )
    box, key, code = grid.cells(small_first[:, kept], small_past[:, kept])
    box = small[kept][box]
    # Blocks that large triangles of two groups reach, then come near: a fine cell a triangle
    # comes near lies in a block it comes near (the cell grown by the margin lies in its block
    # grown by the margin), so only those blocks' cells can pair the two.
    shared = _groups_differ(coarse.n_cells, c_key, group)
    tested = np.flatnonzero(wanted | shared)
    c_box, c_key, group, wanted = c_box[tested], c_key[tested], group[tested], wanted[tested]
    touching = coarse.touches(stored[:, :, c_box], c_key, margin)
    c_box, c_key, group, wanted = (
        c_box[touching],
        c_key[touching],
        group[touching],
        wanted[touching],
    )
    wanted |= _groups_differ(coarse.n_cells, c_key, group)
    c_box, c_key = c_box[wanted], c_key[wanted]
    # The cells of each wanted block inside the triangle's box.
    start = coarse.index(c_key) << shift
    position = np.searchsorted(spread, c_box)
    box_first = first[:, position]
    box_last = box_first + past[:, position]
    sub_first = np.maximum(box_first, start)
    sub_past = np.minimum(box_last, start + _COARSE - 1) - sub_first
    f_row, f_key, _ = grid.cells(sub_first, sub_past)
    return (
        np.concatenate([box, c_box[f_row]]),
        np.concatenate([key, f_key]),
        np.concatenate([code, np.zeros(f_key.shape[0], dtype=np.int64)]),
    )


def _not_alone(
    coarse: _Grid,
    extremes: tuple[NDArray[Any], NDArray[Any]],
    large_blocks: tuple[IntArray, NDArray[np.integer]],
    rows: tuple[IntArray, IntArray, NDArray[np.integer]],
    n_boxes: int,
) -> IntArray:
    """The spread boxes (not large) that another group may meet: those with a block of their
    range (``rows``: box, block key, group) within two blocks of which some box of another
    group has its first cell or a cell it may enter. ``extremes``: the least and greatest group
    per block of the first cells (the 3 x 3 x 3 cells around them) and of the spread boxes'
    ranges; ``large_blocks``: the blocks of the large triangles' ranges, by group.

    A box left out has rows only in cells the broad phase would find not mixed, and keeping
    them would mix none: every box near such a cell (its first cell, or a cell it enters, one
    cell from it or from a cell one cell from it) lies within two blocks, all of its group.
    Its rows would be dropped with the cells that are not mixed; the others are unchanged."""
    dims = tuple(coarse.dims.tolist())
    lowest, highest = extremes[0].copy(), extremes[1].copy()
    c_key, group = large_blocks
    np.minimum.at(lowest, c_key, group)
    np.maximum.at(highest, c_key, group)
    lowest = _dilated(_dilated(lowest.reshape(dims), np.minimum), np.minimum).reshape(-1)
    highest = _dilated(_dilated(highest.reshape(dims), np.maximum), np.maximum).reshape(-1)
    b_row, block, b_group = rows
    shared = (lowest[block] != b_group) | (highest[block] != b_group)
    return np.flatnonzero(np.bincount(b_row[shared], minlength=n_boxes) > 0)


def _near_other_groups(
    grid: _Grid,
    first: IntArray,
    spread_boxes: tuple[IntArray, IntArray],
    groups: NDArray[np.integer],
    large: tuple[BoolArray, FloatArray, float],
) -> tuple[BoolArray, IntArray, IntArray, IntArray]:
    """Which boxes may meet a box of another group, and the rows of the spread boxes (those
    reaching more than two cells along an axis, ``spread_boxes``: their indices and how many
    cells past their first they reach): box, cell key, offset code (``large``: which boxes are
    large triangles, the corners and the margin, for :func:`_spread_rows`).

    A box reaching at most two cells per axis is entered in its first cell only: a box it
    overlaps has entered a cell of the 3 x 3 x 3 around that one."""
    lower = grid.keys(first)
    spread, past = spread_boxes
    dims = tuple(grid.dims.tolist())
    maximum = np.iinfo(groups.dtype).max
    sizes = past + 1
    if int((sizes[0] * sizes[1] * sizes[2]).sum()) <= _BLOCKS_OVER * first.shape[1]:
        # Few spread rows: all of them at once, one dilation.
        box, key, code = grid.cells(first[:, spread], past)
        box = spread[box]
        lowest = np.full(grid.n_cells, maximum, dtype=groups.dtype)
        highest = np.zeros(grid.n_cells, dtype=groups.dtype)
        for where, group in ((lower, groups), (key, groups[box])):
            np.minimum.at(lowest, where, group)
            np.maximum.at(highest, where, group)
        mixed = (
            _dilated(lowest.reshape(dims), np.minimum) < _dilated(highest.reshape(dims), np.maximum)
        ).reshape(-1)
        return _near_and_rows(mixed, lower, spread, (box, key, code))
    lowest = np.full(grid.n_cells, maximum, dtype=groups.dtype)
    highest = np.zeros(grid.n_cells, dtype=groups.dtype)
    np.minimum.at(lowest, lower, groups)
    np.maximum.at(highest, lower, groups)
    around = (
        _dilated(lowest.reshape(dims), np.minimum),
        _dilated(highest.reshape(dims), np.maximum),
    )
    is_large, stored, margin = large
    box, key, code = _spread_rows(
        grid, (spread, first[:, spread], past), around, is_large, stored, groups, margin
    )
    if box.size:
        lowest = np.full(grid.n_cells, maximum, dtype=groups.dtype)
        highest = np.zeros(grid.n_cells, dtype=groups.dtype)
        np.minimum.at(lowest, key, groups[box])
        np.maximum.at(highest, key, groups[box])
        around = (
            np.minimum(around[0], _dilated(lowest.reshape(dims), np.minimum)),
            np.maximum(around[1], _dilated(highest.reshape(dims), np.maximum)),
        )
    mixed = (around[0] < around[1]).reshape(-1)
    return _near_and_rows(mixed, lower, spread, (box, key, code))


def _near_and_rows(
    mixed: BoolArray, lower: IntArray, spread: IntArray, rows: tuple[IntArray, IntArray, IntArray]
) -> tuple[BoolArray, IntArray, IntArray, IntArray]:
    """Which boxes are near another group's (``mixed``: the cells with two groups' boxes in
    the 3 x 3 x 3 around them, ``lower``: every box's first cell, ``spread``: the spread boxes)
    and the spread boxes' ``rows`` (box, cell key, code) in mixed cells only.

    A row in a cell that is not mixed can never pair: a cell pairs boxes of two groups that
    have rows there, and every row of a box lies in its first cell or in one of the 3 x 3 x 3
    around it (a compact box) or is one of the spread rows (whose cells ``mixed`` counts), so
    two groups with rows in a cell make it mixed. Such rows would be dropped with the cells
    that only one group reaches; they are dropped here, before they are gathered again."""
    box, key, code = rows
    near = mixed[lower]
    near[spread] = False
    live = mixed[key]
    box, key, code = box[live], key[live], code[live]
    near[box] = True
    return near, box, key, code


def overlapping_pairs(
    corners: FloatArray, groups: IntArray, margin: float = 0.0, cell: float | None = None
) -> tuple[IntArray, IntArray]:
    """Pairs ``(i, j)``, ``groups[i] < groups[j]``, of triangles ``corners`` (K, 3, 3) that may
    lie within ``margin`` of each other: their boxes, grown by ``margin``, overlap, and a
    triangle larger than two median extents (or than ``cell`` · 4/3) comes within ``margin`` of
    a grid cell the other's box reaches. Every pair closer than ``margin`` is listed.

    A point is a triangle with three equal corners. Each pair is listed once, in no set order.
    ``cell`` is the grid cell size (default 1.5 median triangle extents).

    >>> import numpy as np
    >>> flat = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]
    >>> corners = np.array([flat, np.add(flat, [0.5, 0.5, 0]), np.add(flat, 3.0)], dtype=float)
    >>> i, j = overlapping_pairs(corners, np.array([0, 1, 1]))
    >>> i.tolist(), j.tolist()
    ([0], [1])
    """
    stored = np.ascontiguousarray(np.transpose(corners, (1, 2, 0)), dtype=np.float64)
    return stored_pairs(stored, groups, margin, cell)


def component_major(columns: FloatArray, triangles: IntArray) -> FloatArray:
    """Corners of ``triangles`` (K, 3) over vertex ``columns`` (3, V), stored component-major
    as :func:`stored_pairs` takes them: (corner, xyz, K)."""
    by_corner = np.ascontiguousarray(triangles.T)
    stored = np.empty((3, 3, triangles.shape[0]), dtype=np.float64)
    for k in range(3):
        for axis in range(3):  # 1-D gathers: faster than taking columns along axis 1
            np.take(columns[axis], by_corner[k], out=stored[k, axis])
    return stored


def stored_pairs(
    stored: FloatArray,
    groups: IntArray,
    margin: float = 0.0,
    cell: float | None = None,
    triangles: IntArray | None = None,
) -> tuple[IntArray, IntArray]:
    """:func:`overlapping_pairs` of triangles given component-major, ``stored`` (corner, xyz,
    K) float64, as callers that gather the corners that way pass them (no transposed copy).
    ``triangles``: the vertices (K, 3) of the triangles; pairs sharing one are then left out
    (the others in the same order)."""
    n = stored.shape[2]
    empty = np.zeros(0, dtype=np.int64)
    if n == 0:
        return empty, empty
    mins, maxs, extent = _boxes(stored, margin)  # extents: margins included
    if cell is None:
        cell = _CELL_FACTOR * float(np.median(extent - 2.0 * margin))
    origin, top = mins.min(axis=1), maxs.max(axis=1)
    span = float((top - origin).max())
    cell = max(cell, 3.0 * margin, span / _MAX_CELLS, span / 2.0**20, np.finfo(np.float64).tiny)
    grid = _Grid(origin, cell, top)
    shifted = np.asarray(groups) - int(np.min(groups))
    table = shifted.astype(np.min_scalar_type(int(shifted.max())))
    # The first cell of every box; the last only where needed: a box reaches three cells along
    # an axis only when longer than a cell there (1e-6: far more than the rounding of the cell
    # indices, under 2^20 cells per axis), and of the others only those near another group.
    first = grid.cells_of(mins)
    long = np.flatnonzero(extent > cell * (1.0 - 1e-6))
    long_past = grid.cells_of(np.take(maxs, long, axis=1)) - np.take(first, long, axis=1)
    spreading = (long_past > 1).any(axis=0)
    spread = long[spreading]
    large = extent > cell * (_LARGE_FACTOR / _CELL_FACTOR) + 2.0 * margin
    near, s_box, s_key, s_code = _near_other_groups(
        grid, first, (spread, long_past[:, spreading]), table, (large, stored, margin)
    )
    # Rows of the boxes left: those reaching at most two cells per axis from the offsets table.
    is_spread = np.zeros(n, dtype=np.bool_)
    is_spread[spread] = True
    compact = np.flatnonzero(near & ~is_spread)
    compact_first = np.take(first, compact, axis=1)
    past = grid.cells_of(np.take(maxs, compact, axis=1)) - compact_first
    reached = (
        (_OFFSETS[0][:, None] <= past[0])
        & (_OFFSETS[1][:, None] <= past[1])
        & (_OFFSETS[2][:, None] <= past[2])
    )
    code, which = np.nonzero(reached)
    box = compact[which]
    key = np.take(grid.keys(compact_first), which) + (grid.strides @ _OFFSETS)[code]
    kept = near[s_box]
    box = np.concatenate([box, s_box[kept]])
    key = np.concatenate([key, s_key[kept]])
    code = np.concatenate([code.astype(np.int64), s_code[kept]])
    # Only cells that two groups reach.
    group = table[box]
    lowest = np.full(grid.n_cells, np.iinfo(table.dtype).max, dtype=table.dtype)
    highest = np.zeros(grid.n_cells, dtype=table.dtype)
    np.minimum.at(lowest, key, group)
    np.maximum.at(highest, key, group)
    live = lowest[key] < highest[key]
    box, key, code = box[live], key[live], code[live]
    # Large triangles: only the cells they come near; their pairs are deduplicated instead.
    rows = np.flatnonzero(large[box])
    if rows.size:
        touching = grid.touches(stored[:, :, box[rows]], key[rows], margin)
        code[rows] = 0
        keep = np.ones(box.shape[0], dtype=np.bool_)
        keep[rows[~touching]] = False
        box, key, code = box[keep], key[keep], code[keep]
    if box.size == 0:
        return empty, empty
    return _cell_pairs(box, key, code, shifted, (mins, maxs), large, triangles)


def _cell_pairs(
    box: IntArray,
    key: IntArray,
    code: IntArray,
    groups: IntArray,
    bounds: tuple[FloatArray, FloatArray],
    large: BoolArray,
    triangles: IntArray | None = None,
) -> tuple[IntArray, IntArray]:
    """Pairs of boxes of different groups sharing a cell, from rows (box, cell key, code);
    with ``triangles`` (vertices of each box's triangle), none of two sharing a vertex."""
    mins, maxs = bounds
    n = groups.shape[0]
    group = np.take(groups, box)
    box_bits = max((n - 1).bit_length(), 1)
    group_bits = max(int(groups.max()).bit_length(), 1)
    block: IntArray | None = None
    if max(int(key.max()).bit_length(), 1) + group_bits + box_bits + 3 <= 63:
        # One sort of the rows packed (cell, group, box, code): bit fields, no divisions.
        packed = np.sort((((key << group_bits | group) << box_bits | box) << 3) | code)
        code = packed & 7
        box = (packed >> 3) & ((1 << box_bits) - 1)
        block = packed >> (3 + box_bits)  # (cell, group)
        key = block >> group_bits
    else:
        order = np.lexsort((box, group, key))
        key, box, code, group = key[order], box[order], code[order], group[order]
    n_rows = key.shape[0]
    new_cell = np.ones(n_rows, dtype=np.bool_)
    np.not_equal(key[1:], key[:-1], out=new_cell[1:])
    new_block = np.ones(n_rows, dtype=np.bool_)
    if block is not None:
        np.not_equal(block[1:], block[:-1], out=new_block[1:])
    else:
        new_block[1:] = new_cell[1:] | (group[1:] != group[:-1])
    cell_end = np.append(np.flatnonzero(new_cell)[1:], n_rows)[np.cumsum(new_cell) - 1]
    block_end = np.append(np.flatnonzero(new_block)[1:], n_rows)[np.cumsum(new_block) - 1]
    partners = cell_end - block_end
    first_row = np.repeat(np.arange(n_rows, dtype=np.int64), partners)
    second_row = concatenated_ranges(block_end, partners)
    # The cell is the lower corner of the boxes' overlap unless both reached it by stepping up
    # along some axis (their offset codes share a bit). Gathers are np.take: on numpy 2 it is
    # several times faster than fancy indexing.
    canonical = np.flatnonzero((np.take(code, first_row) & np.take(code, second_row)) == 0)
    first_row, second_row = np.take(first_row, canonical), np.take(second_row, canonical)
    # The boxes' bounds gathered per row first: the pairs then gather from arrays as long as
    # the rows, not the boxes (fewer cache misses), and only kept pairs gather their boxes.
    keep = np.ones(first_row.shape[0], dtype=np.bool_)
    for k in range(3):
        low, high = np.take(mins[k], box), np.take(maxs[k], box)
        keep &= np.take(low, first_row) <= np.take(high, second_row)
        keep &= np.take(low, second_row) <= np.take(high, first_row)
    first_row, second_row = np.compress(keep, first_row), np.compress(keep, second_row)
    if triangles is not None:
        # Vertices gathered per row first too; a stable mask, so the pairs left keep their order.
        corner = [np.take(triangles[:, k], box) for k in range(3)]
        theirs = [np.take(c, second_row) for c in corner]
        apart = np.ones(first_row.shape[0], dtype=np.bool_)
        for c in corner:
            mine = np.take(c, first_row)
            for other in theirs:
                apart &= mine != other
        first_row, second_row = np.compress(apart, first_row), np.compress(apart, second_row)
    first, second = np.take(box, first_row), np.take(box, second_row)
    once = ~(large[first] | large[second])
    if once.all():
        return first.astype(np.int64, copy=False), second.astype(np.int64, copy=False)
    # Pairs with a large triangle may come from several cells: sorted, the copies are runs.
    twice = np.sort(first[~once] << box_bits | second[~once])
    distinct = np.ones(twice.shape[0], dtype=np.bool_)
    np.not_equal(twice[1:], twice[:-1], out=distinct[1:])
    twice = twice[distinct]
    i = np.concatenate([first[once], twice >> box_bits])
    j = np.concatenate([second[once], twice & ((1 << box_bits) - 1)])
    return i.astype(np.int64, copy=False), j.astype(np.int64, copy=False)
