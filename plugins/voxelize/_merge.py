"""Bottom-up merging of 8 black siblings into their parent, on a sorted linear octree.

Used where leaves were built separately — the sub-cubes of block-by-block voxelization — and as
the final guarantee that no parent with 8 full children of one body survives as 8 leaves.
Merging keeps Morton order: the 8 siblings are consecutive and the parent takes the first
child's code.
"""

from __future__ import annotations

import numpy as np

from geobrep.plugins.voxelize._emission import Leaves

__all__ = ["merge_full_siblings"]


def merge_full_siblings(leaves: Leaves, depth: int) -> Leaves:
    """Replace every complete set of 8 sibling leaves (same body) by their parent, repeatedly.

    >>> import numpy as np
    >>> leaves = Leaves(np.arange(8, dtype=np.uint64), np.full(8, 1, np.uint8), np.zeros(8, int))
    >>> merged = merge_full_siblings(leaves, depth=1)
    >>> merged.codes.tolist(), merged.levels.tolist()
    ([0], [0])
    """
    codes, levels, bodies = leaves.codes, leaves.levels, leaves.bodies
    for level in range(depth, 0, -1):
        if codes.shape[0] < 8:
            break
        span = np.uint64(1) << np.uint64(3 * (depth - level))
        head = codes.shape[0] - 7
        first = np.flatnonzero(
            (levels[:head] == level) & (codes[:head] % (span * np.uint64(8)) == 0)
        )
        if first.size == 0:
            continue
        complete = np.ones(first.size, dtype=np.bool_)
        for t in range(1, 8):
            complete &= (levels[first + t] == level) & (bodies[first + t] == bodies[first])
        complete &= codes[first + 7] == codes[first] + np.uint64(7) * span
        parents = first[complete]
        if parents.size == 0:
            continue
        drop = np.zeros(codes.shape[0], dtype=np.bool_)
        drop[(parents[:, None] + np.arange(1, 8)[None, :]).ravel()] = True
        levels = levels.copy()
        levels[parents] = level - 1
        keep = ~drop
        codes, levels, bodies = codes[keep], levels[keep], bodies[keep]
    return Leaves(codes, levels, bodies)
