"""Signed point-to-surface distances for accuracy reports: NURBS surfaces and triangle meshes.

NURBS distances come from a closest-point projection; mesh distances are exact
(:mod:`geobrep.geometry.distance`: the nearest vertex bounds the search radius, an R-tree yields
the candidate triangles, Ericson's region tests the closest point on each).

>>> import numpy as np
>>> from geobrep.model.entities import Surface
>>> tri = Surface(vertices=[[0, 0, 0], [1, 0, 0], [0, 1, 0]], faces=[[0, 1, 2]])
>>> surface_distances(tri, np.array([[0.2, 0.2, 1.0], [2.0, 0.0, 0.0]])).tolist()
[1.0, 1.0]
"""

from __future__ import annotations

import numpy as np

from geobrep import NurbsSurface, Surface
from geobrep.geometry.arrays import FloatArray
from geobrep.geometry.distance import closest_points_on_triangles, mesh_distances
from geobrep.plugins.fit._projection import project_points

__all__ = ["closest_points_on_triangles", "mesh_distances", "surface_distances"]


def surface_distances(
    surface: NurbsSurface | Surface,
    points: FloatArray,
    u0: FloatArray | None = None,
    v0: FloatArray | None = None,
) -> FloatArray:
    """Signed distances from points to a NurbsSurface (closest-point projection) or a mesh.

    NURBS distances are computed about the control net's centre, so UTM-scale coordinates keep
    their precision; ``u0, v0`` are optional starting parameters.
    """
    pts = np.asarray(points, dtype=np.float64)
    if isinstance(surface, Surface):
        return mesh_distances(surface, pts)
    net = surface.net
    centre = net.centre
    centred = net.with_control_points(net.control_points - centre)
    _, _, distances = project_points(centred, pts - centre, u0, v0)
    return distances
