"""Kriging: PyKrige cross-checks, variogram models and fitting, the gridded output, bad input."""

from __future__ import annotations

import numpy as np
import pytest
from fit_helpers import UTM
from scipy.spatial import cKDTree

import geobrep
from geobrep import Surface
from geobrep.errors import DegenerateGeometryError, OptionsError
from geobrep.ops.fitting import fit
from geobrep.plugins.fit import kriging
from geobrep.plugins.fit._variogram import (
    Variogram,
    experimental_variogram,
    fit_variogram,
    variogram_from_options,
)
from geobrep.plugins.fit.kriging import krige

pykrige_ok = pytest.importorskip("pykrige.ok")
pykrige_uk = pytest.importorskip("pykrige.uk")

PARAMS = {"sill": 1.3, "range": 350.0, "nugget": 0.05}


@pytest.fixture(scope="module")
def data() -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    rng = np.random.default_rng(5)
    xy = rng.uniform(0, 1000, (250, 2))
    gx, gy = np.linspace(0, 1000, 31), np.linspace(-50, 1050, 27)
    xy[7] = [gx[4], gy[5]]  # a datum exactly on a grid node
    z = np.sin(xy[:, 0] / 160) + 0.001 * xy[:, 1] + rng.normal(0, 0.05, 250)
    return xy, z, gx, gy


def _relative(ours: np.ndarray, theirs: np.ndarray) -> float:
    theirs = np.asarray(theirs, dtype=np.float64).ravel()
    return float(np.abs(ours - theirs).max() / np.abs(theirs).max())


@pytest.mark.parametrize("model", ["spherical", "exponential", "gaussian"])
def test_ordinary_kriging_matches_pykrige(model: str, data: tuple[np.ndarray, ...]) -> None:
    xy, z, gx, gy = data
    reference = pykrige_ok.OrdinaryKriging(
        xy[:, 0], xy[:, 1], z, variogram_model=model, variogram_parameters=PARAMS
    )
    z_ref, var_ref = reference.execute("grid", gx, gy, backend="vectorized")
    z_near, var_near = reference.execute("grid", gx, gy, backend="C", n_closest_points=25)
    nodes = np.column_stack([np.tile(gx, gy.size), np.repeat(gy, gx.size)])
    variogram = variogram_from_options(model, PARAMS)
    pred, var = krige(xy, z, nodes, variogram)
    assert _relative(pred, z_ref) <= 1e-6
    assert _relative(var, var_ref) <= 1e-6
    pred, var = krige(xy, z, nodes, variogram, n_closest_points=25)
    assert _relative(pred, z_near) <= 1e-6
    assert _relative(var, var_near) <= 1e-6


@pytest.mark.parametrize("workers", [1, 2])
def test_moving_neighbourhood_blocks_and_shared_sets_match_pykrige(
    workers: int, data: tuple[np.ndarray, ...], monkeypatch: pytest.MonkeyPatch
) -> None:
    # a fine grid: many nodes share a neighbour set; small blocks put set groups and the datum
    # on a node across block boundaries, on one thread or several
    xy, z, _, _ = data
    gx, gy = np.linspace(0, 1000, 61), np.linspace(-50, 1050, 57)
    monkeypatch.setattr(kriging, "_LOCAL_BLOCK", 37)
    monkeypatch.setattr(kriging, "_MAX_WORKERS", workers)
    reference = pykrige_ok.OrdinaryKriging(
        xy[:, 0], xy[:, 1], z, variogram_model="spherical", variogram_parameters=PARAMS
    )
    z_ref, var_ref = reference.execute("grid", gx, gy, backend="C", n_closest_points=12)
    nodes = np.column_stack([np.tile(gx, gy.size), np.repeat(gy, gx.size)])
    tree = cKDTree(xy)
    sets = np.sort(tree.query(nodes, k=12)[1], axis=1)
    assert np.unique(sets, axis=0).shape[0] < 0.7 * nodes.shape[0]  # sets are shared
    pred, var = krige(
        xy, z, nodes, variogram_from_options("spherical", PARAMS), n_closest_points=12
    )
    assert _relative(pred, z_ref) <= 1e-6
    assert _relative(var, var_ref) <= 1e-6


def test_moving_neighbourhood_hash_collisions_and_bordered_fallback(
    data: tuple[np.ndarray, ...], monkeypatch: pytest.MonkeyPatch
) -> None:
    xy, z, gx, gy = data
    nodes = np.column_stack([np.tile(gx, gy.size), np.repeat(gy, gx.size)])
    model = variogram_from_options("exponential", PARAMS)
    expected = krige(xy, z, nodes, model, n_closest_points=20)
    # a few targets: the systems are built from the coordinates, not from the data covariance
    few = krige(xy, z, nodes[:5], model, n_closest_points=20)
    np.testing.assert_allclose(few[0], expected[0][:5], rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(few[1], expected[1][:5], rtol=1e-9, atol=1e-9)
    centred, where = xy - xy.mean(axis=0), nodes - xy.mean(axis=0)
    hood = kriging._Neighbourhoods(centred, z, model, False, kriging.EPS, 500.0, 20, len(nodes))
    hood.keys[:] = 0  # every set hashes alike: the exact check must refuse to share
    collided = hood.block(where)
    np.testing.assert_allclose(collided[0], expected[0], rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(collided[1], expected[1], rtol=1e-9, atol=1e-12)

    def not_positive(matrix: np.ndarray) -> np.ndarray:
        raise np.linalg.LinAlgError("not positive definite")

    # without a Cholesky factor, each target's bordered system is solved (PyKrige's way)
    monkeypatch.setattr(kriging.np.linalg, "cholesky", not_positive)
    bordered = krige(xy, z, nodes, model, n_closest_points=20)
    np.testing.assert_allclose(bordered[0], expected[0], rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(bordered[1], expected[1], rtol=1e-9, atol=1e-9)


@pytest.mark.parametrize("linear_drift", [False, True])
def test_fewer_points_than_neighbours_is_the_global_system(
    linear_drift: bool, data: tuple[np.ndarray, ...]
) -> None:
    xy, z, gx, gy = data
    xy, z = xy[:18], z[:18]  # every target's neighbourhood is all the data: one shared set
    nodes = np.column_stack([np.tile(gx, gy.size), np.repeat(gy, gx.size)])
    model = variogram_from_options("gaussian", PARAMS)
    pred, var = krige(xy, z, nodes, model, linear_drift=linear_drift)
    near, near_var = krige(xy, z, nodes, model, n_closest_points=30, linear_drift=linear_drift)
    assert _relative(near, pred) <= 1e-9
    assert _relative(near_var, var) <= 1e-9


def test_moving_neighbourhood_duplicates_without_nugget(data: tuple[np.ndarray, ...]) -> None:
    xy, z, gx, gy = data
    xy, z = np.vstack([xy, xy[:1]]), np.append(z, z[0] + 1.0)  # same place, other value
    nodes = np.column_stack([np.tile(gx, gy.size), np.repeat(gy, gx.size)])
    with pytest.raises(DegenerateGeometryError, match="duplicate"):
        krige(xy, z, nodes, Variogram("spherical", 1.0, 300.0), n_closest_points=10)


def test_universal_kriging_with_linear_drift_matches_pykrige(data: tuple[np.ndarray, ...]) -> None:
    xy, z, gx, gy = data
    xy, z = xy[:120], z[:120]  # PyKrige's constructor cross-validates every point: keep it small
    reference = pykrige_uk.UniversalKriging(
        xy[:, 0],
        xy[:, 1],
        z,
        variogram_model="exponential",
        variogram_parameters=PARAMS,
        drift_terms=["regional_linear"],
    )
    nodes = np.column_stack([np.tile(gx, gy.size), np.repeat(gy, gx.size)])[::7]
    z_ref, var_ref = reference.execute("points", nodes[:, 0], nodes[:, 1], backend="vectorized")
    pred, var = krige(
        xy, z, nodes, variogram_from_options("exponential", PARAMS), linear_drift=True
    )
    assert _relative(pred, z_ref) <= 1e-6
    assert _relative(var, var_ref) <= 1e-6


def test_exact_values_off_matches_pykrige(data: tuple[np.ndarray, ...]) -> None:
    xy, z, _, _ = data
    reference = pykrige_ok.OrdinaryKriging(
        xy[:, 0],
        xy[:, 1],
        z,
        variogram_model="spherical",
        variogram_parameters=PARAMS,
        exact_values=False,
    )
    z_ref, var_ref = reference.execute("points", xy[:20, 0], xy[:20, 1])
    pred, var = krige(
        xy, z, xy[:20], variogram_from_options("spherical", PARAMS), exact_values=False
    )
    assert _relative(pred, z_ref) <= 1e-6
    assert _relative(var, var_ref) <= 1e-6
    exact, exact_var = krige(xy, z, xy[:20], variogram_from_options("spherical", PARAMS))
    np.testing.assert_allclose(exact, z[:20], atol=1e-9)  # honours the data
    np.testing.assert_allclose(exact_var, 0.0, atol=1e-9)


def test_variogram_models() -> None:
    h = np.array([0.0, 1.0, 50.0, 100.0, 1e6])
    exponential = Variogram("exponential", sill=2.0, range=90.0, nugget=0.5)
    matern_half = Variogram("matern", sill=2.0, range=90.0, nugget=0.5, nu=0.5)
    np.testing.assert_allclose(matern_half.semivariance(h), exponential.semivariance(h), atol=1e-12)
    spherical = Variogram("spherical", sill=2.0, range=90.0, nugget=0.5)
    assert spherical.semivariance(h)[0] == 0.0
    assert spherical.semivariance(h)[3] == 2.0
    np.testing.assert_allclose(spherical.covariance(h, exact_at=0.0)[0], 2.0)
    np.testing.assert_allclose(spherical.covariance(h)[0], 1.5)
    smooth = Variogram("matern", sill=1.0, range=100.0, nu=2.5).semivariance(
        np.linspace(0, 300, 50)
    )
    assert np.all(np.diff(smooth) >= 0)
    assert smooth[-1] == pytest.approx(1.0, abs=1e-3)
    assert variogram_from_options("gaussian", [3.0, 10.0, 1.0]).psill == 2.0
    assert (
        variogram_from_options("gaussian", {"psill": 2.0, "range": 10.0, "nugget": 1.0}).sill == 3.0
    )
    with pytest.raises(OptionsError, match="nugget"):
        Variogram("spherical", sill=1.0, range=5.0, nugget=2.0)


def test_variogram_fit_recovers_a_known_model() -> None:
    # a Gaussian random field with a known exponential covariance, simulated by Cholesky
    rng = np.random.default_rng(0)
    xy = rng.uniform(0, 1000, (700, 2))
    truth = Variogram("exponential", sill=4.0, range=300.0, nugget=0.0)
    from scipy.spatial.distance import cdist

    cov = truth.covariance(cdist(xy, xy), exact_at=0.0) + 1e-9 * np.eye(700)
    z = np.linalg.cholesky(cov) @ rng.normal(size=700)
    lags, gamma, counts = experimental_variogram(xy, z, nlags=15)
    fitted = fit_variogram(lags, gamma, counts, "exponential")
    assert 0.4 * 300.0 < fitted.range < 2.5 * 300.0
    assert 0.3 * 4.0 < fitted.sill < 3.0 * 4.0
    assert fitted.nugget < 0.3 * fitted.sill


def test_kriging_fitter_output_is_a_gridded_surface() -> None:
    points = geobrep.datasets.scattered_points()
    gx = np.linspace(450_000, 451_000, 41)
    gy = np.linspace(6_700_000, 6_701_000, 31)
    result = fit(
        points,
        method="kriging",
        gridx=gx,
        gridy=gy,
        variogram_model="gaussian",
        variogram_parameters={"sill": 600.0, "range": 600.0, "nugget": 0.04},
        epsilon=0.5,
    )
    surface = result.surface
    assert isinstance(surface, Surface)
    assert surface.n_vertices == 41 * 31
    assert surface.metadata["grid_shape"] == [31, 41]
    np.testing.assert_array_equal(surface.vertices[:41, 0], gx)  # row-major, x fastest
    np.testing.assert_array_equal(surface.vertices[::41, 1], gy)
    variance = np.asarray(surface.point_data["variance"].values)
    assert variance.shape == (41 * 31,)
    assert np.all(variance >= 0)
    # the variance grows away from the data: the grid corners are the most uncertain
    assert variance.reshape(31, 41)[0, 0] > np.median(variance)
    assert surface.is_consistently_oriented
    assert np.all(surface.face_normals[:, 2] > 0)
    report = result.report
    assert report is not None
    assert report.passed
    assert report.details["variogram_fitted"] is False
    # predictions near the dome follow the true elevation
    from geobrep.datasets import dome_elevation

    local = surface.vertices - UTM
    inner = np.all(np.abs(local[:, :2] - 500) < 300, axis=1)
    error = local[inner, 2] - dome_elevation(local[inner, 0], local[inner, 1])
    assert np.abs(error).max() < 3.0


def test_kriging_fitter_fits_the_variogram_and_uses_neighbourhoods() -> None:
    points = geobrep.datasets.scattered_points(n_core=100, n_rim=150)
    result = fit(
        points, method="kriging", grid_size=25, n_closest_points=20, drift_terms=["regional_linear"]
    )
    assert result.report is not None
    details = result.report.details
    assert details["variogram_fitted"] is True
    assert details["neighbourhood"] == 20
    assert details["variogram"]["model"] == "spherical"  # type: ignore[index]
    assert result.surface.n_vertices == 625


class TestBadInput:
    def test_duplicates_without_nugget(self) -> None:
        pts = np.column_stack([np.random.default_rng(0).uniform(0, 10, (30, 2)), np.arange(30.0)])
        pts = np.vstack([pts, pts[:1] + np.array([0.0, 0.0, 5.0])])  # same place, other value
        with pytest.raises(DegenerateGeometryError, match="duplicate"):
            fit(
                pts,
                method="kriging",
                grid_size=5,
                variogram_parameters={"sill": 10.0, "range": 5.0, "nugget": 0.0},
            )
        result = fit(
            pts,
            method="kriging",
            grid_size=5,  # with a nugget they are fine
            variogram_parameters={"sill": 10.0, "range": 5.0, "nugget": 1.0},
        )
        assert result.surface.n_vertices == 25

    def test_collinear_points(self) -> None:
        t = np.linspace(0, 100, 30)
        with pytest.raises(DegenerateGeometryError, match="line"):
            fit(np.column_stack([t, t, t]), method="kriging")

    def test_constant_values(self) -> None:
        rng = np.random.default_rng(0)
        with pytest.raises(DegenerateGeometryError, match="do not vary"):
            fit(np.column_stack([rng.uniform(0, 10, (40, 2)), np.ones(40)]), method="kriging")

    def test_bad_options(self) -> None:
        pts = geobrep.datasets.scattered_points(n_core=20, n_rim=20)
        with pytest.raises(OptionsError, match="gridx"):
            fit(pts, method="kriging", gridx=[1.0, 2.0])
        with pytest.raises(OptionsError, match="strictly increasing"):
            fit(pts, method="kriging", gridx=[2.0, 1.0], gridy=[1.0, 2.0])
        with pytest.raises(OptionsError, match="unknown keys"):
            fit(pts, method="kriging", variogram_parameters={"sil": 1.0, "range": 2.0})
        with pytest.raises(OptionsError, match="variogram_model"):
            fit(pts, method="kriging", variogram_model="linear")
        with pytest.raises(OptionsError, match="n_closest_points"):
            fit(pts, method="kriging", n_closest_points=2, drift_terms=["regional_linear"])
