"""Morton (Z-order) codes: three 21-bit cell indices interleaved into one uint64.

Bit ``3b`` of a code is bit ``b`` of the x index, bit ``3b + 1`` of y and bit ``3b + 2`` of z, so
sorting codes visits cells in Z order and the cells of an octant at level ``l`` of a depth-``n``
tree form one contiguous range of ``8**(n - l)`` codes.

>>> morton_encode([1], [2], [3]).tolist()
[53]
>>> [a.tolist() for a in morton_decode([53])]
[[1], [2], [3]]
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["MORTON_BITS", "morton_decode", "morton_encode", "octant_span"]

#: Bits per axis in a uint64 code.
MORTON_BITS = 21

_U = np.uint64
_SPREAD = (
    (32, _U(0x001F00000000FFFF)),
    (16, _U(0x001F0000FF0000FF)),
    (8, _U(0x100F00F00F00F00F)),
    (4, _U(0x10C30C30C30C30C3)),
    (2, _U(0x1249249249249249)),
)
_LOW21 = _U(0x1FFFFF)


def _spread(values: NDArray[np.uint64]) -> NDArray[np.uint64]:
    x = values & _LOW21
    for shift, mask in _SPREAD:
        x = (x | (x << _U(shift))) & mask
    return x


def _compact(codes: NDArray[np.uint64]) -> NDArray[np.uint64]:
    x = codes & _U(0x1249249249249249)
    x = (x ^ (x >> _U(2))) & _U(0x10C30C30C30C30C3)
    x = (x ^ (x >> _U(4))) & _U(0x100F00F00F00F00F)
    x = (x ^ (x >> _U(8))) & _U(0x001F0000FF0000FF)
    x = (x ^ (x >> _U(16))) & _U(0x001F00000000FFFF)
    x = (x ^ (x >> _U(32))) & _LOW21
    return x


def morton_encode(i: ArrayLike, j: ArrayLike, k: ArrayLike) -> NDArray[np.uint64]:
    """Codes of the cells ``(i, j, k)`` (non-negative integers below ``2**21``), vectorised.

    >>> morton_encode([0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]).tolist()
    [0, 1, 2, 4]
    """
    x = _spread(np.asarray(i).astype(np.uint64))
    y = _spread(np.asarray(j).astype(np.uint64))
    z = _spread(np.asarray(k).astype(np.uint64))
    codes: NDArray[np.uint64] = x | (y << _U(1)) | (z << _U(2))
    return codes


def morton_decode(
    codes: ArrayLike,
) -> tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.int64]]:
    """Cell indices ``(i, j, k)`` (int64 arrays) of Morton codes, vectorised.

    >>> [a.tolist() for a in morton_decode([0, 7])]
    [[0, 1], [0, 1], [0, 1]]
    """
    c = np.asarray(codes).astype(np.uint64)
    return (
        _compact(c).astype(np.int64),
        _compact(c >> _U(1)).astype(np.int64),
        _compact(c >> _U(2)).astype(np.int64),
    )


def octant_span(levels: ArrayLike, depth: int) -> NDArray[np.uint64]:
    """Number of finest codes covered by an octant at each level: ``8**(depth - level)``.

    >>> octant_span([0, 1, 2], 2).tolist()
    [64, 8, 1]
    """
    lv = np.asarray(levels).astype(np.uint64)
    spans: NDArray[np.uint64] = np.left_shift(_U(1), _U(3) * (_U(depth) - lv))
    return spans
