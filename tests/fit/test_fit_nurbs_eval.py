"""The vectorised NURBS core: basis functions, evaluation against geomdl, tessellation."""

from __future__ import annotations

import numpy as np
import pytest
from fit_helpers import UTM, geomdl_twin, random_knots, random_surface, sphere_octant
from hypothesis import given
from hypothesis import strategies as st

from geobrep import NurbsSurface
from geobrep.errors import EntityValidationError
from geobrep.geometry.nurbs import (
    NurbsNet,
    basis_derivatives,
    basis_functions,
    basis_matrix,
    find_spans,
    greville_abscissae,
    surface_derivatives,
    surface_grid,
    surface_points,
)


@given(
    degree=st.integers(1, 5),
    extra=st.integers(0, 8),
    seed=st.integers(0, 2**31 - 1),
)
def test_basis_is_a_partition_of_unity(degree: int, extra: int, seed: int) -> None:
    rng = np.random.default_rng(seed)
    knots = random_knots(rng, degree, degree + 1 + extra)
    t = np.r_[rng.uniform(0, 1, 50), knots]  # including every knot value
    values = basis_functions(degree, knots, find_spans(degree, knots, t), t)
    assert np.all(values >= -1e-15)
    np.testing.assert_allclose(values.sum(axis=1), 1.0, atol=1e-14)


def test_basis_derivatives_match_finite_differences() -> None:
    rng = np.random.default_rng(4)
    knots = np.array([0, 0, 0, 0, 0.2, 0.5, 0.7, 1, 1, 1, 1], dtype=float)
    t = rng.uniform(0.01, 0.99, 40)
    t = t[np.min(np.abs(t[:, None] - knots[None, :]), axis=1) > 1e-3]
    h = 1e-6
    for order in (1, 2):
        exact = basis_matrix(3, knots, t, derivative=order)
        lower = basis_matrix(3, knots, t - h, derivative=order - 1)
        upper = basis_matrix(3, knots, t + h, derivative=order - 1)
        np.testing.assert_allclose(exact, (upper - lower) / (2 * h), atol=1e-5 * 10**order)
    assert np.all(
        basis_derivatives(2, knots[1:-1], find_spans(2, knots[1:-1], t), t, 4)[:, 3:] == 0
    )


def test_greville_abscissae_reproduce_linear_functions() -> None:
    knots = np.array([0, 0, 0, 0, 0.1, 0.45, 0.5, 1, 1, 1, 1], dtype=float)
    g = greville_abscissae(3, knots)
    t = np.linspace(0, 1, 33)
    np.testing.assert_allclose(
        basis_matrix(3, knots, t) @ (2.0 * g - 1.0), 2.0 * t - 1.0, atol=1e-14
    )


@pytest.mark.parametrize("rational", [False, True])
def test_evaluation_matches_geomdl_on_random_surfaces(rational: bool) -> None:
    rng = np.random.default_rng(11 if rational else 7)
    for _ in range(6):
        surface = random_surface(rng, rational)
        twin = geomdl_twin(surface)
        uv = np.vstack([rng.uniform(0, 1, (300, 2)), [[0, 0], [1, 1], [0, 1], [1, 0]]])
        uv[:2] = [surface.knots_u[surface.degree_u + 1], surface.knots_v[surface.degree_v + 1]]
        expected = np.asarray(twin.evaluate_list(uv.tolist()))
        got = surface.evaluate(uv[:, 0], uv[:, 1])
        assert np.abs(got - expected).max() <= 1e-12
        derivatives = surface.derivatives(uv[:40, 0], uv[:40, 1], order=2)
        for row, (u, v) in enumerate(uv[:40]):
            reference = np.asarray(twin.derivatives(float(u), float(v), order=2))
            for k in range(3):
                for j in range(3 - k):
                    scale = max(1.0, float(np.abs(reference[k, j]).max()))
                    assert np.abs(derivatives[row, k, j] - reference[k, j]).max() <= 1e-12 * scale


def test_grid_evaluation_equals_pointwise() -> None:
    rng = np.random.default_rng(3)
    s = random_surface(rng, rational=True)
    net = NurbsNet(s.degree_u, s.degree_v, s.knots_u, s.knots_v, s.control_points, s.weights)
    u, v = rng.uniform(0, 1, 9), rng.uniform(0, 1, 7)
    grid = surface_grid(net, u, v)
    points = surface_points(net, np.repeat(u, 7), np.tile(v, 9))
    np.testing.assert_allclose(grid.reshape(-1, 3), points, atol=1e-14)
    assert surface_derivatives(
        net, u, v[:9] if v.size >= 9 else np.r_[v, v][:9], order=1
    ).shape == (9, 2, 2, 3)


def test_rational_sphere_is_exact() -> None:
    sphere = sphere_octant(radius=2.0)
    rng = np.random.default_rng(0)
    points = sphere.evaluate(rng.uniform(0, 1, 500), rng.uniform(0, 1, 500))
    np.testing.assert_allclose(np.linalg.norm(points, axis=1), 2.0, atol=1e-14)


class TestTessellate:
    def test_resolution(self) -> None:
        s = sphere_octant(radius=1.0)
        mesh = s.tessellate(resolution=(5, 7))
        assert mesh.n_vertices == 35
        assert mesh.n_faces == 2 * 4 * 6
        assert mesh.metadata["grid_shape"] == [5, 7]
        np.testing.assert_allclose(np.linalg.norm(mesh.vertices, axis=1), 1.0, atol=1e-14)
        assert mesh.is_consistently_oriented
        # faces follow S_u × S_v: on the sphere octant this is the outward normal up to sign
        centres = mesh.vertices[mesh.faces].mean(axis=1)
        side = np.sign(np.einsum("ij,ij->i", mesh.face_normals, centres))
        proper = mesh.face_areas > 1e-12  # the pole is a collapsed edge: its triangles are flat
        assert proper.sum() == 42
        assert abs(side[proper].sum()) == proper.sum()

    @pytest.mark.parametrize("tolerance", [1e-2, 1e-3])
    def test_tolerance_is_met(self, tolerance: float) -> None:
        s = sphere_octant(radius=100.0)
        mesh = s.tessellate(tolerance=tolerance)
        assert mesh.metadata["deviation"] <= tolerance
        # check independently: midpoints of random mesh edges lie within tolerance of the sphere
        edges = mesh.vertices[mesh.faces[:, [0, 1]]]
        mid = edges.mean(axis=1)
        assert np.abs(np.linalg.norm(mid, axis=1) - 100.0).max() <= tolerance
        coarser = s.tessellate(tolerance=tolerance * 100)
        assert coarser.n_vertices < mesh.n_vertices

    def test_utm_coordinates_keep_precision(self) -> None:
        s = sphere_octant(radius=50.0, centre=UTM)
        mesh = s.tessellate(resolution=9)
        np.testing.assert_allclose(np.linalg.norm(mesh.vertices - UTM, axis=1), 50.0, atol=1e-8)

    def test_knot_lines_are_kept(self) -> None:
        rng = np.random.default_rng(5)
        s = random_surface(rng, rational=False)
        mesh = s.tessellate(tolerance=0.05)
        u = np.asarray(mesh.point_data["u"].values)
        for knot in np.unique(s.knots_u):
            assert np.any(np.isclose(u, knot, atol=0, rtol=0))

    def test_bad_requests(self) -> None:
        s = sphere_octant()
        with pytest.raises(EntityValidationError, match="resolution or tolerance"):
            s.tessellate(resolution=4, tolerance=0.1)
        with pytest.raises(EntityValidationError, match="tolerance must be > 0"):
            s.tessellate(tolerance=0.0)
        with pytest.raises(EntityValidationError, match="at least 2"):
            s.tessellate(resolution=1)


def test_domain_and_evaluate_on_entity() -> None:
    net = np.zeros((2, 2, 3))
    net[1, :, 0] = 1
    net[:, 1, 1] = 1
    s = NurbsSurface(
        degree_u=1, degree_v=1, knots_u=[2, 2, 4, 4], knots_v=[0, 0, 1, 1], control_points=net
    )
    assert s.domain == ((2.0, 4.0), (0.0, 1.0))
    np.testing.assert_allclose(s.evaluate([3.0], [0.5]), [[0.5, 0.5, 0.0]])


class TestNurbsNet:
    """The value type the evaluators take: checked once, derived values agree with the entity."""

    def test_a_surface_and_its_net_agree(self) -> None:
        rng = np.random.default_rng(8)
        for rational in (False, True):
            s = random_surface(rng, rational)
            net = s.net
            assert net.shape == s.shape
            assert net.domain == s.domain
            assert net.is_rational == s.is_rational
            assert (net.weights is None) == (not rational)
            uv = rng.uniform(0, 1, (50, 2))
            np.testing.assert_array_equal(
                surface_points(net, uv[:, 0], uv[:, 1]), s.evaluate(uv[:, 0], uv[:, 1])
            )

    def test_equal_weights_evaluate_as_a_b_spline(self) -> None:
        rng = np.random.default_rng(9)
        s = random_surface(rng, rational=False)
        plain = NurbsNet(s.degree_u, s.degree_v, s.knots_u, s.knots_v, s.control_points)
        weighted = NurbsNet(
            s.degree_u, s.degree_v, s.knots_u, s.knots_v, s.control_points, np.full(s.shape, 2.5)
        )
        assert not weighted.is_rational
        u, v = rng.uniform(0, 1, 30), rng.uniform(0, 1, 30)
        np.testing.assert_array_equal(surface_points(plain, u, v), surface_points(weighted, u, v))

    def test_centre_and_other_control_points(self) -> None:
        s = sphere_octant(radius=50.0, centre=UTM)
        net = s.net
        flat = s.control_points.reshape(-1, 3)
        np.testing.assert_array_equal(net.centre, 0.5 * (flat.min(axis=0) + flat.max(axis=0)))
        moved = net.with_control_points(net.control_points - net.centre)
        assert moved.weights is net.weights
        assert moved.knots_u is net.knots_u
        # about the centre, UTM-scale nets keep the precision of the local coordinates
        u, v = np.linspace(0, 1, 7), np.linspace(1, 0, 7)
        local = surface_points(moved, u, v) - (UTM - net.centre)
        np.testing.assert_allclose(np.linalg.norm(local, axis=1), 50.0, rtol=0, atol=1e-12)
        np.testing.assert_allclose(surface_points(moved, u, v) + net.centre, s.evaluate(u, v))

    def test_many_channels_for_points_only(self) -> None:
        k = np.array([0.0, 0.0, 1.0, 1.0])
        heights = np.array([[[0.0], [1.0]], [[2.0], [3.0]]])  # bilinear h = 2u + v
        net = NurbsNet(1, 1, k, k, heights)
        assert net.channels == 1
        assert surface_points(net, [0.5, 1.0], [0.5, 0.25]).tolist() == [[1.5], [2.25]]

    @pytest.mark.parametrize(
        ("change", "field", "reason"),
        [
            ({"control_points": np.zeros((3, 3))}, "control_points", "expected shape"),
            ({"knots_u": np.array([0.0, 0.0, 1.0])}, "knots_u", "has 3 values"),
            ({"knots_v": np.array([0.0, 0.0, 0.7, 0.5, 1.0, 1.0])}, "knots_v", "non-decreasing"),
            ({"degree_u": 3}, "control_points", "need degree <= 2"),
            ({"weights": np.ones((3, 2))}, "weights", "does not match"),
            (
                {"weights": np.array([[1.0, 1.0, 1.0]] * 2 + [[1.0, 0.0, 1.0]])},
                "weights",
                "positive",
            ),
        ],
    )
    def test_malformed_nets_are_refused(self, change: dict, field: str, reason: str) -> None:
        good: dict = {
            "degree_u": 1,
            "degree_v": 2,
            "knots_u": np.array([0.0, 0.0, 0.5, 1.0, 1.0]),
            "knots_v": np.array([0.0, 0.0, 0.0, 1.0, 1.0, 1.0]),
            "control_points": np.zeros((3, 3, 3)),
            "weights": None,
        }
        NurbsNet(**good)
        with pytest.raises(EntityValidationError, match=f"NurbsNet: {field}: .*{reason}"):
            NurbsNet(**{**good, **change})

    def test_the_entity_format_is_unchanged(self) -> None:
        s = sphere_octant(radius=2.0)
        dumped = s.model_dump()
        assert "net" not in dumped
        assert {"degree_u", "degree_v", "knots_u", "knots_v", "control_points", "weights"} <= set(
            dumped
        )
        again = NurbsSurface.model_validate(dumped)
        np.testing.assert_array_equal(again.net.control_points, s.net.control_points)
