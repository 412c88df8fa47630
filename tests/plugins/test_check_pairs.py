"""The self-intersection broad phase finds exactly the triangle pairs whose boxes overlap."""

from __future__ import annotations

import numpy as np
import pytest

from geobrep.plugins.checks._pairs import near_pairs


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_near_pairs_equal_brute_force_box_overlaps(seed: int) -> None:
    rng = np.random.default_rng(seed)
    n = 400
    centres = rng.random((n, 1, 3)) * 10.0
    sizes = np.exp(rng.normal(0.0, 1.0, (n, 1, 1)))  # radii over two orders of magnitude
    corners = centres + rng.normal(size=(n, 3, 3)) * sizes
    margin = 0.05
    i, j = near_pairs(corners, margin)
    found = {(min(a, b), max(a, b)) for a, b in zip(i.tolist(), j.tolist(), strict=True)}
    assert len(found) == i.size  # each pair once
    low, high = corners.min(axis=1) - margin, corners.max(axis=1) + margin
    overlap = np.all((low[:, None] <= high[None]) & (low[None] <= high[:, None]), axis=2)
    a, b = np.nonzero(np.triu(overlap, k=1))
    assert found == set(zip(a.tolist(), b.tolist(), strict=True))
