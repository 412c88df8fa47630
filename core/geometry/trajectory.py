"""Well trajectories: stations from measured depth, inclination and azimuth (minimum curvature).

Inclination is measured from the vertical (0 = straight down), azimuth clockwise from north
(+y), both in degrees. Offsets are east (x), north (y) and *up* (z = -TVD), so a vertical well
goes to negative z.

>>> import numpy as np
>>> xyz = minimum_curvature([0, 100], [0, 90], [0, 90])
>>> np.round(xyz, 6).tolist()  # a quarter circle of radius 200/pi from vertical to east
[[0.0, 0.0, 0.0], [63.661977, 0.0, -63.661977]]
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["minimum_curvature", "tangents"]


def tangents(inclination: ArrayLike, azimuth: ArrayLike) -> NDArray[np.float64]:
    """Unit direction ``(n, 3)`` (east, north, up) of each station."""
    inc = np.radians(np.asarray(inclination, dtype=np.float64))
    azi = np.radians(np.asarray(azimuth, dtype=np.float64))
    return np.stack([np.sin(inc) * np.sin(azi), np.sin(inc) * np.cos(azi), -np.cos(inc)], axis=1)


def minimum_curvature(
    md: ArrayLike, inclination: ArrayLike, azimuth: ArrayLike
) -> NDArray[np.float64]:
    """Station offsets ``(n, 3)`` from the first station by the minimum-curvature method.

    Each interval is a circular arc tangent to both stations' directions: the chord is
    ``ΔMD/2 · (t1 + t2) · RF`` with the ratio factor ``RF = tan(β/2) / (β/2)`` of the dogleg
    angle ``β`` (1 for a straight interval).
    """
    depths = np.asarray(md, dtype=np.float64)
    t = tangents(inclination, azimuth)
    if depths.shape[0] < 2:
        return np.zeros((depths.shape[0], 3))
    t1, t2 = t[:-1], t[1:]
    cos_beta = np.clip(np.einsum("ij,ij->i", t1, t2), -1.0, 1.0)
    beta = np.arccos(cos_beta)
    half = beta / 2.0
    small = half < 1e-9
    ratio = np.where(small, 1.0, np.tan(np.where(small, 1.0, half)) / np.where(small, 1.0, half))
    steps = (np.diff(depths) / 2.0 * ratio)[:, None] * (t1 + t2)
    return np.vstack([np.zeros((1, 3)), np.cumsum(steps, axis=0)])
