"""Cap faces: triangulating the loops a closed surface leaves on the cutting plane.

The boundary of the kept part of a closed surface lies on the plane. Its directed edges, reversed,
bound the cap; they are joined into loops (:mod:`.loops`), projected on the plane, and sorted by
signed area into outer loops (counter-clockwise seen from the cap's normal) and holes (clockwise),
each hole going to the smallest outer loop that contains it. Every outer loop with its holes is
triangulated by mapbox-earcut (an ear-clipping triangulator for polygons with holes: fast, robust
to touching holes and collinear runs, no extra vertices, ISC licence). Earcut may skip a vertex
lying on a straight run of the loop; such vertices are put back by splitting the triangle that
spans them into a fan, so every cap edge is an edge of the cut surface and the result is closed.
"""

from __future__ import annotations

import math

import numpy as np

from geobrep.errors import DegenerateGeometryError, MissingDependencyError
from geobrep.geometry.arrays import FloatArray, IntArray
from geobrep.plugins.clip._loops import edge_successors, order_cycles

__all__ = [
    "cap_rings",
    "cap_triangles",
    "group_holes",
    "loop_areas",
    "open_boundary",
    "plane_basis",
]


#: Relative mismatch between the triangulated area and the loops' area that is an error.
_AREA_RTOL = 1e-7
#: Holes tested against outer-loop edges in chunks of at most this many (hole, edge) pairs.
_CHUNK = 4_000_000


def plane_basis(normal: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Unit vectors ``(u, w)`` spanning the plane with ``u × w = normal`` (``normal`` unit).

    >>> u, w = plane_basis(np.array([0.0, 0.0, 1.0]))
    >>> np.cross(u, w).tolist()
    [0.0, 0.0, 1.0]
    """
    axis = int(np.argmin(np.abs(normal)))
    helper = np.zeros(3)
    helper[axis] = 1.0
    u = np.cross(helper, normal)
    u /= np.linalg.norm(u)
    w = np.cross(normal, u)
    return u, w


def open_boundary(edges: IntArray, n_points: int) -> IntArray:
    """The directed ``edges`` (E, 2) whose reverse is not among them (interior pairs cancel)."""
    if edges.shape[0] == 0:
        return edges.reshape(0, 2)
    keys = edges[:, 0] * n_points + edges[:, 1]
    reverse = edges[:, 1] * n_points + edges[:, 0]
    return edges[~np.isin(keys, reverse)]


def cap_rings(
    points: FloatArray,
    boundary: IntArray,
    normal: FloatArray,
    what: str,
    keys: IntArray | None = None,
) -> list[list[IntArray]]:
    """The polygons the cap fills: for each, its outer ring then its holes (point indices).

    ``boundary`` holds the directed edges of the kept surface lying on the plane (each traversed
    by one kept face); the cap runs along them the other way, so seen from ``normal`` (the cap's
    outward unit normal) outer rings turn counter-clockwise and holes clockwise. ``keys`` (one
    int per point, default the point indices) fix where each ring starts, so the same loops always
    give the same rings.

    >>> square = np.array([[0.0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]])
    >>> edges = np.array([[1, 0], [2, 1], [3, 2], [0, 3]])  # clockwise seen from +z
    >>> [ring.tolist() for ring in cap_rings(square, edges, np.array([0.0, 0, 1]), "square")[0]]
    [[0, 1, 2, 3]]
    """
    if boundary.shape[0] == 0:
        return []
    cap = _CapLoops(points, boundary, normal, what, keys)
    return [
        [cap.used[cap.loop_points[cap.offsets[r] : cap.offsets[r + 1]]] for r in rings]
        for rings in cap.polygons
    ]


def cap_triangles(
    points: FloatArray,
    boundary: IntArray,
    normal: FloatArray,
    what: str,
    keys: IntArray | None = None,
) -> IntArray:
    """Triangles (C, 3) over ``points`` closing the directed ``boundary`` edges (B, 2).

    Same arguments as :func:`cap_rings`; the triangles face ``normal``.

    >>> square = np.array([[0.0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]])
    >>> edges = np.array([[1, 0], [2, 1], [3, 2], [0, 3]])  # clockwise seen from +z
    >>> cap_triangles(square, edges, np.array([0.0, 0.0, 1.0]), "square").shape
    (2, 3)
    """
    if boundary.shape[0] == 0:
        return np.zeros((0, 3), dtype=np.int64)
    cap = _CapLoops(points, boundary, normal, what, keys)
    triangles = [
        _triangulate_polygon(cap.uv, cap.loop_points, cap.offsets, rings, what)
        for rings in cap.polygons
    ]
    if not triangles:
        return np.zeros((0, 3), dtype=np.int64)
    return np.asarray(cap.used[np.concatenate(triangles)], dtype=np.int64)


class _CapLoops:
    """The loops of a cap in the plane's 2D frame, grouped into polygons with holes."""

    def __init__(
        self,
        points: FloatArray,
        boundary: IntArray,
        normal: FloatArray,
        what: str,
        keys: IntArray | None,
    ) -> None:
        cap_edges = boundary[:, ::-1]
        used, local = np.unique(cap_edges, return_inverse=True)
        local_edges = local.reshape(-1, 2).astype(np.int64)
        u, w = plane_basis(normal)
        relative = points[used] - points[used].mean(axis=0)
        self.used: IntArray = used.astype(np.int64)
        self.uv: FloatArray = np.stack([relative @ u, relative @ w], axis=1)
        successor = edge_successors(local_edges, self.uv, what)
        point_keys = used if keys is None else keys[used]
        order, offsets = order_cycles(successor, point_keys[local_edges[:, 0]])
        self.loop_points: IntArray = local_edges[order, 0]
        self.offsets: IntArray = offsets
        areas = loop_areas(self.uv, self.loop_points, offsets)
        self.polygons = group_holes(self.uv, self.loop_points, offsets, areas, what)


def loop_areas(uv: FloatArray, loop_points: IntArray, offsets: IntArray) -> FloatArray:
    """Signed area of each loop (shoelace), positive when counter-clockwise."""
    xy = uv[loop_points]
    following = np.arange(1, loop_points.shape[0] + 1, dtype=np.int64)
    ends = offsets[1:]
    loop_of = np.repeat(np.arange(ends.shape[0]), np.diff(offsets))
    last = following == ends[loop_of]
    following[last] = offsets[:-1][loop_of[last]]
    nxt = xy[following]
    cross = xy[:, 0] * nxt[:, 1] - xy[:, 1] * nxt[:, 0]
    return np.asarray(0.5 * np.add.reduceat(cross, offsets[:-1]), dtype=np.float64)


def group_holes(
    uv: FloatArray, loop_points: IntArray, offsets: IntArray, areas: FloatArray, what: str
) -> list[list[int]]:
    """Loops grouped into polygons: ``[outer, hole, hole, ...]`` lists of loop numbers."""
    outers = np.flatnonzero(areas > 0)
    holes = np.flatnonzero(areas < 0)
    polygons: dict[int, list[int]] = {int(o): [int(o)] for o in outers}
    if holes.shape[0] == 0:
        return list(polygons.values())
    if outers.shape[0] == 0:
        raise DegenerateGeometryError(f"{what}: the cut has holes but no outer loop")
    # One point strictly inside each hole's boundary line: the midpoint of its first edge.
    first = loop_points[offsets[holes]]
    second = loop_points[offsets[holes] + 1]
    probes = 0.5 * (uv[first] + uv[second])
    rings = [loop_points[offsets[o] : offsets[o + 1]] for o in outers.tolist()]
    a = uv[np.concatenate(rings)]
    b = uv[np.concatenate([np.roll(ring, -1) for ring in rings])]
    owner_starts = np.concatenate([[0], np.cumsum([len(ring) for ring in rings])[:-1]])
    inside = np.zeros((holes.shape[0], outers.shape[0]), dtype=np.bool_)
    step = max(1, _CHUNK // max(1, a.shape[0]))
    for lo in range(0, holes.shape[0], step):
        p = probes[lo : lo + step]
        straddles = (a[None, :, 1] > p[:, None, 1]) != (b[None, :, 1] > p[:, None, 1])
        with np.errstate(divide="ignore", invalid="ignore"):
            x_cross = a[None, :, 0] + (p[:, None, 1] - a[None, :, 1]) * (
                b[None, :, 0] - a[None, :, 0]
            ) / (b[None, :, 1] - a[None, :, 1])
        crossing = (straddles & (x_cross > p[:, None, 0])).astype(np.int64)
        counts = np.add.reduceat(crossing, owner_starts, axis=1)
        inside[lo : lo + step] = counts % 2 == 1
    outer_areas = np.where(inside, areas[outers][None, :], np.inf)
    best = np.argmin(outer_areas, axis=1)
    orphans = ~inside[np.arange(holes.shape[0]), best]
    if orphans.any():
        raise DegenerateGeometryError(
            f"{what}: {int(orphans.sum())} hole loop(s) of the cut lie in no outer loop "
            "(is the surface consistently oriented?)"
        )
    for hole, outer in zip(holes.tolist(), outers[best].tolist(), strict=True):
        polygons[int(outer)].append(int(hole))
    return list(polygons.values())


def _triangulate_polygon(
    uv: FloatArray, loop_points: IntArray, offsets: IntArray, rings: list[int], what: str
) -> IntArray:
    """Earcut one outer loop with its holes; triangles in local point numbers, counter-clockwise."""
    try:
        import mapbox_earcut
    except ImportError as exc:  # pragma: no cover - a declared dependency
        raise MissingDependencyError("mapbox-earcut", "clip", "capping cut blocks") from exc

    ring_points = [loop_points[offsets[r] : offsets[r + 1]] for r in rings]
    vertex_ids = np.concatenate(ring_points)
    coordinates = uv[vertex_ids]
    centre = coordinates.mean(axis=0)
    ends = np.cumsum([len(r) for r in ring_points]).astype(np.uint32)
    corners = _convex_corners(coordinates - centre) if len(rings) == 1 else None
    if corners is not None:
        # A convex loop (the usual cut of a convex body): a fan over its corners, no search;
        # points on its straight runs are put back below.
        positions = np.stack(
            [np.repeat(corners[0], corners.shape[0] - 2), corners[1:-1], corners[2:]], 1
        )
        positions = _restore_skipped(positions, ends.astype(np.int64), coordinates)
    else:
        flat = mapbox_earcut.triangulate_float64(coordinates - centre, ends)
        positions = np.asarray(flat, dtype=np.int64).reshape(-1, 3)
        if _triangle_areas(coordinates, positions).sum() < 0:
            positions = positions[:, [0, 2, 1]]
        positions = _restore_skipped(positions, ends.astype(np.int64), coordinates)
    expected = float(loop_areas(uv, loop_points, offsets)[rings].sum())
    got = float(_triangle_areas(coordinates, positions).sum())
    extent = float(np.ptp(coordinates, axis=0).max())
    if not math.isclose(got, expected, rel_tol=_AREA_RTOL, abs_tol=1e-12 * extent * extent):
        raise DegenerateGeometryError(
            f"{what}: the cap triangulation covers {got:.6g} instead of {expected:.6g} "
            "(self-intersecting cut loops?)"
        )
    return np.asarray(vertex_ids[positions], dtype=np.int64)


def _convex_corners(xy: FloatArray) -> IntArray | None:
    """The corners of a convex counter-clockwise loop (points where it turns left), or ``None``
    if the loop turns right somewhere, winds more than once, or has fewer than three corners."""
    if xy.shape[0] < 3:
        return None
    edges = np.roll(xy, -1, axis=0) - xy
    previous = np.roll(edges, 1, axis=0)
    cross = previous[:, 0] * edges[:, 1] - previous[:, 1] * edges[:, 0]
    dot = np.einsum("ij,ij->i", previous, edges)
    scale = np.einsum("ij,ij->i", edges, edges) + np.einsum("ij,ij->i", previous, previous)
    if (cross < -1e-12 * scale).any():
        return None
    if abs(float(np.arctan2(cross, dot).sum()) - 2.0 * math.pi) > 1e-6:
        return None
    corners = np.flatnonzero(cross > 1e-12 * scale).astype(np.int64)
    return corners if corners.shape[0] >= 3 else None


def _triangle_areas(coordinates: FloatArray, positions: IntArray) -> FloatArray:
    a = coordinates[positions[:, 0]]
    ab = coordinates[positions[:, 1]] - a
    ac = coordinates[positions[:, 2]] - a
    return np.asarray(0.5 * (ab[:, 0] * ac[:, 1] - ab[:, 1] * ac[:, 0]), dtype=np.float64)


def _restore_skipped(positions: IntArray, ends: IntArray, coordinates: FloatArray) -> IntArray:
    """Put back ring vertices earcut skipped, so every ring edge is an edge of the triangles.

    Earcut drops a vertex on a straight run of a ring, and a vertex that coincides with its
    neighbour (two cut points at one corner of a box). A triangle whose edge skips a straight run
    becomes a fan over the run's vertices; what is still missing afterwards is a gap of zero area
    between the ring and the triangles (the coincident corners), which is closed by a fan of its
    own. The caller checks the total area, so no filling can go unnoticed.
    """
    total = int(ends[-1])
    if np.unique(positions).shape[0] == total or positions.shape[0] == 0:
        return positions
    starts = np.concatenate([[0], ends[:-1]])
    ring_of = np.repeat(np.arange(ends.shape[0]), np.diff(np.concatenate([[0], ends])))
    following = np.arange(1, total + 1)
    last = following == ends[ring_of]
    following[last] = starts[ring_of[last]]
    ring_edges = set(zip(range(total), following.tolist(), strict=True))
    extent = float(np.ptp(coordinates, axis=0).max())
    tolerance = 1e-12 * extent * extent
    rows = positions.tolist()
    for _ in range(total):
        rows, changed = _split_spanning(rows, ring_edges, following, coordinates, tolerance)
        if not changed:
            break
    rows.extend(_fill_gaps(rows, ring_edges))
    return np.asarray(rows, dtype=np.int64).reshape(-1, 3)


def _split_spanning(
    rows: list[list[int]],
    ring_edges: set[tuple[int, int]],
    following: IntArray,
    coordinates: FloatArray,
    tolerance: float,
) -> tuple[list[list[int]], bool]:
    """One pass: each triangle with an edge along a straight run of the ring becomes a fan.

    The run from ``a`` to ``b`` must lie on the edge: the fan's triangles may not turn over
    and together cover the triangle they replace, otherwise the edge is left as it is.
    """
    total = int(following.shape[0])
    directed = {(t[k], t[(k + 1) % 3]) for t in rows for k in range(3)}
    result: list[list[int]] = []
    changed = False
    for triangle in rows:
        replaced = False
        for k in range(3):
            a, b, apex = triangle[k], triangle[(k + 1) % 3], triangle[(k + 2) % 3]
            if (b, a) in directed or (a, b) in ring_edges:
                continue
            chain = [a]
            current = a
            while current != b and len(chain) <= total:
                current = int(following[current])
                chain.append(current)
            if current != b:
                continue
            fan = np.array([[chain[j], chain[j + 1], apex] for j in range(len(chain) - 1)])
            areas = _triangle_areas(coordinates, fan)
            whole = float(_triangle_areas(coordinates, np.array([[a, b, apex]]))[0])
            if (areas < -tolerance).any() or abs(float(areas.sum()) - whole) > tolerance:
                continue
            result.extend(fan.tolist())
            replaced = changed = True
            break
        if not replaced:
            result.append(triangle)
    return result, changed


def _fill_gaps(rows: list[list[int]], ring_edges: set[tuple[int, int]]) -> list[list[int]]:
    """Fans closing what lies between the ring and the triangles: loops made of the ring edges
    no triangle has and the reverse of the triangles' edges that are neither shared nor ring
    edges."""
    directed = {(t[k], t[(k + 1) % 3]) for t in rows for k in range(3)}
    gap_edges = [edge for edge in ring_edges if edge not in directed]
    gap_edges += [
        (b, a) for a, b in directed if (b, a) not in directed and (a, b) not in ring_edges
    ]
    if not gap_edges:
        return []
    successors: dict[int, list[int]] = {}
    for a, b in sorted(gap_edges):
        successors.setdefault(a, []).append(b)
    fans: list[list[int]] = []
    for start in sorted(successors):
        while successors.get(start):
            loop = [start]
            current = successors[start].pop()
            while current != start and successors.get(current):
                loop.append(current)
                current = successors[current].pop()
            fans.extend([loop[0], loop[j], loop[j + 1]] for j in range(1, len(loop) - 1))
    return fans
