"""Clipping scenes: the layer cake's blocks stay closed, volumes add up, topology is carried."""

from __future__ import annotations

import numpy as np
import pytest

from geobrep import Block, Plane, Scene, Surface
from geobrep.geometry import mesh
from geobrep.model.arcs import build_corners_and_arcs
from geobrep.ops.clipping import clip, clip_box, section

PLANES = [
    Plane.x(450_512.3),
    Plane.from_point_normal((450_420.0, 6_700_390.0, -210.0), (0.6, 0.35, 0.2)),
    Plane.z(-155.5),
]


def _volume(scene: Scene, block: int) -> float:
    return scene.block_mesh(block).volume if block in scene else 0.0


@pytest.fixture(scope="module")
def halves(layer_cake: Scene) -> dict[int, tuple[Scene, Scene]]:
    return {i: clip(layer_cake, plane, keep="both") for i, plane in enumerate(PLANES)}


@pytest.mark.parametrize("which", range(len(PLANES)))
def test_block_volumes_are_conserved_and_halves_closed(
    layer_cake: Scene, halves: dict[int, tuple[Scene, Scene]], which: int
) -> None:
    negative, positive = halves[which]
    for block in layer_cake.blocks:
        ident = int(block.id or 0)
        original = layer_cake.block_mesh(block).volume
        assert _volume(negative, ident) + _volume(positive, ident) == pytest.approx(
            original, rel=1e-9
        )
        for half in (negative, positive):
            if ident in half:
                boundary = half.block_mesh(ident)
                assert boundary.is_closed
                assert boundary.is_consistently_oriented
                assert boundary.volume > 0
    for half in (negative, positive):
        total = sum(half.block_mesh(b).volume for b in half.blocks)
        assert half.universe is not None
        shell = -half.block_mesh(half.universe).volume
        assert total == pytest.approx(shell, rel=1e-9)


def test_ids_attributes_and_untouched_entities(
    layer_cake: Scene, halves: dict[int, tuple[Scene, Scene]]
) -> None:
    negative, positive = halves[0]
    for half in (negative, positive):
        for block in half.blocks:
            original = layer_cake[int(block.id or 0)]
            assert isinstance(original, Block)
            assert (block.name, block.unit_name, block.kind) == (
                original.name,
                original.unit_name,
                original.kind,
            )
        assert half.crs == layer_cake.crs
    # The plane x = 450512.3 misses the east wall: the west half drops it, the east keeps it as is.
    east = layer_cake["east"]
    assert int(east.id or 0) not in negative
    assert positive[int(east.id or 0)] is east
    assert positive["H1"].name == "H1"
    assert positive["H1"].kind == "horizon"


def test_caps_are_patches_between_block_and_universe(
    layer_cake: Scene, halves: dict[int, tuple[Scene, Scene]]
) -> None:
    negative, positive = halves[0]
    caps = [s for s in negative.surfaces if s.kind == "cap"]
    assert len(caps) == 1
    cap = caps[0]
    cap_patches = [p for p in negative.patches if p.surface == cap.id]
    cut_blocks = {b.id for b in negative.blocks} & {b.id for b in positive.blocks}
    assert {p.negative_block for p in cap_patches} == cut_blocks
    universe = negative.universe
    assert universe is not None
    for patch in cap_patches:
        assert patch.positive_block == universe.id
        assert (patch.id, -1) in negative[int(patch.negative_block or 0)].sides
        assert (patch.id, 1) in universe.sides
    # Neighbouring blocks' caps share their edges: shared edges are interior to the cap surface.
    edges, offsets, faces, _ = mesh.edge_face_incidence(cap.faces)
    counts = np.diff(offsets)
    labels = np.asarray(cap.patch_labels)
    shared = [
        e
        for e in range(edges.shape[0])
        if counts[e] == 2 and len(set(labels[faces[offsets[e] : offsets[e + 1]]])) == 2
    ]
    assert len(shared) > 0
    assert all(x in (1, 2) for x in counts)
    assert np.allclose(cap.vertices[:, 0], 450_512.3)  # the caps lie on the plane


def test_topology_of_halves_is_valid(halves: dict[int, tuple[Scene, Scene]]) -> None:
    for negative, positive in halves.values():
        for half in (negative, positive):
            Scene(**{name: getattr(half, name) for name in Scene.model_fields})  # revalidates
            present = {p.id for p in half.patches}
            for arc in half.topology.arcs:
                assert set(arc.patches) <= present
                for corner, end in ((arc.start, arc.points[0]), (arc.end, arc.points[-1])):
                    if corner is not None:
                        assert np.array_equal(half.topology.corner(corner).point, end)
            assert half.block_adjacency()


def test_arcs_are_cut_at_the_plane(
    layer_cake: Scene, halves: dict[int, tuple[Scene, Scene]]
) -> None:
    negative, positive = halves[0]

    def length(arcs: object) -> float:
        return sum(
            float(np.linalg.norm(np.diff(a.points, axis=0), axis=1).sum())
            for a in arcs  # type: ignore[attr-defined]
        )

    def in_plane(arc: object) -> bool:
        return bool((np.abs(arc.points[:, 0] - 450_512.3) <= 1e-6).all())  # type: ignore[attr-defined]

    # the model's arcs, split at the plane; the caps' borders are new arcs lying in it
    kept = [a for half in (negative, positive) for a in half.topology.arcs if not in_plane(a)]
    assert length(kept) == pytest.approx(length(layer_cake.topology.arcs), rel=1e-12)
    assert any(in_plane(a) for a in negative.topology.arcs)
    for arc in negative.topology.arcs:
        assert (arc.points[:, 0] <= 450_512.3 + 1e-9).all()
    for half in (negative, positive):  # the one rule, as if the half had been read
        rebuilt = build_corners_and_arcs(half)
        assert len(rebuilt.arcs) == len(half.topology.arcs)
        assert len(rebuilt.corners) == len(half.topology.corners)


def test_plane_on_a_wall_keeps_the_model(layer_cake: Scene) -> None:
    west_x = layer_cake.bounds.mins[0]
    negative, positive = clip(layer_cake, Plane.x(west_x), keep="both")
    assert negative.blocks == ()
    assert {b.id for b in positive.blocks} == {b.id for b in layer_cake.blocks}
    for block in layer_cake.blocks:
        assert positive.block_mesh(block.id).volume == pytest.approx(
            layer_cake.block_mesh(block).volume, rel=1e-12
        )
    assert not [s for s in positive.surfaces if s.kind == "cap"]


def test_clip_box_to_the_model_bounds_changes_nothing(layer_cake: Scene) -> None:
    inside = clip_box(layer_cake, layer_cake.bounds)
    assert len(inside.patches) == len(layer_cake.patches)
    for block in layer_cake.blocks:
        assert inside.block_mesh(block.id).volume == pytest.approx(
            layer_cake.block_mesh(block).volume, rel=1e-12
        )


def test_clip_box_carves_a_closed_column(layer_cake: Scene) -> None:
    box = (450_230.0, 450_610.5, 6_700_150.0, 6_700_520.0, -700.0, 100.0)
    column = clip_box(layer_cake, box)
    total = 0.0
    for block in column.blocks:
        boundary = column.block_mesh(block)
        assert boundary.is_closed
        assert boundary.is_consistently_oriented
        total += boundary.volume
    # Walls are vertical: the column's volume is its footprint times the model's mean thickness.
    lo, hi = column.bounds.mins, column.bounds.maxs
    assert np.allclose([lo[0], hi[0], lo[1], hi[1]], box[:4])
    shell = -column.block_mesh(column.universe).volume
    assert total == pytest.approx(shell, rel=1e-9)


def test_section_polygons_match_the_caps(
    layer_cake: Scene, halves: dict[int, tuple[Scene, Scene]]
) -> None:
    plane = PLANES[0]
    panel = section(layer_cake, plane)
    negative, _ = halves[0]
    cap = next(s for s in negative.surfaces if s.kind == "cap")
    areas = {
        int(cap.metadata["blocks"][label]): float(cap.face_areas[cap.patch_labels == label].sum())
        for label in range(cap.n_patches)
    }
    polygons = [e for e in panel.entities if e.kind == "section"]
    assert len(polygons) == len(areas)
    for polygon in polygons:
        block = layer_cake[int(polygon.metadata["block"])]
        assert polygon.name == block.name
        assert polygon.metadata["unit_name"] == block.unit_name
        assert polygon.area == pytest.approx(areas[int(polygon.metadata["block"])], rel=1e-9)
    traces = [e for e in panel.entities if e.kind != "section"]
    assert {t.name for t in traces} >= {"H1", "H2", "fault"}
    assert [g.name for g in panel.groups] == ["sections", "traces"]


def test_a_surface_without_blocks_in_a_scene_is_capped_itself() -> None:
    from clip_shapes import icosphere

    scene = Scene(entities=[icosphere(2).replace(name="salt")])
    negative, positive = clip(scene, Plane.z(0.2), keep="both")
    for half in (negative, positive):
        salt = half["salt"]
        assert isinstance(salt, Surface)
        assert salt.is_closed
        assert "cap" in salt.patch_names
