"""The broad phase given the triangles' vertices leaves out exactly the pairs sharing one."""

from __future__ import annotations

import numpy as np
import pytest

import geobrep
from geobrep.plugins.blocks._broad_phase import stored_pairs
from geobrep.plugins.blocks._csr import concatenated_ranges
from geobrep.plugins.blocks._soup import build_soup


def _without_shared(triangles: np.ndarray, i: np.ndarray, j: np.ndarray) -> np.ndarray:
    return ~(triangles[i][:, :, None] == triangles[j][:, None, :]).any(axis=(1, 2))


@pytest.mark.parametrize("factor", [1.0, 3.0, 1e4])
def test_layer_cake_pairs_sharing_a_vertex_left_out_in_order(factor: float) -> None:
    soup = build_soup(geobrep.datasets.faulted_layer_cake().surfaces, None, 1e-7)
    margin = factor * soup.tolerance
    i, j = stored_pairs(soup.corners, soup.triangle_surface, margin=margin)
    apart = _without_shared(soup.triangles, i, j)
    assert 0 < apart.sum() < apart.size  # both kinds are there
    fi, fj = stored_pairs(
        soup.corners, soup.triangle_surface, margin=margin, triangles=soup.triangles
    )
    np.testing.assert_array_equal(fi, i[apart])
    np.testing.assert_array_equal(fj, j[apart])


def test_random_soup_with_shared_vertices() -> None:
    rng = np.random.default_rng(5)
    points = rng.random((60, 3))
    triangles = rng.integers(0, 60, (400, 3))
    groups = rng.integers(0, 4, 400)
    stored = np.ascontiguousarray(points[triangles].transpose(1, 2, 0))
    i, j = stored_pairs(stored, groups, margin=0.01)
    apart = _without_shared(triangles, i, j)
    assert 0 < apart.sum() < apart.size
    fi, fj = stored_pairs(stored, groups, margin=0.01, triangles=triangles)
    np.testing.assert_array_equal(fi, i[apart])
    np.testing.assert_array_equal(fj, j[apart])


def test_concatenated_ranges() -> None:
    starts, counts = np.array([5, 0, 7, 2]), np.array([2, 3, 0, 1])
    expected = np.concatenate([np.arange(s, s + c) for s, c in zip(starts, counts, strict=True)])
    np.testing.assert_array_equal(concatenated_ranges(starts, counts), expected)
    assert concatenated_ranges(starts[:0], counts[:0]).size == 0
