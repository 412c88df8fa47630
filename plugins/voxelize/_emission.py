"""Emission of the linear octree in Morton order, without sorting.

The patent visits the non-white leaves of the incomplete octree in preorder and scans each grey
octant with a 2 × 2 × 2 window in Z order, keeping unknown and active nodes on a stack so that
codes come out already sorted. This module does the same vectorised over whole levels: it keeps
the leaves emitted so far *and* the grey octants still to resolve in one sequence in Morton
order, and at each level replaces every grey octant, in place, by its non-white children taken in
Z order (child ``c`` = ``x | y << 1 | z << 2``).

Why the output is sorted: the octants of the sequence have disjoint code ranges
(``[code, code + 8**(depth - level))``) in increasing order; the children of an octant split its
range into 8 consecutive ranges in child order, so replacing an octant by any subset of its
children, in child order, keeps the sequence increasing and disjoint. No sort, no compaction.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from geobrep.plugins.voxelize._classify import GREY, WHITE, PriorityClassifier

__all__ = ["CHILD_OFFSETS", "Leaves", "emit_leaves"]

_BYTE_SUM = np.uint64(0x0101010101010101)

#: Cell offsets of the 8 children in Z order.
CHILD_OFFSETS = np.array([[c & 1, (c >> 1) & 1, (c >> 2) & 1] for c in range(8)], dtype=np.int64)


@dataclass(frozen=True)
class Leaves:
    """Leaves of a (sub-)octree in Morton order: codes, levels and owning body index."""

    codes: NDArray[np.uint64]
    levels: NDArray[np.uint8]
    bodies: NDArray[np.int64]

    @classmethod
    def empty(cls) -> Leaves:
        return cls(np.zeros(0, np.uint64), np.zeros(0, np.uint8), np.zeros(0, np.int64))

    @classmethod
    def concatenate(cls, parts: list[Leaves]) -> Leaves:
        if not parts:
            return cls.empty()
        return cls(
            np.concatenate([p.codes for p in parts]),
            np.concatenate([p.levels for p in parts]),
            np.concatenate([p.bodies for p in parts]),
        )


def emit_leaves(classifier: PriorityClassifier) -> Leaves:
    """Black leaves of the octree of depth ``classifier.depth``, in Morton order.

    Each level classifies all children of the grey octants at once; black children become
    leaves, white ones vanish, grey ones wait for the next level.
    """
    depth = classifier.depth
    origin = np.zeros(1, dtype=np.int64)
    state, bodies = classifier.classify_labelled(0, origin, origin, origin)
    if state[0] == WHITE:
        return Leaves.empty()
    codes = np.zeros(1, dtype=np.uint64)
    levels = np.zeros(1, dtype=np.uint8)
    grey = state == GREY
    grey_i, grey_j, grey_k = origin[grey], origin[grey], origin[grey]
    child_number = np.arange(8, dtype=np.uint64)
    for level in range(depth):
        positions = np.flatnonzero(grey)
        if positions.size == 0:
            break
        child_i = (2 * grey_i[:, None] + CHILD_OFFSETS[None, :, 0]).ravel()
        child_j = (2 * grey_j[:, None] + CHILD_OFFSETS[None, :, 1]).ravel()
        child_k = (2 * grey_k[:, None] + CHILD_OFFSETS[None, :, 2]).ravel()
        child_state, child_body = classifier.classify_labelled(level + 1, child_i, child_j, child_k)
        kept = child_state != WHITE
        kept_flat = np.flatnonzero(kept)
        # the 8 child flags of a grey octant are 8 bytes: their sum is the top byte of × 0x01…01
        per_grey = ((kept.view(np.uint64) * _BYTE_SUM) >> np.uint64(56)).astype(np.int64)
        # Slot of every element of the new sequence: settled leaves keep one slot, each grey
        # octant makes room for its kept children, in order.
        counts = np.ones(codes.shape[0], dtype=np.int64)
        counts[positions] = per_grey
        starts = np.cumsum(counts) - counts
        total = int(starts[-1] + counts[-1])
        before = np.cumsum(per_grey) - per_grey  # kept children of the earlier grey octants
        child_slots = np.arange(kept_flat.size) + np.repeat(starts[positions] - before, per_grey)
        span = np.uint64(1) << np.uint64(3 * (depth - level - 1))
        child_codes = (codes[positions][:, None] + child_number[None, :] * span).ravel()

        settled = np.flatnonzero(~grey)
        new_codes = np.empty(total, dtype=np.uint64)
        new_levels = np.empty(total, dtype=np.uint8)
        new_bodies = np.empty(total, dtype=np.int64)
        new_grey = np.zeros(total, dtype=np.bool_)
        slots = starts[settled]
        new_codes[slots] = codes[settled]
        new_levels[slots] = levels[settled]
        new_bodies[slots] = bodies[settled]
        new_codes[child_slots] = child_codes[kept_flat]
        new_levels[child_slots] = level + 1
        new_bodies[child_slots] = child_body[kept_flat]
        kept_state = child_state[kept_flat]
        new_grey[child_slots] = kept_state == GREY
        still_grey = kept_flat[kept_state == GREY]
        grey_i, grey_j, grey_k = child_i[still_grey], child_j[still_grey], child_k[still_grey]
        codes, levels, bodies, grey = new_codes, new_levels, new_bodies, new_grey
    if np.any(grey):
        raise RuntimeError("the classifier left grey octants at the finest level")
    return Leaves(codes, levels, bodies)
