"""Entities as GIS feature tables (shapely geometries + attribute columns), and back.

Shared by the GIS formats (``geobrep.adapters.gis``) and the geopandas bridge
(:mod:`geobrep.gis.crs_ops`). ``shapely`` (the ``gis`` extra) is imported when a function runs.

Writing: a :class:`~geobrep.PointSet` gives one Point Z feature per point (point data
as columns), a :class:`~geobrep.PolyLine` one LineString Z per part (cell data constant
along a part as columns), a :class:`~geobrep.Polygon` one Polygon Z per polygon (cell
data as columns), an :class:`~geobrep.Annotation` a Point Z with its text, height, font
and directions. Every feature carries ``entity_id``, ``entity`` (name), ``entity_type``, ``kind``
and, where known, ``block_id``, ``unit_name`` and ``horizon_name``. The layer is
``metadata["layer"]``, else ``points``, ``lines``, ``polygons`` or ``annotations``.

Reading: features are grouped by ``entity_id`` when the column exists (one entity per group),
otherwise one entity per layer and geometry family. Numeric columns become properties, text
columns ``metadata["attributes"]``. Broken features (no geometry, unreadable, non-finite,
degenerate, missing z) are skipped with a :class:`FeatureWarning` naming layer and feature.

>>> import numpy as np
>>> from geobrep import PointSet
>>> tables = entities_to_tables([PointSet(vertices=np.eye(3), point_data={"a": [1, 2, 3]}, id=4)])
>>> table = tables["points"]
>>> len(table), table.columns["a"].tolist(), table.columns["entity_id"].tolist()
(3, [1, 2, 3], [4, 4, 4])
>>> again = tables_to_entities(list(tables.values()), ReadOptions(), source="memory")
>>> again[0].id, again[0].point_data["a"].values.tolist()
(4, [1, 2, 3])
"""

from __future__ import annotations

import warnings
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict

from geobrep.errors import import_optional
from geobrep.model.entities import Annotation, Entity, PointSet, Polygon, PolyLine

__all__ = [
    "RESERVED_COLUMNS",
    "FeatureTable",
    "FeatureWarning",
    "ReadOptions",
    "entities_to_tables",
    "merge_columns",
    "tables_to_entities",
]

Family = Literal["point", "line", "polygon"]

#: Columns the writers fill from entity fields; readers turn them back into those fields.
RESERVED_COLUMNS = (
    "entity_id",
    "entity",
    "entity_type",
    "kind",
    "block_id",
    "unit_name",
    "horizon_name",
    "part",
)
_ANNOTATION_COLUMNS = (
    "text",
    "height",
    "font",
    "baseline_x",
    "baseline_y",
    "baseline_z",
    "up_x",
    "up_y",
    "up_z",
)
_DEFAULT_LAYER = {"point": "points", "line": "lines", "polygon": "polygons"}
_MAX_NAMED = 8


class FeatureWarning(UserWarning):
    """Some features of a layer could not be used (or some data could not be written)."""


class ReadOptions(BaseModel):
    """How 2D features get their z: a column (``z_field``) or a constant (``z_default``)."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    z_field: str | None = None
    z_default: float | None = None


@dataclass
class FeatureTable:
    """One layer: geometries (shapely objects, WKB bytes or None) and attribute columns.

    Columns are numpy arrays (numeric, bool, or object holding ``str``/``None``); a numpy masked
    array marks null values. ``fids`` are the feature ids of the source (for messages).
    """

    layer: str
    geometry: NDArray[Any]
    columns: dict[str, NDArray[Any]] = field(default_factory=dict)
    fids: NDArray[np.int64] | None = None

    def __len__(self) -> int:
        return int(self.geometry.shape[0])


def _shapely() -> Any:
    return import_optional("shapely", "gis", "GIS features")


# -- writing ------------------------------------------------------------------------------------
def _entity_columns(entity: Entity, rows: int) -> dict[str, NDArray[Any]]:
    meta = entity.metadata
    block = meta.get("block")
    unit = meta.get("unit_name", meta.get("unit"))
    horizon = meta.get("horizon")
    if horizon is None and entity.kind == "horizon":
        horizon = entity.name
    columns: dict[str, NDArray[Any]] = {
        "entity_id": np.ma.masked_array(
            np.full(rows, entity.id if entity.id is not None else 0, dtype=np.int64),
            mask=np.full(rows, entity.id is None),
        ),
        "entity": np.full(rows, entity.name, dtype=object),
        "entity_type": np.full(rows, type(entity).__name__, dtype=object),
        "kind": np.full(rows, entity.kind, dtype=object),
    }
    if isinstance(block, int) and not isinstance(block, bool):
        columns["block_id"] = np.full(rows, block, dtype=np.int64)
    if isinstance(unit, str):
        columns["unit_name"] = np.full(rows, unit, dtype=object)
    if isinstance(horizon, str):
        columns["horizon_name"] = np.full(rows, horizon, dtype=object)
    attributes = meta.get("attributes")
    if isinstance(attributes, dict):
        for name, value in attributes.items():
            if name in columns or name in RESERVED_COLUMNS:
                continue
            if isinstance(value, list) and len(value) == rows:
                columns[name] = np.asarray(
                    [None if v is None else str(v) for v in value], dtype=object
                )
            elif isinstance(value, str):
                columns[name] = np.full(rows, value, dtype=object)
    return columns


def _property_columns(props: Any, rows: NDArray[np.int64] | None) -> dict[str, NDArray[Any]]:
    columns: dict[str, NDArray[Any]] = {}
    for name, prop in props.items():
        values = np.asarray(prop.values)
        if values.dtype.kind == "u":
            values = values.astype(np.int64)
        if rows is not None:
            values = values[rows]
        if values.ndim == 1:
            columns[name] = values
        else:
            for k in range(values.shape[1]):
                columns[f"{name}_{k}"] = values[:, k]
    return columns


def _warn(message: str) -> None:
    warnings.warn(message, FeatureWarning, stacklevel=3)


def _closed_coordinates(
    vertices: NDArray[np.float64], offsets: NDArray[np.int64], order: NDArray[np.int64]
) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """Coordinates of rings/parts ``order[offsets[i]:offsets[i+1]]`` with their first vertex
    repeated at the end; returns the coordinates and the new offsets."""
    lengths = np.diff(offsets)
    starts = offsets[:-1]
    position = np.arange(order.shape[0] + lengths.shape[0])
    new_offsets = np.concatenate([[0], np.cumsum(lengths + 1)]).astype(np.int64)
    ring = np.repeat(np.arange(lengths.shape[0]), lengths + 1)
    local = position - new_offsets[:-1][ring]
    source = np.where(local == lengths[ring], starts[ring], starts[ring] + local)
    return vertices[order[source]], new_offsets


def _pointset_features(entity: PointSet) -> tuple[NDArray[Any], dict[str, NDArray[Any]]]:
    shapely = _shapely()
    geometry = shapely.points(np.asarray(entity.vertices))
    return geometry, _property_columns(entity.point_data, None)


def _polyline_features(entity: PolyLine) -> tuple[NDArray[Any], dict[str, NDArray[Any]]]:
    shapely = _shapely()
    lengths = entity.part_lengths
    closed = np.asarray(entity.closed, dtype=bool)
    # closed parts repeat their first vertex; open parts do not
    coords_closed, offsets_closed = _closed_coordinates(
        np.asarray(entity.vertices),
        np.asarray(entity.part_offsets, dtype=np.int64),
        np.asarray(entity.indices, dtype=np.int64),
    )
    keep = np.ones(coords_closed.shape[0], dtype=bool)
    keep[offsets_closed[1:][~closed] - 1] = False
    part_of = np.repeat(np.arange(entity.n_parts), lengths + 1)[keep]
    geometry = shapely.linestrings(coords_closed[keep], indices=part_of)
    columns: dict[str, NDArray[Any]] = {"part": np.arange(entity.n_parts, dtype=np.int64)}
    segments = lengths - 1 + closed
    first_segment = np.concatenate([[0], np.cumsum(segments)[:-1]]).astype(np.int64)
    dropped: list[str] = []
    for name, values in _property_columns(entity.cell_data, None).items():
        if values.shape[0] == 0:
            continue
        high = np.maximum.reduceat(values, first_segment)
        low = np.minimum.reduceat(values, first_segment)
        if np.array_equal(high, low, equal_nan=values.dtype.kind == "f"):
            columns[name] = values[first_segment]
        else:
            dropped.append(name)
    dropped += [f"point_data {name!r}" for name in entity.point_data]
    if dropped:
        _warn(
            f"{entity.label}: GIS line features hold one value per part: "
            f"not written: {', '.join(dropped)}"
        )
    return geometry, columns


def _polygon_features(entity: Polygon) -> tuple[NDArray[Any], dict[str, NDArray[Any]]]:
    shapely = _shapely()
    order = np.arange(entity.vertices.shape[0], dtype=np.int64)
    coords, ring_offsets = _closed_coordinates(
        np.asarray(entity.vertices), np.asarray(entity.ring_offsets, dtype=np.int64), order
    )
    geometry = shapely.from_ragged_array(
        shapely.GeometryType.POLYGON, coords, (ring_offsets, entity.polygon_offsets)
    )
    if entity.point_data:
        names = ", ".join(repr(n) for n in entity.point_data)
        _warn(f"{entity.label}: GIS polygons hold one value per polygon: not written: {names}")
    return geometry, _property_columns(entity.cell_data, None)


def _annotation_features(entity: Annotation) -> tuple[NDArray[Any], dict[str, NDArray[Any]]]:
    shapely = _shapely()
    geometry = shapely.points(np.asarray(entity.anchor).reshape(1, 3))
    columns: dict[str, NDArray[Any]] = {
        "text": np.array([entity.text], dtype=object),
        "height": np.array([entity.height]),
        "font": np.array([entity.font], dtype=object),
    }
    for axis, value in zip("xyz", entity.baseline.tolist(), strict=True):
        columns[f"baseline_{axis}"] = np.array([value])
    for axis, value in zip("xyz", entity.up.tolist(), strict=True):
        columns[f"up_{axis}"] = np.array([value])
    return geometry, columns


def merge_columns(pieces: Sequence[tuple[int, dict[str, NDArray[Any]]]]) -> dict[str, Any]:
    """Concatenate per-entity columns; a column missing from an entity is null there."""
    names: dict[str, None] = {}
    for _, columns in pieces:
        names.update(dict.fromkeys(columns))
    merged: dict[str, Any] = {}
    for name in names:
        present = [columns[name] for _, columns in pieces if name in columns]
        kinds = {np.asarray(p).dtype.kind for p in present}
        if "O" in kinds or "U" in kinds:
            dtype: Any = object
        elif kinds <= {"b"}:
            dtype = bool
        elif kinds <= {"i", "b"}:
            dtype = np.int64
        else:
            dtype = np.float64
        values, masks = [], []
        for rows, columns in pieces:
            if name in columns:
                column = columns[name]
                values.append(np.asarray(np.ma.getdata(column)).astype(dtype))
                masks.append(np.ma.getmaskarray(column))
            else:
                fill = None if dtype is object else 0
                values.append(np.full(rows, fill, dtype=dtype))
                masks.append(np.ones(rows, dtype=bool))
        data, mask = np.concatenate(values), np.concatenate(masks)
        if dtype is object:
            data[mask] = None
            merged[name] = data
        else:
            merged[name] = np.ma.masked_array(data, mask=mask) if mask.any() else data
    return merged


def entities_to_tables(entities: Iterable[Entity]) -> dict[str, FeatureTable]:
    """Feature tables by layer name for the entities GIS layers can hold.

    Entities that no GIS geometry fits (surfaces, blocks, meshes, octrees) are left out with a
    :class:`FeatureWarning` that names them.
    """
    shapely = _shapely()
    grouped: dict[tuple[str, Family], list[tuple[NDArray[Any], dict[str, NDArray[Any]]]]] = {}
    skipped: list[str] = []
    for entity in entities:
        family: Family
        if isinstance(entity, Annotation):
            geometry, columns = _annotation_features(entity)
            family, default = "point", "annotations"
        elif isinstance(entity, PointSet):
            geometry, columns = _pointset_features(entity)
            family, default = "point", "points"
        elif isinstance(entity, PolyLine):
            geometry, columns = _polyline_features(entity)
            family, default = "line", "lines"
        elif isinstance(entity, Polygon):
            geometry, columns = _polygon_features(entity)
            family, default = "polygon", "polygons"
        else:
            skipped.append(entity.label)
            continue
        layer = entity.metadata.get("layer")
        name = layer if isinstance(layer, str) and layer else default
        rows = int(geometry.shape[0])
        if rows == 0:
            continue
        columns = {**_entity_columns(entity, rows), **columns}
        grouped.setdefault((name, family), []).append((geometry, columns))
    if skipped:
        _warn(
            "GIS layers hold points, lines, polygons and annotations only; left out: "
            + ", ".join(skipped[:_MAX_NAMED])
            + (f" and {len(skipped) - _MAX_NAMED} more" if len(skipped) > _MAX_NAMED else "")
            + " (map products turn surfaces and blocks into polygons and lines)"
        )
    families_of: dict[str, set[Family]] = {}
    for name, family in grouped:
        families_of.setdefault(name, set()).add(family)
    tables: dict[str, FeatureTable] = {}
    for (name, family), pieces in grouped.items():
        layer = name if len(families_of[name]) == 1 else f"{name}_{_DEFAULT_LAYER[family]}"
        geometry = np.concatenate([g for g, _ in pieces]).astype(object)
        columns = merge_columns([(int(g.shape[0]), c) for g, c in pieces])
        tables[layer] = FeatureTable(layer=layer, geometry=geometry, columns=columns)
    del shapely
    return tables


# -- reading ------------------------------------------------------------------------------------
class _Problems:
    """Collect skipped features per reason; one warning per reason naming the features."""

    def __init__(self, source: str, table: FeatureTable) -> None:
        self.source, self.table = source, table
        self.by_reason: dict[str, list[int]] = {}

    def add(self, reason: str, features: NDArray[np.int64]) -> None:
        if features.size:
            self.by_reason.setdefault(reason, []).extend(int(f) for f in features)

    def name(self, feature: int) -> str:
        fids = self.table.fids
        label = f"feature {int(fids[feature]) if fids is not None else feature}"
        entity = self.table.columns.get("entity")
        if entity is None:
            entity = self.table.columns.get("name")
        if entity is not None and np.asarray(entity).dtype == object and entity[feature]:
            label += f" ({entity[feature]!r})"
        return label

    def emit(self) -> None:
        for reason, features in self.by_reason.items():
            unique = sorted(set(features))
            named = ", ".join(self.name(f) for f in unique[:_MAX_NAMED])
            more = f" and {len(unique) - _MAX_NAMED} more" if len(unique) > _MAX_NAMED else ""
            _warn(
                f"{self.source}: layer {self.table.layer!r}: {named}{more}: {reason}; "
                f"skipped ({len(unique)} of {len(self.table)} features)"
            )


def _as_geometries(table: FeatureTable, problems: _Problems) -> NDArray[Any]:
    shapely = _shapely()
    raw = np.asarray(table.geometry, dtype=object)
    is_bytes = np.array([isinstance(g, bytes | bytearray) for g in raw], dtype=bool)
    geoms = raw.copy()
    if is_bytes.any():
        geoms[is_bytes] = shapely.from_wkb(raw[is_bytes], on_invalid="ignore")
        broken = np.flatnonzero(is_bytes & np.array([g is None for g in geoms]))
        problems.add("broken geometry (cannot be decoded, too few points?)", broken)
    missing = np.array([g is None for g in raw], dtype=bool)
    problems.add("no geometry (null, or unreadable by GDAL)", np.flatnonzero(missing))
    return geoms


def _column_z(table: FeatureTable, options: ReadOptions) -> NDArray[np.float64] | None:
    if options.z_field is None:
        return None
    column = table.columns.get(options.z_field)
    if column is None:
        raise_missing = ", ".join(sorted(table.columns)) or "none"
        from geobrep.errors import OptionsError

        raise OptionsError(
            f"layer {table.layer!r}: z_field {options.z_field!r} is not a column "
            f"(columns: {raise_missing})"
        )
    data = np.ma.filled(np.ma.masked_array(column).astype(np.float64), np.nan)
    return np.asarray(data, dtype=np.float64)


@dataclass
class _Parts:
    """Exploded single geometries of one family with their feature and coordinates."""

    feature: NDArray[np.int64]  # feature of each part (or ring's polygon)
    coords: NDArray[np.float64]  # (M, 3)
    offsets: NDArray[np.int64]  # part p: coords[offsets[p]:offsets[p+1]]
    polygon_rings: NDArray[np.int64] | None = None  # polygons: offsets of rings per polygon


def _group_keys(table: FeatureTable, features: NDArray[np.int64]) -> NDArray[np.int64]:
    ids = table.columns.get("entity_id")
    if ids is None:
        return np.full(features.shape[0], -1, dtype=np.int64)
    values = np.ma.filled(np.ma.masked_array(ids).astype(np.float64), np.nan)[features]
    return np.where(np.isfinite(values), values, -1).astype(np.int64)


def _constant(column: NDArray[Any] | None, rows: NDArray[np.int64]) -> Any:
    if column is None or rows.size == 0:
        return None
    values = column[rows]
    if np.ma.isMaskedArray(values):
        if np.ma.getmaskarray(values).any():
            return None
        values = np.asarray(values.data)
    if values.dtype == object:
        first = values[0]
        return first if all(v == first for v in values.tolist()) else None
    if values.dtype.kind == "f" and not np.isfinite(values).all():
        return None
    return values[0].item() if bool(np.all(values == values[0])) else None


def _entity_fields(
    table: FeatureTable, rows: NDArray[np.int64], skip: Sequence[str]
) -> tuple[dict[str, Any], dict[str, NDArray[Any]]]:
    """Entity fields (name, kind, id, metadata) and numeric per-row columns of a group."""
    columns = table.columns
    metadata: dict[str, Any] = {"layer": table.layer}
    block = _constant(columns.get("block_id"), rows)
    if block is not None:
        metadata["block"] = int(block)
    for column_name, key in (("unit_name", "unit_name"), ("horizon_name", "horizon")):
        value = _constant(columns.get(column_name), rows)
        if isinstance(value, str):
            metadata[key] = value
    attributes: dict[str, Any] = {}
    numeric: dict[str, NDArray[Any]] = {}
    for name, column in columns.items():
        if name in RESERVED_COLUMNS or name in skip:
            continue
        values = column[rows]
        if np.asarray(values).dtype == object:
            constant = _constant(column, rows)
            attributes[name] = (
                constant
                if isinstance(constant, str)
                else [None if v is None else str(v) for v in np.asarray(values).tolist()]
            )
        elif np.ma.isMaskedArray(values):
            numeric[name] = np.ma.filled(values.astype(np.float64), np.nan)
        else:
            numeric[name] = np.asarray(values)
    if attributes:
        metadata["attributes"] = attributes
    fields: dict[str, Any] = {"metadata": metadata}
    name = _constant(columns.get("entity"), rows)
    fields["name"] = name if isinstance(name, str) else table.layer
    kind = _constant(columns.get("kind"), rows)
    if isinstance(kind, str):
        fields["kind"] = kind
    if metadata.get("horizon") == fields["name"] and fields.get("kind") == "horizon":
        del metadata["horizon"]  # the writer took it from the name of a horizon
    ident = _constant(columns.get("entity_id"), rows)
    if ident is not None and float(ident) >= 0 and float(ident).is_integer():
        fields["id"] = int(ident)
    return fields, numeric


def tables_to_entities(
    tables: Sequence[FeatureTable], options: ReadOptions, *, source: str
) -> list[Entity]:
    """Entities from feature tables; broken features are skipped with a warning.

    Entity ids come back from ``entity_id`` when they are unique across all tables.
    """
    entities: list[Entity] = []
    for table in tables:
        entities.extend(_table_entities(table, options, source))
    ids = [e.id for e in entities if e.id is not None]
    if len(ids) != len(set(ids)):
        entities = [e.model_copy(update={"id": None}) for e in entities]
    return entities


def _table_entities(table: FeatureTable, options: ReadOptions, source: str) -> list[Entity]:
    shapely = _shapely()
    problems = _Problems(source, table)
    geoms = _as_geometries(table, problems)
    n = len(table)
    present = np.array([g is not None for g in geoms], dtype=bool)
    empty = np.zeros(n, dtype=bool)
    empty[present] = shapely.is_empty(geoms[present].astype(object))
    problems.add("empty geometry", np.flatnonzero(empty))
    usable = present & ~empty
    # -- coordinates, finiteness and z --------------------------------------------------------
    candidates = np.flatnonzero(usable)
    coords, coord_feature = shapely.get_coordinates(
        geoms[candidates].astype(object), include_z=True, return_index=True
    )
    coord_feature = candidates[coord_feature]
    xy_bad = ~np.isfinite(coords[:, :2]).all(axis=1)
    bad_xy = np.zeros(n, dtype=bool)
    bad_xy[coord_feature[xy_bad]] = True
    problems.add("non-finite x or y coordinates", np.flatnonzero(bad_xy & usable))
    usable &= ~bad_xy
    has_z = np.zeros(n, dtype=bool)
    has_z[usable] = shapely.has_z(geoms[usable].astype(object))
    z_missing_coord = ~np.isfinite(coords[:, 2])
    z_nan = np.zeros(n, dtype=bool)
    z_nan[coord_feature[z_missing_coord & has_z[coord_feature]]] = True
    feature_z = np.full(n, np.nan)
    column_z = _column_z(table, options)
    flat = usable & ~has_z
    if column_z is not None:
        feature_z[flat] = column_z[flat]
        problems.add(
            f"no z and no value in column {options.z_field!r}",
            np.flatnonzero(flat & ~np.isfinite(feature_z)),
        )
        usable &= ~(flat & ~np.isfinite(feature_z))
    elif options.z_default is not None:
        feature_z[flat] = options.z_default
    elif flat.any() and not has_z[usable].any():
        _warn(
            f"{source}: layer {table.layer!r} has no z values: z = 0 "
            "(give z_field= or z_default= to choose)"
        )
        feature_z[flat] = 0.0
    else:
        problems.add("missing z (the other features have z)", np.flatnonzero(flat))
        usable &= ~flat
    problems.add("missing z values (NaN)", np.flatnonzero(z_nan & usable))
    usable &= ~z_nan
    # -- explode into single parts --------------------------------------------------------------
    keep = np.flatnonzero(usable)
    parts, part_feature = shapely.get_parts(geoms[keep].astype(object), return_index=True)
    part_feature = keep[part_feature].astype(np.int64)
    part_type = shapely.get_type_id(parts) if parts.size else np.zeros(0, np.int64)
    other = ~np.isin(part_type, (0, 1, 2, 3))
    problems.add("unsupported geometry type", np.unique(part_feature[other]))
    entities: list[Entity] = []
    is_annotation = np.zeros(n, dtype=bool)
    kinds = table.columns.get("entity_type")
    if kinds is not None and np.asarray(kinds).dtype == object:
        is_annotation = np.asarray([k == "Annotation" for k in kinds.tolist()], dtype=bool)
    for family, type_ids in (("point", (0,)), ("line", (1, 2)), ("polygon", (3,))):
        chosen = np.isin(part_type, type_ids) & ~other
        if not chosen.any():
            continue
        family_parts, features = parts[chosen], part_feature[chosen]
        if family == "point":
            entities += _points(table, family_parts, features, feature_z, is_annotation)
        elif family == "line":
            entities += _lines(table, family_parts, features, feature_z, problems)
        else:
            entities += _polygons(table, family_parts, features, feature_z, problems)
    problems.emit()
    return entities


def _coordinates(
    geoms: NDArray[Any], owner: NDArray[np.int64], feature_z: NDArray[np.float64]
) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """Coordinates (z filled for 2D features) and the index of the geometry of each."""
    shapely = _shapely()
    coords, index = shapely.get_coordinates(geoms, include_z=True, return_index=True)
    fill = feature_z[owner[index]]
    coords[:, 2] = np.where(np.isfinite(fill), fill, coords[:, 2])
    return np.asarray(coords, dtype=np.float64), index.astype(np.int64)


def _points(
    table: FeatureTable,
    parts: NDArray[Any],
    features: NDArray[np.int64],
    feature_z: NDArray[np.float64],
    is_annotation: NDArray[np.bool_],
) -> list[Entity]:
    coords, _ = _coordinates(parts, features, feature_z)
    entities: list[Entity] = []
    notes = is_annotation[features]
    for position in np.flatnonzero(notes):
        entities.append(_annotation(table, int(features[position]), coords[position]))
    plain = ~notes
    keys = _group_keys(table, features)
    for key in dict.fromkeys(keys[plain].tolist()):
        select = plain & (keys == key)
        rows = features[select]
        fields, numeric = _entity_fields(table, rows, ())
        entities.append(PointSet(vertices=coords[select], point_data=numeric, **fields))
    return entities


def _annotation(table: FeatureTable, row: int, anchor: NDArray[np.float64]) -> Annotation:
    rows = np.array([row], dtype=np.int64)
    fields, _numeric = _entity_fields(table, rows, _ANNOTATION_COLUMNS)
    columns = table.columns

    def number(name: str, default: float) -> float:
        column = columns.get(name)
        value = _constant(column, rows)
        return float(value) if isinstance(value, int | float) else default

    text = _constant(columns.get("text"), rows)
    font = _constant(columns.get("font"), rows)
    fields["metadata"].pop("attributes", None)
    return Annotation(
        text=text if isinstance(text, str) else "",
        anchor=anchor,
        baseline=[number("baseline_x", 1.0), number("baseline_y", 0.0), number("baseline_z", 0.0)],
        up=[number("up_x", 0.0), number("up_y", 0.0), number("up_z", 1.0)],
        height=number("height", 1.0),
        font=font if isinstance(font, str) else "sans-serif",
        **{k: v for k, v in fields.items() if k != "kind"},
        kind=fields.get("kind", "annotation"),
    )


def _closing_points(
    coords: NDArray[np.float64], index: NDArray[np.int64], n_runs: int, min_points: int
) -> tuple[NDArray[np.bool_], NDArray[np.bool_], NDArray[np.int64]]:
    """Runs of ``coords`` (``index``: the run of each, in order) that close on themselves.

    Returns per run whether it closes (at least ``min_points`` points, the last equal to the
    first), per coordinate whether it is such a closing repeat (to drop), and per run the number
    of points without it.
    """
    counts = np.bincount(index, minlength=n_runs)
    starts = np.concatenate([[0], np.cumsum(counts)[:-1]]).astype(np.int64)
    ends = starts + counts - 1
    closed = (counts >= min_points) & np.all(coords[starts] == coords[np.maximum(ends, 0)], axis=1)
    drop = np.zeros(coords.shape[0], dtype=bool)
    drop[ends[closed]] = True
    return closed, drop, (counts - closed).astype(np.int64)


def _lines(
    table: FeatureTable,
    parts: NDArray[Any],
    features: NDArray[np.int64],
    feature_z: NDArray[np.float64],
    problems: _Problems,
) -> list[Entity]:
    coords, index = _coordinates(parts, features, feature_z)
    closed, drop, lengths = _closing_points(coords, index, parts.shape[0], 4)
    degenerate = lengths < 2
    problems.add("a line needs at least 2 points", np.unique(features[degenerate]))
    bad_feature = np.isin(features, features[degenerate])
    keep_coord = ~drop & ~bad_feature[index]
    coords, index = coords[keep_coord], index[keep_coord]
    good = ~bad_feature
    entities: list[Entity] = []
    keys = _group_keys(table, features)
    for key in dict.fromkeys(keys[good].tolist()):
        select = good & (keys == key)
        chosen = np.flatnonzero(select)
        in_group = np.isin(index, chosen)
        vertices = coords[in_group]
        part_lengths = lengths[chosen]
        offsets = np.concatenate([[0], np.cumsum(part_lengths)]).astype(np.int64)
        rows = features[chosen]
        fields, numeric = _entity_fields(table, rows, ())
        segments = part_lengths - 1 + closed[chosen]
        cell_data = {name: np.repeat(values, segments) for name, values in numeric.items()}
        entities.append(
            PolyLine(
                vertices=vertices,
                indices=np.arange(vertices.shape[0], dtype=np.int64),
                part_offsets=offsets,
                closed=closed[chosen],
                cell_data=cell_data,
                **fields,
            )
        )
    return entities


def _polygons(
    table: FeatureTable,
    parts: NDArray[Any],
    features: NDArray[np.int64],
    feature_z: NDArray[np.float64],
    problems: _Problems,
) -> list[Entity]:
    shapely = _shapely()
    rings, ring_polygon = shapely.get_rings(parts, return_index=True)
    coords, index = _coordinates(rings, features[ring_polygon], feature_z)
    _, drop, sizes = _closing_points(coords, index, rings.shape[0], 1)
    degenerate_polygon = np.zeros(parts.shape[0], dtype=bool)
    degenerate_polygon[ring_polygon[sizes < 3]] = True
    problems.add("a polygon ring needs at least 3 points", np.unique(features[degenerate_polygon]))
    bad_feature = np.isin(features, features[degenerate_polygon])
    good_polygon = ~bad_feature
    keep_coord = ~drop & good_polygon[ring_polygon[index]]
    coords, index = coords[keep_coord], index[keep_coord]
    entities: list[Entity] = []
    keys = _group_keys(table, features)
    for key in dict.fromkeys(keys[good_polygon].tolist()):
        chosen = np.flatnonzero(good_polygon & (keys == key))
        ring_select = np.flatnonzero(np.isin(ring_polygon, chosen))
        vertices = coords[np.isin(index, ring_select)]
        ring_offsets = np.concatenate([[0], np.cumsum(sizes[ring_select])]).astype(np.int64)
        rings_per_polygon = np.bincount(
            np.searchsorted(chosen, ring_polygon[ring_select]), minlength=chosen.shape[0]
        )
        polygon_offsets = np.concatenate([[0], np.cumsum(rings_per_polygon)]).astype(np.int64)
        rows = features[chosen]
        fields, numeric = _entity_fields(table, rows, ())
        entities.append(
            Polygon(
                vertices=vertices,
                ring_offsets=ring_offsets,
                polygon_offsets=polygon_offsets,
                cell_data=numeric,
                **fields,
            )
        )
    return entities
