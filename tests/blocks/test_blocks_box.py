"""Blocks of boxes split by horizontal horizons: answers known by hand."""

from __future__ import annotations

import numpy as np
import pytest
from blocks_models import box_model, grid_surface
from hypothesis import given
from hypothesis import strategies as st

from geobrep import Block, Scene, Surface
from geobrep.ops.building import build_blocks
from geobrep.plugins.blocks.report import block_report

UTM = (450_000.0, 6_700_000.0, -250.0)


def build(surfaces: list[Surface], **options: object) -> Scene:
    return build_blocks(Scene(entities=surfaces), **options)


def test_box_split_by_one_horizon() -> None:
    built = build(box_model(levels=(0.5,)))
    upper, lower = built.blocks
    universe = built.universe
    assert universe is not None
    assert universe.kind == "universe"
    assert [b.unit_name for b in built.blocks] == ["above H1", "below H1"]
    for block in (upper, lower):
        boundary = built.block_mesh(block)
        assert boundary.is_closed
        assert boundary.is_consistently_oriented
        assert boundary.volume == pytest.approx(0.5, rel=1e-12)
        assert block.metadata["volume"] == pytest.approx(0.5, rel=1e-12)
    (horizon_patch,) = [p for p in built.patches if p.surface == built["H1"].id]
    # H1's normal points up: the upper block is on its positive side.
    assert (horizon_patch.positive_block, horizon_patch.negative_block) == (upper.id, lower.id)
    for patch in built.patches:
        if patch.surface != built["H1"].id:  # walls point out of the model, into the universe
            assert patch.positive_block == universe.id
    assert built.block_adjacency() == [(upper.id, lower.id)]
    assert upper.metadata["base_horizons"] == ["H1"]
    assert upper.metadata["top_horizons"] == []


def test_counts_and_direction_triangles() -> None:
    built = build(box_model(levels=(0.5,)))
    report = block_report(built)
    # Walls are cut in two by H1; top, bottom and H1 stay whole.
    assert report.patches == len(built.patches) == 11
    # 8 horizontal box edges, 4 vertical ones cut at H1, 4 contacts of H1 with the walls.
    assert report.arcs == len(built.topology.arcs) == 20
    assert report.corners == len(built.topology.corners) == 12
    valences = sorted(len(arc.patches) for arc in built.topology.arcs)
    assert valences == [2] * 16 + [3] * 4
    assert report.direction_triangles == sum(valences) == 44
    assert report.sorted_share == pytest.approx(44 / report.triangles)
    assert report.internal_patches == []
    assert report.dangling == []
    assert report.validated
    assert all(c.closed and c.oriented for c in report.checks)
    assert report.volume_balance is not None
    assert report.volume_balance < 1e-12
    assert set(report.stage_seconds) >= {"soup", "patches", "arcs", "sort", "traversal"}


def test_arcs_run_between_their_corners_in_right_hand_order() -> None:
    built = build(box_model(levels=(0.5,)))
    topology = built.topology
    for arc in topology.arcs:
        assert arc.start is not None
        assert arc.end is not None
        start = topology.corner(arc.start).point
        end = topology.corner(arc.end).point
        assert np.array_equal(arc.points[0], start)
        assert np.array_equal(arc.points[-1], end)
    # Along the contact of H1 with the west wall, thumb along +y: a right-hand turn about +y
    # takes +z to +x to −z, so the wall above (leaving along +z), H1 (along +x, into the box)
    # and the wall below (along −z) follow each other in that cyclic order.
    west = built["west"].id
    h1 = built["H1"].id
    for arc in topology.arcs:
        if len(arc.patches) != 3:
            continue
        points = arc.points
        if not (np.allclose(points[:, 0], 0.0) and np.allclose(points[:, 2], 0.5)):
            continue
        direction = np.sign(points[-1, 1] - points[0, 1])
        kinds = []
        for pid in arc.patches:
            patch = topology.patch(pid)
            if patch.surface == h1:
                kinds.append("H1")
            else:
                assert patch.surface == west
                faces = built[west].faces[built[west].patch_labels == patch.label]
                z = built[west].vertices[faces].mean(axis=(0, 1))[2]
                kinds.append("above" if z > 0.5 else "below")
        expected = ["above", "H1", "below"] if direction > 0 else ["below", "H1", "above"]
        start = kinds.index(expected[0])
        assert kinds[start:] + kinds[:start] == expected


def test_utm_coordinates_keep_full_precision() -> None:
    surfaces = box_model(levels=(400.0, 250.0), n=4, size=1000.0, origin=UTM)
    built = build(surfaces)
    thickness = sorted(b.metadata["volume"] / 1e6 for b in built.blocks)
    assert thickness == pytest.approx([150.0, 250.0, 600.0], rel=1e-12)
    for original in surfaces:
        rebuilt = built[original.name]
        assert isinstance(rebuilt, Surface)
        assert np.array_equal(rebuilt.vertices, original.vertices)  # bit for bit
        assert np.array_equal(rebuilt.faces, original.faces)


def test_quads_are_split_and_properties_follow() -> None:
    surfaces = box_model(levels=(0.5,))
    horizon = surfaces[-1]
    quads = horizon.faces.reshape(2, -1, 3)  # (a, b, c) then (a, c, d) for each grid cell
    quad_faces = np.concatenate([quads[0], quads[1][:, 2:]], axis=1)
    labelled = Surface(
        vertices=horizon.vertices,
        faces=quad_faces,
        name="H1",
        kind="horizon",
        point_data={"depth": -horizon.vertices[:, 2]},
        cell_data={"cell": np.arange(quad_faces.shape[0])},
    )
    built = build([*surfaces[:-1], labelled])
    rebuilt = built["H1"]
    assert isinstance(rebuilt, Surface)
    assert rebuilt.faces.shape == (2 * quad_faces.shape[0], 3)
    assert np.array_equal(np.asarray(rebuilt.cell_data["cell"]), np.repeat(np.arange(16), 2))
    assert np.array_equal(np.asarray(rebuilt.point_data["depth"]), -rebuilt.vertices[:, 2])
    assert sorted(b.metadata["volume"] for b in built.blocks) == pytest.approx([0.5, 0.5])


def test_an_existing_topology_is_replaced(layer_cake: Scene) -> None:
    built = build_blocks(layer_cake)
    every_block = built.of_type(Block)
    assert len(every_block) == 7
    assert len(built.blocks) == 6
    (group,) = [g for g in built.groups if g.name == "blocks"]
    assert set(group.members) == {b.id for b in every_block}
    assert block_report(built).patches == len(built.patches) == 31


def test_surfaces_option_builds_from_a_subset() -> None:
    surfaces = box_model(levels=(0.5,))
    side = np.linspace(3.0, 4.0, 3)
    aside = grid_surface(
        np.stack([*np.meshgrid(side, side, indexing="ij"), np.full((3, 3), 9.0)], axis=-1),
        "elsewhere",
    )
    scene = Scene(entities=[*surfaces, aside])
    built = build_blocks(scene, surfaces=tuple(s.name for s in surfaces))
    assert len(built.blocks) == 2
    assert built["elsewhere"] == scene["elsewhere"]  # untouched, not a dangling removal
    assert block_report(built).dangling == []


@given(
    gaps=st.lists(st.integers(min_value=1, max_value=6), min_size=1, max_size=4),
    shift=st.tuples(*[st.floats(-1e6, 1e6, allow_nan=False)] * 3),
)
def test_layered_boxes_have_one_block_per_layer(gaps: list[int], shift: tuple[float, ...]) -> None:
    edges = np.cumsum(gaps)
    levels = tuple((edges / (edges[-1] + 1.0)).tolist())
    surfaces = box_model(levels=levels, n=2, origin=shift)
    built = build(surfaces)
    assert len(built.blocks) == len(levels) + 1
    # Layer thicknesses from the stored heights (a far origin rounds the levels themselves).
    heights = {s.name: float(s.vertices[0, 2]) for s in surfaces}
    bounds = sorted(
        [heights["bottom"], heights["top"]] + [heights[f"H{k}"] for k in range(1, len(levels) + 1)]
    )
    expected = sorted(np.diff(bounds).tolist())
    volumes = sorted(b.metadata["volume"] for b in built.blocks)
    assert volumes == pytest.approx(expected, rel=1e-9, abs=1e-12)
    assert len(built.block_adjacency()) == len(levels)
