"""Least squares: accuracy, ε-driven nets, smoothing, boundary curves, base surface."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
from fit_helpers import UTM

import geobrep
from geobrep import NurbsSurface, PointSet
from geobrep.datasets import dome_elevation
from geobrep.errors import DegenerateGeometryError, EntityValidationError, OptionsError
from geobrep.ops.fitting import fit
from geobrep.plugins.fit._design import normal_equations, surface_design_matrix
from geobrep.plugins.fit._knots import uniform_knots
from geobrep.plugins.fit.options import ApproximationOptions, BoundaryCurve


def smooth_points(n: int, noise: float = 0.0, seed: int = 0, hole: bool = False) -> np.ndarray:
    rng = np.random.default_rng(seed)
    xy = rng.uniform(0, 1000, (n, 2))
    if hole:
        xy = xy[np.hypot(xy[:, 0] - 500, xy[:, 1] - 500) > 220]
    z = dome_elevation(xy[:, 0], xy[:, 1]) + rng.normal(0, noise, xy.shape[0])
    return np.column_stack([xy, z]) + UTM


def grid_error(surface: NurbsSurface, mask_hole: bool = False) -> np.ndarray:
    mesh = surface.tessellate(resolution=80)
    local = mesh.vertices - UTM
    inside = np.all((local[:, :2] > 20) & (local[:, :2] < 980), axis=1)
    if mask_hole:
        inside &= np.hypot(local[:, 0] - 500, local[:, 1] - 500) < 200
    return np.asarray(local[inside, 2] - dome_elevation(local[inside, 0], local[inside, 1]))


def test_normal_equations_equal_the_design_matrix_products() -> None:
    rng = np.random.default_rng(0)
    ku, kv = uniform_knots(3, 5), uniform_knots(2, 4)
    u, v = rng.uniform(0, 1, 3000), rng.uniform(0, 1, 3000)
    y = rng.normal(size=(3000, 2))
    w = rng.uniform(0.5, 2.0, 3000)
    normal, rhs = normal_equations(3, 2, ku, kv, u, v, y, w)
    design = surface_design_matrix(3, 2, ku, kv, u, v)
    np.testing.assert_allclose(
        normal.toarray(), (design.T @ sp.diags(w) @ design).toarray(), atol=1e-11
    )
    np.testing.assert_allclose(rhs, design.T @ (w[:, None] * y), atol=1e-11)


def test_smooth_surface_is_reproduced() -> None:
    pts = smooth_points(3000)
    result = fit(pts, method="approximation", epsilon=0.05)
    assert result.report is not None
    assert result.report.passed
    assert result.report.sigma < 0.05
    assert not result.report.notes
    assert np.abs(grid_error(result.surface)).max() < 0.5
    assert result.distances is not None
    assert result.distances.shape == (3000,)


def test_epsilon_met_on_the_survey_data() -> None:
    points = geobrep.datasets.scattered_points()
    result = fit(points, method="approximation", epsilon=0.5)
    report = result.report
    assert report is not None
    assert report.passed
    assert report.sigma < 0.5
    assert report.epsilon == 0.5
    assert report.n == 600
    # the coarsest net that meets ε: far fewer control points than points
    nu, nv = result.surface.shape
    assert nu * nv < 600 / 2
    assert report.worst[0].distance == pytest.approx(
        max(result.distances, key=abs)  # type: ignore[arg-type]
    )


def test_epsilon_that_cannot_be_met_is_reported() -> None:
    pts = smooth_points(800, noise=1.0)
    result = fit(pts, method="approximation", epsilon=0.5)
    report = result.report
    assert report is not None
    assert report.passed is False
    assert report.sigma > 0.5
    assert any("cannot be met" in note for note in report.notes)
    nu, nv = result.surface.shape
    assert nu * nv <= 800 // 2  # it stopped at the finest net the data support


def test_smoothing_keeps_gaps_plausible() -> None:
    pts = smooth_points(2500, noise=0.1, hole=True)
    smooth = fit(pts, method="approximation", control_points=(24, 24))
    in_hole = np.abs(grid_error(smooth.surface, mask_hole=True)).max()
    assert in_hole < 25.0  # the dome's 80 m bump is missing from the data; no wild overshoot
    try:
        rough = fit(pts, method="approximation", control_points=(24, 24), smoothing=0.0)
    except DegenerateGeometryError:
        return  # without smoothing the hole leaves control points undetermined
    assert np.abs(grid_error(rough.surface, mask_hole=True)).max() > 2 * in_hole


class TestBoundaryCurves:
    @pytest.fixture(scope="class")
    @staticmethod
    def halves() -> tuple[np.ndarray, np.ndarray]:
        # both pieces span the seam's full length: survey lines run along y = 0 and y = 1000
        x = np.linspace(0.0, 1000.0, 41)
        edges = np.column_stack([np.r_[x, x], np.r_[np.zeros(41), np.full(41, 1000.0)]])
        edges = np.column_stack([edges, dome_elevation(edges[:, 0], edges[:, 1])]) + UTM
        pts = np.vstack([smooth_points(2000, noise=0.05, seed=3), edges])
        left = pts[pts[:, 0] - UTM[0] <= 500]
        right = pts[pts[:, 0] - UTM[0] >= 500]
        return left, right

    def test_pieces_join_without_a_gap(self, halves: tuple[np.ndarray, np.ndarray]) -> None:
        left_points, right_points = halves
        left = fit(left_points, method="approximation", epsilon=0.2).surface
        assert isinstance(left, NurbsSurface)
        curve = BoundaryCurve.from_surface(left, "u1")
        # the neighbour's edge is where its best-fit frame put it (x ≈ 500-506 m): the right
        # piece takes the points beyond that edge
        edge = left.evaluate(np.ones(200), np.linspace(0, 1, 200))
        beyond = right_points[:, 0] > np.interp(right_points[:, 1], edge[:, 1], edge[:, 0])
        right = fit(
            right_points[beyond], method="approximation", epsilon=0.2, boundary_curves={"u0": curve}
        )
        assert right.report is not None
        assert right.report.passed
        assert not right.report.notes
        assert isinstance(right.surface, NurbsSurface)
        t = np.linspace(0.0, 1.0, 301)
        seam_left = left.evaluate(np.ones_like(t), t)
        seam_right = right.surface.evaluate(np.zeros_like(t), t)
        assert np.linalg.norm(seam_left - seam_right, axis=1).max() <= 1e-9

    def test_degree_must_match(self, halves: tuple[np.ndarray, np.ndarray]) -> None:
        left = fit(halves[0], method="approximation", epsilon=0.5).surface
        assert isinstance(left, NurbsSurface)
        curve = BoundaryCurve.from_surface(left, "u1")
        with pytest.raises(OptionsError, match="degree_v is 2"):
            fit(halves[1], method="approximation", degree_v=2, boundary_curves={"u0": curve})

    def test_curves_must_meet_at_corners(self) -> None:
        a = BoundaryCurve(
            degree=1, knots=[0, 0, 1, 1], control_points=[UTM, UTM + np.array([0.0, 1000.0, 0.0])]
        )
        b = BoundaryCurve(
            degree=1,
            knots=[0, 0, 1, 1],
            control_points=[UTM + np.array([5.0, 0.0, 0.0]), UTM + np.array([1000.0, 0.0, 0.0])],
        )
        with pytest.raises(OptionsError, match="do not meet"):
            fit(
                smooth_points(300),
                method="approximation",
                degree_u=1,
                degree_v=1,
                boundary_curves={"u0": a, "v0": b},
            )

    def test_malformed_curve(self) -> None:
        with pytest.raises(OptionsError, match="knots"):
            fit(
                smooth_points(300),
                method="approximation",
                boundary_curves={"u0": {"degree": 3, "knots": [0, 1], "control_points": [UTM] * 4}},
            )


def test_base_surface_parameterisation_fits_an_overturned_fold() -> None:
    # a recumbent fold: a half-cylinder lying along y, multi-valued over every plane
    rng = np.random.default_rng(0)
    theta = rng.uniform(0.05, np.pi - 0.05, 1500)
    y = rng.uniform(0, 400, 1500)
    radius = 100 + 3 * np.sin(y / 40)
    pts = np.column_stack([radius * np.cos(theta), y, radius * np.sin(theta)]) + UTM
    s = np.sqrt(0.5)
    arc = np.array([[100, 0], [100, 100], [0, 100], [-100, 100], [-100, 0]], dtype=float)
    net = np.zeros((5, 2, 3))
    for j, yy in enumerate((0.0, 400.0)):
        net[:, j] = np.column_stack([arc[:, 0], np.full(5, yy), arc[:, 1]]) + UTM
    base = NurbsSurface(
        degree_u=2,
        degree_v=1,
        knots_u=[0, 0, 0, 0.5, 0.5, 1, 1, 1],
        knots_v=[0, 0, 1, 1],
        control_points=net,
        weights=np.array([[1, 1], [s, s], [1, 1], [s, s], [1, 1]]),
    )
    folded = fit(
        pts, method="approximation", parameterization="base_surface", base_surface=base, epsilon=0.1
    )
    assert folded.report is not None
    assert folded.report.passed
    flat = fit(pts, method="approximation", epsilon=0.1)
    assert flat.report is not None
    assert flat.report.sigma > 10 * folded.report.sigma


class TestBadInput:
    def test_too_few_points(self) -> None:
        with pytest.raises(OptionsError, match=r"degree_u.*10 points.*at least 16"):
            fit(smooth_points(10), method="approximation")

    def test_collinear_points(self) -> None:
        t = np.linspace(0, 1, 50)
        with pytest.raises(DegenerateGeometryError, match="line"):
            fit(np.column_stack([t, 2 * t, 3 * t]), method="approximation")

    def test_nan(self) -> None:
        pts = smooth_points(100)
        pts[7, 0] = np.nan
        with pytest.raises(EntityValidationError, match=r"vertices.*non-finite"):
            fit(PointSet(vertices=pts, name="survey"), method="approximation")

    def test_duplicates_are_harmless(self) -> None:
        pts = smooth_points(400)
        result = fit(np.vstack([pts, pts[:50]]), method="approximation", epsilon=0.5)
        assert result.report is not None
        assert result.report.passed

    def test_bad_options(self) -> None:
        pts = smooth_points(100)
        with pytest.raises(OptionsError, match=r"control_points.*too few"):
            fit(pts, method="approximation", control_points=(3, 3))
        with pytest.raises(OptionsError, match="base_surface"):
            fit(pts, method="approximation", parameterization="base_surface")
        with pytest.raises(OptionsError, match="epsilon"):
            fit(pts, method="approximation", epsilon=-1)
        with pytest.raises(OptionsError, match="smoothin"):
            fit(pts, method="approximation", smoothin=1.0)


class TestGrid:
    @staticmethod
    def grid(side: int = 40) -> np.ndarray:
        x, y = np.meshgrid(np.linspace(0, 1000, side), np.linspace(0, 800, side + 5), indexing="ij")
        rng = np.random.default_rng(4)
        z = dome_elevation(x, y) + rng.normal(0, 0.05, x.shape)
        return np.stack([x, y, z], axis=-1).reshape(-1, 3) + UTM

    def test_separable_solve_equals_general_least_squares(self) -> None:
        from geobrep.plugins.fit._approximation import approximate_points, solve_net
        from geobrep.plugins.fit._frame import LocalFrame

        points = self.grid()
        options = ApproximationOptions(control_points=(12, 14), smoothing=0.0, grid_shape=(40, 45))
        frame = LocalFrame.from_points(points)
        fitted = approximate_points(points, options, frame)
        general = solve_net(
            (3, 3),
            (fitted.net.knots_u, fitted.net.knots_v),
            fitted.u,
            fitted.v,
            frame.to_local(points),
            lam=0.0,
            lengths=(1.0, 1.0),
        )
        np.testing.assert_allclose(fitted.net.control_points, general, atol=1e-8)

    def test_matches_geomdl_with_no_more_error(self) -> None:
        from geomdl import fitting as geomdl_fitting

        from geobrep.plugins.fit.distance import surface_distances

        points = self.grid(30)
        ours = fit(
            points,
            method="approximation",
            control_points=(12, 12),
            smoothing=0.0,
            grid_shape=(30, 35),
        )
        theirs = geomdl_fitting.approximate_surface(
            (points - UTM).tolist(), 30, 35, 3, 3, ctrlpts_size_u=12, ctrlpts_size_v=12
        )
        twin = NurbsSurface(
            degree_u=3,
            degree_v=3,
            knots_u=theirs.knotvector_u,
            knots_v=theirs.knotvector_v,
            control_points=np.asarray(theirs.ctrlpts).reshape(12, 12, 3) + UTM,
            weights=np.ones((12, 12)),
        )
        assert ours.report is not None
        ours_rms = np.sqrt(np.mean(ours.distances**2))  # type: ignore[operator]
        geomdl_rms = np.sqrt(np.mean(surface_distances(twin, points) ** 2))
        assert ours_rms <= geomdl_rms * (1 + 1e-6)

    def test_smoothing_and_epsilon_on_a_grid(self) -> None:
        result = fit(self.grid(), method="approximation", epsilon=0.1, grid_shape=(40, 45))
        assert result.report is not None
        assert result.report.passed
        assert result.report.details["grid_shape"] == [40, 45]

    def test_bad_grid(self) -> None:
        with pytest.raises(OptionsError, match=r"grid_shape.*does not match"):
            fit(self.grid(), method="approximation", grid_shape=(40, 40))
        with pytest.raises(OptionsError, match="grid_shape takes neither"):
            fit(
                self.grid(),
                method="approximation",
                grid_shape=(40, 45),
                boundary_curves={
                    "u0": {
                        "degree": 1,
                        "knots": [0, 0, 1, 1],
                        "control_points": [[0, 0, 0], [0, 1, 0]],
                    }
                },
            )
