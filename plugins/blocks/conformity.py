"""The block builder's conformity machinery, for other plugins (the inspection checks use it).

:func:`surface_nonconformities` welds the surfaces as the builder does (within a tolerance that
follows the data's precision by default, :mod:`geobrep.plugins.blocks.precision`) and lists
where they cross, touch (T-junctions) or stop short of each other (gaps), with the surfaces,
faces and vertices involved. The kernels are exported too: :func:`overlapping_pairs` (the grid
broad phase over triangles of different groups), :func:`triangles_intersect` (exact-enough
triangle-triangle tests within a tolerance), :func:`point_triangle_distance` and
:func:`half_plane_angles` (the radial sort's angles of triangles about an arc edge).

>>> import geobrep
>>> found = surface_nonconformities(geobrep.datasets.faulted_layer_cake().surfaces)
>>> found.defects, found.tolerance > 0
([], True)
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from geobrep import Surface
from geobrep.plugins.blocks._broad_phase import overlapping_pairs
from geobrep.plugins.blocks._conformity import (
    find_defects,
    point_triangle_distance,
    triangles_intersect,
)
from geobrep.plugins.blocks._radial_sort import half_plane_angles
from geobrep.plugins.blocks._soup import Soup, build_soup

__all__ = [
    "Contact",
    "Nonconformities",
    "half_plane_angles",
    "overlapping_pairs",
    "point_triangle_distance",
    "surface_nonconformities",
    "triangles_intersect",
]


@dataclass(frozen=True)
class Contact:
    """One defect between two surfaces (positions in the list given).

    ``kind`` is ``"crossing"``, ``"T-junction"`` or ``"gap"``; ``faces`` the face of each surface
    involved (-1: none, as for a gap's border vertex); ``vertex`` the vertex (of ``surfaces[0]``)
    lying on or near the other surface (-1: none); ``point`` where, ``distance`` how far apart.
    """

    kind: str
    surfaces: tuple[int, int]
    faces: tuple[int, int]
    vertex: int
    point: tuple[float, float, float]
    distance: float


@dataclass(frozen=True)
class Nonconformities:
    """The defects found and the weld/contact tolerance used (with where it came from)."""

    defects: list[Contact]
    tolerance: float
    tolerance_source: str


def _original_vertex(maps: Sequence[NDArray[np.int64]], surface: int, merged: int) -> int:
    hits = np.flatnonzero(maps[surface] == merged)
    return int(hits[0]) if hits.size else -1


def _nearest_corner(
    soup_vertices: NDArray[np.float64], tri_a: NDArray[np.int64], tri_b: NDArray[np.int64]
) -> tuple[int, int, float]:
    """(which triangle, soup vertex, distance): the corner of one nearest the other."""
    best = (0, int(tri_a[0]), np.inf)
    for which, (mine, other) in enumerate(((tri_a, tri_b), (tri_b, tri_a))):
        corners = soup_vertices[other]
        points = soup_vertices[mine]
        distance = point_triangle_distance(
            points, *(np.repeat(corners[m][None], 3, axis=0) for m in range(3))
        )
        k = int(np.argmin(distance))
        if distance[k] < best[2]:
            best = (which, int(mine[k]), float(distance[k]))
    return best


def surface_nonconformities(
    surfaces: Sequence[Surface],
    tolerance: float | None = None,
    gap_tolerance: float | None = None,
    relative_gap_tolerance: float = 1e-3,
    *,
    weld: tuple[NDArray[np.float64], NDArray[np.int64]] | None = None,
) -> Nonconformities:
    """Crossings, T-junctions and gaps between ``surfaces``, as the block builder finds them.

    ``weld`` is the caller's own merge of the surfaces' vertices (``merged points, inverse``
    of :func:`geobrep.geometry.mesh.merge_close_vertices` over their vertices concatenated in
    order, at ``tolerance``), reused instead of merging again."""
    soup = build_soup(tuple(surfaces), tolerance, None, weld)
    gap = gap_tolerance if gap_tolerance is not None else relative_gap_tolerance * soup.diagonal
    if soup.n_triangles == 0:
        return Nonconformities([], soup.tolerance, soup.tolerance_source)
    found = []
    for item in find_defects(soup, None, gap):  # the free border without the patch split
        first, second = item.triangles
        if item.vertex >= 0:  # a border vertex near another surface
            owner = _owner_of(soup, item.vertex, item.surfaces[0])
            other = int(soup.triangle_surface[second])
            found.append(
                Contact(
                    item.kind,
                    (owner, other),
                    (-1, int(soup.triangle_face[second])),
                    _original_vertex(soup.vertex_maps, owner, item.vertex),
                    item.point,
                    item.distance,
                )
            )
            continue
        sa, sb = int(soup.triangle_surface[first]), int(soup.triangle_surface[second])
        fa, fb = int(soup.triangle_face[first]), int(soup.triangle_face[second])
        vertex = -1
        if item.kind == "T-junction":
            which, merged, _ = _nearest_corner(
                soup.vertices, soup.triangles[first], soup.triangles[second]
            )
            if which == 1:
                sa, sb, fa, fb = sb, sa, fb, fa
            vertex = _original_vertex(soup.vertex_maps, sa, merged)
        found.append(Contact(item.kind, (sa, sb), (fa, fb), vertex, item.point, item.distance))
    source = soup.tolerance_source
    if soup.precision is not None:
        source = f"{soup.precision.source} coordinates, quantum {soup.precision.quantum:.3g}"
    return Nonconformities(found, soup.tolerance, source)


def _owner_of(soup: Soup, merged: int, name: str) -> int:
    """The surface holding soup vertex ``merged`` on a free border: the one called ``name``."""
    rows = np.flatnonzero((soup.triangles == merged).any(axis=1))
    holders = np.unique(soup.triangle_surface[rows]).tolist()
    named = [s for s in holders if soup.surface_name(s) == name]
    return int((named or holders or [0])[0])
