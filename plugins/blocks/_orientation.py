"""Direction edges and direction triangles (the paper's 方向边 and 方向三角形).

For each arc one of its edges, traversed along the arc, is the **direction edge**; the triangles
using it, one per patch occurrence around the arc, are its **direction triangles**. A direction
triangle is **forward** when it runs along the arc (it holds the directed edge start → end):
its patch's boundary then follows the arc, and its normal points to the next patch
counter-clockwise around the arc (right-hand rule, thumb along the arc).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from geobrep.geometry.arrays import BoolArray, IntArray
from geobrep.plugins.blocks._arcs import ArcChains
from geobrep.plugins.blocks._csr import concatenated_ranges
from geobrep.plugins.blocks._patches import PatchSplit

__all__ = ["DirectionTriangles", "direction_triangles"]


@dataclass(frozen=True)
class DirectionTriangles:
    """Triangles around chosen edges, grouped (CSR) by ``group``.

    Row ``i`` is triangle ``triangle[i]`` of patch ``patch[i]`` on the edge ``start[i] →
    end[i]`` (an edge of arc ``arc[i]``), ``forward[i]`` when the triangle runs along it.
    """

    offsets: IntArray
    arc: IntArray
    edge_position: IntArray
    start: IntArray
    end: IntArray
    triangle: IntArray
    patch: IntArray
    forward: BoolArray

    @property
    def n_groups(self) -> int:
        return int(self.offsets.shape[0] - 1)

    @property
    def group(self) -> IntArray:
        return np.repeat(np.arange(self.n_groups, dtype=np.int64), np.diff(self.offsets))

    def take_groups(self, groups: IntArray) -> DirectionTriangles:
        """The rows of some groups, in the given group order."""
        starts = self.offsets[groups]
        counts = self.offsets[groups + 1] - starts
        rows = concatenated_ranges(starts, counts)
        return self._rows(rows, np.concatenate([[0], np.cumsum(counts)]).astype(np.int64))

    def reorder(self, rows: IntArray) -> DirectionTriangles:
        """The same groups with rows permuted (``rows`` must keep each group's rows together)."""
        return self._rows(rows, self.offsets)

    def _rows(self, rows: IntArray, offsets: IntArray) -> DirectionTriangles:
        return DirectionTriangles(
            offsets=offsets,
            arc=self.arc[rows],
            edge_position=self.edge_position[rows],
            start=self.start[rows],
            end=self.end[rows],
            triangle=self.triangle[rows],
            patch=self.patch[rows],
            forward=self.forward[rows],
        )


def direction_triangles(
    triangles: IntArray, split: PatchSplit, chains: ArcChains, positions: IntArray
) -> DirectionTriangles:
    """The triangles around the arc edges at ``positions`` (indices into ``chains.edge_ids``).

    Each position makes one group; the arc of a group is the arc holding that edge.

    >>> from geobrep.plugins.blocks._arcs import sample_model_arcs
    >>> soup, split, chains = sample_model_arcs()
    >>> first = direction_triangles(soup.triangles, split, chains, chains.arc_offsets[:-1])
    >>> first.n_groups, first.triangle.shape[0]
    (52, 132)
    """
    edge_arc = chains.edge_arc
    edges = chains.edge_ids[positions]
    starts = split.offsets[edges]
    counts = split.offsets[edges + 1] - starts
    rows = concatenated_ranges(starts, counts)
    triangle = split.incident_triangles[rows]
    side = split.incident_sides[rows]
    start = np.repeat(chains.edge_start[positions], counts)
    return DirectionTriangles(
        offsets=np.concatenate([[0], np.cumsum(counts)]).astype(np.int64),
        arc=np.repeat(edge_arc[positions], counts),
        edge_position=np.repeat(positions, counts),
        start=start,
        end=np.repeat(chains.edge_end[positions], counts),
        triangle=triangle,
        patch=split.triangle_patch[triangle],
        forward=triangles[triangle, side] == start,
    )
