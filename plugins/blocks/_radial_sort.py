"""Sort the patches around every arc by the right-hand rule (the paper's 面片排序表).

Around the direction edge ``s → t`` of an arc, each direction triangle ``(s, t, c)`` leaves the
edge in the half-plane of its third vertex ``c``; patches are ordered by the counter-clockwise
angle of that half-plane about ``t − s`` (thumb along the arc). Coordinates are taken relative to
``s``, so UTM-scale models keep full precision.

Near-coplanar patches (a horizon meeting an unconformity at a grazing angle, a sliver triangle on
the direction edge) can make two half-planes indistinguishable at one edge. When the smallest
angular gap at the direction edge is under ``retry_below`` radians, every edge of that arc is
examined and the one separating its patches best is used; if even that gap is at most
``angle_tolerance`` the patches overlap and a :class:`~geobrep.errors.TopologyError` says where.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from geobrep.errors import TopologyError
from geobrep.geometry.arrays import BoolArray, FloatArray, IntArray
from geobrep.plugins.blocks._arcs import ArcChains
from geobrep.plugins.blocks._csr import concatenated_ranges
from geobrep.plugins.blocks._orientation import DirectionTriangles, direction_triangles
from geobrep.plugins.blocks._patches import PatchSplit

__all__ = ["SortedArcs", "half_plane_angles", "radial_angles", "sort_arcs"]


#: Relative length under which a third vertex counts as lying on the arc's line.
_COLLINEAR_RTOL = 1e-12
_MAX_REPORTED = 5


@dataclass(frozen=True)
class SortedArcs:
    """One group per arc (group ``a`` is arc ``a``), rows in right-hand cyclic order."""

    around: DirectionTriangles
    touched_triangles: int
    retried_arcs: int


def radial_angles(
    vertices: FloatArray, triangles: IntArray, rows: DirectionTriangles
) -> tuple[FloatArray, BoolArray]:
    """Angle in (−π, π] of every row's half-plane about its edge, and which rows are degenerate.

    The zero direction is fixed per edge direction, so angles of one group compare directly.
    """
    third = triangles[rows.triangle].sum(axis=1) - rows.start - rows.end
    return half_plane_angles(vertices, rows.start, rows.end, third)


def half_plane_angles(
    vertices: FloatArray, start: IntArray, end: IntArray, third: IntArray
) -> tuple[FloatArray, BoolArray]:
    """Angle in (−π, π] of the half-plane of vertex ``third[i]`` about edge ``start[i] →
    end[i]`` (right-hand rule, thumb along the edge), and which thirds lie on the edge's line.

    The zero direction depends only on the edge's direction, so rows on one edge compare.

    >>> import numpy as np
    >>> points = np.array([[0, 0, 0], [0, 0, 1], [1, 0, 0], [0, 1, 0], [-1, 0, 0.5]], float)
    >>> angles, flat = half_plane_angles(points, np.zeros(3, int), np.ones(3, int), np.arange(2, 5))
    >>> [round(float(a), 4) for a in np.unwrap(angles - angles[0])], flat.tolist()
    ([0.0, 1.5708, 3.1416], [False, False, False])
    """
    origin = vertices[start]
    axis = vertices[end] - origin
    leg = vertices[third] - origin
    axis /= np.linalg.norm(axis, axis=1)[:, None]
    helper = np.zeros_like(axis)
    helper[np.arange(axis.shape[0]), np.argmin(np.abs(axis), axis=1)] = 1.0
    first = np.cross(axis, helper)
    first /= np.linalg.norm(first, axis=1)[:, None]
    second = np.cross(axis, first)
    x = np.einsum("ij,ij->i", leg, first)
    y = np.einsum("ij,ij->i", leg, second)
    degenerate = np.hypot(x, y) <= _COLLINEAR_RTOL * np.linalg.norm(leg, axis=1)
    return np.arctan2(y, x), degenerate


def _cyclic_order(
    vertices: FloatArray, triangles: IntArray, rows: DirectionTriangles
) -> tuple[IntArray, FloatArray]:
    """Row permutation sorting each group by angle, and each group's smallest cyclic gap."""
    angles, degenerate = radial_angles(vertices, triangles, rows)
    group = rows.group
    order = np.lexsort((angles, group)).astype(np.int64)
    ordered = angles[order]
    starts, ends = rows.offsets[:-1], rows.offsets[1:] - 1
    following = np.empty_like(ordered)
    following[:-1] = ordered[1:]
    following[ends] = ordered[starts] + 2.0 * math.pi  # wrap around each group
    gaps = following - ordered
    smallest = np.minimum.reduceat(gaps, starts) if gaps.size else gaps
    flawed = np.logical_or.reduceat(degenerate, starts) if gaps.size else degenerate
    return order, np.where(flawed, 0.0, smallest)


def sort_arcs(
    vertices: FloatArray,
    triangles: IntArray,
    split: PatchSplit,
    chains: ArcChains,
    angle_tolerance: float,
    describe_patch: Callable[[int], str],
    retry_below: float = 1e-6,
) -> SortedArcs:
    """Sort the patches around every arc, from one direction edge per arc where it suffices.

    >>> from geobrep.plugins.blocks._arcs import sample_model_arcs
    >>> soup, split, chains = sample_model_arcs()
    >>> arcs = sort_arcs(soup.vertices, soup.triangles, split, chains, 1e-10, str)
    >>> arcs.touched_triangles, arcs.retried_arcs  # 132 of 4296 triangles, as in the paper
    (132, 0)"""
    positions = chains.arc_offsets[:-1].copy()
    first = direction_triangles(triangles, split, chains, positions)
    order, gaps = _cyclic_order(vertices, triangles, first)
    touched = first.triangle.shape[0]
    doubtful = np.flatnonzero(gaps <= retry_below)
    if doubtful.size:
        starts = chains.arc_offsets[doubtful]
        counts = chains.arc_offsets[doubtful + 1] - starts
        candidates = concatenated_ranges(starts, counts)
        every = direction_triangles(triangles, split, chains, candidates)
        touched += every.triangle.shape[0]
        _, candidate_gaps = _cyclic_order(vertices, triangles, every)
        # Best edge per doubtful arc: largest smallest-gap (first such edge on ties).
        arc_of_candidate = np.repeat(np.arange(doubtful.shape[0]), counts)
        best = np.lexsort((-candidate_gaps, arc_of_candidate))
        chosen_first = np.ones(best.shape[0], dtype=np.bool_)
        chosen_first[1:] = arc_of_candidate[best][1:] != arc_of_candidate[best][:-1]
        chosen = best[chosen_first]
        overlapping = candidate_gaps[chosen] <= angle_tolerance
        if overlapping.any():
            _raise_overlap(
                vertices,
                triangles,
                every.take_groups(chosen[overlapping]),
                doubtful[overlapping],
                describe_patch,
            )
        positions[doubtful] = candidates[chosen]
        first = direction_triangles(triangles, split, chains, positions)
        order, _ = _cyclic_order(vertices, triangles, first)
    return SortedArcs(first.reorder(order), touched, int(doubtful.size))


def _raise_overlap(
    vertices: FloatArray,
    triangles: IntArray,
    rows: DirectionTriangles,
    arcs: IntArray,
    describe_patch: Callable[[int], str],
) -> None:
    order, _ = _cyclic_order(vertices, triangles, rows)
    angles, _ = radial_angles(vertices, triangles, rows)
    messages = []
    for k, arc in enumerate(arcs[:_MAX_REPORTED].tolist()):
        members = order[rows.offsets[k] : rows.offsets[k + 1]]
        gap = np.diff(np.append(angles[members], angles[members[0]] + 2 * math.pi))
        i = int(np.argmin(gap))
        a, b = members[i], members[(i + 1) % members.shape[0]]
        middle = 0.5 * (vertices[rows.start[a]] + vertices[rows.end[a]])
        where = ", ".join(f"{c:.3f}" for c in middle.tolist())
        messages.append(
            f"arc {arc}: {describe_patch(int(rows.patch[a]))} and "
            f"{describe_patch(int(rows.patch[b]))} leave it in the same direction near ({where})"
        )
    more = (
        f" (and {arcs.shape[0] - _MAX_REPORTED} more arcs)" if arcs.shape[0] > _MAX_REPORTED else ""
    )
    raise TopologyError(
        "non-conformal input: overlapping patches around "
        f"{arcs.shape[0]} arc(s): " + "; ".join(messages) + more
    )
