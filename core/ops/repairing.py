"""Mending what inspection finds: :func:`repair` returns a new scene and what each action did.

Actions, in the order they run (``actions=None`` runs them all):

* ``weld`` — vertices of one surface within the tolerance of each other inside one patch become
  one (the lowest index keeps its point data): the groups ``colocated_vertices`` reports;
* ``drop_degenerate`` — faces repeating a vertex, or whose height is within the tolerance;
* ``drop_duplicates`` — faces over the same vertices as an earlier face;
* ``drop_isolated`` — vertices no face uses;
* ``split_t_junctions`` — a vertex of one surface lying on another's face or edge is inserted
  there (the edge, or the face, is split), so that the two become conformal;
* ``orient`` — the faces of each patch agree with its majority; inverted tets are turned;
* ``orient_blocks`` — each block's sides orient its boundary outward (positive volume).

The mesh actions also mend polylines and tet meshes (:mod:`geobrep.ops._repair_cells`: welded
vertices, zero-length segments collapsed, flat and duplicated tets or duplicated segments
dropped, unused vertices dropped, inverted tets turned).

Properties (point and cell data), ids, names, kinds, patch labels and the topology are kept;
face data follow their faces, a vertex inserted on an edge interpolates its point data.

>>> import geobrep
>>> repaired, report = geobrep.repair(geobrep.datasets.faulted_layer_cake())
>>> report.total
0
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterable
from typing import Any

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict

from geobrep.errors import OptionsError
from geobrep.geometry import mesh
from geobrep.model.entities import Entity, Surface
from geobrep.model.orientation import orient_blocks, orient_patches
from geobrep.model.properties import Property
from geobrep.model.scene import Scene
from geobrep.ops._rederive import connectivity, rederive_patches
from geobrep.ops._repair_cells import CELL_ACTIONS
from geobrep.ops.inspection import Progress, _as_inspected_scene, _checked_tolerance, inspect

__all__ = ["ACTIONS", "RepairAction", "RepairReport", "repair"]

IntArray = NDArray[np.int64]

ACTIONS = (
    "weld",
    "drop_degenerate",
    "drop_duplicates",
    "drop_isolated",
    "split_t_junctions",
    "orient",
    "orient_blocks",
)
#: The check (or checks) whose defects each action mends (inspected before and after).
ADDRESSES: dict[str, str | tuple[str, ...]] = {
    "weld": "colocated_vertices",
    "drop_degenerate": "degenerate_elements",
    "drop_duplicates": "duplicated_elements",
    "drop_isolated": "isolated_vertices",
    "split_t_junctions": "t_junctions",
    "orient": ("inconsistent_orientation", "inverted_tets"),
    "orient_blocks": "region_sides",
}
_ROUNDS = 4
#: The step after the mesh actions (and before orienting) re-deriving patches and blocks.
REDERIVE = "rederive_patches"
_ORIENTING = ("orient", "orient_blocks")


class RepairAction(BaseModel):
    """One action: how many elements it changed, per entity, and notes."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    action: str
    count: int = 0
    entities: dict[str, int] = {}
    notes: tuple[str, ...] = ()


class RepairReport(BaseModel):
    """What :func:`geobrep.repair` did, and the addressed checks' counts before and after."""

    model_config = ConfigDict(frozen=True, extra="forbid")

    tolerance: float | None = None
    actions: tuple[RepairAction, ...] = ()
    before: dict[str, int] = {}
    after: dict[str, int] = {}

    @property
    def total(self) -> int:
        return sum(a.count for a in self.actions)

    def __str__(self) -> str:
        lines = [f"{a.action:<18} {a.count:>8}" for a in self.actions]
        lines += [
            f"{check}: {self.before.get(check, 0)} -> {self.after.get(check, 0)} defect(s)"
            for check in self.before
        ]
        return "\n".join(lines)


def _pick(prop: Property, index: Any) -> Property:
    """``prop`` (its meaning kept) with the values at ``index``."""
    return prop.model_copy(update={"values": np.asarray(prop.values)[index]})


def _take(surface: Surface, keep: NDArray[np.bool_], vertices: Any = None) -> Surface:
    """``surface`` with only the faces ``keep``, their cell data and patch labels."""
    changes: dict[str, Any] = {
        "faces": surface.faces[keep],
        "cell_data": {k: _pick(v, keep) for k, v in surface.cell_data.items()},
    }
    if surface.patch_labels is not None:
        changes["patch_labels"] = surface.patch_labels[keep]
    if vertices is not None:
        changes["vertices"] = vertices
    return surface.replace(**changes)


def _weld(surface: Surface, tol: float) -> tuple[Surface, int]:
    """Merge what ``colocated_vertices`` reports: vertices within ``tol`` inside one patch (the
    copies each GOCAD TFACE holds of a border it shares are left alone)."""
    parts = mesh.part_vertices(surface.faces, surface.patch_labels, surface.vertices.shape[0])
    merged, inverse = mesh.merge_close_vertices_in_parts(surface.vertices, parts, tol)
    count = surface.vertices.shape[0] - merged.shape[0]
    if count == 0:
        return surface, 0
    first = np.full(merged.shape[0], surface.vertices.shape[0], dtype=np.int64)
    np.minimum.at(first, inverse, np.arange(inverse.shape[0]))
    return surface.replace(
        vertices=merged,
        faces=inverse[surface.faces],
        point_data={k: _pick(v, first) for k, v in surface.point_data.items()},
    ), count


def _drop_degenerate(surface: Surface, tol: float) -> tuple[Surface, int]:
    faces = np.asarray(surface.faces, dtype=np.int64)
    k = faces.shape[1]
    repeated = np.zeros(faces.shape[0], dtype=np.bool_)
    for a in range(k):
        for b in range(a + 1, k):
            repeated |= faces[:, a] == faces[:, b]
    if k == 3:
        corners = surface.vertices[faces]
        sides = corners[:, [1, 2, 0]] - corners
        longest = np.linalg.norm(sides, axis=2).max(axis=1)
        doubled = np.linalg.norm(np.cross(sides[:, 0], -sides[:, 2]), axis=1)
        with np.errstate(divide="ignore", invalid="ignore"):
            repeated |= ~(doubled / longest > tol)
    count = int(repeated.sum())
    return (_take(surface, ~repeated), count) if count else (surface, 0)


def _drop_duplicates(surface: Surface, tol: float) -> tuple[Surface, int]:
    if surface.n_faces < 2:
        return surface, 0
    keep = mesh.first_of_duplicates(surface.faces)
    count = int((~keep).sum())
    return (_take(surface, keep), count) if count else (surface, 0)


def _drop_isolated(surface: Surface, tol: float) -> tuple[Surface, int]:
    used, faces = mesh.compact_indices(surface.faces, surface.vertices.shape[0])
    count = surface.vertices.shape[0] - used.shape[0]
    if count == 0:
        return surface, 0
    return surface.replace(
        vertices=surface.vertices[used],
        faces=faces,
        point_data={k: _pick(v, used) for k, v in surface.point_data.items()},
    ), count


def _orient(surface: Surface, tol: float) -> tuple[Surface, int]:
    oriented, flipped = orient_patches(surface)
    return oriented, sum(flipped.values())


_PER_SURFACE = {
    "weld": _weld,
    "drop_degenerate": _drop_degenerate,
    "drop_duplicates": _drop_duplicates,
    "drop_isolated": _drop_isolated,
    "orient": _orient,
}


def _insert_point(surface: Surface, face: int, point: Any, tol: float) -> Surface | None:
    """``surface`` with ``point`` inserted in face ``face``: on the edge it lies on (both faces
    of that edge split in two), else inside (the face split in three). ``None``: not a triangle,
    or the point is one of its corners."""
    faces = np.asarray(surface.faces, dtype=np.int64)
    if faces.shape[1] != 3:
        return None
    tri = faces[face]
    corners = surface.vertices[tri]
    x = np.asarray(point, dtype=np.float64)
    if np.linalg.norm(corners - x, axis=1).min() <= tol:
        return None
    edge_vectors = corners[[1, 2, 0]] - corners
    t = np.clip(
        np.einsum("ij,ij->i", x - corners, edge_vectors)
        / np.einsum("ij,ij->i", edge_vectors, edge_vectors),
        0.0,
        1.0,
    )
    distance = np.linalg.norm(corners + t[:, None] * edge_vectors - x, axis=1)
    side = int(np.argmin(distance))
    new = surface.vertices.shape[0]
    a, b = int(tri[side]), int(tri[(side + 1) % 3])
    if distance[side] <= tol:
        weight = float(t[side])
        rows: list[int] = []
        new_faces: list[tuple[list[int], ...]] = []
        for row in np.flatnonzero(((faces == a) | (faces == b)).sum(axis=1) == 2).tolist():
            f = faces[row].tolist()
            i = f.index(a)
            if f[(i + 1) % 3] == b:
                first, second = [a, new, f[(i + 2) % 3]], [new, b, f[(i + 2) % 3]]
            else:
                j = f.index(b)
                first, second = [b, new, f[(j + 2) % 3]], [new, a, f[(j + 2) % 3]]
            rows.append(row)
            new_faces.append((first, second))
        point_values = {k: _interpolated(v, a, b, weight) for k, v in surface.point_data.items()}
    else:
        c = int(tri[(side + 2) % 3])
        rows, new_faces = [face], [([a, b, new], [b, c, new], [c, a, new])]
        point_values = {k: v.values[a : a + 1] for k, v in surface.point_data.items()}
    return _with_split_faces(surface, x, rows, new_faces, point_values)


def _interpolated(values: Any, a: int, b: int, weight: float) -> Any:
    array = np.asarray(values)
    if np.issubdtype(array.dtype, np.floating):
        return (1.0 - weight) * array[a : a + 1] + weight * array[b : b + 1]
    return array[a : a + 1] if weight < 0.5 else array[b : b + 1]


def _with_split_faces(
    surface: Surface,
    point: Any,
    rows: list[int],
    replacements: list[tuple[list[int], ...]],
    point_values: dict[str, Any],
) -> Surface:
    faces = np.asarray(surface.faces, dtype=np.int64).copy()
    parent = list(range(faces.shape[0]))
    extra: list[list[int]] = []
    for row, pieces in zip(rows, replacements, strict=True):
        faces[row] = pieces[0]
        for piece in pieces[1:]:
            extra.append(piece)
            parent.append(row)
    source = np.asarray(parent, dtype=np.int64)
    changes: dict[str, Any] = {
        "vertices": np.vstack([surface.vertices, np.asarray(point)[None]]),
        "faces": np.vstack([faces, np.asarray(extra, dtype=np.int64).reshape(-1, 3)]),
        "point_data": {
            k: v.model_copy(update={"values": np.concatenate([v.values, point_values[k]])})
            for k, v in surface.point_data.items()
        },
        "cell_data": {k: _pick(v, source) for k, v in surface.cell_data.items()},
    }
    if surface.patch_labels is not None:
        changes["patch_labels"] = surface.patch_labels[source]
    return surface.replace(**changes)


def _split_t_junctions(scene: Scene, tol: float) -> tuple[Scene, int, list[str]]:
    count, notes = 0, []
    for _ in range(_ROUNDS):
        section = inspect(scene, ["t_junctions"], tol, max_listed=1 << 30).section("t_junctions")
        if section.count == 0:
            break
        surfaces = {int(e.id or 0): e for e in scene.surfaces}
        changed: dict[int, Surface] = {}
        done: set[tuple[int, int]] = set()
        for defect in section.defects:
            target_id = defect.other_entity_id
            if target_id is None or not defect.other_ids or target_id in changed:
                continue  # one insertion per surface and round: face ids change after it
            owner = surfaces[int(defect.entity_id or 0)]
            point = owner.vertices[defect.ids[0]] if defect.element == "vertex" else defect.location
            key = (target_id, defect.other_ids[0])
            if key in done:
                continue
            done.add(key)
            result = _insert_point(surfaces[target_id], defect.other_ids[0], point, tol)
            if result is not None:
                changed[target_id] = result
                count += 1
        if not changed:
            notes.append(f"{section.count} T-junction(s) could not be split")
            break
        scene = scene.replace(entities=[changed.get(int(e.id or 0), e) for e in scene.entities])
    return scene, count, notes


def _addressed(action: str) -> tuple[str, ...]:
    checks = ADDRESSES[action]
    return (checks,) if isinstance(checks, str) else checks


def _chosen_actions(actions: str | Iterable[str] | None) -> list[str]:
    if actions is None:
        return list(ACTIONS)
    names = [actions] if isinstance(actions, str) else list(actions)
    unknown = [n for n in names if n not in ACTIONS]
    if unknown or not names:
        raise OptionsError(
            f"actions: unknown action(s) {', '.join(map(repr, unknown)) or '(none given)'}; "
            f"actions: {', '.join(ACTIONS)}"
        )
    return [a for a in ACTIONS if a in names]


def repair(
    scene: Scene | Entity | Iterable[Entity],
    actions: str | Iterable[str] | None = None,
    tolerance: float | None = None,
    *,
    progress: Progress | None = None,
) -> tuple[Scene, RepairReport]:
    """Mend the defects ``actions`` address (default: all of :data:`ACTIONS`), at ``tolerance``
    (default: the one :func:`geobrep.inspect` derives from the data's precision).

    Where the mesh actions changed a surface's connectivity (a weld closing a seam inside a
    patch, an edge split at a T-junction), patches, topology and blocks are re-derived by the
    block builder before orienting (step ``rederive_patches``, see :mod:`geobrep.ops._rederive`),
    keeping properties, ids and names; copies of a border that re-derived patches now hold
    inside one patch are welded then (counted with ``weld``).

    ``progress(step, done, total, seconds)`` is called after the inspection before, each step
    and the inspection after (steps ``inspect before``, the step names, ``inspect after``)."""
    source = _as_inspected_scene(scene)
    chosen = _chosen_actions(actions)
    checks = [c for a in chosen for c in _addressed(a)]
    steps, clock = len(chosen) + 3, time.perf_counter()
    before = inspect(source, checks, _checked_tolerance(tolerance), max_listed=0)
    if progress is not None:
        progress("inspect before", 1, steps, time.perf_counter() - clock)
    tol = before.tolerance if before.tolerance is not None else 0.0
    signatures = {int(s.id or 0): connectivity(s) for s in source.surfaces}
    done: list[RepairAction] = []
    current = source
    plan = [a for a in chosen if a not in _ORIENTING] + [REDERIVE]
    plan += [a for a in chosen if a in _ORIENTING]
    for number, action in enumerate(plan, start=2):
        clock = time.perf_counter()
        if action == REDERIVE:
            current, step = _rederive(current, signatures, tol)
            if step.count and "weld" in chosen:
                current, done = _weld_again(current, done, tol)
        else:
            current, step = _apply(action, current, tol)
        done.append(step)
        if progress is not None:
            progress(action, number, steps, time.perf_counter() - clock)
    clock = time.perf_counter()
    after = inspect(current, checks, tol, max_listed=0)
    if progress is not None:
        progress("inspect after", steps, steps, time.perf_counter() - clock)
    report = RepairReport(
        tolerance=tol, actions=tuple(done), before=before.counts(), after=after.counts()
    )
    return current, report


def _weld_again(
    current: Scene, done: list[RepairAction], tol: float
) -> tuple[Scene, list[RepairAction]]:
    """After patches were re-derived, the copies patches held of a border they no longer split
    lie inside one patch: weld them too (counted with the first weld)."""
    current, again = _apply("weld", current, tol)
    if not again.count:
        return current, done
    merged = []
    for step in done:
        if step.action == "weld":
            entities = dict(step.entities)
            for name, count in again.entities.items():
                entities[name] = entities.get(name, 0) + count
            step = step.model_copy(update={"count": step.count + again.count, "entities": entities})
        merged.append(step)
    return current, merged


def _apply(action: str, current: Scene, tol: float) -> tuple[Scene, RepairAction]:
    """One repair action on the scene, and what it did."""
    notes: list[str] = []
    per_entity: dict[str, int] = {}
    if action in _PER_SURFACE:
        replaced: dict[int, Entity] = {}
        for entity in current.entities:
            function: Callable[[Any, float], tuple[Any, int]] | None = (
                _PER_SURFACE[action] if isinstance(entity, Surface) else None
            )
            function = function or CELL_ACTIONS.get(action, {}).get(type(entity))
            if function is None:
                continue
            fixed, count = function(entity, tol)
            if count:
                replaced[int(entity.id or 0)] = fixed
                per_entity[entity.name or entity.label] = count
        current = current.replace(
            entities=[replaced.get(int(e.id or 0), e) for e in current.entities]
        )
        total = sum(per_entity.values())
    elif action == "split_t_junctions":
        current, total, notes = _split_t_junctions(current, tol)
    else:
        current, notes = orient_blocks(current)
        total = sum(1 for n in notes if "reversed" in n)
    return current, RepairAction(
        action=action, count=total, entities=per_entity, notes=tuple(notes)
    )


def _rederive(
    current: Scene, signatures: dict[int, tuple[int, int]], tol: float
) -> tuple[Scene, RepairAction]:
    """Patches and blocks re-derived by the builder when the repairs so far changed the
    connectivity of a surface (its edges or border edges); count: the surfaces concerned."""
    changed = {
        int(s.id or 0)
        for s in current.surfaces
        if signatures.get(int(s.id or 0)) != connectivity(s)
    }
    repaired, notes = rederive_patches(current, changed, tol)
    names = {int(s.id or 0): s.name or s.label for s in current.surfaces}
    count = len(changed) if repaired is not current else 0
    return repaired, RepairAction(
        action=REDERIVE,
        count=count,
        entities={names[k]: 1 for k in sorted(changed)} if count else {},
        notes=tuple(notes),
    )
