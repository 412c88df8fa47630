"""Scattered survey points on a known smooth surface (a dome with a fold)."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from geobrep.model.crs import CRS
from geobrep.model.entities import PointSet
from geobrep.model.properties import Property

__all__ = ["dome_elevation", "scattered_points"]

#: Extent of the survey area in local metres (added to the origin).
EXTENT = 1000.0


def dome_elevation(x: ArrayLike, y: ArrayLike) -> NDArray[np.float64]:
    """The true surface: a dome with a fold, in local metres (x, y in ``[0, 1000]``).

    >>> float(dome_elevation(500.0, 500.0))
    -120.0
    """
    u = np.asarray(x, dtype=np.float64) / EXTENT - 0.5
    v = np.asarray(y, dtype=np.float64) / EXTENT - 0.5
    dome = -200.0 + 80.0 * np.exp(-(u**2 + v**2) / 0.08)
    fold = 15.0 * np.sin(2.0 * np.pi * (u + 0.5 * v)) * np.exp(-(v**2) / 0.1)
    return np.asarray(dome + fold, dtype=np.float64)


def scattered_points(
    n_core: int = 300,
    n_rim: int = 300,
    noise: float = 0.2,
    seed: int = 0,
    origin: tuple[float, float, float] = (450_000.0, 6_700_000.0, 0.0),
) -> PointSet:
    """Points on :func:`dome_elevation`: a dense, even core grid and a sparse, noisy rim.

    The core is a jittered grid over the central 40 % of the area with exact elevations (like
    boreholes and adits near a dam site); the rim points are uniform over the rest with Gaussian
    noise of standard deviation ``noise`` metres. Point property ``core`` is 1 for core points,
    ``true_z`` holds the noise-free elevation.

    >>> pts = scattered_points()
    >>> pts.n_points, int(pts.point_data["core"].values.sum())
    (600, 300)
    """
    if n_core < 0 or n_rim < 0 or noise < 0:
        raise ValueError("n_core, n_rim and noise must be ≥ 0")
    rng = np.random.default_rng(seed)
    side = max(1, int(np.ceil(np.sqrt(n_core))))
    g = (np.arange(side) + 0.5) / side
    gx, gy = np.meshgrid(g, g)
    core = np.column_stack([gx.ravel(), gy.ravel()])[:n_core]
    core = 0.3 + 0.4 * (core + rng.uniform(-0.2, 0.2, core.shape) / side)
    rim = np.empty((0, 2))
    while len(rim) < n_rim:
        candidates = rng.uniform(0.0, 1.0, (2 * n_rim, 2))
        outside = np.any(np.abs(candidates - 0.5) > 0.22, axis=1)
        rim = np.concatenate([rim, candidates[outside]])[:n_rim]
    xy = np.concatenate([core, rim]) * EXTENT
    true_z = dome_elevation(xy[:, 0], xy[:, 1])
    z = true_z + np.concatenate([np.zeros(len(core)), rng.normal(0.0, noise, len(rim))])
    vertices = np.column_stack([xy, z]) + np.asarray(origin)
    return PointSet(
        vertices=vertices,
        name="survey points",
        kind="horizon",
        point_data={
            "core": Property(
                values=np.r_[np.ones(len(core), np.int8), np.zeros(len(rim), np.int8)],
                description="1 for the dense exact core, 0 for the sparse rim",
            ),
            "true_z": Property(
                values=true_z + origin[2],
                unit="m",
                description="noise-free elevation of the sampled surface",
            ),
        },
        metadata={"crs": CRS(epsg=32631).label, "noise_m": noise, "seed": seed},
    )
