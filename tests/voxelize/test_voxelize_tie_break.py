"""Rays through edges and vertices: the top-left rule counts each crossing exactly once."""

from __future__ import annotations

import numpy as np
import pytest
import voxel_bodies as vb
from hypothesis import given
from hypothesis import strategies as st

from geobrep.ops.voxelization import voxelize
from geobrep.plugins.voxelize._rasterize import ray_crossings


def all_counts(vertices: np.ndarray, faces: np.ndarray, resolution: int) -> list[np.ndarray]:
    return [ray_crossings(vertices, faces, axis, resolution).counts() for axis in range(3)]


def test_shared_edge_through_pixel_centres_is_counted_once() -> None:
    # Two triangles of a unit square [0.5, 2.5]² at z = 1: the diagonal passes through the
    # pixel centres (0.5, 0.5), (1.5, 1.5) and (2.5, 2.5); the sides pass through centres too.
    square = np.array([[0.5, 0.5, 1.0], [2.5, 0.5, 1.0], [2.5, 2.5, 1.0], [0.5, 2.5, 1.0]])
    faces = np.array([[0, 1, 2], [0, 2, 3]])
    counts = ray_crossings(square, faces, axis=2, resolution=4).counts()
    # Half-open square: the left and bottom sides own their centres, right and top do not.
    expected = np.zeros((4, 4), dtype=np.int64)
    expected[0:2, 0:2] = 1
    np.testing.assert_array_equal(counts, expected)
    # The same square wound the other way (seen from below) covers the same pixels.
    flipped = ray_crossings(square, faces[:, ::-1], axis=2, resolution=4)
    np.testing.assert_array_equal(flipped.counts(), expected)
    assert flipped.entering.all()
    assert not ray_crossings(square, faces, 2, 4).entering.any()


def test_fan_around_a_vertex_on_a_pixel_centre() -> None:
    # Six triangles around the vertex (1.5, 1.5): the ray through it hits exactly one.
    angles = np.linspace(0, 2 * np.pi, 7)[:-1] + 0.1
    ring = np.column_stack([1.5 + np.cos(angles), 1.5 + np.sin(angles), np.zeros(6)])
    vertices = np.vstack([[1.5, 1.5, 0.0], ring])
    faces = np.array([[0, 1 + i, 1 + (i + 1) % 6] for i in range(6)])
    counts = ray_crossings(vertices, faces, axis=2, resolution=3).counts()
    assert counts[1, 1] == 1
    assert counts.max() == 1


def test_box_with_corners_on_voxel_centres() -> None:
    # Every face diagonal and every edge of this box runs through voxel centres.
    box = vb.box((0.5, 0.5, 0.5), (4.5, 4.5, 4.5))
    for counts in all_counts(box.vertices, box.faces, 8):
        assert set(np.unique(counts).tolist()) == {0, 2}
        assert int(np.count_nonzero(counts)) == 16  # the half-open square [0.5, 4.5)²
    for method in ("depth-buffer", "exact"):
        tree = voxelize(box, depth=3, method=method, origin=(0.0, 0.0, 0.0), size=8.0)
        # centres 0.5 ... 3.5 on each axis: exactly the octant [0, 4)³, one level-1 leaf
        assert tree.codes.tolist() == [0]
        assert tree.levels.tolist() == [1]


def test_octahedron_with_vertices_on_voxel_centres() -> None:
    octa = vb.octahedron((4.5, 4.5, 4.5), 3.0)
    counts = all_counts(octa.vertices, octa.faces, 8)
    for c in counts:
        assert set(np.unique(c).tolist()) <= {0, 2}  # convex: never 1, 3 or 4 crossings
    exact = voxelize(octa, depth=3, method="exact", origin=(0.0, 0.0, 0.0), size=8.0)
    buffers = voxelize(octa, depth=3, method="depth-buffer", origin=(0.0, 0.0, 0.0), size=8.0)
    centres = np.stack(np.meshgrid(*(np.arange(8) + 0.5,) * 3, indexing="ij"), -1).reshape(-1, 3)
    taxicab = np.abs(centres - 4.5).sum(axis=1)
    inside, outside, on_surface = taxicab < 3, taxicab > 3, taxicab == 3
    for tree in (exact, buffers):
        found = tree.contains(centres)
        assert found[inside].all()
        assert not found[outside].any()
    # Centres exactly on a slanted face are decided by a perturbation: the exact mode moves
    # them up along z (one consistent rule), each depth-buffer axis along its own ray.
    exact_on = exact.contains(centres[on_surface])
    assert np.array_equal(exact_on, centres[on_surface, 2] < 4.5)


@given(st.integers(0, 10_000))
def test_torus_snapped_to_voxel_centres_has_even_crossings(seed: int) -> None:
    # A coarse torus whose vertices are rounded to voxel centres: many rays run exactly through
    # its vertices and edges. Every ray must still cross the closed surface an even number of
    # times (a torus gave wrong columns without a tie-break rule).
    rng = np.random.default_rng(seed)
    torus = vb.torus(5.0, 2.0, around=int(rng.integers(6, 14)), tube=int(rng.integers(4, 9)))
    shift = rng.integers(0, 3, size=3)
    vertices = np.floor(torus.vertices + 8.0) + 0.5 + shift
    for counts in all_counts(vertices, torus.faces, 32):
        assert np.all(counts % 2 == 0)


@pytest.mark.parametrize("offset", [0.0, 450_000.0, 6_700_000.0])
def test_tie_break_survives_utm_offsets(offset: float) -> None:
    box = vb.box((0.5, 0.5, 0.5), (4.5, 4.5, 4.5))
    moved = box.replace(vertices=box.vertices + offset)
    tree = voxelize(moved, depth=3, method="exact", origin=(offset,) * 3, size=8.0)
    assert tree.codes.tolist() == [0]
    assert tree.levels.tolist() == [1]
