"""Intersection checks: a surface crossing itself, two surfaces crossing away from a shared
arc (the builder's conformity machinery), a polyline crossing a surface."""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from geobrep import Scene
from geobrep.plugins import CheckContext, Defect
from geobrep.plugins.blocks.conformity import (
    Nonconformities,
    overlapping_pairs,
    surface_nonconformities,
    triangles_intersect,
)
from geobrep.plugins.checks._common import (
    defects,
    edge_incidence,
    label,
    mesh_entities,
    neighbours,
    tolerance,
    triangles,
    welded,
    welded_surfaces,
)
from geobrep.plugins.checks._embedding import embedded_disk
from geobrep.plugins.checks._pairs import boxes_overlap, centre_pairs

__all__ = ["contacts", "polyline_intersections", "self_intersections", "surface_intersections"]

IntArray = NDArray[np.int64]
FloatArray = NDArray[np.float64]


def self_intersections(scene: Scene, options: Any, context: CheckContext) -> list[Defect]:
    """Pairs of triangles of one surface that meet although they share no vertex (after
    welding within the tolerance): the surface folds through itself."""
    _, maps = welded(scene, context)
    position = {id(e): k for k, e in enumerate(mesh_entities(scene))}
    found: list[Defect] = []
    for surface in scene.surfaces:
        tris, source = triangles(surface, context)
        if tris.shape[0] < 2:
            continue
        welded_index = maps[position[id(surface)]]
        if options.margin == 0.0 and embedded_disk(
            surface.vertices,
            tris,
            edge_incidence(surface, context),
            welded_index,
            neighbours(surface, context)[2],
        ):
            continue  # a disk embedded over a plane: no two triangles cross
        merged = welded_index[tris]
        centre = surface.vertices.mean(axis=0)
        corners = surface.vertices[tris] - centre
        i, j = centre_pairs(corners, options.margin)
        columns = [np.ascontiguousarray(merged[:, a]) for a in range(3)]
        theirs = [column[j] for column in columns]
        apart = np.ones(i.shape[0], dtype=np.bool_)
        for a in range(3):
            mine = columns[a][i]
            for b in range(3):
                apart &= mine != theirs[b]
        i, j = boxes_overlap(corners, i[apart], j[apart], options.margin)
        hit = triangles_intersect(corners[i], corners[j], options.margin)
        i, j = i[hit], j[hit]
        swap = source[i] > source[j]
        i, j = np.where(swap, j, i), np.where(swap, i, j)
        order = np.lexsort((source[j], source[i]))
        i, j = i[order], j[order]
        middle = 0.5 * (corners[i].mean(axis=1) + corners[j].mean(axis=1)) + centre
        found += defects(
            surface,
            "face",
            source[i],
            middle,
            points=corners[i] + centre,
            other=surface,
            other_ids=source[j],
            message="crosses another face of the same surface",
        )
    return found


def contacts(scene: Scene, context: CheckContext, options: Any = None) -> Nonconformities:
    """The builder's conformity defects between the scene's surfaces (cached per inspection)."""
    gap = getattr(options, "gap_tolerance", None)
    relative = getattr(options, "relative_gap_tolerance", 1e-3)
    key = f"contacts:{gap}:{relative}"
    if key not in context.cache:
        tol = tolerance(scene, context)
        weld = welded_surfaces(scene, context)
        context.cache[key] = surface_nonconformities(scene.surfaces, tol, gap, relative, weld=weld)
    result: Nonconformities = context.cache[key]
    return result


def contact_defects(scene: Scene, kinds: set[str], found: Nonconformities) -> list[Defect]:
    """Defects of the kinds asked for, as report records."""
    surfaces = scene.surfaces
    out: list[Defect] = []
    for item in found.defects:
        if item.kind not in kinds:
            continue
        first, second = surfaces[item.surfaces[0]], surfaces[item.surfaces[1]]
        element = "vertex" if item.vertex >= 0 else "face"
        ids = (item.vertex,) if item.vertex >= 0 else (item.faces[0],)
        shape: tuple[tuple[float, float, float], ...] = ()
        if item.vertex < 0 and item.faces[0] >= 0:
            tri = triangles(first, _NO_CACHE)[0]
            face_rows = np.flatnonzero(triangles(first, _NO_CACHE)[1] == item.faces[0])
            shape = tuple((p[0], p[1], p[2]) for p in first.vertices[tri[face_rows[0]]].tolist())
        out.append(
            Defect(
                entity=label(first),
                entity_id=first.id,
                element=element,
                ids=ids,
                location=item.point,
                other_entity=label(second),
                other_entity_id=second.id,
                other_ids=(item.faces[1],) if item.faces[1] >= 0 else (),
                value=item.distance,
                message=f"{item.kind} (value: distance)",
                points=shape or (item.point,),
            )
        )
    return out


_NO_CACHE = CheckContext()


def surface_intersections(scene: Scene, options: Any, context: CheckContext) -> list[Defect]:
    """Triangles of two surfaces crossing away from any arc they share (horizons crossing each
    other, a horizon crossing a fault where no contact was modelled)."""
    if len(scene.surfaces) < 2:
        return []
    return contact_defects(scene, {"crossing"}, contacts(scene, context))


def _segments_cross(
    p: FloatArray, q: FloatArray, tri: FloatArray, tol: float
) -> tuple[NDArray[np.bool_], FloatArray]:
    """Whether segments ``pq`` pass through triangles ``tri`` (ends strictly beyond ``tol`` on
    either side of its plane, crossing point inside it), and the crossing points."""
    a, b, c = tri[:, 0], tri[:, 1], tri[:, 2]
    normal = np.cross(b - a, c - a)
    size = np.linalg.norm(normal, axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        unit = normal / size[:, None]
        dp = np.einsum("ij,ij->i", p - a, unit)
        dq = np.einsum("ij,ij->i", q - a, unit)
        through = (dp * dq < 0) & (np.abs(dp) > tol) & (np.abs(dq) > tol) & (size > 0)
        t = dp / (dp - dq)
    x = p + t[:, None] * (q - p)
    inside = through.copy()
    for u, v in ((a, b), (b, c), (c, a)):
        edge = v - u
        reach = np.einsum("ij,ij->i", np.cross(edge, x - u), unit)
        with np.errstate(invalid="ignore"):
            inside &= reach / np.linalg.norm(edge, axis=1) >= -tol
    return inside, x


def polyline_intersections(scene: Scene, options: Any, context: CheckContext) -> list[Defect]:
    """Polyline segments passing through a surface (not ending on it within the tolerance)."""
    if not scene.polylines or not scene.surfaces:
        return []
    tol = max(tolerance(scene, context), options.margin)
    segments, owners, seg_index = [], [], []
    for k, line in enumerate(scene.polylines):
        ends = line.vertices[line.segments]
        segments.append(ends)
        owners.append(np.full(ends.shape[0], k))
        seg_index.append(np.arange(ends.shape[0]))
    tri_list, tri_owner, tri_face = [], [], []
    for k, surface in enumerate(scene.surfaces):
        tris, source = triangles(surface, context)
        tri_list.append(surface.vertices[tris])
        tri_owner.append(np.full(tris.shape[0], k))
        tri_face.append(source)
    seg = np.concatenate(segments)
    tri = np.concatenate(tri_list)
    centre = tri.reshape(-1, 3).mean(axis=0)
    corners = np.concatenate([seg[:, [0, 1, 1]], tri]) - centre
    groups = np.concatenate([np.zeros(seg.shape[0], np.int64), np.ones(tri.shape[0], np.int64)])
    i, j = overlapping_pairs(corners, groups, margin=tol)
    j = j - seg.shape[0]
    hit, points = _segments_cross(seg[i, 0] - centre, seg[i, 1] - centre, tri[j] - centre, tol)
    i, j, points = i[hit], j[hit], points[hit] + centre
    line_of, seg_of = np.concatenate(owners)[i], np.concatenate(seg_index)[i]
    surf_of, face_of = np.concatenate(tri_owner)[j], np.concatenate(tri_face)[j]
    # A crossing on an edge or corner is found in every triangle there: keep one per point.
    cell = np.floor(points / max(tol, 1e-12 * float(np.abs(corners).max(initial=1.0))))
    key = np.column_stack([line_of, seg_of, surf_of, cell])
    _, first = np.unique(key, axis=0, return_index=True)
    found: list[Defect] = []
    for k in first[np.lexsort((seg_of[first], line_of[first]))].tolist():
        line = scene.polylines[int(line_of[k])]
        found += defects(
            line,
            "segment",
            [[seg_of[k]]],
            points[k][None],
            points=seg[i[k]][None],
            other=scene.surfaces[int(surf_of[k])],
            other_ids=[[face_of[k]]],
            message="passes through a surface",
        )
    return found
