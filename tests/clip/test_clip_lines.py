"""PolyLine clipping (the paper's Fig. 2) with points and segments on the plane."""

from __future__ import annotations

import numpy as np
import pytest

from geobrep import Plane, PolyLine
from geobrep.ops.clipping import clip, section


def _parts(line: PolyLine) -> list[list[list[float]]]:
    return [line.part(i)[:, :2].tolist() for i in range(line.n_parts)]


def test_paper_figure_2() -> None:
    # Six points; the cut keeps the points below y = 1: 1, 3, 5, 6 (numbered from 1).
    points = [[0, 0, 0], [1, 2, 0], [2, 0, 0], [3, 2, 0], [4, 0, 0], [5, -1, 0]]
    line = PolyLine(vertices=points)
    kept = clip(line, Plane.y(1.0))
    assert _parts(kept) == [
        [[0.0, 0.0], [0.5, 1.0]],  # 1A
        [[1.5, 1.0], [2.0, 0.0], [2.5, 1.0]],  # B3C
        [[3.5, 1.0], [4.0, 0.0], [5.0, -1.0]],  # D56
    ]
    above = clip(line, Plane.y(1.0), keep="positive")
    assert _parts(above) == [
        [[0.5, 1.0], [1.0, 2.0], [1.5, 1.0]],
        [[2.5, 1.0], [3.0, 2.0], [3.5, 1.0]],
    ]
    assert kept.length + above.length == pytest.approx(line.length, rel=1e-15)


def test_first_and_last_points_on_the_plane() -> None:
    line = PolyLine(vertices=[[1, 0, 0], [0, 0, 0], [0, 1, 0], [1, 1, 0]])
    left = clip(line, Plane.x(1.0))
    assert left is line  # nothing beyond the plane
    right = clip(line, Plane.x(1.0), keep="positive")
    assert right is None  # two points touching the plane are not a line


def test_touching_and_lying_segments() -> None:
    # Touches x = 1 at a vertex from the left, then runs along the plane, then leaves right.
    line = PolyLine(vertices=[[0, 0, 0], [1, 1, 0], [0, 2, 0], [1, 3, 0], [1, 4, 0], [2, 5, 0]])
    left = clip(line, Plane.x(1.0))
    assert _parts(left) == [[[0.0, 0.0], [1.0, 1.0], [0.0, 2.0], [1.0, 3.0], [1.0, 4.0]]]
    right = clip(line, Plane.x(1.0), keep="positive")
    assert _parts(right) == [[[1.0, 3.0], [1.0, 4.0], [2.0, 5.0]]]  # the lying segment: both


def test_parallel_segments_are_kept_or_dropped_whole() -> None:
    line = PolyLine(vertices=[[0, 0, 0], [0, 5, 0], [3, 5, 0], [3, 0, 0]])
    left = clip(line, Plane.x(2.0))
    assert _parts(left) == [[[0.0, 0.0], [0.0, 5.0], [2.0, 5.0]]]


def test_closed_line_reopens_at_the_cut() -> None:
    ring = PolyLine.from_point_lists([[[0, 0, 0], [2, 0, 0], [2, 2, 0], [0, 2, 0]]], closed=True)
    left = clip(ring, Plane.x(1.0))
    assert left.closed.tolist() == [False]
    assert _parts(left) == [[[1.0, 2.0], [0.0, 2.0], [0.0, 0.0], [1.0, 0.0]]]
    inside = clip(ring, Plane.x(3.0))
    assert inside is ring


def test_point_and_cell_data() -> None:
    line = PolyLine.from_parts(
        [[0, 0, 0], [4, 0, 0], [4, 4, 0], [10, 10, 0], [12, 10, 0]],
        [[0, 1, 2], [3, 4]],
        point_data={"depth": [0.0, 40.0, 80.0, 1.0, 2.0], "well": np.array([1, 2, 3, 4, 5])},
        cell_data={"segment": [10, 11, 12]},
        name="wells",
    )
    kept = clip(line, Plane.x(1.0))
    assert kept.name == "wells"
    assert kept.n_parts == 1
    assert kept.point_data["depth"].values.tolist() == [0.0, 10.0]
    assert kept.point_data["well"].values.tolist() == [1, 1]  # integers: the nearer end
    assert kept.cell_data["segment"].values.tolist() == [10]


def test_utm_crossing_is_on_the_plane() -> None:
    start, end = (
        np.array([450_000.25, 6_700_000.5, -10.0]),
        np.array([450_900.75, 6_700_800.0, -620.0]),
    )
    plane = Plane.from_point_normal([450_333.0, 6_700_100.0, 0.0], [0.3, 0.9, 0.1])
    kept = clip(PolyLine(vertices=[start, end]), plane)
    crossing = kept.vertices[-1]
    assert abs(plane.signed_distance(crossing)[0]) < 1e-8
    assert (
        np.linalg.norm(np.cross(crossing - start, end - start)) / np.linalg.norm(end - start) < 1e-8
    )


def test_section_of_a_line_is_its_crossings() -> None:
    line = PolyLine(vertices=[[0, 0, 0], [2, 0, 0], [2, 2, 0], [0, 2, 0], [1, 3, 0]])
    points = section(line, Plane.x(1.0))
    assert sorted(points.vertices[:, 1].tolist()) == [0.0, 2.0, 3.0]
