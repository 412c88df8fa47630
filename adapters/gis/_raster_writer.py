"""Write a surface or a one-layer grid as a GeoTIFF (rasterio), each value back in its pixel.

* a :class:`~geobrep.RegularGrid` of one layer whose ``u`` and ``v`` are horizontal: one pixel
  per cell, the affine transform from ``origin``, ``u`` and ``v``, one band per cell property;
* a :class:`~geobrep.Surface` read from a raster (``metadata["raster"]``): its pixel-centre
  vertices (or pixel quads) are put back in their pixels, one band per point (or cell) property
  named in the metadata, pixels without a vertex being no-data.

A surface with no pixel lattice is refused (a FormatError saying so): GeoTIFF holds samples on a
lattice, not triangles.
"""

from __future__ import annotations

import warnings
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from geobrep.adapters.gis._raster import RasterWarning, looks_like_tiff
from geobrep.errors import FormatError, import_optional
from geobrep.model.crs import CRS
from geobrep.model.entities import RegularGrid, Surface
from geobrep.model.properties import Property
from geobrep.model.scene import Scene

__all__ = ["raster_losses", "write_raster"]

_Bands = tuple[list[str], list[NDArray[Any]], list[float | None]]


def _say(message: str) -> None:
    warnings.warn(message, RasterWarning, stacklevel=3)


def _grid_bands(grid: RegularGrid) -> tuple[list[float], _Bands]:
    if grid.counts[2] != 1 or grid.u[2] != 0.0 or grid.v[2] != 0.0:
        raise FormatError(
            f"{grid.label}: a GeoTIFF holds one horizontal layer of cells "
            f"(counts {grid.counts}, u {grid.u.tolist()}, v {grid.v.tolist()})"
        )
    if not grid.cell_data:
        raise FormatError(f"{grid.label}: a GeoTIFF band needs cell data (one value per pixel)")
    width, height, _ = grid.counts
    o, u, v = grid.origin, grid.u, grid.v
    affine = [float(u[0]), float(v[0]), float(o[0]), float(u[1]), float(v[1]), float(o[1])]
    names = list(grid.cell_data)
    values = [np.asarray(p.values).reshape(height, width) for p in grid.cell_data.values()]
    return affine, (names, values, [p.no_data_value for p in grid.cell_data.values()])


class _Lattice:
    """The pixel lattice a surface's ``metadata["raster"]`` describes."""

    def __init__(self, surface: Surface) -> None:
        meta = surface.metadata.get("raster")
        meta = meta if isinstance(meta, dict) else {}
        width, height, transform = meta.get("width"), meta.get("height"), meta.get("transform")
        bands = meta.get("bands", [])
        if not (
            isinstance(width, int)
            and isinstance(height, int)
            and isinstance(transform, list)
            and len(transform) == 6
            and all(isinstance(v, (int, float)) for v in transform)
            and isinstance(bands, list)
        ):
            raise FormatError(
                f"{surface.label} was not read from a raster: GeoTIFF needs a pixel lattice "
                "(read the raster with raster_as='grid', or write a one-layer RegularGrid)"
            )
        self.transform = [float(v) for v in transform]  # type: ignore[arg-type]
        self.label = surface.label
        self.width, self.height = width, height
        self.pixels = meta.get("sampling") == "pixels"
        self.bands = [str(b) for b in bands]

    def locate(self, xy: NDArray[np.float64]) -> tuple[NDArray[np.int64], NDArray[np.int64]]:
        """The row and column of the pixel each point ``xy`` is the centre of."""
        a = self.transform
        matrix = np.array([[a[0], a[1]], [a[3], a[4]]])
        cr = np.linalg.solve(matrix, (xy - [a[2], a[5]]).T).T - 0.5
        nearest = np.round(cr)
        off = np.abs(cr - nearest).max(initial=0.0)
        cols, rows = nearest[:, 0].astype(np.int64), nearest[:, 1].astype(np.int64)
        if off > 1e-6 or cols.min(initial=0) < 0 or rows.min(initial=0) < 0:
            raise FormatError(f"{self.label}: its vertices are not on its raster's pixels")
        if cols.max(initial=0) >= self.width or rows.max(initial=0) >= self.height:
            raise FormatError(
                f"{self.label}: a vertex is outside its raster's {self.width} x {self.height}"
            )
        return rows, cols


def _surface_bands(surface: Surface) -> tuple[list[float], _Bands]:
    lattice = _Lattice(surface)
    if lattice.pixels:
        rows, cols = lattice.locate(surface.vertices[surface.faces].mean(axis=1)[:, :2])
        props = dict(surface.cell_data)
    else:
        rows, cols = lattice.locate(surface.vertices[:, :2])
        props = dict(surface.point_data)
        if not props:
            props = {"z": Property(values=surface.vertices[:, 2].copy())}
    named = [n for n in lattice.bands if n in props] or list(props)
    names: list[str] = []
    values: list[NDArray[Any]] = []
    nodata: list[float | None] = []
    for name in named:
        prop = props[name]
        data = np.asarray(prop.values)
        full = np.zeros((lattice.height, lattice.width), dtype=data.dtype)
        filled = np.zeros(full.shape, dtype=bool)
        full[rows, cols] = data
        filled[rows, cols] = True
        missing = prop.no_data_value
        if not filled.all():
            if missing is None and data.dtype.kind != "f":
                raise FormatError(f"{surface.label}: band {name!r} has holes, no no-data value")
            missing = float("nan") if missing is None else missing
            full[~filled] = missing
        names.append(name)
        values.append(full)
        nodata.append(missing)
    return lattice.transform, (names, values, nodata)


def _rasterio_crs(rasterio: Any, crs: CRS | None) -> Any:
    if crs is None:
        return None
    if crs.wkt:
        return rasterio.crs.CRS.from_wkt(crs.wkt)
    if crs.epsg is not None:
        return rasterio.crs.CRS.from_epsg(crs.epsg)
    if crs.proj:
        return rasterio.crs.CRS.from_string(crs.proj)
    _say(f"GeoTIFF: the CRS {crs.label!r} has no EPSG, WKT or PROJ definition: not written")
    return None


def _common(bands: _Bands) -> tuple[np.dtype[Any], float | None]:
    names, values, nodata = bands
    dtype = np.result_type(*values)
    if any(v.dtype != dtype for v in values):
        _say(f"GeoTIFF bands share one type: {', '.join(names)} are written as {dtype}")
    given = [n for n in nodata if n is not None]
    if len({repr(n) for n in given}) > 1:
        _say(f"GeoTIFF has one no-data value for all bands: {given[0]} is written")
    return dtype, given[0] if given else None


def _chosen(scene: Scene) -> RegularGrid | Surface:
    chosen = [e for e in scene.entities if isinstance(e, (RegularGrid, Surface))]
    if not chosen:
        raise FormatError("the scene has no surface or grid to write as a GeoTIFF")
    if len(scene.entities) > 1:
        others = ", ".join(e.label for e in scene.entities if e is not chosen[0])
        _say(f"a GeoTIFF holds one raster: not written: {others}")
    return chosen[0]


def write_raster(scene: Scene, path: Path, options: object) -> None:
    """Write the scene's first surface or grid as a GeoTIFF."""
    rasterio = import_optional("rasterio", "gis", "GeoTIFF rasters")
    entity = _chosen(scene)
    if isinstance(entity, RegularGrid):
        affine, bands = _grid_bands(entity)
    else:
        affine, bands = _surface_bands(entity)
    dtype, nodata = _common(bands)
    names, values, _ = bands
    height, width = values[0].shape
    profile = {
        "driver": "GTiff",
        "width": width,
        "height": height,
        "count": len(values),
        "dtype": dtype.name,
        "crs": _rasterio_crs(rasterio, scene.crs),
        "transform": rasterio.Affine(*affine),
        "nodata": nodata,
    }
    with rasterio.open(path, "w", **profile) as target:
        for index, (name, data) in enumerate(zip(names, values, strict=True), start=1):
            target.write(data.astype(dtype, copy=False), index)
            target.set_band_description(index, name)
    if not looks_like_tiff(path.read_bytes()[:4]):
        raise FormatError("rasterio wrote no TIFF", path)


def raster_losses(scene: Scene, path: Path) -> list[str]:
    """What a GeoTIFF cannot hold of the scene."""
    lost: list[str] = []
    for entity in scene.entities:
        if isinstance(entity, RegularGrid) and entity.point_data:
            lost.append(f"{entity.label}: point data (a GeoTIFF holds one value per pixel)")
        if isinstance(entity, RegularGrid) and entity.origin[2] != 0.0:
            lost.append(f"{entity.label}: the grid's elevation (origin z)")
        if isinstance(entity, Surface) and "raster" not in entity.metadata:
            lost.append(f"{entity.label}: a surface not read from a raster has no pixels")
    return lost
