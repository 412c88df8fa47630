"""Patches are numbered by their first triangle, whichever order the component labels come in."""

from __future__ import annotations

import numpy as np
import pytest

from geobrep.plugins.blocks._patches import _by_first_triangle


def reference(labels: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    _, first = np.unique(labels, return_index=True)
    order = np.argsort(first, kind="stable")
    rank = np.empty(order.shape[0], dtype=np.int64)
    rank[order] = np.arange(order.shape[0])
    return rank[labels], first[order]


@pytest.mark.parametrize("seed", range(6))
def test_renumbering_matches_a_sort_by_first_triangle(seed: int) -> None:
    rng = np.random.default_rng(seed)
    n_labels = int(rng.integers(1, 40))
    labels = rng.integers(0, n_labels, size=300)
    labels = np.unique(labels, return_inverse=True)[1].astype(np.int64)  # every label used
    if seed % 2:  # already in first-appearance order: the fast path
        labels = reference(labels)[0]
    renumbered, first = _by_first_triangle(labels, int(labels.max()) + 1)
    expected, expected_first = reference(labels)
    np.testing.assert_array_equal(renumbered, expected)
    np.testing.assert_array_equal(first, expected_first)
    assert renumbered[first].tolist() == list(range(first.shape[0]))


def test_out_of_order_labels_are_renumbered() -> None:
    renumbered, first = _by_first_triangle(np.array([2, 2, 0, 1, 0]), 3)
    assert renumbered.tolist() == [0, 0, 1, 2, 1]
    assert first.tolist() == [0, 2, 3]
