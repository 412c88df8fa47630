"""A RESQML 2.0.1 model (``.epc`` + ``.h5``) read through resqpy into a scene.

Triangulated sets become surfaces (one patch label per RESQML patch, unless geobrep's patch
property says more), point sets point sets, polyline sets and polylines polylines, geobody
interpretations written by geobrep blocks. Coordinates are taken from each representation's
local CRS to the world: offsets added, depth turned into z up. What the reader does not turn
into entities (grids, wells, ...) is listed in ``scene.metadata["skipped_on_read"]``.
"""

from __future__ import annotations

import warnings
import zipfile
from pathlib import Path
from typing import Any

import h5py
import numpy as np
from numpy.typing import NDArray

from geobrep.adapters.limits import check_declared
from geobrep.adapters.resqml._records import (
    decode_record,
    properties_from,
    scene_from_record,
)
from geobrep.adapters.resqml._writer import PATCH_PROPERTY
from geobrep.errors import FormatError, GeobrepError
from geobrep.host.capabilities import SKIPPED_ON_READ
from geobrep.model.crs import CRS
from geobrep.model.entities import Block, Entity, PointSet, PolyLine, Surface
from geobrep.model.scene import Scene

__all__ = ["read_resqml"]

#: Interpretation type -> geobrep kind.
_KINDS = {
    "HorizonInterpretation": "horizon",
    "FaultInterpretation": "fault",
    "BoundaryFeatureInterpretation": "boundary",
    "GeobodyBoundaryInterpretation": "boundary",
}
_REPRESENTATIONS = (
    "TriangulatedSetRepresentation",
    "PointSetRepresentation",
    "PolylineSetRepresentation",
    "PolylineRepresentation",
)
_QUIET = ("obj_EpcExternalPartReference", "obj_PropertyKind", "Feature", "Interpretation", "Crs")


def _check_sizes(path: Path) -> tuple[Path, h5py.File]:
    """Refuse an EPC or HDF5 file declaring more than its read budget; the .h5 beside it, and
    the HDF5 file open for reading (resqpy is given this handle: one open, not two)."""
    try:
        with zipfile.ZipFile(path) as archive:
            declared = sum(info.file_size for info in archive.infolist())
    except (zipfile.BadZipFile, OSError) as exc:
        raise FormatError(f"not an EPC package: {exc}", path) from exc
    check_declared(declared, path.stat().st_size, "the EPC package", path)
    h5 = path.with_suffix(".h5")
    if not h5.exists():
        raise FormatError(f"the HDF5 file beside it ({h5.name}) is missing", path)
    total = 0
    try:
        store = h5py.File(h5, "r")
    except OSError as exc:
        raise FormatError(f"the HDF5 file beside it cannot be read: {exc}", h5) from exc
    try:

        def add(name: str, item: Any) -> None:
            nonlocal total
            if isinstance(item, h5py.Dataset):
                total += int(item.size) * item.dtype.itemsize

        store.visititems(add)
        check_declared(total, h5.stat().st_size, "its datasets", h5)
    except BaseException as exc:
        store.close()
        if isinstance(exc, OSError):
            raise FormatError(f"the HDF5 file beside it cannot be read: {exc}", h5) from exc
        raise
    return h5, store


def read_resqml(path: Path) -> Scene:
    """The scene of the RESQML model ``path``."""
    import resqpy.model as rq

    h5, store = _check_sizes(path)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = None
        try:
            model = rq.Model(str(path))
            model.h5_set_default_override("full")  # the .h5 of the same stem, as checked
            # resqpy reuses the handle it finds open on the same file (``Model.h5_access``)
            model.h5_currently_open_path = str(h5)
            model.h5_currently_open_mode = "r"
            model.h5_currently_open_root = store
            return _scene(model, path)
        except GeobrepError:
            raise
        except Exception as exc:  # resqpy asserts, indexes and parses without checking first
            raise FormatError(f"damaged RESQML model ({type(exc).__name__}: {exc})", path) from exc
        finally:
            if model is not None and model.h5_currently_open_root is not None:
                model.h5_release()
            store.close()


def _scene(model: Any, path: Path) -> Scene:
    import resqpy.crs as rqc

    crs_uuid = model.uuid(obj_type="LocalDepth3dCrs") or model.uuid(obj_type="LocalTime3dCrs")
    crs_obj = None if crs_uuid is None else rqc.Crs(model, uuid=crs_uuid)
    record = None if crs_obj is None else decode_record(crs_obj.extra_metadata)
    entities: list[Entity] = []
    for obj_type in _REPRESENTATIONS:
        for uuid in model.uuids(obj_type=obj_type):
            entities.append(_entity(model, obj_type, uuid))
    entities.extend(_blocks(model))
    entities = _with_ids(entities)
    scene = scene_from_record(entities, record, _crs(crs_obj), path.stem)
    skipped = _skipped(model)
    if skipped:
        scene = scene.replace(metadata={**scene.metadata, SKIPPED_ON_READ: skipped})
    return scene


def _crs(crs: Any) -> CRS | None:
    if crs is None:
        return None
    epsg = int(crs.epsg_code) if crs.epsg_code and str(crs.epsg_code).isdigit() else None
    return CRS(
        name=crs.title or None,
        epsg=epsg,
        axis_units=(crs.xy_units, crs.xy_units, crs.z_units),
        z_positive="down" if crs.z_inc_down else "up",
    )


def _world(model: Any, crs_uuid: Any, points: NDArray[Any]) -> NDArray[np.float64]:
    """Local CRS coordinates as world coordinates, z up (one new array at most: resqpy's
    arrays are the model's, read for this scene only)."""
    import resqpy.crs as rqc

    crs = rqc.Crs(model, uuid=crs_uuid)
    world = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    if crs.rotation:
        world = crs.local_to_global_array(world.copy(), global_z_inc_down=crs.z_inc_down)
    else:
        offset = np.array([crs.x_offset, crs.y_offset, crs.z_offset], dtype=np.float64)
        axes = np.flatnonzero(offset)  # adding a zero would turn -0.0 into 0.0
        if len(axes):
            world = world.copy()
            world[:, axes] += offset[axes]
    if crs.z_inc_down:
        world = world * np.array([1.0, 1.0, -1.0])
    return world


def _kind(model: Any, root: Any, record: dict[str, Any] | None) -> str | None:
    if record is not None:
        kind = record.get("kind")
        return kind if isinstance(kind, str) else None
    import resqpy.olio.xml_et as rqet

    node = rqet.find_tag(root, "RepresentedInterpretation")
    if node is None:
        return None
    interpretation = model.referenced_node(node)
    return (
        None
        if interpretation is None
        else _KINDS.get(rqet.node_type(interpretation, strip_obj=True))
    )


def _entity(model: Any, obj_type: str, uuid: Any) -> Entity:
    import resqpy.lines as rql
    import resqpy.surface as rqs

    if obj_type == "TriangulatedSetRepresentation":
        return _surface(model, rqs.Surface(model, uuid=uuid))
    if obj_type == "PointSetRepresentation":
        rep = rqs.PointSet(model, uuid=uuid)
        vertices = _world(model, rep.crs_uuid, rep.full_array_ref())
        return _finish(model, rep, PointSet, {"vertices": vertices}, len(vertices), 0)
    if obj_type == "PolylineSetRepresentation":
        rep = rql.PolylineSet(model, uuid=uuid)
        counts = np.asarray(rep.count_perpol, dtype=np.int64)
        closed = np.asarray(rep.closed_array, dtype=bool)
    else:
        rep = rql.Polyline(model, uuid=uuid)
        counts, closed = np.array([len(rep.coordinates)]), np.array([bool(rep.isclosed)])
    vertices = _world(model, rep.crs_uuid, rep.coordinates)
    line = {
        "vertices": vertices,
        "indices": np.arange(len(vertices)),
        "part_offsets": np.concatenate([[0], np.cumsum(counts)]),
        "closed": closed,
    }
    return _finish(model, rep, PolyLine, line, len(vertices), int(counts.sum() - (~closed).sum()))


def _read_whole(model: Any, node: Any, tag: str, dtype: Any, columns: int | None) -> Any:
    """The HDF5 array of ``node`` read straight into a new ``dtype`` array (HDF5 converts while
    reading: no zero-filled array, copy or cast as resqpy's cache makes), or None when its
    shape is not ``(n,)`` / ``(n, columns)`` (resqpy's own reading then has its say)."""
    key = model.h5_uuid_and_path_for_node(node, tag=tag)
    if key is None:
        return None
    dataset = model.h5_access(key[0]).get(key[1])
    if not isinstance(dataset, h5py.Dataset) or dataset.dtype.kind not in "iuf":
        return None
    shape = dataset.shape
    if (columns is None and len(shape) != 1) or (
        columns is not None and (len(shape) != 2 or shape[1] != columns)
    ):
        return None
    array = np.empty(shape, dtype=dtype)
    if array.size:
        dataset.read_direct(array)
    return array


def _patch_arrays(model: Any, rep: Any) -> tuple[Any, Any] | None:
    """Triangles (int64) and points (float64) of every patch of ``rep``, read straight from the
    HDF5 file, patches one after the other (each patch's triangles offset by the points before
    it, as resqpy's ``triangles_and_points``); None for any other layout."""
    import resqpy.olio.xml_et as rqet

    rep.extract_patches(rep.root)
    parts = []
    for patch in rep.patch_list:
        geometry = rqet.find_tag(patch.node, "Geometry")
        points = None if geometry is None else rqet.find_tag(geometry, "Points")
        triangles = rqet.find_tag(patch.node, "Triangles")
        if points is None or triangles is None or rqet.node_type(points) != "Point3dHdf5Array":
            return None
        xyz = _read_whole(model, points, "Coordinates", np.float64, 3)
        corners = _read_whole(model, triangles, "Values", np.int64, 3)
        if xyz is None or corners is None:
            return None
        parts.append((corners, xyz))
    if len(parts) == 1:
        return parts[0]
    if not parts:
        return None
    offsets = np.cumsum([0] + [len(p) for _, p in parts[:-1]])
    return (
        np.concatenate([t + o for (t, _), o in zip(parts, offsets, strict=True)]),
        np.concatenate([p for _, p in parts]),
    )


def _surface(model: Any, rep: Any) -> Entity:
    direct = _patch_arrays(model, rep)
    if direct is None:
        triangles, points = rep.triangles_and_points()
        triangles = np.asarray(triangles, dtype=np.int64)
    else:
        triangles, points = direct
    vertices = _world(model, rep.crs_uuid, points)
    fields: dict[str, Any] = {"vertices": vertices, "faces": triangles}
    if rep.number_of_patches() > 1:
        fields["patch_labels"] = np.asarray(
            rep.patch_indices_for_triangle_indices(np.arange(len(triangles)))
        )
    return _finish(model, rep, Surface, fields, len(vertices), len(triangles))


def _properties(rep: Any, n_nodes: int, n_cells: int) -> tuple[dict[str, Any], dict[str, Any]]:
    """(point properties, cell properties) of ``rep``: name -> (values, unit)."""
    import resqpy.property as rqp

    collection = rqp.PropertyCollection(support=rep)
    nodes: dict[str, Any] = {}
    cells: dict[str, Any] = {}
    for part in collection.parts():
        name = collection.citation_title_for_part(part)
        element = collection.indexable_for_part(part)
        values = _property_values(collection, part)
        unit = None if not collection.continuous_for_part(part) else collection.uom_for_part(part)
        unit = None if unit in (None, "Euc") else unit
        if element == "nodes" and len(values) == n_nodes:
            nodes[name] = (values, unit)
        elif element in ("faces", "intervals") and len(values) == n_cells:
            cells[name] = (values, unit)
    return nodes, cells


def _property_values(collection: Any, part: Any) -> NDArray[Any]:
    """The values of a property part as resqpy gives them (float64 for doubles, int64 for
    integers), read straight from the HDF5 file when it is one patch of values; other parts
    (constant, packed, points) through resqpy."""
    import resqpy.olio.xml_et as rqet

    node = collection.node_for_part(part)
    patches = [] if node is None else rqet.list_of_tag(node, "PatchOfValues")
    if (
        len(patches) == 1
        and collection.constant_value_for_part(part) is None
        and not collection.points_for_part(part)
    ):
        values = rqet.find_tag(patches[0], "Values")
        dtype = {"DoubleHdf5Array": np.float64, "IntegerHdf5Array": np.int64}.get(
            "" if values is None else rqet.node_type(values)
        )
        if dtype is not None:
            array = _read_whole(collection.model, values, "Values", dtype, None)
            if array is not None:
                return array  # type: ignore[no-any-return]
    return np.asarray(collection.cached_part_array_ref(part, masked=False))


def _finish(
    model: Any, rep: Any, cls: type[Entity], fields: dict[str, Any], n_nodes: int, n_cells: int
) -> Entity:
    """The ``cls`` entity of ``fields`` with the name, kind, properties and record of ``rep``
    (built and validated once)."""
    record = decode_record(rep.extra_metadata)
    nodes, cells = _properties(rep, n_nodes, n_cells)
    fields.update(name=rep.title or "", kind=_kind(model, rep.root, record))
    patch = cells.pop(PATCH_PROPERTY, None)
    if patch is not None and cls is Surface:
        fields["patch_labels"] = np.asarray(patch[0], dtype=np.int64)
    if record is not None:
        fields["id"] = record.get("id")
        fields["metadata"] = record.get("metadata", {})
        if cls is Surface and record.get("patch_names"):
            fields["patch_names"] = tuple(record["patch_names"])
    fields["point_data"] = properties_from(nodes, (record or {}).get("point_data"))
    fields["cell_data"] = properties_from(cells, (record or {}).get("cell_data"))
    return cls(**fields)


def _blocks(model: Any) -> list[Entity]:
    """The blocks geobrep wrote as geobody interpretations (others carry no sides)."""
    import resqpy.organize as rqo

    blocks: list[Entity] = []
    for uuid in model.uuids(obj_type="GeobodyInterpretation"):
        interpretation = rqo.GeobodyInterpretation(model, uuid=uuid)
        record = decode_record(interpretation.extra_metadata)
        if record is not None and isinstance(record.get("block"), dict):
            blocks.append(Block.model_validate(record["block"]))
        else:
            blocks.append(Block(name=interpretation.title or "", kind="unit"))
    return blocks


def _with_ids(entities: list[Entity]) -> list[Entity]:
    """Entities with their recorded ids, or fresh ones when ids are missing or repeated."""
    ids = [e.id for e in entities]
    if None not in ids and len(set(ids)) == len(ids):
        return entities
    return [e.replace(id=i) for i, e in enumerate(entities)]


def _skipped(model: Any) -> list[str]:
    """The parts that are neither entities nor what entities are built from."""
    skipped = []
    for part in model.parts():
        kind = part.split("_")[1] if part.count("_") >= 2 else part
        if kind in _REPRESENTATIONS or kind in ("GeobodyInterpretation",) or "Property" in kind:
            continue
        if any(q in kind or q == f"obj_{kind}" for q in _QUIET):
            continue
        skipped.append(f"RESQML {kind} '{model.citation_title_for_part(part)}'")
    return skipped
