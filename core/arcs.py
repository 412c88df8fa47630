"""Rebuild the corners and arcs of a B-Rep from its surface patches.

An **arc** is a maximal chain of patch-boundary edges shared by the *same set* of patches (a
horizon–fault intersection is shared by the horizon patch that ends there and the two fault
patches it separates; a free fault tip by the fault patch alone). A **corner** is a vertex
where that set changes, where more than two chains meet, where a chain ends, where the set
of patches touching the chain grows (a free fault border meeting a horizon), or one given as a
hint (``extra_corners``, e.g. GOCAD BSTONEs). A closed chain without any corner gets one corner
at its lowest vertex.

The computation is vectorised:

1. the vertices of every patch are joined across surfaces within ``tolerance`` (coincident
   vertices of different surfaces often differ in their last digits);
2. a patch's boundary edges are the edges used by exactly one of its triangles;
3. every boundary edge gets the signature of its patch set (two 64-bit hashes and a count);
4. corner vertices are found from edge counts, signature minima/maxima per vertex, and
   where the set of patches touching the chain's vertices grows along an edge;
5. corners are split per incident edge, so the remaining edge graph falls apart into simple
   paths and cycles (scipy connected components); each is ordered by one depth-first walk.

Arc ``patches`` are sorted in right-hand order around the arc's first edge (see
:func:`geobrep.geometry.sort_around_axis`), as :class:`~geobrep.topology.Arc` asks.

>>> import geobrep
>>> scene = geobrep.datasets.faulted_layer_cake()
>>> topology = build_corners_and_arcs(scene)
>>> len(topology.corners), len(topology.arcs)
(28, 52)
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from geobrep.entities import Surface
from geobrep.errors import TopologyError
from geobrep.geometry import mesh
from geobrep.geometry.bbox import column_extremes
from geobrep.scene import Scene
from geobrep.topology import Arc, Corner, Patch, Topology

__all__ = ["DEFAULT_RELATIVE_TOLERANCE", "build_corners_and_arcs", "corners_and_arcs"]

#: Default joining distance, relative to the diagonal of the patches' bounding box.
DEFAULT_RELATIVE_TOLERANCE = 1e-8

IntArray = NDArray[np.int64]

_HASH_A = np.uint64(0x9E3779B97F4A7C15)
_HASH_B = np.uint64(0xC2B2AE3D27D4EB4F)


def build_corners_and_arcs(
    scene: Scene, tolerance: float | None = None, extra_corners: ArrayLike | None = None
) -> Topology:
    """The scene's topology with corners and arcs rebuilt from its patches.

    Uses ``scene.topology.patches`` (their blocks are kept, their ``arcs`` replaced); a scene
    without patches gets one patch per patch label of every :class:`Surface`. ``tolerance`` is
    the distance under which vertices of different surfaces are one point (default:
    :data:`DEFAULT_RELATIVE_TOLERANCE` times the bounding-box diagonal of the patches);
    ``extra_corners`` are points (K, 3) forced to be corners where they meet a boundary vertex.

    >>> import geobrep
    >>> cake = geobrep.datasets.faulted_layer_cake()
    >>> rebuilt = build_corners_and_arcs(cake)
    >>> max(len(a.patches) for a in rebuilt.arcs)  # horizon meets fault: 1 + 2 fault patches
    3
    """
    surfaces = {int(s.id or 0): s for s in scene.surfaces}
    patches = list(scene.topology.patches)
    if not patches:
        for surface in scene.surfaces:
            for label in range(surface.n_patches):
                patches.append(
                    Patch(
                        id=len(patches),
                        surface=int(surface.id or 0),
                        label=label,
                        name=f"{surface.name}:{surface.patch_name(label)}",
                    )
                )
    corners, arcs, patch_arcs = corners_and_arcs(surfaces, patches, tolerance, extra_corners)
    return Topology(
        corners=tuple(corners),
        arcs=tuple(arcs),
        patches=tuple(
            p.model_copy(update={"arcs": tuple(patch_arcs.get(p.id, ()))}) for p in patches
        ),
    )


def _patch_triangles(
    surfaces: Mapping[int, Surface], patches: Sequence[Patch]
) -> tuple[NDArray[np.float64], IntArray, IntArray]:
    """All vertices used by the patches, their triangles (global indices) and patch positions."""
    vertex_parts: list[NDArray[np.float64]] = []
    offsets: dict[int, int] = {}
    total = 0
    triangle_parts: list[IntArray] = []
    owner_parts: list[IntArray] = []
    for position, patch in enumerate(patches):
        surface = surfaces.get(patch.surface)
        if surface is None:
            raise TopologyError(f"patch {patch.id}: entity {patch.surface} is not a Surface")
        if patch.surface not in offsets:
            offsets[patch.surface] = total
            vertex_parts.append(np.asarray(surface.vertices, dtype=np.float64))
            total += surface.n_vertices
        triangles, _ = mesh.triangulate(surface.faces[surface.patch_faces(patch.label)])
        triangle_parts.append(triangles + offsets[patch.surface])
        owner_parts.append(np.full(triangles.shape[0], position, dtype=np.int64))
    vertices = np.concatenate(vertex_parts) if vertex_parts else np.zeros((0, 3))
    triangles = np.concatenate(triangle_parts) if triangle_parts else np.zeros((0, 3), np.int64)
    owners = np.concatenate(owner_parts) if owner_parts else np.zeros(0, np.int64)
    return vertices, triangles.astype(np.int64), owners


def corners_and_arcs(
    surfaces: Mapping[int, Surface],
    patches: Sequence[Patch],
    tolerance: float | None = None,
    extra_corners: ArrayLike | None = None,
) -> tuple[list[Corner], list[Arc], dict[int, list[int]]]:
    """Corners, arcs and ``{patch id: arc ids}`` of ``patches`` (surfaces by entity id).

    The lower-level form of :func:`build_corners_and_arcs`, for readers that assemble a
    topology before they have a scene.
    """
    vertices, triangles, owners = _patch_triangles(surfaces, patches)
    if triangles.shape[0] == 0:
        return [], [], {}
    used, compact = np.unique(triangles, return_inverse=True)
    points = vertices[used]
    if tolerance is None:
        low, high = column_extremes(points)
        diagonal = float(np.linalg.norm(high - low))
        tolerance = DEFAULT_RELATIVE_TOLERANCE * (diagonal if diagonal > 0 else 1.0)
    merged, inverse = mesh.merge_close_vertices(points, tolerance)
    tri = inverse[compact.reshape(-1, 3)]
    proper = (tri[:, 0] != tri[:, 1]) & (tri[:, 1] != tri[:, 2]) & (tri[:, 0] != tri[:, 2])
    tri, owners = tri[proper], owners[proper]
    n_vertices = merged.shape[0]

    # -- boundary half-edges of every patch -------------------------------------------------
    start = tri.reshape(-1)
    end = tri[:, [1, 2, 0]].reshape(-1)
    third = tri[:, [2, 0, 1]].reshape(-1)
    owner = np.repeat(owners, 3)
    lo, hi = np.minimum(start, end), np.maximum(start, end)
    _, record, counts = np.unique(
        np.stack([owner, lo, hi], axis=1), axis=0, return_inverse=True, return_counts=True
    )
    boundary = counts[record.reshape(-1)] == 1
    lo, hi, third, owner = lo[boundary], hi[boundary], third[boundary], owner[boundary]
    if lo.size == 0:
        return [], [], {}

    # -- unique edges and the signature of their patch sets ---------------------------------
    edges, edge_of = np.unique(np.stack([lo, hi], axis=1), axis=0, return_inverse=True)
    edge_of = edge_of.reshape(-1)
    n_edges = edges.shape[0]
    with np.errstate(over="ignore"):
        key = owner.astype(np.uint64) + np.uint64(1)
        h1 = np.zeros(n_edges, dtype=np.uint64)
        h2 = np.zeros(n_edges, dtype=np.uint64)
        np.add.at(h1, edge_of, (key * _HASH_A) ^ (key >> np.uint64(7)))
        np.add.at(h2, edge_of, (key * _HASH_B) ^ (key << np.uint64(13)))
    multiplicity = np.bincount(edge_of, minlength=n_edges)
    # The same signature for the set of patches touching each vertex at all.
    touching = np.unique(np.stack([tri.reshape(-1), np.repeat(owners, 3)], axis=1), axis=0)
    with np.errstate(over="ignore"):
        touch_key = touching[:, 1].astype(np.uint64) + np.uint64(1)
        v1 = np.zeros(n_vertices, dtype=np.uint64)
        v2 = np.zeros(n_vertices, dtype=np.uint64)
        np.add.at(v1, touching[:, 0], (touch_key * _HASH_A) ^ (touch_key >> np.uint64(7)))
        np.add.at(v2, touching[:, 0], (touch_key * _HASH_B) ^ (touch_key << np.uint64(13)))
    touch_count = np.bincount(touching[:, 0], minlength=n_vertices)
    _, signature = np.unique(
        np.stack([h1.view(np.int64), h2.view(np.int64), multiplicity], axis=1),
        axis=0,
        return_inverse=True,
    )
    signature = signature.reshape(-1).astype(np.int64)

    # -- corners ------------------------------------------------------------------------------
    ends = edges.reshape(-1)
    edge_signature = np.repeat(signature, 2)
    degree = np.bincount(ends, minlength=n_vertices)
    sig_min = np.full(n_vertices, np.iinfo(np.int64).max, dtype=np.int64)
    sig_max = np.full(n_vertices, -1, dtype=np.int64)
    np.minimum.at(sig_min, ends, edge_signature)
    np.maximum.at(sig_max, ends, edge_signature)
    is_corner = (degree > 0) & ((degree != 2) | (sig_min != sig_max))
    # Where the set of patches touching the chain grows (a free fault border meeting a
    # horizon, or starting to run along a boundary it is not conformal with), the vertex that
    # touches more patches than its chain neighbour is a corner.
    lo_end, hi_end = edges[:, 0], edges[:, 1]
    differ = (
        (v1[lo_end] != v1[hi_end])
        | (v2[lo_end] != v2[hi_end])
        | (touch_count[lo_end] != touch_count[hi_end])
    )
    is_corner[lo_end[differ & (touch_count[lo_end] >= touch_count[hi_end])]] = True
    is_corner[hi_end[differ & (touch_count[hi_end] >= touch_count[lo_end])]] = True
    if extra_corners is not None:
        hints = np.asarray(extra_corners, dtype=np.float64).reshape(-1, 3)
        if hints.shape[0]:
            from scipy.spatial import cKDTree

            centre = 0.5 * np.add(*column_extremes(merged))
            distance, nearest = cKDTree(merged - centre).query(hints - centre)
            hit = nearest[distance <= max(tolerance, 0.0) * 1.0000001 + 0.0]
            is_corner[hit[degree[hit] > 0]] = True

    # -- split corners per incident edge; components are paths or cycles ---------------------
    node = edges.copy()
    corner_end = is_corner[edges]
    node[corner_end] = n_vertices + np.flatnonzero(corner_end.reshape(-1))
    n_nodes = n_vertices + 2 * n_edges
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components, depth_first_order

    graph = coo_matrix(
        (np.ones(n_edges, dtype=np.int8), (node[:, 0], node[:, 1])), shape=(n_nodes, n_nodes)
    ).tocsr()
    graph = (graph + graph.T).tocsr()
    _, component = connected_components(graph, directed=False)
    edge_component = component[node[:, 0]]
    _, arc_of_edge = np.unique(edge_component, return_inverse=True)
    arc_of_edge = arc_of_edge.reshape(-1)
    n_arcs = int(arc_of_edge.max()) + 1
    node_vertex = np.concatenate([np.arange(n_vertices), ends])

    # Start nodes: a split corner node of the arc (paths), or the lowest vertex (cycles).
    corner_nodes = node[corner_end]
    corner_arc = np.repeat(arc_of_edge, 2)[corner_end.reshape(-1)]
    start_node = np.full(n_arcs, -1, dtype=np.int64)
    lowest = np.full(n_arcs, np.iinfo(np.int64).max, dtype=np.int64)
    np.minimum.at(lowest, corner_arc, node_vertex[corner_nodes])
    has_corner = lowest < np.iinfo(np.int64).max
    # among corner nodes of an arc, start at the one on the lowest corner vertex
    candidate = corner_nodes[node_vertex[corner_nodes] == lowest[corner_arc]]
    candidate_arc = corner_arc[node_vertex[corner_nodes] == lowest[corner_arc]]
    start_node[candidate_arc[::-1]] = candidate[::-1]
    cycles = np.flatnonzero(~has_corner)
    if cycles.size:
        low_vertex = np.full(n_arcs, np.iinfo(np.int64).max, dtype=np.int64)
        np.minimum.at(low_vertex, arc_of_edge, edges.min(axis=1))
        start_node[cycles] = low_vertex[cycles]
        is_corner[low_vertex[cycles]] = True

    corner_vertices = np.flatnonzero(is_corner & (degree > 0))
    corner_id = np.full(n_vertices, -1, dtype=np.int64)
    corner_id[corner_vertices] = np.arange(corner_vertices.shape[0])
    corners = [Corner(id=int(i), point=merged[v]) for i, v in enumerate(corner_vertices.tolist())]

    chains: list[IntArray] = []
    for arc in range(n_arcs):
        walk = depth_first_order(
            graph, int(start_node[arc]), directed=False, return_predecessors=False
        )
        sequence = node_vertex[walk]
        if not has_corner[arc]:
            sequence = np.append(sequence, sequence[0])
        elif not is_corner[sequence[-1]]:
            raise TopologyError("arc reconstruction failed: a chain does not end at a corner")
        chains.append(sequence.astype(np.int64))
    # Direction: from the lower corner id to the higher (ties: lower second vertex first).
    keyed: list[tuple[int, int, int, IntArray, int]] = []
    for arc, sequence in enumerate(chains):
        first, last = int(corner_id[sequence[0]]), int(corner_id[sequence[-1]])
        if first > last or (first == last and sequence.shape[0] > 2 and sequence[-2] < sequence[1]):
            sequence = sequence[::-1].copy()
            first, last = last, first
        keyed.append((first, last, int(sequence[1]), sequence, arc))
    keyed.sort(key=lambda item: (item[0], item[1], item[2]))

    # Patches around each arc, right-hand order about its first edge.
    record_edge = edge_of
    record_order = np.argsort(record_edge, kind="stable")
    record_start = np.searchsorted(record_edge[record_order], np.arange(n_edges + 1))
    edge_keys = edges[:, 0] * n_vertices + edges[:, 1]
    arcs: list[Arc] = []
    patch_arcs: dict[int, list[int]] = {}
    for new_id, (start, end, _, sequence, _) in enumerate(keyed):
        p0, p1 = int(sequence[0]), int(sequence[1])
        edge = int(np.searchsorted(edge_keys, min(p0, p1) * n_vertices + max(p0, p1)))
        records = record_order[record_start[edge] : record_start[edge + 1]]
        members = owner[records]
        origin = merged[p0]
        directions = merged[third[records]] - origin
        if members.shape[0] > 1:
            around = mesh.sort_around_axis(origin, merged[p1] - origin, directions)
            members = members[around]
        patch_ids = tuple(int(patches[int(m)].id) for m in members.tolist())
        arcs.append(
            Arc(
                id=new_id,
                points=merged[sequence],
                start=start,
                end=end,
                patches=patch_ids,
            )
        )
        for patch_id in dict.fromkeys(patch_ids):
            patch_arcs.setdefault(patch_id, []).append(new_id)
    return corners, arcs, patch_arcs
