"""Scenes as OMF v1 projects (through the ``omf`` 1.0 package) and back.

Surfaces are SurfaceElements, point sets PointSetElements, polylines LineSetElements (their
segments), grids (point sets standing for one, :mod:`geobrep.adapters._grid_cells`)
VolumeElements; properties are scalar, 2- or 3-vector data on vertices, faces, segments or
cells; ``metadata["color"]`` is the element colour.
"""

from __future__ import annotations

import json
import struct
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from geobrep.adapters._grid_cells import Grid, as_grid, cell_values, grid_entity, triple
from geobrep.adapters.cell_layout import chain_segments
from geobrep.adapters.limits import check_declared, inflate_bounded, read_budget
from geobrep.errors import FormatError, GeobrepError
from geobrep.model.entities import Entity, PointSet, PolyLine, Surface
from geobrep.model.properties import PropertyMap
from geobrep.model.scene import Scene

__all__ = ["read_omf", "write_omf"]

_MAGIC = b"\x84\x83\x82\x81"


# -- writing ------------------------------------------------------------------------------------


def _data(props: PropertyMap, location: str) -> list[Any]:
    """OMF data of the properties OMF holds: scalars, 2- and 3-vectors of numbers."""
    import omf

    found = []
    for name, prop in props.items():
        values = np.ascontiguousarray(prop.values)
        if values.dtype.kind == "b":
            values = values.astype(np.int64)
        width = values.shape[1] if values.ndim == 2 else 1 if values.ndim == 1 else 0
        kind = {1: omf.ScalarData, 2: omf.Vector2Data, 3: omf.Vector3Data}.get(width)
        if kind is not None:
            found.append(
                kind(name=name, array=values, location=location, description=prop.description)
            )
    return found


def _c(array: Any) -> NDArray[Any]:
    """A C-contiguous copy-free view where possible (omf writes through memoryview)."""
    return np.ascontiguousarray(array)


def _color(entity: Entity) -> Any:
    color = entity.metadata.get("color")
    if isinstance(color, list) and len(color) in (3, 4):
        return [round(float(c) * 255) for c in color[:3] if isinstance(c, int | float)]
    return "random"


def _element(entity: Entity) -> Any:
    import omf

    common = {
        "name": entity.name,
        "description": str(entity.metadata.get("description", "")),
        "color": _color(entity),
    }
    grid = as_grid(entity)
    if grid is not None:
        geometry = omf.VolumeGridGeometry(
            origin=list(grid.origin),
            tensor_u=_c(grid.sizes[0]),
            tensor_v=_c(grid.sizes[1]),
            tensor_w=_c(grid.sizes[2]),
            axis_u=list(grid.axes[0]),
            axis_v=list(grid.axes[1]),
            axis_w=list(grid.axes[2]),
        )
        data = _data(cell_values(entity), "cells")
        if entity.type == "RegularGrid":
            data += _data(entity.point_data, "vertices")
        return omf.VolumeElement(geometry=geometry, data=data, **common)
    if isinstance(entity, Surface):
        geometry = omf.SurfaceGeometry(vertices=_c(entity.vertices), triangles=_c(entity.faces))
        data = _data(entity.point_data, "vertices") + _data(entity.cell_data, "faces")
        return omf.SurfaceElement(geometry=geometry, data=data, **common)
    if isinstance(entity, PolyLine):
        geometry = omf.LineSetGeometry(vertices=_c(entity.vertices), segments=_c(entity.segments))
        data = _data(entity.point_data, "vertices") + _data(entity.cell_data, "segments")
        return omf.LineSetElement(geometry=geometry, data=data, **common)
    assert isinstance(entity, PointSet)
    geometry = omf.PointSetGeometry(vertices=_c(entity.vertices))
    return omf.PointSetElement(
        geometry=geometry, data=_data(entity.point_data, "vertices"), **common
    )


def write_omf(scene: Scene, path: Path) -> None:
    """Write ``scene`` as the OMF v1 project ``path``."""
    import omf

    for surface in scene.surfaces:
        if surface.faces.shape[1] != 3:
            raise FormatError(
                f"{surface.label}: OMF surfaces hold triangles; triangulate its quads"
            )
    project = omf.Project(
        name=scene.name or path.stem,
        description=str(scene.metadata.get("description", "")),
        elements=[_element(e) for e in scene.entities],
    )
    try:  # geobrep entities are valid already: omf's own validate() would double the time
        omf.OMFWriter(project, str(path))
    except Exception as exc:  # properties' ValidationError names the field
        raise FormatError(f"OMF refuses the project: {exc}", path) from exc


# -- reading ------------------------------------------------------------------------------------


def _check_arrays(path: Path) -> None:
    """Refuse a file whose header is not OMF v1 or whose arrays inflate past the read budget
    (omf inflates each array whole, unchecked)."""
    data = path.read_bytes()
    if len(data) < 60 or data[:4] != _MAGIC or not data[4:36].startswith(b"OMF-v0.9"):
        raise FormatError("not an OMF v1 file (no OMF-v0.9 header)", path)
    (json_start,) = struct.unpack("<Q", data[52:60])
    if not 60 <= json_start <= len(data):
        raise FormatError(f"the JSON part starts at {json_start}, outside the file", path)
    try:
        document = json.loads(data[json_start:].decode("utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise FormatError(f"the JSON part is damaged: {exc}", path) from exc
    if not isinstance(document, dict):
        raise FormatError("the JSON part is not an object", path)
    budget, total = read_budget(len(data)), 0
    for uid, item in document.items():
        for key, index in item.items() if isinstance(item, dict) else ():
            if isinstance(index, dict) and {"start", "length", "dtype"} <= set(index):
                start, length = index["start"], index["length"]
                if not (isinstance(start, int) and isinstance(length, int)):
                    raise FormatError(
                        f"array {key} of {uid}: start and length must be integers", path
                    )
                if start < 0 or length < 0 or start + length > json_start:
                    raise FormatError(f"array {key} of {uid} lies outside the file", path)
                total += inflate_bounded(data[start : start + length], budget - total, key, path)
    check_declared(total, len(data), "its arrays", path)


def _values(data: Any) -> NDArray[Any]:
    return np.asarray(data.array)


def _properties(element: Any, location: str) -> PropertyMap:
    found = {}
    for data in element.data:
        if data.location == location and hasattr(data, "array"):
            found[data.name] = {"values": _values(data), "description": data.description or ""}
    return PropertyMap(found)


def _common(element: Any, origin: NDArray[np.float64]) -> dict[str, Any]:
    metadata: dict[str, Any] = {"color": [round(c / 255, 6) for c in element.color]}
    if element.description:
        metadata["description"] = element.description
    return {"name": element.name, "metadata": metadata}


def _shifted(vertices: Any, origin: NDArray[np.float64]) -> NDArray[np.float64]:
    points = np.array(vertices, dtype=np.float64).reshape(-1, 3)
    axes = np.flatnonzero(origin)  # adding a zero would turn -0.0 into 0.0
    points[:, axes] += origin[axes]
    return points


def _entity(element: Any, project_origin: NDArray[np.float64]) -> Entity | None:
    kind = type(element).__name__
    geometry = element.geometry
    origin = project_origin + np.asarray(geometry.origin, dtype=np.float64)
    common = _common(element, origin)
    if kind == "SurfaceElement" and type(geometry).__name__ == "SurfaceGeometry":
        return Surface(
            vertices=_shifted(geometry.vertices, origin),
            faces=np.asarray(geometry.triangles, dtype=np.int64),
            point_data=_properties(element, "vertices"),
            cell_data=_properties(element, "faces"),
            **common,
        )
    if kind == "LineSetElement":
        return chain_segments(
            _shifted(geometry.vertices, origin),
            np.asarray(geometry.segments, dtype=np.int64).reshape(-1, 2),
            _properties(element, "segments"),
            {**common, "point_data": _properties(element, "vertices")},
        )
    if kind == "PointSetElement":
        return PointSet(
            vertices=_shifted(geometry.vertices, origin),
            point_data=_properties(element, "vertices"),
            **common,
        )
    if kind == "VolumeElement":
        grid = Grid(
            origin=triple(origin),
            sizes=tuple(
                np.asarray(t, dtype=np.float64)
                for t in (geometry.tensor_u, geometry.tensor_v, geometry.tensor_w)
            ),  # type: ignore[arg-type]
            axes=tuple(triple(a) for a in (geometry.axis_u, geometry.axis_v, geometry.axis_w)),
        )
        found = grid_entity(grid, element.name, _properties(element, "cells"), common["metadata"])
        nodes = _properties(element, "vertices")
        return found.replace(point_data=nodes) if nodes and found.type == "RegularGrid" else found
    return None  # grid surfaces: skipped (reported)


def read_omf(path: Path) -> Scene:
    """The scene of the OMF v1 file ``path``."""
    import omf

    _check_arrays(path)
    try:
        project = omf.OMFReader(str(path)).get_project()
        origin = np.asarray(project.origin, dtype=np.float64)
        entities, skipped = [], []
        for element in project.elements:
            entity = _entity(element, origin)
            if entity is None:
                skipped.append(f"OMF {type(element).__name__} '{element.name}': no geobrep type")
            else:
                entities.append(entity)
        metadata: dict[str, Any] = {"skipped_on_read": skipped} if skipped else {}
        if project.description:
            metadata["description"] = project.description
        return Scene(entities=entities, name=project.name or path.stem, metadata=metadata)
    except GeobrepError:
        raise
    except Exception as exc:  # omf and properties validate as they go
        raise FormatError(f"damaged OMF project ({type(exc).__name__}: {exc})", path) from exc
