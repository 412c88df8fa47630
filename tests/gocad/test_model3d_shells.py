"""geobrep.model._shells: the edges of all patches summarised once tell, for every block, what
checking its whole shell tells (does it run one way; how many edges bound one triangle), and
the orientation found from them equals the one of the whole rule."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from gocad_files import DATA
from shapes import make_cube

import geobrep
from geobrep import Block, PatchSide, Scene
from geobrep.geometry.mesh import boundary_edges, is_consistently_oriented
from geobrep.model._shells import (
    block_shell,
    open_edges_if_one_way,
    patch_edges,
    patch_edges_of_incidence,
    patch_triangles,
)
from geobrep.model.arcs import corners_and_arcs_of
from geobrep.model.orientation import _one_way_orientation, _patch_areas, _shell_orientation
from geobrep.model.topology import Patch, Topology


def _open_box() -> Scene:
    """The unit cube in six patches of two triangles, one of them no patch of the topology: the
    other five have edges no other patch uses (a hole)."""
    cube = make_cube()
    surface = cube.replace(patch_labels=np.arange(12) // 2, patch_names=tuple("abcdef"), id=0)
    patches = tuple(Patch(id=k, surface=0, label=k) for k in range(5))
    box = Block(id=1, name="box", sides=tuple(PatchSide(k, -1) for k in range(5)))
    return Scene(entities=[surface, box], topology=Topology(patches=patches))


def _models() -> list[Scene]:
    scenes = [geobrep.datasets.faulted_layer_cake(), _open_box()]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for path in sorted(DATA.glob("*.ml")):
            scenes.append(geobrep.read(path, repair=False))
    return scenes


def _variants(scene: Scene, rng: np.random.Generator) -> list[Block]:
    """The scene's blocks, and copies with some sides reversed or left out."""
    blocks = [b for b in scene.blocks if b.sides]
    out = list(blocks)
    for block in blocks:
        sides = list(block.sides)
        for k in rng.choice(len(sides), size=min(2, len(sides)), replace=False).tolist():
            sides[k] = PatchSide(sides[k].patch, -sides[k].side)  # type: ignore[arg-type]
        out.append(block.replace(sides=tuple(dict.fromkeys(sides))))
        if len(sides) > 2:
            out.append(block.replace(sides=tuple(block.sides[1:])))
    return [b for b in out if any(s.patch not in b.internal_patches for s in b.sides)]


@pytest.mark.parametrize("seed", [0, 1])
def test_patch_edges_answer_as_the_whole_shell(seed: int) -> None:
    rng = np.random.default_rng(seed)
    one_way = turned = own_open = 0
    for scene in _models():
        blocks = _variants(scene, rng)
        points, triangles_of = patch_triangles(scene, blocks)
        edges = patch_edges(triangles_of, int(points.shape[0]))
        assert edges is not None
        areas = _patch_areas(points, triangles_of)
        for block in blocks:
            shell = block_shell(points, triangles_of, block)
            expected = (
                int(boundary_edges(shell.faces).shape[0])
                if is_consistently_oriented(shell.faces)
                else None
            )
            found = open_edges_if_one_way(edges, block)
            assert found == expected, (scene.name, block.name)
            if found is None:
                turned += 1
                continue
            one_way += 1
            own_open += int(edges.own_open.sum() > 0)
            fast = _one_way_orientation(block, shell, areas, found)
            whole = _shell_orientation(block, shell)
            assert fast.sides == whole.sides
            assert fast.reversed_patches == whole.reversed_patches
            assert fast.open_edges == whole.open_edges
            assert fast.volume == whole.volume
    assert one_way  # shells that run one way
    assert turned  # and shells with triangles to turn
    assert own_open  # and edges bounding one triangle that no other patch has


@pytest.mark.parametrize("step", [1, 3])
def test_patch_edges_of_the_arcs_incidence_are_those_of_the_sort(step: int) -> None:
    """Summarised from the incidence the corners and arcs were found on (every patch, or the
    patches but every third one), the edges are the ones the sort of their keys gives."""
    checked = conflicts = 0
    for scene in _models():
        surfaces = {int(s.id or 0): s for s in scene.surfaces}
        joined = corners_and_arcs_of(surfaces, scene.topology.patches)[3]
        assert joined is not None
        assert joined.incidence is not None
        bounds = np.searchsorted(joined.owners, np.arange(len(joined.patches) + 1))
        index_of = np.full(len(joined.patches), -1, dtype=np.int64)
        triangles_of = {}
        for k, patch in enumerate(joined.patches):
            if step > 1 and k % step == 1:
                continue
            index_of[k] = len(triangles_of)
            triangles_of[patch.id] = joined.triangles[bounds[k] : bounds[k + 1]]
        n_points = int(joined.points.shape[0])
        expected = patch_edges(triangles_of, n_points)
        found = patch_edges_of_incidence(
            list(triangles_of), index_of, joined.triangles, joined.incidence, n_points
        )
        assert expected is not None
        assert found is not None
        assert found.position == expected.position
        for name in expected._fields[1:]:
            mine, theirs = getattr(found, name), getattr(expected, name)
            assert mine.dtype == theirs.dtype, (scene.name, name)
            assert np.array_equal(mine, theirs), (scene.name, name)
        checked += 1
        conflicts += int(expected.own_conflict.any())
        if len(triangles_of) < 2:
            continue
        # patches out of order: left to the sort
        backwards = np.where(index_of >= 0, len(triangles_of) - 1 - index_of, -1)
        assert (
            patch_edges_of_incidence(
                list(triangles_of), backwards, joined.triangles, joined.incidence, n_points
            )
            is None
        )
    assert checked > 3
    assert conflicts  # some patches use an own edge twice one way
