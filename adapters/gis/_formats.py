"""Readers, writers and sniffers of GeoPackage, GeoJSON and shapefile (pyogrio + shapely 2).

A GeoPackage holds several layers and the full geobrep CRS (in the dataset metadata, beside
GDAL's own CRS); a GeoJSON file holds one FeatureCollection, so several layers are written into
it with a ``layer`` column that the reader splits again; a shapefile holds one layer (choose it
with ``layer=`` when a scene makes several).

Sections in their plane's coordinates (``metadata["section_frame"]``, see
:func:`geobrep.gis.map_products.to_section_plane`) go to GeoPackage layers without a CRS, the frame
in the layer metadata (``geobrep_section_frame``, JSON); GeoJSON and shapefiles cannot say what
such coordinates are, so those entities are left out there with a warning.
"""

from __future__ import annotations

import importlib
import json
import os
import re
import shutil
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray
from pydantic import ConfigDict

from geobrep.adapters._file_format import full_capabilities
from geobrep.adapters.casting import misfit_rows
from geobrep.errors import FormatError, import_optional
from geobrep.gis.feature_tables import (
    RESERVED_COLUMNS,
    FeatureTable,
    FeatureWarning,
    ReadOptions,
    entities_to_tables,
    tables_to_entities,
)
from geobrep.gis.map_products import SECTION_FRAME_KEY
from geobrep.host.registry import FormatSpec
from geobrep.model.crs import CRS
from geobrep.model.scene import Scene
from geobrep.ops.temporaries import temporary_path

__all__ = ["GisOptions", "gis_formats", "looks_like_geojson", "read_gis", "write_gis"]

#: Dataset metadata key of the GeoPackage that keeps the complete geobrep CRS.
CRS_METADATA_KEY = "geobrep_crs"
#: Layer metadata key of a GeoPackage layer in section-plane coordinates (a SectionFrame as JSON).
FRAME_METADATA_KEY = "geobrep_section_frame"
LAYER_COLUMN = "layer"
_GEOMETRY_TYPES = {0: "Point Z", 1: "LineString Z", 2: "LineString Z", 3: "Polygon Z"}
_DRIVERS = {"gpkg": "GPKG", "geojson": "GeoJSON", "shapefile": "ESRI Shapefile"}
_SHAPEFILE_SIDECARS = (".shx", ".dbf", ".prj", ".cpg")
#: Files that belong to one .shp and are replaced with it: its sidecars and spatial indexes
#: (a .qix/.sbn of the old geometry would mislead a reader of the new one).
_SHAPEFILE_REPLACED = (*_SHAPEFILE_SIDECARS, ".qix", ".sbn", ".sbx")


class GisOptions(ReadOptions):
    """``layer``: read only this layer, or write only the entities of this layer.

    ``z_field`` / ``z_default``: z of 2D features, from a column or a constant.
    """

    model_config = ConfigDict(extra="forbid", frozen=True)

    layer: str | None = None


def _pyogrio() -> Any:
    pyogrio = import_optional("pyogrio", "gis", "GIS formats")
    importlib.import_module("pyogrio.raw")  # part of pyogrio: its writer
    # GDAL would leave a ".aux.xml" beside files it only read: GeoPackage keeps its metadata inside
    pyogrio.set_gdal_config_options({"GDAL_PAM_ENABLED": "NO"})
    return pyogrio


def _final_name(path: Path) -> Path:
    """The name the user asked for, from a temporary name of :func:`geobrep.ops.io.atomic_write`."""
    return path.with_name(re.sub(r"^\.(.*)\.tmp-[0-9]+-[0-9a-f]{8}(\.[^.]*)?$", r"\1\2", path.name))


def looks_like_geojson(head: bytes) -> bool:
    """True when the first bytes are a GeoJSON FeatureCollection (for ``.json`` files).

    >>> looks_like_geojson(b'{"type": "FeatureCollection", "features": []}')
    True
    >>> looks_like_geojson(b'{"entities": []}')
    False
    """
    text = head.lstrip(b"\xef\xbb\xbf \t\r\n")
    return (
        text.startswith(b"{") and re.search(rb'"type"\s*:\s*"FeatureCollection"', text) is not None
    )


# -- CRS ----------------------------------------------------------------------------------------
def _crs_for_layer(text: str | None, stored: CRS | None) -> CRS | None:
    if not text:
        return None
    from geobrep.gis.crs_ops import CRSError, crs_from_user_input

    try:
        parsed = crs_from_user_input(text)
    except CRSError as exc:
        warnings.warn(
            f"unknown CRS {text[:60]!r}: {exc}; kept as text", FeatureWarning, stacklevel=4
        )
        return CRS(wkt=text) if "[" in text else CRS(name=text)
    if stored is not None and (stored.epsg is None or stored.epsg == parsed.epsg):
        return stored
    return parsed


_GEOJSON_CRS = re.compile(rb'"crs"\s*:\s*\{.*?"name"\s*:\s*"([^"]+)"', re.DOTALL)


def _geojson_crs(path: Path, crs: CRS | None) -> CRS | None:
    """Check the ``crs`` member of a GeoJSON file ourselves: GDAL silently falls back to
    WGS 84 when it cannot understand it."""
    with path.open("rb") as handle:
        head = handle.read(1 << 16)
    found = _GEOJSON_CRS.search(head)
    if found is None:
        return crs  # RFC 7946: WGS 84 longitude/latitude, as GDAL says
    declared = found.group(1).decode("utf-8", "replace")
    from geobrep.gis.crs_ops import CRSError, crs_from_user_input

    try:
        return crs_from_user_input(declared)
    except CRSError as exc:
        warnings.warn(
            f"{path}: the CRS {declared!r} is unknown ({exc}); the scene has no CRS",
            FeatureWarning,
            stacklevel=4,
        )
        return None


def _stored_crs(info: dict[str, Any]) -> CRS | None:
    metadata = info.get("dataset_metadata") or {}
    text = metadata.get(CRS_METADATA_KEY)
    if not text:
        return None
    try:
        return CRS.model_validate(json.loads(text))
    except (ValueError, TypeError):
        return None


# -- reading ------------------------------------------------------------------------------------
def _shapefile_columns(columns: dict[str, NDArray[Any]]) -> dict[str, NDArray[Any]]:
    """Undo the 10-character truncation of shapefile field names for geobrep's own columns."""
    full = {name[:10]: name for name in (*RESERVED_COLUMNS, LAYER_COLUMN) if len(name) > 10}
    return {full.get(name, name): values for name, values in columns.items()}


def _read_layer(path: Path, layer: str, driver: str) -> tuple[list[FeatureTable], str | None]:
    pyogrio = _pyogrio()
    if driver == "ESRI Shapefile" and path.suffix.lower() == ".shp":
        check_shapefile_set(path)
    meta, fids, geometry, field_data = pyogrio.raw.read(path, layer=layer, return_fids=True)
    columns = {str(name): values for name, values in zip(meta["fields"], field_data, strict=True)}
    if driver == "ESRI Shapefile":
        columns = _shapefile_columns(columns)
    geometry = np.asarray(geometry, dtype=object)
    fids = np.asarray(fids, dtype=np.int64)
    split = columns.pop(LAYER_COLUMN, None) if driver == "GeoJSON" else None
    if split is None or np.asarray(split).dtype != object:
        if split is not None:
            columns[LAYER_COLUMN] = split
        return [FeatureTable(layer=layer, geometry=geometry, columns=columns, fids=fids)], meta.get(
            "crs"
        )
    names = np.asarray([layer if v is None else str(v) for v in split.tolist()], dtype=object)
    integer = {str(n) for n, t in zip(meta["fields"], meta["dtypes"], strict=True) if "int" in t}
    tables = []
    for name in dict.fromkeys(names.tolist()):
        rows = np.flatnonzero(names == name)
        tables.append(
            FeatureTable(
                layer=str(name),
                geometry=geometry[rows],
                columns=_layer_columns(columns, rows, integer),
                fids=fids[rows],
            )
        )
    return tables, meta.get("crs")


def _layer_columns(
    columns: dict[str, NDArray[Any]], rows: NDArray[np.int64], integer: set[str]
) -> dict[str, NDArray[Any]]:
    """The columns of one layer of a merged GeoJSON file: other layers' columns dropped, and
    integer columns that GDAL widened to float (nulls elsewhere) made integer again."""
    result: dict[str, NDArray[Any]] = {}
    for name, column in columns.items():
        values = column[rows]
        if values.dtype == object:
            if all(v is None for v in values.tolist()):
                continue
        elif values.dtype.kind == "f":
            finite = np.isfinite(values)
            if not finite.any():
                continue
            if name in integer and finite.all() and not misfit_rows(values, np.int64).any():
                values = values.astype(np.int64)
        result[name] = values
    return result


def read_gis(path: Path, options: GisOptions, driver: str) -> Scene:
    """Read every layer (or ``options.layer``) of a GIS vector file into a scene."""
    try:
        return _read_gis(path, options, driver)
    except UnicodeDecodeError as exc:  # GDAL hands on field names or values that are not UTF-8
        raise FormatError(f"not a readable {driver} file: text is not UTF-8 ({exc})", path) from exc
    except Exception as exc:
        if not type(exc).__module__.startswith("pyogrio"):
            raise
        # GDAL finds the file corrupt while reading features (older pyogrio names some of
        # these errors CRSError): say so, with the file
        raise FormatError(f"not a readable {driver} file: {exc}", path) from exc


def _read_gis(path: Path, options: GisOptions, driver: str) -> Scene:
    pyogrio = _pyogrio()
    try:
        listed = pyogrio.list_layers(path)
    except Exception as exc:  # GDAL cannot open it: say which file
        raise FormatError(f"not a readable {driver} file: {exc}", path) from exc
    names = [str(row[0]) for row in listed]
    if options.layer is not None and options.layer not in names and driver != "GeoJSON":
        raise FormatError(f"no layer {options.layer!r} (layers: {', '.join(names)})", path)
    stored = _stored_crs(pyogrio.read_info(path, layer=names[0])) if names else None
    tables: list[FeatureTable] = []
    crs_by_layer: dict[str, str | None] = {}
    frames: dict[str, Any] = {}
    for name in names:
        if options.layer is not None and driver != "GeoJSON" and name != options.layer:
            continue
        frame = _layer_frame(path, name) if driver == "GPKG" else None
        layer_tables, crs_text = _read_layer(path, name, driver)
        for table in layer_tables:
            if options.layer is not None and table.layer != options.layer:
                continue
            tables.append(table)
            if frame is not None:
                frames[table.layer] = frame  # section-plane coordinates: no CRS, by design
            else:
                crs_by_layer[table.layer] = crs_text
    if options.layer is not None and not tables:
        raise FormatError(f"no layer {options.layer!r}", path)
    known = {text for text in crs_by_layer.values() if text}
    missing = sorted(name for name, text in crs_by_layer.items() if not text)
    if len(known) > 1:
        listing = "; ".join(f"{n}: {t[:40] if t else 'none'}" for n, t in crs_by_layer.items())
        raise FormatError(
            f"layers have different CRSs ({listing}): read them one at a time with layer=", path
        )
    if missing:
        warnings.warn(
            f"{path}: layer(s) {', '.join(repr(m) for m in missing)} have no CRS: the CRS is "
            "unknown (set scene.crs before reprojecting)",
            FeatureWarning,
            stacklevel=3,
        )
    crs = _crs_for_layer(next(iter(known)), stored) if known else None
    if driver == "GeoJSON":
        crs = _geojson_crs(path, crs)
    entities = tables_to_entities(tables, options, source=str(path))
    if frames:
        entities = [
            e.replace(metadata={**e.metadata, SECTION_FRAME_KEY: frames[str(e.metadata["layer"])]})
            if e.metadata.get("layer") in frames
            else e
            for e in entities
        ]
    return Scene(entities=entities, crs=crs, name=path.stem)


def _layer_frame(path: Path, layer: str) -> Any:
    """The section frame a GeoPackage layer's metadata holds, or None."""
    from geobrep.gis.map_products import SectionFrame

    info = _pyogrio().read_info(path, layer=layer)
    text = (info.get("layer_metadata") or {}).get(FRAME_METADATA_KEY)
    if not text:
        return None
    try:
        return SectionFrame.model_validate(json.loads(text)).model_dump(mode="json")
    except (ValueError, TypeError) as exc:
        raise FormatError(f"layer {layer!r}: unreadable {FRAME_METADATA_KEY}: {exc}", path) from exc


# -- writing ------------------------------------------------------------------------------------
def _geometry_type(table: FeatureTable) -> str:
    shapely = importlib.import_module("shapely")
    types = set(shapely.get_type_id(table.geometry).tolist())
    return _GEOMETRY_TYPES[min(types)] if len(types) == 1 else "Unknown"


def _fields(
    columns: dict[str, NDArray[Any]],
) -> tuple[list[NDArray[Any]], list[str], list[NDArray[np.bool_] | None]]:
    data: list[NDArray[Any]] = []
    names: list[str] = []
    masks: list[NDArray[np.bool_] | None] = []
    for name, values in columns.items():
        names.append(name)
        if np.ma.isMaskedArray(values):
            mask = np.ma.getmaskarray(values)
            data.append(np.asarray(values.data))
            masks.append(mask)
        else:
            data.append(np.asarray(values))
            masks.append(None)
    return data, names, masks


def _merged_for_single_layer(tables: list[FeatureTable]) -> FeatureTable:
    from geobrep.gis.feature_tables import merge_columns

    pieces = [
        (len(t), {LAYER_COLUMN: np.full(len(t), t.layer, dtype=object), **t.columns})
        for t in tables
    ]
    return FeatureTable(
        layer=tables[0].layer if len(tables) == 1 else "layers",
        geometry=np.concatenate([t.geometry for t in tables]),
        columns=merge_columns(pieces),
    )


def _write_tables(
    tables: list[FeatureTable],
    path: Path,
    driver: str,
    crs: CRS | None,
    frames: dict[str, str] | None = None,
) -> None:
    from geobrep.gis.crs_ops import crs_text

    pyogrio = _pyogrio()
    shapely = importlib.import_module("shapely")
    text = crs_text(crs)
    for position, table in enumerate(tables):
        data, names, masks = _fields(table.columns)
        kwargs: dict[str, Any] = {}
        if driver == "GPKG" and position == 0 and crs is not None:
            kwargs["dataset_metadata"] = {CRS_METADATA_KEY: crs.model_dump_json()}
        frame = (frames or {}).get(table.layer)
        if frame is not None:
            kwargs["layer_metadata"] = {FRAME_METADATA_KEY: frame}
        if driver == "GeoJSON":
            kwargs["layer_options"] = {"WRITE_NAME": "YES", "SIGNIFICANT_FIGURES": "17"}
        with warnings.catch_warnings():
            warnings.filterwarnings("ignore", message=".*[Nn]ormalized/laundered.*")
            warnings.filterwarnings("ignore", message=".*truncated.*")
            warnings.filterwarnings("ignore", message=".*'crs' was not provided.*")
            _raw_write(
                pyogrio,
                path,
                shapely.to_wkb(table.geometry, include_srid=False, output_dimension=3),
                data,
                names,
                field_mask=masks if any(m is not None for m in masks) else None,
                layer=table.layer,
                driver=driver,
                geometry_type=_geometry_type(table),
                crs=text if frame is None else None,
                append=position > 0,
                promote_to_multi=False,
                **kwargs,
            )


#: What GDAL's (and SQLite's) messages mean, in words; the first that matches is said.
_WRITE_FAILURES = (
    (("readonly database", "read-only", "read only"), "the file or its folder is read-only"),
    (("disk is full", "no space left"), "the disk is full"),
    (("database is locked",), "the file is locked by another program"),
    (("disk i/o error", "input/output error"), "the disk reported an input/output error"),
    (
        ("unable to open database", "no such file", "permission denied", "failed to create"),
        "the file cannot be created in its folder (is the folder writable?)",
    ),
)
_DRIVER_NAMES = {"GPKG": "GeoPackage", "GeoJSON": "GeoJSON", "ESRI Shapefile": "shapefile"}


def _raw_write(pyogrio: Any, path: Path, *args: Any, **kwargs: Any) -> None:
    """``pyogrio.raw.write``; a GDAL/SQLite failure is a FormatError saying what happened."""
    try:
        pyogrio.raw.write(path, *args, **kwargs)
    except Exception as exc:
        if not type(exc).__module__.startswith("pyogrio"):
            raise
        text = str(exc)
        kind = _DRIVER_NAMES.get(kwargs.get("driver", ""), "GIS")
        for needles, words in _WRITE_FAILURES:
            if any(needle in text.lower() for needle in needles):
                raise FormatError(f"cannot write the {kind} file: {words}", path) from exc
        detail = re.sub(r"sqlite3_\w+\([^)]*\)\s*(failed:?)?\s*", "", text).strip()
        raise FormatError(
            f"cannot write layer {kwargs.get('layer')!r} of the {kind} file: "
            f"{detail or type(exc).__name__}",
            path,
        ) from exc


def _shapefile_write(table: FeatureTable, path: Path, crs: CRS | None) -> None:
    """Write a shapefile set: ``path`` is the (temporary) .shp; sidecars get the final stem.

    The set is written whole into a staging folder beside the target, then put in place so that
    a reader opening the .shp finds the old set, the new set, or no .shp at all: the old .shp
    goes first (into the staging folder), then the new sidecars replace the old ones (and old
    sidecars the new set lacks are removed), and the new .shp comes last (``atomic_write``
    renames ``path`` onto it). See docs/security.md, "Interrupted writes".
    """
    final = _final_name(path)
    long_names = [n for n in table.columns if len(n) > 10 and n not in RESERVED_COLUMNS]
    if long_names:
        warnings.warn(
            f"{final}: shapefile field names are cut to 10 characters: {', '.join(long_names)}",
            FeatureWarning,
            stacklevel=4,
        )
    folder = temporary_path(final, ".set")
    folder.mkdir()
    try:
        staging = folder / f"{final.stem}.shp"
        _write_tables([table], staging, "ESRI Shapefile", crs)
        _replace_set(staging, final, folder)
        os.replace(staging, path)
    finally:
        shutil.rmtree(folder, ignore_errors=True)


def _replace_set(staging: Path, final: Path, folder: Path) -> None:
    """Take the old .shp away, then put the new sidecars (and only them) beside ``final``."""
    if final.exists():
        os.replace(final, folder / "replaced.shp")
    for sidecar in _SHAPEFILE_REPLACED:
        produced = staging.with_suffix(sidecar)
        target = final.with_suffix(sidecar)
        if produced.exists():
            os.replace(produced, target)
        elif target.exists():
            target.unlink()  # the old set's: it would pair with the new .shp


def check_shapefile_set(path: Path) -> None:
    """Refuse a shapefile whose .shp, .shx and .dbf do not describe the same records.

    Catches a set mixed from two writes (by a tool that does not replace sets whole, or a
    reader racing a replacement): the .shp length in its header, the .shx index and the .dbf
    record count must agree. A missing .shx or .dbf is left to GDAL.

    Raises:
        FormatError: naming the files that disagree.
    """
    index, table = path.with_suffix(".shx"), path.with_suffix(".dbf")
    if not (path.is_file() and index.is_file() and table.is_file()):
        return
    with path.open("rb") as shp, index.open("rb") as shx, table.open("rb") as dbf:
        shp_words = _big_int(shp.read(100), 24)
        shx_head = shx.read(100)
        shx_records = (_big_int(shx_head, 24) * 2 - 100) // 8
        dbf_head = dbf.read(8)
        dbf_records = int.from_bytes(dbf_head[4:8], "little") if len(dbf_head) == 8 else -1
        if shx_records > 0:
            shx.seek(100 + 8 * (shx_records - 1))
            last = shx.read(8)
            shp_end = (_big_int(last, 0) + _big_int(last, 4)) * 2 + 8 if len(last) == 8 else -1
        else:
            shp_end = 100
    size = path.stat().st_size
    if shp_words * 2 != size or shx_records != dbf_records or shp_end != size:
        raise FormatError(
            f"the shapefile set does not fit together ({path.name}: {size} bytes, its header "
            f"says {shp_words * 2}; {index.name}: {shx_records} records ending at byte "
            f"{shp_end}; {table.name}: {dbf_records} records): a mix of two writes?",
            path,
        )


def _big_int(data: bytes, offset: int) -> int:
    chunk = data[offset : offset + 4]
    return int.from_bytes(chunk, "big", signed=True) if len(chunk) == 4 else -1


def _plane_frames(
    scene: Scene, tables: list[FeatureTable], path: Path, driver: str
) -> tuple[list[FeatureTable], dict[str, str]]:
    """The section frame (JSON) of each table in section-plane coordinates; GeoJSON and
    shapefile tables of such entities are left out with a warning (no place for the frame)."""
    frames = {
        int(e.id or 0): json.dumps(e.metadata[SECTION_FRAME_KEY], sort_keys=True)
        for e in scene.entities
        if SECTION_FRAME_KEY in e.metadata
    }
    if not frames:
        return tables, {}
    kept: list[FeatureTable] = []
    by_layer: dict[str, str] = {}
    dropped: list[str] = []
    for table in tables:
        ids = np.asarray(table.columns["entity_id"]).tolist()
        found = {frames[i] for i in ids if i in frames}
        if not found:
            kept.append(table)
            continue
        if len(found) > 1 or any(i not in frames for i in ids):
            raise FormatError(
                f"layer {table.layer!r} mixes world coordinates and section-plane coordinates "
                "(or several section planes): give each section plane its own layer",
                path,
            )
        if driver != "GPKG":
            dropped.append(table.layer)
            continue
        by_layer[table.layer] = found.pop()
        kept.append(table)
    if dropped and not kept:
        raise FormatError(
            f"layer(s) {', '.join(repr(d) for d in dropped)} are in section-plane coordinates: "
            f"{driver} cannot store their frame (write a GeoPackage)",
            path,
        )
    if dropped:
        warnings.warn(
            f"{_final_name(path)}: left out layer(s) {', '.join(repr(d) for d in dropped)} in "
            f"section-plane coordinates: {driver} cannot store their frame (write a GeoPackage)",
            FeatureWarning,
            stacklevel=4,
        )
    return kept, by_layer


def write_gis(scene: Scene, path: Path, options: GisOptions, driver: str) -> None:
    """Write the scene's points, lines, polygons and annotations as layers."""
    tables = list(entities_to_tables(scene.entities).values())
    if options.layer is not None:
        tables = [t for t in tables if t.layer == options.layer]
        if not tables:
            raise FormatError(f"the scene has no entities for layer {options.layer!r}", path)
    tables, frames = _plane_frames(scene, tables, path, driver)
    if not tables:
        raise FormatError(
            "nothing to write: GIS layers hold PointSets, PolyLines, Polygons and Annotations",
            path,
        )
    if scene.crs is None:
        warnings.warn(
            f"{_final_name(path)}: the scene has no CRS; the layers are written without one",
            FeatureWarning,
            stacklevel=3,
        )
    if driver == "GeoJSON":
        _write_tables([_merged_for_single_layer(tables)], path, driver, scene.crs)
    elif driver == "ESRI Shapefile":
        if len(tables) > 1:
            names = ", ".join(t.layer for t in tables)
            raise FormatError(
                f"a shapefile holds one layer, the scene makes {len(tables)} ({names}): "
                "choose one with layer=",
                path,
            )
        _shapefile_write(tables[0], path, scene.crs)
    else:
        _write_tables(tables, path, driver, scene.crs, frames)


def _reader(driver: str) -> Any:
    def read(path: Path, options: GisOptions) -> Scene:
        return read_gis(path, options, driver)

    return read


def _writer(driver: str) -> Any:
    def write(scene: Scene, path: Path, options: GisOptions) -> None:
        write_gis(scene, path, options, driver)

    return write


def _looks_like_geopackage(head: bytes) -> bool:
    return head.startswith(b"SQLite format 3\x00") and b"GPKG" in head[60:72]


def _losses(scene: Scene, path: Path) -> list[str]:
    """Vector properties become one attribute column per component (read back as such)."""
    split = sorted(
        {
            f"{name} ({name}_0 ... {name}_{prop.values.shape[1] - 1})"
            for entity in scene.entities
            for name, prop in [*entity.point_data.items(), *entity.cell_data.items()]
            if prop.values.ndim > 1
        }
    )
    if not split:
        return []
    return [f"vector properties written as one column per component: {', '.join(split)}"]


def gis_formats() -> list[FormatSpec]:
    """The three GIS format specs."""
    capabilities = full_capabilities({"PointSet", "PolyLine", "Polygon", "Annotation"})
    formats: tuple[tuple[str, str, str, Callable[[bytes], bool] | None], ...] = (
        (
            "gpkg",
            ".gpkg",
            "OGC GeoPackage: layers of points, lines, polygons with attributes",
            _looks_like_geopackage,
        ),
        (
            "geojson",
            ".geojson",
            "GeoJSON FeatureCollection (.geojson, or .json by content)",
            looks_like_geojson,
        ),
        ("shapefile", ".shp", "ESRI shapefile (.shp with .shx, .dbf, .prj): one layer", None),
    )
    return [
        FormatSpec(
            name=name,
            description=description,
            extensions=(extension,),
            reader=_reader(_DRIVERS[name]),
            writer=_writer(_DRIVERS[name]),
            sniff=sniff,
            options=GisOptions,
            capabilities=capabilities,
            losses=_losses,
        )
        for name, extension, description, sniff in formats
    ]
