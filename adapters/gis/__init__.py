"""GIS vector formats through pyogrio (GDAL) and shapely 2: GeoPackage, GeoJSON and shapefile.

Points (with attribute columns and z) become PointSets with properties, lines PolyLines,
polygons Polygons; PointSets, PolyLines, Polygons (section fills, map outlines) and annotations
are written as layers with their attributes as columns. The CRS travels with every layer.
pyogrio and shapely (the ``gis`` extra) are imported only when a file is read or written.
"""

from __future__ import annotations

from geobrep.adapters.gis._formats import gis_formats
from geobrep.host.registry import FormatRegistry
from geobrep.plugins import hookimpl

__all__ = ["geobrep_register_formats"]


@hookimpl
def geobrep_register_formats(registry: FormatRegistry) -> None:
    """Register ``gpkg``, ``geojson`` and ``shapefile``."""
    for spec in gis_formats():
        registry.add(spec)
