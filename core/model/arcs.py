"""Corners and arcs of a B-Rep from its patches: the one rule the GOCAD reader, the block builder
and the sample model share.

An **arc edge** is an edge where the patches do not simply continue: any edge that is not used by
exactly two triangles of one patch (the block builder, which finds the patches itself, also
cuts them at orientation seams, so there a seam is an arc edge too). Every arc edge has the
*multiset* of the patches of its triangles (``{H, F1, F2}`` where a horizon ends on a fault;
``{B, B, H}`` where a horizon ends inside a box it does not cut). A vertex of arc edges is a
**corner** when

1. it does not join exactly two arc edges (three or more arcs meet there, or a chain ends);
2. its two arc edges have different patch multisets;
3. the set of patches *touching* the chain changes there: of two neighbouring chain vertices
   touched by different sets of patches, the one touched by more (both when as many) is a
   corner (a free fault border crossing a horizon at one vertex);
4. the source marks it as one (``extra_corners``: GOCAD ``BSTONE`` lines, which the GOCAD
   writer puts at every corner so that a written model reads back with the same corners);
5. it is the lowest vertex — in (x, y, z) lexicographic order — of a closed chain that no
   rule above gave a corner.

An **arc** is a maximal chain of arc edges between corners. Corners are numbered in (x, y, z)
order; an arc runs from its lower-numbered corner to its higher one (a loop through one corner
starts along its edge whose other vertex is lower), and arcs are listed by (start, end, second
point). So the same geometry gives the same corners and arcs whatever the vertex numbering:
reading a Model3d, rebuilding its blocks from the bare surfaces and reading it back after
writing all agree.

The computation is vectorised: edge–triangle incidence, multiset signatures per arc edge (one
sort of (edge, patch) keys, each edge's patches packed as the digits of one integer), corner
tests per vertex, and one depth-first walk over the graph of arc edges continuing each other
(list ranking, :func:`geobrep.geometry.graph.path_order`) that lists every chain in order.

>>> import geobrep
>>> scene = geobrep.datasets.faulted_layer_cake()
>>> topology = build_corners_and_arcs(scene)
>>> len(topology.corners), len(topology.arcs)
(28, 52)
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from geobrep.errors import DegenerateGeometryError, TopologyError
from geobrep.geometry import mesh
from geobrep.geometry.arrays import BoolArray, IntArray
from geobrep.geometry.bbox import column_extremes
from geobrep.geometry.graph import cell_hash, component_roots, nearest_within, path_order
from geobrep.geometry.mesh import _PROJECTION_RTOL
from geobrep.model.arrays import as_readonly
from geobrep.model.entities import Surface
from geobrep.model.scene import Scene
from geobrep.model.topology import Arc, Corner, Patch, Topology

__all__ = [
    "DEFAULT_RELATIVE_TOLERANCE",
    "ArcChains",
    "JoinedIncidence",
    "JoinedPatches",
    "build_corners_and_arcs",
    "chain_arc_edges",
    "corners_and_arcs",
    "corners_and_arcs_of",
]

#: Default joining distance, relative to the diagonal of the patches' bounding box.
DEFAULT_RELATIVE_TOLERANCE = 1e-8


_HASH_A = np.uint64(0x9E3779B97F4A7C15)
_HASH_B = np.uint64(0xC2B2AE3D27D4EB4F)


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


class JoinedIncidence(NamedTuple):
    """The edge–face incidence of :class:`JoinedPatches` triangles, as
    :func:`~geobrep.geometry.mesh.edge_face_incidence` gives it, with the patch (position in
    ``patches``) of each incident triangle and whether each edge is **inner**: used by exactly
    two triangles of one patch."""

    edges: IntArray
    offsets: IntArray
    incident: IntArray
    sides: IntArray
    incident_patch: IntArray
    inner: BoolArray


class JoinedPatches(NamedTuple):
    """The patches' triangles once coincident vertices are joined, as
    :func:`corners_and_arcs_of` builds the corners and arcs on them (for a reader that goes on
    to check the blocks on the same mesh, see :func:`geobrep.model.orientation.orient_blocks`).

    ``triangles`` use the ``points`` (joined vertices), triangles the joining collapsed left
    out; ``owners`` (ascending) is the position in ``patches`` of each triangle's patch and
    ``surfaces`` the surface of each patch. ``exact``: every joined point stands for copies of
    one point only (no two different points were joined). ``incidence``: how the triangles
    use their edges, when known.
    """

    points: NDArray[np.float64]
    triangles: IntArray
    owners: IntArray
    patches: tuple[Patch, ...]
    surfaces: tuple[Surface, ...]
    tolerance: float
    exact: bool
    incidence: JoinedIncidence | None = None


def _multiset_signatures(
    offsets: IntArray, incident_patch: IntArray, arc_edges: IntArray
) -> IntArray:
    """An id per arc edge, equal for edges used by the same multiset of patches."""
    positions, rows = mesh.csr_row_positions(offsets, arc_edges)
    counts = np.bincount(rows, minlength=arc_edges.shape[0])
    within = np.arange(rows.shape[0], dtype=np.int64) - np.repeat(
        np.cumsum(counts) - counts, counts
    )
    patches = incident_patch[positions]
    width = int(counts.max())
    highest = int(patches.max(initial=0))
    bits = max(highest.bit_length(), 1)  # a patch
    digit_bits = (highest + 1).bit_length()  # a patch + 1 (0: an empty slot)
    packable = width * digit_bits <= 62 and bits + max(arc_edges.shape[0], 1).bit_length() <= 62
    if packable and int(patches.min(initial=0)) >= 0:
        # Rows ascend already: one sort of (row, patch) keys sorts each row's patches in
        # place, and a row's sorted patches packed as digits of one integer name its multiset.
        ordered = np.sort(rows << bits | patches, kind="stable")  # rows ascend: runs
        digit = (ordered & ((1 << bits) - 1)) + 1
        key = np.zeros(arc_edges.shape[0], dtype=np.int64)
        for slot in range(width):
            used = np.flatnonzero(within == slot)
            key[rows[used]] += digit[used] << (digit_bits * slot)
        return _dense_labels(key)
    order = np.lexsort((patches, rows))
    table = np.full((arc_edges.shape[0], width), -1, dtype=np.int64)
    table[rows, within] = patches[order]
    _, signature = np.unique(table, axis=0, return_inverse=True)
    return signature.reshape(-1).astype(np.int64)


def _sorted_unique(values: IntArray) -> IntArray:
    """``np.unique`` of integers by one sort (numpy's hashing ``unique`` is many times slower).
    The sort is the stable one (timsort, the same values as any sort): keys made from sorted
    edges or rows come in ascending runs that it merges (5-10x faster than quicksort here)."""
    ordered = np.sort(values.reshape(-1), kind="stable")
    keep = np.ones(ordered.shape[0], dtype=np.bool_)
    keep[1:] = ordered[1:] != ordered[:-1]
    return ordered[keep]


def _dense_labels(keys: IntArray) -> IntArray:
    """Labels ``0 … k-1`` of the distinct ``keys`` (equal keys, equal labels), ascending."""
    distinct = _sorted_unique(keys)
    return np.searchsorted(distinct, keys).astype(np.int64)


def _touch_corners(
    edges: IntArray,
    offsets: IntArray,
    incident_patch: IntArray,
    ends: IntArray,
    n_vertices: int,
    corner: BoolArray,
) -> None:
    """Rule 3: mark where the set of patches touching a chain changes (``corner`` in place)."""
    on_arc = np.zeros(n_vertices, dtype=np.bool_)
    on_arc[ends.reshape(-1)] = True
    near = np.flatnonzero(on_arc[edges[:, 0]] | on_arc[edges[:, 1]])
    positions, rows = mesh.csr_row_positions(offsets, near)
    patch = incident_patch[positions]
    n_patches = int(incident_patch.max()) + 1 if incident_patch.size else 1
    vertex, member = _touching_pairs(edges[near[rows]], patch, on_arc, n_patches)
    with np.errstate(over="ignore"):
        key = member.astype(np.uint64) + np.uint64(1)
        h1 = np.zeros(n_vertices, dtype=np.uint64)
        h2 = np.zeros(n_vertices, dtype=np.uint64)
        np.add.at(h1, vertex, (key * _HASH_A) ^ (key >> np.uint64(7)))
        np.add.at(h2, vertex, (key * _HASH_B) ^ (key << np.uint64(13)))
    count = np.bincount(vertex, minlength=n_vertices)
    p, q = ends[:, 0], ends[:, 1]
    differ = (h1[p] != h1[q]) | (h2[p] != h2[q]) | (count[p] != count[q])
    corner[p[differ & (count[p] >= count[q])]] = True
    corner[q[differ & (count[q] >= count[p])]] = True


def _touching_pairs(
    ends: IntArray, patch: IntArray, on_arc: BoolArray, n_patches: int
) -> tuple[IntArray, IntArray]:
    """The distinct ``(vertex, patch)`` pairs, ascending, of the arc vertices (``on_arc``)
    among the ``ends`` of edges used by triangles of ``patch``: marked in a table of arc
    vertex by patch when it is not much larger than the pairs, else sorted."""
    arc_vertices = np.flatnonzero(on_arc)
    size = arc_vertices.shape[0] * n_patches
    if size > 8 * ends.size + (1 << 16):
        keys = []
        for column in (0, 1):
            vertex = ends[:, column]
            keep = on_arc[vertex]
            keys.append(vertex[keep] * n_patches + patch[keep])
        pairs = _sorted_unique(np.concatenate(keys))
        return pairs // n_patches, pairs % n_patches
    local = np.cumsum(on_arc, dtype=np.int64) - 1
    touched = np.zeros(size, dtype=np.bool_)
    for column in (0, 1):
        vertex = ends[:, column]
        keep = on_arc[vertex]
        touched[local[vertex[keep]] * n_patches + patch[keep]] = True
    pairs = np.flatnonzero(touched)
    return arc_vertices[pairs // n_patches], pairs % n_patches


def _through_pairs(
    ends: IntArray, signature: IntArray, n_vertices: int, corner: BoolArray
) -> tuple[IntArray, IntArray]:
    """Pairs of arc edges (local ids) continuing each other through a non-corner vertex.

    ``corner`` (per vertex) is updated in place by rules 1 and 2.
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
    keep = ~differs & ~corner[at]
    return a[keep], b[keep]


def _vertex_rank(points: NDArray[np.float64] | None, used: IntArray, n_vertices: int) -> IntArray:
    """Rank of every vertex of ``used`` in (x, y, z) order (vertex id without points)."""
    rank = np.full(n_vertices, -1, dtype=np.int64)
    if points is None:
        rank[used] = used
        return rank
    p = points[used]
    order = np.lexsort((used, p[:, 2], p[:, 1], p[:, 0]))
    rank[used[order]] = np.arange(used.shape[0], dtype=np.int64)
    return rank


def _permute_rows(offsets: IntArray, perm: IntArray) -> tuple[IntArray, IntArray]:
    """New offsets and gather positions of CSR rows listed in ``perm`` order."""
    lengths = np.diff(offsets)[perm]
    new_offsets = np.zeros(perm.shape[0] + 1, dtype=np.int64)
    np.cumsum(lengths, out=new_offsets[1:])
    gather = np.repeat(offsets[:-1][perm] - new_offsets[:-1], lengths) + np.arange(
        int(new_offsets[-1]), dtype=np.int64
    )
    return new_offsets, gather


def _empty_chains() -> ArcChains:
    empty = np.zeros(0, dtype=np.int64)
    one = np.zeros(1, dtype=np.int64)
    return ArcChains(empty, empty, empty, one, empty, one, empty, empty, empty)


def _edge_components(a: IntArray, b: IntArray, n: int) -> IntArray:
    """Chain label of each of ``n`` arc edges, ``a[i]`` and ``b[i]`` continuing each other."""
    return mesh.compact_indices(component_roots(n, a, b), n)[1]


def _corner_closed_chains(
    ends: IntArray, component: IntArray, rank: IntArray, corner: BoolArray
) -> bool:
    """Rule 5: give every closed chain without a corner its lowest vertex as one.

    ``corner`` is updated in place; returns whether any chain was closed.
    """
    n_components = int(component.max()) + 1
    touches = (corner[ends[:, 0]] | corner[ends[:, 1]]).astype(np.float64)
    closed = np.flatnonzero(np.bincount(component, weights=touches, minlength=n_components) == 0)
    if not closed.size:
        return False
    lowest = np.full(n_components, np.iinfo(np.int64).max, dtype=np.int64)
    np.minimum.at(lowest, component, np.minimum(rank[ends[:, 0]], rank[ends[:, 1]]))
    by_rank = np.empty(int(rank.max()) + 1, dtype=np.int64)
    by_rank[rank[rank >= 0]] = np.flatnonzero(rank >= 0)
    corner[by_rank[lowest[closed]]] = True
    return True


class _Links(NamedTuple):
    """Corners (per vertex), vertex ranks and how the arc edges continue each other."""

    corner: BoolArray
    rank: IntArray
    a: IntArray
    b: IntArray
    component: IntArray


def _find_corners(
    edges: IntArray,
    offsets: IntArray,
    incident_patch: IntArray,
    ends: IntArray,
    signature: IntArray,
    n_vertices: int,
    points: NDArray[np.float64] | None,
    extra_corners: BoolArray | None,
) -> _Links:
    """Corners by rules 1 to 5 and the chains of arc edges between them."""
    corner = np.zeros(n_vertices, dtype=np.bool_)
    _touch_corners(edges, offsets, incident_patch, ends, n_vertices, corner)
    if extra_corners is not None:
        corner |= extra_corners
    degree = np.bincount(ends.reshape(-1), minlength=n_vertices)
    corner &= degree > 0
    a, b = _through_pairs(ends, signature, n_vertices, corner)
    rank = _vertex_rank(points, np.flatnonzero(degree > 0), n_vertices)
    n = int(ends.shape[0])
    component = _edge_components(a, b, n)
    if _corner_closed_chains(ends, component, rank, corner):
        a, b = _through_pairs(ends, signature, n_vertices, corner)
        component = _edge_components(a, b, n)
    return _Links(corner=corner, rank=rank, a=a, b=b, component=component)


def _chain_heads(ends: IntArray, links: _Links) -> tuple[IntArray, IntArray]:
    """Head edge of each chain, at its lowest corner (ties: the lower other vertex), and that
    corner."""
    n = int(ends.shape[0])
    candidate_edge = np.tile(np.arange(n, dtype=np.int64), 2)
    candidate_vertex = ends.T.reshape(-1)
    at_corner = links.corner[candidate_vertex]
    candidate_edge, candidate_vertex = candidate_edge[at_corner], candidate_vertex[at_corner]
    other = ends[candidate_edge].sum(axis=1) - candidate_vertex
    candidate_component = links.component[candidate_edge]
    order = np.lexsort((links.rank[other], links.rank[candidate_vertex], candidate_component))
    first = np.ones(order.shape[0], dtype=np.bool_)
    first[1:] = candidate_component[order][1:] != candidate_component[order][:-1]
    return candidate_edge[order][first], candidate_vertex[order][first]


def _walk_chains(links: _Links, heads: IntArray, n: int) -> IntArray:
    """The ``n`` arc edges chain after chain, each chain in order from its head."""
    try:
        ordered = path_order(n, links.a, links.b, heads)
    except TopologyError:  # pragma: no cover - through pairs form paths
        ordered = np.zeros(0, dtype=np.int64)
    if ordered.shape[0] != n:  # pragma: no cover - every chain has a head
        raise TopologyError("arc reconstruction failed: a chain does not end at a corner")
    return ordered


class _Walk(NamedTuple):
    """Arc edges in walk order, split into arcs, each edge directed along its arc."""

    ordered: IntArray  # arc-edge positions in walk order
    arc: IntArray  # arc of each ordered edge
    arc_offsets: IntArray
    start: IntArray
    end: IntArray
    last: IntArray  # position of each arc's last edge


def _direct_edges(
    ends: IntArray, ordered: IntArray, component: IntArray, heads: IntArray, head_vertex: IntArray
) -> _Walk:
    """Split the walk into arcs and direct every edge along its arc from the arc's head."""
    n = int(ordered.shape[0])
    chain_of = component[ordered]
    new_chain = np.ones(n, dtype=np.bool_)
    new_chain[1:] = chain_of[1:] != chain_of[:-1]
    arc = np.cumsum(new_chain) - 1
    arc_offsets = np.append(np.flatnonzero(new_chain), n).astype(np.int64)
    head_of_component = np.empty(int(component.max()) + 1, dtype=np.int64)
    head_of_component[component[heads]] = head_vertex

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
    return _Walk(ordered, arc, arc_offsets, start, end, last)


def _chain_vertices(walk: _Walk) -> tuple[IntArray, IntArray]:
    """Vertices of every arc in order (its edges' starts, then its last end) and their CSR
    offsets."""
    n = int(walk.ordered.shape[0])
    n_arcs = walk.arc_offsets.shape[0] - 1
    chain_offsets = walk.arc_offsets + np.arange(n_arcs + 1, dtype=np.int64)
    chain = np.empty(n + n_arcs, dtype=np.int64)
    chain[np.arange(n) + walk.arc] = walk.start
    chain[walk.last + walk.arc[walk.last] + 1] = walk.end[walk.last]
    return chain, chain_offsets


def _number_corners(
    links: _Links, walk: _Walk, n_vertices: int
) -> tuple[IntArray, IntArray, IntArray]:
    """Corner vertices in (x, y, z) order and the start and end corner (index) of every arc."""
    corner_vertices = np.flatnonzero(links.corner)
    corners = corner_vertices[np.argsort(links.rank[corner_vertices], kind="stable")].astype(
        np.int64
    )
    corner_index = np.full(n_vertices, -1, dtype=np.int64)
    corner_index[corners] = np.arange(corners.shape[0], dtype=np.int64)
    arc_start = corner_index[walk.start[walk.arc_offsets[:-1]]]
    arc_end = corner_index[walk.end[walk.last]]
    if (arc_start < 0).any() or (arc_end < 0).any():  # pragma: no cover - heads are corners
        raise TopologyError("arc reconstruction failed: a chain does not end at a corner")
    return corners, arc_start, arc_end


def chain_arc_edges(
    edges: IntArray,
    offsets: IntArray,
    incident_patch: IntArray,
    arc_edges: IntArray,
    n_vertices: int,
    points: NDArray[np.float64] | None = None,
    extra_corners: BoolArray | None = None,
) -> ArcChains:
    """Corners and ordered arcs of the arc edges ``arc_edges`` (indices into ``edges``).

    ``edges`` (E, 2) are all edges of the mesh with their triangles' patches in CSR form
    (``incident_patch[offsets[e]:offsets[e + 1]]``); ``points`` (V, 3) give the geometric
    order of corners and arcs (vertex ids without them); ``extra_corners`` (V,) are rule-4
    corners. The rule is the module's.

    >>> import numpy as np
    >>> from geobrep.geometry import mesh
    >>> square = np.array([[0, 1, 2], [0, 2, 3]])
    >>> edges, offsets, faces, _ = mesh.edge_face_incidence(square)
    >>> arc_edges = np.flatnonzero(np.diff(offsets) == 1)
    >>> patch = np.zeros(offsets[-1], np.int64)  # both triangles in patch 0
    >>> chains = chain_arc_edges(edges, offsets, patch, arc_edges, 4)
    >>> chains.n_arcs, chains.corners.tolist()  # one closed border, cornered at vertex 0
    (1, [0])
    """
    arc_edges = np.asarray(arc_edges, dtype=np.int64)
    n = int(arc_edges.shape[0])
    if n == 0:
        return _empty_chains()
    ends = edges[arc_edges]
    signature = _multiset_signatures(offsets, incident_patch, arc_edges)
    links = _find_corners(
        edges, offsets, incident_patch, ends, signature, n_vertices, points, extra_corners
    )
    heads, head_vertex = _chain_heads(ends, links)
    ordered = _walk_chains(links, heads, n)
    walk = _direct_edges(ends, ordered, links.component, heads, head_vertex)
    chain, chain_offsets = _chain_vertices(walk)
    corners, arc_start, arc_end = _number_corners(links, walk, n_vertices)

    # Arcs listed by (start corner, end corner, rank of the second point).
    second = links.rank[chain[chain_offsets[:-1] + 1]]
    perm = np.lexsort((second, arc_end, arc_start)).astype(np.int64)
    arc_offsets, edge_gather = _permute_rows(walk.arc_offsets, perm)
    chain_offsets, chain_gather = _permute_rows(chain_offsets, perm)
    return ArcChains(
        edge_ids=arc_edges[ordered][edge_gather],
        edge_start=walk.start[edge_gather],
        edge_end=walk.end[edge_gather],
        arc_offsets=arc_offsets,
        chain_vertices=chain[chain_gather],
        chain_offsets=chain_offsets,
        corners=corners,
        arc_start=arc_start[perm],
        arc_end=arc_end[perm],
    )


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
    """All vertices used by the patches, their triangles (global indices) and patch positions.

    Each surface is triangulated and its triangles grouped by patch label once (a stable
    sort: a patch's triangles keep the order of its faces)."""
    vertex_parts: list[NDArray[np.float64]] = []
    grouped: dict[int, tuple[IntArray, IntArray]] = {}  # surface id -> triangles, label bounds
    total = 0
    triangle_parts: list[IntArray] = []
    counts = np.zeros(len(patches), dtype=np.int64)
    for position, patch in enumerate(patches):
        surface = surfaces.get(patch.surface)
        if surface is None:
            raise TopologyError(f"patch {patch.id}: entity {patch.surface} is not a Surface")
        if not 0 <= patch.label < surface.n_patches:
            surface.patch_faces(patch.label)  # raises the surface's own error
        if patch.surface not in grouped:
            vertex_parts.append(np.asarray(surface.vertices, dtype=np.float64))
            faces = np.asarray(surface.faces)
            source: IntArray | None = None  # None: each face is its triangle
            if faces.ndim == 2 and faces.shape[1] == 3 and faces.dtype == np.int64:
                # a validated surface's triangles (int64 already: no copy made)
                triangles = faces.astype(np.int64, copy=False)
            else:
                triangles, source = mesh.triangulate(faces)
            if surface.patch_labels is None:
                labels = np.zeros(triangles.shape[0], dtype=np.int64)
            else:
                labels = np.asarray(surface.patch_labels, dtype=np.int64)
                if source is not None:
                    labels = labels[source]
            if labels.shape[0] < 2 or bool((labels[1:] >= labels[:-1]).all()):
                ordered = labels  # grouped already: the stable sort leaves every face
                grouped_triangles = triangles + total
            else:
                order = np.argsort(labels, kind="stable")
                ordered = labels[order]
                grouped_triangles = triangles[order] + total
            bounds = np.searchsorted(ordered, np.arange(surface.n_patches + 1))
            grouped[patch.surface] = (grouped_triangles, bounds)
            total += surface.n_vertices
        triangles, bounds = grouped[patch.surface]
        part = triangles[bounds[patch.label] : bounds[patch.label + 1]]
        triangle_parts.append(part)
        counts[position] = part.shape[0]
    vertices = np.concatenate(vertex_parts) if vertex_parts else np.zeros((0, 3))
    triangles = np.concatenate(triangle_parts) if triangle_parts else np.zeros((0, 3), np.int64)
    owners = np.repeat(np.arange(len(patches), dtype=np.int64), counts)
    return vertices, triangles.astype(np.int64, copy=False), owners


def _around(
    chains: ArcChains,
    arc: int,
    points: NDArray[np.float64],
    tri: IntArray,
    offsets: IntArray,
    incident: IntArray,
    sides: IntArray,
    incident_patch: IntArray,
) -> IntArray:
    """Patches of the triangles at arc ``arc``, in right-hand order about its first edge
    whose triangles all leave it at an angle (a clip may leave slivers on some)."""
    lo, hi = int(chains.arc_offsets[arc]), int(chains.arc_offsets[arc + 1])
    members = incident_patch[offsets[chains.edge_ids[lo]] : offsets[chains.edge_ids[lo] + 1]]
    if members.shape[0] < 2:
        return members
    for k in range(lo, hi):
        edge = int(chains.edge_ids[k])
        around = slice(int(offsets[edge]), int(offsets[edge + 1]))
        thirds = tri[incident[around], (sides[around] + 2) % 3]
        origin = points[int(chains.edge_start[k])]
        axis = points[int(chains.edge_end[k])] - origin
        try:
            order = mesh.sort_around_axis(origin, axis, points[thirds] - origin)
        except DegenerateGeometryError:
            continue
        return incident_patch[around][order]
    return members


def _patch_orders(
    chains: ArcChains,
    points: NDArray[np.float64],
    tri: IntArray,
    offsets: IntArray,
    incident: IntArray,
    sides: IntArray,
    incident_patch: IntArray,
) -> list[IntArray]:
    """:func:`_around` of every arc: the right-hand order about each arc's first edge is
    found for all arcs at once (the sort of :func:`geobrep.geometry.sort_around_axis`, arc by
    arc); an arc whose first edge has a triangle along the axis is left to :func:`_around`."""
    n_arcs = chains.n_arcs
    first = chains.edge_ids[chains.arc_offsets[:-1]]
    positions, arc_of = mesh.csr_row_positions(offsets, first)
    count = np.diff(offsets)[first]
    members = incident_patch[positions]
    orders: list[IntArray] = np.split(members, np.cumsum(count)[:-1])
    sorted_arcs = np.flatnonzero(count >= 2)
    if not sorted_arcs.size:
        return orders
    keep = count[arc_of] >= 2
    positions, arc_of = positions[keep], arc_of[keep]
    start = points[chains.edge_start[chains.arc_offsets[:-1]]]
    axis = points[chains.edge_end[chains.arc_offsets[:-1]]] - start
    axis_length = np.sqrt(np.einsum("ij,ij->i", axis, axis))
    with np.errstate(invalid="ignore", divide="ignore"):
        u = axis / axis_length[:, None]
    thirds = tri[incident[positions], (sides[positions] + 2) % 3]
    dirs = points[thirds] - start[arc_of]
    ua = u[arc_of]
    along = np.einsum("ij,ij->i", dirs, ua)
    proj = dirs - along[:, None] * ua
    proj_length = np.sqrt(np.einsum("ij,ij->i", proj, proj))
    dir_length = np.sqrt(np.einsum("ij,ij->i", dirs, dirs))
    bad = (proj_length <= _PROJECTION_RTOL * dir_length) | (dir_length == 0.0)
    degenerate = np.zeros(n_arcs, dtype=np.bool_)
    degenerate[arc_of[bad]] = True
    degenerate |= ~(axis_length > 0.0)
    # the reference direction of each arc: its first incident triangle
    local_head = np.searchsorted(arc_of, np.arange(n_arcs))  # among the kept ones
    with np.errstate(invalid="ignore", divide="ignore"):
        e1 = proj[np.minimum(local_head, proj.shape[0] - 1)]
        e1 = e1 / proj_length[np.minimum(local_head, proj.shape[0] - 1)][:, None]
    e2 = np.cross(u, e1)
    angles = np.arctan2(
        np.einsum("ij,ij->i", proj, e2[arc_of]), np.einsum("ij,ij->i", proj, e1[arc_of])
    )
    is_head = np.zeros(positions.shape[0], dtype=np.bool_)
    is_head[local_head[sorted_arcs]] = True
    angles[is_head] = 0.0
    angles = np.where(angles < 0.0, angles + 2.0 * np.pi, angles)
    angles[angles >= 2.0 * np.pi] = 0.0
    order = np.lexsort((angles, arc_of))
    ordered = incident_patch[positions[order]]
    bounds = np.cumsum(count[sorted_arcs])
    for a, part in zip(sorted_arcs.tolist(), np.split(ordered, bounds[:-1]), strict=True):
        if degenerate[a]:
            orders[a] = _around(chains, a, points, tri, offsets, incident, sides, incident_patch)
        else:
            orders[a] = part
    return orders


def _nearest(points: NDArray[np.float64], queries: NDArray[np.float64], reach: float) -> IntArray:
    """The nearest of ``points`` to each query within ``reach`` (queries without one left
    out): a hashed grid, or scipy's k-d tree for a crowd of points closer than ``reach``."""
    nearest = nearest_within(points, queries, reach)
    if nearest is None:
        from scipy.spatial import cKDTree

        distance, found = cKDTree(points).query(queries)
        nearest = np.where(distance <= reach, found, -1)
    return np.asarray(nearest[nearest >= 0], dtype=np.int64)


def _exact_rows(points: NDArray[np.float64], queries: NDArray[np.float64]) -> IntArray:
    """For each query, the index of the point with exactly its coordinates (``-0.0`` equal to
    ``0.0``; the points are distinct), or -1: one hash per point, searched among the queries'."""
    found = np.full(queries.shape[0], -1, dtype=np.int64)
    point_bits = np.ascontiguousarray(points + 0.0).view(np.int64)
    query_bits = np.ascontiguousarray(queries + 0.0).view(np.int64)
    wanted = _sorted_unique(cell_hash(query_bits))
    keys = cell_hash(point_bits)
    at = np.minimum(np.searchsorted(wanted, keys), wanted.shape[0] - 1)
    candidates = np.flatnonzero(wanted[at] == keys)
    if not candidates.size:
        return found
    index_of = {point_bits[i].tobytes(): i for i in candidates.tolist()}
    for k, row in enumerate(query_bits):
        found[k] = index_of.get(row.tobytes(), -1)
    return found


def _corner_hints(
    merged: NDArray[np.float64], wanted: NDArray[np.float64], tolerance: float
) -> BoolArray:
    """Rule-4 corners: the joined vertex nearest to each of ``wanted`` within ``tolerance``.

    A wanted point that is one of the vertices (the usual BSTONE) is its own nearest: the
    joined vertices lie more than ``tolerance`` apart, so no other is as near (nor ties with
    it once centred, when the tolerance exceeds the rounding of the centring). The others are
    searched for (:func:`_nearest`)."""
    hints = np.zeros(merged.shape[0], dtype=np.bool_)
    centre = 0.5 * np.add(*column_extremes(merged))
    extent = float(np.abs(merged - centre).max()) + float(np.abs(centre).max())
    if tolerance > 16.0 * np.finfo(np.float64).eps * extent:
        exact = _exact_rows(merged, wanted)
        hints[exact[exact >= 0]] = True
        wanted = wanted[exact < 0]
    if wanted.shape[0]:
        hints[_nearest(merged - centre, wanted - centre, max(tolerance, 0.0) * 1.0000001)] = True
    return hints


def corners_and_arcs(
    surfaces: Mapping[int, Surface],
    patches: Sequence[Patch],
    tolerance: float | None = None,
    extra_corners: ArrayLike | None = None,
) -> tuple[list[Corner], list[Arc], dict[int, list[int]]]:
    """Corners, arcs and ``{patch id: arc ids}`` of ``patches`` (surfaces by entity id).

    The lower-level form of :func:`build_corners_and_arcs`, for readers that assemble a
    topology before they have a scene. Arc ``patches`` list the patch of every triangle at the
    arc's first edge (a patch on both sides twice) in right-hand order about that edge (see
    :func:`geobrep.geometry.sort_around_axis`), as :class:`~geobrep.model.topology.Arc` asks.
    """
    corners, arcs, patch_arcs, _ = corners_and_arcs_of(surfaces, patches, tolerance, extra_corners)
    return corners, arcs, patch_arcs


def corners_and_arcs_of(
    surfaces: Mapping[int, Surface],
    patches: Sequence[Patch],
    tolerance: float | None = None,
    extra_corners: ArrayLike | None = None,
) -> tuple[list[Corner], list[Arc], dict[int, list[int]], JoinedPatches | None]:
    """:func:`corners_and_arcs` and the :class:`JoinedPatches` they are built on (None when
    the patches have no triangles)."""
    vertices, triangles, owners = _patch_triangles(surfaces, patches)
    if triangles.shape[0] == 0:
        return [], [], {}, None
    used, compact = mesh.compact_indices(triangles, vertices.shape[0])
    points = vertices[used]
    if tolerance is None:
        low, high = column_extremes(points)
        diagonal = float(np.linalg.norm(high - low))
        tolerance = DEFAULT_RELATIVE_TOLERANCE * (diagonal if diagonal > 0 else 1.0)
    merged, inverse = mesh.merge_close_vertices(points, tolerance)
    tri = inverse[compact.reshape(-1, 3)]
    proper = (tri[:, 0] != tri[:, 1]) & (tri[:, 1] != tri[:, 2]) & (tri[:, 0] != tri[:, 2])
    tri, owners = tri[proper], owners[proper]
    if tri.shape[0] == 0:
        return [], [], {}, None
    n_vertices = merged.shape[0]
    edges, offsets, incident, sides = mesh.edge_face_incidence(tri)
    incident_patch = owners[incident]
    counts = np.diff(offsets)
    inner = counts == 2
    pair = np.flatnonzero(inner)
    inner[pair] = incident_patch[offsets[pair]] == incident_patch[offsets[pair] + 1]
    joined = JoinedPatches(
        points=merged,
        triangles=tri,
        owners=owners,
        patches=tuple(patches),
        surfaces=tuple(surfaces[p.surface] for p in patches),
        tolerance=float(tolerance),
        exact=bool(np.array_equal(points, np.take(merged, inverse, axis=0))),
        incidence=JoinedIncidence(edges, offsets, incident, sides, incident_patch, inner),
    )
    hints = None
    if extra_corners is not None:
        wanted = np.asarray(extra_corners, dtype=np.float64).reshape(-1, 3)
        if wanted.shape[0]:
            hints = _corner_hints(merged, wanted, tolerance)
    chains = chain_arc_edges(
        edges, offsets, incident_patch, np.flatnonzero(~inner), n_vertices, merged, hints
    )

    # Corners and arcs are built from checked data (finite joined vertices, arcs of at least
    # one edge between numbered corners): what their validation would do is done here.
    corners = [
        Corner.model_construct(id=i, point=as_readonly(merged[v]))
        for i, v in enumerate(chains.corners.tolist())
    ]
    arcs: list[Arc] = []
    patch_arcs: dict[int, list[int]] = {}
    orders = _patch_orders(chains, merged, tri, offsets, incident, sides, incident_patch)
    patch_id_of = [int(p.id) for p in patches]
    starts, ends = chains.arc_start.tolist(), chains.arc_end.tolist()
    bounds = chains.chain_offsets.tolist()
    for a, members in enumerate(orders):
        patch_ids = tuple(patch_id_of[m] for m in members.tolist())
        arcs.append(
            Arc.model_construct(
                id=a,
                points=as_readonly(merged[chains.chain_vertices[bounds[a] : bounds[a + 1]]]),
                start=starts[a],
                end=ends[a],
                patches=patch_ids,
            )
        )
        for patch_id in dict.fromkeys(patch_ids):
            patch_arcs.setdefault(patch_id, []).append(a)
    return corners, arcs, patch_arcs, joined
