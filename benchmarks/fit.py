"""Fitting benchmarks against the issue's anchors, in one run; prints times, errors and ratios.

1. geobrep approximation vs ``geomdl.fitting.approximate_surface`` on the same gridded data
   (same net size and degrees), error = RMS distance from the data to each surface.
2. geobrep approximation vs a plain scipy sparse least-squares B-spline fit
   (``NdBSpline.design_matrix`` + ``spsolve`` of the normal equations), 200k points, 60 × 60 net.
3. geobrep kriging vs PyKrige on 2,000 points to 100 × 100 and 200 × 200 grids: the global
   system against PyKrige's ``vectorized`` backend, the moving neighbourhood against
   ``backend="C", n_closest_points=30`` (runs alternate; best and median times); scipy's
   ``RBFInterpolator`` as an accuracy reference.

Needs the test extras (geomdl, pykrige). Timings are the best of several runs (the machine may
be shared); ratios > 1 mean geobrep is faster. Run: ``python benchmarks/fit.py [--quick]``.
"""

from __future__ import annotations

import sys
import time
from collections.abc import Callable
from typing import Any

import numpy as np
import scipy.sparse.linalg as spla
from scipy.interpolate import NdBSpline, RBFInterpolator

from geobrep import NurbsSurface
from geobrep.datasets import dome_elevation
from geobrep.plugins.fit._approximation import approximate_points
from geobrep.plugins.fit._frame import LocalFrame
from geobrep.plugins.fit._knots import uniform_knots
from geobrep.plugins.fit._variogram import Variogram
from geobrep.plugins.fit.distance import surface_distances
from geobrep.plugins.fit.kriging import krige
from geobrep.plugins.fit.options import ApproximationOptions

QUICK = "--quick" in sys.argv
UTM = np.array([450_000.0, 6_700_000.0, 0.0])


def best_of(function: Callable[[], Any], repeat: int) -> tuple[float, Any]:
    best, result = float("inf"), None
    for _ in range(repeat):
        start = time.perf_counter()
        result = function()
        best = min(best, time.perf_counter() - start)
    return best, result


def rms(values: np.ndarray) -> float:
    return float(np.sqrt(np.mean(np.square(values))))


def row(label: str, ours: float, theirs: float, err_ours: float, err_theirs: float) -> None:
    print(
        f"  {label:<44} geobrep {ours:8.3f} s  anchor {theirs:8.3f} s  "
        f"speed-up {theirs / ours:7.1f}x   error {err_ours:.3e} vs {err_theirs:.3e}"
    )


def geomdl_comparison() -> None:
    from geomdl import fitting

    side = 60 if QUICK else 100
    size = 20 if QUICK else 30
    x, y = np.meshgrid(np.linspace(0, 1000, side), np.linspace(0, 1000, side), indexing="ij")
    rng = np.random.default_rng(0)
    z = dome_elevation(x, y) + rng.normal(0, 0.05, x.shape)
    grid = np.stack([x, y, z], axis=-1).reshape(-1, 3) + UTM
    options = ApproximationOptions(
        control_points=(size, size), smoothing=0.0, grid_shape=(side, side)
    )

    def ours() -> NurbsSurface:
        frame = LocalFrame.from_points(grid)
        fitted = approximate_points(grid, options, frame)
        world = frame.to_world(fitted.net.reshape(-1, 3)).reshape(fitted.net.shape)
        return NurbsSurface(
            degree_u=3,
            degree_v=3,
            knots_u=fitted.knots_u,
            knots_v=fitted.knots_v,
            control_points=world,
            weights=np.ones(world.shape[:2]),
        )

    t_ours, surface = best_of(ours, 3)
    local = (grid - UTM).tolist()
    t_geomdl, theirs = best_of(
        lambda: fitting.approximate_surface(
            local, side, side, 3, 3, ctrlpts_size_u=size, ctrlpts_size_v=size
        ),
        1,
    )
    twin = NurbsSurface(
        degree_u=3,
        degree_v=3,
        knots_u=theirs.knotvector_u,
        knots_v=theirs.knotvector_v,
        control_points=np.asarray(theirs.ctrlpts).reshape(size, size, 3) + UTM,
        weights=np.ones((size, size)),
    )
    e_ours = rms(surface_distances(surface, grid))
    e_geomdl = rms(surface_distances(twin, grid))
    print(f"approximation of a {side} × {side} grid to a {size} × {size} net (geomdl: same grid)")
    row("vs geomdl.fitting.approximate_surface", t_ours, t_geomdl, e_ours, e_geomdl)


def scipy_comparison() -> None:
    n = 50_000 if QUICK else 200_000
    rng = np.random.default_rng(1)
    xy = rng.uniform(0, 1000, (n, 2))
    z = dome_elevation(xy[:, 0], xy[:, 1]) + rng.normal(0, 0.05, n)
    points = np.column_stack([xy, z]) + UTM
    options = ApproximationOptions(control_points=(60, 60), smoothing=0.0)
    t_ours, fitted = best_of(lambda: approximate_points(points, options), 3)

    def anchor() -> np.ndarray:
        lo, hi = xy.min(axis=0), xy.max(axis=0)
        uv = (xy - lo) / (hi - lo)
        knots = uniform_knots(3, 57)
        design = NdBSpline.design_matrix(uv, (knots, knots), 3)
        return np.asarray(spla.spsolve((design.T @ design).tocsc(), design.T @ z)), design

    t_scipy, (coefficients, design) = best_of(anchor, 3)
    e_scipy = rms(design @ coefficients - z)
    print(f"least squares of {n} scattered points to a 60 × 60 cubic net")
    row(
        "vs scipy NdBSpline.design_matrix + spsolve",
        t_ours,
        t_scipy,
        rms(fitted.residuals),
        e_scipy,
    )


def timed(function: Callable[[], Any], repeat: int) -> tuple[float, float, Any]:
    """Best and median wall time of ``repeat`` runs, and the last result."""
    times, result = [], None
    for _ in range(repeat):
        start = time.perf_counter()
        result = function()
        times.append(time.perf_counter() - start)
    return min(times), float(np.median(times)), result


def kriging_row(label: str, ours: tuple[float, float], theirs: tuple[float, float]) -> None:
    print(
        f"  {label:<44} geobrep {ours[0]:6.3f} / {ours[1]:6.3f} s  anchor {theirs[0]:6.3f} / "
        f"{theirs[1]:6.3f} s (best / median)  speed-up {theirs[0] / ours[0]:4.2f}x / "
        f"{theirs[1] / ours[1]:4.2f}x"
    )


def kriging_comparison(side: int) -> None:
    from pykrige.ok import OrdinaryKriging

    n = 1000 if QUICK else 2000
    repeat = 3 if QUICK else 5
    rng = np.random.default_rng(2)
    xy = rng.uniform(0, 1000, (n, 2))
    z = dome_elevation(xy[:, 0], xy[:, 1]) + rng.normal(0, 0.2, n)
    axis = np.linspace(0, 1000, side)
    nodes = np.column_stack([np.tile(axis, side), np.repeat(axis, side)])
    truth = dome_elevation(nodes[:, 0], nodes[:, 1])
    # PyKrige's gaussian model without a nugget is unstable at N = 2000: compare with a nugget
    params = {"sill": 700.0, "range": 600.0, "nugget": 0.04}
    model = Variogram("gaussian", sill=700.0, range=600.0, nugget=0.04)
    reference = OrdinaryKriging(
        xy[:, 0], xy[:, 1], z, variogram_model="gaussian", variogram_parameters=params
    )
    print(f"ordinary kriging, {n} points to a {side} × {side} grid (gaussian model with nugget)")
    # alternate geobrep and anchor runs so that both see the same machine load
    ours, theirs = [], []
    for _ in range(2 if QUICK else 3):
        ours.append(timed(lambda: krige(xy, z, nodes, model), 1))
        theirs.append(timed(lambda: reference.execute("grid", axis, axis, backend="vectorized"), 1))
    pred, var = ours[-1][2]
    z_vec, var_vec = theirs[-1][2]
    kriging_row(
        "global system vs PyKrige vectorized",
        (min(t[0] for t in ours), float(np.median([t[0] for t in ours]))),
        (min(t[0] for t in theirs), float(np.median([t[0] for t in theirs]))),
    )
    ours, theirs = [], []
    for _ in range(repeat):
        ours.append(timed(lambda: krige(xy, z, nodes, model, n_closest_points=30), 1))
        theirs.append(
            timed(
                lambda: reference.execute("grid", axis, axis, backend="C", n_closest_points=30), 1
            )
        )
    near, near_var = ours[-1][2]
    z_c, var_c = theirs[-1][2]
    kriging_row(
        "moving neighbourhood (30) vs PyKrige C",
        (min(t[0] for t in ours), float(np.median([t[0] for t in ours]))),
        (min(t[0] for t in theirs), float(np.median([t[0] for t in theirs]))),
    )

    def relative(a: np.ndarray, b: np.ndarray) -> float:
        b = np.asarray(b).ravel()
        return float(np.abs(a - b).max() / np.abs(b).max())

    print(
        f"  agreement with PyKrige (max relative difference): global {relative(pred, z_vec):.1e}"
        f" (variance {relative(var, var_vec):.1e}), moving {relative(near, z_c):.1e} "
        f"(variance {relative(near_var, var_c):.1e})"
    )
    print(
        f"  RMS error against the true surface: global {rms(pred - truth):.3e} (PyKrige "
        f"{rms(np.asarray(z_vec).ravel() - truth):.3e}), moving {rms(near - truth):.3e} "
        f"(PyKrige {rms(np.asarray(z_c).ravel() - truth):.3e})"
    )
    if side == 200:
        t_rbf, rbf = best_of(
            lambda: RBFInterpolator(xy, z, kernel="thin_plate_spline", smoothing=1e-3)(nodes), 1
        )
        print(
            f"  accuracy reference: scipy RBFInterpolator (thin plate) RMS error "
            f"{rms(rbf - truth):.3e} in {t_rbf:.2f} s; kriging {rms(pred - truth):.3e}"
        )


if __name__ == "__main__":
    geomdl_comparison()
    scipy_comparison()
    for side in (100, 200):
        kriging_comparison(side)
