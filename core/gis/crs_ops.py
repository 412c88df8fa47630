"""Coordinate reference systems done with pyproj: parsing, reprojection, and the geopandas bridge.

``pyproj`` (and ``geopandas`` for the bridge) belong to the ``gis`` extra and are imported only
when a function here needs them, so ``import geobrep`` stays light.

- :func:`parse_crs` turns an EPSG code, ``"EPSG:xxxx"``, WKT, a PROJ string or a
  :class:`~geobrep.CRS` into a validated ``pyproj.CRS`` (a compound one when the geobrep CRS
  names a vertical CRS in ``vertical_datum``); :func:`crs_from_user_input` gives the geobrep
  :class:`~geobrep.CRS` with name, EPSG code, WKT, axis names and units, vertical datum.
- :func:`to_crs` reprojects every entity of a scene with ``pyproj.Transformer`` (``always_xy``):
  3D when both CRSs have a vertical axis, otherwise horizontally with z converted between the
  vertical units (``axis_units[2]``, e.g. feet to metres). Properties, ids and topology are kept.
- :func:`to_geodataframe` / :func:`from_geodataframe` bridge to geopandas.

>>> import geobrep
>>> from geobrep.gis.crs_ops import to_crs
>>> cake = geobrep.datasets.faulted_layer_cake()
>>> lonlat = to_crs(cake, "EPSG:4326")
>>> lonlat.crs.epsg, round(float(lonlat["top"].vertices[:, 0].min()), 3)
(4326, 2.091)
"""

from __future__ import annotations

import importlib
import json
import math
from collections.abc import Iterable
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from geobrep.errors import import_optional
from geobrep.model.crs import CRS, CRSError, as_crs
from geobrep.model.entities import (
    Annotation,
    Entity,
    LinearOctree,
    NurbsSurface,
    RegularGrid,
    StructuredGrid,
    VertexEntity,
    Well,
)
from geobrep.model.scene import Scene

if TYPE_CHECKING:
    import pyproj

    from geobrep.demo import DemoContext

__all__ = [
    "CRSError",
    "crs_from_user_input",
    "crs_text",
    "demo_stage",
    "describe_crs",
    "from_geodataframe",
    "parse_crs",
    "to_crs",
    "to_geodataframe",
    "transform_points",
]

#: Lengths of common vertical unit names in metres (``CRS.axis_units[2]`` of a 2D CRS).
UNIT_METRES: dict[str, float] = {
    "m": 1.0,
    "metre": 1.0,
    "meter": 1.0,
    "metres": 1.0,
    "meters": 1.0,
    "km": 1000.0,
    "ft": 0.3048,
    "foot": 0.3048,
    "feet": 0.3048,
    "international foot": 0.3048,
    "ftus": 1200.0 / 3937.0,
    "us-ft": 1200.0 / 3937.0,
    "us survey foot": 1200.0 / 3937.0,
}

#: Short names written into ``CRS.axis_units`` for pyproj's unit names.
_SHORT_UNITS = {
    "metre": "m",
    "foot": "ft",
    "US survey foot": "ftUS",
    "degree": "deg",
    "kilometre": "km",
}


def _pyproj() -> Any:
    return import_optional("pyproj", "gis", "CRS parsing and reprojection")


def _from_text(text: Any, what: str) -> pyproj.CRS:
    lib = _pyproj()
    try:
        parsed: pyproj.CRS = lib.CRS.from_user_input(text)
    except (lib.exceptions.CRSError, TypeError, ValueError) as exc:
        first = (str(exc).splitlines() or [type(exc).__name__])[0]
        raise CRSError(f"{what} {str(text)[:80]!r} is not a valid CRS: {first}") from exc
    return parsed


def parse_crs(value: CRS | str | int | Any) -> pyproj.CRS:
    """A validated ``pyproj.CRS`` from a geobrep CRS or anything ``pyproj.CRS.from_user_input``
    accepts: an EPSG code, ``"EPSG:xxxx"``, WKT, a PROJ string, an ``(authority, code)`` pair,
    a PROJJSON dict, an object with ``to_wkt()``.

    A 2D geobrep CRS whose ``vertical_datum`` names a vertical CRS (``"EPSG:5703"``) becomes a
    compound CRS. Raises :class:`CRSError` when nothing identifies the CRS.

    >>> parse_crs("EPSG:32631").name
    'WGS 84 / UTM zone 31N'
    >>> parse_crs(CRS(epsg=32631, vertical_datum="EPSG:5773")).name
    'WGS 84 / UTM zone 31N + EGM96 height'
    """
    lib = _pyproj()
    if isinstance(value, lib.CRS):
        given: pyproj.CRS = value
        return given
    if isinstance(value, int) and not isinstance(value, bool):
        return _from_text(value, "EPSG code")
    if isinstance(value, str):
        if not value.strip():
            raise CRSError("an empty string is not a CRS")
        return _from_text(value, "CRS")
    if isinstance(value, dict) and set(value) <= set(CRS.model_fields):
        value = as_crs(value)  # the fields of a geobrep CRS
    if not isinstance(value, CRS):
        to_wkt = getattr(value, "to_wkt", None)
        if not isinstance(value, tuple | list | dict) and callable(to_wkt):
            return _from_text(to_wkt(), "CRS")
        if isinstance(value, tuple | list | dict):
            return _from_text(value, "CRS")
        raise CRSError(
            f"expected a CRS, an EPSG code, WKT, a PROJ string or an (authority, code) pair, "
            f"got {type(value).__name__} {str(value)[:60]!r}"
        )
    if value.epsg is not None:
        base = _from_text(f"EPSG:{value.epsg}", "EPSG code")
    elif value.wkt:
        base = _from_text(value.wkt, "WKT")
    elif value.proj:
        base = _from_text(value.proj, "PROJ string")
    elif value.name:
        base = _from_text(value.name, "CRS name")
    else:
        raise CRSError("the CRS is unknown: it has no EPSG code, WKT, PROJ string or name")
    if value.vertical_datum and _vertical_axis(base) is None:
        try:
            vertical = lib.CRS.from_user_input(value.vertical_datum)
        except lib.exceptions.CRSError:
            return base  # a datum name only (e.g. "MSL"): recorded, not a CRS we can use
        if vertical.is_vertical:
            compound: pyproj.CRS = lib.crs.CompoundCRS(
                f"{base.name} + {vertical.name}", [base, vertical]
            )
            return compound
    return base


def _vertical_axis(crs: pyproj.CRS) -> Any | None:
    axes = crs.axis_info
    return axes[2] if len(axes) >= 3 and axes[2].direction in ("up", "down") else None


def _unit_metres(name: str, what: str) -> float:
    factor = UNIT_METRES.get(name.strip().lower())
    if factor is None:
        known = ", ".join(sorted(UNIT_METRES))
        raise CRSError(f"{what}: unknown vertical unit {name!r} (known: {known})")
    return factor


def crs_from_user_input(value: CRS | str | int | Any) -> CRS:
    """The geobrep :class:`~geobrep.CRS` of anything :func:`parse_crs` accepts.

    >>> crs = crs_from_user_input("EPSG:2263+6360")
    >>> crs.axis_units, crs.vertical_datum
    (('ftUS', 'ftUS', 'ftUS'), 'North American Vertical Datum 1988')
    """
    parsed = parse_crs(value)
    axes = parsed.axis_info
    names = [axis.abbrev or axis.name for axis in axes[:3]]
    units = [_SHORT_UNITS.get(axis.unit_name, axis.unit_name) for axis in axes[:3]]
    if len(axes) >= 2 and axes[0].direction in ("north", "south"):
        # geobrep holds x (east) first, as pyproj's always_xy does
        names[:2], units[:2] = names[1::-1], units[1::-1]
    vertical = _vertical_axis(parsed)
    source = value if isinstance(value, CRS) else None
    if vertical is None:
        names.append(source.axis_names[2] if source else "Z")
        units.append(source.axis_units[2] if source else "m")
    datum = None
    if vertical is not None:
        datum = next(
            (sub.datum.name for sub in parsed.sub_crs_list if sub.is_vertical and sub.datum),
            None,
        ) or (parsed.datum.name if parsed.is_vertical and parsed.datum else None)
    elif source is not None:
        datum = source.vertical_datum
    epsg = parsed.to_epsg(min_confidence=90)
    if epsg is not None and not parsed.equals(_from_text(f"EPSG:{epsg}", "EPSG code")):
        epsg = None  # close to an EPSG CRS but not it (other axes or units): keep the WKT
    return CRS(
        name=parsed.name,
        epsg=epsg,
        wkt=None if epsg is not None else parsed.to_wkt(),
        axis_names=(names[0], names[1], names[2]),
        axis_units=(units[0], units[1], units[2]),
        z_positive="down" if vertical is not None and vertical.direction == "down" else "up",
        vertical_datum=datum,
        metadata=dict(source.metadata) if source else {},
    )


def describe_crs(crs: CRS) -> dict[str, Any]:
    """Name, kind, units and vertical datum of a CRS as pyproj reads it (for ``geobrep info``).

    >>> describe_crs(CRS(epsg=32631))["name"]
    'WGS 84 / UTM zone 31N'
    """
    parsed = parse_crs(crs)
    vertical = _vertical_axis(parsed)
    return {
        "name": parsed.name,
        "type": parsed.type_name,
        "units": [axis.unit_name for axis in parsed.axis_info],
        "vertical_units": vertical.unit_name if vertical is not None else crs.axis_units[2],
        "vertical_datum": (
            crs_from_user_input(crs).vertical_datum if vertical is not None else crs.vertical_datum
        ),
        "area_of_use": parsed.area_of_use.name if parsed.area_of_use else None,
    }


# -- point transformation -------------------------------------------------------------------------
class _PointTransform:
    """``(N, 3)`` z-up points in one CRS to another: 3D through PROJ, or 2D plus unit change."""

    def __init__(self, source: CRS, target: CRS) -> None:
        pyproj = _pyproj()
        self.source, self.target = source, target
        src, tgt = parse_crs(source), parse_crs(target)
        src_v, tgt_v = _vertical_axis(src), _vertical_axis(tgt)
        self.three_d = src_v is not None and tgt_v is not None
        # geobrep holds z up: a depth axis ("down") takes -z.
        self.sign_in = -1.0 if src_v is not None and src_v.direction == "down" else 1.0
        self.sign_out = -1.0 if tgt_v is not None and tgt_v.direction == "down" else 1.0
        if self.three_d:
            horizontal_src, horizontal_tgt = src, tgt
            self.z_scale = 1.0
        else:
            horizontal_src = _horizontal(src)
            horizontal_tgt = _horizontal(tgt)
            f_in = src_v.unit_conversion_factor if src_v is not None else _z_unit(source, "source")
            f_out = tgt_v.unit_conversion_factor if tgt_v is not None else _z_unit(target, "target")
            self.z_scale = f_in / f_out
        try:
            self.transformer = pyproj.Transformer.from_crs(
                horizontal_src, horizontal_tgt, always_xy=True
            )
        except pyproj.exceptions.ProjError as exc:
            raise CRSError(f"no transformation from {src.name} to {tgt.name}: {exc}") from exc

    def __call__(self, points: NDArray[np.float64], what: str) -> NDArray[np.float64]:
        xyz = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        if xyz.shape[0] == 0:
            return xyz.copy()
        if self.three_d:
            x, y, z = self.transformer.transform(
                xyz[:, 0], xyz[:, 1], self.sign_in * xyz[:, 2], errcheck=False
            )
            z = self.sign_out * np.asarray(z, dtype=np.float64)
        else:
            x, y = self.transformer.transform(xyz[:, 0], xyz[:, 1], errcheck=False)
            z = xyz[:, 2] * self.z_scale
        out = np.column_stack([x, y, z]).astype(np.float64, copy=False)
        bad = ~np.isfinite(out).all(axis=1)
        if bad.any():
            first = int(np.argmax(bad))
            raise CRSError(
                f"{what}: {int(bad.sum())} point(s) cannot be transformed from "
                f"{self.source.label} to {self.target.label} (first: point {first} at "
                f"{xyz[first].tolist()}); are the coordinates really in {self.source.label}?"
            )
        return out


def _horizontal(crs: pyproj.CRS) -> pyproj.CRS:
    if crs.is_compound:
        return next(sub for sub in crs.sub_crs_list if not sub.is_vertical)
    if len(crs.axis_info) >= 3 and crs.is_geographic:
        return crs.geodetic_crs.to_2d() if crs.geodetic_crs else crs
    return crs


def _z_unit(crs: CRS, what: str) -> float:
    return _unit_metres(crs.axis_units[2], f"{what} CRS {crs.label}")


def transform_points(
    points: NDArray[np.float64], source: CRS | str | int, target: CRS | str | int
) -> NDArray[np.float64]:
    """``(N, 3)`` points (z up) transformed from ``source`` to ``target``.

    >>> pts = np.array([[450_000.0, 6_700_000.0, 10.0]])
    >>> back = transform_points(transform_points(pts, 32631, 4326), 4326, 32631)
    >>> bool(np.abs(back - pts).max() < 1e-6)
    True
    """
    return _PointTransform(_as_crs(source), _as_crs(target))(points, "points")


def _as_crs(value: CRS | str | int | Any, what: str = "CRS") -> CRS:
    """A geobrep CRS with what pyproj knows of it (name, axes), as the target of a transform."""
    if isinstance(value, CRS):
        return value
    if value is None:
        raise CRSError(f"{what}: None is not a CRS")
    if isinstance(value, dict) and set(value) <= set(CRS.model_fields):
        fields = as_crs(value, what)
        assert fields is not None
        return fields
    try:
        return crs_from_user_input(value)
    except CRSError as exc:
        raise CRSError(f"{what}: {exc}") from exc


def _handedness(transform: _PointTransform, scene: Scene) -> float:
    """Sign of the horizontal Jacobian determinant at the scene centre (+1: orientation kept)."""
    bounds = scene.bounds
    if bounds is None:
        return 1.0
    centre = (np.asarray(bounds.mins) + np.asarray(bounds.maxs)) / 2.0
    step = max(float(bounds.diagonal) * 1e-3, 1e-3)
    probe = np.array(
        [centre, centre + np.array([step, 0.0, 0.0]), centre + np.array([0.0, step, 0.0])]
    )
    try:
        moved = transform(probe, "scene centre")
    except CRSError:
        return 1.0  # the centre is outside the projection: the entities will say where
    du, dv = moved[1, :2] - moved[0, :2], moved[2, :2] - moved[0, :2]
    return float(np.sign(du[0] * dv[1] - du[1] * dv[0]))


def _transform_entity(entity: Entity, transform: _PointTransform) -> Entity:
    label = entity.label
    if isinstance(entity, Well):
        moved = transform(np.vstack([entity.head, entity.vertices]), label)
        return entity.replace(head=moved[0], vertices=moved[1:])
    if isinstance(entity, VertexEntity):
        vertices = entity.vertices  # type: ignore[attr-defined]
        return entity.replace(vertices=transform(vertices, label))
    if isinstance(entity, NurbsSurface):
        net = entity.control_points
        moved = transform(net.reshape(-1, 3), label).reshape(net.shape)
        return entity.replace(control_points=moved)
    if isinstance(entity, Annotation):
        size = float(entity.height)
        base = entity.baseline / np.linalg.norm(entity.baseline)
        up = entity.up / np.linalg.norm(entity.up)
        probe = np.array([entity.anchor, entity.anchor + size * base, entity.anchor + size * up])
        moved = transform(probe, label)
        new_base, new_up = moved[1] - moved[0], moved[2] - moved[0]
        return entity.replace(
            anchor=moved[0],
            baseline=new_base / np.linalg.norm(new_base),
            up=new_up / np.linalg.norm(new_up),
            height=float(np.linalg.norm(new_up)),
        )
    if isinstance(entity, StructuredGrid) and entity.points is not None:
        return entity.replace(points=transform(entity.points, label))
    if isinstance(entity, LinearOctree | RegularGrid | StructuredGrid):
        raise CRSError(
            f"{label}: a {type(entity).__name__} is a grid of the source CRS and cannot be "
            "reprojected; reproject its source data and grid it again"
        )
    return entity  # Blocks and other entities without coordinates


def to_crs(
    obj: Scene | Entity | Iterable[Entity],
    target: CRS | str | int,
    *,
    source: CRS | str | int | None = None,
) -> Scene:
    """Reproject every entity of a scene into ``target``; properties, ids and topology are kept.

    ``source`` defaults to ``scene.crs``; a scene without a CRS is refused (:class:`CRSError`).
    The transformation is 3D when both CRSs have a vertical axis (compound or 3D CRSs, with
    their units), otherwise horizontal with z scaled between the vertical units. NURBS control
    points are transformed (exact for affine changes, an approximation otherwise).

    >>> import geobrep
    >>> pts = geobrep.PointSet(vertices=[[450_000.0, 6_700_000.0, 0.0]], name="p")
    >>> scene = geobrep.Scene(entities=[pts], crs=geobrep.CRS(epsg=32631))
    >>> moved = to_crs(scene, "EPSG:32632")
    >>> moved.crs.label, round(float(moved["p"].vertices[0, 0]))
    ('EPSG:32632', 120192)
    """
    scene = (
        obj
        if isinstance(obj, Scene)
        else Scene(entities=[obj] if isinstance(obj, Entity) else list(obj))
    )
    if source is not None:
        source_crs = _as_crs(source, "source CRS")
    elif scene.crs is not None:
        source_crs = scene.crs
    else:
        raise CRSError(
            "the scene's CRS is unknown: set scene.crs (or pass source=) before reprojecting"
        )
    try:
        parse_crs(source_crs)
    except CRSError as exc:
        raise CRSError(f"source CRS: {exc}") from exc
    target_crs = _as_crs(target, "target CRS")
    transform = _PointTransform(source_crs, target_crs)
    if _handedness(transform, scene) < 0:
        raise CRSError(
            f"the transformation from {source_crs.label} to {target_crs.label} mirrors the map "
            "(a left-handed target): surface orientation and block sides would be inverted"
        )
    entities = [_transform_entity(entity, transform) for entity in scene.entities]
    metadata = dict(scene.metadata)
    metadata["reprojected_from"] = source_crs.label
    return scene.replace(entities=tuple(entities), crs=target_crs, metadata=metadata)


# -- geopandas bridge ---------------------------------------------------------------------------
def _geopandas() -> Any:
    return import_optional("geopandas", "gis", "the geopandas bridge")


def crs_text(crs: CRS | None) -> str | None:
    """The text a CRS is handed to GDAL or geopandas as: ``"EPSG:n"`` for a plain EPSG CRS,
    else the WKT pyproj makes of it (a vertical CRS in ``vertical_datum`` compounded in).

    When pyproj cannot read the CRS, the CRS's own WKT or PROJ text as stored: the consumer
    then says why it cannot use it (the GIS writers raise a FormatError, :func:`to_geodataframe`
    a :class:`CRSError`) instead of the CRS silently vanishing from what is written. ``None``
    for no CRS, or one with no text at all (a name pyproj does not know).

    >>> crs_text(CRS(epsg=32631))
    'EPSG:32631'
    >>> crs_text(CRS(wkt='FOO["bar"]'))
    'FOO["bar"]'
    """
    if crs is None:
        return None
    if crs.epsg is not None and not crs.vertical_datum:
        return f"EPSG:{crs.epsg}"
    try:
        return str(parse_crs(crs).to_wkt())
    except CRSError:
        return crs.wkt or crs.proj


def _geodataframe(geopandas: Any, data: Any, crs_value: str | None, **kwargs: Any) -> Any:
    """``geopandas.GeoDataFrame(data, crs=crs_value, ...)``; a CRS it refuses is a CRSError."""
    try:
        return geopandas.GeoDataFrame(data, crs=crs_value, **kwargs)
    except _pyproj().exceptions.CRSError as exc:
        raise CRSError(f"geopandas cannot use the CRS {str(crs_value)[:60]!r}: {exc}") from exc


def to_geodataframe(entities: Scene | Entity | Iterable[Entity], crs: Any = None) -> Any:
    """A ``geopandas.GeoDataFrame``: one row per point, line part, polygon or annotation.

    Columns are those of the GIS writers (``entity_id``, ``entity``, ``entity_type``, ``kind``,
    ``block_id``, ``unit_name``, ``horizon_name``, properties); ``layer`` says which layer a row
    would go to. The CRS is the scene's (or ``crs``: a CRS or anything pyproj accepts).
    Sections in their plane's coordinates (``metadata["section_frame"]``) are in no map CRS:
    alone they give a frame without a CRS, beside other entities they are left out (warning).

    >>> import geobrep
    >>> pts = geobrep.PointSet(vertices=[[1.0, 2.0, 3.0]], point_data={"a": [7.0]}, name="p")
    >>> frame = to_geodataframe(pts)
    >>> frame["a"].tolist(), frame.geometry.iloc[0].has_z
    ([7.0], True)
    """
    from geobrep.gis.feature_tables import entities_to_tables

    geopandas = _geopandas()
    pandas = importlib.import_module("pandas")

    scene = entities if isinstance(entities, Scene) else None
    items: list[Entity]
    if scene is not None:
        items = list(scene.entities)
    elif isinstance(entities, Entity):
        items = [entities]
    else:
        items = list(entities)  # type: ignore[arg-type]
    plane = [e for e in items if "section_frame" in e.metadata]
    only_plane = bool(plane) and len(plane) == len(items)
    if plane and not only_plane:
        import warnings

        from geobrep.gis.feature_tables import FeatureWarning

        layers = sorted({str(e.metadata.get("layer")) for e in plane})
        warnings.warn(
            f"left out {len(plane)} entities in section-plane coordinates (layers "
            f"{', '.join(layers)}): one GeoDataFrame has one CRS; convert them on their own",
            FeatureWarning,
            stacklevel=2,
        )
        items = [e for e in items if "section_frame" not in e.metadata]
    tables = entities_to_tables(items)
    frames = []
    for table in tables.values():
        columns: dict[str, Any] = {"layer": [table.layer] * len(table)}
        for name, values in table.columns.items():
            if np.ma.isMaskedArray(values):
                mask = np.ma.getmaskarray(values)
                data = np.asarray(values.data)
                dtype = {"i": "Int64", "f": "Float64", "b": "boolean"}.get(
                    data.dtype.kind, "object"
                )
                columns[name] = pandas.array(
                    [None if m else v for v, m in zip(data.tolist(), mask.tolist(), strict=True)],
                    dtype=dtype,
                )
            else:
                columns[name] = values
        frames.append(geopandas.GeoDataFrame(columns, geometry=list(table.geometry)))
    crs_value = crs_text(as_crs(crs) if crs is not None else (scene.crs if scene else None))
    if only_plane:
        crs_value = None  # along-section coordinates are in no map CRS
    if not frames:
        return _geodataframe(geopandas, {"layer": []}, crs_value, geometry=[])
    frame = pandas.concat(frames, ignore_index=True)
    return _geodataframe(geopandas, frame, crs_value, geometry="geometry")


def from_geodataframe(
    gdf: Any, z: str | float | None = None, *, layer: str = "layer", name: str | None = None
) -> Scene:
    """A scene from a ``GeoDataFrame``: points → PointSet, lines → PolyLine, polygons → Polygon.

    ``z`` is a column holding z, or a constant z, for 2D geometries (3D geometries keep theirs).
    Numeric columns become properties; a frame from :func:`to_geodataframe` gives back its
    entities (ids, names, kinds, properties).

    >>> import geopandas, shapely
    >>> frame = geopandas.GeoDataFrame({"depth": [12.5]}, geometry=[shapely.Point(1, 2)])
    >>> scene = from_geodataframe(frame, z="depth", name="wells")
    >>> scene["wells"].vertices.tolist()
    [[1.0, 2.0, 12.5]]
    """
    from geobrep.gis.feature_tables import FeatureTable, ReadOptions, tables_to_entities

    _geopandas()
    if "geometry" not in getattr(gdf, "columns", ()) and not hasattr(gdf, "geometry"):
        raise CRSError("from_geodataframe expects a GeoDataFrame")
    geometry = np.asarray(gdf.geometry.values, dtype=object)
    columns: dict[str, NDArray[Any]] = {}
    geometry_name = gdf.geometry.name
    for column in gdf.columns:
        if column == geometry_name:
            continue
        series = gdf[column]
        if series.dtype.kind in "iufb" or str(series.dtype) in ("Int64", "Float64", "boolean"):
            values = (
                series.to_numpy(dtype=np.float64, na_value=np.nan)
                if series.hasnans
                else series.to_numpy()
            )
            columns[str(column)] = np.asarray(values)
        else:
            columns[str(column)] = np.asarray(
                [None if _is_missing(v) else str(v) for v in series.tolist()], dtype=object
            )
    layer_values = columns.pop(layer, None) if layer in columns else None
    groups: dict[str, NDArray[np.int64]]
    if layer_values is not None:
        keys = np.asarray([str(v) for v in layer_values], dtype=object)
        groups = {str(k): np.flatnonzero(keys == k) for k in dict.fromkeys(keys.tolist())}
    else:
        groups = {name or "layer": np.arange(len(geometry))}
    tables = [
        FeatureTable(
            layer=key,
            geometry=geometry[rows],
            columns={c: v[rows] for c, v in columns.items()},
            fids=rows.astype(np.int64),
        )
        for key, rows in groups.items()
    ]
    options = ReadOptions(
        z_field=z if isinstance(z, str) else None,
        z_default=float(z) if isinstance(z, int | float) else None,
    )
    entities = tables_to_entities(tables, options, source="GeoDataFrame")
    crs = crs_from_user_input(gdf.crs.to_wkt()) if gdf.crs is not None else None
    return Scene(entities=entities, crs=crs)


def _is_missing(value: Any) -> bool:
    return value is None or (isinstance(value, float) and math.isnan(value))


# -- demo ---------------------------------------------------------------------------------------
def demo_stage(ctx: DemoContext) -> None:
    """Write block outlines, fault traces and a horizontal section of the model as a GeoPackage,
    read it back, and reproject the model to WGS 84."""
    from geobrep.gis.map_products import map_products
    from geobrep.ops.io import read, write

    scene = ctx.scene
    products = map_products(scene, section_levels=(-150.0,))
    path = ctx.output / "layer_cake_map.gpkg"
    write(products, path)
    again = read(path)
    counts: dict[str, int] = {}
    for entity in again.entities:
        layer = str(entity.metadata.get("layer"))
        counts[layer] = counts.get(layer, 0) + 1
    traces = [e for e in again.polylines if e.metadata.get("layer") == "traces"]
    trace_length = sum(float(t.length) for t in traces)
    lonlat = to_crs(scene, "EPSG:4326")
    bounds = lonlat.bounds
    wgs84 = [round(v, 6) for v in bounds.as_tuple()] if bounds is not None else None
    ctx.summary["gis"] = {
        "file": str(path),
        "crs": again.crs.label if again.crs else None,
        "layers": counts,
        "trace_length_m": trace_length,
        "wgs84_bounds": wgs84,
    }
    listing = ", ".join(f"{name} ({count})" for name, count in sorted(counts.items()))
    ctx.lines.append(
        f"gis: wrote {path.name} ({again.crs.label if again.crs else 'no CRS'}): layers {listing}; "
        f"fault trace {trace_length:.1f} m"
    )
    ctx.lines.append(f"  model in WGS 84 (lon, lat, z): {json.dumps(wgs84)}")
