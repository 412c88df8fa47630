"""Ordinary and universal kriging: predictions and kriging variances on a grid or at points.

The kriging system is solved in covariance form. For the global system the data covariance
``C`` is factored once (Cholesky, ``C = L Lᵀ``) and the unbiasedness conditions (``Σ λ = 1``, and
``Σ λ x = x₀``, ``Σ λ y = y₀`` for a linear drift) enter through a small generalised least-squares
correction. With ``r = L⁻¹ c₀``, ``W = L⁻¹ F``, ``Q = Wᵀ W`` and ``g = Wᵀ r − f₀``:

    prediction  z* = rᵀ (L⁻¹ z) − (Q⁻¹ g)ᵀ (Wᵀ L⁻¹ z)
    variance    σ² = C(0) − |r|² + gᵀ Q⁻¹ g

which is PyKrige's bordered system, rearranged: one triangular solve per target instead of a
product with the inverse. The moving neighbourhood solves each target's bordered system of its
``k`` nearest data points as one batched solve. Targets go through in blocks to bound memory.

>>> import numpy as np
>>> xy = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0]])
>>> model = Variogram("exponential", sill=1.0, range=3.0)
>>> z, var = krige(xy, np.array([1.0, 2.0, 3.0, 4.0]), np.array([[0.0, 0.0], [0.5, 0.5]]), model)
>>> round(float(z[0]), 12), round(float(var[0]), 12), round(float(z[1]), 6)
(1.0, 0.0, 2.5)
"""

from __future__ import annotations

import warnings

import numpy as np
import scipy.linalg as la
from numpy.typing import NDArray
from scipy.spatial import cKDTree
from scipy.spatial.distance import cdist

from geobrep.entities import Entity, Surface
from geobrep.errors import DegenerateGeometryError, OptionsError
from geobrep.fitting import FitResult
from geobrep.plugins.fit.approximation import collect_points
from geobrep.plugins.fit.distance import mesh_distances
from geobrep.plugins.fit.lsq import single_threaded_blas
from geobrep.plugins.fit.options import KrigingOptions
from geobrep.plugins.fit.report import accuracy_report
from geobrep.plugins.fit.variogram import (
    Variogram,
    experimental_variogram,
    fit_variogram,
    variogram_from_options,
)

__all__ = ["fit_kriging", "krige"]

FloatArray = NDArray[np.float64]
LABEL = "fitter 'kriging'"
#: Distances at or below this count as zero (a target on a datum), as PyKrige's ``eps``.
EPS = 1e-10
#: Targets per block in the global system (bounds the ``n × block`` work arrays).
_GLOBAL_BLOCK = 2048
#: Targets per block in the moving neighbourhood.
_LOCAL_BLOCK = 8192


def _drift(xy: FloatArray, linear: bool, scale: float) -> FloatArray:
    ones = np.ones((xy.shape[0], 1))
    return np.hstack([ones, xy / scale]) if linear else ones


def _data_covariance(xy: FloatArray, model: Variogram) -> FloatArray:
    """``C(|xᵢ − xⱼ|)`` with ``C(0) = sill`` on the diagonal only: coincident but distinct data
    points are correlated by the structured part (PyKrige's matrix), so with a nugget they stay
    solvable."""
    cov = model.covariance(cdist(xy, xy))
    np.fill_diagonal(cov, model.sill)
    return cov


def _global(
    xy: FloatArray,
    z: FloatArray,
    targets: FloatArray,
    model: Variogram,
    linear: bool,
    exact_at: float | None,
    scale: float,
) -> tuple[FloatArray, FloatArray]:
    cov = _data_covariance(xy, model)
    try:
        lower = la.cholesky(cov, lower=True, check_finite=False)
    except la.LinAlgError:
        return _global_bordered(xy, z, targets, model, linear, exact_at, scale, cov)
    f = _drift(xy, linear, scale)
    w = la.solve_triangular(lower, f, lower=True, check_finite=False)
    q = w.T @ w
    zt = la.solve_triangular(lower, z, lower=True, check_finite=False)
    wz = w.T @ zt
    try:
        q_factor = la.cho_factor(q)
    except la.LinAlgError as exc:
        raise DegenerateGeometryError(
            f"{LABEL}: the drift cannot be estimated (points on a line?)"
        ) from exc
    prediction = np.empty(targets.shape[0])
    variance = np.empty(targets.shape[0])
    for start in range(0, targets.shape[0], _GLOBAL_BLOCK):
        block = targets[start : start + _GLOBAL_BLOCK]
        c0 = model.covariance(cdist(xy, block), exact_at=exact_at)  # (n, B)
        r = la.solve_triangular(lower, c0, lower=True, check_finite=False)
        g = w.T @ r - _drift(block, linear, scale).T  # (m, B)
        qg = la.cho_solve(q_factor, g)
        prediction[start : start + _GLOBAL_BLOCK] = r.T @ zt - qg.T @ wz
        variance[start : start + _GLOBAL_BLOCK] = (
            model.sill - np.einsum("ij,ij->j", r, r) + np.einsum("ij,ij->j", g, qg)
        )
    return prediction, variance


def _global_bordered(
    xy: FloatArray,
    z: FloatArray,
    targets: FloatArray,
    model: Variogram,
    linear: bool,
    exact_at: float | None,
    scale: float,
    cov: FloatArray,
) -> tuple[FloatArray, FloatArray]:
    """Fallback when ``C`` is not numerically positive definite: LU of the bordered system."""
    f = _drift(xy, linear, scale)
    n, m = f.shape
    system = np.zeros((n + m, n + m))
    system[:n, :n] = cov
    system[:n, n:] = f
    system[n:, :n] = f.T
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", la.LinAlgWarning)
        lu = la.lu_factor(system, check_finite=False)
    if not np.all(np.abs(np.diag(lu[0])) > 1e-13 * np.abs(np.diag(lu[0])).max()):
        raise DegenerateGeometryError(
            f"{LABEL}: the kriging system is singular (duplicate points without a nugget, or a "
            "gaussian model without a nugget); add a nugget or remove duplicates"
        )
    prediction = np.empty(targets.shape[0])
    variance = np.empty(targets.shape[0])
    for start in range(0, targets.shape[0], _GLOBAL_BLOCK):
        block = targets[start : start + _GLOBAL_BLOCK]
        rhs = np.vstack(
            [model.covariance(cdist(xy, block), exact_at=exact_at), _drift(block, linear, scale).T]
        )
        solution = la.lu_solve(lu, rhs, check_finite=False)
        prediction[start : start + _GLOBAL_BLOCK] = solution[:n].T @ z
        variance[start : start + _GLOBAL_BLOCK] = model.sill - np.einsum("ij,ij->j", solution, rhs)
    return prediction, variance


def _moving(
    xy: FloatArray,
    z: FloatArray,
    targets: FloatArray,
    model: Variogram,
    linear: bool,
    exact_at: float | None,
    scale: float,
    k: int,
) -> tuple[FloatArray, FloatArray]:
    n = xy.shape[0]
    k = min(k, n)
    tree = cKDTree(xy)
    f_all = _drift(xy, linear, scale)
    m = f_all.shape[1]
    full = _data_covariance(xy, model).reshape(-1) if n <= 6000 else None
    prediction = np.empty(targets.shape[0])
    variance = np.empty(targets.shape[0])
    for start in range(0, targets.shape[0], _LOCAL_BLOCK):
        block = targets[start : start + _LOCAL_BLOCK]
        distance, index = tree.query(block, k=k)
        distance = distance.reshape(block.shape[0], k)
        index = index.reshape(block.shape[0], k)
        b = block.shape[0]
        system = np.zeros((b, k + m, k + m))
        if full is not None:  # flat gathers from the data covariance matrix
            system[:, :k, :k] = np.take(full, index[:, :, None] * n + index[:, None, :])
        else:
            local = xy[index]
            pair = np.linalg.norm(local[:, :, None, :] - local[:, None, :, :], axis=3)
            system[:, :k, :k] = model.covariance(pair)
            system[:, np.arange(k), np.arange(k)] = model.sill
        system[:, :k, k:] = f_all[index]
        system[:, k:, :k] = f_all[index].transpose(0, 2, 1)
        rhs = np.empty((b, k + m))
        rhs[:, :k] = model.covariance(distance, exact_at=exact_at)
        rhs[:, k:] = _drift(block, linear, scale)
        try:
            with single_threaded_blas():
                solution = np.linalg.solve(system, rhs[:, :, None])[:, :, 0]
        except np.linalg.LinAlgError as exc:
            raise DegenerateGeometryError(
                f"{LABEL}: a neighbourhood system is singular (duplicate points without a nugget, "
                "or too few points for the drift); add a nugget, remove duplicates or use more "
                "neighbours"
            ) from exc
        prediction[start : start + b] = np.einsum("ij,ij->i", solution[:, :k], z[index])
        variance[start : start + b] = model.sill - np.einsum("ij,ij->i", solution, rhs)
    return prediction, variance


def krige(
    xy: FloatArray,
    z: FloatArray,
    targets: FloatArray,
    model: Variogram,
    *,
    n_closest_points: int | None = None,
    linear_drift: bool = False,
    exact_values: bool = True,
) -> tuple[FloatArray, FloatArray]:
    """Kriging predictions and variances at ``targets (t, 2)`` from data ``xy (n, 2)``, ``z (n,)``.

    Ordinary kriging, or universal kriging with ``linear_drift``; the global system, or a moving
    neighbourhood of the ``n_closest_points`` nearest data. Coordinates are centred internally.
    """
    origin = xy.mean(axis=0)
    data = np.asarray(xy, dtype=np.float64) - origin
    where = np.asarray(targets, dtype=np.float64) - origin
    scale = float(np.abs(data).max(initial=0.0)) or 1.0
    exact_at = EPS if exact_values else None
    values = np.asarray(z, dtype=np.float64)
    needed = 3 if linear_drift else 1
    if data.shape[0] < max(needed, 2):
        raise OptionsError(f"{LABEL}: {data.shape[0]} points are too few to krige")
    if n_closest_points is not None:
        if n_closest_points < needed + 1:
            raise OptionsError(
                f"{LABEL}: option 'n_closest_points': {n_closest_points} neighbours are too few "
                f"for {'a linear drift' if linear_drift else 'ordinary kriging'}"
            )
        return _moving(data, values, where, model, linear_drift, exact_at, scale, n_closest_points)
    return _global(data, values, where, model, linear_drift, exact_at, scale)


def fit_kriging(entities: list[Entity], options: KrigingOptions) -> FitResult:
    """The ``kriging`` fitter: a gridded Surface of predictions with a ``variance`` property."""
    points, pointset = collect_points(entities, LABEL)
    origin = points.mean(axis=0)
    xy = points[:, :2] - origin[:2]
    z = points[:, 2] - origin[2]
    if np.linalg.matrix_rank(np.c_[xy - xy.mean(axis=0)], tol=1e-9 * (np.abs(xy).max() or 1.0)) < 2:
        raise DegenerateGeometryError(f"{LABEL}: the points lie on a line; kriging needs an area")
    if options.variogram_parameters is None:
        lags, gamma, counts = experimental_variogram(xy, z, options.nlags)
        model = fit_variogram(lags, gamma, counts, options.variogram_model, weight=options.weight)
        fitted = True
    else:
        model = variogram_from_options(options.variogram_model, options.variogram_parameters)
        fitted = False
    if options.gridx is not None and options.gridy is not None:
        gx = np.asarray(options.gridx, dtype=np.float64)
        gy = np.asarray(options.gridy, dtype=np.float64)
    else:
        lo, hi = points[:, :2].min(axis=0), points[:, :2].max(axis=0)
        gx = np.linspace(lo[0], hi[0], options.grid_size)
        gy = np.linspace(lo[1], hi[1], options.grid_size)
    nodes_x, nodes_y = np.meshgrid(gx - origin[0], gy - origin[1])  # (ny, nx), as PyKrige
    targets = np.column_stack([nodes_x.reshape(-1), nodes_y.reshape(-1)])
    prediction, variance = krige(
        xy,
        z,
        targets,
        model,
        n_closest_points=options.n_closest_points,
        linear_drift="regional_linear" in options.drift_terms,
        exact_values=options.exact_values,
    )
    ny, nx = nodes_x.shape
    vertices = np.column_stack([targets + origin[:2], prediction + origin[2]])
    j, i = np.meshgrid(np.arange(nx - 1), np.arange(ny - 1))
    a = (i * nx + j).reshape(-1)
    faces = np.concatenate(
        [np.column_stack([a, a + 1, a + nx + 1]), np.column_stack([a, a + nx + 1, a + nx])]
    )
    surface = Surface(
        vertices=vertices,
        faces=faces,
        name="kriging",
        kind=pointset.kind if pointset is not None else None,
        point_data={"variance": np.maximum(variance, 0.0)},
        metadata={
            "grid_shape": [int(ny), int(nx)],
            "variogram": model.as_dict(),
            "variogram_fitted": fitted,
        },
    )
    distances = mesh_distances(surface, points)
    report = accuracy_report(
        distances,
        points,
        epsilon=options.epsilon,
        method="kriging",
        details={
            "variogram": model.as_dict(),
            "variogram_fitted": fitted,
            "grid_shape": [int(ny), int(nx)],
            "neighbourhood": options.n_closest_points or "global",
            "drift": list(options.drift_terms),
        },
    )
    return FitResult(surface=surface, report=report, distances=distances, method="kriging")
