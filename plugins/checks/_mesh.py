"""Mesh checks: colocated and isolated vertices, degenerate, duplicated and inverted elements,
non-manifold edges and vertices, inconsistent orientation. One entity at a time, vectorised."""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from geobrep import PolyLine, Scene, Surface, TetMesh
from geobrep.geometry import mesh
from geobrep.geometry.orientation import neighbour_pairs, orientation_flips
from geobrep.plugins import CheckContext, Defect
from geobrep.plugins.checks._common import (
    defects,
    edge_incidence,
    first_copies,
    mesh_entities,
    neighbours,
    tolerance,
    triangles,
)

__all__ = [
    "colocated_vertices",
    "degenerate_elements",
    "duplicated_elements",
    "inconsistent_orientation",
    "inverted_tets",
    "isolated_vertices",
    "non_manifold_edges",
    "non_manifold_vertices",
]

IntArray = NDArray[np.int64]
FloatArray = NDArray[np.float64]
_TET_FACES = np.array([[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]])


def colocated_vertices(scene: Scene, options: Any, context: CheckContext) -> list[Defect]:
    """Vertices of one entity lying within the tolerance of each other inside one part (a
    surface's patch: GOCAD TFACE parts hold their own copies of the vertices they share, and
    those copies are no defect); groups sharing a vertex are one. One defect per group: the
    vertices the ``weld`` repair merges into one
    (:func:`geobrep.geometry.mesh.merge_close_vertices_in_parts`)."""
    tol = tolerance(scene, context)
    found: list[Defect] = []
    for entity in [*mesh_entities(scene), *scene.point_sets]:
        n = entity.vertices.shape[0]
        if n < 2:
            continue
        _, inverse = mesh.merge_close_vertices_in_parts(entity.vertices, _parts(entity), tol)
        sizes = np.bincount(inverse)
        shared = np.flatnonzero(sizes[inverse] > 1)
        if shared.size == 0:
            continue
        order = shared[np.argsort(inverse[shared], kind="stable")]
        for group in np.split(order, np.flatnonzero(np.diff(inverse[order])) + 1):
            ids = np.sort(group)
            found += defects(
                entity,
                "vertex",
                ids[None, :],
                entity.vertices[ids[0]][None],
                points=entity.vertices[ids[:1]][None],
                message=f"{ids.size} vertices within {tol:.3g}",
            )
    return found


def _parts(entity: Any) -> list[IntArray]:
    """The vertex sets welded on their own: each patch of a surface, else the whole entity."""
    if isinstance(entity, Surface):
        return mesh.part_vertices(entity.faces, entity.patch_labels, entity.vertices.shape[0])
    return [np.arange(entity.vertices.shape[0], dtype=np.int64)]


def _surface_degenerates(surface: Surface, tol: float, context: CheckContext) -> list[Defect]:
    tris, source = triangles(surface, context)
    columns = np.ascontiguousarray(np.asarray(surface.vertices, dtype=np.float64).T)
    corner = [np.take(columns, tris[:, c], axis=1) for c in range(3)]  # (xyz, T) each
    sides = [corner[(c + 1) % 3] - corner[c] for c in range(3)]  # side c: corner c to c + 1
    lengths = np.stack([np.sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]) for s in sides], axis=1)
    found: list[Defect] = []
    short = lengths <= tol
    rows, cols = np.nonzero(short)
    if rows.size:
        ends = np.stack([tris[rows, cols], tris[rows, (cols + 1) % 3]], axis=1)
        ends = np.unique(np.sort(ends, axis=1), axis=0)
        found += defects(
            surface,
            "edge",
            ends,
            surface.vertices[ends].mean(axis=1),
            points=surface.vertices[ends],
            values=np.linalg.norm(np.diff(surface.vertices[ends], axis=1)[:, 0], axis=1),
            message="zero-length edge",
        )
    u, v = sides[0], -sides[2]
    normal = (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])
    doubled = np.sqrt(normal[0] * normal[0] + normal[1] * normal[1] + normal[2] * normal[2])
    longest = np.maximum(np.maximum(lengths[:, 0], lengths[:, 1]), lengths[:, 2])
    with np.errstate(divide="ignore", invalid="ignore"):
        height = np.where(longest > 0.0, doubled / longest, 0.0)
    flat = np.flatnonzero((height <= tol) & ~(short[:, 0] | short[:, 1] | short[:, 2]))
    if flat.size:
        corners = surface.vertices[tris[flat]]
        found += defects(
            surface,
            "face",
            source[flat],
            corners.mean(axis=1),
            points=corners,
            values=0.5 * doubled[flat],
            message="zero-area triangle (a sliver: its height is within the tolerance)",
        )
    return found


def _tet_degenerates(tets: TetMesh, tol: float) -> list[Defect]:
    corners = tets.vertices[tets.cells]
    volume = np.abs(tets.cell_volumes)
    faces = corners[:, _TET_FACES]
    areas = 0.5 * np.linalg.norm(
        np.cross(faces[:, :, 1] - faces[:, :, 0], faces[:, :, 2] - faces[:, :, 0]), axis=2
    )
    with np.errstate(divide="ignore", invalid="ignore"):
        height = np.where(areas.max(axis=1) > 0, 3.0 * volume / areas.max(axis=1), 0.0)
    flat = np.flatnonzero(height <= tol)
    return defects(
        tets,
        "tet",
        flat,
        corners[flat].mean(axis=1),
        values=volume[flat],
        message="flat tet (its height is within the tolerance)",
    )


def _line_degenerates(line: PolyLine, tol: float) -> list[Defect]:
    segments = line.segments
    ends = line.vertices[segments]
    length = np.linalg.norm(ends[:, 1] - ends[:, 0], axis=1)
    short = np.flatnonzero(length <= tol)
    return defects(
        line,
        "segment",
        short,
        ends[short].mean(axis=1),
        points=ends[short],
        values=length[short],
        message="zero-length segment",
    )


def degenerate_elements(scene: Scene, options: Any, context: CheckContext) -> list[Defect]:
    """Zero-length edges and segments, zero-area triangles, flat tets (within the tolerance)."""
    tol = tolerance(scene, context)
    found: list[Defect] = []
    for entity in mesh_entities(scene):
        if isinstance(entity, Surface):
            found += _surface_degenerates(entity, tol, context)
        elif isinstance(entity, TetMesh):
            found += _tet_degenerates(entity, tol)
        else:
            found += _line_degenerates(entity, tol)
    return found


def _elements(entity: Surface | TetMesh | PolyLine, context: CheckContext) -> IntArray:
    if isinstance(entity, Surface):
        return np.asarray(entity.faces, dtype=np.int64)
    if isinstance(entity, TetMesh):
        return np.asarray(entity.cells, dtype=np.int64)
    return np.asarray(entity.segments, dtype=np.int64)


def duplicated_elements(scene: Scene, options: Any, context: CheckContext) -> list[Defect]:
    """Faces, tets or segments over the same vertices as an earlier one (any order)."""
    element: dict[type, str] = {Surface: "face", TetMesh: "tet", PolyLine: "segment"}
    found: list[Defect] = []
    for entity in mesh_entities(scene):
        cells = _elements(entity, context)
        if cells.shape[0] < 2:
            continue
        first = first_copies(np.sort(cells, axis=1))
        copies = np.flatnonzero(first != np.arange(cells.shape[0]))
        if copies.size == 0:
            continue
        shape = entity.vertices[cells[copies]] if cells.shape[1] in (2, 3) else None
        found += defects(
            entity,
            element[type(entity)],
            copies,
            entity.vertices[cells[copies]].mean(axis=1),
            points=shape,
            other_ids=first[copies],
            message="duplicate of the element in other_ids",
        )
    return found


def isolated_vertices(scene: Scene, options: Any, context: CheckContext) -> list[Defect]:
    """Vertices of a surface, tet mesh or polyline that no element uses."""
    found: list[Defect] = []
    for entity in mesh_entities(scene):
        used = np.zeros(entity.vertices.shape[0], dtype=np.bool_)
        used[_elements(entity, context).reshape(-1)] = True
        lonely = np.flatnonzero(~used)
        found += defects(
            entity,
            "vertex",
            lonely,
            entity.vertices[lonely],
            points=entity.vertices[lonely][:, None],
            message="used by no element",
        )
    return found


def _boundary_faces(entity: Surface | TetMesh, context: CheckContext) -> IntArray:
    if isinstance(entity, Surface):
        return triangles(entity, context)[0]
    faces = np.asarray(entity.cells, dtype=np.int64)[:, _TET_FACES].reshape(-1, 3)
    key = np.sort(faces, axis=1)
    _, inverse, counts = np.unique(key, axis=0, return_inverse=True, return_counts=True)
    return np.asarray(faces[counts[inverse.reshape(-1)] == 1], dtype=np.int64)


def non_manifold_edges(scene: Scene, options: Any, context: CheckContext) -> list[Defect]:
    """Surface edges used by more than two faces (and tet meshes' boundary edges so used)."""
    found: list[Defect] = []
    for entity in mesh_entities(scene):
        if isinstance(entity, PolyLine):
            continue
        if isinstance(entity, Surface):
            if entity.n_faces == 0:
                continue
            edges, offsets, _, _ = edge_incidence(entity, context)
            counts = np.diff(offsets)
        else:
            faces = _boundary_faces(entity, context)
            if faces.shape[0] == 0:
                continue
            edges, counts = mesh.edge_face_counts(faces)
        bad = edges[counts > 2]
        found += defects(
            entity,
            "edge",
            bad,
            entity.vertices[bad].mean(axis=1),
            points=entity.vertices[bad],
            values=counts[counts > 2],
            message="edge shared by more than two faces (value: how many)",
        )
    return found


def _fans(
    faces: IntArray, n_vertices: int, incidence: tuple[IntArray, IntArray, IntArray, IntArray]
) -> tuple[IntArray, IntArray]:
    """Per vertex: how many faces use it and how many fans (faces joined across edges), from
    the faces' edge table ``incidence`` (:func:`~geobrep.geometry.mesh.edge_face_incidence`)."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    m = faces.shape[0]
    _, offsets, incident, sides = incidence
    counts = np.diff(offsets)
    # Consecutive faces around an edge join their corners at both of its ends. Corners are
    # numbered 3 * face + side (flat gathers: numpy's 2-D fancy indexing is slower).
    later = np.ones(int(offsets[-1]), dtype=np.bool_)
    later[offsets[:-1][counts > 0]] = False
    pair = np.flatnonzero(later)  # every place but the first of its edge
    flat = faces.reshape(-1)
    step = np.array([1, 2, 0], dtype=np.int64)
    f1, s1 = np.take(incident, pair - 1), np.take(sides, pair - 1)
    f2, s2 = np.take(incident, pair), np.take(sides, pair)
    start1, other_start = 3 * f1 + s1, 3 * f2 + s2
    end1, other_end = 3 * f1 + np.take(step, s1), 3 * f2 + np.take(step, s2)
    same = np.take(flat, other_start) == np.take(flat, start1)
    rows = np.concatenate([start1, end1])
    cols = np.concatenate(
        [np.where(same, other_start, other_end), np.where(same, other_end, other_start)]
    )
    graph = coo_matrix((np.ones(rows.shape[0], np.int8), (rows, cols)), shape=(3 * m, 3 * m))
    n_components, component = connected_components(graph, directed=False)
    # Links join corners at one vertex only: each component (a fan) has a single vertex.
    owner = np.empty(n_components, dtype=np.int64)
    owner[component] = flat
    fans = np.bincount(owner, minlength=n_vertices)
    uses = np.bincount(flat, minlength=n_vertices)
    return uses, fans


def non_manifold_vertices(scene: Scene, options: Any, context: CheckContext) -> list[Defect]:
    """Vertices where faces meet in more than one fan (two cones touching at their tips)."""
    found: list[Defect] = []
    for entity in scene.surfaces:
        tris, _ = triangles(entity, context)
        if tris.shape[0] == 0:
            continue
        _, fans = _fans(tris, entity.vertices.shape[0], edge_incidence(entity, context))
        bad = np.flatnonzero(fans > 1)
        found += defects(
            entity,
            "vertex",
            bad,
            entity.vertices[bad],
            points=entity.vertices[bad][:, None],
            values=fans[bad],
            message="vertex joining separate fans of faces (value: how many)",
        )
    return found


def _patch_neighbours(
    surface: Surface, tris: IntArray, source: IntArray, context: CheckContext
) -> tuple[IntArray, IntArray, NDArray[np.bool_]]:
    """Triangle pairs across the edges two triangles *of one patch* use (patches are oriented
    on their own), from the surface's shared edge table: its sides regrouped by (edge, patch)."""
    if surface.patch_labels is None or surface.n_patches < 2:
        return neighbours(surface, context)
    _, offsets, incident, sides = edge_incidence(surface, context)
    perm = incident * 3 + sides
    labels = np.asarray(surface.patch_labels, dtype=np.int64)[source]
    n_labels = np.int64(labels.max() + 1)
    edge = np.repeat(np.arange(offsets.shape[0] - 1, dtype=np.int64), np.diff(offsets))
    key = edge * n_labels + labels[incident]
    order = np.argsort(key, kind="stable")
    key = key[order]
    starts = np.flatnonzero(np.r_[True, key[1:] != key[:-1]])
    return neighbour_pairs(tris, np.append(starts, key.shape[0]), perm[order])


def inconsistent_orientation(scene: Scene, options: Any, context: CheckContext) -> list[Defect]:
    """Faces wound against their neighbours: per connected piece of each patch, the faces of
    the smaller side (by count) of the orientation split."""
    found: list[Defect] = []
    for surface in scene.surfaces:
        tris, source = triangles(surface, context)
        if tris.shape[0] < 2:
            continue
        result = orientation_flips(
            tris, neighbours=_patch_neighbours(surface, tris, source, context)
        )
        flip = result.flip
        n_flipped = np.bincount(result.piece, weights=flip, minlength=result.n_pieces)
        n_faces = np.bincount(result.piece, minlength=result.n_pieces)
        flip = flip ^ (n_flipped * 2 > n_faces)[result.piece]
        wrong = np.flatnonzero(flip)
        if wrong.size == 0:
            continue
        faces = np.unique(source[wrong])
        corners = surface.vertices[tris[wrong]]
        _, first = np.unique(source[wrong], return_index=True)
        found += defects(
            surface,
            "face",
            faces,
            corners[first].mean(axis=1),
            points=corners[first],
            message="wound against its neighbours",
        )
    return found


def inverted_tets(scene: Scene, options: Any, context: CheckContext) -> list[Defect]:
    """Tets of negative volume (beyond the flat ones, which degenerate_elements reports)."""
    tol = tolerance(scene, context)
    found: list[Defect] = []
    for tets in scene.tet_meshes:
        volume = tets.cell_volumes
        corners = tets.vertices[tets.cells]
        scale = np.linalg.norm(corners[:, 1:] - corners[:, :1], axis=2).max(axis=1)
        bad = np.flatnonzero(volume < -(tol * scale**2))
        found += defects(
            tets,
            "tet",
            bad,
            corners[bad].mean(axis=1),
            values=volume[bad],
            message="negative volume",
        )
    return found
