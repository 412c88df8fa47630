"""geoh5 drillholes as geobrep Wells, both ways, laid out as geoh5py lays out a drillhole.

A ``Drillhole`` object has a ``Collar`` (the well head), float32 ``Surveys`` rows (depth,
azimuth, dip: see ``_desurvey``) and ``End of hole``. geobrep writes the stations exactly too,
as the drillhole's ``Trace`` (x, y, z records) with their measured depths in ``TraceDepth``;
without them (a file from another program) the stations are geoh5's desurveying of the surveys.

Data hang on the drillhole's vertices and cells. Each vertex has its depth in the float data
``DEPTH``: logs are vertex data (float64 or int32, geoh5's no-data value where a log has no
sample), markers ``Referenced`` vertex data ``MARKER`` (the marker names; ``MARKER SURFACE`` the
surfaces they pick), one vertex per marker. Zones are cells (a ``from`` and a ``to`` vertex) with
the float cell data ``FROM`` and ``TO`` and the ``Referenced`` cell data ``ZONE``. Read back, any
referenced vertex data gives markers and any referenced interval data zones (named by the
values, the data's name in their metadata unless it is ``MARKER`` or ``ZONE``).
"""

from __future__ import annotations

from typing import Any

import h5py
import numpy as np
from numpy.typing import NDArray

from geobrep.adapters.geoh5._desurvey import desurvey, station_surveys
from geobrep.adapters.geoh5._schema import (
    FLOAT_NDV,
    INTEGER_NDV,
    XYZ,
    add_data,
    data_values,
    text,
    value_map,
    vertex_rows,
    xyz,
)
from geobrep.errors import FormatError
from geobrep.model.entities import Well, WellLog, WellMarker, WellZone

__all__ = ["RESERVED", "read_drillhole", "write_drillhole"]

#: Data names the drillhole layout uses itself.
RESERVED = ("DEPTH", "FROM", "TO", "MARKER", "MARKER SURFACE", "ZONE")
_Data = tuple[h5py.Group, str, str, NDArray[Any]]


# -- writing ------------------------------------------------------------------------------------


def _layout(well: Well) -> tuple[NDArray[np.float64], NDArray[np.int64], NDArray[np.float64]]:
    """Vertex depths (sorted), the vertex of each row (log depths, markers, zone tops, zone
    bases) and the log depths (every depth a log samples, once)."""
    logs = [log.md for log in well.logs.values()]
    log_depths = np.unique(np.concatenate(logs)) if logs else np.zeros(0)
    rows = np.concatenate(
        [
            log_depths,
            np.array([m.md for m in well.markers], dtype=np.float64),
            np.array([z.top_md for z in well.zones], dtype=np.float64),
            np.array([z.base_md for z in well.zones], dtype=np.float64),
        ]
    )
    order = np.argsort(rows, kind="stable")
    rank = np.empty_like(order)
    rank[order] = np.arange(order.shape[0])
    return rows[order], rank, log_depths


def _positions(
    well: Well, surveys: NDArray[Any], depth: NDArray[np.float64]
) -> NDArray[np.float64]:
    """XYZ of depths along the stations; above or below them, on from the nearest end station
    as geoh5 desurveys the hole there."""
    points = well.position_at(depth)
    outside = np.isnan(points[:, 0])
    if outside.any() and well.n_stations:
        rows = np.column_stack([surveys[k] for k in ("Depth", "Azimuth", "Dip")])
        end = float(well.md[-1])
        below = depth[outside] > end
        anchor = np.where(below, well.n_stations - 1, 0)
        placed = desurvey(well.head, rows, end, np.concatenate([depth[outside], well.md[[0, -1]]]))
        ends = np.where(below[:, None], placed[-1], placed[-2])
        points[outside] = placed[:-2] - ends + well.vertices[anchor]
    return points


def _keys(names: list[str]) -> tuple[list[str], NDArray[np.int32]]:
    """Each distinct name once (first-seen order) and each name's key (1-based)."""
    distinct = list(dict.fromkeys(names))
    index = {name: key for key, name in enumerate(distinct, start=1)}
    return distinct, np.array([index[n] for n in names], dtype=np.int32)


def _write_logs(
    root: h5py.Group,
    obj: h5py.Group,
    well: Well,
    depths: NDArray[np.float64],
    slots: NDArray[np.int64],
    n: int,
) -> None:
    """Each log on the vertices of its depths (``depths``: every log depth, at ``slots``)."""
    for name, log in well.logs.items():
        where = slots[np.searchsorted(depths, log.md)]
        values = np.asarray(log.values)
        if values.dtype.kind == "f":
            column: NDArray[Any] = np.full(n, FLOAT_NDV)
        else:
            column = np.full(n, INTEGER_NDV, dtype=np.int32)
        column[where] = values
        add_data(root, obj, name, "Vertex", column)


def _write_markers(
    root: h5py.Group, obj: h5py.Group, well: Well, slots: NDArray[np.int64], n: int
) -> None:
    names, keys = _keys([m.name for m in well.markers])
    column = np.zeros(n, dtype=np.int32)
    column[slots] = keys
    add_data(root, obj, "MARKER", "Vertex", column, names=names)
    picked = [m.surface for m in well.markers]
    if any(picked):
        surfaces, surface_keys = _keys([s for s in picked if s])
        column = np.zeros(n, dtype=np.int32)
        column[slots[[bool(s) for s in picked]]] = surface_keys
        add_data(root, obj, "MARKER SURFACE", "Vertex", column, names=surfaces)


def _write_zones(
    root: h5py.Group, obj: h5py.Group, well: Well, tops: NDArray[np.int64], bases: NDArray[np.int64]
) -> None:
    obj.create_dataset("Cells", data=np.column_stack([tops, bases]).astype(np.uint32))
    add_data(root, obj, "FROM", "Cell", np.array([z.top_md for z in well.zones], np.float64))
    add_data(root, obj, "TO", "Cell", np.array([z.base_md for z in well.zones], np.float64))
    names, keys = _keys([z.name for z in well.zones])
    add_data(root, obj, "ZONE", "Cell", keys, names=names)


def write_drillhole(root: h5py.Group, obj: h5py.Group, well: Well) -> None:
    """Fill the drillhole object ``obj`` (its group, type and flags made) with ``well``."""
    clash = [name for name in well.logs if name.upper() in RESERVED]
    if clash:
        raise FormatError(
            f"{well.label}: log {clash[0]!r}: geoh5 drillholes use the data names "
            f"{', '.join(RESERVED)} themselves; rename the log"
        )
    obj.attrs["Collar"] = np.array([tuple(float(c) for c in well.head)], dtype=XYZ)[0]
    obj.attrs.update(
        {
            "End of hole": float(well.md[-1]) if well.n_stations else 0.0,
            "Cost": 0.0,
            "Planning": "Default",
        }
    )
    surveys = station_surveys(well.vertices, well.md)
    obj.create_dataset("Surveys", data=surveys)
    obj.create_dataset("Trace", data=vertex_rows(well.vertices))
    obj.create_dataset("TraceDepth", data=np.asarray(well.md, dtype=np.float64))
    depth, rank, log_depths = _layout(well)
    n = depth.shape[0]
    if not n:
        return
    obj.create_dataset("Vertices", data=vertex_rows(_positions(well, surveys, depth)))
    add_data(root, obj, "DEPTH", "Vertex", depth)
    first, markers, zones = log_depths.shape[0], len(well.markers), len(well.zones)
    if well.logs:
        _write_logs(root, obj, well, log_depths, rank[:first], n)
    if markers:
        _write_markers(root, obj, well, rank[first : first + markers], n)
    if zones:
        tops = rank[first + markers : first + markers + zones]
        _write_zones(root, obj, well, tops, rank[first + markers + zones :])


# -- reading ------------------------------------------------------------------------------------


def _collar(obj: h5py.Group) -> NDArray[np.float64]:
    value = np.asarray(obj.attrs.get("Collar", np.zeros(3)))
    if value.dtype.names:
        row = value.reshape(-1)[0]
        return np.array([float(row[k]) for k in ("x", "y", "z")])
    return np.asarray(value, dtype=np.float64).reshape(3)


def _surveys(obj: h5py.Group) -> NDArray[np.float64]:
    if "Surveys" not in obj or not obj["Surveys"].shape[0]:
        return np.array([[0.0, 0.0, -90.0]])
    rows = obj["Surveys"][()]
    return np.column_stack([rows[k] for k in ("Depth", "Azimuth", "Dip")]).astype(np.float64)


def _stations(
    obj: h5py.Group, collar: NDArray[np.float64], end: float | None
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Station XYZ and MD: the trace geobrep wrote, or geoh5's desurveying of the surveys."""
    if "Trace" in obj and "TraceDepth" in obj:
        trace = xyz(obj["Trace"][()])
        md = np.asarray(obj["TraceDepth"][()], dtype=np.float64).reshape(-1)
        if trace.shape[0] == md.shape[0]:
            return trace, md
    surveys = _surveys(obj)
    md = np.unique(np.concatenate([[0.0], surveys[:, 0], [] if end is None else [end]]))
    return desurvey(collar, surveys, end, md), md


def _sampled(values: NDArray[Any]) -> NDArray[np.bool_]:
    if values.dtype.kind == "f":
        no_data = np.isnan(values) | (values == FLOAT_NDV) | (values == np.float32(FLOAT_NDV))
        sampled: NDArray[np.bool_] = ~no_data
    else:
        sampled = np.asarray(values != INTEGER_NDV, dtype=np.bool_)
    return sampled


def _log(depth: NDArray[np.float64], values: NDArray[Any]) -> WellLog:
    keep = _sampled(values)
    md, kept = depth[keep], values[keep]
    order = np.argsort(md, kind="stable")
    return WellLog(md=md[order], values=kept[order])


def _markers(vertex: list[_Data], depth: NDArray[np.float64]) -> list[WellMarker]:
    surfaces = next((d for d in vertex if d[1] == "MARKER SURFACE" and d[2] == "Referenced"), None)
    picks: list[WellMarker] = []
    for data, name, _, keys in vertex:
        if name == "MARKER SURFACE":
            continue
        names = value_map(data)
        surface_names = value_map(surfaces[0]) if surfaces and name == "MARKER" else {}
        metadata: dict[str, Any] = {} if name == "MARKER" else {"geoh5 data": name}
        for row in np.flatnonzero(keys > 0):
            surface = (
                surface_names.get(int(surfaces[3][row])) if surfaces and surface_names else None
            )
            picks.append(
                WellMarker(
                    name=names.get(int(keys[row]), str(int(keys[row]))),
                    md=float(depth[row]),
                    surface=surface or "",
                    metadata=metadata,
                )
            )
    return sorted(picks, key=lambda m: m.md)


def _zones(
    cell: list[_Data], cells: NDArray[np.int64], depth: NDArray[np.float64]
) -> list[WellZone]:
    named = {d[1]: d[3] for d in cell if d[2] == "Float"}
    tops = named.get("FROM", depth[cells[:, 0]] if depth.size else None)
    bases = named.get("TO", depth[cells[:, 1]] if depth.size else None)
    if tops is None or bases is None:
        return []
    zones: list[WellZone] = []
    for data, name, primitive, keys in cell:
        if primitive != "Referenced":
            continue
        names = value_map(data)
        metadata: dict[str, Any] = {} if name == "ZONE" else {"geoh5 data": name}
        zones.extend(
            WellZone(
                name=names.get(int(keys[row]), str(int(keys[row]))),
                top_md=float(tops[row]),
                base_md=float(bases[row]),
                metadata=metadata,
            )
            for row in np.flatnonzero(keys > 0)
        )
    return zones


def _data(obj: h5py.Group, association: str, n: int) -> list[_Data]:
    found = []
    for data in obj.get("Data", {}).values():
        if text(data.attrs.get("Association", "")) != association:
            continue
        read = data_values(data)
        if read is not None and read[2].ndim == 1 and len(read[2]) == n:
            found.append((data, *read))
    return found


def read_drillhole(obj: h5py.Group, name: str, ident: int, skipped: list[str]) -> Well:
    """The Well of the drillhole object ``obj``; data it cannot hold go to ``skipped``."""
    collar = _collar(obj)
    end = obj.attrs.get("End of hole")
    stations, md = _stations(obj, collar, None if end is None else float(end))
    n = obj["Vertices"].shape[0] if "Vertices" in obj else 0
    vertex = _data(obj, "Vertex", n)
    depth = next((d[3] for d in vertex if d[1] == "DEPTH"), np.zeros(0)).astype(np.float64)
    if depth.shape[0] != n:
        vertex, depth = [], np.zeros(0)
    logs: dict[str, WellLog] = {}
    for _, data_name, primitive, values in vertex:
        if data_name != "DEPTH" and primitive in ("Float", "Integer"):
            logs[data_name] = _log(depth, values)
        elif primitive not in ("Float", "Integer", "Referenced"):
            skipped.append(f"drillhole {name!r}: {primitive} depth data {data_name!r}")
    cells = np.asarray(obj["Cells"][()], dtype=np.int64).reshape(-1, 2) if "Cells" in obj else None
    cell = [] if cells is None else _data(obj, "Cell", cells.shape[0])
    for _, data_name, primitive, _ in cell:
        if primitive != "Referenced" and data_name not in ("FROM", "TO"):
            skipped.append(f"drillhole {name!r}: {primitive} interval data {data_name!r}")
    return Well(
        head=collar,
        vertices=stations,
        md=md,
        markers=_markers([d for d in vertex if d[2] == "Referenced"], depth),
        zones=_zones(cell, cells, depth) if cells is not None else [],
        logs=logs,
        name=name,
        id=ident,
    )
