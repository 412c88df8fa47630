"""Consistent orientation of a face soup: which faces to flip so that neighbours agree.

Two faces sharing a *manifold* edge (one used by exactly two face sides) agree when they run
along it in opposite directions. :func:`orientation_flips` finds, for every connected piece of
the mesh (faces joined through manifold edges), the flips that make all its faces agree with
one face of the piece (its *root*), in O(M log M): the two states of every face (as is,
reversed) joined where neighbours agree, and the connected components of those states
(:func:`geobrep.geometry.graph.component_roots`).
Edges used by more than two faces do not join faces: the orientation is not decided there.

>>> import numpy as np
>>> result = orientation_flips(np.array([[0, 1, 2], [1, 2, 3], [3, 2, 4]]))
>>> result.flip.tolist(), result.n_pieces, result.n_conflicts
([False, True, True], 1, 0)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from geobrep.geometry.arrays import BoolArray, IntArray
from geobrep.geometry.graph import component_roots
from geobrep.geometry.mesh import _as_faces, _edge_table

__all__ = ["OrientationFlips", "neighbour_pairs", "orientation_flips"]


@dataclass(frozen=True)
class OrientationFlips:
    """Result of :func:`orientation_flips`.

    ``flip[f]`` says whether face ``f`` must be reversed to agree with the root of its piece;
    ``piece[f]`` numbers the pieces (0 … ``n_pieces`` - 1, in order of their lowest face);
    ``n_conflicts`` counts shared edges on which the two faces still disagree after flipping
    (non-zero only for non-orientable pieces, such as a Möbius strip).
    """

    flip: BoolArray
    piece: IntArray
    n_pieces: int
    n_conflicts: int


def _neighbour_pairs(faces: IntArray) -> tuple[IntArray, IntArray, BoolArray]:
    """Face pairs across manifold edges, and whether they run the edge the same way."""
    _, _, offsets, perm = _edge_table(faces)
    return neighbour_pairs(faces, offsets, perm)


def neighbour_pairs(
    faces: IntArray, offsets: IntArray, perm: IntArray
) -> tuple[IntArray, IntArray, BoolArray]:
    """Face pairs across the edges two face sides use, and whether they run the edge the same
    way, from an edge table: the sides of edge ``e`` are ``perm[offsets[e]:offsets[e + 1]]``
    (flattened face sides, ``face * k + side``)."""
    k = faces.shape[1]
    counts = np.diff(offsets)
    first = offsets[:-1][counts == 2]
    side_a, side_b = perm[first], perm[first + 1]
    face_a, face_b = side_a // k, side_b // k
    flat = np.ascontiguousarray(faces).reshape(-1)  # side s of face f is flat[f * k + s]
    return face_a, face_b, np.take(flat, side_a) == np.take(flat, side_b)


def _labels(n: int, a: IntArray, b: IntArray) -> IntArray:
    """The lowest node of each node's component, nodes ``0 … n-1`` joined by pairs (a, b)."""
    return component_roots(n, a, b)


def orientation_flips(
    faces: ArrayLike,
    roots: ArrayLike | None = None,
    *,
    neighbours: tuple[IntArray, IntArray, BoolArray] | None = None,
) -> OrientationFlips:
    """Flips making each connected piece of ``faces`` agree with its root face.

    ``roots`` optionally lists preferred root faces (e.g. a GOCAD TFACE's key triangle); a
    piece holding none of them is rooted at its lowest face. ``neighbours`` gives the face
    pairs across manifold edges and whether they run the edge the same way, when the caller
    already has them (:func:`neighbour_pairs` of the faces' edge table); the result does not
    depend on their order.

    Each face has two states (as is, ``2f``; reversed, ``2f + 1``); a shared manifold edge links
    the states in which the two faces agree. The components of these states are the consistent
    orientations: ``2f`` and ``2f + 1`` in one component make the piece non-orientable.
    """
    f = _as_faces(faces, "orientation_flips")
    m = f.shape[0]
    if m == 0:
        empty = np.zeros(0, dtype=np.int64)
        return OrientationFlips(np.zeros(0, dtype=np.bool_), empty, 0, 0)
    face_a, face_b, same_way = neighbours if neighbours is not None else _neighbour_pairs(f)
    other = same_way.astype(np.int64)  # running the edge the same way: one of them must turn
    state_a = np.concatenate([2 * face_a, 2 * face_a + 1])
    state_b = np.concatenate([2 * face_b + other, 2 * face_b + 1 - other])
    label = _labels(2 * m, state_a, state_b)
    as_is, turned = label[0::2], label[1::2]
    # Every state of a piece is >= 2 * its lowest face, and 2 * lowest is one of them.
    lowest = np.minimum(as_is, turned) // 2
    # Pieces numbered by their lowest face (a rank by marks: no sort).
    marked = np.zeros(m, dtype=np.bool_)
    marked[lowest] = True
    lowest_faces = np.flatnonzero(marked)
    piece = (np.cumsum(marked) - 1)[lowest].astype(np.int64)
    n_pieces = int(lowest_faces.shape[0])
    root_of_piece = np.full(n_pieces, m, dtype=np.int64)
    if roots is not None:
        preferred = np.asarray(roots, dtype=np.int64).reshape(-1)
        preferred = preferred[(preferred >= 0) & (preferred < m)]
        np.minimum.at(root_of_piece, piece[preferred], preferred)
    root_of_piece = np.where(root_of_piece < m, root_of_piece, lowest_faces)
    orientable = as_is != turned
    flip = orientable & (as_is != as_is[root_of_piece[piece]])
    conflicts = int(np.count_nonzero(same_way ^ flip[face_a] ^ flip[face_b]))
    return OrientationFlips(flip=flip, piece=piece, n_pieces=n_pieces, n_conflicts=conflicts)
