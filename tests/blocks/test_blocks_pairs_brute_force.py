"""The broad phase and the crossing search against brute force on random soups: every pair of
boxes that overlap (no triangle large enough to be kept only in the cells it comes near), and
the same crossings and T-junctions whichever candidate pairs the search starts from."""

from __future__ import annotations

import numpy as np
import pytest
from blocks_models import grid_surface

from geobrep.plugins.blocks._broad_phase import component_major, overlapping_pairs, stored_pairs
from geobrep.plugins.blocks._conformity import _crossings
from geobrep.plugins.blocks._soup import Soup, build_soup

Pairs = set[tuple[int, int]]


def box_pairs(corners: np.ndarray, groups: np.ndarray, margin: float) -> Pairs:
    """Every pair (i, j), groups[i] < groups[j], whose boxes grown by ``margin`` overlap."""
    mins, maxs = corners.min(axis=1) - margin, corners.max(axis=1) + margin
    overlap = np.all(
        (mins[:, None, :] <= maxs[None, :, :]) & (mins[None, :, :] <= maxs[:, None, :]), axis=2
    )
    i, j = np.nonzero(overlap & (groups[:, None] < groups[None, :]))
    return set(zip(i.tolist(), j.tolist(), strict=True))


@pytest.mark.parametrize("seed", range(5))
@pytest.mark.parametrize("margin", [0.0, 1e-3, 0.05])
def test_every_overlapping_box_pair_once(seed: int, margin: float) -> None:
    rng = np.random.default_rng(seed)
    n = 1500
    # One triangle shape, scaled by 0.8-1.2 and turned about z: extents within 1.5 times each
    # other, so no triangle counts as large and the pairs are exactly the box pairs.
    shape = np.array([[0.0, 0.0, 0.0], [0.1, 0.0, 0.02], [0.03, 0.08, -0.02]])
    angle = rng.uniform(0.0, 2.0 * np.pi, n)
    cos, sin = np.cos(angle)[:, None], np.sin(angle)[:, None]
    turned = np.stack(
        [cos * shape[:, 0] - sin * shape[:, 1], sin * shape[:, 0] + cos * shape[:, 1]], axis=-1
    )
    corners = np.concatenate([turned, np.broadcast_to(shape[:, 2], (n, 3))[..., None]], axis=2)
    corners = corners * rng.uniform(0.8, 1.2, (n, 1, 1)) + rng.uniform(0.0, 1.0, (n, 1, 3))
    # Groups in runs, as the soup's surfaces come, and interleaved.
    groups = np.sort(rng.integers(0, 6, n)) if seed % 2 else rng.integers(0, 6, n)
    i, j = overlapping_pairs(corners, groups, margin)
    found = set(zip(i.tolist(), j.tolist(), strict=True))
    assert len(found) == i.size  # each pair once
    expected = box_pairs(corners, groups, margin)
    assert len(expected) > 500
    assert found == expected


def crossing_soup(seed: int) -> Soup:
    """Wavy horizons that cross each other, and a wall sharing a row of vertices (and edges)
    with the first: pairs that share vertices, T-junctions and crossings."""
    rng = np.random.default_rng(seed)
    side = np.linspace(0.0, 1.0, 13)
    xs, ys = np.meshgrid(side, side, indexing="ij")
    surfaces = []
    for k in range(4):
        tilt = rng.uniform(-0.3, 0.3, 2)
        wave = 0.05 * np.sin(rng.uniform(3.0, 9.0) * xs + rng.uniform(0.0, 6.0))
        zs = 0.5 + tilt[0] * (xs - 0.5) + tilt[1] * (ys - 0.5) + wave
        surfaces.append(grid_surface(np.stack([xs, ys, zs], axis=-1), f"H{k}"))
    first = surfaces[0].vertices.reshape(13, 13, 3)
    row = first[6]  # x = 0.5 across y
    heights = np.linspace(0.0, 0.4, 5)[:, None]
    wall = np.stack(
        [
            np.broadcast_to(row[:, 0], (5, 13)),
            np.broadcast_to(row[:, 1], (5, 13)),
            row[:, 2] + heights,
        ],
        axis=-1,
    )
    surfaces.append(grid_surface(wall, "wall"))
    return build_soup(tuple(surfaces), 1e-9, None)


def defects(found: list) -> set[tuple[tuple[int, int], str, float]]:
    return {(d.triangles, d.kind, d.distance) for d in found}


@pytest.mark.parametrize("seed", range(4))
def test_crossings_whichever_pairs_they_start_from(seed: int) -> None:
    soup = crossing_soup(seed)
    tol = soup.tolerance
    own = defects(_crossings(soup, tol))
    assert own
    corners = np.transpose(soup.corners, (2, 0, 1))
    for margin in (tol, 0.01, 0.1):
        # Every box pair at a wider margin, sorted as find_defects passes its own.
        pairs = box_pairs(corners, soup.triangle_surface, margin)
        i, j = np.array(sorted(pairs), dtype=np.int64).reshape(-1, 2).T
        assert defects(_crossings(soup, tol, (i, j))) == own
        i, j = stored_pairs(soup.corners, soup.triangle_surface, margin)
        order = np.lexsort((j, i))
        assert defects(_crossings(soup, tol, (i[order], j[order]))) == own


def test_component_major_gathers_the_corners() -> None:
    rng = np.random.default_rng(3)
    vertices = rng.normal(size=(500, 3))
    triangles = rng.integers(0, 500, size=(2000, 3))
    stored = component_major(np.ascontiguousarray(vertices.T), triangles)
    assert stored.shape == (3, 3, 2000)
    assert np.array_equal(stored, np.transpose(vertices[triangles], (1, 2, 0)))


@pytest.mark.parametrize(
    "shape", [(1, 1, 1), (1, 1, 2), (2, 3, 1), (3, 1, 5), (2, 2, 2), (4, 5, 3), (7, 6, 9)]
)
@pytest.mark.parametrize("op", ["minimum", "maximum"])
def test_grid_dilation_is_the_3x3x3_filter(shape: tuple[int, int, int], op: str) -> None:
    """The broad phase's dilation (the last axis in one pass over the flattened cells, the row
    ends fixed) is scipy's 3 x 3 x 3 minimum / maximum filter: a cell at the grid's edge takes
    the cells there are ("nearest" repeats one of them)."""
    from scipy import ndimage

    from geobrep.plugins.blocks._broad_phase import _dilated

    rng = np.random.default_rng(sum(shape))
    values = rng.integers(-1000, 1000, size=shape).astype(np.int64)
    function = np.minimum if op == "minimum" else np.maximum
    reference = (ndimage.minimum_filter if op == "minimum" else ndimage.maximum_filter)(
        values, size=3, mode="nearest"
    )
    dilated = _dilated(values, function)
    np.testing.assert_array_equal(dilated, reference)
    np.testing.assert_array_equal(_dilated(values.astype(np.float64), function), reference)
