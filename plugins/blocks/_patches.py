"""Split the soup into patches along arc edges.

An edge is an **arc edge** where a surface stops (one triangle), where surfaces meet (triangles
of different surfaces) or where more than two triangles meet; an edge whose two triangles
traverse it in the same direction (an orientation seam inside a surface) is one too, so every
patch is consistently oriented. Patches are the connected components of triangles across the
remaining (manifold, same-surface, consistently oriented) edges.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from geobrep.geometry import mesh
from geobrep.geometry.arrays import IntArray
from geobrep.plugins.blocks._soup import Soup

__all__ = ["PatchSplit", "split_patches"]


@dataclass(frozen=True)
class PatchSplit:
    """Edges with their triangles (CSR), the arc edges and the patch of every triangle.

    The triangles using edge ``e`` are ``incident_triangles[offsets[e]:offsets[e + 1]]`` and
    ``incident_sides`` says which side of each (side ``j`` runs from corner ``j`` to ``j + 1``).
    Patches are numbered by their first triangle, so by surface, then by position in it;
    ``patch_label`` numbers them within their surface.
    """

    edges: IntArray
    offsets: IntArray
    incident_triangles: IntArray
    incident_sides: IntArray
    arc_edges: IntArray
    triangle_patch: IntArray
    patch_surface: IntArray
    patch_label: IntArray
    orientation_seams: int

    @property
    def n_patches(self) -> int:
        return int(self.patch_surface.shape[0])

    def patch_triangle_counts(self) -> IntArray:
        return np.bincount(self.triangle_patch, minlength=self.n_patches).astype(np.int64)


def split_patches(soup: Soup) -> PatchSplit:
    """Classify the edges of the soup and label its patches.

    >>> import geobrep
    >>> from geobrep.plugins.blocks._soup import build_soup
    >>> scene = geobrep.datasets.faulted_layer_cake()
    >>> split_patches(build_soup(scene.surfaces, None, 1e-7)).n_patches
    31
    """
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    triangles = soup.triangles
    n_triangles = triangles.shape[0]
    edges, offsets, incident, sides = mesh.edge_face_incidence(triangles)
    counts = np.diff(offsets)
    pair = np.flatnonzero(counts == 2)
    first, second = offsets[pair], offsets[pair] + 1
    t1, t2 = incident[first], incident[second]
    same_surface = soup.triangle_surface[t1] == soup.triangle_surface[t2]
    # Consistent neighbours traverse the shared edge in opposite directions.
    corner = triangles.reshape(-1)
    consistent = np.take(corner, 3 * t1 + sides[first]) != np.take(corner, 3 * t2 + sides[second])
    manifold = same_surface & consistent
    is_arc = counts != 2
    is_arc[pair[~manifold]] = True

    # float64 weights: the dtype connected_components works in (int8 ones were converted to a
    # float64 copy of the matrix there).
    graph = coo_matrix(
        (np.ones(int(manifold.sum()), dtype=np.float64), (t1[manifold], t2[manifold])),
        shape=(n_triangles, n_triangles),
    )
    n_components, labels = connected_components(graph, directed=False)
    triangle_patch, first_triangle = _by_first_triangle(labels.astype(np.int64), n_components)
    patch_surface = soup.triangle_surface[first_triangle]
    surface_start = np.searchsorted(patch_surface, patch_surface, side="left")
    patch_label = np.arange(patch_surface.shape[0], dtype=np.int64) - surface_start
    return PatchSplit(
        edges=edges,
        offsets=offsets,
        incident_triangles=incident,
        incident_sides=sides,
        arc_edges=np.flatnonzero(is_arc).astype(np.int64),
        triangle_patch=triangle_patch,
        patch_surface=patch_surface.astype(np.int64, copy=False),
        patch_label=patch_label,
        orientation_seams=int((same_surface & ~consistent).sum()),
    )


def _by_first_triangle(labels: IntArray, n_labels: int) -> tuple[IntArray, IntArray]:
    """Component labels renumbered by their first triangle (patches follow surface order), and
    the first triangle of each. Labels that already come in that order (the running maximum
    grows by one at a time) are kept as they are, without a sort."""
    if labels.size == 0:
        return labels, labels
    running = np.maximum.accumulate(labels)
    steps = np.diff(running, prepend=-1)
    if int(steps.max()) <= 1 and int(running[-1]) == n_labels - 1:
        return labels, np.flatnonzero(steps)
    _, first_triangle = np.unique(labels, return_index=True)
    order = np.argsort(first_triangle, kind="stable")
    rank = np.empty(order.shape[0], dtype=np.int64)
    rank[order] = np.arange(order.shape[0], dtype=np.int64)
    return np.take(rank, labels), first_triangle[order]
