"""The Polygon clipper: filled 3D polygons with holes (the paper's "filled polygons").

Rings are first oriented consistently (outer rings counter-clockwise about the polygon's normal,
holes clockwise) and cut as closed lines (:func:`.lines.cut_segments`): the first and last runs of a
ring join. The kept runs of all rings of a polygon end on the cut line; sorted along it, their ends
and starts alternate, and each end is closed along the cut line to the next start, which joins the
runs into rings. That is the paper's closing-and-nesting rule made exact: a notch whose two
pieces would each be closed separately (the paper's case B) comes out as one ring, and separate
pieces (case C) as separate polygons. Rings are then nested by containment: every hole goes to the
smallest outer ring holding it. Point data is interpolated at the cut; each new polygon inherits
the cell data of the polygon it came from.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from geobrep import Polygon, PolyLine
from geobrep.errors import DegenerateGeometryError
from geobrep.geometry import Plane
from geobrep.geometry.arrays import FloatArray, IntArray
from geobrep.plugins import ClipContext, Keep, halves, pack_halves
from geobrep.plugins.clip._caps import group_holes, loop_areas, plane_basis
from geobrep.plugins.clip._lines import LineCut, cut_segments
from geobrep.plugins.clip._sides import interpolate_properties, vertex_sides
from geobrep.plugins.clip.options import ClipOptions, tolerance_of

__all__ = ["clip_polygon", "section_polygon"]


def _ring_of_vertex(polygon: Polygon) -> IntArray:
    return np.repeat(np.arange(polygon.n_rings, dtype=np.int64), np.diff(polygon.ring_offsets))


def _polygon_of_ring(polygon: Polygon) -> IntArray:
    return np.repeat(
        np.arange(polygon.n_polygons, dtype=np.int64), np.diff(polygon.polygon_offsets)
    )


def _normals(polygon: Polygon) -> FloatArray:
    """Unit normal of each polygon: the direction of its outer ring's vector area."""
    outer = polygon.ring_vector_areas[polygon.polygon_offsets[:-1]]
    length = np.linalg.norm(outer, axis=1)
    if (length == 0).any():
        bad = int(np.argmax(length == 0))
        raise DegenerateGeometryError(f"{polygon.label}: polygon {bad} has a zero-area outer ring")
    return np.asarray(outer / length[:, None], dtype=np.float64)


def _oriented_segments(polygon: Polygon, normals: FloatArray) -> tuple[IntArray, IntArray]:
    """Segments of every ring: outer rings counter-clockwise about the normal, holes clockwise."""
    offsets = polygon.ring_offsets
    lengths = np.diff(offsets)
    ring_polygon = _polygon_of_ring(polygon)
    is_outer = np.zeros(polygon.n_rings, dtype=np.bool_)
    is_outer[polygon.polygon_offsets[:-1]] = True
    facing = np.einsum("ij,ij->i", polygon.ring_vector_areas, normals[ring_polygon])
    reverse = (facing > 0) != is_outer
    ring = _ring_of_vertex(polygon)
    local = np.arange(offsets[-1], dtype=np.int64) - offsets[ring]
    length = lengths[ring]
    flipped = reverse[ring]
    order = np.where(flipped, (length - local) % length, local) + offsets[ring]
    after = (local + 1) % length
    following = np.where(flipped, (length - after) % length, after) + offsets[ring]
    return np.stack([order, following], axis=1), ring


def clip_polygon(
    polygon: Polygon, plane: Plane, keep: Keep, options: ClipOptions, context: ClipContext
) -> Any:
    """Clipper of :class:`Polygon` entities (see the module docstring)."""
    tolerance = tolerance_of(options, context)
    distances = plane.signed_distance(polygon.vertices)
    sides = vertex_sides(distances, tolerance)
    parts: dict[int, Polygon | None] = {}
    normals: FloatArray | None = None
    for side in halves(keep):
        if not (sides == -side).any():
            parts[side] = polygon
            continue
        if not (sides == side).any() and not (sides == 0).any():
            parts[side] = None
            continue
        if normals is None:
            normals = _normals(polygon)
        segments, segment_ring = _oriented_segments(polygon, normals)
        cut = cut_segments(
            polygon.vertices,
            segments,
            segment_ring,
            np.ones(polygon.n_rings, dtype=np.bool_),
            distances,
            tolerance,
            side,
        )
        parts[side] = _assemble(polygon, plane, side, cut, normals)
    return pack_halves(keep, parts)


def _runs(cut: LineCut) -> list[IntArray]:
    return [cut.indices[cut.offsets[r] : cut.offsets[r + 1]] for r in range(cut.closed.shape[0])]


def _assemble(
    polygon: Polygon, plane: Plane, side: int, cut: LineCut, normals: FloatArray
) -> Polygon | None:
    runs = _runs(cut)
    run_polygon = _polygon_of_ring(polygon)[cut.source_chain]
    rings: list[tuple[int, IntArray]] = []
    for index in range(polygon.n_polygons):
        mine = np.flatnonzero(run_polygon == index)
        if mine.shape[0] == 0:
            continue
        closed = [int(r) for r in mine if cut.closed[r]]
        rings.extend((index, runs[r]) for r in closed)
        open_runs = [int(r) for r in mine if not cut.closed[r]]
        if open_runs:
            joined = _close_along_cut(
                cut, runs, open_runs, normals[index], plane, side, polygon.label
            )
            rings.extend((index, ring) for ring in joined)
    if not rings:
        return None
    pieces = _nest(cut.vertices, rings, normals, polygon.label)
    if not pieces:
        return None
    point_data = interpolate_properties(
        polygon.point_data, cut.kept_points, cut.edge_a, cut.edge_b, cut.edge_t
    )
    ring_ids = [ring for _, group in pieces for ring in group]
    flat = np.concatenate(ring_ids)
    ring_offsets = np.concatenate([[0], np.cumsum([len(r) for r in ring_ids])]).astype(np.int64)
    polygon_offsets = np.concatenate([[0], np.cumsum([len(g) for _, g in pieces])]).astype(np.int64)
    return Polygon(
        vertices=cut.vertices[flat],
        ring_offsets=ring_offsets,
        polygon_offsets=polygon_offsets,
        point_data=point_data.take(flat),
        cell_data=polygon.cell_data.take(np.array([source for source, _ in pieces], np.int64)),
        id=polygon.id,
        name=polygon.name,
        kind=polygon.kind,
        metadata=polygon.metadata,
    )


def _close_along_cut(
    cut: LineCut,
    runs: list[IntArray],
    open_runs: list[int],
    normal: FloatArray,
    plane: Plane,
    side: int,
    what: str,
) -> list[IntArray]:
    """Join open runs (all ending on the cut line) into rings along the cut line."""
    toward = side * (plane.normal - (plane.normal @ normal) * normal)
    length = float(np.linalg.norm(toward))
    if length == 0.0:
        raise DegenerateGeometryError(f"{what}: open runs on a polygon parallel to the plane")
    # Walking along ``direction`` the kept side is on the left: closing edges run that way.
    direction = np.cross(toward / length, normal)
    starts = np.array([runs[r][0] for r in open_runs])
    ends = np.array([runs[r][-1] for r in open_runs])
    t_start = cut.vertices[starts] @ direction
    t_end = cut.vertices[ends] @ direction
    count = len(open_runs)
    values = np.concatenate([t_end, t_start])
    kinds = np.concatenate([np.zeros(count, np.int64), np.ones(count, np.int64)])
    which = np.concatenate([np.arange(count), np.arange(count)])
    order = np.lexsort((kinds, values))
    kinds, which = kinds[order], which[order]
    alternating = bool((kinds[0::2] == 0).all() and (kinds[1::2] == 1).all())
    if not alternating:
        raise DegenerateGeometryError(
            f"{what}: the cut line does not alternate between ring ends and starts "
            "(self-intersecting rings?)"
        )
    successor = np.empty(count, dtype=np.int64)
    successor[which[0::2]] = which[1::2]
    rings: list[IntArray] = []
    seen = np.zeros(count, dtype=np.bool_)
    for first in range(count):
        if seen[first]:
            continue
        chain: list[IntArray] = []
        current = first
        while not seen[current]:
            seen[current] = True
            run = runs[open_runs[current]]
            if chain and chain[-1][-1] == run[0]:
                run = run[1:]
            chain.append(run)
            current = int(successor[current])
        ring = np.concatenate(chain)
        if ring.shape[0] > 1 and ring[0] == ring[-1]:
            ring = ring[:-1]
        rings.append(ring)
    return rings


def _nest(
    vertices: FloatArray, rings: list[tuple[int, IntArray]], normals: FloatArray, what: str
) -> list[tuple[int, list[IntArray]]]:
    """Rings grouped per source polygon into (outer, holes...) by orientation and containment."""
    result: list[tuple[int, list[IntArray]]] = []
    for source in sorted({s for s, _ in rings}):
        mine = [r for s, r in rings if s == source and r.shape[0] >= 3]
        if not mine:
            continue
        u, w = plane_basis(normals[source])
        points = np.concatenate(mine)
        relative = vertices[points] - vertices[points].mean(axis=0)
        uv = np.stack([relative @ u, relative @ w], axis=1)
        offsets = np.concatenate([[0], np.cumsum([len(r) for r in mine])]).astype(np.int64)
        loop_points = np.arange(points.shape[0], dtype=np.int64)
        areas = loop_areas(uv, loop_points, offsets)
        extent = float(np.ptp(uv, axis=0).max()) if uv.size else 0.0
        areas[np.abs(areas) <= 1e-12 * extent * extent] = 0.0  # slivers along the cut line
        for group in group_holes(uv, loop_points, offsets, areas, what):
            result.append((source, [mine[r] for r in group]))
    return result


def section_polygon(
    polygon: Polygon, plane: Plane, options: ClipOptions, context: ClipContext
) -> PolyLine | None:
    """The chords of the cut: where the polygons' filled area meets the plane."""
    negative = clip_polygon(polygon, plane, "negative", options, context)
    if negative is None or negative is polygon:
        return None
    tolerance = tolerance_of(options, context)
    on = vertex_sides(plane.signed_distance(negative.vertices), tolerance) == 0
    nxt = np.arange(1, negative.vertices.shape[0] + 1)
    ring = _ring_of_vertex(negative)
    last = nxt == negative.ring_offsets[1:][ring]
    nxt[last] = negative.ring_offsets[:-1][ring[last]]
    chord = on & on[nxt]
    starts = np.flatnonzero(chord)
    ends = nxt[chord]
    if starts.shape[0] == 0:
        return None
    points = [
        negative.vertices[[a, b]] for a, b in zip(starts.tolist(), ends.tolist(), strict=True)
    ]
    return PolyLine.from_point_lists(
        points, name=polygon.name, kind=polygon.kind, metadata={"polygon": polygon.id}
    )
