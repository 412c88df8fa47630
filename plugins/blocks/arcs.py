"""Arcs: maximal chains of arc edges shared by the same patches, between corners.

A vertex on arc edges is a **corner** unless exactly two arc edges meet there and both are used
by the same multiset of patches; a closed chain without such a vertex gets its lowest vertex as
corner. Each arc is ordered from its start corner (the lower vertex id of its two ends) to its
end corner, which fixes its direction once for all patches around it — the paper's "arc
direction consistency" holds by construction.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from geobrep.plugins.blocks.patches import PatchSplit

__all__ = ["ArcChains", "chain_arcs"]

IntArray = NDArray[np.int64]
BoolArray = NDArray[np.bool_]


@dataclass(frozen=True)
class ArcChains:
    """Arcs as ordered edge and vertex chains (CSR by arc).

    Arc ``a`` runs along edges ``edge_ids[arc_offsets[a]:arc_offsets[a + 1]]``, each traversed
    from ``edge_start`` to ``edge_end``, through vertices
    ``chain_vertices[chain_offsets[a]:chain_offsets[a + 1]]``. ``corners`` are vertex ids and
    ``arc_start`` / ``arc_end`` index into them.
    """

    edge_ids: IntArray
    edge_start: IntArray
    edge_end: IntArray
    arc_offsets: IntArray
    chain_vertices: IntArray
    chain_offsets: IntArray
    corners: IntArray
    arc_start: IntArray
    arc_end: IntArray

    @property
    def n_arcs(self) -> int:
        return int(self.arc_offsets.shape[0] - 1)

    @property
    def edge_arc(self) -> IntArray:
        """Arc of each ordered edge."""
        return np.repeat(np.arange(self.n_arcs, dtype=np.int64), np.diff(self.arc_offsets)).astype(
            np.int64
        )


def _signatures(split: PatchSplit, arc_edges: IntArray) -> IntArray:
    """An id per arc edge, equal for edges used by the same multiset of patches."""
    starts = split.offsets[arc_edges]
    counts = split.offsets[arc_edges + 1] - starts
    rows = np.repeat(np.arange(arc_edges.shape[0], dtype=np.int64), counts)
    within = np.arange(rows.shape[0], dtype=np.int64) - np.repeat(
        np.cumsum(counts) - counts, counts
    )
    patches = split.triangle_patch[split.incident_triangles[np.repeat(starts, counts) + within]]
    order = np.lexsort((patches, rows))
    table = np.full((arc_edges.shape[0], int(counts.max())), -1, dtype=np.int64)
    table[rows, within] = patches[order]
    _, signature = np.unique(table, axis=0, return_inverse=True)
    return signature.reshape(-1).astype(np.int64)


def _through_pairs(
    ends: IntArray, signature: IntArray, n_vertices: int, corner: BoolArray
) -> tuple[IntArray, IntArray, IntArray]:
    """Pairs of arc edges (local ids) continuing each other through a non-corner vertex.

    Also returns the vertex of each pair. ``corner`` (per vertex) is updated in place: vertices
    of arc edges that do not continue a chain become corners.
    """
    n = ends.shape[0]
    flat = ends.T.reshape(-1)
    owner = np.tile(np.arange(n, dtype=np.int64), 2)
    order = np.argsort(flat, kind="stable")
    vertex, edge = flat[order], owner[order]
    degree = np.bincount(flat, minlength=n_vertices)
    corner[flat] |= degree[flat] != 2
    head = np.flatnonzero(
        (vertex[:-1] == vertex[1:]) & (degree[vertex[:-1]] == 2) & ~corner[vertex[:-1]]
    )
    a, b, at = edge[head], edge[head + 1], vertex[head]
    differs = signature[a] != signature[b]
    corner[at[differs]] = True
    keep = ~differs
    return a[keep], b[keep], at[keep]


def chain_arcs(split: PatchSplit, n_vertices: int) -> ArcChains:
    """Group the arc edges of ``split`` into ordered arcs between corners.

    >>> import geobrep
    >>> from geobrep.plugins.blocks.patches import split_patches
    >>> from geobrep.plugins.blocks.soup import build_soup
    >>> soup = build_soup(geobrep.datasets.faulted_layer_cake().surfaces, None, 1e-7)
    >>> chains = chain_arcs(split_patches(soup), soup.vertices.shape[0])
    >>> chains.n_arcs, len(chains.corners)
    (52, 28)"""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components, depth_first_order

    arc_edges = split.arc_edges
    n = int(arc_edges.shape[0])
    if n == 0:
        empty = np.zeros(0, dtype=np.int64)
        return ArcChains(empty, empty, empty, np.zeros(1, np.int64), empty, np.zeros(1, np.int64),
                         empty, empty, empty)  # fmt: skip
    ends = split.edges[arc_edges]
    signature = _signatures(split, arc_edges)
    corner = np.zeros(n_vertices, dtype=np.bool_)
    a, b, _ = _through_pairs(ends, signature, n_vertices, corner)

    def components(a: IntArray, b: IntArray) -> IntArray:
        graph = coo_matrix((np.ones(a.shape[0], np.int8), (a, b)), shape=(n, n))
        labels: IntArray = connected_components(graph, directed=False)[1].astype(np.int64)
        return labels

    component = components(a, b)
    # Closed chains with no corner: their lowest vertex becomes one.
    n_components = int(component.max()) + 1
    touches = (corner[ends[:, 0]] | corner[ends[:, 1]]).astype(np.float64)
    touches_corner = np.bincount(component, weights=touches, minlength=n_components)
    closed = np.flatnonzero(touches_corner == 0)
    if closed.size:
        lowest = np.full(n_components, np.iinfo(np.int64).max, dtype=np.int64)
        np.minimum.at(lowest, component, ends.min(axis=1))
        corner[lowest[closed]] = True
        a, b, _ = _through_pairs(ends, signature, n_vertices, corner)
        component = components(a, b)
        n_components = int(component.max()) + 1

    # Head of each chain: the edge touching its lowest corner (ties: lowest edge).
    candidate_edge = np.tile(np.arange(n, dtype=np.int64), 2)
    candidate_vertex = ends.T.reshape(-1)
    at_corner = corner[candidate_vertex]
    candidate_edge, candidate_vertex = candidate_edge[at_corner], candidate_vertex[at_corner]
    candidate_component = component[candidate_edge]
    order = np.lexsort((candidate_edge, candidate_vertex, candidate_component))
    first = np.ones(order.shape[0], dtype=np.bool_)
    first[1:] = candidate_component[order][1:] != candidate_component[order][:-1]
    heads = candidate_edge[order][first]
    head_vertex = candidate_vertex[order][first]

    # A depth-first walk from a virtual root tied to every head lists each chain in order.
    root = n
    rows = np.concatenate([a, np.full(heads.shape[0], root, dtype=np.int64)])
    cols = np.concatenate([b, heads])
    graph = coo_matrix((np.ones(rows.shape[0], np.int8), (rows, cols)), shape=(n + 1, n + 1))
    walk = depth_first_order(graph.tocsr(), root, directed=False, return_predecessors=False)
    ordered = np.asarray(walk[1:], dtype=np.int64)
    if ordered.shape[0] != n:  # pragma: no cover - every chain has a head
        raise AssertionError("arc chains: the walk missed some edges")
    chain_of = component[ordered]
    new_chain = np.ones(n, dtype=np.bool_)
    new_chain[1:] = chain_of[1:] != chain_of[:-1]
    arc = np.cumsum(new_chain) - 1
    arc_offsets = np.append(np.flatnonzero(new_chain), n).astype(np.int64)
    head_of_component = np.empty(n_components, dtype=np.int64)
    head_of_component[component[heads]] = head_vertex

    # Direction of every edge along its arc.
    p, q = ends[ordered, 0], ends[ordered, 1]
    start = np.empty(n, dtype=np.int64)
    end = np.empty(n, dtype=np.int64)
    has_next = np.zeros(n, dtype=np.bool_)
    has_next[:-1] = arc[1:] == arc[:-1]
    k = np.flatnonzero(has_next)
    p_shared = (p[k] == p[k + 1]) | (p[k] == q[k + 1])
    end[k] = np.where(p_shared, p[k], q[k])
    start[k] = np.where(p_shared, q[k], p[k])
    last = np.flatnonzero(~has_next)
    single = arc_offsets[arc[last]] == last
    previous_end = end[np.maximum(last - 1, 0)]
    start[last] = np.where(single, head_of_component[chain_of[last]], previous_end)
    end[last] = p[last] + q[last] - start[last]

    arc_ids = np.arange(arc_offsets.shape[0] - 1, dtype=np.int64)
    chain_offsets = arc_offsets + np.arange(arc_offsets.shape[0], dtype=np.int64)
    chain = np.empty(n + arc_ids.shape[0], dtype=np.int64)
    chain[np.arange(n) + arc] = start
    chain[last + arc[last] + 1] = end[last]

    corners = np.flatnonzero(corner).astype(np.int64)
    corner_index = np.full(n_vertices, -1, dtype=np.int64)
    corner_index[corners] = np.arange(corners.shape[0], dtype=np.int64)
    arc_start = corner_index[start[arc_offsets[:-1]]]
    arc_end = corner_index[end[last]]
    return ArcChains(
        edge_ids=arc_edges[ordered],
        edge_start=start,
        edge_end=end,
        arc_offsets=arc_offsets,
        chain_vertices=chain,
        chain_offsets=chain_offsets,
        corners=corners,
        arc_start=arc_start,
        arc_end=arc_end,
    )
