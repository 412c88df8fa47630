"""Filled polygon clipping: the paper's cases A, B and C, holes, and sections."""

from __future__ import annotations

import numpy as np
import pytest

from geobrep import Plane, Polygon
from geobrep.ops.clipping import clip, section


def _flat(points: list[tuple[float, float]]) -> np.ndarray:
    xy = np.asarray(points, dtype=np.float64)
    return np.c_[xy, np.zeros(len(xy))]


def _polygon(outer: list[tuple[float, float]], *holes: list[tuple[float, float]]) -> Polygon:
    return Polygon.from_rings(_flat(outer), holes=[_flat(h) for h in holes], name="fill")


CUT = Plane.x(0.0)  # keep the left (negative) side, as in the paper's Fig. 4


def test_case_a_one_piece() -> None:
    # 0-1-a-(2-3 cut away)-b-4-5: the first and last runs join into S(0-1-a-b-4-5).
    a = _polygon([(-2, -1), (-1, -1), (1, -1), (1, 1), (-1, 1), (-2, 1)])
    kept = clip(a, CUT)
    assert (kept.n_polygons, kept.n_rings) == (1, 1)
    assert kept.area == pytest.approx(4.0)
    assert kept.name == "fill"


def test_case_b_a_notch_merges_with_the_main_piece() -> None:
    # A notch cut into the piece from the far side: separately closed, its piece S(b-4-c) would
    # lie inside S(0-1-2-a-d-6-7-8) but outside the polygon; the result is one ring.
    b = _polygon([(-2, -2), (2, -2), (2, -0.5), (-1, 0), (2, 0.5), (2, 2), (-2, 2)])
    kept = clip(b, CUT)
    assert (kept.n_polygons, kept.n_rings) == (1, 1)
    notch = 1.0 / 6.0  # the notch's triangle between x = -1 and the cut line
    assert kept.area == pytest.approx(8.0 - notch, rel=1e-12)
    assert kept.ring(0).shape[0] == 7  # 0-1-2-a-b-4-c-d-6-7-8 with our corners


C_RING = [
    (-2, -3),
    (-1, -3),
    (-0.5, -2),
    (1.5, -3),
    (2, -3),
    (2, 3),
    (-2, 3),
    (-2, 1),
    (1, 1),
    (1, -1),
    (-2, -1),
]


def test_case_c_separate_pieces() -> None:
    # A "U" open to the left: its two arms cross the cut line and give two separate polygons;
    # a notch cut into the lower arm from below must merge with that arm's piece.
    c = _polygon(C_RING)
    kept = clip(c, CUT)
    assert (kept.n_polygons, kept.n_rings) == (2, 2)
    notch = 0.25 + 0.4375  # the notch's part left of the cut line
    assert sorted(kept.polygon_areas.tolist()) == pytest.approx([4.0 - notch, 4.0], rel=1e-12)


def test_pieces_conserve_area() -> None:
    c = _polygon(C_RING)
    left, right = clip(c, Plane.from_point_normal((0.3, 0.0, 0.0), (1.0, 0.2, 0.0)), keep="both")
    assert left.area + right.area == pytest.approx(c.area, rel=1e-12)


def test_holes_are_nested_or_opened() -> None:
    square = _polygon([(-2, -2), (2, -2), (2, 2), (-2, 2)], [(-1, -1), (-1, 1), (1, 1), (1, -1)])
    opened = clip(square, CUT)
    assert (opened.n_polygons, opened.n_rings) == (1, 1)  # the hole becomes a notch
    assert opened.area == pytest.approx(6.0)
    kept = clip(square, Plane.x(1.5))
    assert (kept.n_polygons, kept.n_rings) == (1, 2)  # the hole stays a hole
    assert kept.area == pytest.approx(3.5 * 4 - 4)


def test_vertices_on_the_cut_line() -> None:
    diamond = _polygon([(0, -1), (1, 0), (0, 1), (-1, 0)])
    left, right = clip(diamond, CUT, keep="both")
    assert left.area == pytest.approx(1.0)
    assert right.area == pytest.approx(1.0)
    assert left.n_rings == right.n_rings == 1


def test_tilted_polygon_in_3d_with_data() -> None:
    corners = np.array([[0, 0, 0], [4, 0, 4], [4, 3, 4], [0, 3, 0]], dtype=np.float64)
    outer = corners + np.array([450_000.0, 6_700_000.0, 0.0])
    polygon = Polygon.from_rings(
        outer, point_data={"t": [0.0, 4.0, 4.0, 0.0]}, cell_data={"unit": [7]}, name="section"
    )
    kept = clip(polygon, Plane.x(450_001.0))
    assert kept.area == pytest.approx(np.sqrt(2) * 3, rel=1e-12)
    assert kept.cell_data["unit"].values.tolist() == [7]
    x = kept.vertices[:, 0] - 450_000
    assert np.allclose(kept.point_data["t"].values, x)


def test_section_of_a_polygon_is_its_chords() -> None:
    square = _polygon([(-2, -2), (2, -2), (2, 2), (-2, 2)], [(-1, -1), (-1, 1), (1, 1), (1, -1)])
    chords = section(square, CUT)
    assert chords.length == pytest.approx(2.0)
