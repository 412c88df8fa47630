"""GIS vector formats through pyogrio (GDAL) and shapely 2: GeoPackage, GeoJSON and shapefile;
GeoTIFF / DEM rasters through rasterio (``geotiff``: a surface or a one-layer grid).

Points (with attribute columns and z) become PointSets with properties, lines PolyLines,
polygons Polygons; PointSets, PolyLines, Polygons (section fills, map outlines) and annotations
are written as layers with their attributes as columns. The CRS travels with every layer.
pyogrio and shapely (the ``gis`` extra) are imported only when a file is read or written.
"""

from __future__ import annotations

from pathlib import Path

from geobrep.adapters.gis._formats import gis_formats
from geobrep.host.registry import FormatCapabilities, FormatRegistry, FormatSpec
from geobrep.model.scene import Scene
from geobrep.plugins import hookimpl

__all__ = ["geobrep_register_formats"]


@hookimpl
def geobrep_register_formats(registry: FormatRegistry) -> None:
    """Register ``gpkg``, ``geojson``, ``shapefile`` and ``geotiff``."""
    for spec in gis_formats():
        registry.add(spec)
    registry.add(_geotiff())


def _geotiff() -> FormatSpec:
    from geobrep.adapters.gis._raster import RasterOptions, looks_like_tiff

    def read(path: Path, options: object) -> Scene:
        from geobrep.adapters.gis._raster import read_raster

        return read_raster(path, options)

    def write(scene: Scene, path: Path, options: object) -> None:
        from geobrep.adapters.gis._raster_writer import write_raster

        write_raster(scene, path, options)

    def losses(scene: Scene, path: Path) -> list[str]:
        from geobrep.adapters.gis._raster_writer import raster_losses

        return raster_losses(scene, path)

    return FormatSpec(
        name="geotiff",
        description="GeoTIFF / DEM raster (rasterio): a surface of pixel centres or pixel "
        "quads, or a one-layer grid",
        extensions=(".tif", ".tiff"),
        reader=read,
        writer=write,
        sniff=looks_like_tiff,
        options=RasterOptions,
        capabilities=FormatCapabilities(
            entity_types=frozenset({"Surface", "RegularGrid"}),
            point_data=True,
            cell_data=True,
            crs=True,
        ),
        losses=losses,
    )
