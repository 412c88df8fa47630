"""geobrep.geometry.spatial_index: brute-force references, threads, pickling, empty index."""

from __future__ import annotations

import math
import pickle
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.typing import NDArray

from geobrep.errors import EntityValidationError
from geobrep.geometry import BoundingBox, Plane
from geobrep.geometry.spatial_index import SpatialIndex

UTM = np.array([450_000.0, 6_700_000.0, 0.0])


def _random_boxes(
    rng: np.random.Generator, k: int, span: float = 100.0, size: float = 10.0
) -> tuple[NDArray[np.int64], NDArray[np.float64], NDArray[np.float64]]:
    mins = UTM + rng.uniform(0.0, span, (k, 3))
    maxs = mins + rng.uniform(0.0, size, (k, 3))
    ids = rng.permutation(10 * k)[:k].astype(np.int64) - 3 * k  # unique, some negative
    return ids, mins, maxs


def _brute_intersection(
    ids: NDArray[np.int64],
    mins: NDArray[np.float64],
    maxs: NDArray[np.float64],
    qmin: NDArray[np.float64],
    qmax: NDArray[np.float64],
) -> NDArray[np.int64]:
    hit = ((mins <= qmax) & (qmin <= maxs)).all(axis=1)
    return np.sort(ids[hit])


def _brute_nearest(
    ids: NDArray[np.int64],
    mins: NDArray[np.float64],
    maxs: NDArray[np.float64],
    points: NDArray[np.float64],
    k: int,
) -> NDArray[np.int64]:
    gap = np.maximum(np.maximum(mins[None] - points[:, None], points[:, None] - maxs[None]), 0.0)
    dist2 = (gap**2).sum(axis=2)  # (Q, K)
    out = np.empty((points.shape[0], k), dtype=np.int64)
    for q in range(points.shape[0]):
        order = np.lexsort((ids, dist2[q]))
        out[q] = ids[order[:k]]
    return out


@pytest.fixture(scope="module")
def boxes() -> tuple[NDArray[np.int64], NDArray[np.float64], NDArray[np.float64]]:
    return _random_boxes(np.random.default_rng(42), 500)


def test_known_answers() -> None:
    index = SpatialIndex(
        [10, 20, 30], [[0, 0, 0], [2, 0, 0], [0, 5, 0]], [[1, 1, 1], [3, 1, 1], [1, 6, 1]]
    )
    assert len(index) == 3
    assert index.intersection([1, 0, 0], [2, 1, 1]).tolist() == [10, 20]  # touching faces
    assert index.intersection([1.5, 0, 0], [1.6, 1, 1]).tolist() == []
    assert index.intersection([-9, -9, -9], [9, 9, 9]).dtype == np.int64
    assert index.nearest([[2.5, 0.5, 0.5], [0.5, 4, 0.5]]).tolist() == [[20], [30]]
    assert index.nearest([[0.5, 3.0, 0.5]], k=3).tolist() == [[10, 30, 20]]
    bounds = index.bounds
    assert bounds == BoundingBox([0, 0, 0], [3, 6, 1])
    assert "3 boxes" in repr(index)


def test_arrays_are_read_only_copies() -> None:
    ids = np.array([1, 2])
    mins = np.zeros((2, 3))
    maxs = np.ones((2, 3))
    index = SpatialIndex(ids, mins, maxs)
    mins[0] = 5.0
    ids[0] = 9
    assert index.mins[0].tolist() == [0.0, 0.0, 0.0]
    assert index.ids.tolist() == [1, 2]
    assert index.ids.dtype == np.int64
    for arr in (index.ids, index.mins, index.maxs):
        assert not arr.flags.writeable


@pytest.mark.parametrize(
    ("ids", "mins", "maxs", "field"),
    [
        ([1, 1], np.zeros((2, 3)), np.ones((2, 3)), "ids"),
        ([1.0, 2.0], np.zeros((2, 3)), np.ones((2, 3)), "ids"),
        ([[1, 2]], np.zeros((2, 3)), np.ones((2, 3)), "ids"),
        ([1, 2], np.zeros((3, 3)), np.ones((2, 3)), "mins"),
        ([1, 2], np.zeros((2, 2)), np.ones((2, 2)), "mins"),
        ([1, 2], np.zeros((2, 3)), np.full((2, 3), math.nan), "maxs"),
        ([1, 2], np.zeros((2, 3)), -np.ones((2, 3)), "maxs"),
    ],
)
def test_validation_names_the_field(ids: object, mins: object, maxs: object, field: str) -> None:
    with pytest.raises(EntityValidationError) as info:
        SpatialIndex(ids, mins, maxs)  # type: ignore[arg-type]
    assert info.value.entity == "SpatialIndex"
    assert info.value.field == field


def test_query_validation() -> None:
    index = SpatialIndex([1], [[0, 0, 0]], [[1, 1, 1]])
    with pytest.raises(EntityValidationError, match="maxs"):
        index.intersection([1, 1, 1], [0, 0, 0])
    with pytest.raises(EntityValidationError, match="mins"):
        index.intersection([1, 1], [2, 2, 2])
    with pytest.raises(EntityValidationError, match="k"):
        index.nearest([[0, 0, 0]], k=2)
    with pytest.raises(EntityValidationError, match="k"):
        index.nearest([[0, 0, 0]], k=0)
    with pytest.raises(EntityValidationError, match="points"):
        index.nearest([0, 0, 0])


def test_empty_index() -> None:
    index = SpatialIndex(np.zeros(0, dtype=np.int64), np.zeros((0, 3)), np.zeros((0, 3)))
    assert len(index) == 0
    assert index.bounds is None
    assert index.intersection([0, 0, 0], [1, 1, 1]).shape == (0,)
    query, hits = index.intersection_batch(np.zeros((3, 3)), np.ones((3, 3)))
    assert query.shape == hits.shape == (0,)
    assert index.plane_side(Plane.x(0)).shape == (0,)
    assert index.straddling(Plane.x(0)).shape == (0,)
    with pytest.raises(EntityValidationError, match="k"):
        index.nearest([[0, 0, 0]])
    clone = pickle.loads(pickle.dumps(index))
    assert len(clone) == 0
    assert "empty" in repr(clone)


@settings(max_examples=60, deadline=None)
@given(
    cells=st.lists(st.tuples(*[st.integers(0, 8)] * 3, *[st.integers(0, 3)] * 3), max_size=30),
    queries=st.lists(
        st.tuples(*[st.integers(-1, 9)] * 3, *[st.integers(0, 4)] * 3), min_size=1, max_size=10
    ),
)
def test_intersection_matches_brute_force(
    cells: list[tuple[int, ...]], queries: list[tuple[int, ...]]
) -> None:
    # Integer coordinates make touching boxes common: closed-box semantics are exercised.
    arr = np.asarray(cells, dtype=np.float64).reshape(-1, 6)
    mins = UTM + arr[:, :3]
    maxs = mins + arr[:, 3:]
    ids = np.arange(arr.shape[0], dtype=np.int64) * 7 - 20
    index = SpatialIndex(ids, mins, maxs)
    q = np.asarray(queries, dtype=np.float64)
    qmins = UTM + q[:, :3]
    qmaxs = qmins + q[:, 3:]
    query_index, hit_ids = index.intersection_batch(qmins, qmaxs)
    for i in range(q.shape[0]):
        expected = _brute_intersection(ids, mins, maxs, qmins[i], qmaxs[i])
        np.testing.assert_array_equal(index.intersection(qmins[i], qmaxs[i]), expected)
        np.testing.assert_array_equal(hit_ids[query_index == i], expected)
    assert (np.diff(query_index) >= 0).all()


def test_batch_matches_single(
    boxes: tuple[NDArray[np.int64], NDArray[np.float64], NDArray[np.float64]],
) -> None:
    ids, mins, maxs = boxes
    index = SpatialIndex(ids, mins, maxs)
    rng = np.random.default_rng(1)
    qmins = UTM + rng.uniform(-10, 110, (50, 3))
    qmaxs = qmins + rng.uniform(0, 30, (50, 3))
    query_index, hit_ids = index.intersection_batch(qmins, qmaxs)
    assert hit_ids.size > 50  # the queries do hit things
    for i in range(50):
        single = index.intersection(qmins[i], qmaxs[i])
        np.testing.assert_array_equal(hit_ids[query_index == i], single)
        np.testing.assert_array_equal(
            single, _brute_intersection(ids, mins, maxs, qmins[i], qmaxs[i])
        )


@pytest.mark.parametrize("k", [1, 3, 10])
def test_nearest_matches_brute_force(
    boxes: tuple[NDArray[np.int64], NDArray[np.float64], NDArray[np.float64]], k: int
) -> None:
    ids, mins, maxs = boxes
    index = SpatialIndex(ids, mins, maxs)
    rng = np.random.default_rng(k)
    points = UTM + rng.uniform(-20, 120, (200, 3))
    result = index.nearest(points, k=k)
    assert result.shape == (200, k)
    assert result.dtype == np.int64
    np.testing.assert_array_equal(result, _brute_nearest(ids, mins, maxs, points, k))


@settings(max_examples=60, deadline=None)
@given(
    cells=st.lists(
        st.tuples(*[st.integers(0, 5)] * 3, *[st.integers(0, 2)] * 3), min_size=1, max_size=20
    ),
    points=st.lists(st.tuples(*[st.integers(-2, 8)] * 3), min_size=1, max_size=8),
    k=st.integers(1, 20),
)
def test_nearest_ties_are_deterministic(
    cells: list[tuple[int, ...]], points: list[tuple[int, ...]], k: int
) -> None:
    # Integer boxes and points: many exact ties (including duplicates and distance 0).
    arr = np.asarray(cells, dtype=np.float64)
    mins = arr[:, :3]
    maxs = mins + arr[:, 3:]
    ids = np.arange(arr.shape[0], dtype=np.int64)[::-1].copy()
    k = min(k, arr.shape[0])
    index = SpatialIndex(ids, mins, maxs)
    pts = np.asarray(points, dtype=np.float64)
    np.testing.assert_array_equal(index.nearest(pts, k=k), _brute_nearest(ids, mins, maxs, pts, k))


def test_queries_whose_hits_outgrow_the_first_result_buffer() -> None:
    # rtree's batch calls start with room for 2 hits per query and grow the buffer when more
    # come back; rtree 1.4.1's own growth step fails under numpy < 2 (a float size). 2,000
    # overlapping boxes at UTM scale: every query below hits hundreds to thousands of them.
    rng = np.random.default_rng(20)
    ids, mins, maxs = _random_boxes(rng, 2000, span=20.0, size=60.0)
    index = SpatialIndex(ids, mins, maxs)
    centre = UTM + 30.0
    single = index.intersection(centre - 1.0, centre + 1.0)
    np.testing.assert_array_equal(
        single, _brute_intersection(ids, mins, maxs, centre - 1.0, centre + 1.0)
    )
    assert single.size > 200
    qmins = UTM + rng.uniform(10.0, 40.0, (40, 3))
    qmaxs = qmins + rng.uniform(0.0, 5.0, (40, 3))
    query_index, hit_ids = index.intersection_batch(qmins, qmaxs)
    counts = np.bincount(query_index, minlength=40)
    assert counts.min() > 2
    assert hit_ids.size > 100 * 40  # far past the first buffer
    for i in range(40):
        np.testing.assert_array_equal(
            hit_ids[query_index == i], _brute_intersection(ids, mins, maxs, qmins[i], qmaxs[i])
        )
    # nearest keeps every tie: a point inside many boxes has them all at distance 0
    points = np.array([centre, centre + 2.0, UTM + 1000.0])
    np.testing.assert_array_equal(
        index.nearest(points, k=3), _brute_nearest(ids, mins, maxs, points, 3)
    )


def test_plane_side_and_straddling(
    boxes: tuple[NDArray[np.int64], NDArray[np.float64], NDArray[np.float64]],
) -> None:
    ids, mins, maxs = boxes
    index = SpatialIndex(ids, mins, maxs)
    plane = Plane.x(UTM[0] + 50.0)
    side = index.plane_side(plane)
    assert side.dtype == np.int8
    np.testing.assert_array_equal(side == 1, mins[:, 0] > UTM[0] + 50.0)
    np.testing.assert_array_equal(side == -1, maxs[:, 0] < UTM[0] + 50.0)
    crossing = index.straddling(plane)
    np.testing.assert_array_equal(crossing, np.sort(ids[side == 0]))
    assert 0 < crossing.size < len(index)
    # An oblique plane: straddling boxes have corners on both sides (or on the plane).
    oblique = Plane.from_point_normal(UTM + 50.0, (1.0, 2.0, -0.5))
    rows = np.isin(ids, index.straddling(oblique))
    corners = np.stack([mins, maxs], axis=1)
    pick = np.array([[i >> 2 & 1, i >> 1 & 1, i & 1] for i in range(8)])
    all_corners = corners[:, pick, [0, 1, 2]]  # (K, 8, 3)
    dist = oblique.signed_distance(all_corners.reshape(-1, 3)).reshape(-1, 8)
    np.testing.assert_array_equal(rows, (dist.min(axis=1) <= 0) & (dist.max(axis=1) >= 0))


def test_pickle_round_trip(
    boxes: tuple[NDArray[np.int64], NDArray[np.float64], NDArray[np.float64]],
) -> None:
    ids, mins, maxs = boxes
    index = SpatialIndex(ids, mins, maxs)
    clone = pickle.loads(pickle.dumps(index))
    assert len(clone) == len(index)
    np.testing.assert_array_equal(clone.ids, index.ids)
    points = UTM + np.random.default_rng(3).uniform(0, 100, (30, 3))
    np.testing.assert_array_equal(clone.nearest(points, k=4), index.nearest(points, k=4))
    qmax = points + 5.0
    for got, want in zip(
        clone.intersection_batch(points, qmax), index.intersection_batch(points, qmax), strict=True
    ):
        np.testing.assert_array_equal(got, want)
    assert clone.intersection_batch(points, qmax)[1].size > 0


def test_concurrent_queries_from_four_threads(
    boxes: tuple[NDArray[np.int64], NDArray[np.float64], NDArray[np.float64]],
) -> None:
    ids, mins, maxs = boxes
    index = SpatialIndex(ids, mins, maxs)
    rng = np.random.default_rng(7)
    qmins = UTM + rng.uniform(-10, 110, (40, 3))
    qmaxs = qmins + rng.uniform(0, 20, (40, 3))

    def run(_: int) -> list[NDArray[np.int64]]:
        out: list[NDArray[np.int64]] = []
        for _repeat in range(10):
            out.extend(index.intersection_batch(qmins, qmaxs))
            out.append(index.nearest(qmins, k=3))
            out.append(index.intersection(qmins[0], qmaxs[0]))
        return out

    expected = run(0)
    with ThreadPoolExecutor(max_workers=4) as pool:
        results = list(pool.map(run, range(8)))
    for result in results:
        assert len(result) == len(expected)
        for got, want in zip(result, expected, strict=True):
            np.testing.assert_array_equal(got, want)
