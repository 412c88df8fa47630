"""GeoTIFF / DEM rasters through rasterio, read as a surface or a grid and written back.

Reading (``raster_as``):

* ``"surface"`` (default): a vertex at the centre of every valid pixel, z its value in band
  ``band``, two triangles per square of four pixel centres (each kept when its three corners are
  valid, so no-data pixels leave open holes): a DEM sampled where its values are stated;
* ``"pixels"``: one flat quad (z = 0) per valid pixel on the pixel corners, the band values as
  cell data: the reference reader's layout (one polygon per pixel);
* ``"grid"``: a :class:`~geobrep.RegularGrid` of one layer whose cells are the pixels (``u`` one
  column, ``v`` one row, ``w`` 1 unit up), the bands as cell data.

Every band is a property (named by its description, else ``band_<n>``) in its own dtype, with
the raster's no-data value. The CRS is the raster's. ``metadata["raster"]`` keeps the lattice
(width, height, affine transform, sampling, band names) so the writer puts each value back in
its pixel.
"""

from __future__ import annotations

import warnings
from pathlib import Path
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray
from pydantic import BaseModel, ConfigDict, Field

from geobrep.adapters.limits import check_declared
from geobrep.errors import FormatError, import_optional
from geobrep.model.crs import CRS
from geobrep.model.entities import Entity, RegularGrid, Surface
from geobrep.model.properties import Property
from geobrep.model.scene import Scene

__all__ = [
    "RasterOptions",
    "RasterWarning",
    "affine_of",
    "looks_like_tiff",
    "raster_crs",
    "read_raster",
]


class RasterWarning(UserWarning):
    """What a raster layout or a GeoTIFF cannot hold."""


class RasterOptions(BaseModel):
    """Reading a raster: what it becomes (``raster_as``) and which band gives z (``band``)."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    raster_as: Literal["surface", "pixels", "grid"] = "surface"
    """``surface``: pixel-centre vertices, z from ``band``, a regular triangulation;
    ``pixels``: one flat quad per pixel with the bands as cell data; ``grid``: a one-layer
    RegularGrid whose cells are the pixels."""
    band: int = Field(default=1, ge=1)
    """The band (1-based) whose values are the surface's z."""


def looks_like_tiff(head: bytes) -> bool:
    """True for a TIFF or BigTIFF signature."""
    return head[:4] in (b"II*\0", b"MM\0*", b"II+\0", b"MM\0+")


def _rasterio() -> Any:
    rasterio = import_optional("rasterio", "gis", "GeoTIFF rasters")
    return rasterio


def raster_crs(crs: Any) -> CRS | None:
    """A geobrep CRS of a rasterio CRS (its EPSG code when it has one, and its WKT)."""
    if crs is None or not crs.to_wkt():
        return None
    epsg = crs.to_epsg()
    return CRS(epsg=epsg, wkt=crs.to_wkt(), name=None)


def affine_of(transform: Any) -> list[float]:
    """``[a, b, c, d, e, f]``: x = a·col + b·row + c, y = d·col + e·row + f."""
    return [float(v) for v in tuple(transform)[:6]]


def _bands(dataset: Any, path: Path) -> tuple[list[str], list[NDArray[Any]], list[Any]]:
    """Band names, values ``(height, width)`` and validity masks."""
    count, height, width = dataset.count, dataset.height, dataset.width
    itemsize = max(np.dtype(d).itemsize for d in dataset.dtypes) if count else 1
    check_declared(count * height * width * (itemsize + 9), path.stat().st_size, "the raster", path)
    names: list[str] = []
    values: list[NDArray[Any]] = []
    masks: list[NDArray[np.bool_]] = []
    for index in range(1, count + 1):
        description = dataset.descriptions[index - 1]
        name = description if description and description not in names else f"band_{index}"
        names.append(name)
        data = dataset.read(index)
        valid = dataset.read_masks(index) > 0
        if data.dtype.kind == "f":
            valid &= np.isfinite(data)
        values.append(data)
        masks.append(valid)
    return names, values, masks


def _properties(
    names: list[str], values: list[NDArray[Any]], keep: NDArray[np.bool_], nodata: list[Any]
) -> dict[str, Property]:
    return {
        name: Property(
            values=np.ascontiguousarray(data[keep]),
            no_data_value=None if nd is None or not np.isfinite(nd) else float(nd),
        )
        for name, data, nd in zip(names, values, nodata, strict=True)
    }


def _centre_surface(
    a: list[float], values: NDArray[Any], valid: NDArray[np.bool_]
) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """Pixel-centre vertices of the valid pixels (row-major) and the triangles on them."""
    height, width = valid.shape
    rows, cols = np.nonzero(valid)
    index = np.full((height, width), -1, dtype=np.int64)
    index[rows, cols] = np.arange(rows.size)
    c, r = cols + 0.5, rows + 0.5
    xyz = np.column_stack(
        [a[0] * c + a[1] * r + a[2], a[3] * c + a[4] * r + a[5], values[rows, cols]]
    ).astype(np.float64)
    tl, tr = index[:-1, :-1].ravel(), index[:-1, 1:].ravel()
    bl, br = index[1:, :-1].ravel(), index[1:, 1:].ravel()
    # two triangles per square of four centres, square after square (row-major)
    triangles = np.stack([tl, bl, br, tl, br, tr], axis=1).reshape(-1, 3)
    triangles = triangles[(triangles >= 0).all(axis=1)]
    if a[0] * a[4] - a[1] * a[3] > 0:  # rows go up the map: the winding is mirrored
        triangles = triangles[:, ::-1]
    return xyz, np.ascontiguousarray(triangles)


def _pixel_quads(
    a: list[float], valid: NDArray[np.bool_]
) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """The corners of the valid pixels (z = 0) and one quad per valid pixel (row-major)."""
    height, width = valid.shape
    rows, cols = np.nonzero(valid)
    corner = np.zeros((height + 1, width + 1), dtype=bool)
    for dr in (0, 1):
        for dc in (0, 1):
            corner[rows + dr, cols + dc] = True
    cr, cc = np.nonzero(corner)
    index = np.full(corner.shape, -1, dtype=np.int64)
    index[cr, cc] = np.arange(cr.size)
    xyz = np.column_stack(
        [a[0] * cc + a[1] * cr + a[2], a[3] * cc + a[4] * cr + a[5], np.zeros(cr.size)]
    )
    quads = np.stack(
        [
            index[rows, cols],
            index[rows + 1, cols],
            index[rows + 1, cols + 1],
            index[rows, cols + 1],
        ],
        axis=1,
    )
    if a[0] * a[4] - a[1] * a[3] > 0:
        quads = quads[:, ::-1]
    return xyz, np.ascontiguousarray(quads)


def _entity(
    options: RasterOptions,
    name: str,
    a: list[float],
    bands: tuple[list[str], list[NDArray[Any]], list[NDArray[np.bool_]]],
    nodata: list[Any],
    path: Path,
) -> Entity:
    names, values, masks = bands
    if options.band > len(values):
        raise FormatError(f"band {options.band} asked for, the raster has {len(values)}", path)
    height, width = values[0].shape
    meta: dict[str, Any] = {
        "width": width,
        "height": height,
        "transform": a,
        "sampling": options.raster_as,
        "bands": names,
        "z_band": options.band,
    }
    if options.raster_as == "grid":
        every = np.ones((height, width), dtype=bool)
        return RegularGrid(
            name=name,
            origin=[a[2], a[5], 0.0],
            u=[a[0], a[3], 0.0],
            v=[a[1], a[4], 0.0],
            w=[0.0, 0.0, 1.0],
            counts=(width, height, 1),
            cell_data=_properties(names, values, every, nodata),
            metadata={"raster": meta},
        )
    valid = masks[options.band - 1]
    for name_, mask in zip(names, masks, strict=True):
        dropped = int((mask & ~valid).sum())
        if dropped:
            warnings.warn(
                f"{name_}: {dropped} value{'s' if dropped > 1 else ''} at pixels where band "
                f"{options.band} is no-data are not read (raster_as='grid' keeps every pixel)",
                RasterWarning,
                stacklevel=4,
            )
    if options.raster_as == "pixels":
        vertices, faces = _pixel_quads(a, valid)
        return Surface(
            name=name,
            vertices=vertices,
            faces=faces,
            cell_data=_properties(names, values, valid, nodata),
            metadata={"raster": meta},
        )
    vertices, faces = _centre_surface(a, values[options.band - 1], valid)
    return Surface(
        name=name,
        vertices=vertices,
        faces=faces,
        point_data=_properties(names, values, valid, nodata),
        metadata={"raster": meta},
    )


def read_raster(path: Path, options: object) -> Scene:
    """A scene of one surface or grid made of a GeoTIFF (or any raster GDAL reads)."""
    assert isinstance(options, RasterOptions)
    rasterio = _rasterio()
    try:
        dataset = rasterio.open(path)
    except rasterio.errors.RasterioError as exc:
        raise FormatError(f"not a raster GDAL can read: {exc}", path) from None
    with dataset:
        if dataset.count < 1 or dataset.width < 1 or dataset.height < 1:
            raise FormatError("the raster has no pixels", path)
        a = affine_of(dataset.transform)
        if a[0] * a[4] - a[1] * a[3] == 0.0:
            raise FormatError(f"the raster's transform {a} is singular", path)
        try:
            bands = _bands(dataset, path)
        except rasterio.errors.RasterioError as exc:
            raise FormatError(f"cannot read the raster's pixels: {exc}", path) from None
        nodata = list(dataset.nodatavals)
        crs = raster_crs(dataset.crs)
    entity = _entity(options, path.stem, a, bands, nodata, path)
    return Scene(entities=[entity.replace(id=0)], crs=crs, name=path.stem)
