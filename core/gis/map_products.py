"""Map products of a structural model, ready to be written as GIS layers.

- :func:`block_outlines` / :func:`surface_outlines`: the outline of each block or surface
  projected on the map plane, as :class:`~geobrep.Polygon` (layer ``block_outlines`` /
  ``surface_outlines``);
- :func:`top_traces`: where each fault or horizon meets the top (topographic) surface, as
  :class:`~geobrep.PolyLine` (layer ``traces``);
- :func:`block_sections`: horizontal or vertical sections as polygons per block (layer
  ``sections``), in world coordinates and/or in the section plane's own coordinates (layer
  ``sections_plane``; :class:`SectionFrame`, :func:`to_section_plane`, :func:`from_section_plane`);
- :func:`map_products`: all of them in one scene with the model's CRS, e.g. for a GeoPackage.

Every product carries ``block`` / ``unit_name`` / ``horizon`` / ``surface`` in its metadata,
which the GIS writers turn into columns. Geometry is computed about the model's centre, so
UTM-scale coordinates keep full precision. shapely (the ``gis`` extra) does the 2D unions.

>>> import geobrep
>>> from geobrep.gis.map_products import block_outlines
>>> cake = geobrep.datasets.faulted_layer_cake()
>>> round(block_outlines(cake)[0].area)  # footwall of unit 1: 550 m × 800 m west of the fault
440000
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable, Sequence
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from geobrep.errors import (
    DegenerateGeometryError,
    EntityNotFoundError,
    OptionsError,
    import_optional,
)
from geobrep.geometry import Plane, mesh
from geobrep.model.base import FrozenModel
from geobrep.model.entities import Block, Entity, Polygon, PolyLine, Surface, VertexEntity
from geobrep.model.scene import Scene

__all__ = [
    "SECTION_FRAME_KEY",
    "SectionCoordinates",
    "SectionFrame",
    "block_outlines",
    "block_sections",
    "from_section_plane",
    "level_set_segments",
    "map_products",
    "section_frame",
    "surface_outlines",
    "to_section_plane",
    "top_traces",
]

#: Where sections go: ``world`` (map coordinates, as cut), ``plane`` (the section plane's own
#: coordinates for every plane that is not horizontal), or ``both``.
SectionCoordinates = Literal["world", "plane", "both"]

#: Metadata key of an entity (and of a GeoPackage layer) in section-plane coordinates.
SECTION_FRAME_KEY = "section_frame"

#: Relative tolerance (of the model's diagonal) for "on the surface" / "on the plane".
RELATIVE_TOLERANCE = 1e-9


def _shapely() -> Any:
    return import_optional("shapely", "gis", "map products")


def _centre(scene: Scene) -> tuple[NDArray[np.float64], float]:
    bounds = scene.bounds
    if bounds is None:
        raise DegenerateGeometryError("the scene has no geometry to map")
    centre = (np.asarray(bounds.mins) + np.asarray(bounds.maxs)) / 2.0
    return centre, max(float(bounds.diagonal), 1e-12)


def _shapely_to_polygon(geometry: Any, lift: Any, **fields: Any) -> Polygon | None:
    """A geobrep Polygon from a shapely (Multi)Polygon in local 2D coordinates."""
    shapely = _shapely()
    parts = shapely.get_parts(geometry)
    parts = parts[~shapely.is_empty(parts)] if parts.size else parts
    if parts.size == 0:
        return None
    rings, owner = shapely.get_rings(parts, return_index=True)
    coords, ring_of = shapely.get_coordinates(rings, return_index=True)
    counts = np.bincount(ring_of, minlength=rings.shape[0])
    ends = np.cumsum(counts) - 1
    keep = np.ones(coords.shape[0], dtype=bool)
    keep[ends] = False  # shapely repeats the first vertex
    ring_offsets = np.concatenate([[0], np.cumsum(counts - 1)]).astype(np.int64)
    polygon_offsets = np.concatenate(
        [[0], np.cumsum(np.bincount(owner, minlength=parts.shape[0]))]
    ).astype(np.int64)
    areas = shapely.area(parts)
    return Polygon(
        vertices=lift(coords[keep]),
        ring_offsets=ring_offsets,
        polygon_offsets=polygon_offsets,
        cell_data={"map_area": areas},
        **fields,
    )


def _footprint(surface: Surface, centre: NDArray[np.float64], diagonal: float) -> Any:
    """Union of the map projections of a surface's triangles (local coordinates).

    For a closed surface the up-facing triangles alone cover its projection (the topmost
    crossing of every vertical line is up-facing), which keeps the union free of slivers.
    """
    shapely = _shapely()
    triangles, _ = mesh.triangulate(surface.faces)
    xy = (np.asarray(surface.vertices)[:, :2] - centre[:2])[triangles]
    doubled = (xy[:, 1, 0] - xy[:, 0, 0]) * (xy[:, 2, 1] - xy[:, 0, 1]) - (
        xy[:, 2, 0] - xy[:, 0, 0]
    ) * (xy[:, 1, 1] - xy[:, 0, 1])
    threshold = (RELATIVE_TOLERANCE * diagonal) ** 2
    if surface.is_closed and surface.is_consistently_oriented:
        facing = doubled > threshold if surface.volume > 0 else doubled < -threshold
    else:
        facing = np.abs(doubled) > threshold
    if not facing.any():
        return shapely.Polygon()
    rings = np.concatenate([xy[facing], xy[facing][:, :1]], axis=1)
    union = shapely.union_all(shapely.polygons(rings))
    return shapely.simplify(union, RELATIVE_TOLERANCE * diagonal)


def _lift_to(centre: NDArray[np.float64], elevation: float) -> Any:
    def lift(xy: NDArray[np.float64]) -> NDArray[np.float64]:
        out = np.empty((xy.shape[0], 3))
        out[:, :2] = xy + centre[:2]
        out[:, 2] = elevation
        return out

    return lift


def block_outlines(scene: Scene, elevation: float = 0.0) -> list[Polygon]:
    """The map outline of each block: its boundary projected on the plane z = ``elevation``.

    >>> import geobrep
    >>> cake = geobrep.datasets.faulted_layer_cake()
    >>> outline = block_outlines(cake)[0]
    >>> outline.metadata["layer"], outline.metadata["block"] == cake.blocks[0].id
    ('block_outlines', True)
    """
    blocks = (
        (scene.block_mesh(block), block.name, _block_metadata(block, "block_outlines"))
        for block in scene.blocks
    )
    return _outlines(scene, blocks, elevation)


def surface_outlines(
    scene: Scene, kinds: Sequence[str] | None = None, elevation: float = 0.0
) -> list[Polygon]:
    """The map outline of each surface (of the given ``kinds``, default all).

    >>> import geobrep
    >>> cake = geobrep.datasets.faulted_layer_cake()
    >>> [p.name for p in surface_outlines(cake, kinds=["fault"])]
    ['fault']
    """
    surfaces = (
        (surface, surface.name, _surface_metadata(surface, "surface_outlines"))
        for surface in scene.surfaces
        if kinds is None or surface.kind in kinds
    )
    return _outlines(scene, surfaces, elevation)


def _outlines(
    scene: Scene, meshes: Iterable[tuple[Surface, str, dict[str, Any]]], elevation: float
) -> list[Polygon]:
    """The map outline of each ``(mesh, name, metadata)`` on the plane z = ``elevation``
    (meshes without one give none)."""
    centre, diagonal = _centre(scene)
    lift = _lift_to(centre, elevation)
    outlines = []
    for surface, name, metadata in meshes:
        polygon = _shapely_to_polygon(
            _footprint(surface, centre, diagonal),
            lift,
            name=name,
            kind="outline",
            metadata=metadata,
        )
        if polygon is not None:
            outlines.append(polygon)
    return outlines


def _block_metadata(block: Block, layer: str) -> dict[str, Any]:
    metadata: dict[str, Any] = {"layer": layer, "block": int(block.id or 0)}
    if block.unit_name:
        metadata["unit_name"] = block.unit_name
    return metadata


def _surface_metadata(surface: Surface, layer: str) -> dict[str, Any]:
    metadata: dict[str, Any] = {"layer": layer, "surface": int(surface.id or 0)}
    if surface.kind == "horizon":
        metadata["horizon"] = surface.name
    return metadata


# -- zero level sets on triangle meshes ----------------------------------------------------------
def level_set_segments(
    vertices: NDArray[np.float64],
    faces: NDArray[np.int64],
    values: NDArray[np.float64],
    tolerance: float,
) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """Where a per-vertex scalar is zero on a triangle mesh: nodes ``(K, 3)`` and segments.

    Values within ``tolerance`` of zero count as zero; NaN values (undefined) cut nothing.
    A triangle edge whose two ends are zero is a segment when the third vertex is not; a
    triangle whose values change sign gives the segment between its crossings. Shared
    crossings are one node, so segments join exactly.

    >>> v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]], dtype=float)
    >>> nodes, segments = level_set_segments(v, np.array([[0, 1, 2], [1, 3, 2]]),
    ...                                      v[:, 0] - 0.5, 1e-12)
    >>> sorted(map(tuple, nodes[segments.ravel()].round(3).tolist()))[:2]
    [(0.5, 0.0, 0.0), (0.5, 0.5, 0.0)]
    """
    triangles, _ = mesh.triangulate(np.asarray(faces))
    triangles = triangles.astype(np.int64)
    sign = np.sign(values)
    sign[np.abs(values) <= tolerance] = 0
    defined = np.isfinite(values)
    triangles = triangles[defined[triangles].all(axis=1)]
    s = sign[triangles]
    n = vertices.shape[0]
    edges = np.stack(
        [triangles[:, [0, 1]], triangles[:, [1, 2]], triangles[:, [2, 0]]], axis=1
    )  # (T, 3, 2)
    es = np.stack([s[:, [0, 1]], s[:, [1, 2]], s[:, [2, 0]]], axis=1)
    crossing = es[:, :, 0] * es[:, :, 1] < 0  # strict sign change along the edge
    on_edge = (es[:, :, 0] == 0) & (es[:, :, 1] == 0)
    opposite = s[:, [2, 0, 1]]  # the vertex opposite each edge
    # node ids: a zero vertex is its index; a crossing is n + index of its (sorted) edge
    lo, hi = np.minimum(edges[..., 0], edges[..., 1]), np.maximum(edges[..., 0], edges[..., 1])
    pairs = np.stack([lo[crossing], hi[crossing]], axis=1)
    unique_pairs, edge_id = np.unique(pairs.reshape(-1, 2), axis=0, return_inverse=True)
    crossing_node = np.full(crossing.shape, -1, dtype=np.int64)
    crossing_node[crossing] = n + edge_id.reshape(-1)
    segments: list[NDArray[np.int64]] = []
    # (a) an edge lying on the level set, the third vertex off it
    flat = on_edge & (opposite != 0)
    segments.append(np.stack([edges[..., 0][flat], edges[..., 1][flat]], axis=1))
    zeros = (s == 0).sum(axis=1)
    n_cross = crossing.sum(axis=1)
    # (b) one zero vertex and a crossing on the opposite edge
    one = (zeros == 1) & (n_cross == 1)
    if one.any():
        zero_vertex = triangles[one][s[one] == 0]
        node = crossing_node[one][crossing[one]]
        segments.append(np.stack([zero_vertex, node], axis=1))
    # (c) two crossings
    two = n_cross == 2
    if two.any():
        nodes = crossing_node[two][crossing[two]].reshape(-1, 2)
        segments.append(nodes)
    all_segments: NDArray[np.int64] = (
        np.concatenate(segments).astype(np.int64) if segments else np.zeros((0, 2), np.int64)
    )
    all_segments = np.unique(np.sort(all_segments, axis=1), axis=0)
    all_segments = all_segments[all_segments[:, 0] != all_segments[:, 1]]
    # coordinates of the crossing nodes
    a, b = unique_pairs[:, 0], unique_pairs[:, 1]
    t = values[a] / (values[a] - values[b])
    points = vertices[a] + t[:, None] * (vertices[b] - vertices[a])
    used, compact = np.unique(all_segments, return_inverse=True)
    coordinates = np.concatenate([vertices, points])[used] if used.size else np.zeros((0, 3))
    return coordinates, compact.reshape(-1, 2).astype(np.int64)


def _merge_lines(nodes: NDArray[np.float64], segments: NDArray[np.int64]) -> list[Any]:
    """Chain segments into the longest lines (shapely's line merge keeps z)."""
    shapely = _shapely()
    if segments.shape[0] == 0:
        return []
    lines = shapely.linestrings(
        nodes[segments.reshape(-1)], indices=np.repeat(np.arange(len(segments)), 2)
    )
    merged = shapely.line_merge(shapely.multilinestrings(lines))
    return list(shapely.get_parts(merged))


def _polyline_from_lines(lines: list[Any], lift: Any, **fields: Any) -> PolyLine | None:
    shapely = _shapely()
    if not lines:
        return None
    parts, closed = [], []
    for line in lines:
        coords = shapely.get_coordinates(line, include_z=True)
        ring = coords.shape[0] >= 4 and bool(np.array_equal(coords[0], coords[-1]))
        parts.append(lift(coords[:-1] if ring else coords))
        closed.append(ring)
    return PolyLine.from_point_lists(parts, closed=closed, **fields)


def _height_field(surface: Surface, centre: NDArray[np.float64], diagonal: float) -> Any:
    """z of ``surface`` above map points (local coordinates); NaN outside it."""
    shapely = _shapely()
    triangles, _ = mesh.triangulate(surface.faces)
    local = np.asarray(surface.vertices) - centre
    xy = local[:, :2][triangles]
    doubled = (xy[:, 1, 0] - xy[:, 0, 0]) * (xy[:, 2, 1] - xy[:, 0, 1]) - (
        xy[:, 2, 0] - xy[:, 0, 0]
    ) * (xy[:, 1, 1] - xy[:, 0, 1])
    keep = np.abs(doubled) > (RELATIVE_TOLERANCE * diagonal) ** 2
    triangles, xy, doubled = triangles[keep], xy[keep], doubled[keep]
    tree = shapely.STRtree(shapely.polygons(np.concatenate([xy, xy[:, :1]], axis=1)))

    def height(points: NDArray[np.float64]) -> NDArray[np.float64]:
        result = np.full(points.shape[0], np.nan)
        if not len(triangles):
            return result
        pad = RELATIVE_TOLERANCE * diagonal
        boxes = shapely.box(
            points[:, 0] - pad, points[:, 1] - pad, points[:, 0] + pad, points[:, 1] + pad
        )
        point_index, triangle_index = tree.query(boxes, predicate="intersects")
        p = points[point_index, :2]
        tri = xy[triangle_index]
        area = doubled[triangle_index]
        w1 = (
            (tri[:, 2, 0] - tri[:, 0, 0]) * (p[:, 1] - tri[:, 0, 1])
            - (tri[:, 2, 1] - tri[:, 0, 1]) * (p[:, 0] - tri[:, 0, 0])
        ) / -area
        w2 = (
            (tri[:, 1, 0] - tri[:, 0, 0]) * (p[:, 1] - tri[:, 0, 1])
            - (tri[:, 1, 1] - tri[:, 0, 1]) * (p[:, 0] - tri[:, 0, 0])
        ) / area
        weights = np.stack([1 - w1 - w2, w1, w2], axis=1)
        z = (local[:, 2][triangles[triangle_index]] * np.clip(weights, 0, 1)).sum(axis=1)
        z /= np.clip(weights, 0, 1).sum(axis=1)
        # the best-fitting triangle of each point: the one it is least outside of
        badness = -np.minimum(weights.min(axis=1), 0)
        order = np.lexsort((badness, point_index))
        first = np.unique(point_index[order], return_index=True)[1]
        result[point_index[order][first]] = z[order][first]
        return result

    return height


def top_traces(
    scene: Scene, top: str | int = "top", kinds: Sequence[str] = ("fault", "horizon")
) -> list[PolyLine]:
    """Where each surface of ``kinds`` meets the ``top`` surface, as lines on the top surface.

    The top surface is read as a height field; a surface's trace is the zero level of its
    height above the top (edges lying on the top, and sign changes across triangles).

    >>> import geobrep
    >>> cake = geobrep.datasets.faulted_layer_cake()
    >>> trace = top_traces(cake)[0]
    >>> trace.name, trace.kind, round(trace.length)
    ('fault trace', 'fault', 805)
    """
    try:
        surface_top = scene[top]
    except EntityNotFoundError:
        raise EntityNotFoundError(
            f"no top surface {top!r}: pass top= the name or id of the topographic surface"
        ) from None
    if not isinstance(surface_top, Surface):
        raise DegenerateGeometryError(f"{surface_top.label} is not a Surface")
    centre, diagonal = _centre(scene)
    height = _height_field(surface_top, centre, diagonal)
    tolerance = 1e2 * RELATIVE_TOLERANCE * diagonal
    traces = []
    for surface in scene.surfaces:
        if surface.id == surface_top.id or surface.kind not in kinds:
            continue
        local = np.asarray(surface.vertices) - centre
        above = local[:, 2] - height(local)
        nodes, segments = level_set_segments(
            local, np.asarray(surface.faces, dtype=np.int64), above, tolerance
        )
        lines = _merge_lines(nodes, segments)
        metadata = _surface_metadata(surface, "traces")
        metadata["top"] = int(surface_top.id or 0)
        trace = _polyline_from_lines(
            lines,
            lambda xyz: xyz + centre,
            name=f"{surface.name} trace",
            kind=surface.kind,
            metadata=metadata,
        )
        if trace is not None:
            traces.append(trace)
    return traces


# -- section-plane coordinates -------------------------------------------------------------------
class SectionFrame(FrozenModel):
    """The frame of a section plane: ``world = origin + along·a + elevation·u + offset·n``.

    ``along`` is the horizontal unit vector of the section line (pointing east, or north for a
    north-south line), ``up`` the in-plane unit vector pointing upwards (``(0, 0, 1)`` for a
    vertical plane, so the second coordinate is the elevation: ``origin`` has z = 0), ``normal``
    = ``along × up``. Points of the section have offset 0. ``origin`` is where the section line
    starts (distance along 0 at the first point of the section).

    >>> frame = section_frame(Plane.y(100.0), [[5.0, 100.0, -3.0], [9.0, 100.0, 2.0]])
    >>> frame.origin, frame.along, frame.up
    ((5.0, 100.0, 0.0), (1.0, 0.0, 0.0), (0.0, 0.0, 1.0))
    >>> frame.to_plane([[9.0, 100.0, 2.0]]).tolist()
    [[4.0, 2.0, 0.0]]
    """

    origin: tuple[float, float, float]
    along: tuple[float, float, float]
    up: tuple[float, float, float]
    normal: tuple[float, float, float]

    @property
    def rotation(self) -> NDArray[np.float64]:
        """``(3, 3)`` rows ``along``, ``up``, ``normal`` (orthonormal, determinant +1)."""
        return np.array([self.along, self.up, self.normal], dtype=np.float64)

    def to_plane(self, points: ArrayLike) -> NDArray[np.float64]:
        """``(N, 3)`` world points as (distance along, elevation, offset from the plane)."""
        xyz = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        local: NDArray[np.float64] = (xyz - np.asarray(self.origin)) @ self.rotation.T
        return local

    def to_world(self, points: ArrayLike) -> NDArray[np.float64]:
        """``(N, 3)`` plane coordinates (along, elevation, offset) back to world points."""
        local = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        world: NDArray[np.float64] = local @ self.rotation + np.asarray(self.origin)
        return world


def section_frame(plane: Plane, points: ArrayLike | None = None) -> SectionFrame:
    """The :class:`SectionFrame` of a plane that is not horizontal; ``points`` (the section's
    vertices) place the origin at the start of the section line (default: the plane's point
    nearest to the world origin, at z = 0).

    A horizontal plane has no section line (its sections are map views already): a
    :class:`~geobrep.errors.DegenerateGeometryError`.
    """
    normal = plane.normal
    along = np.cross(normal, [0.0, 0.0, 1.0])
    length = float(np.linalg.norm(along))
    if length < 1e-12:
        raise DegenerateGeometryError(
            f"plane {plane.coefficients.tolist()} is horizontal: its sections are map views, "
            "drawn in world coordinates"
        )
    along /= length
    if along[0] < -1e-12 or (abs(along[0]) <= 1e-12 and along[1] < 0):
        along = -along  # sections read west to east (south to north for a north-south line)
    along[np.abs(along) < 1e-15] = 0.0
    up = np.cross(along, normal)
    if up[2] < 0:
        up = -up
    up /= np.linalg.norm(up)
    up[np.abs(up) < 1e-15] = 0.0
    normal_out = np.cross(along, up)
    xyz = None if points is None else np.asarray(points, dtype=np.float64).reshape(-1, 3)
    base = plane.point if xyz is None or xyz.shape[0] == 0 else xyz.mean(axis=0)
    base = base - (float(normal @ base) + plane.d / math.hypot(plane.a, plane.b, plane.c)) * normal
    origin = base - (base[2] / up[2]) * up  # on the plane, at z = 0
    if xyz is not None and xyz.shape[0]:
        origin = origin + float(((xyz - origin) @ along).min()) * along
    origin[2] = 0.0 if abs(origin[2]) < 1e-9 * max(1.0, float(np.abs(origin).max())) else origin[2]
    return SectionFrame(
        origin=(float(origin[0]), float(origin[1]), float(origin[2])),
        along=(float(along[0]), float(along[1]), float(along[2])),
        up=(float(up[0]), float(up[1]), float(up[2])),
        normal=(float(normal_out[0]), float(normal_out[1]), float(normal_out[2])),
    )


def to_section_plane(entities: Iterable[Entity], frame: SectionFrame) -> list[Entity]:
    """Section entities moved into ``frame``'s coordinates (along, elevation, offset).

    Each gets ``metadata["section_frame"]`` (the frame) and the layer ``<layer>_plane`` (the
    layer of :func:`block_sections` products, or ``sections``); ids are dropped. Entities
    without vertices are left out. :func:`from_section_plane` undoes it.
    """
    moved: list[Entity] = []
    for entity in entities:
        if not isinstance(entity, VertexEntity):
            continue
        metadata = dict(entity.metadata)
        layer = metadata.get("layer")
        metadata["layer"] = f"{layer if isinstance(layer, str) and layer else 'sections'}_plane"
        metadata[SECTION_FRAME_KEY] = frame.model_dump(mode="json")
        vertices = frame.to_plane(entity.vertices)  # type: ignore[attr-defined]
        moved.append(entity.replace(id=None, vertices=vertices, metadata=metadata))
    return moved


_PLANE_LAYER = re.compile(r"_plane(_\d+)?$")


def from_section_plane(entities: Iterable[Entity]) -> list[Entity]:
    """Entities in section-plane coordinates (``metadata["section_frame"]``) back in world
    coordinates, in their world layer; other entities are returned as they are.

    >>> import geobrep
    >>> cake = geobrep.datasets.faulted_layer_cake()
    >>> world = block_sections(cake, [Plane.x(450_700.0)])
    >>> plane = block_sections(cake, [Plane.x(450_700.0)], section_coordinates="plane")
    >>> back = from_section_plane(plane)
    >>> bool(max(abs(b.vertices - w.vertices).max() for b, w in zip(back, world)) < 1e-9)
    True
    """
    result: list[Entity] = []
    for entity in entities:
        stored = entity.metadata.get(SECTION_FRAME_KEY)
        if stored is None or not isinstance(entity, VertexEntity):
            result.append(entity)
            continue
        frame = SectionFrame.model_validate(stored)
        metadata = {k: v for k, v in entity.metadata.items() if k != SECTION_FRAME_KEY}
        layer = metadata.get("layer")
        if isinstance(layer, str):
            metadata["layer"] = _PLANE_LAYER.sub("", layer)
        vertices = frame.to_world(entity.vertices)  # type: ignore[attr-defined]
        result.append(entity.replace(id=None, vertices=vertices, metadata=metadata))
    return result


def block_sections(
    scene: Scene,
    planes: Iterable[Plane],
    *,
    with_traces: bool = False,
    section_coordinates: SectionCoordinates = "world",
) -> list[Polygon | PolyLine]:
    """The section of every block by each plane: one Polygon (with holes) per block and plane.

    The cutting is :func:`geobrep.ops.clipping.section` (the registered clippers); each polygon gets
    ``layer="sections"``, the block id and unit, and the plane's coefficients. With
    ``with_traces`` the section lines of the open surfaces come too (layer ``section_lines``).

    ``section_coordinates`` says where the sections of planes that are not horizontal go:
    ``"world"`` (map coordinates: a vertical section has no area in map view), ``"plane"``
    (the plane's own coordinates, see :class:`SectionFrame`: valid polygons a GIS can draw, in
    layer ``sections_plane``, or ``sections_plane_<k>`` for the k-th such plane when there are
    several), or ``"both"``. Horizontal sections are always in world coordinates.

    >>> import geobrep
    >>> cake = geobrep.datasets.faulted_layer_cake()
    >>> pieces = block_sections(cake, [geobrep.Plane.z(-150.0)])
    >>> round(sum(p.area for p in pieces))  # the whole 1000 m × 800 m model
    800000
    """
    from geobrep.ops.clipping import section

    if section_coordinates not in ("world", "plane", "both"):
        raise OptionsError(
            f"section_coordinates={section_coordinates!r}: choose 'world', 'plane' or 'both'"
        )
    planes = list(planes)
    upright = [p for p in planes if float(np.hypot(p.normal[0], p.normal[1])) >= 1e-12]
    products: list[Polygon | PolyLine] = []
    for plane in planes:
        coefficients = [float(plane.a), float(plane.b), float(plane.c), float(plane.d)]
        panel = section(scene, plane)
        if panel is None:
            continue
        cut: list[Polygon | PolyLine] = []
        for entity in panel.entities:
            metadata = dict(entity.metadata)
            metadata["plane"] = coefficients
            if isinstance(entity, Polygon) and entity.kind == "section":
                metadata["layer"] = "sections"
                cut.append(entity.replace(id=None, metadata=metadata))
            elif with_traces and isinstance(entity, PolyLine):
                metadata["layer"] = "section_lines"
                if entity.kind == "horizon":
                    metadata["horizon"] = entity.name
                cut.append(entity.replace(id=None, metadata=metadata))
        if plane not in upright or section_coordinates == "world":
            products += cut
            continue
        if section_coordinates == "both":
            products += cut
        frame = section_frame(plane, np.concatenate([e.vertices for e in cut]) if cut else None)
        for entity in to_section_plane(cut, frame):
            if len(upright) > 1:
                layer = str(entity.metadata["layer"])
                number = next(k for k, p in enumerate(upright, 1) if p is plane)
                entity = entity.replace(metadata={**entity.metadata, "layer": f"{layer}_{number}"})
            assert isinstance(entity, Polygon | PolyLine)
            products.append(entity)
    return products


def map_products(
    scene: Scene,
    *,
    top: str | int | None = "top",
    section_levels: Sequence[float] = (),
    section_planes: Sequence[Plane] = (),
    elevation: float = 0.0,
    with_section_lines: bool = False,
    section_coordinates: SectionCoordinates = "both",
) -> Scene:
    """Block outlines, top traces and sections of a model in one scene (the model's CRS).

    ``section_levels`` are z values of horizontal sections, ``section_planes`` any other
    planes (vertical sections); ``top=None`` skips the traces; ``with_section_lines`` adds the
    lines where horizons, faults and boundaries cross the section planes.
    ``section_coordinates`` (see :func:`block_sections`): by default the sections of vertical
    and inclined planes come both in world coordinates (layer ``sections``) and in their
    plane's coordinates (layer ``sections_plane``, with ``metadata["section_frame"]``; the GIS
    writers store the frame in the layer's metadata and write such layers without the CRS).

    >>> import geobrep
    >>> cake = geobrep.datasets.faulted_layer_cake()
    >>> products = map_products(cake, section_levels=[-150.0])
    >>> sorted({e.metadata["layer"] for e in products.entities})
    ['block_outlines', 'sections', 'traces']
    """
    entities: list[Any] = list(block_outlines(scene, elevation=elevation))
    if top is not None:
        entities += top_traces(scene, top=top)
    planes = [Plane.z(level) for level in section_levels] + list(section_planes)
    if planes:
        entities += block_sections(
            scene,
            planes,
            with_traces=with_section_lines,
            section_coordinates=section_coordinates,
        )
    return Scene(entities=entities, crs=scene.crs, name=f"{scene.name} map".strip())
