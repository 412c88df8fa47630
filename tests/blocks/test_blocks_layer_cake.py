"""Rebuilding the faulted layer cake from its bare surfaces gives back its exact topology."""

from __future__ import annotations

import numpy as np
import pytest

import geobrep
from geobrep import Block, Scene, Surface
from geobrep.ops.building import build_blocks
from geobrep.plugins.blocks.report import block_report

SignedSet = frozenset[tuple[tuple[int, int], int]]


def signed_sets(scene: Scene) -> dict[SignedSet, Block]:
    """Each block (universe included) keyed by its set of ((surface id, label), side)."""
    key = {p.id: (p.surface, p.label) for p in scene.patches}
    return {frozenset((key[s.patch], s.side) for s in b.sides): b for b in scene.of_type(Block)}


def rebuild(truth: Scene) -> Scene:
    return build_blocks(Scene(entities=truth.surfaces, crs=truth.crs))


def matching(truth: Scene, built: Scene) -> dict[int, int]:
    expected, found = signed_sets(truth), signed_sets(built)
    assert expected.keys() == found.keys()
    return {int(expected[k].id or 0): int(found[k].id or 0) for k in expected}


@pytest.fixture(scope="module")
def cake() -> Scene:
    return geobrep.datasets.faulted_layer_cake()


@pytest.fixture(scope="module")
def rebuilt(cake: Scene) -> Scene:
    return rebuild(cake)


def test_same_blocks_with_the_same_signed_patch_sets(cake: Scene, rebuilt: Scene) -> None:
    match = matching(cake, rebuilt)
    assert len(rebuilt.blocks) == 6
    assert len(match) == 7
    universe = rebuilt.universe
    assert universe is not None
    assert cake.universe is not None
    assert match[int(cake.universe.id or 0)] == universe.id


def test_patches_are_the_truth_patches(cake: Scene, rebuilt: Scene) -> None:
    match = matching(cake, rebuilt)
    truth = {(p.surface, p.label): p for p in cake.patches}
    built = {(p.surface, p.label): p for p in rebuilt.patches}
    assert truth.keys() == built.keys()
    for key, patch in truth.items():
        other = built[key]
        assert match[patch.positive_block or 0] == other.positive_block
        assert match[patch.negative_block or 0] == other.negative_block
        before, after = cake[key[0]], rebuilt[key[0]]
        assert isinstance(before, Surface)
        assert isinstance(after, Surface)
        assert np.array_equal(before.patch_faces(key[1]), after.patch_faces(key[1]))


def test_arcs_have_the_truth_right_hand_order(cake: Scene, rebuilt: Scene) -> None:
    def by_ends(scene: Scene) -> dict[tuple[bytes, bytes], list[tuple[int, int]]]:
        key = {p.id: (p.surface, p.label) for p in scene.patches}
        return {
            (a.points[0].tobytes(), a.points[-1].tobytes()): [key[p] for p in a.patches]
            for a in scene.topology.arcs
        }

    truth, built = by_ends(cake), by_ends(rebuilt)
    assert len(built) == len(truth) == 52
    assert len(rebuilt.topology.corners) == len(cake.topology.corners) == 28
    for (start, end), order in truth.items():
        found = built.get((start, end))
        if found is None:  # built the other way round: the cyclic order reverses
            found = built[(end, start)][::-1]
        assert len(found) == len(order)
        shift = found.index(order[0])
        assert found[shift:] + found[:shift] == order


def test_volumes_match_the_truth_to_1e9(cake: Scene, rebuilt: Scene) -> None:
    match = matching(cake, rebuilt)
    for block in cake.blocks:
        want = cake.block_mesh(block).volume
        got = rebuilt.block_mesh(match[int(block.id or 0)]).volume
        assert abs(got - want) <= 1e-9 * want


def test_adjacency_matches_the_truth(cake: Scene, rebuilt: Scene) -> None:
    match = matching(cake, rebuilt)
    renamed = sorted(tuple(sorted((match[a], match[b]))) for a, b in cake.block_adjacency())
    assert rebuilt.block_adjacency() == renamed


def test_report_and_attributes(cake: Scene, rebuilt: Scene) -> None:
    report = block_report(rebuilt)
    arcs = rebuilt.topology.arcs
    assert report.direction_triangles == sum(len(a.patches) for a in arcs) == 132
    assert report.triangles == sum(s.n_faces for s in cake.surfaces)
    assert report.merged_vertices > 0  # surfaces store their own copies of shared vertices
    match = {v: k for k, v in matching(cake, rebuilt).items()}
    for block in rebuilt.blocks:
        layer = cake[match[int(block.id or 0)]].metadata["layer"]
        tops = [] if layer == 1 else [f"H{layer - 1}"]
        bases = [] if layer == 3 else [f"H{layer}"]
        assert block.metadata["top_horizons"] == tops
        assert block.metadata["base_horizons"] == bases
        assert block.metadata["faults"] == ["fault"]


def test_coordinates_are_kept_bit_for_bit(cake: Scene, rebuilt: Scene) -> None:
    for surface in cake.surfaces:
        again = rebuilt[surface.name]
        assert isinstance(again, Surface)
        assert np.array_equal(again.vertices, surface.vertices)
        assert np.array_equal(again.faces, surface.faces)


@pytest.mark.parametrize(("n_horizons", "resolution"), [(0, 100.0), (1, 60.0), (3, 80.0)])
def test_other_layer_counts(n_horizons: int, resolution: float) -> None:
    truth = geobrep.datasets.faulted_layer_cake(n_horizons=n_horizons, resolution=resolution)
    built = rebuild(truth)
    assert len(built.blocks) == 2 * (n_horizons + 1)
    matching(truth, built)


# -- the unfolded cake: blocks are prisms whose volumes and contacts are known exactly ----------
WIDTH, HEIGHT, LENGTH, THROW = 1000.0, 600.0, 800.0, 80.0
DIP, FAULT_TOP, FAULT_SLOPE = -0.05, 550.0, 0.3


def _section_polygons(n_horizons: int) -> dict[tuple[str, int], list[tuple[float, float]]]:
    """Cross-section polygons (x, z) of every block, from the construction's lines."""
    spacing = HEIGHT / (n_horizons + 1)
    levels = [-spacing * (i + 1) + 0.25 * spacing for i in range(n_horizons)]

    def on_fault(a: float, slope: float) -> tuple[float, float]:
        # Line z = a + slope·x meets the fault x = FAULT_TOP + FAULT_SLOPE·z.
        z = (a + slope * FAULT_TOP) / (1.0 - slope * FAULT_SLOPE)
        return FAULT_TOP + FAULT_SLOPE * z, z

    polygons = {}
    for side, shift in (("footwall", 0.0), ("hanging wall", THROW)):
        lines = [(0.0, 0.0)] + [(c - shift, DIP) for c in levels] + [(-HEIGHT, 0.0)]
        for layer in range(1, n_horizons + 2):
            (a_top, s_top), (a_bottom, s_bottom) = lines[layer - 1], lines[layer]
            top_fault, bottom_fault = on_fault(a_top, s_top), on_fault(a_bottom, s_bottom)
            wall = 0.0 if side == "footwall" else WIDTH
            polygons[(side, layer)] = [
                (wall, a_top + s_top * wall),
                top_fault,
                bottom_fault,
                (wall, a_bottom + s_bottom * wall),
            ]
    return polygons


def _area(points: list[tuple[float, float]]) -> float:
    x, z = np.array(points).T
    return 0.5 * abs(float(np.dot(x, np.roll(z, -1)) - np.dot(np.roll(x, -1), z)))


@pytest.mark.parametrize("n_horizons", [1, 2])
def test_unfolded_cake_volumes_and_contacts_are_exact(n_horizons: int) -> None:
    truth = geobrep.datasets.faulted_layer_cake(
        n_horizons=n_horizons, resolution=100.0, fold_amplitude=0.0
    )
    built = rebuild(truth)
    match = {v: k for k, v in matching(truth, built).items()}
    polygons = _section_polygons(n_horizons)
    assert sum(_area(p) for p in polygons.values()) == pytest.approx(WIDTH * HEIGHT, rel=1e-12)
    label = {}
    for block in built.blocks:
        origin = truth[match[int(block.id or 0)]].metadata
        key = (str(origin["fault_side"]), int(str(origin["layer"])))
        label[block.id] = key
        expected = _area(polygons[key]) * LENGTH
        assert abs(block.metadata["volume"] - expected) <= 1e-9 * expected
        assert abs(built.block_mesh(block).volume - expected) <= 1e-9 * expected
    # Contacts: layers touch their neighbours on the same side, and across the fault wherever
    # their stretches of the fault overlap.
    expected_pairs = set()
    for layer in range(1, n_horizons + 1):
        for side in ("footwall", "hanging wall"):
            expected_pairs.add(frozenset({(side, layer), (side, layer + 1)}))
    for i in range(1, n_horizons + 2):
        for j in range(1, n_horizons + 2):
            foot, hang = polygons[("footwall", i)], polygons[("hanging wall", j)]
            low = max(foot[2][1], hang[2][1])  # the stretches [bottom, top] along the fault
            high = min(foot[1][1], hang[1][1])
            if high - low > 1e-9:
                expected_pairs.add(frozenset({("footwall", i), ("hanging wall", j)}))
    found = {frozenset({label[a], label[b]}) for a, b in built.block_adjacency()}
    assert found == expected_pairs
