"""What the built-in checks share: the tolerance, triangles of a surface, defect records."""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from geobrep import Entity, PolyLine, Scene, Surface, TetMesh
from geobrep.geometry import mesh
from geobrep.geometry.orientation import neighbour_pairs
from geobrep.plugins import CheckContext, Defect
from geobrep.plugins.blocks.precision import data_tolerance, measure_precision

__all__ = [
    "defects",
    "edge_incidence",
    "first_copies",
    "label",
    "mesh_entities",
    "neighbours",
    "tolerance",
    "triangles",
    "unique_ints",
    "welded",
    "welded_surfaces",
]

IntArray = NDArray[np.int64]
FloatArray = NDArray[np.float64]


def unique_ints(values: IntArray) -> IntArray:
    """``np.unique`` of integers by one sort (numpy's hashing ``unique`` is many times slower
    on large arrays)."""
    ordered = np.sort(np.asarray(values, dtype=np.int64).reshape(-1))
    if ordered.size == 0:
        return ordered
    keep = np.ones(ordered.shape[0], dtype=np.bool_)
    keep[1:] = ordered[1:] != ordered[:-1]
    return ordered[keep]


def first_copies(rows: IntArray) -> IntArray:
    """For each row of ``rows`` (K, m) of non-negative integers, the index of the first row equal
    to it (itself for the first of each kind): rows are packed into one int64 key when they fit,
    then one stable sort groups them."""
    rows = np.asarray(rows, dtype=np.int64)
    k = rows.shape[0]
    base = int(rows.max()) + 1 if rows.size else 1
    if rows.ndim != 2 or base ** rows.shape[1] >= 2**62:
        _, first, inverse = np.unique(rows, axis=0, return_index=True, return_inverse=True)
        return np.asarray(first[inverse.reshape(-1)], dtype=np.int64)
    key = np.zeros(k, dtype=np.int64)
    for column in range(rows.shape[1]):
        key = key * base + rows[:, column]
    order = np.argsort(key, kind="stable")
    ordered = key[order]
    start = np.ones(k, dtype=np.bool_)
    start[1:] = ordered[1:] != ordered[:-1]
    group_first = order[np.flatnonzero(start)]
    result = np.empty(k, dtype=np.int64)
    result[order] = group_first[np.cumsum(start) - 1]
    return result


def label(entity: Entity) -> str:
    """How a report names an entity: its name, else its label."""
    return entity.name or entity.label


def _coordinates(scene: Scene) -> FloatArray:
    parts = [
        np.asarray(e.vertices, dtype=np.float64).reshape(-1, 3)
        for e in scene.entities
        if hasattr(e, "vertices")
    ]
    return np.concatenate(parts) if parts else np.zeros((0, 3))


def tolerance(scene: Scene, context: CheckContext) -> float:
    """The tolerance asked for, else the one the data's precision gives (the block builder's
    rule: a few quanta of the coordinates' rounding, within [1e-9, 1e-4] of the diagonal)."""
    if context.tolerance_used is not None:
        return context.tolerance_used
    if context.tolerance is not None:
        context.tolerance_used, context.tolerance_source = context.tolerance, "option tolerance"
        return context.tolerance
    points = _coordinates(scene)
    if points.shape[0] == 0:
        context.tolerance_used, context.tolerance_source = 0.0, "no coordinates"
        return 0.0
    diagonal = float(np.linalg.norm(points.max(axis=0) - points.min(axis=0)))
    precision = measure_precision(points)
    value = data_tolerance(precision, diagonal)
    context.tolerance_used = value
    context.tolerance_source = f"{precision.source} coordinates, quantum {precision.quantum:.3g}"
    return value


def mesh_entities(scene: Scene) -> list[Surface | TetMesh | PolyLine]:
    """The entities with elements over vertices, in scene order."""
    return [e for e in scene.entities if isinstance(e, Surface | TetMesh | PolyLine)]


def triangles(surface: Surface, context: CheckContext) -> tuple[IntArray, IntArray]:
    """The surface's triangles (quads split) and the face each comes from (cached)."""
    key = f"triangles:{id(surface)}"
    if key not in context.cache:
        tris, source = mesh.triangulate(surface.faces)
        context.cache[key] = (tris.astype(np.int64), source.astype(np.int64))
    result: tuple[IntArray, IntArray] = context.cache[key]
    return result


def edge_incidence(
    surface: Surface, context: CheckContext
) -> tuple[IntArray, IntArray, IntArray, IntArray]:
    """The edge table of the surface's triangles (:func:`triangles`), shared by the checks of one
    inspection: ``(edges, offsets, incident triangles, sides)`` as
    :func:`geobrep.geometry.mesh.edge_face_incidence` gives them (cached)."""
    key = f"edges:{id(surface)}"
    if key not in context.cache:
        context.cache[key] = mesh.edge_face_incidence(triangles(surface, context)[0])
    result: tuple[IntArray, IntArray, IntArray, IntArray] = context.cache[key]
    return result


def neighbours(
    surface: Surface, context: CheckContext
) -> tuple[IntArray, IntArray, NDArray[np.bool_]]:
    """Triangle pairs across the surface's edges two triangles use, and whether they run the
    edge the same way (:func:`geobrep.geometry.orientation.neighbour_pairs`, cached)."""
    key = f"neighbours:{id(surface)}"
    if key not in context.cache:
        _, offsets, incident, sides = edge_incidence(surface, context)
        tris = triangles(surface, context)[0]
        context.cache[key] = neighbour_pairs(tris, offsets, incident * 3 + sides)
    result: tuple[IntArray, IntArray, NDArray[np.bool_]] = context.cache[key]
    return result


def welded(scene: Scene, context: CheckContext) -> tuple[FloatArray, list[IntArray]]:
    """Every vertex entity's vertices merged within the tolerance, across entities: the merged
    points and, per entity of :func:`mesh_entities`, the merged index of each vertex (cached)."""
    if "welded" not in context.cache:
        context.cache["welded"] = _merged(mesh_entities(scene), tolerance(scene, context))
    result: tuple[FloatArray, list[IntArray]] = context.cache["welded"]
    return result


def welded_surfaces(scene: Scene, context: CheckContext) -> tuple[FloatArray, IntArray]:
    """The surfaces' vertices (concatenated in scene order) merged within the tolerance: the
    merged points and the merged index of each vertex — :func:`welded` itself when the scene's
    mesh entities are all surfaces (cached)."""
    if "welded_surfaces" not in context.cache:
        entities = mesh_entities(scene)
        if all(isinstance(e, Surface) for e in entities):
            points, maps = welded(scene, context)
        else:
            points, maps = _merged(list(scene.surfaces), tolerance(scene, context))
        inverse = np.concatenate(maps) if maps else np.zeros(0, dtype=np.int64)
        context.cache["welded_surfaces"] = (points, inverse)
    result: tuple[FloatArray, IntArray] = context.cache["welded_surfaces"]
    return result


def _merged(entities: list[Any], tol: float) -> tuple[FloatArray, list[IntArray]]:
    points = np.concatenate([e.vertices for e in entities]) if entities else np.zeros((0, 3))
    merged, inverse = mesh.merge_close_vertices(points, tol)
    offsets = np.cumsum([0] + [e.vertices.shape[0] for e in entities])
    return merged, [inverse[offsets[k] : offsets[k + 1]] for k in range(len(entities))]


def defects(
    entity: Entity,
    element: str,
    ids: Any,
    locations: Any,
    *,
    points: Any = None,
    values: Any = None,
    message: str = "",
    other: Entity | None = None,
    other_ids: Any = None,
) -> list[Defect]:
    """One :class:`Defect` per row of ``ids`` (K, m) with its ``locations`` (K, 3), optional
    shapes ``points`` (K, p, 3), measures ``values`` (K,) and the other entity's ``other_ids``."""
    where = np.asarray(locations, dtype=np.float64).reshape(-1, 3).tolist()
    if not where:
        return []
    id_rows = np.asarray(ids, dtype=np.int64).reshape(len(where), -1).tolist()
    shapes = (
        np.asarray(points, dtype=np.float64).tolist() if points is not None else [[]] * len(where)
    )
    measures = np.asarray(values, dtype=np.float64).tolist() if values is not None else None
    others = (
        np.asarray(other_ids, dtype=np.int64).reshape(len(where), -1).tolist()
        if other_ids is not None
        else None
    )
    found = []
    for k, location in enumerate(where):
        found.append(
            Defect.model_construct(
                entity=label(entity),
                entity_id=entity.id,
                element=element,  # type: ignore[arg-type]
                ids=tuple(id_rows[k]),
                location=(location[0], location[1], location[2]),
                other_entity=label(other) if other is not None else None,
                other_entity_id=other.id if other is not None else None,
                other_ids=tuple(others[k]) if others is not None else (),
                value=measures[k] if measures is not None else None,
                message=message,
                points=tuple(tuple(p) for p in shapes[k]),
            )
        )
    return found
