"""Property tests: random planes through random closed meshes stay closed and conserve volume."""

from __future__ import annotations

import numpy as np
import pytest
from clip_shapes import assert_closed_half, cap_area
from hypothesis import given
from hypothesis import strategies as st

from geobrep import Plane, Surface
from geobrep.ops.clipping import clip

spherical = st.tuples(st.floats(-1.0, 1.0), st.floats(-1.0, 1.0), st.floats(-1.0, 1.0)).filter(
    lambda v: float(np.linalg.norm(v)) > 0.05
)


def _hull(seed: int, count: int) -> Surface:
    """A random convex polyhedron, outward-oriented (scipy's hull of random points)."""
    from scipy.spatial import ConvexHull

    points = np.random.default_rng(seed).normal(size=(count, 3))
    hull = ConvexHull(points)
    faces = hull.simplices.copy()
    centre = points[hull.vertices].mean(axis=0)
    normals = np.cross(
        points[faces[:, 1]] - points[faces[:, 0]], points[faces[:, 2]] - points[faces[:, 0]]
    )
    inward = np.einsum("ij,ij->i", normals, points[faces[:, 0]] - centre) < 0
    faces[inward] = faces[inward][:, ::-1]
    used, compact = np.unique(faces, return_inverse=True)
    return Surface(vertices=points[used], faces=compact.reshape(-1, 3))


def _star(seed: int) -> Surface:
    """A random star-shaped (non-convex) closed mesh: an icosphere with random radii."""
    import trimesh

    sphere = trimesh.creation.icosphere(subdivisions=2)
    radii = np.random.default_rng(seed).uniform(0.4, 1.6, size=len(sphere.vertices))
    return Surface(vertices=sphere.vertices * radii[:, None], faces=sphere.faces)


@given(
    seed=st.integers(0, 10_000),
    count=st.integers(5, 60),
    normal=spherical,
    offset=st.floats(-1.2, 1.2),
    star=st.booleans(),
)
def test_random_planes_through_random_closed_meshes(
    seed: int, count: int, normal: tuple[float, float, float], offset: float, star: bool
) -> None:
    surface = _star(seed) if star else _hull(seed, count)
    assert surface.is_closed
    assert surface.volume > 0
    plane = Plane.from_point_normal(np.array(normal) * offset, normal)
    negative, positive = clip(surface, plane, keep="both")
    volumes = []
    for half in (negative, positive):
        if half is not None:
            assert_closed_half(half)
            volumes.append(half.volume)
    assert sum(volumes) == pytest.approx(surface.volume, rel=1e-9)
    if negative is not None and positive is not None and "cap" in negative.patch_names:
        assert cap_area(negative) == pytest.approx(cap_area(positive), rel=1e-12)


@given(seed=st.integers(0, 10_000), axis=st.integers(0, 2), level=st.integers(-2, 2))
def test_planes_through_lattice_vertices(seed: int, axis: int, level: int) -> None:
    """Planes through many vertices at once (exact on-plane handling)."""
    rng = np.random.default_rng(seed)
    points = rng.integers(-3, 4, size=(40, 3)).astype(np.float64)
    points = np.unique(points, axis=0)
    if points.shape[0] < 5 or np.linalg.matrix_rank(points - points[0]) < 3:
        return
    from scipy.spatial import ConvexHull

    hull = ConvexHull(points)
    faces = hull.simplices.copy()
    centre = points[hull.vertices].mean(axis=0)
    normals = np.cross(
        points[faces[:, 1]] - points[faces[:, 0]], points[faces[:, 2]] - points[faces[:, 0]]
    )
    inward = np.einsum("ij,ij->i", normals, points[faces[:, 0]] - centre) < 0
    faces[inward] = faces[inward][:, ::-1]
    surface = Surface(vertices=points, faces=faces)
    coefficients = [0.0, 0.0, 0.0, -float(level)]
    coefficients[axis] = 1.0
    negative, positive = clip(surface, Plane(*coefficients), keep="both")
    volumes = [h.volume for h in (negative, positive) if h is not None]
    for half in (negative, positive):
        if half is not None:
            assert_closed_half(half)
    assert sum(volumes) == pytest.approx(surface.volume, rel=1e-9)


@given(
    seed=st.integers(0, 10_000),
    low=st.tuples(st.floats(-1.0, 0.2), st.floats(-1.0, 0.2), st.floats(-1.0, 0.2)),
    size=st.floats(0.3, 2.0),
)
def test_random_boxes_carve_closed_columns(
    seed: int, low: tuple[float, float, float], size: float
) -> None:
    """Successive cuts (cutting earlier caps, along their straight edges) stay closed."""
    from geobrep.ops.clipping import clip_box

    surface = _star(seed)
    lo = np.array(low)
    box = (lo[0], lo[0] + size, lo[1], lo[1] + size, lo[2], lo[2] + size)
    inside = clip_box(surface, box)
    if inside is not None:
        assert_closed_half(inside)
        # vertices within the clipper's default tolerance (1e-9 of the mesh's box diagonal)
        # of a plane count as on it, so they may stay where they are
        bounds = surface.bounds
        assert bounds is not None
        slack = 1e-9 * bounds.diagonal + 1e-12
        assert (inside.vertices >= lo - slack).all()
        assert (inside.vertices <= lo + size + slack).all()
