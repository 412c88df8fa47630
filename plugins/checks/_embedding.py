"""A sufficient test that a surface cannot cross itself: an embedded disk over a plane.

Most geological surfaces (horizons, many faults) are height fields over some plane. When a
surface is a topological disk whose triangles all face one side of a direction ``d`` (the
surface's mean normal), and its projection on the plane ⊥ ``d`` is locally one-to-one (the
triangles' angles around each inner vertex add up to one turn, around each border vertex to
less than one) with a border that projects to a simple polygon, the projection is one-to-one
(an immersed disk whose border is embedded is embedded): two triangles that share no vertex are
apart in the plane, so in space. :func:`embedded_disk` checks those conditions in O(M log M)
numpy work; a surface passing it has no self-intersection, and the pairwise search is skipped.
Any doubt (a degenerate or steep triangle, a weld inside the surface, a non-manifold or
inconsistent edge, a hole, a border touching itself) answers ``False``: the pairwise search
then runs as before.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from geobrep.geometry.orientation import neighbour_pairs
from geobrep.plugins.checks._pairs import near_pairs

__all__ = ["embedded_disk"]

IntArray = NDArray[np.int64]
FloatArray = NDArray[np.float64]

#: Triangles must face ``d`` by more than this cosine (a steeper one makes the test give up).
_MIN_COSINE = 1e-6
#: Relative slack of the border's simplicity test (segments nearer than this count as meeting).
_BORDER_SLACK = 1e-9


def _plane(normals: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray] | None:
    """The mean normal ``d`` and two unit vectors spanning the plane ⊥ ``d``."""
    d = normals.sum(axis=1)
    size = float(np.linalg.norm(d))
    if not size > 0.0:
        return None
    d = d / size
    helper = np.zeros(3)
    helper[int(np.argmin(np.abs(d)))] = 1.0
    e1 = np.cross(d, helper)
    e1 /= np.linalg.norm(e1)
    return d, e1, np.cross(d, e1)


def _border_is_simple(x: FloatArray, y: FloatArray, border: IntArray) -> bool:
    """Whether no two border segments (B, 2) without a common vertex meet in the plane."""
    ends = np.stack([np.column_stack([x[border[:, k]], y[border[:, k]]]) for k in (0, 1)], 1)
    scale = float(np.abs(ends).max(initial=0.0)) or 1.0
    slack = _BORDER_SLACK * scale
    flat = np.concatenate([ends, np.zeros((ends.shape[0], 2, 1))], axis=2)
    i, j = near_pairs(flat[:, [0, 1, 1]], slack)
    apart = (
        (border[i, 0] != border[j, 0])
        & (border[i, 0] != border[j, 1])
        & (border[i, 1] != border[j, 0])
        & (border[i, 1] != border[j, 1])
    )
    i, j = i[apart], j[apart]
    if i.size == 0:
        return True
    p, q, r, s = ends[i, 0], ends[i, 1], ends[j, 0], ends[j, 1]

    def side(a: FloatArray, b: FloatArray, c: FloatArray) -> FloatArray:
        area = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])
        length = np.maximum(np.linalg.norm(b - a, axis=1), slack)
        return np.asarray(area / length)  # signed distance of c from line ab

    d1, d2 = side(p, q, r), side(p, q, s)
    d3, d4 = side(r, s, p), side(r, s, q)
    # Clearly on one side of the other's line (beyond the slack): apart; anything else: doubt.
    apart_pairs = ((d1 > slack) & (d2 > slack)) | ((d1 < -slack) & (d2 < -slack))
    apart_pairs |= ((d3 > slack) & (d4 > slack)) | ((d3 < -slack) & (d4 < -slack))
    return bool(apart_pairs.all())


def _angle_sums(x: FloatArray, y: FloatArray, tris: IntArray, n: int) -> FloatArray:
    """Per vertex, the sum of its corners' angles in the plane (triangles counter-clockwise)."""
    total = np.zeros(n)
    for c in range(3):
        a, b, o = tris[:, (c + 1) % 3], tris[:, (c + 2) % 3], tris[:, c]
        ux, uy = x[a] - x[o], y[a] - y[o]
        vx, vy = x[b] - x[o], y[b] - y[o]
        total += np.bincount(o, np.arctan2(ux * vy - uy * vx, ux * vx + uy * vy), minlength=n)
    return total


def embedded_disk(
    vertices: FloatArray,
    tris: IntArray,
    incidence: tuple[IntArray, IntArray, IntArray, IntArray],
    merged: IntArray,
    same_way: NDArray[np.bool_] | None = None,
) -> bool:
    """Whether triangles ``tris`` over ``vertices`` form a disk embedded over a plane (see the
    module), so that no two of them sharing no vertex meet. ``incidence`` is the triangles'
    edge table (:func:`~geobrep.geometry.mesh.edge_face_incidence`), ``merged`` the welded index
    of each vertex (a weld inside the surface makes the test give up); ``same_way``, if known,
    says for each pair of triangles across an edge whether they run it the same way
    (:func:`~geobrep.geometry.orientation.neighbour_pairs`)."""
    n, m = vertices.shape[0], tris.shape[0]
    if m < 2:
        return False
    used = np.zeros(n, dtype=np.bool_)
    used[tris.reshape(-1)] = True
    kept = np.sort(merged[used])
    if (kept[1:] == kept[:-1]).any():
        return False
    local = vertices - vertices[tris[0, 0]]
    columns = np.ascontiguousarray(local.T)
    a, b, c = (np.take(columns, tris[:, k], axis=1) for k in range(3))
    u, v = b - a, c - a
    normals = np.stack(
        [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]]
    )
    plane = _plane(normals)
    if plane is None:
        return False
    d, e1, e2 = plane
    size = np.sqrt((normals * normals).sum(axis=0))
    if not ((d @ normals) > _MIN_COSINE * size).all():
        return False
    edges, offsets, incident, sides = incidence
    counts = np.diff(offsets)
    if (counts > 2).any():
        return False
    if same_way is None:
        same_way = neighbour_pairs(tris, offsets, incident * 3 + sides)[2]
    if same_way.any():
        return False
    border = edges[counts == 1]
    degree = np.bincount(border.reshape(-1), minlength=n)
    if border.shape[0] < 3 or not np.isin(degree, (0, 2)).all():
        return False
    if int(used.sum()) - edges.shape[0] + m != 1 or _loops(border, n) != 1:
        return False
    x, y = local @ e1, local @ e2
    total = _angle_sums(x, y, tris, n)
    inner = used & (degree == 0)
    if (total[inner] > 3.0 * np.pi).any() or (total[degree == 2] >= 2.0 * np.pi - 1e-9).any():
        return False
    return _border_is_simple(x, y, border)


def _loops(border: IntArray, n: int) -> int:
    """How many closed loops the border edges (each vertex on two of them) form."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    nodes, index = np.unique(border, return_inverse=True)
    index = index.reshape(-1, 2)
    k = nodes.shape[0]
    graph = coo_matrix((np.ones(index.shape[0], np.int8), (index[:, 0], index[:, 1])), (k, k))
    return int(connected_components(graph, directed=False)[0])
