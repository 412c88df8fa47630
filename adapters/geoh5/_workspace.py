"""geoh5 workspaces (Geoscience ANALYST, format version 2) on h5py, from the published schema.

A workspace is one HDF5 group ``GEOSCIENCE``: ``Groups``, ``Objects`` and ``Data`` hold one
HDF5 group per entity named by its ``{uuid}``, ``Types`` one group per entity type, and
``Root`` is the workspace group. An object links its ``Type`` and its ``Data``; a data group
holds its values as ``Data`` and its association (``Vertex``, ``Cell``) as an attribute.
Points, Curve (segments as ``Cells``), Surface (triangles as ``Cells``) and BlockModel (cell
delimiters along u, v and z, cells ordered v slowest, z fastest) are read and written.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import h5py
import numpy as np
from numpy.typing import NDArray

from geobrep.adapters._grid_cells import Grid, as_grid, cell_values, grid_entity, triple
from geobrep.adapters.cell_layout import chain_segments
from geobrep.adapters.geoh5._concatenated import (
    concatenated_bytes,
    is_concatenator,
    read_concatenated,
)
from geobrep.adapters.geoh5._drillhole import read_drillhole, write_drillhole
from geobrep.adapters.geoh5._schema import (
    ENTITY_FLAGS,
    OBJECT_TYPES,
    XYZ,
    add_data,
    object_type,
    text,
    uid,
    vertex_rows,
    whole,
    xyz,
)
from geobrep.adapters.limits import check_declared
from geobrep.errors import FormatError, GeobrepError
from geobrep.host.capabilities import SKIPPED_ON_READ
from geobrep.model.entities import Entity, PointSet, PolyLine, Surface, Well
from geobrep.model.properties import PropertyMap
from geobrep.model.scene import Scene

__all__ = ["read_geoh5", "write_geoh5"]

_BY_TYPE = {v.lower(): k for k, v in OBJECT_TYPES.items()}
_ROOT_TYPE = "{dd99b610-be92-48c0-873c-5b5946ea2840}"


# -- writing ------------------------------------------------------------------------------------


def _workspace(store: h5py.File, name: str) -> h5py.Group:
    root = store.create_group("GEOSCIENCE")
    root.attrs.update({"Version": 2.0, "Distance unit": "meter", "GA Version": "1"})
    root.attrs["Contributors"] = np.array(["geobrep"], dtype=h5py.string_dtype())
    for folder in (
        "Data",
        "Groups",
        "Objects",
        "Types/Data types",
        "Types/Group types",
        "Types/Object types",
    ):
        root.create_group(folder, track_order=True)  # objects read back in the order written
    ident = uid()
    group = root["Groups"].create_group(ident)
    group.attrs.update({"ID": ident, "Name": name or "Workspace", **ENTITY_FLAGS})
    for folder in ("Data", "Groups", "Objects"):
        group.create_group(folder, track_order=True)
    kind = root["Types/Group types"].create_group(_ROOT_TYPE)
    kind.attrs.update({"ID": _ROOT_TYPE, "Name": "NoType", "Description": "<Unknown>"})
    group["Type"] = kind
    root["Root"] = group
    return root


def _write_data(root: h5py.Group, obj: h5py.Group, props: PropertyMap, association: str) -> None:
    for name, prop in props.items():
        values = np.asarray(prop.values)
        if values.ndim != 1 or values.dtype.kind not in "biuf":
            continue  # vectors: reported as lost
        stored = np.asarray(values, dtype=np.float64 if values.dtype.kind == "f" else np.int32)
        add_data(root, obj, name, association, stored, description=prop.description)


def _rotation(grid: Grid) -> float:
    """The z rotation (degrees) of a grid whose axes are rotated in plan only."""
    u, v, w = (np.asarray(a) for a in grid.axes)
    angle = math.degrees(math.atan2(u[1], u[0]))
    expected = np.array([[math.cos(math.radians(angle)), math.sin(math.radians(angle)), 0.0]])
    if not (
        np.allclose(u, expected[0]) and np.allclose(np.cross(u, v), w) and np.allclose(w, [0, 0, 1])
    ):
        raise FormatError(f"geoh5 block models rotate about z only; axes {grid.axes} do not")
    return 0.0 if grid.axes[0] == (1.0, 0.0, 0.0) else angle


def _write_object(root: h5py.Group, entity: Entity) -> None:
    grid = as_grid(entity)
    kind = (
        "Block model"
        if grid
        else {"Surface": "Surface", "PolyLine": "Curve", "Well": "Drillhole"}.get(
            entity.type, "Points"
        )
    )
    ident = uid()
    obj = root["Objects"].create_group(ident)
    obj.attrs.update(
        {"ID": ident, "Name": entity.name or entity.label, "Last focus": "None", **ENTITY_FLAGS}
    )
    obj.create_group("Data", track_order=True)
    obj["Type"] = object_type(root, kind)
    root["Root"]["Objects"][ident] = obj
    if grid is not None:
        origin = np.array([tuple(grid.origin)], dtype=XYZ)[0]
        obj.attrs["Origin"] = origin
        obj.attrs["Rotation"] = _rotation(grid)
        for axis, sizes in zip("UVZ", grid.sizes, strict=True):
            obj.create_dataset(
                f"{axis} cell delimiters", data=np.concatenate([[0.0], np.cumsum(sizes)])
            )
        order = _geoh5_order(grid.shape)
        values = {
            n: {"values": np.asarray(p.values)[order], "description": p.description}
            for n, p in cell_values(entity).items()
        }
        _write_data(root, obj, PropertyMap(values), "Cell")
        return
    if isinstance(entity, Well):
        write_drillhole(root, obj, entity)
        return
    assert isinstance(entity, PointSet | PolyLine | Surface)
    obj.create_dataset("Vertices", data=vertex_rows(entity.vertices))
    if isinstance(entity, Surface):
        obj.create_dataset("Cells", data=np.asarray(entity.faces, dtype=np.int32))
    elif isinstance(entity, PolyLine):
        obj.create_dataset("Cells", data=np.asarray(entity.segments, dtype=np.uint32))
    _write_data(root, obj, entity.point_data, "Vertex")
    if isinstance(entity, Surface | PolyLine):
        _write_data(root, obj, entity.cell_data, "Cell")


def _geoh5_order(shape: tuple[int, int, int]) -> NDArray[np.int64]:
    """For each geoh5 cell (v slowest, z fastest), the index of the same cell u fastest."""
    nu, nv, nw = shape
    v, u, w = np.meshgrid(np.arange(nv), np.arange(nu), np.arange(nw), indexing="ij")
    return (u + nu * (v + nv * w)).ravel()


def write_geoh5(scene: Scene, path: Path) -> None:
    """Write ``scene`` as the geoh5 workspace ``path``."""
    for surface in scene.surfaces:
        if surface.faces.shape[1] != 3:
            raise FormatError(
                f"{surface.label}: geoh5 surfaces hold triangles; triangulate its quads"
            )
    with h5py.File(path, "w") as store:
        root = _workspace(store, scene.name)
        for entity in scene.entities:
            _write_object(root, entity)


# -- reading ------------------------------------------------------------------------------------


def _nbytes(item: Any) -> int:
    return int(item.size) * item.dtype.itemsize if isinstance(item, h5py.Dataset) else 0


def _declared(obj: h5py.Group) -> int:
    """Bytes the datasets geobrep may read of ``obj`` declare (its own, its data's values and
    their value maps), from their metadata alone."""
    total = sum(_nbytes(item) for item in obj.values())
    for data in obj.get("Data", {}).values():
        total += _nbytes(data.get("Data"))
        kind = data.get("Type")
        total += 0 if kind is None else _nbytes(kind.get("Value map"))
    return total


def _read_data(obj: h5py.Group, association: str, n: int, order: Any = None) -> PropertyMap:
    found = {}
    for data in obj.get("Data", {}).values():
        if text(data.attrs.get("Association", "")) != association or "Data" not in data:
            continue
        values = whole(data["Data"])
        if values.ndim != 1 or values.dtype.kind not in "biuf" or len(values) != n:
            continue
        kind = data.get("Type")
        description = "" if kind is None else text(kind.attrs.get("Description", ""))
        name = text(data.attrs.get("Name", ""))
        found[name] = {
            "values": values if order is None else values[order],
            "description": "" if description in (name, "Entity") else description,
        }
    return PropertyMap(found)


def _block_model(obj: h5py.Group, name: str, ident: int) -> Entity:
    origin = obj.attrs["Origin"]
    corner = np.array([origin["x"], origin["y"], origin["z"]], dtype=np.float64)
    delimiters = [np.asarray(obj[f"{a} cell delimiters"][()], dtype=np.float64) for a in "UVZ"]
    angle = math.radians(float(obj.attrs.get("Rotation", 0.0)))
    axes = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))
    if angle:
        c, s = math.cos(angle), math.sin(angle)
        axes = ((c, s, 0.0), (-s, c, 0.0), (0.0, 0.0, 1.0))
    start = np.array([d[0] for d in delimiters])
    corner = corner + start @ np.asarray(axes) if start.any() else corner
    grid = Grid(origin=triple(corner), sizes=tuple(np.diff(d) for d in delimiters), axes=axes)  # type: ignore[arg-type]
    order = np.argsort(_geoh5_order(grid.shape))
    cells = _read_data(obj, "Cell", grid.n_cells, order)
    return grid_entity(grid, name, cells, {}, id=ident)


def _cells(stored: NDArray[Any]) -> NDArray[np.int64] | NDArray[np.int32]:
    """Cells as stored when they are int32 (surfaces: the entity holds them as they are, no
    copy), other integers as int64."""
    if stored.dtype == np.int32:
        return stored
    return np.asarray(stored, dtype=np.int64)


def _object(obj: h5py.Group, ident: int, skipped: list[str]) -> Entity | None:
    """The entity of ``obj`` with id ``ident`` (given here: a Scene giving ids would validate
    each entity again), or None for a type geobrep does not read; what it holds and geobrep
    does not read goes to ``skipped``."""
    kind = _BY_TYPE.get(text(obj["Type"].attrs.get("ID", "")).lower())
    name = text(obj.attrs.get("Name", ""))
    if kind == "Block model":
        return _block_model(obj, name, ident)
    if kind == "Drillhole":
        return read_drillhole(obj, name, ident, skipped)
    if kind is None or "Vertices" not in obj:
        return None
    vertices = xyz(whole(obj["Vertices"]))
    points = _read_data(obj, "Vertex", len(vertices))
    if kind == "Points":
        return PointSet(vertices=vertices, name=name, point_data=points, id=ident)
    cells = _cells(whole(obj["Cells"])) if "Cells" in obj else np.zeros((0, 3), np.int64)
    cell_data = _read_data(obj, "Cell", len(cells))
    if kind == "Surface":
        return Surface(
            vertices=vertices,
            faces=cells,
            name=name,
            point_data=points,
            cell_data=cell_data,
            id=ident,
        )
    segments = np.asarray(cells, dtype=np.int64).reshape(-1, 2)
    return chain_segments(
        vertices, segments, cell_data, {"name": name, "point_data": points, "id": ident}
    )


def read_geoh5(path: Path) -> Scene:
    """The scene of the geoh5 workspace ``path``."""
    try:
        with h5py.File(path, "r") as store:
            budget, declared = path.stat().st_size, 0
            if "GEOSCIENCE" not in store:
                raise FormatError("not a geoh5 workspace (no GEOSCIENCE group)", path)
            root = store["GEOSCIENCE"]
            entities: list[Entity] = []
            skipped: list[str] = []
            for ident, obj in root.get("Objects", {}).items():
                declared += _declared(obj)  # before any of it is read
                check_declared(declared, budget, "its objects' datasets", path)
                try:
                    entity = _object(obj, len(entities), skipped)
                except GeobrepError as exc:
                    raise FormatError(f"object {ident}: {exc}", path) from exc
                if entity is None:
                    label = text(obj.attrs.get("Name", ident))
                    skipped.append(f"geoh5 object {label!r}: no reader for its type")
                else:
                    entities.append(entity)
            for ident, group in root.get("Groups", {}).items():
                if not is_concatenator(group):
                    continue
                declared += concatenated_bytes(group)
                check_declared(declared, budget, "its drillhole groups' datasets", path)
                try:
                    entities.extend(read_concatenated(group, root, len(entities), skipped))
                except GeobrepError as exc:
                    label = text(group.attrs.get("Name", ident))
                    raise FormatError(f"drillhole group {label!r}: {exc}", path) from exc
            name = text(root["Root"].attrs.get("Name", path.stem)) if "Root" in root else path.stem
    except GeobrepError:
        raise
    except Exception as exc:  # h5py and damaged attributes
        raise FormatError(f"damaged geoh5 workspace ({type(exc).__name__}: {exc})", path) from exc
    metadata: dict[str, Any] = {SKIPPED_ON_READ: skipped} if skipped else {}
    return Scene(entities=entities, name="" if name == "Workspace" else name, metadata=metadata)
