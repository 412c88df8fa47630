"""``geobrep.repair`` re-derives patches and blocks where a weld changed the connectivity."""

from __future__ import annotations

import numpy as np

import geobrep
from geobrep import Block, PatchSide, Scene, Surface

CUBE = np.array(
    [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]],
    dtype=float,
)
FACES = np.array(  # outward
    [
        [0, 2, 1], [0, 3, 2], [0, 1, 5], [0, 5, 4], [1, 2, 6], [1, 6, 5],
        [2, 3, 7], [2, 7, 6], [3, 0, 4], [3, 4, 7], [4, 5, 6], [4, 6, 7],
    ]
)  # fmt: skip
TOP = np.array([10, 11])


def _split_top_model() -> Scene:
    """A cube block whose top is a patch of its own over its own copies of the vertices (as a
    GOCAD TFACE holds them): two patches whose borders a weld joins into one edge chain."""
    box = Surface(
        vertices=CUBE, faces=FACES, name="box", point_data={"depth": -CUBE[:, 2]},
        cell_data={"unit": np.arange(12)},
    )  # fmt: skip
    built = geobrep.build_blocks(Scene(entities=[box]))
    box = built.surfaces[0]
    faces = np.asarray(box.faces).copy()
    top_vertices = np.unique(faces[TOP])
    copies = np.arange(box.n_vertices, box.n_vertices + top_vertices.size)
    renumber = dict(zip(top_vertices.tolist(), copies.tolist(), strict=True))
    faces[TOP] = np.vectorize(renumber.get)(faces[TOP])
    labels = np.zeros(12, dtype=np.int64)
    labels[TOP] = 1
    split = box.replace(
        vertices=np.vstack([box.vertices, box.vertices[top_vertices]]),
        faces=faces,
        patch_labels=labels,
        patch_names=("sides", "top"),
        point_data={"depth": -np.append(box.vertices[:, 2], box.vertices[top_vertices, 2])},
    )
    sides = built.topology.patches[0]
    top = sides.model_copy(update={"id": 7, "label": 1, "name": "box:top"})
    sides = sides.model_copy(update={"name": "box:sides", "metadata": {"source": "TFACE 1"}})
    blocks = []
    for block in built.of_type(Block):
        (side,) = block.sides
        name = "outside" if block.is_universe else "rock"
        blocks.append(block.replace(name=name, sides=(side, PatchSide(7, side.side))))
    topology = built.topology.model_copy(update={"patches": (sides, top)})
    return Scene(entities=[split, *blocks], topology=topology)


def test_a_weld_joining_two_patches_borders_rederives_patches_and_blocks() -> None:
    scene = _split_top_model()
    assert scene.surfaces[0].n_vertices == 12
    repaired, report = geobrep.repair(scene)
    assert next(a.count for a in report.actions if a.action == "weld") == 4
    step = next(a for a in report.actions if a.action == "rederive_patches")
    assert step.count == 1
    assert any("2 patch(es) -> 1" in n for n in step.notes)
    box = repaired.surfaces[0]
    # One patch now (the builder's split), named after the patch most of its faces had.
    assert box.n_patches == 1
    assert np.asarray(box.patch_labels).tolist() == [0] * 12
    assert box.patch_names == ("sides",)
    (patch,) = repaired.topology.patches
    assert (patch.id, patch.name, patch.metadata) == (0, "box:sides", {"source": "TFACE 1"})
    # Ids, names and properties kept; the blocks are the builder's, under their old names.
    assert [(e.id, e.name, e.type) for e in repaired.entities] == [
        (e.id, e.name, e.type) for e in scene.entities
    ]
    assert np.allclose(box.point_data["depth"].values, -box.vertices[:, 2])
    assert sorted(box.cell_data["unit"].values.tolist()) == list(range(12))
    rock = next(b for b in repaired.blocks if b.name == "rock")
    assert rock.sides == (PatchSide(0, rock.sides[0].side),)
    assert abs(repaired.block_mesh(rock).volume - 1.0) < 1e-12
    assert {patch.positive_block, patch.negative_block} == {
        int(b.id or 0) for b in repaired.of_type(Block)
    }
    assert geobrep.inspect(repaired).ok, geobrep.inspect(repaired).table()


def test_no_rederivation_when_connectivity_is_unchanged() -> None:
    scene = geobrep.datasets.faulted_layer_cake()
    repaired, report = geobrep.repair(scene)
    step = next(a for a in report.actions if a.action == "rederive_patches")
    assert (step.count, step.notes) == (0, ())
    assert repaired.topology == scene.topology
