"""The linear octree's structure: sorted without sorting, no overlaps, maximal merged parents."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import pytest
import voxel_bodies as vb
from shapes import winding_numbers

from geobrep import LinearOctree, Surface
from geobrep.geometry.morton import morton_decode, morton_encode
from geobrep.ops.voxelization import voxelize
from geobrep.plugins.voxelize._classify import PriorityClassifier
from geobrep.plugins.voxelize._depth_buffers import DepthBufferClassifier, depth_buffers
from geobrep.plugins.voxelize._emission import Leaves, emit_leaves
from geobrep.plugins.voxelize._merge import merge_full_siblings
from geobrep.plugins.voxelize._parity import ExactClassifier
from geobrep.plugins.voxelize._rasterize import ray_crossings

DEPTH = 5


def centres(tree: LinearOctree) -> np.ndarray:
    """Centres of all finest cells of the tree's cube, indexed like ``np.indices`` (i, j, k)."""
    n = 1 << tree.depth
    g = (np.arange(n) + 0.5) * (tree.size / n)
    grid = np.stack(np.meshgrid(g, g, g, indexing="ij"), axis=-1).reshape(-1, 3)
    return grid + tree.origin


def inside_truth(name: str, surface: Surface, points: np.ndarray) -> np.ndarray:
    """Point containment independent of geobrep: analytic where certain, else winding numbers."""
    if name == "fold":
        inside, certain = vb.c_shape_inside(points)
    elif name == "sphere":
        inside, certain = vb.convex_inside(surface, np.zeros(3), points)
    else:  # the shell: inside the outer sphere and outside the cavity
        outer = vb.ellipsoid((1.0, 1.0, 1.0), rings=24, segments=48)
        cavity = vb.ellipsoid((0.55, 0.55, 0.55), rings=16, segments=32)
        in_outer, sure_outer = vb.convex_inside(outer, np.zeros(3), points)
        in_cavity, sure_cavity = vb.convex_inside(cavity, np.zeros(3), points)
        inside = in_outer & ~in_cavity
        certain = (sure_outer & ~in_outer) | (sure_outer & sure_cavity)
    doubt = np.flatnonzero(~certain)
    inside = inside.copy()
    if doubt.size:
        chunks = [
            winding_numbers(points[doubt[i : i + 256]], surface.vertices, surface.faces)
            for i in range(0, doubt.size, 256)
        ]
        inside[doubt] = np.abs(np.concatenate(chunks)) > 0.5
    return inside


def finest_cells(tree: LinearOctree) -> np.ndarray:
    """Every finest cell covered by a leaf, as Morton codes (with repeats if leaves overlap)."""
    return np.concatenate(
        [np.arange(c, c + s, dtype=np.uint64) for c, s in zip(tree.codes, tree.spans, strict=True)]
    )


BODIES: dict[str, Callable[[], Surface]] = {
    "sphere": lambda: vb.ellipsoid((1.0, 1.0, 1.0), rings=24, segments=48),
    "fold": vb.c_shape,
    "shell": vb.hollow_sphere,
}


@pytest.fixture(scope="module", params=sorted(BODIES))
def case(request: pytest.FixtureRequest) -> tuple[Surface, LinearOctree, np.ndarray]:
    surface = BODIES[request.param]()
    tree = voxelize(surface, depth=DEPTH, method="exact")
    n = 1 << DEPTH
    truth = inside_truth(request.param, surface, centres(tree)).reshape(n, n, n)
    return surface, tree, truth


def test_codes_strictly_increasing_and_aligned(case: tuple[Any, LinearOctree, Any]) -> None:
    _, tree, _ = case
    assert tree.codes.dtype == np.uint64
    assert np.all(np.diff(tree.codes.astype(np.int64)) > 0)
    assert np.all(tree.codes % tree.spans == 0)


def test_no_two_leaves_overlap(case: tuple[Any, LinearOctree, Any]) -> None:
    _, tree, _ = case
    cells = finest_cells(tree)
    assert cells.size == np.unique(cells).size
    assert np.all(tree.codes[1:] >= tree.codes[:-1] + tree.spans[:-1])


def test_leaves_are_exactly_the_inside_voxels(case: tuple[Any, LinearOctree, Any]) -> None:
    _, tree, truth = case
    n = 1 << DEPTH
    dense = np.zeros((n, n, n), dtype=bool)
    i, j, k = morton_decode(finest_cells(tree))
    dense[i, j, k] = True
    assert np.array_equal(dense, truth)


def test_merged_parents_only_where_all_children_full(case: tuple[Any, LinearOctree, Any]) -> None:
    _, tree, truth = case
    # Every leaf above the finest level is full: all its voxels are inside ...
    cells, edges = tree.leaf_cells()
    for (i, j, k), edge in zip(cells, edges, strict=True):
        assert truth[i : i + edge, j : j + edge, k : k + edge].all()
    # ... and every full octant whose parent is not full is exactly one leaf (maximal merging).
    full = truth
    leaf_set = set(zip(tree.codes.tolist(), tree.levels.tolist(), strict=True))
    for level in range(DEPTH, 0, -1):
        side = full.shape[0] // 2
        parent_full = full.reshape(side, 2, side, 2, side, 2).all(axis=(1, 3, 5))
        parent_of_cell = np.repeat(np.repeat(np.repeat(parent_full, 2, 0), 2, 1), 2, 2)
        i, j, k = np.nonzero(full & ~parent_of_cell)
        shift = DEPTH - level
        codes = morton_encode(i << shift, j << shift, k << shift)
        assert all((int(c), level) in leaf_set for c in codes)
        full = parent_full
    assert not any(level == 0 for _, level in leaf_set) or full.all()


def test_depth_buffer_leaves_are_already_maximal() -> None:
    sphere = vb.ellipsoid((1.0, 1.0, 1.0), rings=24, segments=48)
    tree = voxelize(sphere, depth=6, method="depth-buffer")
    leaves = Leaves(tree.codes, tree.levels, np.zeros(tree.n_leaves, dtype=np.int64))
    merged = merge_full_siblings(leaves, tree.depth)
    np.testing.assert_array_equal(merged.codes, tree.codes)  # nothing left to merge
    assert tree.leaf_count_per_level()[:2].sum() == 0
    assert tree.leaf_count_per_level()[3] > 0  # but large octants were emitted whole


def _grid(surface: Surface, depth: int) -> np.ndarray:
    lo = surface.vertices.min(axis=0)
    size = float((surface.vertices.max(axis=0) - lo).max())
    return (surface.vertices - lo) / (size / (1 << depth))


def test_emission_never_sorts(monkeypatch: pytest.MonkeyPatch) -> None:
    fold = vb.c_shape()
    depth = 6
    grid = _grid(fold, depth)
    crossings = [ray_crossings(grid, fold.faces, axis, 1 << depth) for axis in range(3)]
    classifiers = [
        DepthBufferClassifier([depth_buffers(c) for c in crossings], depth),
        ExactClassifier(crossings[2], depth),
    ]

    def forbidden(*args: object, **kwargs: object) -> None:
        raise AssertionError("the emission must not sort")

    for name in ("sort", "argsort", "lexsort", "unique", "partition", "argpartition"):
        monkeypatch.setattr(np, name, forbidden)
    for classifier in classifiers:
        leaves = emit_leaves(PriorityClassifier([classifier], depth))
        merged = merge_full_siblings(leaves, depth)
        assert leaves.codes.size > 100
        assert np.all(leaves.codes[1:] > leaves.codes[:-1])
        assert np.all(merged.codes[1:] > merged.codes[:-1])
    monkeypatch.undo()
    LinearOctree(codes=leaves.codes, levels=leaves.levels, depth=depth, origin=[0, 0, 0], size=1)


def test_block_by_block_equals_whole_cube() -> None:
    fold = vb.c_shape()
    whole = voxelize(fold, depth=6, method="exact", block_depth=0)
    for block_depth in (1, 2):
        pieces = voxelize(fold, depth=6, method="exact", block_depth=block_depth)
        np.testing.assert_array_equal(pieces.codes, whole.codes)
        np.testing.assert_array_equal(pieces.levels, whole.levels)
    sphere = vb.ellipsoid((1.0, 1.0, 1.0), rings=24, segments=48)
    np.testing.assert_array_equal(
        voxelize(sphere, depth=6, method="depth-buffer", block_depth=2).codes,
        voxelize(sphere, depth=6, method="depth-buffer").codes,
    )


def test_merge_full_siblings_rules() -> None:
    codes = np.arange(16, dtype=np.uint64)
    levels = np.full(16, 2, dtype=np.uint8)
    bodies = np.zeros(16, dtype=np.int64)
    bodies[12] = 1  # the second group of 8 holds another body: it must stay split
    merged = merge_full_siblings(Leaves(codes, levels, bodies), depth=2)
    assert merged.codes.tolist() == [0, *range(8, 16)]
    assert merged.levels.tolist() == [1] + [2] * 8
    seven = merge_full_siblings(Leaves(codes[:7], levels[:7], bodies[:7]), depth=2)
    assert seven.codes.tolist() == list(range(7))  # 7 of 8 children: no parent
    # merging cascades: 8 parents that became full merge again
    everything = Leaves(
        np.arange(64, dtype=np.uint64), np.full(64, 2, np.uint8), np.zeros(64, np.int64)
    )
    root = merge_full_siblings(everything, depth=2)
    assert root.codes.tolist() == [0]
    assert root.levels.tolist() == [0]
