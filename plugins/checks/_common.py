"""What the built-in checks share: the tolerance, triangles of a surface, defect records."""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from geobrep import Entity, PolyLine, Scene, Surface, TetMesh
from geobrep.geometry import mesh
from geobrep.plugins import CheckContext, Defect
from geobrep.plugins.blocks.precision import data_tolerance, measure_precision

__all__ = [
    "defects",
    "label",
    "mesh_entities",
    "tolerance",
    "triangles",
    "welded",
]

IntArray = NDArray[np.int64]
FloatArray = NDArray[np.float64]


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


def welded(scene: Scene, context: CheckContext) -> tuple[FloatArray, list[IntArray]]:
    """Every vertex entity's vertices merged within the tolerance, across entities: the merged
    points and, per entity of :func:`mesh_entities`, the merged index of each vertex (cached)."""
    if "welded" not in context.cache:
        entities = mesh_entities(scene)
        tol = tolerance(scene, context)
        points = np.concatenate([e.vertices for e in entities]) if entities else np.zeros((0, 3))
        merged, inverse = mesh.merge_close_vertices(points, tol)
        offsets = np.cumsum([0] + [e.vertices.shape[0] for e in entities])
        maps = [inverse[offsets[k] : offsets[k + 1]] for k in range(len(entities))]
        context.cache["welded"] = (merged, maps)
    result: tuple[FloatArray, list[IntArray]] = context.cache["welded"]
    return result


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
