"""Closest-point projection, point-to-mesh distances, planar map inversion."""

from __future__ import annotations

import numpy as np
from fit_helpers import UTM, sphere_octant

from geobrep import NurbsSurface, Surface
from geobrep.geometry.nurbs import NurbsNet
from geobrep.plugins.fit._projection import invert_planar_map, project_points
from geobrep.plugins.fit.distance import (
    closest_points_on_triangles,
    mesh_distances,
    surface_distances,
)


def test_distances_to_a_rational_sphere_are_exact() -> None:
    radius = 10.0
    sphere = sphere_octant(radius=radius, centre=UTM)
    rng = np.random.default_rng(1)
    # points along rays through the octant, inside and outside the sphere
    direction = np.abs(rng.normal(size=(400, 3)))
    direction /= np.linalg.norm(direction, axis=1, keepdims=True)
    r = rng.uniform(5.0, 15.0, 400)
    points = UTM + direction * r[:, None]
    d = surface_distances(sphere, points)
    np.testing.assert_allclose(np.abs(d), np.abs(r - radius), atol=1e-8)
    # one consistent sign convention: the sign flips across the sphere
    assert len(np.unique(np.sign(d[r > radius + 0.01]))) == 1
    assert np.sign(d[r > radius + 0.01][0]) == -np.sign(d[r < radius - 0.01][0])


def test_projection_converges_from_poor_starting_parameters() -> None:
    sphere = sphere_octant(radius=1.0)
    p = np.array([[0.3, 0.4, 0.5], [0.9, 0.1, 0.2]]) * 3.0
    u, v, d = project_points(sphere, p, u0=np.array([0.95, 0.05]), v0=np.array([0.95, 0.95]))
    foot = sphere.evaluate(u, v)
    np.testing.assert_allclose(foot, p / np.linalg.norm(p, axis=1, keepdims=True), atol=1e-12)
    np.testing.assert_allclose(np.abs(d), np.linalg.norm(p, axis=1) - 1.0, atol=1e-12)


def test_points_beyond_the_edge_project_onto_it() -> None:
    net = np.zeros((2, 2, 3))
    net[1, :, 0] = 1.0
    net[:, 1, 1] = 1.0
    plate = NurbsSurface(
        degree_u=1, degree_v=1, knots_u=[0, 0, 1, 1], knots_v=[0, 0, 1, 1], control_points=net
    )
    u, v, d = project_points(plate, np.array([[2.0, 0.5, 0.0], [-1.0, -1.0, 1.0]]))
    assert u.tolist() == [1.0, 0.0]
    assert v.tolist() == [0.5, 0.0]
    np.testing.assert_allclose(d, [1.0, np.sqrt(3.0)])


def _brute_force(points: np.ndarray, vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    a, b, c = (vertices[faces[:, i]] for i in range(3))
    best = np.full(points.shape[0], np.inf)
    for i in range(faces.shape[0]):
        n = points.shape[0]
        foot = closest_points_on_triangles(
            points,
            np.repeat(a[i : i + 1], n, 0),
            np.repeat(b[i : i + 1], n, 0),
            np.repeat(c[i : i + 1], n, 0),
        )
        best = np.minimum(best, np.linalg.norm(points - foot, axis=1))
    return best


def test_closest_points_on_triangles_regions() -> None:
    a, b, c = np.zeros(3), np.array([1.0, 0, 0]), np.array([0, 1.0, 0])
    p = np.array(
        [[0.2, 0.2, 1], [-1, -1, 0], [2, -0.5, 0], [0.7, 0.7, 0], [-1, 0.5, 0], [0.5, -1, 3]]
    )
    n = len(p)
    got = closest_points_on_triangles(p, np.tile(a, (n, 1)), np.tile(b, (n, 1)), np.tile(c, (n, 1)))
    expected = [[0.2, 0.2, 0], [0, 0, 0], [1, 0, 0], [0.5, 0.5, 0], [0, 0.5, 0], [0.5, 0, 0]]
    np.testing.assert_allclose(got, expected, atol=1e-15)


def test_mesh_distances_match_brute_force() -> None:
    sphere = sphere_octant(radius=5.0, centre=UTM)
    mesh = sphere.tessellate(resolution=8)
    rng = np.random.default_rng(2)
    points = UTM + rng.uniform(-2.0, 7.0, (150, 3))
    d = mesh_distances(mesh, points)
    expected = _brute_force(points - UTM, mesh.vertices - UTM, mesh.faces)
    np.testing.assert_allclose(np.abs(d), expected, atol=1e-9)


def test_mesh_distances_sign_follows_the_normal() -> None:
    quad = Surface(vertices=[[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], faces=[[0, 1, 2, 3]])
    d = mesh_distances(quad, np.array([[0.5, 0.5, 2.0], [0.5, 0.5, -3.0]]))
    assert d.tolist() == [2.0, -3.0]


def test_invert_planar_map() -> None:
    # a curved planar map: a quarter annulus
    knots = np.array([0.0, 0.0, 0.0, 1.0, 1.0, 1.0])
    s = np.sqrt(0.5)
    net = np.zeros((3, 2, 3))
    arc = np.array([[1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    for j, radius in enumerate((1.0, 2.0)):
        net[:, j, :2] = arc * radius
    weights = np.array([[1.0, 1.0], [s, s], [1.0, 1.0]])
    annulus = NurbsNet(2, 1, knots, np.array([0.0, 0.0, 1.0, 1.0]), net, weights)
    rng = np.random.default_rng(0)
    angle = rng.uniform(0, np.pi / 2, 200)
    radius = rng.uniform(1.0, 2.0, 200)
    targets = np.column_stack([radius * np.cos(angle), radius * np.sin(angle)])
    _, v, off = invert_planar_map(annulus, targets)
    assert off.max() < 1e-10
    np.testing.assert_allclose(v, radius - 1.0, atol=1e-10)
