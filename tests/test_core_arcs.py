"""geobrep.model.arcs.build_corners_and_arcs: corners and arcs rebuilt from patches."""

from __future__ import annotations

import numpy as np
import pytest

from geobrep import Scene, Surface
from geobrep.model.arcs import build_corners_and_arcs
from geobrep.model.topology import Topology


def _cyclic_equal(a: tuple[int, ...], b: tuple[int, ...]) -> bool:
    return len(a) == len(b) and any(a == b[i:] + b[:i] for i in range(len(b)))


def test_layer_cake_topology_is_rebuilt_exactly(layer_cake: Scene) -> None:
    truth = layer_cake.topology
    bare = layer_cake.replace(
        topology=Topology(patches=tuple(p.model_copy(update={"arcs": ()}) for p in truth.patches))
    )
    rebuilt = build_corners_and_arcs(bare)
    assert (len(rebuilt.corners), len(rebuilt.arcs)) == (len(truth.corners), len(truth.arcs))
    truth_points = {tuple(np.round(c.point, 6)) for c in truth.corners}
    assert {tuple(np.round(c.point, 6)) for c in rebuilt.corners} == truth_points
    by_key = {}
    for arc in truth.arcs:
        ends = (tuple(np.round(arc.points[0], 6)), tuple(np.round(arc.points[-1], 6)))
        by_key[(frozenset(ends), frozenset(arc.patches))] = arc
    for arc in rebuilt.arcs:
        first, last = tuple(np.round(arc.points[0], 6)), tuple(np.round(arc.points[-1], 6))
        ref = by_key[(frozenset((first, last)), frozenset(arc.patches))]
        same_direction = tuple(np.round(ref.points[0], 6)) == first
        points = ref.points if same_direction else ref.points[::-1]
        assert np.allclose(arc.points, points, rtol=0, atol=1e-6)
        order = ref.patches if same_direction else tuple(reversed(ref.patches))
        assert _cyclic_equal(arc.patches, order), (arc.patches, ref.patches)
        corner_points = {c.id: c.point for c in rebuilt.corners}
        assert np.array_equal(corner_points[arc.start], arc.points[0])
        assert np.array_equal(corner_points[arc.end], arc.points[-1])
    # patches list their arcs, and blocks are untouched
    for patch in rebuilt.patches:
        assert patch.arcs
        assert all(patch.id in rebuilt.arc(a).patches for a in patch.arcs)
    assert [p.positive_block for p in rebuilt.patches] == [p.positive_block for p in truth.patches]


def test_scene_without_topology_gets_one_patch_per_label(layer_cake: Scene) -> None:
    surfaces_only = Scene(entities=layer_cake.surfaces)
    rebuilt = build_corners_and_arcs(surfaces_only)
    assert len(rebuilt.patches) == 31
    assert (len(rebuilt.corners), len(rebuilt.arcs)) == (28, 52)


def _two_squares(shift: float) -> Scene:
    """Two unit squares sharing the edge x = 1 (the second one's copy moved by ``shift``)."""
    left = Surface(
        vertices=[[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]],
        faces=[[0, 1, 2], [0, 2, 3]],
        name="a",
    )
    right = Surface(
        vertices=[[1 + shift, 0, 0], [2, 0, 0], [2, 1, 0], [1 + shift, 1, 0]],
        faces=[[0, 1, 2], [0, 2, 3]],
        name="b",
    )
    return Scene(entities=[left, right])


def test_coincident_vertices_are_joined_within_the_tolerance() -> None:
    joined = build_corners_and_arcs(_two_squares(1e-13))
    # outer border of each square (1 patch) + the shared edge (2 patches)
    assert sorted(len(a.patches) for a in joined.arcs) == [1, 1, 2]
    assert len(joined.corners) == 2
    shared = next(a for a in joined.arcs if len(a.patches) == 2)
    assert np.allclose(shared.points[:, 0], 1.0)
    apart = build_corners_and_arcs(_two_squares(1e-13), tolerance=0.0)
    assert sorted(len(a.patches) for a in apart.arcs) == [1, 1]  # two closed borders
    assert all(a.start == a.end for a in apart.arcs)


def test_closed_chain_gets_one_corner_and_extra_corners_split_it() -> None:
    square = Surface(
        vertices=[[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], faces=[[0, 1, 2], [0, 2, 3]]
    )
    scene = Scene(entities=[square])
    (loop,) = build_corners_and_arcs(scene).arcs
    assert loop.start == loop.end
    assert len(loop.points) == 5
    assert np.array_equal(loop.points[0], loop.points[-1])
    moved = build_corners_and_arcs(scene, extra_corners=[[1, 1, 0]])
    assert moved.corners[0].point.tolist() == [1, 1, 0]
    assert len(moved.arcs) == 1
    split = build_corners_and_arcs(scene, extra_corners=[[1, 1, 0], [0, 0, 0]])
    assert len(split.corners) == 2
    assert len(split.arcs) == 2
    assert sorted(len(a.points) for a in split.arcs) == [3, 3]


def test_free_border_touching_another_surface_gets_a_corner() -> None:
    """A fault whose free border touches a horizon at one vertex: that vertex is a corner."""
    horizon = Surface(
        vertices=[[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0], [0, 0, 0]],
        faces=[[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]],
        name="horizon",
    )
    fault = Surface(
        vertices=[[0, 0, 0], [0.5, 0, -1], [-0.5, 0, -1]], faces=[[0, 1, 2]], name="fault"
    )
    topology = build_corners_and_arcs(Scene(entities=[horizon, fault]))
    corners = {tuple(c.point.tolist()) for c in topology.corners}
    assert (0.0, 0.0, 0.0) in corners
    assert len(topology.arcs) == 2  # the horizon's closed border, the fault's from the touch


@pytest.mark.parametrize("bad", [-1.0])
def test_negative_tolerance_is_rejected(bad: float) -> None:
    with pytest.raises(ValueError, match="tolerance"):
        build_corners_and_arcs(_two_squares(0.0), tolerance=bad)


@pytest.mark.parametrize("seed", [0, 1])
def test_touching_pairs_by_table_are_those_by_sort(seed: int) -> None:
    """The (vertex, patch) pairs of the arc vertices: marked in a table or sorted, the same."""
    from geobrep.model import arcs

    rng = np.random.default_rng(seed)
    n_vertices, n_patches = 500, 7
    ends = rng.integers(0, n_vertices, (3_000, 2))
    patch = rng.integers(0, n_patches, 3_000)
    on_arc = rng.random(n_vertices) < 0.3
    table = arcs._touching_pairs(ends, patch, on_arc, n_patches)
    keys = [ends[on_arc[ends[:, c]], c] * n_patches + patch[on_arc[ends[:, c]]] for c in (0, 1)]
    expected = np.unique(np.concatenate(keys))
    np.testing.assert_array_equal(table[0], expected // n_patches)
    np.testing.assert_array_equal(table[1], expected % n_patches)
    # a table far larger than the pairs: sorted instead, the same pairs
    wide = arcs._touching_pairs(ends[:5], patch[:5], on_arc, 100_000)
    keys = [
        ends[:5][on_arc[ends[:5, c]], c] * 100_000 + patch[:5][on_arc[ends[:5, c]]] for c in (0, 1)
    ]
    expected = np.unique(np.concatenate(keys))
    np.testing.assert_array_equal(wide[0], expected // 100_000)
    np.testing.assert_array_equal(wide[1], expected % 100_000)
