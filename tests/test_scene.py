"""The scene graph: ids, lookup, groups, topology references, the spatial index, block meshes.

The layer-cake checks recompute every answer independently of geobrep's kernels: volumes with
trimesh, inside/outside with winding numbers, arc order with ``atan2`` in a frame of the arc.
"""

from __future__ import annotations

import itertools
import math
import re
from itertools import combinations
from typing import Any

import numpy as np
import pytest
from numpy.typing import NDArray
from shapes import CUBE_FACES, CUBE_VERTICES, winding_numbers

import geobrep
from geobrep import (
    CRS,
    Arc,
    Block,
    Corner,
    EntityNotFoundError,
    EntityValidationError,
    Group,
    Patch,
    PointSet,
    PolyLine,
    Scene,
    Surface,
    Topology,
    TopologyError,
)

TRIANGLE = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]


def wells(**fields: Any) -> PointSet:
    return PointSet(vertices=[[0.0, 0.0, 0.0]], **{"name": "wells", **fields})


# ----------------------------------------------------------------------------- ids and lookup
class TestIdsAndLookup:
    def test_ids_are_assigned_in_order(self) -> None:
        scene = Scene(entities=[wells(), wells(name="b"), wells(name="c")])
        assert [e.id for e in scene.entities] == [0, 1, 2]

    def test_given_ids_are_kept_and_new_ones_follow_the_largest(self) -> None:
        scene = Scene(entities=[wells(name="a"), wells(name="b", id=7), wells(name="c")])
        assert [e.id for e in scene.entities] == [8, 7, 9]

    def test_duplicate_ids_are_rejected(self) -> None:
        with pytest.raises(EntityValidationError, match="entity id 1 is used twice") as info:
            Scene(entities=[wells(id=1), wells(name="b", id=1)])
        assert info.value.entity == "Scene"
        assert info.value.field == "entities"

    def test_lookup_by_id_and_name(self) -> None:
        scene = Scene(entities=[wells(), Surface(vertices=TRIANGLE, faces=[[0, 1, 2]], name="top")])
        assert scene[1].name == "top"
        assert scene["top"].id == 1
        assert scene.get(0).name == "wells"
        assert scene.find("top") == [scene[1]]
        assert scene.find("nothing") == []
        assert 1 in scene
        assert "top" in scene
        assert 5 not in scene
        assert "bottom" not in scene
        assert len(scene) == 2

    def test_ambiguous_name(self) -> None:
        scene = Scene(entities=[wells(), wells(), wells(name="other")])
        with pytest.raises(EntityNotFoundError) as info:
            scene["wells"]
        assert isinstance(info.value, KeyError)
        assert str(info.value) == "2 entities are named 'wells' (ids 0, 1): use the id"
        assert [e.id for e in scene.find("wells")] == [0, 1]

    def test_missing_name_and_id(self) -> None:
        scene = Scene(entities=[wells()])
        with pytest.raises(KeyError, match="no entity named 'nope'"):
            scene["nope"]
        with pytest.raises(EntityNotFoundError, match="no entity with id 3"):
            scene[3]

    def test_entities_from_dicts(self) -> None:
        scene = Scene(entities=[{"type": "PointSet", "vertices": [[1, 2, 3]], "name": "p"}])
        assert isinstance(scene["p"], PointSet)
        assert scene["p"].id == 0

    def test_bad_entity_is_named(self) -> None:
        with pytest.raises(EntityValidationError, match="Surface 'top': faces: face 0 refers"):
            Scene(
                entities=[
                    {"type": "Surface", "vertices": TRIANGLE, "faces": [[0, 1, 5]], "name": "top"}
                ]
            )

    def test_of_type_and_collections(self) -> None:
        line = PolyLine(vertices=TRIANGLE, name="trace")
        surface = Surface(vertices=TRIANGLE, faces=[[0, 1, 2]], name="top")
        scene = Scene(entities=[wells(), line, surface, wells(name="w2")])
        assert [e.name for e in scene.of_type(PointSet)] == ["wells", "w2"]
        assert scene.point_sets == scene.of_type(PointSet)
        assert [e.name for e in scene.polylines] == ["trace"]
        assert [e.name for e in scene.surfaces] == ["top"]
        assert scene.blocks == ()
        assert scene.universe is None
        assert scene.patches == ()


# ----------------------------------------------------------------------------- groups
class TestGroups:
    def test_nested_groups(self) -> None:
        inner = Group(name="inner", members=(1,))
        scene = Scene(
            entities=[wells(), wells(name="b")],
            groups=[Group(name="outer", kind="folder", members=(0,), children=(inner,))],
        )
        assert [g.name for g in scene.groups[0].walk()] == ["outer", "inner"]

    @pytest.mark.parametrize(
        "groups",
        [
            [Group(name="g", members=(0, 5))],
            [Group(name="top", children=(Group(name="g", members=(5,)),))],
        ],
    )
    def test_members_must_exist(self, groups: list[Group]) -> None:
        with pytest.raises(EntityValidationError) as info:
            Scene(entities=[wells(), wells(name="b")], groups=groups)
        assert str(info.value) == "Scene: groups['g']: member 5 is not an entity id"


# ----------------------------------------------------------------------------- topology
def cube_scene(with_internal: bool = False) -> Scene:
    """The unit cube as one block: 6 patches (one per side) with the universe outside.

    With ``with_internal``, a horizontal square at z = 0.5 lies inside the block, listed with
    both sides (a surface ending inside a body).
    """
    cube = Surface(
        vertices=CUBE_VERTICES,
        faces=CUBE_FACES,
        patch_labels=np.repeat(np.arange(6), 2),
        patch_names=("bottom", "top", "south", "north", "west", "east"),
        name="box",
        id=0,
    )
    patches = [
        Patch(
            id=k, surface=0, label=k, name=cube.patch_name(k), positive_block=11, negative_block=10
        )
        for k in range(6)
    ]
    entities: list[Any] = [cube]
    inner_sides: list[tuple[int, int]] = []
    if with_internal:
        sheet = Surface(
            vertices=[[0.25, 0.25, 0.5], [0.75, 0.25, 0.5], [0.75, 0.75, 0.5], [0.25, 0.75, 0.5]],
            faces=[[0, 1, 2, 3]],
            name="sheet",
            id=1,
        )
        entities.append(sheet)
        patches.append(Patch(id=6, surface=1, positive_block=10, negative_block=10))
        inner_sides = [(6, 1), (6, -1)]
    entities += [
        Block(id=10, name="body", sides=[*((k, -1) for k in range(6)), *inner_sides]),
        Block(id=11, name="universe", kind="universe", sides=[(k, 1) for k in range(6)]),
    ]
    return Scene(entities=entities, topology=Topology(patches=tuple(patches)))


class TestTopologyReferences:
    def test_cube_scene(self) -> None:
        scene = cube_scene()
        assert [b.name for b in scene.blocks] == ["body"]
        assert scene.universe is not None
        assert scene.universe.name == "universe"
        assert len(scene.patches) == 6

    def test_block_mesh_of_the_cube(self) -> None:
        scene = cube_scene()
        body = scene.block_mesh("body")
        assert body.volume == pytest.approx(1.0)
        assert body.is_closed
        assert body.is_consistently_oriented
        assert body.patch_names == ("bottom", "top", "south", "north", "west", "east")
        assert body.patch_labels is not None
        assert body.patch_labels.tolist() == np.repeat(np.arange(6), 2).tolist()
        assert body.metadata == {"block": 10}
        assert body.name == "body"
        universe = scene.block_mesh(11)
        assert universe.volume == pytest.approx(-1.0)

    def test_internal_patch_is_left_out(self) -> None:
        scene = cube_scene(with_internal=True)
        block = scene["body"]
        assert isinstance(block, Block)
        assert block.internal_patches == frozenset({6})
        assert scene.patches[6].is_internal
        body = scene.block_mesh(block)
        assert body.n_faces == 12
        assert body.volume == pytest.approx(1.0)
        assert body.is_closed

    def test_block_mesh_needs_a_block(self) -> None:
        scene = cube_scene()
        with pytest.raises(TopologyError, match="Surface 'box' is not a Block"):
            scene.block_mesh("box")
        with pytest.raises(EntityNotFoundError):
            scene.block_mesh("nothing")
        empty = Scene(entities=[Block(name="hollow")])
        with pytest.raises(TopologyError, match="has no boundary patches"):
            empty.block_mesh("hollow")

    def test_patch_on_a_non_surface(self) -> None:
        with pytest.raises(TopologyError, match="patch 0: entity 0 is not a Surface"):
            Scene(entities=[wells()], topology=Topology(patches=(Patch(id=0, surface=0),)))
        with pytest.raises(TopologyError, match="patch 0: entity 9 is not a Surface"):
            Scene(entities=[wells()], topology=Topology(patches=(Patch(id=0, surface=9),)))

    def test_patch_label_out_of_range(self) -> None:
        surface = Surface(vertices=TRIANGLE, faces=[[0, 1, 2]], name="top")
        with pytest.raises(TopologyError, match="Surface 'top' has no patch label 1"):
            Scene(entities=[surface], topology=Topology(patches=(Patch(id=0, surface=0, label=1),)))

    def test_patch_block_must_be_a_block(self) -> None:
        surface = Surface(vertices=TRIANGLE, faces=[[0, 1, 2]])
        patch = Patch(id=0, surface=0, positive_block=1)
        with pytest.raises(TopologyError, match="patch 0: entity 1 is not a Block"):
            Scene(entities=[surface, wells()], topology=Topology(patches=(patch,)))

    def test_block_lists_a_missing_patch(self) -> None:
        surface = Surface(vertices=TRIANGLE, faces=[[0, 1, 2]])
        with pytest.raises(TopologyError, match="Block 'B': patch 3 does not exist"):
            Scene(
                entities=[surface, Block(sides=[(3, 1)], name="B")],
                topology=Topology(patches=(Patch(id=0, surface=0),)),
            )

    def test_conflicting_sides(self) -> None:
        surface = Surface(vertices=TRIANGLE, faces=[[0, 1, 2]])
        with pytest.raises(TopologyError, match=r"lists side \+1 of patch 0.*to block 2"):
            Scene(
                entities=[surface, Block(sides=[(0, 1)], name="B"), Block(name="K")],
                topology=Topology(patches=(Patch(id=0, surface=0, positive_block=2),)),
            )
        with pytest.raises(
            TopologyError, match=r"side \+1 of patch 0 is claimed by blocks 1 and 2"
        ):
            Scene(
                entities=[surface, Block(sides=[(0, 1)], name="B"), Block(sides=[(0, 1)])],
                topology=Topology(patches=(Patch(id=0, surface=0),)),
            )

    def test_topology_is_self_consistent(self) -> None:
        segment = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]]
        cases: list[tuple[dict[str, Any], str]] = [
            ({"patches": (Patch(id=0, surface=0), Patch(id=0, surface=1))}, "patch id 0"),
            ({"corners": (Corner(id=1, point=[0, 0, 0]),) * 2}, "corner id 1"),
            ({"arcs": (Arc(id=0, points=segment, start=3),)}, "arc 0: corner 3 does not exist"),
            ({"arcs": (Arc(id=0, points=segment, patches=(4,)),)}, "arc 0: patch 4 does not"),
            ({"patches": (Patch(id=0, surface=0, arcs=(2,)),)}, "patch 0: arc 2 does not exist"),
        ]
        for fields, message in cases:
            with pytest.raises(TopologyError, match=message):
                Topology(**fields)
        with pytest.raises(TopologyError, match="arc 0: needs at least 2 points"):
            Arc(id=0, points=[[0.0, 0.0, 0.0]])
        with pytest.raises(TopologyError, match="arc 0: needs at least 2 points"):
            Scene(topology={"arcs": [{"id": 0, "points": [[0.0, 0.0, 0.0]]}]})

    def test_topology_lookup(self) -> None:
        topology = cube_scene().topology
        assert topology.patch(3).name == "north"
        assert topology.patch(3).label == 3
        with pytest.raises(TopologyError, match="no patch with id 9"):
            topology.patch(9)
        with pytest.raises(TopologyError, match="no arc with id 0"):
            topology.arc(0)
        with pytest.raises(TopologyError, match="no corner with id 0"):
            topology.corner(0)
        assert Topology().is_empty
        assert not topology.is_empty


# ----------------------------------------------------------------------------- geometry
class TestIndexAndBounds:
    def test_bounds_union(self) -> None:
        scene = Scene(
            entities=[
                PointSet(vertices=[[0, 0, 0], [1, 2, 3]]),
                PointSet(vertices=[[-1, 5, 1]]),
                Block(name="no geometry"),
            ]
        )
        assert scene.bounds is not None
        assert scene.bounds.as_tuple() == (-1.0, 1.0, 0.0, 5.0, 0.0, 3.0)
        assert Scene().bounds is None

    def test_index_queries(self) -> None:
        scene = Scene(
            entities=[
                PointSet(vertices=[[0, 0, 0], [1, 1, 1]], name="a"),
                PointSet(vertices=[[5, 5, 5], [6, 6, 6]], name="b", id=7),
                Block(name="c"),
                Surface(
                    vertices=np.array(TRIANGLE) + np.array([10, 0, 0]), faces=[[0, 1, 2]], name="d"
                ),
            ]
        )
        index = scene.index
        assert len(index) == 3  # the block has no bounds
        assert sorted(index.ids.tolist()) == [7, 8, 10]
        assert index.intersection([0.5, 0.5, 0.5], [5.5, 5.5, 5.5]).tolist() == [7, 8]
        assert index.intersection([10.2, 0.1, -1], [10.3, 0.2, 1]).tolist() == [10]
        assert index.intersection([2, 2, 2], [3, 3, 3]).tolist() == []
        assert index.nearest([[9.0, 0.0, 0.0]]).tolist() == [[10]]
        assert index.bounds == scene.bounds

    def test_empty_index(self) -> None:
        assert len(Scene().index) == 0
        assert Scene().index.intersection([0, 0, 0], [1, 1, 1]).tolist() == []

    def test_layer_cake_index(self, layer_cake: Scene) -> None:
        fault = layer_cake["fault"]
        assert fault.bounds is not None
        centre = fault.bounds.center
        hits = layer_cake.index.intersection(centre, centre)
        assert fault.id in hits.tolist()
        assert all(isinstance(layer_cake[int(i)], Surface) for i in hits)


# ----------------------------------------------------------------------------- derivation
class TestDerivation:
    def test_with_entities(self) -> None:
        scene = Scene(entities=[wells()], name="s")
        grown = scene.with_entities(wells(name="b", id=7), wells(name="c"))
        assert [e.id for e in grown.entities] == [0, 7, 8]
        assert grown.name == "s"
        assert len(scene) == 1

    def test_with_entities_revalidates(self) -> None:
        scene = Scene(entities=[wells(id=3)])
        with pytest.raises(EntityValidationError, match="entity id 3 is used twice"):
            scene.with_entities(wells(name="b", id=3))

    def test_replace(self) -> None:
        scene = Scene(entities=[wells()])
        renamed = scene.replace(name="x", crs=CRS(epsg=32631))
        assert renamed.name == "x"
        assert renamed.crs is not None
        assert renamed.crs.label == "EPSG:32631"
        assert scene.name == ""
        assert renamed.entities == scene.entities
        with pytest.raises(EntityValidationError, match="member 3 is not an entity id"):
            scene.replace(groups=[Group(name="g", members=(3,))])

    def test_scene_is_frozen_and_structural(self) -> None:
        scene = Scene(entities=[wells()])
        with pytest.raises(ValueError, match="frozen"):
            scene.name = "q"  # type: ignore[misc]
        assert scene == Scene(entities=[wells()])
        assert scene != Scene(entities=[wells(name="other")])

    def test_repr(self, layer_cake: Scene) -> None:
        assert repr(layer_cake) == (
            "Scene('faulted layer cake': 7 Block, 9 Surface, crs=EPSG:32631, 31 patches)"
        )
        assert repr(Scene()) == "Scene('': empty, 0 patches)"


# ----------------------------------------------------------------------------- the layer cake
SURFACE_NAMES = ["H1", "H2", "top", "bottom", "west", "east", "fault", "south", "north"]


def patch_triangles(scene: Scene, patch: Patch) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Corner coordinates ``(F, 3, 3)`` and unit normals ``(F, 3)`` of a patch's triangles."""
    surface = scene.get(patch.surface)
    assert isinstance(surface, Surface)
    faces = surface.faces[surface.patch_faces(patch.label)]
    assert faces.shape[1] == 3
    corners = surface.vertices[faces]
    normals = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    return corners, normals / np.linalg.norm(normals, axis=1, keepdims=True)


def assert_geological_adjacency(scene: Scene) -> None:
    """Each layer touches itself across the fault and its neighbours on the same fault side."""
    block_of = {
        (str(b.metadata["fault_side"]), int(b.metadata["layer"])): int(b.id or 0)
        for b in scene.blocks
    }
    layers = sorted({layer for _, layer in block_of})
    assert len(block_of) == 2 * len(layers)
    adjacency = set(scene.block_adjacency())

    def touching(a: int, b: int) -> bool:
        return (min(a, b), max(a, b)) in adjacency

    for layer in layers:
        assert touching(block_of["footwall", layer], block_of["hanging wall", layer]), layer
    for side in ("footwall", "hanging wall"):
        for upper, lower in itertools.pairwise(layers):
            assert touching(block_of[side, upper], block_of[side, lower]), (side, upper)
        for upper, lower in combinations(layers, 2):
            if lower - upper > 1:
                assert not touching(block_of[side, upper], block_of[side, lower])


class TestLayerCake:
    def test_contents(self, layer_cake: Scene) -> None:
        assert [s.name for s in layer_cake.surfaces] == SURFACE_NAMES
        assert len(layer_cake.blocks) == 6
        assert layer_cake.universe is not None
        assert layer_cake.universe.name == "universe"
        assert len(layer_cake.patches) == 31
        assert layer_cake.crs is not None
        assert layer_cake.crs.epsg == 32631
        assert {b.metadata["fault_side"] for b in layer_cake.blocks} == {"footwall", "hanging wall"}
        kinds = {s.name: s.kind for s in layer_cake.surfaces}
        assert kinds["H1"] == kinds["H2"] == "horizon"
        assert kinds["fault"] == "fault"
        assert [g.name for g in layer_cake.groups] == ["horizons", "faults", "boundaries", "blocks"]

    def test_bounds(self, layer_cake: Scene) -> None:
        # a 1000 x 800 x 600 m box at the UTM origin; the fold lifts the top centre by 40 m
        assert layer_cake.bounds is not None
        assert layer_cake.bounds.as_tuple() == (
            450_000.0,
            451_000.0,
            6_700_000.0,
            6_700_800.0,
            -600.0,
            40.0,
        )

    def test_counts_obey_euler(self, layer_cake: Scene) -> None:
        topology = layer_cake.topology
        side_faces = {layer_cake["south"].id, layer_cake["north"].id}
        strips = [p for p in layer_cake.patches if p.surface not in side_faces]
        cells = len(layer_cake.blocks)
        n_section_edges = len(strips)
        n_section_points = len(topology.corners) // 2
        # the model is a cross-section extruded along y: a corner at each end of a section point,
        # an arc along y per point and one per edge at each end, a patch per edge and two per cell
        assert len(topology.corners) == 2 * n_section_points
        assert len(topology.arcs) == n_section_points + 2 * n_section_edges
        assert len(layer_cake.patches) == n_section_edges + 2 * cells
        assert n_section_points - n_section_edges + (cells + 1) == 2

    def test_every_block_mesh_is_a_closed_oriented_body(self, layer_cake: Scene) -> None:
        trimesh = pytest.importorskip("trimesh")
        for block in layer_cake.blocks:
            boundary = layer_cake.block_mesh(block)
            assert boundary.is_closed, block.name
            assert boundary.is_consistently_oriented, block.name
            assert boundary.volume > 0, block.name
            centred = boundary.vertices - boundary.vertices.mean(axis=0)
            reference = trimesh.Trimesh(centred, boundary.faces, process=False)
            assert reference.is_watertight
            assert boundary.volume == pytest.approx(reference.volume, rel=1e-9), block.name

    def test_block_volumes_fill_the_model(self, layer_cake: Scene) -> None:
        total = sum(layer_cake.block_mesh(block).volume for block in layer_cake.blocks)
        assert layer_cake.universe is not None
        shell = layer_cake.block_mesh(layer_cake.universe)
        assert shell.is_closed
        assert shell.volume < 0  # the universe lies outside: its boundary points inwards
        assert total == pytest.approx(-shell.volume, rel=1e-9)
        # the fold moves top and bottom alike, so the volume of the 1000 x 800 x 600 box remains
        assert total == pytest.approx(1000.0 * 800.0 * 600.0, rel=1e-4)

    def test_block_sides_match_patches(self, layer_cake: Scene) -> None:
        listed: set[tuple[int, int, int]] = set()
        for block in layer_cake.of_type(Block):
            listed |= {(side.patch, side.side, int(block.id or 0)) for side in block.sides}
        from_patches = {(p.id, 1, p.positive_block) for p in layer_cake.patches} | {
            (p.id, -1, p.negative_block) for p in layer_cake.patches
        }
        assert listed == from_patches

    def test_adjacency_from_patches(self, layer_cake: Scene) -> None:
        universe = layer_cake.universe
        assert universe is not None
        expected = {
            tuple(sorted((int(p.positive_block), int(p.negative_block))))
            for p in layer_cake.patches
            if p.positive_block is not None
            and p.negative_block is not None
            and universe.id not in (p.positive_block, p.negative_block)
            and p.positive_block != p.negative_block
        }
        adjacency = layer_cake.block_adjacency()
        assert adjacency == sorted(expected)
        assert all(a < b for a, b in adjacency)
        assert_geological_adjacency(layer_cake)

    def test_every_patch_separates_its_blocks(self, layer_cake: Scene) -> None:
        universe = layer_cake.universe
        assert universe is not None
        assert layer_cake.bounds is not None
        centre = layer_cake.bounds.center
        bodies = {
            int(block.id or 0): layer_cake.block_mesh(block) for block in layer_cake.of_type(Block)
        }
        step = 0.01  # metres; triangles are ~50 m, blocks over 100 m thick
        for patch in layer_cake.patches:
            corners, normals = patch_triangles(layer_cake, patch)
            chosen = np.linspace(0, len(corners) - 1, min(6, len(corners))).astype(int)
            centroids = corners[chosen].mean(axis=1) - centre
            for block_id, sign in ((patch.positive_block, 1.0), (patch.negative_block, -1.0)):
                assert block_id is not None
                probes = centroids + sign * step * normals[chosen]
                body = bodies[int(block_id)]
                winding = winding_numbers(probes, body.vertices - centre, body.faces)
                # inside a block's outward boundary: 1; outside the model, w.r.t. the inward
                # boundary of the universe: 0 (and -1 just inside the model)
                expected = 0.0 if block_id == universe.id else 1.0
                np.testing.assert_allclose(
                    winding, expected, atol=1e-6, err_msg=f"{patch.name} side {sign:+.0f}"
                )
                other = winding_numbers(
                    centroids - sign * step * normals[chosen], body.vertices - centre, body.faces
                )
                np.testing.assert_allclose(
                    other, -1.0 if block_id == universe.id else 0.0, atol=1e-6
                )

    def test_arcs_have_the_patches_that_meet_there(self, layer_cake: Scene) -> None:
        topology = layer_cake.topology
        triangles = {p.id: patch_triangles(layer_cake, p)[0] for p in layer_cake.patches}
        orders_that_matter = 0
        for arc in topology.arcs:
            start, end = arc.points[0], arc.points[1]
            direction = (end - start) / np.linalg.norm(end - start)
            helper = np.array([0.0, 0.0, 1.0]) if abs(direction[2]) < 0.9 else np.eye(3)[0]
            e1 = np.cross(direction, helper)
            e1 /= np.linalg.norm(e1)
            e2 = np.cross(direction, e1)  # (e1, e2, direction) is right-handed
            angles: dict[int, list[float]] = {}
            for patch_id, tris in triangles.items():
                for j in range(3):
                    a, b = tris[:, j], tris[:, (j + 1) % 3]
                    on_arc = (
                        (np.linalg.norm(a - start, axis=1) < 1e-6)
                        & (np.linalg.norm(b - end, axis=1) < 1e-6)
                    ) | (
                        (np.linalg.norm(a - end, axis=1) < 1e-6)
                        & (np.linalg.norm(b - start, axis=1) < 1e-6)
                    )
                    for k in np.flatnonzero(on_arc):
                        away = tris[k, (j + 2) % 3] - 0.5 * (start + end)
                        angles.setdefault(patch_id, []).append(
                            math.atan2(float(away @ e2), float(away @ e1))
                        )
            assert set(angles) == set(arc.patches), f"arc {arc.id}"
            assert all(len(a) == 1 for a in angles.values()), f"arc {arc.id}"
            # counter-clockwise seen from the arc's tip, starting anywhere: angles increase
            turn = [(angles[p][0] - angles[arc.patches[0]][0]) % (2 * math.pi) for p in arc.patches]
            assert turn == sorted(turn), f"arc {arc.id}: {arc.patches} is not right-handed"
            orders_that_matter += len(arc.patches) >= 3
        assert orders_that_matter > 0

    def test_arc_and_patch_references_agree(self, layer_cake: Scene) -> None:
        topology = layer_cake.topology
        for arc in topology.arcs:
            listing = {p.id for p in layer_cake.patches if arc.id in p.arcs}
            assert listing == set(arc.patches)
            assert len(set(arc.patches)) == len(arc.patches)

    def test_corners_lie_on_arc_ends(self, layer_cake: Scene) -> None:
        topology = layer_cake.topology
        used = set()
        for arc in topology.arcs:
            assert arc.start is not None
            assert arc.end is not None
            np.testing.assert_array_equal(topology.corner(arc.start).point, arc.points[0])
            np.testing.assert_array_equal(topology.corner(arc.end).point, arc.points[-1])
            used |= {arc.start, arc.end}
        assert used == set(topology.corner_by_id)

    @pytest.mark.parametrize("n_horizons", [0, 1, 3])
    @pytest.mark.parametrize("resolution", [100.0, 200.0])
    def test_other_layer_counts(self, n_horizons: int, resolution: float) -> None:
        scene = geobrep.datasets.faulted_layer_cake(n_horizons=n_horizons, resolution=resolution)
        assert len(scene.blocks) == 2 * (n_horizons + 1)
        assert len([s for s in scene.surfaces if s.kind == "horizon"]) == n_horizons
        volumes = []
        for block in scene.blocks:
            boundary = scene.block_mesh(block)
            assert boundary.is_closed, block.name
            assert boundary.is_consistently_oriented, block.name
            assert boundary.volume > 0
            volumes.append(boundary.volume)
        assert scene.universe is not None
        shell = scene.block_mesh(scene.universe)
        assert sum(volumes) == pytest.approx(-shell.volume, rel=1e-9)
        assert_geological_adjacency(scene)

    @pytest.mark.parametrize(
        ("kwargs", "message"),
        [
            ({"n_horizons": -1}, "n_horizons must be ≥ 0"),
            ({"resolution": 0.0}, "resolution must be > 0"),
            ({"throw": 500.0}, "throw too large"),
        ],
    )
    def test_bad_arguments(self, kwargs: dict[str, Any], message: str) -> None:
        with pytest.raises(ValueError, match=message):
            geobrep.datasets.faulted_layer_cake(**kwargs)


class TestCrsInput:
    """``Scene(crs=...)`` takes EPSG codes as pyproj does, without importing pyproj."""

    @pytest.mark.parametrize("value", ["EPSG:32631", "epsg:32631", 32631, "32631", ("EPSG", 32631)])
    def test_epsg_codes(self, value: Any) -> None:
        scene = Scene(entities=[wells()], crs=value)
        assert scene.crs == CRS(epsg=32631)
        assert scene.replace(crs=value).crs == CRS(epsg=32631)
        assert scene.model_copy(update={"crs": value}).crs == CRS(epsg=32631)

    def test_fields_and_none(self) -> None:
        assert Scene(crs={"epsg": 4326, "z_positive": "down"}).crs == CRS(
            epsg=4326, z_positive="down"
        )
        assert Scene(crs=CRS(epsg=4326)).replace(crs=None).crs is None

    @pytest.mark.parametrize(
        ("value", "message"),
        [
            (0, "CRS 0 is not a valid CRS: an EPSG code is a positive integer"),
            ("EPSG:0", "CRS 'EPSG:0' is not a valid CRS"),
            (True, "CRS True is not a CRS"),
            (1.5, "CRS '1.5' is not a CRS"),
            ({"epsg": -1}, "CRS {'epsg': -1}: epsg: Input should be greater than 0"),
        ],
    )
    def test_bad_values_are_named(self, value: Any, message: str) -> None:
        with pytest.raises(geobrep.GeobrepError, match=re.escape(message)):
            Scene(crs=value)


# ----------------------------------------------------------------------------- validated parts
class TestFromValidated:
    """``Scene.from_validated`` (the readers' constructor) gives what ``Scene(...)`` gives."""

    @staticmethod
    def _parts(scene: Scene) -> dict[str, Any]:
        return {name: getattr(scene, name) for name in Scene.model_fields}

    def test_the_same_scene_as_the_constructor(self) -> None:
        cake = geobrep.datasets.faulted_layer_cake()
        parts = self._parts(cake)
        parts["metadata"] = {"source": {"file": "cake", "rows": [1, 2.5, None]}}
        built, assembled = Scene(**parts), Scene.from_validated(**parts)
        assert assembled == built
        assert assembled.model_fields_set == built.model_fields_set
        assert all(a is b for a, b in zip(assembled.entities, built.entities, strict=True))
        assert assembled.metadata == built.metadata
        assert assembled.metadata is not parts["metadata"]  # validated, as the field is

    def test_ids_are_given_as_the_constructor_gives_them(self) -> None:
        scene = Scene.from_validated(entities=[wells(name="a"), wells(name="b", id=7)])
        assert [e.id for e in scene.entities] == [8, 7]

    def test_references_are_checked(self) -> None:
        with pytest.raises(EntityValidationError, match="entity id 1 is used twice"):
            Scene.from_validated(entities=[wells(id=1), wells(name="b", id=1)])
        patch = Patch(id=0, surface=0, label=0)
        with pytest.raises(TopologyError, match="entity 0 is not a Surface"):
            Scene.from_validated(entities=[wells(id=0)], topology=Topology(patches=(patch,)))

    def test_metadata_is_validated_as_the_field_is(self) -> None:
        with pytest.raises(EntityValidationError) as info:
            Scene.from_validated(entities=[wells()], metadata={"bad": object()})
        with pytest.raises(EntityValidationError) as expected:
            Scene(entities=[wells()], metadata={"bad": object()})
        assert (info.value.entity, info.value.field) == (
            expected.value.entity,
            expected.value.field,
        )
        assert str(info.value) == str(expected.value)

    @pytest.mark.parametrize("metadata", [[], (), "", 0])
    def test_metadata_of_another_kind_is_refused_even_when_empty(self, metadata: object) -> None:
        with pytest.raises(EntityValidationError, match="metadata"):
            Scene.from_validated(entities=[wells()], metadata=metadata)  # type: ignore[arg-type]
        assert Scene.from_validated(entities=[wells()], metadata={}).metadata == {}

    def test_parts_that_are_no_models_go_through_the_constructor(self) -> None:
        scene = Scene.from_validated(
            entities=[wells()],
            topology={"patches": []},  # type: ignore[arg-type]
            crs="EPSG:32633",  # type: ignore[arg-type]
        )
        assert scene == Scene(entities=[wells()], topology={"patches": []}, crs="EPSG:32633")


# ----------------------------------------------------------------------------- lazy entity types
#: The entity modules a surface file does not need: imported on first use of their classes.
LAZY_ENTITY_MODULES = tuple(
    f"geobrep.model.entities.{m}"
    for m in ("annotation", "grid", "nurbs", "octree", "polygon", "structured", "tetmesh", "well")
)


def _in_a_fresh_interpreter(code: str) -> Any:
    import json
    import subprocess
    import sys

    done = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=120, check=False
    )
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout.splitlines()[-1])


class TestLazyEntityTypes:
    """The entity modules a file does not need are imported when a scene is first validated
    (its schema names every type) or a class is named, not with the package."""

    def test_every_entity_type_is_in_the_scene_union(self) -> None:
        from typing import get_args

        from geobrep.model import entities

        union = get_args(get_args(entities.AnyEntity)[0])
        assert [c.__name__ for c in union] == list(entities.ENTITY_MODULES)
        assert {c.__name__: c for c in union} == entities.ENTITY_TYPES
        for name, module in entities.ENTITY_MODULES.items():
            cls = getattr(entities, name)
            assert cls.__module__ == f"geobrep.model.entities.{module}"
            assert entities.is_entity_class(cls)
        assert not entities.is_entity_class(entities.VertexEntity)
        assert not entities.is_entity_class(type("Surface", (Surface,), {}))

    def test_a_surface_scene_loads_no_other_entity_module(self) -> None:
        code = (
            "import json, sys\n"
            "from geobrep import Scene, Surface\n"
            "tri = Surface(vertices=[[0, 0, 0], [1, 0, 0], [0, 1, 0]], faces=[[0, 1, 2]])\n"
            "scene = Scene.from_validated(entities=[tri])\n"
            "before = sorted(m for m in sys.modules if m.startswith('geobrep.model.entities.'))\n"
            "Scene(entities=[{'type': 'PointSet', 'vertices': [[0, 0, 0]]}])\n"
            "after = sorted(m for m in sys.modules if m.startswith('geobrep.model.entities.'))\n"
            "print(json.dumps([scene.entities[0].id, before, after]))\n"
        )
        ident, before, after = _in_a_fresh_interpreter(code)
        assert ident == 0
        assert not [m for m in before if m in LAZY_ENTITY_MODULES]
        assert set(LAZY_ENTITY_MODULES) <= set(after)  # the scene's schema was built

    def test_a_fresh_scene_validates_every_type_by_its_tag(self) -> None:
        code = (
            "import json\n"
            "from geobrep import Scene\n"
            "try:\n"
            "    Scene(entities=[{'type': 'Nope'}])\n"
            "except Exception as exc:\n"
            "    message = str(exc)\n"
            "octree = {'type': 'LinearOctree', 'depth': 2, 'origin': [0, 0, 0], 'size': 4.0,\n"
            "          'codes': [0], 'levels': [0]}\n"
            "scene = Scene(entities=[octree])\n"
            "print(json.dumps([message, type(scene.entities[0]).__name__]))\n"
        )
        message, kind = _in_a_fresh_interpreter(code)
        assert kind == "LinearOctree"
        tags = ", ".join(f"'{name}'" for name in geobrep.model.entities.ENTITY_MODULES)
        assert message == (
            "Scene: entities.0: Input tag 'Nope' found using 'type' does not match any of the "
            f"expected tags: {tags}"
        )

    def test_from_validated_takes_entities_of_every_type_as_they_are(
        self, monkeypatch: pytest.MonkeyPatch
    ) -> None:
        net = np.zeros((2, 2, 3))
        net[1, :, 0] = 1.0
        net[:, 1, 1] = 1.0
        nurbs = geobrep.NurbsSurface(
            degree_u=1, degree_v=1, knots_u=[0, 0, 1, 1], knots_v=[0, 0, 1, 1], control_points=net
        )
        octree = geobrep.LinearOctree(depth=2, origin=[0, 0, 0], size=4.0, codes=[0], levels=[0])
        cake = geobrep.datasets.faulted_layer_cake()
        parts = [*cake.entities, nurbs, octree]

        def constructor(self: Scene, **data: Any) -> None:
            raise AssertionError("validated entities were validated again")

        built = Scene(entities=parts, topology=cake.topology)
        monkeypatch.setattr(Scene, "__init__", constructor)
        assembled = Scene.from_validated(entities=parts, topology=cake.topology)
        assert assembled.entities == built.entities
        assert [type(e) for e in assembled.entities] == [type(e) for e in parts]
        other = type("Surface", (Surface,), {})(vertices=TRIANGLE, faces=[[0, 1, 2]])
        with pytest.raises(AssertionError, match="validated again"):  # not one of the classes
            Scene.from_validated(entities=[other])
