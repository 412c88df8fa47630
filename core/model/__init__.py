"""The data model: entities, properties, CRS, topology (corners, arcs, patches) and the scene.

Immutable pydantic models holding numpy arrays. Depends only on :mod:`geobrep.geometry` and
:mod:`geobrep.errors`; everything else in geobrep is built on it. The public names are exported
by :mod:`geobrep` itself (``geobrep.Scene``, ``geobrep.Surface``, ...).
"""
