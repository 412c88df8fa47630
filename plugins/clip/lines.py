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
from geobrep.plugins import ClipContext, Keep, halves, pack_halves
from geobrep.plugins.clip.options import ClipOptions, tolerance_of
from geobrep.plugins.clip.sides import (
    crossing_points,
    interpolate_properties,
    vertex_sides,
)

__all__ = ["LineCut", "clip_polyline", "cut_segments", "section_polyline"]

IntArray = NDArray[np.int64]
FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]


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
    n = vertices.shape[0]
    sides = vertex_sides(distances, tolerance)
    s0, s1 = sides[segments[:, 0]], sides[segments[:, 1]]
    ok0, ok1 = (s0 == side) | (s0 == 0), (s1 == side) | (s1 == 0)
    whole = ok0 & ok1
    crossing = (s0 * s1) < 0
    cut_rows = np.flatnonzero(crossing)
    points, edge_a, edge_b, edge_t = crossing_points(
        vertices, distances, segments[cut_rows, 0], segments[cut_rows, 1]
    )
    starts = segments[:, 0].copy()
    ends = segments[:, 1].copy()
    new_id = n + np.arange(cut_rows.shape[0], dtype=np.int64)
    start_kept = s0[cut_rows] == side
    ends[cut_rows[start_kept]] = new_id[start_kept]
    starts[cut_rows[~start_kept]] = new_id[~start_kept]
    rows = np.flatnonzero(whole | crossing)
    p, q, chain = starts[rows], ends[rows], segment_chain[rows]
    joins = np.zeros(rows.shape[0], dtype=np.bool_)
    if rows.shape[0] > 1:
        joins[1:] = (chain[1:] == chain[:-1]) & (rows[1:] == rows[:-1] + 1) & (q[:-1] == p[1:])
    # A closed chain cut somewhere: its last run continues into its first.
    counts = np.bincount(segment_chain, minlength=chain_closed.shape[0])
    first_row = np.concatenate([[0], np.cumsum(counts)[:-1]])
    last_row = first_row + counts - 1
    order_key = rows.copy()
    run_id = np.cumsum(~joins) - 1
    if rows.shape[0]:
        run_first = np.flatnonzero(~joins)
        run_last = np.append(run_first[1:] - 1, rows.shape[0] - 1)
        first_chain = chain[run_first]
        wraps = (
            chain_closed[first_chain]
            & (rows[run_last] == last_row[first_chain])
            & (rows[run_first] != first_row[first_chain])
        )
        # The run ending at the closing segment, followed by the run starting the chain.
        head = np.flatnonzero(rows == first_row[chain])
        head_run = np.full(chain_closed.shape[0], -1, dtype=np.int64)
        head_run[chain[head]] = run_id[head]
        for_runs = np.flatnonzero(wraps)
        targets = head_run[first_chain[for_runs]]
        mergeable = (targets >= 0) & (targets != for_runs)
        mergeable &= q[run_last[for_runs]] == p[run_first[np.maximum(targets, 0)]]
        merges = zip(for_runs[mergeable].tolist(), targets[mergeable].tolist(), strict=True)
        for run, target in merges:
            members = run_id == run
            order_key[members] = rows[members] - (last_row[chain[members]] + 1)
            run_id[members] = target
    order = np.lexsort((order_key, chain))
    p, q, chain, run_id, source = p[order], q[order], chain[order], run_id[order], rows[order]
    starts_run = np.ones(p.shape[0], dtype=np.bool_)
    starts_run[1:] = run_id[1:] != run_id[:-1]
    run_starts = np.flatnonzero(starts_run)
    run_lengths = np.diff(np.append(run_starts, p.shape[0]))
    run_chain = chain[run_starts]
    whole_count = (
        np.add.reduceat(whole[source].astype(np.int64), run_starts)
        if run_starts.shape[0]
        else np.zeros(0, dtype=np.int64)
    )
    closed_run = (
        chain_closed[run_chain] & (run_lengths == counts[run_chain]) & (whole_count == run_lengths)
    )
    # Vertex sequence of each run: its first start, then every end (closed: no repeat).
    sequence = np.insert(q, run_starts, p[run_starts])
    offsets = np.append(run_starts + np.arange(run_starts.shape[0]), sequence.shape[0])
    drop_last = np.flatnonzero(closed_run)
    if drop_last.shape[0]:
        remove = offsets[drop_last + 1] - 1
        sequence = np.delete(sequence, remove)
        offsets = offsets - np.searchsorted(np.sort(remove), offsets, side="left")
    used, local = np.unique(sequence, return_inverse=True)
    kept_points = used[used < n]
    new_points = used[used >= n] - n
    out_vertices = np.concatenate([vertices[kept_points], points[new_points]])
    on_plane = np.concatenate([sides[kept_points] == 0, np.ones(new_points.shape[0], bool)])
    local = local.reshape(-1).astype(np.int64)
    first_points = local[offsets[:-1]]
    last_points = local[offsets[1:] - 1]
    return LineCut(
        vertices=out_vertices,
        kept_points=kept_points,
        edge_a=edge_a[new_points],
        edge_b=edge_b[new_points],
        edge_t=edge_t[new_points],
        indices=local,
        offsets=offsets.astype(np.int64),
        closed=closed_run,
        source_chain=run_chain.astype(np.int64),
        segment_source=source.astype(np.int64),
        starts_on_plane=on_plane[first_points],
        ends_on_plane=on_plane[last_points],
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
