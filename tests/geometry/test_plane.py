"""Tests for geobrep.geometry.plane."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from geobrep.errors import DegenerateGeometryError, EntityValidationError
from geobrep.geometry import Plane

finite = st.floats(min_value=-1e3, max_value=1e3, allow_nan=False, allow_infinity=False)
vector = st.tuples(finite, finite, finite)
normal_vector = vector.filter(lambda v: math.hypot(*v) > 1e-3)


def test_positional_coefficients_and_float_coercion() -> None:
    plane = Plane(1, 0, 0, -450)
    assert (plane.a, plane.b, plane.c, plane.d) == (1.0, 0.0, 0.0, -450.0)
    assert all(type(v) is float for v in (plane.a, plane.b, plane.c, plane.d))
    assert plane.coefficients.tolist() == [1.0, 0.0, 0.0, -450.0]
    assert plane.coefficients.dtype == np.float64


def test_plane_is_frozen_and_hashable() -> None:
    plane = Plane.z(3)
    with pytest.raises(dataclasses.FrozenInstanceError):
        plane.d = 0.0  # type: ignore[misc]
    assert hash(plane) == hash(Plane(0, 0, 1, -3))
    assert plane == Plane(0.0, 0.0, 1.0, -3.0)


@pytest.mark.parametrize(
    "coefficients",
    [(0, 0, 0, 1), (0.0, 0.0, 0.0, 0.0), (math.nan, 0, 1, 0), (1, 0, 0, math.inf)],
)
def test_degenerate_or_non_finite_plane_rejected(coefficients: tuple[float, ...]) -> None:
    with pytest.raises(DegenerateGeometryError):
        Plane(*coefficients)


def test_degenerate_message_names_coefficient() -> None:
    with pytest.raises(DegenerateGeometryError, match="coefficient d"):
        Plane(1, 0, 0, math.nan)


def test_axis_shortcuts_and_sides() -> None:
    px = Plane.x(450)
    assert px.side([[451, 0, 0], [449, 0, 0], [450, 7, -3]]).tolist() == [1, -1, 0]
    assert Plane.y(6_700_000).signed_distance([0, 6_700_010, 0]).tolist() == [10.0]
    assert Plane.z(-100).signed_distance([[0, 0, -150]]).tolist() == [-50.0]


def test_side_dtype_and_tolerance() -> None:
    sides = Plane.z(0).side([[0.0, 0.0, 0.5], [0.0, 0.0, -0.5], [0.0, 0.0, 2.0]], tolerance=1.0)
    assert sides.dtype == np.int8
    assert sides.tolist() == [0, 0, 1]
    with pytest.raises(EntityValidationError, match="tolerance"):
        Plane.z(0).side([0, 0, 0], tolerance=-1.0)


def test_signed_distance_is_euclidean_for_unnormalised_coefficients() -> None:
    plane = Plane(0, 3, 4, -10)  # |n| = 5; plane 3y + 4z = 10
    assert plane.signed_distance([[0, 0, 0], [0, 3, 4]]) == pytest.approx([-2.0, 3.0])
    assert plane.normal.tolist() == pytest.approx([0.0, 0.6, 0.8])
    assert plane.signed_distance(plane.point) == pytest.approx([0.0], abs=1e-12)
    assert plane.point.tolist() == pytest.approx([0.0, 1.2, 1.6])


def test_signed_distance_shape_validation() -> None:
    plane = Plane.x(0)
    with pytest.raises(EntityValidationError, match="points"):
        plane.signed_distance([1.0, 2.0])
    with pytest.raises(EntityValidationError, match="points"):
        plane.signed_distance(np.zeros((4, 2)))
    with pytest.raises(EntityValidationError, match="NaN"):
        plane.signed_distance([[0.0, math.nan, 0.0]])
    assert plane.signed_distance(np.zeros((0, 3))).shape == (0,)


def test_from_points_right_hand_normal() -> None:
    plane = Plane.from_points((0, 0, 5), (1, 0, 5), (0, 1, 5))
    assert plane.normal.tolist() == pytest.approx([0.0, 0.0, 1.0])
    assert plane.signed_distance([0, 0, 6]) == pytest.approx([1.0])
    reverse = Plane.from_points((0, 0, 5), (0, 1, 5), (1, 0, 5))
    assert reverse.normal.tolist() == pytest.approx([0.0, 0.0, -1.0])


def test_from_points_at_utm_scale() -> None:
    origin = np.array([450_000.0, 6_700_000.0, -1_500.0])
    step_u = np.array([100.0, 0.0, 0.0])
    step_v = np.array([0.0, 100.0, 50.0])
    plane = Plane.from_points(origin, origin + step_u, origin + step_v)
    probe = origin + np.array([37.0, 12.0, 6.0]) + 2.5 * plane.normal
    assert plane.signed_distance(probe)[0] == pytest.approx(2.5, abs=1e-8)


@pytest.mark.parametrize(
    "points",
    [
        ((0, 0, 0), (1, 1, 1), (2, 2, 2)),
        ((0, 0, 0), (0, 0, 0), (1, 0, 0)),
        ((5, 5, 5), (5, 5, 5), (5, 5, 5)),
    ],
)
def test_from_points_collinear_rejected(points: tuple[tuple[float, ...], ...]) -> None:
    with pytest.raises(DegenerateGeometryError, match="collinear"):
        Plane.from_points(*points)


def test_from_point_normal() -> None:
    plane = Plane.from_point_normal((1, 2, 3), (0, 0, 10))
    assert plane == Plane(0, 0, 1, -3)
    with pytest.raises(DegenerateGeometryError, match="normal"):
        Plane.from_point_normal((1, 2, 3), (0, 0, 0))
    with pytest.raises(EntityValidationError, match="point"):
        Plane.from_point_normal((1, 2), (0, 0, 1))


def test_flipped_swaps_sides() -> None:
    plane = Plane(1, 2, 3, -4)
    flipped = plane.flipped()
    pts = np.array([[5.0, 0, 0], [-5.0, 0, 0], [0, 2, 0]])
    assert flipped.side(pts).tolist() == (-plane.side(pts)).tolist()
    assert flipped.flipped() == plane
    assert Plane.x(1).flipped() == Plane(-1, 0, 0, 1)


def test_project_single_point_and_batch() -> None:
    assert Plane.z(2).project([5, 6, 7]).tolist() == [[5.0, 6.0, 2.0]]
    out = Plane.x(1).project([[3, 4, 5], [-1, 0, 0]])
    assert out.tolist() == [[1.0, 4.0, 5.0], [1.0, 0.0, 0.0]]


@settings(max_examples=60, deadline=None)
@given(
    normal=normal_vector,
    anchor=vector,
    offsets=st.lists(vector, min_size=1, max_size=20),
    shift=finite,
)
def test_random_planes_project_and_offset(
    normal: tuple[float, float, float],
    anchor: tuple[float, float, float],
    offsets: list[tuple[float, float, float]],
    shift: float,
) -> None:
    utm = np.array([450_000.0, 6_700_000.0, 0.0])
    plane = Plane.from_point_normal(utm + anchor, normal)
    points = utm + np.asarray(offsets)
    on_plane = plane.project(points)
    assert np.abs(plane.signed_distance(on_plane)).max() < 1e-6
    moved = on_plane + shift * plane.normal
    np.testing.assert_allclose(plane.signed_distance(moved), shift, atol=1e-6)
    # The projection moves a point along the normal only.
    delta = points - on_plane
    np.testing.assert_allclose(np.cross(delta, plane.normal), 0.0, atol=1e-6)
