"""Consistent orientation of a face soup: which faces to flip so that neighbours agree.

Two faces sharing a *manifold* edge (one used by exactly two face sides) agree when they run
along it in opposite directions. :func:`orientation_flips` finds, for every connected piece of
the mesh (faces joined through manifold edges), the flips that make all its faces agree with
one face of the piece (its *root*), in O(M log M): a breadth-first spanning forest from scipy,
then the flip parities summed along the tree by pointer jumping (log₂ of the tree depth passes).
Edges used by more than two faces do not join faces: the orientation is not decided there.

>>> import numpy as np
>>> result = orientation_flips(np.array([[0, 1, 2], [1, 2, 3], [3, 2, 4]]))
>>> result.flip.tolist(), result.n_pieces, result.n_conflicts
([False, True, True], 1, 0)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from geobrep.geometry.mesh import _as_faces, _edge_table

__all__ = ["OrientationFlips", "orientation_flips"]

IntArray = NDArray[np.int64]
BoolArray = NDArray[np.bool_]


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
    k = faces.shape[1]
    _, _, offsets, perm = _edge_table(faces)
    counts = np.diff(offsets)
    first = offsets[:-1][counts == 2]
    side_a, side_b = perm[first], perm[first + 1]
    face_a, face_b = side_a // k, side_b // k
    start_a = faces[face_a, side_a % k]
    start_b = faces[face_b, side_b % k]
    return face_a, face_b, start_a == start_b


def orientation_flips(faces: ArrayLike, roots: ArrayLike | None = None) -> OrientationFlips:
    """Flips making each connected piece of ``faces`` agree with its root face.

    ``roots`` optionally lists preferred root faces (e.g. a GOCAD TFACE's key triangle); a
    piece holding none of them is rooted at its lowest face.
    """
    f = _as_faces(faces, "orientation_flips")
    m = f.shape[0]
    if m == 0:
        empty = np.zeros(0, dtype=np.int64)
        return OrientationFlips(np.zeros(0, dtype=np.bool_), empty, 0, 0)
    from scipy.sparse import coo_matrix  # imported here: keeps `import geobrep` fast
    from scipy.sparse.csgraph import breadth_first_order, connected_components

    face_a, face_b, same_way = _neighbour_pairs(f)
    graph = coo_matrix(
        (np.ones(face_a.shape[0], dtype=np.int8), (face_a, face_b)), shape=(m, m)
    ).tocsr()
    n_pieces, piece = connected_components(graph, directed=False)
    piece = piece.astype(np.int64)
    root_of_piece = np.full(n_pieces, m, dtype=np.int64)
    if roots is not None:
        preferred = np.asarray(roots, dtype=np.int64).reshape(-1)
        preferred = preferred[(preferred >= 0) & (preferred < m)]
        np.minimum.at(root_of_piece, piece[preferred], preferred)
    lowest = np.full(n_pieces, m, dtype=np.int64)
    np.minimum.at(lowest, piece, np.arange(m, dtype=np.int64))
    root_of_piece = np.where(root_of_piece < m, root_of_piece, lowest)
    # One breadth-first forest: a virtual node m joined to every root.
    tree_rows = np.concatenate([face_a, face_b, np.full(n_pieces, m), root_of_piece])
    tree_cols = np.concatenate([face_b, face_a, root_of_piece, np.full(n_pieces, m)])
    forest = coo_matrix(
        (np.ones(tree_rows.shape[0], dtype=np.int8), (tree_rows, tree_cols)), shape=(m + 1, m + 1)
    ).tocsr()
    _, predecessors = breadth_first_order(forest, m, directed=False, return_predecessors=True)
    parent = predecessors[:m].astype(np.int64)
    parent[parent == m] = root_of_piece[piece[parent == m]]
    parent[root_of_piece] = root_of_piece
    # Parity of the tree edge (f, parent[f]): look it up among the neighbour pairs.
    pair_key = np.concatenate([face_a * (m + 1) + face_b, face_b * (m + 1) + face_a])
    pair_parity = np.concatenate([same_way, same_way])
    order = np.argsort(pair_key, kind="stable")
    sorted_keys = pair_key[order]
    wanted = np.arange(m, dtype=np.int64) * (m + 1) + parent
    where = np.searchsorted(sorted_keys, wanted)
    where = np.minimum(where, sorted_keys.shape[0] - 1) if sorted_keys.size else where
    is_tree_edge = parent != np.arange(m)
    parity = np.zeros(m, dtype=np.bool_)
    if sorted_keys.size:
        parity[is_tree_edge] = pair_parity[order[where[is_tree_edge]]]
    # Pointer jumping: parity[f] becomes the xor of the tree edges from f up to its root.
    jump = parent.copy()
    while True:
        further = jump[jump]
        if np.array_equal(further, jump):
            break
        parity = parity ^ parity[jump]
        jump = further
    flip = parity
    conflicts = int(np.count_nonzero(same_way ^ flip[face_a] ^ flip[face_b]))
    return OrientationFlips(flip=flip, piece=piece, n_pieces=int(n_pieces), n_conflicts=conflicts)
