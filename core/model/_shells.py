"""The boundary shells of many blocks at once, for :mod:`geobrep.model.orientation`.

:meth:`Scene.block_mesh` builds one block's shell and joins its coincident vertices; orienting
every block of a model that way merges the same vertices once per block. Here the vertices of
all the surfaces are joined once (the same tolerance) and each patch's triangles are gathered
once: each shell is then a few slices of them.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from geobrep.geometry import mesh
from geobrep.geometry.arrays import BoolArray, FloatArray, IntArray
from geobrep.model.entities import Block, Surface
from geobrep.model.scene import RELATIVE_MERGE_TOLERANCE, Scene

if TYPE_CHECKING:
    from geobrep.model.arcs import JoinedIncidence

__all__ = [
    "PatchEdges",
    "Shell",
    "block_shell",
    "block_shells",
    "open_edges_if_one_way",
    "patch_edges",
    "patch_edges_of_incidence",
    "patch_triangles",
]


class Shell(NamedTuple):
    """A block's boundary: its vertices, triangles and the boundary side of each triangle."""

    vertices: FloatArray
    faces: IntArray
    patch_labels: IntArray


def patch_triangles(scene: Scene, blocks: list[Block]) -> tuple[FloatArray, dict[int, IntArray]]:
    """All the surfaces' vertices (joined) and each listed patch's triangles in their ids."""
    surfaces: dict[int, Surface] = {}
    for block in blocks:
        for side in block.sides:
            patch = scene.topology.patch(side.patch)
            if patch.surface not in surfaces:
                surface = scene.get(patch.surface)
                assert isinstance(surface, Surface)  # checked at construction
                surfaces[patch.surface] = surface
    offsets: dict[int, int] = {}
    total = 0
    for surface_id, surface in surfaces.items():
        offsets[surface_id] = total
        total += surface.n_vertices
    sorted_triangles: list[IntArray] = []
    label_bounds: list[IntArray] = []
    for surface_id, surface in surfaces.items():
        triangles, source = mesh.triangulate(surface.faces)
        labels = (
            np.zeros(source.shape[0], dtype=np.int64)
            if surface.patch_labels is None
            else np.asarray(surface.patch_labels, dtype=np.int64)[source]
        )
        order = np.argsort(labels, kind="stable")
        label_bounds.append(np.searchsorted(labels[order], np.arange(surface.n_patches + 1)))
        sorted_triangles.append(triangles.astype(np.int64)[order] + offsets[surface_id])
    vertices = np.concatenate([s.vertices for s in surfaces.values()] or [np.zeros((0, 3))])
    every = np.concatenate(sorted_triangles) if sorted_triangles else np.zeros((0, 3), np.int64)
    used, _ = mesh.compact_indices(every, total)
    box = scene.bounds
    tolerance = RELATIVE_MERGE_TOLERANCE * (box.diagonal if box else 1.0)
    points, inverse = mesh.merge_close_vertices(vertices[used], tolerance)
    renumber = np.full(total, -1, dtype=np.int64)
    renumber[used] = inverse
    # each surface's triangles renumbered once; the triangles the joining collapses are no
    # part of any shell; each label keeps a slice of the rest
    by_patch: dict[tuple[int, int], IntArray] = {}
    for surface_id, triangles, bounds in zip(surfaces, sorted_triangles, label_bounds, strict=True):
        joined = renumber[triangles]
        a, b, c = joined[:, 0], joined[:, 1], joined[:, 2]
        keep = (a != b) & (b != c) & (a != c)
        kept = joined[keep]
        kept_bounds = np.concatenate([[0], np.cumsum(keep)])[bounds].tolist()
        for label in range(bounds.shape[0] - 1):
            by_patch[(surface_id, label)] = kept[kept_bounds[label] : kept_bounds[label + 1]]
    triangles_of = {
        patch.id: by_patch[(patch.surface, patch.label)]
        for patch in scene.topology.patches
        if (patch.surface, patch.label) in by_patch
    }
    return points, triangles_of


def block_shell(points: FloatArray, triangles_of: dict[int, IntArray], block: Block) -> Shell:
    """One block's boundary from the joined patch triangles."""
    internal = block.internal_patches
    pieces: list[IntArray] = []
    labels: list[IntArray] = []
    for patch_id, side in block.sides:
        if patch_id in internal:
            continue
        triangles = triangles_of[patch_id]
        pieces.append(mesh.flip_faces(triangles) if side == 1 else triangles)
        labels.append(np.full(triangles.shape[0], len(labels), dtype=np.int64))
    used, compact = mesh.compact_indices(np.concatenate(pieces), int(points.shape[0]))
    return Shell(points[used], compact, np.concatenate(labels))


def block_shells(scene: Scene, blocks: list[Block]) -> Iterator[Shell]:
    """The boundary of each of ``blocks`` as :meth:`Scene.block_mesh` builds it (faces flipped
    where the block is on a patch's positive side, patches listed with both sides left out,
    triangles the joining collapses dropped, one patch label per boundary side), in order."""
    points, triangles_of = patch_triangles(scene, blocks)
    for block in blocks:
        yield block_shell(points, triangles_of, block)


class PatchEdges(NamedTuple):
    """How the joined triangles of every patch use their edges, for checking many shells at
    once: an edge only one patch has ("own") decides alone whether a shell through that patch
    runs one way there and is closed there; the edges several patches share are listed.

    Patches are numbered by ``position`` (patch id -> index). ``own_conflict[i]``: an own edge
    of patch ``i`` is used twice in one direction; ``own_open[i]``: its own edges used by one
    triangle. ``shared_*`` (CSR by patch, ``shared_offsets``): each shared edge's key and how
    many triangles of the patch use it from its lower vertex (``forward``) and the other way.
    """

    position: dict[int, int]
    own_conflict: BoolArray
    own_open: IntArray
    shared_offsets: IntArray
    shared_key: IntArray
    shared_forward: IntArray
    shared_backward: IntArray


def patch_edges(triangles_of: dict[int, IntArray], n_points: int) -> PatchEdges | None:
    """:class:`PatchEdges` of the joined patch triangles (one sort of one key per triangle
    side); None when the keys would not fit an int64."""
    ids = list(triangles_of)
    n_patches = max(len(ids), 1)
    n = max(n_points, 1)
    if not _keys_fit(n, n_patches):
        return None
    counts = np.array([triangles_of[i].shape[0] for i in ids], dtype=np.int64)
    triangles = (
        np.concatenate([triangles_of[i] for i in ids]) if ids else np.zeros((0, 3), np.int64)
    )
    start = triangles.reshape(-1)
    end = triangles[:, [1, 2, 0]].reshape(-1)
    patch = np.repeat(np.repeat(np.arange(len(ids), dtype=np.int64), counts), 3)
    edge = np.minimum(start, end) * n + np.maximum(start, end)
    # one key per triangle side: (edge, patch, direction), sorted
    ordered = np.sort(((edge * n_patches + patch) << 1) | (start > end))
    pair = ordered >> 1  # edge * n_patches + patch
    edge = pair // n_patches
    return _grouped_patch_edges(ids, edge, pair - edge * n_patches, (ordered & 1).astype(np.bool_))


def patch_edges_of_incidence(
    ids: list[int], index_of: IntArray, faces: IntArray, incidence: JoinedIncidence, n_points: int
) -> PatchEdges | None:
    """:func:`patch_edges` from the incidence of the joined triangles ``faces`` (no sort): the
    patches are ``ids``, patch ``p`` of the incidence is ``ids[index_of[p]]`` (-1: none of
    them). ``index_of`` must ascend over the patches it keeps (so that each edge's triangles
    list them in order); None when it does not, or when :func:`patch_edges` gives None.

    An inner edge (two triangles of one patch) is an own edge used by two triangles: it only
    tells whether they use it the same way. The other edges go through the whole rule."""
    if not _keys_fit(max(n_points, 1), max(len(ids), 1)):
        return None
    listed = index_of[index_of >= 0]
    if listed.size > 1 and bool((listed[1:] < listed[:-1]).any()):
        return None
    edges, offsets, incident, sides, incident_patch, inner = incidence
    # the vertex each incident triangle side starts at, in incidence order (one gather of the
    # faces for all the sides rather than one per use)
    side_start = np.take(faces.reshape(-1), incident * faces.shape[1] + sides)
    every = bool(listed.shape[0] == index_of.shape[0])  # no patch of the incidence left out
    pair = np.flatnonzero(inner)
    at = offsets[pair]
    pair_patch = np.take(index_of, np.take(incident_patch, at))
    if not every:
        kept = pair_patch >= 0
        pair, at, pair_patch = pair[kept], at[kept], pair_patch[kept]
    # both triangles start the edge at one vertex
    one_way = pair_patch[np.take(side_start, at) == np.take(side_start, at + 1)]
    # the other edges' triangle sides, by edge then patch
    others = np.flatnonzero(~inner)
    positions, row = mesh.csr_row_positions(offsets, others)
    patch = np.take(index_of, np.take(incident_patch, positions))
    if every:
        edge = np.take(others, row)
    else:
        kept_sides = np.flatnonzero(patch >= 0)
        positions, patch = positions[kept_sides], patch[kept_sides]
        edge = others[row[kept_sides]]
    start = np.take(side_start, positions)
    high = edges[edge, 1]
    # the triangles are proper: every edge joins two vertices, the higher one second
    key = edges[edge, 0] * max(n_points, 1) + high
    found = _grouped_patch_edges(ids, key, patch, start == high)
    if one_way.size:
        found.own_conflict[one_way] = True
    return found


def _keys_fit(n: int, n_patches: int) -> bool:
    """Whether :func:`patch_edges`'s side keys fit an int64."""
    return float(n) * n * n_patches * 2 < 2.0**62


def _grouped_patch_edges(
    ids: list[int], edge: IntArray, patch: IntArray, backward: BoolArray
) -> PatchEdges:
    """:class:`PatchEdges` of triangle sides grouped by ``(edge, patch)`` in ascending order
    (in any order within a group): each side's edge key, patch (index into ``ids``) and
    whether it runs from the edge's higher vertex."""
    n_ids = len(ids)
    n_sides = edge.shape[0]
    edge_start = np.ones(n_sides, dtype=np.bool_)
    np.not_equal(edge[1:], edge[:-1], out=edge_start[1:])
    pair_start = edge_start.copy()
    pair_start[1:] |= patch[1:] != patch[:-1]
    # one row per (edge, patch) pair: its sides each way
    first = np.flatnonzero(pair_start)
    length = np.diff(np.append(first, n_sides))
    backward_count = (
        np.add.reduceat(backward.astype(np.int64), first) if first.size else first.copy()
    )
    forward_count = length - backward_count
    row_patch = patch[first]
    # an edge is shared when its run of sides holds two patches
    run = np.cumsum(edge_start[first]) - 1
    shared = np.bincount(run, minlength=int(run[-1]) + 1 if run.size else 0)[run] > 1
    own = ~shared
    # own edges: used twice one way, or by one triangle
    conflict = own & ((forward_count > 1) | (backward_count > 1))
    own_conflict = np.bincount(row_patch[conflict], minlength=n_ids) > 0
    own_open = np.bincount(row_patch[own & (length == 1)], minlength=n_ids).astype(np.int64)
    # shared edges: how often each patch uses them each way, by patch
    rows = np.flatnonzero(shared)
    row_patch = row_patch[rows]
    by_patch = np.argsort(row_patch, kind="stable")
    offsets = np.zeros(n_ids + 1, dtype=np.int64)
    np.cumsum(np.bincount(row_patch, minlength=n_ids), out=offsets[1:])
    return PatchEdges(
        position={patch_id: k for k, patch_id in enumerate(ids)},
        own_conflict=own_conflict,
        own_open=own_open,
        shared_offsets=offsets,
        shared_key=edge[first[rows]][by_patch],
        shared_forward=forward_count[rows][by_patch].astype(np.int64),
        shared_backward=backward_count[rows][by_patch].astype(np.int64),
    )


def open_edges_if_one_way(edges: PatchEdges, block: Block) -> int | None:
    """The number of edges of ``block``'s shell used by one triangle when every edge of the
    shell is used at most once in each direction (the shell runs one way: no triangle to
    flip), else None."""
    internal = block.internal_patches
    sides = [(edges.position[p], side) for p, side in block.sides if p not in internal]
    where = np.array([k for k, _ in sides], dtype=np.int64)
    if edges.own_conflict[where].any():
        return None
    keys: list[IntArray] = []
    forward: list[IntArray] = []
    backward: list[IntArray] = []
    bounds = edges.shared_offsets
    for k, side in sides:
        lo, hi = int(bounds[k]), int(bounds[k + 1])
        keys.append(edges.shared_key[lo:hi])
        ahead, back = edges.shared_forward[lo:hi], edges.shared_backward[lo:hi]
        forward.append(back if side == 1 else ahead)  # the positive side is flipped
        backward.append(ahead if side == 1 else back)
    open_edges = int(edges.own_open[where].sum())
    key = np.concatenate(keys)
    if key.size:
        _, inverse = np.unique(key, return_inverse=True)
        ahead_total = np.bincount(inverse, weights=np.concatenate(forward))
        back_total = np.bincount(inverse, weights=np.concatenate(backward))
        if (ahead_total > 1).any() or (back_total > 1).any():
            return None
        open_edges += int(((ahead_total + back_total) == 1).sum())
    return open_edges
