"""The broad phase lists a large triangle's cells only in blocks where another group may be:
the same pairs as listing every cell of its box."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

import geobrep
from geobrep.plugins.blocks import _broad_phase
from geobrep.plugins.blocks._broad_phase import overlapping_pairs, stored_pairs
from geobrep.plugins.blocks._soup import build_soup

Pairs = set[tuple[int, int]]


def both_ways(
    monkeypatch: pytest.MonkeyPatch, run: Callable[[], tuple[np.ndarray, np.ndarray]]
) -> tuple[Pairs, Pairs]:
    found = []
    for threshold in (10**9, 0):  # every cell of the boxes; through the blocks
        monkeypatch.setattr(_broad_phase, "_BLOCKS_OVER", threshold)
        i, j = run()
        assert np.unique(i * (int(j.max(initial=0)) + 1) + j).size == i.size  # each pair once
        found.append(set(zip(i.tolist(), j.tolist(), strict=True)))
    return found[0], found[1]


@pytest.mark.parametrize("seed", range(4))
def test_fans_and_small_triangles(monkeypatch: pytest.MonkeyPatch, seed: int) -> None:
    rng = np.random.default_rng(seed)
    apex = np.array([0.0, 0.0, 10.0])
    base = np.stack([np.linspace(-10.0, 10.0, 41), np.zeros(41), np.zeros(41)], axis=1)
    fan = np.stack([np.repeat(apex[None], 40, axis=0), base[:-1], base[1:]], axis=1)
    tilted = fan @ np.array([[1.0, 0.0, 0.0], [0.0, 0.8, 0.6], [0.0, -0.6, 0.8]]) + [0, 3, 0]
    n = 600
    centres = rng.uniform([-10.0, -2.0, 0.0], [10.0, 4.0, 10.0], size=(n, 1, 3))
    small = centres + 0.3 * rng.normal(size=(n, 3, 3))
    corners = np.concatenate([fan, tilted, small])
    groups = np.concatenate([np.zeros(40), np.ones(40), rng.integers(2, 5, size=n)]).astype(int)
    order = np.argsort(groups, kind="stable")
    corners, groups = corners[order], groups[order]
    for margin in (1e-3, 0.2):
        direct, blocked = both_ways(
            monkeypatch, lambda m=margin: overlapping_pairs(corners, groups, m)
        )
        assert direct == blocked
        assert any(groups[a] == 0 and groups[b] == 1 for a, b in direct)  # the fans cross


def test_layer_cake_walls(monkeypatch: pytest.MonkeyPatch) -> None:
    # The south and north walls are fans of long triangles; horizons and the fault meet them.
    model = geobrep.datasets.faulted_layer_cake(resolution=20.0)
    soup = build_soup(model.surfaces, None, None)
    for margin in (soup.tolerance, 1e-3 * soup.diagonal):
        direct, blocked = both_ways(
            monkeypatch, lambda m=margin: stored_pairs(soup.corners, soup.triangle_surface, m)
        )
        assert direct == blocked
        assert len(direct) > 1000


def test_spread_box_two_cells_past_its_first(monkeypatch: pytest.MonkeyPatch) -> None:
    # Boxes longer than a cell but not large reach cells two past their first, beyond the
    # 3 x 3 x 3 around it: a large triangle's block holding only such a cell still pairs them
    # (a random soup where blocks wanted only for the boxes' first cells miss a pair).
    rng = np.random.default_rng(11)
    n = int(rng.integers(2, 3000))
    centres = rng.uniform(0, 10, (n, 1, 3))
    big = rng.random((n, 1, 1)) < 0.05
    scale = np.where(big, rng.uniform(2, 8, (n, 1, 1)), rng.uniform(0.05, 0.6, (n, 1, 1)))
    corners = centres + scale * rng.normal(size=(n, 3, 3))
    groups = np.sort(rng.integers(0, int(rng.integers(2, 12)), n))
    direct, blocked = both_ways(
        monkeypatch, lambda: overlapping_pairs(corners, groups, 0.1, cell=0.3)
    )
    assert (224, 375) in direct
    assert direct == blocked


@pytest.mark.parametrize("seed", range(3))
def test_spread_boxes_far_from_other_groups(monkeypatch: pytest.MonkeyPatch, seed: int) -> None:
    # Groups in bands along x: spread boxes inside a band, two blocks away from any other
    # group, are left out of the blocks path (their cells are never mixed); the pairs are
    # those of listing every cell.
    rng = np.random.default_rng(seed)
    n = 3000
    centres = rng.uniform(0, 20, (n, 1, 3)) * [5.0, 1.0, 1.0]
    r = rng.random((n, 1, 1))
    scale = np.where(r < 0.03, 6.0, np.where(r < 0.3, 1.5, 0.25))
    corners = centres + scale * rng.normal(size=(n, 3, 3))
    groups = np.clip((centres[:, 0, 0] / 100.0 * 4).astype(int), 0, 3)
    order = np.argsort(groups, kind="stable")
    corners, groups = corners[order], groups[order]
    left_out = []
    not_alone = _broad_phase._not_alone

    def spy(*args: object) -> np.ndarray:
        kept = not_alone(*args)  # type: ignore[arg-type]
        left_out.append(int(args[-1]) - kept.size)  # type: ignore[call-overload]
        return kept

    monkeypatch.setattr(_broad_phase, "_not_alone", spy)
    for margin in (1e-3, 0.5):
        direct, blocked = both_ways(
            monkeypatch, lambda m=margin: overlapping_pairs(corners, groups, m)
        )
        assert direct == blocked
        assert any(groups[a] != groups[b] for a, b in direct)
    assert sum(left_out) > 0
