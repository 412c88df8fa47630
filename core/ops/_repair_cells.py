"""The repair actions on polylines and tet meshes (surfaces: :mod:`geobrep.ops.repairing`).

Each function takes the entity and the tolerance and returns ``(entity, count)``, the entity
unchanged when the count is 0. Point data follow their vertices (a weld keeps the lowest index's
values); cell data (one value per segment or tet) follow their cells.

* ``weld`` — vertices within the tolerance become one;
* ``drop_degenerate`` — a polyline's zero-length segments are collapsed (its later end joins the
  earlier one, the part stays one chain); flat tets are dropped;
* ``drop_duplicates`` — segments (tets) over the same vertices as an earlier one are dropped (a
  part loses the segment and splits there);
* ``drop_isolated`` — vertices no segment (tet) uses;
* ``orient`` — inverted tets (negative volume beyond the tolerance) get two corners swapped.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from geobrep.geometry import mesh
from geobrep.model.entities import PolyLine, TetMesh
from geobrep.model.properties import Property

__all__ = ["CELL_ACTIONS"]

IntArray = NDArray[np.int64]
BoolArray = NDArray[np.bool_]
_TET_FACES = np.array([[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]])


def _pick(prop: Property, index: Any) -> Property:
    return prop.model_copy(update={"values": np.asarray(prop.values)[index]})


def _renumbered(entity: Any, inverse: IntArray, n_new: int) -> dict[str, Any]:
    """Vertices and point data after mapping vertex ``i`` to ``inverse[i]`` (lowest kept)."""
    first = np.full(n_new, inverse.shape[0], dtype=np.int64)
    np.minimum.at(first, inverse, np.arange(inverse.shape[0], dtype=np.int64))
    return {
        "vertices": entity.vertices[first],
        "point_data": {k: _pick(v, first) for k, v in entity.point_data.items()},
    }


def _weld(entity: PolyLine | TetMesh, tol: float) -> tuple[Any, int]:
    merged, inverse = mesh.merge_close_vertices(entity.vertices, tol)
    count = entity.vertices.shape[0] - merged.shape[0]
    if count == 0:
        return entity, 0
    changes = _renumbered(entity, inverse, merged.shape[0])
    if isinstance(entity, PolyLine):
        line = entity.replace(indices=inverse[entity.indices], **changes)
        return _collapse_repeats(line)[0], count
    return entity.replace(cells=inverse[entity.cells], **changes), count


def _drop_isolated(entity: PolyLine | TetMesh, tol: float) -> tuple[Any, int]:
    cells = entity.indices if isinstance(entity, PolyLine) else entity.cells
    used, renumbered = mesh.compact_indices(cells, entity.vertices.shape[0])
    count = entity.vertices.shape[0] - used.shape[0]
    if count == 0:
        return entity, 0
    changes: dict[str, Any] = {
        "vertices": entity.vertices[used],
        "point_data": {k: _pick(v, used) for k, v in entity.point_data.items()},
        "indices" if isinstance(entity, PolyLine) else "cells": renumbered,
    }
    return entity.replace(**changes), count


# --------------------------------------------------------------------------- polylines
def _rebuild(line: PolyLine, keep: BoolArray) -> PolyLine:
    """``line`` with only the segments ``keep`` (in segment order): each part becomes the runs
    of its kept segments (a closed part with all kept stays closed)."""
    parts: list[NDArray[Any]] = []
    closed: list[bool] = []
    kept_segments: list[IntArray] = []
    segment = 0
    for p in range(line.n_parts):
        chain = np.asarray(line.indices[line.part_offsets[p] : line.part_offsets[p + 1]])
        n_seg = chain.shape[0] - 1 + int(line.closed[p])
        ids = np.arange(segment, segment + n_seg)
        mask = keep[ids]
        segment += n_seg
        if line.closed[p] and mask.all():
            parts.append(chain)
            closed.append(True)
            kept_segments.append(ids)
            continue
        if line.closed[p]:  # open it after a dropped segment
            shift = int(np.flatnonzero(~mask)[0]) + 1
            chain = np.roll(chain, -shift)
            chain = np.append(chain, chain[0])  # segment k: chain[k] to chain[k + 1]
            ids, mask = np.roll(ids, -shift), np.roll(mask, -shift)
        breaks = np.flatnonzero(~mask)
        start = 0
        for stop in [*breaks.tolist(), mask.shape[0]]:
            if stop > start:
                parts.append(chain[start : stop + 1])
                closed.append(False)
                kept_segments.append(ids[start:stop])
            start = stop + 1
    order = np.concatenate(kept_segments) if kept_segments else np.zeros(0, np.int64)
    return line.replace(
        indices=np.concatenate(parts) if parts else np.zeros(0, np.int64),
        part_offsets=np.cumsum([0, *[len(c) for c in parts]]).astype(np.int64),
        closed=np.asarray(closed, dtype=np.bool_),
        cell_data={k: _pick(v, order) for k, v in line.cell_data.items()},
    )


def _collapse_repeats(line: PolyLine) -> tuple[PolyLine, int]:
    """Segments from a vertex to itself removed by joining their ends (the chain stays whole);
    parts left with one vertex dropped, closed parts left with two opened."""
    segments = line.segments
    repeated = segments[:, 0] == segments[:, 1]
    count = int(repeated.sum())
    if count == 0:
        return line, 0
    parts: list[NDArray[Any]] = []
    closed: list[bool] = []
    kept: list[IntArray] = []
    segment = 0
    for p in range(line.n_parts):
        chain = np.asarray(line.indices[line.part_offsets[p] : line.part_offsets[p + 1]])
        n_seg = chain.shape[0] - 1 + int(line.closed[p])
        ids = np.arange(segment, segment + n_seg)
        segment += n_seg
        drop = repeated[ids]
        vertex_kept = np.ones(chain.shape[0], dtype=np.bool_)
        vertex_kept[1:] = ~drop[: chain.shape[0] - 1]  # the later end of a repeat goes
        is_closed = bool(line.closed[p])
        if is_closed and drop[-1] and vertex_kept[-1]:
            vertex_kept[-1] = False  # the closing segment repeats: the last vertex goes
        chain, ids = chain[vertex_kept], ids[~drop]
        if is_closed and chain.shape[0] < 3:
            is_closed, ids = False, ids[: max(chain.shape[0] - 1, 0)]
        if chain.shape[0] < 2:
            continue
        parts.append(chain)
        closed.append(is_closed)
        kept.append(ids)
    order = np.concatenate(kept) if kept else np.zeros(0, np.int64)
    return line.replace(
        indices=np.concatenate(parts) if parts else np.zeros(0, np.int64),
        part_offsets=np.cumsum([0, *[len(c) for c in parts]]).astype(np.int64),
        closed=np.asarray(closed, dtype=np.bool_),
        cell_data={k: _pick(v, order) for k, v in line.cell_data.items()},
    ), count


def _line_degenerate(line: PolyLine, tol: float) -> tuple[PolyLine, int]:
    segments = line.segments
    ends = line.vertices[segments]
    short = np.linalg.norm(ends[:, 1] - ends[:, 0], axis=1) <= tol
    if not short.any():
        return line, 0
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    n = line.vertices.shape[0]
    a, b = segments[short, 0], segments[short, 1]
    graph = coo_matrix((np.ones(a.shape[0], np.int8), (a, b)), shape=(n, n))
    _, label = connected_components(graph, directed=False)
    lowest = np.full(int(label.max()) + 1, n, dtype=np.int64)
    np.minimum.at(lowest, label, np.arange(n, dtype=np.int64))
    joined = line.replace(indices=lowest[label][line.indices])
    return _collapse_repeats(joined)[0], int(short.sum())


def _line_duplicates(line: PolyLine, tol: float) -> tuple[PolyLine, int]:
    segments = np.sort(line.segments, axis=1)
    if segments.shape[0] < 2:
        return line, 0
    _, first = np.unique(segments, axis=0, return_index=True)
    keep = np.zeros(segments.shape[0], dtype=np.bool_)
    keep[first] = True
    count = int((~keep).sum())
    return (_rebuild(line, keep), count) if count else (line, 0)


# --------------------------------------------------------------------------- tet meshes
def _take_tets(tets: TetMesh, keep: BoolArray | IntArray) -> TetMesh:
    changes: dict[str, Any] = {
        "cells": tets.cells[keep],
        "cell_data": {k: _pick(v, keep) for k, v in tets.cell_data.items()},
    }
    if tets.region_labels is not None:
        changes["region_labels"] = tets.region_labels[keep]
    return tets.replace(**changes)


def _tet_degenerate(tets: TetMesh, tol: float) -> tuple[TetMesh, int]:
    corners = tets.vertices[tets.cells]
    faces = corners[:, _TET_FACES]
    areas = 0.5 * np.linalg.norm(
        np.cross(faces[:, :, 1] - faces[:, :, 0], faces[:, :, 2] - faces[:, :, 0]), axis=2
    )
    largest = areas.max(axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        height = np.where(largest > 0, 3.0 * np.abs(tets.cell_volumes) / largest, 0.0)
    flat = height <= tol
    count = int(flat.sum())
    return (_take_tets(tets, ~flat), count) if count else (tets, 0)


def _tet_duplicates(tets: TetMesh, tol: float) -> tuple[TetMesh, int]:
    if tets.n_cells < 2:
        return tets, 0
    keep = mesh.first_of_duplicates(tets.cells)
    count = int((~keep).sum())
    return (_take_tets(tets, keep), count) if count else (tets, 0)


def _tet_orient(tets: TetMesh, tol: float) -> tuple[TetMesh, int]:
    """Inverted tets (as ``inverted_tets`` finds them) with corners 1 and 2 swapped."""
    corners = tets.vertices[tets.cells]
    scale = np.linalg.norm(corners[:, 1:] - corners[:, :1], axis=2).max(axis=1)
    bad = tets.cell_volumes < -(tol * scale**2)
    count = int(bad.sum())
    if count == 0:
        return tets, 0
    cells = np.asarray(tets.cells, dtype=np.int64).copy()
    cells[bad] = cells[bad][:, [0, 2, 1, 3]]
    return tets.replace(cells=cells), count


#: action name -> entity type -> function(entity, tol) -> (entity, count)
CELL_ACTIONS: dict[str, dict[type, Any]] = {
    "weld": {PolyLine: _weld, TetMesh: _weld},
    "drop_degenerate": {PolyLine: _line_degenerate, TetMesh: _tet_degenerate},
    "drop_duplicates": {PolyLine: _line_duplicates, TetMesh: _tet_duplicates},
    "drop_isolated": {PolyLine: _drop_isolated, TetMesh: _drop_isolated},
    "orient": {TetMesh: _tet_orient},
}
