"""Ray crossings of a triangle mesh along one axis, through every pixel centre of a 2ⁿ × 2ⁿ grid.

This is the rasteriser behind both the depth buffers and the exact mode. It is vectorised over
(triangle, pixel) pairs: each triangle proposes the pixel centres of its projected bounding box
and an exact integer edge test keeps the covered ones.

Robustness. Projected coordinates are snapped to a fixed-point lattice (``2**-s`` of a pixel,
``s`` ≥ 20 bits at depth 8), so every edge function is evaluated *exactly* in int64. A pixel
centre lying exactly on an edge or a vertex is resolved by the top-left rule, which is the
symbolic perturbation of the ray by ``(ε, ε²)`` in the image plane: a ray through a shared edge
is counted by exactly one of the two triangles when the surface continues across it, by both or
neither when the edge is a silhouette, and a ray through a vertex by exactly one triangle of the
fan. Every ray therefore crosses a closed surface an even number of times and parity is exact.
Triangles seen edge-on (zero projected area) are crossed by no perturbed ray and are skipped.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from geobrep.errors import DegenerateGeometryError

__all__ = ["RayCrossings", "fixed_point_bits", "ray_crossings"]

#: Candidate (triangle, pixel) pairs evaluated at once; bounds the temporary memory (~100 B each).
CHUNK_CANDIDATES = 1 << 20
#: Triangles prepared at once; bounds the per-triangle data (~30 numbers of 8 bytes each).
TRIANGLE_CHUNK = 1 << 17
#: Fixed-point coordinates stay below ``2**LATTICE_BITS`` so edge functions fit int64 exactly.
LATTICE_BITS = 29
#: Triangles whose pixel box is at most this many pixels on a side are tested as regular blocks.
SMALL_BOX = 4
#: Pixels, depths and entering flags of some crossings.
_Crossings = tuple[NDArray[np.int64], NDArray[np.float64], NDArray[np.bool_]]


@dataclass(frozen=True)
class RayCrossings:
    """Where the rays along ``axis`` cross the surface.

    Rays run in the ``+axis`` direction through pixel centres; pixel ``(p, q)`` indexes the two
    other axes in cyclic order (``u = (axis + 1) % 3``, ``v = (axis + 2) % 3``) and its flat
    index is ``p * resolution + q``. ``depths`` are in grid units along ``axis``; ``entering`` is
    true where the triangle's normal points against the ray (an entry for outward normals).
    """

    axis: int
    resolution: int
    pixels: NDArray[np.int64]
    depths: NDArray[np.float64]
    entering: NDArray[np.bool_]

    @property
    def size(self) -> int:
        return int(self.pixels.shape[0])

    def counts(self) -> NDArray[np.int64]:
        """Number of crossings of each ray, shape ``(resolution, resolution)``."""
        n = self.resolution
        return np.bincount(self.pixels, minlength=n * n).reshape(n, n)


def fixed_point_bits(max_abs: float, resolution: int) -> int:
    """Sub-pixel bits ``s`` such that coordinates up to ``max_abs`` pixels fit the lattice."""
    reach = max(float(max_abs), float(resolution), 1.0)
    exponent = math.frexp(reach)[1]  # reach < 2**exponent
    bits = LATTICE_BITS - exponent
    if bits < 1:
        raise DegenerateGeometryError(
            f"the surface reaches {reach:.3g} cells from the octree cube: too far for exact "
            "ray casting; voxelize a cube closer to the body"
        )
    return bits


@dataclass(frozen=True)
class _Triangles:
    """Per-triangle data of the covered-pixel test, one 1-D array per quantity.

    A box width of 0 marks a triangle that covers no pixel centre or is seen edge-on.

    Edge ``e`` is opposite corner ``e``; its function ``alpha·Pu + beta·Pv + gamma`` is positive
    inside the triangle, and ``owns`` is 1 where the edge owns pixel centres lying on it.
    """

    alpha: tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.int64]]
    beta: tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.int64]]
    gamma: tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.int64]]
    owns: tuple[NDArray[np.int64], NDArray[np.int64], NDArray[np.int64]]
    depths: tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]
    area: NDArray[np.float64]  # twice the projected area (positive)
    entering: NDArray[np.bool_]
    first_u: NDArray[np.int64]  # first pixel of the bounding box
    first_v: NDArray[np.int64]
    width_u: NDArray[np.int64]  # pixels of the bounding box along u and v
    width_v: NDArray[np.int64]


def _covered(
    tri: _Triangles,
    rows: NDArray[np.int64],
    p: NDArray[np.int64],
    q: NDArray[np.int64],
    half: int,
    n: int,
) -> tuple[NDArray[np.int64], NDArray[np.float64], NDArray[np.bool_]]:
    """Crossings of triangles ``rows`` with pixels ``(p, q)``: flat pixels, depths, entering.

    ``p, q`` have shape ``(c,)`` (one candidate per row) or ``(c, k)`` (a regular block of
    ``k`` candidates per row).
    """
    column = (slice(None),) + (None,) * (p.ndim - 1)
    pu = (2 * p + 1) * half
    pv = (2 * q + 1) * half
    inside: NDArray[np.bool_] | None = None
    values = []
    for e in range(3):
        alpha = np.take(tri.alpha[e], rows)[column]
        beta = np.take(tri.beta[e], rows)[column]
        gamma = np.take(tri.gamma[e], rows)[column] + np.take(tri.owns[e], rows)[column]
        value = alpha * pu + beta * pv + gamma  # the edge function plus the tie-break
        test = value > 0
        inside = test if inside is None else inside & test
        values.append(value)
    assert inside is not None
    hit = np.nonzero(inside)
    owner = np.take(rows, hit[0])
    depth = (
        (values[0][hit] - np.take(tri.owns[0], owner)) * np.take(tri.depths[0], owner)
        + (values[1][hit] - np.take(tri.owns[1], owner)) * np.take(tri.depths[1], owner)
        + (values[2][hit] - np.take(tri.owns[2], owner)) * np.take(tri.depths[2], owner)
    ) / np.take(tri.area, owner)
    return p[hit] * n + q[hit], depth, np.take(tri.entering, owner)


def _prepare(
    lattice_u: NDArray[np.int64],
    lattice_v: NDArray[np.int64],
    triangles: NDArray[np.int64],
    depth_of_vertex: NDArray[np.float64],
    half: int,
    n: int,
) -> _Triangles:
    corners = [np.ascontiguousarray(triangles[:, k]) for k in range(3)]
    u = [np.take(lattice_u, c) for c in corners]
    v = [np.take(lattice_v, c) for c in corners]
    area2 = (u[1] - u[0]) * (v[2] - v[0]) - (v[1] - v[0]) * (u[2] - u[0])
    # Pixel p's centre is (2p + 1)·half: first centre ≥ the box minimum, last ≤ its maximum.
    first_u = np.maximum(-((half - np.minimum(np.minimum(u[0], u[1]), u[2])) // (2 * half)), 0)
    first_v = np.maximum(-((half - np.minimum(np.minimum(v[0], v[1]), v[2])) // (2 * half)), 0)
    last_u = np.minimum((np.maximum(np.maximum(u[0], u[1]), u[2]) - half) // (2 * half), n - 1)
    last_v = np.minimum((np.maximum(np.maximum(v[0], v[1]), v[2]) - half) // (2 * half), n - 1)
    width_u = np.maximum(last_u - first_u + 1, 0)
    width_v = np.maximum(last_v - first_v + 1, 0)
    width_u[area2 == 0] = 0
    sigma = np.where(area2 > 0, 1, -1)
    alpha, beta, gamma, owns = [], [], [], []
    for start, end in ((1, 2), (2, 0), (0, 1)):
        du = (u[end] - u[start]) * sigma
        dv = (v[end] - v[start]) * sigma
        alpha.append(-dv)
        beta.append(du)
        gamma.append(dv * u[start] - du * v[start])
        owns.append(((dv < 0) | ((dv == 0) & (du > 0))).astype(np.int64))
    depths = [np.take(depth_of_vertex, c) for c in corners]
    return _Triangles(
        alpha=(alpha[0], alpha[1], alpha[2]),
        beta=(beta[0], beta[1], beta[2]),
        gamma=(gamma[0], gamma[1], gamma[2]),
        owns=(owns[0], owns[1], owns[2]),
        depths=(depths[0], depths[1], depths[2]),
        area=np.abs(area2).astype(np.float64),
        entering=sigma < 0,
        first_u=first_u,
        first_v=first_v,
        width_u=width_u,
        width_v=width_v,
    )


def ray_crossings(
    grid_vertices: NDArray[np.float64],
    triangles: NDArray[np.int64],
    axis: int,
    resolution: int,
) -> RayCrossings:
    """Every crossing of the rays along ``axis`` with the triangles.

    ``grid_vertices`` are in grid units (pixel ``p`` spans ``[p, p + 1]``); the rays pass
    through the centres ``p + 0.5`` of the ``resolution × resolution`` pixels.

    >>> import numpy as np
    >>> square = np.array([[0.2, 0.2, 1.0], [1.8, 0.2, 1.0], [1.8, 1.8, 1.0], [0.2, 1.8, 1.0]])
    >>> hits = ray_crossings(square, np.array([[0, 1, 2], [0, 2, 3]]), axis=2, resolution=2)
    >>> hits.counts().tolist(), hits.depths.tolist()
    ([[1, 1], [1, 1]], [1.0, 1.0, 1.0, 1.0])
    """
    n = int(resolution)
    u_axis, v_axis = (axis + 1) % 3, (axis + 2) % 3
    uv = grid_vertices[:, [u_axis, v_axis]]
    max_abs = float(np.abs(uv).max()) if uv.size else 0.0
    bits = fixed_point_bits(max_abs, n)
    half = 1 << (bits - 1)
    lattice = np.rint(uv * float(1 << bits)).astype(np.int64)
    lattice_u, lattice_v = np.ascontiguousarray(lattice[:, 0]), np.ascontiguousarray(lattice[:, 1])
    del lattice
    depth_of_vertex = np.ascontiguousarray(grid_vertices[:, axis])
    # Triangles are prepared a chunk at a time (the per-triangle data is ~30 arrays); the
    # pieces are put together in the order one pass over all triangles gives.
    by_shape: dict[int, list[_Crossings]] = {}
    large_pieces: list[_Crossings] = []
    for start in range(0, triangles.shape[0], TRIANGLE_CHUNK):
        chunk = triangles[start : start + TRIANGLE_CHUNK]
        tri = _prepare(lattice_u, lattice_v, chunk, depth_of_vertex, half, n)
        boxed = (tri.width_u > 0) & (tri.width_v > 0)
        small = (tri.width_u <= SMALL_BOX) & (tri.width_v <= SMALL_BOX) & boxed
        for shape, piece in _small_box_crossings(tri, small, half, n).items():
            by_shape.setdefault(shape, []).append(piece)
        large_pieces += _large_box_crossings(tri, np.flatnonzero(~small & boxed), half, n)
        del tri, boxed, small
    pieces = [piece for shape in sorted(by_shape) for piece in by_shape[shape]] + large_pieces
    if not pieces:
        return RayCrossings(
            axis, n, np.zeros(0, np.int64), np.zeros(0, np.float64), np.zeros(0, np.bool_)
        )
    return RayCrossings(
        axis,
        n,
        np.concatenate([piece[0] for piece in pieces]),
        np.concatenate([piece[1] for piece in pieces]),
        np.concatenate([piece[2] for piece in pieces]),
    )


def _small_box_crossings(
    tri: _Triangles, small: NDArray[np.bool_], half: int, n: int
) -> dict[int, _Crossings]:
    """Triangles with small pixel boxes (most of a fine mesh): one regular block per box shape,
    by box shape (in increasing order)."""
    pieces: dict[int, _Crossings] = {}
    shape_key = np.where(small, (tri.width_u - 1) * SMALL_BOX + tri.width_v - 1, -1)
    for wu in range(1, SMALL_BOX + 1):
        for wv in range(1, SMALL_BOX + 1):
            rows = np.flatnonzero(shape_key == (wu - 1) * SMALL_BOX + wv - 1)
            if rows.size == 0:
                continue
            du = np.repeat(np.arange(wu), wv)[None, :]
            dv = np.tile(np.arange(wv), wu)[None, :]
            p = np.take(tri.first_u, rows)[:, None] + du
            q = np.take(tri.first_v, rows)[:, None] + dv
            pieces[(wu - 1) * SMALL_BOX + wv - 1] = _covered(tri, rows, p, q, half, n)
    return pieces


def _large_box_crossings(
    tri: _Triangles, large: NDArray[np.int64], half: int, n: int
) -> list[_Crossings]:
    """Triangles with larger boxes: candidate pixels listed one by one, in bounded chunks."""
    pieces: list[_Crossings] = []
    counts = np.take(tri.width_u, large) * np.take(tri.width_v, large)
    ends = np.cumsum(counts)
    begin = 0
    while begin < large.size:
        base = int(ends[begin - 1]) if begin else 0
        stop = max(int(np.searchsorted(ends, base + CHUNK_CANDIDATES, side="right")), begin + 1)
        rows = large[begin:stop]
        local = counts[begin:stop]
        owner = np.repeat(rows, local)
        offset = np.arange(int(local.sum()), dtype=np.int64) - np.repeat(
            np.cumsum(local) - local, local
        )
        v_width = np.take(tri.width_v, owner)
        p = np.take(tri.first_u, owner) + offset // v_width
        q = np.take(tri.first_v, owner) + offset % v_width
        pieces.append(_covered(tri, owner, p, q, half, n))
        begin = stop
    return pieces
