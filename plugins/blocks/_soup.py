"""The triangle soup: every surface's triangles over one table of merged (welded) vertices.

Surfaces of a conformal model meet along shared vertices; files store each surface with its own
copy of them, so colocated vertices are merged first, within a tolerance (by default a few
quanta of the precision the coordinates carry: :mod:`.precision`).
Triangles that collapse in the merge (two corners welded together) are dropped and
counted. Quads are split along their 0-2 diagonal.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from functools import cached_property

import numpy as np

from geobrep import Surface
from geobrep.errors import DegenerateGeometryError
from geobrep.geometry import mesh
from geobrep.geometry.arrays import BoolArray, FloatArray, IntArray
from geobrep.geometry.bbox import column_extremes
from geobrep.plugins.blocks._broad_phase import component_major
from geobrep.plugins.blocks.precision import Precision, data_tolerance, measure_precision

__all__ = ["Soup", "build_soup"]


@dataclass(frozen=True)
class Soup:
    """Merged vertices and the live triangles of all surfaces.

    ``triangle_surface[t]`` is the position of triangle ``t``'s surface in ``surfaces`` and
    ``triangle_face[t]`` the face of that surface it comes from. ``vertex_maps[s][i]`` is the
    merged vertex of vertex ``i`` of surface ``s``. Triangles of one surface are contiguous and
    surfaces come in order.
    """

    surfaces: tuple[Surface, ...]
    vertices: FloatArray
    triangles: IntArray
    triangle_surface: IntArray
    triangle_face: IntArray
    vertex_maps: tuple[IntArray, ...]
    merged_vertices: int
    degenerate_triangles: int
    tolerance: float
    centre: FloatArray
    diagonal: float
    precision: Precision | None = None
    tolerance_source: str = "tolerance"

    @property
    def n_triangles(self) -> int:
        return int(self.triangles.shape[0])

    def subset(self, keep: BoolArray) -> Soup:
        """The same soup with only the triangles where ``keep`` is true."""
        return replace(
            self,
            triangles=np.compress(keep, self.triangles, axis=0),  # rows: faster than [keep]
            triangle_surface=self.triangle_surface[keep],
            triangle_face=self.triangle_face[keep],
        )

    @cached_property
    def local_vertices(self) -> FloatArray:
        """The vertices relative to the model centre (:meth:`local`), read-only — computed once
        for the stages that need them (contact and gap search, patch measures, the universe)."""
        local = self.local(self.vertices)
        local.flags.writeable = False
        return local

    @cached_property
    def corners(self) -> FloatArray:
        """Model-centred corners of the triangles, component-major: (corner, xyz, T) — gathered
        once for the stages that need them (contact search, patch measures)."""
        return component_major(np.ascontiguousarray(self.local_vertices.T), self.triangles)

    def surface_name(self, index: int) -> str:
        surface = self.surfaces[index]
        return surface.name or surface.label

    def local(self, points: FloatArray) -> FloatArray:
        """Coordinates relative to the model centre (products keep full precision there)."""
        return np.asarray(points - self.centre, dtype=np.float64)


def build_soup(
    surfaces: tuple[Surface, ...],
    tolerance: float | None,
    relative_tolerance: float | None,
    weld: tuple[FloatArray, IntArray] | None = None,
) -> Soup:
    """Merge the surfaces' vertices within the tolerance and collect their triangles.

    The tolerance is ``tolerance``, else ``relative_tolerance`` × the bounding-box diagonal, else
    (both ``None``) the one the coordinates' precision gives (:func:`.precision.data_tolerance`).
    ``weld`` is the merge already made by the caller (``merge_close_vertices`` of the surfaces'
    vertices, concatenated in order, at that tolerance), reused as it is.

    >>> import geobrep
    >>> scene = geobrep.datasets.faulted_layer_cake()
    >>> soup = build_soup(scene.surfaces, None, 1e-7)
    >>> soup.n_triangles == sum(s.n_faces for s in scene.surfaces), soup.merged_vertices > 0
    (True, True)
    """
    if not surfaces:
        raise DegenerateGeometryError("block builder: the scene has no surfaces to build from")
    vertex_counts = np.array([s.n_vertices for s in surfaces], dtype=np.int64)
    vertex_offsets = np.concatenate([[0], np.cumsum(vertex_counts)])
    all_vertices = np.concatenate([s.vertices for s in surfaces]).astype(np.float64, copy=False)
    if all_vertices.shape[0] == 0:
        raise DegenerateGeometryError("block builder: the surfaces have no vertices")
    lower, upper = column_extremes(all_vertices)
    centre = 0.5 * (lower + upper)
    diagonal = float(np.linalg.norm(upper - lower))
    precision = None
    rule = "tolerance"
    if tolerance is None and relative_tolerance is not None:
        tolerance, rule = relative_tolerance * diagonal, "relative_tolerance"
    elif tolerance is None:
        precision = measure_precision(all_vertices)
        tolerance, rule = data_tolerance(precision, diagonal), "precision"
    if weld is not None and weld[1].shape[0] == all_vertices.shape[0]:
        merged, inverse = weld
    else:
        merged, inverse = mesh.merge_close_vertices(all_vertices, tolerance)

    triangle_parts: list[IntArray] = []
    surface_parts: list[IntArray] = []
    face_parts: list[IntArray] = []
    for index, surface in enumerate(surfaces):
        triangles, source = mesh.triangulate(surface.faces)
        triangle_parts.append(inverse[triangles + vertex_offsets[index]])
        surface_parts.append(np.full(triangles.shape[0], index, dtype=np.int64))
        face_parts.append(source)
    triangles = np.concatenate(triangle_parts).reshape(-1, 3)
    collapsed = (
        (triangles[:, 0] == triangles[:, 1])
        | (triangles[:, 1] == triangles[:, 2])
        | (triangles[:, 0] == triangles[:, 2])
    )
    keep = ~collapsed
    maps = tuple(inverse[vertex_offsets[i] : vertex_offsets[i + 1]] for i in range(len(surfaces)))
    return Soup(
        surfaces=surfaces,
        vertices=merged,
        triangles=np.compress(keep, triangles, axis=0),
        triangle_surface=np.concatenate(surface_parts)[keep],
        triangle_face=np.concatenate(face_parts)[keep],
        vertex_maps=maps,
        merged_vertices=int(all_vertices.shape[0] - merged.shape[0]),
        degenerate_triangles=int(collapsed.sum()),
        tolerance=float(tolerance),
        centre=centre,
        diagonal=diagonal,
        precision=precision,
        tolerance_source=rule,
    )
