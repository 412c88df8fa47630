"""Voxelizing every block of a scene into one labelled octree; options and errors."""

from __future__ import annotations

import numpy as np
import pytest
import voxel_bodies as vb
from shapes import winding_numbers

import geobrep.plugins
from geobrep import LinearOctree, Scene, Surface
from geobrep.errors import EntityNotFoundError, OptionsError, TopologyError
from geobrep.ops.io import read, write
from geobrep.ops.voxelization import voxelize

DEPTH = 6


@pytest.fixture(scope="module")
def cake_octree(layer_cake: Scene) -> LinearOctree:
    return voxelize(layer_cake, depth=DEPTH)


def test_every_block_is_labelled(layer_cake: Scene, cake_octree: LinearOctree) -> None:
    assert cake_octree.labels is not None
    assert sorted(set(cake_octree.labels.tolist())) == sorted(b.id for b in layer_cake.blocks)
    report = cake_octree.metadata["voxelization"]
    assert isinstance(report, dict)
    names = {b["label"]: b["name"] for b in report["bodies"]}
    assert names == {b.id: b.name for b in layer_cake.blocks}


def test_block_volumes(layer_cake: Scene, cake_octree: LinearOctree) -> None:
    volumes = cake_octree.label_volumes()
    for block in layer_cake.blocks:
        exact = layer_cake.block_mesh(block).volume
        assert volumes[int(block.id or 0)] == pytest.approx(exact, rel=0.015), block.name
    total = sum(layer_cake.block_mesh(b).volume for b in layer_cake.blocks)
    assert cake_octree.volume == pytest.approx(total, rel=0.01)


def test_labels_match_block_containment(layer_cake: Scene, cake_octree: LinearOctree) -> None:
    # At voxel centres the classification is exact: compare with winding numbers per block.
    rng = np.random.default_rng(3)
    n = 1 << DEPTH
    cells = rng.integers(0, n, size=(400, 3))
    points = cake_octree.origin + (cells + 0.5) * (cake_octree.size / n)
    expected = np.full(len(points), -1)
    for block in layer_cake.blocks:
        mesh = layer_cake.block_mesh(block)
        centre = mesh.vertices.mean(axis=0)  # centred: UTM-scale coordinates
        w = winding_numbers(points - centre, mesh.vertices - centre, mesh.faces)
        expected[np.abs(w) > 0.5] = int(block.id or 0)
    np.testing.assert_array_equal(cake_octree.label_at(points), expected)
    assert (expected >= 0).sum() > 100


def test_blocks_partition_without_gaps_or_overlaps(layer_cake: Scene) -> None:
    together = voxelize(layer_cake, depth=5, method="exact")
    alone = [
        voxelize(
            layer_cake,
            depth=5,
            method="exact",
            bodies=[b.name],
            origin=tuple(together.origin),
            size=together.size,
        )
        for b in layer_cake.blocks
    ]
    assert sum(t.volume for t in alone) == pytest.approx(together.volume, rel=1e-12)
    for tree, block in zip(alone, layer_cake.blocks, strict=True):
        assert tree.label_volumes() == {int(block.id or 0): together.label_volumes()[block.id]}


def test_selected_bodies_and_cube(layer_cake: Scene) -> None:
    block = layer_cake.blocks[2]
    tree = voxelize(layer_cake, depth=5, bodies=[block.name])
    assert set(tree.labels.tolist()) == {block.id}
    by_id = voxelize(layer_cake, depth=5, bodies=[block.id])
    np.testing.assert_array_equal(by_id.codes, tree.codes)
    mesh = layer_cake.block_mesh(block)
    np.testing.assert_allclose(tree.origin, mesh.vertices.min(axis=0))
    assert tree.size == pytest.approx(float(np.ptp(mesh.vertices, axis=0).max()))
    assert tree.name == f"{layer_cake.name} octree"


def test_scene_of_closed_surfaces_and_native_round_trip(tmp_path: object) -> None:
    a = vb.ellipsoid((1.0, 1.0, 1.0), rings=16, segments=32, name="a")
    b = vb.ellipsoid((0.5, 0.5, 0.5), centre=(3.0, 0.0, 0.0), rings=16, segments=32, name="b")
    open_sheet = Surface(vertices=[[0, 0, 5], [1, 0, 5], [0, 1, 5]], faces=[[0, 1, 2]], name="s")
    scene = Scene(entities=[a, b, open_sheet], name="two")
    tree = voxelize(scene, depth=5, name="vox")
    assert set(tree.labels.tolist()) == {scene["a"].id, scene["b"].id}
    path = tmp_path / "vox.geobrep"
    write(tree, path)
    again = read(path).octrees[0]
    assert again == tree.replace(id=again.id)


def test_single_surface_has_no_labels() -> None:
    tree = voxelize(vb.box((0.0, 0.0, 0.0), (1.0, 1.0, 1.0)), depth=2)
    assert tree.labels is None
    assert tree.codes.tolist() == [0]
    assert tree.levels.tolist() == [0]
    assert tree.volume == pytest.approx(1.0)
    assert vb.body_report(tree)["octree_volume"] == tree.volume


def test_voxelizer_is_registered(layer_cake: Scene) -> None:
    spec = geobrep.plugins.registries().voxelizers.get("voxelize")
    assert spec.plugin == "voxelize"
    octree = spec.function(layer_cake, spec.validate_options(depth=3))
    assert isinstance(octree, LinearOctree)
    assert "voxelize" not in geobrep.plugins.registries().builders


def test_errors(layer_cake: Scene) -> None:
    sheet = Surface(vertices=[[0, 0, 0], [1, 0, 0], [0, 1, 0]], faces=[[0, 1, 2]], name="sheet")
    with pytest.raises(TopologyError, match="Surface 'sheet' is not closed"):
        voxelize(sheet)
    with pytest.raises(TopologyError, match="no blocks and no closed surface"):
        voxelize(Scene(entities=[sheet]))
    with pytest.raises(OptionsError, match="through its scene"):
        voxelize(layer_cake.blocks[0])
    with pytest.raises(EntityNotFoundError, match="no entity named 'nowhere'"):
        voxelize(layer_cake, bodies=["nowhere"])
    universe = layer_cake.universe
    assert universe is not None
    with pytest.raises(OptionsError, match="universe"):
        voxelize(layer_cake, bodies=[universe.id])
    with pytest.raises(OptionsError, match="option 'depth'"):
        voxelize(sheet, depth=13)
    with pytest.raises(OptionsError, match="option 'method'"):
        voxelize(sheet, method="fast")
    with pytest.raises(OptionsError, match="block_depth"):
        voxelize(layer_cake, depth=2, block_depth=3)
    with pytest.raises(OptionsError, match="option 'size'"):
        voxelize(layer_cake, size=-1.0)
    with pytest.raises(OptionsError, match="option 'origin"):
        voxelize(layer_cake, origin=(0.0, float("nan"), 0.0))
