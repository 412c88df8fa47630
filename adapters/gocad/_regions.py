"""Regions of a TSolid / LightTSolid from what its file says about faces and seeds.

A ``# CTETRA`` line gives, for each face of its TETRA (face ``k`` is the one opposite vertex
``k``), the model surface the face lies on, or ``none``; the ``MODEL`` section's ``TRGL`` lines
list the same faces. Tetrahedra joined through faces that lie on no surface form one region;
``MODEL_REGION <name> <±tface>`` names the region on the ``+`` (or ``-``) side of TFACE's key
triangle, whose right-hand normal points to ``+`` in the z-up frame (the Model3d rule).
Everything here is vectorised: faces are keyed by their sorted root vertices (an ATOM or
SHAREDVRTX is the vertex it refers to) and sorted once.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from geobrep.geometry.arrays import BoolArray, IntArray
from geobrep.geometry.graph import component_roots
from geobrep.geometry.mesh import compact_indices

__all__ = ["TetFaces", "root_vertices"]


#: Local vertices of face k (the face opposite vertex k).
_FACE_VERTICES = np.array([[1, 2, 3], [0, 2, 3], [0, 1, 3], [0, 1, 2]], dtype=np.int64)


def root_vertices(atom_of: IntArray) -> IntArray:
    """For each vertex, the vertex with coordinates its ATOM / SHAREDVRTX chain ends at.

    >>> root_vertices(np.array([-1, 0, 1, -1])).tolist()
    [0, 0, 0, 3]
    """
    roots = np.arange(atom_of.shape[0], dtype=np.int64)
    linked = atom_of >= 0
    roots[linked] = atom_of[linked]
    while True:
        deeper = atom_of[roots]
        chained = deeper >= 0
        if not chained.any():
            return roots
        roots = np.where(chained, deeper, roots)


class TetFaces:
    """The faces of a tetrahedral mesh (row ``4 t + k``: face ``k`` of tetrahedron ``t``),
    keyed by sorted root vertices and sorted once for matching."""

    def __init__(self, tetra: IntArray, roots: IntArray) -> None:
        self.tetra = tetra
        self.n_cells = int(tetra.shape[0])
        keys = roots[tetra][:, _FACE_VERTICES].reshape(-1, 3)
        keys = np.sort(keys, axis=1)
        self.order = np.lexsort((keys[:, 2], keys[:, 1], keys[:, 0]))
        self.sorted = keys[self.order]
        self.roots = roots

    def on_triangles(self, triangles: IntArray) -> BoolArray:
        """``(n_cells, 4)``: whether each face is one of ``triangles`` (vertex indices)."""
        n_faces = self.sorted.shape[0]
        if triangles.size == 0 or n_faces == 0:
            return np.zeros((self.n_cells, 4), dtype=bool)
        keys = np.sort(self.roots[triangles], axis=1)
        rows = np.concatenate([self.sorted, keys])
        is_triangle = np.r_[np.zeros(n_faces, dtype=bool), np.ones(keys.shape[0], dtype=bool)]
        order = np.lexsort((rows[:, 2], rows[:, 1], rows[:, 0]))
        ranked = rows[order]
        starts = np.r_[True, (ranked[1:] != ranked[:-1]).any(axis=1)]
        group = np.cumsum(starts) - 1
        has_triangle = np.zeros(int(group[-1]) + 1, dtype=bool)
        has_triangle[group[is_triangle[order]]] = True
        faces = ~is_triangle[order]
        marked = np.zeros(n_faces, dtype=bool)
        marked[self.order[order[faces]]] = has_triangle[group[faces]]
        return marked.reshape(self.n_cells, 4)

    def components(self, barrier: BoolArray) -> tuple[int, IntArray]:
        """Connected sets of tetrahedra through faces not marked in ``barrier`` ``(n, 4)``:
        their number and the set of each tetrahedron (numbered by first tetrahedron)."""
        n = self.n_cells
        if n == 0:
            return 0, np.zeros(0, dtype=np.int64)
        ranked = self.sorted
        shared = np.flatnonzero((ranked[1:] == ranked[:-1]).all(axis=1))
        a, b = self.order[shared], self.order[shared + 1]
        flat = barrier.reshape(-1)
        keep = ~(flat[a] | flat[b])
        roots = component_roots(n, a[keep] // 4, b[keep] // 4)
        used, labels = compact_indices(roots, n)
        return int(used.shape[0]), labels

    def seed(self, xyz: NDArray[np.float64], key: IntArray, side: int) -> int | None:
        """The tetrahedron on the ``side`` (+1 / -1) of triangle ``key`` (3 vertex indices)
        that has it as a face, or None (the triangle is no face there)."""
        target = np.sort(self.roots[key])
        column = self.sorted[:, 0]
        lo = int(np.searchsorted(column, target[0], side="left"))
        hi = int(np.searchsorted(column, target[0], side="right"))
        hits = lo + np.flatnonzero((self.sorted[lo:hi] == target).all(axis=1))
        if not hits.size:
            return None
        rows = self.order[hits]
        cells, local = rows // 4, rows % 4
        p0, p1, p2 = xyz[key[0]], xyz[key[1]], xyz[key[2]]
        normal = np.cross(p1 - p0, p2 - p0)
        opposite = xyz[self.tetra[cells, local]]
        sides = np.sign((opposite - p0) @ normal)
        match = np.flatnonzero(sides == np.sign(side))
        return int(cells[match[0]]) if match.size else None
