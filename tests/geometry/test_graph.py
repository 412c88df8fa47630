"""geometry.graph: components, close pairs and path order, checked against scipy."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from geobrep.errors import TopologyError
from geobrep.geometry.graph import close_pairs, component_roots, nearest_within, path_order
from geobrep.geometry.mesh import merge_close_vertices

seeds = st.integers(min_value=0, max_value=2**32 - 1)


@given(seeds)
def test_component_roots_are_scipy_components_labelled_by_their_lowest_node(seed: int) -> None:
    rng = np.random.default_rng(seed)
    n, m = int(rng.integers(1, 400)), int(rng.integers(0, 600))
    a, b = rng.integers(0, n, m), rng.integers(0, n, m)
    graph = coo_matrix((np.ones(m), (a, b)), shape=(n, n))
    count, labels = connected_components(graph, directed=False)
    lowest = np.full(count, n)
    np.minimum.at(lowest, labels, np.arange(n))
    assert component_roots(n, a, b).tolist() == lowest[labels].tolist()


def test_a_long_path_in_reverse_order_joins_in_few_rounds() -> None:
    n = 200_000
    a = np.arange(n - 1)[::-1]
    assert (component_roots(n, a, a + 1) == 0).all()


def _cloud(rng: np.random.Generator, n: int) -> np.ndarray:
    """Points on a coarse lattice (many near neighbours) with a jitter (no exact ties)."""
    lattice = np.round(rng.uniform(0.0, 1.0, (n, 3)) * 20.0) / 20.0
    return (
        lattice
        + rng.normal(0.0, 0.01, (n, 3)) * (rng.random() < 0.5)
        + rng.normal(0.0, 1e-7, (n, 3))
    )


@given(seeds, st.sampled_from([0.005, 0.02, 0.06, 0.3]))
def test_close_pairs_and_nearest_agree_with_a_kd_tree(seed: int, distance: float) -> None:
    rng = np.random.default_rng(seed)
    points = _cloud(rng, int(rng.integers(2, 300)))
    found = close_pairs(points, distance)
    assert found is not None
    expected = np.sort(cKDTree(points).query_pairs(distance, output_type="ndarray"), axis=1)
    assert set(map(tuple, found.tolist())) == set(map(tuple, expected.tolist()))
    queries = rng.uniform(0.0, 1.0, (60, 3))
    gap, index = cKDTree(points).query(queries)
    nearest = nearest_within(points, queries, distance)
    assert nearest is not None
    assert nearest.tolist() == np.where(gap <= distance, index, -1).tolist()


def test_equal_points_pair_with_their_first_copy_at_distance_zero() -> None:
    points = [[0, 0, 0], [1, 0, 0], [0, 0, 0], [-0.0, 0, 0], [1, 0, 0]]
    assert close_pairs(points, 0.0).tolist() == [[0, 2], [0, 3], [1, 4]]
    assert nearest_within(points, [[1, 0, 0], [2, 0, 0]], 0.0).tolist() == [1, -1]


def test_a_crowd_of_close_points_is_left_to_another_search() -> None:
    crowd = 5e-4 + np.random.default_rng(1).normal(0.0, 1e-9, (1_500, 3))  # in one cube
    assert close_pairs(crowd, 1e-3) is None
    unique, inverse = merge_close_vertices(crowd, 1e-3)  # the k-d tree takes over
    assert unique.shape[0] == 1
    assert (inverse == 0).all()


@given(seeds)
def test_path_order_walks_every_path_from_its_head(seed: int) -> None:
    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 300))
    perm = rng.permutation(n)
    k = int(rng.integers(0, min(n - 1, 12) + 1))
    cuts = np.sort(rng.choice(np.arange(1, n), size=k, replace=False)) if k else []
    paths = np.split(perm, cuts)
    a = np.concatenate([p[:-1] for p in paths])
    b = np.concatenate([p[1:] for p in paths])
    swap = rng.random(a.shape[0]) < 0.5
    a, b = np.where(swap, b, a), np.where(swap, a, b)
    heads = [int(p[0] if rng.random() < 0.5 else p[-1]) for p in paths]
    expected = np.concatenate(
        [p if h == p[0] else p[::-1] for p, h in zip(paths, heads, strict=True)]
    )
    assert path_order(n, a, b, heads).tolist() == expected.tolist()


def test_path_order_refuses_loops_and_branches() -> None:
    with pytest.raises(TopologyError, match="loop"):
        path_order(4, [0, 1, 2, 3], [1, 2, 3, 0], [])
    with pytest.raises(TopologyError, match="more than two"):
        path_order(4, [0, 0, 0], [1, 2, 3], [1])
    with pytest.raises(TopologyError, match="not the end"):
        path_order(3, [0, 1], [1, 2], [1])
