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

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["ARC_AGREEMENT", "StationPath", "angles", "arc_points", "minimum_curvature", "tangents"]

#: Two stations are joined by the minimum-curvature arc of their angles when that arc ends this
#: close to the second station, relative to the interval's measured depth.
ARC_AGREEMENT = 1e-7


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


def angles(directions: ArrayLike) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Inclination and azimuth in degrees (azimuth in ``[0, 360)``) of unit directions ``(n, 3)``.

    >>> inc, azi = angles(tangents([30.0], [300.0]))
    >>> np.round(inc, 9).tolist(), np.round(azi, 9).tolist()
    ([30.0], [300.0])
    """
    t = np.asarray(directions, dtype=np.float64).reshape(-1, 3)
    inclination = np.degrees(np.arccos(np.clip(-t[:, 2], -1.0, 1.0)))
    azimuth = np.mod(np.degrees(np.arctan2(t[:, 0], t[:, 1])), 360.0)
    return inclination, np.where(azimuth >= 360.0, 0.0, azimuth)


def arc_points(
    start: ArrayLike, t1: ArrayLike, t2: ArrayLike, length: ArrayLike, fraction: ArrayLike
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Points and unit tangents ``(n, 3)`` a ``fraction`` of the way along minimum-curvature arcs.

    Arc ``i`` leaves ``start[i]`` in direction ``t1[i]`` and arrives in direction ``t2[i]`` after
    ``length[i]`` (a measured-depth interval): a circular arc of dogleg ``β`` and radius
    ``length / β``, or a straight line when ``β`` is 0. ``fraction`` 1 gives the station
    :func:`minimum_curvature` puts at the end of the interval.

    >>> point, tangent = arc_points([[0, 0, 0]], tangents([0], [90]), tangents([90], [90]),
    ...                             [100.0], [1.0])
    >>> np.round(point, 6).tolist(), (np.round(tangent, 12) + 0.0).tolist()
    ([[63.661977, 0.0, -63.661977]], [[1.0, 0.0, 0.0]])
    """
    p0 = np.asarray(start, dtype=np.float64).reshape(-1, 3)
    a = np.asarray(t1, dtype=np.float64).reshape(-1, 3)
    b = np.asarray(t2, dtype=np.float64).reshape(-1, 3)
    s = np.asarray(length, dtype=np.float64).reshape(-1) * np.asarray(fraction, np.float64)
    span = np.asarray(length, dtype=np.float64).reshape(-1)
    beta = np.arccos(np.clip(np.einsum("ij,ij->i", a, b), -1.0, 1.0))
    straight = beta < 1e-9
    sin_beta = np.where(straight, 1.0, np.sin(beta))
    # the unit normal in the arc's plane, pointing from t1 towards t2
    normal = (b - np.cos(beta)[:, None] * a) / sin_beta[:, None]
    radius = np.where(straight, 0.0, span / np.where(straight, 1.0, beta))
    phi = np.where(straight, 0.0, s / np.where(radius == 0.0, 1.0, radius))
    bent = p0 + radius[:, None] * (np.sin(phi)[:, None] * a + (1.0 - np.cos(phi))[:, None] * normal)
    line = p0 + s[:, None] * a
    points = np.where(straight[:, None], line, bent)
    direction = np.where(
        straight[:, None], a, np.cos(phi)[:, None] * a + np.sin(phi)[:, None] * normal
    )
    return points, direction


@dataclass(frozen=True)
class StationPath:
    """A path through stations as a function of measured depth.

    Between two stations whose inclination and azimuth give the second from the first by the
    minimum-curvature method (within :data:`ARC_AGREEMENT`), the path is that method's circular
    arc; elsewhere (or without angles) the straight segment between them.

    >>> md = np.array([0.0, 100.0])
    >>> path = StationPath.of(md, minimum_curvature(md, [0, 90], [0, 90]), [0, 90], [0, 90])
    >>> np.round(path.at(np.array([50.0]))[0], 6).tolist()  # half way round the quarter circle
    [[18.646161, 0.0, -45.015816]]
    """

    md: NDArray[np.float64]
    xyz: NDArray[np.float64]
    direction: NDArray[np.float64] | None
    arc: NDArray[np.bool_]

    @classmethod
    def of(
        cls,
        md: ArrayLike,
        xyz: ArrayLike,
        inclination: ArrayLike | None = None,
        azimuth: ArrayLike | None = None,
    ) -> StationPath:
        depths = np.asarray(md, dtype=np.float64).reshape(-1)
        points = np.asarray(xyz, dtype=np.float64).reshape(-1, 3)
        arc = np.zeros(max(depths.shape[0] - 1, 0), dtype=bool)
        if inclination is None or azimuth is None or depths.shape[0] < 2:
            return cls(depths, points, None, arc)
        direction = tangents(inclination, azimuth)
        steps = np.diff(minimum_curvature(depths, inclination, azimuth), axis=0)
        error = np.linalg.norm(steps - np.diff(points, axis=0), axis=1)
        arc = np.isfinite(error) & (error <= ARC_AGREEMENT * np.diff(depths))
        return cls(depths, points, direction if arc.any() else None, arc)

    def at(
        self, md: ArrayLike
    ) -> tuple[
        NDArray[np.float64], NDArray[np.int64], NDArray[np.float64], NDArray[np.float64] | None
    ]:
        """Points at ``md`` (clamped to the stations' range), each depth's interval, the fraction
        of it, and the path's direction there (None without arcs)."""
        depths = np.asarray(md, dtype=np.float64).reshape(-1)
        k = np.clip(np.searchsorted(self.md, depths, side="right") - 1, 0, max(len(self.md) - 2, 0))
        if self.md.shape[0] < 2:
            points = np.repeat(self.xyz[:1], depths.shape[0], axis=0)
            return points, k.astype(np.int64), np.zeros_like(depths), None
        span = self.md[k + 1] - self.md[k]
        fraction = np.clip((depths - self.md[k]) / span, 0.0, 1.0)
        start, end = self.xyz[k], self.xyz[k + 1]
        points = start + fraction[:, None] * (end - start)
        direction = None
        if self.direction is not None:
            bent, direction = arc_points(
                start, self.direction[k], self.direction[k + 1], span, fraction
            )
            points = np.where(self.arc[k][:, None], bent, points)
        points = np.where((fraction == 0.0)[:, None], start, points)
        points = np.where((fraction == 1.0)[:, None], end, points)
        return points, k.astype(np.int64), fraction, direction
