"""geoh5's own desurveying of a drillhole and the surveys geobrep writes for a well.

A geoh5 drillhole's surveys are float32 rows (``Depth``, ``Azimuth``, ``Dip``): depth along the
hole from the collar, azimuth clockwise from north and dip from the horizontal, positive up (a
vertical hole dips -90). geoh5 (Geoscience ANALYST, and geoh5py, whose ``Drillhole.desurvey``
says it is translated from ANALYST's C++) places a depth on an arc between two survey rows after
densifying the survey: a row at depth 0 repeats the first row, a row at the end of hole repeats
the last, and intervals of 50 m or more get rows every 50 m, azimuth and dip linear in depth
(only when two or more intervals are that long: geoh5py's condition, kept). Between rows the
hole is the circular arc tangent to both directions, as minimum curvature.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

__all__ = ["SURVEY_DTYPE", "desurvey", "station_surveys"]

#: geoh5's survey rows.
SURVEY_DTYPE = np.dtype([("Depth", "<f4"), ("Azimuth", "<f4"), ("Dip", "<f4")])
_INFINITE_RADIUS = 99999.9
_MAXIMUM_INTERVAL = 50.0


def station_surveys(vertices: NDArray[np.float64], md: NDArray[np.float64]) -> NDArray[np.void]:
    """Survey rows of the stations of a well: its MD and the azimuth and dip of the hole there
    (the direction between the neighbouring stations; vertical down for a single station)."""
    n = vertices.shape[0]
    rows = np.zeros(n, dtype=SURVEY_DTYPE)
    rows["Depth"] = md
    rows["Dip"] = -90.0
    if n < 2:
        return rows
    ahead = np.vstack([vertices[1:], vertices[-1:]])
    behind = np.vstack([vertices[:1], vertices[:-1]])
    direction = ahead - behind
    horizontal = np.hypot(direction[:, 0], direction[:, 1])
    rows["Azimuth"] = np.degrees(np.arctan2(direction[:, 0], direction[:, 1])) % 360.0
    rows["Dip"] = np.degrees(np.arctan2(direction[:, 2], horizontal))
    return rows


def _unit_vectors(dip: NDArray[np.float64], azimuth: NDArray[np.float64]) -> NDArray[np.float64]:
    azi, dip_r = np.radians(90.0 - azimuth), np.radians(dip)
    return np.column_stack(
        [np.cos(dip_r) * np.cos(azi), np.cos(dip_r) * np.sin(azi), np.sin(dip_r)]
    )


def _densified(survey: NDArray[np.float64], end_of_hole: float | None) -> NDArray[np.float64]:
    """The survey rows geoh5 desurveys: depth 0, end of hole and 50 m rows added, sorted."""
    full = survey
    if survey[0, 0] != 0.0:
        full = np.vstack([[0.0, survey[0, 1], survey[0, 2]], full])
    if end_of_hole is not None and end_of_hole > full[-1, 0]:
        full = np.vstack([full, [end_of_hole, full[-1, 1], full[-1, 2]]])
    deltas = np.diff(full[:, 0])
    long = deltas >= _MAXIMUM_INTERVAL
    if np.count_nonzero(long) > 1:
        counts = np.where(long, np.ceil(deltas / _MAXIMUM_INTERVAL).astype(np.int64) - 1, 0)
        counts = np.maximum(counts, 0)
        interval = np.repeat(np.arange(deltas.shape[0]), counts)
        step = np.arange(interval.shape[0]) - np.repeat(np.cumsum(counts) - counts, counts) + 1
        offset = step * _MAXIMUM_INTERVAL
        slope = (full[interval + 1, 1:] - full[interval, 1:]) / deltas[interval, None]
        added = np.column_stack(
            [full[interval, 0] + offset, full[interval, 1:] + slope * offset[:, None]]
        )
        full = np.vstack([full, added])
    return np.unique(full, axis=0)


def desurvey(
    collar: ArrayLike, surveys: ArrayLike, end_of_hole: float | None, depths: ArrayLike
) -> NDArray[np.float64]:
    """XYZ ``(n, 3)`` geoh5 gives depths ``depths`` of a hole from ``collar`` with survey rows
    ``surveys (m, 3)`` (depth, azimuth, dip), as geoh5py's ``Drillhole.desurvey``."""
    survey = np.asarray(surveys, dtype=np.float64).reshape(-1, 3)
    start = np.asarray(collar, dtype=np.float64).reshape(1, 3)
    full = _densified(survey, end_of_hole)
    unit = _unit_vectors(full[:, 2], full[:, 1])
    if survey.shape[0] < 2:
        rows, radius = np.zeros(1), np.array([_INFINITE_RADIUS])
        tangential, locations = np.zeros((1, 3)), start
    else:
        vr = np.linalg.norm(np.cross(unit[:-1], unit[1:]), axis=1)
        dot = np.einsum("ij,ij->i", unit[:-1], unit[1:])
        tangential = unit[1:] - dot[:, None] * unit[:-1]
        norm = np.linalg.norm(tangential, axis=1)
        norm[norm == 0.0] = _INFINITE_RADIUS
        tangential = np.vstack([tangential / norm[:, None], np.zeros((1, 3))])
        alpha = np.abs(0.5 * np.pi - np.arctan2(dot, vr))
        alpha[alpha == 0.0] = 1.0 / _INFINITE_RADIUS
        arc = np.diff(full[:, 0]) / alpha
        steps = arc[:, None] * (
            np.sin(alpha)[:, None] * unit[:-1] + (1 - np.cos(alpha))[:, None] * tangential[:-1]
        )
        rows, radius = full[:, 0], np.append(arc, _INFINITE_RADIUS)
        locations = np.vstack([start, start + np.cumsum(steps, axis=0)])
    at = np.asarray(depths, dtype=np.float64).ravel()
    index = np.searchsorted(rows, at, side="right") - 1
    along = at - rows[index]
    radii = radius[index]
    radii[radii == 0.0] = 1.0
    angle = along / radii
    placed: NDArray[np.float64] = locations[index] + radii[:, None] * (
        np.sin(angle)[:, None] * unit[index] + (1 - np.cos(angle))[:, None] * tangential[index]
    )
    return placed
