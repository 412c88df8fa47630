"""Sorting of non-negative integer keys by least-significant-digit radix passes.

numpy sorts 16-bit integers by a radix sort (``kind="stable"``), several times faster per
element than any of its comparison sorts of 64-bit keys once these leave the cache. A stable
order of keys below ``2**48`` is three such passes, one per 16-bit digit from the lowest: each
pass sorts the digit of the keys in the order the passes before it left, and keeps ties in that
order (the order :func:`numpy.argsort` with ``kind="stable"`` gives).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from geobrep.geometry.arrays import IntArray

__all__ = ["RADIX_MIN", "RADIX_PASSES", "digit_order", "radix_order", "radix_pays", "sorted_keys"]

#: Keys of up to this many 16-bit digits are sorted by radix passes; wider keys, or fewer
#: than ``RADIX_MIN`` of them, by ``np.sort`` (faster then).
RADIX_PASSES = 3
RADIX_MIN = 4096
_DIGIT = 16
_MASK = (1 << _DIGIT) - 1


def radix_order(keys: IntArray, bits: int) -> IntArray:
    """The stable order (``np.argsort(keys, kind="stable")``) of int64 ``keys``, each in
    ``[0, 2**bits)``.

    >>> radix_order(np.array([70000, 3, 70000, 2]), 17).tolist()
    [3, 1, 0, 2]
    """
    digits = [
        ((keys >> shift) & _MASK).astype(np.uint16) for shift in range(0, max(bits, 1), _DIGIT)
    ]
    order = np.argsort(digits[0], kind="stable")
    for digit in digits[1:]:
        order = np.take(order, np.argsort(np.take(digit, order), kind="stable"))
    return order.astype(np.int64, copy=False)


def digit_order(*digits: NDArray[np.uint16]) -> IntArray:
    """The stable lexicographic order of rows given as 16-bit columns, the most significant
    first (``np.lexsort(digits[::-1])``): one radix pass per column.

    >>> digit_order(np.array([1, 0, 1], np.uint16), np.array([5, 9, 2], np.uint16)).tolist()
    [1, 2, 0]
    """
    order = np.argsort(digits[-1], kind="stable")
    for digit in digits[-2::-1]:
        order = np.take(order, np.argsort(np.take(digit, order), kind="stable"))
    return order.astype(np.int64, copy=False)


def radix_pays(n: int, bits: int) -> bool:
    """Whether :func:`radix_order` beats a comparison sort of ``n`` keys of ``bits`` bits."""
    return n >= RADIX_MIN and -(-max(bits, 1) // _DIGIT) <= RADIX_PASSES


def sorted_keys(keys: IntArray) -> IntArray:
    """``np.sort(keys)`` of int64 keys (any sign), by :func:`radix_order` when it pays.

    >>> sorted_keys(np.array([5, -1, 3])).tolist()
    [-1, 3, 5]
    """
    flat = keys.reshape(-1)
    if flat.shape[0] < RADIX_MIN:
        return np.sort(flat)
    low = int(flat.min())
    bits = (int(flat.max()) - low).bit_length()
    if not radix_pays(flat.shape[0], bits):
        return np.sort(flat)
    shifted = flat - low if low else flat
    return np.take(flat, radix_order(shifted, bits))
