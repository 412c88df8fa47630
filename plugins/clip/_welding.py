"""Surfaces that would be closed once their seams are welded: the clipper warns about them.

A surface is capped when it is closed as given (every edge shared by two faces). A surface that
is closed *geometrically* but not topologically — vertices of a seam duplicated within the
tolerance, or a sliver face between them — gets no caps, and its halves come back open. The
Surface clipper warns with :class:`UnweldedSurfaceWarning` and says how to get caps.

>>> import numpy as np
>>> from geobrep import Surface
>>> tetra = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1.0]])
>>> faces = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 4]])
>>> seam = Surface(vertices=np.vstack([tetra, tetra[3] + 1e-12]), faces=faces)
>>> closed_once_welded(seam, 1e-9)
(1, 0)
"""

from __future__ import annotations

import numpy as np

from geobrep import Surface
from geobrep.geometry import mesh

__all__ = ["UnweldedSurfaceWarning", "closed_once_welded"]


class UnweldedSurfaceWarning(UserWarning):
    """A surface closed up to the tolerance, but not as given: it is clipped without caps."""


def closed_once_welded(surface: Surface, tolerance: float) -> tuple[int, int] | None:
    """``(vertices welded, faces dropped)`` when welding the border vertices of ``surface``
    within ``tolerance`` (and dropping the faces that collapse) closes it; else None.

    Only the vertices on border edges are welded: a seam is made of borders. Cost: a
    k-d tree over the border vertices, run only for surfaces that are not closed.
    """
    faces = np.asarray(surface.faces, dtype=np.int64)
    border = mesh.boundary_edges(faces)
    if border.shape[0] == 0:
        return None
    ends = np.unique(border)
    merged, group = mesh.merge_close_vertices(surface.vertices[ends], tolerance)
    if merged.shape[0] == ends.shape[0]:
        return None
    representative = np.empty(merged.shape[0], dtype=np.int64)
    representative[group[::-1]] = ends[::-1]  # the lowest vertex index of each group
    remap = np.arange(surface.n_vertices, dtype=np.int64)
    remap[ends] = representative[group]
    welded = remap[faces]
    repeats = np.zeros(welded.shape[0], dtype=bool)
    for a in range(welded.shape[1]):
        for b in range(a + 1, welded.shape[1]):
            repeats |= welded[:, a] == welded[:, b]
    kept = welded[~repeats]
    if kept.shape[0] == 0 or not mesh.is_closed(kept):
        return None
    return int(ends.shape[0] - merged.shape[0]), int(repeats.sum())
