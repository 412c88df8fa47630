"""The PolyLine clipper (the paper's line cutting) and the PointSet section of a line.

Every segment is classified from the sides of its ends: kept whole (both ends on the kept side or
on the plane, including segments lying in the plane, which belong to both sides), cut (ends
strictly on opposite sides: the kept end joins the crossing point ``D + tE`` with
``t = d(D) / (d(D) − d(E))``), or dropped. Runs of consecutive kept segments become the new parts;
a closed part that is cut reopens at the cut, its last run joining its first. A point merely
touching the plane from the dropped side is not a part (a part needs two points). Point data is
interpolated at the crossing points, segment data follows each segment.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from geobrep import PointSet, PolyLine
from geobrep.geometry import Plane
from geobrep.geometry.arrays import BoolArray, FloatArray, IntArray
from geobrep.plugins import ClipContext, Keep, halves, pack_halves
from geobrep.plugins.clip._sides import (
    crossing_points,
    interpolate_properties,
    vertex_sides,
)
from geobrep.plugins.clip.options import ClipOptions, tolerance_of

__all__ = ["LineCut", "clip_polyline", "cut_segments", "section_polyline"]


@dataclass(frozen=True)
class LineCut:
    """The kept runs of a set of chains on one side of a plane.

    Output points are ``kept_points`` (input indices) then crossing points ``a + t (b − a)``.
    Run ``r`` visits ``indices[offsets[r]:offsets[r+1]]``; ``closed[r]`` says it is a whole
    closed chain; ``source_chain`` gives each run's input chain and ``segment_source`` each
    output segment's input segment (runs in order, a closed run's closing segment last).
    """

    vertices: FloatArray
    kept_points: IntArray
    edge_a: IntArray
    edge_b: IntArray
    edge_t: FloatArray
    indices: IntArray
    offsets: IntArray
    closed: BoolArray
    source_chain: IntArray
    segment_source: IntArray
    #: For each run, whether its first and last points lie on the plane.
    starts_on_plane: BoolArray
    ends_on_plane: BoolArray


def cut_segments(
    vertices: FloatArray,
    segments: IntArray,
    segment_chain: IntArray,
    chain_closed: BoolArray,
    distances: FloatArray,
    tolerance: float,
    side: int,
) -> LineCut:
    """Cut chains of ``segments`` (S, 2), listed chain by chain in order (a closed chain's closing
    segment last), keeping ``side``.

    >>> v = np.array([[0.0, 0, 0], [2, 0, 0], [2, 2, 0]])
    >>> cut = cut_segments(v, np.array([[0, 1], [1, 2]]), np.array([0, 0]), np.array([False]),
    ...                    v[:, 0] - 1.0, 0.0, -1)
    >>> cut.vertices.tolist(), cut.indices.tolist()
    ([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]], [0, 1])
    """
    sides = vertex_sides(distances, tolerance)
    pieces = _kept_pieces(vertices, segments, segment_chain, sides, distances, side)
    chains = _ChainRows.of(segment_chain, chain_closed)
    run_of_piece, order_in_chain = _runs_of_pieces(pieces, chains)
    runs = _ordered_runs(pieces, chains, run_of_piece, order_in_chain)
    return _line_cut(vertices, sides, pieces, runs)


@dataclass(frozen=True)
class _Pieces:
    """What each segment keeps on one side: the segment whole, or its kept end and a crossing.

    ``segment`` is the input segment of each piece (increasing); ``start`` and ``end`` its points,
    crossing point ``k`` numbered ``n_vertices + k``; ``whole`` flags every *input* segment
    that is kept whole; ``crossings`` are the crossing points of the cut segments, on the edges
    ``(edge_a, edge_b)`` at ``edge_t``.
    """

    segment: IntArray
    start: IntArray
    end: IntArray
    chain: IntArray
    whole: BoolArray
    crossings: FloatArray
    edge_a: IntArray
    edge_b: IntArray
    edge_t: FloatArray


def _kept_pieces(
    vertices: FloatArray,
    segments: IntArray,
    segment_chain: IntArray,
    sides: NDArray[np.int8],
    distances: FloatArray,
    side: int,
) -> _Pieces:
    """The segments kept whole and the kept halves of the cut ones, in input order."""
    start_side, end_side = sides[segments[:, 0]], sides[segments[:, 1]]
    start_kept = (start_side == side) | (start_side == 0)
    end_kept = (end_side == side) | (end_side == 0)
    whole = start_kept & end_kept
    crossing = (start_side * end_side) < 0
    cut = np.flatnonzero(crossing)
    crossings, edge_a, edge_b, edge_t = crossing_points(
        vertices, distances, segments[cut, 0], segments[cut, 1]
    )
    starts = segments[:, 0].copy()
    ends = segments[:, 1].copy()
    crossing_id = vertices.shape[0] + np.arange(cut.shape[0], dtype=np.int64)
    keeps_start = start_side[cut] == side
    ends[cut[keeps_start]] = crossing_id[keeps_start]
    starts[cut[~keeps_start]] = crossing_id[~keeps_start]
    kept = np.flatnonzero(whole | crossing)
    return _Pieces(
        segment=kept,
        start=starts[kept],
        end=ends[kept],
        chain=segment_chain[kept],
        whole=whole,
        crossings=crossings,
        edge_a=edge_a,
        edge_b=edge_b,
        edge_t=edge_t,
    )


@dataclass(frozen=True)
class _ChainRows:
    """Per input chain: its segment count, first and last segment, and whether it is closed."""

    count: IntArray
    first: IntArray
    last: IntArray
    closed: BoolArray

    @classmethod
    def of(cls, segment_chain: IntArray, chain_closed: BoolArray) -> _ChainRows:
        count = np.bincount(segment_chain, minlength=chain_closed.shape[0])
        first = np.concatenate([[0], np.cumsum(count)[:-1]])
        return cls(count=count, first=first, last=first + count - 1, closed=chain_closed)


def _runs_of_pieces(pieces: _Pieces, chains: _ChainRows) -> tuple[IntArray, IntArray]:
    """The run of every piece, and the key that orders the pieces of a chain.

    Consecutive pieces of a chain that share a point form a run; the key is the input segment.
    """
    segment, start, end, chain = pieces.segment, pieces.start, pieces.end, pieces.chain
    joins_previous = np.zeros(segment.shape[0], dtype=np.bool_)
    if segment.shape[0] > 1:
        joins_previous[1:] = (
            (chain[1:] == chain[:-1]) & (segment[1:] == segment[:-1] + 1) & (end[:-1] == start[1:])
        )
    run_of_piece = np.cumsum(~joins_previous) - 1
    order_in_chain = segment.copy()
    if segment.shape[0]:
        _wrap_closed_chains(pieces, chains, joins_previous, run_of_piece, order_in_chain)
    return run_of_piece, order_in_chain


def _wrap_closed_chains(
    pieces: _Pieces,
    chains: _ChainRows,
    joins_previous: BoolArray,
    run_of_piece: IntArray,
    order_in_chain: IntArray,
) -> None:
    """A closed chain cut somewhere: the run ending at its closing segment continues into the
    run starting the chain (``run_of_piece`` and ``order_in_chain`` are updated in place)."""
    segment, start, end, chain = pieces.segment, pieces.start, pieces.end, pieces.chain
    run_first = np.flatnonzero(~joins_previous)  # first piece of every run
    run_last = np.append(run_first[1:] - 1, segment.shape[0] - 1)
    run_chain = chain[run_first]
    wraps = (
        chains.closed[run_chain]
        & (segment[run_last] == chains.last[run_chain])
        & (segment[run_first] != chains.first[run_chain])
    )
    heads = np.flatnonzero(segment == chains.first[chain])  # pieces that start their chain
    head_run_of_chain = np.full(chains.closed.shape[0], -1, dtype=np.int64)
    head_run_of_chain[chain[heads]] = run_of_piece[heads]
    wrapping = np.flatnonzero(wraps)
    head_runs = head_run_of_chain[run_chain[wrapping]]
    mergeable = (head_runs >= 0) & (head_runs != wrapping)
    mergeable &= end[run_last[wrapping]] == start[run_first[np.maximum(head_runs, 0)]]
    merges = zip(wrapping[mergeable].tolist(), head_runs[mergeable].tolist(), strict=True)
    for run, head_run in merges:
        members = run_of_piece == run
        # before the head run's pieces: negative keys, in the chain's order
        order_in_chain[members] = segment[members] - (chains.last[chain[members]] + 1)
        run_of_piece[members] = head_run


@dataclass(frozen=True)
class _Runs:
    """The runs as point sequences: run ``r`` visits ``sequence[offsets[r]:offsets[r+1]]``."""

    sequence: IntArray
    offsets: IntArray
    closed: BoolArray
    chain: IntArray
    segment_source: IntArray


def _ordered_runs(
    pieces: _Pieces, chains: _ChainRows, run_of_piece: IntArray, order_in_chain: IntArray
) -> _Runs:
    """Pieces sorted into runs, each run's points (its first start, then every end; a whole
    closed chain without the repeated first point)."""
    order = np.lexsort((order_in_chain, pieces.chain))
    start, end = pieces.start[order], pieces.end[order]
    chain, run_of_piece, source = pieces.chain[order], run_of_piece[order], pieces.segment[order]
    begins_run = np.ones(start.shape[0], dtype=np.bool_)
    begins_run[1:] = run_of_piece[1:] != run_of_piece[:-1]
    run_starts = np.flatnonzero(begins_run)
    run_lengths = np.diff(np.append(run_starts, start.shape[0]))
    run_chain = chain[run_starts]
    whole_pieces = (
        np.add.reduceat(pieces.whole[source].astype(np.int64), run_starts)
        if run_starts.shape[0]
        else np.zeros(0, dtype=np.int64)
    )
    closed = (
        chains.closed[run_chain]
        & (run_lengths == chains.count[run_chain])
        & (whole_pieces == run_lengths)
    )
    sequence = np.insert(end, run_starts, start[run_starts])
    offsets = np.append(run_starts + np.arange(run_starts.shape[0]), sequence.shape[0])
    closed_runs = np.flatnonzero(closed)
    if closed_runs.shape[0]:
        repeated = offsets[closed_runs + 1] - 1
        sequence = np.delete(sequence, repeated)
        offsets = offsets - np.searchsorted(np.sort(repeated), offsets, side="left")
    return _Runs(sequence, offsets, closed, run_chain, source)


def _line_cut(
    vertices: FloatArray, sides: NDArray[np.int8], pieces: _Pieces, runs: _Runs
) -> LineCut:
    """The runs renumbered over the points they use: kept input points, then crossings."""
    n_vertices = vertices.shape[0]
    used, local = np.unique(runs.sequence, return_inverse=True)
    kept_points = used[used < n_vertices]
    new_points = used[used >= n_vertices] - n_vertices
    out_vertices = np.concatenate([vertices[kept_points], pieces.crossings[new_points]])
    on_plane = np.concatenate([sides[kept_points] == 0, np.ones(new_points.shape[0], bool)])
    local = local.reshape(-1).astype(np.int64)
    return LineCut(
        vertices=out_vertices,
        kept_points=kept_points,
        edge_a=pieces.edge_a[new_points],
        edge_b=pieces.edge_b[new_points],
        edge_t=pieces.edge_t[new_points],
        indices=local,
        offsets=runs.offsets.astype(np.int64),
        closed=runs.closed,
        source_chain=runs.chain.astype(np.int64),
        segment_source=runs.segment_source.astype(np.int64),
        starts_on_plane=on_plane[local[runs.offsets[:-1]]],
        ends_on_plane=on_plane[local[runs.offsets[1:] - 1]],
    )


def _segment_chains(line: PolyLine) -> IntArray:
    """The part of every segment of ``line.segments``."""
    counts = line.part_lengths - 1 + line.closed.astype(np.int64)
    return np.repeat(np.arange(line.n_parts, dtype=np.int64), counts)


def clip_polyline(
    line: PolyLine, plane: Plane, keep: Keep, options: ClipOptions, context: ClipContext
) -> Any:
    """Clipper of :class:`PolyLine` entities (see the module docstring)."""
    tolerance = tolerance_of(options, context)
    distances = plane.signed_distance(line.vertices)
    sides = vertex_sides(distances, tolerance)
    parts: dict[int, PolyLine | None] = {}
    for side in halves(keep):
        if not (sides == -side).any():
            parts[side] = line
            continue
        cut = cut_segments(
            line.vertices,
            np.asarray(line.segments, dtype=np.int64),
            _segment_chains(line),
            np.asarray(line.closed, dtype=np.bool_),
            distances,
            tolerance,
            side,
        )
        if cut.offsets.shape[0] <= 1:
            parts[side] = None
            continue
        parts[side] = PolyLine(
            vertices=cut.vertices,
            indices=cut.indices,
            part_offsets=cut.offsets,
            closed=cut.closed,
            point_data=interpolate_properties(
                line.point_data, cut.kept_points, cut.edge_a, cut.edge_b, cut.edge_t
            ),
            cell_data=line.cell_data.take(cut.segment_source),
            id=line.id,
            name=line.name,
            kind=line.kind,
            metadata=line.metadata,
        )
    return pack_halves(keep, parts)


def section_polyline(
    line: PolyLine, plane: Plane, options: ClipOptions, context: ClipContext
) -> PointSet | None:
    """Where a line meets the plane: crossing points and vertices on the plane."""
    tolerance = tolerance_of(options, context)
    distances = plane.signed_distance(line.vertices)
    sides = vertex_sides(distances, tolerance)
    segments = np.asarray(line.segments, dtype=np.int64)
    crossing = np.flatnonzero(sides[segments[:, 0]] * sides[segments[:, 1]] < 0)
    points, a, b, t = crossing_points(
        line.vertices, distances, segments[crossing, 0], segments[crossing, 1]
    )
    on = np.flatnonzero(sides == 0)
    if on.shape[0] == 0 and crossing.shape[0] == 0:
        return None
    return PointSet(
        vertices=np.concatenate([line.vertices[on], points]),
        point_data=interpolate_properties(line.point_data, on, a, b, t),
        name=line.name,
        kind=line.kind,
        metadata={**line.metadata, "polyline": line.id},
    )
