"""Cutting a triangle mesh by a plane: one vectorised classification, then only the cut triangles.

Every triangle is classified from the sides of its corners with one pass over the mesh. Triangles
entirely on one side (corners on the plane allowed) are kept or dropped whole; only the triangles
with corners strictly on both sides (about √F of them for a plane through a mesh of F triangles)
are split. Each cut edge gets one new vertex, shared by the triangles on both sides of it, so the
result has no cracks and no duplicate vertices; a triangle with a corner on the plane is split
through that corner. Crossing points closer than the tolerance (two edges of a sliver) are one
vertex, and the pieces that collapse with them are dropped.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import NDArray

from geobrep.geometry import mesh
from geobrep.geometry.arrays import BoolArray, FloatArray, IntArray
from geobrep.plugins.clip._sides import (
    NEGATIVE_BIT,
    POSITIVE_BIT,
    crossing_points,
    side_bits,
    vertex_sides,
)

__all__ = ["HalfMesh", "InPlaneRule", "TriangleCut", "cut_triangles"]


#: What happens to a triangle lying in the plane: kept on ``"both"`` sides (open surfaces), or
#: given to the side its normal points away from (``"normal"``: closed surfaces, so each half
#: stays closed), or ``"none"``.
InPlaneRule = Literal["both", "normal", "none"]

_ROTATIONS = np.array([[0, 1, 2], [1, 2, 0], [2, 0, 1]], dtype=np.int64)


@dataclass(frozen=True)
class HalfMesh:
    """One side of a cut triangle mesh, with compact vertex numbering.

    Output vertices are ``kept_points`` (indices of input vertices) followed by the crossing
    points of :class:`TriangleCut` (all of them: each cut edge has pieces on both sides).
    ``face_source`` gives the input triangle of every output face; ``on_plane`` flags output
    vertices on the plane; ``plane_edges`` are the directed edges of output faces whose two ends
    are on the plane (the candidates for the boundary along the cut) and ``plane_edge_faces``
    the output face of each; faces ``in_plane_faces`` lie in the plane.
    """

    vertices: FloatArray
    faces: IntArray
    face_source: IntArray
    kept_points: IntArray
    on_plane: BoolArray
    plane_edges: IntArray
    plane_edge_faces: IntArray
    in_plane_faces: IntArray


@dataclass(frozen=True)
class TriangleCut:
    """A triangle mesh classified against a plane, with its cut triangles split.

    ``sides`` (N,) is −1/0/+1 per input vertex and ``codes`` (M,) ORs the side bits of each
    triangle's corners (1 negative, 2 positive, 3 cut, 0 lying in the plane). Crossing point
    ``e`` is ``points[e] = vertices[edge_a[e]] + edge_t[e] · (vertices[edge_b[e]] − ...)``;
    ``pieces`` (P, 3) index input vertices (< N) or crossing points (N + e), ``piece_side`` and
    ``piece_source`` give each piece's side and input triangle.
    """

    vertices: FloatArray
    triangles: IntArray
    sides: NDArray[np.int8]
    codes: NDArray[np.uint8]
    points: FloatArray
    edge_a: IntArray
    edge_b: IntArray
    edge_t: FloatArray
    pieces: IntArray
    piece_side: NDArray[np.int8]
    piece_source: IntArray

    @property
    def n_points(self) -> int:
        return int(self.vertices.shape[0])

    @property
    def has_on_plane_points(self) -> bool:
        return bool((self.sides == 0).any())

    def half(self, side: int, in_plane: InPlaneRule, plane_normal: FloatArray) -> HalfMesh:
        """The triangles on ``side`` (−1 or +1) with compact numbering."""
        return _half(self, side, in_plane, plane_normal)


def cut_triangles(
    vertices: FloatArray, triangles: IntArray, distances: FloatArray, tolerance: float
) -> TriangleCut:
    """Classify ``triangles`` by the signed ``distances`` of their corners and split the cut ones.

    >>> v = np.array([[0.0, 0, 0], [2, 0, 0], [0, 2, 0]])
    >>> cut = cut_triangles(v, np.array([[0, 1, 2]]), v[:, 0] - 1.0, 1e-12)
    >>> cut.points.tolist(), cut.piece_side.tolist()
    ([[1.0, 0.0, 0.0], [1.0, 1.0, 0.0]], [1, -1, -1])
    """
    n = vertices.shape[0]
    sides = vertex_sides(distances, tolerance)
    bits = side_bits(sides)
    corner_bits = bits[triangles]
    codes = corner_bits[:, 0] | corner_bits[:, 1] | corner_bits[:, 2]
    straddling = np.flatnonzero(codes == (NEGATIVE_BIT | POSITIVE_BIT))
    cut = np.take(triangles, straddling, axis=0)
    corner_sides = sides[cut]
    zero = corner_sides == 0
    has_zero = zero.any(axis=1)
    total = corner_sides.sum(axis=1, dtype=np.int64)
    # The pivot corner: the one on the plane, or else the one alone on its side.
    pivot = np.where(
        has_zero, np.argmax(zero, axis=1), np.argmax(corner_sides == -total[:, None], axis=1)
    )
    order = _ROTATIONS[pivot]
    rotated = np.take_along_axis(cut, order, axis=1)
    rotated_sides = np.take_along_axis(corner_sides, order, axis=1).astype(np.int8)

    lone = np.flatnonzero(~has_zero)  # one corner alone: two cut edges
    through = np.flatnonzero(has_zero)  # a corner on the plane: one cut edge
    ra, rb = rotated[lone], rotated[through]
    starts = np.concatenate([ra[:, 0], ra[:, 0], rb[:, 1]])
    ends = np.concatenate([ra[:, 1], ra[:, 2], rb[:, 2]])
    keys = np.minimum(starts, ends) * n + np.maximum(starts, ends)
    unique_keys, first, inverse = np.unique(keys, return_index=True, return_inverse=True)
    points, edge_a, edge_b, edge_t = crossing_points(
        vertices, distances, starts[first], ends[first]
    )
    points, edge_a, edge_b, edge_t, point_of = _weld_crossings(
        points, edge_a, edge_b, edge_t, tolerance
    )
    new_id = point_of[inverse.reshape(-1)] + n
    k = lone.shape[0]
    p01, p02, p12 = new_id[:k], new_id[k : 2 * k], new_id[2 * k :]

    lone_side = rotated_sides[lone, 0]
    through_side = rotated_sides[through, 1]
    pieces = np.concatenate(
        [
            np.stack([ra[:, 0], p01, p02], axis=1),  # the lone corner's triangle
            np.stack([p01, ra[:, 1], ra[:, 2]], axis=1),  # the other side's quad, in two
            np.stack([p01, ra[:, 2], p02], axis=1),
            np.stack([rb[:, 0], rb[:, 1], p12], axis=1),  # through the corner on the plane
            np.stack([rb[:, 0], p12, rb[:, 2]], axis=1),
        ]
    ).astype(np.int64, copy=False)
    piece_side = np.concatenate(
        [lone_side, -lone_side, -lone_side, through_side, -through_side]
    ).astype(np.int8)
    piece_source = np.concatenate([straddling[lone]] * 3 + [straddling[through]] * 2).astype(
        np.int64, copy=False
    )
    del unique_keys
    if point_of.shape[0] != points.shape[0]:
        # welded crossings: the pieces of a sliver that collapse to a point or an edge go
        real = (
            (pieces[:, 0] != pieces[:, 1])
            & (pieces[:, 1] != pieces[:, 2])
            & (pieces[:, 2] != pieces[:, 0])
        )
        pieces, piece_side, piece_source = pieces[real], piece_side[real], piece_source[real]
    return TriangleCut(
        vertices=vertices,
        triangles=triangles,
        sides=sides,
        codes=codes,
        points=points,
        edge_a=edge_a,
        edge_b=edge_b,
        edge_t=edge_t,
        pieces=pieces,
        piece_side=piece_side,
        piece_source=piece_source,
    )


def _weld_crossings(
    points: FloatArray, edge_a: IntArray, edge_b: IntArray, edge_t: FloatArray, tolerance: float
) -> tuple[FloatArray, IntArray, IntArray, FloatArray, IntArray]:
    """Crossing points within ``tolerance`` of each other made one (the lowest-numbered).

    Two edges of a sliver triangle can cross the plane at one place; left as two points they
    give the cut's boundary a zero-length edge that no cap can close. Returns the welded points
    with the edge each keeps, and ``point_of`` (one entry per crossing) mapping onto them.
    """
    identity = np.arange(points.shape[0], dtype=np.int64)
    if points.shape[0] < 2:
        return points, edge_a, edge_b, edge_t, identity
    merged, point_of = mesh.merge_close_vertices(points, tolerance)
    if merged.shape[0] == points.shape[0]:
        return points, edge_a, edge_b, edge_t, identity
    keeper = np.full(merged.shape[0], points.shape[0], dtype=np.int64)
    np.minimum.at(keeper, point_of, identity)
    return points[keeper], edge_a[keeper], edge_b[keeper], edge_t[keeper], point_of


def _in_plane_selection(
    cut: TriangleCut, side: int, in_plane: InPlaneRule, plane_normal: FloatArray
) -> IntArray:
    if in_plane == "none":
        return np.zeros(0, dtype=np.int64)
    lying = np.flatnonzero(cut.codes == 0)
    if in_plane == "both" or lying.shape[0] == 0:
        return lying
    tri = cut.triangles[lying]
    v = cut.vertices
    a = v[tri[:, 0]]
    normals = np.cross(v[tri[:, 1]] - a, v[tri[:, 2]] - a)
    facing = normals @ plane_normal
    # A face whose normal points to +n bounds a body on its negative side, and vice versa.
    return lying[facing * side < 0]


def _half(cut: TriangleCut, side: int, in_plane: InPlaneRule, plane_normal: FloatArray) -> HalfMesh:
    n = cut.n_points
    bit = NEGATIVE_BIT if side < 0 else POSITIVE_BIT
    whole = np.flatnonzero(cut.codes == bit)
    lying = _in_plane_selection(cut, side, in_plane, plane_normal)
    chosen = np.flatnonzero(cut.piece_side == side)
    extended_faces = np.concatenate(
        [
            np.take(cut.triangles, whole, axis=0),
            np.take(cut.triangles, lying, axis=0),
            cut.pieces[chosen],
        ]
    )
    face_source = np.concatenate([whole, lying, cut.piece_source[chosen]])

    keep = cut.sides == side
    on_plane_input = cut.sides == 0
    any_on_plane = cut.has_on_plane_points
    if any_on_plane:
        referenced = extended_faces[extended_faces < n]
        used = np.zeros(n, dtype=np.bool_)
        used[referenced[on_plane_input[referenced]]] = True
        keep = keep | used
    n_points = cut.points.shape[0]
    extended_keep = np.concatenate([keep, np.ones(n_points, dtype=np.bool_)])
    new_index = np.cumsum(extended_keep, dtype=np.int64) - 1
    faces = np.take(new_index, extended_faces)
    kept_points = np.flatnonzero(keep)
    vertices = np.concatenate([np.take(cut.vertices, kept_points, axis=0), cut.points])
    on_plane = np.concatenate([on_plane_input[kept_points], np.ones(n_points, dtype=np.bool_)])
    # Faces that may have an edge on the plane: the pieces, the faces lying in the plane, and
    # (only when some input vertex is on the plane) whole faces with two corners on it.
    n_whole = whole.shape[0]
    candidates = np.arange(n_whole, faces.shape[0], dtype=np.int64)
    if any_on_plane and n_whole:
        corner_on = on_plane_input[np.take(cut.triangles, whole, axis=0)]
        touching = np.flatnonzero(corner_on.sum(axis=1) >= 2)
        candidates = np.concatenate([touching, candidates])
    plane_edges, edge_rows = _edges_on_plane(faces[candidates], on_plane)
    in_plane_faces = np.arange(n_whole, n_whole + lying.shape[0], dtype=np.int64)
    return HalfMesh(
        vertices=vertices,
        faces=faces,
        face_source=face_source,
        kept_points=kept_points,
        on_plane=on_plane,
        plane_edges=plane_edges,
        plane_edge_faces=candidates[edge_rows],
        in_plane_faces=in_plane_faces,
    )


def _edges_on_plane(faces: IntArray, on_plane: BoolArray) -> tuple[IntArray, IntArray]:
    """Directed edges (a, b) of ``faces`` with both ends on the plane, and the row of each."""
    if faces.shape[0] == 0:
        return np.zeros((0, 2), dtype=np.int64), np.zeros(0, dtype=np.int64)
    starts = faces.reshape(-1)
    ends = faces[:, [1, 2, 0]].reshape(-1)
    both = np.flatnonzero(on_plane[starts] & on_plane[ends])
    return np.stack([starts[both], ends[both]], axis=1), both // 3
