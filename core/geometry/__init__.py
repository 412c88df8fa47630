"""Geometry kernels: planes, bounding boxes and vectorised mesh functions."""

from __future__ import annotations

from geobrep.geometry.bbox import BoundingBox, boxes_plane_side
from geobrep.geometry.mesh import (
    boundary_edges,
    edge_face_counts,
    edge_face_incidence,
    face_areas,
    face_centroids,
    face_normals,
    flip_faces,
    is_closed,
    is_consistently_oriented,
    merge_close_vertices,
    non_manifold_edges,
    signed_volume,
    sort_around_axis,
    surface_area,
    triangulate,
    unique_edges,
)
from geobrep.geometry.plane import Plane

__all__ = [
    "BoundingBox",
    "Plane",
    "boundary_edges",
    "boxes_plane_side",
    "edge_face_counts",
    "edge_face_incidence",
    "face_areas",
    "face_centroids",
    "face_normals",
    "flip_faces",
    "is_closed",
    "is_consistently_oriented",
    "merge_close_vertices",
    "non_manifold_edges",
    "signed_volume",
    "sort_around_axis",
    "surface_area",
    "triangulate",
    "unique_edges",
]
