"""The conformity search's free border without the patch split (:func:`free_border`, what
inspection uses) against the one from the split (what the builder uses): the same edges, points
and owners, so the same crossings, T-junctions and gaps, on non-conformal models and real data."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest
from blocks_models import box_model, grid_surface, vertical_fault

import geobrep
from geobrep import Surface
from geobrep.plugins.blocks._conformity import _border, find_defects, free_border
from geobrep.plugins.blocks._patches import split_patches
from geobrep.plugins.blocks._soup import build_soup

DATA = Path(__file__).resolve().parents[1] / "data" / "gocad"


def _horizontal(name: str, z: float, low: float = 0.0, high: float = 1.0) -> Surface:
    side = np.linspace(low, high, 5)
    xs, ys = np.meshgrid(side, side, indexing="ij")
    return grid_surface(np.stack([xs, ys, np.full_like(xs, z)], axis=-1), name, "horizon")


def _models() -> dict[str, list[Surface]]:
    models = {
        "T-junctions": [*box_model(levels=()), _horizontal("H", 0.6)],
        "crossing": [*box_model(levels=(0.5,)), vertical_fault(0.6, [0, 0.2, 0.4, 0.6, 0.8, 1])],
        "gap": [*box_model(levels=(), extra_rows=(0.5,)), _horizontal("H", 0.5, 0.001, 0.999)],
        "open box": [s for s in box_model(levels=(0.5,)) if s.name != "top"],
    }
    for path in sorted(DATA.glob("*.ml")):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            models[path.name] = list(geobrep.read(path, repair=False).surfaces)
    return models


MODELS = _models()


@pytest.mark.parametrize("name", sorted(MODELS))
def test_free_border_is_the_split_border(name: str) -> None:
    soup = build_soup(tuple(MODELS[name]), None, 1e-7)
    split = split_patches(soup)
    mine, theirs = free_border(soup), _border(soup, split)
    for a, b in zip(mine, theirs, strict=True):
        assert np.array_equal(a, b)
    # The border is what it says: edges one triangle uses, each vertex owned by a surface.
    counts = np.diff(split.offsets)
    assert mine[0].shape[0] == int((counts == 1).sum())
    assert (mine[2][mine[1]] >= 0).all()
    gap = 1e-3 * soup.diagonal
    assert find_defects(soup, None, gap) == find_defects(soup, split, gap)


def test_the_models_have_borders_and_defects() -> None:
    # Not vacuous: free borders and every kind of defect occur in the models above.
    kinds: set[str] = set()
    bordered = 0
    for surfaces in MODELS.values():
        soup = build_soup(tuple(surfaces), None, 1e-7)
        bordered += free_border(soup)[0].shape[0] > 0
        kinds |= {d.kind for d in find_defects(soup, None, 1e-3 * soup.diagonal)}
    assert kinds == {"crossing", "T-junction", "gap"}
    assert bordered >= 4
