"""Give every patch side its region by walking across the arcs (the paper's traversal).

Around an arc sorted counter-clockwise, two consecutive direction triangles ``o`` and ``o′``
bound one wedge of space. The side of ``o`` facing it is its positive side when ``o`` is
forward (its normal points counter-clockwise) and the side of ``o′`` facing it is the one
pointing back — so both sides lie in the same body. The paper walks from patch to patch with
these rules (its steps 8–11), creating a body whenever it meets an unassigned side; the same
bodies are the connected components of the graph whose nodes are patch sides and whose links are
these wedges, which is what is computed here in one pass. An arc used by a single patch links
the two sides of that patch: the patch then has the same region on both sides.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from geobrep.geometry.arrays import IntArray
from geobrep.plugins.blocks._csr import components
from geobrep.plugins.blocks._orientation import DirectionTriangles

__all__ = ["Regions", "side_node", "traverse"]


def side_node(patch: IntArray, side: IntArray) -> IntArray:
    """Node of a patch side: ``2 · patch`` (positive side) or ``2 · patch + 1`` (negative)."""
    return (2 * patch + (side < 0)).astype(np.int64)


@dataclass(frozen=True)
class Regions:
    """Region of every patch side, and the links that joined them (for components)."""

    positive: IntArray
    negative: IntArray
    n_regions: int
    link_patches: tuple[IntArray, IntArray]


def traverse(around: DirectionTriangles, n_patches: int) -> Regions:
    """Regions of the patch sides from arcs sorted by :func:`~.radial_sort.sort_arcs`.

    >>> import numpy as np
    >>> from geobrep.plugins.blocks._orientation import DirectionTriangles
    >>> one = np.array([0], dtype=np.int64)
    >>> lone = DirectionTriangles(np.array([0, 1]), one, one, one, one, one, one, np.array([True]))
    >>> r = traverse(lone, 1)  # one patch alone around its arc: both sides in one region
    >>> int(r.positive[0]) == int(r.negative[0])
    True
    """
    rows = np.arange(around.patch.shape[0], dtype=np.int64)
    following = rows + 1
    ends = around.offsets[1:] - 1
    following[ends] = around.offsets[:-1]
    sense = np.where(around.forward, 1, -1).astype(np.int64)
    here = side_node(around.patch, sense)  # the side facing the next patch
    there = side_node(around.patch[following], -sense[following])  # its side facing back
    n_regions, labels = components(2 * n_patches, here, there)
    return Regions(
        positive=labels[0::2],
        negative=labels[1::2],
        n_regions=int(n_regions),
        link_patches=(around.patch, around.patch[following]),
    )
