"""Tests for geobrep.geometry.mesh: known answers, a trimesh cross-check, property tests."""

from __future__ import annotations

import math

import numpy as np
import pytest
import trimesh
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.typing import NDArray
from scipy.sparse.csgraph import connected_components

from geobrep.errors import DegenerateGeometryError, EntityValidationError
from geobrep.geometry import (
    boundary_edges,
    edge_face_counts,
    edge_face_incidence,
    face_areas,
    face_centroids,
    face_normals,
    flip_faces,
    is_closed,
    is_consistently_oriented,
    merge_close_vertices,
    non_manifold_edges,
    signed_volume,
    sort_around_axis,
    surface_area,
    triangulate,
    unique_edges,
)

CUBE_VERTICES = np.array(
    [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]],
    dtype=np.float64,
)
# Outward-oriented quads: bottom, top, front (y=0), back (y=1), left (x=0), right (x=1).
CUBE_QUADS = np.array(
    [[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [3, 7, 6, 2], [0, 4, 7, 3], [1, 2, 6, 5]],
    dtype=np.int32,
)
CUBE_TRIANGLES = np.concatenate([CUBE_QUADS[:, [0, 1, 2]], CUBE_QUADS[:, [0, 2, 3]]])
CUBE_OUTWARD = np.array(
    [[0, 0, -1], [0, 0, 1], [0, -1, 0], [0, 1, 0], [-1, 0, 0], [1, 0, 0]], dtype=np.float64
)

TETRA_VERTICES = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=np.float64)
TETRA_FACES = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])

UTM = np.array([450_000.0, 6_700_000.0, -2_000.0])


# --------------------------------------------------------------------------- faces
def test_triangulate_quads_along_0_2_diagonal() -> None:
    tris, source = triangulate(np.array([[4, 5, 6, 7], [0, 1, 2, 3]], dtype=np.uint16))
    assert tris.tolist() == [[4, 5, 6], [4, 6, 7], [0, 1, 2], [0, 2, 3]]
    assert source.tolist() == [0, 0, 1, 1]
    assert tris.dtype == np.int64


def test_triangulate_triangles_is_identity() -> None:
    tris, source = triangulate(TETRA_FACES)
    assert tris.tolist() == TETRA_FACES.tolist()
    assert source.tolist() == [0, 1, 2, 3]


@pytest.mark.parametrize("faces", [CUBE_TRIANGLES, CUBE_QUADS], ids=["triangles", "quads"])
def test_unit_cube(faces: NDArray[np.int32]) -> None:
    assert signed_volume(CUBE_VERTICES, faces) == pytest.approx(1.0, rel=1e-15)
    assert surface_area(CUBE_VERTICES, faces) == pytest.approx(6.0, rel=1e-15)
    assert is_closed(faces)
    assert is_consistently_oriented(faces)
    edges, counts = edge_face_counts(faces)
    assert edges.shape[0] == (18 if faces.shape[1] == 3 else 12)
    assert (counts == 2).all()
    assert boundary_edges(faces).shape == (0, 2)
    assert non_manifold_edges(faces).shape == (0, 2)


def test_cube_quad_normals_centroids_areas() -> None:
    normals = face_normals(CUBE_VERTICES, CUBE_QUADS)
    np.testing.assert_array_equal(normals, CUBE_OUTWARD)
    vector_area = face_normals(CUBE_VERTICES, CUBE_QUADS, normalize=False)
    np.testing.assert_array_equal(vector_area, CUBE_OUTWARD)  # unit squares: |n| = area
    assert face_areas(CUBE_VERTICES, CUBE_QUADS).tolist() == [1.0] * 6
    centroids = face_centroids(CUBE_VERTICES, CUBE_QUADS)
    np.testing.assert_array_equal(centroids, 0.5 + 0.5 * CUBE_OUTWARD)


def test_cube_triangle_normals_point_outwards() -> None:
    normals = face_normals(CUBE_VERTICES, CUBE_TRIANGLES)
    np.testing.assert_array_equal(normals, np.concatenate([CUBE_OUTWARD, CUBE_OUTWARD]))
    np.testing.assert_allclose(face_areas(CUBE_VERTICES, CUBE_TRIANGLES), 0.5)


def test_flipping_one_face_breaks_orientation_not_closedness() -> None:
    for faces in (CUBE_TRIANGLES, CUBE_QUADS):
        broken = faces.copy()
        broken[2] = flip_faces(broken[2:3])[0]
        assert is_closed(broken)
        assert not is_consistently_oriented(broken)


def test_flip_all_faces_negates_volume_and_keeps_orientation() -> None:
    for faces in (CUBE_TRIANGLES, CUBE_QUADS):
        flipped = flip_faces(faces)
        assert signed_volume(CUBE_VERTICES, flipped) == pytest.approx(-1.0, rel=1e-15)
        assert is_consistently_oriented(flipped)
        np.testing.assert_array_equal(flip_faces(flipped), faces)
    assert flip_faces([[0, 1, 2, 3]]).tolist() == [[0, 3, 2, 1]]


def test_removing_a_face_breaks_closedness() -> None:
    for faces in (CUBE_TRIANGLES, CUBE_QUADS):
        opened = faces[1:]
        assert not is_closed(opened)
        assert is_consistently_oriented(opened)
        assert boundary_edges(opened).shape[0] == (3 if faces.shape[1] == 3 else 4)


def test_tetrahedron() -> None:
    assert signed_volume(TETRA_VERTICES, TETRA_FACES) == pytest.approx(1.0 / 6.0, rel=1e-15)
    area = surface_area(TETRA_VERTICES, TETRA_FACES)
    assert area == pytest.approx(1.5 + math.sqrt(3.0) / 2.0, rel=1e-15)
    assert is_closed(TETRA_FACES)
    assert is_consistently_oriented(TETRA_FACES)
    slanted = face_normals(TETRA_VERTICES, TETRA_FACES)[3]
    np.testing.assert_allclose(slanted, np.full(3, 1.0 / math.sqrt(3.0)), rtol=1e-15)


def test_utm_offset_kilometre_cube() -> None:
    vertices = UTM + 1000.0 * CUBE_VERTICES
    for faces in (CUBE_TRIANGLES, CUBE_QUADS):
        assert signed_volume(vertices, faces) == pytest.approx(1e9, rel=1e-12)
        assert surface_area(vertices, faces) == pytest.approx(6e6, rel=1e-12)
        np.testing.assert_allclose(
            face_centroids(vertices, CUBE_QUADS), UTM + 500.0 + 500.0 * CUBE_OUTWARD, rtol=1e-15
        )


def test_utm_offset_rotated_cube_needs_centring() -> None:
    # A rotated cube has inexact coordinates: without centring the volume is off by ~2e-10.
    th = 0.3
    rot = np.array([[math.cos(th), -math.sin(th), 0], [math.sin(th), math.cos(th), 0], [0, 0, 1]])
    vertices = np.array([450_123.456, 6_700_321.789, -2_000.5]) + 1000.0 * CUBE_VERTICES @ rot.T
    for faces in (CUBE_TRIANGLES, CUBE_QUADS):
        assert signed_volume(vertices, faces) == pytest.approx(1e9, rel=1e-12)
        assert surface_area(vertices, faces) == pytest.approx(6e6, rel=1e-12)


def test_non_manifold_edge() -> None:
    # Three triangles hanging off edge (0, 1).
    faces = np.array([[0, 1, 2], [1, 0, 3], [0, 1, 4]])
    assert non_manifold_edges(faces).tolist() == [[0, 1]]
    assert not is_closed(faces)
    assert not is_consistently_oriented(faces)
    # A closed cube plus a fin on one of its edges is no longer closed.
    vertices = np.vstack([CUBE_VERTICES, [[0.5, -1.0, 0.0]]])
    fin = np.vstack([CUBE_TRIANGLES, [[0, 1, 8]]])
    assert not is_closed(fin)
    assert non_manifold_edges(fin).tolist() == [[0, 1]]
    assert signed_volume(vertices, CUBE_TRIANGLES) == pytest.approx(1.0)


def test_degenerate_faces_give_zero_normals_not_nan() -> None:
    vertices = np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0], [1, 1, 0]], dtype=float)
    faces = np.array([[0, 1, 2], [0, 0, 3], [0, 1, 3]])
    normals = face_normals(vertices, faces)
    assert np.isfinite(normals).all()
    assert normals[:2].tolist() == [[0.0, 0.0, 0.0], [0.0, 0.0, 0.0]]
    assert normals[2].tolist() == [0.0, 0.0, 1.0]
    quad = face_normals(vertices, [[0, 1, 2, 1]])
    assert quad.tolist() == [[0.0, 0.0, 0.0]]


def test_unique_edges_layout() -> None:
    faces = np.array([[0, 1, 2], [2, 1, 3]], dtype=np.int8)
    edges, face_edges = unique_edges(faces)
    assert edges.tolist() == [[0, 1], [0, 2], [1, 2], [1, 3], [2, 3]]
    assert face_edges.tolist() == [[0, 2, 1], [2, 3, 4]]
    # Round trip: the sides of every face are its edges.
    sides = np.stack([faces, np.roll(faces, -1, axis=1)], axis=2)
    np.testing.assert_array_equal(np.sort(sides, axis=2), edges[face_edges])


def test_huge_vertex_indices_use_the_argsort_path() -> None:
    # Keys near 4e18 cannot be packed with positions: the argsort fallback must agree.
    small = np.array([[0, 1, 2], [2, 1, 3], [1, 2, 4]])
    huge = small * 500_000_000
    edges_small, face_edges_small = unique_edges(small)
    edges_huge, face_edges_huge = unique_edges(huge)
    np.testing.assert_array_equal(edges_huge, edges_small * 500_000_000)
    np.testing.assert_array_equal(face_edges_huge, face_edges_small)
    _, offsets, incident, sides = edge_face_incidence(huge)
    _, offsets_small, incident_small, sides_small = edge_face_incidence(small)
    np.testing.assert_array_equal(offsets, offsets_small)
    np.testing.assert_array_equal(incident, incident_small)
    np.testing.assert_array_equal(sides, sides_small)
    with pytest.raises(EntityValidationError, match="too large"):
        unique_edges([[0, 1, 4_000_000_000]])


def test_edge_face_incidence_csr() -> None:
    faces = np.array([[0, 1, 2], [2, 1, 3], [1, 2, 4]])
    edges, offsets, incident, sides = edge_face_incidence(faces)
    assert offsets[0] == 0
    assert offsets[-1] == faces.size
    e = edges.tolist().index([1, 2])
    span = slice(offsets[e], offsets[e + 1])
    assert incident[span].tolist() == [0, 1, 2]
    assert sides[span].tolist() == [1, 0, 0]
    # Every (face, side) pair points back at its edge.
    _, face_edges = unique_edges(faces)
    edge_of_entry = np.repeat(np.arange(edges.shape[0]), np.diff(offsets))
    np.testing.assert_array_equal(face_edges[incident, sides], edge_of_entry)


@pytest.mark.parametrize(("m", "k"), [(70_000, 3), (9_000, 4)])
def test_edge_face_incidence_matches_a_sorted_list(m: int, k: int) -> None:
    """Random faces (triangles across several key slices, quads): edges ascending, each with
    its (face, side) entries ascending, as a plain sort of the sides lists them."""
    faces = np.random.default_rng(m).integers(0, 5_000, (m, k))
    edges, offsets, incident, sides = edge_face_incidence(faces)
    ends = np.stack([faces, np.roll(faces, -1, axis=1)], axis=2)
    rows = sorted(
        (min(a, b), max(a, b), f, j)
        for f, face in enumerate(ends.tolist())
        for j, (a, b) in enumerate(face)
    )
    expected = np.array(rows, dtype=np.int64)
    edge_of_entry = np.repeat(np.arange(edges.shape[0]), np.diff(offsets))
    np.testing.assert_array_equal(edges[edge_of_entry], expected[:, :2])
    np.testing.assert_array_equal(incident, expected[:, 2])
    np.testing.assert_array_equal(sides, expected[:, 3])
    assert np.all(np.diff(offsets) > 0)


def test_empty_mesh() -> None:
    vertices = np.zeros((0, 3))
    for faces in (np.zeros((0, 3), dtype=np.int64), np.zeros((0, 4), dtype=np.int32)):
        k = faces.shape[1]
        tris, source = triangulate(faces)
        assert tris.shape == (0, 3)
        assert source.shape == (0,)
        assert face_normals(vertices, faces).shape == (0, 3)
        assert face_areas(vertices, faces).shape == (0,)
        assert face_centroids(vertices, faces).shape == (0, 3)
        assert surface_area(vertices, faces) == 0.0
        assert signed_volume(vertices, faces) == 0.0
        edges, face_edges = unique_edges(faces)
        assert edges.shape == (0, 2)
        assert face_edges.shape == (0, k)
        _, offsets, incident, _ = edge_face_incidence(faces)
        assert offsets.tolist() == [0]
        assert incident.shape == (0,)
        assert not is_closed(faces)
        assert is_consistently_oriented(faces)
        assert flip_faces(faces).shape == (0, k)


def test_validation_names_the_field() -> None:
    with pytest.raises(EntityValidationError, match="faces"):
        unique_edges(np.zeros((2, 5), dtype=int))
    with pytest.raises(EntityValidationError, match="integer"):
        is_closed(np.array([[0.0, 1.0, 2.0]]))
    with pytest.raises(EntityValidationError, match="negative"):
        triangulate([[0, -1, 2]])
    with pytest.raises(EntityValidationError, match="out of range"):
        signed_volume(TETRA_VERTICES, [[0, 1, 4]])
    with pytest.raises(EntityValidationError, match="vertices"):
        face_areas(np.zeros((3, 2)), [[0, 1, 2]])
    with pytest.raises(EntityValidationError, match="tolerance"):
        merge_close_vertices(TETRA_VERTICES, -1.0)


# --------------------------------------------------------------------------- trimesh
def test_icosphere_matches_trimesh() -> None:
    sphere = trimesh.creation.icosphere(subdivisions=3, radius=250.0)
    vertices = np.asarray(sphere.vertices) + UTM
    faces = np.array(sphere.faces)
    local = np.asarray(sphere.vertices)
    assert signed_volume(vertices, faces) == pytest.approx(sphere.volume, rel=1e-12)
    assert surface_area(vertices, faces) == pytest.approx(sphere.area, rel=1e-12)
    assert sphere.is_watertight
    assert sphere.is_winding_consistent
    assert is_closed(faces)
    assert is_consistently_oriented(faces)
    np.testing.assert_allclose(face_normals(local, faces), sphere.face_normals, atol=1e-12)
    np.testing.assert_allclose(face_areas(local, faces), sphere.area_faces, rtol=1e-12)
    edges, _ = unique_edges(faces)
    reference = np.unique(np.sort(sphere.edges_unique, axis=1), axis=0)
    np.testing.assert_array_equal(edges, reference)
    # Break it the way trimesh sees it too.
    faces[7] = faces[7, ::-1]
    assert not trimesh.Trimesh(local, faces, process=False).is_winding_consistent
    assert not is_consistently_oriented(faces)
    assert is_closed(faces)


def test_box_matches_trimesh() -> None:
    box = trimesh.creation.box(extents=(3.0, 4.0, 5.0))
    vertices = np.asarray(box.vertices)
    faces = np.asarray(box.faces)
    assert signed_volume(vertices, faces) == pytest.approx(60.0, rel=1e-14)
    assert signed_volume(vertices, faces) == pytest.approx(box.volume, rel=1e-14)
    assert surface_area(vertices, faces) == pytest.approx(box.area, rel=1e-14)
    assert is_closed(faces)
    assert is_consistently_oriented(faces)


# --------------------------------------------------------------------------- property tests
unit = st.floats(min_value=-1.0, max_value=1.0, allow_nan=False)
quaternion = st.tuples(unit, unit, unit, unit).filter(lambda q: math.hypot(*q) > 0.1)


def _rotation(q: tuple[float, float, float, float]) -> NDArray[np.float64]:
    w, x, y, z = np.asarray(q) / math.hypot(*q)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


_SPHERE = trimesh.creation.icosphere(subdivisions=2, radius=100.0)
_SPHERE_VOLUME = signed_volume(_SPHERE.vertices, _SPHERE.faces)


@settings(max_examples=40, deadline=None)
@given(
    q=quaternion,
    shift=st.tuples(st.floats(-1e6, 1e6), st.floats(-1e7, 1e7), st.floats(-5e3, 5e3)),
)
def test_rigid_transforms_keep_volume_and_area(
    q: tuple[float, float, float, float], shift: tuple[float, float, float]
) -> None:
    rot = _rotation(q)
    vertices = np.asarray(_SPHERE.vertices) @ rot.T + (UTM + shift)
    faces = np.asarray(_SPHERE.faces)
    assert signed_volume(vertices, faces) == pytest.approx(_SPHERE_VOLUME, rel=1e-9)
    assert surface_area(vertices, faces) == pytest.approx(_SPHERE.area, rel=1e-9)
    # A mirror transform turns the volume negative.
    mirrored = vertices * np.array([-1.0, 1.0, 1.0])
    assert signed_volume(mirrored, faces) == pytest.approx(-_SPHERE_VOLUME, rel=1e-9)


@settings(max_examples=60, deadline=None)
@given(
    gaps=st.lists(st.floats(0.05, 1.0), min_size=1, max_size=8),
    start=st.floats(0.0, 2 * math.pi),
    heights=st.lists(st.floats(-3.0, 3.0), min_size=9, max_size=9),
    scales=st.lists(st.floats(0.1, 10.0), min_size=9, max_size=9),
    q=quaternion,
    perm_seed=st.integers(0, 2**32 - 1),
    flip_axis=st.booleans(),
)
def test_sort_around_axis_random_layouts(
    gaps: list[float],
    start: float,
    heights: list[float],
    scales: list[float],
    q: tuple[float, float, float, float],
    perm_seed: int,
    flip_axis: bool,
) -> None:
    # Known layout: counter-clockwise angles around +z with the given gaps (total < 2π).
    angles = start + np.cumsum([0.0, *gaps])
    k = len(angles)
    if angles[-1] - angles[0] > 2 * math.pi - 0.05:
        angles = angles[0] + (angles - angles[0]) * (2 * math.pi - 0.1) / (angles[-1] - angles[0])
    perm = np.random.default_rng(perm_seed).permutation(k)
    local = (
        np.stack([np.cos(angles), np.sin(angles), np.asarray(heights[:k])], axis=1)
        * np.asarray(scales[:k])[:, None]
    )
    rot = _rotation(q)
    directions = local[perm] @ rot.T
    axis = rot @ np.array([0.0, 0.0, 2.0])
    origin = UTM
    order = sort_around_axis(origin, -axis if flip_axis else axis, directions)
    # Expected: ccw around +z from direction 0 (the element of rank perm[0]); clockwise if flipped.
    rank = perm  # directions[i] has layout rank perm[i]
    step = -1 if flip_axis else 1
    expected_ranks = [(perm[0] + step * j) % k for j in range(k)]
    assert rank[order].tolist() == expected_ranks
    assert order[0] == 0


def test_sort_around_axis_known_and_errors() -> None:
    dirs = [[1, 0, 5], [0, -1, 0], [0, 1, -2], [-1, 0, 0], [1, 1, 0]]
    assert sort_around_axis((0, 0, 0), (0, 0, 1), dirs).tolist() == [0, 4, 2, 3, 1]
    assert sort_around_axis((0, 0, 0), (0, 0, -1), dirs).tolist() == [0, 1, 3, 2, 4]
    assert sort_around_axis((0, 0, 0), (0, 0, 1), np.zeros((0, 3))).shape == (0,)
    with pytest.raises(DegenerateGeometryError, match=r"directions \[1\]"):
        sort_around_axis((0, 0, 0), (0, 0, 1), [[1, 0, 0], [0, 0, 3]])
    with pytest.raises(DegenerateGeometryError, match="axis"):
        sort_around_axis((0, 0, 0), (0, 0, 0), [[1, 0, 0]])
    with pytest.raises(EntityValidationError, match="directions"):
        sort_around_axis((0, 0, 0), (0, 0, 1), [1, 0, 0])


def _merge_reference(
    vertices: NDArray[np.float64], tolerance: float
) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """O(N²) reference: components of the distance ≤ tolerance graph, lowest index kept."""
    n = vertices.shape[0]
    dist = np.linalg.norm(vertices[:, None, :] - vertices[None, :, :], axis=2)
    _, labels = connected_components(dist <= tolerance, directed=False)
    representatives: list[int] = []
    inverse = np.empty(n, dtype=np.int64)
    slot_of_label: dict[int, int] = {}
    for i in range(n):
        label = int(labels[i])
        if label not in slot_of_label:
            slot_of_label[label] = len(representatives)
            representatives.append(i)
        inverse[i] = slot_of_label[label]
    return vertices[representatives], inverse


@settings(max_examples=80, deadline=None)
@given(
    cells=st.lists(st.tuples(*[st.integers(0, 6)] * 3), min_size=0, max_size=40),
    tolerance=st.sampled_from([0.0, 0.15, 0.25, 0.35]),
    offset=st.sampled_from([0.0, 1.0]),
)
def test_merge_close_vertices_matches_brute_force(
    cells: list[tuple[int, int, int]], tolerance: float, offset: float
) -> None:
    # Grid spacing 0.1: squared distances are multiples of 0.01, never equal to tolerance².
    vertices = np.asarray(cells, dtype=np.float64).reshape(-1, 3) * 0.1 + offset * UTM
    unique, inverse = merge_close_vertices(vertices, tolerance)
    ref_unique, ref_inverse = _merge_reference(vertices, tolerance)
    np.testing.assert_array_equal(unique, ref_unique)
    np.testing.assert_array_equal(inverse, ref_inverse)
    assert inverse.dtype == np.int64


@pytest.mark.parametrize(("n", "tolerance"), [(500, 1e-2), (30_000, 1e-2), (30_000, 0.1)])
def test_merge_close_vertices_matches_a_kd_tree(n: int, tolerance: float) -> None:
    """Scattered points with exact copies, close pairs and chains (few candidates: the sweep;
    at 0.1 every cube is crowded and 36,000 go to the hashed grid): the groups of a k-d
    tree's pairs within tolerance."""
    from scipy.sparse import coo_matrix
    from scipy.spatial import cKDTree

    rng = np.random.default_rng(n)
    base = rng.random((n, 3)) * [2000.0, 1500.0, 300.0] + [450_000.0, 6_700_000.0, 0.0]
    copies = base[rng.integers(0, n, n // 5)]
    near = base[rng.integers(0, n, n // 5)] + rng.normal(0.0, 4e-3, (n // 5, 3))
    chain = base[:1] + np.arange(1, 6)[:, None] * [9e-3, 0.0, 0.0]
    vertices = rng.permutation(np.concatenate([base, copies, near, chain]))
    unique, inverse = merge_close_vertices(vertices, tolerance)
    pairs = cKDTree(vertices).query_pairs(tolerance, output_type="ndarray")
    m = vertices.shape[0]
    graph = coo_matrix((np.ones(pairs.shape[0]), (pairs[:, 0], pairs[:, 1])), shape=(m, m))
    _, labels = connected_components(graph, directed=False)
    _, first, ref_inverse = np.unique(labels, return_index=True, return_inverse=True)
    rank = np.argsort(np.argsort(first))
    np.testing.assert_array_equal(inverse, rank[ref_inverse])
    np.testing.assert_array_equal(unique, vertices[np.sort(first)])


def test_merge_close_vertices_known_answer() -> None:
    vertices = np.array(
        [[5, 0, 0], [0, 0, 0], [5, 0, 1e-4], [0, 0, -0.0], [0, 0, 2e-4], [9, 9, 9], [0, 0, 1e-4]]
    ) + np.array([450_000.0, 6_700_000.0, 0.0])
    unique, inverse = merge_close_vertices(vertices, 1.5e-4)
    # 4 is 2e-4 from 1 but joins its group through 6 (single linkage); -0.0 equals 0.0.
    assert inverse.tolist() == [0, 1, 0, 1, 1, 2, 1]
    np.testing.assert_array_equal(unique, vertices[[0, 1, 5]])
    unique0, inverse0 = merge_close_vertices(vertices, 0.0)
    assert inverse0.tolist() == [0, 1, 2, 1, 3, 4, 5]
    np.testing.assert_array_equal(unique0, vertices[[0, 1, 2, 4, 5, 6]])
    empty, empty_inverse = merge_close_vertices(np.zeros((0, 3)), 1.0)
    assert empty.shape == (0, 3)
    assert empty_inverse.shape == (0,)


@pytest.mark.slow
def test_edge_kernels_on_a_million_triangles() -> None:
    n = 708  # (n - 1)² · 2 ≈ 1.0M triangles
    i, j = np.meshgrid(np.arange(n - 1), np.arange(n - 1), indexing="ij")
    v0 = (i * n + j).ravel()
    faces = np.concatenate(
        [np.stack([v0, v0 + n, v0 + n + 1], 1), np.stack([v0, v0 + n + 1, v0 + 1], 1)]
    )
    faces = faces[np.random.default_rng(0).permutation(faces.shape[0])]
    edges, _ = unique_edges(faces)
    assert edges.shape[0] == 3 * (n - 1) ** 2 + 2 * (n - 1)
    assert not is_closed(faces)
    assert is_consistently_oriented(faces)


@pytest.mark.parametrize("chunk", [1, 7, 1 << 18])
def test_signed_volume_in_chunks_is_trimeshs(chunk: int, monkeypatch: pytest.MonkeyPatch) -> None:
    from geobrep.geometry import mesh

    monkeypatch.setattr(mesh, "_VOLUME_CHUNK", chunk)  # the corners gathered a chunk at a time
    sphere = trimesh.creation.icosphere(subdivisions=3, radius=250.0)
    vertices = np.asarray(sphere.vertices) + np.array([4.5e5, 6.1e6, -1.2e3])  # UTM scale
    faces = np.asarray(sphere.faces)
    assert signed_volume(vertices, faces) == pytest.approx(sphere.volume, rel=1e-12)
    assert signed_volume(vertices, faces[:, ::-1]) == pytest.approx(-sphere.volume, rel=1e-12)


def test_incidence_and_orientation_of_large_shuffled_meshes() -> None:
    """Faces in no order (the packed quicksort path) give the incidence of a plain lexsort;
    one repeated directed edge among many makes the mesh inconsistently oriented."""
    from geobrep.geometry.mesh import edge_face_incidence, is_consistently_oriented

    rng = np.random.default_rng(5)
    faces = rng.permutation(4000)[:, None] + np.array([0, 1, 2])
    faces = rng.permutation(faces)  # no runs of ascending first vertices
    edges, offsets, fs, sides = edge_face_incidence(faces)
    start = faces.reshape(-1)
    end = faces[:, [1, 2, 0]].reshape(-1)
    low, high = np.minimum(start, end), np.maximum(start, end)
    order = np.lexsort((np.arange(low.shape[0]), high, low))
    assert np.array_equal(fs, order // 3)
    assert np.array_equal(sides, order % 3)
    starts = np.flatnonzero(np.r_[True, np.diff(low[order] * 10**6 + high[order]) != 0])
    assert np.array_equal(offsets, np.r_[starts, order.shape[0]])
    assert np.array_equal(edges, np.column_stack([low[order][starts], high[order][starts]]))
    grid = np.arange(100 * 100).reshape(100, 100)
    a, b, c, d = (
        grid[:-1, :-1].ravel(),
        grid[:-1, 1:].ravel(),
        grid[1:, :-1].ravel(),
        grid[1:, 1:].ravel(),
    )
    mesh_faces = rng.permutation(
        np.concatenate([np.column_stack([a, b, c]), np.column_stack([b, d, c])])
    )
    assert is_consistently_oriented(mesh_faces)
    mesh_faces[0] = mesh_faces[0, ::-1]
    assert not is_consistently_oriented(mesh_faces)
