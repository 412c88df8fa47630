"""The Surface clipper: triangle and quad meshes, open or closed (then capped).

Quads are cut through their two triangles (split along the 0–2 diagonal, as everywhere in
geobrep), so a cut quad surface comes back as triangles; a surface the plane does not cut comes
back unchanged. Vertices on the cut edges are shared by the faces on both sides, point data is
interpolated along the cut edges, cell data and patch labels follow each face. A closed surface
gets cap faces (patch ``"cap"``) so each half is closed again; a face lying in the plane then goes
to the side its normal points away from. An open surface keeps faces lying in the plane on both
sides.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import Any

import numpy as np

from geobrep import Polygon, PolyLine, Property, Surface
from geobrep.geometry import Plane, mesh
from geobrep.geometry.arrays import FloatArray, IntArray
from geobrep.plugins import ClipContext, Keep, PropertyMap, halves, pack_halves
from geobrep.plugins.clip._caps import cap_rings, cap_triangles, open_boundary
from geobrep.plugins.clip._loops import order_paths
from geobrep.plugins.clip._sides import interpolate_properties
from geobrep.plugins.clip._triangles import HalfMesh, InPlaneRule, TriangleCut, cut_triangles
from geobrep.plugins.clip._welding import UnweldedSurfaceWarning, closed_once_welded
from geobrep.plugins.clip.options import SurfaceClipOptions, tolerance_of

__all__ = ["SurfaceCut", "clip_surface", "section_surface", "surface_cut"]


@dataclass
class SurfaceCut:
    """A surface's triangles cut by the plane, with its halves.

    ``source`` maps the triangles to the surface's faces (``None`` when they are the faces).
    """

    surface: Surface
    source: IntArray | None
    cut: TriangleCut
    normal: FloatArray
    halves: dict[tuple[int, str], HalfMesh]

    def half(self, side: int, rule: InPlaneRule) -> HalfMesh:
        key = (side, rule)
        if key not in self.halves:
            self.halves[key] = self.cut.half(side, rule, self.normal)
        return self.halves[key]

    def labels(self, half: HalfMesh) -> IntArray | None:
        """Patch label of every face of ``half`` (None when the surface has no labels)."""
        labels = self.surface.patch_labels
        if labels is None:
            return None
        return np.asarray(labels[self.face_source(half)], dtype=np.int64)

    def face_source(self, half: HalfMesh) -> IntArray:
        """The surface face each face of ``half`` comes from."""
        return half.face_source if self.source is None else self.source[half.face_source]


def surface_cut(
    surface: Surface, plane: Plane, tolerance: float, context: ClipContext
) -> SurfaceCut:
    """The cut of ``surface`` by ``plane``, computed once per clip and shared via the context."""
    key = ("surface-cut", id(surface), tolerance)
    cached = context.cache.get(key)
    if isinstance(cached, SurfaceCut):
        return cached
    source: IntArray | None = None
    if surface.faces.shape[1] == 4:
        triangles, source = mesh.triangulate(surface.faces)
    else:
        triangles = surface.faces.astype(np.int64, copy=False)
    distances = plane.signed_distance(surface.vertices)
    cut = cut_triangles(surface.vertices, triangles, distances, tolerance)
    result = SurfaceCut(surface, source, cut, plane.normal, {})
    context.cache[key] = result
    context.cache[("surface-cut-of", int(surface.id or 0))] = result
    return result


def clip_surface(
    surface: Surface,
    plane: Plane,
    keep: Keep,
    options: SurfaceClipOptions,
    context: ClipContext,
) -> Any:
    """Clipper of :class:`Surface` entities (see the module docstring)."""
    tolerance = tolerance_of(options, context)
    if surface.n_faces == 0:
        return _clip_vertices_only(surface, plane, keep, tolerance)
    capping = _caps_wanted(surface, options, context)
    rule: InPlaneRule = "normal" if capping else "both"
    state = surface_cut(surface, plane, tolerance, context)
    codes = state.cut.codes
    counts = [int(np.count_nonzero(codes == code)) for code in range(3)]
    counts.append(int(state.cut.pieces.shape[0]))
    parts: dict[int, Surface | None] = {}
    for side in halves(keep):
        own = int(counts[1 if side < 0 else 2])
        if counts[3] == 0 and counts[0] == 0 and own in (0, codes.shape[0]):
            # Entirely on one side (touching allowed): unchanged or gone.
            parts[side] = surface if own else None
        else:
            parts[side] = _half(state, side, rule, capping)
    if len(parts) and counts[3] and not capping:
        _warn_if_unwelded(surface, options, context)
    return pack_halves(keep, parts)


def _caps_wanted(surface: Surface, options: SurfaceClipOptions, context: ClipContext) -> bool:
    if options.caps != "auto":
        return options.caps == "always"
    if _bounds_blocks(surface, context):
        return False  # a boundary of blocks: the Block clipper caps the blocks
    return surface.is_closed


def _bounds_blocks(surface: Surface, context: ClipContext) -> bool:
    scene = context.scene
    return bool(
        scene is not None
        and scene.blocks
        and any(patch.surface == surface.id for patch in scene.patches)
    )


def _warn_if_unwelded(surface: Surface, options: SurfaceClipOptions, context: ClipContext) -> None:
    """Warn when ``surface``, cut without caps by ``caps="auto"``, would be closed (and so
    capped) once its seams are welded."""
    if options.caps != "auto" or surface.is_closed or _bounds_blocks(surface, context):
        return
    tolerance = tolerance_of(options, context)
    welded = closed_once_welded(surface, tolerance)
    if welded is None:
        return
    vertices, faces = welded
    collapsed = f" and dropping {faces} sliver face(s)" if faces else ""
    warnings.warn(
        f"{surface.label} is closed once {vertices} duplicated vertices within {tolerance:g} "
        f"are welded{collapsed}, but not as given: its halves are not capped. Weld it first "
        "(geobrep.geometry.mesh.merge_close_vertices) or clip with caps='always'.",
        UnweldedSurfaceWarning,
        stacklevel=2,
    )


def _half(state: SurfaceCut, side: int, rule: InPlaneRule, capping: bool) -> Surface | None:
    surface, cut = state.surface, state.cut
    half = state.half(side, rule)
    if half.faces.shape[0] == 0:
        return None
    if cut.pieces.shape[0] == 0 and half.faces.shape[0] == cut.triangles.shape[0]:
        return surface  # every face kept whole: the input itself
    labels = state.labels(half)
    faces = half.faces
    names = surface.patch_names
    cell_data = surface.cell_data.take(state.face_source(half)) if surface.cell_data else None
    if capping:
        n = cut.n_points
        keys = np.concatenate([half.kept_points, n + np.arange(cut.points.shape[0])])
        boundary = open_boundary(half.plane_edges, half.vertices.shape[0])
        # Triangulate the loops seen from +n on both sides: the halves get the same cap.
        oriented = boundary if side < 0 else boundary[:, ::-1]
        cap = cap_triangles(half.vertices, oriented, state.normal, surface.label, keys)
        if side > 0:
            cap = cap[:, [0, 2, 1]]
        if cap.shape[0]:
            faces = np.concatenate([faces, cap])
            base = labels if labels is not None else np.zeros(half.faces.shape[0], np.int64)
            labels = np.concatenate([base, np.full(cap.shape[0], surface.n_patches, np.int64)])
            known = names or tuple(str(i) for i in range(surface.n_patches))
            names = (*known, "cap")
            cell_data = None if cell_data is None else _extended(cell_data, cap.shape[0])
    return Surface(
        vertices=half.vertices,
        faces=faces,
        patch_labels=labels,
        patch_names=names,
        point_data=interpolate_properties(
            surface.point_data, half.kept_points, cut.edge_a, cut.edge_b, cut.edge_t
        ),
        cell_data=cell_data or PropertyMap(),
        id=surface.id,
        name=surface.name,
        kind=surface.kind,
        metadata=surface.metadata,
    )


def _extended(cell_data: PropertyMap, count: int) -> PropertyMap:
    """Cell data with ``count`` new cells holding no-data (NaN, the no-data value, or False)."""
    result: dict[str, Property] = {}
    for name, prop in cell_data.items():
        values = prop.values
        fill: Any
        no_data = prop.no_data_value
        if no_data is not None:
            fill = no_data
        elif values.dtype.kind == "f":
            fill = np.nan
        elif values.dtype.kind == "b":
            fill = False
        else:
            fill = (
                np.iinfo(values.dtype).min
                if values.dtype.kind == "i"
                else np.iinfo(values.dtype).max
            )
            no_data = float(fill)
        extra = np.full((count, *values.shape[1:]), fill, dtype=values.dtype)
        new = np.concatenate([values, extra])
        new.flags.writeable = False
        result[name] = prop.model_copy(update={"values": new, "no_data_value": no_data})
    return PropertyMap(result)


def _clip_vertices_only(surface: Surface, plane: Plane, keep: Keep, tolerance: float) -> Any:
    distances = plane.signed_distance(surface.vertices)
    parts: dict[int, Surface | None] = {}
    for side in halves(keep):
        chosen = np.flatnonzero(distances * side >= -tolerance)
        parts[side] = (
            None
            if chosen.shape[0] == 0
            else surface.replace(
                vertices=surface.vertices[chosen], point_data=surface.point_data.take(chosen)
            )
        )
    return pack_halves(keep, parts)


# ----------------------------------------------------------------------------- sections
def section_surface(
    surface: Surface, plane: Plane, options: SurfaceClipOptions, context: ClipContext
) -> PolyLine | Polygon | None:
    """The trace of a surface on the plane: a Polygon (with holes) for a closed surface cut with
    caps, else a PolyLine of the cut lines; ``None`` where the plane misses it."""
    tolerance = tolerance_of(options, context)
    if surface.n_faces == 0:
        return None
    state = surface_cut(surface, plane, tolerance, context)
    fields: dict[str, Any] = {
        "name": surface.name,
        "kind": surface.kind,
        "metadata": {**surface.metadata, "surface": surface.id},
    }
    capping = _caps_wanted(surface, options, context)
    if not capping and state.cut.pieces.shape[0]:
        _warn_if_unwelded(surface, options, context)
    if capping:
        half = state.half(-1, "none")
        boundary = open_boundary(half.plane_edges, half.vertices.shape[0])
        polygons = cap_rings(half.vertices, boundary, state.normal, surface.label)
        if not polygons:
            return None
        return Polygon.from_polygons(
            [
                (half.vertices[rings[0]], [half.vertices[h] for h in rings[1:]])
                for rings in polygons
            ],
            **fields,
        )
    half = state.half(-1, "none")
    edges = half.plane_edges
    if edges.shape[0] == 0:
        return None
    # Each cut line once: drop one of two faces traversing an on-plane edge.
    n = half.vertices.shape[0]
    keys = np.minimum(edges[:, 0], edges[:, 1]) * n + np.maximum(edges[:, 0], edges[:, 1])
    _, first = np.unique(keys, return_index=True)
    edges = edges[np.sort(first)]
    order, offsets, closed = order_paths(edges)
    points = half.vertices
    parts = []
    for part in range(offsets.shape[0] - 1):
        chain = edges[order[offsets[part] : offsets[part + 1]]]
        ids = chain[:, 0] if closed[part] else np.append(chain[:, 0], chain[-1, 1])
        parts.append(ids)
    used, local = np.unique(np.concatenate(parts), return_inverse=True)
    lengths = [len(p) for p in parts]
    return PolyLine(
        vertices=points[used],
        indices=local.astype(np.int64),
        part_offsets=np.concatenate([[0], np.cumsum(lengths)]).astype(np.int64),
        closed=np.asarray(closed, dtype=bool),
        **fields,
    )
