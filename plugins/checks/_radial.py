"""The patches around each arc in right-hand order: the order the topology stores against the
order the geometry gives, by the block builder's radial sort (the angle of each triangle's
half-plane about an arc edge, thumb along the arc, counter-clockwise)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from geobrep import Arc, Scene, Surface
from geobrep.geometry import mesh
from geobrep.plugins import CheckContext, Defect
from geobrep.plugins.blocks.conformity import half_plane_angles
from geobrep.plugins.checks._common import mesh_entities, tolerance, triangles, welded

__all__ = ["arc_patch_order"]

IntArray = NDArray[np.int64]
FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class _Incidence:
    """The patches' triangles (welded vertices), the patch id of each, and their edges."""

    points: FloatArray
    triangles: IntArray
    patch: IntArray
    keys: IntArray  # sorted edge keys (low * n + high)
    order: IntArray  # edge row of each sorted key
    offsets: IntArray
    incident: IntArray


def _incidence(scene: Scene, context: CheckContext) -> _Incidence:
    points, maps = welded(scene, context)
    position = {id(e): k for k, e in enumerate(mesh_entities(scene))}
    parts: list[IntArray] = []
    owners: list[IntArray] = []
    for patch in scene.topology.patches:
        surface = scene.get(patch.surface)
        if not isinstance(surface, Surface):
            continue
        tris, source = triangles(surface, context)
        labels = (
            np.zeros(surface.n_faces, np.int64)
            if surface.patch_labels is None
            else np.asarray(surface.patch_labels, np.int64)
        )
        mine = tris[labels[source] == patch.label]
        parts.append(maps[position[id(surface)]][mine])
        owners.append(np.full(mine.shape[0], patch.id, np.int64))
    tri = np.concatenate(parts) if parts else np.zeros((0, 3), np.int64)
    patch_of = np.concatenate(owners) if owners else np.zeros(0, np.int64)
    if tri.shape[0] == 0:
        empty = np.zeros(0, np.int64)
        return _Incidence(points, tri, patch_of, empty, empty, np.zeros(1, np.int64), empty)
    edges, offsets, incident, _ = mesh.edge_face_incidence(tri)
    n = np.int64(points.shape[0])
    keys = edges.min(axis=1) * n + edges.max(axis=1)
    order = np.argsort(keys, kind="stable").astype(np.int64)
    return _Incidence(points, tri, patch_of, keys[order], order, offsets, incident)


def _edge_rows(incidence: _Incidence, s: int, t: int) -> IntArray:
    """Rows of the triangles using edge ``{s, t}`` (empty when no patch triangle does)."""
    key = min(s, t) * incidence.points.shape[0] + max(s, t)
    at = int(np.searchsorted(incidence.keys, key))
    if at == incidence.keys.shape[0] or incidence.keys[at] != key:
        return np.zeros(0, np.int64)
    edge = int(incidence.order[at])
    return incidence.incident[incidence.offsets[edge] : incidence.offsets[edge + 1]]


def _geometric_order(incidence: _Incidence, chain: IntArray) -> tuple[tuple[int, ...], int] | None:
    """The patches around the first edge of ``chain`` whose triangles all leave it at distinct
    angles, in right-hand order about ``chain[k] → chain[k + 1]``, with that ``k``."""
    for k in range(chain.shape[0] - 1):
        s, t = int(chain[k]), int(chain[k + 1])
        if s < 0 or t < 0 or s == t:
            continue
        rows = _edge_rows(incidence, s, t)
        if rows.size == 0:
            continue
        third = incidence.triangles[rows].sum(axis=1) - s - t
        starts, ends = np.full(rows.shape[0], s), np.full(rows.shape[0], t)
        angles, flat = half_plane_angles(incidence.points, starts, ends, third)
        ranked = np.sort(angles)
        if flat.any() or (ranked.size > 1 and np.min(np.diff(ranked)) <= 1e-9):
            continue
        return tuple(int(p) for p in incidence.patch[rows][np.argsort(angles)]), k
    return None


def _same_cycle(stored: tuple[int, ...], found: tuple[int, ...]) -> bool:
    """Whether two cyclic sequences are equal up to a rotation."""
    if len(stored) != len(found):
        return False
    doubled = found + found
    return any(doubled[k : k + len(stored)] == stored for k in range(len(found) or 1))


def _chain(arc: Arc, centre: FloatArray, tol: float, tree: Any) -> IntArray:
    """The welded vertex of each arc point (-1 where no vertex lies within the tolerance)."""
    distance, nearest = tree.query(np.asarray(arc.points, np.float64) - centre)
    return np.where(distance <= tol, nearest, -1).astype(np.int64)


def arc_patch_order(scene: Scene, options: Any, context: CheckContext) -> list[Defect]:
    """Arcs whose patches, as the topology lists them, are not those around the arc in
    right-hand order (thumb along the arc, from its start corner to its end corner)."""
    arcs = [a for a in scene.topology.arcs if a.patches]
    if not arcs:
        return []
    incidence = _incidence(scene, context)
    if incidence.triangles.shape[0] == 0:
        return []
    from scipy.spatial import cKDTree

    centre = incidence.points.mean(axis=0)
    tree = cKDTree(incidence.points - centre)
    diagonal = float(np.ptp(incidence.points, axis=0).max(initial=0.0))
    tol = max(tolerance(scene, context), 1e-9 * diagonal)
    found = []
    for arc in arcs:
        result = _geometric_order(incidence, _chain(arc, centre, tol, tree))
        if result is None:
            continue
        order, k = result
        if _same_cycle(tuple(arc.patches), order):
            continue
        ends = np.asarray(arc.points[k : k + 2], np.float64)
        x, y, z = (float(c) for c in ends.mean(axis=0))
        what = (
            "not in right-hand order"
            if sorted(order) == sorted(arc.patches)
            else "not the patches around it"
        )
        found.append(
            Defect(
                entity=f"arc {arc.id}",
                element="arc",
                ids=(arc.id,),
                location=(x, y, z),
                value=float(len(arc.patches)),
                message=f"patches listed {tuple(arc.patches)} are {what}: the geometry gives "
                f"{order} (value: patches listed)",
                points=tuple(tuple(p) for p in ends.tolist()),
            )
        )
    return found
