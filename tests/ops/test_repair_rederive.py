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


def _split_top_model(duplicated: bool = False) -> Scene:
    """A cube block whose top is a patch of its own over its own copies of the vertices (as a
    GOCAD TFACE holds them: no defect). ``duplicated``: the second top triangle also holds its
    own copies of the two vertices it shares with the first, inside the top patch (a defect:
    colocated vertices of one patch), which a weld joins."""
    box = Surface(
        vertices=CUBE, faces=FACES, name="box", point_data={"depth": -CUBE[:, 2]},
        cell_data={"unit": np.arange(12)},
    )  # fmt: skip
    built = geobrep.build_blocks(Scene(entities=[box]))
    box = built.surfaces[0]
    faces = np.asarray(box.faces).copy()
    n = box.n_vertices
    top_vertices = np.unique(faces[TOP])
    copies = np.arange(n, n + top_vertices.size)
    renumber = dict(zip(top_vertices.tolist(), copies.tolist(), strict=True))
    faces[TOP] = np.vectorize(renumber.get)(faces[TOP])
    sources = top_vertices.tolist()
    if duplicated:
        second = faces[TOP[1]].copy()
        for vertex in np.intersect1d(faces[TOP[0]], faces[TOP[1]]).tolist():
            second[second == vertex] = n + len(sources)
            sources.append(sources[vertex - n])
        faces[TOP[1]] = second
    top_vertices = np.asarray(sources)
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


def test_copies_each_patch_holds_of_a_shared_border_are_no_defect() -> None:
    scene = _split_top_model()
    assert scene.surfaces[0].n_vertices == 12
    assert geobrep.inspect(scene).ok, geobrep.inspect(scene).table()
    repaired, report = geobrep.repair(scene)
    assert report.total == 0
    assert repaired.surfaces[0].n_vertices == 12


def test_a_weld_joining_two_patches_borders_rederives_patches_and_blocks() -> None:
    scene = _split_top_model(duplicated=True)
    assert scene.surfaces[0].n_vertices == 14
    before = geobrep.inspect(scene, ["colocated_vertices"]).section("colocated_vertices")
    assert before.count == 2  # the two copies inside the top patch, nothing across patches
    assert all(len(d.ids) == 2 and min(d.ids) >= 8 for d in before.defects)
    repaired, report = geobrep.repair(scene)
    # 2 inside the top patch; once the patches are one, the 4 copies the top held of the sides
    assert next(a.count for a in report.actions if a.action == "weld") == 6
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
