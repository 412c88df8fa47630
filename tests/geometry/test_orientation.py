"""orientation_flips: consistent winding of face soups, checked against trimesh and by hand."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from geobrep.geometry.mesh import flip_faces, is_consistently_oriented, signed_volume
from geobrep.geometry.orientation import orientation_flips


def _sphere() -> tuple[np.ndarray, np.ndarray]:
    trimesh = pytest.importorskip("trimesh")
    sphere = trimesh.creation.icosphere(subdivisions=3)
    return np.asarray(sphere.vertices, dtype=np.float64), np.asarray(sphere.faces, dtype=np.int64)


def _apply(faces: np.ndarray, flip: np.ndarray) -> np.ndarray:
    out = faces.copy()
    out[flip] = flip_faces(faces[flip])
    return out


@given(st.integers(min_value=0, max_value=2**32 - 1), st.floats(min_value=0.0, max_value=1.0))
def test_random_flips_are_undone_relative_to_the_root(seed: int, share: float) -> None:
    vertices, faces = _sphere()
    rng = np.random.default_rng(seed)
    scrambled = faces.copy()
    mask = rng.random(faces.shape[0]) < share
    scrambled[mask] = flip_faces(faces[mask])
    result = orientation_flips(scrambled)
    fixed = _apply(scrambled, result.flip)
    assert result.n_pieces == 1
    assert result.n_conflicts == 0
    assert is_consistently_oriented(fixed)
    assert not result.flip[0]  # the root keeps its winding
    expected = 1.0 if not mask[0] else -1.0
    volume = signed_volume(vertices, fixed)
    assert np.sign(volume) == expected
    assert abs(volume) == pytest.approx(abs(signed_volume(vertices, faces)), rel=1e-12)


def test_the_preferred_root_decides_each_piece() -> None:
    vertices, faces = _sphere()
    two = np.concatenate([faces, faces + vertices.shape[0]])
    scrambled = two.copy()
    scrambled[[5, len(faces) + 7]] = flip_faces(two[[5, len(faces) + 7]])
    result = orientation_flips(scrambled, roots=[5, len(faces) + 3])
    assert result.n_pieces == 2
    assert not result.flip[5]
    assert not result.flip[len(faces) + 3]
    fixed = _apply(scrambled, result.flip)
    first, second = fixed[: len(faces)], fixed[len(faces) :]
    # piece 1 follows its root, face 5, which was flipped; piece 2 its unflipped face 3
    assert np.array_equal(first, flip_faces(faces))
    assert np.array_equal(second, faces + vertices.shape[0])


def test_a_moebius_strip_reports_its_conflict() -> None:
    n = 8  # a strip of 2n triangles, closed with a half twist
    top = np.arange(n)
    bottom = np.arange(n, 2 * n)
    faces = []
    for i in range(n - 1):
        faces += [[top[i], bottom[i], top[i + 1]], [top[i + 1], bottom[i], bottom[i + 1]]]
    faces += [[top[-1], bottom[-1], bottom[0]], [bottom[0], bottom[-1], top[0]]]  # the twist
    result = orientation_flips(np.array(faces))
    assert result.n_pieces == 1
    assert result.n_conflicts >= 1


def test_matches_trimesh_fix_winding() -> None:
    trimesh = pytest.importorskip("trimesh")
    vertices, faces = _sphere()
    rng = np.random.default_rng(3)
    mask = rng.random(faces.shape[0]) < 0.4
    mask[0] = False
    scrambled = faces.copy()
    scrambled[mask] = flip_faces(faces[mask])
    ours = _apply(scrambled, orientation_flips(scrambled).flip)
    theirs = trimesh.Trimesh(vertices, scrambled, process=False)
    trimesh.repair.fix_winding(theirs)
    theirs_faces = np.asarray(theirs.faces)
    assert is_consistently_oriented(theirs_faces)
    # the same winding as trimesh's, face by face (up to a rotation of each face's corners)
    ours_normals = np.cross(
        vertices[ours[:, 1]] - vertices[ours[:, 0]], vertices[ours[:, 2]] - vertices[ours[:, 0]]
    )
    theirs_normals = np.cross(
        vertices[theirs_faces[:, 1]] - vertices[theirs_faces[:, 0]],
        vertices[theirs_faces[:, 2]] - vertices[theirs_faces[:, 0]],
    )
    agree = np.einsum("ij,ij->i", ours_normals, theirs_normals) > 0
    assert agree.all() or not agree.any()


def test_non_manifold_edges_do_not_join_faces() -> None:
    faces = np.array([[0, 1, 2], [1, 0, 3], [0, 1, 4]])  # three faces on edge (0, 1)
    result = orientation_flips(faces)
    assert result.n_pieces == 3
    assert not result.flip.any()


def test_empty() -> None:
    result = orientation_flips(np.zeros((0, 3), dtype=np.int64))
    assert result.n_pieces == 0
    assert result.flip.shape == (0,)
