"""Vectorised kernels on polygon meshes: ``vertices`` (N, 3) float64, ``faces`` (M, 3) or (M, 4).

Faces are triangles or quads of vertex indices (any integer dtype); side ``j`` of a face runs
from corner ``j`` to corner ``(j + 1) % k``. Every function accepts M = 0.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from geobrep.errors import DegenerateGeometryError, EntityValidationError
from geobrep.geometry.arrays import BoolArray, FloatArray, IntArray
from geobrep.geometry.bbox import column_extremes
from geobrep.geometry.graph import (
    cell_hash,
    close_pairs,
    component_roots,
    equal_rows,
    hashed_order,
)
from geobrep.geometry.plane import _as_float_array, _as_point, _check_tolerance
from geobrep.geometry.sorting import digit_order, radix_order, radix_pays, sorted_keys

__all__ = [
    "boundary_edges",
    "compact_indices",
    "csr_row_positions",
    "edge_face_counts",
    "edge_face_incidence",
    "face_areas",
    "face_centroids",
    "face_normals",
    "first_of_duplicates",
    "flip_faces",
    "is_closed",
    "is_consistently_oriented",
    "merge_close_vertices",
    "merge_close_vertices_in_parts",
    "non_manifold_edges",
    "part_vertices",
    "signed_volume",
    "sort_around_axis",
    "surface_area",
    "triangulate",
    "unique_edges",
]


_INT64_MAX = np.iinfo(np.int64).max
_MAX_KEY_BASE = 3_037_000_499  # floor(sqrt(2**63 - 1))
# Relative length under which a direction's projection on the plane ⊥ axis counts as zero.
_PROJECTION_RTOL = 1e-12


# --------------------------------------------------------------------------- validation
def _as_faces(faces: ArrayLike, entity: str, n_vertices: int | None = None) -> IntArray:
    """Return ``faces`` as an int64 (M, 3) or (M, 4) array of valid vertex indices."""
    arr = np.asarray(faces)
    if arr.ndim != 2 or arr.shape[1] not in (3, 4):
        raise EntityValidationError(
            entity, "faces", f"expected shape (M, 3) or (M, 4), got {arr.shape}"
        )
    if arr.size == 0:
        return np.zeros(arr.shape, dtype=np.int64)
    if not np.issubdtype(arr.dtype, np.integer):
        raise EntityValidationError(entity, "faces", f"expected an integer dtype, got {arr.dtype}")
    out = arr.astype(np.int64, copy=False)
    lowest = int(out.min())
    if lowest < 0:
        raise EntityValidationError(entity, "faces", f"negative vertex index {lowest}")
    if n_vertices is not None:
        highest = int(out.max())
        if highest >= n_vertices:
            raise EntityValidationError(
                entity, "faces", f"vertex index {highest} out of range for {n_vertices} vertices"
            )
    return out


def _as_vertices(vertices: ArrayLike, entity: str) -> FloatArray:
    """Return ``vertices`` as a finite float64 (N, 3) array."""
    arr = _as_float_array(vertices, entity, "vertices")
    if arr.ndim != 2 or arr.shape[1] != 3:
        raise EntityValidationError(entity, "vertices", f"expected shape (N, 3), got {arr.shape}")
    if not np.isfinite(arr).all():
        raise EntityValidationError(entity, "vertices", "contains NaN or infinite values")
    return arr


def _mesh(vertices: ArrayLike, faces: ArrayLike, entity: str) -> tuple[FloatArray, IntArray]:
    verts = _as_vertices(vertices, entity)
    return verts, _as_faces(faces, entity, verts.shape[0])


# --------------------------------------------------------------------------- edge keys
def _side_ends(faces: IntArray) -> tuple[IntArray, IntArray]:
    """Start and end vertex of every face side, each (M, k); the ends are a new array."""
    return faces, _following(faces)


def _following(faces: IntArray) -> IntArray:
    """``faces[:, [1, ..., k - 1, 0]]`` (a new array) by two slice copies: about three times
    faster than the fancy indexing."""
    out = np.empty(faces.shape, dtype=faces.dtype)  # C order, as fancy indexing gives
    out[:, :-1] = faces[:, 1:]
    out[:, -1] = faces[:, 0]
    return out


def _key_base(faces: IntArray) -> int:
    """Multiplier making lo * base + hi unique per edge; base² must fit in int64."""
    base = int(faces.max()) + 1 if faces.size else 1
    if base > _MAX_KEY_BASE:
        raise EntityValidationError(
            "mesh", "faces", f"vertex index {base - 1} too large for int64 edge keys"
        )
    return base


def _undirected_keys(faces: IntArray) -> tuple[IntArray, int]:
    """One int64 key lo * base + hi per face side (flattened, row-major), and ``base``."""
    start, end = _side_ends(faces)  # ``end`` is a new array (fancy indexing): reused below
    base = _key_base(faces)
    keys = np.minimum(start, end)
    np.maximum(start, end, out=end)
    keys *= base
    keys += end  # in place: two (M, k) arrays at a time, not four
    return keys.ravel(), base


def _directed_keys(faces: IntArray) -> IntArray:
    start, end = _side_ends(faces)
    return (start * _key_base(faces) + end).ravel()


def _stable_sort(keys: IntArray) -> tuple[IntArray, IntArray]:
    """Sorted keys and the stable permutation that sorts them.

    When key * len + position fits in int64, one packed ``np.sort`` replaces the (about
    four times slower) ``argsort``; ties keep their order because positions are packed in.
    """
    n = keys.shape[0]
    if n == 0:
        return keys.copy(), np.zeros(0, dtype=np.int64)
    max_key = int(keys.max())
    bits = (n - 1).bit_length()
    if int(keys.min()) >= 0 and max_key.bit_length() + bits <= 63:
        # Bit fields instead of key * n + position: shifts and masks, no int64 divisions.
        packed = np.sort((keys << bits) | np.arange(n, dtype=np.int64))
        return packed >> bits, packed & ((1 << bits) - 1)
    if max_key < (_INT64_MAX - n) // n:
        packed = np.sort(keys * n + np.arange(n, dtype=np.int64))
        return packed // n, packed % n
    perm = np.argsort(keys, kind="stable")
    return keys[perm], perm


def _edge_table(faces: IntArray) -> tuple[IntArray, IntArray, IntArray, IntArray]:
    """``(edges, face_edges, offsets, perm)``: one sort shared by the edge functions.

    ``perm`` lists the flattened face sides grouped by edge (faces ascending within an edge)
    and ``offsets`` (E + 1,) delimits the groups.
    """
    m, k = faces.shape
    edges, offsets, perm, first = _edge_groups(faces)
    inverse = np.empty(perm.shape[0], dtype=np.int64)
    inverse[perm] = np.cumsum(first) - 1
    return edges, inverse.reshape(m, k), offsets, perm


def _edge_groups(faces: IntArray) -> tuple[IntArray, IntArray, IntArray, BoolArray]:
    """``(edges, offsets, perm, first)`` of :func:`_edge_table` without the face-edge map;
    ``first`` marks the sorted sides that start an edge's group."""
    keys, base = _undirected_keys(faces)
    sorted_keys, perm = _stable_sort(keys)
    first = np.ones(sorted_keys.shape[0], dtype=np.bool_)
    np.not_equal(sorted_keys[1:], sorted_keys[:-1], out=first[1:])
    starts = np.flatnonzero(first)
    unique_keys = np.take(sorted_keys, starts)
    edges = np.empty((starts.shape[0], 2), dtype=np.int64)
    np.floor_divide(unique_keys, base, out=edges[:, 0])
    np.subtract(unique_keys, edges[:, 0] * base, out=edges[:, 1])
    offsets = np.append(starts, sorted_keys.shape[0]).astype(np.int64, copy=False)
    return edges, offsets, perm, first


# --------------------------------------------------------------------------- faces
def triangulate(faces: ArrayLike) -> tuple[IntArray, IntArray]:
    """Split faces into triangles: ``(triangles (T, 3), source_face (T,))``.

    Quads are split along their 0-2 diagonal into (0, 1, 2) and (0, 2, 3).

    >>> tris, src = triangulate([[0, 1, 2, 3]])
    >>> tris.tolist(), src.tolist()
    ([[0, 1, 2], [0, 2, 3]], [0, 0])
    """
    f = _as_faces(faces, "triangulate")
    m = f.shape[0]
    if f.shape[1] == 3:
        return f.copy(), np.arange(m, dtype=np.int64)
    tris = np.stack([f[:, [0, 1, 2]], f[:, [0, 2, 3]]], axis=1).reshape(-1, 3)
    return tris, np.repeat(np.arange(m, dtype=np.int64), 2)


def flip_faces(faces: ArrayLike) -> IntArray:
    """Reverse the winding of every face, keeping corner 0 first (quads keep their 0-2 diagonal).

    >>> flip_faces([[0, 1, 2], [3, 4, 5]]).tolist()
    [[0, 2, 1], [3, 5, 4]]
    """
    f = _as_faces(faces, "flip_faces")
    k = f.shape[1]
    return f[:, [0, *range(k - 1, 0, -1)]]


def _columns(verts: FloatArray, centre: FloatArray | None = None) -> FloatArray:
    """Coordinates as a contiguous (3, N) array (optionally centred): fast per-axis gathers."""
    local = verts if centre is None else verts - centre
    return np.ascontiguousarray(local.T)


def _gather(columns: FloatArray, index: IntArray) -> FloatArray:
    """Corner coordinates (3, M) of the given vertex indices."""
    return np.take(columns, index, axis=1)


def _cross(u: FloatArray, v: FloatArray) -> FloatArray:
    """Cross products of (3, M) column vectors (about twice as fast as ``np.cross`` on rows)."""
    out = np.empty_like(u)
    np.multiply(u[1], v[2], out=out[0])
    out[0] -= u[2] * v[1]
    np.multiply(u[2], v[0], out=out[1])
    out[1] -= u[0] * v[2]
    np.multiply(u[0], v[1], out=out[2])
    out[2] -= u[1] * v[0]
    return out


def _norms(vectors: FloatArray) -> FloatArray:
    """Lengths of (3, M) column vectors."""
    return np.asarray(np.sqrt(np.einsum("ij,ij->j", vectors, vectors)), dtype=np.float64)


def _doubled_vector_areas(columns: FloatArray, f: IntArray) -> FloatArray:
    """Twice the vector area (3, M): edge cross product for triangles, diagonals for quads."""
    if f.shape[1] == 3:
        p0 = _gather(columns, f[:, 0])
        return _cross(_gather(columns, f[:, 1]) - p0, _gather(columns, f[:, 2]) - p0)
    diagonal_02 = _gather(columns, f[:, 2]) - _gather(columns, f[:, 0])
    diagonal_13 = _gather(columns, f[:, 3]) - _gather(columns, f[:, 1])
    return _cross(diagonal_02, diagonal_13)


def face_normals(vertices: ArrayLike, faces: ArrayLike, normalize: bool = True) -> FloatArray:
    """Face normals (M, 3) by the right-hand rule; degenerate faces give a zero vector.

    Quads use the cross product of their diagonals (Newell-like). With ``normalize=False``
    the result is the vector area (length = area for triangles and planar quads).

    >>> face_normals([[0, 0, 0], [2, 0, 0], [0, 2, 0]], [[0, 1, 2]], normalize=False).tolist()
    [[0.0, 0.0, 2.0]]
    """
    verts, f = _mesh(vertices, faces, "face_normals")
    normals = _doubled_vector_areas(_columns(verts), f)
    if normalize:
        length = _norms(normals)
        normals /= np.where(length > 0.0, length, 1.0)
    else:
        normals *= 0.5
    return np.ascontiguousarray(normals.T)


def face_areas(vertices: ArrayLike, faces: ArrayLike) -> FloatArray:
    """Area of each face (M,); a quad's area is that of its two triangles (0-2 diagonal).

    >>> face_areas([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], [[0, 1, 2, 3]]).tolist()
    [1.0]
    """
    verts, f = _mesh(vertices, faces, "face_areas")
    columns = _columns(verts)
    if f.shape[1] == 3:
        return 0.5 * _norms(_doubled_vector_areas(columns, f))
    p0 = _gather(columns, f[:, 0])
    diagonal = _gather(columns, f[:, 2]) - p0
    first = _norms(_cross(_gather(columns, f[:, 1]) - p0, diagonal))
    second = _norms(_cross(diagonal, _gather(columns, f[:, 3]) - p0))
    return 0.5 * (first + second)


def face_centroids(vertices: ArrayLike, faces: ArrayLike) -> FloatArray:
    """Average of each face's corners (M, 3).

    >>> face_centroids([[0, 0, 0], [3, 0, 0], [0, 3, 0]], [[0, 1, 2]]).tolist()
    [[1.0, 1.0, 0.0]]
    """
    verts, f = _mesh(vertices, faces, "face_centroids")
    columns = _columns(verts)
    first = _gather(columns, f[:, 0])
    # Average the offsets from corner 0: keeps precision at UTM-scale coordinates.
    offsets = sum((_gather(columns, f[:, j]) - first for j in range(1, f.shape[1])), start=0.0)
    return np.ascontiguousarray((first + offsets / f.shape[1]).T)


def surface_area(vertices: ArrayLike, faces: ArrayLike) -> float:
    """Total area of the faces.

    >>> surface_area([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]])
    0.5
    """
    return float(face_areas(vertices, faces).sum())


def signed_volume(vertices: ArrayLike, faces: ArrayLike) -> float:
    """Volume enclosed by a closed mesh (divergence theorem); positive if faces point outwards.

    Coordinates are centred on their bounding-box centre first, so UTM-scale meshes keep
    full precision. Quads count as their two triangles (0-2 diagonal).

    >>> signed_volume([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]],
    ...               [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    0.16666666666666666
    """
    verts, f = _mesh(vertices, faces, "signed_volume")
    if f.shape[0] == 0:
        return 0.0
    columns = _columns(verts, 0.5 * np.add(*column_extremes(verts)))
    tris = f if f.shape[1] == 3 else triangulate(f)[0]  # only read: no copy of triangles
    total = 0.0
    for start in range(0, tris.shape[0], _VOLUME_CHUNK):  # corners gathered a chunk at a time
        part = tris[start : start + _VOLUME_CHUNK]
        a = _gather(columns, part[:, 0])
        cross = _cross(_gather(columns, part[:, 1]), _gather(columns, part[:, 2]))
        total += float(np.einsum("ij,ij->", a, cross))
    return total / 6.0


#: Triangles whose corners :func:`signed_volume` gathers at once (about 40 MB of temporaries).
_VOLUME_CHUNK = 1 << 18


# --------------------------------------------------------------------------- edges
def unique_edges(faces: ArrayLike) -> tuple[IntArray, IntArray]:
    """Undirected edges ``(edges (E, 2), face_edges (M, k))``, ``edges`` sorted by (lo, hi).

    ``edges[:, 0] < edges[:, 1]`` (``<=`` only for faces repeating a vertex index) and
    ``face_edges[i, j]`` is the edge of side j of face i.

    >>> edges, face_edges = unique_edges([[0, 1, 2], [2, 1, 3]])
    >>> edges.tolist(), face_edges.tolist()
    ([[0, 1], [0, 2], [1, 2], [1, 3], [2, 3]], [[0, 2, 1], [2, 3, 4]])
    """
    f = _as_faces(faces, "unique_edges")
    edges, face_edges, _, _ = _edge_table(f)
    return edges, face_edges


def edge_face_counts(faces: ArrayLike) -> tuple[IntArray, IntArray]:
    """Undirected edges (E, 2) and the number of face sides using each (E,).

    >>> edge_face_counts([[0, 1, 2], [2, 1, 3]])[1].tolist()
    [1, 1, 2, 1, 1]
    """
    f = _as_faces(faces, "edge_face_counts")
    edges, _, offsets, _ = _edge_table(f)
    return edges, np.diff(offsets)


def boundary_edges(faces: ArrayLike) -> IntArray:
    """Edges (B, 2) used by exactly one face side.

    >>> boundary_edges([[0, 1, 2], [2, 1, 3]]).tolist()
    [[0, 1], [0, 2], [1, 3], [2, 3]]
    """
    edges, counts = edge_face_counts(faces)
    return np.asarray(edges[counts == 1], dtype=np.int64)


def non_manifold_edges(faces: ArrayLike) -> IntArray:
    """Edges (B, 2) used by more than two face sides.

    >>> non_manifold_edges([[0, 1, 2], [1, 0, 3], [0, 1, 4]]).tolist()
    [[0, 1]]
    """
    edges, counts = edge_face_counts(faces)
    return np.asarray(edges[counts > 2], dtype=np.int64)


def edge_face_incidence(faces: ArrayLike) -> tuple[IntArray, IntArray, IntArray, IntArray]:
    """Faces around each edge in CSR form: ``(edges, offsets, incident_faces, incident_sides)``.

    The faces using edge e are ``incident_faces[offsets[e]:offsets[e + 1]]`` (ascending) and
    ``incident_sides`` gives which side of each of those faces it is.

    >>> edges, offsets, fs, sides = edge_face_incidence([[0, 1, 2], [2, 1, 3]])
    >>> e = 2  # edge (1, 2)
    >>> fs[offsets[e]:offsets[e + 1]].tolist(), sides[offsets[e]:offsets[e + 1]].tolist()
    ([0, 1], [1, 0])
    """
    f = _as_faces(faces, "edge_face_incidence")
    m, k = f.shape
    vertex_bits = max(int(f.max(initial=0)).bit_length(), 1)
    side_bits = max((m * k - 1).bit_length(), 1)
    if m and 2 * vertex_bits + side_bits <= 63:
        return _incidence_by_bits(f, vertex_bits, side_bits)
    if m and radix_pays(m * k, 2 * vertex_bits):
        return _incidence_by_radix(f, vertex_bits)
    edges, offsets, perm, _ = _edge_groups(f)
    face = perm // k
    return edges, offsets, face, perm - face * k


#: Faces keyed at a time (temporaries that stay in cache).
_KEY_ROWS = 32_768


def _in_runs(faces: IntArray) -> bool:
    """Whether the faces come mostly in runs of ascending first vertices, as a generated grid
    and a soup of such surfaces do (checked on the first 65,536): numpy's stable sort
    (timsort) then merges the runs of their edge keys, faster than radix passes (1M layer-cake
    triangles 58 against 191 ms CPU); modelA4's 49k faces, in no such order, 6.0 against 3.6.
    """
    head = faces[: 1 << 16, 0]
    return bool(np.count_nonzero(head[1:] < head[:-1]) < 0.25 * head.shape[0])


def _incidence_by_radix(
    faces: IntArray, vertex_bits: int
) -> tuple[IntArray, IntArray, IntArray, IntArray]:
    """:func:`edge_face_incidence` from the stable radix order of the sides' edge keys (low
    vertex, high vertex), which lists the sides of an edge in position order as
    :func:`_incidence_by_bits` does."""
    k = faces.shape[1]
    low = _following(faces)
    high = np.maximum(faces, low)
    np.minimum(faces, low, out=low)
    if vertex_bits <= 16:  # the vertices are the two digits
        low16, high16 = low.astype(np.uint16).reshape(-1), high.astype(np.uint16).reshape(-1)
        position = digit_order(low16, high16)
        low16, high16 = np.take(low16, position), np.take(high16, position)
        starts_mask = np.ones(position.shape[0], dtype=np.bool_)
        np.not_equal(low16[1:], low16[:-1], out=starts_mask[1:])
        starts_mask[1:] |= high16[1:] != high16[:-1]
        starts = np.flatnonzero(starts_mask)
        edges = np.empty((starts.shape[0], 2), dtype=np.int64)
        edges[:, 0] = np.take(low16, starts)
        edges[:, 1] = np.take(high16, starts)
    else:
        low <<= vertex_bits
        low |= high
        keys = low.reshape(-1)
        position = radix_order(keys, 2 * vertex_bits)
        return _incidence_of_sorted(np.take(keys, position), position, vertex_bits, k)
    offsets = np.append(starts, position.shape[0]).astype(np.int64, copy=False)
    face = position // k
    return edges, offsets, face, position - face * k


def _incidence_by_bits(
    faces: IntArray, vertex_bits: int, side_bits: int
) -> tuple[IntArray, IntArray, IntArray, IntArray]:
    """:func:`edge_face_incidence` from one in-place sort of the sides packed as bit fields
    (low vertex, high vertex, side position), keyed in cache-sized slices of faces: the order
    of ``(edge key, position)`` that :func:`_stable_sort` gives, without its copies. The sort
    is numpy's stable one (timsort): the keys are unique, so every sort gives this order, and
    a mesh's faces usually come in runs along which the keys ascend, which timsort merges
    rather than sorts again (3-7x faster than quicksort on surfaces listed row by row, within
    a fifth of it on keys in random order)."""
    m, k = faces.shape
    packed = np.empty((m, k), dtype=np.int64)
    for start in range(0, m, _KEY_ROWS):
        rows = slice(start, start + _KEY_ROWS)
        first = faces[rows]
        low = _following(first)  # a new array: the side ends, then the low ends
        high = np.maximum(first, low)
        np.minimum(first, low, out=low)
        low <<= vertex_bits
        low |= high
        low <<= side_bits
        packed[rows] = low
    flat = packed.reshape(-1)
    flat |= np.arange(m * k, dtype=np.int64)
    # the keys are unique (positions packed in): every sort kind gives the same order
    flat.sort(kind="stable" if _in_runs(faces) else "quicksort")
    mask = (1 << side_bits) - 1
    position = flat & mask
    flat >>= side_bits  # the edge keys, ascending
    return _incidence_of_sorted(flat, position, vertex_bits, k)


def _incidence_of_sorted(
    ordered: IntArray, position: IntArray, vertex_bits: int, k: int
) -> tuple[IntArray, IntArray, IntArray, IntArray]:
    """:func:`edge_face_incidence` from the sides' edge keys (low vertex, high vertex) in
    ascending order and the position (face * k + corner) of each."""
    starts_mask = np.ones(ordered.shape[0], dtype=np.bool_)
    np.not_equal(ordered[1:], ordered[:-1], out=starts_mask[1:])
    starts = np.flatnonzero(starts_mask)
    unique_keys = np.take(ordered, starts)
    edges = np.empty((starts.shape[0], 2), dtype=np.int64)
    np.right_shift(unique_keys, vertex_bits, out=edges[:, 0])
    np.bitwise_and(unique_keys, (1 << vertex_bits) - 1, out=edges[:, 1])
    offsets = np.append(starts, ordered.shape[0]).astype(np.int64, copy=False)
    face = position // k
    return edges, offsets, face, position - face * k


def is_closed(faces: ArrayLike) -> bool:
    """Whether the mesh is non-empty and every undirected edge is used by exactly two faces.

    >>> is_closed([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    True
    """
    f = _as_faces(faces, "is_closed")
    if f.shape[0] == 0:
        return False
    keys, _ = _undirected_keys(f)
    s = np.sort(keys)
    if s.shape[0] % 2:
        return False
    even, odd = s[0::2], s[1::2]
    return bool(np.array_equal(even, odd) and (odd[:-1] != even[1:]).all())


def is_consistently_oriented(faces: ArrayLike) -> bool:
    """Whether no directed edge appears twice (neighbours traverse shared edges oppositely).

    >>> is_consistently_oriented([[0, 1, 2], [2, 1, 3]])
    True
    >>> is_consistently_oriented([[0, 1, 2], [1, 2, 3]])
    False
    """
    f = _as_faces(faces, "is_consistently_oriented")
    if f.size == 0:
        return True
    bits = max(int(f.max()).bit_length(), 1)
    if 2 * bits <= 63:  # the indices are >= 0
        # one int64 key (start, end) per side as bit fields, sorted by numpy's own sort
        # (faster than radix passes of 16-bit digits or a stable sort of keys in no order)
        keys = f << bits
        keys |= _following(f)
        s = np.sort(keys.reshape(-1))
    else:
        s = sorted_keys(_directed_keys(f))
    return bool((s[1:] != s[:-1]).all())


# --------------------------------------------------------------------------- vertices
def _merge_candidates(local: FloatArray, tol: float) -> tuple[IntArray, BoolArray, IntArray]:
    """Vertices that may lie within ``tol`` of another one (a superset; pairs are checked
    after), with whether each lies near a face of its cube and its cube's hash.

    Vertices are binned in cubes of side about ``1000 · tol`` (a hash of the cube numbers, so
    any extent works): two vertices within ``tol`` of each other share a cube or both lie
    within ``tol`` of a cube face, so only vertices in crowded cubes or near a face need the
    exact search — a small share of distinct vertices whose spacing exceeds the tolerance.
    Falls back to every vertex (all near a face) when the cubes are too fine for the
    coordinates.
    """
    n = local.shape[0]
    everything = np.arange(n, dtype=np.int64)
    # An odd cube size and a shifted origin keep lattice-aligned vertices off the cube faces.
    cell = 1021.37 * tol
    reach = float(np.abs(local).max()) if n else 0.0
    if cell <= 1e-9 * reach or reach / cell > 2.0**60:
        return everything, np.ones(n, dtype=np.bool_), np.zeros(n, dtype=np.int64)
    shifted = local + 0.3819 * cell
    scaled = np.floor(shifted / cell)
    offsets = shifted - scaled * cell
    margin = 2.0 * tol + 8.0 * np.finfo(np.float64).eps * reach
    face = (offsets <= margin) | (offsets >= cell - margin)
    near_face = face[:, 0] | face[:, 1] | face[:, 2]  # column operations: faster than any()
    order, sorted_keys = hashed_order(cell_hash(scaled.astype(np.int64)))
    same = sorted_keys[1:] == sorted_keys[:-1]
    crowded = np.zeros(n, dtype=np.bool_)
    crowded[order[1:][same]] = True
    crowded[order[:-1][same]] = True
    candidates = np.flatnonzero(near_face | crowded).astype(np.int64)
    cube = np.empty(n, dtype=np.int64)
    cube[order] = sorted_keys
    return candidates, near_face[candidates], cube[candidates]


def _repeated(keys: IntArray) -> BoolArray:
    """Whether each key occurs more than once."""
    order = np.argsort(keys)
    ordered = keys[order]
    same = ordered[1:] == ordered[:-1]
    repeated = np.zeros(keys.shape[0], dtype=np.bool_)
    repeated[order[1:][same]] = True
    repeated[order[:-1][same]] = True
    return repeated


def first_of_duplicates(cells: ArrayLike) -> BoolArray:
    """True for each cell (row of vertex ids) not seen before in any corner order: the cells to
    keep when dropping duplicated elements.

    >>> first_of_duplicates([[0, 1, 2], [2, 1, 0], [1, 2, 3]]).tolist()
    [True, False, True]
    """
    rows = np.asarray(cells)
    keep = np.zeros(rows.shape[0], dtype=np.bool_)
    if rows.shape[0]:
        _, first = np.unique(np.sort(rows, axis=1), axis=0, return_index=True)
        keep[first] = True
    return keep


def compact_indices(indices: ArrayLike, n: int) -> tuple[IntArray, IntArray]:
    """The used values of ``indices`` (all in ``[0, n)``), sorted, and ``indices`` renumbered
    into them — ``np.unique(indices, return_inverse=True)`` in linear time.

    >>> used, renumbered = compact_indices([[4, 1, 7], [7, 1, 9]], 10)
    >>> used.tolist(), renumbered.tolist()
    ([1, 4, 7, 9], [[1, 0, 2], [2, 0, 3]])
    """
    arr = np.asarray(indices, dtype=np.int64)
    present = np.zeros(n, dtype=np.bool_)
    present[arr.reshape(-1)] = True
    rank = np.cumsum(present, dtype=np.int64) - 1
    return np.flatnonzero(present).astype(np.int64), rank[arr]


def csr_row_positions(offsets: IntArray, rows: IntArray) -> tuple[IntArray, IntArray]:
    """Flat positions of the CSR rows ``rows`` (row ``r`` holds ``offsets[r]:offsets[r + 1]``)
    and the row (index into ``rows``) of each.

    >>> positions, row = csr_row_positions(np.array([0, 2, 2, 5]), np.array([2, 0]))
    >>> positions.tolist(), row.tolist()
    ([2, 3, 4, 0, 1], [0, 0, 0, 1, 1])
    """
    starts = offsets[rows]
    counts = offsets[rows + 1] - starts
    owner = np.repeat(np.arange(rows.shape[0], dtype=np.int64), counts)
    within = np.arange(owner.shape[0], dtype=np.int64) - np.repeat(
        np.cumsum(counts) - counts, counts
    )
    return np.repeat(starts, counts) + within, owner


def merge_close_vertices(vertices: ArrayLike, tolerance: float) -> tuple[FloatArray, IntArray]:
    """Merge vertices within ``tolerance`` of each other: ``(unique_vertices, inverse (N,))``.

    Groups are connected components of the "distance ≤ tolerance" graph (so chains merge);
    each group keeps its lowest-index vertex, in order of first appearance, and
    ``unique_vertices[inverse]`` approximates ``vertices``. ``tolerance=0`` merges exact
    duplicates only.

    >>> u, inv = merge_close_vertices([[0, 0, 0], [5, 0, 0], [0, 0, 1e-9]], 1e-6)
    >>> u.tolist(), inv.tolist()
    ([[0.0, 0.0, 0.0], [5.0, 0.0, 0.0]], [0, 1, 0])
    """
    verts = _as_vertices(vertices, "merge_close_vertices")
    tol = _check_tolerance(tolerance, "merge_close_vertices")
    n = verts.shape[0]
    if n == 0:
        return verts.copy(), np.zeros(0, dtype=np.int64)
    if tol == 0.0:
        # + 0.0 folds -0.0 onto 0.0 so both spellings of zero count as duplicates.
        _, first, labels = np.unique(verts + 0.0, axis=0, return_index=True, return_inverse=True)
        labels = labels.reshape(-1)
    else:
        # One sort of coarse cubes finds the vertices that may merge (every copy of a vertex
        # shares its cube, so duplicates are among them); equal ones are welded first, then
        # close pairs are searched among the distinct ones.
        centre = 0.5 * np.add(*column_extremes(verts))
        local = verts - centre
        candidates, near_face, cube = _merge_candidates(local, tol)
        same = np.take(candidates, equal_rows(np.take(verts, candidates, axis=0)))
        # Of the distinct vertices, those near a cube face or sharing their cube with another
        # distinct one (not only with copies of themselves) are searched.
        kept = np.flatnonzero(same == candidates)
        search = near_face[kept] | _repeated(cube[kept])
        distinct = np.take(candidates, kept[search])
        found = _close_pairs(np.take(local, distinct, axis=0), tol)
        pairs = np.take(distinct, found)
        moved = np.flatnonzero(same != candidates)
        a = np.concatenate([np.take(candidates, moved), pairs[:, 0]])
        b = np.concatenate([np.take(same, moved), pairs[:, 1]])
        roots = component_roots(n, a, b)
        first, labels = compact_indices(roots, n)  # the lowest index of each group
    # first[g] is the lowest index of group g; renumber groups by that index.
    order = np.argsort(first)
    rank = np.empty(order.shape[0], dtype=np.int64)
    rank[order] = np.arange(order.shape[0], dtype=np.int64)
    representatives = first[order]
    return np.take(verts, representatives, axis=0), np.take(rank, labels)


def _close_pairs(points: FloatArray, tol: float) -> IntArray:
    """Pairs of ``points`` within ``tol``: a sweep along x for a few points, else a hashed
    grid, or scipy's k-d tree (imported only then) for a crowd of points so close together
    that the grid would be quadratic."""
    pairs = _swept_pairs(points, tol) if points.shape[0] <= _SWEEP_POINTS else None
    if pairs is None:
        pairs = close_pairs(points, tol)
    if pairs is not None:
        return pairs
    from scipy.spatial import cKDTree

    found: IntArray = cKDTree(points).query_pairs(r=tol, output_type="ndarray")
    return found.astype(np.int64).reshape(-1, 2)


#: Up to this many points, close pairs come from a sweep along x (a handful of whole-array
#: passes) rather than the 14 cube lookups of the hashed grid; beyond this many candidates per
#: point the sweep gives up.
_SWEEP_POINTS = 20_000
_SWEEP_PER_POINT = 8


def _swept_pairs(points: FloatArray, tol: float) -> IntArray | None:
    """Pairs ``(i, j)``, ``i < j``, of the points within ``tol`` (the grid's distance test on
    every pair closer than ``2 · tol`` along x); None when the x slabs are crowded."""
    n = points.shape[0]
    order = np.argsort(points[:, 0], kind="stable")
    x = points[order, 0]
    end = np.searchsorted(x, x + 2.0 * tol, side="right")
    count = end - np.arange(1, n + 1, dtype=np.int64)
    total = int(count.sum())
    if total > _SWEEP_PER_POINT * n + 64:
        return None
    first = np.repeat(np.arange(n, dtype=np.int64), count)
    second = (
        first + 1 + np.arange(total, dtype=np.int64) - np.repeat(np.cumsum(count) - count, count)
    )
    i, j = order[first], order[second]
    d = points[i] - points[j]
    close = np.einsum("ij,ij->i", d, d) <= tol * tol
    i, j = i[close], j[close]
    return np.stack([np.minimum(i, j), np.maximum(i, j)], axis=1).astype(np.int64)


def part_vertices(faces: ArrayLike, labels: ArrayLike | None, n_vertices: int) -> list[IntArray]:
    """The vertex sets that are welded (and checked for colocation) on their own: the vertices
    the faces of each part use (``labels``: a part per face, such as a surface's patch labels),
    each sorted, in order of the labels — a vertex several parts use is in each; with no labels
    or a single part, every vertex (``[arange(n_vertices)]``).

    >>> [p.tolist() for p in part_vertices([[0, 1, 2], [1, 2, 3]], [0, 1], 5)]
    [[0, 1, 2], [1, 2, 3]]
    >>> [p.tolist() for p in part_vertices([[0, 1, 2]], None, 4)]
    [[0, 1, 2, 3]]
    """
    everything = [np.arange(n_vertices, dtype=np.int64)]
    if labels is None:
        return everything
    part = np.asarray(labels, dtype=np.int64).reshape(-1)
    if part.size == 0 or int(part.min()) == int(part.max()):
        return everything
    f = _as_faces(faces, "part_vertices", n_vertices)
    n = np.int64(max(n_vertices, 1))
    keys = np.sort((part[:, None] * n + f).reshape(-1))
    keep = np.ones(keys.shape[0], dtype=np.bool_)
    keep[1:] = keys[1:] != keys[:-1]
    keys = keys[keep]
    owner, vertex = keys // n, keys % n
    cuts = np.flatnonzero(np.diff(owner)) + 1
    return [chunk.astype(np.int64, copy=False) for chunk in np.split(vertex, cuts)]


def merge_close_vertices_in_parts(
    vertices: ArrayLike, parts: list[IntArray], tolerance: float
) -> tuple[FloatArray, IntArray]:
    """:func:`merge_close_vertices` where only vertices of one same part merge: vertices within
    ``tolerance`` of each other (chains included) *inside* a part (``parts``: vertex index
    arrays, which may share vertices) form a group, groups sharing a vertex are one, and each
    keeps its lowest-index vertex, groups in order of first appearance. A vertex in no part
    stays alone. ``(unique_vertices, inverse (N,))``.

    >>> u, inv = merge_close_vertices_in_parts(
    ...     [[0, 0, 0], [0, 0, 1e-9], [0, 0, 2e-9]], [np.array([0, 1]), np.array([2])], 1e-6
    ... )
    >>> inv.tolist()
    [0, 0, 1]
    """
    verts = _as_vertices(vertices, "merge_close_vertices_in_parts")
    n = verts.shape[0]
    rows, cols = [np.zeros(0, np.int64)], [np.zeros(0, np.int64)]
    for members in parts:
        members = np.asarray(members, dtype=np.int64)
        if members.size < 2:
            continue
        _, inverse = merge_close_vertices(verts[members], tolerance)
        first = np.full(int(inverse.max()) + 1, members.shape[0], dtype=np.int64)
        np.minimum.at(first, inverse, np.arange(members.shape[0], dtype=np.int64))
        joined = np.flatnonzero(first[inverse] != np.arange(members.shape[0]))
        rows.append(members[joined])
        cols.append(members[first[inverse[joined]]])
    a, b = np.concatenate(rows), np.concatenate(cols)
    first_index, labels = compact_indices(component_roots(n, a, b), n)
    return verts[first_index].copy(), labels


def sort_around_axis(origin: ArrayLike, axis: ArrayLike, directions: ArrayLike) -> IntArray:
    """Indices of ``directions`` (K, 3) in right-hand order around ``axis``, from direction 0.

    Directions are projected on the plane ⊥ ``axis`` and sorted by their counter-clockwise
    angle (seen from the axis tip) from the projection of ``directions[0]``, so the result
    starts with 0 (ties keep index order). ``origin`` is the axis' base point; the order of
    direction vectors does not depend on it.

    >>> sort_around_axis((0, 0, 0), (0, 0, 1), [[1, 0, 0], [0, -1, 0], [0, 1, 0], [-1, 0, 0]])
    array([0, 2, 3, 1])
    """
    _as_point(origin, "sort_around_axis", "origin")
    u = _as_point(axis, "sort_around_axis", "axis")
    dirs = _as_float_array(directions, "sort_around_axis", "directions")
    if dirs.ndim != 2 or dirs.shape[1] != 3:
        raise EntityValidationError(
            "sort_around_axis", "directions", f"expected shape (K, 3), got {dirs.shape}"
        )
    if not np.isfinite(dirs).all():
        raise EntityValidationError("sort_around_axis", "directions", "contains NaN or infinite")
    axis_length = math.hypot(*u.tolist())
    if axis_length == 0.0:
        raise DegenerateGeometryError("sort_around_axis: axis is the zero vector")
    u = u / axis_length
    if dirs.shape[0] == 0:
        return np.zeros(0, dtype=np.int64)
    proj = dirs - np.outer(dirs @ u, u)
    proj_length = np.sqrt(np.einsum("ij,ij->i", proj, proj))
    dir_length = np.sqrt(np.einsum("ij,ij->i", dirs, dirs))
    bad = np.flatnonzero((proj_length <= _PROJECTION_RTOL * dir_length) | (dir_length == 0.0))
    if bad.size:
        raise DegenerateGeometryError(
            f"sort_around_axis: directions {bad.tolist()} are zero or parallel to axis"
        )
    e1 = proj[0] / proj_length[0]
    e2 = np.cross(u, e1)
    angles = np.arctan2(proj @ e2, proj @ e1)
    angles[0] = 0.0
    angles = np.where(angles < 0.0, angles + 2.0 * math.pi, angles)
    angles[angles >= 2.0 * math.pi] = 0.0
    return np.argsort(angles, kind="stable").astype(np.int64, copy=False)
