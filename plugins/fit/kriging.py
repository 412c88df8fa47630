"""Ordinary and universal kriging: predictions and kriging variances on a grid or at points.

The kriging system is solved in covariance form. For the global system the data covariance
``C`` is factored once (Cholesky, ``C = L Lᵀ``) and the unbiasedness conditions (``Σ λ = 1``, and
``Σ λ x = x₀``, ``Σ λ y = y₀`` for a linear drift) enter through a small generalised least-squares
correction. With ``r = L⁻¹ c₀``, ``W = L⁻¹ F``, ``Q = Wᵀ W`` and ``g = Wᵀ r − f₀``:

    prediction  z* = rᵀ (L⁻¹ z) − (Q⁻¹ g)ᵀ (Wᵀ L⁻¹ z)
    variance    σ² = C(0) − |r|² + gᵀ Q⁻¹ g

which is PyKrige's bordered system, rearranged: one triangular solve per target instead of a
product with the inverse. The moving neighbourhood uses the same formulas on each target's ``k``
nearest data: targets that share a neighbour set (common on a grid) share its factorisation, so
each set is factored once (a batched Cholesky) and each target costs one forward substitution.
Targets go through in blocks, on several threads, to bound memory; a set whose covariance is
not numerically positive definite falls back to PyKrige's bordered LU solve.

>>> import numpy as np
>>> xy = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0]])
>>> model = Variogram("exponential", sill=1.0, range=3.0)
>>> z, var = krige(xy, np.array([1.0, 2.0, 3.0, 4.0]), np.array([[0.0, 0.0], [0.5, 0.5]]), model)
>>> round(float(z[0]), 12), round(float(var[0]), 12), round(float(z[1]), 6)
(1.0, 0.0, 2.5)
"""

from __future__ import annotations

import os
import warnings
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import scipy.linalg as la
from numpy.typing import NDArray
from scipy.spatial import cKDTree
from scipy.spatial.distance import cdist, pdist, squareform

from geobrep import Entity, Surface
from geobrep.errors import DegenerateGeometryError, OptionsError
from geobrep.geometry.arrays import FloatArray
from geobrep.plugins import FitResult
from geobrep.plugins.fit._approximation import collect_points
from geobrep.plugins.fit._lsq import single_threaded_blas
from geobrep.plugins.fit._variogram import (
    Variogram,
    experimental_variogram,
    fit_variogram,
    variogram_from_options,
)
from geobrep.plugins.fit.distance import mesh_distances
from geobrep.plugins.fit.options import KrigingOptions
from geobrep.plugins.fit.report import accuracy_report

__all__ = ["fit_kriging", "krige"]

LABEL = "fitter 'kriging'"
#: Distances at or below this count as zero (a target on a datum), as PyKrige's ``eps``.
EPS = 1e-10
#: Targets per block in the global system (bounds the ``n × block`` work arrays).
_GLOBAL_BLOCK = 2048
#: Targets per block in the moving neighbourhood (a block's systems stay in cache).
_LOCAL_BLOCK = 1024
#: Largest data count for which the moving neighbourhood gathers from the data covariance matrix.
_TABLE_MAX = 6000
#: Threads for the moving neighbourhood (blocks are independent).
_MAX_WORKERS = 8


def _drift(xy: FloatArray, linear: bool, scale: float) -> FloatArray:
    ones = np.ones((xy.shape[0], 1))
    return np.hstack([ones, xy / scale]) if linear else ones


def _data_covariance(xy: FloatArray, model: Variogram) -> FloatArray:
    """``C(|xᵢ − xⱼ|)`` with ``C(0) = sill`` on the diagonal only: coincident but distinct data
    points are correlated by the structured part (PyKrige's matrix), so with a nugget they stay
    solvable."""
    cov = np.asarray(squareform(model.covariance(pdist(xy))), dtype=np.float64)  # pairs once
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

    def predict(block: FloatArray) -> tuple[FloatArray, FloatArray]:
        c0 = model.covariance(cdist(xy, block), exact_at=exact_at)  # (n, B)
        r = la.solve_triangular(lower, c0, lower=True, check_finite=False)
        g = w.T @ r - _drift(block, linear, scale).T  # (m, B)
        qg = la.cho_solve(q_factor, g)
        variance = model.sill - np.einsum("ij,ij->j", r, r) + np.einsum("ij,ij->j", g, qg)
        return r.T @ zt - qg.T @ wz, variance

    return _blockwise(targets, predict)


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

    def predict(block: FloatArray) -> tuple[FloatArray, FloatArray]:
        rhs = np.vstack(
            [model.covariance(cdist(xy, block), exact_at=exact_at), _drift(block, linear, scale).T]
        )
        solution = la.lu_solve(lu, rhs, check_finite=False)
        return solution[:n].T @ z, model.sill - np.einsum("ij,ij->j", solution, rhs)

    return _blockwise(targets, predict)


def _blockwise(
    targets: FloatArray, predict: Callable[[FloatArray], tuple[FloatArray, FloatArray]]
) -> tuple[FloatArray, FloatArray]:
    """Prediction and variance at ``targets``, ``_GLOBAL_BLOCK`` targets at a time."""
    prediction = np.empty(targets.shape[0])
    variance = np.empty(targets.shape[0])
    for start in range(0, targets.shape[0], _GLOBAL_BLOCK):
        rows = slice(start, start + _GLOBAL_BLOCK)
        prediction[rows], variance[rows] = predict(targets[rows])
    return prediction, variance


def _forward(lower: FloatArray, rhs: FloatArray) -> FloatArray:
    """Forward substitution ``L x = b`` for a stack ``L (s, k, k)`` and ``b (s, k)``: one
    vectorised step per row, across the whole stack (a column at a time for ``b (s, k, r)``)."""
    if rhs.ndim == 3:
        return np.stack([_forward(lower, rhs[:, :, c]) for c in range(rhs.shape[2])], axis=2)
    x = np.empty_like(rhs)
    for j in range(lower.shape[1]):
        dot = np.einsum("si,si->s", lower[:, j, :j], x[:, :j])
        x[:, j] = (rhs[:, j] - dot) / lower[:, j, j]
    return x


def _workers() -> int:
    try:
        cores = len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        cores = os.cpu_count() or 1
    return max(1, min(cores, _MAX_WORKERS))


class _Neighbourhoods:
    """Moving-neighbourhood kriging, one block of targets at a time (read-only shared state,
    so blocks can run on several threads).

    Each target's system is that of its ``k`` nearest data. Neighbouring targets often share the
    same neighbour set: targets are grouped by set (a hash of the set, checked exactly), each
    set's covariance matrix is factored once (Cholesky) and every target of the set needs only
    one forward substitution, with the formulas of the global system.
    """

    def __init__(
        self,
        xy: FloatArray,
        z: FloatArray,
        model: Variogram,
        linear: bool,
        exact_at: float | None,
        scale: float,
        k: int,
        n_targets: int,
    ) -> None:
        n = xy.shape[0]
        self.tree = cKDTree(xy)
        # the data in tree order, where a neighbourhood's indices lie close together (cache-
        # friendly gathers); the tree keeps the given order, so ties break as they would
        order = self.tree.indices
        self.rank = np.empty(n, dtype=np.intp)
        self.rank[order] = np.arange(n)
        self.xy = xy[order]
        self.z = z[order]
        self.model = model
        self.linear = linear
        self.exact_at = exact_at
        self.scale = scale
        self.k = k
        self.drift = _drift(self.xy, linear, scale)
        # gather the systems from the data covariance matrix when it is small enough to hold
        # and not much larger than the systems themselves
        small = n <= _TABLE_MAX and n * n <= 2 * n_targets * k * k
        self.table = _data_covariance(self.xy, model).reshape(-1) if small else None
        # an order-free hash of a neighbour set: the wrapping sum of random 64-bit keys
        self.keys: NDArray[np.uint64] = np.asarray(
            np.random.default_rng(0).integers(0, 2**63, n, dtype=np.uint64)
        )

    def _covariance(self, members: NDArray[np.intp]) -> FloatArray:
        """The covariance matrices ``(s, k, k)`` of neighbour sets ``(s, k)``."""
        n = self.xy.shape[0]
        if self.table is not None:
            flat = members[:, :, None] * n + members[:, None, :]
            return np.asarray(np.take(self.table, flat), dtype=np.float64)
        p = self.xy[members]
        dx = p[:, :, None, 0] - p[:, None, :, 0]
        dy = p[:, :, None, 1] - p[:, None, :, 1]
        cov = self.model.covariance(np.sqrt(dx * dx + dy * dy))
        k = self.k
        cov[:, np.arange(k), np.arange(k)] = self.model.sill
        return cov

    def block(self, targets: FloatArray) -> tuple[FloatArray, FloatArray]:
        """Predictions and variances at ``targets (b, 2)``."""
        b, k = targets.shape[0], self.k
        distance, index = self.tree.query(targets, k=k)
        distance = np.asarray(distance).reshape(b, k)
        index = self.rank[np.asarray(index).reshape(b, k)]
        order = np.argsort(index, axis=1)  # each set in a canonical order
        index = np.take_along_axis(index, order, axis=1)
        distance = np.take_along_axis(distance, order, axis=1)
        key = np.asarray(np.sum(self.keys[index], axis=1, dtype=np.uint64))
        _, first, group = np.unique(key, return_index=True, return_inverse=True)
        group = group.reshape(-1)
        if not np.array_equal(index[first][group], index):  # a hash collision: share nothing
            first = group = np.arange(b)
        members = index[first]
        c0 = self.model.covariance(distance, exact_at=self.exact_at)
        f0 = _drift(targets, self.linear, self.scale)
        cov = self._covariance(members)
        m = self.drift.shape[1]
        try:
            lower = np.asarray(np.linalg.cholesky(cov), dtype=np.float64)
            # per set: W = L⁻¹ F, u = L⁻¹ z, Q = Wᵀ W, h = Q⁻¹ Wᵀ u, and r = L⁻¹ c₀ for the
            # target that represents the set
            rhs = [self.drift[members], self.z[members, None], c0[first, :, None]]
            solved = _forward(lower, np.concatenate(rhs, axis=2))
            w, u = solved[:, :, :m], solved[:, :, m]
            q_inverse = np.linalg.inv(np.einsum("skm,skn->smn", w, w))
        except np.linalg.LinAlgError:  # not numerically positive definite: the bordered system
            return self._bordered(index, c0, f0)
        h = np.einsum("smn,skn,sk->sm", q_inverse, w, u)
        # per target: r = L⁻¹ c₀ (for the other targets of each set), g = Wᵀ r − f₀
        r = np.empty((b, k))
        r[first] = solved[:, :, m + 1]
        others = np.ones(b, dtype=bool)
        others[first] = False
        if others.any():
            r[others] = _forward(lower[group[others]], c0[others])
        g = np.einsum("bkm,bk->bm", w[group], r) - f0
        prediction = np.einsum("bk,bk->b", r, u[group]) - np.einsum("bm,bm->b", g, h[group])
        variance = (
            self.model.sill
            - np.einsum("bk,bk->b", r, r)
            + np.einsum("bm,bmn,bn->b", g, q_inverse[group], g)
        )
        return prediction, variance

    def _bordered(
        self, index: NDArray[np.intp], c0: FloatArray, f0: FloatArray
    ) -> tuple[FloatArray, FloatArray]:
        """One LU solve of the bordered system per target (PyKrige's system)."""
        b, k = index.shape
        m = self.drift.shape[1]
        system = np.zeros((b, k + m, k + m))
        system[:, :k, :k] = self._covariance(index)
        system[:, :k, k:] = self.drift[index]
        system[:, k:, :k] = self.drift[index].transpose(0, 2, 1)
        rhs = np.concatenate([c0, f0], axis=1)
        try:
            solution = np.linalg.solve(system, rhs[:, :, None])[:, :, 0]
        except np.linalg.LinAlgError as exc:
            raise DegenerateGeometryError(
                f"{LABEL}: a neighbourhood system is singular (duplicate points without a nugget, "
                "or too few points for the drift); add a nugget, remove duplicates or use more "
                "neighbours"
            ) from exc
        prediction = np.einsum("ij,ij->i", solution[:, :k], self.z[index])
        return prediction, self.model.sill - np.einsum("ij,ij->i", solution, rhs)


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
    t = targets.shape[0]
    hood = _Neighbourhoods(xy, z, model, linear, exact_at, scale, min(k, xy.shape[0]), t)
    prediction = np.empty(t)
    variance = np.empty(t)

    def run(start: int) -> None:
        stop = start + _LOCAL_BLOCK
        prediction[start:stop], variance[start:stop] = hood.block(targets[start:stop])

    starts = range(0, t, _LOCAL_BLOCK)
    workers = min(_workers(), len(starts))
    with single_threaded_blas():  # threads over blocks instead
        if workers > 1:
            with ThreadPoolExecutor(workers) as pool:
                list(pool.map(run, starts))
        else:
            for start in starts:
                run(start)
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
    return FitResult(
        surface=surface,
        report=report,
        distances=distances,
        method="kriging",
        points=points,
    )
