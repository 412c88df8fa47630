"""Detect non-conformal input, which would otherwise give a wrong block set.

* **Crossings and touches**: in a conformal model two triangles of different surfaces meet only
  in shared vertices or edges. Pairs that share no vertex (after merging) yet intersect — within
  the merge tolerance — are surfaces crossing without an intersection line, or T-junctions
  (a vertex of one surface lying on a triangle of another). Candidates come from a grid broad
  phase; the narrow phase first drops the pairs a plane keeps apart (:func:`separated`: one
  triangle wholly beyond the other's plane or one of its sides), then tests the six
  edge–triangle combinations of the others. Pairs that meet only within :data:`ARC_MARGIN`
  tolerances of an edge their two surfaces share (a vertex sealed by a sliver beside the line
  where they meet, moved off it by rounding) are no defect (:func:`_along_shared_lines`).
* **Gaps**: a vertex on a free border (an edge used by one triangle) lying within
  ``gap_tolerance`` of another surface — not one holding it or its neighbours along the border —
  is a surface that stops just short of the one it should meet.

Both raise a :class:`NonConformalError` (a :class:`~geobrep.errors.TopologyError`) listing
locations in model coordinates.
"""

from __future__ import annotations

from collections import defaultdict
from dataclasses import dataclass

import numpy as np

from geobrep.errors import TopologyError
from geobrep.geometry.arrays import BoolArray, FloatArray, IntArray
from geobrep.plugins.blocks._broad_phase import overlapping_pairs, stored_pairs
from geobrep.plugins.blocks._csr import concatenated_ranges
from geobrep.plugins.blocks._patches import PatchSplit
from geobrep.plugins.blocks._soup import Soup

__all__ = [
    "NonConformalError",
    "NonConformity",
    "check_conformity",
    "find_defects",
    "free_border",
    "point_triangle_distance",
    "separated",
    "triangles_intersect",
]


_MAX_LISTED = 8
#: Contacts within this many tolerances of a line two surfaces share are no defect.
ARC_MARGIN = 3.0
#: Triangle pairs tested at once (bounds the (K, 3, 3, 3) temporaries).
_BATCH = 1 << 15
#: Corner j + 1 of corner j (edge j runs from one to the other).
_NEXT = np.array([1, 2, 0])


@dataclass(frozen=True)
class NonConformity:
    """One defect: ``kind`` is ``"crossing"``, ``"T-junction"`` or ``"gap"``."""

    kind: str
    surfaces: tuple[str, str]
    point: tuple[float, float, float]
    distance: float
    triangles: tuple[int, int] = (-1, -1)
    """The soup triangles involved (-1: none; a gap's first is its border vertex's)."""
    vertex: int = -1
    """The soup vertex of a gap or border T-junction (-1: none)."""


class NonConformalError(TopologyError):
    """The surfaces are not conformal; ``defects`` lists where (model coordinates)."""

    def __init__(self, defects: list[NonConformity], hint: str = "") -> None:
        self.defects = defects
        grouped: dict[tuple[str, tuple[str, str]], list[NonConformity]] = defaultdict(list)
        for defect in defects:
            grouped[(defect.kind, defect.surfaces)].append(defect)
        parts = []
        for (kind, (first, second)), items in list(grouped.items())[:_MAX_LISTED]:
            x, y, z = items[0].point
            extra = f" ({len(items)} places)" if len(items) > 1 else ""
            gap = f", {items[0].distance:.3g} apart" if kind == "gap" else ""
            parts.append(
                f"{kind} of {first!r} and {second!r} at ({x:.3f}, {y:.3f}, {z:.3f}){gap}{extra}"
            )
        more = len(grouped) - _MAX_LISTED
        tail = f"; and {more} more" if more > 0 else ""
        super().__init__(
            f"non-conformal input: {len(defects)} defect(s): " + "; ".join(parts) + tail + hint
        )


# --------------------------------------------------------------------------- kernels
def _dot(u: FloatArray, v: FloatArray) -> FloatArray:
    return np.asarray(np.einsum("ij,ij->i", u, v), dtype=np.float64)


def _segment_distance(p1: FloatArray, q1: FloatArray, p2: FloatArray, q2: FloatArray) -> FloatArray:
    """Distance between segments ``p1q1`` and ``p2q2`` (rows), clamped closest points."""
    d1, d2, r = q1 - p1, q2 - p2, p1 - p2
    a, e, f = _dot(d1, d1), _dot(d2, d2), _dot(d2, r)
    c, b = _dot(d1, r), _dot(d1, d2)
    denom = a * e - b * b
    with np.errstate(divide="ignore", invalid="ignore"):
        s = np.where(denom > 0.0, np.clip((b * f - c * e) / denom, 0.0, 1.0), 0.0)
        t = (b * s + f) / e
        s = np.where(
            t < 0.0, np.clip(-c / a, 0.0, 1.0), np.where(t > 1.0, np.clip((b - c) / a, 0.0, 1.0), s)
        )
    t = np.clip(t, 0.0, 1.0)
    gap = p1 + d1 * s[:, None] - (p2 + d2 * t[:, None])
    return np.asarray(np.linalg.norm(gap, axis=1), dtype=np.float64)


def _inside(
    x: FloatArray, a: FloatArray, b: FloatArray, c: FloatArray, unit: FloatArray, tol: float
) -> BoolArray:
    """Whether points ``x`` of the triangles' planes lie in the triangles (within ``tol``)."""
    inside = np.ones(x.shape[0], dtype=np.bool_)
    for p, q in ((a, b), (b, c), (c, a)):
        edge = q - p
        reach = _dot(np.cross(edge, x - p), unit) / np.linalg.norm(edge, axis=1)
        inside &= reach >= -tol
    return inside


def point_triangle_distance(
    x: FloatArray, a: FloatArray, b: FloatArray, c: FloatArray
) -> FloatArray:
    """Distance from each point to its triangle (rows).

    >>> import numpy as np
    >>> tri = [np.array([[0.0, 0, 0]]), np.array([[1.0, 0, 0]]), np.array([[0.0, 1, 0]])]
    >>> point_triangle_distance(np.array([[0.2, 0.2, 3.0], [2.0, 0, 0]]).reshape(2, 3),
    ...                         *[np.repeat(t, 2, axis=0) for t in tri]).tolist()
    [3.0, 1.0]
    """
    normal = np.cross(b - a, c - a)
    unit = normal / np.linalg.norm(normal, axis=1)[:, None]
    height = _dot(x - a, unit)
    foot = x - height[:, None] * unit
    result = np.abs(height)
    outside = ~_inside(foot, a, b, c, unit, 0.0)
    if outside.any():
        xs = x[outside]
        best = np.full(xs.shape[0], np.inf)
        for p, q in ((a, b), (b, c), (c, a)):
            p, q = p[outside], q[outside]
            edge = q - p
            t = np.clip(_dot(xs - p, edge) / _dot(edge, edge), 0.0, 1.0)
            best = np.minimum(best, np.linalg.norm(xs - (p + t[:, None] * edge), axis=1))
        result[outside] = best
    return np.asarray(result, dtype=np.float64)


def _segment_hits_triangle(
    p: FloatArray, q: FloatArray, a: FloatArray, b: FloatArray, c: FloatArray, tol: float
) -> BoolArray:
    """Whether segments ``pq`` meet triangles ``abc`` (closed, within ``tol``)."""
    normal = np.cross(b - a, c - a)
    unit = normal / np.linalg.norm(normal, axis=1)[:, None]
    dp, dq = _dot(p - a, unit), _dot(q - a, unit)
    on_p, on_q = np.abs(dp) <= tol, np.abs(dq) <= tol
    hits = np.zeros(p.shape[0], dtype=np.bool_)
    coplanar = on_p & on_q
    crossing = ~coplanar & ((dp * dq < 0.0) | on_p | on_q)
    if crossing.any():
        i = np.flatnonzero(crossing)
        t = np.where(on_p[i], 0.0, np.where(on_q[i], 1.0, dp[i] / (dp[i] - dq[i])))
        x = p[i] + t[:, None] * (q[i] - p[i])
        hits[i] = _inside(x, a[i], b[i], c[i], unit[i], tol)
    if coplanar.any():
        i = np.flatnonzero(coplanar)
        near = _inside(p[i], a[i], b[i], c[i], unit[i], tol) | _inside(
            q[i], a[i], b[i], c[i], unit[i], tol
        )
        for u, v in ((a, b), (b, c), (c, a)):
            near |= _segment_distance(p[i], q[i], u[i], v[i]) <= tol
        hits[i] = near
    return hits


def _segment_pairs_hit(first: FloatArray, second: FloatArray, tol: float) -> BoolArray:
    """The six edge–triangle tests of :func:`triangles_intersect`, one combination at a time."""
    hits = np.zeros(first.shape[0], dtype=np.bool_)
    for one, other in ((first, second), (second, first)):
        a, b, c = other[:, 0], other[:, 1], other[:, 2]
        for j in range(3):
            todo = ~hits
            if not todo.any():
                return hits
            p, q = one[todo, j], one[todo, (j + 1) % 3]
            hits[todo] = _segment_hits_triangle(p, q, a[todo], b[todo], c[todo], tol)
    return hits


def _cross(u: FloatArray, v: FloatArray) -> FloatArray:
    """Cross products along the last axis (broadcasting)."""
    ux, uy, uz = u[..., 0], u[..., 1], u[..., 2]
    vx, vy, vz = v[..., 0], v[..., 1], v[..., 2]
    return np.stack([uy * vz - uz * vy, uz * vx - ux * vz, ux * vy - uy * vx], axis=-1)


def _any3(flags: BoolArray) -> BoolArray:
    """``flags.any(axis=-1)`` for a last axis of 3 (column operations: much faster)."""
    return np.asarray(flags[..., 0] | flags[..., 1] | flags[..., 2])


def _all3(flags: BoolArray) -> BoolArray:
    """``flags.all(axis=-1)`` for a last axis of 3."""
    return np.asarray(flags[..., 0] & flags[..., 1] & flags[..., 2])


def _edges_touching(one: FloatArray, other: FloatArray, tol: float) -> BoolArray:
    """Whether an edge of each triangle ``one[k]`` meets triangle ``other[k]`` within ``tol``:
    :func:`_segment_hits_triangle` for its three edges at once.

    An edge crossing the plane (or ending within ``tol`` of it) meets the triangle where the
    crossing point lies within ``tol`` inside each of its sides; an edge lying in the plane meets
    it when an end lies inside or the edge comes within ``tol`` of a side."""
    a = other[:, 0]
    normal = _cross(other[:, 1] - a, other[:, 2] - a)
    hits = np.zeros(one.shape[0], dtype=np.bool_)
    with np.errstate(divide="ignore", invalid="ignore"):
        unit = normal / np.linalg.norm(normal, axis=1)[:, None]
        height = np.matmul(one - a[:, None, :], unit[:, :, None])[:, :, 0]  # corners' heights
        dp, dq = height, height[:, _NEXT]  # edge j runs from corner j to j + 1
        on_p, on_q = np.abs(dp) <= tol, np.abs(dq) <= tol
        coplanar = on_p & on_q
        crossing = ~coplanar & ((dp * dq < 0.0) | on_p | on_q)
        involved = crossing | coplanar
        rows = np.flatnonzero(_any3(involved))
        if rows.size == 0:
            return hits
        u = other[rows]
        side = u[:, _NEXT] - u  # (K, side, xyz)
        # In-plane inward normal of each side over its length: (x - u) . inward is how far
        # inside that side a point of the plane lies.
        inward = _cross(unit[rows][:, None, :], side) / np.linalg.norm(side, axis=2)[:, :, None]
        base = np.einsum("ksj,ksj->ks", u, inward)
        p = one[rows]
        q = p[:, _NEXT]
        dp, dq, on_p, on_q = dp[rows], dq[rows], on_p[rows], on_q[rows]
        t = np.where(on_p, 0.0, np.where(on_q, 1.0, dp / (dp - dq)))
        x = p + t[:, :, None] * (q - p)  # (K, edge, xyz)
        reach = np.matmul(x, inward.transpose(0, 2, 1)) - base[:, None, :]  # (K, edge, side)
        found = _any3(crossing[rows] & _all3(reach >= -tol))
        flat = coplanar[rows]
        if flat.any():
            k, e = np.nonzero(flat)
            ends = np.stack([p[k, e], q[k, e]], axis=1)  # (F, end, xyz)
            reach = np.matmul(ends, inward[k].transpose(0, 2, 1)) - base[k][:, None, :]
            inside = _all3(reach >= -tol)  # (F, end)
            near = inside[:, 0] | inside[:, 1]
            starts, stops = u[k].reshape(-1, 3), u[k][:, _NEXT].reshape(-1, 3)
            gap = _segment_distance(
                np.repeat(ends[:, 0], 3, axis=0), np.repeat(ends[:, 1], 3, axis=0), starts, stops
            )
            near |= _any3((gap <= tol).reshape(-1, 3))
            found[k[near]] = True
        hits[rows] = found
    return hits


def _cross_rows(u: FloatArray, v: FloatArray) -> FloatArray:
    """Cross products of vectors stored component-major: ``(..., 3, K)`` arrays (broadcasting)."""
    ux, uy, uz = u[..., 0, :], u[..., 1, :], u[..., 2, :]
    vx, vy, vz = v[..., 0, :], v[..., 1, :], v[..., 2, :]
    return np.stack([uy * vz - uz * vy, uz * vx - ux * vz, ux * vy - uy * vx], axis=-2)


@dataclass(frozen=True)
class _Planes:
    """Per triangle (component-major, last axis the triangle): the triangle grown by a margin
    about its incentre, its unit normal and plane level, and the in-plane inward normals of its
    sides (over their lengths) with their levels — what :func:`_beyond` reads of each pair."""

    grown: FloatArray  # (corner, xyz, T)
    unit: FloatArray  # (xyz, T)
    level: FloatArray  # (T,): unit . corner 0
    inward: FloatArray  # (side, xyz, T): side j runs from corner j to j + 1
    offset: FloatArray  # (side, T): inward . a corner of the side


def _planes(corners: FloatArray, margin: float) -> _Planes:
    """:class:`_Planes` of triangles (component-major: (corner, xyz, T)), grown by ``margin``
    to the region the edge test calls inside: scaled about the incentre by (r + margin) / r,
    r the inradius."""
    with np.errstate(divide="ignore", invalid="ignore"):
        side = corners[_NEXT] - corners  # side j runs from corner j to j + 1
        length = np.sqrt((side * side).sum(axis=1))  # (side, T)
        perimeter = length.sum(axis=0)
        normal = _cross_rows(side[0], -side[2])
        area2 = np.sqrt((normal * normal).sum(axis=0))
        centre = (length[[1, 2, 0], None, :] * corners).sum(axis=0) / perimeter
        grown = centre + (1.0 + margin * perimeter / area2) * (corners - centre)
        unit = normal / area2
        inward = _cross_rows(unit, side) / length[:, None, :]
    level = (corners[0] * unit).sum(axis=0)
    offset = (corners * inward).sum(axis=1)
    return _Planes(grown, unit, level, inward, offset)


def _above_or_under(planes: _Planes, one: IntArray, other: IntArray, margin: float) -> BoolArray:
    """Whether triangles ``one``, grown, lie wholly more than ``margin`` above or under the
    plane of triangles ``other`` (Möller's plane-side test; rows of ``planes``)."""
    grown = np.take(planes.grown, one, axis=2)
    unit = np.take(planes.unit, other, axis=1)
    with np.errstate(invalid="ignore"):
        height = (grown * unit).sum(axis=1) - np.take(planes.level, other)  # (corner, K)
    above, under = height > margin, height < -margin
    return np.asarray((above[0] & above[1] & above[2]) | (under[0] & under[1] & under[2]))


def _outside_a_side(planes: _Planes, one: IntArray, other: IntArray, margin: float) -> BoolArray:
    """Whether triangles ``one``, grown, lie wholly more than ``margin`` outside one side of
    triangles ``other`` (the plane through the side perpendicular to the triangle)."""
    grown = np.take(planes.grown, one, axis=2)
    inward = np.take(planes.inward, other, axis=2)
    with np.errstate(invalid="ignore"):
        reach = (grown[:, None] * inward).sum(axis=2) - np.take(planes.offset, other, axis=1)
    outside = reach < -margin  # (corner, side, K)
    beyond = outside[0] & outside[1] & outside[2]  # (side, K)
    return np.asarray(beyond[0] | beyond[1] | beyond[2])


def _separated_rows(planes: _Planes, one: IntArray, other: IntArray, margin: float) -> BoolArray:
    """Pairs (rows ``one[k]``, ``other[k]`` of ``planes``) a plane of either keeps more than
    ``margin`` from the other grown: the plane-side tests both ways first (cheap), the side
    planes only for the pairs they leave."""
    apart = np.zeros(one.shape[0], dtype=np.bool_)
    rest = np.arange(one.shape[0])
    tests = (_above_or_under, _outside_a_side)
    for test in tests:
        for a, b in ((one, other), (other, one)):
            if rest.size == 0:
                return apart
            hit = test(planes, a[rest], b[rest], margin)
            apart[rest[hit]] = True
            rest = rest[~hit]
    return apart


def _separation_margin(corners: FloatArray, tol: float) -> float:
    """A little more than ``tol``, against rounding in the planes and the grown corners."""
    scale = float(np.abs(corners).max(initial=0.0))
    return tol * (1.0 + 1e-6) + 1e-12 * scale


def separated(first: FloatArray, second: FloatArray, tol: float) -> BoolArray:
    """Pairs of triangles that a plane separates by more than ``tol`` — so that
    :func:`triangles_intersect` is false for them — found cheaply (Möller's plane-side test and
    the in-plane side planes of each triangle, against the other grown by ``tol``).

    Rejecting these never changes a decision: a triangle lying wholly more than ``tol`` above
    the other's plane (or outside one of its sides), even when grown to the region the edge test
    calls inside, can neither reach the other with an edge nor be reached by one of its edges.

    >>> import numpy as np
    >>> flat = np.array([[[0, 0, 0], [2, 0, 0], [0, 2, 0]]], dtype=float)
    >>> separated(flat, flat + [0.0, 0.0, 1.0], 0.1).tolist(), separated(flat, flat, 0.1).tolist()
    ([True], [False])
    """
    k = first.shape[0]
    both = np.concatenate([first, second]).transpose(1, 2, 0).copy()
    margin = _separation_margin(both, tol)
    rows = np.arange(k)
    return _separated_rows(_planes(both, margin), rows, rows + k, margin)


def triangles_intersect(first: FloatArray, second: FloatArray, tol: float) -> BoolArray:
    """Whether triangles ``first[i]`` and ``second[i]`` ((K, 3, 3) corners) meet within ``tol``:
    an edge of one crosses or touches the other (closed triangles), or, lying in the other's
    plane, comes within ``tol`` of it. Pairs a plane keeps apart (:func:`separated`) are
    answered first; the edge tests run on the others.

    >>> import numpy as np
    >>> flat = np.array([[[0, 0, 0], [2, 0, 0], [0, 2, 0]]], dtype=float)
    >>> upright = np.array([[[0.5, 0.5, -1], [0.5, 0.5, 1], [1.5, 0.5, 0]]], dtype=float)
    >>> triangles_intersect(flat, upright, 1e-9).tolist()
    [True]
    >>> triangles_intersect(flat, upright + 5.0, 1e-9).tolist()
    [False]
    """
    hits = np.zeros(first.shape[0], dtype=np.bool_)
    for start in range(0, first.shape[0], _BATCH):
        one, other = first[start : start + _BATCH], second[start : start + _BATCH]
        todo = np.flatnonzero(~separated(one, other, tol))
        one, other = one[todo], other[todo]
        hits[start + todo] = _edges_touching(one, other, tol) | _edges_touching(other, one, tol)
    return hits


def _pairs_intersect(corners: FloatArray, i: IntArray, j: IntArray, tol: float) -> BoolArray:
    """:func:`triangles_intersect` of triangle pairs ``(i[k], j[k])`` of ``corners`` (the soup's,
    component-major: (corner, xyz, T)): each triangle's planes are computed once, however many
    pairs it is in. The separation margin follows the largest coordinate of all the pairs
    (never less than a batch's: the pairs it keeps apart are kept apart there too)."""
    hits = np.zeros(i.shape[0], dtype=np.bool_)
    if i.size == 0:
        return hits
    used = np.zeros(corners.shape[2], dtype=np.bool_)
    used[i] = True
    used[j] = True
    rows = np.flatnonzero(used)
    slot = np.empty(corners.shape[2], dtype=np.int64)
    slot[rows] = np.arange(rows.shape[0])
    mine = np.take(corners, rows, axis=2)
    margin = _separation_margin(mine, tol)
    planes = _planes(mine, margin)
    by_row = np.ascontiguousarray(mine.transpose(2, 0, 1))  # (T, corner, xyz)
    for start in range(0, i.shape[0], _BATCH):
        a, b = slot[i[start : start + _BATCH]], slot[j[start : start + _BATCH]]
        todo = np.flatnonzero(~_separated_rows(planes, a, b, margin))
        one, other = np.take(by_row, a[todo], axis=0), np.take(by_row, b[todo], axis=0)
        hits[start + todo] = _edges_touching(one, other, tol) | _edges_touching(other, one, tol)
    return hits


# --------------------------------------------------------------------------- checks
def _vertex_triangle_distance(points: FloatArray, triangles: FloatArray) -> FloatArray:
    """Smallest distance from any of the 3 ``points[i]`` to triangle ``triangles[i]``."""
    k = points.shape[0]
    flat = points.reshape(-1, 3)
    a, b, c = (np.repeat(triangles[:, m], 3, axis=0) for m in range(3))
    distance: FloatArray = point_triangle_distance(flat, a, b, c).reshape(k, 3).min(axis=1)
    return distance


def _shared_edges(soup: Soup, rows: IntArray, other_surface: IntArray) -> BoolArray:
    """(K, 3): whether edge ``j`` (corner j to j + 1) of triangle ``rows[k]`` is also an edge of
    a triangle of surface ``other_surface[k]``."""
    n_vertices = np.int64(soup.vertices.shape[0])
    n_surfaces = np.int64(len(soup.surfaces))
    tri = soup.triangles
    low = np.minimum(tri, tri[:, _NEXT]).reshape(-1)
    high = np.maximum(tri, tri[:, _NEXT]).reshape(-1)
    known = _sorted_unique(
        (low * n_vertices + high) * n_surfaces + np.repeat(soup.triangle_surface, 3)
    )
    mine = tri[rows]
    edge = np.minimum(mine, mine[:, _NEXT]) * n_vertices + np.maximum(mine, mine[:, _NEXT])
    key = edge * n_surfaces + other_surface[:, None]
    place = np.minimum(np.searchsorted(known, key), max(known.size - 1, 0))
    return np.asarray(known[place] == key) if known.size else np.zeros(key.shape, np.bool_)


def _away_from(
    corners: FloatArray, shared: BoolArray, margin: float
) -> tuple[FloatArray, BoolArray]:
    """The triangles (K, 3, 3) without the strip of width ``margin`` along their ``shared``
    edges (K, 3: edge j runs from corner j to j + 1), and which ones nothing is left of."""
    side = corners[:, _NEXT] - corners  # side j
    twice_area = np.linalg.norm(np.cross(side[:, 0], -side[:, 2]), axis=1)
    length = np.linalg.norm(side, axis=2)
    # Side j is opposite corner j + 2; that corner's barycentric coordinate must reach t.
    with np.errstate(divide="ignore", invalid="ignore"):
        reach = np.where(shared, margin * length / twice_area[:, None], 0.0)
    t = np.zeros_like(reach)
    t[:, [2, 0, 1]] = reach  # t[:, m]: for corner m (opposite side m + 1)
    gone = ~(t.sum(axis=1) < 1.0)
    weights = np.repeat(t[:, None, :], 3, axis=1)  # (K, new corner, old corner)
    for m in range(3):
        weights[:, m, m] = 1.0 - t.sum(axis=1) + t[:, m]
    return np.einsum("kmc,kcx->kmx", weights, corners), gone


def _along_shared_lines(
    soup: Soup, one: FloatArray, other: FloatArray, i: IntArray, j: IntArray, tol: float
) -> BoolArray:
    """Pairs (triangles ``i`` and ``j``, corners ``one`` and ``other``) that meet only within
    ``ARC_MARGIN × tol`` of edges the two surfaces share: a vertex of one surface beside the
    line where it meets the other (a sliver triangle sealing a vertex the other surface does
    not have, moved off that line by rounding) is no defect."""
    surface = soup.triangle_surface
    margin = ARC_MARGIN * tol
    first, gone_first = _away_from(one, _shared_edges(soup, i, surface[j]), margin)
    second, gone_second = _away_from(other, _shared_edges(soup, j, surface[i]), margin)
    benign = gone_first | gone_second
    rest = np.flatnonzero(~benign)
    benign[rest] = ~triangles_intersect(first[rest], second[rest], tol)
    return benign


def _crossings(
    soup: Soup, tol: float, pairs: tuple[IntArray, IntArray] | None = None
) -> list[NonConformity]:
    """Crossings and T-junctions between triangles of different surfaces; ``pairs``: the
    candidate pairs when the caller's broad phase (a wider margin) already found them (only
    their triangles are gathered then)."""
    local = soup.local_vertices
    if pairs is None:
        # The broad phase leaves out the pairs sharing a vertex (most candidates: neighbours
        # across a shared line), keeping the order of the others.
        i, j = stored_pairs(
            soup.corners, soup.triangle_surface, margin=tol, triangles=soup.triangles
        )
    else:
        i, j = pairs
        # np.take: row gathers several times faster than fancy indexing on numpy 2.
        ti, tj = np.take(soup.triangles, i, axis=0), np.take(soup.triangles, j, axis=0)
        # Triangles sharing a vertex first, then boxes beyond the contact tolerance: both
        # masks keep the order, so the pairs left are the same either way round.
        apart = np.ones(i.shape[0], dtype=np.bool_)
        for a in range(3):
            for b in range(3):
                apart &= ti[:, a] != tj[:, b]
        i, j, ti, tj = i[apart], j[apart], ti[apart], tj[apart]
        near = _boxes_within(local, ti, tj, tol)
        i, j = i[near], j[near]
    if i.size == 0:
        return []
    hit = _pairs_intersect(soup.corners, i, j, tol)
    i, j = i[hit], j[hit]
    ti, tj = np.take(soup.triangles, i, axis=0), np.take(soup.triangles, j, axis=0)
    if i.size == 0:
        return []
    first, second = np.take(local, ti, axis=0), np.take(local, tj, axis=0)
    real = ~_along_shared_lines(soup, first, second, i, j, tol)
    i, j, first, second = i[real], j[real], first[real], second[real]
    if i.size == 0:
        return []
    touch = np.minimum(
        _vertex_triangle_distance(first, second), _vertex_triangle_distance(second, first)
    )
    middle = 0.5 * (first.mean(axis=1) + second.mean(axis=1)) + soup.centre
    surface = soup.triangle_surface
    return [
        NonConformity(
            kind="T-junction" if d <= tol else "crossing",
            surfaces=(soup.surface_name(int(surface[a])), soup.surface_name(int(surface[b]))),
            point=(float(m[0]), float(m[1]), float(m[2])),
            distance=float(d),
            triangles=(a, b),
        )
        for a, b, d, m in zip(i.tolist(), j.tolist(), touch.tolist(), middle, strict=True)
    ]


def _allowed_surfaces(soup: Soup, border: IntArray) -> IntArray:
    """Keys ``vertex · S + surface``: surfaces holding a border vertex or a border neighbour."""
    n_surfaces = len(soup.surfaces)
    ring_vertex = np.concatenate([border[:, 0], border[:, 1], border[:, 0], border[:, 1]])
    ring_other = np.concatenate([border[:, 1], border[:, 0], border[:, 0], border[:, 1]])
    wanted = np.zeros(soup.vertices.shape[0], dtype=np.bool_)
    wanted[ring_other] = True
    corner_vertex = soup.triangles.reshape(-1)
    keep = wanted[corner_vertex]
    held = _sorted_unique(
        corner_vertex[keep] * n_surfaces + np.repeat(soup.triangle_surface, 3)[keep]
    )
    held_vertex, held_surface = held // n_surfaces, held % n_surfaces
    start = np.searchsorted(held_vertex, ring_other, side="left")
    count = np.searchsorted(held_vertex, ring_other, side="right") - start
    rows = concatenated_ranges(start, count)
    return _sorted_unique(np.repeat(ring_vertex, count) * n_surfaces + held_surface[rows])


def _boxes_within(local: FloatArray, mine: IntArray, theirs: IntArray, margin: float) -> BoolArray:
    """Which pairs of triangles (vertex rows ``mine`` and ``theirs``, (K, 3), over corners
    ``local``) have boxes, grown by ``margin``, that overlap; only the paired triangles are
    gathered."""
    keep = np.ones(mine.shape[0], dtype=np.bool_)
    if mine.shape[0] == 0:
        return keep
    # Corner by corner (elementwise minima and maxima: numpy's reductions over an axis of
    # three are several times slower).
    for axis in range(3):
        column = np.ascontiguousarray(local[:, axis])
        one = [np.take(column, mine[:, k]) for k in range(3)]
        other = [np.take(column, theirs[:, k]) for k in range(3)]
        one_low = np.minimum(np.minimum(one[0], one[1]), one[2]) - margin
        one_high = np.maximum(np.maximum(one[0], one[1]), one[2]) + margin
        other_low = np.minimum(np.minimum(other[0], other[1]), other[2]) - margin
        other_high = np.maximum(np.maximum(other[0], other[1]), other[2]) + margin
        keep &= one_low <= other_high
        keep &= other_low <= one_high
    return keep


#: The free border: edges (B, 2) one triangle uses, their vertices, each vertex's surface.
Border = tuple[IntArray, IntArray, IntArray]


def _sorted_unique(values: IntArray) -> IntArray:
    """The distinct values, ascending, by one sort (numpy's hashing ``unique`` is slower)."""
    ordered = np.sort(values.reshape(-1))
    keep = np.ones(ordered.shape[0], dtype=np.bool_)
    keep[1:] = ordered[1:] != ordered[:-1]
    return ordered[keep]


def _border(soup: Soup, split: PatchSplit) -> Border:
    """The free border edges (B, 2), their vertices and each soup vertex's border surface."""
    free = np.flatnonzero(np.diff(split.offsets) == 1)
    border = split.edges[free]
    owner = np.full(soup.vertices.shape[0], -1, dtype=np.int64)
    border_surface = soup.triangle_surface[split.incident_triangles[split.offsets[free]]]
    owner[border[:, 0]] = border_surface
    owner[border[:, 1]] = border_surface
    return border, _sorted_unique(border), owner


def free_border(soup: Soup) -> Border:
    """What :func:`_border` gives from the patch split, without splitting: one sort of the
    triangle sides packed as ``(edge key · S + surface)``; an edge whose key appears once is
    free (same edges, same order: ascending ``(low, high)``).

    >>> import geobrep
    >>> from geobrep.plugins.blocks._patches import split_patches
    >>> from geobrep.plugins.blocks._soup import build_soup
    >>> surfaces = geobrep.datasets.faulted_layer_cake().surfaces
    >>> soup = build_soup([s for s in surfaces if s.name != "top"], None, 1e-7)
    >>> mine, theirs = free_border(soup), _border(soup, split_patches(soup))
    >>> all(np.array_equal(a, b) for a, b in zip(mine, theirs)), mine[0].shape[0] > 0
    (True, True)
    """
    n_vertices, n_surfaces = soup.vertices.shape[0], max(len(soup.surfaces), 1)
    if n_vertices * n_vertices * n_surfaces >= 2**62:
        from geobrep.plugins.blocks._patches import split_patches

        return _border(soup, split_patches(soup))
    tri = soup.triangles
    low = np.minimum(tri, tri[:, _NEXT])
    high = np.maximum(tri, tri[:, _NEXT])
    side = (low * n_vertices + high) * n_surfaces + soup.triangle_surface[:, None]
    packed = np.sort(side.reshape(-1))
    edge = packed // n_surfaces
    alone = np.ones(edge.shape[0], dtype=np.bool_)
    alone[1:] = edge[1:] != edge[:-1]
    alone[:-1] &= edge[:-1] != edge[1:]
    key, surface = edge[alone], packed[alone] % n_surfaces
    border = np.stack([key // n_vertices, key % n_vertices], axis=1)
    owner = np.full(n_vertices, -1, dtype=np.int64)
    owner[border[:, 0]] = surface
    owner[border[:, 1]] = surface
    return border, _sorted_unique(border), owner


def _gaps(
    soup: Soup,
    free: Border,
    gap_tolerance: float,
    tol: float,
    pairs: tuple[IntArray, IntArray] | None = None,
) -> list[NonConformity]:
    """Gaps (and T-junctions) between free border vertices (``free``: the soup's free border)
    and other surfaces; ``pairs``: candidate (border point, triangle) pairs when the caller's
    broad phase found them."""
    border, points, owner = free
    if border.shape[0] == 0 or gap_tolerance <= 0.0:
        return []
    local = soup.local_vertices
    n_points = points.shape[0]
    if pairs is None:
        dots = np.repeat(local[points][:, None, :], 3, axis=1)
        groups = np.concatenate([np.zeros(n_points, np.int64), np.ones(soup.n_triangles, np.int64)])
        p, t = overlapping_pairs(
            np.concatenate([dots, local[soup.triangles]]), groups, margin=0.5 * gap_tolerance
        )
        t = t - n_points
    else:
        p, t = pairs
    vertex = points[p]
    n_surfaces = len(soup.surfaces)
    allowed = np.isin(
        vertex * n_surfaces + soup.triangle_surface[t], _allowed_surfaces(soup, border)
    )
    vertex, t = vertex[~allowed], t[~allowed]
    if vertex.size == 0:
        return []
    corners = local[soup.triangles[t]]
    distance = point_triangle_distance(local[vertex], corners[:, 0], corners[:, 1], corners[:, 2])
    close = distance <= gap_tolerance
    vertex, t, distance = vertex[close], t[close], distance[close]
    # One defect per border vertex: its nearest other surface.
    order = np.lexsort((distance, vertex))
    first = np.ones(order.shape[0], dtype=np.bool_)
    first[1:] = vertex[order][1:] != vertex[order][:-1]
    defects = []
    for k in order[first].tolist():
        v = int(vertex[k])
        x, y, z = (float(c) for c in soup.vertices[v])
        defects.append(
            NonConformity(
                kind="T-junction" if distance[k] <= tol else "gap",
                surfaces=(
                    soup.surface_name(int(owner[v])),
                    soup.surface_name(int(soup.triangle_surface[t[k]])),
                ),
                point=(x, y, z),
                distance=float(distance[k]),
                triangles=(-1, int(t[k])),
                vertex=v,
            )
        )
    return defects


def _hint(soup: Soup, defects: list[NonConformity], gap_tolerance: float) -> str:
    """Which tolerance the check used, where it came from, and the options that change it."""
    if soup.tolerance_source == "precision" and soup.precision is not None:
        origin = f"{soup.precision.source} coordinates, precision {soup.precision.quantum:.3g}"
    else:
        origin = f"option {soup.tolerance_source}"
    text = (
        f" (merge/contact tolerance {soup.tolerance:.3g}, from {origin}; if the defects are "
        "rounding, relax the check with relative_tolerance= / --relative-tolerance or "
        "tolerance= / --tolerance"
    )
    if any(d.kind == "gap" for d in defects):
        text += f"; gaps are sought within gap_tolerance= / --gap-tolerance ({gap_tolerance:.3g})"
    return text + "; check_conformity=False / --no-conformity-check skips it)"


def find_defects(soup: Soup, split: PatchSplit | None, gap_tolerance: float) -> list[NonConformity]:
    """Every crossing, T-junction and gap of the soup (what :func:`check_conformity` raises);
    the free border comes from ``split``, else (``None``) from :func:`free_border`.

    One broad phase serves both searches: the triangles and the free border points (a group
    of their own, after every surface) at the wider of the two margins; triangle pairs are
    then kept where their boxes come within the contact tolerance, point-triangle pairs go to
    the gap search."""
    tol = soup.tolerance
    free = free_border(soup) if split is None else _border(soup, split)
    border, points, _ = free
    if border.shape[0] == 0 or gap_tolerance <= 0.0:
        return _crossings(soup, tol) + _gaps(soup, free, gap_tolerance, tol)
    n = soup.n_triangles
    columns = np.ascontiguousarray(soup.local_vertices.T)
    stored = np.empty((3, 3, n + points.shape[0]))  # component-major: (corner, xyz, K)
    for corner in range(3):  # 1-D gathers: numpy's fancy indexing of rows is slower
        index = np.ascontiguousarray(soup.triangles[:, corner])
        for axis in range(3):
            np.take(columns[axis], index, out=stored[corner, axis, :n])
            np.take(columns[axis], points, out=stored[corner, axis, n:])
    groups = np.concatenate(
        [soup.triangle_surface, np.full(points.shape[0], len(soup.surfaces), np.int64)]
    )
    i, j = stored_pairs(stored, groups, margin=max(tol, 0.5 * gap_tolerance))
    # groups[i] < groups[j]: a border point (the last group) is always j.
    to_point = j >= n
    first, second = i[~to_point], j[~to_point]
    order = np.lexsort((second, first))
    triangle_pairs = (first[order], second[order])
    p, t = j[to_point] - n, i[to_point]
    order = np.lexsort((t, p))
    crossings = _crossings(soup, tol, triangle_pairs)
    return crossings + _gaps(soup, free, gap_tolerance, tol, (p[order], t[order]))


def check_conformity(soup: Soup, split: PatchSplit, gap_tolerance: float) -> None:
    """Raise :class:`NonConformalError` when surfaces cross, touch or leave gaps."""
    defects = find_defects(soup, split, gap_tolerance)
    if defects:
        raise NonConformalError(defects, _hint(soup, defects, gap_tolerance))
