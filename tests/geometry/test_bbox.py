"""Tests for geobrep.geometry.bbox."""

from __future__ import annotations

import math
import pickle

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from geobrep.errors import DegenerateGeometryError, EntityValidationError
from geobrep.geometry import BoundingBox, Plane, boxes_plane_side


def test_from_points_and_derived_quantities() -> None:
    box = BoundingBox.from_points([[1, 5, -2], [3, 2, 4], [2, 3, 0]])
    assert box.mins.tolist() == [1.0, 2.0, -2.0]
    assert box.maxs.tolist() == [3.0, 5.0, 4.0]
    assert box.center.tolist() == [2.0, 3.5, 1.0]
    assert box.size.tolist() == [2.0, 3.0, 6.0]
    assert box.diagonal == pytest.approx(7.0)
    assert box.as_tuple() == (1.0, 3.0, 2.0, 5.0, -2.0, 4.0)


def test_arrays_are_read_only_copies() -> None:
    mins = np.zeros(3)
    box = BoundingBox(mins, np.ones(3))
    mins[0] = -10.0
    assert box.mins[0] == 0.0
    with pytest.raises(ValueError, match="read-only"):
        box.maxs[0] = 5.0
    assert box.mins.dtype == np.float64


def test_equality_and_hash() -> None:
    a = BoundingBox([0, 0, 0], [1, 1, 1])
    b = BoundingBox(np.zeros(3), np.ones(3))
    assert a == b
    assert hash(a) == hash(b)
    assert a != BoundingBox([0, 0, 0], [1, 1, 2])
    assert a != "box"


def test_validation() -> None:
    with pytest.raises(DegenerateGeometryError, match="empty"):
        BoundingBox.from_points(np.zeros((0, 3)))
    with pytest.raises(EntityValidationError, match="maxs"):
        BoundingBox([0, 0, 0], [1, -1, 1])
    with pytest.raises(EntityValidationError, match="mins"):
        BoundingBox([0, 0], [1, 1, 1])
    with pytest.raises(EntityValidationError, match="mins"):
        BoundingBox([0, math.nan, 0], [1, 1, 1])


def test_union_contains_intersects() -> None:
    a = BoundingBox([0, 0, 0], [1, 1, 1])
    b = BoundingBox([2, -1, 0], [3, 0.5, 4])
    u = a.union(b)
    assert u.as_tuple() == (0.0, 3.0, -1.0, 1.0, 0.0, 4.0)
    inside = a.contains([[0.0, 0.0, 0.0], [1.0, 1.0, 1.0], [0.5, 0.5, 0.5], [1.0001, 0.5, 0.5]])
    assert inside.tolist() == [True, True, True, False]
    assert inside.dtype == np.bool_
    assert not a.intersects(b)
    assert a.intersects(BoundingBox([1, 1, 1], [2, 2, 2]))  # corner contact
    assert a.intersects(BoundingBox([0.2, 0.2, 0.2], [0.3, 0.3, 0.3]))  # nested


def test_pickle_keeps_arrays_read_only() -> None:
    box = pickle.loads(pickle.dumps(BoundingBox([0, 1, 2], [3, 4, 5])))
    assert box == BoundingBox([0, 1, 2], [3, 4, 5])
    assert not box.mins.flags.writeable


def test_expanded() -> None:
    box = BoundingBox([0, 0, 0], [2, 2, 2])
    assert box.expanded(1).as_tuple() == (-1.0, 3.0, -1.0, 3.0, -1.0, 3.0)
    assert box.expanded([0, 1, 2]).as_tuple() == (0.0, 2.0, -1.0, 3.0, -2.0, 4.0)
    assert box.expanded(-1).as_tuple() == (1.0, 1.0, 1.0, 1.0, 1.0, 1.0)
    with pytest.raises(EntityValidationError, match="margin"):
        box.expanded(-1.5)
    with pytest.raises(EntityValidationError, match="margin"):
        box.expanded([1, 2])


def test_boxes_plane_side_known_answers() -> None:
    mins = np.array([[0, 0, 0], [2, 0, 0], [-3, 0, 0], [1, 0, 0], [0.5, 0, 0]], dtype=float)
    maxs = np.array([[1, 1, 1], [3, 1, 1], [-1, 1, 1], [2, 1, 1], [0.5, 1, 1]], dtype=float)
    side = boxes_plane_side(mins, maxs, Plane.x(1))
    assert side.dtype == np.int8
    # straddles, positive, negative, touches from the positive side, flat box on negative side
    assert side.tolist() == [0, 1, -1, 0, -1]
    assert boxes_plane_side(mins, maxs, Plane.x(1), tolerance=0.6).tolist() == [0, 1, -1, 0, 0]
    assert boxes_plane_side(np.zeros((0, 3)), np.zeros((0, 3)), Plane.x(0)).shape == (0,)


def test_boxes_plane_side_oblique_plane() -> None:
    # Plane x + y = 2 (unnormalised coefficients): unit cube corner (1, 1, *) touches it.
    plane = Plane(1, 1, 0, -2)
    side = boxes_plane_side([[0.0, 0.0, 0.0], [1.5, 1.5, 0.0]], [[1, 1, 1], [2, 2, 1]], plane)
    assert side.tolist() == [0, 1]
    side = boxes_plane_side([[0, 0, 0]], [[0.9, 0.9, 1]], plane)
    assert side.tolist() == [-1]


def test_boxes_plane_side_validation() -> None:
    with pytest.raises(EntityValidationError, match="maxs"):
        boxes_plane_side(np.zeros((2, 3)), np.zeros((3, 3)), Plane.x(0))
    with pytest.raises(EntityValidationError, match="mins"):
        boxes_plane_side(np.zeros((2, 2)), np.zeros((2, 2)), Plane.x(0))


coord = st.floats(min_value=-100, max_value=100, allow_nan=False, allow_infinity=False)


@settings(max_examples=60, deadline=None)
@given(
    corners=st.lists(st.tuples(*[coord] * 6), min_size=1, max_size=15),
    normal=st.tuples(coord, coord, coord).filter(lambda v: math.hypot(*v) > 1e-2),
    offset=coord,
)
def test_boxes_plane_side_matches_corner_signs(
    corners: list[tuple[float, ...]], normal: tuple[float, float, float], offset: float
) -> None:
    arr = np.asarray(corners).reshape(-1, 2, 3)
    mins, maxs = arr.min(axis=1), arr.max(axis=1)
    plane = Plane(*normal, offset)
    side = boxes_plane_side(mins, maxs, plane)
    # Reference: signed distances of the 8 corners of every box.
    pick = np.array([[i >> 2 & 1, i >> 1 & 1, i & 1] for i in range(8)], dtype=bool)
    box_corners = np.where(pick[None, :, :], maxs[:, None, :], mins[:, None, :])
    dist = plane.signed_distance(box_corners.reshape(-1, 3)).reshape(-1, 8)
    margin = 1e-9 * (1 + np.abs(box_corners).max())
    clear_pos = dist.min(axis=1) > margin
    clear_neg = dist.max(axis=1) < -margin
    crossing = (dist.min(axis=1) < -margin) & (dist.max(axis=1) > margin)
    assert (side[clear_pos] == 1).all()
    assert (side[clear_neg] == -1).all()
    assert (side[crossing] == 0).all()
