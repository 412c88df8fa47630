"""A scene as a RESQML 2.0.1 model written through resqpy: an ``.epc`` with its ``.h5``.

Surfaces are TriangulatedSetRepresentations, point sets PointSetRepresentations, polylines
PolylineSetRepresentations, each in one LocalDepth3dCrs and representing the interpretation of
a feature of its kind (horizon, fault, boundary); blocks are geobody features and
interpretations whose sides name the surfaces' patches. Properties are continuous or discrete
properties on nodes or faces.
"""

from __future__ import annotations

import os
import shutil
import warnings
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from geobrep.adapters.resqml._records import RECORD_KEY, encode_record, entity_record, scene_record
from geobrep.errors import FormatError, OptionsError
from geobrep.model.crs import CRS
from geobrep.model.entities import Block, Entity, PointSet, PolyLine, Surface
from geobrep.model.properties import PropertyMap
from geobrep.model.scene import Scene
from geobrep.ops.temporaries import parse_temporary, replace_file, temporary_path

__all__ = ["PATCH_PROPERTY", "write_resqml"]

PATCH_PROPERTY = "geobrep patch label"
"""Title of the discrete face property holding a surface's patch labels."""

#: geobrep surface kind -> (resqpy feature class, feature kind, interpretation class).
_INTERPRETATIONS = {
    "horizon": ("GeneticBoundaryFeature", "horizon", "HorizonInterpretation"),
    "fault": ("TectonicBoundaryFeature", "fault", "FaultInterpretation"),
    "boundary": ("BoundaryFeature", None, "BoundaryFeatureInterpretation"),
}


def _final_names(path: Path) -> tuple[Path, str]:
    """The folder and stem of the file the caller means (the temporary's final name)."""
    parsed = parse_temporary(path.name)
    return path.parent, (parsed[1] if parsed is not None else path.stem)


def write_resqml(scene: Scene, path: Path, offset: tuple[float, float, float] | None) -> None:
    """Write ``scene`` as ``path`` (the .epc) and the .h5 beside it under the final stem.

    Both files are written in a temporary folder; the .h5 is renamed into place first and the
    .epc last, so the .epc never names data that is not there yet.
    """
    import resqpy.model as rq

    folder, stem = _final_names(path)
    work = temporary_path(folder / stem, suffix="")
    work.mkdir()
    try:
        model = rq.new_model(str(work / f"{stem}.epc"))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # resqpy's notes on local property kinds
            _fill_model(model, scene, offset)
            model.store_epc()
        replace_file(work / f"{stem}.h5", folder / f"{stem}.h5")
        os.replace(work / f"{stem}.epc", path)
        work.rmdir()  # empty now
    finally:
        if work.exists():
            shutil.rmtree(work, ignore_errors=True)


def _fill_model(model: Any, scene: Scene, offset: tuple[float, float, float] | None) -> None:
    crs = _write_crs(model, scene, offset)
    frame = _Frame(scene.crs, offset)
    uuids: dict[int, str] = {}
    for entity in scene.entities:
        if isinstance(entity, Surface):
            uuids[int(entity.id or 0)] = _write_surface(model, crs, frame, entity)
        elif isinstance(entity, PointSet):
            _write_point_set(model, crs, frame, entity)
        elif isinstance(entity, PolyLine):
            _write_polyline(model, crs, frame, entity)
    patches = scene.topology.patch_by_id
    for block in scene.of_type(Block):
        _write_block(model, block, patches, uuids)


class _Frame:
    """World coordinates (z up) to the local CRS: depth if the source's z pointed down, minus
    the offset, exactly (an offset that would change a coordinate is refused)."""

    def __init__(self, crs: CRS | None, offset: tuple[float, float, float] | None) -> None:
        self.z_down = crs is not None and crs.z_positive == "down"
        self.offset = np.zeros(3) if offset is None else np.asarray(offset, dtype=np.float64)

    def local(self, vertices: NDArray[np.float64], label: str) -> NDArray[np.float64]:
        """The local coordinates of ``vertices`` (``vertices`` itself when nothing changes:
        resqpy copies what it is given)."""
        points = np.asarray(vertices, dtype=np.float64)
        if self.z_down:
            points = points * np.array([1.0, 1.0, -1.0])
        axes = np.flatnonzero(self.offset)  # a zero offset is not applied: -0.0 stays -0.0
        if not len(axes):
            return points
        local = points.copy()
        local[:, axes] -= self.offset[axes]
        restored = local[:, axes] + self.offset[axes]
        if not np.array_equal(restored.view(np.uint64), points[:, axes].view(np.uint64)):
            raise OptionsError(
                f"offset {tuple(self.offset.tolist())} would change coordinates of {label} "
                "(choose an origin near the data, e.g. whole metres below its minimum)"
            )
        return local


def _write_crs(model: Any, scene: Scene, offset: tuple[float, float, float] | None) -> Any:
    import resqpy.crs as rqc

    crs = scene.crs or CRS()
    ox, oy, oz = offset or (0.0, 0.0, 0.0)
    local = rqc.Crs(
        model,
        x_offset=float(ox),
        y_offset=float(oy),
        z_offset=float(oz),
        xy_units=_length_uom(crs.axis_units[0]),
        z_units=_length_uom(crs.axis_units[2]),
        z_inc_down=crs.z_positive == "down",
        epsg_code=None if crs.epsg is None else str(crs.epsg),
        title=crs.name or crs.label,
        extra_metadata={RECORD_KEY: encode_record(scene_record(scene))},
    )
    local.create_xml()
    return local


def _length_uom(unit: str) -> str:
    from resqpy.weights_and_measures import valid_uoms

    if unit in valid_uoms(quantity="length"):
        return unit
    raise FormatError(f"axis unit {unit!r} is not a RESQML length unit of measure")


def _interpretation(model: Any, entity: Entity) -> Any:
    """The root of the interpretation ``entity`` represents (None: no kind RESQML names)."""
    import resqpy.organize as rqo

    known = _INTERPRETATIONS.get(entity.kind or "")
    if known is None:
        return None
    feature_class, feature_kind, interpretation_class = known
    name = entity.name or entity.label
    extra = {} if feature_kind is None else {"kind": feature_kind}
    feature = getattr(rqo, feature_class)(model, feature_name=name, **extra)
    feature.create_xml()
    link = {
        "HorizonInterpretation": "genetic_boundary_feature",
        "FaultInterpretation": "tectonic_boundary_feature",
        "BoundaryFeatureInterpretation": "boundary_feature",
    }[interpretation_class]
    interpretation = getattr(rqo, interpretation_class)(model, title=name, **{link: feature})
    interpretation.create_xml()
    return interpretation.root


def _extra(entity: Entity) -> dict[str, str]:
    return {RECORD_KEY: encode_record(entity_record(entity))}


def _write_surface(model: Any, crs: Any, frame: _Frame, surface: Surface) -> str:
    import resqpy.surface as rqs

    if surface.faces.shape[1] != 3:
        raise FormatError(
            f"{surface.label}: RESQML triangulated sets hold triangles; triangulate its quads"
        )
    rep = rqs.Surface(
        model,
        crs_uuid=crs.uuid,
        title=surface.name or surface.label,
        extra_metadata=_extra(surface),
    )
    rep.set_from_triangles_and_points(
        np.asarray(surface.faces, dtype=np.int64), frame.local(surface.vertices, surface.label)
    )
    interpretation = _interpretation(model, surface)
    if interpretation is not None:
        rep.set_represented_interpretation_root(interpretation)
    rep.write_hdf5()
    rep.create_xml()
    cells: dict[str, Any] = dict(surface.cell_data)
    if surface.patch_labels is not None:
        cells[PATCH_PROPERTY] = np.asarray(surface.patch_labels)
    _write_properties(rep, surface.point_data, PropertyMap(cells), "faces")
    return str(rep.uuid)


def _write_point_set(model: Any, crs: Any, frame: _Frame, points: PointSet) -> None:
    import resqpy.surface as rqs

    rep = rqs.PointSet(
        model,
        crs_uuid=crs.uuid,
        points_array=frame.local(points.vertices, points.label),
        title=points.name or points.label,
        extra_metadata=_extra(points),
    )
    rep.represented_interpretation_root = _interpretation(model, points)
    rep.write_hdf5()
    rep.create_xml()
    _write_properties(rep, points.point_data, PropertyMap(), "nodes")


def _write_polyline(model: Any, crs: Any, frame: _Frame, line: PolyLine) -> None:
    import resqpy.lines as rql

    coordinates = frame.local(line.vertices[line.indices], line.label)
    offsets = np.asarray(line.part_offsets)
    title = line.name or line.label
    parts = [  # resqpy builds a set from one object per part (parts are few)
        rql.Polyline(
            model,
            set_coord=coordinates[start:end],
            set_crs=crs.uuid,
            is_closed=bool(closed),
            title=f"{title} part {index}",
        )
        for index, (start, end, closed) in enumerate(
            zip(offsets[:-1], offsets[1:], line.closed, strict=True)
        )
    ]
    rep = rql.PolylineSet(
        model, polylines=parts, crs_uuid=crs.uuid, title=title, extra_metadata=_extra(line)
    )
    rep.rep_int_root = _interpretation(model, line)
    rep.write_hdf5()
    rep.create_xml()
    _write_properties(rep, line.point_data, line.cell_data, "intervals")


def _write_properties(rep: Any, nodes: PropertyMap, cells: PropertyMap, cell_element: str) -> None:
    """Every property of ``rep``: continuous (floats) or discrete (integers, booleans)."""
    import resqpy.property as rqp
    from resqpy.weights_and_measures import valid_uoms

    if not nodes and not cells:
        return
    units = set(valid_uoms())
    collection = rqp.PropertyCollection()
    collection.set_support(support=rep)
    for element, props in (("nodes", nodes), (cell_element, cells)):
        for name, prop in props.items():
            values = np.asarray(prop.values)
            discrete = values.dtype.kind in "biu"
            if values.dtype.kind == "b":
                values = values.astype(np.int8)
            unit = prop.unit if prop.unit in units else None
            collection.add_cached_array_to_imported_list(
                values,
                "geobrep",
                name,
                discrete=discrete,
                uom=None if discrete else (unit or "Euc"),
                property_kind="discrete" if discrete else "continuous",
                indexable_element=element,
                count=int(np.prod(values.shape[1:])) if values.ndim > 1 else 1,
            )
    collection.write_hdf5_for_imported_list(use_int32=False)
    collection.create_xml_for_imported_list_and_add_parts_to_model()


def _write_block(
    model: Any, block: Block, patches: dict[int, Any], surfaces: dict[int, str]
) -> None:
    """A geobody feature and interpretation; the sides as (surface uuid, patch label, side)."""
    import resqpy.organize as rqo

    sides = []
    for patch_id, side in block.sides:
        patch = patches.get(patch_id)
        if patch is not None and patch.surface in surfaces:
            sides.append([surfaces[patch.surface], patch.label, side])
    extra = {
        RECORD_KEY: encode_record({**entity_record(block), "block": block.model_dump(mode="json")}),
        "geobrep_sides": encode_record(sides),
    }
    name = block.name or block.label
    feature = rqo.GeobodyFeature(model, feature_name=name)
    feature.create_xml()
    interpretation = rqo.GeobodyInterpretation(
        model, title=name, geobody_feature=feature, extra_metadata=extra
    )
    interpretation.create_xml()
