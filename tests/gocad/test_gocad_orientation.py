"""Model3d REGION signs, read in the z-up frame, agree with the geometry of real exports."""

from __future__ import annotations

import numpy as np
import pytest
from gocad_files import DATA, read_quietly

from geobrep import Surface


@pytest.mark.parametrize(("name", "boundary_patches"), [("modelA1.ml", 18), ("modelA4.ml", 32)])
def test_universe_sides_agree_with_the_outward_normal(name: str, boundary_patches: int) -> None:
    scene = read_quietly(DATA / name)
    universe = scene.universe
    assert universe is not None
    assert len(universe.sides) == boundary_patches
    box = scene.bounds
    assert box is not None
    centre = 0.5 * (np.asarray(box.mins) + np.asarray(box.maxs))
    for patch_id, side in universe.sides:
        patch = scene.topology.patch(patch_id)
        surface = scene[patch.surface]
        assert isinstance(surface, Surface)
        faces = surface.patch_faces(patch.label)
        vector_area = (surface.face_normals[faces] * surface.face_areas[faces][:, None]).sum(axis=0)
        centroid = surface.vertices[np.unique(surface.faces[faces])].mean(axis=0)
        outward = float(np.dot(vector_area, centroid - centre)) > 0
        # +k: the universe lies on the side the normal points to, i.e. the normal points out
        assert outward == (side == 1), f"{name}: patch {patch.name} side {side:+d}"


@pytest.mark.parametrize("name", ["modelA1.ml", "modelA4.ml"])
def test_every_block_is_closed_and_outward(name: str) -> None:
    scene = read_quietly(DATA / name)
    total = 0.0
    for block in scene.blocks:
        boundary = scene.block_mesh(block)
        assert boundary.is_closed
        assert boundary.is_consistently_oriented
        assert boundary.volume > 0
        total += boundary.volume
    assert scene.universe is not None
    shell = -scene.block_mesh(scene.universe).volume
    assert total == pytest.approx(shell, rel=1e-9)


def test_raw_depth_coordinates_would_read_every_side_backwards() -> None:
    """The same check on z as stored (depth) fails for every boundary patch."""
    scene = read_quietly(DATA / "modelA4.ml")
    assert scene.crs is not None
    assert scene.crs.z_positive == "down"
    universe = scene.universe
    assert universe is not None
    mirrored = []
    for surface in scene.surfaces:
        vertices = surface.vertices * np.array([1.0, 1.0, -1.0])
        mirrored.append(surface.replace(vertices=vertices))
    by_id = {s.id: s for s in mirrored}
    points = np.concatenate([s.vertices for s in mirrored])
    centre = 0.5 * (points.min(axis=0) + points.max(axis=0))
    agree = 0
    for patch_id, side in universe.sides:
        patch = scene.topology.patch(patch_id)
        surface = by_id[patch.surface]
        faces = surface.patch_faces(patch.label)
        vector_area = (surface.face_normals[faces] * surface.face_areas[faces][:, None]).sum(axis=0)
        centroid = surface.vertices[np.unique(surface.faces[faces])].mean(axis=0)
        agree += (float(np.dot(vector_area, centroid - centre)) > 0) == (side == 1)
    assert agree == 0
