"""Drillholes filed inside drillhole groups: geoh5's concatenated layout (format 2.0 and 2.1, as
geoh5py 0.8 and later writes a ``DrillholeGroup``), read as geobrep Wells.

A drillhole group holding its drillholes concatenated has no HDF5 group per drillhole. Its
``Concatenated Data`` group holds:

* the attributes of every drillhole, data and property group as JSON: one string per entity in
  ``Attributes Jsons`` (2.1), or one JSON document ``{"Attributes": [...]}`` in ``Attributes``
  (2.0). A drillhole's record has its ``ID``, ``Name``, ``Collar`` (``"{x, y, z}"``) and
  ``End of hole``; a data record its ``ID``, ``Name`` and data ``Type ID``; a property group
  record its ``Property Group Type`` (``Depth table`` or ``Interval table``) and ``Properties``
  (data ids: a depth table's first is its depths, an interval table's first two its tops and
  bases, as geoh5py takes them);
* the arrays, every drillhole's rows one after the other: ``Surveys`` (and, when written,
  ``Trace`` and ``TraceDepth``) beside ``Data``, and ``Data/<name>`` for each data name;
* ``Index/<name>``: for each array, rows ``(Start index, Size, Object ID, Data ID)`` giving the
  slice of each drillhole (and, for data, which data record it is).

A Well gets the collar as its head and, as its stations, the trace when the file has one, else
geoh5's desurveying of the surveys at depth 0, the survey depths, the end of hole and, when a
sample lies deeper, the deepest sample (beyond the surveys geoh5 goes on straight). A depth
table's numeric data become logs at its depths, its referenced data markers (named by the value
map, the data's name in their metadata); an interval table's referenced data become zones
named by their values, its numeric data zones named after the data with the value in their
metadata (``{"geoh5 data": name, "value": v}``). geoh5's no-data value and NaN mark samples not
taken. Data outside any table are skipped and reported.
"""

from __future__ import annotations

import json
import re
from collections.abc import Iterator
from typing import Any

import h5py
import numpy as np
from numpy.typing import NDArray

from geobrep.adapters.geoh5._desurvey import desurvey
from geobrep.adapters.geoh5._schema import (
    FLOAT_NDV,
    INTEGER_NDV,
    OBJECT_TYPES,
    text,
    whole,
    xyz,
)
from geobrep.errors import FormatError
from geobrep.model.entities import Well, WellLog, WellMarker, WellZone

__all__ = ["concatenated_bytes", "is_concatenator", "read_concatenated"]

_DRILLHOLE = OBJECT_TYPES["Drillhole"].lower()
_OWN = ("Surveys", "Trace", "TraceDepth", "Property Group IDs")
_NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?|[-+]?(?:nan|inf)", re.I)
_Rows = dict[str, list[tuple[int, int, str]]]


def is_concatenator(group: h5py.Group) -> bool:
    return isinstance(group, h5py.Group) and "Concatenated Data" in group


def concatenated_bytes(group: h5py.Group) -> int:
    """Bytes the datasets of a concatenator declare (from their metadata alone)."""
    total = 0

    def add(_: str, item: Any) -> None:
        nonlocal total
        if isinstance(item, h5py.Dataset):
            total += int(item.size) * item.dtype.itemsize

    group["Concatenated Data"].visititems(add)
    return total


def _key(ident: Any) -> str:
    return text(ident).strip().lower()


def _records(concat: h5py.Group) -> list[dict[str, Any]]:
    """The JSON attribute records (2.1: one string each; 2.0: one document)."""
    records: Any
    if "Attributes Jsons" in concat:
        rows = np.atleast_1d(concat["Attributes Jsons"][()])
        records = [json.loads(text(row)) for row in rows.reshape(-1)]
    elif "Attributes" in concat:
        value = concat["Attributes"][()]
        if isinstance(value, np.ndarray):
            value = value.reshape(-1)[0]
        document = json.loads(text(value))
        records = document.get("Attributes", []) if isinstance(document, dict) else None
    else:
        raise FormatError("concatenated data without Attributes")
    if not isinstance(records, list) or not all(isinstance(r, dict) for r in records):
        raise FormatError("concatenated Attributes are not a list of JSON objects")
    return records


def _index(concat: h5py.Group) -> dict[str, _Rows]:
    """For each array label, each object's slices ``(start, size, data id)``."""
    found: dict[str, _Rows] = {}
    for label, table in concat.get("Index", {}).items():
        rows = table[()]
        names = rows.dtype.names or ()
        if not {"Start index", "Size", "Object ID"} <= set(names):
            raise FormatError(f"concatenated Index {label!r} lacks its columns")
        per_object: _Rows = {}
        data_ids = rows["Data ID"] if "Data ID" in names else [""] * len(rows)
        for start, size, obj, data in zip(
            rows["Start index"].tolist(),
            rows["Size"].tolist(),
            rows["Object ID"],
            data_ids,
            strict=True,
        ):
            per_object.setdefault(_key(obj), []).append((int(start), int(size), _key(data)))
        found[label] = per_object
    return found


class _Arrays:
    """The concatenated arrays, each read once, sliced by drillhole."""

    def __init__(self, concat: h5py.Group) -> None:
        self.concat = concat
        self.read: dict[str, NDArray[Any]] = {}

    def slice(self, label: str, start: int, size: int) -> NDArray[Any]:
        if label not in self.read:
            data = self.concat.get("Data")
            source = data[label] if data is not None and label in data else self.concat.get(label)
            if not isinstance(source, h5py.Dataset):
                raise FormatError(f"concatenated array {label!r} is indexed but missing")
            self.read[label] = whole(source)
        array = self.read[label]
        if start < 0 or size < 0 or start + size > array.shape[0]:
            raise FormatError(
                f"concatenated array {label!r}: rows {start}..{start + size} of {array.shape[0]}"
            )
        return array[start : start + size]


def _collar(value: Any, name: str) -> NDArray[np.float64]:
    """A collar as geoh5 writes it in JSON (``"{x, y, z}"``), or as a list or x/y/z mapping."""
    if isinstance(value, dict):
        value = [value.get(k) for k in ("x", "y", "z")]
    if isinstance(value, str):
        value = _NUMBER.findall(value)
    try:
        collar = np.array([float(v) for v in value], dtype=np.float64)
    except (TypeError, ValueError):
        collar = np.zeros(0)
    if collar.shape != (3,) or not np.isfinite(collar).all():
        raise FormatError(f"drillhole {name!r}: collar {value!r} is not three finite numbers")
    return collar


def _types(root: h5py.Group) -> dict[str, h5py.Group]:
    kinds = root.get("Types/Data types")
    return {} if kinds is None else {k.lower(): v for k, v in kinds.items()}


def _value_map(kind: h5py.Group | None) -> dict[int, str]:
    if kind is None or "Value map" not in kind:
        return {}
    rows = kind["Value map"][()]
    return {int(k): text(v) for k, v in zip(rows["Key"], rows["Value"], strict=True) if int(k)}


def _unsampled(values: NDArray[Any]) -> NDArray[np.bool_]:
    if values.dtype.kind == "f":
        missing: NDArray[np.bool_] = (
            np.isnan(values) | (values == FLOAT_NDV) | (values == np.float32(FLOAT_NDV))
        )
        return missing
    return np.asarray(values == INTEGER_NDV, dtype=np.bool_)


def _as_read(values: NDArray[Any]) -> NDArray[Any]:
    """float data as float64 (geoh5py's view of float32 arrays), integers as int32."""
    if values.dtype.kind == "f":
        return values.astype(np.float64)
    if values.dtype.kind in "iu":
        return values.astype(np.int32)
    return values


class _Hole:
    """One drillhole's records and data, read from the concatenator."""

    def __init__(self, record: dict[str, Any], types: dict[str, Any]) -> None:
        self.record, self.types = record, types
        self.id = _key(record.get("ID", ""))
        self.name = text(record.get("Name", ""))
        self.data: dict[str, tuple[dict[str, Any], NDArray[Any]]] = {}

    def primitive(self, data: dict[str, Any]) -> str:
        kind = self.types.get(_key(data.get("Type ID", "")))
        return "" if kind is None else text(kind.attrs.get("Primitive type", ""))

    def kind(self, data: dict[str, Any]) -> h5py.Group | None:
        return self.types.get(_key(data.get("Type ID", "")))


def _unique(name: str, taken: dict[str, Any]) -> str:
    if name not in taken:
        return name
    n = 1
    while f"{name} ({n})" in taken:
        n += 1
    return f"{name} ({n})"


def _table_columns(
    hole: _Hole, idents: list[str], rows: tuple[int, ...], what: str, skipped: list[str]
) -> Iterator[tuple[str, dict[str, Any], NDArray[Any]]]:
    """``(name, record, values)`` of each data column of a table whose rows have shape
    ``rows``; a column of another length is reported in ``skipped`` and left out."""
    for ident in idents:
        if ident not in hole.data:
            continue
        record, values = hole.data[ident]
        name = text(record.get("Name", ""))
        values = _as_read(values)
        if values.shape != rows:
            skipped.append(f"drillhole {hole.name!r}: {what} data {name!r} not one per {what}")
            continue
        yield name, record, values


def _depth_table(hole: _Hole, members: list[str], well: dict[str, Any], skipped: list[str]) -> None:
    depth_id, *rest = members
    if depth_id not in hole.data:
        skipped.append(f"drillhole {hole.name!r}: a depth table without its depths")
        return
    depth = _as_read(hole.data[depth_id][1]).astype(np.float64)
    for name, record, values in _table_columns(hole, rest, depth.shape, "depth", skipped):
        keep = ~_unsampled(values) & np.isfinite(depth)
        primitive = hole.primitive(record)
        if primitive == "Referenced":
            names = _value_map(hole.kind(record))
            for row in np.flatnonzero(keep & (values > 0)):
                key = int(values[row])
                well["markers"].append(
                    WellMarker(
                        name=names.get(key, str(key)),
                        md=float(depth[row]),
                        metadata={"geoh5 data": name},
                    )
                )
        elif primitive in ("Float", "Integer"):
            md, kept = depth[keep], values[keep]
            order = np.argsort(md, kind="stable")
            well["logs"][_unique(name, well["logs"])] = WellLog(md=md[order], values=kept[order])
        else:
            skipped.append(f"drillhole {hole.name!r}: {primitive or 'untyped'} depth data {name!r}")


def _interval_table(
    hole: _Hole, members: list[str], well: dict[str, Any], skipped: list[str]
) -> None:
    if len(members) < 2 or members[0] not in hole.data or members[1] not in hole.data:
        skipped.append(f"drillhole {hole.name!r}: an interval table without its from-to")
        return
    tops = _as_read(hole.data[members[0]][1]).astype(np.float64)
    bases = _as_read(hole.data[members[1]][1]).astype(np.float64)
    if tops.shape != bases.shape:
        raise FormatError(f"drillhole {hole.name!r}: {tops.size} interval tops, {bases.size} bases")
    placed = np.isfinite(tops) & np.isfinite(bases) & ~_unsampled(tops) & ~_unsampled(bases)
    upside = placed & (bases < tops)
    if upside.any():
        row = int(np.argmax(upside))
        raise FormatError(
            f"drillhole {hole.name!r}: interval {row} ends at {bases[row]} above its top "
            f"{tops[row]}"
        )
    for name, record, values in _table_columns(hole, members[2:], tops.shape, "interval", skipped):
        keep = placed & ~_unsampled(values)
        primitive = hole.primitive(record)
        if primitive == "Referenced":
            names = _value_map(hole.kind(record))
            rows = np.flatnonzero(keep & (values > 0))
            well["zones"].extend(
                WellZone(
                    name=names.get(int(values[r]), str(int(values[r]))),
                    top_md=float(tops[r]),
                    base_md=float(bases[r]),
                    metadata={"geoh5 data": name},
                )
                for r in rows
            )
        elif primitive in ("Float", "Integer"):
            well["zones"].extend(
                WellZone(
                    name=name,
                    top_md=float(tops[r]),
                    base_md=float(bases[r]),
                    metadata={"geoh5 data": name, "value": values[r].item()},
                )
                for r in np.flatnonzero(keep)
            )
        else:
            skipped.append(
                f"drillhole {hole.name!r}: {primitive or 'untyped'} interval data {name!r}"
            )


def _stations(
    hole: _Hole, arrays: _Arrays, index: dict[str, _Rows], deepest: float
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    collar = _collar(hole.record.get("Collar", [0.0, 0.0, 0.0]), hole.name)
    trace = index.get("Trace", {}).get(hole.id)
    trace_md = index.get("TraceDepth", {}).get(hole.id)
    if trace and trace_md:
        stations = xyz(arrays.slice("Trace", *trace[0][:2]))
        md = np.asarray(arrays.slice("TraceDepth", *trace_md[0][:2]), dtype=np.float64)
        if stations.shape[0] == md.shape[0] and md.size:
            return collar, stations, md
    rows = index.get("Surveys", {}).get(hole.id)
    surveys = np.array([[0.0, 0.0, -90.0]])
    if rows and rows[0][1]:
        table = arrays.slice("Surveys", *rows[0][:2])
        surveys = np.column_stack([table[k] for k in ("Depth", "Azimuth", "Dip")]).astype(
            np.float64
        )
        if not np.isfinite(surveys).all():
            raise FormatError(f"drillhole {hole.name!r}: surveys hold non-finite values")
        surveys = surveys[np.argsort(surveys[:, 0], kind="stable")]
    stated = hole.record.get("End of hole")
    end = float(stated) if isinstance(stated, int | float) and np.isfinite(stated) else None
    stops: list[Any] = [[0.0], surveys[:, 0], [] if end is None else [end]]
    last = max(float(surveys[-1, 0]), end or 0.0)
    if deepest > last:
        stops.append([deepest])
    md = np.unique(np.concatenate(stops))
    md = md[md >= 0.0]
    return collar, desurvey(collar, surveys, end, md), md


def read_concatenated(
    group: h5py.Group, root: h5py.Group, first_id: int, skipped: list[str]
) -> list[Well]:
    """The Wells of the drillholes concatenated in ``group`` (ids from ``first_id`` on)."""
    concat = group["Concatenated Data"]
    records = _records(concat)
    by_id = {_key(r.get("ID", "")): r for r in records}
    index = _index(concat)
    arrays = _Arrays(concat)
    types = _types(root)
    holes: list[_Hole] = []
    for record in records:
        if "Object Type ID" not in record:
            continue
        if _key(record["Object Type ID"]) == _DRILLHOLE:
            holes.append(_Hole(record, types))
        else:
            label = text(record.get("Name", ""))
            skipped.append(f"geoh5 concatenated object {label!r}: not a drillhole")
    table_of: dict[str, dict[str, Any]] = {}
    position = {id(r): i for i, r in enumerate(records)}
    for record in records:
        if "Property Group Type" in record:
            for member in record.get("Properties", []) or []:
                table_of.setdefault(_key(member), record)
    wells: list[Well] = []
    for hole in holes:
        for label, per_object in index.items():
            if label in _OWN:
                continue
            for start, size, data_id in per_object.get(hole.id, []):
                found = by_id.get(data_id)
                if found is not None:
                    hole.data[data_id] = (found, arrays.slice(label, start, size))
        well: dict[str, Any] = {"markers": [], "zones": [], "logs": {}}
        grouped: set[str] = set()
        tables = {id(t): t for t in (table_of.get(d) for d in hole.data) if t is not None}
        for table in sorted(tables.values(), key=lambda t: position[id(t)]):
            members = [_key(p) for p in table.get("Properties", []) or []]
            grouped.update(members)
            kind = text(table.get("Property Group Type", ""))
            if kind == "Depth table":
                _depth_table(hole, members, well, skipped)
            elif kind == "Interval table":
                _interval_table(hole, members, well, skipped)
            else:
                grouped.difference_update(members)
        for ident, (record, _) in hole.data.items():
            if ident not in grouped:
                name = text(record.get("Name", ""))
                skipped.append(
                    f"drillhole {hole.name!r}: data {name!r} in no depth or interval table"
                )
        deepest = max(
            [float(m.md) for m in well["markers"]]
            + [float(z.base_md) for z in well["zones"]]
            + [float(log.md[-1]) for log in well["logs"].values() if log.md.size],
            default=0.0,
        )
        collar, stations, md = _stations(hole, arrays, index, deepest)
        wells.append(
            Well(
                head=collar,
                vertices=stations,
                md=md,
                markers=sorted(well["markers"], key=lambda m: m.md),
                zones=well["zones"],
                logs=well["logs"],
                name=hole.name,
                id=first_id + len(wells),
            )
        )
    return wells
