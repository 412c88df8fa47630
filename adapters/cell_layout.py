"""A scene as one point array plus typed cell blocks: how mesh file formats see it.

VTK, meshio, PLY and pyvista all store *one* point array and cells of a few types
(``vertex``, ``line``, ``triangle``, ``quad``, ``tetra``), with named arrays per point and per
cell. :func:`scene_to_layout` flattens the mesh entities of a scene into that shape, adding
two cell arrays — :data:`ENTITY_ARRAY` (the entity id of each cell) and :data:`PART_ARRAY`
(its patch, region or part) — and a JSON *header* (names, kinds, ids, property units, CRS,
groups) that formats keep as field data or comments. :func:`layout_to_scene` rebuilds the
scene from the header when it is present, and from the cell types alone when it is not
(files written by other programs).

>>> import geobrep
>>> scene = geobrep.datasets.faulted_layer_cake()
>>> layout = scene_to_layout(scene)
>>> [e.name for e in layout_to_scene(layout).entities][:3]
['H1', 'H2', 'top']
"""

from __future__ import annotations

import itertools
import json
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import Any, Final, Literal, cast

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, NonNegativeInt, ValidationError

from geobrep.adapters import _strict_json as strict_json
from geobrep.adapters.casting import cast_exactly, misfit_rows
from geobrep.errors import FormatError, GeobrepError
from geobrep.model.crs import CRS
from geobrep.model.entities import Entity, PointSet, PolyLine, Surface, TetMesh
from geobrep.model.properties import Property, PropertyMap
from geobrep.model.scene import Group, Scene

__all__ = [
    "ENTITY_ARRAY",
    "HEADER_ARRAY",
    "LAYOUT_TYPES",
    "PART_ARRAY",
    "CellLayout",
    "chain_segments",
    "check_header",
    "decode_header",
    "encode_header",
    "header_applies",
    "layout_to_scene",
    "located",
    "scene_to_layout",
]

ENTITY_ARRAY: Final = "geobrep_entity"
"""Cell array holding the id of the entity each cell belongs to."""
PART_ARRAY: Final = "geobrep_part"
"""Cell array holding the patch (Surface), region (TetMesh) or part (PolyLine) of each cell."""
HEADER_ARRAY: Final = "geobrep_header"
"""Field-data name of the JSON header (stored as UTF-8 bytes)."""
HEADER_FORMAT: Final = "geobrep-layout"
HEADER_VERSION: Final = 1

#: Entity types a cell layout holds.
LAYOUT_TYPES: Final = frozenset({"PointSet", "PolyLine", "Surface", "TetMesh"})

_CELL_WIDTH: Final = {"vertex": 1, "line": 2, "triangle": 3, "quad": 4, "tetra": 4}
_EMPTY_WIDTH: Final = {"Surface": 3, "TetMesh": 4, "PolyLine": 2, "PointSet": 1}


@dataclass
class CellLayout:
    """Points, cell blocks and their arrays, plus the JSON header.

    ``blocks`` is a list of ``(cell_type, connectivity)``, connectivity ``(k, width)`` int64
    indices into ``points``; ``cell_data`` arrays run over the cells of all blocks in order.
    """

    points: NDArray[np.float64]
    blocks: list[tuple[str, NDArray[np.int64]]]
    point_data: dict[str, NDArray[Any]] = field(default_factory=dict)
    cell_data: dict[str, NDArray[Any]] = field(default_factory=dict)
    header: dict[str, Any] | None = None

    @property
    def n_cells(self) -> int:
        """Number of cells over all blocks."""
        return sum(int(conn.shape[0]) for _, conn in self.blocks)

    def block_slices(self) -> list[slice]:
        """The slice of the flat cell arrays that belongs to each block."""
        sizes = np.cumsum([0] + [int(conn.shape[0]) for _, conn in self.blocks])
        return [slice(int(a), int(b)) for a, b in itertools.pairwise(sizes)]


def encode_header(header: dict[str, Any]) -> NDArray[np.uint8]:
    """The header as UTF-8 JSON bytes in a uint8 array (storable as VTK field data)."""
    text = json.dumps(header, separators=(",", ":"), allow_nan=False)
    return np.frombuffer(text.encode("utf-8"), dtype=np.uint8).copy()


def decode_header(data: Any) -> dict[str, Any] | None:
    """The header from :func:`encode_header` bytes (or a JSON string); None if not ours."""
    try:
        if isinstance(data, str):
            text = data
        else:
            raw = np.asarray(data).ravel()
            if misfit_rows(raw, np.uint8).any():
                return None
            text = raw.astype(np.uint8).tobytes().decode("utf-8")
        header = strict_json.loads(text)
    except (ValueError, TypeError, UnicodeDecodeError):
        return None
    if not isinstance(header, dict) or header.get("format") != HEADER_FORMAT:
        return None
    return header


# -- scene -> layout ---------------------------------------------------------------------------


def _property_record(prop: Property, array_name: str) -> dict[str, Any]:
    return {
        "array": array_name,
        "dtype": str(prop.dtype),
        "unit": prop.unit,
        "no_data_value": _json_number(prop.no_data_value),
        "description": prop.description,
        "metadata": prop.metadata,
    }


def _json_number(value: float | None) -> float | str | None:
    """JSON has no NaN or infinity: the strings pydantic reads back as floats."""
    if value is None or np.isfinite(value):
        return value
    return "NaN" if np.isnan(value) else ("Infinity" if value > 0 else "-Infinity")


def header_applies(header: dict[str, Any] | None, cell_data: dict[str, Any]) -> bool:
    """True when ``header`` describes these cells: entity ids present, or a single entity."""
    if header is None:
        return False
    entities = header.get("entities", ())
    # a header whose entities are not a list still claims the file: check_header says why not
    return ENTITY_ARRAY in cell_data or not isinstance(entities, list) or len(entities) <= 1


def _entity_cells(entity: Entity) -> tuple[str, NDArray[np.int64], NDArray[np.int64] | None]:
    """Cell type, local connectivity and part label per cell of a mesh entity (None: all 0).

    The entity's own arrays are returned when they already are int64 (no copies).
    """
    if isinstance(entity, Surface):
        kind = "triangle" if entity.faces.shape[1] == 3 else "quad"
        labels = entity.patch_labels
        parts = None if labels is None else labels.astype(np.int64, copy=False)
        return kind, entity.faces.astype(np.int64, copy=False), parts
    if isinstance(entity, TetMesh):
        labels = entity.region_labels
        parts = None if labels is None else labels.astype(np.int64, copy=False)
        return "tetra", entity.cells.astype(np.int64, copy=False), parts
    if isinstance(entity, PolyLine):
        segments = entity.segments.astype(np.int64)
        counts = np.diff(entity.part_offsets) - 1 + entity.closed.astype(np.int64)
        counts = np.maximum(counts, 0)
        parts = np.repeat(np.arange(len(counts), dtype=np.int64), counts)
        return "line", segments, parts
    if isinstance(entity, PointSet):
        count = entity.n_points
        return "vertex", np.arange(count, dtype=np.int64)[:, None], None
    raise TypeError(f"{entity.label} has no cell layout")


def _merge_arrays(
    owners: list[tuple[int, int, NDArray[Any]]], total: int, name: str
) -> NDArray[Any]:
    """One array over ``total`` elements from ``(start, stop, values)`` pieces; gaps filled."""
    dtype = np.result_type(*[values.dtype for _, _, values in owners])
    shape = owners[0][2].shape[1:]
    if len(owners) == 1 and owners[0][:2] == (0, total) and owners[0][2].dtype == dtype:
        return owners[0][2]  # one entity holds all the elements: its array as it is
    if dtype.kind == "f":
        merged = np.full((total, *shape), np.nan, dtype=dtype)
    else:
        merged = np.zeros((total, *shape), dtype=dtype)
    for start, stop, values in owners:
        merged[start:stop] = values
    return merged


def _array_name(name: str) -> str:
    """A property name usable as an array name everywhere (no whitespace)."""
    return "_".join(name.split()) or "_"


def scene_to_layout(scene: Scene, reserved: frozenset[str] = frozenset()) -> CellLayout:
    """Flatten the PointSet, PolyLine, Surface and TetMesh entities of ``scene``.

    Other entities are left out (see :data:`LAYOUT_TYPES`); the header records what was kept.
    A property name used by entities with different element sizes, or one of the ``reserved``
    names a format uses itself, gets one array per entity (``"name#<id>"``); whitespace in
    names becomes ``_`` (the header keeps the real name).
    """
    reserved = reserved | {ENTITY_ARRAY, PART_ARRAY}
    kept = [e for e in scene.entities if e.type in LAYOUT_TYPES]
    point_offsets = np.cumsum([0] + [int(e.n_points) for e in kept])
    cell_counts: list[int] = []
    blocks: list[tuple[str, NDArray[np.int64]]] = []
    part_column: list[NDArray[np.int64] | None] = []
    for index, entity in enumerate(kept):
        kind, conn, parts = _entity_cells(entity)
        offset = int(point_offsets[index])
        blocks.append((kind, conn + offset if offset else conn))
        cell_counts.append(int(conn.shape[0]))
        part_column.append(parts)
    cell_offsets = np.cumsum([0, *cell_counts])
    point_data, point_records = _layout_arrays(kept, "point_data", point_offsets, reserved)
    cell_data, cell_records = _layout_arrays(kept, "cell_data", cell_offsets, reserved)
    if len(kept) > 1:
        cell_data[ENTITY_ARRAY] = _small_ints(
            np.repeat(np.asarray([e.id for e in kept], dtype=np.int64), cell_counts)
        )
    if any(_has_parts(e) for e in kept):
        cell_data[PART_ARRAY] = _small_ints(
            _concat(
                [
                    np.zeros(count, np.int64) if parts is None else parts
                    for parts, count in zip(part_column, cell_counts, strict=True)
                ]
            )
        )
    kept_ids = {e.id for e in kept}
    entities = [
        _entity_record(
            entity,
            (int(point_offsets[index]), int(point_offsets[index + 1])),
            point_records[index],
            cell_records[index],
        )
        for index, entity in enumerate(kept)
    ]
    header = {
        "format": HEADER_FORMAT,
        "version": HEADER_VERSION,
        "name": scene.name,
        "metadata": scene.metadata,
        "crs": None if scene.crs is None else scene.crs.model_dump(mode="json"),
        "groups": [_group_json(g, kept_ids) for g in scene.groups],
        "entities": entities,
    }
    vertices = [cast(Any, e).vertices for e in kept]
    return CellLayout(
        points=vertices[0] if len(vertices) == 1 else _concat_points(vertices),
        blocks=blocks,
        point_data=point_data,
        cell_data=cell_data,
        header=header,
    )


def _layout_arrays(
    kept: Sequence[Entity], kind: str, offsets: NDArray[np.int64], reserved: frozenset[str]
) -> tuple[dict[str, NDArray[Any]], list[dict[str, Any]]]:
    """The ``kind`` (``point_data`` / ``cell_data``) arrays of the entities merged over the
    layout (entity ``i`` owns elements ``offsets[i]:offsets[i + 1]``) and, per entity, the
    header records of its properties."""
    sizes: dict[str, set[tuple[int, ...]]] = {}
    for entity in kept:
        for name, prop in getattr(entity, kind).items():
            sizes.setdefault(name, set()).add(prop.values.shape[1:])
    pieces: dict[str, list[tuple[int, int, NDArray[Any]]]] = {}
    records: list[dict[str, Any]] = []
    for index, entity in enumerate(kept):
        record: dict[str, Any] = {}
        for name, prop in getattr(entity, kind).items():
            array_name = _array_name(name)
            if len(sizes[name]) > 1 or array_name in reserved:
                array_name = f"{array_name}#{entity.id}"
            start, stop = int(offsets[index]), int(offsets[index + 1])
            pieces.setdefault(array_name, []).append((start, stop, prop.values))
            record[name] = _property_record(prop, array_name)
        records.append(record)
    total = int(offsets[-1])
    merged = {name: _merge_arrays(parts, total, name) for name, parts in pieces.items()}
    return merged, records


def _entity_record(
    entity: Entity,
    points: tuple[int, int],
    point_records: dict[str, Any],
    cell_records: dict[str, Any],
) -> dict[str, Any]:
    """The header entry of one entity: what its cells and points alone do not say."""
    record: dict[str, Any] = {
        "id": entity.id,
        "type": entity.type,
        "name": entity.name,
        "kind": entity.kind,
        "metadata": entity.metadata,
        "points": list(points),
        "point_data": point_records,
        "cell_data": cell_records,
    }
    if isinstance(entity, Surface):
        record["patch_names"] = list(entity.patch_names)
        record["has_patches"] = entity.patch_labels is not None
    elif isinstance(entity, TetMesh):
        record["region_names"] = list(entity.region_names)
        record["has_regions"] = entity.region_labels is not None
    elif isinstance(entity, PolyLine):
        record["part_offsets"] = entity.part_offsets.tolist()
        record["closed"] = entity.closed.tolist()
    return record


def _has_parts(entity: Entity) -> bool:
    if isinstance(entity, Surface):
        return entity.patch_labels is not None
    if isinstance(entity, TetMesh):
        return entity.region_labels is not None
    if isinstance(entity, PolyLine):
        return len(entity.part_offsets) > 2
    return False


def _small_ints(values: NDArray[np.int64]) -> NDArray[np.integer[Any]]:
    """int32 when the values fit (half the bytes to write), else int64."""
    if values.size == 0 or (values.min() >= -(2**31) and values.max() < 2**31):
        return values.astype(np.int32)
    return values


def _group_json(group: Group, kept: set[int | None]) -> dict[str, Any]:
    return {
        "name": group.name,
        "kind": group.kind,
        "members": [m for m in group.members if m in kept],
        "children": [_group_json(c, kept) for c in group.children],
        "metadata": group.metadata,
    }


def _concat(arrays: list[NDArray[np.int64]]) -> NDArray[np.int64]:
    return np.concatenate(arrays) if arrays else np.zeros(0, dtype=np.int64)


def _concat_points(arrays: list[NDArray[np.float64]]) -> NDArray[np.float64]:
    return np.concatenate(arrays) if arrays else np.zeros((0, 3), dtype=np.float64)


# -- layout -> scene ---------------------------------------------------------------------------


# (their schemas are built when a header is first checked: a file without one needs none)
class _PropertyRecord(BaseModel):
    model_config = ConfigDict(extra="allow", defer_build=True)
    array: str
    dtype: str


class _EntityRecord(BaseModel):
    model_config = ConfigDict(extra="allow", defer_build=True)
    id: int
    type: Literal["PointSet", "PolyLine", "Surface", "TetMesh"]
    points: tuple[NonNegativeInt, NonNegativeInt]
    point_data: dict[str, _PropertyRecord] = {}
    cell_data: dict[str, _PropertyRecord] = {}
    part_offsets: list[NonNegativeInt] | None = None
    closed: list[bool] | None = None


class _HeaderRecord(BaseModel):
    model_config = ConfigDict(extra="allow", defer_build=True)
    entities: list[_EntityRecord] = []
    groups: list[dict[str, Any]] = []


def _record_problem(record: _EntityRecord, n_points: int) -> str | None:
    """What is wrong with one entity's header record, or None."""
    start, stop = record.points
    if not start <= stop <= n_points:
        return f"points {start}..{stop} are not within the file's {n_points} points"
    for kind in (record.point_data, record.cell_data):
        for name, prop in kind.items():
            try:
                dtype = np.dtype(prop.dtype)
            except (TypeError, ValueError):
                return f"property {name!r}: dtype {prop.dtype!r} is not a numpy type"
            if dtype.kind not in "biuf" or dtype.subdtype is not None:
                return f"property {name!r}: dtype {prop.dtype!r} is not a number type"
    if record.type == "PolyLine":
        offsets, closed = record.part_offsets, record.closed
        if offsets is None or closed is None:
            return "a PolyLine record needs part_offsets and closed"
        if offsets and (offsets[0] != 0 or offsets[-1] > stop - start):
            return f"part_offsets must run from 0 to at most its {stop - start} points"
        parts = max(len(offsets) - 1, 0)
        if any(b < a for a, b in itertools.pairwise(offsets)) or len(closed) != parts:
            return "part_offsets must not decrease and closed needs one flag per part"
    return None


def check_header(header: dict[str, Any], n_points: int, source: Any = None) -> None:
    """Refuse a geobrep header that does not fit the ``n_points`` points of its file.

    Every entity needs an id, a layout type and a range of points within the file, ranges of
    different entities do not overlap (so nothing a header says can make a reader allocate
    more than the file holds), property records name an array and a number dtype, polyline
    parts cover their points. ``source`` (a path) names the file in the :class:`FormatError`.
    """
    try:
        checked = _HeaderRecord.model_validate(header)
    except ValidationError as exc:
        first = exc.errors()[0]
        where = ".".join(str(p) for p in first["loc"])
        raise FormatError(f"geobrep header: {where}: {first['msg']}", source) from None
    previous_stop = 0
    for index, record in sorted(enumerate(checked.entities), key=lambda item: item[1].points):
        problem = _record_problem(record, n_points)
        if problem is None and record.points[0] < previous_stop:
            problem = f"points {record.points[0]}..{record.points[1]} overlap another entity's"
        if problem is not None:
            raise FormatError(
                f"geobrep header: entities.{index} (id {record.id}): {problem}", source
            )
        previous_stop = max(previous_stop, record.points[1])


def layout_to_scene(layout: CellLayout, source: Any = None) -> Scene:
    """Rebuild a scene; with a header exactly, without one from the cell types.

    ``source`` (a path) names the file in errors.
    """
    points = np.ascontiguousarray(layout.points, dtype=np.float64)
    if points.ndim != 2 or points.shape[1] not in (2, 3):
        raise FormatError(f"points must be (N, 3), got shape {points.shape}", source)
    if points.shape[1] == 2:
        points = np.column_stack([points, np.zeros(len(points))])
    header = layout.header
    if header is not None and header_applies(header, layout.cell_data):
        check_header(header, len(points), source)
        with located(source):
            try:
                return _scene_from_header(layout, points, header)
            except (KeyError, IndexError, TypeError, ValueError) as exc:
                if isinstance(exc, GeobrepError):
                    raise
                raise FormatError(f"inconsistent geobrep header: {exc}", source) from exc
    for kind, conn in layout.blocks:
        if conn.size and (conn.min() < 0 or conn.max() >= len(points)):
            raise FormatError(
                f"{kind} cells refer to point {int(conn.max())} but there are {len(points)} points",
                source,
            )
    with located(source):
        return _scene_from_cells(layout, points)


@contextmanager
def located(source: Any) -> Iterator[None]:
    """Make every geobrep error raised inside a :class:`FormatError` naming ``source``.

    An entity refusing what a file holds (NaN coordinates, an index past its vertices) says
    which entity and field; the file it came from is added here.
    """
    try:
        yield
    except FormatError as exc:
        if exc.path is not None or source is None:
            raise
        raise FormatError(exc.message, source, exc.line) from exc
    except GeobrepError as exc:
        raise FormatError(str(exc), source) from exc


def _cells_of(layout: CellLayout, entity_id: int) -> tuple[str | None, NDArray[np.int64], Any]:
    """Connectivity of one entity's cells and the index selecting them in the flat arrays.

    The index is ``slice(None)`` when the entity owns every cell (no copies then).
    """
    owners = layout.cell_data.get(ENTITY_ARRAY)
    mask: Any = slice(None)
    if owners is not None:
        selected_all = np.asarray(owners).ravel() == entity_id
        if not selected_all.all():
            mask = selected_all
    kind: str | None = None
    pieces: list[NDArray[np.int64]] = []
    for (block_kind, conn), cells in zip(layout.blocks, layout.block_slices(), strict=True):
        if isinstance(mask, slice):
            chosen: Any = slice(None) if len(conn) else None
        else:
            chosen = mask[cells] if mask[cells].any() else None
        if chosen is None:
            continue
        if kind is not None and block_kind != kind:
            raise ValueError(f"entity {entity_id} mixes {kind} and {block_kind} cells")
        kind = block_kind
        pieces.append(np.asarray(conn, dtype=np.int64)[chosen])
    width = _CELL_WIDTH.get(kind or "vertex", 1)
    if len(pieces) == 1:
        return kind, pieces[0], mask
    conn_all = np.concatenate(pieces) if pieces else np.zeros((0, width), np.int64)
    return kind, conn_all, mask


def _labels(values: Any, name: str = PART_ARRAY) -> NDArray[np.int64]:
    """A label array of the file (patch, region, part or entity per cell) as int64 indices."""
    return cast_exactly(np.asarray(values).ravel(), np.int64, f"cell array {name!r}")


def _properties(
    records: dict[str, Any], arrays: dict[str, NDArray[Any]], index: Any
) -> PropertyMap:
    props: dict[str, Property] = {}
    for name, record in records.items():
        values = cast_exactly(
            np.asarray(arrays[record["array"]])[index], record["dtype"], f"property {name!r}"
        )
        props[name] = Property(
            values=values,
            unit=record.get("unit"),
            no_data_value=record.get("no_data_value"),
            description=record.get("description", ""),
            metadata=record.get("metadata", {}),
        )
    return PropertyMap(props)


def _scene_from_header(
    layout: CellLayout, points: NDArray[np.float64], header: dict[str, Any]
) -> Scene:
    entities: list[Entity] = []
    parts_all = layout.cell_data.get(PART_ARRAY)
    for record in header["entities"]:
        start, stop = record["points"]
        vertices = points[start:stop]
        _kind, conn, mask = _cells_of(layout, int(record["id"]))
        if conn.size == 0:  # an entity without cells: the width its type has
            conn = conn.reshape(0, _EMPTY_WIDTH.get(record["type"], 1))
        if start:
            conn = conn - start  # the entity's own checks catch indices outside its points
        has_parts = record.get("has_patches") or record.get("has_regions")
        parts = (
            None
            if not has_parts
            else _labels(parts_all)[mask]
            if parts_all is not None
            else np.zeros(len(conn), np.int64)
        )
        common: dict[str, Any] = {
            "id": record["id"],
            "name": record.get("name", ""),
            "kind": record.get("kind"),
            "metadata": record.get("metadata", {}),
            "point_data": _properties(record["point_data"], layout.point_data, slice(start, stop)),
            "cell_data": _properties(record["cell_data"], layout.cell_data, mask),
        }
        entity_type = record["type"]
        entity: Entity
        if entity_type == "Surface":
            entity = Surface(
                vertices=vertices,
                faces=conn,
                patch_labels=parts if record.get("has_patches") else None,
                patch_names=tuple(record.get("patch_names", ())),
                **common,
            )
        elif entity_type == "TetMesh":
            entity = TetMesh(
                vertices=vertices,
                cells=conn,
                region_labels=parts if record.get("has_regions") else None,
                region_names=tuple(record.get("region_names", ())),
                **common,
            )
        elif entity_type == "PolyLine":
            entity = PolyLine(
                vertices=vertices,
                indices=_polyline_indices(conn, record["part_offsets"], record["closed"]),
                part_offsets=np.asarray(record["part_offsets"], dtype=np.int64),
                closed=np.asarray(record["closed"], dtype=bool),
                **common,
            )
        elif entity_type == "PointSet":
            entity = PointSet(vertices=vertices, **common)
        else:
            raise ValueError(f"entity type {entity_type!r} cannot come from a cell layout")
        entities.append(entity)
    kept = {e.id for e in entities}
    groups = [_group_from_json(g, kept) for g in header.get("groups", [])]
    crs = header.get("crs")
    return Scene.from_validated(  # the entities and groups are validated models already
        entities=entities,
        groups=groups,
        crs=None if crs is None else CRS.model_validate(crs),
        name=header.get("name", ""),
        metadata=header.get("metadata", {}),
    )


def _group_from_json(data: dict[str, Any], kept: set[int | None]) -> Group:
    return Group(
        name=data["name"],
        kind=data.get("kind"),
        members=tuple(m for m in data.get("members", ()) if m in kept),
        children=tuple(_group_from_json(c, kept) for c in data.get("children", ())),
        metadata=data.get("metadata", {}),
    )


def _polyline_indices(
    segments: NDArray[np.int64], part_offsets: list[int], closed: list[bool]
) -> NDArray[np.int64]:
    """Vertex order of each part from its segments (in part order)."""
    offsets = np.asarray(part_offsets, dtype=np.int64)
    is_closed = np.asarray(closed, dtype=bool)
    lengths = np.diff(offsets)
    counts = np.maximum(lengths - 1 + is_closed, 0)
    if int(counts.sum()) != len(segments):
        raise ValueError(f"polyline has {len(segments)} segments, its parts need {counts.sum()}")
    indices = np.zeros(int(offsets[-1]) if len(offsets) else 0, dtype=np.int64)
    seg_start = np.concatenate([[0], np.cumsum(counts)[:-1]]) if len(counts) else counts
    part_of_segment = np.repeat(np.arange(len(counts)), counts)
    rank = np.arange(len(segments)) - seg_start[part_of_segment]
    indices[offsets[part_of_segment] + rank] = segments[:, 0]
    open_parts = np.flatnonzero(~is_closed & (counts > 0))
    last = seg_start[open_parts] + counts[open_parts] - 1
    indices[offsets[open_parts + 1] - 1] = segments[last, 1]
    single = np.flatnonzero(lengths == 1)
    if single.size:
        raise ValueError("a polyline part of one vertex has no segment to recover it from")
    return indices


def _scene_from_cells(layout: CellLayout, points: NDArray[np.float64]) -> Scene:
    """Entities from a file without header: one per cell type (and per entity id if present).

    Each entity keeps only the points its cells use.
    """
    n_cells = layout.n_cells
    kinds = np.empty(n_cells, dtype=object)
    for (kind, _), cells in zip(layout.blocks, layout.block_slices(), strict=True):
        kinds[cells] = kind
    owner_array = layout.cell_data.get(ENTITY_ARRAY)
    owners = (
        np.zeros(n_cells, np.int64)
        if owner_array is None or len(owner_array) != n_cells
        else _labels(owner_array, ENTITY_ARRAY)
    )
    part_array = layout.cell_data.get(PART_ARRAY)
    entities: list[Entity] = []
    for kind in ("triangle", "quad", "tetra", "line", "vertex"):
        of_kind = kinds == kind
        if not of_kind.any():
            continue
        conn_all = np.concatenate(
            [np.asarray(c, dtype=np.int64) for k, c in layout.blocks if k == kind]
        )
        kind_owners = owners[of_kind]
        # np.unique asked for indices sorts; without, numpy 2 imports numpy.ma (~5 ms) first
        for owner in np.unique(kind_owners, return_index=True)[0]:
            mask = np.zeros(n_cells, dtype=bool)
            mask[np.flatnonzero(of_kind)[kind_owners == owner]] = True
            conn = conn_all[kind_owners == owner]
            entities.append(
                _foreign_entity(layout, points, kind, conn, mask, part_array, owner_array, owner)
            )
    if not entities and len(points):
        entities.append(
            PointSet(
                vertices=points,
                name="points",
                point_data=PropertyMap(
                    {n: v for n, v in layout.point_data.items() if len(v) == len(points)}
                ),
            )
        )
    return Scene.from_validated(entities=entities)  # validated models already


def _foreign_entity(
    layout: CellLayout,
    points: NDArray[np.float64],
    kind: str,
    conn: NDArray[np.int64],
    mask: NDArray[np.bool_],
    part_array: NDArray[Any] | None,
    owner_array: NDArray[Any] | None,
    owner: Any,
) -> Entity:
    used, inverse = np.unique(conn, return_inverse=True)
    if kind == "vertex":
        used = conn[:, 0]
        inverse = np.arange(len(used))
    local = inverse.reshape(conn.shape).astype(np.int64)
    point_data = PropertyMap(
        {
            name: np.asarray(values)[used]
            for name, values in layout.point_data.items()
            if len(values) == len(points)
        }
    )
    n_cells = layout.n_cells
    cell_data = PropertyMap(
        {
            name: np.asarray(values)[mask]
            for name, values in layout.cell_data.items()
            if len(values) == n_cells and name not in (ENTITY_ARRAY, PART_ARRAY)
        }
    )
    common: dict[str, Any] = {"name": kind, "point_data": point_data}
    if owner_array is not None:
        common["id"] = int(owner)
        common["name"] = f"{kind} {int(owner)}"
    vertices = points[used]
    if kind in ("triangle", "quad"):
        labels = None
        if part_array is not None and len(part_array) == n_cells:
            labels = _labels(part_array)[mask]
        return Surface(
            vertices=vertices, faces=local, patch_labels=labels, cell_data=cell_data, **common
        )
    if kind == "tetra":
        return TetMesh(vertices=vertices, cells=local, cell_data=cell_data, **common)
    if kind == "line":
        return chain_segments(vertices, local, cell_data, common)
    return PointSet(vertices=vertices, **common)


def chain_segments(
    vertices: NDArray[np.float64],
    segments: NDArray[np.int64],
    cell_data: PropertyMap,
    common: dict[str, Any],
) -> PolyLine:
    """A polyline whose parts are runs of segments that continue one another."""
    starts = np.ones(len(segments), dtype=bool)
    starts[1:] = segments[1:, 0] != segments[:-1, 1]
    seg_part = np.cumsum(starts) - 1
    n_parts = int(seg_part[-1]) + 1 if len(segments) else 0
    seg_counts = np.bincount(seg_part, minlength=n_parts)
    first_seg = np.flatnonzero(starts)
    last_seg = np.concatenate([first_seg[1:], [len(segments)]]) - 1
    closed = segments[last_seg, 1] == segments[first_seg, 0]
    closed &= seg_counts > 1
    lengths = seg_counts + (~closed).astype(np.int64)
    offsets = np.concatenate([[0], np.cumsum(lengths)]).astype(np.int64)
    indices = np.empty(int(offsets[-1]), dtype=np.int64)
    rank = np.arange(len(segments)) - first_seg[seg_part]
    indices[offsets[seg_part] + rank] = segments[:, 0]
    open_parts = np.flatnonzero(~closed)
    indices[offsets[open_parts + 1] - 1] = segments[last_seg[open_parts], 1]
    return PolyLine(
        vertices=vertices,
        indices=indices,
        part_offsets=offsets,
        closed=closed,
        cell_data=cell_data,
        **common,
    )
