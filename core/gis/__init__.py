"""GIS: reprojection with pyproj, entities as feature tables (geopandas, GeoPackage layers), and
map products (outlines, traces, sections). pyproj, shapely and geopandas are imported only when
used.
"""
