"""The builder's checks against slower independent answers: the one-pass block validation
against ``Scene.block_mesh``, the grid broad phase against every pair, and the all-edges
triangle test against the edge-by-edge one. Broken scenes must fail validation."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pytest
from blocks_models import box_model, closed_cube, vertical_fault

import geobrep
from geobrep import Scene, Surface
from geobrep.errors import TopologyError
from geobrep.plugins.blocks._arcs import chain_arcs
from geobrep.plugins.blocks._assembly import Assembly, assemble
from geobrep.plugins.blocks._broad_phase import overlapping_pairs
from geobrep.plugins.blocks._conformity import (
    _segment_distance,
    _segment_pairs_hit,
    point_triangle_distance,
    separated,
    triangles_intersect,
)
from geobrep.plugins.blocks._measures import PatchMeasures, measure_patches
from geobrep.plugins.blocks._patches import PatchSplit, split_patches
from geobrep.plugins.blocks._radial_sort import sort_arcs
from geobrep.plugins.blocks._soup import Soup, build_soup
from geobrep.plugins.blocks._traversal import traverse
from geobrep.plugins.blocks._universe import find_universe
from geobrep.plugins.blocks._validation import Validation, validate_scene


@dataclass
class Stages:
    soup: Soup
    split: PatchSplit
    measures: PatchMeasures
    assembly: Assembly

    def validate(self, scene: Scene | None = None) -> Validation:
        built = self.assembly.scene if scene is None else scene
        return validate_scene(built, self.soup, self.split, self.measures, self.assembly.vertex_ids)


def run_stages(surfaces: list[Surface]) -> Stages:
    """The builder's stages for a model without dangling patches."""
    scene = Scene(entities=surfaces)
    soup = build_soup(scene.surfaces, None, 1e-7)
    split = split_patches(soup)
    chains = chain_arcs(split, soup.vertices.shape[0])
    arcs = sort_arcs(soup.vertices, soup.triangles, split, chains, 1e-10, str)
    regions = traverse(arcs.around, split.n_patches)
    measures = measure_patches(soup, split)
    bodies = find_universe(soup, split, regions, measures)
    assert bodies.dangling.size == 0
    assembly = assemble(scene, soup, split, chains, arcs, bodies, measures)
    return Stages(soup, split, measures, assembly)


MODELS = {
    "layer cake": lambda: list(geobrep.datasets.faulted_layer_cake().surfaces),
    "dying fault": lambda: [
        *box_model(levels=(0.5,), extra_rows=(0.75,)),
        vertical_fault(0.5, [0, 0.25, 0.5, 0.75]),
    ],
    "cavity": lambda: [*box_model(), closed_cube((0.4, 0.4, 0.1), 0.2)],
}


@pytest.mark.parametrize("name", sorted(MODELS))
def test_validation_agrees_with_block_meshes(name: str) -> None:
    stages = run_stages(MODELS[name]())
    built = stages.assembly.scene
    validation = stages.validate()
    assert len(validation.checks) == len(built.blocks)
    for check, block in zip(validation.checks, built.blocks, strict=True):
        boundary = built.block_mesh(block)
        assert check.id == block.id
        assert check.closed == boundary.is_closed is True
        assert check.oriented == boundary.is_consistently_oriented is True
        assert check.triangles == boundary.n_faces
        assert check.volume == pytest.approx(boundary.volume, rel=1e-12)
    assert built.universe is not None
    shell = built.block_mesh(built.universe)
    assert validation.universe_closed is True
    assert shell.is_closed
    assert shell.is_consistently_oriented
    assert validation.volume_balance < 1e-12


def test_validation_reports_a_block_with_a_missing_side() -> None:
    stages = run_stages(MODELS["layer cake"]())
    built = stages.assembly.scene
    block = built.blocks[0]
    cut = block.replace(sides=block.sides[1:])
    broken = built.replace(entities=[cut if e.id == block.id else e for e in built.entities])
    assert not broken.block_mesh(cut).is_closed  # what the validation must see
    with pytest.raises(TopologyError, match=rf"{block.label}: closed=False"):
        stages.validate(broken)


@pytest.mark.parametrize("change", ["faces", "vertices", "labels"])
def test_validation_reports_a_surface_changed_after_the_build(change: str) -> None:
    stages = run_stages(MODELS["dying fault"]())
    built = stages.assembly.scene
    surface = built["H1"]
    assert isinstance(surface, Surface)
    if change == "faces":
        altered = surface.flipped()
    elif change == "vertices":
        vertices = surface.vertices.copy()
        vertices[0, 2] += 1e-9
        altered = surface.replace(vertices=vertices)
    else:
        assert surface.patch_labels is not None
        altered = surface.replace(patch_labels=surface.patch_labels[::-1].copy())
    broken = built.replace(entities=[altered if e.id == surface.id else e for e in built.entities])
    with pytest.raises(TopologyError, match="differs from the triangles"):
        stages.validate(broken)


def brute_force_pairs(
    corners: np.ndarray, groups: np.ndarray, margin: float
) -> set[tuple[int, int]]:
    mins, maxs = corners.min(axis=1) - margin, corners.max(axis=1) + margin
    overlap = np.all(
        (mins[:, None, :] <= maxs[None, :, :]) & (mins[None, :, :] <= maxs[:, None, :]), axis=2
    )
    i, j = np.nonzero(overlap & (groups[:, None] < groups[None, :]))
    return set(zip(i.tolist(), j.tolist(), strict=True))


@pytest.mark.parametrize("seed", range(4))
def test_broad_phase_finds_every_overlapping_pair(seed: int) -> None:
    rng = np.random.default_rng(seed)
    n = 400
    centres = rng.uniform(0.0, 10.0, size=(n, 1, 3))
    sizes = np.where(rng.uniform(size=(n, 1, 1)) < 0.05, 6.0, 0.5)  # a few large triangles
    corners = centres + sizes * rng.normal(size=(n, 3, 3))
    groups = np.sort(rng.integers(0, 5, size=n))
    margin = 0.01
    i, j = overlapping_pairs(corners, groups, margin=margin)
    found = set(zip(i.tolist(), j.tolist(), strict=True))
    assert len(found) == i.size  # each pair once
    assert all(groups[a] < groups[b] for a, b in found)
    # Pieces of bisected triangles hug them, so some box pairs are rightly left out, but every
    # pair of triangles that really meet must be there.
    assert found <= brute_force_pairs(corners, groups, margin)
    a, b = np.array(sorted(brute_force_pairs(corners, groups, margin))).T
    meeting = triangles_intersect(corners[a], corners[b], margin)
    assert set(zip(a[meeting].tolist(), b[meeting].tolist(), strict=True)) <= found


@pytest.mark.parametrize("tol", [1e-9, 1e-3, 0.2])
def test_all_edges_test_matches_the_edge_by_edge_test(tol: float) -> None:
    rng = np.random.default_rng(7)
    first = rng.normal(size=(3000, 3, 3))
    second = rng.normal(size=(3000, 3, 3)) + 0.5
    # Half the pairs lie in one plane, where the coplanar branch decides.
    first[:1500, :, 2] = 0.0
    second[:1500, :, 2] = 0.0
    fast = triangles_intersect(first, second, tol)
    slow = _segment_pairs_hit(first, second, tol)
    assert fast.any()
    assert not fast.all()
    np.testing.assert_array_equal(fast, slow)


def triangle_distances(first: np.ndarray, second: np.ndarray) -> np.ndarray:
    """Distance between triangles ``first[k]`` and ``second[k]``: 0 where they intersect, else
    the least of the corner-to-triangle and edge-to-edge distances."""
    crossing = triangles_intersect(first, second, 0.0)
    best = np.full(first.shape[0], np.inf)
    for one, other in ((first, second), (second, first)):
        for c in range(3):
            best = np.minimum(
                best, point_triangle_distance(one[:, c], other[:, 0], other[:, 1], other[:, 2])
            )
    for e in range(3):
        for f in range(3):
            best = np.minimum(
                best,
                _segment_distance(
                    first[:, e], first[:, (e + 1) % 3], second[:, f], second[:, (f + 1) % 3]
                ),
            )
    return np.where(crossing, 0.0, best)


@pytest.mark.parametrize("seed", range(3))
def test_broad_phase_keeps_large_triangles_near_what_they_meet(seed: int) -> None:
    # Long fan triangles in the wall y = 0 (as a coarse model boundary) and small triangles of
    # other surfaces around it, some touching it: the large ones are kept only in the cells
    # they come near, yet every pair closer than the margin is found.
    rng = np.random.default_rng(seed)
    apex = np.array([0.0, 0.0, 10.0])
    base = np.stack([np.linspace(-10.0, 10.0, 41), np.zeros(41), np.zeros(41)], axis=1)
    fan = np.stack([np.repeat(apex[None], 40, axis=0), base[:-1], base[1:]], axis=1)
    n = 500
    centres = rng.uniform([-10.0, -1.0, 0.0], [10.0, 1.0, 10.0], size=(n, 1, 3))
    centres[: n // 4, 0, 1] = rng.choice([-1.0, 1.0], n // 4) * 10.0 ** rng.uniform(-6, -2, n // 4)
    small = centres + 0.4 * rng.normal(size=(n, 3, 3))
    corners = np.concatenate([fan, small])
    groups = np.concatenate([np.zeros(40, np.int64), rng.integers(1, 4, size=n)])
    order = np.argsort(groups, kind="stable")
    corners, groups = corners[order], groups[order]
    margin = 1e-3
    i, j = overlapping_pairs(corners, groups, margin=margin)
    found = set(zip(i.tolist(), j.tolist(), strict=True))
    assert len(found) == i.size
    a, b = np.array(sorted(brute_force_pairs(corners, groups, margin))).T
    close = triangle_distances(corners[a], corners[b]) <= margin
    assert close[groups[a] == 0].sum() > 10  # the wall is met
    assert set(zip(a[close].tolist(), b[close].tolist(), strict=True)) <= found
    assert found <= brute_force_pairs(corners, groups, margin)


@pytest.mark.parametrize("tol", [1e-9, 1e-4, 0.05])
def test_plane_rejection_never_changes_a_decision(tol: float) -> None:
    # Slivers with sharp corners, corners placed within a few tol of the other triangle's
    # corner, and pairs in one plane: the cases where a plane-side test on the bare corners
    # would disagree with the edge tests (the edge tests call "inside" a region that reaches
    # past a sharp corner by more than tol). The rejection grows each triangle to that region.
    rng = np.random.default_rng(11)
    n = 20000
    first = rng.normal(size=(n, 3, 3))
    sliver = rng.uniform(size=n) < 0.3
    first[sliver, 2] = (
        first[sliver, 0]
        + rng.uniform(0.0, 1e-2, size=(int(sliver.sum()), 1))
        * (first[sliver, 1] - first[sliver, 0])
        + 1e-3 * rng.normal(size=(int(sliver.sum()), 3))
    )
    second = rng.normal(size=(n, 3, 3))
    near = rng.uniform(size=n) < 0.5
    shift = first[near, 0] + 3.0 * tol * rng.normal(size=(int(near.sum()), 3)) - second[near, 0]
    second[near] += shift[:, None, :]
    flat = rng.uniform(size=n) < 0.2
    first[flat, :, 2] = 0.0
    second[flat, :, 2] = 2.0 * tol * rng.normal(size=(int(flat.sum()), 1))
    apart = separated(first, second, tol)
    slow = _segment_pairs_hit(first, second, tol)
    assert 0.2 * n < apart.sum() < n - slow.sum()
    assert not (apart & slow).any()
    np.testing.assert_array_equal(triangles_intersect(first, second, tol), slow)
